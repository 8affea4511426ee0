"""The plausibility layer: what every method's estimate passes through before it may be ``ok``.

:func:`~sensing_antenna.estimation.pipeline.conclude` hands each method's estimate here with the
evidence it concluded from, offline and online alike, so ``paper``, ``ratio``,
``two-frequency``, ``fast`` and any method registered later are judged by the same physics.
Every check reads only the samples up to the estimate's own t_e, so the batch and the streaming
forms agree.

1. Whole samples (``bad_input``, :meth:`~.evidence.Evidence.sample_problem`): no gap longer
   than the estimators fill in inside [t_c, t_e], no corrupted run too long to put back before
   t_e; in a stream, no more than :data:`_LATE_SHARE` of the samples up to t_e left out for a
   place another had taken (:func:`_misplaced_problem`), and its time stamps up to t_e
   stepping by the declared period (:func:`_clock_problem`). The recording's units and signs
   (``implausible_input``): the loads at rest before t_c against the link's weight and the
   free motion against the observer (found by the front end at t_c,
   ``Evidence.input_problem``), the angles up to t_e
   (:func:`~sensing_antenna.units_check.angle_problem`), and the push against the head's turn
   into the contact (an obstacle only pushes back; a push that opposed the turn up to t_1 and
   not over the hold after it is a link that slid off the object, ``slip_suspected``), and the
   head's work against the contact's moment against the energy the push stores in the link
   (an obstacle gives no energy: angles swapped turn the head across the push; a share short
   by less than ``1 / input_work_share`` is a scale, torques that read high or a stiffer link,
   ``model_mismatch``; :func:`_work_problem`). The contact found at t_c holds until the head
   rests at t_1 (``uncertain``, :func:`_detected_before_touch`: a detection on something else
   fades while the head sweeps on to the touch; the work and the bend, which start at t_c,
   are then not judged).
2. The answer lies on the link: 0 < x_c <= l (``model_mismatch``). An answer past the tip by
   no more than ``disagreement_sigmas`` statistical uncertainties of the ratio at the tip (noise
   and tare, :meth:`~.evidence.Evidence.ratio_uncertainty` without its model term, which grows
   with the push and would admit any reading near the tip) is a contact at the tip measured a
   little long: the contact cannot lie beyond l, so the estimate constrained to the link is l,
   reported so (the method's own value in ``diagnostics["x_c_past_tip"]``, the touched point
   recomputed at l from the hold's push).
   The answer's contact can be at rest: the hold's reaction lies inside a friction cone of
   ``max_friction_ratio`` about the normal across the link's tangent there (the elastica's;
   ``slip_suspected``, :func:`_friction_problem`). The answer agrees with the statics: the front
   end's settled ratio at its t_e lies within ``disagreement_sigmas`` of their uncertainties
   (``estimators_disagree``; every method but ``ratio``, :func:`_statics_problem`). The push
   bends the link as far as the head turned into the object since the touch, or, sliding with
   friction, a little less (``model_mismatch``, :func:`_bend_against_turn`): forces that read
   high, a stiffer link, angles that are not the head's or an answer too near the base say
   otherwise.
3. A real vibration: the fundamental omega_1 that the method measured, or, for a method that
   measures none (``ratio``), Estimator 1 on the samples from t_1 to t_e, must be a clear peak
   (``no_clear_peak``).
4. One scale (``model_mismatch``; ``implausible_input`` beyond a factor 30, a unit's 1000): the
   vibration puts the contact at the point of the sensing
   curve with that omega_1 (the nearest of its candidates); the front end's torque/force ratio at
   t_e and the answer must lie within ``max_scale_mismatch`` of it, unless
   ``disagreement_sigmas`` statistical uncertainties of the ratio (noise and tare, which do not
   grow with the loads' scale) cover the difference. The frequency does
   not depend on the scale of the loads, the ratio does: forces doubled halve the ratio, a
   synthetic sine in the wrench matches no contact point with both.
5. One stiffness (``model_mismatch``, :func:`_mode_ratio_problem`): omega_2 / omega_1, which
   T does not enter, must fit the model's at the answer; where it does not, but fits it at a
   point the statics allow, the answer's omega_1 is one the model misplaces there (a wrong T or
   a clock of the time stamps). Asked of an answer that is ``ok`` or ``uncertain`` and that the
   statics allow.
6. Loads a tare corrected (``uncertain``): a recording that starts too close to t_c leaves
   the sensor's offset in every load. A straight enough link (``uncertain``): the sensing
   curves are the straight link's, and a push that bends the link shifts its frequencies
   (:func:`_bent_link_problem`); a method that read omega_1 is not ``ok`` where that shift, in
   whichever plane, may move the vibration's point by more than ``max_model_spread``; nor any
   method beyond ``max_deflection_ratio``, where the statics were not checked. One time base
   (``uncertain``, :func:`_time_base_problem`): readings sent again in all six channels where
   the loads move fast, more than the sensor's resolution explains and not in place of lost
   readings, would have stretched the time if stamped as new samples; a method that read
   omega_1 is not ``ok`` where that stretch moves its point by more than
   ``max_model_spread``.

The status is the first problem in :data:`~.result.STATUS_PRECEDENCE`, the method's own included;
the rest go to ``diagnostics["other_reasons"]``. Whatever the status, a best guess outside
(0, l] or not finite is not reported: x_c is NaN, as are the touched point and the interval, and
the reason gives the dropped value; an infinite torque/force ratio (loads that overflow Eq. 21)
is no reading, NaN. An interval is cut to the link [0, l] (the contact lies on
it), or dropped when it is not finite or lies off the link; a touched point farther from the base
than the link can reach is dropped. Under ``bad_input`` and ``implausible_input`` no interval is
reported (it is kept in ``diagnostics["interval_dropped"]``): it would hold the contact only if
the samples were whole and what the format says, and the status says they are not.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import Any

import numpy as np

from sensing_antenna.antenna import RANGE_SHARE, STANDARD_GRAVITY, Link
from sensing_antenna.beam import SensingCurve, free_plane_shift, natural_frequencies
from sensing_antenna.beam.elastica import loaded_end
from sensing_antenna.beam.free_plane import FREE_PLANE_DEFLECTIONS
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.estimation.config import periods_in
from sensing_antenna.estimation.disturbance import line_at, rest_line
from sensing_antenna.estimation.front.contact_frame import motor_axes, to_absolute
from sensing_antenna.estimation.front.evidence import (
    TWO_FREQUENCY_GRID_STEP,
    Evidence,
    sensing_curve,
    support_coefficients,
)
from sensing_antenna.estimation.front.held import FAST_PACE, repeated_rows
from sensing_antenna.estimation.front.spectrum import power_spectrum
from sensing_antenna.estimation.front.spikes import WRENCH_CHANNELS
from sensing_antenna.estimation.front.steps import declared_period_refused, stream_period_problem
from sensing_antenna.estimation.held_joint import COMPLIANCE_MARGIN, held_line, swept_joint
from sensing_antenna.estimation.methods.fast.parametric import fit_damped_sinusoids
from sensing_antenna.estimation.methods.paper.frequency import find_peak, measure_frequency
from sensing_antenna.estimation.methods.paper.fusion import (
    candidates_from_omega1,
    harmonic_of,
    mode_ratio_share,
    model_spread,
    second_mode_band,
    second_peak,
)
from sensing_antenna.estimation.methods.touch_point import placement, touched_point_filtered
from sensing_antenna.estimation.result import STATUS_PRECEDENCE, ContactEstimate, Status
from sensing_antenna.torque_point import metadata_line
from sensing_antenna.units_check import angle_problem

__all__ = ["review"]

_RANK = {status: rank for rank, status in enumerate(STATUS_PRECEDENCE)}
#: Statuses that say the samples are not what the format says: no interval is claimed under them.
_INPUT_STATUSES = (Status.BAD_INPUT, Status.IMPLAUSIBLE_INPUT)
#: Least radius (m) of an object's surface the bend check allows a contact to slide over: the
#: simulator's default post is 10 mm.
_LEAST_RADIUS = 0.01


def review(evidence: Evidence, estimate: ContactEstimate) -> ContactEstimate:
    """The estimate after the plausibility checks (module docstring).

    Parameters
    ----------
    evidence : Evidence
        What the method concluded from.
    estimate : ContactEstimate
        The method's estimate; its ``t_e`` bounds the samples the checks read.

    Returns
    -------
    ContactEstimate
        The same estimate when every check passes and its guess lies on the link; otherwise the
        status of the first problem, the others in ``diagnostics["other_reasons"]``.
    """
    reviewed = _reviewed(evidence, estimate)
    if reviewed.status is Status.ESTIMATORS_DISAGREE and math.isfinite(reviewed.x_c):
        hint = _torque_point_hint(evidence, reviewed.x_c, _index_at(evidence, estimate.t_e))
        reviewed = dataclasses.replace(reviewed, reason=f"{reviewed.reason}{hint}")
    if reviewed.status is Status.UNCERTAIN and reviewed.method != "ratio":
        # the ratio's statics do not weigh the link
        hint = _payload_hint(evidence)
        reviewed = dataclasses.replace(reviewed, reason=f"{reviewed.reason}{hint}")
    return reviewed


def _payload_hint(evidence: Evidence) -> str:
    """What an unsure answer owes to a payload the weight at rest reads, or ""."""
    mass = evidence.carried_payload_mass()
    if not mass > 0.0:
        return ""
    return (
        f"; at rest the link's moment ty reads {float(evidence.load_offset[4]):.3g} N m more "
        f"than the model's weight, as {1e3 * mass:.2g} g at the tip the antenna file does not "
        "carry, which lowers omega_1 (the fast method's interval carries that shift): give the "
        "payload in link.tip_mass (or calibrate with it on), or tare the sensor"
    )


def _reviewed(evidence: Evidence, estimate: ContactEstimate) -> ContactEstimate:
    """The estimate after the checks, before a disagreement's hint."""
    link = evidence.antenna.link
    end = _index_at(evidence, estimate.t_e)
    if math.isinf(estimate.ratio_estimate):
        # loads beyond float range (torques in N mm, a glitch) overflow Eq. 21: no reading
        estimate = dataclasses.replace(estimate, ratio_estimate=math.nan)
    notes: dict[str, Any] = {}
    found: list[tuple[Status, str]] = []
    broken = evidence.sample_problem(estimate.t_e)
    if broken is not None:
        found.append((Status.BAD_INPUT, broken))
    clipped = _clipped_problem(evidence, end)
    if clipped is not None:
        found.append((Status.BAD_INPUT, clipped))
    misplaced = _misplaced_problem(estimate, end)
    clock = (
        _clock_problem(evidence, end) if misplaced is None and evidence.declared_period else None
    )
    for problem in (misplaced, clock):
        if problem is not None:
            found.append((Status.BAD_INPUT, problem))
    if evidence.input_problem is not None:
        found.append((Status.IMPLAUSIBLE_INPUT, evidence.input_problem))
    angles = angle_problem(evidence.theta[: end + 1])
    if angles is not None and angles not in (evidence.input_problem or ""):
        found.append((Status.IMPLAUSIBLE_INPUT, angles))
    push = _push_direction_problem(evidence)
    if push is not None:
        found.append(push)
    estimate = _at_tip_when_just_past(evidence, estimate)
    x_c = estimate.x_c
    on_link = math.isfinite(x_c) and 0.0 < x_c <= link.length
    if math.isfinite(x_c) and not on_link:
        found.append(
            (
                Status.MODEL_MISMATCH,
                f"x_c = {x_c:.4g} m lies outside the link, (0, {link.length:g}] m",
            )
        )
    friction = _friction_problem(evidence, estimate, notes)
    if friction is not None:
        found.append((Status.SLIP_SUSPECTED, friction))
    statics = _statics_problem(evidence, estimate, end, notes)
    if statics is not None:
        found.append((Status.ESTIMATORS_DISAGREE, statics))
    # an answer the statics, or the method itself, already disagree with keeps that reason
    judged = on_link and not statics and estimate.status in (Status.OK, Status.UNCERTAIN)
    stiffness = _mode_ratio_problem(evidence, estimate, end, notes) if judged else None
    if stiffness is not None:
        found.append((Status.MODEL_MISMATCH, stiffness))
    pinned = _pinned_contact_problem(evidence, estimate, end, notes) if judged else None
    if pinned is not None:
        found.append((Status.UNCERTAIN, pinned))
    # the damping speaks only where the second mode could not (a stiff contact's friction damps)
    told = "second_mode_quality" in notes
    lossy = _lossy_contact_problem(evidence, estimate, end, notes) if judged and not told else None
    if lossy is not None:
        found.append((Status.UNCERTAIN, lossy))
    rocked = _base_motion_problem(evidence, estimate, end, notes) if judged else None
    if rocked is not None:
        found.append((Status.UNCERTAIN, rocked))
    tone = _rest_line_problem(evidence, estimate, end, notes) if judged else None
    if tone is not None:
        found.append((Status.UNCERTAIN, tone))
    found.extend(_vibration_problems(evidence, estimate, end, notes))
    bent = _bent_link_problem(evidence, estimate, notes) if on_link else None
    if bent is not None:
        found.append((Status.UNCERTAIN, bent))
    stretched = _time_base_problem(evidence, estimate, end, notes) if on_link else None
    if stretched is not None:
        found.append((Status.UNCERTAIN, stretched))
    bend = float(estimate.diagnostics.get("deflection_ratio", math.nan))
    if on_link and bend > evidence.config.max_deflection_ratio:
        found.append(
            (
                Status.UNCERTAIN,
                f"the measured push would bend the link by {100 * bend:.0f} % of x_c at "
                f"x_c = {x_c:.3f} m, beyond the "
                f"{100 * evidence.config.max_deflection_ratio:g} % the statics and the sensing "
                "curves were checked to",
            )
        )
    if evidence.tare == "none":
        found.append((Status.UNCERTAIN, _untared(evidence)))
    payload = _payload_problem(evidence, estimate, notes)
    if payload is not None:
        found.append((Status.MODEL_MISMATCH, payload))
    early = _detected_before_touch(evidence)
    if early is not None:
        found.append((Status.UNCERTAIN, early))
    # the head's work and its turn into the push are read from t_c: judged when it was the touch
    from_touch = on_link and push is None and early is None
    work = _work_problem(evidence, estimate, end, notes) if from_touch else None
    if work is not None:
        found.append(work)
    turn = _bend_against_turn(evidence, estimate, end, notes) if from_touch else None
    if turn is not None:
        found.append((Status.MODEL_MISMATCH, turn))
    interval = _on_link(estimate.interval, link.length)
    if pinned is not None or lossy is not None or rocked is not None or tone is not None:
        interval = _widened_to_statics(evidence, interval, end, notes)
    point_ok = _within_reach(estimate.contact_point, evidence)
    if not found and on_link:
        interval = _claimed(interval, estimate.status, notes)  # the method's own bad_input
        if interval != estimate.interval:
            notes["interval"] = interval
        if not point_ok:
            notes["contact_point"] = np.full(3, np.nan)
        return _with_notes(estimate, notes)
    problems = sorted(found, key=lambda item: _RANK[item[0]])
    if estimate.status is not Status.OK:
        assert estimate.reason is not None
        problems.insert(0, (estimate.status, estimate.reason))
        problems.sort(key=lambda item: _RANK[item[0]])
    status, reason = problems[0] if problems else (Status.OK, None)
    diagnostics = dict(estimate.diagnostics)
    diagnostics.update(notes)
    diagnostics["other_reasons"] = [text for _, text in problems[1:]] + list(
        diagnostics.get("other_reasons", [])
    )
    changes: dict[str, Any] = {"status": status, "reason": reason, "diagnostics": diagnostics}
    if not on_link:
        # No guess off the link: neither the number, nor the point or interval built on it
        if math.isfinite(x_c) and reason is not None and "lies outside the link" not in reason:
            changes["reason"] = (
                f"{reason}; best guess x_c = {x_c:.4g} m dropped: outside the link, "
                f"(0, {link.length:g}] m"
            )
        changes.update(x_c=math.nan, contact_point=np.full(3, np.nan), interval=None)
    else:
        interval = _claimed(interval, status, diagnostics)
        if interval != estimate.interval:
            changes["interval"] = interval
        if not point_ok:
            changes["contact_point"] = np.full(3, np.nan)
    kept = tuple(c for c in estimate.candidates if math.isfinite(c) and 0.0 < c <= link.length)
    if kept != estimate.candidates:
        changes["candidates"] = kept
    return dataclasses.replace(estimate, **changes)


