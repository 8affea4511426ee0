"""Unit tests of the estimation building blocks on closed-form signals (no beam model needed).

Reference values come from closed forms written next to each test: sinusoid frequencies set by
construction, the statics of a cantilever loaded at x_c (Gamma = r_c x R), the recording format's
frame definitions and sign check (docs/recording-format.md), and Section 5.4 note (a) of the
paper (azimuthal push: Y^c = -Y^m).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from _models import weightless
from sensing_antenna.antenna import STANDARD_GRAVITY, paper_antenna
from sensing_antenna.beam import natural_frequencies
from sensing_antenna.estimation.config import EstimatorConfig, EstimatorConfigError
from sensing_antenna.estimation.front.contact_frame import (
    contact_frame,
    first_rest_index,
    motor_axes,
    rest_drift_tolerance,
    rest_tolerance,
    signal_noise,
)
from sensing_antenna.estimation.front.ratio import (
    contact_loads,
    converged_index,
    filtered_contact_loads,
    paper_ratio,
    perpendicular_ratio,
)
from sensing_antenna.estimation.methods.paper.frequency import (
    find_peak,
    measure_frequency,
    power_spectrum,
)
from sensing_antenna.estimation.methods.paper.fusion import fuse, model_spread
from sensing_antenna.estimation.result import ContactEstimate, Status

TS = 1e-3


def damped(t: np.ndarray, omega: float, zeta: float, amplitude: float, phase: float) -> np.ndarray:
    return amplitude * np.exp(-zeta * omega * t) * np.sin(omega * t + phase)


# ---------------------------------------------------------------- Estimator 1: spectrum


@pytest.mark.parametrize("omega", [31.4, 55.0, 70.3, 106.8])
@pytest.mark.parametrize("zeta", [0.0, 0.03])
def test_peak_frequency_of_damped_sinusoid_on_trend(omega: float, zeta: float) -> None:
    # Reference: the sinusoid's own frequency (by construction). Tolerance 0.1 rad/s: 1/60 of
    # the 6.3 rad/s DFT bin of a 1 s window; the sensing curve's smallest useful slope (~40 rad/s
    # per m away from its top) turns it into 2.5 mm.
    rng = np.random.default_rng(1)
    t = np.arange(1000) * TS
    signal = 0.03 + 0.004 * t + damped(t, omega, zeta, 1e-3, 0.4)
    signal += 2e-5 * rng.standard_normal(t.size)
    freq, power = power_spectrum(signal, TS, 16)
    peak = find_peak(freq, power, (25.0, 125.0))
    assert peak is not None
    assert abs(peak.omega - omega) < 0.1
    assert peak.quality > 100.0


def test_noise_only_has_no_clear_peak() -> None:
    # White noise: a bin's power is exponential, so it exceeds 20 times the median with
    # probability exp(-20 ln 2) ~ 1e-6; over ~250 independent bins and three spectra the default
    # clarity threshold (EstimatorConfig.min_peak_quality = 20) is passed with probability ~1e-3.
    rng = np.random.default_rng(2)
    torque = 1e-4 * rng.standard_normal((1000, 3))
    axes = np.eye(3)
    m = measure_frequency(torque, axes, TS, (27.0, 123.0), EstimatorConfig().min_peak_quality)
    assert not m.clear


def test_peak_outside_band_is_ignored() -> None:
    # A strong vibration above the band (a second mode) with a sensor noise floor 60 dB below:
    # the Hann sidelobes reaching into the band must not make a clear peak.
    rng = np.random.default_rng(7)
    t = np.arange(1000) * TS
    signal = damped(t, 200.0, 0.0, 1.0, 0.0) + 1e-3 * rng.standard_normal(t.size)
    freq, power = power_spectrum(signal, TS, 16)
    peak = find_peak(freq, power, (27.0, 123.0))
    assert peak is None or peak.quality < EstimatorConfig().min_peak_quality


@pytest.mark.parametrize("component", ["y_c", "z_c"])
def test_vibration_found_in_either_perpendicular_component(component: str) -> None:
    # The vibration is placed in one torque component of the contact frame only; the estimator
    # must find it whichever it is and say which spectrum it used.
    rng = np.random.default_rng(3)
    t = np.arange(1000) * TS
    axes = motor_axes(np.array([0.3, 0.1]))  # an arbitrary orthonormal frame (rows)
    column = {"y_c": 1, "z_c": 2}[component]
    torque_c = 1e-5 * rng.standard_normal((t.size, 3))
    torque_c[:, column] += damped(t, 48.0, 0.01, 5e-4, 1.0)
    torque_m = torque_c @ axes  # components along the axes -> motor coordinates
    m = measure_frequency(torque_m, axes, TS, (27.0, 123.0), min_quality=10.0)
    assert m.clear
    assert abs(m.omega1 - 48.0) < 0.05
    assert m.component in (component, "sum")
    assert m.peaks[component] is not None


# ---------------------------------------------------------------- frames and gravity


def test_motor_axes_match_recording_format() -> None:
    theta = np.array([0.7, -0.4])
    axes = motor_axes(theta)
    c1, s1, c2, s2 = math.cos(0.7), math.sin(0.7), math.cos(-0.4), math.sin(-0.4)
    np.testing.assert_allclose(axes[0], [c2 * c1, c2 * s1, s2], atol=1e-15)
    np.testing.assert_allclose(axes[1], [-s1, c1, 0.0], atol=1e-15)
    np.testing.assert_allclose(axes[2], np.cross(axes[0], axes[1]), atol=1e-15)
    np.testing.assert_allclose(axes @ axes.T, np.eye(3), atol=1e-15)
    # many angles at once: each frame as for its angles alone (the same arithmetic, exactly)
    many = np.array([[0.7, -0.4], [-1.2, 0.9], [0.0, 0.0]])
    frames = motor_axes(many)
    assert frames.shape == (3, 3, 3)
    for angles, frame in zip(many, frames, strict=True):
        np.testing.assert_array_equal(frame, motor_axes(angles))


def test_gravity_terms_match_spec_sign_check() -> None:
    # Spec sign check: theta2 = 0, at rest: F = (0, 0, -m_b g), torque = (0, +0.5 m_b g l, 0).
    antenna = paper_antenna()
    w = antenna.link.mass * STANDARD_GRAVITY
    np.testing.assert_allclose(antenna.gravity_force(np.array(0.0)), [0, 0, -w], atol=1e-15)
    np.testing.assert_allclose(
        antenna.gravity_torque(np.array(0.0)), [0, 0.5 * w * antenna.link.length, 0]
    )
    # Vectorised over theta2: one row per angle, the same as angle by angle
    angles = np.array([-0.1, 0.0, 0.3])
    np.testing.assert_array_equal(
        antenna.gravity_torque(angles), [antenna.gravity_torque(a) for a in angles]
    )
    assert antenna.gravity_force(angles).shape == (3, 3)


def test_azimuthal_push_frame_is_minus_y_m() -> None:
    # Paper Section 5.4 (a): pushing azimuthally, Y^c is Y^m in the opposite direction.
    # The link pushes towards +Y^m, the object reacts along -Y^m.
    theta = np.tile([0.2, 0.0], (5, 1))
    reaction = np.tile([0.0, -0.05, 0.0], (5, 1))
    frame = contact_frame(theta, reaction, 0.98)
    assert frame is not None
    np.testing.assert_allclose(frame.axes_m, [[1, 0, 0], [0, -1, 0], [0, 0, -1]], atol=1e-15)
    np.testing.assert_allclose(frame.axes_a[1], -motor_axes(np.array([0.2, 0.0]))[1], atol=1e-15)


def test_frame_is_right_handed_for_oblique_reaction() -> None:
    rng = np.random.default_rng(4)
    reaction = rng.normal(size=3)
    frame = contact_frame(np.zeros((1, 2)), reaction[None, :], 0.98)
    assert frame is not None
    axes = frame.axes_m
    np.testing.assert_allclose(axes @ axes.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(np.cross(axes[0], axes[1]), axes[2], atol=1e-12)
    np.testing.assert_allclose(axes[1], reaction / np.linalg.norm(reaction), atol=1e-12)
    assert axes[2] @ np.array([1.0, 0.0, 0.0]) == pytest.approx(0.0, abs=1e-12)


def test_axial_reaction_gives_no_frame() -> None:
    assert contact_frame(np.zeros((1, 2)), np.array([[0.1, 0.0, 0.0]]), 0.98) is None


def test_a_frame_turned_to_another_reaction_keeps_the_heads_pose() -> None:
    # the same frame as a fresh one built from the new reaction at the same angles; a reaction
    # along the link leaves it undefined
    theta = np.array([[0.2, -0.1]])
    frame = contact_frame(theta, np.array([[0.0, -0.05, 0.0]]), 0.98)
    assert frame is not None
    reaction = np.array([0.01, -0.04, 0.02])
    turned = frame.turned_to(reaction)
    fresh = contact_frame(theta, reaction[None, :], 0.98)
    assert turned is not None and fresh is not None
    np.testing.assert_allclose(turned.axes_m, fresh.axes_m, atol=1e-14)
    np.testing.assert_array_equal(turned.motor_axes_a, frame.motor_axes_a)
    np.testing.assert_array_equal(turned.theta, frame.theta)
    assert frame.turned_to(np.array([0.1, 0.0, 0.0])) is None


def test_rest_found_after_ramp_stops() -> None:
    # The angle ramps until sample 600 then holds with noise 1e-6 rad: rest starts at 600.
    rng = np.random.default_rng(5)
    n = 1000
    theta = np.zeros((n, 2))
    theta[:600, 0] = 0.5 * np.arange(600) * TS
    theta[600:, 0] = theta[599, 0]
    theta += 1e-6 * rng.standard_normal(theta.shape)
    tolerance = rest_tolerance(theta[:300], EstimatorConfig())
    assert tolerance == pytest.approx(1e-4)  # the floor: 8 sigma of 1e-6 rad noise is smaller
    index = first_rest_index(theta, 300, 50, tolerance)
    # The head moves 5e-4 rad per sample interval of the ramp... 0.5 rad/s * 1 ms = 5e-4 rad, so
    # a window may include at most the last sample of the ramp: 599 or 600.
    assert index in (599, 600)
    assert first_rest_index(theta[:640], 300, 50, tolerance) is None


@pytest.mark.parametrize("seed", range(5, 15))
def test_a_slow_push_within_a_coarse_encoders_tolerance_is_no_rest(seed: int) -> None:
    # A 12-bit encoder flickering a count (1.5e-3 rad; the peak-to-peak tolerance, 8 noise
    # deviations, 0.015 rad): a head still turning at 0.1 rad/s moves 5e-3 rad over a 50 ms
    # rest window, within that tolerance, but drifts 0.01 rad across the 200 ms hold, against a
    # tolerance of 5 standard deviations of the noise's drift there (1.3e-3 rad). Rest is
    # found where the turn stops (sample 600), not at the first window.
    rng = np.random.default_rng(seed)
    step = 2.0 * math.pi / 4096
    n = 1200
    exact = np.zeros((n, 2))
    exact[:600, 1] = 0.1 * np.arange(600) * TS
    exact[600:, 1] = exact[599, 1]
    theta = (np.round(exact / step) + rng.integers(-1, 2, size=exact.shape)) * step
    config = EstimatorConfig()
    tolerance = rest_tolerance(theta[:300], config)
    assert tolerance > 0.1 * 50 * TS  # the turn over a rest window stays within it
    # the spread alone finds a rest mid-turn, earlier than the drift lets a rest reach back
    alone = first_rest_index(theta, 300, 50, tolerance)
    assert alone is not None and alone < 600 - 60
    drift = rest_drift_tolerance(theta[:300], config, tolerance, 50, 200, TS)
    index = first_rest_index(theta, 300, 50, tolerance, drift, 200)
    # the span's first half may hold the turn's last k samples while their drift, k^2 / 2 of
    # 1e-4 rad a sample over its 100, stays within the tolerance: k up to about 51
    assert index is not None and 600 - 60 <= index <= 600


def test_signal_noise_estimate() -> None:
    # Reference: the noise standard deviation set below; 10 % tolerance for 5000 samples' MAD.
    rng = np.random.default_rng(6)
    t = np.arange(5000) * TS
    theta = np.column_stack([0.3 * np.sin(2 * t), 0.1 * t]) + 2e-5 * rng.standard_normal((5000, 2))
    noise, _ = signal_noise(theta)
    assert noise == pytest.approx(2e-5, rel=0.1)
    quantised = np.round(theta / 1e-4) * 1e-4
    _, step = signal_noise(quantised)
    assert step == pytest.approx(1e-4, rel=1e-6)


# ---------------------------------------------------------------- Estimator 2: ratio


def static_contact_samples(
    x_c: float, reaction: np.ndarray, theta2: float, n: int = 50
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Loads of a link pushed at arc length x_c: F = R + W, Gamma = r_c x R + Gamma_W, r_c the
    end of the elastica of length x_c under the end load R (a boundary-value problem solved
    here: solve_ivp from the base, the base moment found by brentq so that the moment vanishes
    at x_c)."""
    antenna = paper_antenna()
    rigidity = antenna.link.flexural_rigidity
    axial = float(reaction[0])
    lateral = float(np.hypot(reaction[1], reaction[2]))
    u = np.array([0.0, reaction[1], reaction[2]]) / lateral

    def end(moment: float) -> np.ndarray:
        def rhs(_s: float, y: np.ndarray) -> list[float]:
            bending = moment - (y[0] * lateral - y[1] * axial)
            return [math.cos(y[2]), math.sin(y[2]), bending / rigidity]

        sol = solve_ivp(rhs, (0.0, x_c), [0.0, 0.0, 0.0], rtol=1e-12, atol=1e-14)
        return np.asarray(sol.y[:2, -1])

    def residual(moment: float) -> float:
        x, y = end(moment)
        return moment - (x * lateral - y * axial)

    x, y = end(brentq(residual, 1e-9, 3.0 * x_c * lateral, xtol=1e-15))
    r_c = np.array([x, 0.0, 0.0]) + y * u
    force = reaction + antenna.gravity_force(theta2)
    torque = np.cross(r_c, reaction) + antenna.gravity_torque(theta2)
    theta = np.tile([0.1, theta2], (n, 1))
    return theta, np.tile(force, (n, 1)), np.tile(torque, (n, 1)), r_c


