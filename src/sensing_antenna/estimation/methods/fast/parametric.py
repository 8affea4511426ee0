"""Short-record frequency estimation: damped sinusoids with a static part, fitted jointly.

After t_1 the head is still and the link, clamped at the base and pinned at the contact, rings at
its contact-mode frequencies (Eq. 3 with the boundary conditions of Eq. 4). Every load channel of
the F/T sensor sees the same modes with its own amplitude and phase, on top of the static load
of the push. Over a window of ``n`` samples at t_n = t_0 + n T_s each channel k is modelled as

    y_k(t) = P_k(t - t_ref) + sum_m exp(-s_m (t - t_ref))
             * (a_km cos(w_m (t - t_ref)) + b_km sin(w_m (t - t_ref))) + noise_k

with t_ref the centre of the window: P_k a low-degree polynomial whose constant term c_k is the
static load at t_ref and whose other terms absorb slow changes (the servo still creeps after t_1;
the simulated head drifts by ~1e-2 rad over 0.5 s, a slow oscillation of about 8 rad/s that a
quadratic follows over a few hundred ms), w_m (rad/s) and s_m (1/s) the frequencies and decay
rates, shared by every channel because they belong to the structure. Modes are kept above a lowest
frequency so that they do not compete with the polynomial for the static part.

Fit (variable projection): for given (w, s) the model is linear in (P, a, b), solved by least
squares for every channel at once; only the 2 M nonlinear parameters go to a bounded
trust-region Levenberg-Marquardt solver (with Kaufman's approximation of the Jacobian, Golub and
Pereyra 2003), compiled with the residual and Jacobian in :mod:`.varpro`. Each channel is
weighted by the inverse of its noise standard deviation (estimated from the residuals of a first
fit, then refitted), so the channels are combined as independent measurements. Initial poles
come from the matrix pencil method on the stacked Hankel matrices of all channels (Hua and
Sarkar 1990).

Model order: M = 1 .. ``max_modes`` damped modes; the order with the smallest Bayesian
information criterion (Schwarz 1978) sum_k n ln(RSS_k / n) + P ln(n K) is kept, P being the
number of fitted parameters (:func:`select_model` chooses the polynomial degree by the same
criterion). Extra modes absorb the second contact mode and servo transients that
would otherwise bias the fundamental or make the residual non-white.

Standard errors: the covariance of every parameter is (J^T J)^-1 with J the Jacobian of the
weighted residuals at the solution (Gauss-Newton approximation; weights set from the residual
variance, so the reduced chi-square is 1 by construction). The Cramer-Rao bound of the same record
(:func:`damped_sinusoid_crb`) is computed from the Fisher information J^T J / sigma^2 of the
noiseless model.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.methods.fast.varpro import (
    bounded_levenberg_marquardt,
    mode_columns,
    mode_derivatives,
    projected_residual,
)
from sensing_antenna.estimation.methods.paper.frequency import find_peak, power_spectrum

__all__ = [
    "DampedSinusoidFit",
    "damped_sinusoid_crb",
    "first_poles",
    "fit_damped_sinusoids",
    "matrix_pencil_poles",
    "select_model",
    "select_model_order",
]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: Largest decay of a fitted mode over the window, s * duration: e^-20 leaves nothing of the mode
#: in the second half of the window; a faster transient is not a vibration worth fitting, and
#: the bound keeps exp(-s tau) finite.
_MAX_WINDOW_DECAY = 20.0
#: Smallest decay rate (1/s): slight growth is allowed (a fit on a short record may need it), more
#: is not physical for a passive link.
_MIN_DECAY = -20.0
#: Largest pencil parameter of the matrix pencil (see :func:`matrix_pencil_poles`).
_MAX_PENCIL = 64
#: Solver tolerances (those of least_squares, used before): relative steps of 1e-8 are 1e-5 of
#: the smallest standard error of omega_1 (~1e-3); cost changes of 1e-8 relative; scaled
#: gradient 1e-8; at most 100 residual evaluations.
_XTOL = _FTOL = _GTOL = 1e-8
_MAX_EVALUATIONS = 100


@dataclass(frozen=True)
class DampedSinusoidFit:
    """Damped sinusoids plus offset and drift, fitted jointly to several channels.

    Attributes
    ----------
    omega : array, shape (M,)
        Angular frequencies w_m (rad/s), ascending.
    decay : array, shape (M,)
        Decay rates s_m (1/s); the damping ratio is about s_m / w_m.
    omega_se, decay_se : array, shape (M,)
        Their standard errors (rad/s, 1/s).
    offsets : array, shape (K,)
        Static part c_k of each channel at ``t_ref`` (channel units).
    offset_cov : array, shape (K, K)
        Covariance of the offsets (channel units squared), including their correlation through
        the shared nonlinear parameters.
    drifts : array, shape (K,)
        Slow drift g_k (channel units per s).
    amplitudes : array, shape (K, M)
        Amplitude sqrt(a^2 + b^2) of each mode in each channel at ``t_ref`` (channel units).
    noise_std : array, shape (K,)
        Residual standard deviation of each channel (channel units).
    t_ref : float
        Reference instant, the centre of the window (s).
    n_samples : int
        Samples per channel.
    sample_period : float
        T_s (s).
    bic : float
        Bayesian information criterion of the fit (smaller is better).
    converged : bool
        False when the optimiser stopped without meeting its tolerances or the normal matrix was
        singular (the standard errors are then NaN).
    restart : int or None
        Sample of the window from which the modes' amplitudes hold (``amplitudes`` are those
        of the vibration after it); None: the whole window.
    """

    omega: FloatArray
    decay: FloatArray
    omega_se: FloatArray
    decay_se: FloatArray
    offsets: FloatArray
    offset_cov: FloatArray
    drifts: FloatArray
    amplitudes: FloatArray
    noise_std: FloatArray
    t_ref: float
    n_samples: int
    sample_period: float
    bic: float
    converged: bool
    restart: int | None = None

    @property
    def n_modes(self) -> int:
        """Number of damped modes M."""
        return int(self.omega.shape[0])

    @property
    def duration(self) -> float:
        """Window length (n - 1) T_s (s)."""
        return (self.n_samples - 1) * self.sample_period

    def start_amplitudes(self) -> FloatArray:
        """Amplitude of each mode in each channel at the window start, or at the restart when
        there is one (channel units), (K, M).

        ``amplitudes`` are at the window centre; the decay carries them back to that instant
        (at most e^(_MAX_WINDOW_DECAY / 2) by the fit's bound on s_m times the duration).
        """
        if self.restart is None:
            return self.amplitudes * np.exp(0.5 * self.decay * self.duration)[None, :]
        lead = (0.5 * (self.n_samples - 1) - self.restart) * self.sample_period
        return self.amplitudes * np.exp(self.decay * lead)[None, :]

    def snr(self) -> FloatArray:
        """Amplitude at the window start over noise, combined over channels, shape (M,)."""
        ratio = self.start_amplitudes() / self.noise_std[:, None]
        return np.asarray(np.sqrt(np.sum(ratio**2, axis=0)), dtype=float)

    def strongest_in_band(self, band: tuple[float, float]) -> int | None:
        """Index of the mode inside ``band`` (rad/s) with the largest combined SNR, or None."""
        inside = np.flatnonzero((self.omega >= band[0]) & (self.omega <= band[1]))
        if inside.size == 0:
            return None
        return int(inside[np.argmax(self.snr()[inside])])


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


class _Design:
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

    def derivative_times_coef(self, columns: FloatArray, coef: NDArray[np.floating]) -> FloatArray:
        """d(basis @ coef) / d(w_j, s_j), shape (2M, n, K), from the basis ``columns`` at (w, s):
        only mode j's columns depend on them."""
        derivatives = mode_derivatives(
            columns, self.axes, self.starts, self.n_fixed, np.ascontiguousarray(coef, dtype=float)
        )
        return np.asarray(derivatives, dtype=float)

    def residual(self, params: FloatArray, weighted: FloatArray) -> FloatArray:
        """Residual of ``weighted`` (n, K) after the linear least-squares solve, flattened."""
        residual = projected_residual(self.fixed, self.axes, self.starts, params, weighted)
        return np.asarray(residual, dtype=float)

    def free_amplitudes(self, params: FloatArray, coef: NDArray[np.floating]) -> FloatArray:
        """Amplitude at t_ref of each mode's vibration after the restart (or of the only one),
        shape (K, M): the restarted pair carried to the origin tau = 0 and added."""
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
        return np.asarray(np.hypot(a, b).T, dtype=float)


def _difference_scale(y: FloatArray) -> FloatArray:
    """Rough noise standard deviation of each channel of ``y`` (n, K): the spread of the first
    differences over sqrt(2) (noise-dominated at 1 kHz); 1 where a channel is constant."""
    scale = np.std(np.diff(y, axis=0), axis=0) / math.sqrt(2.0)
    return np.where(scale > 0.0, scale, 1.0)


def first_poles(y: FloatArray, n_modes: int) -> ComplexArray | None:
    """The matrix-pencil poles :func:`fit_damped_sinusoids` starts from without ``noise_std``
    (channels weighted by :func:`_difference_scale`): the same for every polynomial degree."""
    y = np.asarray(y, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    return _pencil_poles(y / _difference_scale(y), n_modes)


def _pencil_poles(y: FloatArray, n_modes: int) -> ComplexArray | None:
    """Matrix-pencil poles for up to ``n_modes`` modes plus the polynomial and spare poles."""
    n_poles = min(2 * n_modes + 4, y.shape[0] // 3)
    if n_poles < 2:
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


def _initial_modes(
    y: FloatArray,
    z: ComplexArray,
    n_modes: int,
    sample_period: float,
    lower: FloatArray,
    upper: FloatArray,
    target_band: tuple[float, float] | None = None,
) -> FloatArray:
    """(w, s) pairs of the ``n_modes`` strongest oscillatory poles ``z`` above lower[0].

    With ``target_band`` (rad/s) the first pair is the strongest pole inside that band or, when
    the pencil has none there (a weak mode beside strong ones), the largest periodogram peak
    inside it; the other pairs are the strongest remaining poles.
    """
    n = y.shape[0]
    with np.errstate(divide="ignore", invalid="ignore"):
        s_plane = np.log(z) / sample_period
    keep = np.isfinite(s_plane) & (s_plane.imag > 0.0)
    s_plane = s_plane[keep]
    # Amplitude of each pole: least squares on the complex exponentials of all kept poles
    idx = np.arange(n)
    vander = np.exp(np.multiply.outer(idx * sample_period, s_plane))
    basis = np.hstack([np.ones((n, 1)), idx[:, None] * 1.0, vander.real, vander.imag])
    coef, *_ = np.linalg.lstsq(basis, y, rcond=None)
    m = s_plane.size
    power = np.sum(coef[2 : 2 + m] ** 2 + coef[2 + m :] ** 2, axis=1)
    power = np.where(s_plane.imag >= lower[0], power, -1.0)
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
            omega.append(_periodogram_peak(y, sample_period, target_band))
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


def fit_damped_sinusoids(
    signals: FloatArray,
    sample_period: float,
    n_modes: int,
    t_start: float = 0.0,
    noise_std: FloatArray | None = None,
    min_omega: float = 0.0,
    degree: int = 1,
    poles: ComplexArray | None = None,
    target_band: tuple[float, float] | None = None,
    regressors: FloatArray | None = None,
    restart: int | None = None,
) -> DampedSinusoidFit | None:
    """Fit ``n_modes`` damped sinusoids with shared poles, plus a polynomial per channel.

    Parameters
    ----------
    signals : array, shape (n,) or (n, K)
        Samples of K channels, time on axis 0 (any units per channel).
    sample_period : float
        T_s (s).
    n_modes : int
        Number of damped modes M >= 1.
    t_start : float
        Time of the first sample (s).
    noise_std : array, shape (K,), optional
        Noise standard deviation of each channel; estimated from the residuals when omitted
        (one fit with weights from each channel's first differences, then a refit).
    min_omega : float
        Lowest frequency a mode may take (rad/s); slower content is left to the polynomial.
    degree : int
        Degree of the polynomial (offset, drift, ...) of each channel, >= 0.
    poles : array of complex, optional
        Discrete-time poles for the initial values (:func:`matrix_pencil_poles` of the weighted
        channels); computed when omitted.
    target_band : tuple of float, optional
        Band (rad/s) where one mode is known to lie (the fundamental): one mode starts there
        even when stronger modes elsewhere would otherwise take every initial slot.
    regressors : array, shape (n,) or (n, R), optional
        Known slow inputs the static part follows linearly (e.g. the head's angle while it
        pushes), one coefficient per channel each, beside the polynomial.
    restart : int, optional
        Sample from which every mode's amplitude and phase may change (the head stopping);
        ``amplitudes`` are then those after it. None: one vibration over the whole window.

    Returns
    -------
    DampedSinusoidFit or None
        None when the record is too short for the model (fewer samples than 3 times the
        parameters per channel).
    """
    candidate = _fit_candidate(
        signals,
        sample_period,
        n_modes,
        t_start,
        noise_std,
        min_omega,
        degree,
        poles,
        target_band,
        regressors,
        restart,
    )
    return None if candidate is None else candidate.summary()


def _fit_candidate(
    signals: FloatArray,
    sample_period: float,
    n_modes: int,
    t_start: float,
    noise_std: FloatArray | None,
    min_omega: float,
    degree: int,
    poles: ComplexArray | None,
    target_band: tuple[float, float] | None,
    regressors: FloatArray | None,
    restart: int | None,
) -> _Candidate | None:
    """:func:`fit_damped_sinusoids` up to its solution and BIC, without the covariance."""
    y = np.asarray(signals, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    n, k = y.shape
    design = _Design(n, sample_period, degree, regressors, restart)
    n_linear = design.n_linear(n_modes)
    if n < 3 * (n_linear + 2 * n_modes):
        return None
    lower = np.array([max(min_omega, 1e-3), _MIN_DECAY])
    upper = np.array([math.pi / sample_period, _MAX_WINDOW_DECAY / ((n - 1) * sample_period)])
    if noise_std is None:
        scale = _difference_scale(y)
    else:
        scale = np.asarray(noise_std, dtype=float)
    z: ComplexArray | None
    if poles is not None:
        z = poles
    elif noise_std is None:
        z = first_poles(y, n_modes)  # weights _difference_scale(y), as above
    else:
        z = _pencil_poles(y / scale, n_modes)
    if z is None:
        return None
    start = _initial_modes(y / scale, z, n_modes, sample_period, lower, upper, target_band)
    weighted = np.ascontiguousarray(y / scale)
    if not np.all(np.isfinite(design.residual(start, weighted))):
        return None
    bounds = (np.tile(lower, n_modes), np.tile(upper, n_modes))
    params, ok = _refine(start, design, weighted, bounds)
    if noise_std is None:
        residual = design.residual(params, weighted).reshape(n, k) * scale
        dof = max(n - n_linear - 2 * n_modes, 1)
        scale = np.sqrt(np.sum(residual**2, axis=0) / dof)
        scale = np.where(scale > 0.0, scale, np.finfo(float).tiny)
        params, ok = _refine(params, design, np.ascontiguousarray(y / scale), bounds)
    return _candidate(params, ok, design, y, scale, t_start, noise_std is None)


def _refine(
    start: FloatArray,
    design: _Design,
    weighted: FloatArray,
    bounds: tuple[FloatArray, FloatArray],
) -> tuple[FloatArray, bool]:
    """The least-squares (w, s) from ``start`` and whether the solver converged."""
    params, status = bounded_levenberg_marquardt(
        design.fixed,
        design.axes,
        design.starts,
        weighted,
        np.asarray(start, dtype=float),
        bounds[0],
        bounds[1],
        xtol=_XTOL,
        ftol=_FTOL,
        gtol=_GTOL,
        max_evaluations=_MAX_EVALUATIONS,
    )
    return np.asarray(params, dtype=float), bool(status > 0)


@dataclass(frozen=True)
class _Candidate:
    """A solved fit before its covariance: what the BIC compares orders and degrees on.

    Attributes
    ----------
    params : array, shape (2M,)
        The solution, interleaved (w_m rad/s, s_m 1/s).
    converged : bool
        The solver's flag (:meth:`summary` also needs a finite covariance).
    design : _Design
        The window's model columns.
    y : array, shape (n, K)
        The unweighted signals.
    basis : array, shape (n, L)
        ``design``'s columns at ``params``.
    coef : array, shape (L, K)
        Their least-squares coefficients for ``y``.
    noise : array, shape (K,)
        Each channel's noise standard deviation: from this solution's residuals when it was
        estimated (the fit itself was weighted with a first fit's), else the one given.
    t_start : float
        Time of the first sample (s).
    bic : float
        Schwarz's criterion of the unweighted residuals.
    """

    params: FloatArray
    converged: bool
    design: _Design
    y: FloatArray
    basis: FloatArray
    coef: FloatArray
    noise: FloatArray
    t_start: float
    bic: float

    def summary(self) -> DampedSinusoidFit:
        """The fit with the standard errors of (J^T J)^-1 of the weighted residuals."""
        params, design, basis, coef, noise = (
            self.params,
            self.design,
            self.basis,
            self.coef,
            self.noise,
        )
        n, k = self.y.shape
        m = params.size // 2
        n_linear = basis.shape[1]
        # J^T J of the weighted residuals, J = [shared (w, s) columns | each channel's basis
        # block]: built by blocks, as every channel shares the basis (its Gram matrix once)
        deriv = design.derivative_times_coef(basis, coef)  # (2M, n, K)
        n_par = 2 * m + k * n_linear
        weight = 1.0 / noise**2
        normal = np.zeros((n_par, n_par))
        normal[: 2 * m, : 2 * m] = np.einsum("pik,qik,k->pq", deriv, deriv, weight)
        gram = basis.T @ basis
        for ch in range(k):
            block = slice(2 * m + ch * n_linear, 2 * m + (ch + 1) * n_linear)
            cross = (deriv[:, :, ch] @ basis) * weight[ch]
            normal[: 2 * m, block] = cross
            normal[block, : 2 * m] = cross.T
            normal[block, block] = gram * weight[ch]
        try:
            cov = np.linalg.inv(normal)
            ok = self.converged and bool(np.all(np.isfinite(cov)))
        except np.linalg.LinAlgError:
            cov = np.full((n_par, n_par), np.nan)
            ok = False
        diag = np.sqrt(np.clip(np.diag(cov)[: 2 * m], 0.0, None))
        offset_idx = 2 * m + np.arange(k) * n_linear
        order = np.argsort(params[0::2])
        amplitudes = design.free_amplitudes(params, coef)
        drifts = coef[1] if design.degree >= 1 else np.zeros(k)
        sample_period = design.sample_period
        return DampedSinusoidFit(
            omega=params[0::2][order],
            decay=params[1::2][order],
            omega_se=diag[0::2][order],
            decay_se=diag[1::2][order],
            offsets=np.asarray(coef[0], dtype=float),
            offset_cov=cov[np.ix_(offset_idx, offset_idx)],
            drifts=np.asarray(drifts, dtype=float),
            amplitudes=np.asarray(amplitudes[:, order], dtype=float),
            noise_std=np.asarray(noise, dtype=float),
            t_ref=self.t_start + 0.5 * (n - 1) * sample_period,
            n_samples=n,
            sample_period=sample_period,
            bic=self.bic,
            converged=ok,
            restart=design.restart,
        )


def _candidate(
    params: FloatArray,
    converged: bool,
    design: _Design,
    y: FloatArray,
    scale: FloatArray,
    t_start: float,
    scale_from_residuals: bool,
) -> _Candidate:
    """The linear part, noise and BIC of the solution ``params`` (noise from its residuals when
    ``scale_from_residuals``, else ``scale``)."""
    n, k = y.shape
    m = params.size // 2
    basis = design.basis(params)
    coef = np.asarray(np.linalg.lstsq(basis, y, rcond=None)[0], dtype=np.float64)
    residual = y - basis @ coef
    n_linear = basis.shape[1]
    dof = max(n - n_linear - 2 * m, 1)
    noise = np.sqrt(np.sum(residual**2, axis=0) / dof) if scale_from_residuals else scale
    noise = np.asarray(np.where(noise > 0.0, noise, np.finfo(float).tiny), dtype=float)
    n_par = 2 * m + k * n_linear
    rss = np.sum(residual**2, axis=0)
    tiny = np.finfo(float).tiny
    # Schwarz (1978): BIC = sum_k n ln(RSS_k / n) + P ln(n K)
    bic = float(np.sum(n * np.log(np.maximum(rss, tiny) / n)) + n_par * math.log(n * k))
    return _Candidate(params, converged, design, y, basis, coef, noise, t_start, bic)


def select_model_order(
    signals: FloatArray,
    sample_period: float,
    max_modes: int = 3,
    t_start: float = 0.0,
    min_omega: float = 0.0,
    degree: int = 1,
    target_band: tuple[float, float] | None = None,
    poles: ComplexArray | None = None,
    regressors: FloatArray | None = None,
    restart: int | None = None,
) -> DampedSinusoidFit | None:
    """The fit with the smallest BIC among M = 1 .. ``max_modes`` damped modes.

    Returns None when no order could be fitted (record too short). The noise of each channel is
    estimated once, from the residuals of the largest order that fits, and used for every order,
    so that the BIC compares the orders on the same weights. ``min_omega``, ``degree``,
    ``target_band``, ``regressors`` and ``restart`` as in :func:`fit_damped_sinusoids`.
    ``poles``: :func:`first_poles` of the signals for ``max_modes`` when already at hand (they
    do not depend on the degree).
    """
    return select_model(
        signals,
        sample_period,
        max_modes,
        (degree,),
        t_start,
        min_omega,
        target_band,
        poles,
        regressors,
        restart,
    )


def select_model(
    signals: FloatArray,
    sample_period: float,
    max_modes: int,
    degrees: Sequence[int],
    t_start: float = 0.0,
    min_omega: float = 0.0,
    target_band: tuple[float, float] | None = None,
    poles: ComplexArray | None = None,
    regressors: FloatArray | None = None,
    restart: int | None = None,
) -> DampedSinusoidFit | None:
    """The fit with the smallest BIC over the polynomial ``degrees`` and M = 1 .. ``max_modes``.

    Each degree's orders as in :func:`select_model_order` (the BIC is computed on the unweighted
    residuals, so it compares degrees too); only the chosen fit's covariance is computed. On a
    tie the earlier degree, then the larger order, wins.

    Parameters
    ----------
    signals : array, shape (n,) or (n, K)
        Samples of K channels, time on axis 0.
    sample_period : float
        T_s (s).
    max_modes : int
        Largest number of damped modes M tried at each degree.
    degrees : sequence of int
        Polynomial degrees tried (>= 0).
    t_start : float
        Time of the first sample (s).
    min_omega : float
        Lowest frequency a mode may take (rad/s).
    target_band : tuple of float, optional
        Band of the fundamental (rad/s), as in :func:`fit_damped_sinusoids`.
    poles : array of complex, optional
        :func:`first_poles` of the signals for ``max_modes``, shared by every degree (they do
        not depend on it); computed per degree when omitted.
    regressors, restart
        As in :func:`fit_damped_sinusoids`.

    Returns
    -------
    DampedSinusoidFit or None
        None when no degree and order could be fitted (record too short).
    """
    y = np.asarray(signals, dtype=float)
    candidates = [
        candidate
        for degree in degrees
        for candidate in _order_candidates(
            y,
            sample_period,
            max_modes,
            t_start,
            min_omega,
            degree,
            target_band,
            poles,
            regressors,
            restart,
        )
    ]
    if not candidates:
        return None
    return min(candidates, key=lambda c: c.bic).summary()


def _order_candidates(
    y: FloatArray,
    sample_period: float,
    max_modes: int,
    t_start: float,
    min_omega: float,
    degree: int,
    target_band: tuple[float, float] | None,
    poles: ComplexArray | None,
    regressors: FloatArray | None,
    restart: int | None,
) -> list[_Candidate]:
    """The solved fits of M = ``max_modes`` .. 1 at one degree (those the record allows)."""
    candidates = []
    noise: FloatArray | None = None
    # The largest order that fits starts from ``poles`` (or its own pencil) and sets the noise;
    # the smaller ones start from the pencil of the signals weighted by that noise
    initial_poles = poles
    for m in range(max_modes, 0, -1):
        candidate = _fit_candidate(
            y,
            sample_period,
            m,
            t_start,
            noise,
            min_omega,
            degree,
            initial_poles,
            target_band,
            regressors,
            restart,
        )
        if noise is None:
            initial_poles = None  # the next order, if this one did not fit, starts from its own
            if candidate is not None:
                noise = candidate.noise
                initial_poles = _pencil_poles(y / noise if y.ndim == 2 else y[:, None] / noise, m)
        if candidate is not None:
            candidates.append(candidate)
    return candidates


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
