"""End-to-end tests of the estimation pipeline on synthetic recordings built from closed forms.

The synthetic device (``synthetic_recording``) is independent of the project's simulator: the
swept motor follows a raised-cosine speed profile, touches at a chosen abscissa, pushes until the
static deflection is a set fraction of x_c, stops; the loads are the cantilever statics of the
ratio module's notes (R = F - F_g^m, Gamma - Gamma_g^m = r_c x R with |R| = 3 E I y_c / x_c^3,
Eq. 13) plus damped vibrations at the beam model's omega_1(x_c) and omega_2(x_c) in chosen
directions, plus the free link's coupling torque while the head turns (Eq. 15), plus sensor noise
of one ATI Nano17 count. Because the vibration frequency is taken
from the same beam model the estimator inverts, these tests check the pipeline (signs, frames,
instants, fusion, statuses), not the beam model (tested in test_beam*).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.signal import lsim

from _models import calibrated
from _recordings import samples_kept
from sensing_antenna.antenna import STANDARD_GRAVITY, Antenna, paper_antenna
from sensing_antenna.beam import natural_frequencies
from sensing_antenna.beam.weight import pushed_weight_moment
from sensing_antenna.detection.contact import detect_contact
from sensing_antenna.errors import FieldError
from sensing_antenna.estimation import (
    METHODS,
    EarlyOutcome,
    EarlyStopping,
    EstimatorConfig,
    Evidence,
    FrontEnd,
    OnlineEstimator,
    Sessioned,
    Status,
    conclude,
    estimate,
    gather,
    measure_omega1,
)
from sensing_antenna.estimation.config import EstimatorConfigError
from sensing_antenna.estimation.front.contact_frame import motor_axes
from sensing_antenna.estimation.front.evidence import spectrum_window
from sensing_antenna.recording import Recording
from sensing_antenna.simulator import Scenario, simulate

TS = 1e-3
#: One resolution count of an ATI Nano17 (N, N m), the sensor noise of the synthetic device.
FORCE_NOISE = 1.0 / 320.0
TORQUE_NOISE = 1.0 / 64000.0


@dataclasses.dataclass(frozen=True)
class Synthetic:
    x_c: float = 0.5
    case: str = "azimuthal"
    seed: int = 0
    duration: float = 3.5
    deflection_ratio: float = 0.04
    out_of_plane: float = 0.15  # vibration torque amplitude about Y^c / static torque
    in_plane: float = 0.25  # vibration torque amplitude about Z^c / static torque
    second_mode: float = 0.3  # second-mode amplitude / first-mode amplitude
    zeta: float = 0.01
    noise: float = 1.0
    stops: bool = True
    ratio_lever: float | None = None  # lever arm of the static torque (x_c when None)
    slip_speed: float = 0.0  # m/s of the contact point along the link after the stop
    speed: float = 0.3  # rad/s
    contact_time: float = 0.8


def synthetic_recording(spec: Synthetic, antenna: Antenna | None = None) -> Recording:
    antenna = antenna or calibrated()
    link = antenna.link
    rng = np.random.default_rng(spec.seed)
    n = round(spec.duration / TS) + 1
    t = np.arange(n) * TS
    accel = 0.1
    ramp = np.clip((t - 0.3) / accel, 0.0, 1.0)
    speed = spec.speed * 0.5 * (1.0 - np.cos(np.pi * ramp))
    y_final = spec.deflection_ratio * spec.x_c
    push_angle = y_final / spec.x_c
    decel = 0.05
    t_stop = spec.contact_time + (push_angle - 0.5 * spec.speed * decel) / spec.speed
    if spec.stops:
        down = np.clip((t - t_stop) / decel, 0.0, 1.0)
        speed = speed * 0.5 * (1.0 + np.cos(np.pi * down))
    swept = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * TS)])
    swept_contact = float(np.interp(spec.contact_time, t, swept))
    theta = np.zeros((n, 2))
    column = 0 if spec.case == "azimuthal" else 1
    theta[:, column] = swept + (0.0 if spec.case == "azimuthal" else -swept_contact + 0.1)
    # Push direction: +Y^m for the azimuth, +Z^m for the elevation; the reaction is opposite.
    push_dir = np.array([0.0, 1.0, 0.0]) if spec.case == "azimuthal" else np.array([0, 0, 1.0])
    side = np.cross(np.array([1.0, 0.0, 0.0]), push_dir)  # out of the push plane
    x_c = spec.x_c + spec.slip_speed * np.clip(t - (t_stop + decel), 0.0, None)
    y_c = np.clip(x_c * (swept - swept_contact), 0.0, None)  # Eq. 9: deflection at the contact
    magnitude = 3.0 * link.flexural_rigidity * y_c / x_c**3  # Eq. 13
    reaction = -magnitude[:, None] * push_dir
    lever = x_c if spec.ratio_lever is None else spec.ratio_lever + 0 * x_c
    r_c = lever[:, None] * np.array([1.0, 0.0, 0.0]) - y_c[:, None] * push_dir
    moment = np.cross(r_c, reaction)
    # the link's own weight: what the push moves of the sagging link adds about v = X^m x u,
    # u = -push_dir the reaction's direction (beam.weight), gravity along z^m
    up = np.column_stack([np.sin(theta[:, 1]), np.zeros(n), np.cos(theta[:, 1])])
    weight_moment = pushed_weight_moment(
        link, np.clip(x_c, 0.0, link.length), magnitude, 0.0, up[:, 0], -(up @ push_dir)
    ).sum(axis=-1)
    moment += weight_moment[:, None] * np.cross(np.array([1.0, 0.0, 0.0]), -push_dir)
    # Vibration from the impact on: first two contact modes, decaying.
    omegas = natural_frequencies(link, spec.x_c, 2)
    after = np.clip(t - spec.contact_time, 0.0, None)
    static_final = 3.0 * link.flexural_rigidity * y_final / spec.x_c**2
    envelope = (t >= spec.contact_time) * static_final
    modes = np.zeros(n)
    modes_out = np.zeros(n)
    for k, (w, share) in enumerate(zip(omegas, (1.0, spec.second_mode), strict=True)):
        decay = np.exp(-spec.zeta * w * after)
        modes += share * decay * np.sin(w * after + 0.3 * k)
        modes_out += share * decay * np.sin(w * after + 1.1 + 0.5 * k)
    # Torque about the out-of-plane axis comes with in-plane shear force, and vice versa; the
    # base shear of a vibrating link is of the order of its base moment over x_c / 2.
    in_torque = spec.in_plane * envelope * modes
    out_torque = spec.out_of_plane * envelope * modes_out
    moment += in_torque[:, None] * side + out_torque[:, None] * push_dir
    reaction += (in_torque / (0.5 * spec.x_c))[:, None] * push_dir
    reaction += (out_torque / (0.5 * spec.x_c))[:, None] * side
    weight = link.mass * STANDARD_GRAVITY
    s2, c2 = np.sin(theta[:, 1]), np.cos(theta[:, 1])
    gravity_force = np.column_stack([-weight * s2, 0 * s2, -weight * c2])
    gravity_torque = np.column_stack([0 * s2, 0.5 * weight * link.length * c2, 0 * s2])
    # The free link's first mode resists the head's turn: Eq. 15 of the paper,
    # Gamma_e = K s^2 / (s^2 + d s + omega^2) theta with the paper's K, omega, d, integrated by
    # scipy (not the project's discrete observer). By the link on the head it acts about -Z^m
    # for the azimuth (theta2 = 0) and about +Y^m for a rising elevation (docs/develop.md).
    # Until the touch only: the contact pins the link, whose modes are then the contact modes.
    observer = antenna.observer
    numerator = [observer.gain, 0.0, 0.0]
    denominator = [1.0, observer.damping, observer.natural_frequency**2]
    _, coupling, _ = lsim((numerator, denominator), theta[:, column] - theta[0, column], t)
    coupling = np.where(t < spec.contact_time, coupling, 0.0)
    moment[:, 2 if spec.case == "azimuthal" else 1] += (
        -coupling if spec.case == "azimuthal" else coupling
    )
    force = reaction + gravity_force + spec.noise * FORCE_NOISE * rng.standard_normal((n, 3))
    torque = moment + gravity_torque + spec.noise * TORQUE_NOISE * rng.standard_normal((n, 3))
    return Recording(
        t=t,
        theta=theta,
        force=force,
        torque=torque,
        metadata={"sample_period": "0.001", "true_xc": repr(spec.x_c), "seed": str(spec.seed)},
    )


def expected_point(spec: Synthetic, recording: Recording) -> np.ndarray:
    """Touched point: x_c X^m displaced by y_c against the push direction (towards R), plus the
    sag of the link under its own weight (uniformly loaded cantilever, Gere and Timoshenko:
    v = q x^2 (6 l^2 - 4 l x + x^2) / (24 E I)), which the synthetic device's link also has."""
    link = calibrated().link
    theta = recording.theta[-1]
    axes = motor_axes(theta)
    push_row = 1 if spec.case == "azimuthal" else 2
    point = spec.x_c * axes[0] - spec.deflection_ratio * spec.x_c * axes[push_row]
    q = link.linear_density * STANDARD_GRAVITY * math.cos(theta[1])
    x, length = spec.x_c, link.length
    sag = q * x**2 * (6 * length**2 - 4 * length * x + x**2) / (24 * link.flexural_rigidity)
    down = np.array([0.0, 0.0, -1.0])
    across = down - (down @ axes[0]) * axes[0]
    return point + sag * across / np.linalg.norm(across)