@pytest.mark.parametrize("theta2", [0.0, 0.4, -0.3])
@pytest.mark.parametrize("push", [1.0, 2.5])
def test_perpendicular_ratio_is_exact_with_axial_friction(theta2: float, push: float) -> None:
    # The estimator inverts the elastica's statics (ratio.perpendicular_ratio notes) through
    # its table (within 1e-3 of the arc length, beam.elastica); here against loads built by an
    # independent boundary-value solution, pushes deflecting the contact by 12 % and 27 % of
    # x_c (R_perp x_c^2 / (E I) = 0.35 and 0.88), with an axial (friction) force of 36 % of the
    # lateral one. Eq. 21 as printed divides |Gamma - Gamma_g| by |R| and is off by the axial
    # force.
    antenna = paper_antenna()
    x_c = 0.62
    reaction = push * np.array([0.03, -0.08, 0.02])
    theta, force, torque, r_c = static_contact_samples(x_c, reaction, theta2)
    r, g = contact_loads(theta, force, torque, antenna)
    # these loads are the elastica's without the link's weight (which test_beam_weight.py
    # adds): read them with a link of the same stiffness and next to no mass
    np.testing.assert_allclose(
        perpendicular_ratio(r, g, weightless(antenna.link), theta[:, 1]), x_c, rtol=1e-3
    )
    printed = paper_ratio(theta, force, torque, antenna, 5.0, TS)
    expected = np.linalg.norm(np.cross(r_c, reaction)) / np.linalg.norm(reaction)
    np.testing.assert_allclose(printed, expected, rtol=1e-9)
    assert abs(expected - x_c) > 5e-3 * push  # what the axial force costs Eq. 21


