"""Where a sweep's link first touches a scene: the angle, x_c, the surface point and normal.

The link is sampled along its length (:class:`~sensing_antenna.scene.sweep.LinkShape`) and
g(theta) = min over the samples of the scene's signed distance, less the link's radius a (a round
link touches with its surface, a off its axis), is followed from the sweep's first angle in its
direction. No point of the link moves faster than its reach r (m per rad of either
joint), so the link cannot meet a surface before the joint has turned g / r further: the search
advances by that much (conservative advancement, the sphere tracing of signed-distance
rendering), at least :data:`MIN_STEP`, until g <= 0, then bisects the last step to
:data:`ANGLE_TOLERANCE`. x_c is the sample nearest the surface refined by a bounded scalar
minimisation between its neighbours; at the tip's sample the contact is the tip's.

The local radius R of the surface along the link, which the simulator's equivalent cylinder
takes, comes from the distance d(+-h) of the points h = :data:`CURVATURE_PROBE` to either side
of the touched point along the link's direction in the tangent plane: a circle of radius R
curves away by d = sqrt(R^2 + h^2) - R, so R = (h^2 - d^2) / (2 d) with d the mean of the two;
exact on a circular section, small at an edge, and capped to [:data:`MIN_RADIUS`,
:data:`MAX_RADIUS`]. The same probe in :data:`BEND_DIRECTIONS` directions of the tangent plane
gives the surface's principal radii, its smallest and largest radius over the directions: equal
on a sphere; on a cylinder's side, or at an edge, the radius across the axis and one many times
larger (the direction nearest the axis is at most half a step off it), whichever way the link
crosses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize_scalar

from sensing_antenna.mapping.pose import BasePose
from sensing_antenna.scene.file import Scene
from sensing_antenna.scene.objects import SceneObject
from sensing_antenna.scene.sweep import LinkShape, Sweep

__all__ = [
    "ANGLE_TOLERANCE",
    "BEND_DIRECTIONS",
    "CURVATURE_PROBE",
    "MAX_RADIUS",
    "MIN_RADIUS",
    "MIN_STEP",
    "SweepGeometry",
    "Touch",
    "first_touch",
]

FloatArray = NDArray[np.float64]

#: Smallest advance of the search (rad): 0.1 mm at 1 m; it only binds within that of a surface.
MIN_STEP = 1e-4

#: The touch angle's bisection stops within this (rad): 1 nm at 1 m.
ANGLE_TOLERANCE = 1e-9

#: Distance to either side of the touched point at which the surface's bend is measured (m):
#: 2 mm, small against the objects (radii of centimetres) and large against the face size of
#: a fine mesh's facets (a 256-gon of 1 cm radius has 0.25 mm facets).
CURVATURE_PROBE = 0.002

#: Smallest local radius (m): an edge's; the simulator needs a positive one.
MIN_RADIUS = 0.001

#: Largest local radius (m): a flat face's, the simulator's largest obstacle radius.
MAX_RADIUS = 10.0

#: Directions of the tangent plane, evenly over half a turn, in which the principal radii are
#: looked for: 22.5 degrees apart, so an edge's straight direction is met within 11.25 degrees,
#: where its bend is at most sin(11.25 deg) = 0.2 of the largest (a wedge's bend grows as the
#: sine of the angle off its edge).
BEND_DIRECTIONS = 8


@dataclass(frozen=True)
class Touch:
    """The first contact of a sweep with a scene.

    Attributes
    ----------
    angle : float
        The swept joint's angle at the touch (rad).
    angles : (float, float)
        (theta1, theta2) at the touch (rad).
    x_c : float
        Where along the link it touches (m); the link's length at the tip.
    link_point : array, shape (3,)
        The link's axis there, world frame (m): the link's radius off the surface.
    surface_point : array, shape (3,)
        The nearest point of the surface, world frame (m).
    normal : array, shape (3,)
        The surface's outward unit normal there (world frame).
    tangent : array, shape (3,)
        The link's unit tangent there (world frame).
    radius : float
        The surface's local radius of curvature along the link (m), capped.
    principal_radii : (float, float)
        Its smallest and largest radius of curvature over the directions of the tangent plane
        (m), capped: equal on a sphere, the largest many times the smallest on a cylinder or an
        edge.
    tip : bool
        True when the link's tip touches (the surface is not tangent to the link).
    object_name : str
        The touched object's name.
    link_radius : float
        The link's radius the touch was found with (m): its axis is that far off the surface.
    """

    angle: float
    angles: tuple[float, float]
    x_c: float
    link_point: FloatArray
    surface_point: FloatArray
    normal: FloatArray
    tangent: FloatArray
    radius: float
    principal_radii: tuple[float, float]
    tip: bool
    object_name: str
    link_radius: float

    def to_dict(self) -> dict[str, object]:
        """JSON-able fields (SI units)."""
        return {
            "angle": self.angle,
            "angles": list(self.angles),
            "x_c": self.x_c,
            "link_point": self.link_point.tolist(),
            "surface_point": self.surface_point.tolist(),
            "normal": self.normal.tolist(),
            "tangent": self.tangent.tolist(),
            "radius": self.radius,
            "principal_radii": list(self.principal_radii),
            "tip": self.tip,
            "object": self.object_name,
            "link_radius": self.link_radius,
        }


@dataclass(frozen=True)
class SweepGeometry:
    """What a sweep meets: a touch, nothing (free), or the link inside an object at the start.

    Attributes
    ----------
    touch : Touch or None
    inside_at_start : bool
        The link already cuts an object at the sweep's start angle (no sweep is possible).
    """

    touch: Touch | None
    inside_at_start: bool = False


def _gap(scene: Scene, shape: LinkShape, sweep: Sweep, base: BasePose, angle: float) -> float:
    """The link's surface's smallest distance to the scene (m): its axis's less its radius."""
    distance = scene.signed_distance(shape.points(sweep.angles(angle), base)).min()
    return float(distance) - shape.link.radius


