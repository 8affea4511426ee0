"""Compiled kernels of the damped-sinusoid fit of :mod:`.parametric`.

The model of a window (docs/fast.md) is linear in the polynomial, regressor and mode amplitudes
and nonlinear in the (w, s) pair of each mode, so it is fitted by variable projection (Golub
and Pereyra 1973): the amplitudes are solved for at every (w, s) and the solver sees only the
two to six nonlinear parameters. Each window needs some ten such solves; the arithmetic of one
is small (a QR factorization of a few hundred rows by ten to twenty columns), so in NumPy and
``scipy.optimize.least_squares`` the per-call overhead would be most of the cost. Here the
columns, the residual and Kaufman's Jacobian are compiled with numba, as is the solver that
uses them (:mod:`.trust_region`).

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
from numpy.typing import NDArray

from sensing_antenna.compiler import njit

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

_EPS = float(np.finfo(np.float64).eps)

__all__ = [
    "kaufman_jacobian",
    "linear_fit",
    "mode_columns",
    "mode_derivatives",
    "projected_residual",
    "projection",
    "residual_and_jacobian",
]


#: Samples between direct evaluations of a mode column (:func:`mode_columns`): between them
#: the column is carried by a complex product, whose relative rounding error grows by about
#: 1e-16 per sample, so it stays below about 1e-14 of the envelope.
_ANCHOR = 64


@njit(cache=True)
def mode_columns(
    fixed: FloatArray, axes: FloatArray, starts: IntArray, params: FloatArray
) -> FloatArray:
    """Every column of the model at (w, s), shape (n, F + 2 M A); each axis evenly spaced.

    exp((-s + i w) t) is carried from sample to sample by the factor exp((-s + i w) dt), one
    complex product instead of an exponential, a cosine and a sine per sample, and evaluated
    directly every :data:`_ANCHOR` samples.
    """
    n, n_fixed = fixed.shape
    n_modes = params.size // 2
    out = np.zeros((n, n_fixed + 2 * n_modes * axes.shape[0]))
    out[:, :n_fixed] = fixed
    for a in range(axes.shape[0]):
        first = n_fixed + 2 * n_modes * a
        dt = axes[a, 1] - axes[a, 0] if n > 1 else 0.0
        for j in range(n_modes):
            omega, decay = params[2 * j], params[2 * j + 1]
            # exp((-s + i w) dt)
            step_re = math.exp(-decay * dt) * math.cos(omega * dt)
            step_im = math.exp(-decay * dt) * math.sin(omega * dt)
            re = im = 0.0
            for i in range(starts[a], n):
                if (i - starts[a]) % _ANCHOR == 0:
                    t = axes[a, i]
                    envelope = math.exp(-decay * t)
                    re = envelope * math.cos(omega * t)
                    im = envelope * math.sin(omega * t)
                else:
                    re, im = re * step_re - im * step_im, re * step_im + im * step_re
                out[i, first + 2 * j] = re
                out[i, first + 2 * j + 1] = im
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
def projection(
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
    tolerance = max(n, size) * _EPS
    # Plain loops and slices rather than reductions and boolean masks: the same numbers, and a
    # shorter first compilation
    largest_norm = 0.0
    for j in range(size):
        largest_norm = max(largest_norm, math.sqrt(np.sum(columns[:, j] ** 2)))
    smallest_pivot = math.inf
    for j in range(size):
        smallest_pivot = min(smallest_pivot, abs(r[j, j]))
    if smallest_pivot > tolerance * largest_norm:
        q = np.ascontiguousarray(q)
        projected = np.ascontiguousarray(q.T) @ weighted
        coef = _back_substitution(r, projected)
    else:
        u, singular, vt = np.linalg.svd(columns, full_matrices=False)
        # The singular values descend: the directions kept are the leading ones
        rank = 0
        while rank < singular.size and singular[rank] > tolerance * singular[0]:
            rank += 1
        q = np.ascontiguousarray(u[:, :rank])
        projected = np.ascontiguousarray(q.T) @ weighted
        scaled = projected.copy()
        for i in range(rank):
            scaled[i] /= singular[i]
        coef = np.ascontiguousarray(vt[:rank].T) @ scaled
    return columns, q, coef, weighted - q @ projected


@njit(cache=True)
def linear_fit(
    fixed: FloatArray, axes: FloatArray, starts: IntArray, params: FloatArray, signals: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The columns at (w, s) (n, P), the least-squares coefficients of ``signals`` (n, K) on
    them (P, K; minimum norm when the columns are dependent, as ``numpy.linalg.lstsq``) and
    the residual (n, K): :func:`projection` without its orthonormal basis."""
    columns, _, coef, residual = projection(fixed, axes, starts, params, signals)
    return columns, coef, residual


@njit(cache=True)
def projected_residual(
    fixed: FloatArray, axes: FloatArray, starts: IntArray, params: FloatArray, weighted: FloatArray
) -> FloatArray:
    """Residual of ``weighted`` (n, K) after the linear least-squares solve at (w, s), (n K,)
    (sample-major, as ``ravel``)."""
    return projection(fixed, axes, starts, params, weighted)[3].ravel()


@njit(cache=True)
def kaufman_jacobian(
    columns: FloatArray,
    axes: FloatArray,
    starts: IntArray,
    n_fixed: int,
    q: FloatArray,
    coef: FloatArray,
) -> FloatArray:
    """Kaufman's approximation of the residual's Jacobian, -(I - Q Q^T) dPhi_j C (Kaufman
    1975), shape (n K, 2M), rows in the residual's order; from :func:`projection`'s parts.
    Every derivative is projected in one pair of matrix products (columns p K + k)."""
    derivatives = mode_derivatives(columns, axes, starts, n_fixed, coef)
    n_par, n, n_channels = derivatives.shape
    stacked = np.empty((n, n_par * n_channels))
    for p in range(n_par):
        for i in range(n):
            for k in range(n_channels):
                stacked[i, p * n_channels + k] = derivatives[p, i, k]
    projected = q @ (np.ascontiguousarray(q.T) @ stacked)
    jacobian = np.empty((n * n_channels, n_par))
    for i in range(n):
        for k in range(n_channels):
            for p in range(n_par):
                column = p * n_channels + k
                jacobian[i * n_channels + k, p] = projected[i, column] - stacked[i, column]
    return jacobian


@njit(cache=True)
def residual_and_jacobian(
    fixed: FloatArray, axes: FloatArray, starts: IntArray, params: FloatArray, weighted: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """The residual of :func:`projected_residual` and its :func:`kaufman_jacobian`."""
    columns, q, coef, residual = projection(fixed, axes, starts, params, weighted)
    return residual.ravel(), kaufman_jacobian(columns, axes, starts, fixed.shape[1], q, coef)
