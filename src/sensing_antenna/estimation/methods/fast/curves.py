"""The sensing curves on the posterior's grid, and the contact points of a fundamental."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Link
from sensing_antenna.beam import natural_frequencies
from sensing_antenna.estimation.front.evidence import sensing_curve
from sensing_antenna.estimation.methods.fast.config import FastConfig, model_floor
from sensing_antenna.estimation.methods.fast.likelihood import ContactPosterior

__all__ = ["CurveTable", "contact_candidates", "curve_table"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class CurveTable:
    """The sensing curves on the posterior's grid.

    Attributes
    ----------
    grid : array, shape (G,)
        Contact points (m).
    omega1 : array, shape (G,)
        omega_1 at each (rad/s).
    edges : tuple of float
        Range limits and the extrema of omega_1 inside (m), ascending: the branch edges.
    higher : array, shape (G, 2)
        Contact modes 2 and 3 at each (rad/s).
    slope : array, shape (G,)
        |d omega_1 / d x_c| at each (rad/s per m), by differences on the grid.
    """

    grid: FloatArray
    omega1: FloatArray
    edges: tuple[float, ...]
    higher: FloatArray
    slope: FloatArray


@functools.lru_cache(maxsize=16)
def curve_table(link: Link, low: float, high: float, step: float) -> CurveTable:
    """:class:`CurveTable` of ``link`` on [low, high] (m) every ``step`` (m); cached."""
    curve = sensing_curve(link)
    n = max(2, round((high - low) / step) + 1)
    grid = np.linspace(low, high, n)
    inner = tuple(x for x in curve.extrema if low < x < high)
    # Contact modes 2 and 3 (Eq. 3 with the boundary conditions of Eq. 4), shape (G, 2)
    higher = np.asarray(natural_frequencies(link, grid, 3), dtype=float)[:, 1:]
    omega1 = np.asarray(curve.omega1(grid), dtype=float)
    slope = np.abs(np.gradient(omega1, grid))
    return CurveTable(grid, omega1, (low, *inner, high), higher, slope)


def contact_candidates(
    link: Link, omega1: float, posterior: ContactPosterior, config: FastConfig
) -> tuple[float, ...]:
    """Contact points (m) whose omega_1 is ``omega1``, inside the posterior's range.

    The last branch of the sensing curve ends at the tip: a frequency just past omega_1(l) on
    that side, within ``max_disagreement`` of the model's floor (:func:`.config.model_floor`),
    has the tip x_c = l as that branch's candidate, as for the paper method, so that the second
    contact mode can still be asked between the branches (a touch at the tip rings there).
    """
    if not math.isfinite(omega1):
        return ()
    low, high = posterior.branch_edges[0], posterior.branch_edges[-1]
    tolerance = config.max_disagreement * model_floor(link, config) * omega1
    return tuple(
        float(c.x_c)
        for c in sensing_curve(link).contact_points(omega1, tolerance)
        if low <= c.x_c <= high
    )
