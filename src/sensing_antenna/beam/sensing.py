"""The sensing curve omega_1(x_c) and its inverse (Section 4.3, Figure 8).

A :class:`SensingCurve` is built once per link: a dense table of beta_1 l and its exact slope
d(beta_1 l)/d xi on xi = x_c / l in [0, 1], with every interior extremum inserted as a node (slope
zero there), so the piecewise cubic Hermite interpolant is split into monotone branches. A
measured fundamental frequency then maps to one candidate contact point per branch that reaches
it (one or two for the paper's link: omega_1 rises to a peak near x_c = 0.78 l and falls to the
clamped-pinned value at x_c = l).

The interpolation error is O(h^4); with the default 2001 nodes it is below 1e-12 relative (checked
against the exact solver in the tests). Near an extremum the inverse is ill-conditioned by nature:
an error ``e`` in omega_1 moves x_c by about ``sqrt(2 e / |omega_1''|)``.
"""

from __future__ import annotations

import bisect
import itertools
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from sensing_antenna.antenna import Link
from sensing_antenna.beam._validate import BeamInputError, as_finite_array
from sensing_antenna.beam.characteristic import eigenvalue_slopes, eigenvalues
from sensing_antenna.beam.modes import contact_ratio, frequency_scale
from sensing_antenna.errors import format_value

__all__ = ["Candidate", "Inversion", "SensingCurve"]

FloatArray = NDArray[np.float64]

#: Default table size: node spacing 5e-4 l keeps the Hermite error near 1e-13 (O(h^4)).
DEFAULT_POINTS = 2001

#: Largest table: 100,001 nodes, 2e-20 in Hermite error terms, far below rounding; beyond, a
#: table only costs time and memory.
MAX_POINTS = 100_001
#: Newton steps on one Hermite cubic; convergence is quadratic from the linear guess, the cap
#: only matters next to an extremum where the bisection safeguard takes over.
_MAX_NEWTON = 60
_T_TOL = 1e-15


@dataclass(frozen=True)
class Candidate:
    """A contact point consistent with a measured fundamental frequency.

    Attributes
    ----------
    x_c : float
        Contact point (m).
    slope : float
        d omega_1 / d x_c at that point (rad/s per m); large magnitude = well conditioned.
    """

    x_c: float
    slope: float


@dataclass(frozen=True)
class Inversion:
    """Vectorised inverse of the sensing curve.

    Attributes
    ----------
    omega1 : ndarray
        The queried frequencies (rad/s), shape (...).
    x_c : ndarray
        Candidate contact points (m), shape (..., n_branches); column j is monotone branch j
        (branches ordered by x_c); NaN where branch j does not reach the frequency.
    slope : ndarray
        d omega_1 / d x_c at each candidate (rad/s per m), same shape, NaN likewise.
    """

    omega1: FloatArray
    x_c: FloatArray
    slope: FloatArray

    @property
    def count(self) -> NDArray[np.int64]:
        """Number of candidates per query, shape (...)."""
        return np.asarray(np.sum(~np.isnan(self.x_c), axis=-1), dtype=np.int64)


def _hermite(t: float, y0: float, y1: float, m0: float, m1: float) -> tuple[float, float]:
    """Cubic Hermite value and d/dt on t in [0, 1]; m0, m1 are slopes times the interval width."""
    t2 = t * t
    t3 = t2 * t
    value = (
        (2 * t3 - 3 * t2 + 1) * y0
        + (t3 - 2 * t2 + t) * m0
        + (-2 * t3 + 3 * t2) * y1
        + (t3 - t2) * m1
    )
    deriv = (6 * t2 - 6 * t) * (y0 - y1) + (3 * t2 - 4 * t + 1) * m0 + (3 * t2 - 2 * t) * m1
    return value, deriv


def _solve_cubic(target: float, y0: float, y1: float, m0: float, m1: float) -> float:
    """t in [0, 1] with Hermite value = target, given target between y0 and y1."""
    if target == y0:
        return 0.0
    if target == y1:
        return 1.0
    lo, hi = 0.0, 1.0
    rising = y1 > y0
    t = (target - y0) / (y1 - y0)
    for _ in range(_MAX_NEWTON):
        value, deriv = _hermite(t, y0, y1, m0, m1)
        residual = value - target
        if residual == 0.0:
            return t
        if (residual < 0) == rising:
            lo = t
        else:
            hi = t
        step = residual / deriv if deriv != 0.0 else math.inf
        t_new = t - step
        if not (lo < t_new < hi):
            t_new = 0.5 * (lo + hi)
        if abs(t_new - t) <= _T_TOL:
            return t_new
        t = t_new
    return t


@dataclass(frozen=True, eq=False)
class _Branch:
    """A monotone run of table nodes, stored with its values in ascending order."""

    keys: tuple[float, ...]
    nodes: tuple[int, ...]
    open_low: bool  # the lowest key is the x_c -> 0 limit, not a contact point
    open_high: bool


