"""Contact physics: contact-mode frequency vs the beam model (Eq. 4), torque/force ratio (Eq. 18),
the default push depth, penalty convergence, bounce-off, friction slip."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from _simulator_helpers import RotationAfterForceStop, dominant_frequency
from sensing_antenna.antenna import STANDARD_GRAVITY, Antenna, paper_antenna
from sensing_antenna.beam import natural_frequencies
from sensing_antenna.calibration.observer import identify_free_motion
from sensing_antenna.mapping.primitives import PRIMITIVES
from sensing_antenna.recording import Recording
from sensing_antenna.simulator import Scenario, ScenarioError, simulate, simulate_detailed
from sensing_antenna.simulator.contact import Obstacle, motor_frame
from sensing_antenna.simulator.run import (
    SMALL_DEFLECTION_LIMIT,
    deflection_warning,
    minimum_contact_point,
)

CONTACT_POINTS = [0.3, 0.55, 0.8, 0.98]


@pytest.fixture(scope="module")
def identified() -> Antenna:
    """The paper antenna with the observer and contact threshold identified on a simulated free
    motion (Section 5.2), as ``antenna identify`` and the campaign do: the device's own
    threshold (about 0.0009 N m) instead of the paper's 0.02 N m."""
    antenna = paper_antenna()
    free = simulate(antenna, Scenario(case="free", duration=4.0, seed=11))
    fit = identify_free_motion(free.without_ground_truth(), antenna)
    return dataclasses.replace(antenna, observer=fit.observer)


def _shallow_stop() -> RotationAfterForceStop:
    # Stop 0.02 rad after the gravity-free force passes 12 mN (above the 5 mN inertial force of
    # the sweep's acceleration ramp): y_c / x_c of 3 % to 6 %, inside Assumption 1.
    return RotationAfterForceStop(paper_antenna(), force_threshold=0.012, rotation=0.02)


@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
@pytest.mark.parametrize("x_c", CONTACT_POINTS)
def test_contact_frequency_matches_beam_model(case: str, x_c: float) -> None:
    antenna = paper_antenna()
    scenario = Scenario(case=case, contact_point=x_c, noise_scale=0.0, duration=3.5)
    detail = simulate_detailed(antenna, scenario, stop_rule=_shallow_stop())
    rec = detail.recording
    assert detail.stop_index is not None
    assert rec.metadata["true_in_contact_at_end"] == "true"
    true_xc = float(rec.metadata["true_xc"])
    # the contact stays where the sagged link touched: within 1 cm (rolling on the 1 cm radius)
    assert true_xc == pytest.approx(x_c, abs=0.01)
    expected = float(natural_frequencies(antenna.link, true_xc, 1)[0])
    # the dominant torque vibration after the stop (the channel with the largest swing)
    tail = rec.torque[detail.stop_index + 300 :]
    channel = int(np.argmax(np.ptp(tail, axis=0)))
    omega = dominant_frequency(tail[:, channel], 1e-3, 0.6 * expected)
    # 1 %: the brief's requirement; penalty (1e4 N/m vs 3EI/x_c^3 <= 10 N/m) and 16 elements
    # contribute < 0.1 %.
    assert omega == pytest.approx(expected, rel=0.01), (case, x_c, channel)


