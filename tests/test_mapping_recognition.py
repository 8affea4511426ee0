"""Recognition: each class recovered from noisy points of a trimesh shape; abstention."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from sensing_antenna.mapping import UNDECIDED, fit_mesh, fit_primitive, recognise
from sensing_antenna.mapping.recognition import shape_gap

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


@pytest.mark.parametrize("name", list(SHAPES))
def test_each_class_is_recognised_with_its_size(name: str) -> None:
    rng = np.random.default_rng(sorted(SHAPES).index(name))
    make, sizes = SHAPES[name]
    mesh = make()
    mesh.apply_transform(_pose(rng))
    points, covariances = _sample(mesh, 35, rng)
    result = recognise(points, covariances, rng=np.random.default_rng(0))
    assert result.decision == name, (result.decision, result.candidates, result.delta_score)
    assert result.confidence > 0.9
    fitted = result.best.sizes
    if name == "box":
        extents = sorted(fitted.values())
        errors = [abs(a / b - 1) for a, b in zip(extents, sizes["extent"], strict=True)]
    else:
        errors = [abs(fitted[k] / v - 1) for k, v in sizes.items()]
    assert max(errors) < SIZE_TOLERANCE, (fitted, sizes)
    # the residual is the noise: the RMS distance of points with 1 mm noise along the normal
    assert result.best.rms < 2 * NOISE


def test_a_few_points_on_a_patch_of_a_large_sphere_abstain_between_plane_and_sphere() -> None:
    # a 3 cm patch of a 50 cm sphere bulges a / 2R = 0.9 mm at its centre, as much as the noise
    rng = np.random.default_rng(11)
    radius = 0.5
    n = 12
    polar = np.arccos(1 - rng.uniform(0, 1, n) * (1 - math.cos(0.03 / radius)))
    azimuth = rng.uniform(0, 2 * math.pi, n)
    unit = np.stack(
        [np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)], axis=1
    )
    points = np.array([0.0, 0.0, -radius + 0.6]) + radius * unit
    points += rng.normal(0.0, NOISE, points.shape)
    covariances = np.tile(np.eye(3) * NOISE**2, (n, 1, 1))
    result = recognise(points, covariances, rng=np.random.default_rng(0))
    assert result.decision == UNDECIDED
    assert set(result.candidates) == {"plane", "sphere"}
    assert result.delta_score < result.threshold


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
