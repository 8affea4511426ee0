"""Identification of each joint's motor model (Eq. 1) from a recording with the motor commands.

Eq. 1 at joint i: ``n K_m u = J theta'' + v theta' + Gamma_nlc + Gamma_coup``. With the commands
u_1, u_2 recorded (the optional columns ``recording.COMMAND_COLUMNS``, V), the gear ratio n and
torque constant K_m of the antenna file (datasheet values), the coupling torque measured by the
F/T sensor (:func:`~sensing_antenna.control.servo.coupling_torques`) and the Coulomb friction
modelled as the simulator and the controller's feedforward model it, ``Gamma_nlc tanh(theta' /
omega_s)`` (``FRICTION_SPEED``), the equation is linear in (J, v, Gamma_nlc).

The derivatives are not differentiated out of the samples: both sides pass through the same
low-pass ``F(s) = lambda^2 / (s + lambda)^2`` (a state-variable filter), so that the regressors
``s^2 F theta`` and ``s F theta`` are outputs of a proper filter and the encoder's quantisation
and the sensor's noise are averaged over about 2 / lambda. Each input is mapped as it reaches the
joint: the command, held over each sample, through the filter's zero-order-hold discretisation;
the angles, the coupling torque and the friction term, which vary smoothly between samples,
through its first-order-hold one (``scipy.signal.lsim``). The filter starts at rest, as the head
does at the start of a recording; the angles are taken relative to the first one. The speed in
the friction term comes from a zero-phase Savitzky-Golay derivative of the angle.

The rows of the fit are the samples whose filter memory saw the joint sliding (faster than
``MOVING_SPEED_FACTOR`` omega_s throughout): at rest and in a stall (pushing an obstacle) the
friction is static, which the regularised model does not describe. Least squares then gives
(J, v, Gamma_nlc) per joint, with standard errors from the residual
(allowing for the filter's correlation of neighbouring residuals). A joint is fitted when it
moved by more than ``MIN_MOTION`` and the fit determines J to ``MAX_RELATIVE_ERROR``; the
others keep the antenna file's motor and are listed with the reason. A fitted J more than
``MAX_INERTIA_FACTOR`` from the antenna file's motor J plus the rigid link's inertia refuses the
recording: its commands are not in V (mV give a thousand times the J).

The servo's gains then follow from the fitted J and v by the pole placement of Section 4.1
(:func:`~sensing_antenna.control.servo.design_servo`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy import signal

from sensing_antenna.antenna import Antenna, Motor
from sensing_antenna.calibration.observer import (
    MAX_INERTIA_FACTOR,
    MIN_MOTION,
    IdentificationError,
    initial_guess,
    units_problem,
)
from sensing_antenna.control.servo import (
    DEFAULT_SERVO_POLE,
    FRICTION_SPEED,
    ServoDesign,
    coupling_torques,
    design_servo,
)
from sensing_antenna.recording import (
    COMMAND_COLUMNS,
    PERIOD_CONSISTENCY,
    Recording,
    resample_uniform,
)

__all__ = [
    "DEFAULT_FILTER_BANDWIDTH",
    "MAX_RELATIVE_ERROR",
    "MOVING_SPEED_FACTOR",
    "JointFit",
    "MotorFit",
    "identify_motors",
    "identify_motors_from",
]

#: lambda of the state-variable filter lambda^2 / (s + lambda)^2 (rad/s): near the servo's
#: closed-loop pole (60 rad/s) and above the link's free mode (16 rad/s), so that the filter keeps
#: the motion's content while it averages the encoder's steps and the sensor's noise over about
#: 2 / lambda = 40 ms. The angle's linear interpolation between samples biases J by about
#: (lambda T_s)^2: on noise-free Eq. 1 data at 1 kHz 0.02 % at 50 rad/s, 0.2 % at 150, 1.3 % at
#: 400.
DEFAULT_FILTER_BANDWIDTH = 50.0

#: A joint's fit is kept when the standard error of J is below this fraction of J: a recording
#: whose motion hardly accelerates the joint cannot tell its inertia.
MAX_RELATIVE_ERROR = 0.2

#: Rows of the fit are those whose filter memory saw the joint move faster than this multiple
#: of omega_s (``FRICTION_SPEED``) throughout, where tanh(omega / omega_s) is within 4 % of its
#: sign and hardly depends on the estimated speed: at rest or in a stall (a push) the friction is
#: static, and the regularised model of Eq. 1 turns a speed error of 1 mrad/s into 3 mN m.
MOVING_SPEED_FACTOR = 2.0

#: The filter's memory counted in 1 / lambda: (1 + x) e^-x of the impulse response left at x = 8.
_MEMORY = 8.0

#: Half-width of the Savitzky-Golay speed estimate of the friction term (samples): 10 ms at
#: 1 kHz, quadratic fit.
_SPEED_HALF_WINDOW = 10


@dataclass(frozen=True)
class JointFit:
    """Fitted Eq. 1 parameters of one joint.

    Attributes
    ----------
    joint : int
        1 (azimuth) or 2 (elevation).
    inertia : float
        J (kg m^2).
    viscous_friction : float
        v (N m s / rad).
    coulomb_torque : float
        Gamma_nlc (N m).
    inertia_error, viscous_error, coulomb_error : float
        Standard errors of the three (same units).
    residual_rms : float
        RMS of the filtered equation's residual (N m).
    source : str or None
        Recording it was fitted on.
    """

    joint: int
    inertia: float
    viscous_friction: float
    coulomb_torque: float
    inertia_error: float
    viscous_error: float
    coulomb_error: float
    residual_rms: float
    source: str | None = None

    def motor(self, base: Motor) -> Motor:
        """``base`` (K_m, n from the antenna file) with the fitted J, v and V^nlc =
        Gamma_nlc / (n K_m)."""
        return replace(
            base,
            inertia=self.inertia,
            viscous_friction=self.viscous_friction,
            coulomb_voltage=self.coulomb_torque / (base.gear_ratio * base.torque_constant),
        )


@dataclass(frozen=True)
class MotorFit:
    """Eq. 1 fitted joint by joint, and the joints left as they were.

    Attributes
    ----------
    joints : tuple of JointFit
        The joints fitted.
    skipped : tuple of (int, str)
        Joints not fitted and why.
    filter_bandwidth : float
        lambda of the state-variable filter (rad/s).
    sample_period : float
        T_s (s) of the recording (after resampling, if it was irregular).
    source : str or None
        Recording file.
    """

    joints: tuple[JointFit, ...]
    skipped: tuple[tuple[int, str], ...]
    filter_bandwidth: float
    sample_period: float
    source: str | None = None

    def antenna(self, antenna: Antenna) -> Antenna:
        """``antenna`` with the fitted joints' motors (:meth:`JointFit.motor`)."""
        motors = list(antenna.motors)
        for fit in self.joints:
            motors[fit.joint - 1] = fit.motor(motors[fit.joint - 1])
        return replace(antenna, azimuth_motor=motors[0], elevation_motor=motors[1])

    def designs(
        self, antenna: Antenna, pole: float = DEFAULT_SERVO_POLE
    ) -> tuple[ServoDesign, ServoDesign]:
        """The servo of Section 4.1 of both joints designed on :meth:`antenna`'s motors."""
        motors = self.antenna(antenna).motors
        first, second = (design_servo(m, pole, self.sample_period) for m in motors)
        return first, second


