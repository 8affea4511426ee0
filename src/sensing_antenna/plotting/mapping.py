"""Figures of a contact map: the points from several sides, coloured by their uncertainty.

Each figure has four views (from the front, the side, above, and an oblique view), the points
(in cm, display edge) coloured by their worst-direction standard deviation (mm), the surface's
mesh in grey when there is one, and the recognised shape's mesh as a wire frame. Every view is
a cube, one span on all three axes (:func:`cube_limits`), so that points on one plane or one
line keep their scale.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.artist import Artist
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator
from mpl_toolkits.mplot3d.art3d import Line3DCollection
from numpy.typing import NDArray

from sensing_antenna.mapping.contact_map import UNHELD_FRACTION, ContactMap, touch_reach, touched
from sensing_antenna.mapping.recognition import shape_size
from sensing_antenna.plotting import save_figure

__all__ = ["LEAST_SPAN_CM", "VIEWS", "cube_limits", "map_figure", "plot_map"]

#: (title, elevation, azimuth, the axis seen end-on or None) of each view, degrees.
VIEWS = (
    ("front (along +X)", 0.0, 180.0, "x"),
    ("side (along +Y)", 0.0, -90.0, "y"),
    ("above", 90.0, -90.0, "z"),
    ("oblique", 25.0, -135.0, None),
)


#: Least span (cm) of the views' axes: a single point or a few close ones still get a box.
LEAST_SPAN_CM = 2.0

#: Most faces of a recognised shape's mesh drawn as a wire frame (more would draw slowly).
_WIRE_FRAME_FACES = 20000


def cube_limits(coordinates: np.ndarray) -> np.ndarray | None:
    """Limits (low, high) of x, y and z, shape (3, 2), one span for all three: the largest
    extent of ``coordinates`` (n, 3), widened by 5 % and to at least :data:`LEAST_SPAN_CM`,
    about each axis's middle; None without finite coordinates."""
    finite = coordinates[np.all(np.isfinite(coordinates), axis=1)]
    if not len(finite):
        return None
    low, high = finite.min(axis=0), finite.max(axis=0)
    half = max(1.05 * float(np.max(high - low)), LEAST_SPAN_CM) / 2.0
    middle = (low + high) / 2.0
    return np.stack([middle - half, middle + half], axis=1)


def plot_map(contact_map: ContactMap, path: Path) -> Path:
    """Draw the map's points from the four :data:`VIEWS` into ``path``; returns ``path``."""
    # laid out by hand (:func:`map_figure`: the colour bar's own axes beside four 3-D views)
    return save_figure(map_figure(contact_map), path, dpi=110, tight=False)


#: Pieces each drawn edge of the recognised shape is cut into, each drawn solid or faint by
#: whether a touch was near it (a cone's edges run from its apex to its base).
_EDGE_PIECES = 8


def _pieces(edges: NDArray[np.float64], count: int) -> NDArray[np.float64]:
    """Each edge (shape (n, 2, 3)) cut into ``count`` equal segments, shape (n count, 2, 3)."""
    steps = np.linspace(0.0, 1.0, count + 1)
    along = edges[:, :1] + steps[None, :, None] * (edges[:, 1:] - edges[:, :1])
    return np.stack([along[:, :-1], along[:, 1:]], axis=2).reshape(-1, 2, 3)


