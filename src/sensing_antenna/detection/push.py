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
sample (steady state there). One compiled kernel computes the criterion, whether the samples come
in blocks or one at a time; :func:`detect_push` is a :class:`PushMonitor` fed one block.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import lfilter_zi

from sensing_antenna.antenna import Antenna
from sensing_antenna.compiler import njit
from sensing_antenna.detection.contact import (
    DEFAULT_RESIDUAL_CUTOFF,
    ContactDetection,
    ContactDetector,
    SampleBlock,
    SampleVector,
    block_rows,
    gravity_moment_sample,
)
from sensing_antenna.detection.filters import (
    PAPER_LOW_PASS_CUTOFF,
    df2t_step,
    low_pass_coefficients,
)
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


@njit(cache=True)
def _axis_angle(theta1: float, theta2: float, ref1: float, ref2: float) -> float:
    """Angle between the link axes X^m(theta1, theta2) and X^m(ref1, ref2) (rad)."""
    # X^m = (cos t2 cos t1, cos t2 sin t1, sin t2)
    c2, r2 = math.cos(theta2), math.cos(ref2)
    dx = c2 * math.cos(theta1) - r2 * math.cos(ref1)
    dy = c2 * math.sin(theta1) - r2 * math.sin(ref1)
    dz = math.sin(theta2) - math.sin(ref2)
    # 2 arcsin(|X - X_ref| / 2): accurate for small angles, unlike arccos of the dot product
    chord = math.sqrt(dx * dx + dy * dy + dz * dz)
    return 2.0 * math.asin(min(0.5 * chord, 1.0))