#: Most of a stream's samples up to t_e that may come for a place on the period's grid another
#: has taken (``late_samples``): a stream stamped within a third of a period leaves a few in a
#: thousand; one whose stamps jitter by half a period leaves a tenth, and its readings sit up
#: to a period from where they were read.
_LATE_SHARE = 0.05


def _misplaced_problem(estimate: ContactEstimate, end: int) -> str | None:
    """Why a stream's samples up to sample ``end`` do not sit where they were read, or None:
    more than :data:`_LATE_SHARE` of them came for a place another had taken (left out, the
    places put back; ``diagnostics["late_samples"]``, streams only)."""
    late = estimate.diagnostics.get("late_samples")
    samples = end + 1
    if not (isinstance(late, int) and late > _LATE_SHARE * samples):
        return None
    return (
        f"{late} of the {samples} samples up to t_e came for a place on the period's grid that "
        "another had taken, and were left out: time stamps that jitter by half a period or "
        "more place the readings no better than a period, and the frequencies read from them "
        "move; stamp the samples on the device's own clock, or send them at a steady period"
    )


def _clock_problem(evidence: Evidence, end: int) -> str | None:
    """Why a stream's samples up to ``end`` were not taken the period it declared apart, or
    None: the line through their time stamps against their places steps by another period
    (:func:`~.front.steps.stream_period_problem`). A stream a few per mille off the period it
    declared, its jitter hiding that from its first stamps, reads every frequency as far off.
    A recording's period is read from its stamps by its reader (``Evidence.declared_period``
    false), which resamples it when they disagree, and is not judged here."""
    problem = stream_period_problem(
        evidence.t[: end + 1], np.arange(end + 1), evidence.sample_period
    )
    return None if problem is None else declared_period_refused(evidence.sample_period, problem)


def _claimed(
    interval: tuple[float, float] | None, status: Status, diagnostics: dict[str, Any]
) -> tuple[float, float] | None:
    """``interval`` unless ``status`` says the samples are not what the format says; then None,
    the interval kept in ``diagnostics["interval_dropped"]``."""
    if interval is None or status not in _INPUT_STATUSES:
        return interval
    diagnostics["interval_dropped"] = interval
    return None


def _at_tip_when_just_past(evidence: Evidence, estimate: ContactEstimate) -> ContactEstimate:
    """``estimate`` with x_c = l when it lies past the tip by no more than
    ``disagreement_sigmas`` statistical uncertainties of the ratio at l (otherwise unchanged),
    the touched point recomputed there with the filtered reaction at the estimate's t_e, as the
    paper method places its point (``touch_point.touched_point_filtered``: the instant it
    describes lies 1 / omega_c before t_e, not before t_1)."""
    link = evidence.antenna.link
    excess = estimate.x_c - link.length
    if not (math.isfinite(excess) and excess > 0.0):
        return estimate
    sigma = evidence.ratio_uncertainty(link.length, model=False)
    allowed = evidence.config.disagreement_sigmas * sigma
    if not excess <= allowed:
        return estimate
    end = evidence.end_index
    if math.isfinite(estimate.t_e):
        end = min(int(np.searchsorted(evidence.t, estimate.t_e)), evidence.end_index)
    touch, frame, t_point = touched_point_filtered(evidence, link.length, end)
    diagnostics = {
        **estimate.diagnostics,
        "x_c_past_tip": estimate.x_c,
        **placement(touch, frame, t_point),
    }
    return dataclasses.replace(
        estimate, x_c=link.length, contact_point=touch.point_a, diagnostics=diagnostics
    )


def _statics_problem(
    evidence: Evidence, estimate: ContactEstimate, end: int, notes: dict[str, Any]
) -> str | None:
    """Why the answer is not where the statics put the contact, or None.

    The front end's torque/force ratio at the estimate's t_e (the elastica's contact,
    :func:`~.front.ratio.perpendicular_ratio`) must lie within ``disagreement_sigmas`` of its
    uncertainty (:meth:`~.front.evidence.Evidence.ratio_uncertainty` at the answer, with the
    bent link's on the answer, :meth:`~.front.evidence.Evidence.bent_link_uncertainty`) of the
    answer, as the paper method's fusion asks of its candidate; a method that reads no ratio
    (``two-frequency``) is held to it here. Not judged for ``ratio`` (the answer is a ratio)
    nor before the ratio settled (t_1 + Delta t_e2) at the estimate's t_e. Notes ``statics_z``
    (the distance in uncertainties).
    """
    x_c = estimate.x_c
    if estimate.method == "ratio" or not math.isfinite(x_c):
        return None
    settled = evidence.converged_index
    if settled is None or settled > end or end >= evidence.ratio_mean.shape[0]:
        # an answer before the ratio settled (``fast`` stops early) is not judged by it
        return None
    reading = float(evidence.ratio_mean[end])
    if not math.isfinite(reading):
        return None
    sigma = math.hypot(evidence.ratio_uncertainty(x_c), evidence.bent_link_uncertainty(x_c))
    if not (math.isfinite(sigma) and sigma > 0.0):
        return None
    z = abs(x_c - reading) / sigma
    notes["statics_z"] = z
    if z <= evidence.config.disagreement_sigmas:
        return None
    return (
        f"the statics put the contact at {reading:.3f} m (torque/force ratio; +-{sigma:.3f} m "
        "with the answer's bent link), "
        f"{abs(x_c - reading):.3f} m from the answer {x_c:.3f} m: more than "
        f"{evidence.config.disagreement_sigmas:g} of their uncertainties"
    )


