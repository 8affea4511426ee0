"""Recognition: each class recovered from noisy points of a trimesh shape; abstention."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation
from scipy.stats import binom

from _contacts import box_but_its_top
from sensing_antenna.mapping import (
    UNDECIDED,
    ClassFit,
    FreeSpace,
    Touches,
    fit_mesh,
    fit_primitive,
    recognise,
    recognition,
)
from sensing_antenna.mapping.primitives import PRIMITIVES
from sensing_antenna.mapping.recognition import (
    LINE_STRETCH,
    OUTLIER_FRACTION,
    LinkLines,
    shape_gap,
)
from sensing_antenna.mapping.store import crossed, overdispersed, unexplained

#: Noise of the synthetic points (m, isotropic 1 sigma): about the points' sigma across the link.
NOISE = 0.001

#: Relative size error allowed: the task's 5 %.
SIZE_TOLERANCE = 0.05


def _pose(rng: np.random.Generator) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, :3] = Rotation.random(random_state=rng).as_matrix()
    direction = rng.normal(size=3)
    matrix[:3, 3] = rng.uniform(0.3, 0.9) * direction / np.linalg.norm(direction)
    return matrix


#: Each class as trimesh builds it (an independent reference), and its true sizes (m).
SHAPES = {
    "sphere": (lambda: trimesh.creation.icosphere(subdivisions=4, radius=0.06), {"radius": 0.06}),
    "cylinder": (
        lambda: trimesh.creation.cylinder(radius=0.04, height=0.15, sections=128),
        {"radius": 0.04, "height": 0.15},
    ),
    "capsule": (
        lambda: trimesh.creation.capsule(height=0.1, radius=0.035, count=[64, 64]),
        {"radius": 0.035, "length": 0.1},
    ),
    "cone": (
        lambda: trimesh.creation.cone(radius=0.06, height=0.14, sections=128),
        {"radius": 0.06, "height": 0.14},
    ),
    "torus": (
        lambda: trimesh.creation.torus(
            major_radius=0.07, minor_radius=0.025, major_sections=128, minor_sections=64
        ),
        {"major_radius": 0.07, "minor_radius": 0.025},
    ),
    "box": (
        lambda: trimesh.creation.box(extents=(0.06, 0.1, 0.16)),
        {"extent": (0.06, 0.1, 0.16)},
    ),
}


def _sample(
    mesh: trimesh.Trimesh, n: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    points, _ = trimesh.sample.sample_surface(mesh, n, seed=int(rng.integers(2**31)))
    noisy = points + rng.normal(0.0, NOISE, points.shape)
    return noisy, np.tile(np.eye(3) * NOISE**2, (n, 1, 1))


def _placed(name: str) -> tuple[trimesh.Trimesh, np.random.Generator]:
    """The class's mesh at a random pose, and the generator that drew it (seeded by the name)."""
    rng = np.random.default_rng(sorted(SHAPES).index(name))
    mesh = SHAPES[name][0]()
    mesh.apply_transform(_pose(rng))
    return mesh, rng


def _lattice(n: int, band: float = 1.0) -> np.ndarray:
    """``n`` unit vectors spread evenly (a Fibonacci lattice) over the unit sphere's band
    |z| <= ``band``, shape (n, 3)."""
    k = np.arange(n) + 0.5
    z = band * (1.0 - 2.0 * k / n)
    azimuth = math.pi * (3.0 - math.sqrt(5.0)) * k
    rho = np.sqrt(1.0 - z**2)
    return np.stack([rho * np.cos(azimuth), rho * np.sin(azimuth), z], axis=1)


def _size_error(name: str, fitted: Mapping[str, float]) -> float:
    """The largest relative error of the fitted sizes against ``SHAPES``' (box extents sorted)."""
    sizes = SHAPES[name][1]
    if name == "box":
        pairs = zip(sorted(fitted.values()), sizes["extent"], strict=True)
        return max(abs(a / b - 1) for a, b in pairs)
    return max(abs(fitted[k] / v - 1) for k, v in sizes.items())


@pytest.mark.parametrize("name", list(SHAPES))
def test_each_class_is_recognised_with_its_size(name: str) -> None:
    mesh, rng = _placed(name)
    points, covariances = _sample(mesh, 35, rng)
    fitted: list[str] = []  # what a progress display hears
    result = recognise(
        points, covariances, rng=np.random.default_rng(0), class_fitted=fitted.append
    )
    assert fitted == list(PRIMITIVES)
    assert result.decision == name, (result.decision, result.candidates, result.delta_score)
    assert result.confidence > 0.9
    assert _size_error(name, result.best.sizes) < SIZE_TOLERANCE, result.best.sizes
    # the residual is the noise: the RMS distance of points with 1 mm noise along the normal
    assert result.best.rms < 2 * NOISE


@pytest.mark.parametrize("name", ["box", "capsule"])
def test_two_wrong_points_do_not_decide_the_class(name: str) -> None:
    # Two of 37 points 3 cm off the surface with the covariance of right ones (estimates
    # reported ok that are wrong): the class and its sizes are still the points' own, whereas
    # under a plain Gaussian chi^2 those two points alone leave both undecided.
    mesh, rng = _placed(name)
    points, covariances = _sample(mesh, 35, rng)
    wrong, _ = _sample(mesh, 2, rng)
    wrong += 0.03 * (wrong - mesh.centroid) / np.linalg.norm(wrong - mesh.centroid, axis=1)[:, None]
    points = np.vstack([points, wrong])
    covariances = np.vstack([covariances, covariances[:2]])
    result = recognise(points, covariances, rng=np.random.default_rng(0))
    assert result.decision == name, (result.decision, result.candidates, result.delta_score)
    assert _size_error(name, result.best.sizes) < SIZE_TOLERANCE, result.best.sizes
    # two in 37 is what wrong estimates (1 in 100) make in one map of 20: nothing to say
    assert result.best.n_wrong == 2
    assert result.best.wrong_chance == pytest.approx(1 - binom.cdf(1, 37, OUTLIER_FRACTION))
    assert unexplained(result) == ""


@pytest.mark.parametrize("name", ["box", "cylinder"])
def test_a_point_placed_far_from_the_rest_is_the_one_counted_wrong(name: str) -> None:
    # One of 36 points half a metre from the object (a base pose written wrong): every start
    # made of all the points lies between it and the object, and the fits from them were
    # dragged (a plane or a cone named, sizes of tens of cm). The class and its sizes are the
    # other points' own, and that point is the one the fit counts wrong
    mesh, rng = _placed(name)
    points, covariances = _sample(mesh, 35, rng)
    away = mesh.centroid + 0.5 * _lattice(1)[0]
    points = np.vstack([points[:7], away, points[7:]])
    covariances = np.vstack([covariances, covariances[:1]])
    result = recognise(points, covariances, rng=np.random.default_rng(0))
    assert result.decision == name, (result.decision, result.candidates, result.delta_score)
    assert _size_error(name, result.best.sizes) < SIZE_TOLERANCE, result.best.sizes
    assert result.best.wrong == (7,)
    assert result.best.distances(points[7:8])[0] > 0.3


def test_points_of_another_object_among_a_spheres_are_said_to_be() -> None:
    # Six of 41 points lie on another object 2 to 6 cm beyond the ball (two explorations'
    # recordings mapped together): the ball is still the class that explains the most, but
    # six wrong estimates or more in 41 happen in one map of 300,000: the map says so, and
    # names no class (the points are not of one sphere)
    mesh, rng = _placed("sphere")
    points, covariances = _sample(mesh, 35, rng)
    other, _ = _sample(mesh, 6, rng)
    outward = (other - mesh.centroid) / np.linalg.norm(other - mesh.centroid, axis=1)[:, None]
    other += np.linspace(0.02, 0.06, 6)[:, None] * outward
    result = recognise(
        np.vstack([points, other]),
        np.vstack([covariances, covariances[:6]]),
        rng=np.random.default_rng(0),
    )
    assert result.best.name == "sphere" and result.decision == UNDECIDED
    assert result.fit_chance < recognition.FIT_CHANCE
    assert result.best.n_wrong == 6
    assert result.best.wrong_chance == pytest.approx(binom.sf(5, 41, OUTLIER_FRACTION))
    assert unexplained(result).startswith("6 of 41 points lie farther from the sphere")
    assert "more than one object" in unexplained(result)


