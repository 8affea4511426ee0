"""The map's figure (map.png): its views keep one scale on every axis, even for flat sets."""

from __future__ import annotations

from pathlib import Path

import matplotlib.image
import numpy as np

from _contacts import contacts
from sensing_antenna.mapping import build_map
from sensing_antenna.plotting.mapping import LEAST_SPAN_CM, cube_limits, plot_map


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


def test_collinear_points_are_drawn_without_a_warning(tmp_path: Path) -> None:
    points = np.array([[0.85, 0.15, z] for z in np.linspace(-0.13, 0.07, 6)])
    path = plot_map(build_map(contacts(points)), tmp_path / "map.png")
    image = matplotlib.image.imread(path)
    assert image.shape[0] > 500 and image.shape[1] > 500
