"""``antenna simulate``: run the simulated device and write a recording."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from sensing_antenna.cli.arguments import ArgumentError, check_contact_points, number

#: The cases of :class:`sensing_antenna.simulator.Scenario`, in the order ``--help`` lists them.
CASES = ("azimuthal", "vertical", "free", "free-vertical")
_FREE = ("free", "free-vertical")

#: The scenario's fields the command fills from its flags: an error about one names the flag.
FLAGS = {
    "case": "--case",
    "contact_point": "--xc",
    "seed": "--seed",
    "duration": "--duration",
    "noise_scale": "--noise",
    "device": "--device",
    "link_model": "--link",
    "push": "--push",
}


def register(subparsers: Any) -> None:
    """Add ``antenna simulate``."""
    parser = subparsers.add_parser(
        "simulate",
        help="simulate one contact manoeuvre and write a recording (CSV)",
        description=(
            "Simulates the 2-DOF head of the antenna sweeping its flexible link (azimuthal: "
            "theta1 into a vertical post; vertical: theta2 up into a horizontal bar; free and "
            "free-vertical: those sweeps with nothing to touch, recordings for antenna "
            "identify), with "
            "sensor noise, the motors stopped by the push criterion, and writes the recording "
            "with its ground truth as metadata. --xc is the nominal contact point, where the "
            "undeflected link meets the obstacle; the link bends as it pushes, and the line "
            "printed says where it actually touched (true_xc in the file)."
        ),
    )
    parser.add_argument("--case", choices=CASES, required=True, help="the manoeuvre")
    parser.add_argument(
        "--xc",
        type=number(unit="m", finite=False),
        default=None,
        metavar="M",
        help="nominal contact point x_c, in (0, l] (m): required for the azimuthal and vertical "
        "cases, not given for the free ones",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of every random quantity, such as the sensor noise",
    )
    parser.add_argument(
        "--duration",
        type=float,
        default=3.0,
        help="total time (s); a deeper --push stops later, and the estimators need 1 s "
        "(EstimatorConfig.spectrum_window) after the stop: the command warns when it is short",
    )
    parser.add_argument("--noise", type=float, default=1.0, help="sensor noise scale (0: none)")
    parser.add_argument(
        "--direction",
        choices=("up", "down"),
        default="up",
        help="the swept joint turns up (towards +Y^m, or lifting the link towards +Z^m) or "
        "down (towards -Y^m, or lowering the link onto a bar below it)",
    )
    parser.add_argument("--antenna", default="paper-2021", help="built-in name or TOML file")
    parser.add_argument(
        "--controller",
        default=None,
        metavar="FILE",
        help="an antenna file (what antenna identify or calibrate wrote) whose observer and "
        "contact threshold the simulated head's controller uses, as a lab's head uses its "
        "identified file; the link simulated stays --antenna's, with --device's imperfections "
        "(default: --antenna's observer)",
    )
    parser.add_argument(
        "--device",
        default="nominal",
        metavar="PROFILE|FILE",
        help="imperfections of the simulated device that the antenna does not know: nominal "
        "(none), realistic (one set drawn from --seed, docs/simulator.md) or a TOML file of "
        'DeviceImperfections fields (optionally with profile = "realistic" under them, and '
        "build = N: the realistic device N, whose manoeuvres differ only in set-up)",
    )
    parser.add_argument(
        "--push",
        type=float,
        default=None,
        metavar="RAD",
        help="stop the motors this far (rad of head rotation) past the detected contact, instead "
        "of the push criterion's default 0.03 rad: deeper pushes bend the link more",
    )
    parser.add_argument(
        "--retract-after",
        type=number(0.0, unit="s"),
        default=None,
        metavar="S",
        help="turn the head back along the sweep by 0.1 rad this long after the stop, so the "
        "link leaves the obstacle (Scenario.retract_after); default: hold to the end",
    )
    parser.add_argument(
        "--link",
        choices=("linear", "nonlinear"),
        default="linear",
        help="the link's model: linear (small deflection) or nonlinear (geometrically exact, "
        "for pushes beyond 10 %% of x_c; about 3 times slower)",
    )
    parser.add_argument(
        "--sample-rate",
        type=number(0.0, low_open=True, unit="Hz"),
        default=None,
        metavar="HZ",
        help="the device's sampling and control rate: the recording's samples and the head's "
        "controller loop (Hz; default 1000, the paper's device)",
    )
    parser.add_argument(
        "--commands",
        action="store_true",
        help="also record the motor voltages u1, u2 (what antenna identify --servo fits)",
    )
    parser.add_argument("--out", type=Path, required=True, help="output CSV file")
    parser.set_defaults(func=_run, flags=FLAGS)


def _run(args: argparse.Namespace) -> int:
    import sys

    from sensing_antenna.antenna import load_antenna
    from sensing_antenna.detection.push import PushConfigError, PushCriterion
    from sensing_antenna.recording import write_recording
    from sensing_antenna.simulator import Scenario, simulate
    from sensing_antenna.simulator.run import deflection_warning, sampling_warning
    from sensing_antenna.simulator.scenario import DEFAULT_SAMPLE_PERIOD, SAMPLE_PERIOD_RANGE

    period = DEFAULT_SAMPLE_PERIOD if args.sample_rate is None else 1.0 / args.sample_rate
    if not SAMPLE_PERIOD_RANGE[0] <= period <= SAMPLE_PERIOD_RANGE[1]:
        raise ArgumentError(
            "--sample-rate",
            f"must be between {1 / SAMPLE_PERIOD_RANGE[1]:g} and {1 / SAMPLE_PERIOD_RANGE[0]:g}"
            f" Hz, got {args.sample_rate:g}",
        )
    antenna = load_antenna(args.antenna)
    if args.controller is not None:
        from sensing_antenna.campaign.simulated import knowing_weight

        antenna = knowing_weight(antenna, load_antenna(args.controller))
    _check_contact_point(args.case, args.xc, antenna.link)
    device = load_device(args.device, args.seed, antenna.link.length)
    push = None
    if args.push is not None:
        try:
            push = PushCriterion(kind="rotation", threshold=args.push)
        except PushConfigError as exc:
            raise ArgumentError("--push", str(exc).split(": ", 1)[-1]) from exc
    scenario = Scenario(
        case=args.case,
        contact_point=args.xc,
        seed=args.seed,
        duration=args.duration,
        noise_scale=args.noise,
        device=device,
        link_model=args.link,
        push=push,
        sweep_direction=1 if args.direction == "up" else -1,
        retract_after=args.retract_after,
        sample_period=period,
    )
    recording = simulate(antenna, scenario, record_commands=args.commands)
    write_recording(recording, args.out)
    print(summary(str(args.out), scenario, recording.n_samples, recording.metadata))
    coarse = sampling_warning(antenna, scenario.sample_period)
    if coarse is not None:
        print(f"warning: {coarse} (--sample-rate)", file=sys.stderr)
    short = window_warning(scenario, recording.metadata, antenna)
    if short is not None:
        print(short, file=sys.stderr)
    warning = None if args.link == "nonlinear" else deflection_warning(recording)
    if warning is not None and args.push is not None:
        # the deep push was asked for: what is wrong is the linear link, not the detection
        warning = (
            f"{warning.split(' (Assumption 1)')[0]} of the linear link (Assumption 1): "
            "--link nonlinear simulates such a push correctly"
        )
    if warning is not None:
        print(warning, file=sys.stderr)
    return 0


def load_device(value: str, seed: int, length: float) -> Any:
    """The ``DeviceImperfections`` of ``--device``: a profile name or a TOML file.

    A file holds ``DeviceImperfections`` fields at its top level or in a ``[device]`` table,
    and may name a ``profile`` whose draw (from ``seed``) its fields are set over, and the
    ``build`` of that profile's device (manoeuvres with one build share one device).
    """
    import tomllib
    from dataclasses import replace

    from sensing_antenna.simulator import DEVICE_PROFILES, device_from_mapping, device_profile

    if value in DEVICE_PROFILES:
        return device_profile(value, seed, length)
    path = Path(value)
    if not path.is_file():
        raise ArgumentError(
            "--device", f"{value!r} is neither a profile ({', '.join(DEVICE_PROFILES)}) nor a file"
        )
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise ArgumentError("--device", f"{value}: not a TOML file ({exc})") from exc
    table = data.get("device", data)
    if not isinstance(table, dict):
        raise ArgumentError("--device", f"{value}: [device] must be a table")
    table = dict(table)
    profile = table.pop("profile", "nominal")
    if profile not in DEVICE_PROFILES:
        raise ArgumentError(
            "--device",
            f"{value}: profile must be one of {', '.join(DEVICE_PROFILES)}, got {profile!r}",
        )
    build = table.pop("build", None)
    if build is not None and (isinstance(build, bool) or not isinstance(build, int) or build < 0):
        raise ArgumentError(
            "--device", f"{value}: build must be an integer >= 0 (a seed), got {build!r}"
        )
    fixed = device_from_mapping(table, value)
    given = {key: getattr(fixed, key) for key in table}
    return replace(device_profile(profile, seed, length, build), **given)


def _check_contact_point(case: str, x_c: float | None, link: Any) -> None:
    """--xc against --case and the link: every message names --xc and the range (0, l] m."""
    allowed = f"a contact point in (0, {link.length:g}] m"
    if case in _FREE and x_c is not None:
        raise ArgumentError("--xc", f"not used with --case {case} (the link touches nothing)")
    if case not in _FREE and x_c is None:
        raise ArgumentError("--xc", f"required with --case {case}: {allowed}")
    if x_c is not None:
        check_contact_points(link, [x_c])


def summary(out: str, scenario: Any, n_samples: int, meta: Any) -> str:
    """The line printed for a simulated recording: where the link touched, and when.

    ``scenario`` is the :class:`~sensing_antenna.simulator.Scenario` simulated, ``meta`` the
    recording's metadata (its ``true_*`` keys).
    """
    text = f"{out}: {n_samples} samples, {scenario.case}"
    x_c = scenario.contact_point
    if x_c is None:
        return text
    touched = float(meta.get("true_xc", "nan"))
    if not math.isfinite(touched):
        return (
            f"{text}, no contact: the link did not reach the obstacle (--xc {x_c:g} m) within "
            f"the {scenario.duration:g} s simulated; a longer --duration lets it"
        )
    stop = float(meta.get("true_t_stop", "nan"))
    if math.isfinite(stop):
        when = f"stop {stop:.4g} s"
    else:
        when = (
            f"the push was not reached within --duration {scenario.duration:g} s (the motors "
            "never stopped; a longer --duration or a shallower --push lets them)"
        )
    deflection = float(meta.get("true_deflection_ratio", "nan"))
    bend = f", y_c / x_c = {100 * deflection:.1f} %" if math.isfinite(deflection) else ""
    return (
        f"{text}, the link touched at x_c = {touched:.4f} m (--xc {x_c:g} m is where the "
        f"undeflected link meets the obstacle; it bends as it pushes), first touch "
        f"{float(meta['true_t_contact']):.4g} s, {when}{bend}"
    )


#: Time constants of the servo (-1 / servo_pole) after the stop within which the head is at rest
#: (e^-5 < 1 %): t_1, where the estimators' spectrum window starts, follows the stop by that much
#: at most.
SETTLING_TIME_CONSTANTS = 5.0


def window_warning(scenario: Any, meta: Any, antenna: Any) -> str | None:
    """One line when the recording ends less than the estimators' spectrum window for
    ``antenna``'s link (``EstimatorConfig.spectrum_window``) after the head comes to rest, or
    None.

    The head comes to rest ``SETTLING_TIME_CONSTANTS`` servo time constants after the stop
    (``true_t_stop`` of the metadata ``meta``, s); the line suggests the ``--duration`` (rounded
    up to 0.1 s) that leaves the whole window. Also one line when the head turns back
    (``scenario.retract_after``) before that window ends. No line without a stop (the summary
    says so).
    """
    from sensing_antenna.estimation import EstimatorConfig
    from sensing_antenna.estimation.front.evidence import spectrum_window

    stop = float(meta.get("true_t_stop", "nan"))
    if not math.isfinite(stop):
        return None
    window = spectrum_window(antenna.link, EstimatorConfig())
    settled = SETTLING_TIME_CONSTANTS / -scenario.servo_pole
    needed = stop + settled + window
    if scenario.retract_after is not None and scenario.retract_after < settled + window:
        return (
            f"warning: --retract-after {scenario.retract_after:g} s turns the head back before"
            f" the estimators' {window:g} s spectrum window (EstimatorConfig.spectrum_window)"
            " ends: their window then holds a push that eases, or no contact at all;"
            f" --retract-after {math.ceil(10 * (settled + window)) / 10:g} leaves the whole"
            " window held"
        )
    if scenario.duration >= needed:
        return None
    return (
        f"warning: the motors stop at {stop:.4g} s, less than the estimators' {window:g} s "
        f"spectrum window (EstimatorConfig.spectrum_window) before the end of --duration "
        f"{scenario.duration:g} s: antenna estimate will report recording_too_short; "
        f"--duration {math.ceil(10 * needed) / 10:g} leaves the whole window"
    )