def test_filtered_ratio_is_exact_while_the_push_grows() -> None:
    # Linear filter + loads proportional to one growing magnitude: the filtered ratio is x_c from
    # the first contact sample on (ratio.py notes). Reference x_c set by construction.
    antenna = paper_antenna()
    x_c = 0.45
    n = 400
    magnitude = np.clip((np.arange(n) - 100) * 5e-4, 0.0, None)  # zero, then a ramp (N)
    direction = np.array([0.0, -0.8, 0.6])
    reaction = magnitude[:, None] * direction
    theta = np.tile([0.0, 0.2], (n, 1))
    force = reaction + antenna.gravity_force(theta[:, 1])
    torque = np.cross(np.array([x_c, 0.0, 0.0]), reaction) + antenna.gravity_torque(theta[:, 1])
    r_f, g_f = filtered_contact_loads(theta, force, torque, antenna, 5.0, TS)
    # loads at x_c without deflection or weight: a stiff link of next to no mass
    ratio = perpendicular_ratio(r_f, g_f, weightless(antenna.link, 1e12), theta[:, 1])
    np.testing.assert_allclose(ratio[110:], x_c, rtol=1e-9)


def test_converged_index_is_causal() -> None:
    ratio = np.concatenate([np.linspace(0.8, 0.5, 300), np.full(300, 0.5)])
    index = converged_index(ratio, 0, 200, 0.01)
    # Window [j-200, j] within 1 cm: the ramp falls 1e-3 m per sample, so the window may hold
    # up to 10 ramp samples (<= 0.01 m above 0.5): j - 200 = 290 -> j = 490.
    assert index == 490
    assert converged_index(ratio[:400], 0, 200, 0.01) is None
    assert converged_index(ratio, 350, 200, 0.01) == 550