def _sphere_patch(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """12 points with noise on a 3 cm patch of a 50 cm sphere around its top (0, 0, 0.6)."""
    radius, n = 0.5, 12
    polar = np.arccos(1 - rng.uniform(0, 1, n) * (1 - math.cos(0.03 / radius)))
    azimuth = rng.uniform(0, 2 * math.pi, n)
    unit = np.stack(
        [np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)], axis=1
    )
    points = np.array([0.0, 0.0, -radius + 0.6]) + radius * unit
    points += rng.normal(0.0, NOISE, points.shape)
    return points, np.tile(np.eye(3) * NOISE**2, (n, 1, 1))


def test_a_few_points_on_a_patch_of_a_large_sphere_abstain_between_plane_and_sphere() -> None:
    # a 3 cm patch of a 50 cm sphere bulges a / 2R = 0.9 mm at its centre, as much as the noise
    points, covariances = _sphere_patch(np.random.default_rng(11))
    result = recognise(points, covariances, rng=np.random.default_rng(0))
    assert result.decision == UNDECIDED
    assert set(result.candidates) == {"plane", "sphere"}
    assert result.delta_score < result.threshold


def test_links_that_swept_past_a_patch_rule_out_the_plane_through_it() -> None:
    # The points alone leave a plane and a sphere undecided. Four links swept past the patch's
    # edges untouched, 6 cm from its top and 2.5 mm below its tangent plane, where the sphere
    # has curved away by 3.6 mm: they cut the plane.
    points, covariances = _sphere_patch(np.random.default_rng(11))
    along = np.linspace(-0.04, 0.04, 81)
    sweeps = []
    for angle in (0.0, 0.5 * math.pi, math.pi, 1.5 * math.pi):
        out = np.array([math.cos(angle), math.sin(angle), 0.0])
        side = np.array([-math.sin(angle), math.cos(angle), 0.0])
        sweeps.append(0.06 * out + along[:, None] * side + [0.0, 0.0, 0.6 - 0.0025])
    samples = np.vstack(sweeps)
    space = FreeSpace(samples, np.full(len(samples), 0.0005), np.repeat(range(4), 81), 4, 0.0005)
    up = np.array([0.0, 0.0, 1.0])  # the antenna is above the patch
    alone = recognise(points, covariances, outward=up, rng=np.random.default_rng(0))
    assert alone.undecided and set(alone.candidates) == {"plane", "sphere"}
    result = recognise(points, covariances, outward=up, rng=np.random.default_rng(0), swept=[space])
    fits = {f.name: f for f in result.fits}
    # the plane gives way between the points and the links, and pays for both
    assert fits["plane"].swept_chi2 > result.threshold
    assert fits["sphere"].swept_chi2 < 1.0
    assert fits["sphere"].score < fits["plane"].score - result.threshold


def test_a_users_box_mesh_is_named_where_the_box_class_leaves_a_height_untouched() -> None:
    # A box touched on five faces, its top never (a bench's object seen from the side and
    # above its base): the box class fits it with its height a lower bound, and the user's mesh
    # of that box, one of the boxes that bound allows, fits it as well. The two are one answer:
    # the mesh is named, the box class counting with it, where they had abstained between them
    extents = np.array([0.06, 0.1, 0.16])
    points = box_but_its_top(extents, 8, seed=3)
    covariances = np.tile(np.eye(3) * NOISE**2, (40, 1, 1))
    block = trimesh.creation.box(extents=extents)
    result = recognise(points, covariances, meshes={"block": block}, rng=np.random.default_rng(0))
    fits = {f.name: f for f in result.fits}
    assert "extent_z" in fits["box"].size_at_least  # the top: a lower bound
    assert result.decision == "mesh:block", (result.decision, result.candidates)
    assert "box" in result.same_shape and result.confidence > 0.95


def test_a_user_mesh_is_registered_at_its_pose() -> None:
    rng = np.random.default_rng(5)
    mesh = trimesh.creation.box(extents=(0.05, 0.08, 0.12))
    mesh = trimesh.util.concatenate(
        [mesh, trimesh.creation.cylinder(radius=0.01, height=0.1).apply_translation([0, 0, 0.1])]
    )
    pose = _pose(rng)
    placed = mesh.copy()
    placed.apply_transform(pose)
    points, covariances = _sample(placed, 40, rng)
    fit = fit_mesh("tool", mesh, points, covariances, rng=np.random.default_rng(1))
    assert fit.name == "mesh:tool"
    assert fit.rms < 2 * NOISE
    # the placed mesh lies on the true one (up to the shape's own symmetry, a half turn about
    # its axis): each of its vertices within a few noise sigmas of the true surface
    assert fit.mesh is not None
    _, distance, _ = trimesh.proximity.closest_point(placed, fit.mesh.vertices)
    assert distance.max() < 0.005


def test_a_user_mesh_is_registered_as_close_to_the_points_as_its_true_pose() -> None:
    # A box's own mesh and 12 points of it at 20 poses: the registration ends in the true pose's
    # basin (the points' RMS distance no larger than at the true pose), which few of its starts
    # reach, on most of them (14 of 20 when written; 10 when each start stopped within an
    # iteration or two)
    ended = 0
    for seed in range(20):
        rng = np.random.default_rng(seed)
        mesh = trimesh.creation.box(extents=(0.06, 0.1, 0.16))
        placed = mesh.copy()
        placed.apply_transform(_pose(rng))
        points, covariances = _sample(placed, 12, rng)
        _, at_truth, _ = trimesh.proximity.closest_point(placed, points)
        fit = fit_mesh("mybox", mesh, points, covariances, rng=np.random.default_rng(0))
        ended += fit.rms <= math.sqrt(np.mean(at_truth**2))
    assert ended >= 13


def test_points_along_one_outline_of_a_torus_name_no_class_confidently() -> None:
    # contacts along the outer equator of a torus (axis Z), the half facing the base: its
    # outline seen along the axis, a band that a cylinder of radius R + r fits about as well;
    # a score that charges the torus's free axis and ring as if the points fixed them names
    # the cylinder
    rng = np.random.default_rng(2)
    major, minor, n = 0.05, 0.02, 24
    azimuth = rng.uniform(math.pi / 2, 3 * math.pi / 2, n)
    elevation = rng.uniform(-0.15, 0.15, n)  # a band of the tube around the equator
    rho = major + minor * np.cos(elevation)
    points = np.stack(
        [rho * np.cos(azimuth), rho * np.sin(azimuth), minor * np.sin(elevation)], axis=1
    )
    points += np.array([0.5, 0.0, 0.0]) + rng.normal(0.0, NOISE, points.shape)
    covariances = np.tile(np.eye(3) * NOISE**2, (n, 1, 1))
    result = recognise(points, covariances, outward=[-1.0, 0.0, 0.0], rng=np.random.default_rng(0))
    assert result.decision == UNDECIDED, (result.decision, result.candidates)
    # below the weight a decision needs, 1 / (1 + exp(-ABSTAIN_DELTA / 2))
    assert result.confidence < 1.0 / (1.0 + math.exp(-result.threshold / 2))


def test_a_capsule_shrunk_to_a_sphere_is_the_same_shape() -> None:
    rng = np.random.default_rng(4)
    mesh = trimesh.creation.icosphere(subdivisions=3, radius=0.04)
    mesh.apply_translation([0.5, 0.1, 0.0])
    points, covariances = _sample(mesh, 30, rng)
    sphere = fit_primitive("sphere", points, covariances)
    cylinder = fit_primitive("cylinder", points, covariances)
    # a sphere against itself: nothing apart; against a cylinder: the cylinder's rims stand
    # out of the ball by about r (sqrt(2) - 1) for a cylinder as high as wide
    assert shape_gap(sphere, sphere) < 1e-3
    assert shape_gap(sphere, cylinder) > 5e-3


