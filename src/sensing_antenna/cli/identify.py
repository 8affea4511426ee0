"""``antenna identify``: fit the free-motion observer (Eq. 15) and the contact threshold, and with
``--servo`` each joint's motor model (Eq. 1) and the servo's gains designed from it."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from sensing_antenna.cli.arguments import antenna_name, distinct_files, number, printable
from sensing_antenna.errors import format_value

_POLE_REQUIREMENT = "must be a finite number < 0 rad/s (a stable pole)"


def _servo_pole(text: str) -> float:
    """An argparse ``type``: a finite float below 0 (rad/s), the closed-loop pole of Eq. 14."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{_POLE_REQUIREMENT}, got {text!r}") from None
    if not (math.isfinite(value) and value < 0):
        raise argparse.ArgumentTypeError(f"{_POLE_REQUIREMENT}, got {format_value(value)}")
    return value


def register(subparsers: Any) -> None:
    """Add ``antenna identify``."""
    parser = subparsers.add_parser(
        "identify",
        help="fit the free-motion observer (Eq. 15) and contact threshold to free motions",
        description=(
            "Fits gain, natural frequency and damping of the free-motion observer to recordings "
            "of free motion (no contact; give one of each joint the head sweeps, e.g. a free "
            "azimuthal and a free vertical sweep), sets the contact threshold to the largest "
            "filtered residual over them times the margin (Section 5.2), and writes the "
            "starting antenna with that observer as a new antenna: named after --out (or "
            "--name), its description saying which recordings it was identified from. With "
            "--servo it also fits each moving joint's Eq. 1 (inertia J, viscous friction v, "
            "Coulomb torque) to the motor commands the recordings carry (columns u1, u2, V; "
            "each joint from the recording that tells its J best), writes them into the "
            "motors, and prints the servo's gains designed from them (Section 4.1, Eq. 14)."
        ),
    )
    parser.add_argument(
        "recordings", type=Path, nargs="+", metavar="recording", help="free-motion recording CSV"
    )
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
    parser.add_argument(
        "--servo",
        action="store_true",
        help="also fit each joint's Eq. 1 (J, v, Coulomb torque) to the commands u1, u2 (V) and "
        "print the servo's gains",
    )
    parser.add_argument(
        "--servo-pole",
        type=_servo_pole,
        default=None,
        metavar="P",
        help="closed-loop pole p of the gains printed with --servo (rad/s, < 0; default -60); "
        "a value in exponent form goes after '=', --servo-pole=-6e1 (argparse reads a separate "
        "'-6e1' as an option)",
    )
    parser.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    name = antenna_name(args.name, args.out)  # before the library loads: an argument error

    from dataclasses import replace

    from sensing_antenna.antenna import load_antenna, save_antenna
    from sensing_antenna.calibration.motor import identify_motors_from
    from sensing_antenna.calibration.observer import IdentificationError, identify_free_motion
    from sensing_antenna.cli.estimate import warn_of_contradicted_period
    from sensing_antenna.control.servo import DEFAULT_SERVO_POLE, ControlConfigError, design_servo
    from sensing_antenna.recording import read_recording

    if args.servo_pole is not None and not args.servo:
        raise ControlConfigError("--servo-pole: the gains are designed with --servo only")
    pole = DEFAULT_SERVO_POLE if args.servo_pole is None else args.servo_pole
    antenna = load_antenna(args.antenna)
    files = distinct_files(args.recordings)
    recordings = [read_recording(path) for path in files]
    for path, recording in zip(files, recordings, strict=True):
        warn_of_contradicted_period(path, recording.period_problem)
    if args.servo:
        try:  # before any fit: a pole the recordings' period cannot realise
            design_servo(antenna.motors[0], pole, recordings[0].sample_period)
        except ControlConfigError as exc:
            raise ControlConfigError(f"--servo-pole: {str(exc).removeprefix('pole: ')}") from None
    motor_fit = identify_motors_from(recordings, antenna) if args.servo else None
    try:
        fit = identify_free_motion(recordings, antenna, margin=args.margin)
    except IdentificationError as exc:
        if motor_fit is None:
            raise
        # a sweep into an object fits the motors, not the free-motion observer
        fit, kept = None, str(exc)
    what = "the free-motion observer and contact threshold" if fit is not None else ""
    if motor_fit is not None:
        fitted = " and ".join(str(j.joint) for j in motor_fit.joints)
        motors = f"the motors of joint{'s' if len(motor_fit.joints) > 1 else ''} {fitted}"
        what = f"{what} and {motors}" if what else motors
    description = (
        f"antenna {printable(antenna.name)} with {what} identified by antenna identify from "
        f"{printable(', '.join(str(path) for path in args.recordings))}"
    )
    start = antenna if motor_fit is None else motor_fit.antenna(antenna)
    identified = replace(start, name=name, description=description)
    if fit is not None:
        identified = fit.apply(identified)
    save_antenna(identified, args.out)
    if fit is None:
        print(
            f"observer: not identified ({kept}); the starting antenna's observer and contact "
            "threshold kept: identify them on a free-motion recording"
        )
    else:
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
        _print_payload(fit.payload, antenna.link, identified.link)
        if fit.angle_lag is not None:
            print(_lag_warning(fit.angle_lag), file=sys.stderr)
        if fit.torque_point is not None:
            from sensing_antenna.torque_point import metadata_line

            print(
                "antenna identify: warning: the torques read as taken about a point off the"
                " link's clamp (Eq. 15 with it explains them far better): if the sensor's"
                f" origin lies there, state '{metadata_line(fit.torque_point)}' in the"
                " recordings and"
                " identify again (the gain and any tip mass read here carry that offset;"
                " docs/real-antenna.md)",
                file=sys.stderr,
            )
    if motor_fit is not None:
        _print_servo(motor_fit, antenna, pole, several=len(recordings) > 1)
    print(args.out)
    return 0


