"""The columns of one window's model, for the damped-sinusoid fit of :mod:`.parametric`.

Per channel the model of a window is a polynomial in the time from the window's centre, the
known regressors (the head's angle through the push) and a cosine and sine pair per damped mode,
with every mode started again at a restart sample when asked for (the head stopping). The
polynomial and regressor columns do not depend on the modes' (w, s) and are built once per
window and degree; the mode columns are computed at every (w, s) by the compiled kernels of
:mod:`.varpro`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.methods.fast.varpro import (
    linear_fit,
    mode_columns,
    mode_derivatives,
)

__all__ = ["ModelDesign"]

FloatArray = NDArray[np.float64]


class ModelDesign:
    """The columns of one window's model: polynomial, regressors, then the modes.

    Columns: tau^0 .. tau^degree, the ``regressors`` (centred on t_ref), then per mode
    exp(-s tau) cos(w tau), exp(-s tau) sin(w tau); with a ``restart`` index, per mode also the
    same pair started at that sample (time from it, zero before): a change of the modes'
    amplitudes and phases there, as an impulsive load on the structure makes (the head stopping).
    The mode columns are computed by the compiled kernels of :mod:`.varpro` (``axes``, ``starts``:
    its layout).
    """

    def __init__(
        self,
        n: int,
        sample_period: float,
        degree: int,
        regressors: FloatArray | None = None,
        restart: int | None = None,
    ) -> None:
        self.tau: FloatArray = (np.arange(n, dtype=float) - 0.5 * (n - 1)) * sample_period
        self.sample_period = sample_period
        self.degree = degree
        fixed = [self.tau[:, None] ** j for j in range(degree + 1)]
        if regressors is not None:
            r = np.asarray(regressors, dtype=float).reshape(n, -1)
            # zero at t_ref, so the constant term stays the static load at the window centre
            fixed.append(r - 0.5 * (r[(n - 1) // 2] + r[n // 2]))
        self.fixed: FloatArray = np.ascontiguousarray(np.hstack(fixed))
        self.restart = restart
        # Time axis of each column pair and the sample from which it is on: the window, then
        # the restart's (time from the restart sample)
        axes, starts = [self.tau], [0]
        if restart is not None:
            axes.append((np.arange(n, dtype=float) - restart) * sample_period)
            starts.append(restart)
        self.axes: FloatArray = np.vstack(axes)
        self.starts: NDArray[np.int64] = np.array(starts, dtype=np.int64)

    @property
    def n_fixed(self) -> int:
        """Columns that do not depend on (w, s)."""
        return int(self.fixed.shape[1])

    def n_linear(self, n_modes: int) -> int:
        """Columns of the model with ``n_modes`` modes (one column pair per mode and time axis)."""
        return self.n_fixed + 2 * self.axes.shape[0] * n_modes

    def basis(self, params: FloatArray) -> FloatArray:
        """All columns at (w, s), shape (n, n_linear)."""
        return np.asarray(mode_columns(self.fixed, self.axes, self.starts, params), dtype=float)

    def linear_fit(
        self, params: FloatArray, signals: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The columns at (w, s) (n, n_linear), the least-squares coefficients of ``signals``
        (n, K) on them (n_linear, K) and the residual (n, K), in one compiled call
        (:func:`.varpro.linear_fit`)."""
        columns, coef, residual = linear_fit(
            self.fixed, self.axes, self.starts, params, np.ascontiguousarray(signals, dtype=float)
        )
        return (
            np.asarray(columns, dtype=float),
            np.asarray(coef, dtype=float),
            np.asarray(residual, dtype=float),
        )

    def derivative_times_coef(self, columns: FloatArray, coef: NDArray[np.floating]) -> FloatArray:
        """d(basis @ coef) / d(w_j, s_j), shape (2M, n, K), from the basis ``columns`` at (w, s):
        only mode j's columns depend on them."""
        derivatives = mode_derivatives(
            columns, self.axes, self.starts, self.n_fixed, np.ascontiguousarray(coef, dtype=float)
        )
        return np.asarray(derivatives, dtype=float)

    def free_phasors(
        self, params: FloatArray, coef: NDArray[np.floating]
    ) -> NDArray[np.complex128]:
        """Complex amplitude a - i b at t_ref of each mode's vibration after the restart (or of
        the only one), shape (K, M): the restarted pair carried to the origin tau = 0 and
        added."""
        m = params.size // 2
        first = self.n_fixed
        a, b = coef[first : first + 2 * m : 2], coef[first + 1 : first + 2 * m : 2]
        if self.axes.shape[0] > 1:
            omega, decay = params[0::2][:, None], params[1::2][:, None]
            lag = float(self.tau[0] - self.axes[1, 0])  # t_restart - t_ref
            second = first + 2 * m
            a2, b2 = coef[second : second + 2 * m : 2], coef[second + 1 : second + 2 * m : 2]
            gain = np.exp(decay * lag)
            cos_lag, sin_lag = np.cos(omega * lag), np.sin(omega * lag)
            a = a + gain * (a2 * cos_lag - b2 * sin_lag)
            b = b + gain * (a2 * sin_lag + b2 * cos_lag)
        return np.asarray((a - 1j * b).T, dtype=complex)
