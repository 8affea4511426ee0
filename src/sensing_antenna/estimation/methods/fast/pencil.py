"""Initial values of the damped-sinusoid fit: poles by the matrix pencil, and the starting modes.

The poles shared by every channel come from the matrix pencil method on the stacked Hankel
matrices of all channels (Hua and Sarkar 1990), with each channel weighted by the inverse of its
noise standard deviation; the fit (:mod:`.parametric`) starts from the strongest oscillatory
poles, with one mode in the band of the fundamental when one is asked for.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.methods.paper.frequency import find_peak, power_spectrum

__all__ = [
    "PoleStrengths",
    "StrengthMemo",
    "difference_scale",
    "first_poles",
    "initial_modes",
    "matrix_pencil_poles",
    "pencil_poles",
    "pole_strengths",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: Largest pencil parameter of the matrix pencil (see :func:`matrix_pencil_poles`).
_MAX_PENCIL = 64


def matrix_pencil_poles(signals: FloatArray, n_poles: int) -> ComplexArray:
    """Discrete-time poles z shared by several channels, by the matrix pencil method.

    Parameters
    ----------
    signals : array, shape (n,) or (n, K)
        Samples, time on axis 0.
    n_poles : int
        Number of poles kept (the rank of the truncated SVD).

    Returns
    -------
    array of complex, shape (n_poles,)
        Poles z = exp((-s + i w) T_s) of the signal model sum_j h_j z_j^n.

    Notes
    -----
    Hua and Sarkar (1990): with pencil parameter L = min(n / 3, 64), the Hankel matrices of every
    channel (rows y[i : i + L + 1]) are stacked, their right singular vectors V (eigenvectors of
    the Gram matrix) truncated to ``n_poles`` and the poles are the eigenvalues of
    pinv(V[:-1]) V[1:] (shift invariance). L = n / 3 is the noise-optimal choice; capping it at 64
    keeps the cost low for long windows and is far above the ten poles ever asked for.
    """
    y = np.asarray(signals, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    n = y.shape[0]
    pencil = max(n_poles, min(n // 3, _MAX_PENCIL))
    if n - pencil < n_poles:
        raise ValueError(f"{n} samples are too few for {n_poles} poles")
    gram = np.zeros((pencil + 1, pencil + 1))
    for k in range(y.shape[1]):
        hankel = np.lib.stride_tricks.sliding_window_view(y[:, k], pencil + 1)
        gram += hankel.T @ hankel
    # Right singular vectors of the stacked Hankel matrix = eigenvectors of its Gram matrix
    _, vectors = np.linalg.eigh(gram)
    v = vectors[:, ::-1][:, :n_poles]
    # Shift invariance: V2 = V1 Z, the poles are the eigenvalues of pinv(V1) V2
    shifted = np.linalg.pinv(v[:-1]) @ v[1:]
    return np.asarray(np.linalg.eigvals(shifted), dtype=complex)


def difference_scale(y: FloatArray) -> FloatArray:
    """Rough noise standard deviation of each channel of ``y`` (n, K): the spread of the first
    differences over sqrt(2) (noise-dominated at 1 kHz); 1 where a channel is constant."""
    scale = np.std(np.diff(y, axis=0), axis=0) / math.sqrt(2.0)
    return np.where(scale > 0.0, scale, 1.0)


def first_poles(y: FloatArray, n_modes: int) -> ComplexArray | None:
    """The matrix-pencil poles :func:`fit_damped_sinusoids` starts from without ``noise_std``
    (channels weighted by :func:`difference_scale`): the same for every polynomial degree."""
    y = np.asarray(y, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    return pencil_poles(y / difference_scale(y), n_modes)


def pencil_poles(y: FloatArray, n_modes: int) -> ComplexArray | None:
    """Matrix-pencil poles for up to ``n_modes`` modes plus the polynomial and spare poles;
    None for too few samples, or samples whose squares overflow (a glitch beyond any sensor)."""
    n_poles = min(2 * n_modes + 4, y.shape[0] // 3)
    if n_poles < 2:
        return None
    with np.errstate(over="ignore", invalid="ignore"):
        if not math.isfinite(float(np.sum(np.square(y)))):
            return None
    return matrix_pencil_poles(y, n_poles)


def _periodogram_peak(y: FloatArray, sample_period: float, band: tuple[float, float]) -> float:
    """Frequency (rad/s) of the largest peak inside ``band`` of the channels' summed spectrum.

    The spectrum of Estimator 1 (:func:`~.frequency.power_spectrum`: detrended, Hann window,
    zero padded); the middle of the band when it holds no peak.
    """
    omega, power = power_spectrum(y, sample_period, zero_padding=8)
    peak = find_peak(omega, power.sum(axis=1) if power.ndim == 2 else power, band)
    return peak.omega if peak is not None else 0.5 * (band[0] + band[1])


class PoleStrengths(NamedTuple):
    """The oscillatory poles of a pencil and what :func:`initial_modes` ranks them by
    (:func:`pole_strengths`).

    Attributes
    ----------
    s_plane : array of complex, shape (P,)
        Continuous-time poles (-s + i w, 1/s and rad/s) with w > 0.
    power : array, shape (P,)
        Each pole's power in the weighted channels (sum over channels of the squared
        coefficients of its exponential); -1 for a pole below the lowest frequency allowed or
        whose envelope grows by more than 1e100 over the window.
    band_peak : float
        The largest periodogram peak inside the target band (rad/s) when no pole above the
        lowest frequency lies in that band; NaN otherwise (or without a band).
    """

    s_plane: ComplexArray
    power: FloatArray
    band_peak: float


#: Largest growth of a pole's envelope over the window (its natural log) that the least squares
#: of :func:`pole_strengths` holds: 1e100, far inside a float's range once squared.
_LARGEST_GROWTH = math.log(1e100)

#: Pole strengths already computed for one set of channels, keyed by the channel weights and
#: the poles (their bytes) and the lowest frequency (rad/s): a model selection
#: (:func:`.model_order.select_model`) starts up to nine fits from the same poles and weights.
StrengthMemo = dict[tuple[bytes, bytes, float], PoleStrengths]


def pole_strengths(
    y: FloatArray,
    z: ComplexArray,
    sample_period: float,
    lowest: float,
    target_band: tuple[float, float] | None = None,
) -> PoleStrengths:
    """The oscillatory poles of ``z`` and the power of each in ``y`` (n, K), the weighted
    channels: least squares on the complex exponentials of all of them, with an offset and a
    drift. Poles below ``lowest`` (rad/s), or growing by more than 1e100 over the window, get
    power -1. They depend neither on the model order nor on the polynomial degree, so one
    model selection computes them once per pencil and weighting (:data:`StrengthMemo`).
    """
    n = y.shape[0]
    with np.errstate(divide="ignore", invalid="ignore"):
        every = np.log(z) / sample_period
    keep = np.isfinite(every) & (every.imag > 0.0)
    s_plane: ComplexArray = np.asarray(every[keep], dtype=np.complex128)
    # Amplitude of each pole: least squares on the complex exponentials of the kept poles whose
    # envelope over the window a float can hold (a pencil on samples far off the link's, a
    # glitch, may return one that grows by more; no vibration of a passive link does)
    bounded = s_plane.real * sample_period * (n - 1) <= _LARGEST_GROWTH
    idx = np.arange(n)
    vander = np.exp(np.multiply.outer(idx * sample_period, s_plane[bounded]))
    basis = np.hstack([np.ones((n, 1)), idx[:, None] * 1.0, vander.real, vander.imag])
    coef, *_ = np.linalg.lstsq(basis, y, rcond=None)
    m = vander.shape[1]
    power = np.full(s_plane.size, -1.0)
    power[bounded] = np.sum(coef[2 : 2 + m] ** 2 + coef[2 + m :] ** 2, axis=1)
    power = np.asarray(np.where(s_plane.imag >= lowest, power, -1.0), dtype=float)
    band_peak = math.nan
    if target_band is not None:
        inside = (s_plane.imag >= target_band[0]) & (s_plane.imag <= target_band[1]) & (power >= 0)
        if not inside.any():
            band_peak = _periodogram_peak(y, sample_period, target_band)
    return PoleStrengths(s_plane, power, band_peak)


def initial_modes(
    strengths: PoleStrengths,
    n_modes: int,
    lower: FloatArray,
    upper: FloatArray,
    target_band: tuple[float, float] | None = None,
) -> FloatArray:
    """(w, s) pairs of the ``n_modes`` strongest oscillatory poles above lower[0]
    (``strengths``, computed with that lowest frequency and the same ``target_band``).

    With ``target_band`` (rad/s) the first pair is the strongest pole inside that band or, when
    the pencil has none there (a weak mode beside strong ones), the largest periodogram peak
    inside it; the other pairs are the strongest remaining poles.
    """
    s_plane = strengths.s_plane
    power = strengths.power.copy()
    omega: list[float] = []
    decay: list[float] = []
    if target_band is not None:
        inside = (s_plane.imag >= target_band[0]) & (s_plane.imag <= target_band[1]) & (power >= 0)
        if inside.any():
            j = int(np.argmax(np.where(inside, power, -1.0)))
            omega.append(float(s_plane[j].imag))
            decay.append(float(-s_plane[j].real))
            power[j] = -1.0
        else:
            omega.append(strengths.band_peak)
            decay.append(1.0)
    order = list(np.argsort(power)[::-1][: n_modes - len(omega)])
    omega += [float(s_plane[j].imag) for j in order if power[j] >= 0.0]
    decay += [float(-s_plane[j].real) for j in order if power[j] >= 0.0]
    # Too few poles above the lower limit: spread the missing ones over the allowed range
    spare = np.geomspace(lower[0] * 1.5, upper[0] * 0.5, n_modes + 2)[1:-1]
    while len(omega) < n_modes:
        omega.append(float(spare[len(omega)]))
        decay.append(1.0)
    params = np.empty(2 * n_modes)
    params[0::2] = np.clip(omega, lower[0] * 1.001, upper[0] * 0.999)
    params[1::2] = np.clip(decay, lower[1] * 0.999, upper[1] * 0.999)
    return params
