"""The compiled kernels of the damped-sinusoid fit (varpro.py) against independent computations.

References: central finite differences of the model columns (derivatives, and Kaufman's
Jacobian at a zero-residual point, where the term it drops vanishes: Kaufman 1975, BIT 15); the
linear least-squares residual from ``numpy.linalg.lstsq``; the bounded minimum found by
``scipy.optimize.least_squares`` (trust-region reflective) on the same residual.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

from sensing_antenna.estimation.varpro import (
    MAX_EVALUATIONS,
    bounded_levenberg_marquardt,
    mode_columns,
    mode_derivatives,
    projected_residual,
)

TS = 1e-3


def _layout(n: int, restart: int | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Quadratic polynomial columns, the window's time axis and, with ``restart``, its own."""
    tau = (np.arange(n) - 0.5 * (n - 1)) * TS
    fixed = np.ascontiguousarray(np.column_stack([tau**0, tau, tau**2]))
    axes, starts = [tau], [0]
    if restart is not None:
        axes.append((np.arange(n) - restart) * TS)
        starts.append(restart)
    return fixed, np.vstack(axes), np.array(starts, dtype=np.int64)


def _signals(params: np.ndarray, n: int, restart: int | None, seed: int) -> np.ndarray:
    """Three channels of the model at ``params`` with random linear coefficients."""
    fixed, axes, starts = _layout(n, restart)
    columns = mode_columns(fixed, axes, starts, params)
    coef = np.random.default_rng(seed).normal(size=(columns.shape[1], 3))
    return np.ascontiguousarray(columns @ coef)


@pytest.mark.parametrize("restart", [None, 90])
def test_columns_and_their_derivatives_match_the_closed_form_and_finite_differences(
    restart: int | None,
) -> None:
    # Columns: exp(-s t) cos(w t), exp(-s t) sin(w t), zero before the restart on its axis.
    # Derivatives: central differences with step 1e-5 (relative error ~1e-9 for these smooth
    # functions, far below the 1e-6 tolerance).
    n, params = 240, np.array([60.0, 3.0, 210.0, 12.0])
    fixed, axes, starts = _layout(n, restart)
    columns = mode_columns(fixed, axes, starts, params)
    assert columns.shape == (n, 3 + 4 * axes.shape[0])
    t = axes[-1]
    on = np.arange(n) >= starts[-1]
    expected = np.where(on, np.exp(-12.0 * t) * np.sin(210.0 * t), 0.0)
    np.testing.assert_allclose(columns[:, -1], expected, rtol=1e-12, atol=1e-15)
    coef = np.random.default_rng(0).normal(size=(columns.shape[1], 2))
    derivatives = mode_derivatives(axes, starts, 3, params, coef)
    for p in range(params.size):
        h = 1e-5 * max(abs(params[p]), 1.0)
        up, down = params.copy(), params.copy()
        up[p] += h
        down[p] -= h
        numeric = (
            (mode_columns(fixed, axes, starts, up) - mode_columns(fixed, axes, starts, down))
            @ coef
            / (2 * h)
        )
        np.testing.assert_allclose(derivatives[p], numeric, rtol=1e-6, atol=1e-9)


def test_projected_residual_is_the_linear_least_squares_residual() -> None:
    n, params = 200, np.array([45.0, 2.0])
    fixed, axes, starts = _layout(n, None)
    y = np.ascontiguousarray(np.random.default_rng(1).normal(size=(n, 3)))
    columns = mode_columns(fixed, axes, starts, params)
    reference = y - columns @ np.linalg.lstsq(columns, y, rcond=None)[0]
    residual = projected_residual(fixed, axes, starts, params, y)
    np.testing.assert_allclose(residual, reference.ravel(), atol=1e-10)


@pytest.mark.parametrize("restart", [None, 70])
def test_solver_recovers_noiseless_parameters(restart: int | None) -> None:
    # Exact data: the least-squares (w, s) are the true ones; started 3 % off in frequency and
    # 50 % in decay, the solver must converge to them within 1e-6 relative.
    n, truth = 260, np.array([52.0, 4.0, 190.0, 9.0])
    fixed, axes, starts = _layout(n, restart)
    y = _signals(truth, n, restart, seed=2)
    start = truth * np.array([1.03, 1.5, 0.97, 0.5])
    lower, upper = np.array([10.0, -20.0] * 2), np.array([3000.0, 300.0] * 2)
    params, status = bounded_levenberg_marquardt(
        fixed, axes, starts, y, start, lower, upper, 1e-10, 1e-10, 1e-10, 200
    )
    assert status > 0
    np.testing.assert_allclose(params, truth, rtol=1e-6)


def test_solver_finds_the_same_bounded_minimum_as_least_squares() -> None:
    # Noisy data, and a decay bound that the unconstrained minimum lies beyond (the data decay
    # at 30 1/s, the upper bound is 10): both solvers must stop on the bound with the same
    # frequency (to 1e-6 relative) and cost (1e-9), both run to tolerances of 1e-12.
    n, truth = 300, np.array([70.0, 30.0])
    fixed, axes, starts = _layout(n, None)
    y = _signals(truth, n, None, seed=3)
    y = np.ascontiguousarray(y + 0.05 * np.random.default_rng(4).normal(size=y.shape))
    lower, upper = np.array([10.0, -20.0]), np.array([3000.0, 10.0])
    start = np.array([66.0, 5.0])
    params, status = bounded_levenberg_marquardt(
        fixed, axes, starts, y, start, lower, upper, 1e-12, 1e-12, 1e-12, 100
    )
    reference = least_squares(
        lambda p: projected_residual(fixed, axes, starts, p, y),
        start,
        bounds=(lower, upper),
        method="trf",
        x_scale="jac",
        xtol=1e-12,
        ftol=1e-12,
        gtol=1e-12,
    )
    assert status > 0
    assert params[1] == pytest.approx(10.0)
    assert reference.x[1] == pytest.approx(10.0)
    assert params[0] == pytest.approx(reference.x[0], rel=1e-6)
    cost = np.sum(projected_residual(fixed, axes, starts, params, y) ** 2)
    assert cost == pytest.approx(2 * reference.cost, rel=1e-9)


def test_solver_reports_when_it_runs_out_of_evaluations() -> None:
    n, truth = 200, np.array([52.0, 4.0])
    fixed, axes, starts = _layout(n, None)
    y = _signals(truth, n, None, seed=5)
    bounds = np.array([10.0, -20.0]), np.array([3000.0, 300.0])
    _, status = bounded_levenberg_marquardt(
        fixed, axes, starts, y, np.array([60.0, 1.0]), *bounds, 1e-12, 1e-12, 1e-12, 2
    )
    assert status == MAX_EVALUATIONS