def _filtered(
    values: NDArray[np.float64], period: float, bandwidth: float, held: bool
) -> NDArray[np.float64]:
    """[F x, s F x, s^2 F x] of samples x (n,), shape (n, 3), F = lambda^2 / (s + lambda)^2 from
    rest: x held over each sample (zero-order hold) or linear between samples."""
    lam = bandwidth
    a = np.array([[0.0, 1.0], [-(lam**2), -2.0 * lam]])
    b = np.array([[0.0], [lam**2]])
    c = np.array([[1.0, 0.0], [0.0, 1.0], [-(lam**2), -2.0 * lam]])
    d = np.array([[0.0], [0.0], [lam**2]])
    t = period * np.arange(values.shape[0])
    _, out, _ = signal.lsim((a, b, c, d), values, t, interp=not held)
    return np.asarray(out, dtype=np.float64)


def _fit_joint(
    joint: int,
    theta: NDArray[np.float64],
    torque: NDArray[np.float64],
    period: float,
    bandwidth: float,
) -> tuple[JointFit | None, str]:
    """Eq. 1 of one joint from its angle (n,) and net torque n K_m u - Gamma_coup split into the
    held command part and the smooth coupling part, shape (n, 2) (N m)."""
    angle = theta - theta[0]
    memory = math.ceil(_MEMORY / (bandwidth * period))
    if angle.size <= memory + 2 * _SPEED_HALF_WINDOW:
        return None, f"the recording is too short ({angle.size} samples) for the filter's memory"
    motion = _filtered(angle, period, bandwidth, held=False)
    speed = signal.savgol_filter(angle, 2 * _SPEED_HALF_WINDOW + 1, 2, deriv=1, delta=period)
    friction = _filtered(np.tanh(speed / FRICTION_SPEED), period, bandwidth, held=False)[:, 0]
    target = (
        _filtered(torque[:, 0], period, bandwidth, held=True)[:, 0]
        - _filtered(torque[:, 1], period, bandwidth, held=False)[:, 0]
    )
    design = np.column_stack([motion[:, 2], motion[:, 1], friction])
    # rows whose filter memory saw the joint moving: the friction model there is the sliding one
    slow = np.abs(speed) < MOVING_SPEED_FACTOR * FRICTION_SPEED
    recent = np.convolve(slow.astype(np.float64), np.ones(memory + 1))[: slow.size]
    rows = recent == 0.0
    if np.count_nonzero(rows) < 3:
        return None, "it never moved steadily: no sample of sliding friction"
    design, target = design[rows], target[rows]
    solution, *_ = np.linalg.lstsq(design, target, rcond=None)
    residual = target - design @ solution
    dof = max(target.size - 3, 1)
    # neighbouring residuals are correlated over the filter's ~2 / lambda: count one in that many
    correlation = max(1.0, 2.0 / (bandwidth * period))
    variance = float(residual @ residual) / dof * correlation
    try:
        covariance = variance * np.linalg.inv(design.T @ design)
    except np.linalg.LinAlgError:
        return None, "its motion cannot separate J, v and Gamma_nlc (a singular fit)"
    errors = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    inertia, viscous, coulomb = (float(v) for v in solution)
    if not inertia > 0:
        return None, (
            f"the fit gives J = {inertia:.3g} kg m^2, not a positive inertia: does column "
            f"'u{joint}' hold the voltage that turns theta{joint} positive (its sign, its unit)?"
        )
    if not errors[0] < MAX_RELATIVE_ERROR * inertia:
        return None, (
            f"its motion does not determine J (J = {inertia:.3g} +- {errors[0]:.2g} kg m^2): "
            "record moves that accelerate it"
        )
    fit = JointFit(
        joint=joint,
        inertia=inertia,
        viscous_friction=max(viscous, 0.0),
        coulomb_torque=max(coulomb, 0.0),
        inertia_error=float(errors[0]),
        viscous_error=float(errors[1]),
        coulomb_error=float(errors[2]),
        residual_rms=float(np.sqrt(np.mean(residual**2))),
    )
    return fit, ""


