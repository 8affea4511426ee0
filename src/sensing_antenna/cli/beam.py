"""``antenna beam``: contact-mode natural frequencies, or the contact points of a frequency.

``antenna beam --xc 0.3 0.5 0.98 [--modes 3]`` prints omega_i (rad/s) and f_i (Hz) per contact
point; ``antenna beam --omega1 80`` prints every contact point whose fundamental frequency is
80 rad/s with the slope d omega_1 / d x_c (the tip too when 80 rad/s lies within ``--tolerance``
of its frequency, on the side no point of the link reaches). ``--json`` prints machine-readable
output instead.

Exit codes: 0 on success; 1 when ``--omega1`` lies outside the model's range (the empty candidate
list is still printed, the reason goes to stderr); 2 for bad arguments.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from sensing_antenna.cli.arguments import ArgumentError, check_contact_points, integer, number

#: Exit code when the frequency has no consistent contact point.
EXIT_OUT_OF_RANGE = 1

#: Default uncertainty of --omega1, relative: 0.1 %, the order of a calibrated model's scatter
#: about the measured frequencies (link.calibration_scatter) and of a frequency printed with
#: four significant digits.
DEFAULT_TOLERANCE = 1e-3

#: Largest --modes accepted: beyond a few dozen modes Euler-Bernoulli theory (no shear, no
#: rotary inertia; Assumption 3 of the paper) no longer describes a real link.
MAX_MODES = 50


def register(subparsers: Any) -> None:
    """Add ``antenna beam``."""
    parser = subparsers.add_parser(
        "beam",
        help="contact-mode natural frequencies, or contact points for a fundamental frequency",
        description=(
            "The beam model of the link pinned at a contact point (Sections 3.3 and 3.4 of the "
            "paper). With --xc, prints the natural frequencies omega_i (rad/s) and f_i (Hz) of "
            "the first --modes modes for each contact point. With --omega1, prints every "
            "contact point whose fundamental frequency is that, with the slope d omega_1 / d x_c, "
            "and exits with 1 when the frequency lies outside the model's range (the reason goes "
            "to stderr). --json prints the same as JSON."
        ),
    )
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument(
        "--xc",
        type=number(unit="m", finite=False),
        nargs="+",
        metavar="M",
        help="contact point(s), from the base (0, excluded) to the tip (the link's length) (m)",
    )
    group.add_argument(
        "--omega1",
        type=number(low=0.0, low_open=True, unit="rad/s", what="frequency"),
        metavar="RAD_S",
        help="measured fundamental frequency (rad/s)",
    )
    parser.add_argument(
        "--modes",
        type=integer(1, MAX_MODES),
        default=3,
        metavar="N",
        help=f"number of modes, 1 to {MAX_MODES}",
    )
    parser.add_argument(
        "--tolerance",
        type=number(low=0.0, unit="rad/s"),
        metavar="RAD_S",
        help="uncertainty of --omega1 (rad/s): a frequency this close to the tip's, on the side "
        "no point of the link reaches, is a contact at the tip (default: "
        f"{100 * DEFAULT_TOLERANCE:g} %% of --omega1)",
    )
    parser.add_argument("--antenna", default="paper-2021", help="built-in name or TOML file")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Execute the command for parsed ``args``; returns the exit code."""
    from sensing_antenna.antenna import load_antenna

    antenna = load_antenna(args.antenna)
    if args.xc is not None:
        if args.tolerance is not None:
            raise ArgumentError("--tolerance", "the uncertainty of --omega1, not used with --xc")
        check_contact_points(antenna.link, args.xc)
        return _frequencies(antenna.name, antenna.link, args.xc, args.modes, args.json)
    tolerance = DEFAULT_TOLERANCE * args.omega1 if args.tolerance is None else args.tolerance
    return _contact_points(antenna.link, args.omega1, tolerance, args.json)


def _frequencies(name: str, link: Any, x_c: list[float], modes: int, as_json: bool) -> int:
    from sensing_antenna.beam import natural_frequencies

    omega = natural_frequencies(link, x_c, modes)
    hz = omega / (2.0 * math.pi)
    if as_json:
        rows = [
            {"x_c": x, "omega": [float(v) for v in w], "hz": [float(v) for v in f]}
            for x, w, f in zip(x_c, omega, hz, strict=True)
        ]
        print(json.dumps(rows, indent=2))
        return 0
    print(f"antenna {name}: l = {link.length:g} m, T = {link.t_param:.4f} s/m^2")
    print(f"{'x_c [m]':>9} {'mode':>5} {'omega [rad/s]':>14} {'f [Hz]':>10}")
    for x, w, f in zip(x_c, omega, hz, strict=True):
        for i, (wi, fi) in enumerate(zip(w, f, strict=True), start=1):
            print(f"{x:9.4f} {i:5d} {wi:14.4f} {fi:10.4f}")
    return 0


def _contact_points(link: Any, omega1: float, tolerance: float, as_json: bool) -> int:
    from sensing_antenna.beam import SensingCurve

    curve = SensingCurve.from_link(link)
    candidates = curve.contact_points(omega1, tolerance)
    low, high = curve.omega1_range()
    if not candidates and high < omega1 <= high + tolerance:
        # measured a little high at the top of the curve: the top is the candidate
        candidates = curve.contact_points(high)
    if as_json:
        payload = {
            "omega1": omega1,
            "tolerance": tolerance,
            "candidates": [{"x_c": c.x_c, "slope": c.slope} for c in candidates],
        }
        print(json.dumps(payload, indent=2))
    else:
        print(
            f"omega1 = {omega1:g} +- {tolerance:.3g} rad/s (f1 = {omega1 / (2 * math.pi):.4g} Hz): "
            f"{len(candidates)} candidate contact point(s)"
        )
        if candidates:
            print(f"{'x_c [m]':>10} {'slope [rad/s per m]':>20}")
            for c in candidates:
                print(f"{c.x_c:10.5f} {c.slope:20.3f}")
    if not candidates:
        print(
            f"antenna beam: omega1 = {omega1:g} rad/s is outside the model's range "
            f"({low:.7g}, {high:.7g}] rad/s for contact points in (0, {link.length:g}] m, "
            f"beyond the tolerance {tolerance:.3g} rad/s",
            file=sys.stderr,
        )
        return EXIT_OUT_OF_RANGE
    return 0