@pytest.mark.parametrize("x_c", [0.12, 0.27])
def test_a_short_stiff_links_contact_frequency_matches_beam_model(x_c: float) -> None:
    # A 0.35 m carbon rod rings at 232 and 776 rad/s touched at 0.12 and 0.27 m. The paper
    # link's penalty (1e4 N/m, 37 times the rod's mass times its omega^2) and step (0.5 ms,
    # omega h = 0.39) put it 1.9 and 0.9 % low; the defaults follow the link (1.6e5 N/m, 8
    # steps): -0.07 and +0.16 % measured, within 0.3 % (the 0.1 % they are set for, the 16
    # elements' and the reading's share)
    paper = paper_antenna()
    rod = dataclasses.replace(
        paper,
        link=dataclasses.replace(
            paper.link, length=0.35, youngs_modulus=120e9, linear_density=5.0265e-3
        ),
    )
    detail = simulate_detailed(rod, Scenario(case="azimuthal", contact_point=x_c, noise_scale=0.0))
    assert detail.stop_index is not None
    true_xc = float(detail.recording.metadata["true_xc"])
    expected = float(natural_frequencies(rod.link, true_xc, 1)[0])
    tail = detail.recording.torque[detail.stop_index + 300 :, 2]
    omega = dominant_frequency(tail, 1e-3, 0.6 * expected)
    assert omega == pytest.approx(expected, rel=3e-3)
    assert detail.scenario.substeps == 8 and detail.scenario.contact_stiffness > 1e5
    # the paper link's resolved defaults are the values its own tests and results were made with
    paper_detail = simulate_detailed(paper, Scenario(case="azimuthal", contact_point=x_c + 0.3))
    assert (paper_detail.scenario.contact_stiffness, paper_detail.scenario.substeps) == (1e4, 2)


@pytest.mark.parametrize(("case", "x_c"), [("azimuthal", 0.8), ("vertical", 0.98)])
def test_contact_frequency_with_the_default_stop_rule(
    identified: Antenna, case: str, x_c: float
) -> None:
    """The same 1 % check with the controller's default stop rule (PushMonitor, 0.02 rad past
    the detected contact, servo lag compensated) and the identified observer."""
    scenario = Scenario(case=case, contact_point=x_c, noise_scale=0.0, duration=3.5)
    detail = simulate_detailed(identified, scenario)
    rec = detail.recording
    assert detail.stop_index is not None
    assert rec.metadata["true_in_contact_at_end"] == "true"
    expected = float(natural_frequencies(identified.link, float(rec.metadata["true_xc"]), 1)[0])
    tail = rec.torque[detail.stop_index + 300 :]
    channel = int(np.argmax(np.ptp(tail, axis=0)))
    omega = dominant_frequency(tail[:, channel], 1e-3, 0.6 * expected)
    # 1 %: the brief's requirement (measured < 0.1 %).
    assert omega == pytest.approx(expected, rel=0.01)


@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
@pytest.mark.parametrize("x_c", [0.3, 0.6, 0.98])
def test_default_push_keeps_the_deflection_small(
    identified: Antenna, case: str, x_c: float
) -> None:
    """With an identified observer the default push ends at y_c / x_c of a few percent over the
    whole link (detection/push.py: about 3 %, simulated 2.9 % to 3.1 %)."""
    scenario = Scenario(case=case, contact_point=x_c, seed=1, duration=2.0)
    detail = simulate_detailed(identified, scenario)
    ratio = float(detail.recording.metadata["true_deflection_ratio"])
    # [1 %, 5 %]: a band around the 3 % the default push aims at; Assumption 1 allows 10 %.
    assert 0.01 <= ratio <= 0.05, (case, x_c, ratio)
    assert deflection_warning(detail.recording) is None
    # Independent check: the link is held at x_c, so y_c / x_c equals the head's final rotation
    # past the touch angle 0 (first order); 1e-3 for the rolling of the contact on the 1 cm
    # post or bar and the residual vibration in the averaging window.
    joint = 1 if case == "vertical" else 0
    turned = float(detail.true_theta[-500:, joint].mean())
    assert ratio == pytest.approx(turned, abs=1e-3)


