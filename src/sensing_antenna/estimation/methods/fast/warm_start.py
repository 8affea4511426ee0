"""Warm starts: a long window's fits start from those of a shorter window of the same record.

Each window tries three polynomial degrees and up to three model orders (:mod:`.model_order`),
each started from the matrix pencil (:mod:`.pencil`), the largest order of every degree solved
twice (weights from first differences, then from its own residuals). A window of the growing
scan at least ``FastConfig.warm_start_after`` long instead starts every (degree, order) from the
solution of the same model on its drift check's reference window, about 2/3 of it on the
evaluation grid (:func:`.evaluation_grid.reference_index`), which the drift check fits anyway:
one solve, weighted by the noise found there; when no detected mode of that fit lies at the
window's clear spectral peak in the omega_1 band (a shorter window may have fitted two close
modes as one, and its solutions carry that on), the fits from the pencil run too and the
smaller BIC wins (:mod:`.window_fit`). The reference is a function of the window alone
(:func:`warm_reference`), so a window has the same fit whichever windows were fitted before it,
offline and online. Windows through the push always start from the pencil (``FastConfig``).
Windows that start warm try two modes or more (``FastConfig.long_window_min_modes``), shorter
ones one or more (:func:`fewest_modes`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.methods.fast.config import FastConfig
from sensing_antenna.estimation.methods.fast.evaluation_grid import reference_index

__all__ = ["Solutions", "fewest_modes", "start_inside", "starts_warm", "warm_reference"]

FloatArray = NDArray[np.float64]

#: The solutions of one window's candidate fits: (polynomial degree, number of modes) ->
#: ((w, s) interleaved in rad/s and 1/s, shape (2M,); the channel noise standard deviations the
#: fit was weighted with or found, shape (K,)). What a longer window of the same record starts
#: from.
Solutions = dict[tuple[int, int], tuple[FloatArray, FloatArray]]


def starts_warm(
    rest_index: int,
    end_index: int,
    sample_period: float,
    config: FastConfig,
    through_push: bool = False,
) -> bool:
    """Whether the window [rest_index, end_index] is long enough to start warm: at least
    ``config.warm_start_after`` (s, > 0) and not fitted ``through_push``."""
    if through_push or config.warm_start_after <= 0.0:
        return False
    return (end_index - rest_index) * sample_period >= config.warm_start_after


def fewest_modes(
    rest_index: int,
    end_index: int,
    sample_period: float,
    config: FastConfig,
    through_push: bool = False,
) -> int:
    """The fewest damped modes tried on the window: ``config.long_window_min_modes`` (at most
    the most tried) on a window that starts warm (:func:`starts_warm`), else 1."""
    if starts_warm(rest_index, end_index, sample_period, config, through_push):
        return min(config.long_window_min_modes, config.max_modes)
    return 1


def warm_reference(
    rest_index: int,
    end_index: int,
    sample_period: float,
    config: FastConfig,
    through_push: bool = False,
) -> int | None:
    """Last index of the window whose :data:`Solutions` the fits of [rest_index, end_index]
    start from; None when they start from the matrix pencil.

    A window that starts warm (:func:`starts_warm`) has the drift check's reference, the grid
    window nearest to 2/3 of it (None when there is none on the grid).
    """
    if not starts_warm(rest_index, end_index, sample_period, config, through_push):
        return None
    return reference_index(rest_index, end_index, 2.0 / 3.0, sample_period, config)


def start_inside(params: FloatArray, lower: FloatArray, upper: FloatArray) -> FloatArray:
    """The solution ``params`` (2M,) of another window moved just inside this window's bounds
    ``lower``, ``upper`` ((w, s) pairs, shape (2,)): a longer window allows slower decays
    only (its largest decay rate is a fixed number of e-foldings over the window). The same
    margins as the pencil's start (:func:`.pencil.initial_modes`)."""
    start = np.empty(params.size)
    start[0::2] = np.clip(params[0::2], lower[0] * 1.001, upper[0] * 0.999)
    start[1::2] = np.clip(params[1::2], lower[1] * 0.999, upper[1] * 0.999)
    return start