# x_c = 0.85 m has two frequency candidates (the sensing curve peaks near 0.78 m), 0.35 m one.
@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
@pytest.mark.parametrize("x_c", [0.35, 0.6, 0.85])
def test_paper_method_recovers_contact_point(case: str, x_c: float) -> None:
    # Reference: the x_c built into the synthetic recording. Tolerance 5 mm: the vibration is at
    # the model's exact omega_1, so only spectral interpolation (< 0.1 rad/s, test_estimation_
    # units) over the curve slope (> 20 rad/s/m here) and the sensor noise remain.
    spec = Synthetic(x_c=x_c, case=case, seed=11)
    recording = synthetic_recording(spec)
    result = estimate(recording, calibrated())
    assert result.status is Status.OK, result.reason
    assert result.x_c == pytest.approx(x_c, abs=5e-3)
    assert result.ratio_estimate == pytest.approx(x_c, abs=0.03)
    assert any(abs(c - x_c) < 5e-3 for c in result.candidates)
    assert result.t_c <= result.t_1 < result.t_e
    # 3D point: the same geometry built independently; tolerance 5 mm as for x_c.
    np.testing.assert_allclose(result.contact_point, expected_point(spec, recording), atol=5e-3)


def test_vibration_only_out_of_plane_or_only_in_plane() -> None:
    antenna = calibrated()
    only_out = estimate(synthetic_recording(Synthetic(in_plane=0.0, seed=3)), antenna)
    only_in = estimate(synthetic_recording(Synthetic(out_of_plane=0.0, seed=3)), antenna)
    assert only_out.ok and only_in.ok
    assert only_out.diagnostics["torque_component"] in ("y_c", "sum")
    assert only_in.diagnostics["torque_component"] in ("z_c", "sum")
    for result in (only_out, only_in):
        assert result.x_c == pytest.approx(0.5, abs=5e-3)