@pytest.mark.parametrize("sample_period", [1e-3, 4e-3, 2.5e-4])
def test_servo_lag_compensation_stops_the_joint_where_it_was_at_t1(
    identified: Antenna, sample_period: float
) -> None:
    """Eq. 14 ramp lag: freezing the reference at r(t_1) the joint travels 2 eps omega* further;
    freezing it at r(t_1) - 2 eps omega* it comes back to rest at theta(t_1) after an overshoot of
    eps omega* / e (the response of 1 / (1 + eps s)^2 to that input, docs/simulator.md). The
    controller discretised at 250 Hz and 4 kHz follows the same continuous design."""
    eps = 1.0 / 60.0  # s, default servo pole -60 rad/s
    speed = 0.3  # rad/s, default sweep
    travel = []
    overshoot = []
    for compensate in (False, True):
        scenario = Scenario(
            case="azimuthal",
            contact_point=0.55,
            noise_scale=0.0,
            duration=2.0,
            compensate_servo_lag=compensate,
            sample_period=sample_period,
        )
        detail = simulate_detailed(identified, scenario)
        assert detail.stop_index is not None
        theta = detail.true_theta[:, 0]
        travel.append(float(theta[-1] - theta[detail.stop_index]))
        overshoot.append(float(theta[detail.stop_index :].max() - theta[detail.stop_index]))
    # 10 % / 0.5 mrad: Coulomb friction of Table 1 (stick-slip, < 1 % of a move) and the contact
    # load, which the coupling-torque feedback cancels only up to the sensor noise.
    assert travel[0] == pytest.approx(2 * eps * speed, rel=0.1)
    assert travel[1] == pytest.approx(0.0, abs=5e-4)
    assert overshoot[1] <= eps * speed / math.e + 5e-4


@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
def test_a_retraction_turns_the_head_back_and_the_link_leaves_the_obstacle(case: str) -> None:
    """The same manoeuvre held and retracted 0.5 s after the stop: the same samples until the
    head turns back, then the swept joint comes to rest 0.1 rad back and the link is free."""
    held_scenario = Scenario(case=case, contact_point=0.55, duration=3.0, seed=1)
    held = simulate_detailed(paper_antenna(), held_scenario)
    back = simulate_detailed(
        paper_antenna(), dataclasses.replace(held_scenario, retract_after=0.5, retract_angle=0.1)
    )
    assert held.stop_index == back.stop_index is not None
    turn = held.stop_index + 500  # samples of 1 ms
    assert np.array_equal(held.recording.torque[: turn + 1], back.recording.torque[: turn + 1])
    joint = 1 if case == "vertical" else 0
    # the ramp (0.59 s) and 0.33 s at speed end 0.92 s after the turn; the servo settles within
    # 0.1 s (eps = 17 ms): 1 mrad for the encoder and what the link's ringing still moves
    turned = held.true_theta[-1, joint] - back.true_theta[-1, joint]
    assert turned == pytest.approx(0.1, abs=1e-3)
    in_contact = back.recording.extra["true_in_contact"] > 0.5
    assert held.recording.extra["true_in_contact"][-1] > 0.5 and not in_contact[-1]
    released = int(np.flatnonzero(in_contact)[-1])
    assert turn < released < turn + 920
    assert back.recording.metadata["true_in_contact_at_end"] == "false"
    with pytest.raises(ScenarioError, match=r"retract_after: the free case never stops"):
        Scenario(case="free", retract_after=1.0)
    with pytest.raises(ScenarioError, match=r"retract_angle: must be > 0"):
        dataclasses.replace(held_scenario, retract_angle=0.0)


def test_deep_push_is_flagged_and_tiny_contact_points_are_rejected() -> None:
    ok = Recording(
        t=np.arange(3) * 1e-3,
        theta=np.zeros((3, 2)),
        force=np.zeros((3, 3)),
        torque=np.zeros((3, 3)),
        metadata={"true_deflection_ratio": "0.04"},
    )
    deep = dataclasses.replace(ok, metadata={"true_deflection_ratio": "0.12"})
    assert deflection_warning(ok) is None
    message = deflection_warning(deep)
    assert message is not None and "12.0 %" in message and "antenna identify" in message
    assert SMALL_DEFLECTION_LIMIT == 0.1  # Assumption 1 of the paper
    antenna = paper_antenna()
    # x_min = (10 * 3 E I / k)^(1/3) = (10 * 3 * 0.0903 / 1e4)^(1/3) = 0.0647 m
    assert minimum_contact_point(antenna.link, 1e4) == pytest.approx(0.0647, abs=1e-4)
    with pytest.raises(ScenarioError, match=r"scenario\.contact_point: 0\.02 m is below"):
        simulate(antenna, Scenario(case="azimuthal", contact_point=0.02, duration=0.1))


