"""The spectrum Estimator 1 reads: detrended, Hann-windowed, zero-padded (Section 5.4), as
power or, for the held joint's check, amplitude.

Shared by the evidence, whose spectrum of the torque over the Delta t_e1 window is computed once,
when a method first reads it (:attr:`~.evidence.Evidence.window_spectrum`), the methods, and the
figures.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ["amplitude_spectrum", "power_spectrum"]

FloatArray = NDArray[np.float64]


def power_spectrum(
    signal: FloatArray, sample_period: float, zero_padding: int = 16
) -> tuple[FloatArray, FloatArray]:
    """One-sided power spectrum of detrended, Hann-windowed, zero-padded signals.

    Parameters
    ----------
    signal : array, shape (n,) or (n, k)
        Samples, time on axis 0.
    sample_period : float
        T_s (s).
    zero_padding : int
        The FFT length is the power of two at or above ``zero_padding * n``.

    Returns
    -------
    omega : array, shape (m,)
        Angular frequencies (rad/s).
    power : array, shape (m,) or (m, k)
        |FFT|^2 of each column (signal units squared).
    """
    omega, spectrum, _ = _transform(signal, sample_period, zero_padding)
    power = np.asarray(spectrum.real**2 + spectrum.imag**2, dtype=float)
    return omega, power


def amplitude_spectrum(
    signal: FloatArray, sample_period: float, zero_padding: int = 16
) -> tuple[FloatArray, FloatArray]:
    """The same transform as :func:`power_spectrum`, scaled to amplitudes: a sinusoid of
    amplitude A reads A at its frequency's bin (the window's gain taken off).

    Returns
    -------
    omega : array, shape (m,)
        Angular frequencies (rad/s).
    amplitude : array, shape (m,) or (m, k)
        Amplitudes of each column (signal units).
    """
    omega, spectrum, gain = _transform(signal, sample_period, zero_padding)
    return omega, np.asarray(2.0 * np.abs(spectrum) / gain, dtype=float)


def _transform(
    signal: FloatArray, sample_period: float, zero_padding: int
) -> tuple[FloatArray, NDArray[np.complex128], float]:
    """Angular frequencies, the one-sided FFT of the detrended, Hann-windowed, zero-padded
    signals, and the window's sum (its gain at a bin's centre)."""
    x = np.asarray(signal, dtype=float)
    n = x.shape[0]
    if n < 4:
        raise ValueError(f"a spectrum needs at least 4 samples, got {n}")
    time = np.arange(n, dtype=float)
    time -= time.mean()
    centred = x - x.mean(axis=0)
    slope = (time @ centred) / (time @ time)
    detrended = centred - np.multiply.outer(time, slope)
    window = np.hanning(n + 2)[1:-1]
    tapered = detrended * (window if x.ndim == 1 else window[:, None])
    n_fft = 1 << max(0, math.ceil(math.log2(zero_padding * n)))
    spectrum = np.fft.rfft(tapered, n=n_fft, axis=0)
    omega = 2.0 * np.pi * np.fft.rfftfreq(n_fft, d=sample_period)
    return np.asarray(omega, dtype=float), spectrum, float(window.sum())
