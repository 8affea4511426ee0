"""Scenes: objects at poses, scene files, the first touch of a sweep, and its simulation."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
import trimesh

from sensing_antenna import paper_antenna
from sensing_antenna.estimation import estimate
from sensing_antenna.mapping import base_pose_from_metadata, points_from_recordings
from sensing_antenna.mapping.pose import BasePose
from sensing_antenna.recording import CONTACT_POINT_COLUMNS, IN_CONTACT_COLUMN, write_recording
from sensing_antenna.scene import (
    LinkShape,
    Scene,
    SceneError,
    SceneObject,
    Sweep,
    facing_region,
    first_touch,
    load_scene,
    mesh_object,
    primitive_object,
    simulate_sweep,
)
from sensing_antenna.scene.file import ExploreRegion
from sensing_antenna.simulator import DeviceImperfections, Scenario, simulate_detailed

DEVICE = paper_antenna()
BALL = '[[objects]]\nshape = "sphere"\nradius = 0.1\nposition = [0, 0, 0]\n'


def _scene(*objects: object, bases: tuple[BasePose, ...] = (BasePose.identity(),)) -> Scene:
    return Scene("test", tuple(objects), bases, ExploreRegion())  # type: ignore[arg-type]


def test_a_post_scene_reproduces_the_simulators_post_run() -> None:
    # the post Scenario(azimuthal, x_c = 0.55) places, built as a scene object from its own
    # true_obstacle: the scene's sweep must derive the same scenario and the same recording
    reference = simulate_detailed(DEVICE, Scenario(case="azimuthal", contact_point=0.55, seed=4))
    post = reference.obstacle
    assert post is not None
    axis = np.array(post.direction)
    # a cylinder's rotation vector taking Z onto the axis (about X: axis = (0, sin t, cos t))
    tilt = math.atan2(axis[1], axis[2])
    centre = np.array(post.point) - axis * post.point[2] / axis[2]  # the axis point at z = 0
    # the simulator's link touches with its axis, the scene's with its surface: the same post
    # is thinner by the link's radius in the scene
    thinner = post.radius - DEVICE.link.radius
    scene = _scene(primitive_object("post", "cylinder", [thinner, 0.6], centre, [-tilt, 0, 0]))
    outcome = simulate_sweep(DEVICE, scene, Sweep(0, "azimuthal", 0.0, -0.3, 0.3), seed=4)
    assert outcome.outcome == "touch" and outcome.scenario is not None
    # x_c to the touch search's tolerance (its bisection and scalar minimisation, 1e-9, and the
    # sag interpolated linearly between the 2 mm samples, below a micrometre)
    assert outcome.scenario.contact_point == pytest.approx(0.55, abs=1e-6)
    # the post itself, grown back by the link's radius, placed where the simulator put its own
    assert outcome.scenario.obstacle == "cylinder"
    assert outcome.scenario.obstacle_radius == pytest.approx(0.01, rel=1e-12)
    assert outcome.scenario.obstacle_placement is not None
    placed = np.array(outcome.scenario.obstacle_placement)
    np.testing.assert_allclose(placed[3:], axis, atol=1e-6)  # the recording's frame turns 1e-7
    offset = placed[:3] - np.array(post.point)
    np.testing.assert_allclose(offset - (offset @ axis) * axis, 0.0, atol=1e-7)
    recording = outcome.recording
    assert recording is not None
    # the same manoeuvre: the loads differ by the micrometres of placement only (the sensor's
    # noise is 6 mN per sample)
    assert np.abs(recording.force - reference.recording.force).max() < 1e-4
    np.testing.assert_array_equal(recording.theta, reference.recording.theta)
    antenna = DEVICE.self_calibrated()
    mine = estimate(recording.without_ground_truth(), antenna, "paper")
    theirs = estimate(reference.recording.without_ground_truth(), antenna, "paper")
    assert mine.status == theirs.status
    assert mine.x_c == pytest.approx(theirs.x_c, abs=1e-5)
    # the recording's frame: turned by the touch angle (1e-7 rad) about Z
    pose = base_pose_from_metadata(recording.metadata)
    np.testing.assert_allclose(pose.rotation, np.eye(3), atol=1e-6)


def test_builtin_post_scene_is_the_same_post() -> None:
    outcome = simulate_sweep(DEVICE, load_scene("post"), Sweep(0, "azimuthal", 0.0, -0.3, 0.3))
    assert outcome.scenario is not None
    assert outcome.scenario.contact_point == pytest.approx(0.55, abs=1e-5)


def test_a_sweep_with_another_links_shape_is_refused() -> None:
    thicker = LinkShape(dataclasses.replace(DEVICE.link, radius=2 * DEVICE.link.radius))
    sweep = Sweep(0, "azimuthal", 0.0, -0.3, 0.3)
    with pytest.raises(ValueError, match="radius"):
        simulate_sweep(DEVICE, load_scene("post"), sweep, shape=thicker)


def test_sphere_touch_matches_the_tangent_line() -> None:
    # without gravity the link is the straight segment [0, l] X^m: sweeping in the plane z = 0,
    # its surface (radius a) first touches a sphere (centre c at height h, radius R) where its
    # axis is tangent to the circle of radius r = sqrt((R + a)^2 - h^2) that the plane cuts of
    # the sphere grown by a, at distance D from the head: theta = alpha - asin(r / D),
    # x_c = sqrt(D^2 - r^2)
    centre = np.array([0.6, 0.2, 0.03])
    radius = 0.07
    scene = _scene(primitive_object("ball", "sphere", [radius], centre))
    shape = LinkShape(DEVICE.link, gravity=0.0)
    touch = first_touch(scene, Sweep(0, "azimuthal", 0.0, -0.5, 0.8), shape).touch
    assert touch is not None and not touch.tip
    grown = radius + DEVICE.link.radius
    r = math.sqrt(grown**2 - centre[2] ** 2)
    distance = math.hypot(centre[0], centre[1])
    assert touch.angle == pytest.approx(
        math.atan2(centre[1], centre[0]) - math.asin(r / distance), abs=1e-8
    )
    assert touch.x_c == pytest.approx(math.sqrt(distance**2 - r**2), abs=1e-7)
    np.testing.assert_allclose(touch.normal, (touch.surface_point - centre) / radius, atol=1e-6)
    # the radius along the link: the sphere's normal curvature is 1 / R in every direction
    assert touch.radius == pytest.approx(radius, rel=1e-4)


def test_tip_touches_a_far_box_and_a_sweep_may_be_free() -> None:
    # a box whose near face is at 0.9 m: the tip (l = 0.98 m) meets its side first
    box = primitive_object("box", "box", [0.2, 0.2, 0.3], [1.0, 0.3, 0.0])
    scene = _scene(box)
    shape = LinkShape(DEVICE.link)
    touch = first_touch(scene, Sweep(0, "azimuthal", 0.0, -0.3, 0.6), shape).touch
    assert touch is not None and touch.tip and touch.x_c == DEVICE.link.length
    # the tip's axis one link radius from the face its surface touches
    gap = box.signed_distance(touch.link_point[None, :])[0]
    assert gap == pytest.approx(DEVICE.link.radius, abs=1e-8)
    # the same box out of reach: nothing touched, free space
    far = _scene(primitive_object("box", "box", [0.2, 0.2, 0.3], [1.5, 0.3, 0.0]))
    outcome = simulate_sweep(DEVICE, far, Sweep(0, "azimuthal", 0.0, -0.3, 0.6))
    assert outcome.outcome == "free" and outcome.recording is None
    assert outcome.sweep_time == pytest.approx(0.9 / 0.3)


def test_a_mesh_file_touches_like_the_primitive(tmp_path: Path) -> None:
    # the same box as an STL file in millimetres, moved by the scene: the same first touch
    box = trimesh.creation.box(extents=[100.0, 150.0, 200.0])
    box.export(tmp_path / "box.stl")
    (tmp_path / "scene.toml").write_text(
        '[[objects]]\nshape = "mesh"\nfile = "box.stl"\nscale = 0.001\n'
        "position = [0.5, 0.2, 0.0]\nrotation = [0.0, 0.0, 0.3]\n"
        '[[objects]]\nname = "ball"\nshape = "sphere"\nradius = 0.05\nposition = [0.4, -0.6, 0]\n'
    )
    scene = load_scene(tmp_path / "scene.toml")
    assert [o.shape for o in scene.objects] == ["mesh", "sphere"]
    primitive = _scene(
        primitive_object("box", "box", [0.1, 0.15, 0.2], [0.5, 0.2, 0.0], [0, 0, 0.3])
    )
    shape = LinkShape(DEVICE.link)
    sweep = Sweep(0, "azimuthal", 0.0, -0.2, 0.8)
    from_mesh = first_touch(scene, sweep, shape).touch
    exact = first_touch(primitive, sweep, shape).touch
    assert from_mesh is not None and exact is not None
    assert from_mesh.object_name == "object1"
    assert from_mesh.angle == pytest.approx(exact.angle, abs=1e-7)
    np.testing.assert_allclose(from_mesh.surface_point, exact.surface_point, atol=1e-6)


@pytest.mark.parametrize(
    ("shape", "sizes"),
    [
        ("cylinder", [0.03, 0.1]),
        ("capsule", [0.02, 0.06]),
        ("cone", [0.04, 0.09]),
        ("torus", [0.05, 0.02]),
        ("box", [0.08, 0.05, 0.03]),
    ],
)
def test_a_primitive_objects_surface_is_its_mesh(shape: str, sizes: list[float]) -> None:
    # What the link touches (the signed distance) and what the figures and scores use (the
    # mesh) are one surface, and the object reports the sizes it was made with: the torus's
    # parameters hold its hole, R - r, not R.
    obj = primitive_object("it", shape, sizes, [0.6, 0.1, -0.02], [0.3, -0.5, 0.2])
    vertices = np.asarray(obj.mesh.vertices)
    # trimesh puts every vertex on the analytic surface: the distances are rounding (1e-16 m);
    # a torus read as (hole, minor) from (major, minor) is off by its minor radius, 2 cm
    assert np.max(np.abs(obj.signed_distance(vertices))) < 1e-12
    assert list(obj.sizes.values()) == pytest.approx(sizes, abs=1e-12)


def test_a_sweep_towards_minus_y_touches_the_other_tangent_line() -> None:
    # the gravity-free link of the test above swept the other way, from the range's end down:
    # it first meets the circle on the tangent line on the other side of the centre's bearing,
    # theta = alpha + asin(r / D), at the same x_c = sqrt(D^2 - r^2), the normal facing back
    # along +Y^m: its component there is r / (R + a) (the rest is the centre's height, along -Z)
    centre = np.array([0.6, 0.2, 0.03])
    radius = 0.07
    scene = _scene(primitive_object("ball", "sphere", [radius], centre))
    shape = LinkShape(DEVICE.link, gravity=0.0)
    touch = first_touch(scene, Sweep(0, "azimuthal", 0.0, -0.5, 0.8, direction=-1), shape).touch
    assert touch is not None and not touch.tip
    grown = radius + DEVICE.link.radius
    r = math.sqrt(grown**2 - centre[2] ** 2)
    distance = math.hypot(centre[0], centre[1])
    alpha = math.atan2(centre[1], centre[0])
    assert touch.angle == pytest.approx(alpha + math.asin(r / distance), abs=1e-8)
    assert touch.x_c == pytest.approx(math.sqrt(distance**2 - r**2), abs=1e-7)
    y_m = np.array([-math.sin(touch.angle), math.cos(touch.angle), 0.0])
    assert touch.normal @ y_m == pytest.approx(r / grown, abs=1e-6)


def test_a_sweep_towards_minus_y_records_the_mirror_image() -> None:
    # the ball reflected in the head's X-Z plane and swept towards -Y^m: the same physics
    # reflected (gravity along Z is unchanged), so without noise the recording is the +Y
    # sweep's with theta1, fy, tx, tz negated, in a proper frame that places its true point on
    # the ball, and the estimate's point lies on the ball as the +Y sweep's does on its own
    ball = primitive_object("ball", "sphere", [0.05], [0.6, 0.1, -0.02])
    mirrored = primitive_object("ball", "sphere", [0.05], [0.6, -0.1, -0.02])
    forward = simulate_sweep(
        DEVICE, _scene(ball), Sweep(0, "azimuthal", 0.0, -0.6, 0.6), noise_scale=0.0
    )
    backward = simulate_sweep(
        DEVICE,
        _scene(mirrored),
        Sweep(0, "azimuthal", 0.0, -0.6, 0.6, direction=-1),
        noise_scale=0.0,
    )
    assert forward.recording is not None and backward.recording is not None
    assert backward.frame is not None and forward.touch is not None
    assert backward.touch is not None
    assert backward.touch.angle == pytest.approx(-forward.touch.angle, abs=1e-7)
    rotation = backward.frame.rotation
    np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-12)
    a, b = forward.recording, backward.recording
    # the swept joint turns the other way: theta1 falls through the touch; to the bit, as the
    # simulator's own sweep down (tests/test_simulator_direction.py): the touch search on the
    # reflected ball runs the same numbers with y negated
    assert b.theta[-1, 0] < b.theta[0, 0]
    np.testing.assert_array_equal(b.theta * [-1, 1], a.theta)
    np.testing.assert_array_equal(b.force * [1, -1, 1], a.force)
    np.testing.assert_array_equal(b.torque * [-1, 1, -1], a.torque)
    truth = np.array(json.loads(b.metadata["true_contact_point"]))
    on_world = backward.frame.point_to_world(truth)
    # the contact on the link's axis: the link's radius off the ball, less the penetration
    distance = mirrored.signed_distance(on_world[None, :])[0]
    assert distance == pytest.approx(DEVICE.link.radius, abs=1e-4)
    ahead = estimate(a.without_ground_truth(), DEVICE, "paper")
    back = estimate(b.without_ground_truth(), DEVICE, "paper")
    assert back.status is ahead.status
    np.testing.assert_array_equal(back.contact_point * [1, -1, 1], ahead.contact_point)
    # with the sensor's noise: the link lies tangent to the ball there, a point 1 cm along it
    # (the paper's typical error) is 1 cm^2 / 2R = 1 mm off the ball, the push's deflection a
    # few mm more
    noisy = simulate_sweep(
        DEVICE, _scene(mirrored), Sweep(0, "azimuthal", 0.0, -0.6, 0.6, direction=-1), seed=2
    )
    assert noisy.recording is not None and noisy.frame is not None
    result = estimate(noisy.recording.without_ground_truth(), DEVICE, "paper")
    point = noisy.frame.point_to_world(result.contact_point)
    assert abs(mirrored.signed_distance(point[None, :])[0]) < 5e-3


def test_a_sweep_keeps_its_direction() -> None:
    back = Sweep(1, "azimuthal", 0.1, -0.4, 0.5, direction=-1)
    assert (back.origin, back.finish) == (0.5, -0.4)
    assert Sweep.from_dict(back.to_dict()) == back
    # a sweep stored before directions existed runs towards +Y
    legacy = {k: v for k, v in back.to_dict().items() if k != "direction"}
    assert Sweep.from_dict(legacy).direction == 1
    assert "-Y" in back.label and "+Y" in Sweep(1, "azimuthal", 0.1, -0.4, 0.5).label
    assert "-Z" in Sweep(0, "vertical", 0.0, -0.2, 0.2, direction=-1).label
    with pytest.raises(ValueError, match="direction must be"):
        Sweep(0, "azimuthal", 0.0, -0.2, 0.2, direction=0)


def test_a_vertical_sweep_down_touches_the_top_of_a_ball() -> None:
    # The link lowered onto a ball below it, its weight helping the push: no mirror image of a
    # sweep up, simulated as such. It touches the ball's top (the normal along +Z^m), the
    # recording's theta2 falls through the touch, its true contact point lies on the ball, and
    # the estimate's point too, within the 5 mm of the mirrored sweep's test above
    ball = primitive_object("ball", "sphere", [0.05], [0.6, 0.0, -0.12])
    sweep = Sweep(0, "vertical", 0.0, -0.6, 0.3, direction=-1)
    outcome = simulate_sweep(DEVICE, _scene(ball), sweep, seed=4)
    assert outcome.outcome == "touch", outcome.reason
    assert outcome.touch is not None and outcome.recording is not None
    assert outcome.frame is not None
    z_m = outcome.frame.rotation[:, 2]
    assert outcome.touch.normal @ z_m > 0.99
    recording = outcome.recording
    assert recording.theta[-1, 1] < recording.theta[0, 1] - 0.1
    truth = np.array(json.loads(recording.metadata["true_contact_point"]))
    # the simulator's obstacle is the ball grown by the link's radius: the contact on the
    # link's axis lies that far (1 mm) off the ball, and the penalty contact's penetration
    # (under 0.1 mm) less
    distance = ball.signed_distance(outcome.frame.point_to_world(truth)[None, :])[0]
    assert distance == pytest.approx(DEVICE.link.radius, abs=1e-4)
    # the estimators with the device's own T as a calibration would give it
    result = estimate(recording.without_ground_truth(), DEVICE.self_calibrated(), "paper")
    assert result.status.value == "ok", result.reason
    point = outcome.frame.point_to_world(result.contact_point)
    assert abs(ball.signed_distance(point[None, :])[0]) < 5e-3


def test_a_point_is_where_the_contact_was_at_its_instant_when_the_contact_slides(
    tmp_path: Path,
) -> None:
    # The exact link lowered onto a ball off its top (the touched normal tilted 25 degrees
    # across the sweep) slides sideways down it after the push. The recording's contact track
    # says where the simulated contact was at every sample; the fast method's point, placed
    # along the reaction its answer's window carries, is where the contact was at the point's
    # instant (t_point) within its covariance: a Mahalanobis distance below 3.37, the 99 %
    # point of the chi distribution with 3 degrees of freedom. The paper method's point, along
    # its filtered reaction at t_e, is where the contact was 1 / omega_c earlier. Both are
    # `ok`: the reaction turns about the link as the contact slides round the ball, which moves
    # neither x_c nor the point placed at its instant. By the recording's end the contact has
    # slid centimetres further, which the points do not claim.
    ball = primitive_object("ball", "sphere", [0.05], [0.6, 0.02, -0.12])
    sweep = Sweep(0, "vertical", 0.0, -0.6, 0.3, direction=-1)
    outcome = simulate_sweep(DEVICE, _scene(ball), sweep, seed=4, link_model="nonlinear")
    assert outcome.recording is not None and outcome.frame is not None
    path = tmp_path / "slide.csv"
    write_recording(outcome.recording, path)
    points = {
        method: points_from_recordings([path], DEVICE.self_calibrated(), method)[0]
        for method in ("fast", "paper")
    }
    for method, point in points.items():
        error = point.point - point.true_point
        assert math.sqrt(error @ np.linalg.solve(point.covariance, error)) < 3.37, method
    assert points["fast"].status.value == "ok"
    assert points["paper"].status.value == "ok"
    ended = outcome.frame.point_to_world(
        np.array(json.loads(outcome.recording.metadata["true_contact_point"]))
    )
    assert np.linalg.norm(ended - points["fast"].true_point) > 0.01


def test_a_link_sliding_off_a_ball_beyond_the_friction_cone_is_not_reported_ok() -> None:
    # The ball further off the link's line (the touched normal 44 degrees across the sweep,
    # beyond mu = 0.6's 31): friction cannot hold the pushed link, which slides centimetres
    # down the ball; both methods see the slip
    ball = primitive_object("ball", "sphere", [0.05], [0.6, 0.035, -0.12])
    sweep = Sweep(0, "vertical", 0.0, -0.6, 0.3, direction=-1)
    outcome = simulate_sweep(DEVICE, _scene(ball), sweep, seed=4, link_model="nonlinear")
    assert outcome.recording is not None and outcome.touch is not None
    assert math.acos(outcome.touch.normal[2]) > math.atan(0.6) + 0.2
    # the ball itself was the obstacle, as the recording's metadata says
    simulation = json.loads(outcome.recording.metadata["simulation"])
    assert simulation["scenario"]["obstacle"] == "ball"
    assert len(simulation["scenario"]["obstacle_placement"]) == 6
    blind = outcome.recording.without_ground_truth()
    for method in ("fast", "paper"):
        result = estimate(blind, DEVICE.self_calibrated(), method)
        assert result.status.value == "slip_suspected", (method, result.status, result.x_c)


_DOWN = Sweep(0, "vertical", 0.0, -0.6, 0.3, direction=-1)


@pytest.mark.parametrize(
    ("touched", "kind"),
    [
        # a ball touched off its top: the link slides down it
        (primitive_object("ball", "sphere", [0.05], [0.6, 0.02, -0.12]), "ball"),
        # a bar sloping 0.9 rad across the sweep, beyond the friction cone: the link slides
        # along it
        (
            primitive_object("bar", "cylinder", [0.03, 0.3], [0.6, 0.0, -0.1], [0.9, 0.0, 0.0]),
            "cylinder",
        ),
        # the same, 3 cm long: touched on its rim, the link slides round it
        (
            primitive_object("disc", "cylinder", [0.03, 0.03], [0.6, 0.0, -0.1], [0.9, 0, 0]),
            "cylinder",
        ),
        # 6 cm long and off the link's line: touched on its side, the link slides onto the
        # rim and off the end
        (
            primitive_object("can", "cylinder", [0.03, 0.06], [0.6, -0.03, -0.1], [0.9, 0, 0]),
            "cylinder",
        ),
        # a capsule as short as the disc, touched on its cap: the link slides onto its side
        (
            primitive_object("pill", "capsule", [0.03, 0.03], [0.6, 0.0, -0.1], [0.9, 0, 0]),
            "capsule",
        ),
        # a capsule standing below the link, touched on its cap off its top: the link slides
        # down the cap and onto the side
        (primitive_object("capsule", "capsule", [0.03, 0.02], [0.6, 0.01, -0.14]), "capsule"),
        # a cube turned on a corner: the link slides along an edge and over faces
        (primitive_object("cube", "box", [0.04] * 3, [0.6, 0.0, -0.1], [0.6, 0.6, 0.3]), "box"),
        # a cone standing below the link, touched off its apex: the link slides down its slant
        (primitive_object("cone", "cone", [0.04, 0.06], [0.6, 0.015, -0.16]), "cone"),
        # a ring standing across the sweep, touched on its tube: the link slides round it
        (
            primitive_object("ring", "torus", [0.05, 0.015], [0.6, 0.0, -0.12], [0.9, 0, 0]),
            "torus",
        ),
    ],
)
def test_a_sliding_contact_stays_on_the_touched_object(touched: SceneObject, kind: str) -> None:
    # The exact link pushed onto a primitive object slides along it by centimetres, over a rim,
    # an edge or from one part onto another; the simulator's obstacle is the object itself,
    # grown by the link's radius, so the contact's track stays on the object throughout:
    # within the penalty contact's penetration F_n / k (a push under 1 N into 1e4 N/m:
    # 0.1 mm). A local stand-in for the surface at the touch let the cone's and the ring's
    # contacts leave them by 8 mm.
    outcome = simulate_sweep(DEVICE, _scene(touched), _DOWN, seed=4, link_model="nonlinear")
    assert outcome.recording is not None and outcome.frame is not None, outcome.reason
    assert outcome.scenario is not None and outcome.scenario.obstacle == kind
    recording = outcome.recording
    touching = recording.extra[IN_CONTACT_COLUMN] > 0.5
    track = np.column_stack([recording.extra[name] for name in CONTACT_POINT_COLUMNS])
    on_world = outcome.frame.point_to_world(track[touching])
    assert np.linalg.norm(on_world[-1] - on_world[0]) > 0.01
    assert np.abs(touched.signed_distance(on_world)).max() < 1e-4


def test_a_turned_base_turns_the_touch() -> None:
    # a level base turned by 0.4 rad and moved: the touch is the unmoved one, carried along,
    # (the ball 2 cm low, where the link sagging 2.5 cm at 0.6 m meets it near its equator)
    # and the simulated recording's frame places its true point on the sphere
    base = BasePose(
        np.array(
            [[math.cos(0.4), -math.sin(0.4), 0], [math.sin(0.4), math.cos(0.4), 0], [0, 0, 1]]
        ),
        [0.3, -0.2, 0.1],
    )
    ball = primitive_object("ball", "sphere", [0.05], [0.6, 0.1, -0.02])
    moved = primitive_object("ball", "sphere", [0.05], base.point_to_world([0.6, 0.1, -0.02]))
    shape = LinkShape(DEVICE.link)
    sweep = Sweep(0, "azimuthal", 0.0, -0.3, 0.6)
    here = first_touch(_scene(ball), sweep, shape).touch
    there = first_touch(_scene(moved, bases=(base,)), sweep, shape).touch
    assert here is not None and there is not None
    assert there.angle == pytest.approx(here.angle, abs=1e-8)
    np.testing.assert_allclose(
        there.surface_point, base.point_to_world(here.surface_point), atol=1e-7
    )
    outcome = simulate_sweep(DEVICE, _scene(moved, bases=(base,)), sweep)
    assert outcome.recording is not None and outcome.frame is not None
    truth = np.array(eval(outcome.recording.metadata["true_contact_point"]))
    on_world = outcome.frame.point_to_world(truth)
    # the simulated link's contact on its axis lies the link's radius off the ball, less the
    # penalty contact's penetration
    distance = moved.signed_distance(on_world[None, :])[0]
    assert distance == pytest.approx(DEVICE.link.radius, abs=1e-4)


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ('[[objects]]\nshape = "blob"\nposition = [0, 0, 0]\n', "objects[0].shape"),
        ('[[objects]]\nshape = "sphere"\nposition = [0, 0, 0]\n', "objects[0].radius"),
        ('[[objects]]\nshape = "sphere"\nradius = -1\nposition = [0, 0, 0]\n', "objects[0].radius"),
        ('[[objects]]\nshape = "sphere"\nradius = 0.1\n', "objects[0].position"),
        # sizes below a millimetre: trimesh meshes a few micrometres' section with no faces
        # and a radius of 1e-30 with non-finite vertices
        (
            '[[objects]]\nshape = "sphere"\nradius = 1e-30\nposition = [0, 0, 0]\n',
            "objects[0].radius",
        ),
        (
            '[[objects]]\nshape = "cylinder"\nradius = 1e-6\nheight = 0.1\nposition = [0, 0, 0]\n',
            "objects[0].radius",
        ),
        (
            '[[objects]]\nshape = "torus"\nmajor_radius = 0.07\nminor_radius = 1e-5\n'
            "position = [0, 0, 0]\n",
            "objects[0].minor_radius",
        ),
        (
            '[[objects]]\nshape = "box"\nextents = [0.1, 0.1, 1e-4]\nposition = [0, 0, 0]\n',
            "objects[0].extents",
        ),
        (
            '[[objects]]\nshape = "box"\nextents = [1, 2]\nposition = [0, 0, 0]\n',
            "objects[0].extents",
        ),
        (
            '[[objects]]\nshape = "sphere"\nradius = 0.1\ncolour = 1\nposition = [0, 0, 0]\n',
            "objects[0].colour",
        ),
        (
            '[[objects]]\nshape = "mesh"\nfile = "nowhere.stl"\nposition = [0, 0, 0]\n',
            "objects[0].file",
        ),
        (
            '[[objects]]\nshape = "sphere"\nradius = 0.1\nposition = [0, 0, 500]\n',
            "objects[0].position",
        ),
        ('name = "x"\n', "objects"),
        # a scene's name goes into every recording's one-line description
        ('name = "a\\nb"\n' + BALL, "name"),
        (
            BALL + "[[bases]]\nquaternion = [2, 0, 0, 0]\n",
            "bases[0].quaternion",
        ),
        (
            BALL + "[explore]\nazimuth = [1, 0]\n",
            "explore.azimuth",
        ),
        (
            BALL + "[[bases]]\n[[bases]]\nelevation = [0.5, 0.2]\n",
            "bases[1].elevation",
        ),
        ("[[objects]\n", "file"),
    ],
)
def test_bad_scene_files_name_file_and_field(tmp_path: Path, text: str, field: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(SceneError) as caught:
        load_scene(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: {field}: ") and "\n" not in message


def test_a_size_in_millimetres_asks_for_metres(tmp_path: Path) -> None:
    path = tmp_path / "mm.toml"
    path.write_text('[[objects]]\nshape = "sphere"\nradius = 60\nposition = [0.5, 0, 0]\n')
    with pytest.raises(SceneError) as caught:
        load_scene(path)
    assert (
        str(caught.value) == f"{path}: objects[0].radius: must be at most 10 m, got 60: in metres?"
    )


def test_a_mesh_in_millimetres_or_a_directory_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a 10 cm cube written in mm reads as a 100 m one; the same file for recognition
    trimesh.creation.box(extents=[100, 100, 100]).export(tmp_path / "cube_mm.stl")
    (tmp_path / "s.toml").write_text(
        '[[objects]]\nshape = "mesh"\nfile = "cube_mm.stl"\nposition = [1, 0, 0]\n'
    )
    with pytest.raises(SceneError, match=r"objects\[0\]\.file: .*100 m.*in metres\?"):
        load_scene(tmp_path / "s.toml")
    (tmp_path / "d.toml").write_text(
        '[[objects]]\nshape = "mesh"\nfile = "."\nposition = [1, 0, 0]\n'
    )
    with pytest.raises(SceneError, match=r"objects\[0\]\.file: .*: a directory"):
        load_scene(tmp_path / "d.toml")
    from sensing_antenna.cli import main

    args = ["map", "r.csv", "--objects", str(tmp_path / "cube_mm.stl"), "--out", "m"]
    assert main(args) == 2
    assert "cube_mm.stl: its largest extent is 100 m" in capsys.readouterr().err


def test_a_mesh_scaled_below_a_millimetre_is_refused_in_one_line(tmp_path: Path) -> None:
    # a 10 mm cube read at a scale meant for nanometres; tiny scales also made trimesh warn
    trimesh.creation.box(extents=[10, 10, 10]).export(tmp_path / "cube.stl")
    for scale in ("1e-6", "1e-100"):
        (tmp_path / "s.toml").write_text(
            f'[[objects]]\nshape = "mesh"\nfile = "cube.stl"\nscale = {scale}\n'
            "position = [1, 0, 0]\n"
        )
        with pytest.raises(SceneError, match=r"objects\[0\]\.file: .*less than 0\.001 m"):
            load_scene(tmp_path / "s.toml")


def test_an_open_mesh_is_refused(tmp_path: Path) -> None:
    open_mesh = trimesh.creation.box(extents=[1, 1, 1])
    open_mesh.update_faces(np.arange(len(open_mesh.faces)) != 0)
    open_mesh.export(tmp_path / "open.stl")
    (tmp_path / "s.toml").write_text(
        '[[objects]]\nshape = "mesh"\nfile = "open.stl"\nposition = [1, 0, 0]\n'
    )
    with pytest.raises(SceneError, match=r"objects\[0\]\.file: .*not closed"):
        load_scene(tmp_path / "s.toml")


def test_a_base_inside_an_object_is_refused(tmp_path: Path) -> None:
    # a ball's radius in cm (6 for 0.06 m) swallows the antenna: every sweep starts inside it
    ball = '[[objects]]\nshape = "sphere"\nradius = 6\nposition = [0.6, 0.05, 0.04]\n'
    (tmp_path / "s.toml").write_text(ball)
    with pytest.raises(
        SceneError,
        match=r"objects\[0\]: the base point \[0\.0, 0\.0, 0\.0\] of bases\[0\] lies inside"
        r" objects\[0\] \('object1'\): a size or position in another unit than m\?$",
    ):
        load_scene(tmp_path / "s.toml")
    # a base of its own, 2 cm inside a box's face: named by the base
    box = '[[objects]]\nshape = "box"\nextents = [0.2, 0.2, 0.2]\nposition = [0.6, 0, 0]\n'
    (tmp_path / "s.toml").write_text(box + "[[bases]]\nposition = [0.52, 0, 0]\n")
    with pytest.raises(SceneError, match=r"bases\[0\]\.position: the base point \[0\.52, "):
        load_scene(tmp_path / "s.toml")


def test_unknown_scene_names_the_builtins() -> None:
    with pytest.raises(SceneError, match="built-in scenes: post, sphere"):
        load_scene("nowhere-scene.toml")


def test_a_directory_named_like_a_builtin_scene_does_not_hide_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # `antenna explore box --out box` run again: the output directory is not the scene
    monkeypatch.chdir(tmp_path)
    (tmp_path / "box").mkdir()
    assert "built-in scene box" in load_scene("box").source
    with pytest.raises(SceneError, match=r"out: file: a directory, not a scene file"):
        (tmp_path / "out").mkdir()
        load_scene("out")


def test_outcomes_the_simulator_cannot_represent_are_named() -> None:
    shape = LinkShape(DEVICE.link)
    sweep = Sweep(0, "azimuthal", 0.0, -0.3, 0.3)
    # a ball cut by the link at the start angle
    inside = _scene(primitive_object("ball", "sphere", [0.05], [0.5, -0.15, -0.02]))
    assert simulate_sweep(DEVICE, inside, sweep, shape=shape).outcome == "inside"
    # a post 4 cm from the head: below the simulator's smallest contact point (6.5 cm)
    near = _scene(primitive_object("post", "cylinder", [0.005, 0.3], [0.045, 0.01, 0.0]))
    outcome = simulate_sweep(DEVICE, near, sweep, shape=shape)
    assert outcome.outcome == "near_head" and outcome.recording is None
    assert outcome.reason is not None and "smallest" in outcome.reason
    # a ball met 1.2 rad off its equator: a straight link (no gravity) 5 sin(1.2) cm above a
    # 5 cm ball's centre
    top = _scene(primitive_object("ball", "sphere", [0.05], [0.6, 0.1, -0.05 * math.sin(1.2)]))
    straight = LinkShape(DEVICE.link, gravity=0.0)
    glancing = simulate_sweep(DEVICE, top, sweep, shape=straight)
    assert glancing.outcome == "glancing" and glancing.touch is not None


def test_a_push_that_would_press_a_second_object_is_reported_not_kept() -> None:
    # two 1 cm posts near one line of the link: the sweep meets the far one first, and the
    # push bends the link's part before the contact forward by several mm, into the near one
    # 2 mm behind that line; the simulator holds one obstacle and would push through it
    sweep = Sweep(0, "azimuthal", 0.0, -0.3, 0.3)
    far = primitive_object("far", "cylinder", [0.01, 0.6], [0.79845, 0.05096, 0.0])
    near = primitive_object("near", "cylinder", [0.01, 0.6], [0.29848, 0.02685, 0.0])
    pressed = simulate_sweep(DEVICE, _scene(far, near), sweep, seed=4)
    assert pressed.outcome == "second_object" and pressed.recording is None
    assert pressed.touch is not None and pressed.touch.object_name == "far"
    assert pressed.reason is not None and "presses on 'near'" in pressed.reason
    # names need not be unique: two posts both called "far" are told apart by where the touch is
    twin = primitive_object("far", "cylinder", [0.01, 0.6], [0.29848, 0.02685, 0.0])
    assert simulate_sweep(DEVICE, _scene(far, twin), sweep, seed=4).outcome == "second_object"
    # 2 cm further back the near post stays clear of the bent link: the touch is kept
    clear = primitive_object("near", "cylinder", [0.01, 0.6], [0.29848, 0.04685, 0.0])
    kept = simulate_sweep(DEVICE, _scene(far, clear), sweep, seed=4)
    assert kept.outcome == "touch" and kept.recording is not None
    assert kept.touch is not None and kept.touch.object_name == "far"


def test_a_base_may_explore_its_own_angles(tmp_path: Path) -> None:
    from sensing_antenna.exploration import grid_sweeps

    path = tmp_path / "two.toml"
    path.write_text(
        BALL.replace("[0, 0, 0]", "[0.6, 0, 0]")
        + "[[bases]]\n"
        + "[[bases]]\nposition = [0.6, -0.5, 0.4]\nyaw = 1.5708\nelevation = [-0.9, -0.5]\n"
        + "[explore]\nazimuth = [-0.2, 0.2]\nelevation = [-0.1, 0.1]\nazimuthal_sweeps = 3\n"
    )
    scene = load_scene(path)
    assert scene.region_of(0) == scene.region
    own = scene.region_of(1)
    # its own elevations, the scene's azimuths and grid counts
    assert own.elevation == (-0.9, -0.5) and own.azimuth == (-0.2, 0.2)
    assert own.azimuthal_sweeps == 3
    for sweep in grid_sweeps(scene):
        elevation = scene.region_of(sweep.base).elevation
        if sweep.case == "azimuthal":
            assert elevation[0] < sweep.fixed < elevation[1]
        else:
            assert (sweep.start, sweep.end) == elevation


def test_facing_region_is_the_angles_a_ball_subtends() -> None:
    # a ball of radius r at distance d on a base's line of sight, seen 0.5 rad from above: the
    # straight link's tangent lines are asin(r / d) to either side (the mesh's vertices lie on
    # the ball, within its facets' 0.1 mm of it: 2e-4 rad at 0.6 m)
    radius, distance, sight = 0.06, 0.6, -0.5
    ball = primitive_object("ball", "sphere", [radius], [0.3, 0.2, 0.1])
    direction = np.array([math.cos(sight), 0.0, math.sin(sight)])
    base = BasePose(np.eye(3), ball.parameters[:3] - distance * direction)
    half = math.asin(radius / distance)
    straight = LinkShape(DEVICE.link, gravity=0.0)
    azimuth, elevation = facing_region(ball.mesh.vertices, base, straight, margin=0.0)
    assert elevation == pytest.approx((sight - half, sight + half), abs=2e-3)
    # across the sight line the angle narrows as the vertical circle leans: asin(r / d) / cos
    assert azimuth[1] == pytest.approx(-azimuth[0], abs=1e-9)
    assert 0.9 * half < azimuth[1] < 1.1 * half / math.cos(sight)
    # the sagged link passes below its line: the region rises by about -w(d) / d
    sagged = LinkShape(DEVICE.link)
    _, raised = facing_region(ball.mesh.vertices, base, sagged, margin=0.0)
    rise = -float(np.interp(distance, sagged.abscissae, sagged.sag())) / distance
    assert raised[0] - elevation[0] == pytest.approx(rise, rel=0.15)


def test_a_rounded_surface_is_simulated_as_a_ball_a_straight_one_as_a_cylinder() -> None:
    # A sphere curves by 1 / R both along the link and across it; a vertical cylinder met by a
    # level azimuthal sweep along the link only. Either primitive is placed itself, grown by
    # the link's radius (the simulated link touches with its axis). A surface the simulator
    # has no shape for gets the equivalent local obstacle: where it curves every way a ball,
    # on which a link sliding across stays on the surface.
    from scipy.spatial.transform import Rotation

    from sensing_antenna.scene.simulate import touch_scenario
    from sensing_antenna.scene.touch import MIN_RADIUS

    shape = LinkShape(DEVICE.link, gravity=0.0)
    sweep = Sweep(0, "azimuthal", 0.0, -0.5, 0.8)
    ball = _scene(primitive_object("ball", "sphere", [0.07], [0.6, 0.2, 0.03]))
    touch = first_touch(ball, sweep, shape).touch
    assert touch is not None
    # the bend probe is exact on a circle; its chord depth h^2 / (2 R) = 29 um read from
    # distances rounded to about 1e-16 m puts R within about 1e-11 of itself
    assert touch.principal_radii == pytest.approx((0.07, 0.07), rel=1e-9)
    scenario, frame = touch_scenario(touch, sweep, ball)
    assert scenario.obstacle == "ball" and scenario.obstacle_placement is not None
    assert touch.link_radius == DEVICE.link.radius
    assert scenario.obstacle_radius == pytest.approx(0.07 + DEVICE.link.radius, rel=1e-12)
    centre = frame.point_to_world(np.array(scenario.obstacle_placement[:3]))
    np.testing.assert_allclose(centre, [0.6, 0.2, 0.03], atol=1e-12)
    post = _scene(primitive_object("post", "cylinder", [0.03, 0.5], [0.6, 0.2, 0.0]))
    touch = first_touch(post, sweep, shape).touch
    assert touch is not None and touch.principal_radii[1] > 1.0
    scenario, _ = touch_scenario(touch, sweep, post)
    assert scenario.obstacle == "cylinder"
    assert scenario.obstacle_length == pytest.approx(0.5 + 2 * DEVICE.link.radius, rel=1e-12)
    # a corner, curved every way: a user's mesh of a cube turned to point a corner at the
    # sweeping link meets a ball (of the smallest radius, grown by the link's); the primitive
    # cube is placed itself, in its own frame, its sizes its own
    corner = Rotation.align_vectors([[0.0, -1.0, 0.0]], [[1.0, 1.0, 1.0]])[0].as_rotvec()
    mesh = _scene(
        mesh_object("cube", trimesh.creation.box(extents=[0.1] * 3), [0.6, 0.2, 0.0], corner)
    )
    touch = first_touch(mesh, sweep, shape).touch
    assert touch is not None and not touch.tip
    scenario, _ = touch_scenario(touch, sweep, mesh)
    assert scenario.obstacle == "ball" and scenario.obstacle_placement is None
    assert scenario.obstacle_radius == pytest.approx(MIN_RADIUS + DEVICE.link.radius)
    cube = _scene(primitive_object("cube", "box", [0.1, 0.1, 0.1], [0.6, 0.2, 0.0], corner))
    touch = first_touch(cube, sweep, shape).touch
    assert touch is not None and not touch.tip
    scenario, frame = touch_scenario(touch, sweep, cube)
    assert scenario.obstacle == "box" and scenario.obstacle_sizes == (0.1, 0.1, 0.1)
    assert scenario.obstacle_placement is not None
    placed = np.array(scenario.obstacle_placement)
    np.testing.assert_allclose(frame.point_to_world(placed[:3]), [0.6, 0.2, 0.0], atol=1e-12)
    axes = Rotation.from_rotvec(corner).as_matrix()
    np.testing.assert_allclose(frame.rotation @ placed[3:6], axes[:, 2], atol=1e-12)
    np.testing.assert_allclose(frame.rotation @ placed[6:9], axes[:, 0], atol=1e-12)


@pytest.mark.parametrize("lean", [0.0, 40.0, 60.0])
def test_an_edge_is_simulated_as_a_cylinder_whichever_way_the_link_crosses_it(lean: float) -> None:
    # A user's mesh of a box turned to meet the level sweep with a vertical edge, then leant by
    # ``lean`` degrees about Y: the link crosses the edge that far off the perpendicular, and
    # the surface bends both along the link and across it. It is still curved one way only
    # (straight along the edge), so its local obstacle is a post, on which a link sliding
    # across stays on the edge, not a ball, off which it would slide.
    from scipy.spatial.transform import Rotation

    from sensing_antenna.scene.simulate import touch_scenario

    turn = Rotation.from_euler("y", lean, degrees=True) * Rotation.from_euler("z", 45, degrees=True)
    box = trimesh.creation.box(extents=[0.1, 0.1, 0.3])
    scene = _scene(mesh_object("box", box, [0.6, 0.2, 0.0], turn.as_rotvec()))
    sweep = Sweep(0, "azimuthal", 0.0, -0.5, 0.8)
    touch = first_touch(scene, sweep, LinkShape(DEVICE.link, gravity=0.0)).touch
    assert touch is not None and not touch.tip
    # the edge, 0.1 / sqrt(2) m in front of the box's centre
    assert touch.surface_point[1] == pytest.approx(0.2 - 0.1 / math.sqrt(2), abs=1e-4)
    smallest, largest = touch.principal_radii
    assert smallest < 2e-3 and largest > 5 * smallest
    scenario, _ = touch_scenario(touch, sweep, scene)
    assert scenario.obstacle == "post"


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("[[bases]]\nposition = [0.0, 0.0, 0.0]\nyaw = 90\n", r"bases\[0\]\.yaw: .*in radians\?"),
        ("[[bases]]\nposition = [0.0, 0.0, 0.0]\nyaw = 1e300\n", r"bases\[0\]\.yaw: "),
        (
            BALL.replace("position", "rotation = [0, 0, 90]\nposition"),
            r"objects\[0\]\.rotation: turns by 90 rad.*in radians\?",
        ),
    ],
)
def test_an_angle_in_degrees_is_refused(text: str, words: str, tmp_path: Path) -> None:
    # a scene's angles are in radians: a yaw of 90 (a quarter turn written in degrees) turns
    # 14 times round, which no one means
    path = tmp_path / "scene.toml"
    path.write_text(text if text.startswith("[[objects]]") else BALL + text)
    with pytest.raises(SceneError, match=words):
        load_scene(path)


def test_the_sag_carries_a_built_devices_tip_mass_and_clamp() -> None:
    # Euler-Bernoulli in closed form: a tip load P adds P x^2 (3 l - x) / (6 E I) to the sag,
    # a root spring k turns the whole link by its moment M = (rho l / 2 + m_t) g l over k,
    # adding M x / k. The Hermite elements are exact for both (cubic and linear in x).
    link = DEVICE.link
    mass, spring, g = 0.5e-3, 30.0, 9.80665
    nominal = LinkShape(link, gravity=g)
    built = LinkShape(link, gravity=g, device=DeviceImperfections(tip_mass=mass))
    clamped = LinkShape(link, gravity=g, device=DeviceImperfections(clamp_stiffness=spring))
    x, length, rigidity = nominal.abscissae, link.length, link.flexural_rigidity
    tip_load = -mass * g * x**2 * (3.0 * length - x) / (6.0 * rigidity)
    np.testing.assert_allclose(built.sag() - nominal.sag(), tip_load, rtol=1e-9, atol=1e-12)
    moment = (link.linear_density * length / 2.0 + link.tip_mass) * g * length
    turn = -moment * x / spring
    np.testing.assert_allclose(clamped.sag() - nominal.sag(), turn, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("link_model", ["linear", "nonlinear"])
def test_a_built_device_touches_where_its_own_sagged_link_meets_the_object(
    link_model: str,
) -> None:
    # A device whose tip carries 0.5 g and whose clamp gives (30 N m/rad) sags a centimetre
    # more at 0.74 m: its sweep's simulated contact starts where the geometric touch of its
    # own sagged link met the ball (within one sample's travel and the penalty contact's
    # penetration, a few tenths of a millimetre), a centimetre from where the uniform link's
    # would have met it
    from sensing_antenna.simulator import DeviceImperfections

    device = DeviceImperfections(tip_mass=0.5e-3, clamp_stiffness=30.0)
    scene = _scene(primitive_object("ball", "sphere", [0.05], [0.7, 0.25, -0.05]))
    sweep = Sweep(0, "azimuthal", 0.0, -0.2, 0.8)
    outcome = simulate_sweep(
        DEVICE, scene, sweep, seed=3, imperfections=device, link_model=link_model
    )
    recording, frame, touch = outcome.recording, outcome.frame, outcome.touch
    assert recording is not None and frame is not None and touch is not None
    simulated = json.loads(recording.metadata["simulation"])["scenario"]["device"]
    assert simulated["tip_mass"] == pytest.approx(0.5e-3)
    touching = np.flatnonzero(recording.extra[IN_CONTACT_COLUMN] > 0.5)
    track = np.column_stack([recording.extra[name] for name in CONTACT_POINT_COLUMNS])
    start = frame.point_to_world(track[touching[:1]])[0]
    assert np.linalg.norm(start - touch.surface_point) < 5e-4
    uniform = first_touch(scene, sweep, LinkShape(DEVICE.link)).touch
    assert uniform is not None and np.linalg.norm(start - uniform.surface_point) > 5e-3
    # a shape of another build is refused: the two touches would not meet
    with pytest.raises(ValueError, match="not the device's as built"):
        simulate_sweep(DEVICE, scene, sweep, shape=LinkShape(DEVICE.link), imperfections=device)


def test_a_primitives_sizes_may_be_named_as_in_a_scene_file_or_as_the_object_names_them() -> None:
    by_order = primitive_object("b", "box", [0.08, 0.05, 0.03])
    by_key = primitive_object("b", "box", {"extents": [0.08, 0.05, 0.03]})
    again = primitive_object("b", "box", by_order.sizes)
    for obj in (by_key, again):
        assert np.array_equal(obj.parameters, by_order.parameters)
    torus = primitive_object("t", "torus", {"minor_radius": 0.02, "major_radius": 0.05})
    assert torus.sizes == {"major_radius": 0.05, "minor_radius": 0.02}


@pytest.mark.parametrize(
    ("shape", "sizes", "words"),
    [
        ("cylinder", {"radius": 0.05}, "a cylinder takes radius, height, got radius"),
        ("cylinder", [0.05], r"\(2 numbers, m\), got 1"),
        ("cylinder", "wide", r"a cylinder takes radius, height \(m\)"),
        ("sphere", -0.05, "each a length > 0"),
        ("sphere", 60.0, r"each from 0.001 to 10 m, got 60.0: in metres\?"),
        ("torus", [0.02, 0.05], "minor_radius must be smaller than its major_radius"),
    ],
)
def test_a_primitives_wrong_sizes_are_named(shape: str, sizes: object, words: str) -> None:
    with pytest.raises(ValueError, match=words):
        primitive_object("it", shape, sizes)  # type: ignore[arg-type]


def test_a_sweeps_base_is_an_index_of_the_scenes_bases() -> None:
    with pytest.raises(TypeError, match="index of a base pose"):
        Sweep(BasePose.identity(), "azimuthal", 0.0, -0.5, 0.5)  # type: ignore[arg-type]
    scene = load_scene("post")
    sweep = Sweep(3, "azimuthal", 0.0, -0.5, 0.5)
    named = r"base 3: scene 'post' has 1 base pose \(indices 0 to 0\)"
    with pytest.raises(ValueError, match=named):
        first_touch(scene, sweep, LinkShape(DEVICE.link))
    with pytest.raises(ValueError, match="base 3"):
        scene.region_of(3)


@pytest.mark.parametrize("as_mesh", [False, True])
def test_a_tip_pushed_across_a_slanted_face_stays_on_it(as_mesh: bool) -> None:
    # The tip meets a box's side face with the link 12 degrees off it (the face's normal 78
    # degrees from the link) and is pushed across it. The simulator's obstacle is the box
    # itself, or for a mesh the plane of the face at the touch, so the contact's track stays on
    # the face throughout, within the penalty contact's penetration (0.1 mm, as above); an
    # obstacle at an angle of the simulator's own put this track 0.6 mm off the face.
    box = primitive_object("box", "box", [0.2, 0.2, 0.3], [1.0, 0.3, 0.0])
    touched = box
    if as_mesh:
        touched = mesh_object("box", trimesh.creation.box(extents=[0.2, 0.2, 0.3]), [1.0, 0.3, 0])
    outcome = simulate_sweep(DEVICE, _scene(touched), Sweep(0, "azimuthal", 0.0, -0.3, 0.6), seed=2)
    assert outcome.touch is not None and outcome.touch.tip
    assert outcome.recording is not None and outcome.frame is not None, outcome.reason
    assert outcome.scenario is not None
    assert outcome.scenario.obstacle == ("plane" if as_mesh else "box")
    recording = outcome.recording
    touching = recording.extra[IN_CONTACT_COLUMN] > 0.5
    track = np.column_stack([recording.extra[name] for name in CONTACT_POINT_COLUMNS])
    on_world = outcome.frame.point_to_world(track[touching])
    assert np.abs(box.signed_distance(on_world)).max() < 1e-4


def test_a_bowed_link_is_refused_in_a_scene() -> None:
    # the scene's link shape is straight: a bowed device's touch would not be where it is found
    with pytest.raises(ValueError, match="a bowed link"):
        simulate_sweep(
            DEVICE,
            load_scene("post"),
            Sweep(0, "azimuthal", 0.0, -0.3, 0.3),
            imperfections=DeviceImperfections(bow=(0.01, 0.0)),
        )


def test_a_drooping_tip_on_a_mesh_face_above_the_root_is_simulated_at_the_tip() -> None:
    # The link, nearly level, rises from its root and droops onto the top face of a mesh box
    # 5 mm above the root's height with its tip: the face's plane, which has no edge, would
    # cut the link near its root (the simulated contact 83 cm from the box, at x = 0.02 m), so
    # the simulator's own plane through the tip stands in; the contact stays at the tip, on the
    # face to within a millimetre (that plane's normal is not the face's)
    box = mesh_object("box", trimesh.creation.box(extents=[0.45, 0.3, 0.305]), [1.075, 0, -0.1475])
    outcome = simulate_sweep(
        DEVICE, _scene(box), Sweep(0, "vertical", 0.0, -0.3, 0.3, direction=-1), seed=1
    )
    assert outcome.touch is not None and outcome.touch.tip
    assert outcome.recording is not None and outcome.frame is not None, outcome.reason
    recording = outcome.recording
    touching = recording.extra[IN_CONTACT_COLUMN] > 0.5
    track = np.column_stack([recording.extra[name] for name in CONTACT_POINT_COLUMNS])
    on_world = outcome.frame.point_to_world(track[touching])
    assert np.all(on_world[:, 0] > 0.97)
    assert np.abs(box.signed_distance(on_world)).max() < 1e-3
