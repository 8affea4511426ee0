"""From the scan's final window to the :class:`~.result.ContactEstimate`.

The status and reason come from the checks' problems (:func:`.checks.problems`, in the order of
:data:`~.result.STATUS_PRECEDENCE`); at the cap, when the posterior still holds two branches,
the second contact mode may choose one (:func:`.second_mode.branch_at_cap`) and, on a link whose
calibration measured it, narrow an interval still too wide
(:func:`.second_mode.narrowed_by_second_mode`); the touched point
in 3D follows from the maximum a posteriori x_c and the contact frame.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.front.evidence import Evidence
from sensing_antenna.estimation.methods.fast.checks import (
    accepted_at_cap,
    frequency_check,
    frequency_sigma,
    problems,
    ratio_check,
)
from sensing_antenna.estimation.methods.fast.config import FastConfig, model_floor
from sensing_antenna.estimation.methods.fast.curves import contact_candidates, curve_table
from sensing_antenna.estimation.methods.fast.likelihood import ContactPosterior
from sensing_antenna.estimation.methods.fast.planes import free_plane_share
from sensing_antenna.estimation.methods.fast.search import ScanResult
from sensing_antenna.estimation.methods.fast.second_mode import (
    branch_at_cap,
    narrowed_by_second_mode,
    second_mode_chooser,
    second_mode_objection,
)
from sensing_antenna.estimation.methods.fast.static_fit import SensorBias
from sensing_antenna.estimation.methods.fast.window import WindowEstimate
from sensing_antenna.estimation.methods.touch_point import placement, touched_point
from sensing_antenna.estimation.result import STATUS_PRECEDENCE, ContactEstimate, Status

__all__ = ["conclude_fast"]


def conclude_fast(
    evidence: Evidence, result: ScanResult, bias: SensorBias, config: FastConfig, name: str
) -> ContactEstimate:
    """The :class:`ContactEstimate` of a scan: status, interval, branch probabilities, 3D point."""
    final = result.final
    t = evidence.t
    t_c = float(t[evidence.contact_index])
    t_1 = float(t[evidence.rest_index])
    diag: dict[str, Any] = dict(evidence.diagnostics)
    diag.update({"evaluations": result.evaluations, "bias_samples": bias.n_samples})
    if bias.n_samples == 0:
        diag["bias_note"] = "no initial rest: sensor bias not removed"
    if final is None:
        return ContactEstimate(
            status=Status.RECORDING_TOO_SHORT,
            reason="too few samples after t_1 for a first window",
            method=name,
            t_c=t_c,
            t_1=t_1,
            diagnostics=diag,
        )
    post = final.posterior
    # The branch edges do not change with conditioning: the candidates serve before and after
    candidates = contact_candidates(evidence.antenna.link, final.omega1, post, config)
    if final.second_mode:
        diag["second_mode"] = final.second_mode
    if final.branch_chosen_by_second_mode:
        diag["branch_chosen_by"] = "omega2"
    if result.reached_cap and not final.sure:
        # The final window's samples (from t_1 when it is too short), online and offline alike
        answers = accepted_at_cap(final, config)
        post, second_mode = branch_at_cap(evidence, final, candidates, answers)
        diag.update(second_mode)
        if post is not final.posterior:
            ratio_z, frequency_z = final.ratio_z, final.frequency_z
            if final.statics is not None:
                # The ratio's and the frequency's agreement judged again at the branch's maximum
                ratio_z, _, frequency_z, _ = _judged_at(evidence, final, post, config)
            final = dataclasses.replace(
                final, posterior=post, ratio_z=ratio_z, frequency_z=frequency_z
            )
            result = dataclasses.replace(result, final=final)
        # omega_2's narrowing reads the model's curves, which a payload the weight at rest
        # reads lowers as well: not with one
        if (
            (final.checks_passed or final.near_top)
            and not accepted_at_cap(final, config)
            and not np.any(evidence.payload_shifts(np.array([post.x_c])) > 0.0)
        ):
            final, narrowing = _narrowed(evidence, final, config)
            diag["second_mode_narrowing"] = narrowing
            result = dataclasses.replace(result, final=final)
            post = final.posterior
    statics = final.statics
    push = statics.perpendicular_force if statics is not None else math.nan
    # the axial part of the push is not fitted: the hold's, from the front end
    axial = float(evidence.frame.reaction_m[0])
    # the point where the contact was at the window's centre, where the fitted statics hold:
    # the link bends along the reaction it carries then, which has turned from the hold's
    # when the contact slid along the surface meanwhile
    turned = None
    if statics is not None:
        # and the head where it held over the window: a servo yields a little under the push
        held = np.mean(evidence.theta[final.start_index : final.end_index + 1], axis=0)
        turned = evidence.frame.turned_to(np.array([axial, *statics.reaction_perp]), held)
    if turned is not None:
        frame, t_point = turned, 0.5 * float(t[final.start_index] + t[final.end_index])
    else:
        # the hold's frame: its mean reaction over [t_1, t_1 + frame_window]
        frame = evidence.frame
        t_point = float(t[evidence.rest_index]) + 0.5 * evidence.config.frame_window
    touch = touched_point(post.x_c, frame, push, evidence.antenna.link, axial)
    found = problems(result, config)
    if "second_mode_objection" in diag:
        found.append((Status.ESTIMATORS_DISAGREE, diag["second_mode_objection"]))
    order = {status: rank for rank, status in enumerate(STATUS_PRECEDENCE)}
    found.sort(key=lambda item: order.get(item[0], len(order)))
    status, reason = found[0] if found else (Status.OK, None)
    narrowing = diag.get("second_mode_narrowing", {})
    # the one fault at the cap is the interval's width: every check passed, and the interval
    # is one spread (x_c near one of two points is none a map can take, unless one branch
    # holds the level's mass and the other a sliver the hull also covers)
    diag["held_back_by_width"] = bool(
        len(found) == 1
        and status is Status.UNCERTAIN
        and result.reached_cap
        and final.checks_passed
        and not narrowing.get("disagrees")
        and (len(post.pieces()) == 1 or max(post.branch_probability) >= post.level)
    )
    if reason is not None and narrowing.get("disagrees"):
        reason += f"; {narrowing['disagrees']}"
    link = evidence.antenna.link
    if (
        status is Status.UNCERTAIN
        and reason is not None
        and link.calibrated_t is not None
        and link.mode2_scatter is None
        and not config.higher_modes
        and (final.near_top or (final.checks_passed and post.width > config.cap_tolerance))
    ):
        reason += (
            "; a calibration that measures the second contact mode (link.mode2_scatter, five "
            "contacts or more) could let omega_2 narrow it"
        )
    if reason is not None and "branch_chosen_by" in diag:
        reason += (
            f"; the second contact mode then chose the branch of x_c = {post.x_c:.3f} m, and "
            "the interval is given on that branch"
        )
    if status is Status.UNCERTAIN and reason is not None and link.calibrated_t is None:
        reason += (
            f"; the antenna is not calibrated: its omega_1 is known to "
            f"{100 * link.frequency_uncertainty:.2g} % only (calibrate the antenna)"
        )
    branch_of = [post.branch_of(c) for c in candidates]
    diag.update(
        {
            "interval_width": post.width,
            "branch_edges": post.branch_edges,
            "branch_probability_by_branch": post.branch_probability,
            "omega1_se": final.omega1_se,
            "omega1_crb": final.omega1_crb,
            "omega1_drift": final.omega1_drift,
            "ratio_z": final.ratio_z,
            "frequency_z": final.frequency_z,
            "ratio_se": statics.standard_error if statics is not None else math.nan,
            "model_order": final.fit.n_modes if final.fit is not None else 0,
            "fit_through_push": final.fit is not None and final.fit.restart is not None,
            "modes": final.fit.omega if final.fit is not None else (),
            "free_plane_share": _free_plane_share(final, evidence.frame.reaction_m[1:]),
            # the plausibility layer judges the straight enough link on that plane's bound
            **(
                {"free_plane_mode": {"omega": final.omega1, "separation": 0.0}}
                if final.free_plane
                else {}
            ),
            "push_force": push,
            **placement(touch, frame, t_point),
            # the window's first sample: t_1, or later when the link bounced after t_1
            "window_start": float(t[final.start_index]),
            "note": final.note,
            "other_reasons": [text for _, text in found[1:]],
        }
    )
    return ContactEstimate(
        status=status,
        reason=reason,
        method=name,
        x_c=post.x_c,
        candidates=candidates,
        omega1=final.omega1,
        ratio_estimate=statics.ratio if statics is not None else math.nan,
        t_c=t_c,
        t_1=t_1,
        t_e=float(t[final.end_index]),
        contact_point=touch.point_a,
        diagnostics=diag,
        interval=post.interval,
        branch_probability=tuple(post.branch_probability[b] for b in branch_of),
    )


def _narrowed(
    evidence: Evidence, final: WindowEstimate, config: FastConfig
) -> tuple[WindowEstimate, dict[str, Any]]:
    """The window at the cap with the second contact mode in its posterior
    (:func:`.second_mode.narrowed_by_second_mode`), unchanged when the mode is not used.

    omega_2 places the contact where omega_1 is flat, so the peak margin no longer holds the
    answer back; every other check is judged again at the new maximum: the ratio, the
    frequency (omega_1 more than ``max_disagreement`` standard deviations above the curve's
    top is at no contact point), and the second-mode test of the other branch."""
    post, notes = narrowed_by_second_mode(evidence, final, final.posterior, config)
    if post is None:
        return final, notes
    ratio_z, ratio_note, frequency_z, frequency_note = _judged_at(evidence, final, post, config)
    objection, answer = second_mode_objection(
        post,
        contact_candidates(evidence.antenna.link, final.omega1, post, config),
        final.omega1,
        final.start_index,
        final.end_index,
        second_mode_chooser(evidence),
    )
    found = [text for text in (ratio_note, frequency_note, objection) if text]
    note = "; ".join(found)
    if not found and post.width > config.cap_tolerance:
        note = (
            f"the 95 % interval is {1000 * post.width:.1f} mm wide with the second contact "
            f"mode (cap tolerance {1000 * config.cap_tolerance:g} mm)"
        )
    narrowed = dataclasses.replace(
        final,
        posterior=post,
        ratio_z=ratio_z,
        frequency_z=frequency_z,
        checks_passed=not found,
        near_top=False,
        note=note,
    )
    info = {**notes, "interval_before": final.posterior.interval}
    if answer:
        info["second_mode_test"] = answer
    return narrowed, info


def _free_plane_share(final: WindowEstimate, push_direction: NDArray[np.float64]) -> float:
    """Share of the fundamental's signal in the free plane (:mod:`.planes`); NaN without one."""
    if final.fit is None or not math.isfinite(final.omega1):
        return math.nan
    k = int(np.argmin(np.abs(final.fit.omega - final.omega1)))
    return float(free_plane_share(final.fit, push_direction)[k])