@pytest.mark.parametrize(
    ("case", "x_c"),
    [("azimuthal", 0.3), ("azimuthal", 0.8), ("vertical", 0.55), ("vertical", 0.98)],
)
def test_static_torque_force_ratio(case: str, x_c: float) -> None:
    """Eq. 18 with gravity removed (Eq. 19) once the vibration has died out (heavy damping here
    only to shorten the wait; the static state does not depend on it), against the exact static
    expectation from the simulator's own state, and its deviation from x_c."""
    antenna = paper_antenna()
    scenario = Scenario(
        case=case, contact_point=x_c, noise_scale=0.0, duration=3.5, damping_ratio=0.1
    )
    detail = simulate_detailed(antenna, scenario, stop_rule=_shallow_stop())
    rec = detail.recording
    # The last second: long against the servo's slow hunting about its hold angle (Coulomb
    # friction), whose inertial share of the wrench swings the ratio by +-0.3 % over 0.3 s.
    window = slice(-1000, None)
    force = rec.force[window].mean(axis=0)
    torque = rec.torque[window].mean(axis=0)
    theta2 = rec.theta[-1, 1]
    weight = antenna.link.mass * STANDARD_GRAVITY
    force_g = weight * np.array([-math.sin(theta2), 0.0, -math.cos(theta2)])
    torque_g = np.array([0.0, 0.5 * weight * antenna.link.length * math.cos(theta2), 0.0])
    ratio = np.linalg.norm(torque - torque_g) / np.linalg.norm(force - force_g)

    # Exact statics of the simulated link (independent of the sensor code): the link's torque on
    # the head about O is p_c x F_c (true contact point and force, motor frame) plus the moment
    # of the deflected link's weight, int rho (x, v, w) x g dx, whose straight-link part is the
    # Gamma_g removed above; what remains is (g_z V, g_x W, -g_x V), V = int rho v, W = int rho w.
    point_m = np.array(
        [
            motor_frame(*th) @ p
            for th, p in zip(detail.true_theta, detail.contact_point, strict=True)
        ]
    )
    contact_force = detail.contact_force[window]
    moment = np.cross(point_m[window], contact_force).mean(axis=0)
    v_integral, w_integral = detail.link_model.translation_load @ detail.final_deflection.T
    true_theta2 = detail.true_theta[-1, 1]
    g_x = -STANDARD_GRAVITY * math.sin(true_theta2)
    g_z = -STANDARD_GRAVITY * math.cos(true_theta2)
    weight_moment = np.array([g_z * v_integral, g_x * w_integral, -g_x * v_integral])
    mean_force = contact_force.mean(axis=0)
    expected = np.linalg.norm(moment + weight_moment) / np.linalg.norm(mean_force)
    # 0.1 %: the residual vibration and the dynamic part of the force (measured <= 0.05 %).
    assert ratio == pytest.approx(expected, rel=1e-3)
    # The moment arm of the contact force alone, |p_c x F_c| / |F_c|: the contact point sits off
    # the straight axis (sag, deflection) and the normal is tilted by the sag slope.
    arm = np.linalg.norm(moment) / np.linalg.norm(mean_force)

    # Deviation from x_c, a physical effect the estimators live with (docs/simulator.md,
    # "Neglected effects"): azimuthal < 0.5 % (measured < 0.1 %);
    # vertical < 1 % (measured 0.5 % at 0.55 m and 0.9 % at 0.98 m, of which the moment arm
    # gives 0.2 % / 0.3 % and the weight of the deflected, raised link the rest).
    true_xc = float(rec.metadata["true_xc"])
    assert abs(arm / true_xc - 1) < 5e-3
    assert ratio == pytest.approx(true_xc, rel=5e-3 if case == "azimuthal" else 1e-2)


def test_contact_frequency_converges_with_penalty_stiffness() -> None:
    antenna = paper_antenna()
    x_c = 0.55
    errors = []
    for stiffness in (30.0, 300.0, 3000.0):
        scenario = Scenario(
            case="azimuthal",
            contact_point=x_c,
            noise_scale=0.0,
            duration=3.0,
            contact_stiffness=stiffness,
        )
        detail = simulate_detailed(antenna, scenario, stop_rule=_shallow_stop())
        assert detail.stop_index is not None
        tail = detail.recording.torque[detail.stop_index + 300 :, 2]
        true_xc = float(detail.recording.metadata["true_xc"])
        reference = float(natural_frequencies(antenna.link, true_xc, 1)[0])
        errors.append(abs(dominant_frequency(tail, 1e-3, 20.0) / reference - 1))
    # a soft support lowers the frequency; the error falls roughly as 1/k
    assert errors[0] > errors[1] > errors[2]
    assert errors[0] / errors[2] > 10.0
    assert errors[2] < 0.01