def test_ground_truth_metadata_is_not_read() -> None:
    recording = synthetic_recording(Synthetic(x_c=0.7, seed=5))
    with_truth = estimate(recording, calibrated())
    without = estimate(recording.without_ground_truth(), calibrated())
    lying = estimate(recording.with_metadata(true_xc="0.2"), calibrated())
    assert "true_xc" not in recording.without_ground_truth().metadata
    assert with_truth.to_dict() == without.to_dict() == lying.to_dict()


def run_online(recording: Recording, method: str = "paper", config: EstimatorConfig | None = None):
    online = OnlineEstimator(calibrated(), recording.sample_period, method=method, config=config)
    given = []
    for k in range(recording.n_samples):
        out = online.update(
            recording.t[k], recording.theta[k], recording.force[k], recording.torque[k]
        )
        if out is not None:
            given.append((k, out))
    return given, online.finalize()


def comparable(result) -> dict:
    data = result.to_dict()
    data["diagnostics"] = {
        k: v for k, v in data["diagnostics"].items() if k not in ("sampling", "resampled")
    }
    return data


@pytest.mark.parametrize("method", sorted(METHODS))
def test_online_and_offline_agree(method: str) -> None:
    recording = synthetic_recording(Synthetic(x_c=0.8, case="vertical", seed=9))
    offline = estimate(recording, calibrated(), method=method)
    given, final = run_online(recording, method)
    assert len(given) == 1, "the estimate is given exactly once"
    index, online = given[0]
    assert recording.t[index] == online.t_e
    assert final is online
    assert comparable(online) == comparable(offline)


@pytest.mark.parametrize(
    ("spec", "status"),
    [
        (Synthetic(duration=1.9), Status.RECORDING_TOO_SHORT),
        (Synthetic(stops=False, speed=0.05), Status.PUSH_NOT_REACHED),
        (Synthetic(in_plane=0.0, out_of_plane=0.0), Status.NO_CLEAR_PEAK),
        # a lever 1.4 times x_c: within the scale check's factor 1.5, off the candidate
        (Synthetic(x_c=0.5, ratio_lever=0.7), Status.ESTIMATORS_DISAGREE),
        # 5 cm/s: the ratio settles, then moves by 2.8 cm (limit 2 cm) whatever the seed; at
        # 10 cm/s it sat on the edge of settling at all within the recording (seed-dependent)
        (Synthetic(x_c=0.4, slip_speed=0.05), Status.SLIP_SUSPECTED),
    ],
    ids=["too_short", "no_stop", "no_vibration", "lever_mismatch", "slip"],
)
def test_doubtful_recordings_get_a_status(spec: Synthetic, status: Status) -> None:
    recording = synthetic_recording(spec)
    result = estimate(recording, calibrated())
    assert result.status is status, result.reason
    assert result.reason
    _, final = run_online(recording)
    assert comparable(final) == comparable(result)


def _turned_during_hold(spec: Synthetic, share: float, along: np.ndarray) -> Recording:
    """The synthetic recording with a force at the contact growing over 0.6 s from the stop on
    to ``share`` of the push, then held, along the unit vector ``along`` of the motor frame (its
    moment about O with it)."""
    recording = synthetic_recording(spec)
    link = calibrated().link
    push = 3.0 * link.flexural_rigidity * spec.deflection_ratio / spec.x_c**2  # Eq. 13 (N)
    start = spec.contact_time + spec.deflection_ratio / spec.speed + 0.1  # after the stop
    ramp = np.clip((recording.t - start) / 0.6, 0.0, 1.0)
    added = share * push * ramp[:, None] * along
    contact = spec.x_c * np.array([1.0, 0.0, 0.0])
    return dataclasses.replace(
        recording, force=recording.force + added, torque=recording.torque + np.cross(contact, added)
    )


@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
def test_a_force_turning_across_the_link_is_slip_only_when_asked(case: str) -> None:
    # A contact sliding over the obstacle across the link turns the reaction about the link's
    # axis; a contact held by friction may take a growing share along the link as the servo
    # settles, which turns the reaction too but moves nothing (and sliding along the link is
    # the ratio's check). A quarter of the push is 14 deg. By default the turn is not judged
    # (it moves neither x_c nor the point placed at its instant); with the limit set to 8.6 deg
    # the turn across is slip and the one along is not.
    spec = Synthetic(x_c=0.5, case=case, seed=3)
    along_link = np.array([1.0, 0.0, 0.0])
    across = np.array([0.0, 0.0, 1.0]) if case == "azimuthal" else np.array([0.0, 1.0, 0.0])
    limited = EstimatorConfig(max_direction_drift=0.15)
    clean = estimate(synthetic_recording(spec), calibrated(), config=limited)
    assert clean.status is Status.OK, clean.reason
    held = estimate(_turned_during_hold(spec, 0.25, along_link), calibrated(), config=limited)
    assert held.status is Status.OK, held.reason
    assert held.x_c == pytest.approx(clean.x_c, abs=2e-3)
    slid = _turned_during_hold(spec, 0.25, across)
    result = estimate(slid, calibrated(), config=limited)
    assert result.status is Status.SLIP_SUSPECTED
    assert "turned about the link" in (result.reason or "")
    _, final = run_online(slid, config=limited)
    assert comparable(final) == comparable(result)
    unlimited = estimate(slid, calibrated())
    assert unlimited.status is Status.OK, unlimited.reason
    assert unlimited.x_c == pytest.approx(clean.x_c, abs=2e-3)


