"""Non-dimensional frequency equation of the link in contact mode (Section 3.3, Eq. 4).

Everything here is dimensionless: the coordinate is ``s = x / l``, the contact point
``xi = x_c / l`` and the frequency parameter ``lam = beta l``, with
``beta^4 = rho omega^2 / (E I)``.
The physical frequency is ``omega = lam^2 / (T l^2)`` (see :mod:`sensing_antenna.beam.modes`).

Derivation (the printed Eq. 6 of the paper fails the limit checks and is not used). The link is
clamped at ``s = 0``, pinned at ``s = xi`` (zero deflection, continuous slope and moment, free
shear jump) and free at ``s = 1`` where a tip mass ``m_t`` obeys ``E I y'''(l) = m_t y_tt(l)``,
i.e. ``phi'''(1) = -R_m lam^4 phi(1)`` with ``R_m = m_t / m_b``. Eliminating everything but the
rotation ``theta`` of the pin leaves one equation, moment balance at the pin::

    F(lam) = a1(lam) + b2(lam) = 0,
    a1 = lam n(mu1) / d(mu1)                                     (span [0, xi], clamped-pinned)
    b2 = -lam [n(mu2) + 2 R lam sin mu2 sinh mu2] / g(mu2)       (span [xi, 1], pinned-free)

with ``mu1 = lam xi``, ``mu2 = lam (1 - xi)``, ``n(mu) = sin mu cosh mu - cos mu sinh mu``,
``d(mu) = 1 - cos mu cosh mu`` and ``g(mu2) = 1 + cos mu2 cosh mu2 + R lam (cos mu2 sinh mu2 -
sin mu2 cosh mu2)`` (the cantilever-with-tip-mass function). ``a1`` and ``b2`` are the rotational
dynamic stiffnesses of the two spans at the pin; they have poles, so roots are bracketed on the
pole-free product ``D = n(mu1) g(mu2) - d(mu1) [n(mu2) + 2 R lam sin mu2 sinh mu2]``, scaled by
``cosh mu1 cosh mu2 mu1^3 / (1 + mu1^3)`` so that it neither overflows nor vanishes identically as
``xi -> 0``. Limits: ``xi = 1`` gives ``n(lam) = 0`` (clamped-pinned), ``xi -> 0`` gives
``g(lam) = 0`` (cantilever with tip mass), ``R -> inf`` at ``xi = 0`` gives clamped-pinned again.

Root counting uses the Wittrick-Williams algorithm: the number of eigenvalues below ``lam`` is
``J = J0 + s{K}``, where ``J0`` counts the clamped-clamped eigenvalues of the two spans and
``s{K}`` is the number of negative pivots of the dynamic stiffness matrix on the degrees of
freedom (tip deflection, tip rotation, pin rotation), eliminated in that order: the last pivot is
``F`` itself. Bisection on ``J`` isolates each root in a bracket holding exactly one eigenvalue,
then a vectorised Illinois (regula falsi) iteration on ``D`` refines it to machine precision.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.beam._validate import (
    BeamInputError,
    as_finite_array,
    check_mode_count,
)
from sensing_antenna.errors import format_value

__all__ = [
    "characteristic_function",
    "eigenvalue_slopes",
    "eigenvalues",
    "mode_count",
]

FloatArray = NDArray[np.float64]

#: Below this argument the functions n(mu) and d(mu) are evaluated from their Taylor series:
#: their closed forms lose all digits to cancellation as mu -> 0; at mu = 1 the truncation error of
#: the six-term series is below 1e-19 and the closed form loses under one digit.
SERIES_SWITCH = 1.0

# Taylor coefficients in u = mu^4 of n(mu) / mu^3 and d(mu) / mu^4 (derived with sympy).
_N_OVER_MU3 = (
    2.0 / 3.0,
    -1.0 / 315.0,
    1.0 / 623700.0,
    -1.0 / 5108103000.0,
    1.0 / 118794043368000.0,
    -1.0 / 6311527524141840000.0,
)
_D_OVER_MU4 = (
    1.0 / 6.0,
    -1.0 / 2520.0,
    1.0 / 7484400.0,
    -1.0 / 81729648000.0,
    1.0 / 2375880867360000.0,
    -1.0 / 151476660579404160000.0,
)

#: Relative width at which a bracket counts as converged (a few ulps).
_ROOT_RTOL = 4.0 * np.finfo(np.float64).eps
#: Iteration caps: each bisection halves the bracket, so 200 steps reach any float spacing.
_MAX_BISECTIONS = 200
_MAX_ILLINOIS = 100


def _poly(coeffs: tuple[float, ...], u: FloatArray) -> FloatArray:
    result = np.full_like(u, coeffs[-1])
    for c in coeffs[-2::-1]:
        result = result * u + c
    return result


class _SpanTerms:
    """Scaled trigonometric and hyperbolic terms of one span, argument mu >= 0.

    Attributes (all bounded for any mu): ``c, s`` = cos, sin; ``t`` = tanh; ``e`` = sech;
    ``n_c = n / cosh``; ``d_c = d / cosh``; ``nu = n / (cosh h)``, ``eps = d / (cosh h)`` with
    ``h = mu^3 / (1 + mu^3)``.
    """

    __slots__ = ("c", "d_c", "e", "eps", "n_c", "nu", "s", "t")

    def __init__(self, mu: FloatArray) -> None:
        self.c = np.cos(mu)
        self.s = np.sin(mu)
        self.t = np.tanh(mu)
        em = np.exp(-mu)
        self.e = 2.0 * em / (1.0 + em * em)
        small = mu < SERIES_SWITCH
        mu_small = np.where(small, mu, 0.0)
        u = mu_small**4
        n3 = _poly(_N_OVER_MU3, u)  # n / mu^3
        d3 = _poly(_D_OVER_MU4, u) * mu_small  # d / mu^3
        mu3_small = mu_small**3
        mu_large = np.where(small, 1.0, mu)
        n_c_large = self.s - self.c * self.t
        d_c_large = self.e - self.c
        growth = (1.0 + mu_large**3) / mu_large**3
        self.n_c = np.where(small, n3 * mu3_small * self.e, n_c_large)
        self.d_c = np.where(small, d3 * mu3_small * self.e, d_c_large)
        self.nu = np.where(small, n3 * (1.0 + mu3_small) * self.e, n_c_large * growth)
        self.eps = np.where(small, d3 * (1.0 + mu3_small) * self.e, d_c_large * growth)


def _spans(
    lam: FloatArray, xi: FloatArray, ratio: float
) -> tuple[_SpanTerms, _SpanTerms, FloatArray, FloatArray]:
    """Terms of both spans plus g(mu2)/cosh(mu2) and the pinned-free numerator / cosh(mu2)."""
    one = _SpanTerms(lam * xi)
    two = _SpanTerms(lam * (1.0 - xi))
    r_lam = ratio * lam
    # Eq. 4, tip mass E I y'''(l) = m_t y_tt(l): cantilever-with-tip-mass function g / cosh
    g_scaled = two.e + two.c + r_lam * (two.c * two.t - two.s)
    # Eq. 4, pinned end at x_c, free end with tip mass: numerator of -b2 / lam, over cosh
    h_scaled = two.n_c + 2.0 * r_lam * two.s * two.t
    return one, two, g_scaled, h_scaled


def _characteristic(lam: FloatArray, xi: FloatArray, ratio: float) -> FloatArray:
    one, _, g_scaled, h_scaled = _spans(lam, xi, ratio)
    # Eq. 4: moment balance at the pin, a1 + b2 = 0, times d(mu1) g(mu2) (pole-free form)
    return np.asarray(one.nu * g_scaled - one.eps * h_scaled)


def _clamped_clamped_count(terms: _SpanTerms, mu: FloatArray) -> NDArray[np.int64]:
    """Number of clamped-clamped eigenvalues (cos mu cosh mu = 1) below mu.

    The k-th root lies in (k pi, (k + 1) pi); inside [i pi, (i + 1) pi) the sign of d(mu) tells
    whether it has been passed (Williams and Wittrick 1970).
    """
    i = np.floor(mu / np.pi).astype(np.int64)
    parity = np.where(i % 2 == 0, 1.0, -1.0)
    passed = (1.0 + parity * np.sign(terms.d_c)) / 2.0
    return np.where(i == 0, 0, i - 1 + passed.astype(np.int64))


def _count(lam: FloatArray, xi: FloatArray, ratio: float) -> NDArray[np.int64]:
    one, two, g_scaled, h_scaled = _spans(lam, xi, ratio)
    j0 = _clamped_clamped_count(one, lam * xi) + _clamped_clamped_count(two, lam * (1.0 - xi))
    # Pivot 1: tip deflection, K_ww = lam^3 (f5 - R lam d_c) / d_c,
    # f5 = (cos sinh + sin cosh) / cosh
    f5_minus_mass = two.c * two.t + two.s - ratio * lam * two.d_c
    sign_p1 = np.sign(f5_minus_mass) * np.sign(two.d_c)
    # Pivot 2: det(K_tip) / K_ww, det(K_tip) = lam^4 [(f5 - R lam d_c) n_c - (sin tanh)^2] / d_c^2
    sign_p2 = np.sign(f5_minus_mass * two.n_c - (two.s * two.t) ** 2) * sign_p1
    # Pivot 3: F = a1 + b2 = lam D / (eps1 g2)
    d_scaled = one.nu * g_scaled - one.eps * h_scaled
    sign_p3 = np.sign(d_scaled) * np.sign(one.eps) * np.sign(g_scaled)
    negatives = (sign_p1 < 0).astype(np.int64) + (sign_p2 < 0) + (sign_p3 < 0)
    return np.asarray(j0 + negatives, dtype=np.int64)


def _check_ratio(tip_mass_ratio: float) -> float:
    if not (isinstance(tip_mass_ratio, (int, float, np.floating)) and tip_mass_ratio >= 0):
        raise BeamInputError(
            "tip_mass_ratio", f"must be a finite number >= 0, got {format_value(tip_mass_ratio)}"
        )
    if not math.isfinite(tip_mass_ratio):
        raise BeamInputError(
            "tip_mass_ratio", f"must be a finite number >= 0, got {format_value(tip_mass_ratio)}"
        )
    return float(tip_mass_ratio)


def characteristic_function(
    lam: ArrayLike, xi: ArrayLike, tip_mass_ratio: float = 0.0
) -> FloatArray:
    """Scaled, pole-free frequency function D(beta l; xi, R_m) whose zeros are the eigenvalues.

    Parameters
    ----------
    lam : array_like
        Frequency parameter beta l >= 0 (dimensionless).
    xi : array_like
        Contact point x_c / l in [0, 1], broadcast against ``lam``; 0 is the cantilever limit.
    tip_mass_ratio : float
        R_m = m_t / m_b >= 0.

    Returns
    -------
    ndarray
        D, broadcast shape of ``lam`` and ``xi``; bounded, changes sign at each simple eigenvalue.
    """
    lam_a = as_finite_array("lam", lam, low=0.0)
    xi_a = as_finite_array("xi", xi, low=0.0, high=1.0)
    lam_b, xi_b = np.broadcast_arrays(lam_a, xi_a)
    return _characteristic(lam_b, xi_b, _check_ratio(tip_mass_ratio))


def mode_count(lam: ArrayLike, xi: ArrayLike, tip_mass_ratio: float = 0.0) -> NDArray[np.int64]:
    """Wittrick-Williams count: how many natural frequencies have beta_i l < ``lam``.

    Parameters and broadcasting as in :func:`characteristic_function`; returns integers.
    """
    lam_a = as_finite_array("lam", lam, low=0.0)
    xi_a = as_finite_array("xi", xi, low=0.0, high=1.0)
    lam_b, xi_b = np.broadcast_arrays(lam_a, xi_a)
    return _count(lam_b, xi_b, _check_ratio(tip_mass_ratio))


def _bisect_on_count(
    lo: FloatArray,
    hi: FloatArray,
    j_lo: NDArray[np.int64],
    j_hi: NDArray[np.int64],
    xi: FloatArray,
    k: NDArray[np.int64],
    ratio: float,
    to_full_precision: bool,
) -> None:
    """Shrink [lo, hi] in place keeping j_lo <= k - 1 < k <= j_hi.

    Stops when the bracket holds exactly the k-th eigenvalue (j_lo = k - 1, j_hi = k), or, with
    ``to_full_precision``, when it is a few ulps wide.
    """
    for _ in range(_MAX_BISECTIONS):
        narrow = hi - lo <= _ROOT_RTOL * hi
        if to_full_precision:
            active = ~narrow
        else:
            active = ~narrow & ~((j_lo == k - 1) & (j_hi == k))
        idx = np.flatnonzero(active)
        if idx.size == 0:
            return
        mid = 0.5 * (lo[idx] + hi[idx])
        j_mid = _count(mid, xi[idx], ratio)
        upper = j_mid >= k[idx]
        hi[idx[upper]] = mid[upper]
        j_hi[idx[upper]] = j_mid[upper]
        lo[idx[~upper]] = mid[~upper]
        j_lo[idx[~upper]] = j_mid[~upper]


def _illinois(lo: FloatArray, hi: FloatArray, xi: FloatArray, ratio: float) -> FloatArray:
    """Refine roots of D bracketed by [lo, hi] (sign change assumed); returns the roots."""
    f_lo = _characteristic(lo, xi, ratio)
    f_hi = _characteristic(hi, xi, ratio)
    root = 0.5 * (lo + hi)
    exact = (f_lo == 0) | (f_hi == 0)
    root[f_lo == 0] = lo[f_lo == 0]
    root[f_hi == 0] = hi[f_hi == 0]
    side = np.zeros(lo.shape, dtype=np.int64)  # which end moved last: -1 lo, +1 hi
    done = exact | (hi - lo <= _ROOT_RTOL * hi)
    for _ in range(_MAX_ILLINOIS):
        idx = np.flatnonzero(~done)
        if idx.size == 0:
            break
        a, b, fa, fb = lo[idx], hi[idx], f_lo[idx], f_hi[idx]
        x = b - fb * (b - a) / (fb - fa)
        bad = ~((x > a) & (x < b))
        x[bad] = 0.5 * (a[bad] + b[bad])
        fx = _characteristic(x, xi[idx], ratio)
        root[idx] = x
        hit = fx == 0
        done[idx[hit]] = True
        move_hi = (np.sign(fx) == np.sign(fb)) & ~hit
        move_lo = ~move_hi & ~hit
        # Illinois: halve the stale end's value when the same end moves twice in a row
        i_hi, i_lo = idx[move_hi], idx[move_lo]
        f_lo[i_hi[side[i_hi] == 1]] *= 0.5
        f_hi[i_lo[side[i_lo] == -1]] *= 0.5
        hi[i_hi], f_hi[i_hi], side[i_hi] = x[move_hi], fx[move_hi], 1
        lo[i_lo], f_lo[i_lo], side[i_lo] = x[move_lo], fx[move_lo], -1
        narrow = hi[idx] - lo[idx] <= _ROOT_RTOL * hi[idx]
        done[idx[narrow]] = True
        root[idx[narrow]] = 0.5 * (lo[idx[narrow]] + hi[idx[narrow]])
    return root


def _solve(xi: FloatArray, n_modes: int, ratio: float) -> FloatArray:
    """Eigenvalues beta_k l, k = 1..n_modes, for a flat array xi; shape (len(xi), n_modes)."""
    k = np.broadcast_to(np.arange(1, n_modes + 1), (xi.size, n_modes)).ravel()
    xi_f = np.repeat(xi, n_modes)
    lo = np.zeros(k.shape)
    # Upper bound: clamping the pin rotation and the tip only raises eigenvalues; the k-th
    # eigenvalue of the two clamped-clamped spans is below 2 (k + 1) pi for any xi.
    hi = np.asarray(2.0 * (k + 1) * np.pi, dtype=np.float64)
    j_lo = np.zeros(k.shape, dtype=np.int64)
    j_hi = _count(hi, xi_f, ratio)
    if np.any(j_hi < k):  # pragma: no cover - guarded by the bound above
        raise RuntimeError("eigenvalue upper bound failed; please report")
    _bisect_on_count(lo, hi, j_lo, j_hi, xi_f, k, ratio, to_full_precision=False)
    isolated = (j_lo == k - 1) & (j_hi == k)
    d_lo = _characteristic(lo, xi_f, ratio)
    d_hi = _characteristic(hi, xi_f, ratio)
    sign_change = isolated & (np.sign(d_lo) * np.sign(d_hi) <= 0)
    roots = 0.5 * (lo + hi)
    idx = np.flatnonzero(sign_change)
    roots[idx] = _illinois(lo[idx], hi[idx], xi_f[idx], ratio)
    rest = np.flatnonzero(~sign_change)
    if rest.size:
        # Repeated eigenvalue or rounding at a pole: finish by bisection on the count alone.
        lo_r, hi_r, jl_r, jh_r = lo[rest], hi[rest], j_lo[rest], j_hi[rest]
        _bisect_on_count(lo_r, hi_r, jl_r, jh_r, xi_f[rest], k[rest], ratio, True)
        roots[rest] = 0.5 * (lo_r + hi_r)
    return roots.reshape(xi.size, n_modes)


def eigenvalues(xi: ArrayLike, n_modes: int = 3, tip_mass_ratio: float = 0.0) -> FloatArray:
    """First ``n_modes`` frequency parameters beta_i l of the link touching at ``xi = x_c / l``.

    Parameters
    ----------
    xi : array_like
        Contact point as a fraction of the length, in [0, 1]; 0 is the limit x_c -> 0
        (cantilever with tip mass), 1 is contact at the tip (clamped-pinned span).
    n_modes : int
        Number of modes, >= 1.
    tip_mass_ratio : float
        R_m = m_t / m_b >= 0 (Eq. 4).

    Returns
    -------
    ndarray
        beta_i l, shape ``xi.shape + (n_modes,)``, strictly increasing along the last axis
        (equal only at an exactly repeated eigenvalue).

    Raises
    ------
    BeamInputError
        If ``xi`` is outside [0, 1], ``n_modes < 1`` or ``tip_mass_ratio < 0``.
    """
    xi_a = as_finite_array("xi", xi, low=0.0, high=1.0)
    n = check_mode_count(n_modes)
    ratio = _check_ratio(tip_mass_ratio)
    return _solve(xi_a.reshape(-1), n, ratio).reshape((*xi_a.shape, n))


#: Relative step of the central differences in :func:`eigenvalue_slopes`: balances the O(h^2)
#: truncation against rounding of D (about 1e-16 / h), both near 1e-10.
_SLOPE_STEP = 1e-5


def eigenvalue_slopes(xi: ArrayLike, lam: ArrayLike, tip_mass_ratio: float = 0.0) -> FloatArray:
    """d(beta_i l) / d xi at eigenvalues ``lam`` (from :func:`eigenvalues`), implicitly.

    ``d lam / d xi = -(dD/dxi) / (dD/dlam)`` on the root; the partial derivatives are second-order
    finite differences of D (one-sided at xi = 0 and xi = 1). Accuracy about 1e-9 relative.

    Parameters
    ----------
    xi : array_like
        Contact points x_c / l in [0, 1], shape (...).
    lam : array_like
        Eigenvalues at those points, shape (...) or (..., n_modes).
    tip_mass_ratio : float
        R_m >= 0.

    Returns
    -------
    ndarray
        Same shape as ``lam``.
    """
    ratio = _check_ratio(tip_mass_ratio)
    lam_a = as_finite_array("lam", lam, low=0.0, low_open=True)
    xi_a = as_finite_array("xi", xi, low=0.0, high=1.0)
    if lam_a.ndim == xi_a.ndim + 1:
        xi_a = xi_a[..., None]
    lam_b, xi_b = np.broadcast_arrays(lam_a, xi_a)
    h_lam = _SLOPE_STEP * lam_b
    d_lam = (
        _characteristic(lam_b + h_lam, xi_b, ratio) - _characteristic(lam_b - h_lam, xi_b, ratio)
    ) / (2.0 * h_lam)
    h = _SLOPE_STEP
    centre = (xi_b >= h) & (xi_b <= 1.0 - h)
    forward = xi_b < h
    x1 = np.where(centre, xi_b + h, np.where(forward, xi_b + h, xi_b - h))
    x2 = np.where(centre, xi_b - h, np.where(forward, xi_b + 2 * h, xi_b - 2 * h))
    f0 = _characteristic(lam_b, xi_b, ratio)
    f1 = _characteristic(lam_b, x1, ratio)
    f2 = _characteristic(lam_b, x2, ratio)
    one_sided = (-3.0 * f0 + 4.0 * f1 - f2) / (2.0 * h)
    d_xi = np.where(centre, (f1 - f2) / (2.0 * h), np.where(forward, one_sided, -one_sided))
    return np.asarray(-d_xi / d_lam)