@njit(cache=True)
def _axis_angles(
    theta: NDArray[np.float64], ref: NDArray[np.float64], out: NDArray[np.float64]
) -> None:
    for i in range(theta.shape[0]):
        out[i] = _axis_angle(theta[i, 0], theta[i, 1], ref[i, 0], ref[i, 1])


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
        2 arcsin(|X - X_ref| / 2), accurate for small angles (unlike arccos of the dot product);
        the push criterion's own computation.
    """
    a, b = np.broadcast_arrays(
        np.asarray(theta, dtype=np.float64), np.asarray(theta_ref, dtype=np.float64)
    )
    out = np.empty(a.shape[:-1])
    _axis_angles(block_rows(a, out.size, 2), block_rows(b, out.size, 2), out.reshape(-1))
    return out


# The push kernel's parameters (``par``) and state (``mem``), float64 arrays. par: low-pass b (2),
# a (2), its lfilter_zi, kind (0 rotation, 1 force, 2 torque), threshold, weight, weight
# moments. mem: low-pass state; angles at t_c; samples fed; t_1 index (-1: none); measure.
_LP_B, _LP_A = slice(0, 2), slice(2, 4)
_ZI, _KIND, _THRESHOLD, _WEIGHT, _WEIGHT_MOMENT, _SAG_MOMENT = range(4, 10)
_N_PAR = 10
_LP_Z = slice(0, 1)
_THETA_C, _COUNT, _INDEX, _MEASURE = 1, 3, 4, 5
_N_MEM = 6


@njit(cache=True)
def _push_block(
    par: NDArray[np.float64],
    mem: NDArray[np.float64],
    contact: int,
    theta: NDArray[np.float64],
    force: NDArray[np.float64],
    torque: NDArray[np.float64],
    measures: NDArray[np.float64],
) -> int:
    """Feed rows of theta (n, 2), force and torque (n, 3); ``contact`` is the contact index
    counted since reset (-1: none). Writes rows count.. of ``measures``; returns the t_1 index
    (-1: none)."""
    kind = int(par[_KIND])
    lp_z = mem[_LP_Z]
    for i in range(theta.shape[0]):
        k = int(mem[_COUNT])
        in_contact = 0 <= contact <= k
        theta2 = theta[i, 1]
        if kind == 0:
            if in_contact:
                if k == contact:
                    mem[_THETA_C], mem[_THETA_C + 1] = theta[i, 0], theta2
                mem[_MEASURE] = _axis_angle(theta[i, 0], theta2, mem[_THETA_C], mem[_THETA_C + 1])
        else:
            if kind == 1:
                # Section 4.2: F^m - F_g^m, F_g^m = -m g (sin theta2, 0, cos theta2)
                x = force[i, 0] + par[_WEIGHT] * math.sin(theta2)
                y = force[i, 1] - 0.0
                z = force[i, 2] + par[_WEIGHT] * math.cos(theta2)
            else:
                # Section 4.2: Gamma^m - Gamma_g^m, Gamma_g^m on Y^m (Link.gravity_moment)
                x = torque[i, 0] - 0.0
                y = torque[i, 1] - gravity_moment_sample(
                    theta2, par[_WEIGHT_MOMENT], par[_SAG_MOMENT]
                )
                z = torque[i, 2] - 0.0
            magnitude = math.sqrt(x * x + y * y + z * z)
            if k == 0:
                # the filter starts in steady state at its first input
                lp_z[0] = par[_ZI] * magnitude
            # Eq. 20: low-pass filtered magnitude
            mem[_MEASURE] = df2t_step(par[_LP_B], par[_LP_A], lp_z, magnitude)
        measures[k] = mem[_MEASURE]
        mem[_COUNT] = k + 1
        if in_contact and mem[_INDEX] < 0.0 and mem[_MEASURE] > par[_THRESHOLD]:
            mem[_INDEX] = k
    return int(mem[_INDEX])


@dataclass(frozen=True, eq=False)
class PushDetection:
    """Result of :func:`detect_push` (or of :meth:`PushMonitor.detection`).

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
        Signal compared with the threshold (rad, N or N m; rotation: zero before t_c).
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
        ``ContactDetector(antenna, sample_period, check_input=check_input)`` when None.
    check_input : bool
        As the contact detector's: refuse a block with a value that is not finite, the force's
        too (ValueError, the state unchanged), and samples whose time stamps step by another
        period than ``sample_period`` (``contact.SamplePeriodError``). A given
        ``contact_detector`` keeps its own setting.

    Attributes
    ----------
    pushed : bool
        True from t_1 on (latched until :meth:`reset`).
    contact_time, push_time : float or None
        t_c and t_1 (s).
    push_index : int or None
        Sample index of t_1 counted from the first sample after reset.
    measure : float
        Latest value of the criterion's signal (rad, N or N m).

    Notes
    -----
    Samples come in blocks (:meth:`update_block`) or one at a time (:meth:`update`, a block of
    one); one compiled kernel gives the same numbers to the bit either way.
    """

    def __init__(
        self,
        criterion: PushCriterion,
        antenna: Antenna,
        sample_period: float,
        contact_detector: ContactDetector | None = None,
        *,
        check_input: bool = True,
    ) -> None:
        self.criterion = criterion
        self.antenna = antenna
        self.sample_period = float(sample_period)
        self.contact_detector = (
            ContactDetector(antenna, sample_period, check_input=check_input)
            if contact_detector is None
            else contact_detector
        )
        b, a = low_pass_coefficients(criterion.cutoff, self.sample_period)
        par = np.zeros(_N_PAR)
        par[_LP_B], par[_LP_A], par[_ZI] = b, a, lfilter_zi(b, a)[0]
        par[_KIND] = _KINDS.index(criterion.kind)
        par[_THRESHOLD] = criterion.threshold
        par[_WEIGHT] = antenna.link.weight
        par[_WEIGHT_MOMENT] = antenna.link.weight_moment
        par[_SAG_MOMENT] = antenna.link.sag_moment
        self._par = par
        self._time = np.zeros(1)  # the time of one sample, as a block
        self.reset()

    def reset(self) -> None:
        """Forget everything, including the contact detector's state."""
        self.contact_detector.reset()
        self._mem = np.zeros(_N_MEM)
        self._mem[_INDEX] = -1.0
        self._measures = np.empty(0)
        self.push_index: int | None = None
        self.push_time: float | None = None

    @property
    def pushed(self) -> bool:
        """True from t_1 on."""
        return self.push_index is not None

    @property
    def contact_time(self) -> float | None:
        """t_c (s), or None before contact."""
        return self.contact_detector.contact_time

    @property
    def measure(self) -> float:
        """Latest value of the criterion's signal (rad, N or N m)."""
        return float(self._mem[_MEASURE])

    def update_block(
        self, t: ArrayLike, theta: SampleBlock, force: SampleBlock, torque: SampleBlock
    ) -> bool:
        """Feed samples (as :meth:`ContactDetector.update_block`, the force used here: by the
        link on the head, motor frame, N); returns True from the block where the criterion is
        met (t_1) on."""
        detector = self.contact_detector
        start = detector.n_samples
        times = np.asarray(t, dtype=np.float64).reshape(-1)
        count = times.shape[0]
        angles = block_rows(theta, count, 2)
        forces, moments = block_rows(force, count, 3), block_rows(torque, count, 3)
        if detector.check_input:
            detector._check(times, (("theta", angles), ("force", forces), ("torque", moments)))
        detector._feed(times, angles, moments)
        if start + count > self._measures.shape[0]:
            grown = np.empty(max(start + count, 2 * self._measures.shape[0], 4096))
            grown[:start] = self._measures[:start]
            self._measures = grown
        contact = -1 if detector.contact_index is None else detector.contact_index
        index = _push_block(
            self._par,
            self._mem,
            contact,
            angles,
            forces,
            moments,
            self._measures,
        )
        if index >= 0 and self.push_index is None:
            self.push_index = index
            self.push_time = float(times[index - start])
        return self.push_index is not None

    def update(
        self, t: float, theta: SampleVector, force: SampleVector, torque: SampleVector
    ) -> bool:
        """Feed one sample (a block of one: t in s, theta (2,) in rad, force (3,) in N, torque
        (3,) in N m); returns True from the sample where the criterion is met (t_1) on."""
        self._time[0] = t
        return self.update_block(self._time, theta, force, torque)

    def detection(self, resampled: bool = False) -> PushDetection:
        """The decision over every sample fed since reset (arrays are views, not copies)."""
        contact = self.contact_detector.detection(resampled)
        rule = self.criterion
        measure = self._measures[: self.contact_detector.n_samples]
        if contact.index is None:
            status: Literal["pushed", "no_push", "no_contact"] = "no_contact"
            reason = contact.reason
        elif self.push_time is None:
            status = "no_push"
            reason = f"{rule.kind} stays at or below {rule.threshold:g} {rule.unit} after t_c"
        else:
            status = "pushed"
            reason = (
                f"{rule.kind} exceeds {rule.threshold:g} {rule.unit} at t = {self.push_time:g} s"
            )
        return PushDetection(
            status, reason, contact.t_c, self.push_time, self.push_index, measure, rule, contact
        )


def detect_push(
    recording: Recording,
    antenna: Antenna,
    criterion: PushCriterion | None = None,
    threshold: float | None = None,
    residual_cutoff: float = DEFAULT_RESIDUAL_CUTOFF,
) -> PushDetection:
    """Contact instant t_c and push instant t_1 of a recording: a :class:`PushMonitor` fed the
    whole recording.

    Parameters
    ----------
    recording : Recording
        Irregular sampling is handled by linear resampling first, as in ``detect_contact``.
    antenna : Antenna
    criterion : PushCriterion, optional
        Default ``PushCriterion()`` (``DEFAULT_ROTATION`` of rotation).
    threshold, residual_cutoff
        Passed to the :class:`~sensing_antenna.detection.contact.ContactDetector`.

    Returns
    -------
    PushDetection
    """
    resampled = recording.sampling.irregular
    uniform = resample_uniform(recording) if resampled else recording
    period = uniform.sample_period
    detector = ContactDetector(antenna, period, threshold, residual_cutoff)
    monitor = PushMonitor(criterion or PushCriterion(), antenna, period, detector)
    monitor.update_block(uniform.t, uniform.theta, uniform.force, uniform.torque)
    return monitor.detection(resampled)