def test_a_capsule_shrunk_onto_a_ball_is_not_its_runner_up() -> None:
    # the capsule's segment shrinks to a few mm on a ball's points (3.5 mm here) and trails
    # the sphere by its extra parameters' penalty (3 ln 30 = 10.2 less the 5.7 it gains in
    # chi^2): under a threshold of 20 (or 6) it would make the decision abstain between two
    # names of one ball. Its fit lies 1.0 mm from the sphere's, beside the points' 0.94 mm
    # scatter, and narrows that scatter no more than three parameters narrow noise: it is
    # the ball under a richer name, and the decision is the sphere against the next shape,
    # with the capsule's weight
    rng = np.random.default_rng(4)
    mesh = trimesh.creation.icosphere(subdivisions=3, radius=0.04)
    mesh.apply_translation([0.5, 0.1, 0.0])
    points, covariances = _sample(mesh, 30, rng)
    result = recognise(points, covariances, rng=np.random.default_rng(0), threshold=20.0)
    fits = {f.name: f for f in result.fits}
    assert fits["capsule"].score - fits["sphere"].score < 20.0
    assert fits["capsule"].sizes["length"] < 0.005
    assert result.decision == "sphere"
    assert "capsule" not in result.candidates
    assert result.same_shape == ("capsule",)
    # the score gap is to the next shape, which the report names
    assert result.runner_up == result.candidates[1] != "capsule"
    assert result.delta_score > 20.0
    assert result.confidence >= result.confidence_floor


def test_a_capsule_under_wide_covariances_is_not_merged_into_a_ball() -> None:
    # a capsule of 3 cm radius and a 10 mm segment, 30 points of 1 mm noise whose covariances
    # say 4 mm: the likelihood gains less than 6 from its segment (the covariances are four
    # times the errors), and its fit lies within 3 of their sigma of the sphere's; but the
    # points scatter about the sphere twice as widely as about the capsule (1.8 to 2.0 mm
    # against 0.8 to 0.9), far more than three parameters narrow noise (the F test): the
    # capsule is not the ball under another name, and the sphere is not named
    mesh = trimesh.creation.capsule(height=0.010, radius=0.03, count=[32, 32])
    mesh.apply_translation([0.5, 0.1, 0.0])
    for seed in range(3):
        points, _ = trimesh.sample.sample_surface(mesh, 30, seed=seed)
        points = points + np.random.default_rng(seed).normal(0.0, NOISE, points.shape)
        covariances = np.tile(np.eye(3) * (4 * NOISE) ** 2, (30, 1, 1))
        result = recognise(
            points,
            covariances,
            classes=["sphere", "capsule", "cylinder", "plane"],
            rng=np.random.default_rng(0),
        )
        assert "capsule" not in result.same_shape
        assert result.decision != "sphere", (result.decision, result.confidence)


def test_a_capsule_the_points_favour_is_not_a_name_of_the_ball() -> None:
    # a capsule of 3 cm radius and a 3 mm segment: its fit is within a millimetre of the
    # sphere's, about the noise, but its chi^2 is 7 better than the sphere's, which the
    # penalty of its three extra parameters (10.2) outweighs: the points tell the two apart
    # without deciding, and the decision abstains between them
    mesh = trimesh.creation.capsule(height=0.003, radius=0.03, count=[32, 32])
    mesh.apply_translation([0.5, 0.1, 0.0])
    points, _ = trimesh.sample.sample_surface(mesh, 30, seed=2)
    points = points + np.random.default_rng(2).normal(0.0, NOISE, points.shape)
    covariances = np.tile(np.eye(3) * NOISE**2, (30, 1, 1))
    result = recognise(
        points,
        covariances,
        classes=["sphere", "capsule", "cylinder", "plane"],
        rng=np.random.default_rng(0),
    )
    fits = {f.name: f for f in result.fits}
    assert fits["sphere"].chi2 - fits["capsule"].chi2 > result.threshold
    assert shape_gap(fits["sphere"], fits["capsule"]) < 3 * NOISE
    assert result.decision == UNDECIDED
    assert set(result.candidates) == {"sphere", "capsule"}
    assert result.same_shape == ()


def test_fits_apart_by_more_than_the_points_scatter_are_not_one_shape() -> None:
    # points on a 2.4 cm thick, 5 cm long cylinder with 1 mm of noise and covariances that say
    # 4 mm (as the explorations' do along the normal): a capsule's and a box's fits lie about
    # 3 mm from the cylinder's, within 3 of the covariances' sigma but three times the points'
    # scatter about the cylinder (0.7 mm RMS): other shapes, which a contact there would tell
    # apart. The decision abstains between the cylinder and another class: the capsule, or
    # the torus (which one it names as the rival has differed between installations of the
    # numerical libraries)
    rng = np.random.default_rng(0)
    mesh = trimesh.creation.cylinder(radius=0.012, height=0.05, sections=128)
    mesh.apply_translation([0.5, 0.1, 0.0])
    points, _ = trimesh.sample.sample_surface(mesh, 30, seed=0)
    points = points + rng.normal(0.0, NOISE, points.shape)
    covariances = np.tile(np.eye(3) * (4 * NOISE) ** 2, (30, 1, 1))
    result = recognise(points, covariances, rng=np.random.default_rng(0))
    fits = {f.name: f for f in result.fits}
    assert result.best.name == "cylinder"
    for other in ("capsule", "box"):
        assert result.best.rms < shape_gap(result.best, fits[other]) < 3 * 4 * NOISE
    assert result.same_shape == ()
    assert result.decision == UNDECIDED
    assert result.candidates[0] == "cylinder" and result.candidates[1] in ("capsule", "torus")


def test_a_line_cutting_into_a_sphere_costs_its_depth() -> None:
    # a line through a point of a sphere at an angle beta into it reaches R (1 - cos beta)
    # deep at s = R sin beta along it (|p + s t - c| is least there); with beta chosen so that
    # this is one of the sampled stretches (R sin beta = LINE_STRETCH / 2) the residual is that
    # depth over the spread there; a tangent line costs nothing
    radius, sigma, std = 0.05, 0.002, 0.02
    beta = math.asin(0.5 * LINE_STRETCH / radius)
    centre = np.array([0.6, 0.0, 0.0])
    point = centre + radius * np.array([-1.0, 0.0, 0.0])
    cutting = np.array([math.sin(beta), math.cos(beta), 0.0])
    tangent = np.array([0.0, 1.0, 0.0])
    lines = LinkLines(np.array([cutting, tangent]), [std, std], [0.6, 0.6], [0.3, 0.3])

    def distance(q: np.ndarray) -> np.ndarray:
        return np.linalg.norm(q - centre, axis=1) - radius

    got = lines.residuals(distance, np.array([point, point]), np.array([sigma, sigma]))
    depth = radius * (1 - math.cos(beta))
    spread = math.hypot(sigma, 0.5 * LINE_STRETCH * std)
    assert got[0] == pytest.approx(-depth / spread, rel=1e-9)
    assert got[1] == 0.0


def _first_touch(
    mesh: trimesh.Trimesh, pivot: np.ndarray, ahead: np.ndarray, across: np.ndarray
) -> tuple[np.ndarray, np.ndarray] | None:
    """Where a ray from ``pivot`` turning from ahead - across towards ``ahead`` (unit vectors)
    first meets ``mesh`` (bisection on trimesh's ray test, to 1e-12 rad), and its direction."""

    def ray(angle: float) -> np.ndarray:
        d = math.cos(angle) * ahead - math.sin(angle) * across
        return np.asarray(d / np.linalg.norm(d))

    def hits(angle: float) -> bool:
        return bool(mesh.ray.intersects_any([pivot], [ray(angle)])[0])

    low, high = 0.5, 0.0
    if hits(low) or not hits(high):
        return None
    for _ in range(40):
        middle = 0.5 * (low + high)
        low, high = (middle, high) if not hits(middle) else (low, middle)
    location, _, _ = mesh.ray.intersects_location([pivot], [ray(high)])
    return location[np.argmin(np.linalg.norm(location - pivot, axis=1))], ray(high)


