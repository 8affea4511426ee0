"""Model order and polynomial degree of the damped-sinusoid fit, by the BIC.

M = 1 .. ``max_modes`` damped modes at each polynomial degree; the fit with the smallest
Bayesian information criterion (Schwarz 1978) sum_k n ln(RSS_k / n) + P ln(n K) is kept, P
being the number of fitted parameters. Extra modes absorb the higher contact modes and servo
transients that would otherwise bias the fundamental or make the residual non-white. The noise
of each channel is estimated once per degree, from the residuals of the largest order that
fits, so that the BIC compares the orders on the same weights.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.methods.fast.design import ModelDesign
from sensing_antenna.estimation.methods.fast.parametric import (
    DampedSinusoidFit,
    FitCandidate,
    fit_candidate,
)
from sensing_antenna.estimation.methods.fast.pencil import StrengthMemo, pencil_poles
from sensing_antenna.estimation.methods.fast.warm_start import Solutions

__all__ = ["select_model", "select_model_order", "select_model_solutions"]

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


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
    return select_model_solutions(
        signals,
        sample_period,
        max_modes,
        degrees,
        t_start,
        min_omega,
        target_band,
        poles,
        regressors,
        restart,
    )[0]


def select_model_solutions(
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
    warm: Solutions | None = None,
    min_modes: int = 1,
) -> tuple[DampedSinusoidFit | None, Solutions]:
    """:func:`select_model` over M = ``min_modes`` .. ``max_modes``, with every candidate's
    solution (:data:`.warm_start.Solutions`).

    Each (degree, number of modes) found in ``warm`` (the solutions of a shorter window of the
    same record) starts from there, with one solve, the largest order weighted by the noise
    found there, instead of from the matrix pencil (:mod:`.warm_start`); the others as in
    :func:`select_model`. The other parameters as there.
    """
    y = np.asarray(signals, dtype=float)
    # The largest order of every degree starts from the same poles and weights, and the smaller
    # orders of one degree from the same pencil and weights: their pole strengths once
    memo: StrengthMemo = {}
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
            memo,
            warm or {},
            min_modes,
        )
    ]
    solutions = {(c.design.degree, c.params.size // 2): (c.params, c.noise) for c in candidates}
    if not candidates:
        return None, solutions
    return min(candidates, key=lambda c: c.bic).summary(), solutions


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
    memo: StrengthMemo,
    warm: Solutions,
    min_modes: int = 1,
) -> list[FitCandidate]:
    """The solved fits of M = ``max_modes`` .. ``min_modes`` at one degree (those the record
    allows); ``memo`` as in :func:`.parametric.fit_candidate`, ``warm`` as in
    :func:`select_model_solutions`."""
    candidates = []
    noise: FloatArray | None = None
    design = ModelDesign(y.shape[0], sample_period, degree, regressors, restart)
    # The largest order that fits starts from ``poles`` (or its own pencil) and sets the noise;
    # the smaller ones start from the pencil of the signals weighted by that noise
    initial_poles = poles
    for m in range(max_modes, min_modes - 1, -1):
        candidate = fit_candidate(
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
            memo=memo,
            design=design,
            warm=warm.get((degree, m)),
        )
        if noise is None:
            initial_poles = None  # the next order, if this one did not fit, starts from its own
            if candidate is not None:
                noise = candidate.noise
                # The pencil of the smaller orders, unless every one of them starts warm
                if any((degree, smaller) not in warm for smaller in range(min_modes, m)):
                    weighted = y / noise if y.ndim == 2 else y[:, None] / noise
                    initial_poles = pencil_poles(weighted, m)
        if candidate is not None:
            candidates.append(candidate)
    return candidates