def _check_inertia(inertia: float, expected: float, joint: int, where: str) -> None:
    """IdentificationError unless the fitted J (kg m^2) of ``joint`` lies within
    ``MAX_INERTIA_FACTOR`` of ``expected``, the motor's J plus the rigid link's inertia (kg m^2).

    The coupling torque is measured, so the fit's J is the motor's alone; the link's inertia
    widens the band for a head whose sensor misses part of it. Commands in mV give a thousand
    times the J, a datasheet J off by a few tens of percent stays far inside the band (the same
    factor as the observer's inertia check)."""
    if 1.0 / MAX_INERTIA_FACTOR <= inertia / expected <= MAX_INERTIA_FACTOR:
        return
    raise IdentificationError(
        f"{where}: column 'u{joint}': the fit gives J = {inertia:.3g} kg m^2, "
        f"{inertia / expected:.3g} times the antenna file's motor J plus the rigid link's inertia "
        f"({expected:.3g} kg m^2, more than a factor {MAX_INERTIA_FACTOR:g}): is 'u{joint}' in V "
        "(not mV), and its motor's gear_ratio and torque_constant the head's?"
    )


def identify_motors(
    recording: Recording,
    antenna: Antenna,
    filter_bandwidth: float = DEFAULT_FILTER_BANDWIDTH,
) -> MotorFit:
    """Fit J, v and Gamma_nlc of Eq. 1 for each joint that moved, from the recorded commands.

    Parameters
    ----------
    recording : Recording
        With the command columns ``u1, u2`` (V); irregular sampling is resampled linearly first.
        Any motion will do (free or in contact: the coupling torque is measured), the head at
        rest at the start.
    antenna : Antenna
        Its motors' n and K_m turn the voltages into torques; the link's weight serves the units
        check.
    filter_bandwidth : float
        lambda of the state-variable filter (rad/s), below the Nyquist frequency pi / T_s.

    Returns
    -------
    MotorFit

    Raises
    ------
    IdentificationError
        When the recording lacks the command columns, is not in the format's units, a fitted J
        is more than ``MAX_INERTIA_FACTOR`` from the motor's plus the rigid link's, or no joint
        could be fitted (none moved by more than ``MIN_MOTION``, or the motion did not determine
        J); the message names the file and the columns.
    """
    where = recording.source or "<recording>"
    missing = [name for name in COMMAND_COLUMNS if name not in recording.extra]
    if missing:
        columns = ", ".join(repr(name) for name in missing)
        raise IdentificationError(
            f"{where}: column{'s' if len(missing) > 1 else ''} {columns} missing: the servo's "
            "Eq. 1 (J, v, Gamma_nlc) cannot be fitted without the motor commands (record the "
            "voltages u1, u2 in V, docs/recording-format.md)"
        )
    uniform = resample_uniform(recording) if recording.sampling.irregular else recording
    period = uniform.sample_period
    if not (math.isfinite(filter_bandwidth) and 0 < filter_bandwidth < math.pi / period):
        raise IdentificationError(
            f"filter_bandwidth: must lie between 0 and pi / T_s = {math.pi / period:.4g} rad/s,"
            f" got {filter_bandwidth!r}"
        )
    problem = units_problem(uniform, antenna)
    if problem is not None:
        raise IdentificationError(f"{where}: {problem}")
    coupling = coupling_torques(uniform.theta, uniform.torque)
    gain, omega, _ = initial_guess(antenna)
    link_inertia = gain / omega**2
    fits: list[JointFit] = []
    skipped: list[tuple[int, str]] = []
    for j, motor in enumerate(antenna.motors):
        angle = uniform.theta[:, j]
        if np.ptp(angle) <= MIN_MOTION:
            skipped.append((j + 1, f"it did not move by more than {MIN_MOTION:g} rad"))
            continue
        command = motor.gear_ratio * motor.torque_constant * uniform.extra[COMMAND_COLUMNS[j]]
        with np.errstate(over="raise", invalid="raise"):
            try:
                fit, reason = _fit_joint(
                    j + 1,
                    angle,
                    np.column_stack([command, coupling[:, j]]),
                    period,
                    filter_bandwidth,
                )
            except (FloatingPointError, np.linalg.LinAlgError):
                fit, reason = None, "the fit overflows: commands or torques far beyond a head's"
        if fit is None:
            skipped.append((j + 1, reason))
        else:
            _check_inertia(fit.inertia, motor.inertia + link_inertia, j + 1, where)
            fits.append(replace(fit, source=recording.source))
    if not fits:
        reasons = "; ".join(f"joint {j}: {reason}" for j, reason in skipped)
        raise IdentificationError(
            f"{where}: columns 'theta1', 'theta2', 'u1', 'u2': no joint's Eq. 1 could be fitted"
            f" ({reasons})"
        )
    return MotorFit(
        joints=tuple(fits),
        skipped=tuple(skipped),
        filter_bandwidth=float(filter_bandwidth),
        sample_period=period,
        source=recording.source,
    )


