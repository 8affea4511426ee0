"""A map's directory: the named object's surface (object.ply) against the true object."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

from sensing_antenna.estimation.result import Status
from sensing_antenna.mapping import ContactPoint, build_map, write_map

#: The 99 % point of the chi distribution with 4 degrees of freedom (a sphere's parameters).
CHI4_99 = 3.64


def _half_sphere(n: int, centre: np.ndarray, radius: float) -> list[ContactPoint]:
    """n points with 1 mm noise (their stated sigma) on the half of a sphere facing a base at
    the origin."""
    rng = np.random.default_rng(3)
    directions = rng.normal(size=(n, 3))
    directions[:, 0] = -np.abs(directions[:, 0])
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    points = centre + radius * directions + rng.normal(scale=1e-3, size=(n, 3))
    return [
        ContactPoint(p, 1e-6 * np.eye(3), Status.OK, f"r{i}", "paper", 0.5, np.zeros(3))
        for i, p in enumerate(points)
    ]


def test_the_named_object_is_the_whole_surface_within_its_deviation(tmp_path: Path) -> None:
    centre, radius = np.array([0.5, 0.0, 0.0]), 0.05
    contact_map = build_map(_half_sphere(30, centre, radius))
    assert contact_map.named_fit is not None and contact_map.named_fit.name == "sphere"
    written = write_map(contact_map, tmp_path)
    assert tmp_path / "object.ply" in written
    mesh = trimesh.load(tmp_path / "object.ply", process=False)
    assert len(mesh.faces) and len(mesh.visual.vertex_colors) == len(mesh.vertices)
    surface = contact_map.object_surface()
    assert surface is not None
    _, std = surface
    # the back half too, never touched: a sphere is the whole object once its four parameters
    # are fitted. Each vertex moves with them, so its error over its deviation is at most the
    # parameters' Mahalanobis error (Cauchy-Schwarz), below chi_4's 99 % point
    error = np.abs(np.linalg.norm(mesh.vertices - centre, axis=1) - radius)
    back = mesh.vertices[:, 0] > centre[0] + 0.5 * radius
    assert back.any() and np.all(error <= CHI4_99 * std)
    assert 0 < np.median(std) < 1e-3  # 30 points of 1 mm hold the sphere to under a mm
    report = (tmp_path / "report.md").read_text()
    assert "Object surface: the sphere's fitted shape" in report


def test_no_object_surface_without_a_named_object(tmp_path: Path) -> None:
    contact_map = build_map(_half_sphere(8, np.array([0.5, 0.0, 0.0]), 0.05))
    assert contact_map.recognition is None and contact_map.object_surface() is None
    assert tmp_path / "object.ply" not in write_map(contact_map, tmp_path)
    assert not (tmp_path / "object.ply").exists()
    assert "Object surface: none" in (tmp_path / "report.md").read_text()
    assert contact_map.summary()["object_surface"] is None