def _judged_at(
    evidence: Evidence, final: WindowEstimate, post: ContactPosterior, config: FastConfig
) -> tuple[float, str, float, str]:
    """The window's ratio and frequency judged again at ``post``'s maximum: the ratio's
    distance in its standard deviations (:func:`.checks.ratio_check`, the window's own when it
    has no statics) and why it disagrees, then the frequency's (:func:`_frequency_judged`)."""
    ratio_z, ratio_note = final.ratio_z, ""
    if final.statics is not None:
        model_sd = float(evidence.ratio_model_uncertainty(np.array(post.x_c), coupling=True))
        ratio_z, ratio_note = ratio_check(final.statics, post.x_c, model_sd, config)
    frequency_z, note = _frequency_judged(evidence, final.omega1, final.omega1_se, post, config)
    return ratio_z, ratio_note, frequency_z, note


def _frequency_judged(
    evidence: Evidence,
    omega1: float,
    omega1_se: float,
    post: ContactPosterior,
    config: FastConfig,
) -> tuple[float, str]:
    """The frequency's distance from the sensing curve at ``post``'s maximum, in its standard
    deviations (:func:`.checks.frequency_check`, the bent link's and a payload's terms included
    as the windows have them, :func:`.search.scan_inputs`), and why it does not allow that
    maximum ("" when it does): farther from the curve there than ``max_disagreement`` standard
    deviations, or as far above the curve's top, where no contact point rings."""
    link = evidence.antenna.link
    table = curve_table(link, post.branch_edges[0], post.branch_edges[-1], config.grid_step)
    slope = float(np.interp(post.x_c, table.grid, table.slope))
    bent = slope * evidence.bent_link_uncertainty(post.x_c)
    payload = float(evidence.payload_shifts(np.array([post.x_c]))[0])
    sigma = frequency_sigma(omega1, omega1_se, model_floor(link, config), math.hypot(bent, payload))
    top = float(table.omega1.max())
    z, note = frequency_check(
        omega1, sigma, float(np.interp(post.x_c, table.grid, table.omega1)), post.x_c, top, config
    )
    if not note and math.isfinite(omega1) and omega1 - top > config.max_disagreement * sigma:
        note = (
            f"omega_1 = {omega1:.2f} rad/s is {(omega1 - top) / sigma:.1f} standard deviations "
            f"above the top of the sensing curve ({top:.2f} rad/s): no contact point rings so"
        )
    return z, note
