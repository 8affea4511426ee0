"""Contact points on known surfaces, for the map's tests."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.result import Status
from sensing_antenna.mapping import ContactPoint

#: The points' noise and their stated sigma in every direction (m).
NOISE = 1e-3


def contacts(points: NDArray[np.float64]) -> list[ContactPoint]:
    """``ok`` contact points at ``points`` (m, shape (n, 3)), each with sigma :data:`NOISE`."""
    return [
        ContactPoint(p, NOISE**2 * np.eye(3), Status.OK, f"r{i}", "paper", 0.5, np.zeros(3))
        for i, p in enumerate(points)
    ]


def half_sphere(n: int, centre: NDArray[np.float64], radius: float) -> NDArray[np.float64]:
    """n points (m, shape (n, 3)) with :data:`NOISE` on the half of a sphere facing a base at
    the origin (seed 3)."""
    rng = np.random.default_rng(3)
    directions = rng.normal(size=(n, 3))
    directions[:, 0] = -np.abs(directions[:, 0])
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    return np.asarray(centre + radius * directions + rng.normal(scale=NOISE, size=(n, 3)))


def box_but_its_top(extents: NDArray[np.float64], per_face: int, seed: int) -> NDArray[np.float64]:
    """Points (m, shape (5 per_face, 3)) with :data:`NOISE` on five faces of a box of
    ``extents`` (m) centred at (0.5, 0.1, 0) m, its +z face never touched."""
    rng = np.random.default_rng(seed)
    faces = []
    for axis in range(3):
        for sense in (1.0, -1.0):
            if axis == 2 and sense > 0:
                continue
            on_face = rng.uniform(-0.5, 0.5, (per_face, 3)) * extents
            on_face[:, axis] = 0.5 * sense * extents[axis]
            faces.append(on_face)
    points = np.vstack(faces)
    return np.asarray(points + rng.normal(0.0, NOISE, points.shape) + [0.5, 0.1, 0.0])
