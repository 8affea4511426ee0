"""The joints' servo: the 2-DOF PID with coupling-torque feedback (Section 4.1, Eq. 14).

Eq. 1 at joint i: ``n K_m u = J theta_dd + v theta_d + Gamma_nlc + Gamma_coup``. The controller
adds the measured coupling torque to its command, ``n K_m u = R1 theta* - R2 theta + Gamma_coup``,
so the servo sees the plant ``1 / (s (J s + v))`` whatever the link does. With
``R(s) = (a2 s^2 + a1 s + a0) / (s (s + b))`` the closed loop is
``theta / theta* = N1 / (s^2 (s + b) (J s + v) + N2)``. Placing the four poles at p:

    J s^4 + (J b + v) s^3 + (v b + a2) s^2 + a1 s + a0 = J (s - p)^4
    => b = -4 p - v / J,  a2 = 6 J p^2 - v b,  a1 = -4 J p^3,  a0 = J p^4.

The zeros of R1 at p, ``N1 = J p^2 (s - p)^2``, cancel two poles and give Eq. 14,
``theta / theta* = p^2 / (s - p)^2 = 1 / (1 + eps s)^2`` with ``eps = -1/p``; ``N1(0) = N2(0) =
J p^4`` gives unit DC gain.

The controller runs at 1 kHz. Each R is discretised with the bilinear (Tustin) map
``s = (2 / T_s) (z - 1) / (z + 1)``; the command is held over the sample (zero-order hold).
To the coupling-torque feedback the step adds a feedforward of the modelled Coulomb friction of
Eq. 1 at the reference speed, ``Gamma_nlc tanh(omega* / omega_s)`` (``FRICTION_SPEED``).

An optional command limit L (N m, per joint) stands for the amplifier's saturation: the command
applied is clipped to [-L, L], with back-calculation anti-windup in the polynomial form of
Astrom and Wittenmark (*Computer-Controlled Systems*, "Integrator windup") for a controller whose
two parts share the denominator A = (1 - q^-1)(1 - z_b q^-1), the Tustin image of s (s + b):
``A_o v = B1 theta* - B2 theta + (A_o - A) w``, with w the PID's share of the command applied
(the applied command less the coupling-torque and friction terms) and the observer polynomial
``A_o = (1 - z_p q^-1)(1 - z_b q^-1)``, z_p the Tustin image of the closed-loop pole p. While
the command stays inside the limit w = v and this is the unlimited controller; while it is
clipped, the integrator's pole moves from 1 to z_p: the integral state tracks the command
applied with the closed loop's time constant eps = -1/p instead of winding up. Without a limit
(L infinite) the arithmetic is the unlimited controller's, to the bit, and so it is while the
command stays inside a finite limit.

One implementation: :func:`joint_servo_step`, compiled with numba, advances one joint by one
sample on a state array (``JOINT_STATE_SIZE`` values: the two biquads' direct form II transposed
states, the angle origin, the previous reference, a started flag, the command limit and the
anti-windup's tracking gain). The simulator's compiled time
loop calls it at every sample, and :class:`HeadController` calls it for a real device's loop
(per sample with :meth:`HeadController.step`, or a block at a time with
:meth:`HeadController.step_block`), so both run the same arithmetic to the bit.

Units: angles in rad, torques in N m. The command is the joint torque ``n K_m u`` of Eq. 1 (N m);
:meth:`HeadController.voltage` divides by ``n K_m`` for an amplifier fed with the voltage u (V).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import Antenna, Motor
from sensing_antenna.compiler import njit
from sensing_antenna.errors import SensingAntennaError, refuse_non_finite

__all__ = [
    "DEFAULT_SERVO_POLE",
    "FRICTION_SPEED",
    "JOINT_STATE_SIZE",
    "MAX_POLE_STEP",
    "ControlConfigError",
    "HeadController",
    "ServoDesign",
    "coupling_torques",
    "design_servo",
    "initial_servo_state",
    "joint_coupling_torques",
    "joint_servo_step",
    "tustin_biquad",
]

#: Closed-loop pole p of Eq. 14 used by default (rad/s): eps = 1/60 s, fast next to the link's
#: free-motion mode (16.4 rad/s) and slow next to the 1 kHz sampling (|p| T_s = 0.06).
DEFAULT_SERVO_POLE = -60.0

#: Largest |p| T_s a servo is designed for (the simulator's bound): faster poles leave the
#: controller's discrete (Tustin) form further from the continuous design it is made from (a
#: pole of -1500 rad/s at 1 kHz, |p| T_s = 1.5, diverged on a rigid Eq. 1 plant).
MAX_POLE_STEP = 0.3

#: Regularisation speed omega_s of the motors' Coulomb friction, ``Gamma_nlc tanh(omega /
#: omega_s)`` (rad/s): the friction model of Eq. 1 that the simulator integrates and the
#: controller's friction feedforward uses.
FRICTION_SPEED = 0.05

#: Values of one joint's servo state (:func:`initial_servo_state`).
JOINT_STATE_SIZE = 9

# Joint state layout: R1's biquad state (2), R2's (2), the angle origin, the previous reference,
# 1.0 once a sample has been stepped, the command limit (N m; inf: none), the tracking gain
# 1 - z_p of the anti-windup.
_R1 = 0
_R2 = 2
_ORIGIN = 4
_PREVIOUS = 5
_STARTED = 6
_LIMIT = 7
_TRACKING = 8


class ControlConfigError(SensingAntennaError, ValueError):
    """A controller cannot be designed with the requested parameters."""


@dataclass(frozen=True)
class ServoDesign:
    """Continuous 2-DOF PID design of one joint and its 1 kHz discretisation.

    Attributes
    ----------
    pole : float
        Closed-loop pole p (rad/s, < 0).
    b : float
        Controller pole location (R denominator s (s + b)) (rad/s).
    feedback : tuple of 3 float
        (a2, a1, a0) of R2 (N m/rad, N m/(rad s), N m/(rad s^2)).
    feedforward : tuple of 3 float
        (a2, a1, a0) of R1 = J p^2 (s - p)^2 / (s (s + b)).
    sample_period : float
        Controller period T_s (s).
    """

    pole: float
    b: float
    feedback: tuple[float, float, float]
    feedforward: tuple[float, float, float]
    sample_period: float

    @property
    def time_constant(self) -> float:
        """eps = -1/p of Eq. 14 (s)."""
        return -1.0 / self.pole

    @property
    def tracking_gain(self) -> float:
        """1 - z_p, z_p = (1 + p T_s / 2) / (1 - p T_s / 2) the Tustin image of the pole: the
        share of the gap between the PID's output and the command applied that its integral
        state takes on per sample while the command is clipped (dimensionless)."""
        half = 0.5 * self.pole * self.sample_period
        return 1.0 - (1.0 + half) / (1.0 - half)

    def discrete(self) -> NDArray[np.float64]:
        """Tustin biquads, shape (2, 2, 3): [R1, R2] x [numerator, denominator] in z^-1."""
        den = (1.0, self.b, 0.0)
        out = np.empty((2, 2, 3))
        for i, num in enumerate((self.feedforward, self.feedback)):
            bz, az = tustin_biquad(num, den, self.sample_period)
            out[i, 0] = bz
            out[i, 1] = az
        return out


def design_servo(motor: Motor, pole: float, sample_period: float) -> ServoDesign:
    """Place the four closed-loop poles and R1's zeros at ``pole`` (Section 4.1, Eq. 14).

    Parameters
    ----------
    motor : Motor
        J and v are used (link-side values of Table 1).
    pole : float
        p (rad/s), negative.
    sample_period : float
        Controller period (s), finite and > 0.

    Raises
    ------
    ControlConfigError
        When ``pole`` is not a negative number or ``sample_period`` not a positive one, or
        the pole is too fast for the period (:data:`MAX_POLE_STEP`).
    """
    if not (math.isfinite(pole) and pole < 0):
        raise ControlConfigError(f"pole: must be a finite number < 0 (stable), got {pole!r}")
    if not (math.isfinite(sample_period) and sample_period > 0):
        raise ControlConfigError(f"sample_period: must be finite and > 0, got {sample_period!r}")
    if -pole * sample_period > MAX_POLE_STEP and sample_period >= 1.0:
        raise ControlConfigError(
            f"sample_period: {sample_period!r} s, the period in s of the loop (not its rate in "
            f"Hz: 1 kHz is 0.001 s)"
        )
    if -pole * sample_period > MAX_POLE_STEP:
        raise ControlConfigError(
            f"pole: {pole:g} rad/s is too fast for the controller's period {sample_period:g} s "
            f"(|p| T_s = {-pole * sample_period:.3g}, more than {MAX_POLE_STEP:g}: its discrete "
            f"form no longer follows the design); at most {MAX_POLE_STEP / sample_period:.0f} "
            "rad/s in magnitude"
        )
    j = motor.inertia
    v = motor.viscous_friction
    p = pole
    # Sec. 4.1: characteristic polynomial s^2 (s+b)(J s+v) + a2 s^2 + a1 s + a0 = J (s-p)^4
    b = -4.0 * p - v / j
    a2 = 6.0 * j * p * p - v * b
    a1 = -4.0 * j * p**3
    a0 = j * p**4
    # Eq. 14: R1 = J p^2 (s - p)^2 / (s (s + b)) cancels two closed-loop poles
    feedforward = (j * p * p, -2.0 * j * p**3, j * p**4)
    return ServoDesign(
        pole=p, b=b, feedback=(a2, a1, a0), feedforward=feedforward, sample_period=sample_period
    )


def tustin_biquad(
    num: tuple[float, float, float], den: tuple[float, float, float], sample_period: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Bilinear map of ``(n2 s^2 + n1 s + n0) / (d2 s^2 + d1 s + d0)`` to a biquad in z^-1.

    Returns
    -------
    (bz, az) : ndarrays, shape (3,)
        ``y_k = (bz . [x_k, x_k-1, x_k-2] - az[1:] . [y_k-1, y_k-2]) / 1`` with az[0] = 1.
    """
    c = 2.0 / sample_period
    n2, n1, n0 = num
    d2, d1, d0 = den
    bz = np.array([n2 * c * c + n1 * c + n0, 2.0 * n0 - 2.0 * n2 * c * c, n2 * c * c - n1 * c + n0])
    az = np.array([d2 * c * c + d1 * c + d0, 2.0 * d0 - 2.0 * d2 * c * c, d2 * c * c - d1 * c + d0])
    return bz / az[0], az / az[0]