def _mode_ratio_problem(
    evidence: Evidence, estimate: ContactEstimate, end: int, notes: dict[str, Any]
) -> str | None:
    """Why the answer's omega_1 puts the contact where omega_2 / omega_1, which T does not
    enter, says it is not, while the statics allow where it says it is, or None.

    The second contact mode's clear peak (the paper method's band, :func:`second_peak`; not
    within ``omega2_window`` of 2 or 3 omega_1, where a harmonic may be what it is) over the
    answer's omega_1 is held against the model's omega_2 / omega_1 curve, each point's known to
    ``mode_ratio_uncertainty`` (or, a calibration having measured them, the scatters of omega_1
    and omega_2 when larger). The answer must fit it within ``disagreement_sigmas`` somewhere
    within ``disagreement_sigmas`` of its own uncertainty (the frequency model's,
    ``Link.frequency_uncertainty``). Where it does not, the points that fit and that the
    statics allow (the settled torque/force ratio at t_e, as :func:`_statics_problem` reads
    it, within ``disagreement_sigmas`` of theirs; before it settled, as ``fast`` answers, any)
    must lie in one stretch of the curve; else the peak is no contact mode, or the statics are
    off, or the curve turns within the stretch: nothing is said. The best of them (on each of
    the curve's branches in the stretch, the one nearest the answer) is known to the ratio's
    uncertainty over the curve's slope there, with the statics'; an answer farther from it
    than ``disagreement_sigmas`` of that and its own, and than ``max_model_spread``, is read
    from an omega_1 the model misplaces there: a T (a calibration) or a clock of the time
    stamps that far off. Not asked where the bent link's preload may move the vibration's
    point by more than ``max_model_spread``: the curves are the straight link's, omega_2's
    too. Notes ``mode_ratio_stretch`` (the points that fit, m), ``mode_ratio_point`` (the best)
    and ``mode_ratio_scale`` (the measured omega_1 over the model's there).
    """
    x_c, omega1 = estimate.x_c, estimate.omega1
    cfg = evidence.config
    link = evidence.antenna.link
    if not _modes_judge(evidence, estimate):
        return None
    settled = evidence.converged_index
    reading = math.nan
    if settled is not None and settled <= end < evidence.ratio_mean.shape[0]:
        reading = float(evidence.ratio_mean[end])
    component = str(estimate.diagnostics.get("torque_component", "sum"))
    peak = second_peak(evidence, component, omega1)
    if peak is None or harmonic_of(omega1, peak.omega, cfg):
        return None
    points, omegas = evidence.contact_modes
    if not points[0] <= x_c <= points[-1]:
        return None  # the curve is tabulated over the contact range only
    curve = omegas[:, 1] / omegas[:, 0]
    ratio = peak.omega / omega1
    sigma = mode_ratio_share(evidence) * ratio
    misfit = np.abs(curve - ratio) / sigma
    limit = cfg.disagreement_sigmas
    own = model_spread(link, x_c, link.frequency_uncertainty)
    near = np.abs(points - x_c) <= max(limit * own, TWO_FREQUENCY_GRID_STEP)
    answer_misfit = float(misfit[near].min())
    if answer_misfit <= limit:
        return None
    if math.isfinite(reading):
        # the statics' uncertainty, at least the curve's grid step
        statics = math.hypot(
            evidence.ratio_uncertainty(reading),
            evidence.bent_link_uncertainty(reading),
            TWO_FREQUENCY_GRID_STEP,
        )
        apart = np.abs(points - reading) / statics
    else:
        # an answer before the ratio settled (fast): omega_2 / omega_1 alone, in one stretch
        apart = np.zeros(points.shape)
    allowed = (misfit <= limit) & (apart <= limit)
    where = np.flatnonzero(allowed)
    if where.size == 0 or np.any(np.diff(where) > 1):
        # none, or apart stretches (the ratio's curve turns): no one point to name
        return None
    # each branch's best point (the stretch may span the curve's turn), the nearest the answer
    cost = np.where(allowed, np.hypot(misfit, apart), np.inf)
    inner = (cost[1:-1] <= cost[:-2]) & (cost[1:-1] <= cost[2:])
    best_points = np.flatnonzero(
        np.concatenate([[cost[0] <= cost[1]], inner, [cost[-1] <= cost[-2]]])
    )
    best_points = best_points[np.isfinite(cost[best_points])]
    best = int(best_points[np.argmin(np.abs(points[best_points] - x_c))])
    point = float(points[best])
    # how well it is known: omega_2 / omega_1 over the curve's slope there, with the statics
    steep = abs(float(np.gradient(curve, points)[best]))
    sigma_point = sigma / steep if steep > 0.0 else math.inf
    if math.isfinite(reading):
        sigma_point = (sigma_point**-2 + statics**-2) ** -0.5
    margin = max(cfg.max_model_spread, limit * math.hypot(sigma_point, own))
    if not abs(point - x_c) > margin:
        return None
    scale = omega1 / float(omegas[best, 0])
    low, high = float(points[where[0]]), float(points[where[-1]])
    notes["mode_ratio_point"] = point
    notes["mode_ratio_scale"] = scale
    notes["mode_ratio_stretch"] = (low, high)
    head = (
        f"omega_2 / omega_1 = {ratio:.3f}, which T does not enter, is {answer_misfit:.1f} of "
        f"its uncertainties off the model's at the answer {x_c:.3f} m"
    )
    cause = (
        "as a T (a calibration) or a clock of the time stamps that far off makes it: check the "
        "calibration and the time stamps"
    )
    where_fits = "where the statics allow the contact" if math.isfinite(reading) else "alone"
    return (
        f"{head}, and fits it {where_fits} from {low:.3f} to {high:.3f} m, best at "
        f"{point:.3f} m +-{sigma_point:.3f} m ({100 * abs(point - x_c):.1f} cm from the "
        f"answer): the measured omega_1 is {100 * (scale - 1.0):+.1f} % off the model's there, "
        f"{cause}"
    )


def _modes_judge(evidence: Evidence, estimate: ContactEstimate) -> bool:
    """Whether the contact modes' curves can judge the answer: a method that reads omega_1 (not
    ``ratio``), a finite answer, and a bent link's preload that moves the vibration's point by no
    more than ``max_model_spread`` (the curves are the straight link's)."""
    if estimate.method == "ratio" or not (
        math.isfinite(estimate.x_c) and math.isfinite(estimate.omega1)
    ):
        return False
    return evidence.bent_link_uncertainty(estimate.x_c) <= evidence.config.max_model_spread


def _check3_window(evidence: Evidence, end: int) -> slice:
    """The samples check 3 reads: from t_1 to ``end`` (the estimate's t_e), at most Delta t_e1
    (``spectrum_window``)."""
    window = round(evidence.spectrum_window / evidence.sample_period)
    stop = min(evidence.rest_index + window, end)
    return slice(evidence.rest_index, stop + 1)


def _pinned_contact_problem(
    evidence: Evidence, estimate: ContactEstimate, end: int, notes: dict[str, Any]
) -> str | None:
    """Why the answer's omega_1 may be that of a contact that gives (a soft object), or None.

    The sensing curves are a pinned contact's. A support of finite stiffness k at x_c lowers
    omega_i by c_i / k to first order (:func:`~sensing_antenna.beam.modes.
    support_compliance_coefficients`), and the second mode, whose reaction at the contact is
    larger, by more: at 0.4 m on the paper's link c_1 = 7.1 N/m, c_2 = 15.2 N/m, so an object
    of 100 N/m puts omega_1's point 3 cm short while omega_2 / omega_1 falls 8 %; a lossy one
    (foam) also damps the second mode out. A pinned contact rings its second mode at omega_1
    times the model's omega_2 / omega_1 at the answer; the spectrum over the same samples as
    check 3 (t_1 to the estimate's t_e, at most Delta t_e1) must hold a clear peak
    (``min_peak_quality`` times the median of the band :func:`second_mode_band` searches,
    widened to the window) within ``disagreement_sigmas`` of the ratio's uncertainty (as
    :func:`_mode_ratio_problem` takes it) of there. Judged only where that window tells: no
    harmonic of omega_1 (2 or 3 omega_1) within the spectrum's resolution of it (near 0.73 m
    2 omega_1 meets omega_2, near 0.63, 0.84 and 0.98 m 3 omega_1), and a
    support soft enough to move omega_1's point by ``max_model_spread`` moves omega_2 /
    omega_1 by at least one of its standard uncertainties (not where the contact sits on a
    node of the second mode's shear, as near 0.49 m, nor where omega_2 moves with omega_1,
    as near 0.9 m). Notes ``second_mode_quality`` (the best peak's quality in the window)
    and ``support_coefficients`` (c_1, c_2, N/m).
    """
    x_c, omega1 = estimate.x_c, estimate.omega1
    cfg = evidence.config
    link = evidence.antenna.link
    if not _modes_judge(evidence, estimate):
        return None
    points, omegas = evidence.contact_modes
    if not points[0] <= x_c <= points[-1]:
        return None
    c_1, c_2 = support_coefficients(link, float(points[0]), x_c)
    u = mode_ratio_share(evidence)
    slope = abs(float(sensing_curve(link).omega1_slope(x_c)))
    # the stiffest support that moves omega_1's point by max_model_spread (inf at the top)
    reach = slope * cfg.max_model_spread / omega1
    if c_1 > 0.0 and reach > 0.0 and (c_2 - c_1) * reach / c_1 < u:
        return None
    ratio = float(np.interp(x_c, points, omegas[:, 1] / omegas[:, 0]))
    expected = ratio * omega1
    half = cfg.disagreement_sigmas * u
    window = (expected / (1.0 + half), expected * (1.0 + half))
    samples = _check3_window(evidence, end)
    if samples.stop - samples.start < 4:
        return None
    # a harmonic of omega_1 (a clipping contact's) within the spectrum's resolution of the
    # window, the Hann main lobe's half-width 4 pi / duration, merges with the mode: unreadable
    resolution = 4.0 * math.pi / ((samples.stop - samples.start) * evidence.sample_period)
    if any(abs(k * omega1 - expected) < half * expected + resolution for k in (2.0, 3.0)):
        return None
    component = str(estimate.diagnostics.get("torque_component", "sum"))
    projected = evidence.torque[samples] @ evidence.frame.axes_m[1:].T
    omega, power = power_spectrum(projected, evidence.sample_period, cfg.zero_padding)
    spectrum = {"y_c": power[:, 0], "z_c": power[:, 1]}.get(component, power.sum(axis=1))
    low, high = second_mode_band(evidence, omega1)
    band = (omega >= min(low, window[0])) & (omega <= max(high, window[1]))
    if not np.any(band):
        return None  # the second mode lies past the spectrum
    floor = float(np.median(spectrum[band]))
    peak = find_peak(omega, spectrum, window)
    quality = peak.power / floor if peak is not None and floor > 0.0 else 0.0
    notes["second_mode_quality"] = quality
    notes["support_coefficients"] = (c_1, c_2)
    if quality >= cfg.min_peak_quality:
        return None
    return (
        f"no second contact mode where a pinned contact at the answer {x_c:.3f} m rings it: "
        f"omega_1 {omega1:.1f} rad/s times the model's omega_2 / omega_1 = {ratio:.3f} puts it "
        f"at {expected:.0f} rad/s, and the spectrum holds no clear peak within "
        f"{100 * half:.0f} % of it (best {quality:.1f} times the median, "
        f"{cfg.min_peak_quality:g} asked). A contact that gives (a soft object: foam, rubber, a "
        f"stem) moves and damps the second mode and lowers omega_1 by {c_1:.1f} N/m over its "
        f"stiffness: at 100 N/m omega_1's point moves "
        f"{100 * c_1 / 100.0 * omega1 / slope if slope > 0 else math.inf:.1f} cm towards "
        "lower omega_1"
    )


#: How far the link's own damping ratio in a contact mode is taken to exceed the free mode's
#: (the free-motion observer's, Eq. 15): a material's loss factor changes little over the 2 to
#: 20 Hz of the first contact modes, and a pin that holds the link takes no energy from it
#: (an assumption, not a measured bound: docs/design-notes.md, "A slightly soft object").
_OWN_DAMPING_FACTOR = 2.0


