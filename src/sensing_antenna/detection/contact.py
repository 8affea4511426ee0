"""Contact instant t_c from the coupling-torque residual (Sections 4.2 and 5.2 of the paper).

The free-motion observer of Eq. 15, Gamma_e,i = K s^2 / (s^2 + d s + omega^2) theta_i, predicts the
torque each joint's motion causes at the base while nothing touches the link; the weight of the link
adds Gamma_g^m = (0, m_b g l cos(theta2) / 2, 0). The residual of Eq. 16,
r^m = Gamma^m - (Gamma_e^m + Gamma_g^m), stays small in free motion and grows at contact; t_c is the
first sample where the norm of the low-pass filtered residual exceeds a threshold.

Signs (re-derived; the paper's are opposite). Recordings hold the torque exerted BY the link ON the
head (``docs/recording-format.md``). At low frequency Eq. 15 reduces to
(K / omega^2) theta_ddot, the inertial torque of a rigid link (K / omega^2 ~ m_b l^2 / 3).
Turning the head with angular acceleration alpha about an axis u needs a torque J alpha u on the
link, so the link exerts -J alpha u on the head. The azimuth turns about Z^a (= Z^m when
theta2 = 0), and a positive theta2 turns X^m towards Z^a, i.e. about -Y^m. Hence, in the
recording's convention,

    Gamma_e^m = (0, +Gamma_e,2, -Gamma_e,1),

the opposite of the paper's "Gamma_e,1 on Z^m, -Gamma_e,2 on Y^m", which would double the
dynamic torque in the residual instead of cancelling it. The gravity term keeps the paper's sign
(it matches the spec's sign check). High-frequency check: Eq. 15 tends to K theta, the bent link's
spring torque, which also resists the rotation. ``OBSERVER_TORQUE_SIGNS`` holds this choice.

Residual filter (not given in the paper): each component of r^m passes through a first-order
low-pass filter with cut-off ``DEFAULT_RESIDUAL_CUTOFF`` = 100 rad/s (time constant 10 ms), six
times the free-motion mode (16.4 rad/s) so that the observer's bandwidth is kept, while sensor
noise is attenuated (the unmodelled second free-motion mode, about 6.3 times the first or
100 rad/s, only by 3 dB). It adds about one time constant of delay on a ramp-like residual.
The threshold of Section 5.2 is identified with this same filter (``calibration/observer.py``).

Taring (not in the paper, standard with strain-gauge sensors): a force/torque sensor carries an
offset of a few counts that drifts between runs, and the free-motion residual must not contain it,
or the threshold identified on one run is crossed at the first sample of another. The mean residual
over the first ``DEFAULT_TARE_TIME`` of the recording (the head at rest, or moving as the observer
predicts) is taken as the offset and removed; no contact is declared during that window.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import Antenna
from sensing_antenna.detection.filters import (
    FirstOrderLowPass,
    FreeMotionObserverFilter,
    low_pass,
    observe_free_motion,
)
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.recording import Recording, resample_uniform

__all__ = [
    "DEFAULT_RESIDUAL_CUTOFF",
    "DEFAULT_TARE_TIME",
    "OBSERVER_TORQUE_SIGNS",
    "ContactConfigError",
    "ContactDetection",
    "ContactDetector",
    "SampleVector",
    "contact_residual",
    "detect_contact",
    "free_motion_torque",
]

#: One sample of a vector signal: a numpy array or a plain sequence of floats.
SampleVector: TypeAlias = "Sequence[float] | NDArray[np.float64]"

#: Cut-off of the first-order low-pass filter applied to the residual of Eq. 16 (rad/s).
DEFAULT_RESIDUAL_CUTOFF = 100.0

#: Length of the taring window at the start of a recording (s): 50 samples at 1 kHz average the
#: sensor noise down by a factor of 7 while costing only 50 ms at the start of a manoeuvre.
DEFAULT_TARE_TIME = 0.05

#: (sign on Y^m of Gamma_e,2, sign on Z^m of Gamma_e,1): torque by the link on the head.
OBSERVER_TORQUE_SIGNS = (1.0, -1.0)


class ContactConfigError(SensingAntennaError, ValueError):
    """An argument of the contact detector is out of range."""


def _check_threshold(threshold: float, name: str = "threshold") -> float:
    value = float(threshold)
    if not (math.isfinite(value) and value > 0):
        raise ContactConfigError(f"{name}: must be a finite number > 0, got {threshold!r}")
    return value


def tare_samples(tare_time: float, sample_period: float) -> int:
    """Number of samples in the taring window (at least 1)."""
    if not (math.isfinite(tare_time) and tare_time >= 0):
        raise ContactConfigError(f"tare_time: must be a finite number >= 0 s, got {tare_time!r}")
    return max(1, round(tare_time / sample_period))


def free_motion_torque(
    theta: ArrayLike, antenna: Antenna, sample_period: float
) -> NDArray[np.float64]:
    """Observed coupling torque in free motion, Gamma_e^m + Gamma_g^m, motor frame (N m).

    Parameters
    ----------
    theta : array_like, shape (n, 2)
        Motor angles (rad), uniformly sampled.
    antenna : Antenna
        Supplies the observer (Eq. 15) and the link weight.
    sample_period : float
        T_s (s).

    Returns
    -------
    ndarray, shape (n, 3)
        Torque by the link on the head about O predicted without contact (observer from rest at
        theta[0]).
    """
    angles = np.asarray(theta, dtype=np.float64)
    # Eq. 15: Gamma_e,i = K s^2 / (s^2 + d s + omega^2) theta_i, per joint
    gamma_e = observe_free_motion(angles, antenna.observer, sample_period)
    sign_y, sign_z = OBSERVER_TORQUE_SIGNS
    torque = np.zeros((angles.shape[0], 3))
    # Section 4.2: Gamma_e^m = (0, +Gamma_e,2, -Gamma_e,1) (signs: module docstring)
    torque[:, 1] = sign_y * gamma_e[:, 1]
    torque[:, 2] = sign_z * gamma_e[:, 0]
    # Section 4.2: Gamma_g^m = (0, m_b g l cos(theta2) / 2, 0), with tip mass and sag
    torque[:, 1] += antenna.link.gravity_moment(angles[:, 1])
    return torque


def contact_residual(
    recording: Recording,
    antenna: Antenna,
    residual_cutoff: float = DEFAULT_RESIDUAL_CUTOFF,
    tare_time: float = DEFAULT_TARE_TIME,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Residual of Eq. 16 and its filtered norm for a uniformly sampled recording.

    Parameters
    ----------
    recording : Recording
        Uniformly sampled (see :func:`~sensing_antenna.recording.resample_uniform`).
    antenna : Antenna
    residual_cutoff : float
        Cut-off of the residual low-pass filter (rad/s).
    tare_time : float
        Taring window at the start (s); its mean residual is the sensor offset.

    Returns
    -------
    estimated_torque : ndarray, shape (n, 3)
        Gamma_e^m + Gamma_g^m (N m).
    residual : ndarray, shape (n, 3)
        r^m of Eq. 16 (N m), offset removed after the taring window.
    filtered_norm : ndarray, shape (n,)
        |low-pass(r^m)| (N m); zero during the taring window.
    """
    period = recording.sample_period
    estimated = free_motion_torque(recording.theta, antenna, period)
    # Eq. 16: r^m = Gamma^m - (Gamma_e^m + Gamma_g^m)
    residual = recording.torque - estimated
    n_tare = tare_samples(tare_time, period)
    norm = np.zeros(residual.shape[0])
    if residual.shape[0] > n_tare:
        # taring: the mean residual of the first n_tare samples is the sensor offset
        residual[n_tare:] -= residual[:n_tare].mean(axis=0)
        filtered = low_pass(residual[n_tare:], residual_cutoff, period)
        norm[n_tare:] = np.sqrt(np.sum(filtered**2, axis=1))
    return estimated, residual, norm


