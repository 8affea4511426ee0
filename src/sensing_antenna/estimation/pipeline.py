"""The contact-point pipeline of Section 4, offline (:func:`estimate`) and online
(:class:`OnlineEstimator`), with one front end and interchangeable methods.

Front end (shared by every method, causal, so both forms reach the same indices):

1. t_c: the contact detector of Section 4.2 (:mod:`.contact`).
2. t_1: the head comes to rest after t_c (:func:`.contact_frame.first_rest_index`); the contact
   frame from the samples just after t_1 (Section 5.3); the push must have a measurable force.
3. Estimator 2's ratio x_c(t) and its convergence (Delta t_e2, :mod:`.ratio`).
4. t_e = t_1 + max(Delta t_e1, Delta t_e2) (Section 4, step 6).

At t_e the samples up to t_e are handed, as :class:`~.fusion.Evidence`, to the method, which
returns a :class:`~.result.ContactEstimate`. A method that can stop earlier (``fast``) also has
``due(samples_since_t1, sample_period)`` (cheap, is this an evaluation instant?) and
``ready(evidence)``; the online form asks it on its cadence and concludes at the first ready
sample, the offline form lets the method find that same sample in the longer evidence. Methods
are looked up by name in :data:`METHODS`; a new method is an object with a ``name`` and
``conclude(evidence)``, added to ``_BUILTIN_METHODS``; the command line lists whatever
:data:`METHODS` holds.

The online form keeps only cheap per-sample state (detector, Eq. 20 filters, two sliding-window
tests) and, at t_e, calls the very function the offline form calls on the same samples.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from types import MappingProxyType
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import STANDARD_GRAVITY, Antenna, Link
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.estimation.baselines import RatioMethod, TwoFrequencyMethod
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.contact import ContactDetector, detect_contact
from sensing_antenna.estimation.contact_frame import (
    ContactFrame,
    contact_frame,
    first_rest_index,
    rest_tolerance,
    signal_noise,
)
from sensing_antenna.estimation.fast import FastMethod
from sensing_antenna.estimation.filters import FirstOrderLowPass
from sensing_antenna.estimation.frequency import FrequencyMeasurement, measure_frequency
from sensing_antenna.estimation.fusion import Evidence, PaperMethod, sensing_curve
from sensing_antenna.estimation.ratio import (
    converged_index,
    filtered_contact_loads,
    load_offset,
    perpendicular_ratio,
    perpendicular_ratio_sample,
    ratio_noise,
    window_mean,
)
from sensing_antenna.estimation.result import ContactEstimate, Status
from sensing_antenna.recording import Recording, resample_uniform

__all__ = [
    "METHODS",
    "EstimationMethod",
    "OnlineEstimator",
    "UnknownMethodError",
    "estimate",
    "measure_omega1",
    "search_band",
]

FloatArray = NDArray[np.float64]


class EstimationMethod(Protocol):
    """A way to turn the evidence at t_e into an estimate."""

    @property
    def name(self) -> str:
        """Name used by ``--method``."""
        ...

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        """The estimate from the evidence at t_e."""
        ...


_BUILTIN_METHODS: tuple[EstimationMethod, ...] = (
    PaperMethod(),
    RatioMethod(),
    TwoFrequencyMethod(),
    FastMethod(),
)

#: Available methods by name (read-only).
METHODS: Mapping[str, EstimationMethod] = MappingProxyType({m.name: m for m in _BUILTIN_METHODS})


class UnknownMethodError(SensingAntennaError, ValueError):
    """The requested estimation method does not exist."""


def _resolve(method: str | EstimationMethod) -> EstimationMethod:
    if not isinstance(method, str):
        return method
    try:
        return METHODS[method]
    except KeyError:
        raise UnknownMethodError(
            f"method: unknown {method!r}; known: {', '.join(sorted(METHODS))}"
        ) from None


def search_band(link: Link, config: EstimatorConfig) -> tuple[float, float]:
    """omega_1 band allowed by the sensing curve over the contact range, with the margin (rad/s).

    Section 4.3: the fundamental is searched only where the sensing curve can put it; the margin
    ``config.band_margin`` allows for calibration error of T.
    """
    low, high = sensing_curve(link).omega1_range(
        config.contact_range[0] * link.length, config.contact_range[1] * link.length
    )
    return float(low) / (1.0 + config.band_margin), float(high) * (1.0 + config.band_margin)


def _samples(n: float, sample_period: float) -> int:
    return max(1, round(n / sample_period))


def _bad_input(
    force: FloatArray,
    torque: FloatArray,
    sample_period: float,
    band_top: float,
    cfg: EstimatorConfig,
) -> str | None:
    nyquist = math.pi / sample_period
    if nyquist < cfg.min_nyquist_factor * band_top:
        return (
            f"sample period {sample_period:g} s: the Nyquist frequency {nyquist:.0f} rad/s is "
            f"below {cfg.min_nyquist_factor:g} times the top of the omega_1 band "
            f"({band_top:.0f} rad/s)"
        )
    for name, values in (("force", force), ("torque", torque)):
        if values.shape[0] > 1 and np.all(np.ptp(values, axis=0) == 0.0):
            return f"{name}: every component is constant over the recording (sensor not working)"
    return None


def _early(
    status: Status,
    reason: str,
    method: str,
    diagnostics: Mapping[str, Any],
    t_c: float = math.nan,
    t_1: float = math.nan,
) -> ContactEstimate:
    return ContactEstimate(
        status=status,
        reason=reason,
        method=method,
        t_c=t_c,
        t_1=t_1,
        diagnostics=dict(diagnostics),
    )


def _frame_at(
    theta: FloatArray,
    reaction_f: FloatArray,
    rest_index: int,
    antenna: Antenna,
    cfg: EstimatorConfig,
    sample_period: float,
) -> tuple[ContactFrame | None, str | None]:
    stop = rest_index + _samples(cfg.frame_window, sample_period) + 1
    frame = contact_frame(theta[rest_index:stop], reaction_f[rest_index:stop], antenna.link.length)
    if frame is None:
        return None, "the contact force at t_1 is zero or along the link: no lateral push"
    perpendicular = math.hypot(frame.reaction_m[1], frame.reaction_m[2])
    if perpendicular < cfg.min_push_force:
        return None, (
            f"the contact force at t_1 is {1000 * perpendicular:.1f} mN, below the "
            f"{1000 * cfg.min_push_force:g} mN of a push (gravity removed)"
        )
    return frame, None


def _ratio_noise(
    force: FloatArray, frame: ContactFrame, antenna: Antenna, cfg: EstimatorConfig, ts: float
) -> tuple[float, float]:
    """Ratio noise (m) and the convergence tolerance it implies (m), from samples up to the
    instant t_1 is known (t_1 + rest_window), so both forms compute them on the same samples."""
    noise = ratio_noise(
        signal_noise(force)[0],
        math.hypot(frame.reaction_m[1], frame.reaction_m[2]),
        antenna.link.length,
        cfg.lowpass_cutoff,
        ts,
    )
    # The moving average's spread over a window stays within three noise deviations.
    return noise, max(cfg.convergence_tolerance, 3.0 * noise)


@dataclasses.dataclass(frozen=True)
class _ContactStart:
    """What is fixed at the contact sample: rest tolerance and sensor offset."""

    rest_tolerance: float
    offset: FloatArray
    tare: str


def _at_contact(
    theta: FloatArray,
    force: FloatArray,
    torque: FloatArray,
    antenna: Antenna,
    contact_index: int,
    cfg: EstimatorConfig,
    ts: float,
) -> _ContactStart:
    """Rest tolerance and sensor offset from the samples up to t_c (both forms call this)."""
    before = slice(0, contact_index + 1)
    tolerance = rest_tolerance(theta[before], cfg)
    w_rest = _samples(cfg.rest_window, ts)
    moved = np.flatnonzero(np.any(np.abs(theta[before] - theta[0]) > tolerance, axis=1))
    quiet = int(moved[0]) if moved.size else contact_index + 1
    if quiet >= w_rest + 1:
        # The head rests at the start: the link hangs still, the mean load is the offset.
        window, tare = slice(0, quiet), "rest"
    else:
        end = contact_index - _samples(cfg.tare_margin, ts)
        window, tare = slice(0, max(end, 0)), "approach"
        if end < w_rest + 1:
            return _ContactStart(tolerance, np.zeros(6), "none")
    offset = load_offset(theta[window], force[window], torque[window], antenna)
    return _ContactStart(tolerance, offset, tare)


def _evidence(
    t: FloatArray,
    theta: FloatArray,
    force: FloatArray,
    torque: FloatArray,
    sample_period: float,
    antenna: Antenna,
    cfg: EstimatorConfig,
    band: tuple[float, float],
    contact_index: int,
    rest_index: int,
    converged: int | None,
    end_index: int,
    complete: bool,
    diagnostics: dict[str, Any],
) -> Evidence | str:
    """Evidence from the samples [0, end_index]: the one function both forms call at t_e."""
    stop = end_index + 1
    t, theta, force, torque = t[:stop], theta[:stop], force[:stop], torque[:stop]
    start = _at_contact(theta, force, torque, antenna, contact_index, cfg, sample_period)
    reaction_f, torque_f = filtered_contact_loads(
        theta, force, torque, antenna, cfg.lowpass_cutoff, sample_period, start.offset
    )
    frame, problem = _frame_at(theta, reaction_f, rest_index, antenna, cfg, sample_period)
    if frame is None:
        return problem or "no contact frame"
    ratio = perpendicular_ratio(reaction_f, torque_f, antenna.link.flexural_rigidity)
    known = rest_index + _samples(cfg.rest_window, sample_period) + 1
    noise, _ = _ratio_noise(force[:known], frame, antenna, cfg, sample_period)
    return Evidence(
        t=t,
        theta=theta,
        force=force,
        torque=torque,
        sample_period=sample_period,
        antenna=antenna,
        config=cfg,
        contact_index=contact_index,
        rest_index=rest_index,
        end_index=end_index,
        converged_index=converged,
        complete=complete,
        frame=frame,
        reaction_f=reaction_f,
        torque_f=torque_f,
        ratio=ratio,
        ratio_mean=window_mean(ratio, rest_index, _samples(cfg.convergence_window, sample_period)),
        load_offset=start.offset,
        ratio_noise=noise,
        band=band,
        diagnostics=diagnostics,
    )


def _planned_end(
    rest_index: int, converged: int | None, cfg: EstimatorConfig, sample_period: float
) -> int:
    # Section 4, step 6: t_e = t_1 + max(Delta t_e1, Delta t_e2)
    spectrum_end = rest_index + _samples(cfg.spectrum_window, sample_period)
    ratio_end = (
        converged
        if converged is not None
        else rest_index + _samples(cfg.max_ratio_wait, sample_period)
    )
    return max(spectrum_end, ratio_end)


def estimate(
    recording: Recording,
    antenna: Antenna,
    method: str | EstimationMethod = "paper",
    config: EstimatorConfig | None = None,
) -> ContactEstimate:
    """Estimate the contact point of one recording (offline form).

    Parameters
    ----------
    recording : Recording
        Any recording in the format of the specification; irregular sampling is resampled
        linearly onto the nominal grid first (reported in the diagnostics). Ground-truth metadata
        is never read.
    antenna : Antenna
        Link, observer and (calibrated) T of the sensing curve.
    method : str or EstimationMethod
        A key of :data:`METHODS` (``"paper"``, ``"ratio"``, ``"two-frequency"``, ``"fast"``).
    config : EstimatorConfig, optional
        Defaults to ``EstimatorConfig()``.

    Returns
    -------
    ContactEstimate
        With an explicit status; doubtful data never raise.

    Raises
    ------
    UnknownMethodError
        For an unknown method name.
    """
    impl = _resolve(method)
    cfg = config if config is not None else EstimatorConfig()
    sampling = recording.sampling
    diagnostics: dict[str, Any] = {
        "sampling": dataclasses.asdict(sampling),
        "resampled": sampling.irregular,
    }
    uniform = resample_uniform(recording) if sampling.irregular else recording
    sample_period = uniform.sample_period
    band = search_band(antenna.link, cfg)
    t, theta, force, torque = uniform.t, uniform.theta, uniform.force, uniform.torque
    problem = _bad_input(force, torque, sample_period, band[1], cfg)
    if problem is not None:
        return _early(Status.BAD_INPUT, problem, impl.name, diagnostics)
    detection = detect_contact(uniform, antenna)
    if detection.index is None:
        return _early(Status.NO_CONTACT, detection.reason, impl.name, diagnostics)
    i_c = detection.index
    t_c = float(t[i_c])
    start = _at_contact(theta, force, torque, antenna, i_c, cfg, sample_period)
    tolerance = start.rest_tolerance
    diagnostics.update(
        {"rest_tolerance": tolerance, "tare": start.tare, "load_offset": start.offset}
    )
    w_rest = _samples(cfg.rest_window, sample_period)
    i_1 = first_rest_index(theta, i_c, w_rest, tolerance)
    if i_1 is None:
        return _early(
            Status.PUSH_NOT_REACHED,
            f"the head never came to rest after t_c (angles within {tolerance:.2g} rad for "
            f"{cfg.rest_window:g} s)",
            impl.name,
            diagnostics,
            t_c=t_c,
        )
    reaction_f, torque_f = filtered_contact_loads(
        theta, force, torque, antenna, cfg.lowpass_cutoff, sample_period, start.offset
    )
    frame, problem = _frame_at(theta, reaction_f, i_1, antenna, cfg, sample_period)
    if frame is None:
        return _early(
            Status.PUSH_NOT_REACHED, problem or "", impl.name, diagnostics, t_c, float(t[i_1])
        )
    ratio = perpendicular_ratio(reaction_f, torque_f, antenna.link.flexural_rigidity)
    w_conv = _samples(cfg.convergence_window, sample_period)
    ratio_mean = window_mean(ratio, i_1, w_conv)
    last_check = i_1 + _samples(cfg.max_ratio_wait, sample_period)
    _, tolerance_ratio = _ratio_noise(force[: i_1 + w_rest + 1], frame, antenna, cfg, sample_period)
    converged = converged_index(ratio_mean[: last_check + 1], i_1 + w_conv, w_conv, tolerance_ratio)
    planned = _planned_end(i_1, converged, cfg, sample_period)
    n = t.shape[0]
    end = min(planned, n - 1)
    if converged is not None and converged > end:
        converged = None
    evidence = _evidence(
        t,
        theta,
        force,
        torque,
        sample_period,
        antenna,
        cfg,
        band,
        i_c,
        i_1,
        converged,
        end,
        planned <= n - 1,
        diagnostics,
    )
    if isinstance(evidence, str):
        return _early(Status.PUSH_NOT_REACHED, evidence, impl.name, diagnostics, t_c, float(t[i_1]))
    return impl.conclude(evidence)


class OnlineEstimator:
    """Streaming form of :func:`estimate`, one :meth:`update` per sample of a 1 kHz loop.

    Parameters
    ----------
    antenna : Antenna
    sample_period : float
        T_s (s) of the uniform samples that will be fed.
    method : str or EstimationMethod
        As for :func:`estimate`.
    config : EstimatorConfig, optional

    Attributes
    ----------
    result : ContactEstimate or None
        The estimate once given (at t_e), else None.

    Notes
    -----
    :meth:`update` returns the estimate exactly once, at the sample t_e, and None otherwise
    (also after the estimate). :meth:`finalize` closes a run that ended before t_e (no contact,
    no push, too short) and returns the estimate :func:`estimate` gives on the same samples.
    """

    def __init__(
        self,
        antenna: Antenna,
        sample_period: float,
        method: str | EstimationMethod = "paper",
        config: EstimatorConfig | None = None,
    ) -> None:
        self.antenna = antenna
        self.sample_period = float(sample_period)
        self.method = _resolve(method)
        self.config = config if config is not None else EstimatorConfig()
        cfg = self.config
        self._band = search_band(antenna.link, cfg)
        self._w_rest = _samples(cfg.rest_window, self.sample_period)
        self._w_conv = _samples(cfg.convergence_window, self.sample_period)
        self._n_wait = _samples(cfg.max_ratio_wait, self.sample_period)
        self._weight = antenna.link.mass * STANDARD_GRAVITY
        self._half_moment = 0.5 * self._weight * antenna.link.length
        self._rigidity = antenna.link.flexural_rigidity
        self._detector = ContactDetector(antenna, self.sample_period)
        self._filters = [
            FirstOrderLowPass(cfg.lowpass_cutoff, self.sample_period) for _ in range(6)
        ]
        self.reset()

    def reset(self) -> None:
        """Forget every sample: ready for a new manoeuvre."""
        self._detector.reset()
        for low_pass in self._filters:
            low_pass.reset()
        capacity = 4096
        self._t = np.empty(capacity)
        self._theta = np.empty((capacity, 2))
        self._force = np.empty((capacity, 3))
        self._torque = np.empty((capacity, 3))
        self._ratio = np.empty(capacity)
        self._mean = np.empty(capacity)
        self._n = 0
        self._contact: int | None = None
        self._tolerance = math.nan
        self._rest: int | None = None
        self._converged: int | None = None
        self._ratio_tolerance = math.nan
        self._start: _ContactStart | None = None
        self._offset: tuple[float, ...] = (0.0,) * 6
        self._planned: int | None = None
        self._done = False
        self.result: ContactEstimate | None = None

    def _grow(self) -> None:
        size = 2 * self._t.shape[0]
        for name in ("_t", "_theta", "_force", "_torque", "_ratio", "_mean"):
            old = getattr(self, name)
            new = np.empty((size, *old.shape[1:]))
            new[: self._n] = old[: self._n]
            setattr(self, name, new)

    @property
    def n_samples(self) -> int:
        """Samples fed since :meth:`reset`."""
        return self._n

    def update(
        self,
        t: float,
        theta: Sequence[float] | FloatArray,
        force: Sequence[float] | FloatArray,
        torque: Sequence[float] | FloatArray,
    ) -> ContactEstimate | None:
        """Feed one sample; returns the estimate at t_e (once), else None.

        Parameters
        ----------
        t : float
            Sample time (s).
        theta : array_like, shape (2,)
            Motor angles (rad).
        force, torque : array_like, shape (3,)
            F/T sensor sample, motor frame (N, N m).
        """
        if self._done:
            return None
        j = self._n
        if j == self._t.shape[0]:
            self._grow()
        theta1, theta2 = float(theta[0]), float(theta[1])
        fx, fy, fz = float(force[0]), float(force[1]), float(force[2])
        tx, ty, tz = float(torque[0]), float(torque[1]), float(torque[2])
        self._t[j] = t
        self._theta[j, 0] = theta1
        self._theta[j, 1] = theta2
        self._force[j] = (fx, fy, fz)
        self._torque[j] = (tx, ty, tz)
        self._n = j + 1
        # Section 4.2: contact loads R = F - F_g^m, Gamma - Gamma_g^m, then Eq. 20
        sin2, cos2 = math.sin(theta2), math.cos(theta2)
        filters = self._filters
        r_x = filters[0].update(fx + self._weight * sin2)
        r_y = filters[1].update(fy)
        r_z = filters[2].update(fz + self._weight * cos2)
        filters[3].update(tx)
        g_y = filters[4].update(ty - self._half_moment * cos2)
        g_z = filters[5].update(tz)
        if self._contact is None:
            if not self._detector.update(t, (theta1, theta2), force, torque):
                return None
            index = self._detector.contact_index
            self._contact = j if index is None else index
            self._start = _at_contact(
                self._theta,
                self._force,
                self._torque,
                self.antenna,
                self._contact,
                self.config,
                self.sample_period,
            )
            self._tolerance = self._start.rest_tolerance
            self._offset = tuple(float(v) for v in self._start.offset)
        contact: int = self._contact
        if self._rest is None:
            start = j - self._w_rest
            if start < contact:
                return None
            window = self._theta[start : j + 1]
            spread = window.max(axis=0) - window.min(axis=0)
            if not (spread[0] <= self._tolerance and spread[1] <= self._tolerance):
                return None
            self._rest = start
            reaction_f, torque_f = filtered_contact_loads(
                self._theta[: j + 1],
                self._force[: j + 1],
                self._torque[: j + 1],
                self.antenna,
                self.config.lowpass_cutoff,
                self.sample_period,
                None if self._start is None else self._start.offset,
            )
            frame, problem = _frame_at(
                self._theta[: j + 1],
                reaction_f,
                start,
                self.antenna,
                self.config,
                self.sample_period,
            )
            if frame is None:
                return self._emit(
                    _early(
                        Status.PUSH_NOT_REACHED,
                        problem or "",
                        self.method.name,
                        self._diagnostics(),
                        float(self._t[self._contact]),
                        float(self._t[start]),
                    )
                )
            self._ratio[start : j + 1] = perpendicular_ratio(
                reaction_f[start : j + 1], torque_f[start : j + 1], self._rigidity
            )
            _, self._ratio_tolerance = _ratio_noise(
                self._force[: j + 1], frame, self.antenna, self.config, self.sample_period
            )
        else:
            offset = self._offset
            self._ratio[j] = perpendicular_ratio_sample(
                r_x - offset[0],
                r_y - offset[1],
                r_z - offset[2],
                g_y - offset[4],
                g_z - offset[5],
                self._rigidity,
            )
        rest = self._rest
        w = self._w_conv
        if self._converged is None and self._planned is None and j >= rest + w:
            # Moving average of the ratio over the last window, then its spread (ratio.py)
            self._mean[j] = self._ratio[j - w : j + 1].mean()
            if j >= rest + 2 * w:
                means = self._mean[j - w : j + 1]
                if means.max() - means.min() <= self._ratio_tolerance:
                    self._converged = j
                    self._planned = _planned_end(rest, j, self.config, self.sample_period)
            if self._planned is None and j >= rest + self._n_wait:
                self._planned = _planned_end(rest, None, self.config, self.sample_period)
        if self._planned is not None and j >= self._planned:
            return self._emit(self._conclude(complete=True))
        # A method that can stop early (``fast``) is asked on its own cadence, causally
        due = getattr(self.method, "due", None)
        if due is not None and due(j - rest, self.sample_period):
            evidence = self._evidence_now(complete=True)
            ready = getattr(self.method, "ready", None)
            if not isinstance(evidence, str) and ready is not None and ready(evidence):
                return self._emit(self.method.conclude(evidence))
        return None

    def _diagnostics(self) -> dict[str, Any]:
        diag: dict[str, Any] = {"resampled": False}
        if self._start is not None:
            diag.update(
                {
                    "rest_tolerance": self._tolerance,
                    "tare": self._start.tare,
                    "load_offset": self._start.offset,
                }
            )
        return diag

    def _emit(self, result: ContactEstimate) -> ContactEstimate:
        self.result = result
        self._done = True
        return result

    def _evidence_now(self, complete: bool) -> Evidence | str:
        assert self._contact is not None and self._rest is not None
        return _evidence(
            self._t,
            self._theta,
            self._force,
            self._torque,
            self.sample_period,
            self.antenna,
            self.config,
            self._band,
            self._contact,
            self._rest,
            self._converged,
            self._n - 1,
            complete,
            self._diagnostics(),
        )

    def _conclude(self, complete: bool) -> ContactEstimate:
        assert self._contact is not None and self._rest is not None
        evidence = self._evidence_now(complete)
        if isinstance(evidence, str):
            return _early(
                Status.PUSH_NOT_REACHED,
                evidence,
                self.method.name,
                self._diagnostics(),
                float(self._t[self._contact]),
                float(self._t[self._rest]),
            )
        return self.method.conclude(evidence)

    def finalize(self) -> ContactEstimate:
        """Close the run at the end of the samples; returns the estimate (given or final)."""
        if self.result is not None:
            return self.result
        name = self.method.name
        n = self._n
        if n == 0:
            return self._emit(_early(Status.BAD_INPUT, "no samples", name, {}))
        problem = _bad_input(
            self._force[:n], self._torque[:n], self.sample_period, self._band[1], self.config
        )
        if problem is not None:
            return self._emit(_early(Status.BAD_INPUT, problem, name, self._diagnostics()))
        if self._contact is None:
            limit = self._detector.threshold
            return self._emit(
                _early(
                    Status.NO_CONTACT,
                    f"filtered residual stays at or below {limit:g} N m",
                    name,
                    self._diagnostics(),
                )
            )
        t_c = float(self._t[self._contact])
        if self._rest is None:
            cfg = self.config
            return self._emit(
                _early(
                    Status.PUSH_NOT_REACHED,
                    f"the head never came to rest after t_c (angles within "
                    f"{self._tolerance:.2g} rad for {cfg.rest_window:g} s)",
                    name,
                    self._diagnostics(),
                    t_c=t_c,
                )
            )
        return self._emit(self._conclude(complete=False))


def measure_omega1(
    recording: Recording,
    antenna: Antenna,
    band: tuple[float, float] | None = None,
    config: EstimatorConfig | None = None,
) -> FrequencyMeasurement:
    """Estimator 1's frequency measurement alone, e.g. for calibrating T_e (Section 5.1).

    Parameters
    ----------
    recording : Recording
    antenna : Antenna
        Observer and link weight for t_c, t_1 and the frame; its sensing curve gives the default
        band.
    band : tuple of float, optional
        Search band (rad/s); calibration passes a wide band so the fit is not biased by the
        current T.
    config : EstimatorConfig, optional

    Returns
    -------
    FrequencyMeasurement
        omega_1 (rad/s), peak quality, analysed window; ``reason`` set and omega_1 NaN when the
        recording has no contact, no push or too few samples after t_1.
    """
    cfg = config if config is not None else EstimatorConfig()
    search = band if band is not None else search_band(antenna.link, cfg)
    result = estimate(recording, antenna, _FrequencyOnly(search), cfg)
    measurement = result.diagnostics.get("frequency_measurement")
    if isinstance(measurement, FrequencyMeasurement):
        if result.status is Status.RECORDING_TOO_SHORT:
            return dataclasses.replace(measurement, reason=result.reason)
        return measurement
    return FrequencyMeasurement(
        omega1=math.nan,
        quality=math.nan,
        component="none",
        t_start=math.nan,
        t_end=math.nan,
        band=search,
        clear=False,
        reason=result.reason,
    )


@dataclasses.dataclass(frozen=True)
class _FrequencyOnly:
    """Internal method for :func:`measure_omega1`: the spectrum over a given band."""

    band: tuple[float, float]
    name: str = "frequency"

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        window = evidence.spectrum_slice
        measurement = measure_frequency(
            evidence.torque[window],
            evidence.frame.axes_m,
            evidence.sample_period,
            self.band,
            evidence.config.min_peak_quality,
            evidence.config.zero_padding,
            t_start=float(evidence.t[window.start]),
        )
        complete = evidence.complete
        return ContactEstimate(
            status=Status.OK if complete else Status.RECORDING_TOO_SHORT,
            reason=None if complete else "fewer samples after t_1 than the spectrum window",
            method=self.name,
            omega1=measurement.omega1,
            peak_quality=measurement.quality,
            diagnostics={"frequency_measurement": measurement},
        )
