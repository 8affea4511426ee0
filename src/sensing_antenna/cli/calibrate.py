"""``antenna calibrate``: fit T_e of the frequency model to recordings at known contact points."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any


def register(subparsers: Any) -> None:
    """Add ``antenna calibrate``."""
    parser = subparsers.add_parser(
        "calibrate",
        help="fit T_e (Section 5.1) and write a calibrated antenna file",
        description=(
            "Measures the fundamental frequency of each recording, fits T_e so that the model "
            "omega_1(x_c) matches them, and writes the antenna with T_e. Contact points come from "
            "--points (CSV with columns file,x_c in m) or from each recording's true_xc metadata."
        ),
    )
    parser.add_argument("recordings", nargs="+", type=Path, help="recording CSV files")
    parser.add_argument("--out", type=Path, required=True, help="calibrated antenna TOML to write")
    parser.add_argument("--antenna", default=None, help="starting antenna: built-in name or TOML")
    parser.add_argument("--points", type=Path, default=None, help="CSV table with file,x_c (m)")
    parser.add_argument("--plot", type=Path, default=None, help="directory for Figure 10")
    parser.add_argument(
        "--loss", default="soft_l1", help="fit loss: linear, soft_l1, huber, cauchy, arctan"
    )
    parser.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    from sensing_antenna.antenna import load_antenna, save_antenna
    from sensing_antenna.calibration.frequency import (
        calibrate_from_recordings,
        read_contact_points,
    )
    from sensing_antenna.recording import read_recording

    antenna = load_antenna(args.antenna)
    recordings = [read_recording(path) for path in args.recordings]
    points = read_contact_points(args.recordings, recordings, args.points)
    calibration = calibrate_from_recordings(
        recordings,
        antenna,
        points,
        sources=[str(p) for p in args.recordings],
        loss=args.loss,
    )
    calibrated = calibration.apply(antenna)
    save_antenna(calibrated, args.out)
    print(
        f"T_e = {calibration.t_e:.5f} +- {calibration.t_e_std_error:.5f} s/m^2 "
        f"(theoretical T = {calibration.t_theoretical:.5f}, "
        f"{100.0 * calibration.relative_difference:+.2f} %), "
        f"rms residual {calibration.rms_residual:.3g} rad/s over {int(calibration.used.sum())} "
        "points"
    )
    scatter = calibration.relative_scatter
    print(
        f"model scatter {100.0 * scatter:.3f} % (rms relative residual; written as "
        "link.calibration_scatter)"
        if math.isfinite(scatter)
        else "model scatter: not measured (fewer than 3 points)"
    )
    for i, x_c in enumerate(calibration.contact_points):
        print(
            f"  {calibration.sources[i]}: x_c = {x_c:.4f} m, omega_1 measured "
            f"{calibration.omega1_measured[i]:.3f}, fitted {calibration.omega1_fitted[i]:.3f} rad/s"
        )
    for note in calibration.notes:
        print(f"  left out: {note}")
    if args.plot is not None:
        from sensing_antenna.plotting.calibration import plot_calibration

        print(plot_calibration(calibration, antenna.link, args.plot))
    print(args.out)
    return 0
