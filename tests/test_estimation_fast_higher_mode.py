"""The fast method's higher contact mode: a second sensing curve where omega_1 is flat.

Reference values are the pinned-contact sensing curves of the paper link
(:func:`sensing_antenna.beam.natural_frequencies`); measurements are drawn from those curves
with known standard errors, so every expectation follows from the model itself.
"""

from __future__ import annotations

import math

import numpy as np

from sensing_antenna.antenna import paper_antenna
from sensing_antenna.beam import natural_frequencies
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.methods.fast import FastConfig, ScanInputs, scan
from sensing_antenna.estimation.methods.fast.likelihood import ContactPosterior, contact_posterior
from sensing_antenna.estimation.methods.fast.static_fit import SensorBias
from sensing_antenna.estimation.methods.paper.fusion import sensing_curve
from sensing_antenna.estimation.pipeline import search_band

TS = 1e-3
LINK = paper_antenna().link
X_RANGE = (0.2 * LINK.length, LINK.length)
GRID = np.linspace(X_RANGE[0], X_RANGE[1], 3201)
CURVE = sensing_curve(LINK)
OMEGA_GRID = np.asarray(CURVE.omega1(GRID), dtype=float)
HIGHER_GRID = np.asarray(natural_frequencies(LINK, GRID, 3), dtype=float)[:, 1:]
EDGES = (X_RANGE[0], *CURVE.extrema, X_RANGE[1])
FLOOR = 0.005


def _modes(x: float) -> np.ndarray:
    return np.asarray(natural_frequencies(LINK, np.array(x), 3), dtype=float)


def _posterior(
    omega1: float, omega1_se: float, omega_h: float, omega_h_se: float
) -> ContactPosterior:
    return contact_posterior(
        OMEGA_GRID,
        GRID,
        EDGES,
        omega1,
        omega1_se,
        math.nan,
        math.nan,
        0.0,
        0.0,
        higher_modes_of_x=HIGHER_GRID,
        omega_higher=omega_h,
        omega_higher_se=omega_h_se,
        higher_mode_floor=FLOOR,
    )


def test_higher_mode_resolves_the_peak_of_omega1() -> None:
    # x_c = 0.77 m sits on the flat top of omega_1(x_c): with omega_1 alone (0.1 rad/s) the
    # interval spans both branches (> 1.5 cm). omega_2 there changes by ~0.8 rad/s per mm, so with
    # a 0.5 % floor (1.1 rad/s) its interval is a few mm and holds the truth.
    x = 0.77
    w = _modes(x)
    alone = _posterior(float(w[0]), 0.1, math.nan, math.nan)
    both = _posterior(float(w[0]), 0.1, float(w[1]), 0.2)
    assert alone.width > 0.015
    assert both.width < 0.008
    assert both.interval[0] <= x <= both.interval[1]
    assert abs(both.x_c - x) < 1e-3


def test_mixture_accepts_the_third_mode() -> None:
    # The fit may hold mode 3 instead of mode 2 (at 0.5 m mode 3, 406 rad/s, is the stronger):
    # the mixture over modes 2 and 3 must still centre on the truth.
    x = 0.5
    w = _modes(x)
    post = _posterior(float(w[0]), 0.2, float(w[2]), 0.3)
    assert post.interval[0] <= x <= post.interval[1]
    assert abs(post.x_c - x) < 2e-3


def test_coverage_with_the_higher_mode() -> None:
    # Draws from the model with mode 2 or 3 chosen at random and the model floor drawn as a
    # Gaussian error: the 95 % HPD interval holds the truth in 0.92..0.98 of 300 draws
    # (binomial sd 0.013 about 0.95).
    rng = np.random.default_rng(77)
    hits = 0
    draws = 300
    for _ in range(draws):
        x = rng.uniform(0.3, 0.97)
        w = _modes(x)
        j = int(rng.integers(1, 3))
        se_h = 0.3
        sigma_h = math.hypot(se_h, FLOOR * w[j])
        omega1 = float(w[0]) + 0.3 * rng.standard_normal()
        omega_h = float(w[j]) + sigma_h * rng.standard_normal()
        post = _posterior(omega1, 0.3, omega_h, se_h)
        hits += post.interval[0] <= x <= post.interval[1]
    assert 0.92 <= hits / draws <= 0.98


def _two_mode_channels(x_c: float, n: int, rng: np.random.Generator) -> np.ndarray:
    """A 60 mN push at x_c ringing at contact modes 1 and 2, with sensor noise."""
    t = np.arange(n) * TS
    w = _modes(x_c)
    r_y = -0.06 * (
        1.0 + 0.2 * np.exp(-0.5 * t) * np.cos(w[0] * t + 0.3) + 0.05 * np.cos(w[1] * t + 1.0)
    )
    zeros = np.zeros(n)
    out = np.column_stack([r_y, zeros, zeros, zeros, x_c * r_y])
    noise = np.array([6e-3, 6e-3, 3e-5, 3e-5, 3e-5])
    return out + noise * rng.standard_normal((n, 5))


def test_scan_declares_at_the_peak_with_the_second_mode() -> None:
    # Where omega_1 alone stays unsure until the cap (test_unsure_until_the_cap_near_the_peak
    # in test_estimation_fast_method.py), the second mode (opt-in: higher_modes=True) lets the
    # scan declare within the
    # tolerance. 8 mm, not the default 5 mm: the 0.5 % floor alone (1.1 rad/s at 0.8 rad/s
    # per mm) gives a 95 % width of about 5.5 mm at this point.
    rng = np.random.default_rng(12)
    cfg = FastConfig(cap=0.4, tolerance=0.008, higher_modes=True)
    channels = _two_mode_channels(0.77, 500, rng)
    band = search_band(LINK, EstimatorConfig())
    no_bias = SensorBias(np.zeros(5), np.zeros((5, 5)), 0)
    result = scan(ScanInputs(channels, no_bias, 0, 499, TS, band, LINK, X_RANGE, cfg))
    assert result.final is not None and result.final.sure
    assert abs(result.final.posterior.x_c - 0.77) <= cfg.tolerance