#: The held joint's angle near omega_1 is judged beyond this many times its median amplitude
#: beside the band (half to twice omega_1, outside the main lobe about it) where that exceeds the
#: encoder's count (an encoder read finer than its noise): the largest of a few hundred bins of
#: noise lies within about three.
_HELD_NOISE_FACTOR = 10.0


def _base_motion_problem(
    evidence: Evidence, estimate: ContactEstimate, end: int, notes: dict[str, Any]
) -> str | None:
    """Why the swept joint's angle says the base moved near omega_1, or None.

    Over the samples check 3 reads (t_1 to the estimate's t_e, at most Delta t_e1: the same in
    the batch and the streaming forms), the held joint's angle near omega_1 beyond
    :data:`~.held_joint.COMPLIANCE_MARGIN` times what the link's torque turns it by (the
    joint's ``held_compliance``, measured by the calibration's posts) by more than an encoder
    count (or :data:`_HELD_NOISE_FACTOR` times the angle's noise, the larger): the base moving
    near omega_1 drives the head besides the link, a line the window cannot part from the
    contact's fundamental. Not judged without a measured compliance for the joint."""
    omega1 = float(estimate.omega1)
    if not (math.isfinite(omega1) and omega1 > 0.0):
        return None
    joint = swept_joint(evidence.push_turn[0])
    compliance = evidence.antenna.motors[joint].held_compliance
    if compliance is None:
        return None
    window = _check3_window(evidence, end)
    line = held_line(
        evidence.t[window],
        evidence.theta[window],
        evidence.torque[window],
        joint,
        omega1,
        compliance,
    )
    if line is None:
        return None
    if not math.isfinite(line.noise):
        return None  # a window too short to read the noise beside the band
    floor = max(line.count, _HELD_NOISE_FACTOR * line.noise)
    if not floor > 0.0:
        return None
    notes["held_angle_excess"] = line.excess / floor
    if not line.excess > floor:
        return None
    counts = f", {line.excess / line.count:.0f} encoder counts" if line.count > 0.0 else ""
    return (
        f"the {('azimuth', 'elevation')[joint]} joint's angle rings near omega_1 "
        f"({omega1:.1f} rad/s) by {line.excess:.2g} rad{counts} beyond what the link's torque "
        f"turns the held joint by ({COMPLIANCE_MARGIN:g} times the {compliance:.2g} rad/(N m) "
        "the calibration's posts measured): the base moving near omega_1 (a robot, a table "
        "rocking) puts a line beside the contact's fundamental that one window cannot part "
        "from it"
    )


#: Standard errors beyond which a line at omega_1 in the torques at rest before the contact is
#: a disturbance: white noise leaves one there by chance about once in 10^14; noise through a
#: sensor's second-order low-pass filter (its colour in the error) about once in a thousand at
#: 100 Hz, three times in a thousand at 50 Hz, over 80 to 200 samples of a channel.
_REST_LINE_SIGMAS = 8.0

#: Least amplitude of such a line over the contact's ringing at omega_1 (the torque channel
#: that rings most, over the samples check 3 reads) for it to matter: a line far below the
#: ringing moves no fit (a long, quiet rest finds lines of a fraction of a count).
_REST_LINE_SHARE = 0.05


def _rest_line_problem(
    evidence: Evidence, estimate: ContactEstimate, end: int, notes: dict[str, Any]
) -> str | None:
    """Why the torques at rest before the contact hold a line at the answer's omega_1, or None.

    Over each torque channel's rest at the start (the tare's, before t_c) a sinusoid at
    omega_1 (:func:`~.disturbance.rest_line`) beyond :data:`_REST_LINE_SIGMAS` standard errors
    and :data:`_REST_LINE_SHARE` of the contact's ringing at omega_1: a steady disturbance in
    the band, which the ringing's fit may read for the contact's mode. Not judged without a
    rest at the start or with less than half a period of omega_1 in it."""
    omega1 = float(estimate.omega1)
    if evidence.tare != "rest" or len(evidence.tare_samples) < 6:
        return None
    rests = tuple(min(n, evidence.contact_index) for n in evidence.tare_samples[3:6])
    line = rest_line(evidence.t, evidence.torque, rests, omega1)
    if line is None:
        return None
    notes["rest_line_sigmas"] = line.significance
    if not line.significance > _REST_LINE_SIGMAS:
        return None
    window = _check3_window(evidence, end)
    ringing = max(
        line_at(evidence.t[window], evidence.torque[window, k], omega1)[0] for k in range(3)
    )
    share = line.amplitude / ringing if ringing > 0.0 else math.inf
    notes["rest_line_share"] = share
    if not share > _REST_LINE_SHARE:
        return None
    return (
        f"the torques at rest before the contact already ring at omega_1 ({omega1:.1f} rad/s): "
        f"'{line.channel}' {line.amplitude:.2g} N m, {line.significance:.0f} standard errors, "
        f"over the {line.samples} samples of its rest: a steady disturbance in the band (a "
        "drive's PWM or a switching supply aliased by a sampler without an anti-alias filter, "
        "a machine nearby), which goes on through the hold and which the ringing's fit can take "
        "for the contact's mode: filter or shield it before the samples are read"
    )


def _widened_to_statics(
    evidence: Evidence, interval: tuple[float, float] | None, end: int, notes: dict[str, Any]
) -> tuple[float, float] | None:
    """``interval`` widened to hold the statics' reading at ``end`` within
    ``disagreement_sigmas`` of its uncertainty (noise, tare, statics model and the bent link at
    the reading), when the vibration's point may be a contact that gives, or a line beside the
    fundamental: a support's give, or a base moving near omega_1, moves omega_1 by an amount
    nothing measured bounds, the torque/force ratio hardly (the object's compliance is in
    series with the push, not in the lever; the base's motion averages out of the hold). The
    interval before goes to ``notes["interval_before_support"]``. None stays None: a method
    that gives no interval is not given one."""
    if interval is None or not end < evidence.ratio_mean.shape[0]:
        return interval
    reading = float(evidence.ratio_mean[end])
    if not math.isfinite(reading) or reading <= 0.0:
        return interval
    sigma = math.hypot(evidence.ratio_uncertainty(reading), evidence.bent_link_uncertainty(reading))
    reach = evidence.config.disagreement_sigmas * sigma
    length = evidence.antenna.link.length
    widened = (
        max(0.0, min(interval[0], reading - reach)),
        min(length, max(interval[1], reading + reach)),
    )
    if widened != interval:
        notes["interval_before_support"] = interval
    return widened


def _lossy_contact_problem(
    evidence: Evidence, estimate: ContactEstimate, end: int, notes: dict[str, Any]
) -> str | None:
    """Why the fundamental's ringing loses energy at the contact, or None.

    A pin holds the contact point still and takes no energy from the ringing; a contact that
    gives (foam, rubber, a stem: lossy as well as soft) moves with it and damps it. The
    fundamental's decay rate over the samples check 3 reads (t_1 to the estimate's t_e, at most
    Delta t_e1) is fitted with a second mode and a quadratic static part to the torque about
    Y^c and Z^c (:func:`~.methods.fast.parametric.fit_damped_sinusoids`); its damping ratio may
    exceed the link's own, the free-motion observer's (``observer.damping_ratio``), by
    :data:`_OWN_DAMPING_FACTOR`, plus ``disagreement_sigmas`` of its standard error. Beyond,
    the contact gives and omega_1 reads low by an amount the damping does not tell (a
    support's loss over its stiffness): ``uncertain``. A lossless soft support does not show
    here (:func:`_pinned_contact_problem` sees its second mode). Asked only where that check
    could not judge (the contact on a node of the second mode's shear, near 0.44 to 0.55 m and
    0.85 to 0.90 m on the paper's link; a harmonic over the second mode; a bent link): where the
    second mode rings in place it bounds the support's give, and a fundamental that still
    decays fast loses its energy to a stiff contact's friction (a box edge's, an answer 1.4 mm
    from the contact at 4 times the link's own damping), which moves omega_1 little. Notes
    ``fundamental_damping`` (ratio, standard error).
    """
    omega1 = estimate.omega1
    cfg = evidence.config
    if estimate.method == "ratio" or not (math.isfinite(estimate.x_c) and math.isfinite(omega1)):
        return None
    own = evidence.antenna.observer.damping_ratio
    if not own > 0.0:
        return None
    samples = _check3_window(evidence, end)
    projected = evidence.torque[samples] @ evidence.frame.axes_m[1:].T
    try:
        fit = fit_damped_sinusoids(
            projected,
            evidence.sample_period,
            2,
            min_omega=0.5 * omega1,
            degree=2,
            target_band=(omega1 / 1.1, omega1 * 1.1),
        )
    except (ValueError, np.linalg.LinAlgError):
        return None
    if fit is None or not fit.converged:
        return None
    k = int(np.argmin(np.abs(fit.omega - omega1)))
    if abs(float(fit.omega[k]) / omega1 - 1.0) > 0.05:
        return None  # not the answer's fundamental
    zeta = float(fit.decay[k] / fit.omega[k])
    sigma = float(fit.decay_se[k] / fit.omega[k])
    if not (math.isfinite(zeta) and math.isfinite(sigma)):
        return None
    notes["fundamental_damping"] = (zeta, sigma)
    bar = _OWN_DAMPING_FACTOR * own
    if not zeta - cfg.disagreement_sigmas * sigma > bar:
        return None
    return (
        f"the fundamental decays with a damping ratio of {zeta:.4f} +-{sigma:.4f}, more than "
        f"{_OWN_DAMPING_FACTOR:g} times the link's own in free motion ({own:.4f}, the "
        "observer's): the ringing loses energy at the contact, which a pin does not take. A "
        "contact that gives (a soft object: foam, rubber, a stem) lowers omega_1, and the "
        "answer with it, by an amount the damping does not tell"
    )


#: Farthest (m) a sensor's origin is taken to lie from the link's clamp along the link when a
#: disagreement between the answer and the ratio is read as torques about it: a sensor sits on
#: the head, its origin within centimetres of where the link is clamped.
_SENSOR_ORIGIN_REACH = 0.05


def _torque_point_hint(evidence: Evidence, x_c: float, end: int) -> str:
    """What to check when the answer and the torque/force ratio disagree, beyond the ratio's
    uncertainty and by no more than a sensor's origin can lie from O along the link, or "" (a
    ratio on the answer leaves the disagreement to other evidence: the second mode, say).

    Torques about a point S, (S - O) = (s, 0, 0) on the motor axes, read
    Gamma_S = Gamma_O - (S - O) x F: the ratio reads x_c - s at every contact, the frequency
    x_c.
    """
    reading = float(evidence.ratio_mean[end]) if end < evidence.ratio_mean.shape[0] else math.nan
    shift = x_c - reading
    if not (math.isfinite(shift) and abs(shift) <= _SENSOR_ORIGIN_REACH):
        return ""
    agreed = evidence.config.disagreement_sigmas * evidence.ratio_uncertainty(reading)
    if abs(shift) <= agreed:
        return ""
    uncalibrated = ""
    if evidence.antenna.link.calibrated_t is None:
        # an uncalibrated T moves the frequency's answer by an amount that varies along the link
        uncalibrated = (
            "; if it varies from contact to contact, calibrate first (antenna calibrate): no "
            "calibration measured the frequency model's T here"
        )
    return (
        f"; the torque/force ratio reads {reading:.3f} m, {100 * abs(shift):.1f} cm "
        f"{'short of' if shift > 0 else 'beyond'} the answer. If every contact shows this "
        "shift (drift, a gain or cross-talk vary it): torques about a point off the clamp along "
        "the link, the sensor's own origin, that '# torque_point' does not state or states "
        f"wrong? The ratio reads x_c less that point's offset along X^m: {shift:+.3f} m more "
        "in its first number (the whole point, when none is stated) would put the ratio on the "
        f"answer (docs/recording-format.md){uncalibrated}"
    )


