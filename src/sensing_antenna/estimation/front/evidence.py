"""The front end shared by every method: from samples to the :class:`Evidence` known at t_e.

Steps (causal, so the batch and the streaming forms reach the same indices on the same samples):

1. t_c: the contact detector of Section 4.2 (:mod:`.contact`), called by the two forms.
2. Sensor offset (tare) and rest tolerance from the samples up to t_c (:func:`at_contact`).
3. t_1: the head comes to rest after t_c (:func:`.contact_frame.first_rest_index`).
4. The static push over the hold window [t_1, t_1 + frame_window] (:func:`hold_push`): the mean
   contact force, not the force at one instant, because near the tip the link bounces on the
   obstacle for a few tenths of a second after the stop while the static preload is small
   against the impact. The push counts when its mean is ``min_push_significance`` standard
   errors above zero; the frame of Section 5.3 is built from that mean.
5. Estimator 2's ratio and its convergence (:mod:`.ratio`); t_e (:func:`planned_end`).

At t_e :func:`build_evidence` gathers everything a method needs into :class:`Evidence`.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Antenna, Link
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.front.contact_frame import (
    ContactFrame,
    contact_frame,
    rest_tolerance,
    signal_noise,
)
from sensing_antenna.estimation.front.ratio import (
    contact_loads,
    filtered_contact_loads,
    load_offset,
    perpendicular_ratio,
    ratio_noise,
    window_mean,
)

__all__ = [
    "ContactStart",
    "Evidence",
    "HoldPush",
    "at_contact",
    "bad_input",
    "build_evidence",
    "gap_problem",
    "hold_push",
    "planned_end",
    "ratio_tolerance",
    "samples",
    "search_band",
    "sensing_curve",
    "time_gaps",
    "two_frequency_curve",
]

FloatArray = NDArray[np.float64]


def samples(duration: float, sample_period: float) -> int:
    """Number of sample intervals in ``duration`` (at least one)."""
    return max(1, round(duration / sample_period))


def sensing_curve(link: Link) -> Any:
    """The omega_1(x_c) sensing curve of a link, built once per link."""
    return _sensing_curve(link)


@functools.lru_cache(maxsize=16)
def _sensing_curve(link: Link) -> Any:
    from sensing_antenna.beam import SensingCurve

    return SensingCurve.from_link(link)


#: Spacing of the x_c grid on which the (omega_1, omega_2) curve is tabulated (m); 0.5 mm is
#: twenty times finer than the paper's typical error.
TWO_FREQUENCY_GRID_STEP = 5e-4


@functools.lru_cache(maxsize=16)
def two_frequency_curve(link: Link, x_min: float, x_max: float) -> tuple[FloatArray, FloatArray]:
    """Tabulated sensing curve (omega_1, omega_2)(x_c) of Figure 9.

    Returns
    -------
    x : array, shape (m,)
        Contact points (m).
    omegas : array, shape (m, 2)
        First two natural frequencies in contact (rad/s).
    """
    from sensing_antenna.beam import natural_frequencies

    x = np.arange(x_min, x_max + 0.5 * TWO_FREQUENCY_GRID_STEP, TWO_FREQUENCY_GRID_STEP)
    x = x[(x > 0.0) & (x <= link.length)]
    omegas = np.asarray(natural_frequencies(link, x, 2), dtype=float)
    return x, omegas


def search_band(link: Link, config: EstimatorConfig) -> tuple[float, float]:
    """omega_1 band allowed by the sensing curve over the contact range, with the margin (rad/s).

    Section 4.3: the fundamental is searched only where the sensing curve can put it; the margin
    ``config.band_margin`` allows for calibration error of T.
    """
    low, high = sensing_curve(link).omega1_range(
        config.contact_range[0] * link.length, config.contact_range[1] * link.length
    )
    return float(low) / (1.0 + config.band_margin), float(high) * (1.0 + config.band_margin)


def bad_input(
    force: FloatArray,
    torque: FloatArray,
    sample_period: float,
    band_top: float,
    cfg: EstimatorConfig,
) -> str | None:
    """Why the samples cannot be used at all (coarse sampling, dead sensor), or None."""
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


def time_gaps(t: FloatArray, sample_period: float, max_gap: int) -> tuple[tuple[float, float], ...]:
    """Intervals (s) between consecutive time stamps that miss more than ``max_gap`` samples.

    Parameters
    ----------
    t : array, shape (n,)
        Original (not resampled) time stamps (s).
    sample_period : float
        Nominal T_s (s).
    max_gap : int
        Largest number of missing samples in a row that linear interpolation may fill.
    """
    steps = np.diff(np.asarray(t, dtype=float))
    missing = np.rint(steps / sample_period) - 1.0
    where = np.flatnonzero(missing > max_gap)
    return tuple((float(t[k]), float(t[k + 1])) for k in where)


def gap_problem(
    gaps: Sequence[tuple[float, float]], t_1: float, t_e: float, sample_period: float
) -> str | None:
    """The first gap overlapping [t_1, t_e], described, or None.

    After t_1 the estimators read the vibration (tens to hundreds of rad/s) and the hold's static
    loads; a straight line across a gap of several samples replaces a part of a period and both
    the spectrum and the fitted modes see a signal that was never there.
    """
    for start, end in gaps:
        if end > t_1 and start < t_e:
            missing = round((end - start) / sample_period) - 1
            return (
                f"t: {missing} samples missing between {start:.4f} s and {end:.4f} s, inside "
                f"the estimation window [{t_1:.3f}, {t_e:.3f}] s (only a few may be interpolated)"
            )
    return None


@dataclass(frozen=True)
class ContactStart:
    """What is fixed at the contact sample: rest tolerance (rad), sensor offset (N, N m), the
    kind of tare and the number of samples it averaged."""

    rest_tolerance: float
    offset: FloatArray
    tare: str
    count: int


def at_contact(
    theta: FloatArray,
    force: FloatArray,
    torque: FloatArray,
    antenna: Antenna,
    contact_index: int,
    cfg: EstimatorConfig,
    ts: float,
) -> ContactStart:
    """Rest tolerance and sensor offset from the samples up to t_c (both forms call this)."""
    before = slice(0, contact_index + 1)
    tolerance = rest_tolerance(theta[before], cfg)
    w_rest = samples(cfg.rest_window, ts)
    moved = np.flatnonzero(np.any(np.abs(theta[before] - theta[0]) > tolerance, axis=1))
    quiet = int(moved[0]) if moved.size else contact_index + 1
    if quiet >= w_rest + 1:
        # The head rests at the start: the link hangs still, the mean load is the offset.
        window, tare = slice(0, quiet), "rest"
    else:
        end = contact_index - samples(cfg.tare_margin, ts)
        window, tare = slice(0, max(end, 0)), "approach"
        if end < w_rest + 1:
            return ContactStart(tolerance, np.zeros(6), "none", 0)
    offset = load_offset(theta[window], force[window], torque[window], antenna)
    return ContactStart(tolerance, offset, tare, window.stop)


@dataclass(frozen=True)
class HoldPush:
    """The static push over the hold window after t_1.

    Attributes
    ----------
    frame : ContactFrame or None
        Frame of Section 5.3 from the mean reaction; None when no push is measurable.
    problem : str or None
        Why there is no push (for ``push_not_reached``).
    stop : int
        Index one past the last sample of the hold window used.
    force_noise : float
        White noise of one force channel measured up to the end of the hold (N).
    standard_error : float
        Standard error of the mean perpendicular force over the hold (N).
    rebounds : dict
        Contact losses seen in the hold (count, last instant), see :func:`_contact_losses`.
    """

    frame: ContactFrame | None
    problem: str | None
    stop: int
    force_noise: float
    standard_error: float
    rebounds: dict[str, Any]


def hold_push(
    theta: FloatArray,
    force: FloatArray,
    torque: FloatArray,
    antenna: Antenna,
    offset: FloatArray,
    rest_index: int,
    cfg: EstimatorConfig,
    ts: float,
) -> HoldPush:
    """Judge the push and build the contact frame from the mean reaction over the hold window.

    The static (mean) reaction R = F - F_g^m - offset over [t_1, t_1 + frame_window] is the push:
    the vibration and the rebounds of the impact average out, the preload does not. The push
    counts when |mean R_perp| exceeds ``min_push_significance`` standard errors of that mean,
    sigma_F / sqrt(N) with sigma_F the white force noise measured in the recording (the
    magnitude of a two-component Gaussian mean exceeds k standard errors with probability
    exp(-k^2 / 2): 4e-6 for k = 5). The samples used end at
    t_1 + max(rest_window, frame_window), the instant the streaming form knows them.
    """
    n = theta.shape[0]
    stop = min(rest_index + max(samples(cfg.frame_window, ts), samples(cfg.rest_window, ts)), n - 1)
    stop += 1
    hold = slice(rest_index, min(rest_index + samples(cfg.frame_window, ts) + 1, stop))
    reaction, _ = contact_loads(theta[hold], force[hold], torque[hold], antenna)
    reaction = reaction - np.asarray(offset, dtype=float)[:3]
    noise = signal_noise(force[:stop])[0]
    count = reaction.shape[0]
    standard_error = noise / math.sqrt(count)
    losses = _contact_losses(reaction, noise, cfg, ts)
    frame = contact_frame(theta[hold], reaction, antenna.link.length)
    if frame is None:
        problem = "the mean contact force over the hold is zero or along the link: no lateral push"
        return HoldPush(None, problem, stop, noise, standard_error, losses)
    perpendicular = math.hypot(frame.reaction_m[1], frame.reaction_m[2])
    limit = cfg.min_push_significance * standard_error
    if perpendicular <= limit:
        problem = (
            f"the mean contact force over the {count * ts:.3f} s after t_1 is "
            f"{1000 * perpendicular:.2f} mN, not above {cfg.min_push_significance:g} standard "
            f"errors ({1000 * limit:.2f} mN, force noise {1000 * noise:.2f} mN) of a push "
            "(gravity and sensor offset removed)"
        )
        return HoldPush(None, problem, stop, noise, standard_error, losses)
    return HoldPush(frame, None, stop, noise, standard_error, losses)


def _contact_losses(
    reaction: FloatArray, noise: float, cfg: EstimatorConfig, ts: float
) -> dict[str, Any]:
    """Short windows of the hold where the push along its mean direction is not measurable.

    The obstacle can only push: while the link is off it, the reaction along the mean push
    direction has no static part. Means over ``loss_window`` below ``loss_significance``
    standard errors of such a mean (sigma_F / sqrt(n)) are counted as losses (rebounds); the
    count and the last one are reported, not used as a status (the link's own vibration also
    moves short means).
    """
    mean = reaction.mean(axis=0)
    norm = float(np.linalg.norm(mean))
    width = samples(cfg.loss_window, ts)
    if norm == 0.0 or reaction.shape[0] < width:
        return {"count": 0, "last": None}
    along = reaction @ (mean / norm)
    windows = np.lib.stride_tricks.sliding_window_view(along, width).mean(axis=-1)
    low = windows < cfg.loss_significance * noise / math.sqrt(width)
    starts = np.flatnonzero(low & ~np.concatenate([[False], low[:-1]]))
    last = np.flatnonzero(low)
    return {
        "count": int(starts.size),
        "last": None if not last.size else float((last[-1] + width) * ts),
    }


def ratio_tolerance(
    hold: HoldPush, antenna: Antenna, cfg: EstimatorConfig, ts: float
) -> tuple[float, float]:
    """Ratio noise (m) and the convergence tolerance it implies (m), from the hold."""
    assert hold.frame is not None
    noise = ratio_noise(
        hold.force_noise,
        math.hypot(hold.frame.reaction_m[1], hold.frame.reaction_m[2]),
        antenna.link.length,
        cfg.lowpass_cutoff,
        ts,
    )
    # The moving average's spread over a window stays within three noise deviations.
    return noise, max(cfg.convergence_tolerance, 3.0 * noise)


def planned_end(
    rest_index: int, converged: int | None, cfg: EstimatorConfig, sample_period: float
) -> int:
    """Index of t_e planned from t_1 and the ratio's convergence."""
    # Section 4, step 6: t_e = t_1 + max(Delta t_e1, Delta t_e2)
    spectrum_end = rest_index + samples(cfg.spectrum_window, sample_period)
    ratio_end = (
        converged
        if converged is not None
        else rest_index + samples(cfg.max_ratio_wait, sample_period)
    )
    return max(spectrum_end, ratio_end)


