"""The pushed link out of its bending plane: how far its fundamental may leave the straight link's.

A push bends the link in the plane of the reaction (the push plane). Out of that plane (the
"free" plane) the contact still pins the link, held by friction along the obstacle's other
surface direction, and the bent link rings close to the straight link's omega_1: linearised
about the bent static state, its out-of-plane motion is that of a straight beam under an
effective axial force N - M0^2 / (E I) (N the reaction's share along the bent axis, M0 the
static bending moment), the twist following the bending at no cost (docs/estimation.md, "The
two bending planes"). In the push plane, by contrast, a contact that friction holds along the
obstacle stiffens the mode by up to 170 %, by an amount no function of the deflection bounds.

:func:`free_plane_shift` bounds the relative shift of the free plane's fundamental from the
straight link's omega_1 at a given contact point and push deflection. The bound is the largest
shift of the independent computation in ``benchmarks/bent_link_free_plane.py`` (200 cubic
elements on the planar elastica of the pushed link) over its variants: a frictionless push,
friction along the link carrying +-0.6 of the push (tension or compression), the twist held at
the contact, and Poisson's ratios 0.2, 0.3 and 0.4. For a uniform rod of circular section the
shift depends only on x_c / l and d = y_c / x_c (the reaction that bends the link by d scales
with E I / x_c^2, and G J / E I = 1 / (1 + nu)), so the table serves any such link. Between its
nodes the shift is interpolated linearly in x_c / l and in d: it is convex in d, so the
interpolation in d lies above it; between 0.6 and 0.8 m it is concave in x_c, where the
interpolation may lie up to about 2 % of it below. Below the first
contact the first row is used (the shift grows with x_c up to 0.8 l and is flat beyond); past
the deepest push tabulated the bound is not known (inf).
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import RegularGridInterpolator

__all__ = [
    "FREE_PLANE_DEFLECTIONS",
    "FREE_PLANE_SHIFTS",
    "FREE_PLANE_SPANS",
    "free_plane_shift",
    "free_plane_shifts",
]

FloatArray = NDArray[np.float64]

#: Contact points of the table, as x_c / l (the paper link's 0.3 to 0.975 m of l = 0.98 m).
FREE_PLANE_SPANS = tuple(x / 0.98 for x in (0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.975))

#: Push deflections of the table, d = y_c / x_c.
FREE_PLANE_DEFLECTIONS = (0.0, 0.03, 0.05, 0.10, 0.20, 0.30, 0.40)

#: Largest relative shift |omega_free / omega_1 - 1| over the variants (rows: spans, columns:
#: deflections), from ``benchmarks/results/bent_link_free_plane.json``.
FREE_PLANE_SHIFTS = (
    (0.0, 2.97e-4, 5.13e-4, 1.15e-3, 2.85e-3, 5.40e-3, 9.41e-3),
    (0.0, 4.03e-4, 6.96e-4, 1.54e-3, 3.83e-3, 7.27e-3, 1.27e-2),
    (0.0, 5.11e-4, 8.90e-4, 1.98e-3, 4.91e-3, 9.32e-3, 1.63e-2),
    (0.0, 6.72e-4, 1.16e-3, 2.58e-3, 6.39e-3, 1.21e-2, 2.13e-2),
    (0.0, 1.03e-3, 1.78e-3, 3.92e-3, 9.63e-3, 1.83e-2, 3.22e-2),
    (0.0, 1.36e-3, 2.35e-3, 5.11e-3, 1.24e-2, 2.33e-2, 4.13e-2),
    (0.0, 1.37e-3, 2.35e-3, 5.09e-3, 1.23e-2, 2.30e-2, 4.07e-2),
    (0.0, 1.37e-3, 2.35e-3, 5.09e-3, 1.22e-2, 2.30e-2, 4.07e-2),
    (0.0, 1.37e-3, 2.35e-3, 5.09e-3, 1.22e-2, 2.30e-2, 4.06e-2),
)


@functools.cache
def _table() -> RegularGridInterpolator:
    return RegularGridInterpolator(
        (np.array(FREE_PLANE_SPANS), np.array(FREE_PLANE_DEFLECTIONS)),
        np.array(FREE_PLANE_SHIFTS),
    )


def free_plane_shift(span: float, deflection_ratio: float) -> float:
    """Bound of the relative shift of the free plane's fundamental from omega_1 (dimensionless).

    Parameters
    ----------
    span : float
        x_c / l.
    deflection_ratio : float
        d = y_c / x_c of the push.

    Returns
    -------
    float
        The bound, 0 for a straight link; inf beyond the deepest push tabulated (0.4) or for
        inputs that are not finite.
    """
    return float(free_plane_shifts(span, deflection_ratio))


def free_plane_shifts(span: ArrayLike, deflection_ratio: ArrayLike) -> FloatArray:
    """:func:`free_plane_shift` elementwise over arrays that broadcast together."""
    u, d = np.broadcast_arrays(np.asarray(span, dtype=float), np.abs(deflection_ratio))
    known = np.isfinite(u) & (d <= FREE_PLANE_DEFLECTIONS[-1])
    points = np.stack(
        [
            np.clip(
                np.where(known, u, FREE_PLANE_SPANS[0]), FREE_PLANE_SPANS[0], FREE_PLANE_SPANS[-1]
            ),
            np.where(known, d, 0.0),
        ],
        axis=-1,
    )
    return np.where(known, _table()(points.reshape(-1, 2)).reshape(u.shape), np.inf)
