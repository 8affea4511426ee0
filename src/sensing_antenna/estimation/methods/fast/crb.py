"""The Cramer-Rao bound of a damped sinusoid in white Gaussian noise."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["damped_sinusoid_crb"]

FloatArray = NDArray[np.float64]


def damped_sinusoid_crb(
    omega: float,
    decay: float,
    amplitude: float,
    phase: float,
    noise_std: float,
    n_samples: int,
    sample_period: float,
    drift: bool = False,
) -> FloatArray:
    """Cramer-Rao bound of (omega, decay, amplitude, phase, offset[, drift]) for a damped sinusoid.

    Model y_n = c + g t_n + A exp(-s t_n) cos(w t_n + phi) + e_n, t_n = n T_s, e_n white Gaussian
    with standard deviation ``noise_std``; the drift g is a parameter only when ``drift`` is True
    (as in :func:`fit_damped_sinusoids`). The Fisher information is J^T J / sigma^2 with J the
    derivatives of the noiseless model; the bound is its inverse.

    Parameters
    ----------
    omega : float
        w (rad/s).
    decay : float
        s (1/s).
    amplitude : float
        A (signal units).
    phase : float
        phi (rad) at the first sample.
    noise_std : float
        sigma (signal units).
    n_samples : int
        N.
    sample_period : float
        T_s (s).
    drift : bool
        Whether a linear drift is estimated too (it costs information at short records).

    Returns
    -------
    array, shape (5, 5) or (6, 6)
        Lower bound of the covariance of (w, s, A, phi, c[, g]) (units rad/s, 1/s, signal, rad,
        signal[, signal/s]).
    """
    t = np.arange(n_samples) * sample_period
    envelope = np.exp(-decay * t)
    cos_part = np.cos(omega * t + phase)
    sin_part = np.sin(omega * t + phase)
    jac = np.column_stack(
        [
            -amplitude * t * envelope * sin_part,
            -amplitude * t * envelope * cos_part,
            envelope * cos_part,
            -amplitude * envelope * sin_part,
            np.ones_like(t),
        ]
    )
    if drift:
        jac = np.column_stack([jac, t])
    # Fisher information of Gaussian white noise: J^T J / sigma^2
    fisher = jac.T @ jac / noise_std**2
    return np.asarray(np.linalg.inv(fisher), dtype=float)
