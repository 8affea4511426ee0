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

#: Status of :func:`bounded_levenberg_marquardt`: 0 the evaluations ran out (not converged);
#: > 0 converged (as for ``least_squares``' status, whose codes differ): the scaled gradient,
#: the cost's change, the step's length, or the trust region collapsed.
NOT_CONVERGED, GRADIENT, COST, STEP, REGION = 0, 1, 2, 3, 4

# Trust region (Moré 1978; the values of least_squares' trf): shrink to a quarter of the step
# when the cost fell by less than a quarter of the predicted reduction (such a step does not
# count for the cost test either), double when by more than three quarters and the step reached
# the radius; accept any step with a ratio above 1e-4
_SHRINK_BELOW, _SHRINK_FACTOR, _GROW_ABOVE, _AT_RADIUS, _ACCEPT_ABOVE = 0.25, 0.25, 0.75, 0.95, 1e-4
# Damping search: ||u(mu)|| within 1e-3 of the radius, at most 60 Newton or bisection steps;
# eigenvalues floored at 1e-12 of the largest so a singular direction stays finite
_RADIUS_MATCH, _DAMPING_ITERATIONS, _EIGEN_FLOOR = 1e-3, 60, 1e-12
# The radius has collapsed when below 1e-15 of the scaled parameters
_COLLAPSED = 1e-15


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
    columns: FloatArray, axes: FloatArray, starts: IntArray, n_fixed: int, coef: FloatArray
) -> FloatArray:
    """d(columns @ coef) / d(w_j, s_j), shape (2M, n, K), from the ``columns`` of
    :func:`mode_columns` at (w, s) and ``coef`` (n_columns, K)."""
    n = columns.shape[0]
    n_axes = axes.shape[0]
    n_modes = (columns.shape[1] - n_fixed) // (2 * n_axes)
    out = np.zeros((2 * n_modes, n, coef.shape[1]))
    for a in range(n_axes):
        first = n_fixed + 2 * n_modes * a
        for j in range(n_modes):
            for i in range(starts[a], n):
                t = axes[a, i]
                c, s = columns[i, first + 2 * j], columns[i, first + 2 * j + 1]
                for k in range(coef.shape[1]):
                    a_k, b_k = coef[first + 2 * j, k], coef[first + 2 * j + 1, k]
                    # d/dw: t (b cos - a sin) envelope;  d/ds: -t (a cos + b sin) envelope
                    out[2 * j, i, k] += t * (b_k * c - a_k * s)
                    out[2 * j + 1, i, k] -= t * (a_k * c + b_k * s)
    return out


@njit(cache=True)
def _back_substitution(upper: FloatArray, rhs: FloatArray) -> FloatArray:
    """Solution of ``upper`` x = ``rhs``: upper triangular (P, P) with no zero pivot, rhs (P, K)."""
    size, n_rhs = rhs.shape
    out = np.zeros((size, n_rhs))
    for i in range(size - 1, -1, -1):
        for k in range(n_rhs):
            acc = rhs[i, k]
            for j in range(i + 1, size):
                acc -= upper[i, j] * out[j, k]
            out[i, k] = acc / upper[i, i]
    return out


