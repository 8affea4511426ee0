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
predicts) is taken as the offset and removed; no contact is declared during that window. The
residual filter then starts at rest, at that mean: started at its first input instead, it would
hold that one sample's unfiltered noise, about 4.6 times the filtered noise at this cut-off, and
an identified threshold would be crossed there.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, TypeAlias

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import Antenna
from sensing_antenna.compiler import njit
from sensing_antenna.detection.filters import (
    df2t_step,
    low_pass_coefficients,
    observer_coefficients,
)
from sensing_antenna.errors import SensingAntennaError, refuse_non_finite
from sensing_antenna.recording import Recording, resample_uniform

if TYPE_CHECKING:
    from sensing_antenna.estimation.front.steps import DeclaredPeriodCheck

__all__ = [
    "DEFAULT_RESIDUAL_CUTOFF",
    "DEFAULT_TARE_TIME",
    "OBSERVER_TORQUE_SIGNS",
    "ContactConfigError",
    "ContactDetection",
    "ContactDetector",
    "SampleBlock",
    "SamplePeriodError",
    "SampleVector",
    "detect_contact",
    "free_motion_torque",
]

#: One sample of a vector signal: a numpy array or a plain sequence of floats.
SampleVector: TypeAlias = "Sequence[float] | NDArray[np.float64]"

#: Samples of a vector signal, time on axis 0: shape (n, k).
SampleBlock: TypeAlias = "ArrayLike"

#: Cut-off of the first-order low-pass filter applied to the residual of Eq. 16 (rad/s).
DEFAULT_RESIDUAL_CUTOFF = 100.0

#: Length of the taring window at the start of a recording (s): 50 samples at 1 kHz average the
#: sensor noise down by a factor of 7 while costing only 50 ms at the start of a manoeuvre.
DEFAULT_TARE_TIME = 0.05

#: (sign on Y^m of Gamma_e,2, sign on Z^m of Gamma_e,1): torque by the link on the head.
OBSERVER_TORQUE_SIGNS = (1.0, -1.0)


class ContactConfigError(SensingAntennaError, ValueError):
    """An argument of the contact detector is out of range."""


class SamplePeriodError(SensingAntennaError):
    """Samples whose time stamps step by another period than the one a streaming detector was
    built for: its observer and filters would run at the wrong speed. A set-up error, not a
    glitch: not a ValueError, so a loop that leaves glitched samples out does not leave this
    one unseen."""


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


def block_rows(values: SampleBlock, count: int, width: int) -> NDArray[np.float64]:
    """``values`` as a writable C-ordered float array of shape (count, width), the one layout
    the compiled kernels are built for (a recording's read-only arrays would need another):
    the array itself when it already is one, else a copy."""
    rows = np.asarray(values, dtype=np.float64).reshape(count, width)
    flags = rows.flags
    return rows if flags.c_contiguous and flags.writeable else np.array(rows, order="C")


# Layout of the contact kernel's parameters (``par``) and state (``mem``), float64 arrays:
# par: observer b (3), a (3); residual low-pass b (2), a (2); signs; weight moments; threshold;
# taring samples. mem: observer states of both joints (2 + 2); first angles
# (2); tare sums (3); offset (3); low-pass states (3); samples fed; contact index (-1: none).
_OBS_B, _OBS_A, _LP_B, _LP_A = slice(0, 3), slice(3, 6), slice(6, 8), slice(8, 10)
_SIGN_Y, _SIGN_Z, _WEIGHT_MOMENT, _SAG_MOMENT, _THRESHOLD, _N_TARE = range(10, 16)
_N_PAR = 16
_Z1, _Z2, _LP_Z = slice(0, 2), slice(2, 4), slice(12, 15)
_ORIGIN, _TARE_SUM, _OFFSET, _COUNT, _INDEX = 4, 6, 9, 15, 16
_N_MEM = 17


@njit(cache=True)
def gravity_moment_sample(theta2: float, weight_moment: float, sag_moment: float) -> float:
    """:meth:`Link.gravity_moment` of one angle theta2 (rad), compiled (N m)."""
    return math.cos(theta2) * (weight_moment + sag_moment * math.sin(theta2))