def identify_motors_from(
    recordings: Sequence[Recording],
    antenna: Antenna,
    filter_bandwidth: float = DEFAULT_FILTER_BANDWIDTH,
) -> MotorFit:
    """:func:`identify_motors` on each of ``recordings``, each joint taken from the one that
    determines its J best (smallest relative standard error): a free sweep of each joint, say.
    The servo's gains (:meth:`MotorFit.designs`) are designed at the recordings' period, the
    loop's.

    Raises
    ------
    IdentificationError
        As :func:`identify_motors`, for the first recording that cannot be used (one that
        moves no joint included); none given; recordings whose sample periods differ by more
        than ``PERIOD_CONSISTENCY`` (the gains hold at one period only).
    """
    if not recordings:
        raise IdentificationError("no recording to fit the motors to")
    fits = [identify_motors(recording, antenna, filter_bandwidth) for recording in recordings]
    period = fits[0].sample_period
    for recording, fit in zip(recordings[1:], fits[1:], strict=True):
        if abs(fit.sample_period - period) > PERIOD_CONSISTENCY * period:
            raise IdentificationError(
                f"{recording.source or '<recording>'}: sampled every {fit.sample_period:g} s, "
                f"{recordings[0].source or 'the first recording'} every {period:g} s: the "
                "servo's gains hold at one period, the loop's; fit the motors from recordings "
                "of one loop"
            )
    best: dict[int, JointFit] = {}
    for joint in (j for fit in fits for j in fit.joints):
        kept = best.get(joint.joint)
        if kept is None or joint.inertia_error / joint.inertia < kept.inertia_error / kept.inertia:
            best[joint.joint] = joint
    skipped: dict[int, str] = {}
    for number, reason in (s for fit in fits for s in fit.skipped):
        if number not in best:
            skipped.setdefault(number, reason)
    sources = [fit.source for fit in fits if fit.source]
    return MotorFit(
        joints=tuple(best[number] for number in sorted(best)),
        skipped=tuple(sorted(skipped.items())),
        filter_bandwidth=float(filter_bandwidth),
        sample_period=period,
        source=", ".join(sources) if sources else None,
    )
