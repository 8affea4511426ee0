"""The map's figure (map.png): its views keep one scale on every axis, even for flat sets."""

from __future__ import annotations

from pathlib import Path

import matplotlib.image
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Line3DCollection

from _contacts import contacts, half_sphere
from sensing_antenna.mapping import build_map
from sensing_antenna.mapping.contact_map import touch_reach, touched
from sensing_antenna.plotting.mapping import (
    LEAST_SPAN_CM,
    VIEWS,
    cube_limits,
    map_figure,
    plot_map,
)


def test_the_views_span_one_length_on_every_axis_about_the_points_middle() -> None:
    # Points on a vertical line (a box's edge touched at four heights): 20 cm along z, none
    # across; every axis gets the same 21 cm (5 % wider) about the points' middle, so the
    # thin axes are not squeezed to a sliver
    line = np.array([[85.0, 15.0, z] for z in (-13.0, -9.0, 0.0, 7.0)])
    limits = cube_limits(line)
    assert limits is not None
    assert np.allclose(limits[:, 1] - limits[:, 0], 21.0)
    assert np.allclose(limits.mean(axis=1), [85.0, 15.0, -3.0])
    # one point: the least span; no finite point: no limits
    single = cube_limits(np.array([[1.0, 2.0, 3.0], [np.nan, 0.0, 0.0]]))
    assert single is not None
    assert np.allclose(
        single,
        [
            [1.0 - LEAST_SPAN_CM / 2, 1.0 + LEAST_SPAN_CM / 2],
            [2.0 - LEAST_SPAN_CM / 2, 2.0 + LEAST_SPAN_CM / 2],
            [3.0 - LEAST_SPAN_CM / 2, 3.0 + LEAST_SPAN_CM / 2],
        ],
    )
    assert cube_limits(np.full((2, 3), np.nan)) is None


def test_collinear_points_are_drawn_in_cubic_views_that_hold_them(tmp_path: Path) -> None:
    # Six points on a vertical line, 20 cm long: every view's x, y and z span one length (that
    # of the points and the surface's mesh), and the points lie inside it (autoscaled, the axes
    # across the line would span the mesh's width alone)
    points = np.array([[0.85, 0.15, z] for z in np.linspace(-0.13, 0.07, 6)])
    contact_map = build_map(contacts(points))
    figure = map_figure(contact_map)
    views = [ax for ax in figure.axes if hasattr(ax, "get_zlim")]
    assert len(views) == len(VIEWS)
    for ax in views:
        limits = np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()])
        spans = limits[:, 1] - limits[:, 0]
        assert np.allclose(spans, spans[0]) and spans[0] >= 21.0
        assert np.all(limits[:, 0] < points.min(axis=0) * 100.0)
        assert np.all(points.max(axis=0) * 100.0 < limits[:, 1])
    plt.close(figure)
    path = plot_map(contact_map, tmp_path / "map.png")
    image = matplotlib.image.imread(path)
    assert image.shape[0] > 500 and image.shape[1] > 500


def test_a_named_shapes_part_beyond_the_touches_is_drawn_faint() -> None:
    # A ball touched on the half facing the base (x below its centre): the fitted sphere's
    # points behind it lie beyond the touches' reach, those in front within it; its wire frame
    # is drawn in two collections, solid and dotted, and the legend says what the dotted is
    centre, radius = np.array([0.5, 0.0, 0.0]), 0.05
    points = half_sphere(30, centre, radius)
    contact_map = build_map(contacts(points))
    sphere = centre + radius * np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    assert list(touched(points, sphere, touch_reach(points, 0.1 * 2 * radius))) == [True, False]
    figure = map_figure(contact_map)
    view = next(ax for ax in figure.axes if hasattr(ax, "get_zlim"))
    frames = [c for c in view.collections if isinstance(c, Line3DCollection)]
    styles = sorted(c.get_alpha() for c in frames)
    assert len(frames) == 2 and styles[0] < styles[1]
    labels = [text.get_text() for legend in figure.legends for text in legend.get_texts()]
    assert "beyond the touches" in labels
    plt.close(figure)
