"""Accuracy of contact-point estimates against the truth, as plain data (SI: m, s, rad/s).

The summaries a campaign's tables compute (:mod:`sensing_antenna.campaign.tables`) and its
figures draw (:mod:`sensing_antenna.plotting.campaign`). Nothing here computes: this module sits
below both, so that plotting needs nothing from the campaign package.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

__all__ = ["FrequencyErrorSummary", "PointStats", "PointTable", "RunPoints"]


@dataclass(frozen=True)
class PointStats:
    """One method's statistics at one contact point (the layout of Tables 3 and 4; m).

    Attributes
    ----------
    x_c : float
        Nominal contact point (m).
    n_runs : int
        Runs at this point (including failed ones and runs without an estimate).
    n_estimates : int
        Runs with a finite estimate; the statistics are over these.
    mean_estimate, mean_abs_error, max_error, std_error : float
        Mean estimate, mean |error|, max |error| and sample standard deviation (ddof = 1) of the
        signed error against ``x_c``, all in m; NaN without estimates (std: with fewer than 2).
    """

    x_c: float
    n_runs: int
    n_estimates: int
    mean_estimate: float
    mean_abs_error: float
    max_error: float
    std_error: float


@dataclass(frozen=True)
class PointTable:
    """Per-point statistics of one method in one case, ordered by x_c.

    Attributes
    ----------
    case : str
        Manoeuvre (``"azimuthal"``, ``"vertical"``).
    method : str
        Method name, or a label for reference values (the paper's tables).
    points : tuple of PointStats
    """

    case: str
    method: str
    points: tuple[PointStats, ...]

    @property
    def x_c(self) -> NDArray[np.float64]:
        """Contact points (m), shape (n_points,)."""
        return np.array([p.x_c for p in self.points], dtype=float)

    @property
    def mean_abs_error(self) -> NDArray[np.float64]:
        """Mean absolute error at each point (m), shape (n_points,)."""
        return np.array([p.mean_abs_error for p in self.points], dtype=float)

    @property
    def max_error(self) -> NDArray[np.float64]:
        """Maximum absolute error at each point (m), shape (n_points,)."""
        return np.array([p.max_error for p in self.points], dtype=float)


@dataclass(frozen=True, eq=False)
class RunPoints:
    """Every run of one method in one case, arrays of shape (n_runs,); NaN where a run has none.

    Attributes
    ----------
    case, method : str
    x_c : array
        Nominal contact point of each run (m).
    estimate : array
        Estimated contact point (m).
    error : array
        Estimate minus where the link touched: the contact abscissa, or the nominal x_c for a
        run without one (m).
    delay : array
        t_e - t_1, how long after the push the estimate was available (s).
    omega1 : array
        Measured fundamental frequency (rad/s).
    ok : array of bool or None
        Whether each run's status is ``ok``; None when not recorded.
    """

    case: str
    method: str
    x_c: NDArray[np.float64]
    estimate: NDArray[np.float64]
    error: NDArray[np.float64]
    delay: NDArray[np.float64]
    omega1: NDArray[np.float64]
    ok: NDArray[np.bool_] | None = None


@dataclass(frozen=True)
class FrequencyErrorSummary:
    """One method's omega_1 against the device's true fundamental at one noise level.

    Relative errors are (omega_1 - omega_1,true) / omega_1,true, with omega_1,true the device's
    contact-mode fundamental at the run's contact abscissa (nominal x_c if unknown).

    Attributes
    ----------
    method : str
    noise_scale : float
        Multiple of the simulator's nominal sensor noise.
    n : int
        Runs with a finite omega_1.
    rms_relative_error, median_abs_relative_error : float
        Over those runs; NaN without any.
    median_relative_crb, median_relative_se : float
        Median over runs of the method's Cramer-Rao bound and reported standard error of
        omega_1, relative to omega_1,true; NaN for methods that report none.
    """

    method: str
    noise_scale: float
    n: int
    rms_relative_error: float
    median_abs_relative_error: float
    median_relative_crb: float
    median_relative_se: float