@dataclass(frozen=True)
class Evidence:
    """Everything the pipeline knows at t_e, from the samples up to t_e only.

    Built identically by the batch :func:`~sensing_antenna.estimation.pipeline.estimate` and the
    streaming :class:`~sensing_antenna.estimation.online.OnlineEstimator`; a method turns it into
    a :class:`~sensing_antenna.estimation.result.ContactEstimate`.

    Attributes
    ----------
    t : array, shape (n,)
        Sample times up to and including t_e (s).
    theta, force, torque : array, shape (n, 2), (n, 3), (n, 3)
        Samples up to t_e (rad, N, N m; motor frame).
    sample_period : float
        T_s (s).
    antenna : Antenna
    config : EstimatorConfig
    contact_index, rest_index, end_index : int
        Indices of t_c, t_1 and t_e (end_index = n - 1).
    converged_index : int or None
        Index of t_1 + Delta t_e2, None when the ratio never settled.
    complete : bool
        False when the samples ended before the planned t_e (recording too short).
    frame : ContactFrame
        Contact frame from the mean reaction over the hold after t_1.
    reaction_f, torque_f : array, shape (n, 3)
        Filtered contact loads (Eq. 20 after removing gravity), motor frame (N, N m).
    ratio : array, shape (n,)
        Estimator 2, x_c(t) (m).
    ratio_mean : array, shape (n,)
        Its causal moving average over ``convergence_window`` from t_1 on (NaN before) (m).
    load_offset : array, shape (6,)
        Sensor offset removed from the loads (N, N m), see
        :func:`~sensing_antenna.estimation.front.ratio.load_offset`.
    ratio_noise : float
        Expected standard deviation of the ratio from the force noise (m), see
        :func:`~sensing_antenna.estimation.front.ratio.ratio_noise`.
    band : tuple of float
        omega_1 search band (rad/s).
    hold_end : int
        Last index of the hold window that judged the push and built the frame; a method that
        stops early (``fast``) may not declare before it.
    offset_error, torque_offset_error : float
        Standard errors of the force (N) and torque (N m) offsets removed by the tare.
    gap : str or None
        A gap of missing samples inside [t_1, t_e] (bad input), described.
    diagnostics : dict
        Front-end diagnostics (sampling, rest tolerance, rebounds, ...).
    """

    t: FloatArray
    theta: FloatArray
    force: FloatArray
    torque: FloatArray
    sample_period: float
    antenna: Antenna
    config: EstimatorConfig
    contact_index: int
    rest_index: int
    end_index: int
    converged_index: int | None
    complete: bool
    frame: ContactFrame
    reaction_f: FloatArray
    torque_f: FloatArray
    ratio: FloatArray
    ratio_mean: FloatArray
    load_offset: FloatArray
    ratio_noise: float
    band: tuple[float, float]
    hold_end: int = 0
    offset_error: float = 0.0
    torque_offset_error: float = 0.0
    gap: str | None = None
    diagnostics: dict[str, Any] = field(default_factory=dict)

    @property
    def spectrum_slice(self) -> slice:
        """Samples of the Delta t_e1 window after t_1 (shortened if the samples end first)."""
        n_window = round(self.config.spectrum_window / self.sample_period)
        return slice(self.rest_index, min(self.rest_index + n_window, self.end_index + 1))

    def ratio_uncertainty(self, x_c: float) -> float:
        """Standard uncertainty (m) of the ratio estimate at a contact point ``x_c``.

        Three independent terms, added in quadrature:

        - the white force noise through the Eq. 20 filter (``ratio_noise``, given at x = l, here
          scaled to x_c: the ratio's error is x e_F / R_perp);
        - the residual sensor offset after the tare: errors e_F on R_perp and e_T on Gamma'
          move x = Gamma' / R_perp by x e_F / R_perp and e_T / R_perp;
        - the small-deflection model: the statics neglect terms of order (y_c / x_c) x_c
          (the moment of the axial force with the link's slope, the weight moment of the bent
          link); y_c / x_c = |R_perp| x_c^2 / (3 E I) (Eq. 13), scaled by
          ``ratio_model_factor``.
        """
        if not math.isfinite(x_c):
            return math.inf
        link = self.antenna.link
        push = math.hypot(self.frame.reaction_m[1], self.frame.reaction_m[2])
        if push <= 0.0:
            return math.inf
        offset_term = math.hypot(x_c * self.offset_error, self.torque_offset_error) / push
        # Eq. 13: y_c / x_c = |R_perp| x_c^2 / (3 E I)
        deflection_ratio = push * x_c**2 / (3.0 * link.flexural_rigidity)
        model_term = self.config.ratio_model_factor * deflection_ratio * x_c
        noise_term = self.ratio_noise * x_c / link.length
        return math.sqrt(noise_term**2 + offset_term**2 + model_term**2)


