"""``antenna beam``: contact-mode natural frequencies, or the contact points of a frequency.

``antenna beam --xc 0.3 0.5 0.98 [--modes 3]`` prints omega_i (rad/s) and f_i (Hz) per contact
point; ``antenna beam --omega1 80`` prints every contact point whose fundamental frequency is
80 rad/s with the slope d omega_1 / d x_c. ``--json`` prints machine-readable output instead.

Exit codes: 0 on success; 1 when ``--omega1`` lies outside the model's range (the empty candidate
list is still printed, the reason goes to stderr); 2 for bad arguments.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

#: Exit code when the frequency has no consistent contact point.
EXIT_OUT_OF_RANGE = 1


def register(subparsers: Any) -> None:
    """Add ``antenna beam``."""
    parser = subparsers.add_parser(
        "beam",
        help="contact-mode natural frequencies, or contact points for a fundamental frequency",
        description=__doc__.split("\n\n")[1] if __doc__ else None,
    )
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument(
        "--xc", type=float, nargs="+", metavar="M", help="contact point(s) in (0, l] (m)"
    )
    group.add_argument(
        "--omega1", type=float, metavar="RAD_S", help="measured fundamental frequency (rad/s)"
    )
    parser.add_argument("--modes", type=int, default=3, help="number of modes (default 3)")
    parser.add_argument("--antenna", default=None, help="built-in name or TOML file")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Execute the command for parsed ``args``; returns the exit code."""
    from sensing_antenna.antenna import load_antenna

    antenna = load_antenna(args.antenna)
    if args.xc is not None:
        return _frequencies(antenna.name, antenna.link, args.xc, args.modes, args.json)
    return _contact_points(antenna.link, args.omega1, args.json)


#: Largest --modes accepted: beyond a few dozen modes Euler-Bernoulli theory (no shear, no
#: rotary inertia; Assumption 3 of the paper) no longer describes a real link.
MAX_MODES = 50


def _frequencies(name: str, link: Any, x_c: list[float], modes: int, as_json: bool) -> int:
    from sensing_antenna.beam import BeamInputError, natural_frequencies

    if not 1 <= modes <= MAX_MODES:
        raise BeamInputError("--modes", f"must be an integer from 1 to {MAX_MODES}, got {modes}")
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


def _contact_points(link: Any, omega1: float, as_json: bool) -> int:
    from sensing_antenna.beam import BeamInputError, SensingCurve

    if not (math.isfinite(omega1) and omega1 > 0):
        raise BeamInputError("--omega1", f"must be a finite frequency > 0 rad/s, got {omega1}")
    curve = SensingCurve.from_link(link)
    candidates = curve.contact_points(omega1)
    low, high = curve.omega1_range()
    if as_json:
        payload = {
            "omega1": omega1,
            "candidates": [{"x_c": c.x_c, "slope": c.slope} for c in candidates],
        }
        print(json.dumps(payload, indent=2))
    else:
        print(
            f"omega1 = {omega1:g} rad/s (f1 = {omega1 / (2 * math.pi):.4g} Hz): "
            f"{len(candidates)} candidate contact point(s)"
        )
        if candidates:
            print(f"{'x_c [m]':>10} {'slope [rad/s per m]':>20}")
            for c in candidates:
                print(f"{c.x_c:10.5f} {c.slope:20.3f}")
    if not candidates:
        print(
            f"antenna beam: omega1 = {omega1:g} rad/s is outside the model's range "
            f"({low:.4g}, {high:.4g}] rad/s for contact points in (0, {link.length:g}] m",
            file=sys.stderr,
        )
        return EXIT_OUT_OF_RANGE
    return 0
