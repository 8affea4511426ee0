"""The bounded trust-region Levenberg-Marquardt solver of the damped-sinusoid fit (numba).

It minimises the variable-projection residual of :mod:`.varpro` over the (w, s) pairs within
bounds, as ``scipy.optimize.least_squares`` does with its trust-region reflective method and
``x_scale="jac"``: Marquardt's scaling by the Jacobian's column norms, never decreasing
(:func:`updated_scale`); the step minimising the Gauss-Newton model within the scaled trust
region (:func:`trust_region_step`, Moré 1978); parameters on a bound that descent would leave
held for the step (:func:`free_parameters`); the radius following the ratio of the actual to the
predicted reduction (:func:`updated_radius`). Layout of the arguments as in :mod:`.varpro`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.compiler import njit
from sensing_antenna.estimation.methods.fast.varpro import (
    kaufman_jacobian,
    projection,
    residual_and_jacobian,
)

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

__all__ = [
    "COST",
    "GRADIENT",
    "NOT_CONVERGED",
    "NOT_FINITE",
    "REGION",
    "STEP",
    "bounded_levenberg_marquardt",
    "free_parameters",
    "trust_region_step",
    "updated_radius",
    "updated_scale",
]

#: Status of :func:`bounded_levenberg_marquardt`: -1 the residual at the start is not finite
#: (nothing was solved); 0 the evaluations ran out (not converged); > 0 converged (as for
#: ``least_squares``' status, whose codes differ): the scaled gradient, the cost's change, the
#: step's length, or the trust region collapsed.
NOT_FINITE, NOT_CONVERGED, GRADIENT, COST, STEP, REGION = -1, 0, 1, 2, 3, 4

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
def trust_region_step(
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
def free_parameters(
    params: FloatArray, gradient: FloatArray, lower: FloatArray, upper: FloatArray
) -> NDArray[np.bool_]:
    """False for a parameter on a bound that the cost's descent (-gradient) would leave by."""
    held_low = (params <= lower) & (gradient > 0.0)
    held_high = (params >= upper) & (gradient < 0.0)
    return ~(held_low | held_high)


@njit(cache=True)
def updated_radius(radius: float, ratio: float, step_length: float) -> float:
    """The trust radius after a step of scaled length ``step_length`` whose actual reduction of
    the cost was ``ratio`` times the predicted one."""
    if ratio < _SHRINK_BELOW:
        return _SHRINK_FACTOR * (step_length if step_length > 0.0 else radius)
    if ratio > _GROW_ABOVE and step_length > _AT_RADIUS * radius:
        return 2.0 * radius
    return radius


@njit(cache=True)
def updated_scale(scale: FloatArray, jacobian: FloatArray) -> FloatArray:
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
    held there for the step (:func:`free_parameters`), and the step is clipped to the box.
    Converged when the largest |g_p| / scale_p over the free parameters is below ``gtol``; when
    an accepted step lowers the cost by less than ``ftol`` of it (with a ratio above 1/4); when
    a step is shorter than ``xtol * (xtol + ||params||)``; or when the radius collapses. Not
    converged after ``max_evaluations`` residual evaluations; :data:`NOT_FINITE` when the
    start's residual is not finite (the caller's check of its start, at no extra cost).

    Returns
    -------
    params : array, shape (2M,)
    status : int
        :data:`NOT_FINITE` (-1), :data:`NOT_CONVERGED` (0) or the test met (> 0).
    """
    n_fixed = fixed.shape[1]
    params = np.minimum(np.maximum(start, lower), upper)
    residual, jacobian = residual_and_jacobian(fixed, axes, starts, params, weighted)
    if not np.all(np.isfinite(residual)):
        return params, NOT_FINITE
    cost = 0.5 * (residual @ residual)
    if not np.isfinite(cost):
        return params, NOT_CONVERGED
    evaluations = 1
    scale = updated_scale(np.zeros(params.size), jacobian)
    normal = jacobian.T @ jacobian
    gradient = jacobian.T @ residual
    radius = math.sqrt(np.sum((scale * params) ** 2))
    if radius == 0.0:
        radius = 1.0
    while evaluations < max_evaluations:
        free = free_parameters(params, gradient, lower, upper)
        if np.max(np.where(free, np.abs(gradient) / scale, 0.0)) < gtol:
            return params, GRADIENT
        step = trust_region_step(normal, gradient, scale, free, radius)
        trial = np.minimum(np.maximum(params + step, lower), upper)
        step = trial - params
        columns, q, coef, residual_2d = projection(fixed, axes, starts, trial, weighted)
        evaluations += 1
        trial_residual = residual_2d.ravel()
        trial_cost = 0.5 * (trial_residual @ trial_residual)
        # The Gauss-Newton model's reduction for the (clipped) step
        predicted = -(gradient @ step + 0.5 * (step @ (normal @ step)))
        actual = cost - trial_cost if np.isfinite(trial_cost) else -1.0
        ratio = float(actual / predicted) if predicted > 0.0 else -1.0
        radius = updated_radius(radius, ratio, math.sqrt(np.sum((scale * step) ** 2)))
        small_step = math.sqrt(step @ step) < xtol * (xtol + math.sqrt(params @ params))
        if actual > 0.0 and ratio > _ACCEPT_ABOVE:
            small_change = actual < ftol * cost and ratio > _SHRINK_BELOW
            params, residual, cost = trial, trial_residual, trial_cost
            jacobian = kaufman_jacobian(columns, axes, starts, n_fixed, q, coef)
            scale = updated_scale(scale, jacobian)
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
