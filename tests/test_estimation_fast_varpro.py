"""The compiled kernels and solver of the damped-sinusoid fit (varpro.py, trust_region.py)
against independent computations.

References: central finite differences of the model columns and of the residual (Kaufman's
Jacobian at a zero-residual point, where the term it drops vanishes: Kaufman 1975, BIT 15); the
linear least-squares residual from ``numpy.linalg.lstsq``; the same fit without a column that is
zero; the constrained minimum of the trust-region model found by brute force; the bounded
minimum found by ``scipy.optimize.least_squares`` (trust-region reflective) on the same residual.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import least_squares

from sensing_antenna.estimation.methods.fast.trust_region import (
    NOT_CONVERGED,
    NOT_FINITE,
    bounded_levenberg_marquardt,
    free_parameters,
    trust_region_step,
    updated_radius,
    updated_scale,
)
from sensing_antenna.estimation.methods.fast.varpro import (
    linear_fit,
    mode_columns,
    mode_derivatives,
    projected_residual,
    residual_and_jacobian,
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
    derivatives = mode_derivatives(columns, axes, starts, 3, coef)
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


@pytest.mark.parametrize("restart", [None, 333])
def test_columns_of_a_long_window_match_the_closed_form(restart: int | None) -> None:
    # A 1.5 s window (the longest the method fits is 1 s, the cap, plus the push): the columns
    # are carried from sample to sample between direct evaluations, so their rounding must
    # stay at the level of the closed form's own (an argument w t of up to 2200 rad holds
    # about 2e-13 rad of rounding): within 1e-12 of the envelope, for a decaying mode and for
    # the fastest growth the fit allows (-20 1/s) near the Nyquist frequency.
    n, params = 1500, np.array([61.7, 12.0, 2900.0, -20.0])
    fixed, axes, starts = _layout(n, restart)
    columns = mode_columns(fixed, axes, starts, params)
    for a in range(axes.shape[0]):
        t = axes[a]
        on = np.arange(n) >= starts[a]
        for j in range(2):
            omega, decay = params[2 * j], params[2 * j + 1]
            envelope = np.where(on, np.exp(-decay * t), 0.0)
            first = 3 + 4 * a + 2 * j
            for column, wave in ((first, np.cos(omega * t)), (first + 1, np.sin(omega * t))):
                error = np.abs(columns[:, column] - envelope * wave)
                assert np.all(error <= 1e-12 * np.maximum(envelope, 1e-300))


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
    assert status == NOT_CONVERGED


def test_solver_reports_a_start_whose_residual_is_not_finite() -> None:
    # exp(-s t) overflows for s = -1e6 over a window of +-0.1 s: the solver returns the start
    # unsolved with its own status, so a caller need not evaluate the start beforehand.
    fixed, axes, starts = _layout(200, None)
    y = np.ascontiguousarray(np.ones((200, 3)))
    start = np.array([50.0, -1e6])
    params, status = bounded_levenberg_marquardt(
        fixed,
        axes,
        starts,
        y,
        start,
        np.array([10.0, -2e6]),
        np.array([3000.0, 300.0]),
        1e-8,
        1e-8,
        1e-8,
        100,
    )
    assert status == NOT_FINITE
    np.testing.assert_array_equal(params, start)


@pytest.mark.parametrize("restart", [None, 90, 0])
def test_kaufman_jacobian_matches_finite_differences_at_zero_residual(restart: int | None) -> None:
    # At a zero residual the term Kaufman's approximation drops vanishes, so it equals the exact
    # Jacobian there; central differences with step 1e-6 relative (truncation ~1e-12, rounding
    # ~1e-10 of the residual's scale) within 1e-5. A restart at sample 0 makes every restarted
    # pair a combination of the window's own pair (linearly dependent columns).
    n, params = 240, np.array([60.0, 3.0, 210.0, 12.0])
    y = _signals(params, n, restart, seed=6)
    fixed, axes, starts = _layout(n, restart)
    residual, jacobian = residual_and_jacobian(fixed, axes, starts, params, y)
    assert np.max(np.abs(residual)) < 1e-10
    for p in range(params.size):
        h = 1e-6 * abs(params[p])
        up, down = params.copy(), params.copy()
        up[p] += h
        down[p] -= h
        numeric = (
            projected_residual(fixed, axes, starts, up, y)
            - projected_residual(fixed, axes, starts, down, y)
        ) / (2 * h)
        np.testing.assert_allclose(
            jacobian[:, p], numeric, rtol=1e-5, atol=1e-5 * np.abs(numeric).max()
        )


def test_a_zero_column_changes_neither_residual_nor_jacobian() -> None:
    # A constant regressor centred to zero is a column of zeros: the least-squares fit is that of
    # the other columns, so residual and Jacobian must equal those computed without it.
    n, params = 200, np.array([45.0, 2.0, 150.0, 6.0])
    fixed, axes, starts = _layout(n, None)
    y = np.ascontiguousarray(
        _signals(params, n, None, seed=7) + 0.01 * np.random.default_rng(8).normal(size=(n, 3))
    )
    with_zero = np.ascontiguousarray(np.column_stack([fixed[:, :1], np.zeros(n), fixed[:, 1:]]))
    residual, jacobian = residual_and_jacobian(with_zero, axes, starts, params, y)
    reference_residual, reference_jacobian = residual_and_jacobian(fixed, axes, starts, params, y)
    np.testing.assert_allclose(residual, reference_residual, atol=1e-9)
    np.testing.assert_allclose(jacobian, reference_jacobian, rtol=1e-6, atol=1e-9)


def _lstsq_residual(columns: np.ndarray, y: np.ndarray) -> np.ndarray:
    return (y - columns @ np.linalg.lstsq(columns, y, rcond=None)[0]).ravel()


def test_dependent_columns_give_the_least_squares_residual() -> None:
    # Two bases whose columns are linearly dependent, against numpy's lstsq (SVD, the same rank
    # tolerance): a mode on the Nyquist frequency (its sine column is zero to rounding) beside a
    # quartic and a fast-decaying mode on a short window, where the weak tau^3, tau^4 directions
    # must be kept; and a fixed column 1e3 times larger than the others that is a combination
    # of them (a rounding-level pivot far below its own norm).
    rng = np.random.default_rng(12)
    n = 51
    tau = (np.arange(n) - 0.5 * (n - 1)) * TS
    quartic = np.ascontiguousarray(np.column_stack([tau**j for j in range(5)]))
    axes, starts = tau[None, :].copy(), np.zeros(1, dtype=np.int64)
    y = np.ascontiguousarray(rng.normal(size=(n, 3)))
    params = np.array([np.pi / TS, 5.0, 300.0, 400.0])
    columns = mode_columns(quartic, axes, starts, params)
    residual = projected_residual(quartic, axes, starts, params, y)
    np.testing.assert_allclose(residual, _lstsq_residual(columns, y), atol=1e-9)
    scaled = np.ascontiguousarray(np.column_stack([quartic[:, :3], 1e3 * (3 + 50 * tau)]))
    params = np.array([200.0, 5.0])
    columns = mode_columns(scaled, axes, starts, params)
    residual = projected_residual(scaled, axes, starts, params, y)
    np.testing.assert_allclose(residual, _lstsq_residual(columns, y), atol=1e-9)


def test_linear_fit_gives_the_least_squares_coefficients() -> None:
    # Against numpy's lstsq (SVD): full-rank columns with a restart, and columns of which one
    # is another's copy, where both give the minimum-norm solution (the copy's coefficient
    # split in two halves). Coefficients to 1e-10 relative of their largest (the columns'
    # condition number is about 1e3), residuals to 1e-10 on unit-variance data.
    rng = np.random.default_rng(13)
    n, params = 200, np.array([45.0, 2.0, 160.0, 8.0])
    y = np.ascontiguousarray(rng.normal(size=(n, 3)))
    fixed, axes, starts = _layout(n, 70)
    plain, plain_axes, plain_starts = _layout(n, None)
    doubled = np.ascontiguousarray(np.column_stack([plain, plain[:, 1]]))
    for layout in ((fixed, axes, starts), (doubled, plain_axes, plain_starts)):
        columns, coef, residual = linear_fit(*layout, params, y)
        np.testing.assert_array_equal(columns, mode_columns(*layout, params))
        reference = np.linalg.lstsq(columns, y, rcond=None)[0]
        np.testing.assert_allclose(coef, reference, atol=1e-10 * np.abs(reference).max())
        np.testing.assert_allclose(residual, y - columns @ reference, atol=1e-10)


def test_columns_that_overflow_give_an_infinite_residual() -> None:
    # exp(-s t) overflows for s = -1e6 over a window of +-0.1 s: no number, not an error.
    fixed, axes, starts = _layout(200, None)
    y = np.ones((200, 3))
    residual = projected_residual(fixed, axes, starts, np.array([50.0, -1e6]), y)
    assert np.all(np.isinf(residual))


def test_trust_region_step_is_the_constrained_minimum_of_the_model() -> None:
    # Inside the radius: the Gauss-Newton step (lstsq). On the radius: length within the 1e-3
    # the damping search allows, and no point of the ball (5000 random points per problem) has
    # a lower model value. Scales differ by up to 10^4 between parameters.
    rng = np.random.default_rng(9)
    for _ in range(20):
        m = int(rng.integers(1, 5))
        jac = rng.normal(size=(30, m)) * 10 ** rng.uniform(-2, 2, size=m)
        residual = rng.normal(size=30)
        normal, gradient = jac.T @ jac, jac.T @ residual
        scale = np.sqrt((jac**2).sum(axis=0)) * 10 ** rng.uniform(-1, 1, size=m)
        free = np.ones(m, dtype=np.bool_)
        gauss_newton = np.linalg.lstsq(jac, -residual, rcond=None)[0]
        full = float(np.linalg.norm(scale * gauss_newton))
        inside = trust_region_step(normal, gradient, scale, free, 2 * full)
        np.testing.assert_allclose(inside, gauss_newton, rtol=1e-8)
        radius = full * 10 ** rng.uniform(-3, -0.1)
        step = trust_region_step(normal, gradient, scale, free, radius)
        assert np.linalg.norm(scale * step) == pytest.approx(radius, rel=1.1e-3)
        u = rng.normal(size=(5000, m))
        u *= radius * rng.uniform(size=(5000, 1)) ** (1 / m) / np.linalg.norm(u, axis=1)[:, None]
        points = u / scale
        values = points @ gradient + 0.5 * np.einsum("ij,jk,ik->i", points, normal, points)
        model = gradient @ step + 0.5 * step @ normal @ step
        assert model <= values.min() + 1e-9 * abs(values.min())


def test_held_parameters_do_not_move() -> None:
    normal, gradient = np.array([[2.0, 0.5], [0.5, 1.0]]), np.array([1.0, -1.0])
    step = trust_region_step(normal, gradient, np.ones(2), np.array([False, True]), 10.0)
    assert step[0] == 0.0
    assert step[1] == pytest.approx(1.0)  # the Gauss-Newton step of the free one: -g / H


def test_a_parameter_is_held_only_where_descent_would_leave_the_box() -> None:
    lower, upper = np.array([0.0, 0.0, 0.0, 0.0]), np.array([1.0, 1.0, 1.0, 1.0])
    params = np.array([0.0, 0.0, 1.0, 0.5])
    # descent is -gradient: out of the box below, into it, out above, inside
    gradient = np.array([1.0, -1.0, -1.0, 1.0])
    assert list(free_parameters(params, gradient, lower, upper)) == [False, True, False, True]


@pytest.mark.parametrize(
    ("ratio", "length", "expected"),
    [
        (0.1, 0.8, 0.2),  # poor model: a quarter of the step taken
        (-1.0, 0.0, 0.25),  # rejected and no step (clipped away): a quarter of the radius
        (0.5, 1.0, 1.0),  # fair: unchanged
        (0.9, 0.5, 1.0),  # good but inside the region: unchanged
        (0.9, 0.99, 2.0),  # good and at the radius: doubled
    ],
)
def test_radius_follows_the_reduction_ratio(ratio: float, length: float, expected: float) -> None:
    assert updated_radius(1.0, ratio, length) == pytest.approx(expected)


def test_scale_is_the_column_norm_and_never_decreases() -> None:
    jacobian = np.array([[3.0, 0.0, 0.1], [4.0, 0.0, 0.0]])
    first = updated_scale(np.zeros(3), jacobian)
    np.testing.assert_allclose(first, [5.0, 1.0, 0.1])
    np.testing.assert_allclose(updated_scale(first, 0.5 * jacobian), first)
    np.testing.assert_allclose(updated_scale(first, 2 * jacobian), [10.0, 1.0, 0.2])


def test_cost_never_rises_and_the_solver_converges_from_afar() -> None:
    # Started 30 % off in the lower frequency and far off in decay, with noise: far enough that
    # some steps are rejected. Each extra evaluation may only lower the cost, and the solver
    # must end at the frequencies within 0.1 % (noise 0.05 against unit amplitudes).
    n, truth = 260, np.array([52.0, 4.0, 190.0, 9.0])
    fixed, axes, starts = _layout(n, None)
    rng = np.random.default_rng(10)
    y = np.ascontiguousarray(_signals(truth, n, None, seed=11) + 0.05 * rng.normal(size=(n, 3)))
    start = truth * np.array([1.3, 4.0, 0.9, 0.2])
    lower, upper = np.array([10.0, -20.0] * 2), np.array([3000.0, 300.0] * 2)
    costs, statuses = [], []
    for evaluations in range(1, 40):
        params, status = bounded_levenberg_marquardt(
            fixed, axes, starts, y, start, lower, upper, 1e-10, 1e-10, 1e-10, evaluations
        )
        costs.append(np.sum(projected_residual(fixed, axes, starts, params, y) ** 2))
        statuses.append(status)
    assert np.all(np.diff(costs) <= 0.0)
    # At least one step was rejected before convergence: the cost stood still while unconverged
    rejected = [
        i for i in range(1, len(costs)) if costs[i] == costs[i - 1] and statuses[i] == NOT_CONVERGED
    ]
    assert rejected
    params, status = bounded_levenberg_marquardt(
        fixed, axes, starts, y, start, lower, upper, 1e-10, 1e-10, 1e-10, 200
    )
    assert status > 0
    np.testing.assert_allclose(params[0::2], truth[0::2], rtol=1e-3)