def test_link_bounces_off_after_a_fast_impact() -> None:
    """Unilateral contact: a fast sweep (1 rad/s, 0.8 m/s at the contact) with little contact
    damping hits the post; the normal force falls back to zero and the link leaves the post for
    tens of ms before the push re-establishes the contact. The normal force is never negative
    (no adhesion)."""
    antenna = paper_antenna()
    scenario = Scenario(
        case="azimuthal",
        contact_point=0.8,
        noise_scale=0.0,
        duration=1.5,
        sweep_speed=1.0,
        accel_time=0.2,
        approach_time=0.6,
        contact_damping=0.05,
    )
    # The 1 rad/s ramp's inertial force (about 20 mN) would trip a 12 mN force threshold.
    detail = simulate_detailed(
        antenna, scenario, stop_rule=RotationAfterForceStop(antenna, 0.1, 0.03)
    )
    assert np.all(detail.normal_force >= 0.0)
    first = int(np.argmax(detail.in_contact))
    assert detail.in_contact[first]
    assert detail.normal_force[first] > 0.1  # N, the impact
    after = detail.in_contact[first:]
    # longest run of samples without contact after the first touch
    runs = np.diff(np.flatnonzero(np.diff(np.concatenate([[1], after.astype(int), [1]])) != 0))
    longest_gap = int(runs[1::2].max()) if runs.size > 1 else 0
    assert longest_gap >= 20  # ms: the link has left the post, not a one-sample chatter
    assert np.all(detail.normal_force[first:][~after] == 0.0)
    assert detail.recording.metadata["true_in_contact_at_end"] == "true"
    # the first touch happens inside the 1 ms before the first sample that shows it
    t_contact = float(detail.recording.metadata["true_t_contact"])
    assert (first - 1) * 1e-3 < t_contact <= first * 1e-3 + 1e-12


@pytest.mark.parametrize("mu", [0.1, 0.6])
def test_friction_slip_on_a_leaning_post(mu: float) -> None:
    """A post leaning by phi = 0.3 rad along the sweep: the link pushes horizontally, so a stuck
    contact needs a tangential (along-the-post) force of tan(phi) = 0.31 times the normal force.
    With mu = 0.6 the contact sticks and ends at that ratio; with mu = 0.1 it slips along the
    post with |F_t| = mu F_n until the link's own bending carries the along-post load."""
    antenna = paper_antenna()
    tilt = 0.3
    scenario = Scenario(
        case="azimuthal",
        contact_point=0.55,
        noise_scale=0.0,
        duration=2.0,
        friction_coefficient=mu,
        obstacle_tilt=tilt,
    )
    detail = simulate_detailed(
        antenna, scenario, stop_rule=RotationAfterForceStop(antenna, 0.012, 0.03)
    )
    contact = detail.in_contact
    normal = detail.normal_force
    tangential = np.sqrt(np.maximum(np.sum(detail.contact_force**2, axis=1) - normal**2, 0.0))
    # Coulomb cone, every sample (1e-9: round-off)
    assert np.all(tangential[contact] <= mu * normal[contact] * (1 + 1e-9))
    slipping = contact & ~detail.sticking
    along_post = 1000.0 * np.ptp(detail.contact_point[contact, 2])  # mm, vertical travel
    final = tangential[-1] / normal[-1]
    if mu > math.tan(tilt):
        assert slipping.sum() <= 0.01 * contact.sum()  # a few samples at the impact
        assert along_post < 0.1
        # stuck: the link's force is horizontal, ratio tan(phi); 1 % for the sag and the
        # out-of-plane bending of the link
        assert final == pytest.approx(math.tan(tilt), rel=0.01)
    else:
        assert slipping.sum() >= 0.1 * contact.sum()
        np.testing.assert_allclose(tangential[slipping], mu * normal[slipping], rtol=1e-9)
        assert along_post > 2.0  # mm along the post
        assert final <= mu