def _print_payload(payload: Any, before: Any, after: Any) -> None:
    """What the moments at rest said of weight at the tip, and the field written: the links
    ``before`` and ``after`` identification (``link.weight_tip_mass`` where the link has one,
    ``Payload.apply``)."""
    if payload is None or payload.samples == 0:
        print("payload: not read (no recording starts at rest)")
        return
    read = (
        f"payload: the moment at rest reads {1e3 * payload.mass:+.4g} g +- "
        f"{1e3 * payload.std:.2g} g at the tip beyond the antenna's weight"
    )
    field = "weight_tip_mass" if before.weight_tip_mass is not None else "tip_mass"
    if payload.significant:
        print(
            f"{read}: link.{field} = {after.weighed_tip_mass:.4g} kg "
            f"(was {before.weighed_tip_mass:.4g} kg)"
        )
    else:
        print(f"{read}: not significant, link.{field} kept at {before.weighed_tip_mass:.4g} kg")


def _print_servo(motor_fit: Any, antenna: Any, pole: float, several: bool = False) -> None:
    """The fitted Eq. 1 of each joint and the servo's gains designed from it; ``several``: the
    joints were fitted from several recordings, each named."""
    names = {1: "azimuth", 2: "elevation"}
    for joint in motor_fit.joints:
        motor = antenna.motors[joint.joint - 1]
        volts = joint.coulomb_torque / (motor.gear_ratio * motor.torque_constant)
        source = f" (from {printable(joint.source)})" if several and joint.source else ""
        print(
            f"joint {joint.joint} ({names[joint.joint]}), Eq. 1{source}: "
            f"J = {joint.inertia:.4g} +- {joint.inertia_error:.2g} kg m^2, "
            f"v = {joint.viscous_friction:.4g} +- {joint.viscous_error:.2g} N m s/rad, "
            f"Gamma_nlc = {joint.coulomb_torque:.4g} +- {joint.coulomb_error:.2g} N m "
            f"(coulomb_voltage {volts:.4g} V), rms of the filtered residual "
            f"{joint.residual_rms:.3g} N m"
        )
    for number_, reason in motor_fit.skipped:
        print(
            f"joint {number_} ({names[number_]}), Eq. 1: not fitted, {reason}; the motor of "
            f"{printable(antenna.name)} is kept"
        )
    fitted = {joint.joint for joint in motor_fit.joints}
    for number_, design in enumerate(motor_fit.designs(antenna, pole), start=1):
        source = "fitted" if number_ in fitted else "kept"
        feedback = ", ".join(f"{c:.6g}" for c in design.feedback)
        feedforward = ", ".join(f"{c:.6g}" for c in design.feedforward)
        print(
            f"joint {number_} servo on the {source} motor (Section 4.1, p = {pole:g} rad/s, "
            f"eps = {1e3 * design.time_constant:.4g} ms): R = (c2 s^2 + c1 s + c0) / "
            f"(s (s + b)) with b = {design.b:.6g} rad/s, feedback R2 (c2, c1, c0) = "
            f"({feedback}), feedforward R1 = ({feedforward})"
        )


def _lag_warning(lag: float) -> str:
    """The line warning of angles read ``lag`` (s) late (early when negative) against the
    torques."""
    from sensing_antenna.calibration.observer import LAG_SEARCH

    size = f"about {1e3 * abs(lag):.0f} ms"
    if abs(lag) >= LAG_SEARCH * (1.0 - 1e-9):
        size = f"{1e3 * LAG_SEARCH:.0f} ms or more"
    cause = "The encoder's and the sensor's clocks do not agree?"
    if lag < 0.0:
        cause = (
            "The encoder's and the sensor's clocks do not agree, or the sensor's own filter"
            " delays the loads (its cut-off)?"
        )
    return (
        f"antenna identify: warning: the angles read {size} {'late' if lag > 0 else 'early'}"
        " against the torques (Eq. 15 with them moved that much leaves a largest free-motion"
        " residual well under this fit's), and the threshold here holds the lag's residual."
        f" {cause} Synchronise them, or shift the joints' stamps, and identify again"
        " (docs/import.md,"
        " 'Another log, from Python')"
    )