@njit(cache=True)
def _contact_block(
    par: NDArray[np.float64],
    mem: NDArray[np.float64],
    times: NDArray[np.float64],
    theta: NDArray[np.float64],
    torque: NDArray[np.float64],
    history_t: NDArray[np.float64],
    estimated: NDArray[np.float64],
    residual: NDArray[np.float64],
    norm: NDArray[np.float64],
) -> int:
    """Feed times (n,), rows of theta (n, 2) and torque (n, 3); write rows count.. of the
    histories.

    Returns the index of the contact sample (counted since reset), -1 before contact.
    """
    n_tare = int(par[_N_TARE])
    z1, z2, lp_z = mem[_Z1], mem[_Z2], mem[_LP_Z]
    for i in range(theta.shape[0]):
        k = int(mem[_COUNT])
        history_t[k] = times[i]
        if k == 0:
            mem[_ORIGIN], mem[_ORIGIN + 1] = theta[i, 0], theta[i, 1]
        # Eq. 15: Gamma_e,i = K s^2 / (s^2 + d s + omega^2) (theta_i - theta_i[0])
        gamma_e1 = df2t_step(par[_OBS_B], par[_OBS_A], z1, theta[i, 0] - mem[_ORIGIN])
        gamma_e2 = df2t_step(par[_OBS_B], par[_OBS_A], z2, theta[i, 1] - mem[_ORIGIN + 1])
        # Section 4.2: Gamma_e^m + Gamma_g^m = (0, +Gamma_e,2 + Gamma_g, -Gamma_e,1)
        moment = gravity_moment_sample(theta[i, 1], par[_WEIGHT_MOMENT], par[_SAG_MOMENT])
        est_y = par[_SIGN_Y] * gamma_e2 + moment
        est_z = par[_SIGN_Z] * gamma_e1
        estimated[k, 0], estimated[k, 1], estimated[k, 2] = 0.0, est_y, est_z
        # Eq. 16: r^m = Gamma^m - (Gamma_e^m + Gamma_g^m)
        r = (torque[i, 0] - 0.0, torque[i, 1] - est_y, torque[i, 2] - est_z)
        mem[_COUNT] = k + 1
        if k < n_tare:
            # taring: the mean residual of the first n_tare samples is the sensor offset
            for c in range(3):
                residual[k, c] = r[c]
                mem[_TARE_SUM + c] += r[c]
                if k == n_tare - 1:
                    mem[_OFFSET + c] = mem[_TARE_SUM + c] / n_tare
            norm[k] = 0.0
            continue
        total = 0.0
        for c in range(3):
            tared = r[c] - mem[_OFFSET + c]
            residual[k, c] = tared
            filtered = df2t_step(par[_LP_B], par[_LP_A], lp_z[c : c + 1], tared)
            total += filtered * filtered
        norm[k] = math.sqrt(total)
        if mem[_INDEX] < 0.0 and norm[k] > par[_THRESHOLD]:
            mem[_INDEX] = k
    return int(mem[_INDEX])