def test_no_contact() -> None:
    # A free sweep: the obstacle is never reached (contact far beyond the recording).
    recording = synthetic_recording(Synthetic(contact_time=50.0, stops=False, duration=2.0))
    result = estimate(recording, calibrated())
    assert result.status is Status.NO_CONTACT
    assert math.isnan(result.x_c)
    _, final = run_online(recording)
    assert final.status is Status.NO_CONTACT
    # Without a contact there is no evidence to study: the front end gives the early outcome
    early = gather(recording, calibrated())
    assert isinstance(early, EarlyOutcome)
    assert early.status is Status.NO_CONTACT
    assert early.reason == result.reason
    assert "push deeper" not in (result.reason or "")


def test_a_push_under_the_threshold_is_named_in_no_contact() -> None:
    # Stopped 0.03 rad past the touch at 0.9 m, the link's moment at the base is about
    # 3 E I 0.03 / x_c = 0.009 N m, under the datasheet's 0.02: no contact, but the residual
    # holds that moment to the end where a free sweep's dies out

    class PastTheTouch:
        """Stop 0.03 rad past theta1 = 0, where the simulator's sweep meets the post."""

        def reset(self) -> None:
            pass

        def update(self, t: float, theta: np.ndarray, force: object, torque: object) -> bool:
            return bool(theta[0] >= 0.03)

    antenna = paper_antenna()
    scenario = Scenario(case="azimuthal", contact_point=0.9, duration=2.5, seed=1)
    recording = simulate(antenna, scenario, stop_rule=PastTheTouch())
    assert recording.metadata["true_in_contact_at_end"] == "true"
    recording = recording.without_ground_truth()
    result = estimate(recording, antenna)
    assert result.status is Status.NO_CONTACT
    assert "push deeper, or give the antenna the device's own threshold" in (result.reason or "")


@pytest.mark.parametrize("count", [2, 50, 300])
def test_too_few_samples_for_any_manoeuvre_are_too_short_not_a_free_sweep(count: int) -> None:
    # The first samples of a free sweep: no contact in them, but too few to hold one the front
    # end could use (two rests of 50 ms and the 0.2 s hold: 0.3 s), so they say nothing of free
    # space; 301 samples span 0.3 s, a free sweep's record however short
    recording = synthetic_recording(Synthetic(contact_time=50.0, stops=False, duration=2.0))
    head = samples_kept(recording, np.arange(recording.n_samples) < count)
    result = estimate(head, calibrated())
    assert result.status is Status.RECORDING_TOO_SHORT
    assert result.reason.startswith(f"{count} samples (")
    assert "no contact" in result.reason
    _, final = run_online(head)
    assert comparable(final) == comparable(result)
    longer = samples_kept(recording, np.arange(recording.n_samples) < 301)
    assert estimate(longer, calibrated()).status is Status.NO_CONTACT


def test_push_too_gentle_is_not_a_push() -> None:
    # 0.2 % deflection at 0.9 m: |R| = 3 E I y / x^3 = 0.7 mN... below the 5 mN push threshold,
    # but the vibration still triggers the contact detector.
    spec = Synthetic(x_c=0.9, deflection_ratio=0.0005, in_plane=40.0, out_of_plane=40.0)
    result = estimate(synthetic_recording(spec), calibrated())
    assert result.status in (Status.PUSH_NOT_REACHED, Status.NO_CONTACT)


def test_bad_input_coarse_sampling_and_dead_sensor() -> None:
    recording = synthetic_recording(Synthetic())
    coarse = Recording(
        t=recording.t[::25],
        theta=recording.theta[::25],
        force=recording.force[::25],
        torque=recording.torque[::25],
    )
    result = estimate(coarse, calibrated())
    assert result.status is Status.BAD_INPUT and "Nyquist" in (result.reason or "")
    assert "in ms?" not in (result.reason or "")  # 25 ms is no period in ms
    # what the link needs: 2 times the band's top (116 rad/s for the paper's link) over pi
    assert (result.reason or "").endswith(": this link needs samples at 74 Hz or faster")
    # time stamps in ms, us or ns: 1 s, 1000 s or 1e6 s read as the period, which the reason
    # names
    for unit, factor in (("ms", 1e3), ("us", 1e6), ("ns", 1e9)):
        scaled = dataclasses.replace(recording, t=factor * recording.t)
        result = estimate(scaled, calibrated())
        assert result.status is Status.BAD_INPUT
        assert (result.reason or "").endswith(f"(time stamps in {unit}? the format's are in s)")
    dead = Recording(
        t=recording.t, theta=recording.theta, force=recording.force, torque=0 * recording.torque
    )
    assert estimate(dead, calibrated()).status is Status.BAD_INPUT


def test_irregular_sampling_is_resampled_and_reported() -> None:
    recording = synthetic_recording(Synthetic(x_c=0.45, seed=2))
    keep = np.ones(recording.n_samples, dtype=bool)
    keep[1000:3000:97] = False  # drop about 20 samples
    dropped = Recording(
        t=recording.t[keep],
        theta=recording.theta[keep],
        force=recording.force[keep],
        torque=recording.torque[keep],
        metadata={"sample_period": "0.001"},
    )
    result = estimate(dropped, calibrated())
    assert result.diagnostics["resampled"] is True
    assert result.diagnostics["sampling"]["n_dropped"] > 0
    assert result.ok and result.x_c == pytest.approx(0.45, abs=5e-3)


