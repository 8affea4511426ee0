"""``antenna calibrate``: fit T_e of the frequency model to recordings at known contact points."""

from __future__ import annotations

import argparse
import math
import sys
from itertools import compress
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sensing_antenna.cli.arguments import antenna_name, distinct_files, printable

if TYPE_CHECKING:
    from sensing_antenna.calibration.frequency import FrequencyCalibration

#: The fit losses of :data:`sensing_antenna.calibration.frequency.LOSSES`, written out so that
#: parsing arguments does not import the calibration (``tests/test_cli_help.py`` checks them).
LOSS_NAMES = ("linear", "soft_l1", "huber", "cauchy", "arctan")


def register(subparsers: Any) -> None:
    """Add ``antenna calibrate``."""
    parser = subparsers.add_parser(
        "calibrate",
        help="fit T_e (Section 5.1) and write a calibrated antenna file",
        description=(
            "Measures the fundamental frequency of each recording, fits T_e so that the model "
            "omega_1(x_c) matches them, and writes the antenna with T_e. Contact points come from "
            "--points (CSV with columns file,x_c in m) or from each recording's true_xc metadata. "
            "The new antenna is named after --out (or --name), its description saying which "
            "recordings calibrated it. With four recordings or more of one sweep direction, the "
            "same contacts also calibrate the F/T sensor's cross-talk into the lateral forces "
            "(written as [sensor]; --no-sensor leaves the antenna's)."
        ),
    )
    parser.add_argument("recordings", nargs="+", type=Path, help="recording CSV files")
    parser.add_argument("--out", type=Path, required=True, help="calibrated antenna TOML to write")
    parser.add_argument(
        "--name", default=None, help="name of the new antenna (default: the stem of --out)"
    )
    parser.add_argument(
        "--antenna", default="paper-2021", help="starting antenna: built-in name or TOML file"
    )
    parser.add_argument(
        "--points",
        type=Path,
        default=None,
        help="CSV table with columns file,x_c (m) (default: each recording's true_xc)",
    )
    parser.add_argument(
        "--plot", type=Path, default=None, help="directory for Figure 10 (default: no figure)"
    )
    parser.add_argument(
        "--loss",
        choices=LOSS_NAMES,
        default="soft_l1",
        help="fit loss (scipy.optimize.least_squares); a robust one tempers points off the "
        "others (one clearly off, a wrong peak or a wrong known point, is left out and T_e "
        "fitted again whatever the loss)",
    )
    parser.add_argument(
        "--tip-mass",
        action="store_true",
        help="fit the link's tip mass with T_e (4 points or more, spread along the link): the "
        "two together take up a payload, a taper or a joint that T_e alone leaves as scatter",
    )
    parser.add_argument(
        "--no-sensor",
        action="store_true",
        help="do not calibrate the sensor's cross-talk (keep the antenna's [sensor])",
    )
    parser.set_defaults(func=_run)


def _description(start: str, recordings: list[Path]) -> str:
    """What the written antenna is: ``start`` with T_e from which recordings (the first three)."""
    files = [printable(str(path)) for path in recordings]
    shown = ", ".join(files[:3]) + (f" and {len(files) - 3} more" if len(files) > 3 else "")
    return (
        f"antenna {printable(start)} with T_e calibrated by antenna calibrate from "
        f"{len(files)} recording(s): {shown}"
    )


def _calibrate_sensor(
    antenna: Any, recordings: list[Any], points: list[float], paths: list[Path]
) -> tuple[Any, list[str]]:
    """``antenna`` with the sensor's cross-talk fitted to the recordings, and what to print."""
    from sensing_antenna.calibration.sensor import (
        MIN_SENSOR_RECORDINGS,
        SensorCalibrationError,
        calibrate_sensor,
    )

    try:
        fit = calibrate_sensor(recordings, antenna, points, sources=[str(p) for p in paths])
    except SensorCalibrationError as exc:
        return antenna, [f"sensor: not calibrated, {exc}; the antenna's [sensor] is kept"]
    unmeasured = fit.correction.unmeasured_sweeps
    terms = ", ".join(
        f"{k} = {v:.4g}" for k, v in vars(fit.correction).items() if k != "unmeasured_sweeps"
    )
    fitted = f"on {len(fit.sources)} recordings ({', '.join(fit.sweeps)} sweeps)"
    lines = [
        f"sensor: lateral-force correction (a sensor's cross-talk, or the statics' bias at "
        f"the push) fitted {fitted}: {terms}; {fit.ratio_summary}"
        if fit.adopted
        else f"sensor: no cross-talk correction written ({fitted}; {fit.ratio_summary}); "
        f"ratio_scatter = {fit.correction.ratio_scatter:.4g}"
    ]
    lines += [f"  sensor, left out: {note}" for note in fit.notes]
    if unmeasured:
        lines.append(
            f"  sensor: no {' or '.join(unmeasured)} sweep calibrated it, so pushes that way keep"
            f" the sensor's nominal cross-talk uncertainty ({MIN_SENSOR_RECORDINGS} recordings"
            " of a direction measure it)"
        )
    return fit.apply(antenna), lines


