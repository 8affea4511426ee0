"""Fusion of the two estimators (Section 4, steps 6 and 7) and the common end of every method.

Estimator 1 gives one or two contact points compatible with the measured omega_1 (the sensing
curve omega_1(x_c) is not monotonic); Estimator 2 gives one rough value. The estimate is the
frequency candidate nearest to the ratio value; it is ready at t_e = t_1 + max(dt_e1, dt_e2).

:class:`Evidence` is what the front end of the pipeline knows at t_e; :func:`conclude` adds what
every method shares (the 3D point and the physical consistency checks that set the status);
:class:`PaperMethod` is the paper's method. Baselines live in :mod:`.baselines`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Link
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.front.evidence import (
    TWO_FREQUENCY_GRID_STEP,
    Evidence,
    sensing_curve,
)
from sensing_antenna.estimation.front.steps import samples
from sensing_antenna.estimation.methods.paper.frequency import (
    SpectralPeak,
    evidence_frequency,
    evidence_spectrum,
    find_peak,
)
from sensing_antenna.estimation.methods.paper.held_contact import HeldContact, held_contact
from sensing_antenna.estimation.methods.paper.planes import bending_planes
from sensing_antenna.estimation.methods.touch_point import placement, touched_point_filtered
from sensing_antenna.estimation.result import STATUS_PRECEDENCE, ContactEstimate, Status

__all__ = [
    "Evidence",
    "Fusion",
    "PaperMethod",
    "candidates_from_omega1",
    "conclude",
    "curve_allowance",
    "fuse",
    "harmonic_of",
    "mode_ratio_share",
    "model_spread",
    "pair_distance",
    "second_mode_against",
    "second_mode_band",
    "second_peak",
    "sensing_curve",
]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Fusion:
    """Outcome of step 7.

    Attributes
    ----------
    x_c : float
        Chosen contact point (m): the candidate nearest to the ratio estimate, or the ratio
        estimate itself when there is no candidate; NaN when neither exists.
    chosen : int or None
        Index of the chosen candidate, None when the ratio estimate was used.
    distance : float
        |chosen candidate - ratio estimate| (m); NaN when one of them is missing.
    agree : bool
        True when the distance is within the tolerance.
    """

    x_c: float
    chosen: int | None
    distance: float
    agree: bool


#: t_1 later than this share of the spectrum window after t_c is named in a record too short:
#: the head was slow to rest (a servo or a mount ringing), not the record cut early.
_LATE_REST = 0.5


def fuse(candidates: Sequence[float], ratio_estimate: float, tolerance: float) -> Fusion:
    """Step 7 of Section 4: of the candidates of Estimator 1, the one nearest to Estimator 2.

    Parameters
    ----------
    candidates : sequence of float
        Contact points from the inverse sensing curve (m).
    ratio_estimate : float
        x_c from the torque/force ratio (m); NaN when not available.
    tolerance : float
        Largest accepted distance between the two estimators (m).

    Returns
    -------
    Fusion
    """
    have_ratio = math.isfinite(ratio_estimate)
    if not candidates:
        x_c = ratio_estimate if have_ratio else math.nan
        return Fusion(x_c=x_c, chosen=None, distance=math.nan, agree=False)
    if not have_ratio:
        # Without Estimator 2 a single candidate is still usable; two are ambiguous.
        return Fusion(x_c=float(candidates[0]), chosen=0, distance=math.nan, agree=False)
    # Section 4, step 7: the candidate closest to the torque/force estimate
    distances = [abs(float(c) - ratio_estimate) for c in candidates]
    chosen = min(range(len(distances)), key=distances.__getitem__)
    return Fusion(
        x_c=float(candidates[chosen]),
        chosen=chosen,
        distance=distances[chosen],
        agree=distances[chosen] <= tolerance,
    )


def candidates_from_omega1(
    link: Link, omega1: float, x_range: tuple[float, float], tolerance: float = 0.0
) -> tuple[tuple[float, ...], dict[str, Any]]:
    """Contact points on the sensing curve with fundamental ``omega1`` (m), and notes.

    When the measured frequency lies above the curve's maximum (calibration error near the top of
    the curve, where the paper's worst errors are), there is no exact solution; the point of the
    curve with the nearest frequency inside ``x_range`` is returned instead and flagged. Within
    ``tolerance`` (rad/s) past the tip's frequency, the tip is a candidate
    (:meth:`~sensing_antenna.beam.SensingCurve.contact_points`).
    """
    curve = sensing_curve(link)
    notes: dict[str, Any] = {}
    found = tuple(float(c.x_c) for c in curve.contact_points(omega1, tolerance))
    inside = tuple(x for x in found if 0.0 < x <= link.length)
    if inside:
        slopes = [float(curve.omega1_slope(x)) for x in inside]
        notes["candidate_slopes"] = slopes
        return tuple(sorted(inside)), notes
    grid = np.linspace(x_range[0], x_range[1], 2001)
    omegas = np.asarray(curve.omega1(grid), dtype=float)
    k = int(np.argmin(np.abs(omegas - omega1)))
    notes["off_curve"] = float(omega1 / omegas[k] - 1.0)
    return (float(grid[k]),), notes


#: Step (m) of the points :func:`model_spread` walks along the link.
_SPREAD_STEP = 5e-4


def model_spread(link: Link, x_c: float, relative: float) -> float:
    """How far (m) from ``x_c`` the contact may lie for the frequency omega_1(x_c) known to a
    relative ``relative``: the largest |x - x_c| over the points next to x_c, on the link,
    whose omega_1 lies within that of omega_1(x_c) (the contiguous stretch of the sensing
    curve; across the curve's maximum when the band reaches it, where the inverse is singular),
    walked to the link's ends if need be.
    """
    curve = sensing_curve(link)
    omega = float(curve.omega1(x_c))
    steps = math.ceil(link.length / _SPREAD_STEP)
    spread = 0.0
    for sign in (-1.0, 1.0):
        # in stretches of _SPREAD_CHUNK points, up to the first outside the band or the link
        for first in range(1, steps + 1, _SPREAD_CHUNK):
            walk = _SPREAD_STEP * np.arange(first, min(first + _SPREAD_CHUNK, steps + 1))
            x = x_c + sign * walk
            on_link = (x > 0.0) & (x <= link.length)
            omegas = np.asarray(curve.omega1(np.where(on_link, x, x_c)), dtype=float)
            inside = on_link & (np.abs(omegas - omega) <= relative * omega)
            stop = int(np.argmin(inside)) if not inside.all() else inside.size
            if stop:
                spread = max(spread, abs(float(x[stop - 1]) - x_c))
            if stop < inside.size:
                break
    return spread


#: Points :func:`model_spread` evaluates at once: most spreads end within the first stretch.
_SPREAD_CHUNK = 64


def held_contact_spread(
    evidence: Evidence, omega1: float, x_c: float, diag: dict[str, Any], alone: bool = True
) -> tuple[HeldContact | None, float]:
    """A contact held along the link (:func:`.held_contact.held_contact`) for an omega_1
    (rad/s) of the push plane at the answer ``x_c`` (m), and how far (m) its rise
    may move that answer (:func:`model_spread`; 0 with nothing to read); stored in ``diag``
    under ``held_contact``. Read in the push plane ``alone``, any ringing counts; read in both
    planes with a free-plane peak that may be the push plane's leak, only a hold that
    stiffens (:attr:`.held_contact.HeldContact.stiffens`) voids that agreement, else 0."""
    held = held_contact(evidence, omega1, x_c)
    if held is None:
        return None, 0.0
    diag["held_contact"] = dataclasses.asdict(held)
    if not (alone or held.stiffens):
        return held, 0.0  # the free plane's agreement stands
    return held, model_spread(evidence.antenna.link, x_c, held.shift)


#: A ratio beyond this many link lengths (or below zero) is off the link: no contact's.
_OFF_LINK = 1.5


def conclude(
    evidence: Evidence,
    method: str,
    x_c: float,
    candidates: tuple[float, ...] = (),
    omega1: float = math.nan,
    peak_quality: float = math.nan,
    ratio_estimate: float = math.nan,
    problems: Sequence[tuple[Status, str]] = (),
    diagnostics: Mapping[str, Any] | None = None,
) -> ContactEstimate:
    """Common end of every method: 3D point, physical consistency checks, status.

    Parameters
    ----------
    evidence : Evidence
    method : str
        Method name for the result.
    x_c : float
        The method's best guess (m).
    candidates, omega1, peak_quality, ratio_estimate
        Reported as given.
    problems : sequence of (Status, str)
        Method-specific doubts (no clear peak, disagreement).
    diagnostics : mapping, optional
        Method-specific diagnostics, merged into the front end's.

    Returns
    -------
    ContactEstimate
        Status is the first problem in :data:`STATUS_PRECEDENCE`; the other reasons are kept in
        ``diagnostics["other_reasons"]``.
    """
    cfg = evidence.config
    e = evidence.end_index
    found: list[tuple[Status, str]] = list(problems)
    length = evidence.antenna.link.length
    ratio_end = float(evidence.ratio_mean[e])
    off_link = math.isfinite(ratio_end) and not 0.0 <= ratio_end <= _OFF_LINK * length
    if evidence.converged_index is None and off_link:
        # a ratio that reads off the link is not settling because it is no contact's: not a
        # record too short or a slip
        found.append(
            (
                Status.MODEL_MISMATCH,
                f"the torque/force ratio reads {_metres(ratio_end)} m, off the {length:g} m "
                f"link, and did not settle: loads in other units than N and N m, or a sensor "
                "axis turned?",
            )
        )
    elif not evidence.complete:
        have = evidence.t[e] - evidence.t[evidence.rest_index]
        t_c, t_1 = evidence.t[evidence.contact_index], evidence.t[evidence.rest_index]
        if evidence.converged_index is None:
            wait = max(cfg.max_ratio_wait, evidence.spectrum_window)
            need = (
                "the torque/force ratio had not settled yet (it is waited for up to "
                f"{wait:g} s after t_1: record to t = {t_1 + wait:.2f} s)"
            )
        else:
            need = f"the spectrum needs {evidence.spectrum_window:.3g} s"
        if t_1 - t_c > _LATE_REST * evidence.spectrum_window:
            # the record is long enough for a head that rests soon after the touch
            need += (
                f" (t_1 came {t_1 - t_c:.2f} s after the contact: the head was slow to come to "
                f"rest, its angles within {evidence.diagnostics.get('rest_tolerance', 0.0):.2g}"
                f" rad for {cfg.rest_window:g} s)"
            )
        found.append(
            (
                Status.RECORDING_TOO_SHORT,
                f"only {have:.3f} s of samples after t_1; {need}",
            )
        )
    elif evidence.converged_index is None:
        rings, how = _unsettled_ratio(evidence, e)
        found.append(
            (
                Status.UNCERTAIN if rings else Status.SLIP_SUSPECTED,
                f"the torque/force ratio did not stay within {cfg.convergence_tolerance:g} m "
                f"for {cfg.convergence_window:g} s within {cfg.max_ratio_wait:g} s after t_1"
                f"{how}",
            )
        )
    reaction_now = evidence.reaction_f[e]
    # Drift of the contact force's direction across the link between the hold (Y^c) and t_e:
    # a contact sliding over the obstacle
    drift = _direction_drift(evidence, e)
    if cfg.max_direction_drift is not None and drift > cfg.max_direction_drift:
        found.append(
            (
                Status.SLIP_SUSPECTED,
                f"the contact force turned about the link by {math.degrees(drift):.1f} deg "
                f"between t_1 and t_e (limit {math.degrees(cfg.max_direction_drift):.1f} deg)",
            )
        )
    push_force = float(math.hypot(reaction_now[1], reaction_now[2]))
    if evidence.converged_index is not None:
        settled = float(evidence.ratio_mean[evidence.converged_index])
        ratio_drift = abs(float(evidence.ratio_mean[e]) - settled)
        # Four standard deviations of the ratio's noise, at least the configured drift.
        drift_limit = max(cfg.max_ratio_drift, 4.0 * evidence.ratio_noise)
        if ratio_drift > drift_limit:
            # the ratio is moment over force: a force offset d moves it by about r d / F
            offset = push_force * ratio_drift / settled if settled > 0.0 else math.nan
            drifting = (
                f": the contact sliding along the link, or the sensor's force offset drifting "
                f"by {1e3 * offset:.2g} mN under this push of {1e3 * push_force:.2g} mN, which "
                "moves the ratio as much"
                if math.isfinite(offset)
                else ""
            )
            found.append(
                (
                    Status.SLIP_SUSPECTED,
                    f"the torque/force ratio moved by {ratio_drift:.3f} m after it had settled "
                    f"(limit {drift_limit:.3f} m){drifting}",
                )
            )
    touch, frame, t_point = touched_point_filtered(evidence, x_c, e)
    if not math.isfinite(x_c):
        found.append((Status.NO_CLEAR_PEAK, "no estimate of x_c could be formed"))
    order = {status: rank for rank, status in enumerate(STATUS_PRECEDENCE)}
    found.sort(key=lambda item: order[item[0]])
    status, reason = found[0] if found else (Status.OK, None)
    diag: dict[str, Any] = dict(evidence.diagnostics)
    diag.update(diagnostics or {})
    diag.update(
        {
            "push_force": push_force,
            "axial_fraction": evidence.frame.axial_fraction,
            "direction_drift": drift,
            **placement(touch, frame, t_point),
            "delta_t_e2": (
                float(evidence.t[evidence.converged_index] - evidence.t[evidence.rest_index])
                if evidence.converged_index is not None
                else None
            ),
            "other_reasons": [text for _, text in found[1:]],
        }
    )
    return ContactEstimate(
        status=status,
        reason=reason,
        method=method,
        x_c=x_c,
        candidates=candidates,
        omega1=omega1,
        peak_quality=peak_quality,
        ratio_estimate=ratio_estimate,
        t_c=float(evidence.t[evidence.contact_index]),
        t_1=float(evidence.t[evidence.rest_index]),
        t_e=float(evidence.t[e]),
        contact_point=touch.point_a,
        diagnostics=diag,
    )


#: The span (s), ending at t_e, over which an unsettled ratio's drift is read: two periods of a
#: fundamental down to 12.6 rad/s (a 1.5 m carbon rod's lowest over its contact range is 14.8),
#: over which a ripple barely tilts the least-squares line.
_DRIFT_SPAN = 1.0


def _unsettled_ratio(evidence: Evidence, end: int) -> tuple[bool, str]:
    """Whether a ratio that never settled rang rather than drifted over the :data:`_DRIFT_SPAN`
    to sample ``end``, and what it did: the swing of its moving average over the last
    convergence window against its drift (a least-squares line's rise over the span). A contact
    that slides drifts (``slip_suspected``); a link that rings slower than the window (a period
    longer than ``convergence_window``: a link slower than the paper's) swings about a steady
    mean, which says nothing of a slide (``uncertain``). False and "" when the record holds no
    such span after t_1."""
    cfg = evidence.config
    width = samples(cfg.convergence_window, evidence.sample_period)
    first = end + 1 - samples(_DRIFT_SPAN, evidence.sample_period)
    if first < evidence.rest_index:
        return False, ""
    mean = evidence.ratio_mean[first : end + 1]
    t = evidence.t[first : end + 1]
    if not np.all(np.isfinite(mean)):
        return False, ""  # loads the ratio cannot read (its status says so)
    swing = float(np.ptp(mean[-width:]))
    # the least-squares line's rise over the second: a ripple of a few periods barely tilts it
    drift = abs(float(np.polyfit(t - t[0], mean, 1)[0]) * float(t[-1] - t[0]))
    if drift >= 0.5 * swing:
        return False, (
            f": it drifted by {100 * drift:.1f} cm over the last {_DRIFT_SPAN:g} s, as a contact "
            "that slides makes"
        )
    return True, (
        f": it swung by {100 * swing:.1f} cm over the last {cfg.convergence_window:g} s about a "
        f"steady mean (drift {100 * drift:.1f} cm over the last {_DRIFT_SPAN:g} s), as a link "
        "that rings slower than that window leaves it (a link slower than the paper's: "
        "EstimatorConfig.convergence_window a period of its omega_1), more than a contact that "
        "slides"
    )


def predicted_omega2(evidence: Evidence, candidates: Sequence[float]) -> list[float]:
    """omega_2 (rad/s) at each candidate contact point (m), from the tabulated (omega_1,
    omega_2) curve (0.5 mm grid, far finer than the ``omega2_window`` search) instead of solving
    the beam model at t_e."""
    grid, omegas = evidence.contact_modes
    return [float(np.interp(x, grid, omegas[:, 1])) for x in candidates]


def second_mode_choice(
    evidence: Evidence, component: str, candidates: tuple[float, ...]
) -> tuple[int | None, dict[str, Any]]:
    """Which of two omega_1 candidates the second mode supports (None: no clear answer).

    Near the top of the sensing curve the two candidates are a few cm apart, closer than the
    ratio can resolve; their second natural frequencies differ by 20 % (about 208 against
    250 rad/s at the paper's top). The spectrum is searched within ``omega2_window`` of each
    candidate's omega_2; the candidate whose window holds a clear peak (and the other not, or
    a weaker one) is chosen. The notes hold the predicted omega_2, each window's peak quality
    and the peak's frequency (rad/s, NaN without a peak).
    """
    cfg = evidence.config
    omega, spectrum = evidence_spectrum(evidence, component)
    predicted = predicted_omega2(evidence, candidates)
    low = min(predicted) / (1.0 + 2.0 * cfg.omega2_window)
    high = max(predicted) * (1.0 + 2.0 * cfg.omega2_window)
    band = spectrum[(omega >= low) & (omega <= high)]
    if band.size == 0:  # the second modes lie past the spectrum (a coarse sampling)
        empty = [math.nan, math.nan]
        return None, {"predicted_omega2": predicted, "quality": [0.0, 0.0], "peak_omega": empty}
    floor = float(np.median(band))
    qualities: list[float] = []
    peaks: list[float] = []
    for omega2 in predicted:
        peak = find_peak(
            omega,
            spectrum,
            (omega2 / (1.0 + cfg.omega2_window), omega2 * (1.0 + cfg.omega2_window)),
        )
        qualities.append(peak.power / floor if peak is not None and floor > 0 else 0.0)
        peaks.append(peak.omega if peak is not None else math.nan)
    notes = {"predicted_omega2": predicted, "quality": qualities, "peak_omega": peaks}
    best = int(np.argmax(qualities))
    other = qualities[1 - best]
    if qualities[best] >= cfg.min_peak_quality and qualities[best] >= 10.0 * other:
        return best, notes
    return None, notes


def second_mode_band(evidence: Evidence, omega1: float) -> tuple[float, float]:
    """The band (rad/s) the second contact mode is sought in: the curve's omega_2 range widened
    by ``band_margin``, above 1.3 times ``omega1`` (rad/s)."""
    margin = evidence.config.band_margin
    omegas = evidence.contact_modes[1]
    low = max(float(omegas[:, 1].min()) / (1.0 + margin), 1.3 * omega1)
    return low, float(omegas[:, 1].max()) * (1.0 + margin)


def second_peak(evidence: Evidence, component: str, omega1: float) -> SpectralPeak | None:
    """The clearest peak of ``component``'s spectrum in :func:`second_mode_band`, None when it
    is not clear (``min_peak_quality`` times the band's median)."""
    omega, spectrum = evidence_spectrum(evidence, component)
    peak = find_peak(omega, spectrum, second_mode_band(evidence, omega1))
    clear = peak is not None and peak.quality >= evidence.config.min_peak_quality
    return peak if clear else None


def curve_allowance(link: Link, config: EstimatorConfig) -> float:
    """How far (relative) a pair (omega_1, omega_2) may lie from the sensing curves and still
    be a contact's modes: ``max_curve_distance``, or three times what the frequency model's own
    uncertainty allows in the two frequencies when that is larger."""
    return max(
        config.max_curve_distance,
        config.disagreement_sigmas * math.sqrt(2.0) * link.frequency_uncertainty,
    )


def pair_distance(evidence: Evidence, omega1: float, omega2: float) -> tuple[int, float]:
    """The nearest point of the (omega_1, omega_2) curve to the measured pair (rad/s) in relative
    distance: its index on the evidence's ``contact_modes`` grid and the distance. A pair
    further off than the frequency model's own uncertainty shows the model off by at least that
    much on this manoeuvre."""
    omegas = evidence.contact_modes[1]
    distance = np.hypot(omegas[:, 0] / omega1 - 1.0, omegas[:, 1] / omega2 - 1.0)
    k = int(np.argmin(distance))
    return k, float(distance[k])


def harmonic_of(omega1: float, omega2: float, config: EstimatorConfig) -> bool:
    """Whether a peak at ``omega2`` (rad/s) lies within ``omega2_window`` of 2 or 3
    ``omega1``: a harmonic of the fundamental (a clipping or bouncing contact's) may be what it
    is, not the second contact mode."""
    return any(abs(omega2 - k * omega1) < config.omega2_window * omega2 for k in (2.0, 3.0))


def mode_ratio_share(evidence: Evidence) -> float:
    """The standard uncertainty of omega_2 / omega_1 as a share of it: ``mode_ratio_uncertainty``,
    or a calibration's measured scatters of omega_1 and omega_2 in quadrature when larger."""
    link = evidence.antenna.link
    measured = math.hypot(link.calibration_scatter or 0.0, link.mode2_scatter or 0.0)
    return max(evidence.config.mode_ratio_uncertainty, measured)


def _pair_elsewhere(
    evidence: Evidence, omega1: float, omega2: float, x_c: float, nearest: int, off: float
) -> str | None:
    """Why the second contact mode puts the contact away from the answer ``x_c`` (m), or None.

    The measured pair (``omega1``, ``omega2``, rad/s; not a harmonic of omega_1 within
    ``omega2_window``) lies ``off`` from the curves' point ``nearest`` (its index on
    ``contact_modes``), within what a contact's modes may (:func:`curve_allowance`), and more
    than that from the model's pair at the answer, which lies farther than ``max_model_spread``
    from it: the second mode is another contact point's. An answer with one frequency
    candidate (omega_1 below the sensing curve's value at the tip by more than its
    uncertainty, as a link softer than its calibration makes it) meets no other evidence on
    the frequency's side but this."""
    cfg = evidence.config
    link = evidence.antenna.link
    points, omegas = evidence.contact_modes
    if not points[0] <= x_c <= points[-1]:
        return None
    if harmonic_of(omega1, omega2, cfg):
        return None
    allowance = curve_allowance(link, cfg)
    other = float(points[nearest])
    if not (off <= allowance and abs(other - x_c) > cfg.max_model_spread):
        return None
    model1 = float(np.interp(x_c, points, omegas[:, 0]))
    model2 = float(np.interp(x_c, points, omegas[:, 1]))
    at_answer = math.hypot(model1 / omega1 - 1.0, model2 / omega2 - 1.0)
    if not at_answer > allowance:
        return None
    return (
        f"the second contact mode at {omega2:.1f} rad/s is that of x_c = {other:.3f} m (with "
        f"omega_1 = {omega1:.1f} rad/s, {100 * off:.1f} % from the model's pair there), not of "
        f"the answer {x_c:.3f} m, where the model puts omega_2 at {model2:.1f} rad/s "
        f"({100 * at_answer:.1f} % off the pair, more than the {100 * allowance:.0f} % a "
        "contact's modes may lie from the curves): the device departs from the model by more "
        "than its uncertainty (a stiffness changed since the calibration, a mass at the tip), "
        "or the peak is another vibration"
    )


def _tip_alternative(evidence: Evidence, omega1: float, omega2: float, x_c: float) -> str | None:
    """Why a contact at the tip may be what rings, though ``omega1`` (rad/s) has its one point
    at ``x_c`` (m), or None.

    Where the sensing curve falls towards the tip, an omega_1 a little below its value at l
    (within ``band_margin``) has no point near the tip, yet a link softer than its calibration
    touched there rings so. omega_2 / omega_1, which the stiffness does not enter, then says
    which: more than two of its standard uncertainties (``mode_ratio_uncertainty``, or the
    calibration's measured scatters when larger) off the model's at ``x_c`` and within one of
    the tip's is the tip's (not asked within ``omega2_window`` of 2 or 3 omega_1)."""
    cfg = evidence.config
    link = evidence.antenna.link
    points, omegas = evidence.contact_modes
    if not (points[0] <= x_c <= points[-1]) or link.length - x_c <= cfg.max_model_spread:
        return None
    at_tip = float(omegas[-1, 0])
    if link.length - points[-1] > TWO_FREQUENCY_GRID_STEP:
        return None  # the contact range stops short of the tip
    if not at_tip / (1.0 + cfg.band_margin) <= omega1 < at_tip:
        return None
    if float(omegas[-2, 0]) <= at_tip:
        return None  # the curve does not fall towards the tip
    if harmonic_of(omega1, omega2, cfg):
        return None
    share = mode_ratio_share(evidence)
    ratio = omega2 / omega1
    here = float(np.interp(x_c, points, omegas[:, 1] / omegas[:, 0]))
    tip = float(omegas[-1, 1] / omegas[-1, 0])
    misfit_here, misfit_tip = abs(ratio / here - 1.0) / share, abs(ratio / tip - 1.0) / share
    if not (misfit_here > 2.0 and misfit_tip < 1.0):
        return None
    return (
        f"omega_1 = {omega1:.1f} rad/s lies {100 * (1.0 - omega1 / at_tip):.1f} % below the "
        f"sensing curve's value at the tip ({at_tip:.1f} rad/s), where a link that much softer "
        f"than its calibration touched there rings, and omega_2 / omega_1 = {ratio:.3f}, which "
        f"the stiffness does not enter, fits the tip's ({tip:.3f}, {misfit_tip:.1f} of its "
        f"uncertainties) rather than the answer's ({here:.3f} at {x_c:.3f} m, "
        f"{misfit_here:.1f}): the contact may be at the tip; calibrate again if the link's "
        "temperature changed"
    )


def _uncertainty_source(link: Link) -> str:
    """Where the link's frequency uncertainty comes from, in words."""
    if link.calibrated_t is None:
        return "a nominal T"
    if link.calibration_scatter is None:
        return "assumed: the calibration measured no scatter"
    if link.calibration_scatter < link.frequency_uncertainty:
        return (
            f"the model's floor, above the calibration's scatter of "
            f"{100 * link.calibration_scatter:.2g} %"
        )
    return "the calibration's scatter"


def second_mode_against(notes: dict[str, Any], chosen: int, cfg: Any) -> int | None:
    """The other candidate when the second mode speaks against ``chosen``, else None.

    A scale error of the loads moves the ratio, not the modes: a peak in the other candidate's
    omega_2 window ten times stronger than in the chosen one's, and at least half as clear as a
    peak the method would choose by (``min_peak_quality``), is evidence against the choice.
    """
    other = 1 - chosen
    chosen_q, other_q = notes["quality"][chosen], notes["quality"][other]
    if other_q >= 0.5 * cfg.min_peak_quality and other_q >= 10.0 * chosen_q:
        return other
    return None


@dataclass(frozen=True)
class PaperMethod:
    """The paper's method (Section 4): Estimator 1 candidates, chosen by Estimator 2."""

    name: str = "paper"

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        """Fuse the frequency candidates with the ratio at t_e."""
        cfg = evidence.config
        link = evidence.antenna.link
        measurement = evidence_frequency(evidence)
        ratio_estimate = float(evidence.ratio_mean[evidence.end_index])
        problems: list[tuple[Status, str]] = []
        diag: dict[str, Any] = {
            "torque_component": measurement.component,
            "band": measurement.band,
            "spectrum_window": (measurement.t_start, measurement.t_end),
            "component_peaks": {
                name: (None if peak is None else {"omega": peak.omega, "quality": peak.quality})
                for name, peak in measurement.peaks.items()
            },
        }
        agree = measurement.components_agree(cfg.component_agreement)
        diag["components_agree"] = agree
        x_range = (cfg.contact_range[0] * link.length, cfg.contact_range[1] * link.length)
        # Tolerances from the ratio's own uncertainty (noise, tare, statics model)
        sigma_ratio = evidence.ratio_uncertainty(ratio_estimate)
        # the candidate's own uncertainty from the bent link (its deflection's preload)
        sigma_bent = evidence.bent_link_uncertainty(ratio_estimate)
        tolerance = cfg.disagreement_sigmas * math.hypot(sigma_ratio, sigma_bent)
        diag["ratio_uncertainty"] = sigma_ratio
        diag["bent_link_uncertainty"] = sigma_bent
        measurement, plane_problem = bending_planes(
            measurement,
            lambda omega: candidates_from_omega1(
                link, omega, x_range, cfg.disagreement_sigmas * link.frequency_uncertainty * omega
            )[0],
            ratio_estimate,
            sigma_ratio,
            cfg,
            diag,
        )
        if plane_problem is not None:
            problems.append(plane_problem)
        candidates: tuple[float, ...] = ()
        if math.isfinite(measurement.omega1):
            omega_tolerance = (
                cfg.disagreement_sigmas * link.frequency_uncertainty * measurement.omega1
            )
            candidates, notes = candidates_from_omega1(
                link, measurement.omega1, x_range, omega_tolerance
            )
            diag.update(notes)
        if not measurement.clear:
            problems.append(
                (
                    Status.NO_CLEAR_PEAK,
                    f"no spectral peak in {measurement.band[0]:.1f} to {measurement.band[1]:.1f} "
                    f"rad/s reaches {cfg.min_peak_quality:g} times the median power "
                    f"(best {measurement.quality:.1f})",
                )
            )
            candidates_used: tuple[float, ...] = ()
        else:
            candidates_used = candidates
        fusion = fuse(candidates_used, ratio_estimate, tolerance)
        diag["discriminated_by"] = "ratio" if len(candidates_used) > 1 else None
        if len(candidates_used) == 2 and math.isfinite(ratio_estimate):
            margin = abs(
                abs(candidates_used[0] - ratio_estimate) - abs(candidates_used[1] - ratio_estimate)
            )
            choice, notes = second_mode_choice(evidence, measurement.component, candidates_used)
            diag["second_mode"] = notes
            # the branch rests on the ratio: at a deep push its uncertainty holds the axial
            # force's cross-talk, which no calibration of the lateral forces measured, as large
            # as it would be were the contact the candidate farther out (it grows as x_c^4)
            axial = float(evidence.axial_cross_talk_uncertainty(np.array(max(candidates_used))))
            sigma_branch = math.hypot(sigma_ratio, axial)
            diag["branch_ratio_uncertainty"] = sigma_branch
            if margin < cfg.ratio_resolution_sigmas * sigma_branch and choice is not None:
                x_pick = candidates_used[choice]
                fusion = Fusion(
                    x_c=x_pick,
                    chosen=choice,
                    distance=abs(x_pick - ratio_estimate),
                    agree=abs(x_pick - ratio_estimate) <= tolerance,
                )
                diag["discriminated_by"] = "omega2"
            elif margin < cfg.ratio_resolution_sigmas * sigma_branch:
                other = candidates_used[1 - int(fusion.chosen or 0)]
                problems.append(
                    (
                        Status.UNCERTAIN,
                        f"the torque/force ratio ({ratio_estimate:.3f} m, +-{sigma_branch:.3f} m) "
                        f"cannot tell the candidate {fusion.x_c:.3f} m from {other:.3f} m and "
                        "the second contact mode is not clear",
                    )
                )
            contradiction = second_mode_against(notes, int(fusion.chosen or 0), cfg)
            if contradiction is not None:
                problems.append(
                    (
                        Status.ESTIMATORS_DISAGREE,
                        f"the torque/force ratio ({ratio_estimate:.3f} m) chose the candidate "
                        f"{fusion.x_c:.3f} m, but the second contact mode is that of "
                        f"{candidates_used[contradiction]:.3f} m",
                    )
                )
        if candidates_used and math.isfinite(ratio_estimate) and not fusion.agree:
            problems.append(
                (
                    Status.ESTIMATORS_DISAGREE,
                    f"the frequency candidate {fusion.x_c:.3f} m is {_metres(fusion.distance)} "
                    f"m from the ratio estimate {_metres(ratio_estimate)} m, more than "
                    f"{cfg.disagreement_sigmas:g} times their uncertainty "
                    f"({_metres(math.hypot(sigma_ratio, sigma_bent))} m: noise, tare, statics "
                    "model, bent link)",
                )
            )
        if candidates_used and math.isfinite(fusion.x_c):
            spread = model_spread(link, fusion.x_c, 2.0 * link.frequency_uncertainty)
            diag["model_spread"] = spread
            plane = diag.get("frequency_plane")
            if plane == "push" or (plane == "both" and diag.get("free_plane_mode") is None):
                # the push plane's frequency, alone or with a free-plane peak that may be its
                # leak, carries the rise a contact held along the link makes, bounded by the
                # force along it; read alone, the bent link's preload too
                preload = 0.0
                if plane == "push":
                    preload = 2.0 * evidence.bent_link_uncertainty(fusion.x_c)
                    diag["preload_spread"] = preload
                held, held_spread = held_contact_spread(
                    evidence, measurement.omega1, fusion.x_c, diag, alone=plane == "push"
                )
                total = math.hypot(spread, preload, held_spread)
                if total > cfg.max_model_spread and (plane == "push" or held_spread > 0.0):
                    # a nominal T's spread the larger share: calibrating is what narrows it
                    nominal = not link.calibrated_t and spread >= math.hypot(preload, held_spread)
                    reason = _push_plane_reason(total, held, plane == "push", cfg)
                    if nominal:
                        reason += ", most of it the frequency model's own: calibrate the antenna"
                    problems.append((Status.UNCERTAIN, reason))
            peak2 = second_peak(evidence, measurement.component, measurement.omega1)
            off = math.nan
            if peak2 is not None:
                nearest, off = pair_distance(evidence, measurement.omega1, peak2.omega)
                diag["curve_distance"] = off
                if len(candidates_used) == 1:
                    # one candidate: the second mode is the frequency side's only other word
                    omega1, x_c = measurement.omega1, fusion.x_c
                    elsewhere = _pair_elsewhere(evidence, omega1, peak2.omega, x_c, nearest, off)
                    if elsewhere is not None:
                        problems.append((Status.ESTIMATORS_DISAGREE, elsewhere))
                    elif (tip := _tip_alternative(evidence, omega1, peak2.omega, x_c)) is not None:
                        problems.append((Status.UNCERTAIN, tip))
            mismatch = 0.0
            if 2.0 * link.frequency_uncertainty < off <= curve_allowance(link, cfg):
                # the model is at least that far off on this manoeuvre: omega_1 may be too (a
                # pair further off is no pair of contact modes: the peak is another vibration)
                mismatch = model_spread(link, fusion.x_c, off)
                diag["mismatch_spread"] = mismatch
            if mismatch > cfg.max_model_spread:
                # never less than the model's own spread: one reason, the larger
                problems.append(
                    (
                        Status.UNCERTAIN,
                        f"omega_1 and omega_2 lie {100 * off:.2g} % from the nearest point of "
                        f"the sensing curves, more than twice the frequency model's own "
                        f"uncertainty ({100 * link.frequency_uncertainty:.2g} % in each) "
                        f"allows: the model is that far off on this manoeuvre, and an error of "
                        f"omega_1 that large moves the candidate by up to "
                        f"{100 * mismatch:.1f} cm, more than {100 * cfg.max_model_spread:g} cm",
                    )
                )
            elif spread > cfg.max_model_spread:
                problems.append(
                    (
                        Status.UNCERTAIN,
                        f"the frequency model's own uncertainty "
                        f"({100 * link.frequency_uncertainty:.2g} % of omega_1, "
                        f"{_uncertainty_source(link)}) "
                        f"moves this candidate by up to {100 * spread:.1f} cm at two standard "
                        f"deviations, more than {100 * cfg.max_model_spread:g} cm"
                        + ("" if link.calibrated_t else ": calibrate the antenna"),
                    )
                )
        if "off_curve" in diag and abs(diag["off_curve"]) > cfg.band_margin:
            problems.append(
                (
                    Status.NO_CLEAR_PEAK,
                    f"omega_1 = {measurement.omega1:.1f} rad/s is off the sensing curve by "
                    f"{100 * diag['off_curve']:.0f} %",
                )
            )
        return conclude(
            evidence,
            self.name,
            fusion.x_c,
            candidates=candidates,
            omega1=measurement.omega1,
            peak_quality=measurement.quality,
            ratio_estimate=ratio_estimate,
            problems=problems,
            diagnostics=diag,
        )


def _push_plane_reason(
    total: float, held: HeldContact | None, alone: bool, cfg: EstimatorConfig
) -> str:
    """Why an omega_1 of the push plane, read there ``alone`` or with a free-plane peak that may
    be its leak, may put the candidate ``total`` (m) off."""
    causes = [
        "where the bent link's preload shifts it"
        if alone
        else "where the free plane's peak may be the push plane's leak"
    ]
    if held is not None and math.isinf(held.shift):
        causes.append("the loads along the link are not finite: no bound of a hold's rise")
    elif held is not None and held.shift > 0.0:
        causes.append(
            f"the force along the link rings with it, {held.ringing:.2g} N per N m of "
            f"the bending moment ({held.in_phase:.2g} in phase), more than sliding, cross-talk "
            f"and noise make: "
            f"friction holds the contact along the link, which may raise omega_1 by up to "
            f"{100 * held.shift:.1f} %"
        )
    where = "in the push plane alone" if alone else "in both planes"
    return (
        f"omega_1 was read {where}, {', and '.join(causes)}: with the frequency model's own "
        f"uncertainty the candidate may be {100 * total:.1f} cm off at two standard deviations, "
        f"more than {100 * cfg.max_model_spread:g} cm"
    )


def _metres(value: float) -> str:
    """A length (m) to the millimetre, or to four digits when it is no link's (loads in another
    unit make ratios of 10^3 to 10^70 m)."""
    return f"{value:.3f}" if abs(value) < 1e3 else f"{value:.4g}"


def _direction_drift(evidence: Evidence, end: int) -> float:
    """Angle (rad) about the link's axis X^c between the hold's push direction Y^c and the
    filtered reaction's part across the link, its mean over the last ``convergence_window`` up
    to sample ``end``.

    A contact that slides over the obstacle across the link turns that part; one that slides
    along the link moves the ratio (its own check), and a contact held by friction may carry a
    changing share along the link (the friction cone's check bounds it) as the servo settles.
    The window holds a period of the slowest vibration or more, so what the low-pass leaves of
    the ringing averages out and a slip's turn does not."""
    t = evidence.t
    start = int(np.searchsorted(t, t[end] - evidence.config.convergence_window, side="left"))
    _, push, out = evidence.frame.axes_m @ np.mean(evidence.reaction_f[start : end + 1], axis=0)
    return abs(math.atan2(float(out), float(push)))