@dataclass(frozen=True, eq=False)
class SensingCurve:
    """omega_1(x_c) of one link, tabulated once, with its monotone branches and inverse.

    Build with :meth:`from_link`. Nodes are in xi = x_c / l; values are beta_1 l.
    """

    link: Link
    xi: FloatArray
    lam: FloatArray
    lam_slope: FloatArray
    extrema: tuple[float, ...]
    _branches: tuple[_Branch, ...] = field(repr=False)
    _xi_list: tuple[float, ...] = field(repr=False)
    _lam_list: tuple[float, ...] = field(repr=False)
    _slope_list: tuple[float, ...] = field(repr=False)

    @classmethod
    def from_link(cls, link: Link, n_points: int = DEFAULT_POINTS) -> SensingCurve:
        """Tabulate beta_1 l and its slope on ``n_points`` uniform nodes plus the extrema.

        Parameters
        ----------
        link : Link
            The link (length, tip-mass ratio and T or T_e).
        n_points : int
            Uniform nodes on xi in [0, 1], from 3 to :data:`MAX_POINTS`; xi = 0 is the
            x_c -> 0 limit.
        """
        if (
            isinstance(n_points, bool)
            or not isinstance(n_points, int)
            or not 3 <= n_points <= MAX_POINTS
        ):
            raise BeamInputError(
                "n_points",
                f"must be an integer from 3 to {MAX_POINTS}, got {format_value(n_points)}",
            )
        ratio = link.tip_mass_ratio
        xi = np.linspace(0.0, 1.0, n_points)
        lam = eigenvalues(xi, 1, ratio)[:, 0]
        slope = eigenvalue_slopes(xi, lam, ratio)
        extrema = []
        for j in np.flatnonzero(np.sign(slope[:-1]) * np.sign(slope[1:]) < 0):

            def slope_at(x: float) -> float:
                value = eigenvalues(x, 1, ratio)[0]
                return float(eigenvalue_slopes(x, value, ratio))

            extrema.append(float(brentq(slope_at, xi[j], xi[j + 1], xtol=1e-15, rtol=1e-15)))
        if extrema:
            ex = np.array(extrema)
            at = np.searchsorted(xi, ex)
            xi = np.insert(xi, at, ex)
            lam = np.insert(lam, at, eigenvalues(ex, 1, ratio)[:, 0])
            slope = np.insert(slope, at, 0.0)  # an extremum: slope zero by construction
        branches = _split_branches(xi, lam, extrema)
        return cls(
            link=link,
            xi=xi,
            lam=lam,
            lam_slope=slope,
            extrema=tuple(float(x) * link.length for x in extrema),
            _branches=branches,
            _xi_list=tuple(float(v) for v in xi),
            _lam_list=tuple(float(v) for v in lam),
            _slope_list=tuple(float(v) for v in slope),
        )

    # ------------------------------------------------------------------ forward map
    @property
    def _scale(self) -> float:
        return frequency_scale(self.link)

    def _interpolate(self, xi: FloatArray) -> tuple[FloatArray, FloatArray]:
        """beta_1 l and d(beta_1 l)/d xi at xi (Hermite)."""
        k = np.clip(np.searchsorted(self.xi, xi, side="right") - 1, 0, self.xi.size - 2)
        x0, x1 = self.xi[k], self.xi[k + 1]
        width = x1 - x0
        t = (xi - x0) / width
        y0, y1 = self.lam[k], self.lam[k + 1]
        m0, m1 = self.lam_slope[k] * width, self.lam_slope[k + 1] * width
        value, deriv = _hermite_array(t, y0, y1, m0, m1)
        return value, deriv / width

    def omega1(self, x_c: ArrayLike) -> FloatArray:
        """Fundamental frequency omega_1 (rad/s) at contact points x_c in (0, l] (m), any shape."""
        lam, _ = self._interpolate(contact_ratio(self.link, x_c))
        # omega_1 = (beta_1 l)^2 / (T l^2)
        return lam**2 * self._scale

    def omega1_slope(self, x_c: ArrayLike) -> FloatArray:
        """d omega_1 / d x_c (rad/s per m) at x_c in (0, l] (m), any shape."""
        lam, dlam = self._interpolate(contact_ratio(self.link, x_c))
        # d/dx_c of (beta_1 l)^2 / (T l^2) = 2 beta_1 l (d beta_1 l / d xi) / (T l^2 l)
        return 2.0 * lam * dlam * self._scale / self.link.length

    def omega1_range(
        self, x_min: float | None = None, x_max: float | None = None
    ) -> tuple[float, float]:
        """Lowest and highest omega_1 (rad/s) for contact points in [x_min, x_max] (m).

        ``x_min = None`` means the limit x_c -> 0 (cantilever), ``x_max = None`` means l.
        """
        lo = 0.0 if x_min is None else float(contact_ratio(self.link, x_min))
        hi = 1.0 if x_max is None else float(contact_ratio(self.link, x_max))
        if lo > hi:
            raise BeamInputError(
                "x_min", f"must not exceed x_max, got {format_value(x_min)} > {format_value(x_max)}"
            )
        points = [lo, hi] + [
            x / self.link.length for x in self.extrema if lo < x / self.link.length < hi
        ]
        lam, _ = self._interpolate(np.array(points))
        omega = lam**2 * self._scale
        return float(omega.min()), float(omega.max())

    # ------------------------------------------------------------------ inverse map
    def _target(self, omega1: float) -> float:
        return math.sqrt(omega1 / self._scale) if omega1 > 0 else -1.0

    def contact_points(self, omega1: float, tolerance: float = 0.0) -> tuple[Candidate, ...]:
        """Every contact point whose fundamental frequency is ``omega1`` (rad/s), by x_c.

        Returns an empty tuple when ``omega1`` lies outside the model's range. Fast scalar path
        (pure Python, no array allocation); agrees with :meth:`invert` when ``tolerance`` is 0.

        Parameters
        ----------
        omega1 : float
            Measured fundamental frequency (rad/s).
        tolerance : float
            Uncertainty of ``omega1`` (rad/s, >= 0). The curve ends at the tip, where the last
            branch stops short of the frequencies just beyond omega_1(l) (they would need a
            contact past the link's end): within ``tolerance`` of omega_1(l) on that side, the
            tip x_c = l is the candidate of that branch.
        """
        try:
            value = float(omega1)
        except (TypeError, ValueError) as exc:
            raise BeamInputError("omega1", f"must be a number, got {format_value(omega1)}") from exc
        if not math.isfinite(value):
            raise BeamInputError("omega1", f"must be finite, got {format_value(omega1)}")
        target = self._target(value)
        xs, ys, ms = self._xi_list, self._lam_list, self._slope_list
        found: list[Candidate] = []
        for branch in self._branches:
            keys = branch.keys
            if not _in_branch(target, branch):
                continue
            p = min(max(bisect.bisect_right(keys, target) - 1, 0), len(keys) - 2)
            a, b = branch.nodes[p], branch.nodes[p + 1]
            i, j = (a, b) if a < b else (b, a)
            width = xs[j] - xs[i]
            t = _solve_cubic(target, ys[i], ys[j], ms[i] * width, ms[j] * width)
            _, deriv = _hermite(t, ys[i], ys[j], ms[i] * width, ms[j] * width)
            xi = xs[i] + t * width
            lam, _ = _hermite(t, ys[i], ys[j], ms[i] * width, ms[j] * width)
            slope = 2.0 * lam * (deriv / width) * self._scale / self.link.length
            x_c = xi * self.link.length
            if found and found[-1].x_c == x_c:
                continue  # exactly at an extremum: both branches meet there
            found.append(Candidate(x_c=x_c, slope=slope))
        tip = self._tip_within(target, value, tolerance)
        if tip is not None and all(c.x_c != tip.x_c for c in found):
            found.append(tip)
        return tuple(sorted(found, key=lambda c: c.x_c))

    def _tip_within(self, target: float, omega1: float, tolerance: float) -> Candidate | None:
        """The tip as a candidate when ``omega1`` misses the last branch by <= ``tolerance``."""
        if not (math.isfinite(tolerance) and tolerance >= 0.0):
            raise BeamInputError("tolerance", f"must be >= 0, got {format_value(tolerance)}")
        last = self._branches[-1]
        if tolerance == 0.0 or _in_branch(target, last):
            return None
        omega_tip = self._lam_list[-1] ** 2 * self._scale
        # the side of omega_1(l) the last branch does not reach: below it when the branch falls
        # to the tip, above it when it rises
        falling = last.nodes[0] == len(self._lam_list) - 1
        beyond = omega_tip - omega1 if falling else omega1 - omega_tip
        if not 0.0 < beyond <= tolerance:
            return None
        slope = 2.0 * self._lam_list[-1] * self._slope_list[-1] * self._scale / self.link.length
        return Candidate(x_c=self.link.length, slope=slope)

    def invert(self, omega1: ArrayLike) -> Inversion:
        """Vectorised inverse: candidates per monotone branch for every frequency (rad/s).

        Parameters
        ----------
        omega1 : array_like
            Fundamental frequencies (rad/s), any shape; must be finite.

        Returns
        -------
        Inversion
            ``x_c`` and ``slope`` of shape ``omega1.shape + (n_branches,)``, NaN where a branch
            does not reach the frequency.
        """
        omega = as_finite_array("omega1", omega1)
        target = np.sqrt(np.maximum(omega, 0.0) / self._scale)
        target = np.where(omega > 0, target, -1.0).reshape(-1)
        n_b = len(self._branches)
        x_out = np.full((target.size, n_b), np.nan)
        s_out = np.full((target.size, n_b), np.nan)
        for col, branch in enumerate(self._branches):
            keys = np.array(branch.keys)
            nodes = np.array(branch.nodes)
            low_ok = target > keys[0] if branch.open_low else target >= keys[0]
            high_ok = target < keys[-1] if branch.open_high else target <= keys[-1]
            idx = np.flatnonzero(low_ok & high_ok)
            if idx.size == 0:
                continue
            y = target[idx]
            p = np.clip(np.searchsorted(keys, y, side="right") - 1, 0, keys.size - 2)
            i = np.minimum(nodes[p], nodes[p + 1])
            j = i + 1
            x0, width = self.xi[i], self.xi[j] - self.xi[i]
            y0, y1 = self.lam[i], self.lam[j]
            m0, m1 = self.lam_slope[i] * width, self.lam_slope[j] * width
            t = _solve_cubic_array(y, y0, y1, m0, m1)
            lam, deriv = _hermite_array(t, y0, y1, m0, m1)
            x_out[idx, col] = (x0 + t * width) * self.link.length
            s_out[idx, col] = 2.0 * lam * (deriv / width) * self._scale / self.link.length
        # a frequency exactly at an extremum appears in both adjacent branches: keep one
        for col in range(1, n_b):
            same = x_out[:, col] == x_out[:, col - 1]
            x_out[same, col] = np.nan
            s_out[same, col] = np.nan
        shape = (*omega.shape, n_b)
        return Inversion(omega1=omega, x_c=x_out.reshape(shape), slope=s_out.reshape(shape))


