"""Compiled kernels of the damped-sinusoid fit of :mod:`.parametric`.

The model of a window (docs/fast.md) is linear in the polynomial, regressor and mode amplitudes
and nonlinear in the (w, s) pair of each mode, so it is fitted by variable projection (Golub
and Pereyra 1973): the amplitudes are solved for at every (w, s) and the solver sees only the
two to six nonlinear parameters. Each window needs some ten such solves; the arithmetic of one
is small (a QR factorization of a few hundred rows by ten to twenty columns), so in NumPy and
``scipy.optimize.least_squares`` the per-call overhead was most of the cost. Here the columns,
the residual, Kaufman's Jacobian and a bounded trust-region Levenberg-Marquardt solver are
compiled with numba.

Layout shared by every kernel:

- ``fixed`` (n, F): the columns that do not depend on (w, s) (polynomial, regressors);
- ``axes`` (A, n): the time of every sample on each mode time axis (s): the window's own (from
  its centre) and, for a restart, the time since the restart sample;
- ``starts`` (A,): the first sample at which each axis's columns are on (0, or the restart);
- ``params`` (2M,): w_0, s_0, w_1, s_1, ... (rad/s, 1/s);
- columns F + 2 M a + 2 j and F + 2 M a + 2 j + 1: exp(-s_j t) cos(w_j t) and
  exp(-s_j t) sin(w_j t) on axis a.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

__all__ = [
    "bounded_levenberg_marquardt",
    "mode_columns",
    "mode_derivatives",
    "projected_residual",
    "residual_and_jacobian",
]

#: Status of :func:`bounded_levenberg_marquardt` (as ``least_squares``' ``status``: > 0 means a
#: tolerance was met): evaluations used up, gradient, cost, step, trust region collapsed.
MAX_EVALUATIONS, GRADIENT, COST, STEP, REGION = 0, 1, 2, 3, 4


@njit(cache=True)
def mode_columns(
    fixed: FloatArray, axes: FloatArray, starts: IntArray, params: FloatArray
) -> FloatArray:
    """Every column of the model at (w, s), shape (n, F + 2 M A)."""
    n, n_fixed = fixed.shape
    n_modes = params.size // 2
    out = np.zeros((n, n_fixed + 2 * n_modes * axes.shape[0]))
    out[:, :n_fixed] = fixed
    for a in range(axes.shape[0]):
        first = n_fixed + 2 * n_modes * a
        for j in range(n_modes):
            omega, decay = params[2 * j], params[2 * j + 1]
            for i in range(starts[a], n):
                t = axes[a, i]
                envelope = math.exp(-decay * t)
                out[i, first + 2 * j] = envelope * math.cos(omega * t)
                out[i, first + 2 * j + 1] = envelope * math.sin(omega * t)
    return out


@njit(cache=True)
def mode_derivatives(
    axes: FloatArray, starts: IntArray, n_fixed: int, params: FloatArray, coef: FloatArray
) -> FloatArray:
    """d(columns @ coef) / d(w_j, s_j), shape (2M, n, K); ``coef`` (n_columns, K)."""
    n = axes.shape[1]
    n_modes = params.size // 2
    n_channels = coef.shape[1]
    out = np.zeros((2 * n_modes, n, n_channels))
    for a in range(axes.shape[0]):
        first = n_fixed + 2 * n_modes * a
        for j in range(n_modes):
            omega, decay = params[2 * j], params[2 * j + 1]
            for i in range(starts[a], n):
                t = axes[a, i]
                envelope = math.exp(-decay * t)
                c = envelope * math.cos(omega * t)
                s = envelope * math.sin(omega * t)
                for k in range(n_channels):
                    a_k, b_k = coef[first + 2 * j, k], coef[first + 2 * j + 1, k]
                    # d/dw: t (b cos - a sin) envelope;  d/ds: -t (a cos + b sin) envelope
                    out[2 * j, i, k] += t * (b_k * c - a_k * s)
                    out[2 * j + 1, i, k] -= t * (a_k * c + b_k * s)
    return out


@njit(cache=True)
def _projection(
    fixed: FloatArray, axes: FloatArray, starts: IntArray, params: FloatArray, weighted: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Q, R of the columns at (w, s), Q^T ``weighted`` and the residual (n, K) after the linear
    least-squares solve."""
    q, r = np.linalg.qr(mode_columns(fixed, axes, starts, params))
    q = np.ascontiguousarray(q)
    projected = np.ascontiguousarray(q.T) @ weighted
    return q, r, projected, weighted - q @ projected