@dataclass(frozen=True, eq=False)
class ContactDetection:
    """Result of :func:`detect_contact` (or of :meth:`ContactDetector.detection`).

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


class ContactDetector:
    """Streaming contact-instant detector: blocks of samples, or one sample at a time.

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
    check_input : bool
        Refuse a block with a value that is not finite (a ValueError, the detector's state
        unchanged: one would hold every later decision at NaN), and samples whose first
        ``recording.PERIOD_CHECK_STEPS`` time stamps do not step by ``sample_period``
        (:class:`SamplePeriodError`, from then on until :meth:`reset`; the rule of a stream's
        declared period, ``estimation.front.steps.declared_period_problem``). Off where the
        caller has put the samples on their period's grid and judged them itself (the
        estimators' front end).

    Attributes
    ----------
    detected : bool
        True from the contact sample on (latched until :meth:`reset`).
    contact_time : float or None
        t_c (s).
    contact_index : int or None
        Index of the contact sample, counted from the first sample after reset.
    n_samples : int
        Number of samples fed since reset.

    Notes
    -----
    One compiled kernel runs every sample, whether fed in blocks (:meth:`update_block`) or one by
    one (:meth:`update`, a block of one): both give the same numbers to the bit, and
    :func:`detect_contact` is this detector fed one block.
    """

    def __init__(
        self,
        antenna: Antenna,
        sample_period: float,
        threshold: float | None = None,
        residual_cutoff: float = DEFAULT_RESIDUAL_CUTOFF,
        tare_time: float = DEFAULT_TARE_TIME,
        *,
        check_input: bool = True,
    ) -> None:
        self.antenna = antenna
        self.sample_period = float(sample_period)
        self.check_input = check_input
        self.threshold = _check_threshold(
            antenna.observer.contact_threshold if threshold is None else threshold
        )
        self.residual_cutoff = float(residual_cutoff)
        obs_b, obs_a = observer_coefficients(antenna.observer, self.sample_period)
        lp_b, lp_a = low_pass_coefficients(self.residual_cutoff, self.sample_period)
        par = np.zeros(_N_PAR)
        par[_OBS_B], par[_OBS_A], par[_LP_B], par[_LP_A] = obs_b, obs_a, lp_b, lp_a
        par[_SIGN_Y], par[_SIGN_Z] = OBSERVER_TORQUE_SIGNS
        par[_WEIGHT_MOMENT] = antenna.link.weight_moment
        par[_SAG_MOMENT] = antenna.link.sag_moment
        par[_THRESHOLD] = self.threshold
        par[_N_TARE] = tare_samples(tare_time, self.sample_period)
        self._par = par
        self._time = np.zeros(1)  # the time of one sample, as a block
        self.reset()

    def reset(self) -> None:
        """Forget everything: the next sample is the first one (observer at rest there)."""
        self._mem = np.zeros(_N_MEM)
        self._mem[_INDEX] = -1.0
        self._t = np.empty(0)
        self._estimated = np.empty((0, 3))
        self._residual = np.empty((0, 3))
        self._norm = np.empty(0)
        self.n_samples = 0
        self.contact_index: int | None = None
        self.contact_time: float | None = None
        # the period judged on the first time stamps (check_input), and why it was refused
        self._period: DeclaredPeriodCheck | None = None
        if self.check_input:
            from sensing_antenna.estimation.front.steps import DeclaredPeriodCheck

            self._period = DeclaredPeriodCheck(self.sample_period)
        self._period_refused: str | None = None

    @property
    def detected(self) -> bool:
        """True from the contact sample on."""
        return self.contact_index is not None

    def _reserve(self, count: int) -> None:
        """Room in the histories for ``count`` more samples (capacity doubled as needed)."""
        need = self.n_samples + count
        size = self._t.shape[0]
        if need <= size:
            return
        size = max(need, 2 * size, 4096)
        for name in ("_t", "_estimated", "_residual", "_norm"):
            old = getattr(self, name)
            new = np.empty((size, *old.shape[1:]))
            new[: self.n_samples] = old[: self.n_samples]
            setattr(self, name, new)

    def update_block(
        self, t: ArrayLike, theta: SampleBlock, force: SampleBlock, torque: SampleBlock
    ) -> bool:
        """Feed samples; returns True once contact has been detected.

        Parameters
        ----------
        t : array_like, shape (n,)
            Sample times (s).
        theta : array_like, shape (n, 2)
            Motor angles (rad).
        force : array_like, shape (n, 3)
            Force (N); unused by this detector, accepted for a uniform interface.
        torque : array_like, shape (n, 3)
            Torque by the link on the head about O, motor frame (N m).
        """
        times = np.asarray(t, dtype=np.float64).reshape(-1)
        count = times.shape[0]
        angles, moments = block_rows(theta, count, 2), block_rows(torque, count, 3)
        if self.check_input:
            self._check(times, (("theta", angles), ("torque", moments)))
        return self._feed(times, angles, moments)

    def _check(
        self, times: NDArray[np.float64], named: Sequence[tuple[str, NDArray[np.float64]]]
    ) -> None:
        """Raise a ValueError for a value of the block that is not finite, or a
        :class:`SamplePeriodError` for time stamps whose first steps are not the detector's
        period (``check_input``), before any state moves but the stamps kept for that check."""
        if self._period_refused is not None:
            raise SamplePeriodError(self._period_refused)
        columns = (("t", times[:, None]), *named)
        if not all(math.isfinite(float(values.sum())) for _, values in columns):  # cheap
            refuse_non_finite(columns, "contact decision")
        problem = None if self._period is None else self._period.feed(times)
        if problem is None:
            return
        self._period_refused = (
            f"t: the detector was built for a sample_period of {self.sample_period!r} s, but"
            f" {problem}: build it with the samples' period"
        )
        raise SamplePeriodError(self._period_refused)

    def _feed(
        self, times: NDArray[np.float64], angles: NDArray[np.float64], moments: NDArray[np.float64]
    ) -> bool:
        """:meth:`update_block` on arrays already in the kernel's layout (:func:`block_rows`)."""
        count = times.shape[0]
        if self.n_samples + count > self._t.shape[0]:
            self._reserve(count)
        index = _contact_block(
            self._par,
            self._mem,
            times,
            angles,
            moments,
            self._t,
            self._estimated,
            self._residual,
            self._norm,
        )
        self.n_samples += count
        if index >= 0 and self.contact_index is None:
            self.contact_index = index
            self.contact_time = float(self._t[index])
        return self.contact_index is not None

    def update(
        self, t: float, theta: SampleVector, force: SampleVector, torque: SampleVector
    ) -> bool:
        """Feed one sample (a block of one: t in s, theta (2,) in rad, force (3,) unused,
        torque (3,) in N m); returns True once contact has been detected."""
        self._time[0] = t
        return self.update_block(self._time, theta, force, torque)

    @property
    def filtered_residual_norm(self) -> float:
        """Latest |low-pass(r^m)| (N m); 0 before the first sample."""
        return float(self._norm[self.n_samples - 1]) if self.n_samples else 0.0

    @property
    def residual(self) -> NDArray[np.float64]:
        """Latest residual r^m of Eq. 16, shape (3,) (N m)."""
        return self._latest(self._residual)

    @property
    def estimated_torque(self) -> NDArray[np.float64]:
        """Latest Gamma_e^m + Gamma_g^m, shape (3,) (N m)."""
        return self._latest(self._estimated)

    def _latest(self, history: NDArray[np.float64]) -> NDArray[np.float64]:
        return history[self.n_samples - 1].copy() if self.n_samples else np.zeros(3)

    def detection(self, resampled: bool = False) -> ContactDetection:
        """The detection over every sample fed since reset (arrays are views, not copies).

        ``resampled`` records that the caller resampled an irregular recording first (said in
        the reason).
        """
        n = self.n_samples
        note = " (irregular sampling: linearly resampled first)" if resampled else ""
        t_c = self.contact_time
        return ContactDetection(
            status="no_contact" if t_c is None else "contact",
            reason=(
                f"filtered residual stays at or below {self.threshold:g} N m{note}"
                if t_c is None
                else f"filtered residual exceeds {self.threshold:g} N m at t = {t_c:g} s{note}"
            ),
            t_c=t_c,
            index=self.contact_index,
            t=self._t[:n],
            residual=self._residual[:n],
            filtered_residual_norm=self._norm[:n],
            estimated_torque=self._estimated[:n],
            threshold=self.threshold,
            residual_cutoff=self.residual_cutoff,
            resampled=resampled,
        )


