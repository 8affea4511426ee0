"""``antenna estimate``: the contact point of one recording (Section 4 pipeline or a baseline)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from sensing_antenna.cli.arguments import number, printable

#: The antenna an estimate uses without --antenna.
DEFAULT_ANTENNA = "paper-2021"

#: The names of :data:`sensing_antenna.estimation.METHODS`, in the order ``--help`` lists them.
#: Written out so that parsing arguments does not import the estimators (``antenna estimate
#: --help`` and an argument error answer at once); ``tests/test_cli_estimate.py`` checks that
#: they are the registry's names.
METHOD_NAMES = ("fast", "paper", "ratio", "two-frequency")


def register(subparsers: Any) -> None:
    """Add ``antenna estimate``."""
    parser = subparsers.add_parser(
        "estimate",
        help="estimate the contact point of a recording (CSV)",
        description=(
            "Estimates where the link touched from a recording of one contact manoeuvre (the "
            "format of docs/recording-format.md): the contact instant t_c, the push and its end "
            "t_1, the vibration after it, and the contact point x_c along the link with its 3D "
            "point. Prints the status (ok, or why no confirmed estimate), x_c, the candidates, "
            "the fundamental frequency and the instants; --json prints one JSON object."
        ),
    )
    parser.add_argument("recording", type=Path, help="recording in the sensing-antenna format")
    parser.extra_positional_hint = (
        "estimate reads one recording: run it once per file, or give them all to antenna map"
        " or antenna calibrate"
    )
    parser.add_argument(
        "--method",
        choices=METHOD_NAMES,
        default="paper",
        help="paper (Section 4), fast (short record, stops when sure), or a baseline",
    )
    parser.add_argument(
        "--tolerance",
        type=number(low=0.0, high=0.1, low_open=True, unit="m"),
        default=None,
        metavar="M",
        help="fast method: declare when the 95 %% interval of x_c is narrower than this (m, at "
        "most 0.1; default: the fast method's, 0.005), or earlier within 1 cm when the model's "
        "floors hold it wider; at the cap the answer is ok within 1 cm or this, if larger",
    )
    parser.add_argument(
        "--t1",
        choices=("rest", "push"),
        default="rest",
        help="t_1 from the head coming to rest (any device) or from the default push "
        "criterion's decision (a device that stops with it, such as our simulator)",
    )
    parser.add_argument(
        "--antenna", default=None, help=f"built-in name or TOML file (default {DEFAULT_ANTENNA})"
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    from sensing_antenna.antenna import load_antenna
    from sensing_antenna.estimation.config import EstimatorConfig
    from sensing_antenna.estimation.pipeline import estimate
    from sensing_antenna.recording import read_recording

    method: Any = args.method
    if args.tolerance is not None:
        method = _fast_with_tolerance(args.method, args.tolerance)
    antenna = load_antenna(DEFAULT_ANTENNA if args.antenna is None else args.antenna)
    recording = read_recording(args.recording)
    warn_of_contradicted_period(args.recording, recording.period_problem)
    if args.antenna is None:  # the default: recordings of another antenna are warned of
        warn_of_other_antennas(
            {recording.metadata.get("antenna", ""): [str(args.recording)]}, antenna.name
        )
    result = estimate(recording, antenna, method=method, config=EstimatorConfig(t1_source=args.t1))
    warn_of_a_second_contact(args.recording, recording, antenna, result.t_c, result.t_1)
    if args.json:
        data = {"recording": str(args.recording), **result.to_dict()}
        print(json.dumps(data, allow_nan=False))
    else:
        print(summary(str(args.recording), result.to_dict()))
    return 0


def other_antennas(
    named: Mapping[str, Sequence[str]], model: str, use: str = "estimated"
) -> list[str]:
    """A warning for each antenna that recordings' ``antenna`` metadata names (``named``:
    that name, "" when absent, to the recordings' sources) other than the built-in ``model``
    the command falls back on (``use``: what it does with them, "estimated" or "checked"): the
    device's observer, threshold and stiffness are in its own file, and estimates with
    another's can go wrong in ways that look like bad data (a contact missed, a push that
    seems to turn the wrong way)."""
    consequence = (
        "its loads at rest are judged against another link's weight"
        if use == "checked"
        else "with another's observer and stiffness a good recording can come back "
        "implausible_input or no_contact"
    )
    warnings = []
    for recorded, sources in named.items():
        if not recorded or recorded == model or not sources:
            continue
        which = sources[0]
        if len(sources) > 1:
            which = f"{len(sources)} recording(s) ({sources[0]} and {len(sources) - 1} more)"
        warnings.append(
            f"{which} recorded with antenna {printable(recorded)!r} (its metadata) and {use} "
            f"with the default {printable(model)!r}: give that antenna's file with --antenna "
            f"({consequence})"
        )
    return warnings


def warn_of_other_antennas(
    named: Mapping[str, Sequence[str]], model: str, use: str = "estimated"
) -> None:
    """:func:`other_antennas`' warnings, a line each on stderr."""
    for warning in other_antennas(named, model, use):
        print(f"antenna: warning: {warning}", file=sys.stderr)


