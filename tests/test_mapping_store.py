"""A map's directory: the named object's surface (object.ply) against the true object."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

from _contacts import NOISE, box_but_its_top, contacts, half_sphere
from sensing_antenna.mapping import build_map, recognise, write_map
from sensing_antenna.mapping.store import GREY, OVERDISPERSED, overdispersed

#: The 99 % point of the chi distribution with 4 degrees of freedom (a sphere's parameters).
CHI4_99 = 3.64
#: Pure red and pure blue in object.ply's colours (RGB).
RED, BLUE = (255, 64, 0), (0, 64, 255)


def _colours(path: Path) -> np.ndarray:
    mesh = trimesh.load(path, process=False)
    return np.asarray(mesh.visual.vertex_colors)[:, :3]


def test_a_named_sphere_is_the_whole_object_within_its_deviation(tmp_path: Path) -> None:
    centre, radius = np.array([0.5, 0.0, 0.0]), 0.05
    contact_map = build_map(contacts(half_sphere(30, centre, radius)))
    surface = contact_map.object_surface()
    assert surface is not None and surface.name == "sphere"
    assert tmp_path / "object.ply" in write_map(contact_map, tmp_path)
    vertices, std = surface.mesh.vertices, surface.std
    # Each vertex moves with the four fitted parameters, so its error over its deviation is at
    # most their Mahalanobis error (Cauchy-Schwarz), below chi_4's 99 % point; the faces are
    # flat, so a vertex split off an edge lies inside the sphere by at most edge^2 / (8 r)
    assert contact_map.recognition is not None
    fitted = contact_map.recognition.best.mesh
    edge = float(np.max(fitted.edges_unique_length))
    error = np.abs(np.linalg.norm(vertices - centre, axis=1) - radius)
    assert np.all(error <= CHI4_99 * std + edge**2 / (8 * radius))
    # the back half, never touched, is placed by the fit and less sure than the front
    back = vertices[:, 0] > centre[0] + 0.5 * radius
    front = vertices[:, 0] < centre[0] - 0.5 * radius
    assert np.median(std[back]) > 2 * np.median(std[front])
    summary = contact_map.summary()["object_surface"]
    assert summary["class"] == "sphere" and summary["held_share"] == 1.0
    assert 0 < summary["held_std_median_m"] < summary["held_std_p90_m"] < NOISE
    # held everywhere by the class, but touched on the front half only: the points' reach (their
    # median spacing, or a tenth of the size) leaves the back uncounted, less than 60 % in all
    assert 0.3 < summary["touched_share"] < 0.6
    assert np.all(
        np.linalg.norm(vertices[back][:, None] - half_sphere(30, centre, radius)[None], axis=2).min(
            axis=1
        )
        > summary["touch_reach_m"]
    )
    # coloured from blue (no deviation) towards red (a tenth of the size): all held, all bluish
    colours = _colours(tmp_path / "object.ply")
    assert len(colours) == len(vertices) and np.all(colours[:, 0] < 0.1 * 255)
    assert np.corrcoef(colours[:, 0].astype(float), std)[0, 1] > 0.99
    report = (tmp_path / "report.md").read_text()
    assert "Object surface: the sphere's fitted shape (object.ply); " in report
    assert "% of its area within" in report and "mm of a contact point" in report
    assert "; 100 % of its area held by the fit" in report


def test_an_end_no_touch_reached_is_not_held(tmp_path: Path) -> None:
    # a cylinder (radius 3 cm, height 10 cm) touched on the half of its side facing the base
    # and on its top face; its bottom face never
    rng = np.random.default_rng(5)
    centre, r, h = np.array([0.5, 0.0, 0.0]), 0.03, 0.10
    phi, z = rng.uniform(np.pi / 2, 3 * np.pi / 2, 40), rng.uniform(-h / 2, h / 2, 40)
    rho, angle = r * np.sqrt(rng.uniform(0, 1, 12)), rng.uniform(0, 2 * np.pi, 12)
    side = np.c_[r * np.cos(phi), r * np.sin(phi), z]
    top = np.c_[rho * np.cos(angle), rho * np.sin(angle), np.full(12, h / 2)]
    points = centre + np.r_[side, top] + rng.normal(scale=NOISE, size=(52, 3))
    contact_map = build_map(contacts(points))
    surface = contact_map.object_surface()
    assert surface is not None and surface.name == "cylinder"
    write_map(contact_map, tmp_path)
    z_local = surface.mesh.vertices[:, 2]
    bottom = z_local < z_local.min() + 1e-4
    middle = np.abs(z_local - centre[2]) < 0.3 * h
    assert np.all(surface.std[bottom] >= surface.unheld)  # the extent prior's end, not evidence
    assert np.all(surface.std[middle] < NOISE)
    # held: the side and the top, (h + r / 2) / (h + r) of the area (the rim's vertices share
    # their area with the bottom: a couple of per cent)
    held = contact_map.summary()["object_surface"]["held_share"]
    assert abs(held - (h + r / 2) / (h + r)) < 0.03
    colours = _colours(tmp_path / "object.ply")
    assert np.all(colours[bottom] == RED)
    assert np.all(colours[middle][:, 0] < 0.1 * 255)


def test_a_registered_mesh_carries_no_deviation(tmp_path: Path) -> None:
    centre, radius = np.array([0.5, 0.0, 0.0]), 0.05
    points = half_sphere(30, centre, radius)
    ball = trimesh.creation.icosphere(subdivisions=3, radius=radius)
    recognition = recognise(points, NOISE**2 * np.ones((30, 1, 1)) * np.eye(3), [], {"ball": ball})
    contact_map = build_map(contacts(points), recognition=recognition)
    surface = contact_map.object_surface()
    assert surface is not None and surface.name == "mesh:ball"
    assert np.all(np.isnan(surface.std))
    assert contact_map.summary()["object_surface"]["held_share"] is None
    write_map(contact_map, tmp_path)  # recognition.json with nulls, no NaN
    assert np.all(_colours(tmp_path / "object.ply") == GREY[:3])
    assert "it carries no deviation" in (tmp_path / "report.md").read_text()


def test_no_object_surface_without_a_named_object(tmp_path: Path) -> None:
    contact_map = build_map(contacts(half_sphere(8, np.array([0.5, 0.0, 0.0]), 0.05)))
    assert contact_map.recognition is None and contact_map.object_surface() is None
    assert tmp_path / "object.ply" not in write_map(contact_map, tmp_path)
    assert not (tmp_path / "object.ply").exists()
    assert "Object surface: none (recognition names no object)" in (
        (tmp_path / "report.md").read_text()
    )
    assert contact_map.summary()["object_surface"] is None


def test_points_far_from_every_class_are_said_to_be(tmp_path: Path) -> None:
    # a ball's points, a third of them shifted by 3 cm (a base pose wrong by that much): no class
    # fits them within their deviations, and the report says so with how far off they lie
    points = half_sphere(30, np.array([0.5, 0.0, 0.0]), 0.05)
    points[::3] += [0.0, 0.03, 0.0]
    contact_map = build_map(contacts(points))
    assert contact_map.recognition is not None
    c = contact_map.recognition.overdispersion
    assert c > OVERDISPERSED
    said = overdispersed(contact_map.recognition)
    assert said.startswith(f"the points lie {np.sqrt(c):.1f} times farther from the best")
    write_map(contact_map, tmp_path)
    assert f"{said[:1].upper()}{said[1:]}." in (tmp_path / "report.md").read_text()
    # the unshifted ball: nothing said
    clean = build_map(contacts(half_sphere(30, np.array([0.5, 0.0, 0.0]), 0.05)))
    assert clean.recognition is not None and overdispersed(clean.recognition) == ""


def test_the_report_names_a_point_far_from_the_named_object(tmp_path: Path) -> None:
    # one of 31 points half a metre from the ball (a base pose written wrong): the sphere is
    # named, and the report names that point's recording, the one its fit counts wrong
    centre, radius = np.array([0.5, 0.0, 0.0]), 0.05
    points = np.vstack([half_sphere(30, centre, radius), centre + np.array([0.0, 0.5, 0.0])])
    contact_map = build_map(contacts(points))
    assert contact_map.recognition is not None
    assert contact_map.recognition.decision == "sphere"
    write_map(contact_map, tmp_path)
    report = (tmp_path / "report.md").read_text()
    assert "Points the sphere's fit counts as wrong estimates" in report
    assert "r30 (451 mm from it)" in report and "r29" not in report  # 0.5 m less the radius
    # what a named class is of: a straight link touches the convex hull only
    assert "The class is the one of the object's convex hull" in report


def test_a_named_mesh_says_what_of_it_the_points_do_not_hold(tmp_path: Path) -> None:
    # a box touched on five faces, its top never, and the user's mesh of it: the mesh is named,
    # and the report says the box class bounds its height only from below
    extents = np.array([0.06, 0.1, 0.16])
    points = box_but_its_top(extents, 8, seed=3)
    block = trimesh.creation.box(extents=extents)
    contact_map = build_map(contacts(points), meshes={"block": block})
    assert contact_map.recognition is not None
    assert contact_map.recognition.decision == "mesh:block"
    write_map(contact_map, tmp_path)
    report = (tmp_path / "report.md").read_text()
    assert "The box class fits the same points with" in report and "at least" in report
    assert "the mesh is one such box, and the points hold no more of its size than that" in report
    # a user's mesh is the object's own shape, not its hull's class
    assert "convex hull" not in report