def test_baselines_on_the_same_recording() -> None:
    recording = synthetic_recording(Synthetic(x_c=0.6, seed=4))
    ratio = estimate(recording, calibrated(), method="ratio")
    two = estimate(recording, calibrated(), method="two-frequency")
    paper = estimate(recording, calibrated())
    assert ratio.t_e == two.t_e == paper.t_e  # same wait for a side-by-side comparison
    # Eq. 21 on cantilever statics: 3 cm (the paper's 3 % of length for prior methods).
    assert ratio.x_c == pytest.approx(0.6, abs=0.03)
    # Two peaks at the exact model frequencies: the nearest curve point, 5 mm.
    assert two.ok and two.x_c == pytest.approx(0.6, abs=5e-3)


def test_measure_omega1_for_calibration() -> None:
    spec = Synthetic(x_c=0.55, seed=8)
    measured = measure_omega1(synthetic_recording(spec), calibrated(), band=(10.0, 150.0))
    expected = float(natural_frequencies(calibrated().link, 0.55, 1)[0])
    # Noise: the Cramer-Rao bound of a sinusoid's frequency (Rife and Boorstyn 1974),
    # sqrt(12 sigma^2 / (A^2 T_s^2 N^3)), is 5e-4 rad/s for sigma = 1/64000 N m, rms amplitude
    # A = 3.5e-3 N m over N = 1000 samples; the Hann periodogram spreads about three times that
    # (2.6e-3 rad/s at most over seeds 1 to 10). Without noise the interpolated peak is 5e-6
    # rad/s off. 0.01 rad/s leaves a 4x margin and still fails a peak read off the padded grid
    # (0.38 rad/s spacing; 0.054 rad/s off here), which 0.1 rad/s would not.
    assert measured.clear and measured.omega1 == pytest.approx(expected, rel=0, abs=0.01)
    assert measured.reason is None
    silent = measure_omega1(
        synthetic_recording(Synthetic(contact_time=50.0, stops=False, duration=2.0)),
        calibrated(),
    )
    assert math.isnan(silent.omega1) and silent.reason


def test_config_changes_delta_t_e1() -> None:
    recording = synthetic_recording(Synthetic(x_c=0.5, seed=1))
    short = estimate(recording, calibrated(), config=EstimatorConfig(spectrum_window=0.5))
    long = estimate(recording, calibrated(), config=EstimatorConfig(spectrum_window=1.2))
    assert short.t_e < long.t_e
    # t_e = t_1 + 1200 samples (the ratio converged sooner): times are k T_s, so only float
    # round-off separates them from 1.2 s; half a sample still tells 1200 from 1199 or 1201.
    assert long.t_e - long.t_1 == pytest.approx(1.2, rel=0, abs=0.5 * TS)


def _carbon_rod() -> Antenna:
    """The paper's antenna with a 1.5 m carbon rod (r 1.5 mm, E 130 GPa, 11.3 g/m) for a link:
    a lab's own, slower than the paper's."""
    base = paper_antenna()
    link = dataclasses.replace(
        base.link,
        length=1.5,
        radius=1.5e-3,
        youngs_modulus=130e9,
        linear_density=11.3e-3,
        tip_mass=0.0,
    )
    return dataclasses.replace(base, link=link)


def test_a_link_slower_than_the_papers_reads_as_many_of_its_periods() -> None:
    # A 1.5 m carbon rod (r 1.5 mm): its lowest omega_1 over 0.2 l to l, 14.8 rad/s, lies below
    # the 19.5 rad/s the paper link's band searches down to, so Delta t_e1 holds as many of its
    # periods as the paper's 1 s holds of that: 19.5 / 14.8 = 1.32 s. Touched at 0.7 m from
    # below, the first quarter second of the hold reads omega_1 low (the head settling with the
    # heavy link, the touch's transients); over 1 s the paper method's answer is 1.3 cm short,
    # over the longer window within 1 cm. The paper's link, calibrated or not, keeps 1 s.
    antenna = _carbon_rod()
    scenario = Scenario(case="vertical", contact_point=0.7, seed=1, sample_period=0.002)
    simulated = simulate(antenna, scenario)
    truth = float(simulated.metadata["true_xc"])
    recording, model = simulated.without_ground_truth(), antenna.self_calibrated()
    result = estimate(recording, model, "paper")
    paper_window = estimate(recording, model, "paper", EstimatorConfig(spectrum_window=1.0))
    assert result.t_e - result.t_1 == pytest.approx(1.32, abs=0.01)
    assert abs(result.x_c - truth) < 0.75 * abs(paper_window.x_c - truth)
    assert abs(result.x_c - truth) < 0.01
    for paper in (paper_antenna(), paper_antenna().self_calibrated(), calibrated()):
        assert spectrum_window(paper.link, EstimatorConfig()) == 1.0
    # a contact range given as a list is the same range
    listed = EstimatorConfig(contact_range=[0.2, 1.0])  # type: ignore[arg-type]
    assert spectrum_window(antenna.link, listed) == spectrum_window(antenna.link, EstimatorConfig())


def test_a_ratio_that_rings_slower_than_its_window_is_no_slip() -> None:
    # The 1.5 m rod touched from below at 0.45 m: omega_1 18.5 rad/s, a period of 0.34 s, longer
    # than the ratio's 0.2 s convergence window, so its moving average swings by some 4 cm about
    # a steady mean and never settles within 1 cm. A contact that slides drifts; this one does
    # not: uncertain, and the reason names the ringing, not a slip
    antenna = _carbon_rod()
    scenario = Scenario(
        case="vertical", contact_point=0.45, seed=1, sample_period=0.002, duration=6.0
    )
    recording = simulate(antenna, scenario).without_ground_truth()
    result = estimate(recording, antenna.self_calibrated(), "paper")
    assert result.status is Status.UNCERTAIN, result.reason
    reasons = [result.reason or "", *result.diagnostics.get("other_reasons", [])]
    assert any("as a link that rings slower than that window" in r for r in reasons), reasons