def build_evidence(
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
    gaps: Sequence[tuple[float, float]],
    diagnostics: dict[str, Any],
) -> Evidence | str:
    """Evidence from the samples [0, end_index]: the one function both forms call at t_e.

    Returns the reason of ``push_not_reached`` instead when the hold shows no push.
    """
    stop = end_index + 1
    t, theta, force, torque = t[:stop], theta[:stop], force[:stop], torque[:stop]
    start = at_contact(theta, force, torque, antenna, contact_index, cfg, sample_period)
    hold = hold_push(theta, force, torque, antenna, start.offset, rest_index, cfg, sample_period)
    if hold.frame is None:
        return hold.problem or "no contact frame"
    reaction_f, torque_f = filtered_contact_loads(
        theta, force, torque, antenna, cfg.lowpass_cutoff, sample_period, start.offset
    )
    ratio = perpendicular_ratio(reaction_f, torque_f, antenna.link.flexural_rigidity)
    noise, _ = ratio_tolerance(hold, antenna, cfg, sample_period)
    # Standard errors of the tare's means; without a tare the offset is taken as one noise
    # deviation (a sensor tared shortly before, as the simulator's two-count offset).
    torque_noise = signal_noise(torque[: hold.stop])[0]
    root = math.sqrt(start.count) if start.count else 1.0
    diag = dict(diagnostics)
    diag.update(
        {
            "rebounds": hold.rebounds,
            "hold_push_standard_error": hold.standard_error,
            "force_noise": hold.force_noise,
        }
    )
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
        frame=hold.frame,
        reaction_f=reaction_f,
        torque_f=torque_f,
        ratio=ratio,
        ratio_mean=window_mean(ratio, rest_index, samples(cfg.convergence_window, sample_period)),
        load_offset=start.offset,
        ratio_noise=noise,
        band=band,
        hold_end=hold.stop - 1,
        offset_error=hold.force_noise / root,
        torque_offset_error=torque_noise / root,
        gap=gap_problem(gaps, float(t[rest_index]), float(t[end_index]), sample_period),
        diagnostics=diag,
    )
