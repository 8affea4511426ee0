"""One evaluation of the growing window: its fundamental and statics, the posterior over x_c,
the checks, and whether it is sure.

:func:`evaluate_window` measures the window's fundamental (:mod:`.window_fit`; through the
push when that fit stands, :func:`.checks.push_agrees`) and its static torque/force ratio
(:mod:`.static_fit`), forms the posterior over x_c (:mod:`.likelihood`), lets the second
contact mode choose between two branches (:mod:`.second_mode`) and runs the checks
(:mod:`.checks`). :func:`evaluate_from_t1_or_hold` restarts the window at the end of the
pipeline's hold when the link bounced (the contact opened, or the push plane rang at two
fundamentals), and keeps it there at later evaluations once it has (:func:`bounced_from_t1`);
:func:`with_early_statics_of` adds the slip check's reference, the statics of the window's
first half.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Link
from sensing_antenna.estimation.methods.fast.checks import (
    branch_contradiction,
    frequency_check,
    frequency_sigma,
    is_slip_reference,
    opening_check,
    other_fundamental,
    peak_check,
    periods_held,
    push_agrees,
    ratio_check,
)
from sensing_antenna.estimation.methods.fast.config import FastConfig, model_floor
from sensing_antenna.estimation.methods.fast.curves import contact_candidates, curve_table
from sensing_antenna.estimation.methods.fast.evaluation_grid import reference_index
from sensing_antenna.estimation.methods.fast.likelihood import ContactPosterior, contact_posterior
from sensing_antenna.estimation.methods.fast.parametric import DampedSinusoidFit
from sensing_antenna.estimation.methods.fast.planes import free_plane_share
from sensing_antenna.estimation.methods.fast.second_mode import (
    BranchChooser,
    on_chosen_branch,
    second_mode_objection,
)
from sensing_antenna.estimation.methods.fast.static_fit import (
    SensorBias,
    StaticRatio,
    StaticsModel,
    static_ratio,
)
from sensing_antenna.estimation.methods.fast.window_fit import (
    FitCache,
    PushPhase,
    WindowSpan,
    fit_window,
    measure_fundamental,
)

__all__ = [
    "ScanInputs",
    "WindowEstimate",
    "bounced_from_t1",
    "evaluate_from_t1_or_hold",
    "evaluate_window",
    "with_early_statics_of",
]

FloatArray = NDArray[np.float64]


class ScanInputs(NamedTuple):
    """The samples and model a window reads: :func:`evaluate_window`'s leading arguments, in order.

    ``end_index`` is the last sample available; :func:`.search.evaluations` replaces it by each
    window's end.
    """

    channels: FloatArray
    bias: SensorBias
    rest_index: int
    end_index: int
    sample_period: float
    band: tuple[float, float]
    link: Link
    x_range: tuple[float, float]
    config: FastConfig
    push: PushPhase | None = None
    statics_model: StaticsModel | None = None


@dataclass(frozen=True)
class WindowEstimate:
    """One evaluation of the growing window [t_s, t_j] (t_s: t_1, or later when the link bounced).

    Attributes
    ----------
    start_index : int
        First sample of the window: t_1, or, when the link bounced (the contact opened or the
        push plane rang at two fundamentals), the end of the hold or a hold's length later. A fit
        through the push (``FastConfig.push_phase``) reaches back to t_c; its ``restart`` is
        then t_1's place in it.
    end_index : int
        j, the last sample used.
    fit : DampedSinusoidFit or None
        The chosen fit of the contact-load channels (None: too few samples or no pole).
    omega1, omega1_se : float
        Fundamental and its standard error (rad/s): the fit's statistical error and
        ``drift_factor`` times the drift, in quadrature (the relative model floor is added by
        the posterior); NaN when not usable.
    omega1_crb : float
        Cramer-Rao bound of omega_1 for this record length and noise (rad/s): the square root
        of the inverse Fisher information of the fitted model at the fitted parameters and the
        residual noise (the statistical part of ``omega1_se``); NaN when not usable.
    statics : StaticRatio or None
        The static torque/force ratio.
    posterior : ContactPosterior
    sure : bool
        ``checks_passed`` and the interval no wider than the tolerance, or ``settled``.
    checks_passed : bool
        True when every check but the interval's width passes (usable frequency, periods in
        the window, drift, ratio agreement, contact closed, one fundamental in the push plane
        and, started again after two, long enough to tell them apart, away from the top of the
        curve):
        ``sure`` at any tolerance at least the interval's width.
    note : str
        Why the frequency was not used or why it is not sure (empty when sure).
    omega1_drift : float
        Change of omega_1 from the window's first 2/3 beyond what the noise explains (rad/s).
    early_statics : StaticRatio or None
        Statics of the window's first half (the slip reference); None when that half holds
        fewer than ``min_periods`` periods, has no mode near the whole window's fundamental, or
        when not added (:func:`evaluate_window` leaves them to :func:`with_early_statics_of`,
        which adds them only for the direction check).
    ratio_z : float
        Distance of the ratio from the MAP x_c in its standard deviations.
    frequency_z : float
        Distance of omega_1 from the sensing curve at the MAP x_c in its standard deviations
        (NaN when omega_1 is not usable or above the curve's maximum).
    opening : float
        Predicted vibration amplitude of the contact force over the static push at the window
        start (> 1: the contact opens); NaN when not computed.
    fundamentals : tuple of float
        The push plane's two fundamentals when the window rang at two (rad/s,
        :func:`~.checks.other_fundamental`): the link was not held at one point over it. NaN,
        NaN when it rang at one.
    branch_contradicted : bool
        True when a higher mode of the fit points to another branch than the posterior's.
    branch_chosen_by_second_mode : bool
        True when the posterior held two branches and the second contact mode chose one
        (``FastConfig.branch_by_second_mode``); ``posterior`` is then conditioned on it.
    second_mode : dict
        What the second contact mode's test reported when it was asked (empty otherwise).
    settled : bool
        True when the window is sure although its interval is wider than the tolerance: within
        ``cap_tolerance``, long enough for the slip check's reference, and within
        ``settled_margin`` of the narrowest width unlimited data could leave (the model
        floors'), so waiting for the cap would narrow it little.
    near_top : bool
        True when every check passed but the peak margin: omega_1 is within ``peak_margin``
        standard deviations of the top of the sensing curve, or above it, where it does not
        place x_c.
    free_plane : bool
        True when omega_1 is the free plane's own mode (the fitted fundamental vibrates mostly
        out of the push plane, :mod:`.planes`): its model term is the free plane's bound
        (``StaticsModel.free_omega1_sd``), not the bent link's.
    """

    start_index: int
    end_index: int
    fit: DampedSinusoidFit | None
    omega1: float
    omega1_se: float
    omega1_crb: float
    statics: StaticRatio | None
    posterior: ContactPosterior
    sure: bool
    checks_passed: bool
    note: str
    omega1_drift: float = math.nan
    early_statics: StaticRatio | None = None
    ratio_z: float = math.nan
    frequency_z: float = math.nan
    opening: float = math.nan
    fundamentals: tuple[float, float] = (math.nan, math.nan)
    branch_contradicted: bool = False
    branch_chosen_by_second_mode: bool = False
    second_mode: dict[str, Any] = field(default_factory=dict)
    settled: bool = False
    near_top: bool = False
    free_plane: bool = False


def evaluate_window(
    channels: FloatArray,
    bias: SensorBias,
    rest_index: int,
    end_index: int,
    sample_period: float,
    band: tuple[float, float],
    link: Link,
    x_range: tuple[float, float],
    config: FastConfig,
    push: PushPhase | None = None,
    statics_model: StaticsModel | None = None,
    cache: FitCache | None = None,
    choose_branch: BranchChooser | None = None,
) -> WindowEstimate:
    """Fit the window [rest_index, end_index] and form the posterior over x_c.

    The slip check's early statics (the fit of the window's first half) enter neither the
    posterior nor ``sure``: they are left out (None), and :func:`with_early_statics_of` adds
    them to the window that is concluded on.

    Parameters
    ----------
    channels : array, shape (n, 5)
        :func:`~.static_fit.contact_channels` of the samples (at least up to ``end_index``).
    bias : SensorBias
    rest_index, end_index : int
        Indices of t_1 and of the last sample used.
    sample_period : float
        T_s (s).
    band : tuple of float
        omega_1 band (rad/s).
    link : Link
    x_range : tuple of float
        Prior range of x_c (m).
    config : FastConfig
    push : PushPhase, optional
        With it, every window fitted here reaches back to the push's start
        (``FastConfig.push_phase``); None: windows start at ``rest_index``.
    statics_model : StaticsModel, optional
        The front end's filtered axial reaction, the statics' model term on the posterior's grid
        (:func:`.search.scan_inputs`); None: neither (no axial force, no model term).
    cache : dict, optional
        Window fits keyed by the windows' own samples (:data:`FitCache`); the drift check's
        shorter windows are taken from it (and added to it). The scan and an online session
        pass one; None refits.
    choose_branch : BranchChooser, optional
        When the posterior holds two branches of omega_1(x_c), asked which candidate the
        window supports (:func:`.second_mode.second_mode_chooser`); the posterior is
        conditioned on its answer before the checks. None: not asked.

    Returns
    -------
    WindowEstimate
    """
    statics_model = statics_model if statics_model is not None else StaticsModel()
    direction = statics_model.push_direction
    span = WindowSpan(channels, rest_index, end_index, sample_period, band, config, cache)
    from_t1 = measure_fundamental(span, None, direction)
    frequency = from_t1
    if push is not None:
        through = measure_fundamental(span, push, direction)
        if push_agrees(through, from_t1, config):
            frequency = through
    fit, k = frequency.fit, frequency.mode
    omega1, omega1_se, omega1_crb = frequency.omega1, frequency.omega1_se, frequency.omega1_crb
    drift = frequency.drift
    notes = list(frequency.notes)
    fundamentals = (math.nan, math.nan)
    if fit is not None and k is not None:
        first, second, note = other_fundamental(fit, k, band, direction, config)
        fundamentals = (first, second)
        if note:
            notes.append(note)
    # The statics from the window from t_1 always: a fit through the push has its static part
    # at the centre of [t_c, t], inside the push for short windows, while the opening check
    # compares it with the vibration at t_1
    statics = (
        static_ratio(
            from_t1.fit,
            bias,
            statics_model.axial_at(end_index),
            link,
            statics_model.elevation_at(end_index),
        )
        if from_t1.fit is not None
        else None
    )
    table = curve_table(link, x_range[0], x_range[1], config.grid_step)
    frequency_floor = model_floor(link, config)
    omega_h = omega_h_se = math.nan
    if config.higher_modes and fit is not None and math.isfinite(omega1):
        omega_h, omega_h_se = _higher_mode(fit, omega1, table.higher, config)
    ratio = statics.ratio if statics is not None else math.nan
    ratio_se = statics.standard_error if statics is not None else math.nan
    push_force = statics.perpendicular_force if statics is not None else 0.0
    ratio_model = _on_grid(statics_model.model_sd, table.grid)
    # a fundamental that vibrates mostly out of the push plane is the free plane's own mode
    free_plane = bool(
        direction is not None
        and fit is not None
        and k is not None
        and free_plane_share(fit, direction)[k] > 0.5
    )
    frequency_model = _on_grid(statics_model.frequency_sd(free_plane), table.grid)

    def posterior_with(
        omega: float, frequency_se: float, ratio_se: float, higher_se: float
    ) -> ContactPosterior:
        return contact_posterior(
            table.omega1,
            table.grid,
            table.edges,
            omega,
            frequency_se,
            ratio,
            ratio_se,
            ratio_model,
            frequency_floor,
            higher_modes_of_x=table.higher,
            omega_higher=omega_h,
            omega_higher_se=higher_se,
            higher_mode_floor=config.higher_mode_floor,
            frequency_model=frequency_model,
        )

    posterior = posterior_with(omega1, omega1_se, ratio_se, omega_h_se)
    chosen = False
    second_mode: dict[str, Any] = {}
    if (
        choose_branch is not None
        and config.branch_by_second_mode
        and max(posterior.branch_probability) < posterior.level
    ):
        candidates = contact_candidates(link, omega1, posterior, config)
        if len(candidates) == 2:
            choice, second_mode = choose_branch(rest_index, end_index, omega1, candidates)
            conditioned = on_chosen_branch(posterior, candidates, choice)
            chosen = conditioned is not None
            posterior = conditioned or posterior
    ratio_z = math.nan
    if statics is not None and math.isfinite(omega1):
        ratio_z, disagreement = ratio_check(
            statics, posterior.x_c, statics_model.sd_at(posterior.x_c), config
        )
        if disagreement:
            notes.append(disagreement)
    frequency_z = math.nan
    if math.isfinite(omega1):
        frequency_z, note = frequency_check(
            omega1,
            frequency_sigma(
                omega1,
                omega1_se,
                frequency_floor,
                statics_model.omega1_sd_at(posterior.x_c, free_plane),
            ),
            float(np.interp(posterior.x_c, table.grid, table.omega1)),
            posterior.x_c,
            float(table.omega1.max()),
            config,
        )
        if note:
            notes.append(note)
    opening = math.nan
    if fit is not None and k is not None and push_force > 0.0:
        opening, note = opening_check(fit, k, push_force, link, posterior.x_c, config)
        if note:
            notes.append(note)
    contradiction = ""
    if fit is not None and k is not None:
        contradiction = branch_contradiction(fit, k, posterior, table, link, config)
        if contradiction:
            notes.append(contradiction)
    near_top = False
    if not notes and math.isfinite(omega1) and not math.isfinite(omega_h):
        # No declaration near the top of omega_1(x_c), unless a higher contact mode (whose
        # curves do not peak there) enters the posterior
        note = peak_check(omega1, omega1_se, frequency_floor, float(table.omega1.max()), config)
        if note:
            notes.append(note)
            near_top = True
    settled = (
        not notes
        and config.settled_margin > 0.0
        and config.tolerance < posterior.width <= config.cap_tolerance
        # the ratio's model term must bound it where its statistical error goes
        and (not math.isfinite(ratio) or bool(np.all(np.asarray(ratio_model) > 0.0)))
        # twice min_periods, which a window reaching the cap holds anyway; with the direction
        # check on, its first half is the slip check's reference
        and fit is not None
        and periods_held(fit, omega1) >= 2.0 * config.min_periods
        and posterior.width
        <= (1.0 + config.settled_margin)
        * _floors_width(posterior, posterior_with, omega1, omega1_crb, chosen)
    )
    if (
        not notes
        and not chosen
        and (posterior.width <= config.tolerance or settled)
        and choose_branch is not None
        # a settled window skips the cap, which would have asked
        and (config.branch_by_second_mode or settled)
        and math.isfinite(omega1)
    ):
        # About to declare one branch of two: the second contact mode, evidence independent of
        # the ratio that chose the branch, must not point to the other one
        objection, answer = second_mode_objection(
            posterior,
            contact_candidates(link, omega1, posterior, config),
            omega1,
            rest_index,
            end_index,
            choose_branch,
        )
        if answer:
            second_mode = answer
        if objection:
            notes.append(objection)
            contradiction = objection
    checks_passed = not notes
    if not notes and posterior.width > config.tolerance and not settled:
        notes.append(
            f"the 95 % interval is {1000 * posterior.width:.1f} mm wide "
            f"(tolerance {1000 * config.tolerance:g} mm)"
        )
    return WindowEstimate(
        start_index=rest_index,
        end_index=end_index,
        fit=fit,
        omega1=omega1,
        omega1_se=omega1_se,
        omega1_crb=omega1_crb,
        statics=statics,
        posterior=posterior,
        sure=not notes,
        checks_passed=checks_passed,
        note="; ".join(notes),
        omega1_drift=drift,
        early_statics=None,
        ratio_z=ratio_z,
        frequency_z=frequency_z,
        opening=opening,
        fundamentals=fundamentals,
        branch_contradicted=bool(contradiction),
        branch_chosen_by_second_mode=chosen,
        second_mode=second_mode,
        settled=settled and not notes,
        near_top=near_top,
        free_plane=free_plane,
    )


#: The floors' width is taken as its smallest at omega_1 and this many of its Cramer-Rao
#: standard errors either side: where the width moves with omega_1 (near the top of the sensing
#: curve), the omega_1 unlimited data would read may leave a narrower interval than the current
#: one.
_FLOORS_SPAN = 2.0


def _floors_width(
    posterior: ContactPosterior,
    posterior_with: Callable[[float, float, float, float], ContactPosterior],
    omega1: float,
    omega1_crb: float,
    chosen: bool,
) -> float:
    """Width (m) of the 95 % interval that unlimited data could leave: every statistical error
    gone (omega_1's with its drift term, since a longer window outgrows a transient; the
    ratio's; a higher mode's), the model floors kept, the narrowest at omega_1 and
    :data:`_FLOORS_SPAN` of its Cramer-Rao standard errors either side; on the same branch
    when the second mode chose one."""
    widths = []
    for k in (-_FLOORS_SPAN, 0.0, _FLOORS_SPAN):
        limit = posterior_with(omega1 + k * omega1_crb, 0.0, 0.0, 0.0)
        if chosen:
            limit = limit.given_branch(limit.branch_of(posterior.x_c))
        widths.append(limit.width)
    return min(widths)


def _on_grid(values: FloatArray | None, grid: FloatArray) -> float | FloatArray:
    """``values`` given at every point of ``grid``, else 0 (no term)."""
    return values if values is not None and values.shape == grid.shape else 0.0


def _higher_mode(
    fit: DampedSinusoidFit, omega1: float, higher: FloatArray, config: FastConfig
) -> tuple[float, float]:
    """The strongest detected mode above omega_1 within the range of contact modes 2 and 3.

    Returns its frequency and the fit's standard error of it (rad/s); NaN when there is none
    (or the fit did not converge).
    """
    low, high = float(higher.min()), float(higher.max())
    detection = fit.detection()
    usable = [
        k
        for k in range(fit.n_modes)
        if fit.omega[k] > 1.5 * omega1
        and low * (1.0 - 5.0 * config.higher_mode_floor)
        <= fit.omega[k]
        <= high * (1.0 + 5.0 * config.higher_mode_floor)
        and detection[k] >= config.min_detection
        and math.isfinite(fit.omega_se[k])
    ]
    if not usable or not fit.converged:
        return math.nan, math.nan
    k = max(usable, key=lambda i: float(detection[i]))
    return float(fit.omega[k]), float(fit.omega_se[k])


def _early_statics(
    span: WindowSpan, omega1: float, bias: SensorBias, model: StaticsModel, link: Link
) -> StaticRatio | None:
    """Statics of the window's first half from t_1, the slip check's reference; None when that
    half is not on the grid or is no reference (:func:`.checks.is_slip_reference`: too few
    periods of ``omega1`` (rad/s), or another mode in the fundamental's place)."""
    config = span.config
    half = reference_index(span.rest_index, span.end_index, 0.5, span.sample_period, config)
    half_fit = None if half is None else fit_window(*span._replace(end_index=half))
    if half_fit is None or not is_slip_reference(half_fit, omega1, span.band, config):
        return None
    assert half is not None
    return static_ratio(half_fit, bias, model.axial_at(half), link, model.elevation_at(half))


def _held(window: WindowEstimate, config: FastConfig) -> bool:
    """Whether nothing in ``window`` says the link bounced on the obstacle: the contact force
    stays closed (``max_opening``) and the push plane has one fundamental."""
    return not (window.opening > config.max_opening or math.isfinite(window.fundamentals[1]))


def _closer(pair: tuple[float, float], other: tuple[float, float]) -> tuple[float, float]:
    """Of two pairs of fundamentals (rad/s; NaN, NaN for none), the closer one: the one that
    takes the longer window to tell apart."""
    if not math.isfinite(other[1]):
        return pair
    if not math.isfinite(pair[1]):
        return other
    return pair if abs(pair[0] - pair[1]) <= abs(other[0] - other[1]) else other


def _resolving(
    window: WindowEstimate, pair: tuple[float, float], sample_period: float
) -> WindowEstimate:
    """``window``, not sure when it is shorter than 2 pi / |omega_a - omega_b| (s), the time
    that tells apart the two fundamentals ``pair`` (rad/s) of a window before it: in a shorter
    one a single fitted mode may be the two read as one."""
    needed = 2.0 * math.pi / abs(pair[0] - pair[1])
    length = (window.end_index - window.start_index) * sample_period
    if length >= needed or not (window.checks_passed or window.near_top):
        return window
    return _not_sure(
        window,
        f"the window ({length:.2f} s) is too short to tell apart the push plane's two "
        f"fundamentals of an earlier one, {pair[0]:.2f} and {pair[1]:.2f} rad/s "
        f"({needed:.2f} s)",
    )


def _not_sure(window: WindowEstimate, note: str) -> WindowEstimate:
    """``window`` with every check failed, for the reason ``note`` added to its own."""
    return dataclasses.replace(
        window,
        sure=False,
        checks_passed=False,
        settled=False,
        near_top=False,
        note="; ".join(text for text in (window.note, note) if text),
    )


def evaluate_from_t1_or_hold(
    inputs: ScanInputs,
    hold_end: int,
    caches: tuple[FitCache, FitCache] | None = None,
    choose_branch: BranchChooser | None = None,
    with_early_statics: bool = True,
    bounced: tuple[float, float] | None = None,
) -> WindowEstimate:
    """:func:`evaluate_window` on [t_1, ``inputs.end_index``]; from the end of the hold when the
    link bounced.

    When the window from t_1 shows the contact opening (``max_opening``) or two fundamentals
    (``WindowEstimate.fundamentals``), the link was bouncing on the obstacle early in the
    window; the window [hold_end, end_index] is evaluated instead once it is at least
    ``first_window`` long (before that the one from t_1 is returned, not sure), and while that
    one still shows it, the window from a hold's length later, and so on. A restarted window
    after two fundamentals is sure only when it is long enough to tell them apart
    (2 pi / their distance): one mode in a shorter one may be both.
    ``bounced``: None, or an earlier evaluation's window from t_1 showed it, and these are the
    closest two fundamentals seen then (rad/s; NaN, NaN after openings only;
    :func:`bounced_from_t1`). This window from t_1 holds those samples, and a fit over a longer
    window may merge the bouncing into one fundamental that no check tells from the contact's,
    read low; so the window starts at the end of the hold as above whatever this one from t_1
    shows (it is then not fitted), is not sure while that is too short, and must tell those two
    fundamentals apart as well. No effect when ``hold_end`` is not after t_1.
    ``caches`` holds the fits of the windows from t_1 and of those restarted; None refits.
    ``choose_branch`` as in :func:`evaluate_window`; ``with_early_statics``: the returned window
    gets the slip check's early statics when the direction check is on
    (:func:`with_early_statics_of`).
    """
    early, late = caches if caches is not None else (None, None)
    first = round(inputs.config.first_window / inputs.sample_period)
    start, step = hold_end, hold_end - inputs.rest_index
    if step <= 0:
        bounced = None
    window: WindowEstimate | None = None
    if bounced is None or not start <= inputs.end_index - first:
        # the window from t_1; not even fitted once a bounce keeps it out and a later one fits
        window = evaluate_window(*inputs, cache=early, choose_branch=choose_branch)
    none = (math.nan, math.nan)
    pair = _closer(none if window is None else window.fundamentals, bounced or none)
    restart = window is None or not _held(window, inputs.config)
    while restart and inputs.rest_index < start <= inputs.end_index - first:
        window = evaluate_window(
            *inputs._replace(rest_index=start, push=None),
            cache=late,
            choose_branch=choose_branch,
        )
        pair = _closer(window.fundamentals, pair)
        start += step
        restart = not _held(window, inputs.config)
    assert window is not None
    if bounced is not None and window.start_index == inputs.rest_index:
        window = _not_sure(
            window,
            "the link bounced on the obstacle in an earlier window from t_1, whose samples"
            " this one holds, and the window from the end of the hold is still too short",
        )
    if window.start_index != inputs.rest_index and math.isfinite(pair[1]):
        window = _resolving(window, pair, inputs.sample_period)
    return with_early_statics_of(inputs, window, caches) if with_early_statics else window


def bounced_from_t1(
    window: WindowEstimate, inputs: ScanInputs, carried: tuple[float, float] | None, hold_end: int
) -> tuple[float, float] | None:
    """What the next evaluation takes as its ``bounced`` (:func:`evaluate_from_t1_or_hold`),
    after the one on ``inputs`` that gave ``window`` with ``carried`` as its own: None while no
    evaluation restarted its window or returned the one from t_1 showing the contact opening or
    two fundamentals; else the closest two fundamentals seen (rad/s; NaN, NaN for none).

    Only windows ending at or after ``hold_end`` (the pipeline's hold) carry a bounce: earlier
    ones are evaluated by the information bound and the history from t_1, not by the method,
    and must not change its windows; before it ``carried`` is returned as it is."""
    if window.end_index < hold_end:
        return carried
    if carried is None and window.start_index == inputs.rest_index and _held(window, inputs.config):
        return None
    return _closer(window.fundamentals, carried if carried is not None else (math.nan, math.nan))


def with_early_statics_of(
    inputs: ScanInputs,
    estimate: WindowEstimate,
    caches: tuple[FitCache, FitCache] | None = None,
) -> WindowEstimate:
    """``estimate`` (a window of :func:`evaluate_from_t1_or_hold` on ``inputs``' samples) with
    the slip check's early statics: those of its first half, with the fundamental of its fit
    from its own start (never through the push). Its fits come from ``caches`` (the windows
    from t_1 or, when it was restarted, those from the hold's end); None refits them. Unchanged
    when the direction check is off (``max_direction_drift`` None), which alone reads them."""
    if inputs.config.max_direction_drift is None:
        return estimate
    restarted = estimate.start_index != inputs.rest_index
    cache = None if caches is None else caches[1 if restarted else 0]
    span = WindowSpan(
        inputs.channels,
        estimate.start_index,
        estimate.end_index,
        inputs.sample_period,
        inputs.band,
        inputs.config,
        cache,
    )
    statics_model = inputs.statics_model if inputs.statics_model is not None else StaticsModel()
    from_t1 = measure_fundamental(span, None, statics_model.push_direction)
    early = (
        None
        if from_t1.mode is None
        else _early_statics(span, from_t1.omega1, inputs.bias, statics_model, inputs.link)
    )
    return dataclasses.replace(estimate, early_statics=early)
