"""The contact-point pipeline of Section 4, offline: :func:`estimate` and :func:`measure_omega1`.

One front end (:mod:`.evidence`) and interchangeable methods (:mod:`.methods`); the streaming
form is :class:`~.online.OnlineEstimator`. Steps, all causal so both forms reach the same indices:

1. t_c: the contact detector of Section 4.2 (:mod:`.contact`).
2. t_1: the head comes to rest after t_c (:func:`.contact_frame.first_rest_index`); the static
   push over the hold after t_1 must be measurable; the contact frame from its mean (Section 5.3).
3. Estimator 2's ratio x_c(t) and its convergence (Delta t_e2, :mod:`.ratio`).
4. t_e = t_1 + max(Delta t_e1, Delta t_e2) (Section 4, step 6).

At t_e the samples up to t_e are handed, as :class:`~.evidence.Evidence`, to the method, which
returns a :class:`~.result.ContactEstimate`. A method that can stop earlier (``fast``) finds its
own, earlier sample in the longer evidence, the one the online form stops at.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from sensing_antenna.antenna import Antenna
from sensing_antenna.detection.contact import detect_contact
from sensing_antenna.detection.push import detect_push
from sensing_antenna.estimation.config import EstimatorConfig, no_t1_reason
from sensing_antenna.estimation.front.contact_frame import first_rest_index
from sensing_antenna.estimation.front.evidence import (
    Evidence,
    at_contact,
    bad_input,
    build_evidence,
    hold_push,
    planned_end,
    ratio_tolerance,
    samples,
    search_band,
    time_gaps,
)
from sensing_antenna.estimation.front.ratio import (
    converged_index,
    filtered_contact_loads,
    perpendicular_ratio,
    window_mean,
)
from sensing_antenna.estimation.methods import (
    METHODS,
    EstimationMethod,
    UnknownMethodError,
    resolve_method,
)
from sensing_antenna.estimation.methods.paper.frequency import (
    FrequencyMeasurement,
    evidence_frequency,
)
from sensing_antenna.estimation.online import OnlineEstimator, early_result
from sensing_antenna.estimation.result import ContactEstimate, Status
from sensing_antenna.recording import Recording, resample_uniform

__all__ = [
    "METHODS",
    "EstimationMethod",
    "OnlineEstimator",
    "UnknownMethodError",
    "estimate",
    "gather",
    "gather_evidence",
    "measure_omega1",
    "search_band",
]


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
    impl = resolve_method(method)
    cfg = config if config is not None else EstimatorConfig()
    sampling = recording.sampling
    diagnostics: dict[str, Any] = {
        "sampling": dataclasses.asdict(sampling),
        "resampled": sampling.irregular,
    }
    gaps = time_gaps(recording.t, recording.sample_period, cfg.max_gap)
    uniform = resample_uniform(recording) if sampling.irregular else recording
    sample_period = uniform.sample_period
    band = search_band(antenna.link, cfg)
    t, theta, force, torque = uniform.t, uniform.theta, uniform.force, uniform.torque
    problem = bad_input(force, torque, sample_period, band[1], cfg)
    if problem is not None:
        return early_result(Status.BAD_INPUT, problem, impl.name, diagnostics)
    detection = detect_contact(uniform, antenna)
    if detection.index is None:
        return early_result(Status.NO_CONTACT, detection.reason, impl.name, diagnostics)
    i_c = detection.index
    t_c = float(t[i_c])
    start = at_contact(theta, force, torque, antenna, i_c, cfg, sample_period)
    tolerance = start.rest_tolerance
    diagnostics.update(
        {"rest_tolerance": tolerance, "tare": start.tare, "load_offset": start.offset}
    )
    if cfg.t1_source == "push":
        # Section 4 step 4: t_1 is the push criterion's decision (same detector as t_c)
        i_1 = detect_push(uniform, antenna, cfg.push_criterion).index
    else:
        i_1 = first_rest_index(theta, i_c, samples(cfg.rest_window, sample_period), tolerance)
    if i_1 is None:
        return early_result(
            Status.PUSH_NOT_REACHED,
            no_t1_reason(cfg, tolerance),
            impl.name,
            diagnostics,
            t_c=t_c,
        )
    hold = hold_push(theta, force, torque, antenna, start.offset, i_1, cfg, sample_period)
    if hold.frame is None:
        return early_result(
            Status.PUSH_NOT_REACHED, hold.problem or "", impl.name, diagnostics, t_c, float(t[i_1])
        )
    reaction_f, torque_f = filtered_contact_loads(
        theta, force, torque, antenna, cfg.lowpass_cutoff, sample_period, start.offset
    )
    ratio = perpendicular_ratio(reaction_f, torque_f, antenna.link.flexural_rigidity)
    w_conv = samples(cfg.convergence_window, sample_period)
    ratio_mean = window_mean(ratio, i_1, w_conv)
    last_check = i_1 + samples(cfg.max_ratio_wait, sample_period)
    _, tolerance_ratio = ratio_tolerance(hold, antenna, cfg, sample_period)
    converged = converged_index(ratio_mean[: last_check + 1], i_1 + w_conv, w_conv, tolerance_ratio)
    planned = planned_end(i_1, converged, cfg, sample_period)
    n = t.shape[0]
    end = min(planned, n - 1)
    if converged is not None and converged > end:
        converged = None
    evidence = build_evidence(
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
        gaps,
        diagnostics,
    )
    if isinstance(evidence, str):
        return early_result(
            Status.PUSH_NOT_REACHED, evidence, impl.name, diagnostics, t_c, float(t[i_1])
        )
    return impl.conclude(evidence)


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
        if result.status in (Status.RECORDING_TOO_SHORT, Status.BAD_INPUT):
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


def gather_evidence(
    recording: Recording, antenna: Antenna, config: EstimatorConfig | None = None
) -> Evidence | ContactEstimate:
    """What the pipeline hands a method at t_e, for studying a method on a recording.

    Returns the :class:`Evidence` (e.g. for :meth:`~.fast.FastMethod.history`), or the early
    result (no contact, no push, bad input) when the pipeline stops before building it.
    """
    result = estimate(recording, antenna, _EvidenceOnly(), config)
    evidence = result.diagnostics.get("evidence")
    return evidence if isinstance(evidence, Evidence) else result


#: The front end alone: the evidence at t_e, or the early result.
gather = gather_evidence


@dataclasses.dataclass(frozen=True)
class _EvidenceOnly:
    """Internal method for :func:`gather_evidence`: keeps the evidence, estimates nothing."""

    name: str = "evidence"

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        return ContactEstimate(
            status=Status.OK, reason=None, method=self.name, diagnostics={"evidence": evidence}
        )


@dataclasses.dataclass(frozen=True)
class _FrequencyOnly:
    """Internal method for :func:`measure_omega1`: the spectrum over a given band."""

    band: tuple[float, float]
    name: str = "frequency"

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        measurement = evidence_frequency(evidence, self.band)
        status, reason = Status.OK, None
        if evidence.gap is not None:
            status, reason = Status.BAD_INPUT, evidence.gap
        elif not evidence.complete:
            status = Status.RECORDING_TOO_SHORT
            reason = "fewer samples after t_1 than the spectrum window"
        return ContactEstimate(
            status=status,
            reason=reason,
            method=self.name,
            omega1=measurement.omega1,
            peak_quality=measurement.quality,
            diagnostics={"frequency_measurement": measurement},
        )