def test_t1_from_the_push_criterion_is_the_controllers_stop_and_online_equals_offline() -> None:
    """Section 4 step 4: with t1_source = "push" the pipeline's t_1 is the push criterion's
    decision. The simulator's controller stops its motors with the same criterion
    (PushMonitor, default PushCriterion) on the same samples, so t_1 must be the simulator's
    recorded stop instant exactly (an independent check), and online equals offline."""
    antenna = calibrated()
    scenario = Scenario(case="azimuthal", contact_point=0.55, seed=4)
    recording = simulate(antenna, scenario)
    stop = float(recording.metadata["true_t_stop"])  # read for evaluation only
    blind = recording.without_ground_truth()
    config = EstimatorConfig(t1_source="push")
    offline = estimate(blind, antenna, config=config)
    assert offline.t_1 == pytest.approx(stop, abs=1e-12)
    online = OnlineEstimator(antenna, blind.sample_period, config=config)
    result = None
    for k in range(blind.n_samples):
        result = online.update(blind.t[k], blind.theta[k], blind.force[k], blind.torque[k])
        if result is not None:
            break
    assert result is not None
    assert comparable(result) == comparable(offline)  # the whole-file sampling report aside
    rest = estimate(blind, antenna)  # the default rest rule finds the same stop a little later
    # The head moves at the sweep speed until the stop (0.3 rad/s x 50 ms rest window = 15 mrad,
    # 100x the rest tolerance), so rest is never before it; after it the servo's double pole at
    # Scenario.servo_pole = -60 rad/s brings the joint to a standstill within one time constant,
    # 1/60 s (it peaks 7 ms after the stop; 5 to 9 ms over seeds 1 to 5 at 0.3, 0.55, 0.8 m).
    servo_time_constant = -1.0 / scenario.servo_pole
    assert 0.0 <= rest.t_1 - offline.t_1 < servo_time_constant
    # Windows shifted by under 1 % of their 1 s move omega_1 by a fraction of its 5e-4 rad/s
    # noise bound, x_c by micrometres (2e-5 m at most over those runs): 0.1 mm.
    assert abs(rest.x_c - offline.x_c) < 1e-4


def test_t1_source_is_validated() -> None:
    with pytest.raises(EstimatorConfigError, match="t1_source"):
        EstimatorConfig(t1_source="later")  # type: ignore[arg-type]


def test_the_bent_link_factor_may_be_zero_but_not_negative() -> None:
    # 0: a link whose frequencies do not move with the push
    assert EstimatorConfig(bent_link_factor=0.0).bent_link_factor == 0.0
    for bad in (-0.1, math.nan, math.inf):
        with pytest.raises(EstimatorConfigError, match=r"bent_link_factor: must be a finite"):
            EstimatorConfig(bent_link_factor=bad)


def test_the_gap_limit_is_a_duration_unless_given_in_samples() -> None:
    # 20 ms by default: 20 samples at 1 kHz, 5 at 250 Hz, 40 at 2 kHz, at least one
    default = EstimatorConfig()
    assert [default.gap_limit(ts) for ts in (1e-3, 4e-3, 5e-4, 0.05)] == [20, 5, 40, 1]
    # a 1 kHz clock read as 999.995 Hz (an importer's fit of the stamps) is still 1 kHz's
    assert default.gap_limit(1.0 / 999.995) == 20
    assert default.gap_limit(1.0 / 990.0) == 19  # 1 % slow: 20 samples span 20.2 ms
    assert EstimatorConfig(max_gap=3).gap_limit(4e-3) == 3
    for bad in (0, 2.5, -1, True):
        with pytest.raises(EstimatorConfigError, match=r"max_gap: must be an integer >= 1"):
            EstimatorConfig(max_gap=bad)  # type: ignore[arg-type]


def _simulated(case: str) -> Recording:
    """A simulated manoeuvre (the project's simulator, an independent source of samples)."""
    x_c, seed = (0.45, 7) if case == "azimuthal" else (0.8, 8)
    scenario = Scenario(case=case, contact_point=x_c, seed=seed)
    return simulate(calibrated(), scenario).without_ground_truth()


def _assert_same_evidence(evidence: Evidence, other: Evidence) -> None:
    """Every field equal to the bit (NaN where NaN), the trace and the whole file's sampling
    report aside."""
    for f in dataclasses.fields(Evidence):
        value, expected = getattr(evidence, f.name), getattr(other, f.name)
        if f.name == "diagnostics":
            value, expected = (
                {k: v for k, v in d.items() if k != "sampling"} for d in (value, expected)
            )
        if f.name == "frame":
            np.testing.assert_equal(dataclasses.asdict(value), dataclasses.asdict(expected))
        elif f.name != "trace":
            np.testing.assert_equal(value, expected, err_msg=f.name)