# ---------------------------------------------------------------- fusion, result, config


def test_fusion_picks_candidate_nearest_to_ratio() -> None:
    fusion = fuse((0.62, 0.91), 0.88, 0.1)
    assert fusion.x_c == 0.91 and fusion.agree and fusion.distance == pytest.approx(0.03)
    far = fuse((0.62, 0.91), 0.3, 0.1)
    assert far.x_c == 0.62 and not far.agree
    assert fuse((), 0.5, 0.1).x_c == 0.5
    assert math.isnan(fuse((), math.nan, 0.1).x_c)


def test_estimate_to_dict_is_json() -> None:
    estimate = ContactEstimate(
        status=Status.NO_CLEAR_PEAK,
        reason="no peak",
        method="paper",
        x_c=0.5,
        candidates=(0.5,),
        omega1=math.nan,
        diagnostics={"band": (27.0, 123.0), "q": np.float64(3.0), "a": np.arange(3)},
    )
    data = json.loads(json.dumps(estimate.to_dict(), allow_nan=False))
    assert data["status"] == "no_clear_peak"
    assert data["omega1"] is None
    assert data["contact_point"] == [None, None, None]
    for key in ("x_c", "candidates", "ratio_estimate", "t_c", "t_1", "t_e", "reason"):
        assert key in data