def warn_of_a_second_contact(
    source: object, recording: Any, antenna: Any, t_c: float, t_1: float
) -> None:
    """A line on stderr when ``recording`` touches again after its contact at ``t_c`` (s) was
    lost after the head's rest at ``t_1`` (s) (:func:`~sensing_antenna.detection.
    contact_watch.contact_changes`): the estimate is the first contact's, the second is not
    estimated. A contact lost before t_1 was no touch; the estimate's status says so."""
    from sensing_antenna.detection.contact_watch import contact_changes, lost_before_rest
    from sensing_antenna.errors import SensingAntennaError

    if not math.isfinite(t_c):
        return
    try:
        found = contact_changes(recording, antenna, t_c)
    except SensingAntennaError:
        return  # samples the detector refuses: the estimate's status says what is wrong
    changes = {change.kind: change for change in found}
    if "again" not in changes or not math.isfinite(t_1) or lost_before_rest(found, t_1):
        return
    print(
        f"antenna: warning: {source}: the link touched again at t = {changes['again'].t:.3f} s, "
        f"after the contact at t_c = {t_c:.3f} s was lost at {changes['lost'].t:.3f} s: not "
        "estimated (a recording holds one contact, the estimate is the first's: cut a log of "
        "several sweeps into one recording per sweep, docs/import.md)",
        file=sys.stderr,
    )


def warn_of_contradicted_period(source: object, problem: str | None) -> None:
    """One line on stderr naming ``source`` when its recording's ``sample_period`` metadata
    disagrees with its time stamps (``problem``:
    :attr:`~sensing_antenna.recording.Recording.period_problem`): the estimators go by the
    stamps, and one of the two is wrong."""
    if problem is not None:
        print(f"antenna: warning: {source}: {problem}", file=sys.stderr)


def _fast_with_tolerance(method: str, tolerance: float) -> Any:
    from sensing_antenna.errors import SensingAntennaError
    from sensing_antenna.estimation.methods.fast import FastConfig, FastMethod

    if method != "fast":
        raise SensingAntennaError(f"--tolerance: only used by --method fast, not {method!r}")
    default = FastConfig()
    # a tolerance looser than the cap's makes the cap's as loose
    return FastMethod(
        FastConfig(tolerance=tolerance, cap_tolerance=max(default.cap_tolerance, tolerance))
    )


def _cm(value: Any) -> str:
    """A length (m) in cm to the millimetre; in m, said to be no link's, from 1 km (loads in
    other units make ratios of 10^3 to 10^70 m)."""
    if value is None:
        return "-"
    if abs(value) < 1e3:
        return f"{100 * value:.1f} cm"
    return f"{value:.3g} m (no point of a link: loads in other units?)"


def _s(value: Any) -> str:
    return "-" if value is None else f"{value:.3f} s"


def summary(name: str, data: dict[str, Any]) -> str:
    """Human-readable lines for an estimate's ``to_dict()`` (units for display only)."""
    omega = data["omega1"]
    omega_text = "-" if omega is None else f"{omega:.2f} rad/s ({omega / (2 * math.pi):.2f} Hz)"
    point = data["contact_point"]
    point_text = (
        "-" if point[0] is None else "(" + ", ".join(f"{100 * v:.1f}" for v in point) + ") cm"
    )
    x_c_text = _cm(data["x_c"])
    if data["status"] != "ok" and data["x_c"] is not None:
        x_c_text += " (best guess, not confirmed: see the status)"
    lines = [
        f"{name}: method {data['method']}",
        f"  status          {data['status']}" + (f" ({data['reason']})" if data["reason"] else ""),
        f"  x_c             {x_c_text}",
        f"  candidates      {', '.join(_cm(c) for c in data['candidates']) or '-'}",
        f"  omega_1         {omega_text}",
        f"  ratio estimate  {_cm(data['ratio_estimate'])}",
        f"  t_c, t_1, t_e   {_s(data['t_c'])}, {_s(data['t_1'])}, {_s(data['t_e'])}",
        f"  contact point   {point_text} (absolute frame)",
    ]
    start = data.get("diagnostics", {}).get("window_start")
    if start is not None and data["t_1"] is not None and start > data["t_1"]:
        lines.append(f"  window from     {_s(start)} (the contact bounced after t_1)")
    interval = data.get("interval")
    if interval is not None:
        lines.append(f"  95 % interval   {_cm(interval[0])} to {_cm(interval[1])}")
    before = data.get("diagnostics", {}).get("second_mode_narrowing", {}).get("interval_before")
    if before is not None:
        lines.append(
            f"                  narrowed at the cap by omega_2 from {_cm(before[0])} to "
            f"{_cm(before[1])}"
        )
    probability = data.get("branch_probability")
    if probability:
        lines.append("  branch prob.    " + ", ".join(f"{p:.3f}" for p in probability))
    diagnostics = data.get("diagnostics", {})
    sampling = diagnostics.get("sampling")
    dropped = sampling.get("n_dropped") if isinstance(sampling, dict) else None
    dropped = dropped or diagnostics.get("filled_samples")
    if dropped:
        lines.append(f"  missing         {dropped} sample(s), bridged by straight lines")
    repaired = diagnostics.get("repaired_samples", [])
    if repaired:
        where = ", ".join(_put_back(r) for r in repaired[:3])
        more = f" and {len(repaired) - 3} more" if len(repaired) > 3 else ""
        lines.append(f"  put back        sensor samples off their neighbours at {where}{more}")
    return "\n".join(lines)


def _put_back(repaired: dict[str, Any]) -> str:
    """One run of samples put back: its time, channels and length (when more than one)."""
    count = repaired["samples"]
    length = f", {count} samples" if count > 1 else ""
    return f"{_s(repaired['t'])} ({' '.join(repaired['channels'])}{length})"
