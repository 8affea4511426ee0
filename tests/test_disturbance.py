"""A steady line in the band, there before the contact: told from the contact's ringing, and
never found in the noise of a clean rest."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from _models import calibrated
from sensing_antenna.estimation import Status, estimate
from sensing_antenna.estimation.disturbance import line_at
from sensing_antenna.simulator import Scenario, simulate


def test_a_sinusoid_s_amplitude_is_read_beside_a_parabola() -> None:
    # 0.1 s at 1 kHz: a 5e-5 sinusoid at 90 rad/s (1.4 periods) on a bow and a drift, and white
    # noise of 1e-5: the amplitude within three of its standard errors, which the noise sets
    rng = np.random.default_rng(4)
    t = np.arange(100) * 1e-3
    bow = 2e-4 * (t - 0.05) ** 2 / 0.05**2 + 3e-4 * t
    y = 5e-5 * np.sin(90.0 * t + 0.7) + bow + 1e-5 * rng.standard_normal(t.size)
    amplitude, error = line_at(t, y, 90.0)
    assert abs(amplitude - 5e-5) < 3.0 * error
    assert 1e-6 < error < 1e-5  # sigma sqrt(2 / n) = 1.4e-6, inflated by the parabola's share


@pytest.mark.parametrize("cutoff", [None, 100.0, 50.0])
def test_noise_leaves_no_line_beyond_eight_errors(cutoff: float | None) -> None:
    # the significance of a line over 80 to 200 samples at 50 to 140 rad/s in white noise, and
    # in noise through a second-order low-pass filter (a sensor's own, its colour in the band
    # carried into the error): beyond the check's 8 in at most 1 % of 1000 draws (measured on
    # 4000: none white, 0.08 % at 100 Hz, 0.3 % at 50 Hz; the line must also be 5 % of the
    # contact's ringing, which such noise is not)
    from scipy.signal import butter, lfilter

    rng = np.random.default_rng(7)
    found = []
    for k in range(1000):
        n = 80 + k % 121
        noise = rng.standard_normal(n + 400)
        if cutoff is not None:
            b, a = butter(2, cutoff / 500.0)
            noise = lfilter(b, a, noise)
        t = np.arange(n) * 1e-3
        amplitude, error = line_at(t, noise[400:], 50.0 + 90.0 * rng.random())
        found.append(amplitude / error)
    assert np.mean(np.array(found) > 8.0) <= 0.01
    if cutoff is None:
        assert max(found) < 8.0
        assert np.mean(np.array(found) > 3.0) < 0.03  # about one in a hundred (Rayleigh)


@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
def test_a_tone_at_omega1_there_before_the_contact_makes_the_answer_uncertain(case: str) -> None:
    # a steady tone of eight sensor counts of torque (2.4e-4 N m, a tenth of the contact's
    # ringing at omega_1) on every torque channel, from the start: the answer is not ok, the
    # reason names the rest's line; the clean manoeuvre is ok with no line at its rest, and a
    # tone of two counts (3 % of the ringing, which no fit mistakes) leaves it ok
    antenna = calibrated()
    recording = simulate(antenna, Scenario(case=case, contact_point=0.55, seed=5))
    recording = recording.without_ground_truth()
    for method in ("paper", "fast"):
        clean = estimate(recording, antenna, method)
        assert clean.ok, (method, clean.reason)
        assert clean.diagnostics["rest_line_sigmas"] < 5.0
        phases = np.array([0.3, 1.9, 4.1])
        tone = np.sin(clean.omega1 * recording.t[:, None] + phases)
        faint = dataclasses.replace(recording, torque=recording.torque + 6e-5 * tone)
        kept = estimate(faint, antenna, method)
        assert kept.ok and abs(kept.x_c - clean.x_c) < 1e-3, (method, kept.reason)
        assert kept.diagnostics["rest_line_sigmas"] > 8.0  # found, and judged too faint
        toned = dataclasses.replace(recording, torque=recording.torque + 2.4e-4 * tone)
        result = estimate(toned, antenna, method)
        reasons = " ".join([result.reason or "", *result.diagnostics.get("other_reasons", [])])
        assert result.status is not Status.OK, (method, result.x_c)
        assert "the torques at rest before the contact already ring at omega_1" in reasons
        assert math.isfinite(result.diagnostics["rest_line_sigmas"])
