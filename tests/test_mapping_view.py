"""The interactive view (map.html): what it holds, read back from the file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

from _contacts import contacts, half_sphere
from _map_html import html_scene
from sensing_antenna.mapping import build_map
from sensing_antenna.mapping.view import write_map_html


def test_the_view_holds_points_surface_recognised_shape_and_truth(tmp_path: Path) -> None:
    # 30 points with 1 mm noise on the half of a 5 cm sphere facing a base at the origin
    centre, radius = np.array([0.5, 0.0, 0.0]), 0.05
    points = half_sphere(30, centre, radius)
    contact_map = build_map(contacts(points))
    truth = trimesh.creation.icosphere(subdivisions=3, radius=radius)
    truth.apply_translation(centre)
    path = write_map_html(contact_map, tmp_path / "map.html", truth)
    assert path is not None
    view = html_scene(path)
    assert {"points", "point_markers", "surface", "recognised", "truth"} <= set(view.geometry)
    assert np.allclose(view.geometry["points"].vertices, points)
    assert np.allclose(view.geometry["truth"].bounds, truth.bounds)
    # the recognised sphere lies around the true centre (the fit, not a copy of the truth)
    fitted = view.geometry["recognised"].bounds.mean(axis=0)
    assert np.linalg.norm(fitted - centre) < 5e-3


def test_nothing_to_draw_writes_no_file(tmp_path: Path) -> None:
    contact_map = build_map([])
    assert write_map_html(contact_map, tmp_path / "map.html") is None
    assert not (tmp_path / "map.html").exists()
