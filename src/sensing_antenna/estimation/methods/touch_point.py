"""The touched point in 3D (Section 4, step 7, made explicit).

The contact lies at the abscissa x_c along the link. The link is bent by the reaction R of the
object, so the contact is displaced from the rigid line x_c X^m by the static deflection of a
cantilever loaded at x_c, y_c = |R_perp| x_c^3 / (3 E I) (Eq. 13 solved for y_c), in the direction
of the load R, i.e. along +Y^c: the object holds the contact back while the rigid line of the
motor angles has moved on into the object. (The brief of this module said "minus Y^c"; the
cantilever deflects along the load it carries, which is the reaction R, so the sign here is +.)

The link also carries its own weight. The beam is linear (Section 3.3), so the displacement at
x_c is the sum of the push deflection and the sag of a uniformly loaded cantilever,
v(x) = q x^2 (6 l^2 - 4 l x + x^2) / (24 E I) with q = rho g cos(theta2) the weight per length
perpendicular to the link (standard handbook result, e.g. Gere and Timoshenko, Mechanics of
Materials, cantilever under uniform load), directed along the part of -Z^a perpendicular to X^m.
Near the tip of the paper's link it reaches 5 cm, as large as the push deflection; the paper's
Assumption 5 neglects it. The point is expressed in the absolute frame with the motor axes at t_1
(X^m, Y^m, Z^m of the recording format).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import STANDARD_GRAVITY, Link
from sensing_antenna.estimation.front.contact_frame import ContactFrame

__all__ = ["TouchPoint", "touched_point"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class TouchPoint:
    """The touched point.

    Attributes
    ----------
    point_a : array, shape (3,)
        Contact point in the absolute frame (m).
    deflection : float
        Static deflection y_c at the contact (m).
    deflection_ratio : float
        y_c / x_c (dimensionless), to compare with the 10 % limit of Assumption 1.
    sag : float
        Gravity sag of the link at x_c (m).
    """

    point_a: FloatArray
    deflection: float
    deflection_ratio: float
    sag: float = math.nan


def touched_point(x_c: float, frame: ContactFrame, push_force: float, link: Link) -> TouchPoint:
    """Absolute position of the touched point.

    Parameters
    ----------
    x_c : float
        Contact point along the link (m).
    frame : ContactFrame
        Contact frame at t_1 (axes and motor angles).
    push_force : float
        |R_perp|, the reaction perpendicular to the link (N), e.g. filtered at t_e.
    link : Link
        Supplies 1 / (E I) (:attr:`~sensing_antenna.antenna.Link.bending_compliance`, the
        stiffness the frequency model and the sag use).

    Returns
    -------
    TouchPoint
        NaN point when x_c is not a finite point of the link.
    """
    if not (math.isfinite(x_c) and 0.0 < x_c <= link.length and math.isfinite(push_force)):
        return TouchPoint(np.full(3, np.nan), math.nan, math.nan)
    # Eq. 13 solved for y_c: y_c = |F| x_c^3 / (3 E I), with the E I of the sag below (the
    # link's bending compliance: a calibrated T_e measures the stiffness of both)
    y_c = push_force * x_c**3 * link.bending_compliance / 3.0
    # Rigid abscissa along X^m plus the deflection along Y^c, in motor coordinates
    point_m = np.array([x_c, 0.0, 0.0]) + y_c * frame.axes_m[1]
    point_a = point_m @ frame.motor_axes_a
    # Gravity sag: -Z^a without its component along X^m, times the cantilever deflection
    down = np.array([0.0, 0.0, -1.0])
    x_axis = frame.motor_axes_a[0]
    across = down - (down @ x_axis) * x_axis
    across_norm = float(np.linalg.norm(across))
    sag = 0.0
    if across_norm > 0.0:
        # The cantilever's sag at x_c under the weight's part across the link
        sag = STANDARD_GRAVITY * across_norm * float(link.unit_sag(x_c))
        point_a = point_a + sag * across / across_norm
    return TouchPoint(point_a=point_a, deflection=y_c, deflection_ratio=y_c / x_c, sag=sag)
