"""``antenna simulate``: run the simulated device and write a recording."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


def register(subparsers: Any) -> None:
    """Add ``antenna simulate``."""
    parser = subparsers.add_parser(
        "simulate", help="simulate one contact manoeuvre and write a recording (CSV)"
    )
    parser.add_argument("--case", choices=("azimuthal", "vertical", "free"), required=True)
    parser.add_argument("--xc", type=float, default=None, help="contact point x_c (m)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--duration", type=float, default=3.0, help="total time (s)")
    parser.add_argument("--noise", type=float, default=1.0, help="sensor noise scale (0: none)")
    parser.add_argument("--antenna", default=None, help="built-in name or TOML file")
    parser.add_argument("--out", type=Path, required=True, help="output CSV file")
    parser.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    import sys

    from sensing_antenna.antenna import load_antenna
    from sensing_antenna.recording import write_recording
    from sensing_antenna.simulator import Scenario, simulate
    from sensing_antenna.simulator.run import deflection_warning

    antenna = load_antenna(args.antenna)
    scenario = Scenario(
        case=args.case,
        contact_point=args.xc,
        seed=args.seed,
        duration=args.duration,
        noise_scale=args.noise,
    )
    recording = simulate(antenna, scenario)
    write_recording(recording, args.out)
    meta = recording.metadata
    summary = f"{args.out}: {recording.n_samples} samples, {args.case}"
    if "true_xc" in meta:
        summary += (
            f", x_c = {float(meta['true_xc']):.4f} m, first touch {meta['true_t_contact']} s,"
            f" stop {meta['true_t_stop']} s,"
            f" y_c / x_c = {100 * float(meta['true_deflection_ratio']):.1f} %"
        )
    print(summary)
    warning = deflection_warning(recording)
    if warning is not None:
        print(warning, file=sys.stderr)
    return 0
