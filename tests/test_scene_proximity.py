"""Distances to meshes in calls of bounded size (scene/proximity.py) against trimesh's own."""

from __future__ import annotations

import numpy as np
import trimesh

from sensing_antenna.scene.proximity import CHUNK, closest_point, signed_distance


def test_queries_in_chunks_equal_one_call_and_the_sign_is_positive_outside() -> None:
    mesh = trimesh.creation.icosphere(subdivisions=2, radius=0.05)
    points = np.random.default_rng(0).uniform(-0.1, 0.1, (2 * CHUNK + 7, 3))
    inside = np.linalg.norm(points, axis=1) < 0.045
    outside = np.linalg.norm(points, axis=1) > 0.055
    d = signed_distance(mesh, points)
    np.testing.assert_array_equal(d, -trimesh.proximity.signed_distance(mesh, points))
    assert np.all(d[inside] < 0.0) and np.all(d[outside] > 0.0)
    near, distance, faces = closest_point(mesh, points)
    reference = trimesh.proximity.closest_point(mesh, points)
    np.testing.assert_array_equal(near, reference[0])
    np.testing.assert_array_equal(distance, reference[1])
    np.testing.assert_array_equal(faces, reference[2])
    assert signed_distance(mesh, np.zeros((0, 3))).shape == (0,)
    assert closest_point(mesh, np.zeros((0, 3)))[0].shape == (0, 3)
