"""An interactive 3D view of a map: one self-contained HTML file (``map.html``).

The view is trimesh's own (``trimesh.viewer.notebook.scene_to_html``): the scene exported as a
binary glTF, base64-encoded into an HTML page that carries three.js inline, so the file opens
in any browser with WebGL and needs no network and no server. It holds, as named nodes:

- ``points``: the points used, as a point cloud coloured by their worst-direction standard
  deviation, blue (smallest) to red (largest), the colours of ``points.ply``;
- ``point_markers``: a small sphere at each point (radius a hundredth of the points' spread,
  at least 1 mm) in the same colours, since a browser draws a point cloud one pixel wide;
- ``surface``: the fitted surface's mesh, coloured by its predictive standard deviation;
- ``recognised``: the best class's fitted shape (even when the decision abstains), green;
- ``truth``: the true surface when known (``antenna explore``: the scene), grey.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh
from numpy.typing import NDArray

from sensing_antenna.mapping.contact_map import ContactMap
from sensing_antenna.mapping.store import GREY, std_colours

__all__ = ["map_scene", "write_map_html"]

#: Colour (RGBA) of the recognised shape (the true surface's is grey).
RECOGNISED_COLOUR = (40, 160, 60, 255)


def _markers(points: NDArray[np.float64], colours: NDArray[np.uint8]) -> trimesh.Trimesh:
    """One small icosphere per point, in the point's colour."""
    spread = float(np.linalg.norm(np.ptp(points, axis=0))) if len(points) > 1 else 0.0
    radius = max(0.01 * spread, 1e-3)
    unit = trimesh.creation.icosphere(subdivisions=1, radius=radius)
    n, m = len(points), len(unit.vertices)
    vertices = (unit.vertices[None, :, :] + points[:, None, :]).reshape(-1, 3)
    faces = (unit.faces[None, :, :] + m * np.arange(n)[:, None, None]).reshape(-1, 3)
    return trimesh.Trimesh(
        vertices=vertices, faces=faces, vertex_colors=np.repeat(colours, m, axis=0), process=False
    )


def _coloured(mesh: trimesh.Trimesh, colour: tuple[int, int, int, int]) -> trimesh.Trimesh:
    """A copy of ``mesh`` with every face in ``colour``."""
    return trimesh.Trimesh(
        vertices=mesh.vertices,
        faces=mesh.faces,
        face_colors=np.tile(colour, (len(mesh.faces), 1)),
        process=False,
    )


def map_scene(contact_map: ContactMap, truth: trimesh.Trimesh | None = None) -> trimesh.Scene:
    """The map's points, surface, recognised shape and (when given) true surface as a
    trimesh scene with the node names of the module docstring (world frame, m)."""
    scene = trimesh.Scene()
    if contact_map.used:
        points = np.array([p.point for p in contact_map.used]).reshape(-1, 3)
        colours = std_colours(np.array([p.std for p in contact_map.used]))
        scene.add_geometry(
            trimesh.PointCloud(points, colors=colours), node_name="points", geom_name="points"
        )
        scene.add_geometry(
            _markers(points, colours), node_name="point_markers", geom_name="point_markers"
        )
    mesh = contact_map.surface_mesh
    if mesh is not None and len(mesh.faces):
        surface = trimesh.Trimesh(
            vertices=mesh.vertices,
            faces=mesh.faces,
            vertex_colors=std_colours(contact_map.surface_std),
            process=False,
        )
        scene.add_geometry(surface, node_name="surface", geom_name="surface")
    recognition = contact_map.recognition
    if recognition is not None and recognition.best.mesh is not None:
        shape = _coloured(recognition.best.mesh, RECOGNISED_COLOUR)
        scene.add_geometry(shape, node_name="recognised", geom_name="recognised")
    if truth is not None and len(truth.faces):
        scene.add_geometry(_coloured(truth, GREY), node_name="truth", geom_name="truth")
    return scene


def write_map_html(
    contact_map: ContactMap, path: Path, truth: trimesh.Trimesh | None = None
) -> Path | None:
    """Write :func:`map_scene` as a self-contained HTML page to ``path``; returns ``path``, or
    None when the map holds nothing to draw (no point used and no true surface)."""
    from trimesh.viewer.notebook import scene_to_html

    scene = map_scene(contact_map, truth)
    if not scene.geometry:
        return None
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(scene_to_html(scene))
    return path