@dataclass(frozen=True, eq=False)
class ContactDetection:
    """Result of :func:`detect_contact`.

    Parameters
    ----------
    status : {"contact", "no_contact"}
    reason : str
        Why, in words (threshold crossed at t_c, or never crossed; resampling if any).
    t_c : float or None
        Contact instant (s), the time of the first sample above the threshold.
    index : int or None
        Index of that sample in ``t``.
    t : ndarray, shape (n,)
        Sample times the other arrays refer to (s); a uniform grid if ``resampled``.
    residual : ndarray, shape (n, 3)
        r^m of Eq. 16 (N m).
    filtered_residual_norm : ndarray, shape (n,)
        Norm of the low-pass filtered residual (N m).
    estimated_torque : ndarray, shape (n, 3)
        Gamma_e^m + Gamma_g^m (N m).
    threshold : float
        Threshold on the filtered residual norm (N m).
    residual_cutoff : float
        Cut-off of the residual filter (rad/s).
    resampled : bool
        True when the recording was irregularly sampled and was linearly resampled first.
    """

    status: Literal["contact", "no_contact"]
    reason: str
    t_c: float | None
    index: int | None
    t: NDArray[np.float64]
    residual: NDArray[np.float64]
    filtered_residual_norm: NDArray[np.float64]
    estimated_torque: NDArray[np.float64]
    threshold: float
    residual_cutoff: float
    resampled: bool