def test_obstacle_tilt_turns_the_contact_normal() -> None:
    """A post leaning by ``tilt`` along the sweep gives the contact force a vertical component
    of sin(tilt) of its horizontal one: the imperfection that excites the Z^c bending."""
    antenna = paper_antenna()
    ratios = []
    for tilt in (0.0, 0.05):
        scenario = Scenario(
            case="azimuthal", contact_point=0.55, noise_scale=0.0, duration=2.0, obstacle_tilt=tilt
        )
        detail = simulate_detailed(antenna, scenario, stop_rule=_shallow_stop())
        assert detail.obstacle is not None
        axis = np.array(detail.obstacle.direction)
        ratios.append(float(axis[1] / axis[2]))
    assert ratios[0] == pytest.approx(0.0, abs=1e-12)
    assert ratios[1] == pytest.approx(math.tan(0.05), rel=1e-9)


def test_a_ball_keeps_the_contact_on_its_surface_where_a_post_lets_it_slide() -> None:
    # A 6 cm ball and a 6 cm post, both tangent to the link at x_c = 0.6 m with their normal
    # turned 0.45 rad out of the sweep's plane; the geometrically exact link slides along what it
    # touches. Along the post's axis it slides off any rounded object of the post's radius: its
    # last contact lies millimetres from the sphere through the touch point with the post's
    # radius. On the ball the link slides over the surface: the contact stays on it (the
    # penalty's penetration, F / k = 0.02 N / 1e4 N/m = 2 um, is the tolerance's scale).
    import json

    def off_sphere(kind: str) -> float:
        scenario = Scenario(
            case="azimuthal",
            contact_point=0.6,
            obstacle=kind,  # type: ignore[arg-type]
            obstacle_radius=0.06,
            obstacle_tilt=0.45,
            link_model="nonlinear",
            seed=1,
        )
        recording = simulate(paper_antenna(), scenario)
        obstacle = json.loads(recording.metadata["true_obstacle"])
        point = np.array(json.loads(recording.metadata["true_contact_point"]))
        # the post's "point" is where its axis passes the nominal touch's normal: the centre of
        # the ball of its radius tangent to the link there
        return float(np.linalg.norm(point - obstacle["point"]) - obstacle["radius"])

    assert abs(off_sphere("ball")) < 2e-5
    assert off_sphere("post") > 1e-3


_SOLID_AXES = (0.0, -0.8, 0.6, 1.0, 0.0, 0.0, 0.0, 0.6, 0.8)  # rows X, Y, Z = X x Y
_SOLID_SIZES = {"box": (0.04, 0.06, 0.1), "cone": (0.04, 0.08), "torus": (0.05, 0.02)}


@pytest.mark.parametrize(
    "kind", ["post", "ball", "plane", "capsule", "cylinder", "box", "cone", "torus"]
)
def test_an_obstacles_outward_normal_is_the_gradient_of_its_gap(kind: str) -> None:
    # central differences of the signed distance, 1e-6 m steps: their error is the step's
    # curvature term, h^2 / R ~ 3e-11 on the 3 cm radius (the capped cylinder's rim, rounded
    # by 5 mm, 2e-10; a box's edges, a cone's rim and apex, rounded by 5 mm; (h / t)^2 / 6 =
    # 6e-9 at a point t = 5 mm from the torus's core circle or the cone's apex, where the
    # gradient turns at 1 / t), and rounding, eps |gap| / h ~ 1e-11
    solid = kind in _SOLID_SIZES
    obstacle = Obstacle(
        kind,
        (0.5, 0.1, -0.2),
        (0.0, 0.6, 0.8),
        0.0 if kind == "plane" or solid else 0.03,
        half_length=0.04 if kind in ("capsule", "cylinder") else 0.0,
        rounding=0.005 if kind == "cylinder" or solid else 0.0,
        axes=_SOLID_AXES if solid else (),
        sizes=_SOLID_SIZES.get(kind, ()),
    )
    rng = np.random.default_rng(3)
    points = np.asarray(obstacle.point) + rng.normal(0.0, 0.05, (20, 3))
    if solid:  # and about the cone's apex, the box's top face, the torus's hole
        top = np.asarray(obstacle.point) + 0.08 * np.asarray(_SOLID_AXES[6:])
        points = np.vstack([points, top + rng.normal(0.0, 0.01, (20, 3))])
    normals = obstacle.outward_normals(points)
    for point, normal in zip(points, normals, strict=True):
        gradient = [
            (obstacle.gap(point + 1e-6 * e) - obstacle.gap(point - 1e-6 * e)) / 2e-6
            for e in np.eye(3)
        ]
        assert normal == pytest.approx(gradient, abs=1e-8 if kind in ("torus", "cone") else 1e-9)


