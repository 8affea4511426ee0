"""Rigid obstacles in the absolute frame, their placement from x_c, and the contact geometry.

An obstacle is an endless cylinder (post: near-vertical axis; bar: near-horizontal axis), a
ball, a plane, or, placed explicitly (``Scenario.obstacle_placement``), a capsule, a capped
cylinder, a box, a cone or a torus. The gap between a point p and the obstacle is its signed
distance: ``distance(p, axis) - R`` for an endless cylinder, ``|p - C| - R`` for a ball of
centre C, ``(p - P0) . n`` for a plane, the distance to the axis's segment less R for a
capsule, the exact distance to a capped cylinder (its side, its end discs, or its rim beyond
both), and for a box, a cone or a torus the exact distance to the solid (in its own frame, as
``mapping.primitives`` has it) less a rounding radius: the solid grown by the link's radius,
its edges, rim and apex rounded by it. The outward normal is the distance's gradient, pointing
from the obstacle towards p. A cylinder is
curved across the link only: a link pushed along its axis (a post leaning out of the sweep's
plane beyond the friction cone) slides along it as along a straight edge. A ball is curved both
ways, as a rounded object is: sliding, the contact stays on its surface. The contact
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

from sensing_antenna.compiler import njit
from sensing_antenna.simulator.scenario import SIZED_KINDS, ScenarioError

__all__ = [
    "BALL",
    "BOX",
    "CAPPED_CYLINDER",
    "CAPSULE",
    "CONE",
    "CYLINDER",
    "NO_OBSTACLE",
    "PLANE",
    "TORUS",
    "Obstacle",
    "distance_and_normal",
    "distances_and_normals",
    "motor_frame",
    "place_obstacle",
    "place_solid",
]

NO_OBSTACLE = 0
CYLINDER = 1
PLANE = 2
BALL = 3
CAPSULE = 4
CAPPED_CYLINDER = 5
BOX = 6
CONE = 7
TORUS = 8

#: The codes of the compiled loop by obstacle kind (an endless cylinder otherwise).
_CODES = {
    "plane": PLANE,
    "ball": BALL,
    "capsule": CAPSULE,
    "cylinder": CAPPED_CYLINDER,
    "box": BOX,
    "cone": CONE,
    "torus": TORUS,
}

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
        "post", "bar" (endless cylinders), "ball", "plane", "capsule", "cylinder" (capped),
        "box", "cone" or "torus".
    point : tuple of 3 float
        A point of the endless cylinder's axis, the ball's centre, a point of the plane, the
        capsule's, the capped cylinder's, the box's or the torus's centre, or the centre of the
        cone's base (m).
    direction : tuple of 3 float
        Unit axis of a cylinder, a capsule, a cone (towards its apex) or a torus, the box's
        local Z, unit outward normal of the plane, or of the ball at the nominal touch.
    radius : float
        Radius of a cylinder, a ball or a capsule (m); 0 for a plane.
    half_length : float
        Half the capsule's axis segment, half the capped cylinder's height (m); 0 otherwise.
    rounding : float
        Radius (m) the capped cylinder's rim is rounded by: it is its core, ``rounding``
        thinner and shorter at each end, grown by ``rounding`` (a cylinder grown by the link's
        radius); what a box, a cone or a torus is grown by (m); 0 otherwise.
    axes : tuple of 9 float
        A box's, a cone's or a torus's own X, Y and Z axes (rows, unit, absolute frame; Z the
        ``direction``); empty otherwise.
    sizes : tuple of float
        The solid's own sizes before ``rounding`` (m): a box's three edge lengths along its
        axes, a cone's base radius and height, a torus's major and minor radii; empty
        otherwise.
    """

    kind: str
    point: tuple[float, float, float]
    direction: tuple[float, float, float]
    radius: float
    half_length: float = 0.0
    rounding: float = 0.0
    axes: tuple[float, ...] = ()
    sizes: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if self.kind in SIZED_KINDS:  # a box, a cone, a torus: a frame of its own and sizes
            frame = np.asarray(self.axes, dtype=float)
            if frame.shape != (9,) or not np.allclose(
                frame.reshape(3, 3) @ frame.reshape(3, 3).T, np.eye(3), atol=1e-9
            ):
                raise ValueError(f"Obstacle: a {self.kind} needs orthonormal axes, 9 numbers")
            count = SIZED_KINDS[self.kind]
            if len(self.sizes) != count or not all(v > 0.0 for v in self.sizes):
                raise ValueError(f"Obstacle: a {self.kind} needs {count} sizes > 0 m")
            if not self.rounding >= 0.0:
                raise ValueError(f"Obstacle: rounding {self.rounding!r} m must be >= 0")
            return
        # a rim rounded by more than the radius or the half length has no core cylinder
        largest = min(self.radius, self.half_length)
        if self.rounding != 0.0 and not 0.0 < self.rounding <= largest:
            raise ValueError(
                f"Obstacle: rounding {self.rounding!r} m must lie in [0, {largest!r}] m (the"
                " radius and the half length)"
            )

    def as_array(self) -> NDArray[np.float64]:
        """Packed form for the compiled loop: [code, point(3), direction(3), radius, half
        length, rounding, axes (9, rows), sizes (3, a box's halved; zeros when unused)]."""
        code = _CODES.get(self.kind, CYLINDER)
        values = [code, *self.point, *self.direction, self.radius]
        axes = list(self.axes) if self.axes else [0.0] * 9
        sizes = list(self.sizes) + [0.0] * (3 - len(self.sizes))
        if self.kind == "box":
            sizes = [0.5 * v for v in sizes]
        return np.array([*values, self.half_length, self.rounding, *axes, *sizes], dtype=np.float64)

    def gap(self, point: NDArray[np.float64]) -> float:
        """Signed distance of ``point`` (3,) (m) outside the obstacle (negative inside)."""
        return float(self._distances(np.asarray(point, dtype=float).reshape(1, 3))[0][0])

    def outward_normals(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """Unit outward normals (n, 3) at the obstacle's surface points nearest ``points``
        (n, 3) (m): the gradient of :meth:`gap` (zero on a cylinder's or a capsule's axis or
        at a ball's centre)."""
        return self._distances(np.asarray(points, dtype=float).reshape(-1, 3))[1]

    def _distances(self, points: NDArray[np.float64]) -> tuple[NDArray[np.float64], ...]:
        """Signed distances (n,) and outward unit normals (n, 3) of ``points`` (n, 3), as the
        compiled loop computes them (:func:`distance_and_normal`)."""
        return distances_and_normals(np.ascontiguousarray(points), self.as_array())

    def to_json(self) -> str:
        """JSON text for the recording's ``true_obstacle`` metadata."""
        data: dict[str, object] = {
            "kind": self.kind,
            "point": [round(v, 12) for v in self.point],
            "direction": [round(v, 12) for v in self.direction],
            "radius": self.radius,
        }
        if self.half_length:
            data["half_length"] = self.half_length
        if self.rounding:
            data["rounding"] = self.rounding
        if self.axes:
            data["axes"] = [round(v, 12) for v in self.axes]
            data["sizes"] = list(self.sizes)
        return json.dumps(data)


# inlined into its callers: the time loop's gap search uses the distance alone, and only
# inlined does the compiler drop the normal's arithmetic there (a post's contact run took 9 %
# longer with a call)
@njit(cache=True, inline="always")
def distance_and_normal(
    px: float, py: float, pz: float, obst: NDArray[np.float64]
) -> tuple[float, float, float, float]:
    """Signed distance (m) from the obstacle's surface of the point (px, py, pz) taken from
    the obstacle's point, and the outward unit normal there, (distance, nx, ny, nz): the
    distance's gradient, zero where it is undefined (a ball's centre, a cylinder's or a
    capsule's axis). ``obst`` is ``Obstacle.as_array()``: [code, point (3), direction (3),
    radius, half length, rounding, axes (9), sizes (3)]: a capped cylinder's rim is rounded
    by the rounding radius (its side and ends as the radius and half length say); a box, a
    cone or a torus is its solid grown by the rounding radius."""
    if obst[0] >= 6.0:
        return _solid_distance_and_normal(px, py, pz, obst)
    ax, ay, az = obst[4], obst[5], obst[6]
    along = px * ax + py * ay + pz * az
    if obst[0] == 2.0:  # plane
        return along, ax, ay, az
    if obst[0] == 3.0:  # ball
        along = 0.0
    elif obst[0] == 4.0:  # capsule: the nearest point of its segment
        along = min(max(along, -obst[8]), obst[8])
    qx, qy, qz = px - along * ax, py - along * ay, pz - along * az
    rho = math.sqrt(qx * qx + qy * qy + qz * qz)
    scale = 1.0 / rho if rho > 0.0 else 0.0
    if obst[0] != 5.0:  # ball, endless cylinder, capsule
        return rho - obst[7], qx * scale, qy * scale, qz * scale
    # capped cylinder: how far beyond the side (dr) and beyond the nearer end (da) of its
    # core, the cylinder the rounding grows to it
    dr = rho - (obst[7] - obst[9])
    da = abs(along) - (obst[8] - obst[9])
    end = 1.0 if along >= 0.0 else -1.0
    if dr > 0.0 and da > 0.0:  # beyond the rim
        distance = math.sqrt(dr * dr + da * da)
        side, cap = dr / distance * scale, da / distance * end
        normal_x, normal_y, normal_z = (
            side * qx + cap * ax,
            side * qy + cap * ay,
            side * qz + cap * az,
        )
        return distance - obst[9], normal_x, normal_y, normal_z
    if dr > da:
        return dr - obst[9], qx * scale, qy * scale, qz * scale
    return da - obst[9], end * ax, end * ay, end * az


@njit(cache=True)
def _solid_distance_and_normal(
    px: float, py: float, pz: float, obst: NDArray[np.float64]
) -> tuple[float, float, float, float]:
    """:func:`distance_and_normal` of a box, a cone or a torus: in the solid's own frame
    (local = axes @ p), the exact distance to it and its gradient, less the rounding."""
    lx = obst[10] * px + obst[11] * py + obst[12] * pz
    ly = obst[13] * px + obst[14] * py + obst[15] * pz
    lz = obst[16] * px + obst[17] * py + obst[18] * pz
    if obst[0] == 6.0:  # box of half extents sizes: how far beyond each pair of faces
        qx, qy, qz = abs(lx) - obst[19], abs(ly) - obst[20], abs(lz) - obst[21]
        sx = 1.0 if lx >= 0.0 else -1.0
        sy = 1.0 if ly >= 0.0 else -1.0
        sz = 1.0 if lz >= 0.0 else -1.0
        if qx > 0.0 or qy > 0.0 or qz > 0.0:
            mx, my, mz = max(qx, 0.0), max(qy, 0.0), max(qz, 0.0)
            core = math.sqrt(mx * mx + my * my + mz * mz)
            nx, ny, nz = sx * mx / core, sy * my / core, sz * mz / core
        elif qx >= qy and qx >= qz:
            core, nx, ny, nz = qx, sx, 0.0, 0.0
        elif qy >= qz:
            core, nx, ny, nz = qy, 0.0, sy, 0.0
        else:
            core, nx, ny, nz = qz, 0.0, 0.0, sz
    else:
        rho = math.sqrt(lx * lx + ly * ly)
        # the radial direction; on the axis any (the distance's gradient is undefined there)
        cx, cy = (lx / rho, ly / rho) if rho > 0.0 else (1.0, 0.0)
        if obst[0] == 7.0:  # cone: its half-section is the triangle (0, 0), (R, 0), (0, h)
            radius, height = obst[19], obst[20]
            # nearest points of the base (0, 0)-(R, 0) and of the slant (R, 0)-(0, h)
            br, bz = rho - min(rho, radius), lz
            t = ((radius - rho) * radius + lz * height) / (radius * radius + height * height)
            t = min(max(t, 0.0), 1.0)
            sr, sz_ = rho - radius * (1.0 - t), lz - height * t
            base, slant = math.hypot(br, bz), math.hypot(sr, sz_)
            dr, dz, nearest = (br, bz, base) if base <= slant else (sr, sz_, slant)
            if nearest == 0.0:  # on the surface itself: that face's own normal
                scale = 1.0 / math.hypot(height, radius)
                gr, gz = (0.0, -1.0) if base <= slant else (height * scale, radius * scale)
                core = 0.0
            elif lz >= 0.0 and rho * height + lz * radius <= radius * height:  # inside
                core, gr, gz = -nearest, -dr / nearest, -dz / nearest
            else:
                core, gr, gz = nearest, dr / nearest, dz / nearest
        else:  # torus of major radius sizes[0], minor sizes[1]
            dr, dz = rho - obst[19], lz
            tube = math.sqrt(dr * dr + dz * dz)
            core = tube - obst[20]
            gr, gz = (dr / tube, dz / tube) if tube > 0.0 else (1.0, 0.0)
        nx, ny, nz = gr * cx, gr * cy, gz
    # back to the absolute frame: the axes are the rows
    normal_x = nx * obst[10] + ny * obst[13] + nz * obst[16]
    normal_y = nx * obst[11] + ny * obst[14] + nz * obst[17]
    normal_z = nx * obst[12] + ny * obst[15] + nz * obst[18]
    return core - obst[9], normal_x, normal_y, normal_z


@njit(cache=True)
def distances_and_normals(
    points: NDArray[np.float64], obst: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`distance_and_normal` of each of ``points`` (n, 3) (m, absolute frame): the
    signed distances (n,) and the outward unit normals (n, 3)."""
    n = points.shape[0]
    distances = np.empty(n)
    normals = np.empty((n, 3))
    for i in range(n):
        distances[i], normals[i, 0], normals[i, 1], normals[i, 2] = distance_and_normal(
            points[i, 0] - obst[1], points[i, 1] - obst[2], points[i, 2] - obst[3], obst
        )
    return distances, normals


def _unit(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.asarray(v / np.linalg.norm(v))


def place_solid(
    kind: str, placement: NDArray[np.float64], sizes: tuple[float, ...], rounding: float
) -> Obstacle:
    """A box, a cone or a torus placed as ``Scenario.obstacle_placement`` says (its centre, or
    the cone's base centre, its Z axis, and a box's X axis, made perpendicular to Z), of its
    own ``sizes`` (m), grown by ``rounding`` (m)."""
    z_axis = placement[3:6] / np.linalg.norm(placement[3:6])
    if kind == "box":
        x_axis = placement[6:9] - (placement[6:9] @ z_axis) * z_axis
    else:  # symmetric about Z: any X across it
        x_axis = np.cross(z_axis, np.eye(3)[int(np.argmin(np.abs(z_axis)))])
    x_axis = x_axis / np.linalg.norm(x_axis)
    axes = np.vstack([x_axis, np.cross(z_axis, x_axis), z_axis])
    return Obstacle(
        kind,
        tuple(placement[:3]),
        tuple(z_axis),
        0.0,
        rounding=rounding,
        axes=tuple(axes.reshape(-1)),
        sizes=tuple(sizes),
    )


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
    lateral: tuple[float, float] = (0.0, 0.0),
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
    lateral : (float, float)
        A bowed link's rest shape along Y^m at x_c, its offset (m) and slope (the vertical
        bow's part is in ``sag``). Default 0.

    Returns
    -------
    Obstacle
    """
    frame = motor_frame(*theta_touch)
    xm, ym, zm = frame
    ahead = direction * (ym if sweep_joint == 0 else zm)
    aside = zm if sweep_joint == 0 else ym
    # a bowed link's rest shape lies along Y^m by lateral[0], at the slope lateral[1]
    p_touch = contact_point * xm + lateral[0] * ym + sag * zm
    tangent = _unit(xm + lateral[1] * ym + sag_slope * zm)
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