def detect_contact(
    recording: Recording,
    antenna: Antenna,
    threshold: float | None = None,
    residual_cutoff: float = DEFAULT_RESIDUAL_CUTOFF,
    tare_time: float = DEFAULT_TARE_TIME,
) -> ContactDetection:
    """Contact instant t_c of a recording (batch form of :class:`ContactDetector`).

    Parameters
    ----------
    recording : Recording
        Irregular sampling is handled by linear resampling at the nominal period first.
    antenna : Antenna
        Observer of Eq. 15 and link weight.
    threshold : float, optional
        Threshold on the filtered residual norm (N m); ``antenna.observer.contact_threshold``
        when None.
    residual_cutoff : float
        Cut-off of the residual low-pass filter (rad/s).
    tare_time : float
        Taring window at the start (s), see the module docstring.

    Returns
    -------
    ContactDetection
        Identical to running :class:`ContactDetector` over the samples of a regular recording.
    """
    limit = _check_threshold(antenna.observer.contact_threshold if threshold is None else threshold)
    resampled = recording.sampling.irregular
    uniform = resample_uniform(recording) if resampled else recording
    estimated, residual, norm = contact_residual(uniform, antenna, residual_cutoff, tare_time)
    above = np.flatnonzero(norm > limit)
    note = " (irregular sampling: linearly resampled first)" if resampled else ""
    index = int(above[0]) if above.size else None
    t_c = float(uniform.t[index]) if index is not None else None
    return ContactDetection(
        status="no_contact" if t_c is None else "contact",
        reason=(
            f"filtered residual stays at or below {limit:g} N m{note}"
            if t_c is None
            else f"filtered residual exceeds {limit:g} N m at t = {t_c:g} s{note}"
        ),
        t_c=t_c,
        index=index,
        t=uniform.t,
        residual=residual,
        filtered_residual_norm=norm,
        estimated_torque=estimated,
        threshold=limit,
        residual_cutoff=residual_cutoff,
        resampled=resampled,
    )