@pytest.mark.parametrize("shape", ["capsule", "cylinder"])
def test_a_capsule_or_capped_cylinder_obstacle_is_the_object_grown_by_the_links_radius(
    shape: str,
) -> None:
    # The obstacle a link of radius a meets with its axis is the object grown by a: its gap is
    # the object's own signed distance less a, everywhere (inside, beside the side, beyond the
    # ends and the rim), against the primitive's independent distance (mapping.primitives);
    # a capped cylinder's radius and height grow by a and its rim is rounded by a
    a, radius, length = 0.001, 0.03, 0.05
    rotation = np.array([0.4, -0.3, 0.2])
    centre = np.array([0.6, 0.02, -0.1])
    axis = Rotation.from_rotvec(rotation).as_matrix()[:, 2]
    grow = 2.0 * a if shape == "cylinder" else 0.0
    obstacle = Obstacle(
        shape,
        tuple(centre),
        tuple(axis),
        radius + a,
        half_length=0.5 * (length + grow),
        rounding=a if shape == "cylinder" else 0.0,
    )
    points = centre + np.random.default_rng(5).normal(0.0, 0.04, (400, 3))
    expected = PRIMITIVES[shape].signed_distance(
        np.array([*centre, *rotation, radius, length]), points
    )
    gaps = np.array([obstacle.gap(p) for p in points])
    np.testing.assert_allclose(gaps, expected - a, atol=1e-12)
    assert (gaps < 0).any() and (gaps > 0.02).any()


@pytest.mark.parametrize("shape", ["box", "cone", "torus"])
def test_a_box_cone_or_torus_obstacle_is_the_object_grown_by_the_links_radius(shape: str) -> None:
    # the same for the solids with a frame of their own: the gap is the primitive's exact
    # signed distance less a, the solid grown by a (its edges, rim and apex rounded by a),
    # inside, beside faces and beyond edges and corners
    a = 0.001
    rotation = np.array([0.4, -0.3, 0.2])
    centre = np.array([0.6, 0.02, -0.1])
    axes = Rotation.from_rotvec(rotation).as_matrix()
    sizes = _SOLID_SIZES[shape]
    rows = tuple(axes.T.flat)  # the solid's own X, Y, Z
    obstacle = Obstacle(shape, tuple(centre), rows[6:], 0.0, rounding=a, axes=rows, sizes=sizes)
    # the torus's parameters name its hole, R - r
    own = (sizes[0] - sizes[1], sizes[1]) if shape == "torus" else sizes
    points = centre + np.random.default_rng(5).normal(0.0, 0.05, (400, 3))
    expected = PRIMITIVES[shape].signed_distance(np.array([*centre, *rotation, *own]), points)
    gaps = np.array([obstacle.gap(p) for p in points])
    np.testing.assert_allclose(gaps, expected - a, atol=1e-12)
    assert (gaps < 0).any() and (gaps > 0.02).any()


def test_an_obstacle_rounded_beyond_its_radius_or_length_is_refused() -> None:
    with pytest.raises(ValueError, match="rounding"):
        Obstacle(
            "cylinder", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.01, half_length=0.05, rounding=0.02
        )
    with pytest.raises(ValueError, match="rounding"):
        Obstacle(
            "cylinder", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.05, half_length=0.01, rounding=0.02
        )