def map_figure(contact_map: ContactMap) -> Figure:
    """The figure of :func:`plot_map`: four 3-D views (cm) of the map's used points, coloured
    by their sigma, over the surface mesh and the recognised shape's wire frame."""
    used = contact_map.used
    fig = plt.figure(figsize=(11, 9))
    points = np.array([p.point for p in used]).reshape(-1, 3) * 100.0
    std = np.array([p.std for p in used]) * 1000.0
    mesh = contact_map.surface_mesh
    shape = None  # drawn as a wire frame when it has few enough faces to draw quickly
    if contact_map.recognition is not None:
        best = contact_map.recognition.best.mesh
        shape = best if best is not None and len(best.faces) < _WIRE_FRAME_FACES else None
    parts = [points]
    if mesh is not None and len(mesh.faces):
        parts.append(mesh.vertices * 100.0)
    if shape is not None:
        parts.append(shape.vertices * 100.0)
    limits = cube_limits(np.concatenate(parts))
    segments = np.zeros((0, 2, 3))
    near = np.zeros(0, dtype=bool)
    if shape is not None:
        # each drawn edge in short pieces: one near a touch is the touched shape, the others
        # carry the class's shape past the touches, drawn faint: as sure as the class is right
        edges = shape.vertices[shape.edges_unique]
        segments = _pieces(edges[:: max(1, len(edges) // 600)], _EDGE_PIECES)
        # the reach the report's touched share counts with (the same size, a tenth of it)
        touches = points / 100.0
        reach = touch_reach(touches, UNHELD_FRACTION * shape_size(shape))
        near = touched(touches, segments.mean(axis=1), reach)
    scatter = None
    for index, (title, elevation, azimuth, end_on) in enumerate(VIEWS, start=1):
        ax = fig.add_subplot(2, 2, index, projection="3d")
        if mesh is not None and len(mesh.faces):
            ax.plot_trisurf(
                *(mesh.vertices * 100.0).T,
                triangles=mesh.faces,
                color="0.8",
                alpha=0.35,
                linewidth=0,
            )
        for chosen, alpha, style in ((near, 0.5, "-"), (~near, 0.25, ":")):
            if chosen.any():
                ax.add_collection3d(
                    Line3DCollection(
                        segments[chosen] * 100.0,
                        colors="tab:green",
                        linewidths=0.4,
                        alpha=alpha,
                        linestyles=style,
                    )
                )
        if len(points):
            scatter = ax.scatter(*points.T, c=std, cmap="viridis", s=18, depthshade=False)
        ax.view_init(elev=elevation, azim=azimuth)
        if limits is not None:
            # one span on every axis in a cubic box: equal scales, even for points on one
            # plane or one line, whose thin axis would otherwise squeeze the view to a sliver
            ax.set(xlim=limits[0], ylim=limits[1], zlim=limits[2])
            ax.set_box_aspect((1.0, 1.0, 1.0))
        ax.set_title(title)
        for name in "xyz":
            axis = getattr(ax, f"{name}axis")
            if name == end_on:  # seen end-on, its ticks fall on one spot
                axis.set_ticklabels([])
                axis.set_label_text("")
            else:
                axis.set_major_locator(MaxNLocator(nbins=4))  # labels that do not run together
                axis.set_label_text(f"{name} (cm)")
    if scatter is not None:
        fig.colorbar(
            scatter,
            cax=fig.add_axes((0.9, 0.25, 0.02, 0.5)),
            label="point sigma, worst direction (mm)",
        )
    recognition = contact_map.recognition
    decision = "" if recognition is None else f": {recognition.decision}"
    fig.suptitle(f"{len(used)} contact points{decision}")
    # what the grey and the green are (the green: the best class's fit, named or not)
    handles: list[Artist] = []
    if mesh is not None and len(mesh.faces):
        handles.append(Patch(color="0.8", alpha=0.6, label="surface through the points"))
    if shape is not None and recognition is not None:
        fitted = recognition.best.name.replace("mesh:", "mesh ")
        said = "recognised" if not recognition.undecided else "best fit, not recognised"
        handles.append(Line2D([], [], color="tab:green", label=f"{fitted} ({said})"))
        if not near.all():
            handles.append(
                Line2D(
                    [], [], color="tab:green", alpha=0.4, linestyle=":", label="beyond the touches"
                )
            )
    if handles:
        fig.legend(handles=handles, loc="lower center", ncol=len(handles), frameon=False)
    fig.subplots_adjust(left=0.02, right=0.85, wspace=0.1, hspace=0.15)
    return fig
