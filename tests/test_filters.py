"""Tests of the discrete filters of Eq. 15 (free-motion observer) and Eq. 20 (low-pass)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from sensing_antenna.antenna import FreeMotionObserver, paper_antenna
from sensing_antenna.detection.filters import (
    FilterConfigError,
    FirstOrderLowPass,
    FreeMotionObserverFilter,
    low_pass,
    low_pass_coefficients,
    observe_free_motion,
    observer_coefficients,
)

TS = 1e-3  # s, the paper's sample period (Section 5)
PAPER_OBSERVER = paper_antenna().observer  # Eq. 15: 0.37 s^2 / (s^2 + 0.3 s + 16.4^2)


def test_observer_coefficients_match_scipy_bilinear_with_prewarp() -> None:
    # scipy.signal.bilinear maps s = 2 fs (z - 1) / (z + 1); with 2 fs = w / tan(w T / 2) it is
    # the prewarped Tustin transform, an independent implementation of the same algebra.
    k, w, d = 0.37, 16.4, 0.3
    fs = 0.5 * w / math.tan(0.5 * w * TS)
    b_ref, a_ref = signal.bilinear([k, 0.0, 0.0], [1.0, d, w * w], fs=fs)
    b, a = observer_coefficients(FreeMotionObserver(k, w, d, 0.02), TS)
    np.testing.assert_allclose(b, b_ref, rtol=1e-12)
    np.testing.assert_allclose(a, a_ref, rtol=1e-12, atol=1e-15)


def test_low_pass_coefficients_match_scipy_bilinear_with_prewarp() -> None:
    wc = 5.0
    fs = 0.5 * wc / math.tan(0.5 * wc * TS)
    b_ref, a_ref = signal.bilinear([1.0], [1.0 / wc, 1.0], fs=fs)
    b, a = low_pass_coefficients(wc, TS)
    np.testing.assert_allclose(b, b_ref, rtol=1e-12)
    np.testing.assert_allclose(a, a_ref, rtol=1e-12)


def test_low_pass_gain_at_dc_and_cutoff() -> None:
    # Eq. 20: |G(0)| = 1 and |G(j omega_c)| = 1 / sqrt(2); prewarping keeps the latter exact.
    b, a = low_pass_coefficients(5.0, TS)
    _, h = signal.freqz(b, a, worN=[0.0, 5.0 * TS])
    assert abs(h[0]) == pytest.approx(1.0, rel=1e-12)
    assert abs(h[1]) == pytest.approx(1.0 / math.sqrt(2.0), rel=1e-9)


def test_observer_frequency_response_matches_continuous() -> None:
    # For omega < 0.1 pi / T_s the Tustin frequency warping is below 0.1 % (module docstring);
    # near the lightly damped resonance a small frequency shift changes the gain more, so the
    # comparison avoids +-30 % around omega and uses a 1 % tolerance away from it.
    b, a = observer_coefficients(PAPER_OBSERVER, TS)
    omegas = np.array([1.0, 5.0, 10.0, 25.0, 50.0, 100.0, 150.0])
    _, h_d = signal.freqz(b, a, worN=omegas * TS)
    s = 1j * omegas
    k, w, d = PAPER_OBSERVER.gain, PAPER_OBSERVER.natural_frequency, PAPER_OBSERVER.damping
    h_c = k * s**2 / (s**2 + d * s + w * w)
    np.testing.assert_allclose(np.abs(h_d), np.abs(h_c), rtol=1e-2)
    # Exact at the prewarping frequency (the resonance itself).
    _, h_w = signal.freqz(b, a, worN=[w * TS])
    assert abs(h_w[0]) == pytest.approx(k * w / d, rel=1e-9)


def test_observer_against_continuous_simulation() -> None:
    # Independent method: scipy.signal.lsim of the continuous Eq. 15 at a 10x finer step on a
    # smooth sweep. The Tustin output lags the exact response by at most a fraction of a sample;
    # tolerance 1 % of the peak torque.
    t_fine = np.arange(0.0, 3.0, TS / 10)
    theta = 0.4 * (1 - np.cos(2 * np.pi * 0.8 * t_fine)) * np.minimum(t_fine / 0.5, 1.0) ** 3
    k, w, d = PAPER_OBSERVER.gain, PAPER_OBSERVER.natural_frequency, PAPER_OBSERVER.damping
    _, ref, _ = signal.lsim(([k, 0.0, 0.0], [1.0, d, w * w]), theta, t_fine)
    out = observe_free_motion(theta[::10], PAPER_OBSERVER, TS)
    scale = np.max(np.abs(ref))
    assert scale > 1e-3
    np.testing.assert_allclose(out, ref[::10], atol=1e-2 * scale)


def test_observer_ignores_constant_initial_angle() -> None:
    # s^2 in the numerator: a constant angle gives no torque, whatever its value.
    out = observe_free_motion(np.full(100, 1.3), PAPER_OBSERVER, TS)
    assert np.all(out == 0.0)


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    w=st.floats(1.0, 3000.0),
    zeta=st.floats(0.0, 2.0),
)
def test_observer_is_stable_below_nyquist(seed: int, w: float, zeta: float) -> None:
    # Tustin maps the open left half-plane into the unit disc; with zero damping the poles sit
    # on the unit circle (radius 1 to rounding).
    obs = FreeMotionObserver(
        gain=1.0, natural_frequency=w, damping=2 * zeta * w, contact_threshold=1
    )
    _, a = observer_coefficients(obs, TS)
    radius = np.max(np.abs(np.roots(a)))
    assert radius <= 1.0 + 1e-9
    if zeta > 1e-3:
        assert radius < 1.0
    rng = np.random.default_rng(seed)
    x = rng.normal(size=50)
    streaming = FreeMotionObserverFilter(obs, TS)
    np.testing.assert_array_equal([streaming.update(v) for v in x], observe_free_motion(x, obs, TS))


def test_nyquist_is_refused() -> None:
    obs = FreeMotionObserver(1.0, 4000.0, 1.0, 1.0)
    with pytest.raises(FilterConfigError, match="Nyquist"):
        observer_coefficients(obs, TS)
    with pytest.raises(FilterConfigError, match="sample_period"):
        low_pass_coefficients(5.0, 0.0)


def test_streaming_equals_batch_and_reset() -> None:
    rng = np.random.default_rng(3)
    x = np.cumsum(rng.normal(size=(400, 3)), axis=0) + 2.0
    batch = low_pass(x, 5.0, TS)
    for col in range(3):
        lp = FirstOrderLowPass(5.0, TS)
        out = [lp.update(v) for v in x[:, col]]
        # One recursion in both forms: equal to the bit.
        np.testing.assert_array_equal(out, batch[:, col])
        lp.reset()
        assert lp.update(x[0, col]) == pytest.approx(x[0, col], rel=1e-14)
    obs = FreeMotionObserverFilter(PAPER_OBSERVER, TS)
    theta = x[:, 0] * 1e-2
    first = [obs.update(v) for v in theta]
    obs.reset()
    second = [obs.update(v) for v in theta]
    assert first == second
    np.testing.assert_array_equal(first, observe_free_motion(theta, PAPER_OBSERVER, TS))


def test_filters_equal_lfilter_to_the_bit_in_any_blocks() -> None:
    # Reference: scipy.signal.lfilter, an independent implementation of the same direct form II
    # transposed recursion (started at lfilter_zi times the first sample for the low-pass, at
    # rest on the angle relative to the first one for the observer). Same coefficients, same
    # operations in the same order: equal to the bit, however the samples are cut into blocks.
    rng = np.random.default_rng(8)
    x = np.cumsum(rng.normal(size=(1000, 6)), axis=0)
    b, a = low_pass_coefficients(5.0, TS)
    reference, _ = signal.lfilter(b, a, x, axis=0, zi=signal.lfilter_zi(b, a)[:, None] * x[:1])
    b_obs, a_obs = observer_coefficients(PAPER_OBSERVER, TS)
    angles = 1e-3 * x[:, :2]
    observed = signal.lfilter(b_obs, a_obs, angles - angles[:1], axis=0)
    np.testing.assert_array_equal(low_pass(x, 5.0, TS), reference)
    np.testing.assert_array_equal(observe_free_motion(angles, PAPER_OBSERVER, TS), observed)
    for _ in range(5):
        cuts = np.sort(rng.choice(np.arange(1, 1000), size=12, replace=False))
        lp, obs = FirstOrderLowPass(5.0, TS), FreeMotionObserverFilter(PAPER_OBSERVER, TS)
        blocks = [lp.update_block(part) for part in np.split(x, cuts)]
        np.testing.assert_array_equal(np.vstack(blocks), reference)
        blocks = [obs.update_block(part) for part in np.split(angles, cuts)]
        np.testing.assert_array_equal(np.vstack(blocks), observed)


def test_low_pass_starts_in_steady_state_and_has_unit_step_response() -> None:
    x = np.full(50, 3.0)
    np.testing.assert_allclose(low_pass(x, 5.0, TS), 3.0, rtol=1e-14)
    # Step at t = 0 from zero: after one time constant the continuous response is 1 - 1/e.
    step = np.concatenate([[0.0], np.ones(400)])
    y = low_pass(step, 5.0, TS)
    assert y[201] == pytest.approx(1 - math.exp(-1.0), abs=2e-3)  # 1/omega_c = 200 samples