def initial_servo_state(
    origin: float = math.nan, limit: float = math.inf, tracking_gain: float = 0.0
) -> NDArray[np.float64]:
    """A joint's servo state at rest, shape (``JOINT_STATE_SIZE``,).

    Parameters
    ----------
    origin : float
        Angle (rad) about which the PID starts at rest: the head at rest at ``origin`` with the
        reference ``origin`` gives a zero command. NaN (the default): the first reference
        stepped.
    limit : float
        Largest magnitude of the joint torque command n K_m u (N m), > 0; inf (the default):
        no limit.
    tracking_gain : float
        The anti-windup's :attr:`ServoDesign.tracking_gain`, in (0, 1], needed with a finite
        limit (unused without one).
    """
    if not limit > 0:
        raise ControlConfigError(f"limit: must be > 0 N m (inf: none), got {limit!r}")
    if math.isfinite(limit) and not 0.0 < tracking_gain <= 1.0:
        raise ControlConfigError(
            f"tracking_gain: must lie in (0, 1] with a finite limit, got {tracking_gain!r}"
        )
    state = np.zeros(JOINT_STATE_SIZE)
    state[_ORIGIN] = origin
    state[_LIMIT] = limit
    state[_TRACKING] = tracking_gain
    return state


@njit(cache=True)
def _biquad(coef: NDArray[np.float64], state: NDArray[np.float64], k: int, x: float) -> float:
    """Direct form II transposed; coef (2, 3) = [b, a]; state[k], state[k+1]."""
    y = coef[0, 0] * x + state[k]
    state[k] = coef[0, 1] * x - coef[1, 1] * y + state[k + 1]
    state[k + 1] = coef[0, 2] * x - coef[1, 2] * y
    return y


