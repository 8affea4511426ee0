"""The growing-window search: every window on the evaluation grid, stopping when sure.

:func:`scan_inputs` gathers what every window of a manoeuvre reads from the pipeline's evidence
(the contact-load channels, the sensor bias, t_1, the omega_1 band, the prior range and the
push); :func:`evaluations` evaluates each window of the evaluation grid in turn
(:mod:`.evaluation_grid`) and :func:`scan` stops at the first sure one. The fits of one
recording are cached, so each window is fitted once.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from sensing_antenna.beam import free_plane_shifts
from sensing_antenna.estimation.front.evidence import Evidence
from sensing_antenna.estimation.methods.fast.config import FastConfig
from sensing_antenna.estimation.methods.fast.curves import curve_table
from sensing_antenna.estimation.methods.fast.evaluation_grid import evaluation_offsets
from sensing_antenna.estimation.methods.fast.second_mode import BranchChooser
from sensing_antenna.estimation.methods.fast.static_fit import (
    StaticsModel,
    contact_channels,
    sensor_bias,
)
from sensing_antenna.estimation.methods.fast.window import (
    ScanInputs,
    WindowEstimate,
    bounced_from_t1,
    evaluate_from_t1_or_hold,
    with_early_statics_of,
)
from sensing_antenna.estimation.methods.fast.window_fit import FitCache, push_phase

__all__ = ["ScanResult", "evaluations", "scan", "scan_inputs"]


def scan_inputs(evidence: Evidence, config: FastConfig) -> ScanInputs:
    """What every window of the manoeuvre reads, from the pipeline's evidence.

    The contact-load channels, the sensor bias from the initial rest (``bias_min_samples``,
    ``bias_guard``), t_1 and the last sample, T_s, the omega_1 band, the link, the prior range
    of x_c (``EstimatorConfig.contact_range``), with ``push_phase`` the push from t_c, and what
    every window reads from the front end: its filtered axial reaction, the model term of the
    elastica's statics and the bent link's uncertainty of omega_1 on the posterior's grid
    and the push's direction across the link (fixed once the hold has built the contact frame, so
    the same for every window, offline and online).
    """
    link = evidence.antenna.link
    channels = contact_channels(evidence.theta, evidence.force, evidence.torque, evidence.antenna)
    tolerance = float(evidence.diagnostics.get("rest_tolerance", 1e-4))
    bias = sensor_bias(
        channels,
        evidence.theta,
        evidence.contact_index,
        tolerance,
        config.bias_min_samples,
        guard=round(config.bias_guard / evidence.sample_period),
        settled=_rest_samples(evidence),
    )
    x_range = (
        evidence.config.contact_range[0] * link.length,
        evidence.config.contact_range[1] * link.length,
    )
    push = (
        push_phase(evidence.theta, evidence.contact_index, evidence.rest_index)
        if config.push_phase
        else None
    )
    table = curve_table(link, x_range[0], x_range[1], config.grid_step)
    # Loads beyond any sensor (a glitch of 1e155 N) overflow the bent link's term too (the
    # ratio's comes back infinite, which leaves the ratio out): not a number, no term
    bent = table.slope * evidence.bent_link_uncertainties(table.grid)
    # a payload the weight at rest reads and the model does not carry lowers omega_1 by as
    # much as its shift: the whole shift as the term's standard uncertainty, since the mass
    # read is itself uncertain and a sensor's offset may be in it
    payload = evidence.payload_shifts(table.grid)
    push_term = np.hypot(np.where(np.isfinite(bent), bent, 0.0), payload)
    # out of the push plane the bent link rings within the free plane's bound (taken as two
    # standard uncertainties), where it is known
    free = (
        0.5
        * table.omega1
        * free_plane_shifts(table.grid / link.length, evidence.push_deflection_ratio(table.grid))
    )
    statics = StaticsModel(
        evidence.reaction_f[:, 0],
        table.grid,
        evidence.ratio_model_uncertainty(table.grid, coupling=True),
        push_term,
        np.array(evidence.frame.reaction_m[1:], dtype=float),
        np.array(evidence.theta[:, 1], dtype=float),
        np.where(np.isfinite(free), np.hypot(free, payload), push_term),
    )
    return ScanInputs(
        channels,
        bias,
        evidence.rest_index,
        evidence.end_index,
        evidence.sample_period,
        evidence.band,
        link,
        x_range,
        config,
        push,
        statics,
    )


@dataclass(frozen=True)
class ScanResult:
    """Outcome of the growing-window search.

    Attributes
    ----------
    final : WindowEstimate or None
        The declared evaluation (sure), or the last one (unsure); None if none could run.
    evaluations : int
        Number of grid windows evaluated (the concluded window's early statics, added after,
        are not another evaluation).
    reached_cap : bool
        True when the search stopped at the cap without being sure.
    """

    final: WindowEstimate | None
    evaluations: int
    reached_cap: bool


def evaluations(
    inputs: ScanInputs,
    earliest: int = 0,
    hold_end: int = -1,
    choose_branch: BranchChooser | None = None,
    caches: tuple[FitCache, FitCache] | None = None,
    with_early_statics: bool = True,
) -> Iterator[WindowEstimate]:
    """Every window ending on the evaluation grid from ``earliest`` to the cap, in order.

    The grid is t_1 + :func:`~.evaluation_grid.evaluation_offsets`; evaluation starts at the
    first grid point at or after ``earliest`` and ends at the cap or at ``inputs.end_index``,
    whichever comes first. Each window starts at t_1, or at ``hold_end`` when the link bounced
    in this evaluation's window from t_1 or an earlier one's
    (:func:`.window.evaluate_from_t1_or_hold`; -1: always t_1). The fits of one recording are
    cached, so the drift check's shorter windows are fitted once; ``caches`` (windows from t_1,
    windows from the hold's end) are used and filled when given, else new ones (a cache never
    serves a fit made with other settings). ``choose_branch`` and ``with_early_statics`` as in
    :func:`.window.evaluate_from_t1_or_hold`. A bounce is carried to later evaluations from
    those at or after ``hold_end``, the method's own (:meth:`.FastMethod.history` from t_1 and
    the information bound read earlier ones too, which must not change the method's windows).
    """
    if caches is None:
        caches = ({}, {})
    bounced: tuple[float, float] | None = None
    for offset in evaluation_offsets(inputs.sample_period, inputs.config):
        j = inputs.rest_index + int(offset)
        if j < earliest:
            continue
        if j > inputs.end_index:
            return
        window = evaluate_from_t1_or_hold(
            inputs._replace(end_index=j),
            hold_end,
            caches,
            choose_branch,
            with_early_statics,
            bounced,
        )
        bounced = bounced_from_t1(window, inputs, bounced, hold_end)
        yield window


def scan(
    inputs: ScanInputs,
    earliest: int = 0,
    hold_end: int = -1,
    choose_branch: BranchChooser | None = None,
    caches: tuple[FitCache, FitCache] | None = None,
) -> ScanResult:
    """Evaluate the growing window on the evaluation grid until sure, the cap or the samples' end.

    The windows are those of :func:`evaluations` (``caches`` as there); ``earliest`` is the end
    of the pipeline's hold, before which there is no contact frame. With the direction check on,
    only the window concluded on gets the slip check's early statics (they do not decide
    ``sure``), added after from the cached fits (:func:`.window.with_early_statics_of`).
    """
    if caches is None:
        caches = ({}, {})
    last = inputs.rest_index + int(evaluation_offsets(inputs.sample_period, inputs.config)[-1])
    final: WindowEstimate | None = None
    count = 0
    for final in evaluations(inputs, earliest, hold_end, choose_branch, caches, False):
        count += 1
        if final.sure:
            break
    if final is None:
        return ScanResult(None, 0, last <= inputs.end_index)
    final = with_early_statics_of(inputs, final, caches)
    return ScanResult(final, count, not final.sure and last <= inputs.end_index)


def _rest_samples(evidence: Evidence) -> tuple[int, ...] | None:
    """Samples of the front end's tare at rest on each contact channel (R_y, R_z, Gamma_x,
    Gamma_y, Gamma_z: where each channel's load settled), None without one."""
    if evidence.tare != "rest" or not evidence.tare_samples:
        return None
    return evidence.tare_samples[1:]