def first_touch(scene: Scene, sweep: Sweep, shape: LinkShape) -> SweepGeometry:
    """Where the link of ``shape`` first touches ``scene`` during ``sweep``, followed from the
    sweep's first angle in its direction (module docstring)."""
    base = scene.base(sweep.base)
    reach = shape.reach
    sign = float(sweep.direction)
    angle = sweep.origin
    gap = _gap(scene, shape, sweep, base, angle)
    if gap <= 0:
        return SweepGeometry(None, inside_at_start=True)
    while True:
        step = max(gap / reach, MIN_STEP)
        remaining = sign * (sweep.finish - angle)
        if remaining <= 0:
            return SweepGeometry(None)
        next_angle = angle + sign * min(step, remaining)
        next_gap = _gap(scene, shape, sweep, base, next_angle)
        if next_gap <= 0:
            break
        angle, gap = next_angle, next_gap
    # clear at ``clear``, cutting the surface at ``cut``; the sweep goes from the one to the other
    clear, cut = angle, next_angle
    # bisection on the samples
    while abs(cut - clear) > ANGLE_TOLERANCE:
        middle = 0.5 * (clear + cut)
        if _gap(scene, shape, sweep, base, middle) > 0:
            clear = middle
        else:
            cut = middle
    # between samples the link may already cut the surface: bisect again on the gap between
    # the samples, stepping back until the link is clear
    if _nearest(scene, shape, sweep, base, clear)[1] <= 0:
        cut = clear
        clear = cut - sign * MIN_STEP
        while _nearest(scene, shape, sweep, base, clear)[1] <= 0:
            clear -= sign * MIN_STEP
        while abs(cut - clear) > ANGLE_TOLERANCE:
            middle = 0.5 * (clear + cut)
            if _nearest(scene, shape, sweep, base, middle)[1] > 0:
                clear = middle
            else:
                cut = middle
    return SweepGeometry(_touch_at(scene, sweep, shape, base, clear))


def _nearest(
    scene: Scene, shape: LinkShape, sweep: Sweep, base: BasePose, angle: float
) -> tuple[float, float, bool]:
    """(x, gap, tip): the link's point nearest the scene at ``angle``, between samples, and
    the gap from its surface (m)."""
    theta = sweep.angles(angle)
    x = shape.abscissae
    k = int(np.argmin(scene.signed_distance(shape.points(theta, base))))
    length = float(x[-1])
    thickness = shape.link.radius

    def gap_at(s: float) -> float:
        distance = scene.signed_distance(shape.point_at(s, theta, base)[None, :])[0]
        return float(distance) - thickness

    if k == len(x) - 1 and gap_at(length) <= gap_at(length - 0.1 * shape.spacing):
        return length, gap_at(length), True
    low, high = float(x[max(k - 1, 0)]), float(x[min(k + 1, len(x) - 1)])
    found = minimize_scalar(gap_at, bounds=(low, high), method="bounded", options={"xatol": 1e-9})
    return float(found.x), float(found.fun), False


def _bend_radius(touched: SceneObject, point: FloatArray, direction: FloatArray) -> float:
    """The surface's radius of curvature (m) at ``point`` along the unit tangent ``direction``:
    a circle of radius R curves away by d = sqrt(R^2 + h^2) - R at h = CURVATURE_PROBE to
    either side, capped to [MIN_RADIUS, MAX_RADIUS]."""
    h = CURVATURE_PROBE
    probes = point + np.outer([h, -h], direction)
    bend = float(np.mean(touched.signed_distance(probes)))
    radius = (h * h - bend * bend) / (2.0 * bend) if bend > 0 else MAX_RADIUS
    return min(max(radius, MIN_RADIUS), MAX_RADIUS)


def _touch_at(scene: Scene, sweep: Sweep, shape: LinkShape, base: BasePose, angle: float) -> Touch:
    theta = sweep.angles(angle)
    x_c, _, tip = _nearest(scene, shape, sweep, base, angle)
    link_point = shape.point_at(x_c, theta, base)
    per_object = [float(obj.signed_distance(link_point[None, :])[0]) for obj in scene.objects]
    touched = scene.objects[int(np.argmin(per_object))]
    normal = touched.normal(link_point)
    distance = min(per_object)
    surface_point = link_point - distance * normal
    radius = MAX_RADIUS
    principal = (MAX_RADIUS, MAX_RADIUS)
    tangent = shape.tangent_at(x_c, theta, base)
    if not tip:
        along = tangent - (tangent @ normal) * normal
        along /= np.linalg.norm(along)
        across = np.cross(normal, along)
        # the first direction is along the link
        turns = np.pi * np.arange(BEND_DIRECTIONS) / BEND_DIRECTIONS
        radii = [
            _bend_radius(touched, surface_point, math.cos(t) * along + math.sin(t) * across)
            for t in turns
        ]
        radius = radii[0]
        principal = (min(radii), max(radii))
    return Touch(
        angle=angle,
        angles=theta,
        x_c=x_c,
        link_point=link_point,
        surface_point=surface_point,
        normal=normal,
        tangent=tangent,
        radius=float(radius) if math.isfinite(radius) else MAX_RADIUS,
        principal_radii=(float(principal[0]), float(principal[1])),
        tip=tip,
        object_name=touched.name,
        link_radius=shape.link.radius,
    )