#: A contact this close to the tip (m) may be made by the link's end face, whose normal need not
#: lie across the link: the friction cone is not judged there.
_TIP_ZONE = 0.005

#: Standard errors of the reaction the friction cone must be left by.
_FRICTION_SIGMAS = 3.0


def _friction_problem(
    evidence: Evidence, estimate: ContactEstimate, notes: dict[str, Any]
) -> str | None:
    """Why the static reaction cannot be held by friction at the answer's contact, or None.

    A point contact on the link's side has its normal across the link's tangent there; the
    tangent is the elastica's at x_c under the hold's reaction R (the loaded end of a cantilever
    of length x_c, :func:`~sensing_antenna.beam.elastica.loaded_end`; beyond its table the
    small-deflection slope 3 y_c / (2 x_c), Eq. 9). At rest the reaction
    lies inside the friction cone, |R_t| <= mu R_n (``max_friction_ratio``). Each component of
    the hold's mean reaction carries the tare's standard error and the hold mean's, bounded by
    twice the tare's; the force along the link also the moments' cross-talk into it, which no
    calibration here measures (the sensor's ``nominal_coupling`` times the moment x_c |R_perp|:
    on a long link the moment dwarfs the force); the ratio's standard error follows. Notes
    ``friction_ratio`` (R_t / R_n).
    """
    link = evidence.antenna.link
    x_c = estimate.x_c
    if not (math.isfinite(x_c) and 0.0 < x_c <= link.length - _TIP_ZONE):
        return None
    reaction = evidence.frame.reaction_m
    axial = float(reaction[0])
    across = math.hypot(float(reaction[1]), float(reaction[2]))
    if not across > 0.0:
        return None
    slope = loaded_end(x_c, axial, across, 1.0 / link.bending_compliance).slope
    if not math.isfinite(slope):
        # beyond the elastica's table: the small-deflection slope at the contact, 3 y_c / (2 x_c)
        slope = math.atan(0.5 * across * x_c**2 * link.bending_compliance)
    cos_t, sin_t = math.cos(slope), math.sin(slope)
    tangential = axial * cos_t + across * sin_t
    normal = across * cos_t - axial * sin_t
    if not normal > 0.0:
        ratio = math.inf
        sigma = 0.0
    else:
        ratio = tangential / normal
        component = 2.0 * evidence.offset_error
        # the axial force read c x_c |R_perp| off moves R_t by cos and R_n by -sin of the slope
        leak = evidence.antenna.sensor.nominal_coupling * x_c * across
        sigma = (
            math.hypot(component * math.hypot(1.0, ratio), leak * (cos_t + ratio * sin_t)) / normal
        )
    notes["friction_ratio"] = ratio
    mu = evidence.config.max_friction_ratio
    if abs(ratio) <= mu + _FRICTION_SIGMAS * sigma:
        return None
    lean = math.degrees(math.atan2(abs(tangential), normal))
    return (
        f"the reaction leans {lean:.0f} deg from the contact normal at x_c = {x_c:.3f} m "
        f"(tangential / normal {abs(ratio):.2f} +- {sigma:.2f}), outside a friction cone of "
        f"mu = {mu:g}: the contact slides, or it is not a point contact on the link's side"
    )


#: Fraction of ``max_model_spread`` beyond which the payload's effect is computed on the heavier
#: link's own sensing curve (a table of its eigenvalues, tens of ms) rather than scaled.
_EXACT_FROM = 0.25


def _payload_problem(
    evidence: Evidence, estimate: ContactEstimate, notes: dict[str, Any]
) -> str | None:
    """Why the link's weight at rest disagrees with the model enough to move the frequency's
    contact point, or None.

    The weight at rest read as a payload at the tip
    (:meth:`~.front.evidence.Evidence.payload_mass`) lowers omega_1(x_c). The check asks how
    far that would move the contact point the vibration gives (the point of the sensing curve a
    link with that mass would read the measured omega_1 at); beyond the paper method's
    ``max_model_spread`` the answer is a model mismatch. Methods that measure no
    vibration (``ratio``) are not judged: the weight does not enter the statics of the push.
    """
    link = evidence.antenna.link
    if not (math.isfinite(estimate.omega1) and math.isfinite(estimate.x_c)):
        return None
    if not 0.0 < estimate.x_c <= link.length:
        return None
    mass = evidence.payload_mass()
    if not mass > 0.0:
        return None
    excess = float(evidence.load_offset[4])
    try:
        heavier = dataclasses.replace(link, tip_mass=link.tip_mass + mass)
    except SensingAntennaError:
        return (
            f"at rest the link's moment ty is {excess:.3g} N m more than the model's weight: "
            f"{1e3 * mass:.3g} g at the tip, more than the link could carry; tare the sensor"
        )
    change = float(
        natural_frequencies(heavier, estimate.x_c, 1)[0]
        / natural_frequencies(link, estimate.x_c, 1)[0]
    )
    # The heavier link rings at omega_1 where the model's rings at omega_1 / change: the point
    # of the model's curve with that frequency nearest the answer, or, past the curve's top,
    # the stretch of the curve within the change
    curve = sensing_curve(link)
    moved = _on_branch(curve, estimate.x_c, curve.contact_points(estimate.omega1 / change))
    if moved:
        spread = min(abs(x - estimate.x_c) for x in moved)
    else:
        spread = model_spread(link, estimate.x_c, abs(1.0 - change))
    limit = evidence.config.max_model_spread
    if spread > _EXACT_FROM * limit:
        # Not small: the heavier link's own curve (a tip mass reshapes it near the tip, where
        # the one scale of the change at the answer does not hold)
        own = SensingCurve.from_link(heavier)
        exact = _on_branch(own, estimate.x_c, own.contact_points(estimate.omega1))
        if exact:
            spread = min(abs(x - estimate.x_c) for x in exact)
    notes["payload_moment"] = excess
    notes["payload_spread"] = spread
    if not spread > limit:
        return None
    if evidence.tare == "approach":
        # no rest at the start: the moment was read while the head moved towards the contact
        return (
            f"before the contact the link's moment ty reads {excess:.3g} N m more than the "
            "model's weight, over the approach (the recording does not start at rest, so the "
            "head's motion is in that reading): as a payload at the tip, "
            f"{1e3 * mass:.2g} g, it would move the contact point the vibration gives by "
            f"{100 * spread:.1f} cm, more than {100 * limit:g} cm; start the recording with "
            "half a second at rest to read the weight"
        )
    return (
        f"at rest the link's moment ty is {excess:.3g} N m more than the model's weight (the "
        f"offset a tare leaves is a few sensor counts): {1e3 * mass:.2g} g at the tip that the "
        f"antenna file does not carry would move the contact point the vibration gives by "
        f"{100 * spread:.1f} cm, more than {100 * limit:g} cm; give the payload in "
        f"link.tip_mass, or tare the sensor{_behind_the_clamp(link, excess)}"
    )


def _behind_the_clamp(link: Link, excess: float) -> str:
    """The other reading of a moment ``excess`` (N m) at rest beyond the link's weight: torques
    about a point s behind the clamp, where the weight W reads s W more (Gamma_S = Gamma_O -
    (S - O) x F), when s is within a sensor's origin's reach; "" otherwise."""
    behind = excess / ((link.mass + link.tip_mass) * STANDARD_GRAVITY)
    if not 0.0 < behind <= _SENSOR_ORIGIN_REACH:
        return ""
    return (
        f"; or, the same moment, torques taken about a point {100 * behind:.1f} cm behind the"
        f" clamp that the recording does not state ('{metadata_line((-behind, 0.0, 0.0))}',"
        " docs/recording-format.md)"
    )


def _on_branch(curve: Any, x_c: float, candidates: Any) -> list[float]:
    """The candidates (m) on the monotone branch of ``curve`` that holds ``x_c``."""

    def branch(x: float) -> int:
        return sum(1 for extremum in curve.extrema if extremum < x)

    return [c.x_c for c in candidates if branch(c.x_c) == branch(x_c)]


#: A push across the link within this many standard errors of a filtered, tared force may be
#: no push (a link still swinging from the sweep left 4 to 5 of them on the simulator after a
#: false detection at 4 times the sensor's noise; the default push read 12 at 0.9 m and about
#: 100 at 0.35 m at its noise): the push direction check then names a detector firing on the
#: free motion beside the signs, as a reading, not a verdict.
_WEAK_PUSH = 10.0


def _push_direction_problem(evidence: Evidence) -> tuple[Status, str] | None:
    """Why the push does not oppose the head's motion into the contact, or None.

    An obstacle can only push back: from where the push began (at t_c or a little before,
    :attr:`Evidence.push_onset_index`: a detector may fire late, after the head stopped) to t_1
    the head turns into it by dtheta, which moves the link along
    d = (0, dtheta_1 cos theta_2, dtheta_2) in the motor frame (the azimuth about
    Z^a moves X^m along cos theta_2 Y^m, the elevation along Z^m), and the mean reaction over the
    hold must have R . d < 0 (Y^c = -Y^m for an azimuthal push, Section 5.4). A sign flipped in
    one angle or in the forces turns it, during the push as over the hold
    (``implausible_input``), unless the reaction pushes across the turn by more than three of
    its standard errors (the low-passed noise and the tare's) and along it by no more: a
    contact on a surface steep to the sweep, where the link slides aside, pushes nearly across
    the turn. When the push's filtered reaction at t_1 did oppose the turn, by more than three
    of those errors, and the hold's does not, the signs are right and the contact moved: the
    link slid off the object or past it, and touches it from the other side if at all
    (``slip_suspected``). Not judged when the head turned by less than the rest tolerance.
    """
    turn, direction = evidence.push_turn
    tolerance = float(evidence.diagnostics.get("rest_tolerance", 0.0))
    if float(np.max(np.abs(turn))) <= tolerance:
        return None
    unit = direction / float(np.linalg.norm(direction))
    reaction = evidence.frame.reaction_m
    error = evidence.filtered_force_error
    along = float(reaction @ unit)
    across = float(np.linalg.norm(reaction[1:] - along * unit[1:]))
    if along <= 0.0 or (along <= 3.0 * error and across > 3.0 * error):
        return None  # it opposes the turn, or pushes across it, along it within its noise
    pushed = np.asarray(evidence.reaction_f[evidence.rest_index], dtype=float)
    if float(pushed @ unit) < -3.0 * error:
        return Status.SLIP_SUSPECTED, (
            f"the contact force opposed the head's turn into the contact while it pushed "
            f"({_vector(pushed)} N at t_1, filtered) but not over the hold after t_1 "
            f"({_vector(reaction)} N): the link slid off the object or past it"
        )
    lateral = float(np.linalg.norm(reaction[1:]))
    # a contact that sticks anywhere on the link bends it by the head's turn there: at the tip,
    # the weakest, it pushes back with 3 E I |turn| / l^2
    link = evidence.antenna.link
    sticking = 3.0 * float(np.linalg.norm(direction)) / (link.bending_compliance * link.length**2)
    untouched = ""
    if lateral <= _WEAK_PUSH * error:
        untouched = (
            f"; or the link touched nothing: a force of {lateral / error:.2g} standard errors "
            "is what a link still swinging from the sweep leaves, a detector firing on the free "
            "motion (its threshold below this device's residual: antenna identify on its free "
            "sweeps)"
        )
    elif lateral < sticking:
        untouched = (
            f"; or the link touched nothing: {1e3 * lateral:.3g} mN is less than a contact that "
            f"sticks anywhere on the link pushes back with for the head's turn "
            f"({1e3 * sticking:.3g} mN at the tip), a detector firing on the free motion (its "
            "threshold below what this link's swing leaves, or a link that swings more than "
            "the one it was identified on: antenna identify on its free sweeps)"
        )
    return Status.IMPLAUSIBLE_INPUT, (
        f"columns 'theta1', 'theta2', 'fx', 'fy', 'fz': the mean contact force over the hold "
        f"{_vector(reaction)} N does not oppose the head's turn into the contact "
        f"({_vector(turn)} rad from t = {float(evidence.t[evidence.push_onset_index]):.3f} s, "
        "where the push began, to t_1); an obstacle can only push back: a sign "
        "flipped in an angle or in the forces, the two angles swapped or one read from another "
        "joint (the joint mapping), or forces read wrong by as much as the push (cross-talk "
        f"from the torques, an offset){untouched}?"
    )