@njit(cache=True)
def joint_servo_step(
    coefficients: NDArray[np.float64],
    state: NDArray[np.float64],
    reference: float,
    measured: float,
    coupling: float,
    coupling_gain: float,
    coulomb_torque: float,
    friction_speed: float,
    sample_period: float,
) -> float:
    """One joint's command for one sample (Section 4.1, Fig. 7): the 2-DOF PID, the coupling
    torque and the Coulomb friction feedforward, clipped to the state's command limit with
    back-calculation anti-windup (the module's docstring).

    Parameters
    ----------
    coefficients : ndarray, shape (2, 2, 3)
        :meth:`ServoDesign.discrete`: [R1, R2] x [numerator, denominator] in z^-1.
    state : ndarray, shape (JOINT_STATE_SIZE,)
        :func:`initial_servo_state`, updated in place.
    reference, measured : float
        theta* and the measured angle theta at this sample (rad).
    coupling : float
        Measured coupling torque Gamma_coup of the joint (N m, :func:`joint_coupling_torques`).
    coupling_gain : float
        Weight of the coupling-torque feedback (1 as designed, 0 without it).
    coulomb_torque : float
        Gamma_nlc of Eq. 1 (N m), fed forward at the reference speed.
    friction_speed : float
        omega_s of the friction model (rad/s).
    sample_period : float
        T_s (s), for the reference speed.

    Returns
    -------
    float
        Joint torque n K_m u (N m), to hold until the next sample; within the limit.
    """
    if math.isnan(state[_ORIGIN]):
        state[_ORIGIN] = reference
    # Eq. 14, 2-DOF PID: n K_m u = R1 theta* - R2 theta, about the origin where it starts at rest
    y1 = _biquad(coefficients[0], state, _R1, reference - state[_ORIGIN])
    y2 = _biquad(coefficients[1], state, _R2, measured - state[_ORIGIN])
    command = y1 - y2
    # Fig. 7: feedback of the measured coupling torque
    command += coupling_gain * coupling
    # feedforward of the modelled Coulomb friction of Eq. 1 from the reference speed
    if state[_STARTED] > 0.0:
        speed = (reference - state[_PREVIOUS]) / sample_period
        command += coulomb_torque * math.tanh(speed / friction_speed)
    state[_PREVIOUS] = reference
    state[_STARTED] = 1.0
    limit = state[_LIMIT]
    if command > limit or command < -limit:
        applied = math.copysign(limit, command)
        # back-calculation, A_o v = B1 r - B2 theta + (A_o - A) w: with A = 1 + a1 q^-1 +
        # a2 q^-2 (a2 = z_b) and A_o = (1 - z_p q^-1)(1 - z_b q^-1), A_o - A = g q^-1 (1 -
        # a2 q^-1), g = 1 - z_p; w - v = applied - command enters R1's state (the two share A)
        excess = state[_TRACKING] * (applied - command)
        state[_R1] += excess
        state[_R1 + 1] -= coefficients[0, 1, 2] * excess
        command = applied
    return command