def _run(args: argparse.Namespace) -> int:
    name = antenna_name(args.name, args.out)  # before the library loads: an argument error

    from dataclasses import replace

    from sensing_antenna.antenna import load_antenna, save_antenna
    from sensing_antenna.calibration.frequency import (
        MIN_TIP_MASS_POINTS,
        MIN_WRONG_PEAK_POINTS,
        WRONG_PEAK,
        CalibrationError,
        calibrate_from_recordings,
        read_contact_points,
        scatter_problem,
        unmatched_point_rows,
    )
    from sensing_antenna.cli.arguments import ArgumentError
    from sensing_antenna.cli.estimate import warn_of_contradicted_period
    from sensing_antenna.errors import SensingAntennaError
    from sensing_antenna.recording import read_recording

    antenna = load_antenna(args.antenna)
    paths, recordings, unread = [], [], []
    for path in distinct_files(args.recordings):
        try:
            recordings.append(read_recording(path))
        except SensingAntennaError as exc:
            unread.append(str(exc))  # one bad file does not sink the set
        else:
            paths.append(path)
            warn_of_contradicted_period(path, recordings[-1].period_problem)
    if len(recordings) < 2 and unread:
        raise CalibrationError(f"{unread[0]} (and fewer than 2 readable recordings left)")
    points = read_contact_points(paths, recordings, args.points)
    if args.points is not None:
        for line in unmatched_point_rows(args.points, paths):
            print(f"antenna calibrate: warning: {line}", file=sys.stderr)
    if args.points is None and not any(math.isfinite(point) for point in points):
        # a real device's recordings carry no true_xc: the table is what is missing
        raise ArgumentError(
            "--points",
            "none given, and no recording states its contact point (true_xc metadata, which "
            "only a simulator writes): give --points FILE, a CSV with columns file,x_c (m), one "
            "row per recording (docs/real-antenna.md)",
        )
    try:
        calibration = calibrate_from_recordings(
            recordings,
            antenna,
            points,
            sources=[str(p) for p in paths],
            loss=args.loss,
            fit_tip_mass=args.tip_mass,
        )
    except CalibrationError as exc:
        if exc.field != "contact_points":
            raise
        # the known points came from the table the user gave, or from each file's true_xc
        where = f"--points {args.points}" if args.points is not None else "true_xc"
        raise CalibrationError(exc.problem, field=where) from None
    fitted = [path for path, used in zip(paths, calibration.used, strict=True) if used]
    description = _description(antenna.name, fitted)
    calibrated = replace(calibration.apply(antenna), name=name, description=description)
    sensor_lines: list[str] = []
    if not args.no_sensor:
        # a point the frequency fit found wrong may be a wrong known point: not for the sensor
        right = [not wrong for wrong in calibration.wrong_peak_points]
        calibrated, sensor_lines = _calibrate_sensor(
            calibrated,
            list(compress(recordings, right)),
            list(compress(points, right)),
            list(compress(paths, right)),
        )
        sensor_lines += [
            f"  sensor, left out: {path}: a wrong spectral peak or known point to the T_e fit"
            for path in compress(paths, calibration.wrong_peak_points)
        ]
    save_antenna(calibrated, args.out)
    print(
        f"T_e = {calibration.t_e:.5f} +- {calibration.t_e_std_error:.5f} s/m^2 "
        f"(theoretical T = {calibration.t_theoretical:.5f}, "
        f"{100.0 * calibration.relative_difference:+.2f} %), "
        f"rms residual {calibration.rms_residual:.3g} rad/s over {int(calibration.used.sum())} "
        "points"
    )
    if calibration.tip_mass is not None:
        print(f"tip mass = {1e3 * calibration.tip_mass:.4g} g (fitted with T_e; link.tip_mass)")
    elif args.tip_mass:
        print(
            f"tip mass: not fitted (fewer than {MIN_TIP_MASS_POINTS} points that agree with one "
            "another), link.tip_mass kept"
        )
    scatter = calibration.relative_scatter
    print(
        f"model scatter {100.0 * scatter:.3f} % (rms relative residual; written as "
        "link.calibration_scatter)"
        if math.isfinite(scatter)
        else "model scatter: not measured (too few points: 3 needed, 4 with the tip mass)"
    )
    if math.isfinite(scatter) and scatter > 2.0 * WRONG_PEAK:
        # more than a wrong point's worth on most points: the estimates will be unsure
        print(
            f"antenna calibrate: warning: {scatter_problem(scatter, int(calibration.used.sum()))}",
            file=sys.stderr,
        )
    print(_mode2_line(calibration))
    print(_held_joints_line(calibration))
    wrong = calibration.wrong_peak_points
    doubtful = calibration.kept_far_points
    for i, x_c in enumerate(calibration.contact_points):
        if not (
            0.0 < float(x_c) <= antenna.link.length
            and math.isfinite(float(calibration.omega1_measured[i]))
        ):
            continue  # no known point on the link or no omega_1 read: its note below says why
        print(
            f"  {calibration.sources[i]}: x_c = {x_c:.4f} m, omega_1 measured "
            f"{calibration.omega1_measured[i]:.3f}, fitted {calibration.omega1_fitted[i]:.3f} rad/s"
            + _omega2_text(calibration, i)
            + (
                f"; more than {100 * WRONG_PEAK:g} % off the others, left out of the fit: a "
                "wrong spectral peak or a wrong known point?"
                if wrong[i]
                else f"; more than {100 * WRONG_PEAK:g} % off the others, kept in the fit (it "
                f"leaves such a point out from {MIN_WRONG_PEAK_POINTS} points on, one or a tenth "
                "of them: more are the model's error): a wrong spectral peak or known point? "
                "check it"
                if doubtful[i]
                else ""
            )
        )
    for note in (*unread, *calibration.notes):
        print(f"  left out: {note}")
    for line in sensor_lines:
        print(line)
    if args.plot is not None:
        from sensing_antenna.plotting.calibration import plot_calibration

        print(f"figure {plot_calibration(calibration, antenna.link, args.plot)}")
    print(f"wrote {args.out}")
    return 0


