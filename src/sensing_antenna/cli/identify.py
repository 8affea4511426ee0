"""``antenna identify``: fit the free-motion observer (Eq. 15) and the contact threshold."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from sensing_antenna.cli.arguments import antenna_name, number, printable


def register(subparsers: Any) -> None:
    """Add ``antenna identify``."""
    parser = subparsers.add_parser(
        "identify",
        help="fit the free-motion observer (Eq. 15) and contact threshold to a free motion",
        description=(
            "Fits gain, natural frequency and damping of the free-motion observer to a recording "
            "of free motion (no contact), sets the contact threshold to the largest filtered "
            "residual times the margin (Section 5.2), and writes the starting antenna with that "
            "observer as a new antenna: named after --out (or --name), its description saying "
            "which recording it was identified from."
        ),
    )
    parser.add_argument("recording", type=Path, help="free-motion recording CSV")
    parser.add_argument("--out", type=Path, required=True, help="antenna TOML to write")
    parser.add_argument(
        "--name", default=None, help="name of the new antenna (default: the stem of --out)"
    )
    parser.add_argument(
        "--antenna", default="paper-2021", help="starting antenna: built-in name or TOML file"
    )
    parser.add_argument(
        "--margin",
        type=number(low=1.0),
        default=1.5,
        help="safety factor on the largest filtered residual",
    )
    parser.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    name = antenna_name(args.name, args.out)  # before the library loads: an argument error

    from dataclasses import replace

    from sensing_antenna.antenna import load_antenna, save_antenna
    from sensing_antenna.calibration.observer import identify_free_motion
    from sensing_antenna.recording import read_recording

    antenna = load_antenna(args.antenna)
    fit = identify_free_motion(read_recording(args.recording), antenna, margin=args.margin)
    description = (
        f"antenna {printable(antenna.name)} with the free-motion observer and contact "
        f"threshold identified by antenna identify from {printable(str(args.recording))}"
    )
    identified = replace(antenna, name=name, description=description, observer=fit.observer)
    save_antenna(identified, args.out)
    joints = ", ".join(f"theta{j}" for j in fit.joints)
    print(
        f"gain = {fit.gain:.5g} N m/rad, natural_frequency = {fit.natural_frequency:.5g} "
        f"rad/s ({fit.natural_frequency / (2 * math.pi):.4g} Hz), "
        f"damping = {fit.damping:.4g} 1/s (zeta = {fit.damping_ratio:.3g})"
    )
    print(
        f"contact_threshold = {fit.contact_threshold:.4g} N m "
        f"({fit.margin:g} x the largest low-pass filtered residual of Eq. 16, "
        f"{fit.max_filtered_residual:.4g} N m), rms of the unfiltered fit residual "
        f"{fit.residual_rms:.3g} N m, joints used: {joints}"
    )
    print(args.out)
    return 0
