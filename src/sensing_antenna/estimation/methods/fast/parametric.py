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
trust-region Levenberg-Marquardt solver (:mod:`.trust_region`) with Kaufman's approximation of
the Jacobian (Golub and Pereyra 2003), compiled with the residual and Jacobian (:mod:`.varpro`).
Each channel is weighted by the inverse of its noise standard deviation (estimated from the
residuals of a first fit, then refitted), so the channels are combined as independent
measurements. Initial poles come from the matrix pencil method on the stacked Hankel matrices of
all channels (Hua and Sarkar 1990, :mod:`.pencil`).

The model order and the polynomial degree are chosen by the BIC (:mod:`.model_order`).

Standard errors: the covariance of every parameter is (J^T J)^-1 with J the Jacobian of the
weighted residuals at the solution (Gauss-Newton approximation; weights set from the residual
variance, so the reduced chi-square is 1 by construction). The Cramer-Rao bound of a damped
sinusoid (:mod:`.crb`) is computed from the Fisher information J^T J / sigma^2 of the noiseless
model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.methods.fast.design import ModelDesign
from sensing_antenna.estimation.methods.fast.pencil import (
    StrengthMemo,
    difference_scale,
    first_poles,
    initial_modes,
    pencil_poles,
    pole_strengths,
)
from sensing_antenna.estimation.methods.fast.trust_region import (
    NOT_FINITE,
    bounded_levenberg_marquardt,
)
from sensing_antenna.estimation.methods.fast.warm_start import start_inside