class ContactDetector:
    """Streaming contact-instant detector: one :meth:`update` per sample, plain floats inside.

    Parameters
    ----------
    antenna : Antenna
        Observer of Eq. 15 and link weight.
    sample_period : float
        T_s (s) of the samples that will be fed (uniform).
    threshold : float, optional
        Threshold on the filtered residual norm (N m); ``antenna.observer.contact_threshold``
        when None.
    residual_cutoff : float
        Cut-off of the residual low-pass filter (rad/s).
    tare_time : float
        Taring window at the start (s), see the module docstring.

    Attributes
    ----------
    detected : bool
        True from the contact sample on (latched until :meth:`reset`).
    contact_time : float or None
        t_c (s).
    contact_index : int or None
        Index of the contact sample, counted from the first update after reset.
    filtered_residual_norm : float
        Latest |low-pass(r^m)| (N m).
    n_samples : int
        Number of samples fed since reset.
    """

    def __init__(
        self,
        antenna: Antenna,
        sample_period: float,
        threshold: float | None = None,
        residual_cutoff: float = DEFAULT_RESIDUAL_CUTOFF,
        tare_time: float = DEFAULT_TARE_TIME,
    ) -> None:
        self.antenna = antenna
        self._n_tare = tare_samples(tare_time, float(sample_period))
        self.sample_period = float(sample_period)
        self.threshold = _check_threshold(
            antenna.observer.contact_threshold if threshold is None else threshold
        )
        self.residual_cutoff = float(residual_cutoff)
        self._observers = (
            FreeMotionObserverFilter(antenna.observer, sample_period),
            FreeMotionObserverFilter(antenna.observer, sample_period),
        )
        self._filters = tuple(FirstOrderLowPass(residual_cutoff, sample_period) for _ in range(3))
        self._link = antenna.link
        self._sign_y, self._sign_z = OBSERVER_TORQUE_SIGNS
        self.reset()

    def reset(self) -> None:
        """Forget everything: the next sample is the first one (observer at rest there)."""
        for observer in self._observers:
            observer.reset()
        for lowpass in self._filters:
            lowpass.reset()
        self.detected = False
        self.contact_time: float | None = None
        self.contact_index: int | None = None
        self.n_samples = 0
        self.filtered_residual_norm = 0.0
        self._residual = (0.0, 0.0, 0.0)
        self._estimated = (0.0, 0.0, 0.0)
        self._tare_sum = [0.0, 0.0, 0.0]
        self._offset = (0.0, 0.0, 0.0)

    @property
    def residual(self) -> NDArray[np.float64]:
        """Latest residual r^m of Eq. 16, shape (3,) (N m)."""
        return np.array(self._residual)

    @property
    def estimated_torque(self) -> NDArray[np.float64]:
        """Latest Gamma_e^m + Gamma_g^m, shape (3,) (N m)."""
        return np.array(self._estimated)

    def update(
        self, t: float, theta: SampleVector, force: SampleVector, torque: SampleVector
    ) -> bool:
        """Feed one sample; returns True once contact has been detected.

        Parameters
        ----------
        t : float
            Sample time (s).
        theta : array_like, shape (2,)
            Motor angles (rad).
        force : array_like, shape (3,)
            Force (N); unused by this detector, accepted for a uniform estimator interface.
        torque : array_like, shape (3,)
            Torque by the link on the head about O, motor frame (N m).
        """
        theta1, theta2 = float(theta[0]), float(theta[1])
        # Eq. 15: Gamma_e,i = K s^2 / (s^2 + d s + omega^2) theta_i, per joint
        gamma_e1 = self._observers[0].update(theta1)
        gamma_e2 = self._observers[1].update(theta2)
        # Section 4.2: Gamma_e^m + Gamma_g^m = (0, +Gamma_e,2 + m_b g l cos(theta2) / 2, -Gamma_e,1)
        # (the weight's moment with tip mass and sag: Link.gravity_moment)
        est_y = self._sign_y * gamma_e2 + float(self._link.gravity_moment(theta2))
        est_z = self._sign_z * gamma_e1
        # Eq. 16: r^m = Gamma^m - (Gamma_e^m + Gamma_g^m)
        r_x = float(torque[0])
        r_y = float(torque[1]) - est_y
        r_z = float(torque[2]) - est_z
        self._estimated = (0.0, est_y, est_z)
        if self.n_samples < self._n_tare:
            # taring: accumulate the offset, no detection yet
            self._tare_sum[0] += r_x
            self._tare_sum[1] += r_y
            self._tare_sum[2] += r_z
            self._residual = (r_x, r_y, r_z)
            self.n_samples += 1
            if self.n_samples == self._n_tare:
                n = float(self._n_tare)
                self._offset = (self._tare_sum[0] / n, self._tare_sum[1] / n, self._tare_sum[2] / n)
            return self.detected
        r_x -= self._offset[0]
        r_y -= self._offset[1]
        r_z -= self._offset[2]
        f_x = self._filters[0].update(r_x)
        f_y = self._filters[1].update(r_y)
        f_z = self._filters[2].update(r_z)
        norm = math.sqrt(f_x * f_x + f_y * f_y + f_z * f_z)
        self._residual = (r_x, r_y, r_z)
        self.filtered_residual_norm = norm
        if not self.detected and norm > self.threshold:
            self.detected = True
            self.contact_time = float(t)
            self.contact_index = self.n_samples
        self.n_samples += 1
        return self.detected