def _in_branch(target: float, branch: _Branch) -> bool:
    keys = branch.keys
    low_ok = target > keys[0] if branch.open_low else target >= keys[0]
    high_ok = target < keys[-1] if branch.open_high else target <= keys[-1]
    return low_ok and high_ok


def _split_branches(xi: FloatArray, lam: FloatArray, extrema: list[float]) -> tuple[_Branch, ...]:
    """Monotone runs between xi = 0, the extrema and xi = 1."""
    cuts = [0] + [int(np.searchsorted(xi, x)) for x in extrema] + [xi.size - 1]
    branches = []
    for start, stop in itertools.pairwise(cuts):
        nodes = list(range(start, stop + 1))
        rising = lam[stop] > lam[start]
        if not rising:
            nodes.reverse()
        keys = [float(lam[k]) for k in nodes]
        # xi = 0 is only a limit; it sits at the low end of a rising first branch
        zero_low = start == 0 and rising
        zero_high = start == 0 and not rising
        branches.append(
            _Branch(keys=tuple(keys), nodes=tuple(nodes), open_low=zero_low, open_high=zero_high)
        )
    return tuple(branches)


def _hermite_array(
    t: FloatArray, y0: FloatArray, y1: FloatArray, m0: FloatArray, m1: FloatArray
) -> tuple[FloatArray, FloatArray]:
    t2, t3 = t * t, t * t * t
    value = (2 * t3 - 3 * t2 + 1) * y0 + (t3 - 2 * t2 + t) * m0 + (-2 * t3 + 3 * t2) * y1
    value = value + (t3 - t2) * m1
    deriv = (6 * t2 - 6 * t) * (y0 - y1) + (3 * t2 - 4 * t + 1) * m0 + (3 * t2 - 2 * t) * m1
    return value, deriv


def _solve_cubic_array(
    target: FloatArray, y0: FloatArray, y1: FloatArray, m0: FloatArray, m1: FloatArray
) -> FloatArray:
    """Vectorised :func:`_solve_cubic`."""
    rising = y1 > y0
    lo = np.zeros_like(target)
    hi = np.ones_like(target)
    t = (target - y0) / (y1 - y0)
    done = (target == y0) | (target == y1)
    t = np.where(target == y0, 0.0, np.where(target == y1, 1.0, t))
    for _ in range(_MAX_NEWTON):
        if done.all():
            break
        value, deriv = _hermite_array(t, y0, y1, m0, m1)
        residual = value - target
        below = (residual < 0) == rising
        lo = np.where(~done & below, t, lo)
        hi = np.where(~done & ~below, t, hi)
        with np.errstate(divide="ignore", invalid="ignore"):
            t_new = t - residual / deriv
        bad = ~((t_new > lo) & (t_new < hi))
        t_new = np.where(bad, 0.5 * (lo + hi), t_new)
        t_new = np.where(done | (residual == 0), t, t_new)
        done = done | (residual == 0) | (np.abs(t_new - t) <= _T_TOL)
        t = t_new
    return t