@njit(cache=True)
def joint_coupling_torques(theta2: float, torque_m: NDArray[np.float64]) -> tuple[float, float]:
    """Coupling torques of the two joints from the sensor's torque (by the link on the head).

    Parameters
    ----------
    theta2 : float
        Measured elevation angle (rad).
    torque_m : ndarray, shape (3,)
        Torque about O in the motor frame (N m), columns x, y, z.

    Returns
    -------
    (float, float)
        Gamma_coup of joint 1, about Z^a, and of joint 2, about -Y^m (N m).
    """
    # the azimuth axis Z^a = sin(theta2) X^m + cos(theta2) Z^m; the elevation axis is -Y^m
    coupling1 = -(math.sin(theta2) * torque_m[0] + math.cos(theta2) * torque_m[2])
    coupling2 = torque_m[1]
    return coupling1, coupling2


@njit(cache=True)
def _coupling_block(
    theta: NDArray[np.float64], torque: NDArray[np.float64], out: NDArray[np.float64]
) -> None:
    for k in range(theta.shape[0]):
        out[k, 0], out[k, 1] = joint_coupling_torques(theta[k, 1], torque[k])


def coupling_torques(theta: ArrayLike, torque: ArrayLike) -> NDArray[np.float64]:
    """Coupling torques of both joints from measured angles and sensor torques.

    Parameters
    ----------
    theta : array_like, shape (n, 2) or (2,)
        Measured joint angles (rad).
    torque : array_like, shape (n, 3) or (3,)
        Sensor torque by the link on the head about O, motor frame (N m).

    Returns
    -------
    ndarray, shape (n, 2) or (2,)
        Gamma_coup of joints 1 and 2 (N m), what :meth:`HeadController.step` feeds back.
    """
    angles = np.asarray(theta, dtype=np.float64)
    loads = np.asarray(torque, dtype=np.float64)
    if angles.ndim not in (1, 2) or angles.shape[-1] != 2:
        raise ValueError(f"theta: expected two angles (joints 1 and 2), got shape {angles.shape}")
    if loads.ndim not in (1, 2) or loads.shape[-1] != 3:
        raise ValueError(f"torque: expected three torques (tx, ty, tz), got shape {loads.shape}")
    single = angles.ndim == 1
    angles2 = np.ascontiguousarray(angles.reshape(-1, 2))
    loads2 = np.ascontiguousarray(loads.reshape(-1, 3))
    if angles2.shape[0] != loads2.shape[0]:
        raise ValueError(f"{angles2.shape[0]} angle rows but {loads2.shape[0]} torque rows")
    out = np.empty((angles2.shape[0], 2))
    _coupling_block(angles2, loads2, out)
    return out[0] if single else out


