"""The push criterion: when to stop the motors after contact, the instant t_1 (Section 4 steps 3-4,
Section 5.3).

After the contact instant t_c the motors keep following their trajectory and push the link against
the object; they stop at t_1, when the push is strong enough. The paper stops at a low-pass filtered
force |F^m| of F_m = 0.8 N, but that force does not fit its own link: the static deflection at the
contact point is y_c = F x_c^3 / (3 E I) with E I = 0.090 N m^2, i.e. 8 cm at x_c = 0.3 m (27 % of
x_c) and metres near the tip, far beyond the 10 % small-deflection limit of Assumption 1.

The default criterion therefore limits the head rotation past t_c. With the contact point held by
the object, turning the head by delta_theta after first touch deflects the link at the contact point
by y_c ~ x_c delta_theta relative to the motor axis X^m, so y_c / x_c ~ delta_theta whatever x_c.
The corresponding contact force F = 3 E I delta_theta / x_c^2 is 0.09 N at x_c = 0.3 m and 8 mN
at the tip for 0.03 rad.

What the final y_c / x_c adds up to (simulated device, vibration-free 0.3 rad/s sweep, checked in
``tests/test_simulator_contact.py``):

- the detection delay from first touch to t_c times the sweep speed. A quasi-static contact raises
  the residual torque by 3 E I delta_theta / x_c, so a threshold thr cannot fire before
  delta_theta = thr x_c / (3 E I), plus the residual filter's 10 ms. With the paper's
  0.02 N m that is 0.022 rad at 0.3 m and 0.073 rad at the tip: shallow pushes near the tip are
  then impossible, and the device's threshold must be identified (``antenna identify``,
  Section 5.2). With an observer identified on a simulated free motion (threshold about
  0.0002 N m after taring) the delay is a few ms, under 0.002 rad;
- ``DEFAULT_ROTATION`` = 0.03 rad;
- the servo's travel after the reference freezes: 2 eps omega* = 0.01 rad for Eq. 14 with
  eps = 16.7 ms at 0.3 rad/s. The simulated controller compensates it by freezing the reference
  at r(t_1) - 2 eps omega*(t_1) (``Scenario.compensate_servo_lag``): the joint then comes to rest
  at its angle at t_1, after a transient overshoot of eps omega* / e = 1.8 mrad.

Total with an identified observer: about 3 % over the whole link (simulated: 2.9 % to 3.1 % at
0.3, 0.6 and 0.98 m in both cases). With the paper's observer (0.02 N m) the same criterion ends at
5 % (0.3 m) to 10.6 % (0.98 m), the detection floor plus 3 %.

Criteria (``PushCriterion.kind``):

- ``rotation``: angle (rad) between the link axis X^m now and at t_c;
- ``force``: Eq. 20 low-pass filtered |F^m - F_g^m| (N), the paper's criterion without the weight;
- ``torque``: Eq. 20 low-pass filtered |Gamma^m - Gamma_g^m| (N m).

Only samples from t_c on can meet the criterion. The force and torque filters run from the first
sample (steady state there), so the streaming and batch forms agree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import Antenna
from sensing_antenna.detection.contact import (
    DEFAULT_RESIDUAL_CUTOFF,
    ContactDetection,
    ContactDetector,
    SampleVector,
    detect_contact,
)
from sensing_antenna.detection.filters import PAPER_LOW_PASS_CUTOFF, FirstOrderLowPass, low_pass
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.recording import Recording, resample_uniform

__all__ = [
    "DEFAULT_ROTATION",
    "PushConfigError",
    "PushCriterion",
    "PushDetection",
    "PushMonitor",
    "detect_push",
    "link_axis_angle",
    "push_measure",
]

#: Default head rotation past t_c (rad): the final y_c / x_c is about 3 % with an identified
#: observer (module docstring).
DEFAULT_ROTATION = 0.03

PushKind = Literal["rotation", "force", "torque"]
_KINDS = ("rotation", "force", "torque")
_UNITS = {"rotation": "rad", "force": "N", "torque": "N m"}


class PushConfigError(SensingAntennaError, ValueError):
    """A push criterion field is out of range."""


@dataclass(frozen=True)
class PushCriterion:
    """When the push after contact is strong enough to stop the motors (t_1).

    Parameters
    ----------
    kind : {"rotation", "force", "torque"}
        What is compared with ``threshold`` (module docstring).
    threshold : float
        rad of head rotation past t_c, N of filtered |F - F_g|, or N m of filtered
        |Gamma - Gamma_g|. Default ``DEFAULT_ROTATION`` (0.03 rad).
    cutoff : float
        omega_c of the Eq. 20 low-pass filter for the force and torque kinds (rad/s); 5 rad/s as
        in the paper.
    """

    kind: PushKind = "rotation"
    threshold: float = DEFAULT_ROTATION
    cutoff: float = PAPER_LOW_PASS_CUTOFF

    def __post_init__(self) -> None:
        if self.kind not in _KINDS:
            raise PushConfigError(
                f"push.kind: must be one of {', '.join(_KINDS)}, got {self.kind!r}"
            )
        for name in ("threshold", "cutoff"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise PushConfigError(f"push.{name}: must be a finite number > 0, got {value!r}")

    @property
    def unit(self) -> str:
        """Unit of ``threshold``."""
        return _UNITS[self.kind]


def link_axis_angle(theta: ArrayLike, theta_ref: ArrayLike) -> NDArray[np.float64]:
    """Angle between the link axes X^m(theta) and X^m(theta_ref) (rad).

    Parameters
    ----------
    theta : array_like, shape (..., 2)
        Motor angles (rad).
    theta_ref : array_like, shape (2,) or broadcastable
        Reference motor angles (rad).

    Returns
    -------
    ndarray, shape (...)
        2 arcsin(|X - X_ref| / 2), accurate for small angles (unlike arccos of the dot product).
    """
    a = np.asarray(theta, dtype=np.float64)
    b = np.asarray(theta_ref, dtype=np.float64)
    chord = np.sqrt(
        (np.cos(a[..., 1]) * np.cos(a[..., 0]) - np.cos(b[..., 1]) * np.cos(b[..., 0])) ** 2
        + (np.cos(a[..., 1]) * np.sin(a[..., 0]) - np.cos(b[..., 1]) * np.sin(b[..., 0])) ** 2
        + (np.sin(a[..., 1]) - np.sin(b[..., 1])) ** 2
    )
    return np.asarray(2.0 * np.arcsin(np.minimum(0.5 * chord, 1.0)), dtype=np.float64)


def _axis(theta1: float, theta2: float) -> tuple[float, float, float]:
    c2 = math.cos(theta2)
    return (c2 * math.cos(theta1), c2 * math.sin(theta1), math.sin(theta2))


def _gravity_free_magnitudes(
    recording: Recording, antenna: Antenna
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """|F^m - F_g^m| (N) and |Gamma^m - Gamma_g^m| (N m), shape (n,) each."""
    theta2 = recording.theta[:, 1]
    # Section 4.2: F^m - F_g^m and Gamma^m - Gamma_g^m
    force = recording.force - antenna.gravity_force(theta2)
    torque = recording.torque - antenna.gravity_torque(theta2)
    return np.sqrt(np.sum(force**2, axis=1)), np.sqrt(np.sum(torque**2, axis=1))


def push_measure(
    recording: Recording, antenna: Antenna, criterion: PushCriterion, contact_index: int | None
) -> NDArray[np.float64]:
    """The signal a criterion compares with its threshold, for a uniformly sampled recording.

    Parameters
    ----------
    recording : Recording
    antenna : Antenna
    criterion : PushCriterion
    contact_index : int or None
        Sample of t_c; the rotation is measured from there (zero before it, and everywhere if
        None).

    Returns
    -------
    ndarray, shape (n,)
        rad, N or N m depending on ``criterion.kind``.
    """
    if criterion.kind == "rotation":
        measure = np.zeros(recording.n_samples)
        if contact_index is not None:
            measure[contact_index:] = link_axis_angle(
                recording.theta[contact_index:], recording.theta[contact_index]
            )
        return measure
    force, torque = _gravity_free_magnitudes(recording, antenna)
    # Eq. 20: G(s) = 1 / (1 + s / omega_c) on the magnitude
    return low_pass(
        force if criterion.kind == "force" else torque, criterion.cutoff, recording.sample_period
    )


@dataclass(frozen=True, eq=False)
class PushDetection:
    """Result of :func:`detect_push`.

    Parameters
    ----------
    status : {"pushed", "no_push", "no_contact"}
    reason : str
    t_c : float or None
        Contact instant (s).
    t_1 : float or None
        Instant the push criterion is first met at or after t_c (s).
    index : int or None
        Sample index of t_1 in ``contact.t``.
    measure : ndarray, shape (n,)
        Signal compared with the threshold (``push_measure``).
    criterion : PushCriterion
    contact : ContactDetection
    """

    status: Literal["pushed", "no_push", "no_contact"]
    reason: str
    t_c: float | None
    t_1: float | None
    index: int | None
    measure: NDArray[np.float64]
    criterion: PushCriterion
    contact: ContactDetection


def detect_push(
    recording: Recording,
    antenna: Antenna,
    criterion: PushCriterion | None = None,
    threshold: float | None = None,
    residual_cutoff: float = DEFAULT_RESIDUAL_CUTOFF,
) -> PushDetection:
    """Contact instant t_c and push instant t_1 of a recording (batch form of
    :class:`PushMonitor`).

    Parameters
    ----------
    recording : Recording
        Irregular sampling is handled by linear resampling first, as in ``detect_contact``.
    antenna : Antenna
    criterion : PushCriterion, optional
        Default ``PushCriterion()`` (``DEFAULT_ROTATION`` of rotation).
    threshold, residual_cutoff
        Passed to :func:`~sensing_antenna.detection.contact.detect_contact`.

    Returns
    -------
    PushDetection
    """
    rule = PushCriterion() if criterion is None else criterion
    contact = detect_contact(recording, antenna, threshold, residual_cutoff)
    uniform = resample_uniform(recording) if contact.resampled else recording
    measure = push_measure(uniform, antenna, rule, contact.index)

    def result(status: Literal["pushed", "no_push", "no_contact"], reason: str) -> PushDetection:
        return PushDetection(status, reason, contact.t_c, None, None, measure, rule, contact)

    if contact.index is None:
        return result("no_contact", contact.reason)
    above = np.flatnonzero(measure[contact.index :] > rule.threshold)
    if above.size == 0:
        return result(
            "no_push",
            f"{rule.kind} stays at or below {rule.threshold:g} {rule.unit} after t_c",
        )
    index = contact.index + int(above[0])
    t_1 = float(uniform.t[index])
    return PushDetection(
        status="pushed",
        reason=f"{rule.kind} exceeds {rule.threshold:g} {rule.unit} at t = {t_1:g} s",
        t_c=contact.t_c,
        t_1=t_1,
        index=index,
        measure=measure,
        criterion=rule,
        contact=contact,
    )


class PushMonitor:
    """Streaming push criterion: the simulated (or real) controller's stop rule.

    Parameters
    ----------
    criterion : PushCriterion
    antenna : Antenna
    sample_period : float
        T_s (s).
    contact_detector : ContactDetector, optional
        Detector of t_c, updated by this monitor (do not update it separately); a default
        ``ContactDetector(antenna, sample_period)`` when None.

    Attributes
    ----------
    pushed : bool
        True from t_1 on (latched until :meth:`reset`).
    contact_time, push_time : float or None
        t_c and t_1 (s).
    push_index : int or None
        Sample index of t_1 counted from the first update after reset.
    measure : float
        Latest value of the criterion's signal (rad, N or N m).
    """

    def __init__(
        self,
        criterion: PushCriterion,
        antenna: Antenna,
        sample_period: float,
        contact_detector: ContactDetector | None = None,
    ) -> None:
        self.criterion = criterion
        self.antenna = antenna
        self.sample_period = float(sample_period)
        self.contact_detector = (
            ContactDetector(antenna, sample_period)
            if contact_detector is None
            else contact_detector
        )
        self._filter = FirstOrderLowPass(criterion.cutoff, sample_period)
        self._link = antenna.link
        self._weight = antenna.link.weight
        self.reset()

    def reset(self) -> None:
        """Forget everything, including the contact detector's state."""
        self.contact_detector.reset()
        self._filter.reset()
        self._axis_c: tuple[float, float, float] | None = None
        self.pushed = False
        self.push_time: float | None = None
        self.push_index: int | None = None
        self.measure = 0.0
        self._count = 0

    @property
    def contact_time(self) -> float | None:
        """t_c (s), or None before contact."""
        return self.contact_detector.contact_time

    def update(
        self, t: float, theta: SampleVector, force: SampleVector, torque: SampleVector
    ) -> bool:
        """Feed one sample; returns True from the sample where the criterion is met (t_1) on.

        Parameters
        ----------
        t : float
            Sample time (s).
        theta : array_like, shape (2,)
            Motor angles (rad).
        force : array_like, shape (3,)
            Force by the link on the head, motor frame (N).
        torque : array_like, shape (3,)
            Torque by the link on the head about O, motor frame (N m).
        """
        in_contact = self.contact_detector.update(t, theta, force, torque)
        theta1, theta2 = float(theta[0]), float(theta[1])
        kind = self.criterion.kind
        if kind == "rotation":
            if in_contact:
                if self._axis_c is None:
                    self._axis_c = _axis(theta1, theta2)
                x, y, z = _axis(theta1, theta2)
                cx, cy, cz = self._axis_c
                chord = math.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2)
                self.measure = 2.0 * math.asin(min(0.5 * chord, 1.0))
        elif kind == "force":
            # Section 4.2: F^m - F_g^m, F_g^m = -m_b g (sin theta2, 0, cos theta2)
            f = force
            fx = float(f[0]) + self._weight * math.sin(theta2)
            fy = float(f[1])
            fz = float(f[2]) + self._weight * math.cos(theta2)
            # Eq. 20: low-pass filtered |F^m - F_g^m|
            self.measure = self._filter.update(math.sqrt(fx * fx + fy * fy + fz * fz))
        else:
            # Section 4.2: Gamma^m - Gamma_g^m, Gamma_g^m = (0, m_b g l cos theta2 / 2, 0) with
            # tip mass and sag (Link.gravity_moment)
            g = torque
            gx = float(g[0])
            gy = float(g[1]) - float(self._link.gravity_moment(theta2))
            gz = float(g[2])
            # Eq. 20: low-pass filtered |Gamma^m - Gamma_g^m|
            self.measure = self._filter.update(math.sqrt(gx * gx + gy * gy + gz * gz))
        if in_contact and not self.pushed and self.measure > self.criterion.threshold:
            self.pushed = True
            self.push_time = float(t)
            self.push_index = self._count
        self._count += 1
        return self.pushed
