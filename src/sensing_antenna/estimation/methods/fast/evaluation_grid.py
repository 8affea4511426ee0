"""The evaluation grid: the instants after t_1 at which the growing window is evaluated.

The grid is geometric (``FastConfig.growth``) above a shortest spacing (``cadence``), from
``first_window`` to ``cap``; the windows the drift and slip checks compare a window with (of
about 2/3 and 1/2 its length) are taken on the same grid, so the fits of earlier evaluations
serve them.
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.methods.fast.config import FastConfig

__all__ = ["evaluation_offsets", "reference_index"]


@functools.lru_cache(maxsize=32)
def _offsets(
    sample_period: float, first: float, cadence: float, growth: float, cap: float
) -> tuple[int, ...]:
    offsets = [max(1, round(first / sample_period))]
    last = max(1, round(cap / sample_period))
    while offsets[-1] < last:
        step = max(cadence, (growth - 1.0) * offsets[-1] * sample_period)
        offsets.append(min(last, offsets[-1] + max(1, round(step / sample_period))))
    return tuple(offsets)


def evaluation_offsets(sample_period: float, config: FastConfig) -> NDArray[np.int_]:
    """Samples after t_1 at which windows are evaluated, ascending; the last is the cap."""
    return np.asarray(
        _offsets(sample_period, config.first_window, config.cadence, config.growth, config.cap),
        dtype=int,
    )


def reference_index(
    rest_index: int, end_index: int, fraction: float, sample_period: float, config: FastConfig
) -> int | None:
    """The evaluation-grid index whose window is nearest to ``fraction`` of [t_1, end]."""
    offsets = evaluation_offsets(sample_period, config)
    target = fraction * (end_index - rest_index)
    k = int(np.argmin(np.abs(offsets - target)))
    if offsets[k] >= end_index - rest_index:
        return None
    return rest_index + int(offsets[k])