def _detected_before_touch(evidence: Evidence) -> str | None:
    """Why t_c is not the touch the hold reads, or None: the contact found at t_c was lost
    before the head came to rest at t_1 (the contact detector's residual, averaged over a free
    period, fell to a fifth of its largest and to the threshold, the fall dated before t_1:
    :func:`~sensing_antenna.detection.contact_watch.lost_before_rest`; the front end's
    ``contact_lost_before_rest`` is by when it had gone).
    The answer reads the hold after t_1 and may be right; the checks that start at t_c (the
    head's work and its turn against the push's bend) cannot be made."""
    lost = evidence.diagnostics.get("contact_lost_before_rest")
    if lost is None:
        return None
    t_c = float(evidence.t[evidence.contact_index])
    t_1 = float(evidence.t[evidence.rest_index])
    return (
        f"the contact found at t_c = {t_c:.3f} s faded before the head came to rest at t_1 = "
        f"{t_1:.3f} s (gone by {float(lost):.3f} s): the contact detector fired on something "
        "other than the touch the hold reads, and what starts at the touch (the push's bend "
        "against the head's turn) cannot be checked. Angles stamped late against the loads "
        "make the free-motion observer's prediction lag through the sweep's start (antenna "
        "identify names such a lag); a knock, hum on the torques, or a link that swings more "
        "than the one the threshold was identified on do the same"
    )


def _clipped_problem(evidence: Evidence, end: int) -> str | None:
    """Why the loads up to sample ``end`` may be clipped, or None: a reading at
    :data:`~sensing_antenna.antenna.RANGE_SHARE` of the sensor's range on its column or beyond
    (the antenna's ``sensor_range``; not judged without one). A clipped reading is a load the
    estimators cannot tell from one within range: the ratio, the push and the ringing all read
    it."""
    span = evidence.antenna.sensor_range
    if span is None:
        return None
    loads = np.column_stack([evidence.force[: end + 1], evidence.torque[: end + 1]])
    with np.errstate(invalid="ignore"):
        share = np.abs(loads) / span.limits
    share = np.where(np.isfinite(share), share, 0.0)  # a missing reading is no clipped one
    worst = share.max(axis=0)
    channel = int(np.argmax(worst))
    if not worst[channel] >= RANGE_SHARE:
        return None
    k = int(np.argmax(share[:, channel]))
    unit = "N" if channel < 3 else "N m"
    return (
        f"column {WRENCH_CHANNELS[channel]!r}: {float(loads[k, channel]):.4g} {unit} at t = "
        f"{float(evidence.t[k]):.3f} s, {100 * float(worst[channel]):.0f} % of the sensor's "
        f"range of {float(span.limits[channel]):g} {unit} (sensor_range): readings there may be "
        "clipped, which no estimate can tell from a load; push less far or less fast, or use a "
        "sensor of a larger range"
    )


def _head_turned(evidence: Evidence, end: int) -> bool:
    """Whether the head turned from t_c to sample ``end`` by more than the rest tolerance (an
    object pushed into a still link leaves the angles within it)."""
    tolerance = float(evidence.diagnostics.get("rest_tolerance", 0.0))
    turn = evidence.theta[end] - evidence.theta[evidence.contact_index]
    return float(np.max(np.abs(turn))) > tolerance


def _hold_end(evidence: Evidence, end: int) -> int:
    """The last sample up to ``end`` before the head turned back from its rest at t_1, against
    its turn from t_c, by half that turn (a retraction before t_e: the push eases and the link
    may leave the object); ``end`` when it did not."""
    rest, contact = evidence.rest_index, evidence.contact_index
    push = evidence.theta[rest] - evidence.theta[contact]
    size = float(np.linalg.norm(push))
    if not size > float(evidence.diagnostics.get("rest_tolerance", 0.0)):
        return end
    back = -(evidence.theta[rest : end + 1] - evidence.theta[rest]) @ (push / size)
    beyond = np.flatnonzero(back > 0.5 * size)
    return end if beyond.size == 0 else max(rest + int(beyond[0]) - 1, rest)


def _last_period_start(evidence: Evidence, omega: float, end: int) -> int:
    """First sample of the hold's last period of a fundamental ``omega`` (rad/s) before
    sample ``end``, not before t_1: the window over which the touch's ringing averages out."""
    period = max(periods_in(2.0 * math.pi / omega, evidence.sample_period), 1)
    return max(end - period, evidence.rest_index)


#: Least share of the energy the hold's push holds that must have been stored within the work's
#: count for the work to be judged against it: what was stored before is read from the moment
#: there, and a few per cent error on it weighs E_0 / (E - E_0) times on the share (three times
#: at this bound).
_LEAST_STORED_SHARE = 0.25


def _work_problem(
    evidence: Evidence, estimate: ContactEstimate, end: int, notes: dict[str, Any]
) -> tuple[Status, str] | None:
    """Why the head's turn did not put into the link the energy its push holds, with its
    status, or None.

    Passivity: the obstacle and the link store or dissipate what the head puts in. From
    ``tare_margin`` before t_c (not from the start: a sensor's drift over a long approach
    would weigh on the whole turn), or from the start when the record is shorter and began at
    rest, to t_e (sample ``end``; to where the head began to turn back when it did before t_e,
    :func:`_hold_end`), the head turns by dphi = 1/2 sum_i e_i x de_i (e_i the
    motor axes, absolute frame) and does the work W = -sum Gamma . dphi against the contact's
    moment about O. A push Gamma_perp
    across the link bent at x_c holds E = |Gamma_perp|^2 x_c / (6 E I) in it; the head must
    have put in what it holds at t_e (Gamma_perp averaged over the last period of the contact's
    fundamental before it) less what it held where the count starts (over the first), x_c the
    lesser of the answer and the torque/force ratio (an answer far out on the link, wrong, is
    not taken for angles that do not describe the turn). Two angle columns swapped on a sweep
    of one joint put the moment across the turn (share near 0); on a turn at alpha to a
    joint's axis the share is sin 2 alpha. W scales with the torques and E with their square:
    torques read k times high, or a link k times stiffer than the model, take 1 / k of the
    share, a unit (N dm, N cm for N m) a tenth or less. W must be at least ``min_work_share``
    of the energy put in (``model_mismatch``), and at least ``input_work_share`` of it
    (``implausible_input``), with three times the tare's torque error over the head's path as
    slack. Samples with a load or an angle not finite are left out, the turn across them
    counted as one step. ``notes`` gets ``work_share`` (W over the energy put in). Not judged
    when the recording starts less than ``tare_margin`` before t_c with the head moving (the
    touch may precede it), the head did not turn (an object pushed into a still link), or the
    push stored less than :data:`_LEAST_STORED_SHARE` of what it holds at t_e within the count
    (a detector that fired at the end of a slow push).
    """
    cfg = evidence.config
    t, k = evidence.t, evidence.contact_index
    if not _head_turned(evidence, end):
        return None
    end = _hold_end(evidence, end)  # a head turned back before t_e: counted to the turn
    if float(t[k] - t[0]) >= cfg.tare_margin:
        start = int(np.searchsorted(t, t[k] - cfg.tare_margin))
    elif evidence.tare == "rest":
        start = 0
    else:
        return None
    theta = evidence.theta[start : end + 1]
    moment = evidence.contact_loads_unfiltered[1][start : end + 1] - evidence.load_offset[3:]
    whole = np.isfinite(theta).all(axis=1) & np.isfinite(moment).all(axis=1)
    if np.count_nonzero(whole) < 2:
        return None
    theta, moment = theta[whole], moment[whole]
    axes = motor_axes(theta)
    middle, step = 0.5 * (axes[1:] + axes[:-1]), np.diff(axes, axis=0)
    turn = 0.5 * np.cross(middle, step).sum(axis=1)
    absolute = to_absolute(moment, theta)
    work = -float(np.einsum("ni,ni->", 0.5 * (absolute[1:] + absolute[:-1]), turn))
    link = evidence.antenna.link
    # the lesser of the answer and the statics' reading: a wrong answer far out is no swap
    ratio = estimate.ratio_estimate
    x_c = min(estimate.x_c, ratio) if 0.0 < ratio < math.inf else estimate.x_c
    period = end - _last_period_start(evidence, float(sensing_curve(link).omega1(x_c)), end)
    held = np.mean(moment[-max(period, 1) :, 1:], axis=0)
    before = np.mean(moment[: max(period, 1), 1:], axis=0)
    stored = float(held @ held) * x_c * link.bending_compliance / 6.0
    energy = stored - float(before @ before) * x_c * link.bending_compliance / 6.0
    if not energy >= _LEAST_STORED_SHARE * stored > 0.0:
        return None
    notes["work_share"] = work / energy
    slack = 3.0 * evidence.torque_offset_error * float(np.sum(np.linalg.norm(turn, axis=1)))
    if work + slack >= cfg.min_work_share * energy:
        return None
    found = (
        f"columns 'theta1', 'theta2', 'tx', 'ty', 'tz': from {float(t[start]):.3f} s to"
        f" {'t_e' if end == evidence.end_index else f'{float(t[end]):.3f} s'} "
        f"the head's turn did {1e3 * work:.3g} mJ of work against the contact's moment, "
        f"{100.0 * work / energy:.0f} % of the {1e3 * energy:.3g} mJ the push stored in the "
        f"link bent at x_c = {x_c:.3f} m meanwhile (at least "
    )
    if work + slack >= cfg.input_work_share * energy:
        return Status.MODEL_MISMATCH, (
            f"{found}{100.0 * cfg.min_work_share:g} %: the object and the link only store or "
            "dissipate what the head puts in); torques that read high (the share falls as one "
            "over their scale) or drifted since the tare, a link stiffer than the model, or "
            "angles that do not describe the turn (swapped on a sweep off a joint's axis)?"
        )
    return Status.IMPLAUSIBLE_INPUT, (
        f"{found}{100.0 * cfg.input_work_share:g} %: the object and the link only store or "
        "dissipate what the head puts in); the angles do not describe the turn that pushed, or "
        "the torques are not in N m: the two angles swapped, the torque axes swapped, torques "
        "in a unit smaller than N m, a link several times stiffer than the model, or an object "
        "that moved into the link?"
    )


