"""The information bound of the fast method's delay: how early its own model could declare.

The bound instant is the first window of the growing scan (from ``first_window`` after t_1, on
the evaluation grid, up to the cap) whose 95 % interval would be no wider than the tolerance
with the standard error of omega_1 at its Cramer-Rao bound (for the window's fitted model and
residual noise) and no model floors, every other check ignored (the pipeline's hold, the
periods in the window, the drift, the ratio's agreement, the peak margin): the earliest instant
at which the record's fundamental and torque/force ratio could give an interval that narrow to
an efficient estimator that trusted the linear model completely. The method's own interval
adds the model floors, the bent link's term and the fit's drift to the same windows, and its
declaration waits for the checks and the hold as well.

:func:`bound_width` is that interval's width for one window, :func:`bound_delay` the bound
instant of a manoeuvre, as t - t_1.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from sensing_antenna.antenna import Link
from sensing_antenna.estimation.front.evidence import Evidence
from sensing_antenna.estimation.methods.fast.config import FastConfig
from sensing_antenna.estimation.methods.fast.curves import curve_table
from sensing_antenna.estimation.methods.fast.likelihood import contact_posterior
from sensing_antenna.estimation.methods.fast.search import evaluations, scan_inputs
from sensing_antenna.estimation.methods.fast.second_mode import second_mode_chooser
from sensing_antenna.estimation.methods.fast.window import WindowEstimate
from sensing_antenna.estimation.methods.fast.window_fit import FitCache

__all__ = ["bound_delay", "bound_width"]


def bound_width(window: WindowEstimate, link: Link, config: FastConfig) -> float:
    """Width (m) of the window's 95 % interval with omega_1's standard error at its Cramer-Rao
    bound and no floors (on the branch the second contact mode chose, when it chose one).

    The window's statics (ratio and its statistical standard error) enter as in its own
    posterior, without the statics' model term; NaN when the window has no statics or no finite,
    positive bound of omega_1.
    """
    statics = window.statics
    if statics is None or not (math.isfinite(window.omega1_crb) and window.omega1_crb > 0.0):
        return math.nan  # no statics, or no bound of omega_1 to weigh the frequency by
    grid = window.posterior.grid
    table = curve_table(link, float(grid[0]), float(grid[-1]), config.grid_step)
    posterior = contact_posterior(
        table.omega1,
        table.grid,
        table.edges,
        window.omega1,
        window.omega1_crb,
        statics.ratio,
        statics.standard_error,
        0.0,
        frequency_floor=0.0,
    )
    if window.branch_chosen_by_second_mode:
        # The same branch the method's own posterior was conditioned on
        posterior = posterior.given_branch(posterior.branch_of(window.posterior.x_c))
    return posterior.width


def bound_delay(
    evidence: Evidence,
    config: FastConfig | None = None,
    *,
    windows: Iterable[WindowEstimate] | None = None,
    caches: tuple[FitCache, FitCache] | None = None,
) -> float:
    """The bound instant of the manoeuvre, t - t_1 (s); NaN when no window qualifies before the
    cap (or the samples' end).

    Parameters
    ----------
    evidence : Evidence
        What the pipeline's front end gathered (``estimation.gather``).
    config : FastConfig, optional
        The fast method's settings (its tolerance, grid and cap); default ``FastConfig()``.
    windows : iterable of WindowEstimate, optional
        The windows to read, in order, as ``FastMethod(config).history(evidence, from_t1=True)``
        gives them; None evaluates them here, stopping at the first that qualifies.
    caches : tuple of two dict, optional
        The manoeuvre's window fits made so far, as :meth:`FastMethod.conclude` takes them
        (windows from t_1, windows from the end of the hold): read and added to, so the windows
        the method has fitted are not fitted again (a window's fit is a function of its own
        samples, so the bound is the same); None: fresh ones.
    """
    config = config if config is not None else FastConfig()
    link = evidence.antenna.link
    if windows is None:
        windows = evaluations(
            scan_inputs(evidence, config),
            evidence.rest_index,
            evidence.hold_end,
            second_mode_chooser(evidence),
            caches,
            with_early_statics=False,  # the slip check's reference: no part of the bound
        )
    t_1 = float(evidence.t[evidence.rest_index])
    for window in windows:
        if bound_width(window, link, config) <= config.tolerance:
            return float(evidence.t[window.end_index]) - t_1
    return math.nan