@njit(cache=True)
def _projection(
    fixed: FloatArray, axes: FloatArray, starts: IntArray, params: FloatArray, weighted: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The linear least-squares solve of ``weighted`` (n, K) at (w, s).

    Returns the columns (n, P), an orthonormal basis Q of their span (n, R), the coefficients
    (P, K) and the residual (n, K). QR when every pivot of R is above max(n, P) eps times the
    largest column norm; otherwise (linearly dependent columns: a regressor that is constant, a
    mode pair restarted at the first or last sample, a mode on the Nyquist frequency, whose sine
    column vanishes) from the singular value decomposition, keeping the directions above that
    tolerance of the largest singular value, with the minimum-norm coefficients (as
    ``numpy.linalg.lstsq``). Columns that are not finite give an infinite residual, an empty Q
    and NaN coefficients.
    """
    columns = mode_columns(fixed, axes, starts, params)
    n, size = columns.shape
    if not np.all(np.isfinite(columns)):
        nan_coef = np.full((size, weighted.shape[1]), np.nan)
        return columns, np.empty((n, 0)), nan_coef, np.full(weighted.shape, np.inf)
    q, r = np.linalg.qr(columns)
    tolerance = max(n, size) * np.finfo(np.float64).eps
    largest_norm = math.sqrt(np.max(np.sum(columns**2, axis=0)))
    if np.abs(np.diag(r)).min() > tolerance * largest_norm:
        q = np.ascontiguousarray(q)
        projected = np.ascontiguousarray(q.T) @ weighted
        coef = _back_substitution(r, projected)
    else:
        u, singular, vt = np.linalg.svd(columns, full_matrices=False)
        keep = singular > tolerance * singular[0]
        q = np.ascontiguousarray(u[:, keep])
        projected = np.ascontiguousarray(q.T) @ weighted
        coef = np.ascontiguousarray(vt[keep].T) @ (projected / singular[keep].reshape(-1, 1))
    return columns, q, coef, weighted - q @ projected


@njit(cache=True)
def projected_residual(
    fixed: FloatArray, axes: FloatArray, starts: IntArray, params: FloatArray, weighted: FloatArray
) -> FloatArray:
    """Residual of ``weighted`` (n, K) after the linear least-squares solve at (w, s), (n K,)
    (sample-major, as ``ravel``)."""
    return _projection(fixed, axes, starts, params, weighted)[3].ravel()


@njit(cache=True)
def _kaufman_jacobian(
    columns: FloatArray,
    axes: FloatArray,
    starts: IntArray,
    n_fixed: int,
    q: FloatArray,
    coef: FloatArray,
) -> FloatArray:
    """Kaufman's approximation of the residual's Jacobian, -(I - Q Q^T) dPhi_j C (Kaufman
    1975), shape (n K, 2M), rows in the residual's order; from :func:`_projection`'s parts."""
    derivatives = mode_derivatives(columns, axes, starts, n_fixed, coef)
    n_channels = coef.shape[1]
    qt = np.ascontiguousarray(q.T)
    jacobian = np.empty((columns.shape[0] * n_channels, derivatives.shape[0]))
    for p in range(derivatives.shape[0]):
        column = derivatives[p] - q @ (qt @ derivatives[p])
        jacobian[:, p] = -column.ravel()
    return jacobian


@njit(cache=True)
def residual_and_jacobian(
    fixed: FloatArray, axes: FloatArray, starts: IntArray, params: FloatArray, weighted: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The residual of :func:`projected_residual` and its :func:`_kaufman_jacobian`."""
    columns, q, coef, residual = _projection(fixed, axes, starts, params, weighted)
    return residual.ravel(), _kaufman_jacobian(columns, axes, starts, fixed.shape[1], q, coef)


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
    damping mu in closed form, and mu is found by Newton's method on 1 / ||u(mu)|| (Moré
    1978), kept inside a bracket. Held parameters do not move.
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
    floor = _EIGEN_FLOOR * max(eigenvalues[-1], 1e-300)
    weights = vectors.T @ scaled_gradient
    mu = 0.0
    if math.sqrt(np.sum((weights / (eigenvalues + floor)) ** 2)) > radius:
        low, high = 0.0, math.sqrt(np.sum(weights**2)) / radius
        mu = high
        for _ in range(_DAMPING_ITERATIONS):
            length = math.sqrt(np.sum((weights / (eigenvalues + mu + floor)) ** 2))
            if abs(length - radius) <= _RADIUS_MATCH * radius:
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
def _free_parameters(
    params: FloatArray, gradient: FloatArray, lower: FloatArray, upper: FloatArray
) -> NDArray[np.bool_]:
    """False for a parameter on a bound that the cost's descent (-gradient) would leave by."""
    held_low = (params <= lower) & (gradient > 0.0)
    held_high = (params >= upper) & (gradient < 0.0)
    return ~(held_low | held_high)


