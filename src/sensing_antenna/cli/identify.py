"""``antenna identify``: fit the free-motion observer (Eq. 15) and the contact threshold."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any


def register(subparsers: Any) -> None:
    """Add ``antenna identify``."""
    parser = subparsers.add_parser(
        "identify",
        help="fit the free-motion observer (Eq. 15) and contact threshold to a free motion",
        description=(
            "Fits gain, natural frequency and damping of the free-motion observer to a recording "
            "of free motion (no contact), sets the contact threshold to the largest filtered "
            "residual times the margin (Section 5.2), and writes the antenna with that observer."
        ),
    )
    parser.add_argument("recording", type=Path, help="free-motion recording CSV")
    parser.add_argument("--out", type=Path, required=True, help="antenna TOML to write")
    parser.add_argument("--antenna", default=None, help="starting antenna: built-in name or TOML")
    parser.add_argument(
        "--margin", type=float, default=1.5, help="safety factor on the residual (default 1.5)"
    )
    parser.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    from dataclasses import replace

    from sensing_antenna.antenna import load_antenna, save_antenna
    from sensing_antenna.calibration.observer import identify_free_motion
    from sensing_antenna.recording import read_recording

    antenna = load_antenna(args.antenna)
    fit = identify_free_motion(read_recording(args.recording), antenna, margin=args.margin)
    save_antenna(replace(antenna, observer=fit.observer), args.out)
    joints = ", ".join(f"theta{j}" for j in fit.joints)
    print(
        f"gain = {fit.gain:.5g} N m/rad, natural_frequency = {fit.natural_frequency:.5g} "
        f"rad/s ({fit.natural_frequency / (2 * math.pi):.4g} Hz), "
        f"damping = {fit.damping:.4g} 1/s (zeta = {fit.damping_ratio:.3g})"
    )
    print(
        f"contact_threshold = {fit.contact_threshold:.4g} N m "
        f"({fit.margin:g} x max residual {fit.max_filtered_residual:.4g} N m), "
        f"rms fit residual {fit.residual_rms:.3g} N m, joints used: {joints}"
    )
    print(args.out)
    return 0