@pytest.mark.parametrize("t1_source", ["rest", "push"])
@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
def test_front_end_and_estimate_are_the_same_sample_by_sample_in_blocks_and_in_batch(
    case: str, t1_source: str
) -> None:
    """One front end: fed sample by sample, in random blocks or the whole recording at once
    (gather), it gives the same evidence to the bit, and the online estimate is the offline one."""
    recording, antenna = _simulated(case), calibrated()
    config = EstimatorConfig(t1_source=t1_source)  # type: ignore[arg-type]
    batch = gather(recording, antenna, config)
    assert isinstance(batch, Evidence)
    t, theta, force, torque = recording.t, recording.theta, recording.force, recording.torque
    front = FrontEnd(antenna, recording.sample_period, config)
    given = [
        out
        for k in range(recording.n_samples)
        if (out := front.update(t[k], theta[k], force[k], torque[k])) is not None
    ]
    assert len(given) == 1 and isinstance(given[0], Evidence)
    _assert_same_evidence(given[0], batch)
    front.reset()
    rng = np.random.default_rng(3)
    cuts = np.sort(rng.choice(np.arange(1, recording.n_samples), size=40, replace=False))
    outs = [
        front.update_block(t[p], theta[p], force[p], torque[p])
        for p in np.split(np.arange(recording.n_samples), cuts)
    ]
    blocked = [out for out in outs if out is not None]
    assert len(blocked) == 1 and isinstance(blocked[0], Evidence)
    _assert_same_evidence(blocked[0], batch)
    offline = estimate(recording, antenna, config=config)
    online = OnlineEstimator(antenna, recording.sample_period, config=config)
    results = [
        out
        for k in range(recording.n_samples)
        if (out := online.update(t[k], theta[k], force[k], torque[k])) is not None
    ]
    assert [r.t_e for r in results] == [offline.t_e] and offline.ok
    assert comparable(results[0]) == comparable(offline)


def test_estimate_is_gather_then_conclude_and_keeps_what_the_front_end_saw() -> None:
    recording, antenna = synthetic_recording(Synthetic(x_c=0.6, seed=4)), calibrated()
    gathered = gather(recording, antenna)
    assert isinstance(gathered, Evidence)
    for method in ("paper", "ratio", "two-frequency"):
        once = conclude(gathered, method)
        assert once.to_dict() == estimate(recording, antenna, method).to_dict()
    result = estimate(recording, antenna)
    trace = result.trace
    assert trace is not None and "trace" not in result.to_dict()
    # The trace covers every sample of the recording, its instants are the estimate's
    assert trace.t.shape == (recording.n_samples,)
    assert trace.contact_index is not None and trace.rest_index is not None
    assert trace.end_index == gathered.end_index
    assert (trace.t[trace.contact_index], trace.t[trace.rest_index]) == (result.t_c, result.t_1)
    assert trace.t[gathered.end_index] == result.t_e
    # Figure 11's signals are the contact detector's (its batch form, an independent call)
    detection = detect_contact(recording, antenna)
    np.testing.assert_array_equal(trace.filtered_residual_norm, detection.filtered_residual_norm)
    np.testing.assert_array_equal(trace.estimated_torque, detection.estimated_torque)
    assert trace.contact_index == detection.index
    # Figures 12 to 14: the evidence's loads, ratio, frame and window, continued to the end
    e = gathered.end_index
    np.testing.assert_array_equal(trace.reaction_f[: e + 1], gathered.reaction_f)
    np.testing.assert_array_equal(trace.ratio[: e + 1], gathered.ratio)
    assert trace.frame is not None and trace.spectrum == gathered.spectrum_slice
    np.testing.assert_array_equal(trace.frame.axes_m, gathered.frame.axes_m)
    # An early outcome keeps what was seen too
    silent = estimate(synthetic_recording(Synthetic(contact_time=50.0, stops=False)), antenna)
    assert silent.status is Status.NO_CONTACT and silent.trace is not None
    assert silent.trace.contact_index is None and np.all(np.isnan(silent.trace.ratio))


def test_method_abilities_are_typed() -> None:
    fast, paper = METHODS["fast"], METHODS["paper"]
    assert isinstance(fast, EarlyStopping) and isinstance(fast, Sessioned)
    assert isinstance(fast.session(), EarlyStopping)
    assert not isinstance(paper, EarlyStopping) and not isinstance(paper, Sessioned)


def test_front_end_names_a_misshapen_block() -> None:
    front = FrontEnd(calibrated(), TS)
    with pytest.raises(FieldError, match=r"theta: shape \(2, 3\), expected \(2, 2\)"):
        front.update_block(np.zeros(2), np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3)))


def test_online_samples_skipped_are_put_back_and_a_time_jump_is_bad_input() -> None:
    # Fed sample by sample without every 25th: the estimate of the file those samples make
    # (which reading resamples); a stamp a day late cannot be filled and ends the run
    recording = synthetic_recording(Synthetic(x_c=0.6, seed=5))
    lossy = samples_kept(recording, np.arange(recording.n_samples) % 25 != 24)
    _, online = run_online(lossy)
    offline = estimate(lossy, calibrated())
    assert online.status is offline.status is Status.OK
    # the file's resampling and the online filling interpolate between the same neighbours:
    # equal but for the rounding of the interpolated times
    assert online.x_c == pytest.approx(offline.x_c, abs=1e-9)
    # and the 4 % of samples put back by straight lines move the answer by well under the
    # millimetre the whole record's answer is known to (read as uniform, without them it
    # would ring 4 % fast: a centimetre)
    assert online.x_c == pytest.approx(estimate(recording, calibrated()).x_c, abs=1e-3)
    jumped = OnlineEstimator(calibrated(), TS)
    jumped.update(0.0, np.zeros(2), np.zeros(3), np.zeros(3))
    jumped.update(86400.0, np.zeros(2), np.zeros(3), np.zeros(3))
    result = jumped.finalize()
    assert result.status is Status.BAD_INPUT
    assert (result.reason or "").startswith("t: time jumps from 0.0 to 86400.0 s")