def _mode2_line(calibration: FrequencyCalibration) -> str:
    """What the calibration measured of the second contact mode, in one line."""
    from sensing_antenna.calibration.frequency import MIN_MODE2_POINTS

    count = calibration.mode2_points
    scatter = calibration.mode2_scatter
    if math.isfinite(scatter):
        return (
            f"second contact mode: scatter {100.0 * scatter:.3f} % about the model over {count} "
            "points (written as link.mode2_scatter; the fast method's omega_2 at its cap)"
        )
    return (
        f"second contact mode: found near the model's at {count} of "
        f"{int(calibration.used.sum())} points; its scatter needs {MIN_MODE2_POINTS} and two "
        "thirds of the points (link.mode2_scatter not written)"
    )


def _held_joints_line(calibration: FrequencyCalibration) -> str:
    """What the calibration measured of the held joints' compliance, in one line."""
    from sensing_antenna.estimation.held_joint import MIN_POSTS

    joints = calibration.held_joint
    said = []
    for joint, (name, value) in enumerate(
        zip(("azimuth", "elevation"), calibration.held_compliance, strict=True)
    ):
        posts = 0 if joints is None else int(((joints == joint) & calibration.used).sum())
        said.append(
            f"{name} {value:.3g} rad/(N m) over {posts} points (written as "
            f"{name}_motor.held_compliance)"
            if value is not None
            else f"{name} not written ({posts} points of its sweep, {MIN_POSTS} needed)"
        )
    return (
        "held joints' angle per link torque at omega_1 (a base moving near omega_1 is looked "
        f"for on the joints written): {'; '.join(said)}"
    )


def _omega2_text(calibration: FrequencyCalibration, i: int) -> str:
    """ ", omega_2 measured ... model ... rad/s" for point ``i``, "" when not measured."""
    measured, fitted = calibration.omega2_measured, calibration.omega2_fitted
    if measured is None or fitted is None or not math.isfinite(float(measured[i])):
        return ""
    return f"; omega_2 measured {float(measured[i]):.2f}, model {float(fitted[i]):.2f} rad/s"