def test_status_needs_reason() -> None:
    with pytest.raises(ValueError, match="needs a reason"):
        ContactEstimate(status=Status.NO_CONTACT, reason=None, method="paper")
    assert Status("ok") is Status.OK and str(Status.SLIP_SUSPECTED) == "slip_suspected"


def test_config_validation_names_the_field() -> None:
    with pytest.raises(EstimatorConfigError, match="spectrum_window"):
        EstimatorConfig(spectrum_window=-1.0)
    with pytest.raises(EstimatorConfigError, match="contact_range"):
        EstimatorConfig(contact_range=(0.5, 0.4))


def test_touched_point_sag_is_the_finite_element_cantilever_sag_with_a_tip_mass() -> None:
    # The touched point sits on the link sagged under its weight and its tip mass; at theta = 0
    # the closed-form cantilever sag at x_c equals the simulator's finite-element static sag
    # (20 cubic Hermite elements: exact at their nodes for these loads, within q h^4 / (384 E I)
    # = 1e-8 m between them, so 1e-5 relative on sags of 1.8 to 8.8 cm with a 2 g tip mass).
    from dataclasses import replace

    from sensing_antenna.estimation.front.contact_frame import ContactFrame, motor_axes
    from sensing_antenna.estimation.methods.touch_point import touched_point
    from sensing_antenna.simulator.run import _unit_sag

    link = replace(paper_antenna().link, tip_mass=0.002)
    theta = np.zeros(2)
    frame = ContactFrame(np.eye(3), motor_axes(theta), theta, np.array([0.0, -1e-9, 0.0]))
    grid, unit = _unit_sag(link, 20)
    for k in (122, 245, 400):  # x_c = 0.30, 0.60, 0.98 m, points of the finite-element grid
        point = touched_point(float(grid[k]), frame, 0.0, link)
        expected = STANDARD_GRAVITY * float(unit[k])  # negative: down
        assert point.sag == pytest.approx(-expected, rel=1e-5)
        assert point.point_a[2] == pytest.approx(expected, rel=1e-5)


@pytest.mark.parametrize(("x_c", "relative"), [(0.3, 1.0), (0.45, 0.6), (0.9, 0.05)])
def test_model_spread_walks_the_stretch_the_band_holds_to_its_end(
    x_c: float, relative: float
) -> None:
    # Reference: the contiguous stretch around x_c whose omega_1, solved directly on 4,000
    # points of the link, lies within the band; at 60 and 100 % it reaches the base, 30 and
    # 45 cm away (a spread the reason reports must not stop at a search limit). Tolerance: the
    # two grids' steps (0.5 mm and 0.25 mm).
    link = paper_antenna().link
    x = np.linspace(1e-3, link.length, 4000)
    omega = np.asarray(natural_frequencies(link, x, 1), dtype=float)[:, 0]
    centre = float(np.asarray(natural_frequencies(link, x_c, 1), dtype=float)[..., 0])
    inside = np.abs(omega - centre) <= relative * centre
    k = int(np.searchsorted(x, x_c))
    low, high = k, k
    while low > 0 and inside[low - 1]:
        low -= 1
    while high < x.size - 1 and inside[high + 1]:
        high += 1
    expected = max(x_c - x[low], x[high] - x_c)
    assert model_spread(link, x_c, relative) == pytest.approx(expected, abs=1e-3)