@njit(cache=True)
def _head_block(
    coefficients: NDArray[np.float64],
    parameters: NDArray[np.float64],
    state: NDArray[np.float64],
    reference: NDArray[np.float64],
    measured: NDArray[np.float64],
    coupling: NDArray[np.float64],
    out: NDArray[np.float64],
) -> None:
    """Both joints over the rows of reference, measured, coupling (n, 2); parameters (2, 4) =
    coupling gain, Coulomb torque, friction speed, sample period."""
    for k in range(reference.shape[0]):
        for j in range(2):
            out[k, j] = joint_servo_step(
                coefficients[j],
                state[j],
                reference[k, j],
                measured[k, j],
                coupling[k, j],
                parameters[j, 0],
                parameters[j, 1],
                parameters[j, 2],
                parameters[j, 3],
            )


class HeadController:
    """The head's two servos (Section 4.1, Fig. 7) for a loop at ``sample_period``.

    Each sample: the references theta* (rad), the measured angles theta (rad) and the measured
    coupling torques (N m, :func:`coupling_torques` of the sensor's torque) in, the joint torques
    n K_m u (N m) out, to apply until the next sample (:meth:`voltage` for the motor voltages u).
    The closed loop follows Eq. 14, theta / theta* = 1 / (1 + eps s)^2 with eps = -1 / pole,
    whatever the link does.

    Parameters
    ----------
    antenna : Antenna
        Its motors (Table 1: J, v for the design; K_m, n for the voltage; the Coulomb torque for
        the feedforward).
    sample_period : float
        T_s (s), the loop's period: the device's own (1e-3 for the paper's 1 kHz), which the
        discrete design follows.
    pole : float
        Closed-loop pole p (rad/s), negative.
    coupling_feedback : bool
        Feed the measured coupling torque back (Fig. 7); without it the servo sees the link.
    friction_feedforward : bool
        Feed the motors' modelled Coulomb torque forward at the reference speed.
    friction_speed : float
        omega_s of the friction model tanh(omega / omega_s) (rad/s).
    torque_limit : float or array_like of 2 float, optional
        Largest joint torque each amplifier delivers, |n K_m u| <= L (N m), one for both joints
        or one per joint; the command is clipped there, with back-calculation anti-windup.
        None (the default): no limit.
    voltage_limit : float or array_like of 2 float, optional
        The same limit given as the amplifier's voltage range |u| <= U (V): L = n K_m U. At most
        one of ``torque_limit`` and ``voltage_limit``.

    Notes
    -----
    Each joint starts at rest about an origin: after :meth:`reset` (or construction) the first
    reference stepped, or the angles passed to ``reset(origin)``. The simulator starts it at the
    initial angles and steps it with the same compiled :func:`joint_servo_step`.
    """

    def __init__(
        self,
        antenna: Antenna,
        sample_period: float,
        *,
        pole: float = DEFAULT_SERVO_POLE,
        coupling_feedback: bool = True,
        friction_feedforward: bool = True,
        friction_speed: float = FRICTION_SPEED,
        torque_limit: float | ArrayLike | None = None,
        voltage_limit: float | ArrayLike | None = None,
    ) -> None:
        if not (math.isfinite(friction_speed) and friction_speed > 0):
            raise ControlConfigError(
                f"friction_speed: must be finite and > 0, got {friction_speed!r}"
            )
        motors = antenna.motors
        self.designs = tuple(design_servo(m, pole, sample_period) for m in motors)
        self.sample_period = float(sample_period)
        #: n K_m of each joint (N m / V).
        self.torque_gains = np.array([m.gear_ratio * m.torque_constant for m in motors])
        #: Command limit of each joint (N m); inf where there is none.
        self.torque_limits = _limits(torque_limit, voltage_limit, self.torque_gains)
        self._coefficients = np.stack([d.discrete() for d in self.designs])
        self._parameters = np.array(
            [
                [
                    1.0 if coupling_feedback else 0.0,
                    m.coulomb_torque if friction_feedforward else 0.0,
                    float(friction_speed),
                    self.sample_period,
                ]
                for m in motors
            ]
        )
        self.reset()

    @property
    def time_constant(self) -> float:
        """eps = -1/p of Eq. 14 (s)."""
        return self.designs[0].time_constant

    def reset(self, origin: ArrayLike | None = None) -> None:
        """Start again at rest.

        Parameters
        ----------
        origin : array_like, shape (2,), optional
            Angles (rad) at which the head rests; default: the first reference stepped.
        """
        start = (math.nan, math.nan) if origin is None else _pair(origin, "origin")
        self._state = np.stack(
            [
                initial_servo_state(float(a), float(limit), design.tracking_gain)
                for a, limit, design in zip(start, self.torque_limits, self.designs, strict=True)
            ]
        )

    def step(
        self, reference: ArrayLike, measured: ArrayLike, coupling: ArrayLike
    ) -> NDArray[np.float64]:
        """Commands for one sample.

        Parameters
        ----------
        reference, measured : array_like, shape (2,)
            theta* and theta of joints 1 and 2 (rad).
        coupling : array_like, shape (2,)
            Measured coupling torques of joints 1 and 2 (N m).

        Returns
        -------
        ndarray, shape (2,)
            Joint torques n K_m u (N m).

        Raises
        ------
        ValueError
            For a value that is NaN or infinite (an encoder or sensor glitch), naming it. The
            controller's state is untouched: the loop may keep its last command for the sample
            and step on with the next; a NaN stepped in would hold every later command at NaN.
        """
        rows = [
            _pair(v, name)[None, :]
            for v, name in (
                (reference, "reference"),
                (measured, "measured"),
                (coupling, "coupling"),
            )
        ]
        _finite(rows)
        return self._block(*rows)[0]

    def step_block(
        self, reference: ArrayLike, measured: ArrayLike, coupling: ArrayLike
    ) -> NDArray[np.float64]:
        """Commands for consecutive samples: :meth:`step` row by row, compiled.

        Parameters
        ----------
        reference, measured, coupling : array_like, shape (n, 2)
            As for :meth:`step`, time on axis 0.

        Returns
        -------
        ndarray, shape (n, 2)
            Joint torques (N m); the command of row k uses the rows up to k only.

        Raises
        ------
        ValueError
            For misshapen inputs, or a NaN or infinite value (naming its row), the state
            untouched, as :meth:`step`.
        """
        rows = [
            np.ascontiguousarray(np.asarray(v, dtype=np.float64).reshape(-1, 2))
            for v in (reference, measured, coupling)
        ]
        if not rows[0].shape == rows[1].shape == rows[2].shape:
            raise ValueError(
                "reference, measured, coupling: shapes "
                f"{', '.join(str(r.shape) for r in rows)} differ"
            )
        _finite(rows)
        return self._block(*rows)

    def _block(
        self,
        reference: NDArray[np.float64],
        measured: NDArray[np.float64],
        coupling: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        out = np.empty(reference.shape)
        _head_block(
            self._coefficients, self._parameters, self._state, reference, measured, coupling, out
        )
        return out

    def voltage(self, torque: ArrayLike) -> NDArray[np.float64]:
        """Motor voltages u = torque / (n K_m) of Eq. 1 (V), shape like ``torque`` (..., 2)."""
        return np.asarray(torque, dtype=np.float64) / self.torque_gains


def _limits(
    torque_limit: float | ArrayLike | None,
    voltage_limit: float | ArrayLike | None,
    torque_gains: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Each joint's command limit (N m), shape (2,), inf without one."""
    if torque_limit is not None and voltage_limit is not None:
        raise ControlConfigError("torque_limit, voltage_limit: give one of them, not both")
    if torque_limit is None and voltage_limit is None:
        return np.full(2, math.inf)
    name = "torque_limit" if torque_limit is not None else "voltage_limit"
    given = np.asarray(torque_limit if torque_limit is not None else voltage_limit)
    try:
        values = np.broadcast_to(given.astype(np.float64), (2,)).copy()
    except (TypeError, ValueError):
        raise ControlConfigError(
            f"{name}: expected one number or two (joints 1 and 2), got {given!r}"
        ) from None
    if not np.all(values > 0):
        unit = "N m" if name == "torque_limit" else "V"
        raise ControlConfigError(f"{name}: must be > 0 {unit}, got {values.tolist()}")
    return values if name == "torque_limit" else values * torque_gains


def _finite(rows: list[NDArray[np.float64]]) -> None:
    """Refuse NaN or infinite inputs (reference, measured, coupling: rows of shape (n, 2))."""
    if rows[0].shape[0] == 1:
        (a, b), (c, d), (e, f) = (r[0].tolist() for r in rows)
        if math.isfinite(a + b + c + d + e + f):  # one sample, the loop's case: cheap
            return
    refuse_non_finite(zip(("reference", "measured", "coupling"), rows, strict=True), "command")


def _pair(values: ArrayLike, name: str) -> NDArray[np.float64]:
    array = np.asarray(values, dtype=np.float64)
    if array.shape != (2,):
        raise ValueError(f"{name}: expected two values (joints 1 and 2), got shape {array.shape}")
    return array