@njit(cache=True)
def _updated_radius(radius: float, ratio: float, step_length: float) -> float:
    """The trust radius after a step of scaled length ``step_length`` whose actual reduction of
    the cost was ``ratio`` times the predicted one."""
    if ratio < _SHRINK_BELOW:
        return _SHRINK_FACTOR * (step_length if step_length > 0.0 else radius)
    if ratio > _GROW_ABOVE and step_length > _AT_RADIUS * radius:
        return 2.0 * radius
    return radius


@njit(cache=True)
def _updated_scale(scale: FloatArray, jacobian: FloatArray) -> FloatArray:
    """Marquardt's scale: each column norm of ``jacobian``, never below the previous scale
    (ones for zero columns at the start, when ``scale`` is all zeros)."""
    out = np.empty(scale.size)
    for p in range(scale.size):
        out[p] = max(scale[p], math.sqrt(np.sum(jacobian[:, p] ** 2)))
        if out[p] == 0.0:
            out[p] = 1.0
    return out


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
    with ``x_scale="jac"``. Bounds: a parameter on a bound whose gradient points outwards is
    held there for the step (:func:`_free_parameters`), and the step is clipped to the box.
    Converged when the largest |g_p| / scale_p over the free parameters is below ``gtol``; when
    an accepted step lowers the cost by less than ``ftol`` of it (with a ratio above 1/4); when
    a step is shorter than ``xtol * (xtol + ||params||)``; or when the radius collapses. Not
    converged after ``max_evaluations`` residual evaluations, or when the start's residual is
    not finite.

    Returns
    -------
    params : array, shape (2M,)
    status : int
        :data:`NOT_CONVERGED` (0) or the test met (> 0).
    """
    n_fixed = fixed.shape[1]
    params = np.minimum(np.maximum(start, lower), upper)
    residual, jacobian = residual_and_jacobian(fixed, axes, starts, params, weighted)
    cost = 0.5 * (residual @ residual)
    if not np.isfinite(cost):
        return params, NOT_CONVERGED
    evaluations = 1
    scale = _updated_scale(np.zeros(params.size), jacobian)
    normal = jacobian.T @ jacobian
    gradient = jacobian.T @ residual
    radius = math.sqrt(np.sum((scale * params) ** 2))
    if radius == 0.0:
        radius = 1.0
    while evaluations < max_evaluations:
        free = _free_parameters(params, gradient, lower, upper)
        if np.max(np.where(free, np.abs(gradient) / scale, 0.0)) < gtol:
            return params, GRADIENT
        step = _trust_region_step(normal, gradient, scale, free, radius)
        trial = np.minimum(np.maximum(params + step, lower), upper)
        step = trial - params
        columns, q, coef, residual_2d = _projection(fixed, axes, starts, trial, weighted)
        evaluations += 1
        trial_residual = residual_2d.ravel()
        trial_cost = 0.5 * (trial_residual @ trial_residual)
        # The Gauss-Newton model's reduction for the (clipped) step
        predicted = -(gradient @ step + 0.5 * (step @ (normal @ step)))
        actual = cost - trial_cost if np.isfinite(trial_cost) else -1.0
        ratio = actual / predicted if predicted > 0.0 else -1.0
        radius = _updated_radius(radius, ratio, math.sqrt(np.sum((scale * step) ** 2)))
        small_step = math.sqrt(step @ step) < xtol * (xtol + math.sqrt(params @ params))
        if actual > 0.0 and ratio > _ACCEPT_ABOVE:
            small_change = actual < ftol * cost and ratio > _SHRINK_BELOW
            params, residual, cost = trial, trial_residual, trial_cost
            jacobian = _kaufman_jacobian(columns, axes, starts, n_fixed, q, coef)
            scale = _updated_scale(scale, jacobian)
            normal = jacobian.T @ jacobian
            gradient = jacobian.T @ residual
            if small_change:
                return params, COST
            if small_step:
                return params, STEP
        elif small_step:
            return params, STEP
        elif radius < _COLLAPSED * max(math.sqrt(np.sum((scale * params) ** 2)), 1.0):
            return params, REGION
    return params, NOT_CONVERGED