def free_motion_torque(
    theta: ArrayLike, antenna: Antenna, sample_period: float
) -> NDArray[np.float64]:
    """Observed coupling torque in free motion, Gamma_e^m + Gamma_g^m, motor frame (N m): the
    contact detector's estimate (Eq. 15 and the weight), without any measured torque.

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
    count = angles.shape[0]
    detector = ContactDetector(antenna, sample_period)
    still = np.zeros((count, 3))
    detector.update_block(sample_period * np.arange(count), angles, still, still)
    return detector.detection().estimated_torque.copy()


def detect_contact(
    recording: Recording,
    antenna: Antenna,
    threshold: float | None = None,
    residual_cutoff: float = DEFAULT_RESIDUAL_CUTOFF,
    tare_time: float = DEFAULT_TARE_TIME,
) -> ContactDetection:
    """Contact instant t_c of a recording: a :class:`ContactDetector` fed the whole recording.

    Parameters
    ----------
    recording : Recording
        Irregular sampling is handled by linear resampling at the nominal period first.
    antenna, threshold, residual_cutoff, tare_time
        As for :class:`ContactDetector`.

    Returns
    -------
    ContactDetection
    """
    resampled = recording.sampling.irregular
    uniform = resample_uniform(recording) if resampled else recording
    detector = ContactDetector(
        antenna, uniform.sample_period, threshold, residual_cutoff, tare_time
    )
    detector.update_block(uniform.t, uniform.theta, uniform.force, uniform.torque)
    return detector.detection(resampled)