def _untared(evidence: Evidence) -> str:
    """Why an answer from loads no tare corrected is not ``ok``."""
    t_c = float(evidence.t[evidence.contact_index])
    cfg = evidence.config
    return (
        f"the recording starts {1e3 * (t_c - float(evidence.t[0])):.0f} ms before the contact "
        f"(t_c = {t_c:.3f} s), too little to tare the sensor on (at least "
        f"{1e3 * (cfg.rest_window + cfg.tare_margin):.0f} ms free of contact): the push's size "
        "and direction, the torque/force ratio and the touched point carry the sensor's whole "
        "offset; start the recording with the head at rest for half a second"
    )


def _bend_at_touch(
    evidence: Evidence, k: int, bend_over: Any, push: np.ndarray, x_c: float, omega1: float
) -> tuple[float, float]:
    """The link's bend at t_c (sample ``k``) and its standard error (m, m).

    From t_c to t_1 the head turns into the object and the static bend grows along a line in
    the distance the rigid link's point x_c moved against the push (unit vector ``push``),
    while the touch sets the first two contact modes ringing: the bend from the unfiltered
    contact moment is fitted by least squares with a line in that distance and a sine and a
    cosine at each mode's frequency (the straight link's at x_c), and the line's value at t_c
    is the bend there. A push shorter than half a period of the fundamental (``omega1``, rad/s)
    cannot tell the line from the ringing: the bend before the touch, none, with infinite error
    (the bend since t_c is then at most the held one)."""
    last = max(evidence.rest_index, k)
    bends = bend_over(k, last)
    axes = motor_axes(evidence.theta[k : last + 1])[:, 0]
    moved = x_c * (axes - axes[0])
    moved = moved - np.einsum("ij,j->i", moved, axes[-1])[:, None] * axes[-1]
    reach = -(moved @ push)
    age = evidence.t[k : last + 1] - evidence.t[k]
    columns = [np.ones_like(age), reach]
    for omega in _contact_modes(evidence, x_c):
        columns += [np.sin(omega * age), np.cos(omega * age)]
    design = np.column_stack(columns)
    free = bends.size - design.shape[1]
    if age[-1] * omega1 >= math.pi and free >= 3 and float(np.ptp(reach)) > 0.0:
        fit, residual, rank, _ = np.linalg.lstsq(design, bends, rcond=None)
        if rank == design.shape[1] and residual.size:
            covariance = np.linalg.pinv(design.T @ design) * float(residual[0]) / free
            return float(fit[0]), math.sqrt(max(float(covariance[0, 0]), 0.0))
    return 0.0, math.inf


def _contact_modes(evidence: Evidence, x_c: float) -> tuple[float, float]:
    """omega_1 and omega_2 (rad/s) of the straight link in contact at ``x_c`` (m): read from
    :attr:`Evidence.contact_modes`, solved where ``x_c`` lies outside its grid."""
    grid, omegas = evidence.contact_modes
    if not grid[0] <= x_c <= grid[-1]:
        first, second = natural_frequencies(evidence.antenna.link, x_c, 2)
        return float(first), float(second)
    return float(np.interp(x_c, grid, omegas[:, 0])), float(np.interp(x_c, grid, omegas[:, 1]))


def _bend_against_turn(
    evidence: Evidence, estimate: ContactEstimate, end: int, notes: dict[str, Any]
) -> str | None:
    """Why the link's bend is not what the head's turn into the object makes, or None.

    From t_c to t_e the rigid link's point at x_c moves by u = x_c (X^m(theta_e) - X^m(theta_c));
    the object holds the touched point back, so the link bends by y along the reaction R, at an
    angle phi to -u. A contact that sticks stays where it touched: y = -u, phi = 0. One that slides
    with Coulomb friction mu stays on the surface of normal n, y (R^ . n) = -u . n, with R on the
    friction cone's edge between n and -u; then 1 - mu tan(phi) <= y / (-R^ . u) <= 1 on a flat
    surface. Sliding over a convex one of radius rho moves the contact out along the reaction by up
    to d^2 / (2 rho), d the head's reach across the push, which the upper bound allows for
    ``_LEAST_RADIUS`` (a convex surface only raises y, so the lower bound holds). A head that turned
    across the push or away from it (-R^ . u <= 0: a slide aside over a steep or curved surface, or
    joints swapped) is judged on the upper bound with no turn into the push, not on the lower one.
    Both vectors are taken across the link (X^m at t_e removed), mu is ``max_friction_ratio``, and
    ``max_bend_per_turn`` widens the band both ways for the forces' scale and the stiffness. The
    bends are the elastica's y_c of the answer scaled by the contact moment across the link over the
    moment of the push y_c was computed from (``push_force`` times the filtered torque/force ratio
    at t_e): at t_e the mean over the hold's last period of the contact's fundamental, at t_c
    :func:`_bend_at_touch` (the detector declares t_c once the push has built up), whose two
    standard errors widen the band. A push from t_c to t_1 shorter than half a period of the
    fundamental cannot tell the bend at t_c from the ringing: it is taken as none (the static
    bend before the touch), so the bend since t_c is at most the held one, and only the band's
    lower end is judged (a detector that fired on the free motion before a touch barely made
    counts a turn the link never felt). At a given push y grows as x_c^3 and u as x_c: an answer
    off the contact moves the ratio as (x_c / true x_c)^2. ``notes`` gets ``turn_against_push``
    (-R^ . u, m) and ``bend_per_turn`` (y over it). Not judged when the head turned by less than
    the rest tolerance (an object pushed into a still link).
    """
    bend = float(estimate.diagnostics.get("deflection", math.nan))
    if not (math.isfinite(bend) and bend > 0.0):
        return None
    axes_c = np.asarray(
        estimate.diagnostics.get("axes_c_absolute", evidence.frame.axes_a), dtype=float
    )
    k = evidence.contact_index
    if not _head_turned(evidence, end):
        return None
    x_axis = motor_axes(evidence.theta[end])[0]
    moved = estimate.x_c * (x_axis - motor_axes(evidence.theta[k])[0])
    moved = moved - (moved @ x_axis) * x_axis
    push = axes_c[1] - (axes_c[1] @ x_axis) * x_axis
    norm = float(np.linalg.norm(push))
    # the moment across the link that goes with the push y_c was computed from: the filtered
    # torque/force ratio at t_e (both lag alike) times that push
    filtered = np.asarray(evidence.torque_f[end, 1:], dtype=float)
    force = float(np.linalg.norm(evidence.reaction_f[end, 1:]))
    push_force = float(estimate.diagnostics.get("push_force", force))
    scale = float(np.linalg.norm(filtered)) * push_force / force if force > 0.0 else math.nan
    if not (norm > 0.0 and scale > 0.0):
        return None
    filtered = filtered / float(np.linalg.norm(filtered))

    def bend_over(first: int, last: int) -> np.ndarray:
        """The bend (m) the contact moment across the link gives at each sample."""
        moment = evidence.contact_loads_unfiltered[1][max(first, 0) : min(last, end) + 1]
        return bend * ((moment[:, 1:] - evidence.load_offset[4:]) @ filtered) / scale

    # the hold over one period of the contact's fundamental, which the touch sets ringing
    omega = float(sensing_curve(evidence.antenna.link).omega1(estimate.x_c))
    held = float(np.mean(bend_over(_last_period_start(evidence, omega, end), end)))
    touch, error = _bend_at_touch(evidence, k, bend_over, push / norm, estimate.x_c, omega)
    # the bend since t_c, and its least and largest values within two standard errors
    since = held - max(touch, 0.0)
    least_since = held - max(touch + 2.0 * error, 0.0)
    most_since = held - max(touch - 2.0 * error, 0.0)
    turn = -float(push @ moved) / norm
    notes["turn_against_push"] = turn
    if turn > 0.0:
        notes["bend_per_turn"] = since / turn
    cfg = evidence.config
    limit = cfg.max_bend_per_turn
    t_c = float(evidence.t[k])
    measured = (
        f"the measured push bent the link by {1e3 * since:.3g} mm at x_c = {estimate.x_c:.3f} m "
        f"from the touch at t_c = {t_c:.3f} s to t_e, while the angles move that point "
        f"{1e3 * turn:.3g} mm against the push"
    )
    # the head's reach across the push: a contact sliding over a convex object moves out along
    # its normal by up to that squared over twice the surface's radius
    reach = float(np.linalg.norm(moved))
    across = math.sqrt(max(reach**2 - max(turn, 0.0) ** 2, 0.0))
    curved = across**2 / (2.0 * _LEAST_RADIUS)
    if least_since > limit * max(turn, 0.0) + curved:
        if not turn > across:
            return (
                f"{measured}, and {1e3 * across:.3g} mm across it: more than a slide over a "
                f"surface curved to a radius of {1e3 * _LEAST_RADIUS:g} mm allows "
                f"({1e3 * curved:.2g} mm); the angles turn the head across the push that bent "
                "it, or away from it, more than into it (two joints swapped, or one read from "
                "another column or with its sign flipped; or an object that moved into the link, "
                "or forces that read high for the model's stiffness)"
            )
        return (
            f"{measured} (a contact that sticks bends the link as far as the head turned into "
            f"it, one that slides over a flat surface less; up to {limit:g} times that, plus "
            f"{1e3 * curved:.2g} mm for a slide over a surface curved to a radius of "
            f"{1e3 * _LEAST_RADIUS:g} mm, is allowed): forces that read high for the model's "
            "stiffness (the sensor's gain or cross-talk, which antenna calibrate fits), a link "
            "stiffer than the antenna file says, or angles that do not describe the head's turn "
            "(a joint read from the wrong column, a scale off)"
        )
    if not turn > 0.0:
        return None  # no turn into the push to bend the link at least as far as
    tan_phi = across / turn
    least = 1.0 - cfg.max_friction_ratio * tan_phi
    if not most_since * limit < least * turn:
        return None
    return (
        f"{measured}, {math.degrees(math.atan(tan_phi)):.0f} deg off the push (a contact "
        f"sliding with friction up to {cfg.max_friction_ratio:g} bends it at least "
        f"{least:.2f} times as far; down to 1/{limit:g} of that is allowed): an answer nearer "
        "the base than the contact (the bend at a given push grows as x_c^3, the head's reach "
        "as x_c), a contact found before the link touched, or forces that read low"
    )


def _vector(values: np.ndarray) -> str:
    return "(" + ", ".join(f"{v:.3g}" for v in values) + ")"


def _with_notes(estimate: ContactEstimate, notes: dict[str, Any]) -> ContactEstimate:
    changes: dict[str, Any] = {}
    for name in ("interval", "contact_point"):
        if name in notes:
            changes[name] = notes.pop(name)
    if notes:
        changes["diagnostics"] = {**estimate.diagnostics, **notes}
    return dataclasses.replace(estimate, **changes) if changes else estimate


#: How far past l a touched point may lie from the base (fraction of l). The elastica's contact
#: lies within x_c <= l of the base; the linear sag (6 % of l at the paper link's tip) across
#: the link adds 0.2 % of l; 10 % leaves room for a heavier link's sag.
_REACH_MARGIN = 0.1


def _within_reach(point: np.ndarray, evidence: Evidence) -> bool:
    """Whether a touched point (m, absolute frame) can be a point of the link: within
    l (1 + :data:`_REACH_MARGIN`) of the base. A point beyond comes from loads far outside the
    model (forces in mN: 20 m away). A point not computed (NaN) stays as it is."""
    if np.all(np.isnan(point)):
        return True
    reach = evidence.antenna.link.length * (1.0 + _REACH_MARGIN)
    with np.errstate(over="ignore", invalid="ignore"):
        distance = float(np.linalg.norm(point))
    return math.isfinite(distance) and distance <= reach


