"""Fusion as likelihoods over x_c: a posterior on a fine grid instead of "nearest candidate".

Two measurements, each with a standard error:

- the fundamental omega_1 (rad/s), with likelihood N(omega_hat; omega_1(x_c), sigma_w^2) through
  the forward sensing curve omega_1(x_c) (Eq. 3 with the boundary conditions of Eq. 4). Using
  the forward model, not the linearised inverse, keeps the right shape near the peak of
  omega_1(x_c) (x_c ~ 0.77 l), where dx_c/d omega_1 diverges and both sides of the peak fit;
- the torque/force ratio r (m), with likelihood N(r_hat; x_c, sigma_r^2);
- optionally a higher contact mode omega_h (rad/s) fitted beside the fundamental, with a mixture
  likelihood sum_j N(omega_h; omega_j(x_c), sigma_h^2) / J over the candidate contact modes j
  (2 and 3: which one the fit holds is not known). Its sensing curves peak elsewhere than
  omega_1's, so near the top of omega_1(x_c) it carries the information the fundamental lacks.

Model-error floors are added in quadrature to the statistical standard errors:

- frequency: a relative error ``frequency_floor`` of omega_1 (T or T_e known to that relative
  precision; the model frequency is proportional to 1 / T), sigma_w^2 = se^2 + (eps omega_hat)^2,
  and the curve's own term at each grid point (``frequency_model``: the bent link's shift and a
  payload's the weight at rest reads) in quadrature;
- ratio: what the elastica's statics do not hold, the front end's model term at each grid point
  (:meth:`~sensing_antenna.estimation.front.evidence.Evidence.ratio_model_uncertainty`: the
  stiffness's uncertainty on the statics' corrections, what the link's weight terms leave, a
  floor, and the cross-talk of a sensor no calibration has measured for the push's direction),
  sigma_r^2 = se^2 + model^2.

Prior: flat on the contact range. The posterior is normalised on the grid; the point estimate is
its maximum (MAP); the 95 % interval is the highest-density region, reported as [lowest, highest]
point of that region (conservative when the region has two parts, one on each branch:
:meth:`ContactPosterior.pieces` gives the parts); the branch probabilities are the posterior
mass on each monotone branch of omega_1(x_c). Another measurement's likelihood on the grid
updates it (:meth:`ContactPosterior.times`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

__all__ = ["ContactPosterior", "contact_posterior"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class ContactPosterior:
    """Posterior over the contact point.

    Attributes
    ----------
    grid : array, shape (G,)
        Contact points (m).
    density : array, shape (G,)
        Posterior probability of each grid cell (sums to 1).
    x_c : float
        Maximum a posteriori contact point (m).
    interval : tuple of float
        (low, high) of the highest-density region of mass ``level`` (m).
    level : float
        Mass of the interval (0.95).
    branch_edges : tuple of float
        Limits of the monotone branches of omega_1(x_c) (m), ascending, from the range's low end
        to its high end.
    branch_probability : tuple of float
        Posterior mass of each branch (same order; sums to 1).
    """

    grid: FloatArray
    density: FloatArray
    x_c: float
    interval: tuple[float, float]
    level: float
    branch_edges: tuple[float, ...]
    branch_probability: tuple[float, ...]

    @property
    def width(self) -> float:
        """high - low of the interval (m)."""
        return self.interval[1] - self.interval[0]

    def pieces(self) -> tuple[tuple[float, float, float], ...]:
        """The highest-density region's separate parts as (low, high, mass) (m, m, posterior
        mass over [low, high]), ascending: one when the region is one interval, two when x_c is
        near one point on each of two branches of omega_1(x_c) and nowhere between. A gap
        within one branch (a dip between the ratio's and the frequency's likelihoods) stays
        inside its part, as does a gap narrower than the narrower part beside it (a region
        across the curve's top, where the branches meet): the hull of such parts is one
        spread."""
        cells = np.sort(_hpd_cells(self.density, self.level))
        branch = _branch_indices(self.branch_edges, self.grid)[cells]
        # runs of the region's cells that skip a cell where the branch changes across the gap
        starts = np.flatnonzero((np.diff(cells) > 1) & (np.diff(branch) != 0)) + 1
        runs = [[int(c[0]), int(c[-1])] for c in np.split(cells, starts)]
        merged = [runs[0]]
        for low, high in runs[1:]:
            gap = low - merged[-1][1] - 1
            if gap < min(high - low + 1, merged[-1][1] - merged[-1][0] + 1):
                merged[-1][1] = high
            else:
                merged.append([low, high])
        half = _half_cell(self.grid)
        return tuple(
            (
                float(self.grid[low] - half),
                float(self.grid[high] + half),
                float(self.density[low : high + 1].sum()),
            )
            for low, high in merged
        )

    def branch_of(self, x_c: float) -> int:
        """Index of the branch holding ``x_c``."""
        inner = self.branch_edges[1:-1]
        return int(np.searchsorted(np.asarray(inner), x_c))

    def given_branch(self, branch: int) -> ContactPosterior:
        """The posterior conditioned on x_c lying on ``branch`` (another measurement chose it).

        The density is set to zero off the branch and renormalised; x_c, the interval and the
        branch probabilities (1 on ``branch``) follow. Unchanged when the branch holds no mass.
        """
        on_branch = _branch_indices(self.branch_edges, self.grid) == branch
        conditioned = self.times(on_branch.astype(float))
        if conditioned is None:
            return self
        count = len(self.branch_probability)
        probability = tuple(1.0 if b == branch else 0.0 for b in range(count))
        return replace(conditioned, branch_probability=probability)

    def times(self, likelihood: FloatArray) -> ContactPosterior | None:
        """The posterior updated by another measurement's ``likelihood`` on the grid (shape
        (G,), any positive scale): x_c, the interval and the branch probabilities follow. None
        when the product holds no mass (the measurement excludes every x_c this posterior
        allows)."""
        product = self.density * np.asarray(likelihood, dtype=float)
        mass = float(product.sum())
        if not (math.isfinite(mass) and mass > 0.0):
            return None
        density = product / mass
        branches = _branch_indices(self.branch_edges, self.grid)
        probability = tuple(
            float(density[branches == b].sum()) for b in range(len(self.branch_probability))
        )
        return replace(
            self,
            density=density,
            x_c=float(self.grid[int(np.argmax(density))]),
            interval=_hpd_bounds(density, self.grid, self.level),
            branch_probability=probability,
        )


def _branch_indices(branch_edges: tuple[float, ...], grid: FloatArray) -> NDArray[np.int_]:
    """Index of the monotone branch holding each grid point."""
    edges = np.asarray(branch_edges, dtype=float)
    return np.asarray(np.clip(np.searchsorted(edges[1:-1], grid), 0, edges.size - 2), dtype=int)


def _hpd_cells(density: FloatArray, level: float) -> NDArray[np.int_]:
    """Indices of the highest-density cells that hold ``level`` of the mass."""
    order = np.argsort(density)[::-1]
    cumulative = np.cumsum(density[order])
    count = int(np.searchsorted(cumulative, level)) + 1
    return np.asarray(order[: min(count, order.size)], dtype=int)


def _half_cell(grid: FloatArray) -> float:
    """Half the grid's step (m): each grid point stands for a cell of one step, so a region
    reaches half a step beyond its outermost points; 0 on a grid of one point."""
    return 0.5 * float(grid[1] - grid[0]) if grid.size > 1 else 0.0


def _hpd_bounds(density: FloatArray, grid: FloatArray, level: float) -> tuple[float, float]:
    chosen = _hpd_cells(density, level)
    half = _half_cell(grid)
    return float(grid[chosen].min() - half), float(grid[chosen].max() + half)


def _check_model_term(name: str, term: float | FloatArray, infinite: bool) -> None:
    values = np.asarray(term, dtype=float)
    valid = values >= 0.0 if infinite else np.isfinite(values) & (values >= 0.0)
    if not np.all(valid):
        what = ">= 0" if infinite else "finite and >= 0"
        raise ValueError(f"{name}: must be {what} at every grid point")


def contact_posterior(
    omega1_of_x: FloatArray,
    grid: FloatArray,
    branch_edges: tuple[float, ...],
    omega1: float,
    omega1_se: float,
    ratio: float,
    ratio_se: float,
    ratio_model: float | FloatArray,
    frequency_floor: float,
    level: float = 0.95,
    higher_modes_of_x: FloatArray | None = None,
    omega_higher: float = math.nan,
    omega_higher_se: float = math.nan,
    higher_mode_floor: float = 0.0,
    frequency_model: float | FloatArray = 0.0,
) -> ContactPosterior:
    """Posterior over x_c on ``grid`` from omega_1 and the torque/force ratio.

    Parameters
    ----------
    omega1_of_x : array, shape (G,)
        The sensing curve omega_1 at each grid point (rad/s).
    grid : array, shape (G,)
        Uniform grid of contact points covering the prior range (m).
    branch_edges : tuple of float
        Range limits and extrema of omega_1(x_c) inside it (m), ascending.
    omega1, omega1_se : float
        Measured fundamental and its statistical standard error (rad/s); NaN: not measured.
    ratio, ratio_se : float
        Torque/force ratio and its statistical standard error (m); NaN: not measured.
    ratio_model : float or array, shape (G,)
        The statics model's standard uncertainty of the ratio at each grid point (m); 0: none.
    frequency_floor : float
        Relative model error of omega_1 (dimensionless).
    level : float
        Mass of the highest-density interval.
    higher_modes_of_x : array, shape (G, J), optional
        Sensing curves of the candidate higher contact modes at each grid point (rad/s).
    omega_higher, omega_higher_se : float
        Measured higher mode and its statistical standard error (rad/s); NaN: not measured.
    higher_mode_floor : float
        Relative model error of the higher modes (dimensionless).
    frequency_model : float or array, shape (G,)
        The sensing curve's own standard uncertainty of omega_1 at each grid point (rad/s), in
        quadrature with the floor: what the straight link's curve leaves out at the hold's push
        (the bent link's shift); 0: none.

    Returns
    -------
    ContactPosterior

    Raises
    ------
    ValueError
        A model term that is NaN or negative, or a ``frequency_model`` that is infinite, at
        some grid point: the density would be NaN and the answer the grid's start. An infinite
        ``ratio_model`` (no push to read the ratio by) leaves the ratio out.
    """
    _check_model_term("ratio_model", ratio_model, infinite=True)
    _check_model_term("frequency_model", frequency_model, infinite=False)
    log_like = np.zeros(grid.shape)
    if math.isfinite(omega1) and math.isfinite(omega1_se):
        # Gaussian likelihood of omega_1 through the forward sensing curve, the floor and the
        # curve's own term in quadrature; a sigma that varies along the grid brings its norm
        sigma_w = np.sqrt(
            omega1_se**2 + (frequency_floor * omega1) ** 2 + np.square(frequency_model)
        )
        log_like += -0.5 * ((omega1 - omega1_of_x) / sigma_w) ** 2
        if np.ndim(sigma_w):
            log_like -= np.log(sigma_w)
    if math.isfinite(ratio) and math.isfinite(ratio_se) and np.all(np.isfinite(ratio_model)):
        sigma_r = np.sqrt(ratio_se**2 + np.square(ratio_model)) * np.ones(grid.shape)
        log_like += -0.5 * ((ratio - grid) / sigma_r) ** 2 - np.log(sigma_r)
    if (
        higher_modes_of_x is not None
        and math.isfinite(omega_higher)
        and math.isfinite(omega_higher_se)
    ):
        # Mixture over the candidate contact modes, relative model floor in quadrature
        sigma_h = math.sqrt(omega_higher_se**2 + (higher_mode_floor * omega_higher) ** 2)
        z = (omega_higher - np.asarray(higher_modes_of_x, dtype=float)) / sigma_h
        log_like += np.logaddexp.reduce(-0.5 * z**2, axis=1)
    weights = np.exp(log_like - log_like.max())
    density = weights / weights.sum()
    k = int(np.argmax(density))
    interval = _hpd_bounds(density, grid, level)
    edges = np.asarray(branch_edges, dtype=float)
    mass = np.bincount(
        _branch_indices(branch_edges, grid), weights=density, minlength=edges.size - 1
    )
    return ContactPosterior(
        grid=grid,
        density=density,
        x_c=float(grid[k]),
        interval=interval,
        level=level,
        branch_edges=tuple(float(e) for e in edges),
        branch_probability=tuple(float(m) for m in mass),
    )