@njit(cache=True)
def _back_substitution(upper: FloatArray, rhs: FloatArray) -> FloatArray:
    """Solution of ``upper`` x = ``rhs`` (upper triangular, shape (P, P); rhs (P, K)); an
    unknown whose pivot is exactly zero (columns linearly dependent) is set to zero."""
    size, n_rhs = rhs.shape
    out = np.zeros((size, n_rhs))
    for i in range(size - 1, -1, -1):
        if upper[i, i] == 0.0:
            continue
        for k in range(n_rhs):
            acc = rhs[i, k]
            for j in range(i + 1, size):
                acc -= upper[i, j] * out[j, k]
            out[i, k] = acc / upper[i, i]
    return out


@njit(cache=True)
def projected_residual(
    fixed: FloatArray, axes: FloatArray, starts: IntArray, params: FloatArray, weighted: FloatArray
) -> FloatArray:
    """Residual of ``weighted`` (n, K) after the linear least-squares solve at (w, s), (n K,)."""
    return _projection(fixed, axes, starts, params, weighted)[3].ravel()


@njit(cache=True)
def residual_and_jacobian(
    fixed: FloatArray, axes: FloatArray, starts: IntArray, params: FloatArray, weighted: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The residual of :func:`projected_residual` and Kaufman's approximation of its Jacobian,
    -(I - Q Q^T) dPhi_j C, shape (n K, 2M) (rows in the residual's order, sample-major)."""
    q, r, projected, residual = _projection(fixed, axes, starts, params, weighted)
    coef = _back_substitution(r, projected)
    derivatives = mode_derivatives(axes, starts, fixed.shape[1], params, coef)
    qt = np.ascontiguousarray(q.T)
    jacobian = np.empty((residual.size, params.size))
    for p in range(params.size):
        column = derivatives[p] - q @ (qt @ derivatives[p])
        jacobian[:, p] = -column.ravel()
    return residual.ravel(), jacobian


@njit(cache=True)
def _trust_region_step(
    normal: FloatArray,
    gradient: FloatArray,
    scale: FloatArray,
    free: NDArray[np.bool_],
    radius: float,
) -> FloatArray:
    """The Levenberg-Marquardt step on the ``free`` parameters within ||scale * step|| <= radius.

    Minimises the Gauss-Newton model g^T p + p^T (J^T J) p / 2 in the scaled variables
    u = scale * p: the eigen-decomposition of the scaled normal matrix gives ||u(mu)|| for any
    damping mu in closed form, and mu is found by Newton's method on ||u(mu)|| = radius
    (Moré 1978), bracketed.
    """
    index = np.flatnonzero(free)
    m = index.size
    step = np.zeros(gradient.size)
    if m == 0:
        return step
    scaled_normal = np.empty((m, m))
    scaled_gradient = np.empty(m)
    for a in range(m):
        scaled_gradient[a] = gradient[index[a]] / scale[index[a]]
        for b in range(m):
            scaled_normal[a, b] = normal[index[a], index[b]] / (scale[index[a]] * scale[index[b]])
    eigenvalues, vectors = np.linalg.eigh(scaled_normal)
    eigenvalues = np.maximum(eigenvalues, 0.0)
    # A floor keeps a singular direction finite (it is then limited by the radius)
    floor = 1e-12 * max(eigenvalues[-1], 1e-300)
    weights = vectors.T @ scaled_gradient
    mu = 0.0
    if math.sqrt(np.sum((weights / (eigenvalues + floor)) ** 2)) > radius:
        low, high = 0.0, math.sqrt(np.sum(weights**2)) / radius
        mu = high
        for _ in range(60):
            length = math.sqrt(np.sum((weights / (eigenvalues + mu + floor)) ** 2))
            if abs(length - radius) <= 1e-3 * radius:
                break
            if length > radius:
                low = mu
            else:
                high = mu
            slope = -np.sum(weights**2 / (eigenvalues + mu + floor) ** 3) / length
            # Newton on 1/||u|| - 1/radius, nearly linear in mu
            trial = mu - (length - radius) / slope * (length / radius)
            mu = trial if low < trial < high else 0.5 * (low + high)
    scaled_step = -(vectors @ (weights / (eigenvalues + mu + floor)))
    for a in range(m):
        step[index[a]] = scaled_step[a] / scale[index[a]]
    return step


@njit(cache=True)
def bounded_levenberg_marquardt(
    fixed: FloatArray,
    axes: FloatArray,
    starts: IntArray,
    weighted: FloatArray,
    start: FloatArray,
    lower: FloatArray,
    upper: FloatArray,
    xtol: float,
    ftol: float,
    gtol: float,
    max_evaluations: int,
) -> tuple[FloatArray, int]:
    """Least-squares (w, s) of the variable-projection residual, within [lower, upper].

    A trust-region Levenberg-Marquardt method with Marquardt's scaling (the Jacobian's column
    norms, never decreasing) and the initial radius ||scale * start||, as ``least_squares``
    with ``x_scale="jac"``. Bounds: a parameter at a bound whose gradient points outwards is
    held there for the step, and the step is clipped to the box. Stops as ``least_squares``
    does: gradient (scaled, over the free parameters) below ``gtol``; an accepted step that
    lowers the cost by less than ``ftol`` of it; a step shorter than
    ``xtol * (xtol + ||params||)``; or ``max_evaluations`` residual evaluations.

    Returns
    -------
    params : array, shape (2M,)
    status : int
        :data:`MAX_EVALUATIONS` (0, not converged) or the test met (> 0).
    """
    params = np.minimum(np.maximum(start, lower), upper)
    residual, jacobian = residual_and_jacobian(fixed, axes, starts, params, weighted)
    cost = 0.5 * (residual @ residual)
    evaluations = 1
    n_par = params.size
    scale = np.empty(n_par)
    for p in range(n_par):
        norm = math.sqrt(np.sum(jacobian[:, p] ** 2))
        scale[p] = norm if norm > 0.0 else 1.0
    normal = jacobian.T @ jacobian
    gradient = jacobian.T @ residual
    radius = math.sqrt(np.sum((scale * params) ** 2))
    if radius == 0.0:
        radius = 1.0
    while evaluations < max_evaluations:
        free = np.ones(n_par, dtype=np.bool_)
        largest = 0.0
        for p in range(n_par):
            held_low = params[p] <= lower[p] and gradient[p] > 0.0
            held_high = params[p] >= upper[p] and gradient[p] < 0.0
            if held_low or held_high:
                free[p] = False
            else:
                largest = max(largest, abs(gradient[p]) / scale[p])
        if largest < gtol:
            return params, GRADIENT
        step = _trust_region_step(normal, gradient, scale, free, radius)
        trial = np.minimum(np.maximum(params + step, lower), upper)
        step = trial - params
        trial_residual = projected_residual(fixed, axes, starts, trial, weighted)
        evaluations += 1
        trial_cost = 0.5 * (trial_residual @ trial_residual)
        predicted = -(gradient @ step + 0.5 * (step @ (normal @ step)))
        actual = cost - trial_cost if np.isfinite(trial_cost) else -1.0
        ratio = actual / predicted if predicted > 0.0 else -1.0
        step_length = math.sqrt(np.sum((scale * step) ** 2))
        if ratio < 0.25:
            radius = 0.25 * (step_length if step_length > 0.0 else radius)
        elif ratio > 0.75 and step_length > 0.95 * radius:
            radius *= 2.0
        small_step = math.sqrt(step @ step) < xtol * (xtol + math.sqrt(trial @ trial))
        if actual > 0.0 and ratio > 1e-4:
            small_change = actual < ftol * cost and ratio > 0.25
            params = trial
            residual, jacobian = residual_and_jacobian(fixed, axes, starts, params, weighted)
            cost = trial_cost
            for p in range(n_par):
                scale[p] = max(scale[p], math.sqrt(np.sum(jacobian[:, p] ** 2)))
            normal = jacobian.T @ jacobian
            gradient = jacobian.T @ residual
            if small_change:
                return params, COST
            if small_step:
                return params, STEP
        elif small_step:
            return params, STEP
        elif radius < 1e-15 * max(math.sqrt(np.sum((scale * params) ** 2)), 1.0):
            return params, REGION
    return params, MAX_EVALUATIONS