def _on_link(interval: tuple[float, float] | None, length: float) -> tuple[float, float] | None:
    """An interval (m) cut to the link [0, l]; None when not finite or off the link."""
    if interval is None:
        return None
    low, high = interval
    if not (math.isfinite(low) and math.isfinite(high)) or high < 0.0 or low > length:
        return None
    if 0.0 <= low and high <= length:
        return interval
    return (max(low, 0.0), min(high, length))


def _index_at(evidence: Evidence, t_e: float) -> int:
    """Index of the sample at ``t_e`` (s) in the evidence; its end when t_e is not known."""
    if not math.isfinite(t_e):
        return evidence.end_index
    index = int(np.searchsorted(evidence.t, t_e))
    return min(max(index, evidence.rest_index), evidence.end_index)


def _bent_link_problem(
    evidence: Evidence, estimate: ContactEstimate, notes: dict[str, Any]
) -> str | None:
    """Why the point the vibration gives may be more than ``max_model_spread`` off on a link
    the push bends, or None: the sensing curves are the straight link's, and the bent link's
    preload shifts its frequencies by up to ``Evidence.bent_link_uncertainty`` (a bound of the
    shift the rod showed), in whichever plane it was read; an omega_1 of the free plane's own
    mode by up to its own, smaller bound (:func:`_free_plane_spread`). Only for methods that
    read omega_1. Notes ``free_plane_spread`` when that bound was asked.
    """
    if not math.isfinite(estimate.omega1):
        return None
    shift = evidence.bent_link_uncertainty(estimate.x_c)
    limit = evidence.config.max_model_spread
    if not shift > limit:
        return None
    free = _free_plane_spread(evidence, estimate)
    if free is not None:
        notes["free_plane_spread"] = free
        if free <= limit:
            return None
    bend = float(evidence.push_deflection_ratio(estimate.x_c))
    # the term grows as the deflection squared, the deflection as the push
    gentler = math.sqrt(limit / shift)
    push = evidence.frame.lateral_force
    read = "omega_1 was not read in the free plane's own mode"
    if free is not None and math.isinf(free):
        read = (
            "the free plane's own mode has no bound computed beyond "
            f"{100 * FREE_PLANE_DEFLECTIONS[-1]:.0f} % deflection"
        )
    elif free is not None:
        read = f"read in the free plane's own mode it may be up to {100 * free:.1f} cm off"
    return (
        f"the push bends the link by {100 * bend:.0f} % of x_c at x_c = {estimate.x_c:.3f} m: "
        f"the sensing curves are the straight link's, and the bent link's preload may move the "
        f"point the vibration gives by up to {100 * shift:.1f} cm, more than {100 * limit:g} cm; "
        f"{read} (a push of {gentler * push:.2g} N or less, {100 * gentler * bend:.0f} % of "
        "x_c, keeps it within that here)"
    )


def _time_base_problem(
    evidence: Evidence, estimate: ContactEstimate, end: int, notes: dict[str, Any]
) -> str | None:
    """Why the time stamps from t_1 to t_e may run long by more than ``max_model_spread`` of
    the answer, or None: readings sent again in all six channels where the loads move fast, more
    than chance allows (:func:`~.front.held.repeated_rows`), stretch the record's time by their
    share when a logger stamped them as new samples, and omega_1 was read that much low; not
    when they stand in place of lost readings. Only for methods that read omega_1. Notes
    ``repeated_rows`` (count, steps, fast, expected, channel, in_place) when they are found.
    """
    if not math.isfinite(estimate.omega1):
        return None
    wrench = np.hstack([evidence.force[: end + 1], evidence.torque[: end + 1]])
    rows = repeated_rows(wrench, first=evidence.rest_index)
    if rows is None:
        return None
    notes["repeated_rows"] = {
        "count": rows.count,
        "steps": rows.steps,
        "fast": rows.fast,
        "expected": rows.expected,
        "channel": WRENCH_CHANNELS[rows.channel],
        "in_place": rows.in_place,
    }
    if rows.in_place:
        return None
    omega = estimate.omega1 / (1.0 - rows.share) if rows.share < 1.0 else math.inf
    points = _vibration_points(evidence, omega) if math.isfinite(omega) else ()
    limit = evidence.config.max_model_spread
    stretched = f"omega_1 = {omega:.1f} rad/s"
    if points:
        point = min(points, key=lambda c: abs(c - estimate.x_c))
        if abs(point - estimate.x_c) <= limit:
            return None
        there = (
            f"{stretched} would put the contact at {point:.3f} m, "
            f"{100 * abs(point - estimate.x_c):.1f} cm from the answer"
        )
    else:
        there = f"{stretched}, which lies on no point of the sensing curve, would move the answer"
    return (
        f"{rows.count} of the {rows.steps} samples from t_1 to t_e repeat the one before in all "
        f"six channels, {rows.fast} where the loads move fast ({WRENCH_CHANNELS[rows.channel]} at "
        f"{FAST_PACE:g} times its typical step), where chance gives about "
        f"{rows.expected:.2g}: a sensor or driver that sends a reading again. Stamped as new "
        f"samples they stretch the time by {100 * rows.share:.1f} %, and {there}, more than "
        f"{100 * limit:g} cm; stamp the samples where they were read, or leave out the repeats "
        "with their stamps"
    )


def _free_plane_spread(evidence: Evidence, estimate: ContactEstimate) -> float | None:
    """How far (m) from the answer the contact may lie when omega_1 is the free plane's own mode
    (the method's ``free_plane_mode``: :func:`~.methods.paper.planes.free_plane_mode`), None
    when it is not, inf where its bound is not known: out of its bending plane the pushed link
    rings within :func:`~sensing_antenna.beam.free_plane.free_plane_shift` of the straight
    link's omega_1 at the answer's deflection (the elastica's, else the linear statics'),
    widened by the mode's distance to a push-plane peak it may be merged with and by the
    answer's own distance to it; in quadrature with the frequency model's own spread at two
    standard deviations, as the push plane's term is (the paper method's "read in the push
    plane alone").
    """
    mode = estimate.diagnostics.get("free_plane_mode")
    if not isinstance(mode, dict):
        return None
    link = evidence.antenna.link
    x_c = estimate.x_c
    omega = float(mode["omega"])
    bend = float(estimate.diagnostics.get("deflection_ratio", math.nan))
    if not math.isfinite(bend):
        bend = float(evidence.push_deflection_ratio(x_c))
    relative = (
        free_plane_shift(x_c / link.length, bend)
        + float(mode["separation"])
        + abs(estimate.omega1 - omega) / omega
    )
    if not math.isfinite(relative):
        return math.inf
    own = model_spread(link, x_c, 2.0 * link.frequency_uncertainty)
    return math.hypot(model_spread(link, x_c, relative), own)


def _vibration_problems(
    evidence: Evidence, estimate: ContactEstimate, end: int, notes: dict[str, Any]
) -> list[tuple[Status, str]]:
    """Checks 3 and 4 of the module docstring."""
    cfg = evidence.config
    link = evidence.antenna.link
    omega1 = estimate.omega1
    if not math.isfinite(omega1):
        # Estimator 1 over the samples from t_1 to the estimate's t_e (at most Delta t_e1)
        window = _check3_window(evidence, end)
        measurement = measure_frequency(
            evidence.torque[window],
            evidence.frame.axes_m,
            evidence.sample_period,
            evidence.band,
            cfg.min_peak_quality,
            cfg.zero_padding,
            t_start=float(evidence.t[window.start]),
        )
        notes["plausibility_omega1"] = measurement.omega1
        notes["plausibility_peak_quality"] = measurement.quality
        if not measurement.clear:
            return [
                (
                    Status.NO_CLEAR_PEAK,
                    f"no clear vibration of the link in contact: no spectral peak in "
                    f"{evidence.band[0]:.1f} to {evidence.band[1]:.1f} rad/s reaches "
                    f"{cfg.min_peak_quality:g} times the median power "
                    f"(best {measurement.quality:.1f})",
                )
            ]
        omega1 = measurement.omega1
    candidates = _vibration_points(evidence, omega1)
    found: list[tuple[Status, str]] = []
    ratio = float(evidence.ratio_mean[end])
    for value, what in ((ratio, "the torque/force ratio"), (estimate.x_c, "the answer")):
        if not math.isfinite(value) or (what == "the answer" and not 0.0 < value <= link.length):
            continue
        nearest = min(candidates, key=lambda c: abs(c - value))
        notes.setdefault("vibration_contact_point", nearest)
        problem = _scale_problem(evidence, value, nearest, omega1)
        if problem is not None:
            found.append((problem[0], f"{what} {problem[1]}"))
    return found


#: A torque/force ratio this many times the vibration's contact point, or this fraction of it,
#: is loads in another unit (mN, N mm, kN: a factor 1000), not a model or a push gone wrong
#: (within a factor of a few): the status is ``implausible_input``, before the others.
_UNITS_FACTOR = 30.0


def _vibration_points(evidence: Evidence, omega1: float) -> tuple[float, ...]:
    """Where the vibration puts the contact: the points of the sensing curve with ``omega1``
    (rad/s), the nearest point when it lies above the curve, and the link's end l when the curve
    falls towards the tip and ``omega1`` lies below its value there by less than
    ``band_margin`` (a tip contact measured a little low has no exact point on the link)."""
    cfg = evidence.config
    link = evidence.antenna.link
    x_range = (cfg.contact_range[0] * link.length, cfg.contact_range[1] * link.length)
    candidates, _ = candidates_from_omega1(link, omega1, x_range)
    at_tip, falling = _tip(link)
    if falling and at_tip / (1.0 + cfg.band_margin) <= omega1 < at_tip:
        candidates = (*candidates, link.length)
    return candidates


@functools.lru_cache(maxsize=16)
def _tip(link: Link) -> tuple[float, bool]:
    """omega_1 (rad/s) of a contact at the tip, and whether the sensing curve falls there."""
    curve = sensing_curve(link)
    return float(curve.omega1(link.length)), float(curve.omega1_slope(link.length)) < 0.0


def _scale_problem(
    evidence: Evidence, value: float, nearest: float, omega1: float
) -> tuple[Status, str] | None:
    """Why ``value`` (m) is not the contact point ``nearest`` (m) the vibration gives, with its
    status (``implausible_input`` beyond :data:`_UNITS_FACTOR`), or None."""
    cfg = evidence.config
    factor = cfg.max_scale_mismatch
    quotient = value / nearest
    if 1.0 / factor <= quotient <= factor:
        return None
    # Noise and tare only: the model term grows with the push, so with the push scaled too
    sigma = evidence.ratio_uncertainty(nearest, model=False)
    if abs(value - nearest) <= cfg.disagreement_sigmas * sigma:
        return None
    units = not 1.0 / _UNITS_FACTOR < quotient < _UNITS_FACTOR
    return Status.IMPLAUSIBLE_INPUT if units else Status.MODEL_MISMATCH, (
        f"{value:.4g} m is {quotient:.3g} times the contact point {nearest:.3f} m where the "
        f"vibration (omega_1 = {omega1:.1f} rad/s) puts it (more than a factor {factor:g}, and "
        f"{cfg.disagreement_sigmas:g} statistical uncertainties of the ratio, {sigma:.3f} m, "
        "do not cover it): forces or torques scaled, or a wrench that is no contact?"
    )
