"""Static deflection of the pushed link and the base force and torque (Eqs. 7 to 13).

Re-derivation. ``y_s'''' = 0`` (Eq. 7) with ``y(0) = y'(0) = 0``, ``y(x_c) = y_c``, slope and
moment continuous at ``x_c`` and a free end (Eq. 8). Beyond the contact nothing loads the link, so
``y'' = y''' = 0`` on ``[x_c, l]`` and, by continuity, ``y''(x_c) = 0``. On ``[0, x_c]`` the cubic
``a x^2 + b x^3`` with ``y''(x_c) = 0`` and ``y(x_c) = y_c`` gives ``a = 3 y_c / (2 x_c^2)``,
``b = -y_c / (2 x_c^3)``: Eq. 9 as printed is right. At the base ``y''(0) = 3 y_c / x_c^2`` and
``y'''(0) = -3 y_c / x_c^3``, so Eqs. 10 to 13 give ``|Gamma| = 3 E I |y_c| / x_c^2`` and
``|F| = 3 E I |y_c| / x_c^3``; their ratio is ``x_c`` (Eq. 18).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import Link
from sensing_antenna.beam._validate import as_finite_array
from sensing_antenna.beam.modes import contact_ratio

__all__ = [
    "base_force",
    "base_torque",
    "contact_deflection_from_force",
    "static_deflection",
    "torque_force_ratio",
]

FloatArray = NDArray[np.float64]


def static_deflection(x: ArrayLike, x_c: ArrayLike, y_c: ArrayLike) -> FloatArray:
    """Eq. 9: static deflection y_s(x) (m) of the link pushed by y_c (m) at x_c (m).

    Parameters
    ----------
    x : array_like
        Positions along the link, >= 0 (m).
    x_c : array_like
        Contact point(s), > 0 (m).
    y_c : array_like
        Deflection at the contact (m), any sign.

    Returns
    -------
    ndarray
        y_s (m), the broadcast shape of the three arguments.
    """
    x_a = as_finite_array("x", x, low=0.0)
    x_c_a = as_finite_array("x_c", x_c, low=0.0, low_open=True)
    y_c_a = as_finite_array("y_c", y_c)
    r = x_a / x_c_a
    # Eq. 9, [0, x_c]: y = 3/2 y_c (x/x_c)^2 - 1/2 y_c (x/x_c)^3
    inner = 1.5 * y_c_a * r**2 - 0.5 * y_c_a * r**3
    # Eq. 9, [x_c, l]: y = 3/2 y_c (x/x_c) - 1/2 y_c
    outer = 1.5 * y_c_a * r - 0.5 * y_c_a
    return np.asarray(np.where(r <= 1.0, inner, outer))


def base_force(link: Link, x_c: ArrayLike, y_c: ArrayLike) -> FloatArray:
    """Eq. 13: magnitude of the base force |F| = 3 E I |y_c| / x_c^3 (N).

    ``x_c`` in (0, l] (m) and ``y_c`` (m) broadcast together.
    """
    x_c_a = contact_ratio(link, x_c) * link.length
    y_c_a = as_finite_array("y_c", y_c)
    # Eq. 13
    return np.asarray(3.0 * link.flexural_rigidity * np.abs(y_c_a) / x_c_a**3)


def base_torque(link: Link, x_c: ArrayLike, y_c: ArrayLike) -> FloatArray:
    """Eq. 12: magnitude of the base torque |Gamma| = 3 E I |y_c| / x_c^2 (N m).

    ``x_c`` in (0, l] (m) and ``y_c`` (m) broadcast together.
    """
    x_c_a = contact_ratio(link, x_c) * link.length
    y_c_a = as_finite_array("y_c", y_c)
    # Eq. 12
    return np.asarray(3.0 * link.flexural_rigidity * np.abs(y_c_a) / x_c_a**2)


def torque_force_ratio(link: Link, x_c: ArrayLike, y_c: ArrayLike) -> FloatArray:
    """Eq. 18: |Gamma| / |F| (m) of the static push; equals x_c wherever y_c != 0."""
    # Eq. 18: x_c = |Gamma| / |F|
    return np.asarray(base_torque(link, x_c, y_c) / base_force(link, x_c, y_c))


def contact_deflection_from_force(link: Link, x_c: ArrayLike, force: ArrayLike) -> FloatArray:
    """Eq. 13 inverted: contact deflection y_c = |F| x_c^3 / (3 E I) (m) for a base force (N).

    ``force`` is a magnitude (>= 0, N); ``x_c`` in (0, l] (m); they broadcast together.
    """
    x_c_a = contact_ratio(link, x_c) * link.length
    force_a = as_finite_array("force", force, low=0.0)
    # Eq. 13 solved for y_c
    return np.asarray(force_a * x_c_a**3 / (3.0 * link.flexural_rigidity))
