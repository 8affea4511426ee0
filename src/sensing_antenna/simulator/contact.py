"""Rigid obstacles in the absolute frame, their placement from x_c, and the contact geometry.

An obstacle is a cylinder (post: near-vertical axis; bar: near-horizontal axis), a ball or a
plane. The gap between a point p and the obstacle is ``distance(p, axis) - R`` for a cylinder,
``|p - C| - R`` for a ball of centre C and ``(p - P0) . n`` for a plane; the outward normal
points from the obstacle towards p. A cylinder is curved across the link only: a link pushed
along its axis (a post leaning out of the sweep's plane beyond the friction cone) slides along
it as along a straight edge. A ball is curved both ways, as a rounded object is: sliding, the
contact stays on its surface. The contact
law itself (penalty normal force with damping, tangential stick spring, Coulomb slip) lives in the
time loop of :mod:`sensing_antenna.simulator.integrator`; the functions here are shared with it.

Placement. The scenario gives x_c, where the gravity-sagged, otherwise undeflected link touches
the obstacle at the nominal touch angles. With the link point P = p(x_c) and the link tangent e at
P, a cylinder of axis direction a touches the link tangentially at P when its outward normal is
``n = +-(e x a) / |e x a|`` (gap stationary along the link: n . e = 0) and its axis passes through
``C = P - R n``. The sign puts the obstacle ahead of the sweep. A plane touches a straight link at
an end, so a plane obstacle is placed through the tip and needs x_c = l.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.simulator.scenario import ScenarioError

__all__ = [
    "BALL",
    "CYLINDER",
    "NO_OBSTACLE",
    "PLANE",
    "Obstacle",
    "motor_frame",
    "place_obstacle",
]

NO_OBSTACLE = 0
CYLINDER = 1
PLANE = 2
BALL = 3

#: Angle (rad) between a plane's normal and the sweep direction, in the sweep plane: the link
#: meets the plane at 90 degrees minus this, so the plane clears the rest of the link by
#: (l - x) sin(PLANE_INCIDENCE) at the touch.
PLANE_INCIDENCE = 0.3


def motor_frame(theta1: float, theta2: float) -> NDArray[np.float64]:
    """Rows X^m, Y^m, Z^m in absolute coordinates (recording format), shape (3, 3)."""
    c1, s1 = math.cos(theta1), math.sin(theta1)
    c2, s2 = math.cos(theta2), math.sin(theta2)
    return np.array([[c2 * c1, c2 * s1, s2], [-s1, c1, 0.0], [-s2 * c1, -s2 * s1, c2]])


@dataclass(frozen=True)
class Obstacle:
    """A rigid obstacle in the absolute frame.

    Attributes
    ----------
    kind : str
        "post", "bar", "ball" or "plane".
    point : tuple of 3 float
        A point of the cylinder axis, the ball's centre, or a point of the plane (m).
    direction : tuple of 3 float
        Unit axis of the cylinder, unit outward normal of the plane, or of the ball at the
        nominal touch.
    radius : float
        Cylinder or ball radius (m); 0 for a plane.
    """

    kind: str
    point: tuple[float, float, float]
    direction: tuple[float, float, float]
    radius: float

    def as_array(self) -> NDArray[np.float64]:
        """Packed form for the compiled loop: [kind, point(3), direction(3), radius]."""
        code = {"plane": PLANE, "ball": BALL}.get(self.kind, CYLINDER)
        return np.array([code, *self.point, *self.direction, self.radius], dtype=np.float64)

    def gap(self, point: NDArray[np.float64]) -> float:
        """Signed distance of ``point`` (3,) (m) outside the obstacle (negative inside)."""
        p0 = np.asarray(self.point)
        a = np.asarray(self.direction)
        d = np.asarray(point, dtype=float) - p0
        if self.kind == "plane":
            return float(d @ a)
        if self.kind == "ball":
            return float(np.linalg.norm(d) - self.radius)
        perp = d - (d @ a) * a
        return float(np.linalg.norm(perp) - self.radius)

    def outward_normals(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Unit outward normals (n, 3) at the obstacle's surface points nearest ``points``
        (n, 3) (m): the gradient of :meth:`gap` (NaN on a cylinder's axis or a ball's centre)."""
        d = np.asarray(points, dtype=float).reshape(-1, 3) - np.asarray(self.point)
        a = np.asarray(self.direction)
        if self.kind == "plane":
            return np.tile(a, (len(d), 1))
        if self.kind != "ball":
            d = d - np.outer(d @ a, a)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.asarray(d / np.linalg.norm(d, axis=1, keepdims=True))

    def to_json(self) -> str:
        """JSON text for the recording's ``true_obstacle`` metadata."""
        return json.dumps(
            {
                "kind": self.kind,
                "point": [round(v, 12) for v in self.point],
                "direction": [round(v, 12) for v in self.direction],
                "radius": self.radius,
            }
        )


