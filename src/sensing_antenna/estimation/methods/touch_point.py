"""The touched point in 3D (Section 4, step 7, made explicit).

The contact lies at the arc length x_c along the link. The link is bent by the reaction R of the
object, so the contact is displaced from the rigid line x_c X^m: it is the loaded end of a
cantilever of length x_c under the end load R (the planar elastica,
:func:`~sensing_antenna.beam.elastica.loaded_end`; exact for any deflection), at x along X^m and
y_c along u, the direction of the reaction's part across the link: the cantilever deflects along
the load it carries, i.e. towards where the link came from (the object holds the contact back
while the rigid line of the motor angles has moved on into the object). In the small-deflection
limit y_c = |R_perp| x_c^3 / (3 E I) (Eq. 13) and x = x_c; at a deflection of 30 % of x_c the
contact lies 5 to 6 % of x_c nearer the base along X^m than x_c.

The link also carries its own weight: the sag of a uniformly loaded cantilever,
v(x) = q x^2 (6 l^2 - 4 l x + x^2) / (24 E I) with q = rho g cos(theta2) the weight per length
perpendicular to the link (standard handbook result, e.g. Gere and Timoshenko, Mechanics of
Materials, cantilever under uniform load), directed along the part of -Z^a perpendicular to X^m,
added to the push's displacement (the weight handled as a free link's, as everywhere in the
estimators). Near the tip of the paper's link it reaches 5 cm, as large as the push deflection;
the paper's Assumption 5 neglects it. Both use one stiffness, 1 / (E I) =
:attr:`~sensing_antenna.antenna.Link.bending_compliance` (rho / T^2 with the frequency model's T:
a calibrated T_e measures it). The point is expressed in the absolute frame with the motor axes
(X^m, Y^m, Z^m of the recording format) of the frame it is placed in: at the instant the point
describes, as the reaction it bends along (a servo holding the head yields a little under the
push, by about a milliradian on the simulated head, half a millimetre at x_c = 0.5 m).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import STANDARD_GRAVITY, Link
from sensing_antenna.beam.elastica import loaded_end
from sensing_antenna.estimation.front.contact_frame import ContactFrame

if TYPE_CHECKING:
    from sensing_antenna.estimation.front.evidence import Evidence

__all__ = ["TouchPoint", "placement", "touched_point", "touched_point_filtered"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class TouchPoint:
    """The touched point.

    Attributes
    ----------
    point_a : array, shape (3,)
        Contact point in the absolute frame (m).
    deflection : float
        Static deflection y_c at the contact across the link (m).
    deflection_ratio : float
        y_c / x_c (dimensionless); Assumption 1 of the paper (linear statics) asks for less
        than 10 %, the elastica here holds beyond.
    sag : float
        Gravity sag of the link at x_c (m).
    """

    point_a: FloatArray
    deflection: float
    deflection_ratio: float
    sag: float = math.nan


def touched_point(
    x_c: float, frame: ContactFrame, push_force: float, link: Link, axial_force: float = 0.0
) -> TouchPoint:
    """Absolute position of the touched point.

    Parameters
    ----------
    x_c : float
        Contact point along the link, arc length (m).
    frame : ContactFrame
        The motor angles and Y^c along the reaction at the instant the point describes
        (``ContactFrame.turned_to``); the push's direction across the link is Y^c without its
        part along X^m.
    push_force : float
        |R_perp|, the reaction perpendicular to the link (N), e.g. filtered at t_e.
    link : Link
        Supplies 1 / (E I) (:attr:`~sensing_antenna.antenna.Link.bending_compliance`, the
        stiffness the frequency model and the sag use).
    axial_force : float
        R_x, the reaction's part along X^m (N); its moment bends the link too.

    Returns
    -------
    TouchPoint
        NaN point when x_c is not a finite point of the link or the push lies beyond the
        elastica's table.
    """
    nan = TouchPoint(np.full(3, np.nan), math.nan, math.nan)
    if not (math.isfinite(x_c) and 0.0 < x_c <= link.length and math.isfinite(push_force)):
        return nan
    axial = axial_force if math.isfinite(axial_force) else 0.0
    end = loaded_end(x_c, axial, max(push_force, 0.0), 1.0 / link.bending_compliance)
    if not math.isfinite(end.x):
        return nan
    # The push's direction across the link: Y^c without its part along X^m
    across_push = frame.axes_m[1] - frame.axes_m[1][0] * np.array([1.0, 0.0, 0.0])
    norm = float(np.linalg.norm(across_push))
    u = across_push / norm if norm > 0.0 else frame.axes_m[1]
    point_m = np.array([end.x, 0.0, 0.0]) + end.y * u
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
    return TouchPoint(point_a=point_a, deflection=end.y, deflection_ratio=end.y / x_c, sag=sag)


def placement(touch: TouchPoint, frame: ContactFrame, t_point: float) -> dict[str, Any]:
    """The diagnostics every method reports of where its point was placed: the push deflection
    ``deflection`` (m) and ``deflection_ratio``, the frame ``axes_c_absolute`` (rows X^c, Y^c,
    Z^c in the absolute frame) and ``theta_at_point`` (the motor angles, rad) it was placed in,
    and the instant ``t_point`` (s) it describes; a map's covariance reads them."""
    return {
        "deflection": touch.deflection,
        "deflection_ratio": touch.deflection_ratio,
        "axes_c_absolute": frame.axes_a,
        "theta_at_point": frame.theta,
        "t_point": t_point,
    }


def touched_point_filtered(
    evidence: Evidence, x_c: float, index: int
) -> tuple[TouchPoint, ContactFrame, float]:
    """The touched point at ``x_c`` (m) placed with the front end's filtered reaction at sample
    ``index``, the frame it was placed in and the instant it describes (s, not before t_1): the
    first-order low-pass's output lags its input by 1 / omega_c on average, a contact that
    slides along the surface turns the reaction the link bends along, and a servo that yields
    under the push turns the head. Y^c is turned to that reaction, and the head is at its motor
    angles weighted as the low-pass weighs its input, exp(-omega_c age), cut off at t_1: the
    head still turns into the object before t_1, and the reaction's content from before t_1
    weighs exp(-omega_c (t - t_1)) of it (under 1 % a second after t_1). A reaction whose
    direction across the link is undefined leaves the hold's frame and instant."""
    reaction = evidence.reaction_f[index]
    start = min(evidence.rest_index, index)
    age = evidence.t[index] - evidence.t[start : index + 1]
    weights = np.exp(-evidence.config.lowpass_cutoff * age)
    theta = weights @ evidence.theta[start : index + 1] / np.sum(weights)
    frame = evidence.frame.turned_to(reaction, theta)
    t_1 = float(evidence.t[evidence.rest_index])
    if frame is None:
        frame, t_point = evidence.frame, t_1 + 0.5 * evidence.config.frame_window
    else:
        t_point = max(float(evidence.t[index]) - 1.0 / evidence.config.lowpass_cutoff, t_1)
    push = math.hypot(reaction[1], reaction[2])
    touch = touched_point(x_c, frame, push, evidence.antenna.link, float(reaction[0]))
    return touch, frame, t_point