__all__ = ["DampedSinusoidFit", "FitCandidate", "fit_candidate", "fit_damped_sinusoids"]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: Largest decay of a fitted mode over the window, s * duration: e^-20 leaves nothing of the mode
#: in the second half of the window; a faster transient is not a vibration worth fitting, and
#: the bound keeps exp(-s tau) finite.
_MAX_WINDOW_DECAY = 20.0
#: Smallest decay rate (1/s): slight growth is allowed (a fit on a short record may need it), more
#: is not physical for a passive link.
_MIN_DECAY = -20.0
#: Solver tolerances. Relative steps of 1e-8 (scipy's least_squares' default) are 1e-5 of the
#: smallest standard error of omega_1 (~1e-3 relative); scaled gradient 1e-8; at most 100
#: residual evaluations per solve. A solve ends when an accepted step lowers the cost by less
#: than 1e-6 of it: in the noise-weighted units the cost is about n K / 2, and a parameter
#: delta standard errors from the minimum adds delta^2 / 2 to it, so what such a step leaves
#: is a change of at most sqrt(1e-6 n K) standard errors, 0.07 on the longest window (1 s,
#: five channels). The fundamental settles in the first steps; the last ones polish the weak
#: modes' decay rates, where the solver converges linearly (a few tenths of the rest per step).
_XTOL = _GTOL = 1e-8
_FTOL = 1e-6
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
    phasors : complex array, shape (K, M), or None
        Complex amplitude a - i b of each mode in each channel at ``t_ref`` for the term
        e^(-s tau) (a cos w tau + b sin w tau) (channel units; ``amplitudes`` is its modulus):
        the channels of a standing vibration share its phase. None when not kept.
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
    phasors: ComplexArray | None = None

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

    def detection(self) -> FloatArray:
        """Each mode's detection statistic, shape (M,): :meth:`snr` times sqrt(n / 2), the
        amplitude at the window start over the noise of one periodogram ordinate."""
        return np.asarray(self.snr() * math.sqrt(0.5 * self.n_samples), dtype=float)

    def in_band(self, band: tuple[float, float]) -> NDArray[np.bool_]:
        """Which modes lie inside ``band`` (rad/s, inclusive), shape (M,)."""
        return np.asarray((self.omega >= band[0]) & (self.omega <= band[1]))

    def strongest_in_band(self, band: tuple[float, float]) -> int | None:
        """Index of the mode inside ``band`` (rad/s) with the largest combined SNR, or None."""
        inside = np.flatnonzero(self.in_band(band))
        if inside.size == 0:
            return None
        return int(inside[np.argmax(self.snr()[inside])])


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
    max_evaluations: int = _MAX_EVALUATIONS,
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
    max_evaluations : int
        Most residual evaluations of each solve; a solve that reaches it has not converged
        (``DampedSinusoidFit.converged`` False).

    Returns
    -------
    DampedSinusoidFit or None
        None when the record is too short for the model (fewer samples than 3 times the
        parameters per channel).
    """
    candidate = fit_candidate(
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
        max_evaluations,
    )
    return None if candidate is None else candidate.summary()


def fit_candidate(
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
    max_evaluations: int = _MAX_EVALUATIONS,
    memo: StrengthMemo | None = None,
    design: ModelDesign | None = None,
    warm: tuple[FloatArray, FloatArray] | None = None,
) -> FitCandidate | None:
    """:func:`fit_damped_sinusoids` up to its solution and BIC, without the covariance.

    ``memo``: the pole strengths already computed for these signals
    (:data:`.pencil.StrengthMemo`), filled with those computed here; None: computed afresh.
    ``design``: the model's columns for these samples, ``degree``, ``regressors`` and
    ``restart`` when already built (they do not depend on the number of modes).
    ``warm``: the (w, s) to start from and the channel noise to weight with when ``noise_std``
    is not given (the solution of the same model on a shorter window of the same record,
    :mod:`.warm_start`): one solve from there instead of two from the matrix pencil.
    """
    y = np.asarray(signals, dtype=float)
    if y.ndim == 1:
        y = y[:, None]
    n = y.shape[0]
    if design is None:
        design = ModelDesign(n, sample_period, degree, regressors, restart)
    n_linear = design.n_linear(n_modes)
    if n < 3 * (n_linear + 2 * n_modes):
        return None
    lower = np.array([max(min_omega, 1e-3), _MIN_DECAY])
    upper = np.array([math.pi / sample_period, _MAX_WINDOW_DECAY / ((n - 1) * sample_period)])
    bounds = (np.tile(lower, n_modes), np.tile(upper, n_modes))
    if warm is not None:
        scale = np.asarray(warm[1] if noise_std is None else noise_std, dtype=float)
        start = start_inside(warm[0], lower, upper)
        params, status = _refine(
            start, design, np.ascontiguousarray(y / scale), bounds, max_evaluations
        )
        if status == NOT_FINITE:
            return None
        return _candidate(params, status > 0, design, y, scale, t_start, noise_std is None)
    if noise_std is None:
        scale = difference_scale(y)
    else:
        scale = np.asarray(noise_std, dtype=float)
    z: ComplexArray | None
    if poles is not None:
        z = poles
    elif noise_std is None:
        z = first_poles(y, n_modes)  # weights difference_scale(y), as above
    else:
        z = pencil_poles(y / scale, n_modes)
    if z is None:
        return None
    weighted = np.ascontiguousarray(y / scale)
    key = (scale.tobytes(), z.tobytes(), float(lower[0]))
    strengths = None if memo is None else memo.get(key)
    if strengths is None:
        strengths = pole_strengths(weighted, z, sample_period, lower[0], target_band)
        if memo is not None:
            memo[key] = strengths
    start = initial_modes(strengths, n_modes, lower, upper, target_band)
    params, status = _refine(start, design, weighted, bounds, max_evaluations)
    if status == NOT_FINITE:
        return None  # the model at the start is not finite (a mode's envelope overflows)
    ok = status > 0
    if noise_std is None:
        residual = design.linear_fit(params, weighted)[2] * scale
        dof = max(n - n_linear - 2 * n_modes, 1)
        scale = np.sqrt(np.sum(residual**2, axis=0) / dof)
        scale = np.where(scale > 0.0, scale, np.finfo(float).tiny)
        params, status = _refine(
            params, design, np.ascontiguousarray(y / scale), bounds, max_evaluations
        )
        ok = status > 0
    return _candidate(params, ok, design, y, scale, t_start, noise_std is None)


def _refine(
    start: FloatArray,
    design: ModelDesign,
    weighted: FloatArray,
    bounds: tuple[FloatArray, FloatArray],
    max_evaluations: int,
) -> tuple[FloatArray, int]:
    """The least-squares (w, s) from ``start`` and the solver's status (> 0 converged,
    :data:`.trust_region.NOT_FINITE` when the residual at ``start`` is not finite)."""
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
        max_evaluations=max_evaluations,
    )
    return np.asarray(params, dtype=float), int(status)


@dataclass(frozen=True)
class FitCandidate:
    """A solved fit before its covariance: what the BIC compares orders and degrees on.

    Attributes
    ----------
    params : array, shape (2M,)
        The solution, interleaved (w_m rad/s, s_m 1/s).
    converged : bool
        The solver's flag (:meth:`summary` also needs a finite covariance).
    design : ModelDesign
        The window's model columns (:mod:`.design`).
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
    design: ModelDesign
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
        phasors = design.free_phasors(params, coef)
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
            amplitudes=np.asarray(np.abs(phasors[:, order]), dtype=float),
            noise_std=np.asarray(noise, dtype=float),
            t_ref=self.t_start + 0.5 * (n - 1) * sample_period,
            n_samples=n,
            sample_period=sample_period,
            bic=self.bic,
            converged=ok,
            restart=design.restart,
            phasors=np.asarray(phasors[:, order], dtype=complex),
        )


def _candidate(
    params: FloatArray,
    converged: bool,
    design: ModelDesign,
    y: FloatArray,
    scale: FloatArray,
    t_start: float,
    scale_from_residuals: bool,
) -> FitCandidate:
    """The linear part, noise and BIC of the solution ``params`` (noise from its residuals when
    ``scale_from_residuals``, else ``scale``)."""
    n, k = y.shape
    m = params.size // 2
    basis, coef, residual = design.linear_fit(params, y)
    n_linear = basis.shape[1]
    dof = max(n - n_linear - 2 * m, 1)
    noise = np.sqrt(np.sum(residual**2, axis=0) / dof) if scale_from_residuals else scale
    noise = np.asarray(np.where(noise > 0.0, noise, np.finfo(float).tiny), dtype=float)
    n_par = 2 * m + k * n_linear
    rss = np.sum(residual**2, axis=0)
    tiny = np.finfo(float).tiny
    # Schwarz (1978): BIC = sum_k n ln(RSS_k / n) + P ln(n K)
    bic = float(np.sum(n * np.log(np.maximum(rss, tiny) / n)) + n_par * math.log(n * k))
    return FitCandidate(params, converged, design, y, basis, coef, noise, t_start, bic)