def _unit(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.asarray(v / np.linalg.norm(v))


def place_obstacle(
    kind: str,
    contact_point: float,
    length: float,
    theta_touch: tuple[float, float],
    sag: float,
    sag_slope: float,
    radius: float,
    tilt: float,
    sweep_joint: int,
    direction: int = 1,
) -> Obstacle:
    """Place an obstacle that the sagged link touches at ``contact_point`` at ``theta_touch``.

    Parameters
    ----------
    kind : str
        "post", "bar", "ball" or "plane".
    contact_point : float
        x_c (m).
    length : float
        Link length l (m).
    theta_touch : (float, float)
        Motor angles at the nominal first touch (rad).
    sag, sag_slope : float
        Static gravity deflection w(x_c) (m) and slope w'(x_c) along Z^m at the touch angles.
    radius : float
        Cylinder or ball radius (m).
    tilt : float
        Misalignment (rad): post leans along the sweep; bar rolls about X^m; plane normal turns
        out of the sweep plane; a ball's normal at the touch turns as the post's (azimuthal
        sweep) or the bar's (vertical sweep) does.
    sweep_joint : int
        0 when theta1 sweeps (towards +Y^m), 1 when theta2 sweeps (towards +Z^m).
    direction : {1, -1}
        The sweep's sense: -1 turns the joint down, towards -Y^m or -Z^m.

    Returns
    -------
    Obstacle
    """
    frame = motor_frame(*theta_touch)
    xm, ym, zm = frame
    ahead = direction * (ym if sweep_joint == 0 else zm)
    aside = zm if sweep_joint == 0 else ym
    p_touch = contact_point * xm + sag * zm
    tangent = _unit(xm + sag_slope * zm)
    if kind == "plane":
        if not math.isclose(contact_point, length, rel_tol=1e-9):
            raise ScenarioError(
                "contact_point", f"a plane is touched by the link tip: needs x_c = l = {length:g} m"
            )
        # Normal against the sweep, turned by PLANE_INCIDENCE back towards the head (n . e < 0),
        # and by ``tilt`` out of the sweep plane: the head lies outside the plane, and along the
        # link the gap (l - x) sin(PLANE_INCIDENCE) is smallest at the tip, so the tip touches
        # first and the rest of the link stays clear.
        normal = _unit(
            -ahead * math.cos(PLANE_INCIDENCE)
            - tangent * math.sin(PLANE_INCIDENCE)
            + aside * math.tan(tilt)
        )
        return Obstacle("plane", tuple(p_touch), tuple(normal), 0.0)
    post = kind == "post" or (kind == "ball" and sweep_joint == 0)
    # the post leans along the sweep, the bar rolls so that the normal turns towards +Y^m:
    # either way the normal's part out of the sweep's plane is +sin(tilt) whatever the sense
    if post:
        axis = _unit(np.array([0.0, 0.0, 1.0]) * math.cos(tilt) + direction * ym * math.sin(tilt))
    else:
        axis = _unit(ym * math.cos(tilt) + direction * zm * math.sin(tilt))
    normal = _unit(np.cross(tangent, axis))
    if normal @ ahead > 0:
        normal = -normal
    centre = p_touch - radius * normal
    if kind == "ball":
        # the cylinder's normal at the touch: the ball of that radius tangent to the link there
        return Obstacle(kind, tuple(centre), tuple(normal), radius)
    return Obstacle(kind, tuple(centre), tuple(axis), radius)