@pytest.mark.parametrize("clock", [1.008, 0.995])
def test_stamps_off_the_declared_period_are_resampled_by_them(clock: float) -> None:
    # Stamps one period apart under a sample_period declared 0.8 % long or 0.5 % short (under
    # the 1 % of jitter that alone makes sampling irregular). Read as samples one declared
    # period apart, the vibration rings that much off and x_c moves by millimetres, still `ok`;
    # the file is resampled by its stamps and answers as if declared right
    recording = synthetic_recording(Synthetic(x_c=0.6, seed=5))
    declared = recording.with_metadata(sample_period=repr(TS * clock))
    right = estimate(recording, calibrated())
    offline = estimate(declared, calibrated())
    assert offline.status is right.status is Status.OK
    assert offline.diagnostics["resampled"]
    # interpolation between samples 10+ per period of the vibration: micrometres at most
    assert offline.x_c == pytest.approx(right.x_c, abs=1e-5)
    as_declared = dataclasses.replace(declared, t=TS * clock * np.arange(recording.n_samples))
    assert abs(estimate(as_declared, calibrated()).x_c - right.x_c) > 1e-3


def test_candidates_the_ratio_cannot_tell_apart_without_a_second_mode_are_uncertain() -> None:
    # Near the top of the sensing curve (x_c = 0.8 m; its maximum near 0.768 l) the two
    # candidates of omega_1 (0.739 and 0.800 m) lie 6 cm apart, within two of the ratio's
    # uncertainties there (3.2 cm); with no second mode in the vibration nothing tells them
    # apart, and the answer is uncertain, not ok; with it, the second mode chooses
    recording = synthetic_recording(Synthetic(x_c=0.8, second_mode=0.0, seed=3))
    result = estimate(recording, calibrated())
    assert len(result.candidates) == 2
    assert result.status is Status.UNCERTAIN, result.reason
    assert "cannot tell the candidate" in (result.reason or "")
    chosen = estimate(synthetic_recording(Synthetic(x_c=0.8, seed=3)), calibrated())
    assert chosen.status is Status.OK and chosen.diagnostics["discriminated_by"] == "omega2"
    assert chosen.x_c == pytest.approx(0.8, abs=1e-3)


@pytest.mark.parametrize("method", ["fast", "paper"])
def test_the_point_turns_with_a_head_that_yields_after_t1(method: str) -> None:
    # A servo holding the head against the push yields a little after t_1. The point is placed
    # with the head's angles at the instant it describes: the same recording with the azimuth
    # stepped by 2 mrad after the hold that sets the contact frame (forces unchanged) gives the
    # same x_c and a point turned about the azimuth axis by the step's share of those angles:
    # of the answer's window for `fast`, of the reaction's low-pass weights from t_1 for `paper`
    # (stepped where it takes about half of them).
    antenna = calibrated()
    recording = simulate(antenna, Scenario(case="azimuthal", contact_point=0.5, seed=4))
    blind = recording.without_ground_truth()
    before = estimate(blind, antenna, method=method)
    config = EstimatorConfig()
    start = before.t_1 + config.frame_window + 0.05
    if method == "paper":
        start = max(start, before.t_e - math.log(2.0) / config.lowpass_cutoff)
    step, stepped = 2e-3, blind.t > start
    theta = np.array(blind.theta)
    theta[stepped, 0] += step
    after = estimate(dataclasses.replace(blind, theta=theta), antenna, method=method)
    assert after.x_c == before.x_c
    t = blind.t
    if method == "fast":
        held = (t >= before.diagnostics["window_start"]) & (t <= before.t_e)
        share = np.count_nonzero(held & stepped) / np.count_nonzero(held)
    else:
        held = (t >= before.t_1) & (t <= before.t_e)
        weights = np.exp(-config.lowpass_cutoff * (before.t_e - t[held]))
        share = weights[stepped[held]].sum() / weights.sum()
    turned = after.diagnostics["theta_at_point"][0] - before.diagnostics["theta_at_point"][0]
    assert 0.2 < share < 0.8  # a share that tells these angles from t_1's (0) and the step's (1)
    # the same samples' weighted mean: equal but for rounding
    assert turned == pytest.approx(share * step, rel=1e-6)
    azimuth = [math.atan2(e.contact_point[1], e.contact_point[0]) for e in (before, after)]
    assert azimuth[1] - azimuth[0] == pytest.approx(turned, abs=1e-9)
    assert after.contact_point[2] == pytest.approx(before.contact_point[2], abs=1e-12)


def test_a_path_for_a_recording_is_told_to_read_it_first(tmp_path: Path) -> None:
    with pytest.raises(TypeError, match=r"read_recording\(path\)"):
        estimate(str(tmp_path / "rec.csv"), paper_antenna())  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="a Recording is needed"):
        estimate(None, paper_antenna())  # type: ignore[arg-type]


def test_a_record_short_for_a_head_slow_to_rest_says_so() -> None:
    # The head's angles keep swaying (1 mrad at 8 Hz, a servo or a mount ringing) for 0.8 s
    # after the stop, and the record ends 0.7 s after the rest: too short, and the reason says
    # the rest came late, not that the record was cut early
    antenna = paper_antenna()
    recording = simulate(antenna, Scenario(case="azimuthal", contact_point=0.6, duration=3.5))
    stop = float(recording.metadata["true_t_stop"])
    theta = recording.theta.copy()
    sway = (recording.t > stop) & (recording.t < stop + 0.8)
    theta[sway, 0] += 1e-3 * np.sin(2 * np.pi * 8.0 * (recording.t[sway] - stop))
    swayed = dataclasses.replace(recording, theta=theta)
    cut = samples_kept(swayed, swayed.t < stop + 0.8 + 0.7)
    result = estimate(cut.without_ground_truth(), antenna, "paper")
    assert result.status is Status.RECORDING_TOO_SHORT
    assert "the head was slow to come to rest" in (result.reason or ""), result.reason
    # the same record without the sway, cut as short after its rest, says nothing of it
    plain = samples_kept(recording, recording.t < stop + 0.7)
    reason = estimate(plain.without_ground_truth(), antenna, "paper").reason or ""
    assert "only" in reason and "slow to come to rest" not in reason, reason