def _first_touches(
    mesh: trimesh.Trimesh, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """First touches of lines swept about three pivots around ``mesh`` (trimesh's rays,
    independent of the scene module) and the lines' directions: each pivot 0.5 m from the
    mesh's centre, sweeping both ways in four planes through it turned at random about the
    line of sight."""
    centre = mesh.bounding_box.centroid
    points, tangents = [], []
    for heading in (0.0, 2.1, 4.2):
        pivot = centre + 0.5 * np.array([-math.cos(heading), -math.sin(heading), 0.0])
        ahead = (centre - pivot) / 0.5
        side = np.cross([0.0, 0.0, 1.0], ahead)
        for tilt in rng.uniform(-0.6, 0.6, 4):
            across = math.cos(tilt) * side + math.sin(tilt) * np.array([0.0, 0.0, 1.0])
            for sense in (1.0, -1.0):
                touch = _first_touch(mesh, pivot, ahead, sense * across)
                if touch is not None:
                    points.append(touch[0])
                    tangents.append(touch[1])
    return np.array(points), np.array(tangents)


def _swept_touches(
    mesh: trimesh.Trimesh, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, LinkLines]:
    """The posed ``mesh`` moved to 0.6 m ahead, its first touches by swept lines
    (:func:`_first_touches`, at least 20) with 1 mm noise, their covariances and their lines
    (tangent within 0.01 rad, 0.4 m of link behind each touch, 0.3 m beyond)."""
    mesh.apply_translation([0.6, 0.0, 0.0] - mesh.bounding_box.centroid)
    points, tangents = _first_touches(mesh, rng)
    n = len(points)
    assert n >= 20
    points = points + rng.normal(0.0, NOISE, points.shape)
    covariances = np.tile(np.eye(3) * NOISE**2, (n, 1, 1))
    lines = LinkLines(tangents, np.full(n, 0.01), np.full(n, 0.4), np.full(n, 0.3))
    return points, covariances, lines


def test_a_user_mesh_on_few_points_is_registered_where_the_links_that_touched_it_allow() -> None:
    # Ten touches of a box, their links' lines, and the box's own mesh, at ten poses: several
    # poses put the mesh's faces on ten points, and the one that fits them best by a hair can
    # have links passing through the box (line chi^2 in the thousands); the pose kept is one
    # the lines allow on most (8 of 10 when written; 4 when the points alone chose)
    allowed = 0
    for seed in range(10):
        rng = np.random.default_rng(seed)
        own = SHAPES["box"][0]()
        mesh = own.copy()
        mesh.apply_transform(_pose(rng))
        points, covariances, lines = _swept_touches(mesh, rng)
        few = rng.choice(len(points), 10, replace=False)
        touched = LinkLines(
            lines.tangents[few], lines.std[few], lines.behind[few], lines.beyond[few]
        )
        fit = fit_mesh(
            "own", own, points[few], covariances[few], rng=np.random.default_rng(0), lines=touched
        )
        # the true pose's lines: each one-sided residual about a sigma at most, half of them 0
        allowed += fit.line_chi2 < 10 and fit.rms < 2 * NOISE
    assert allowed >= 7


@pytest.mark.parametrize("name", ["box", "cylinder"])
def test_the_lines_that_touched_tell_a_box_from_a_cylinder(name: str) -> None:
    # a line swept towards a box first meets it on an edge, and a cylinder fits points on a
    # box's edges nearly as well as the box: the lines tell them apart, as a cylinder through
    # those points is not tangent to the lines that touched them; on a cylinder, the lines
    # cost the cylinder nothing. These 24 points on one side of the cylinder are fitted as
    # well by a torus whose tube is the cylinder (major radius about 19 cm, chi^2 15.7 against
    # 20.9, the lines costing neither): the decision may abstain between the two, never name
    # the box
    rng = np.random.default_rng(3)
    mesh = SHAPES[name][0]()
    mesh.apply_transform(_pose(rng))
    points, covariances, lines = _swept_touches(mesh, rng)
    n = len(points)
    result = recognise(points, covariances, rng=np.random.default_rng(0), lines=lines)
    allowed = (name,) if name == "box" else (name, UNDECIDED)
    assert result.decision in allowed, (result.decision, result.candidates)
    assert name in result.candidates, result.candidates
    fits = {f.name: f for f in result.fits}
    # the true shape: tangent within the noise, each one-sided residual at most about one
    # sigma, and zero whenever the noise moves the line outwards (half the time): chi^2 per
    # contact about a quarter, below half
    assert fits[name].line_chi2 < 0.5 * n
    other = "cylinder" if name == "box" else "box"
    assert fits[other].line_chi2 > fits[name].line_chi2 + result.threshold


def test_a_decision_needs_the_weight_the_threshold_stands_for() -> None:
    # points without noise in a band round a 5 cm ball's equator (|z| < 1.5 cm), and user
    # meshes of the ball and of the same ball dr larger with its poles cut flat at |z| = 3.5 cm
    # (fine enough that their facets stand at most 8 um inside the sphere): another shape,
    # 1.5 cm off the ball at its poles, that the band's points lie about dr inside, chi^2 =
    # n (dr / NOISE)^2 = 7.5 less the facets' share, past the gap of 6. One such runner-up
    # leaves the best about e^3.5 / (1 + e^3.5) = 0.97 and a decision; four take about
    # 4 / (e^3.5 + 4) = 11 % between them, and the decision abstains
    n = 300
    points = 0.05 * _lattice(n, band=0.3)
    covariances = np.tile(np.eye(3) * NOISE**2, (n, 1, 1))
    dr = NOISE * math.sqrt(7.5 / n)
    ball = trimesh.creation.icosphere(subdivisions=5, radius=0.05)
    flat = trimesh.creation.icosphere(subdivisions=5, radius=0.05 + dr)
    vertices = flat.vertices.copy()
    vertices[:, 2] = np.clip(vertices[:, 2], -0.035, 0.035)
    flat.vertices = vertices
    one = recognise(points, covariances, classes=[], meshes={"ball": ball, "flat": flat})
    four = recognise(
        points,
        covariances,
        classes=[],
        meshes={"ball": ball} | {f"flat{i}": flat for i in range(4)},
    )
    floor = 1.0 / (1.0 + math.exp(-one.threshold / 2))
    assert one.confidence_floor == pytest.approx(floor)
    assert one.threshold < one.delta_score < 7.5
    assert four.threshold < four.delta_score < 7.5
    assert one.decision == "mesh:ball" and one.confidence >= floor
    # abstaining for the weight alone: past the gap, no rival
    assert four.rival is None
    assert four.decision == UNDECIDED and four.confidence < floor


def test_points_on_one_side_of_a_torus_name_the_torus_at_its_size() -> None:
    # 60 points on the side of a torus (major radius 54.0 mm, minor 36.6 mm) facing the base,
    # each drawn from the covariance of a fast estimate pushed to 5 % (standard deviations of 4
    # to 6 mm): eval_recognition's scene 4 (seed 0, 60 contacts), kept as data. From the
    # principal axes and the algebraic sphere alone the torus's fit stops far from its best
    # (chi^2 about 200 against 34), a flat cone then fits best and a box nearly as well; from
    # axes turned and sizes scaled it reaches it, and no other class comes within the
    # threshold, whichever generator draws the box's random starts
    table = np.loadtxt(
        Path(__file__).parent / "data" / "torus_side_60_points.csv", delimiter=",", skiprows=1
    )
    points, covariances = table[:, :3], table[:, 3:].reshape(-1, 3, 3)
    for seed in range(2):
        result = recognise(
            points, covariances, outward=-points.mean(axis=0), rng=np.random.default_rng(seed)
        )
        assert result.decision == "torus", (result.decision, result.confidence)
        sizes = result.best.sizes
        # the benchmark's 5 % (2.7 and 1.8 mm; the fit's deviations are 1.0 and 1.9 mm, and it
        # is off by 1.3 and 0.2 mm)
        assert sizes["major_radius"] == pytest.approx(0.0540, rel=SIZE_TOLERANCE)
        assert sizes["minor_radius"] == pytest.approx(0.0366, rel=SIZE_TOLERANCE)


@pytest.mark.parametrize("seed", range(12))
def test_a_squat_cylinder_seen_from_one_side_is_fitted_about_its_own_axis(seed: int) -> None:
    # A cylinder as tall as it is wide (radius 3 cm, height 6 cm) at a random orientation, 40
    # points of 1 mm on the half facing the base: the points' principal axes do not tell its
    # axis from a diameter, and a fit from them alone can stop with its axis across the true
    # one (seed 4: 86 degrees off, chi^2 215 against 30). The fit's axis is within 5 degrees
    # of the true one (about six of its deviations, 0.6 to 1 degree each way; the failure
    # this catches is tens of degrees), its radius within the benchmark's 5 %
    rng = np.random.default_rng(seed)
    mesh = trimesh.creation.cylinder(radius=0.03, height=0.06, sections=64)
    rotation = Rotation.random(random_state=seed).as_matrix()
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rotation, [0.5, 0.1, 0.05]
    mesh.apply_transform(pose)
    exact, faces = trimesh.sample.sample_surface(mesh, 4000, seed=seed)
    facing = np.einsum("ij,ij->i", mesh.face_normals[faces], -exact) > 0
    exact = exact[facing][:40]
    points = exact + rng.normal(0.0, NOISE, exact.shape)
    covariances = np.tile(np.eye(3) * NOISE**2, (len(points), 1, 1))
    fit = fit_primitive("cylinder", points, covariances, outward=-points.mean(axis=0))
    axis = Rotation.from_rotvec(fit.vector[3:6]).as_matrix()[:, 2]
    assert math.degrees(math.acos(min(1.0, abs(float(axis @ rotation[:, 2]))))) < 5.0
    assert fit.sizes["radius"] == pytest.approx(0.03, rel=SIZE_TOLERANCE)


def test_a_squat_cylinder_is_fitted_along_its_own_axis_whichever_copy_of_its_points() -> None:
    # A cylinder about as wide as it is tall (16.3 mm radius, 37.1 mm high) touched by swept
    # lines: a fit from the points' principal axes alone can stop with its axis across the
    # shape's (radius 19 mm, height 31 mm, chi^2 about 94 against 38), and which minimum it
    # finds turns on a nanometre (two of these six copies). With the fits also started along
    # the icosahedron's axes each copy of the points, moved by about a nanometre, gives the
    # same fit: the shape's own sizes within the benchmark's 5 %, chi^2 equal to within 0.5
    # (the fits stop at a relative tolerance of 1e-6; the copies' spread is about 0.01, the
    # wrong basin 54 above), the axis within 5 degrees
    rng = np.random.default_rng(3)
    radius, height = rng.uniform(0.015, 0.03), rng.uniform(0.03, 0.06)
    mesh = trimesh.creation.cylinder(radius=radius, height=height, sections=128)
    pose = _pose(rng)
    mesh.apply_transform(pose)
    points, covariances, lines = _swept_touches(mesh, rng)
    fits = []
    for copy in range(6):
        moved = points + np.random.default_rng(copy).normal(0.0, 1e-9, points.shape)
        result = recognise(
            moved, covariances, classes=["cylinder"], rng=np.random.default_rng(0), lines=lines
        )
        fits.append(result.fits[0])
    chi2 = [f.chi2 for f in fits]
    assert max(chi2) - min(chi2) < 0.5, chi2
    for f in fits:
        assert f.sizes["radius"] == pytest.approx(radius, rel=SIZE_TOLERANCE)
        assert f.sizes["height"] == pytest.approx(height, rel=SIZE_TOLERANCE)
        axis = Rotation.from_rotvec(f.vector[3:6]).as_matrix()[:, 2]
        assert abs(axis @ pose[:3, 2]) > math.cos(math.radians(5.0))


def test_a_sphere_radius_standard_deviation_is_the_noise_over_root_n() -> None:
    # Points spread evenly over a whole sphere with isotropic noise sigma: the normals average
    # out, the centre and the radius decouple, and least squares gives var(r) = sigma^2 / n
    # (the mean of n independent radial residuals); 200 points on a Fibonacci lattice
    n, radius = 200, 0.06
    rng = np.random.default_rng(5)
    points = np.array([0.4, 0.1, -0.05]) + radius * _lattice(n) + rng.normal(0.0, NOISE, (n, 3))
    fit = fit_primitive("sphere", points, np.tile(np.eye(3) * NOISE**2, (n, 1, 1)))
    # the lattice's normals sum to zero within a few per cent of n, and the normalised
    # residuals of points off the surface by 1 mm change the normals by 1 / 60: 5 %
    assert fit.size_std["radius"] == pytest.approx(NOISE / math.sqrt(n), rel=0.05)


@pytest.mark.parametrize("name", ["cylinder", "box"])
def test_reported_size_deviations_match_the_spread_of_repeated_fits(name: str) -> None:
    # An independent check of the propagation: the same shape sampled afresh 30 times, each
    # fitted; the fitted sizes' sample standard deviation against the mean reported one. With
    # 30 repeats a sample standard deviation is within 1.96 / sqrt(2 x 29) = 26 % of the true
    # one 95 % of the time, and the reported one (a linearisation) is itself a few per cent off
    mesh = SHAPES[name][0]()
    rng = np.random.default_rng(21)
    fitted, reported = [], []
    n = 100  # with 60 points an end of the cylinder went untouched in one draw of 30
    for _ in range(30):
        points, covariances = _sample(mesh, n, rng)
        fit = fit_primitive(name, points, covariances, rng=np.random.default_rng(0))
        order = np.argsort(list(fit.sizes.values())) if name == "box" else slice(None)
        fitted.append(np.array(list(fit.sizes.values()))[order])
        reported.append(np.array(list(fit.size_std.values()))[order])
    assert np.all(np.isfinite(reported)), reported  # every face or end touched
    ratio = np.mean(reported, axis=0) / np.std(fitted, axis=0, ddof=1)
    assert np.all((ratio > 0.7) & (ratio < 1.35)), ratio


def test_a_box_touched_on_three_faces_gives_its_extents_as_lower_bounds() -> None:
    # One face per axis touched (as from one side at a corner): each extent could be anything
    # beyond the points, and the fit's extents, the smallest the points allow, are lower bounds
    extents = np.array([0.04, 0.06, 0.08])
    rng = np.random.default_rng(0)
    faces = []
    for axis in range(3):
        on_face = rng.uniform(-0.5, 0.5, (12, 3)) * extents
        on_face[:, axis] = 0.5 * extents[axis]
        faces.append(on_face)
    points = np.vstack(faces) + rng.normal(0.0, 0.5 * NOISE, (36, 3))
    covariances = np.tile(np.eye(3) * (0.5 * NOISE) ** 2, (36, 1, 1))
    fit = fit_primitive("box", points, covariances, outward=np.ones(3) / math.sqrt(3.0))
    assert fit.rms < NOISE
    assert all(math.isinf(v) for v in fit.size_std.values()), fit.size_std
    assert fit.sizes_text().count("at least") == 3
    assert all(v is None for v in fit.to_dict()["size_std"].values())
    # the bounds lie below the truth (the box's axes are its own: compare sorted)
    assert np.all(np.sort(list(fit.size_at_least.values())) < extents), fit.size_at_least
    # where the fitted box lies: held on the faces touched, anywhere beyond on the others
    touched = np.vstack([0.5 * np.eye(3)[axis] * extents for axis in range(3)])
    untouched = -touched
    assert np.all(fit.distance_std(touched) < NOISE)
    assert np.all(np.isinf(fit.distance_std(untouched)))
    # the same box touched on all six faces: every extent measured, within 3 sigma
    faces = []
    for axis in range(3):
        for sense in (1.0, -1.0):
            on_face = rng.uniform(-0.5, 0.5, (8, 3)) * extents
            on_face[:, axis] = 0.5 * sense * extents[axis]
            faces.append(on_face)
    points = np.vstack(faces) + rng.normal(0.0, 0.5 * NOISE, (48, 3))
    covariances = np.tile(np.eye(3) * (0.5 * NOISE) ** 2, (48, 1, 1))
    fit = fit_primitive("box", points, covariances)
    got = np.array(list(fit.sizes.values()))
    std = np.array(list(fit.size_std.values()))
    order = np.argsort(got)
    assert np.all(np.abs(got[order] - extents) < 3 * std[order]), (got, std)
    assert "+-" in fit.sizes_text()


@pytest.mark.parametrize("name", ["box", "cylinder", "cone", "torus"])
def test_a_fit_reads_one_way_whatever_its_start(name: str) -> None:
    # The canonical form is the same shape (the same signed distance everywhere), with a
    # rotation vector of at most pi and a box's extents in increasing order
    shape = PRIMITIVES[name]
    rng = np.random.default_rng(7)
    x = np.concatenate([[0.5, 0.1, -0.1], [2.0, -2.5, 1.5], rng.uniform(0.02, 0.08, 3)])
    x = x[: len(shape.parameter_names)]
    probes = x[:3] + rng.normal(0.0, 0.1, (500, 3))
    canonical = shape.canonical(x)
    assert np.allclose(shape.signed_distance(canonical, probes), shape.signed_distance(x, probes))
    assert np.linalg.norm(canonical[3:6]) <= math.pi + 1e-12
    if name == "box":
        assert list(canonical[6:9]) == sorted(x[6:9])
    # and a fit reports it so: the box touched on all sides, its extents smallest first
    mesh, rng = _placed(name)
    points, covariances = _sample(mesh, 60, rng)
    fit = fit_primitive(name, points, covariances, rng=np.random.default_rng(0))
    assert np.linalg.norm(fit.vector[3:6]) <= math.pi + 1e-12
    if name == "box":
        assert list(fit.sizes.values()) == sorted(fit.sizes.values())


def _cylinder_points(
    keep: Callable[[np.ndarray], np.ndarray], n: int, rng: np.random.Generator, noise: float = NOISE
) -> tuple[np.ndarray, np.ndarray]:
    """``n`` noisy points of SHAPES' cylinder (radius 4 cm, height 15 cm, axis on Z) where
    ``keep`` (a function of the exact points) is true."""
    mesh = SHAPES["cylinder"][0]()
    exact, _ = trimesh.sample.sample_surface(mesh, 200 * n, seed=int(rng.integers(2**31)))
    exact = exact[keep(exact)][:n]
    return exact + rng.normal(0.0, noise, exact.shape), np.tile(np.eye(3) * noise**2, (n, 1, 1))


def test_what_the_points_do_not_show_has_no_deviation() -> None:
    rng = np.random.default_rng(4)
    # one cap untouched: the height could be anything beyond the points, a lower bound below
    # the true 15 cm; the radius is measured
    points, covariances = _cylinder_points(lambda q: q[:, 2] > -0.074, 60, rng)
    fit = fit_primitive("cylinder", points, covariances)
    assert math.isinf(fit.size_std["height"]) and fit.size_at_least["height"] < 0.15
    assert abs(fit.sizes["radius"] - 0.04) < 3 * fit.size_std["radius"]
    assert "height at least" in fit.sizes_text()
    # both caps and no side: the radius is not measured (not a bound: any radius above the
    # caps' points fits), the height is
    points, covariances = _cylinder_points(lambda q: np.abs(q[:, 2]) > 0.0749, 60, rng)
    fit = fit_primitive("cylinder", points, covariances)
    assert math.isinf(fit.size_std["radius"]) and "radius" not in fit.size_at_least
    assert "(not measured)" in fit.sizes_text()
    assert abs(fit.sizes["height"] - 0.15) < 3 * fit.size_std["height"]
    # a 0.15 rad cap of a 6 cm sphere: its radius is not measured
    unit = rng.normal(size=(400, 3))
    unit /= np.linalg.norm(unit, axis=1)[:, None]
    cap = 0.06 * unit[unit[:, 2] > math.cos(0.15)][:25]
    cap += rng.normal(0.0, NOISE, cap.shape)
    fit = fit_primitive("sphere", cap, np.tile(np.eye(3) * NOISE**2, (len(cap), 1, 1)))
    assert math.isinf(fit.size_std["radius"]) and not fit.size_at_least


def test_an_end_a_few_wide_points_touch_is_held_loosely_or_bounded_below() -> None:
    # The side at 0.3 mm, each cap touched by three points of 4 mm: the height is measured with
    # a deviation of the caps' order (4 mm / sqrt(3) each end; up to a few times that where
    # the caps' points lie near the rim, whose growth releases them), not the side's, or, where
    # they lie too near the rim to be told from the side's, a lower bound below the truth;
    # never the side's precision
    rng = np.random.default_rng(6)
    outcomes = []
    for _ in range(5):
        side, side_cov = _cylinder_points(lambda q: np.abs(q[:, 2]) < 0.07, 50, rng, 0.0003)
        top, top_cov = _cylinder_points(lambda q: q[:, 2] > 0.0749, 3, rng, 0.004)
        bottom, bottom_cov = _cylinder_points(lambda q: q[:, 2] < -0.0749, 3, rng, 0.004)
        fit = fit_primitive(
            "cylinder",
            np.vstack([side, top, bottom]),
            np.concatenate([side_cov, top_cov, bottom_cov]),
        )
        if "height" in fit.size_at_least:
            assert fit.size_at_least["height"] < 0.15
            outcomes.append("bound")
        else:
            assert 0.001 < fit.size_std["height"] < 0.025
            assert abs(fit.sizes["height"] - 0.15) < 3 * fit.size_std["height"]
            outcomes.append("measured")
    assert "measured" in outcomes, outcomes


def test_points_noisier_than_their_covariance_widen_the_deviations() -> None:
    # 2 mm of noise where the covariances say 1 mm: the overdispersion c (about 4) widens the
    # radius's deviation to the spread's, 2 mm / sqrt(n), as it widens the scores
    n = 200
    rng = np.random.default_rng(8)
    points = 0.06 * _lattice(n) + rng.normal(0.0, 2 * NOISE, (n, 3))
    result = recognise(
        points, np.tile(np.eye(3) * NOISE**2, (n, 1, 1)), classes=["sphere"], rng=rng
    )
    assert result.overdispersion == pytest.approx(4.0, rel=0.25)
    # c's own sampling error (about 10 % on 200 points) and the normals' spread (5 %)
    assert result.best.size_std["radius"] == pytest.approx(2 * NOISE / math.sqrt(n), rel=0.15)


@pytest.mark.parametrize(
    ("name", "keep", "bounded"),
    [
        # one end of the capsule untouched: its length is only a lower bound
        ("capsule", lambda q: q[:, 2] > -0.04, "length"),
        # the cone's base untouched: the slant goes on beyond the points, its height is only a
        # lower bound and its radius (which the extent prior does not hold) is not measured
        ("cone", lambda q: q[:, 2] > 0.02, "height"),
    ],
)
def test_an_untouched_end_of_a_capsule_or_a_cone_is_a_lower_bound(
    name: str, keep: Callable[[np.ndarray], np.ndarray], bounded: str
) -> None:
    mesh = SHAPES[name][0]()  # axis on Z, centred (the cone's base at z = 0)
    rng = np.random.default_rng(9)
    exact, _ = trimesh.sample.sample_surface(mesh, 20000, seed=3)
    exact = exact[keep(exact)][:60]
    points = exact + rng.normal(0.0, NOISE, exact.shape)
    fit = fit_primitive(name, points, np.tile(np.eye(3) * NOISE**2, (len(points), 1, 1)))
    assert set(fit.size_at_least) == {bounded}, fit.sizes_text()
    assert fit.size_at_least[bounded] < SHAPES[name][1][bounded]
    assert math.isinf(fit.size_std[bounded])


def test_a_cone_touched_below_its_apex_keeps_its_height_and_says_how_sure_its_surface_is() -> None:
    # Points on the lower 60 % of a cone and its base, drawn afresh 30 times and fitted: the
    # apex is where the slant meets the axis, so the fitted height is not pulled down to the
    # points' reach (the mean within three standard errors of the truth), and the fitted
    # surface's reported deviation, on the slant among the points and beyond them at 85 % of
    # the height, matches the spread of the 30 fits' distances there (a sample deviation of 30
    # is within 26 % of the true one 95 % of the time; the reported one is a linearisation)
    radius, height = 0.06, 0.14
    mesh = trimesh.creation.cone(radius=radius, height=height, sections=128)
    probes = np.array([[0.7 * radius, 0.0, 0.3 * height], [0.0, 0.15 * radius, 0.85 * height]])
    rng = np.random.default_rng(23)
    heights, distances, reported = [], [], []
    for _ in range(30):
        points, _ = trimesh.sample.sample_surface(mesh, 300, seed=int(rng.integers(2**31)))
        points = points[points[:, 2] < 0.6 * height][:100]
        points = points + rng.normal(0.0, NOISE, points.shape)
        covariances = np.tile(np.eye(3) * NOISE**2, (len(points), 1, 1))
        fit = fit_primitive("cone", points, covariances, rng=np.random.default_rng(0))
        heights.append(fit.sizes["height"])
        distances.append(PRIMITIVES["cone"].signed_distance(fit.vector, probes))
        reported.append(fit.distance_std(probes))
    standard_error = np.std(heights, ddof=1) / math.sqrt(len(heights))
    assert abs(np.mean(heights) - height) < 3.0 * standard_error, np.mean(heights)
    ratio = np.mean(reported, axis=0) / np.std(distances, axis=0, ddof=1)
    assert np.all((ratio > 0.7) & (ratio < 1.35)), ratio
    # beyond the points the surface is less sure than among them: the 30 fits' own spread is
    # about four times wider at 85 % of the height than on the slant among the points (0.78
    # against 0.18 mm), so twice is a margin the ratios above leave it
    assert np.mean(reported, axis=0)[1] > 2.0 * np.mean(reported, axis=0)[0]


def _edge_touched_box_fit(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A 6 x 10 x 16 cm box at a random pose touched by swept lines (:func:`_first_touches`),
    its points drawn from covariances of 3 mm along the link and 0.3 mm across, fitted with
    the lines: the errors of its sizes, smallest first, and their stated deviations (m)."""
    extents = np.array([0.06, 0.1, 0.16])
    mesh = trimesh.creation.box(extents=extents)
    mesh.apply_transform(_pose(rng))
    mesh.apply_translation([0.6, 0.0, 0.0] - mesh.bounding_box.centroid)
    points, tangents = _first_touches(mesh, rng)
    n = len(points)
    along, across = 0.003, 0.0003  # the estimates' deviations along and across the link (m)
    covariances = np.array(
        [along**2 * np.outer(t, t) + across**2 * (np.eye(3) - np.outer(t, t)) for t in tangents]
    )
    points = points + np.array([rng.multivariate_normal(np.zeros(3), c) for c in covariances])
    lines = LinkLines(tangents, np.full(n, 0.001), np.full(n, 0.4), np.full(n, 0.3))
    fit = fit_primitive("box", points, covariances, rng=np.random.default_rng(0), lines=lines)
    names = sorted(fit.sizes, key=lambda k: fit.sizes[k])
    error = np.array([fit.sizes[k] for k in names]) - extents
    return error, np.array([fit.size_std[k] for k in names])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_box_touched_on_its_edges_is_not_grown_by_errors_along_the_link(seed: int) -> None:
    # the lines' first touches of a box are on its edges, and an error along the link moves a
    # point off the box whichever way it goes: the Euclidean distance reads every such point
    # outside and a box fitted by it grows by a good part of the errors (by 1.1 to 1.3 mm on
    # average over the three extents here); at each contact's nearest point along its line the
    # box stays where the edges are
    error, std = _edge_touched_box_fit(np.random.default_rng(10 + seed))
    # the sizes the fit measures (a finite deviation; an extent no touch bounds is held by the
    # extent prior alone) each within 1.5 mm, half the points' deviation along the link, and
    # their mean, which an outward growth moves one way, within 0.6 mm (half the Euclidean
    # fit's growth)
    measured = np.isfinite(std)
    assert measured.sum() >= 2, std
    assert np.all(np.abs(error[measured]) < 1.5e-3), (error, std)
    assert abs(float(np.mean(error[measured]))) < 6e-4, (error, std)


def test_a_box_touched_on_its_edges_states_deviations_its_errors_keep_to() -> None:
    # each contact's residuals (its distance, its place along its line, the line's cut) are
    # measured in the deviations its covariance gives them, and a fit's size deviations come
    # from their slopes: with errors drawn from the covariances, the sizes' errors over their
    # stated deviations have an RMS of 1 (within about 0.2 for some 12 sizes). Dividing the
    # cut by the deviation along one face's normal, a place that moves in the samples' steps,
    # and the edge placed where the secants' mirror image meets, gave an RMS of 2.5
    ratios = []
    for seed in range(4):
        error, std = _edge_touched_box_fit(np.random.default_rng(40 + seed))
        ratios.extend(error[np.isfinite(std)] / std[np.isfinite(std)])
    assert len(ratios) >= 8, ratios
    rms = float(np.sqrt(np.mean(np.square(ratios))))
    assert 0.5 < rms < 1.8, ratios


@pytest.mark.parametrize("name", list(PRIMITIVES))
def test_a_batch_of_shapes_gives_each_shapes_own_distances(name: str) -> None:
    # the batch form (a Jacobian's columns in one call) is the one-vector form, vector by
    # vector, to the last bit: the fits' steps must not depend on which form evaluated them
    rng = np.random.default_rng(3)
    shape = PRIMITIVES[name]
    vectors = rng.normal(0.0, 0.3, (4, len(shape.parameter_names)))
    sizes = len(shape.size_names)
    vectors[:, len(vectors[0]) - sizes :] = rng.uniform(0.02, 0.2, (4, sizes))
    probes = rng.normal(0.0, 0.2, (4, 50, 3))
    batch = shape.signed_distance(vectors, probes)
    one_by_one = [shape.signed_distance(v, q) for v, q in zip(vectors, probes, strict=True)]
    assert batch.shape == (4, 50)
    assert np.array_equal(batch, np.stack(one_by_one))
    with pytest.raises(ValueError, match="4 parameter vectors"):
        shape.signed_distance(vectors, probes[0])


def test_a_fit_is_the_same_whether_its_jacobians_are_batched_or_not(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # each Jacobian's columns are evaluated in one batch (least_squares' workers): evaluated one
    # by one instead, every step, and so the fit and its covariance, are the same to the last
    # bit; with the links' lines (one tangent unknown), free space and touching links
    rng = np.random.default_rng(3)
    mesh = SHAPES["box"][0]()
    mesh.apply_transform(_pose(rng))
    mesh.apply_translation([0.6, 0.0, 0.0] - mesh.bounding_box.centroid)
    points, tangents = _first_touches(mesh, rng)
    n = len(points)
    points = points + rng.normal(0.0, NOISE, points.shape)
    tangents[0] = np.nan
    covariances = np.tile(np.eye(3) * NOISE**2, (n, 1, 1))
    lines = LinkLines(tangents, np.full(n, 0.01), np.full(n, 0.4), np.full(n, 0.3))
    samples, faces = trimesh.sample.sample_surface(mesh, 300, seed=1)
    outside = samples + 0.004 * mesh.face_normals[faces]
    swept = [
        FreeSpace(outside, np.full(300, 0.002), np.arange(300) % 6, 6, 0.001),
        Touches(outside[:60], np.full(60, 0.002), np.arange(60) % 3, 3, 0.001),
    ]

    def fitted() -> list[object]:
        fit = fit_primitive(
            "cylinder", points, covariances, lines=lines, swept=swept, rng=np.random.default_rng(0)
        )
        return [fit.vector, fit.covariance, fit.chi2, fit.line_chi2, fit.swept_chi2]

    batched = fitted()
    original = recognition.least_squares
    monkeypatch.setattr(
        recognition, "least_squares", lambda *a, workers=None, **k: original(*a, **k)
    )
    one_by_one = fitted()
    for got, expected in zip(batched, one_by_one, strict=True):
        assert np.array_equal(got, expected, equal_nan=True)


def test_sizes_are_known_when_twice_each_deviation_is_within_the_share() -> None:
    # a 40 mm height with a deviation of 0.9 mm: 2 sigma is 4.5 % of it, within 5 % but not 4 %;
    # a size only bounded from below (inf) or without a deviation is never known
    def fit(sizes: dict[str, float], std: dict[str, float]) -> ClassFit:
        return ClassFit("cylinder", {}, sizes, 0.0, 0.0, 0.0, 5, 20, size_std=std)

    measured = fit({"radius": 0.02, "height": 0.04}, {"radius": 0.0002, "height": 0.0009})
    assert measured.sizes_known(0.05)
    assert not measured.sizes_known(0.04)
    bounded = fit({"radius": 0.02, "height": 0.04}, {"radius": 0.0002, "height": math.inf})
    assert not bounded.sizes_known(0.5)
    assert not fit({"radius": 0.02}, {}).sizes_known(0.5)
    plane = ClassFit("plane", {}, {}, 0.0, 0.0, 0.0, 3, 20)
    assert plane.sizes_known(0.01)
    # a user mesh is registered at its own size: its extents have no deviations to know
    extents = {"extent_x": 0.1, "extent_y": 0.05, "extent_z": 0.02}
    assert ClassFit("mesh:block", {}, extents, 0.0, 0.0, 0.0, 6, 20).sizes_known(0.01)


def test_a_user_mesh_touched_on_its_side_slides_along_its_axis_to_where_the_lines_allow() -> None:
    # 19 touches of a 40 x 220 mm cylinder standing at (0.6, 0.05, 0), from an exploration of
    # the built-in cylinder scene kept as data, and the cylinder's own mesh (32 sections, as a
    # user's STL would come): the points hold its radius and axis but not where along the axis
    # it stands, and ICP left it 27 mm low, where the links' lines cross it (line chi^2 450).
    # Slid along the axis to where points and lines fit best, it stands within 3 mm of its
    # place (twice the points' median deviation, 1.5 mm; measured 0.8 mm), and the lines cross
    # it nowhere
    data = json.loads((Path(__file__).parent / "data" / "cylinder_side_touches.json").read_text())
    lines = LinkLines(np.array(data["tangents"]), data["std"], data["behind"], data["beyond"])
    mesh = trimesh.creation.cylinder(radius=0.04, height=0.22, sections=32)
    fit = fit_mesh(
        "bottle",
        mesh,
        np.array(data["points"]),
        np.array(data["covariances"]),
        rng=np.random.default_rng(0),
        lines=lines,
    )
    centre = np.array([fit.parameters[f"m{i}3"] for i in range(3)])
    np.testing.assert_allclose(centre, [0.6, 0.05, 0.0], atol=0.003)
    assert fit.line_chi2 < 1.0


def test_a_touch_placed_far_from_the_rest_is_counted_wrong_with_the_links_lines() -> None:
    # The swept touches of a box with their links' lines, one of them moved half a metre with
    # its line (its base pose written wrong): the box and its sizes are the other touches' own,
    # and that touch is the one its fit counts wrong (the fits from the others' starts, first
    # without it, had been dragged towards it along the lines: a capsule or torus abstained)
    mesh, rng = _placed("box")
    points, covariances, lines = _swept_touches(mesh, rng)
    n, k = len(points), 5
    points = np.vstack([points, points[k] + [0.0, 0.5, 0.0]])
    covariances = np.vstack([covariances, covariances[k : k + 1]])
    tangents = np.vstack([lines.tangents, lines.tangents[k]])
    lines = LinkLines(tangents, np.full(n + 1, 0.01), np.full(n + 1, 0.4), np.full(n + 1, 0.3))
    result = recognise(
        points,
        covariances,
        classes=["box", "capsule", "torus", "plane"],
        rng=np.random.default_rng(0),
        lines=lines,
    )
    assert result.decision == "box", (result.decision, result.candidates)
    assert result.best.wrong == (n,)
    assert _size_error("box", result.best.sizes) < SIZE_TOLERANCE, result.best.sizes


def test_a_link_swept_through_the_best_shape_names_no_class() -> None:
    # points all round a 5 cm ball (touched from several bases) fit the ball and leave no
    # shape that misses its middle; a link that swept untouched through that middle (as one
    # does through the gap between two balls whose points fit one capsule) runs 5 cm inside
    # it, far beyond its deviation: the ball is not the object's whole shape, or that sweep is
    # wrong, and no class is named
    rng = np.random.default_rng(5)
    directions = rng.normal(size=(24, 3))
    centre = np.array([0.6, 0.0, 0.0])
    points = centre + 0.05 * directions / np.linalg.norm(directions, axis=1)[:, None]
    points += rng.normal(0.0, NOISE, points.shape)
    covariances = np.tile(np.eye(3) * NOISE**2, (len(points), 1, 1))
    across = np.linspace(-0.1, 0.1, 41)
    line = centre + np.column_stack([np.zeros_like(across), across, np.zeros_like(across)])

    def swept(samples: np.ndarray) -> list[FreeSpace]:
        return [FreeSpace(samples, np.full(len(samples), 0.002), np.zeros(41, int), 1, 0.0005)]

    through = recognise(points, covariances, swept=swept(line))
    assert through.best.name == "sphere" and through.best.n_crossed == 1
    assert through.undecided
    assert "1 swept link contradicts the best-fitting sphere" in crossed(through)
    # the same link 8 cm behind the ball's centre, clear of it: the ball is named
    behind = recognise(points, covariances, swept=swept(line + np.array([0.08, 0.0, 0.0])))
    assert behind.decision == "sphere" and behind.best.n_crossed == 0
    assert crossed(behind) == ""


@pytest.mark.parametrize(
    "mesh",
    [
        # a hexagonal prism (circumradius 5 cm): its faces 3.3 mm inside its round hull
        trimesh.creation.cylinder(radius=0.05, height=0.12, sections=6),
        # a square pyramid: a cone of four sections
        trimesh.creation.cone(radius=0.07, height=0.12, sections=4),
    ],
    ids=["hexagonal prism", "square pyramid"],
)
def test_an_object_no_class_fits_within_the_points_deviations_is_not_named(
    mesh: trimesh.Trimesh,
) -> None:
    # 35 points with 1 mm of noise all round an object of no class: the nearest class (a
    # cylinder, a cone) misses its flat faces by millimetres, several deviations at each
    # point, which chance does not make (the chi^2 tail far below FIT_CHANCE): no class is
    # named, and the map's line says why; the classes' own points pass (the test above)
    rng = np.random.default_rng(5)
    mesh = mesh.copy()
    mesh.apply_transform(_pose(rng))
    points, covariances = _sample(mesh, 35, rng)
    result = recognise(points, covariances, rng=np.random.default_rng(0))
    assert result.fit_chance < recognition.FIT_CHANCE
    assert result.decision == UNDECIDED
    said = overdispersed(result)
    assert "so no class is named" in said and said.startswith("the points lie")


def test_a_truncated_cone_with_its_top_is_not_named() -> None:
    # A cone cut at half its 20 cm height (7 cm base radius), touched from one side: 30 points
    # on its slant and 3 on its flat top. The cone bent to take the top fits the slant worse
    # than its points' deviations allow (and counts a top point wrong): too unlikely for
    # points of a cone, and no class is named. Without the test the cone was named at 1.0.
    rng = np.random.default_rng(5)
    z = rng.uniform(0.0, 0.1, 30)
    turn = rng.uniform(-1.2, 1.2, 30)
    radius = 0.07 * (1.0 - z / 0.2)
    slant = np.column_stack([radius * np.cos(turn), radius * np.sin(turn), z])
    top = np.array([[0.01, 0.0, 0.1], [-0.01, 0.015, 0.1], [0.0, -0.02, 0.1]])
    pose = _pose(rng)

    def placed(points: np.ndarray) -> np.ndarray:
        noisy = points + rng.normal(0.0, NOISE, points.shape)
        return noisy @ pose[:3, :3].T + pose[:3, 3]

    points = np.vstack([placed(slant), placed(top)])
    covariances = np.tile(np.eye(3) * NOISE**2, (33, 1, 1))
    result = recognise(points, covariances, rng=np.random.default_rng(0))
    assert result.best.name == "cone"
    assert result.fit_chance < recognition.FIT_CHANCE
    assert result.decision == UNDECIDED


def test_many_points_a_little_noisier_than_their_covariances_still_name_their_class() -> None:
    # 120 points of a ball whose errors are 1.3 times the deviations their covariances state
    # (an overdispersion of about 1.7): the chi^2 of so many is far in its tail, but a spread
    # within FIT_OVERDISPERSION is the covariances' shortfall, not another shape: named
    mesh, rng = _placed("sphere")
    points, _ = trimesh.sample.sample_surface(mesh, 120, seed=int(rng.integers(2**31)))
    points = points + rng.normal(0.0, 1.3 * NOISE, points.shape)
    covariances = np.tile(np.eye(3) * NOISE**2, (120, 1, 1))
    result = recognise(points, covariances, rng=np.random.default_rng(0))
    assert result.fit_chance < recognition.FIT_CHANCE
    assert result.overdispersion < recognition.FIT_OVERDISPERSION
    assert not result.none_fits and result.decision == "sphere"
