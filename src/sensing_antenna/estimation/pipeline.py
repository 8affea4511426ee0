"""The contact-point pipeline of Section 4, offline: :func:`gather` is the front end
(:class:`~.front.frontend.FrontEnd`) fed the whole recording as one block; :func:`estimate` is
``gather`` then the method's ``conclude`` (:func:`conclude`); :func:`measure_omega1` is
``gather`` then Estimator 1 alone.

The streaming form is :class:`~.online.OnlineEstimator`, on the same front end fed sample by
sample, so both forms give the same estimate on the same samples.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np

from sensing_antenna.antenna import Antenna
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.front.evidence import search_band
from sensing_antenna.estimation.front.frontend import FrontEnd, Gathered
from sensing_antenna.estimation.front.outcome import EarlyOutcome
from sensing_antenna.estimation.front.steps import time_gaps
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
from sensing_antenna.estimation.plausibility import review
from sensing_antenna.estimation.result import ContactEstimate
from sensing_antenna.recording import Recording, resample_uniform

__all__ = [
    "METHODS",
    "EstimationMethod",
    "UnknownMethodError",
    "conclude",
    "estimate",
    "gather",
    "measure_omega1",
    "omega1_of",
    "search_band",
]


def gather(
    recording: Recording, antenna: Antenna, config: EstimatorConfig | None = None
) -> Gathered:
    """The front end on a whole recording (batch form of :class:`FrontEnd`).

    Parameters
    ----------
    recording : Recording
        Irregular sampling is resampled linearly onto the nominal grid first (said in the
        diagnostics, and gaps too long to fill are remembered). Ground truth is never read.
    antenna : Antenna
    config : EstimatorConfig, optional

    Returns
    -------
    Evidence or EarlyOutcome
        The evidence at t_e, or why there is none; either carries the
        :class:`~.outcome.FrontTrace` of the whole recording.

    Raises
    ------
    TypeError
        When ``recording`` is not a :class:`Recording` (a file's path: read it first).
    """
    if not isinstance(recording, Recording):
        hint = (
            ": read the file first, sensing_antenna.recording.read_recording(path)"
            if isinstance(recording, (str, Path))
            else ""
        )
        raise TypeError(f"recording: a Recording is needed, got {recording!r}{hint}")
    cfg = config if config is not None else EstimatorConfig()
    sampling = recording.sampling
    uniform = resample_uniform(recording) if sampling.irregular else recording
    front = FrontEnd(
        antenna,
        uniform.sample_period,
        cfg,
        diagnostics={"sampling": dataclasses.asdict(sampling), "resampled": sampling.irregular},
    )
    filled = (
        time_gaps(recording.t, recording.sample_period, cfg.gap_limit(recording.sample_period))
        if sampling.irregular
        else ()
    )
    front.update_block(uniform.t, uniform.theta, uniform.force, uniform.torque, filled)
    return front.finish()


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
        With an explicit status (doubtful data never raise) and the front end's trace.

    Raises
    ------
    UnknownMethodError
        For an unknown method name.
    TypeError
        When ``recording`` is not a :class:`Recording` (a file's path: read it first).
    """
    impl = resolve_method(method)
    return conclude(gather(recording, antenna, config), impl)


def conclude(gathered: Gathered, method: str | EstimationMethod = "paper") -> ContactEstimate:
    """The estimate of ``method`` from what the front end gathered (:func:`gather`).

    The evidence goes to ``method.conclude``, and its estimate through the plausibility layer
    (:func:`~.plausibility.review`: the recording's units, the answer on the link, a real
    vibration, one scale for the loads and the vibration) before it may be ``ok``; an early
    outcome becomes the estimate without a contact point. Either way the front end's trace rides
    on the result. One ``gather`` serves any number of methods.

    Raises
    ------
    UnknownMethodError
        For an unknown method name.
    TypeError
        When ``recording`` is not a :class:`Recording` (a file's path: read it first).
    """
    impl = resolve_method(method)
    if isinstance(gathered, EarlyOutcome):
        return gathered.estimate(impl.name)
    with method_arithmetic():
        reviewed = review(gathered, impl.conclude(gathered))
    return dataclasses.replace(reviewed, trace=gathered.trace)


def method_arithmetic() -> np.errstate:
    """A method's arithmetic on the evidence, its conclusion or an early evaluation: samples far
    beyond any device's (loads in wrong units, a glitch of 1e300 N in the hold) overflow it and
    the review; the statuses judge the non-finite values that follow, so NumPy's warnings would
    only put lines on a user's terminal."""
    return np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore")


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
        omega_1 (rad/s), peak quality, analysed window; ``reason`` set (and omega_1 NaN without
        evidence) when the recording has no contact, no push, a gap in the window, a corrupted
        run too long to put back, or too few samples after t_1.
    """
    cfg = config if config is not None else EstimatorConfig()
    search = band if band is not None else search_band(antenna.link, cfg)
    return omega1_of(gather(recording, antenna, cfg), search)


def omega1_of(gathered: Gathered, band: tuple[float, float]) -> FrequencyMeasurement:
    """:func:`measure_omega1` on what :func:`gather` returned, searched in ``band`` (rad/s):
    for a caller that reads more of the same evidence (a calibration's omega_2)."""
    if isinstance(gathered, EarlyOutcome):
        return FrequencyMeasurement(
            omega1=math.nan,
            quality=math.nan,
            component="none",
            t_start=math.nan,
            t_end=math.nan,
            band=band,
            clear=False,
            reason=gathered.reason,
        )
    # Estimator 1 on the evidence at t_e
    measurement = evidence_frequency(gathered, band)
    broken = gathered.sample_problem(float(gathered.t[gathered.end_index]))
    if broken is not None:
        return dataclasses.replace(measurement, reason=broken)
    if not gathered.complete:
        return dataclasses.replace(
            measurement, reason="fewer samples after t_1 than the spectrum window"
        )
    return measurement
