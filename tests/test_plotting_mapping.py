"""The map's figure (map.png): its views keep one scale on every axis, even for flat sets."""

from __future__ import annotations

from pathlib import Path

import matplotlib.image
import matplotlib.pyplot as plt
import numpy as np

from _contacts import contacts
from sensing_antenna.mapping import build_map
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
