"""Distances to triangle meshes, in bounded memory.

trimesh's proximity queries take every face whose bounding box could hold a query point's
closest point as a candidate; for a point far from the mesh that is every face, so memory grows
as points times faces. The queries here go in calls of :data:`CHUNK` points (docs/design-notes.md,
"Meshes queried in bounded memory").
"""

from __future__ import annotations

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray

__all__ = ["CHUNK", "closest_point", "signed_distance"]

#: Query points per call of a trimesh proximity query.
CHUNK = 250


def closest_point(
    mesh: trimesh.Trimesh, points: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.int64]]:
    """The closest point on ``mesh`` (m, shape (n, 3)) to each of ``points`` (m, shape (n, 3)),
    its distance (m, shape (n,)) and its face (shape (n,))."""
    q = np.asarray(points, dtype=float).reshape(-1, 3)
    parts = [
        trimesh.proximity.closest_point(mesh, q[i : i + CHUNK]) for i in range(0, len(q), CHUNK)
    ]
    if not parts:
        return np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=np.int64)
    return (
        np.concatenate([np.asarray(part[0], dtype=float).reshape(-1, 3) for part in parts]),
        np.concatenate([np.asarray(part[1], dtype=float) for part in parts]),
        np.concatenate([np.asarray(part[2], dtype=np.int64) for part in parts]),
    )


def signed_distance(mesh: trimesh.Trimesh, points: ArrayLike) -> NDArray[np.float64]:
    """Signed distance (m, shape (n,)) of ``points`` (m, shape (n, 3)) to a closed ``mesh``:
    positive outside (trimesh's own sign is the opposite)."""
    q = np.asarray(points, dtype=float).reshape(-1, 3)
    if not len(q):
        return np.zeros(0)
    parts = [
        trimesh.proximity.signed_distance(mesh, q[i : i + CHUNK]) for i in range(0, len(q), CHUNK)
    ]
    return -np.concatenate([np.asarray(part, dtype=float) for part in parts])
