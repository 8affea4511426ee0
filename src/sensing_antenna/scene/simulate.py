"""A sweep of the simulated device in a scene: the geometric touch, then the contact physics.

:func:`~sensing_antenna.scene.touch.first_touch` finds where the link first meets the scene.
The simulator's own manoeuvre (``simulator.simulate``) is then run against an obstacle of the
shapes it has. A primitive object is the obstacle itself, placed in the recording's frame
(``Scenario.obstacle_placement``: a ball, a capped cylinder, a capsule, a box, a cone, a
torus), so that a contact sliding along it, over an edge or a rim, from a cap onto a side,
stays on the object. A user's mesh is met by a local obstacle equivalent to the surface at the
touch, placed by the simulator from x_c as for any of its runs:

- a contact along the link: a cylinder tangent to the link at x_c whose axis is perpendicular
  to the link and to the surface's normal, of the surface's local radius along the link (a post
  for an azimuthal sweep, a bar for a vertical one), turned by the normal's angle out of the
  sweep's plane (the scenario's ``obstacle_tilt``); where the surface is curved both ways (its
  largest principal radius at most :data:`BALL_RATIO` times its smallest: a mesh's corner or
  rounded part) a ball of the radius along the link instead, on which a link sliding across
  stays on the surface. An edge is curved one way only, whichever way the link crosses it:
  a cylinder, along which a link sliding across stays on the edge, as it does on a real one;
- a contact at the tip: the plane of the surface at the touch, along its normal there, on
  which a tip pushed across a face it meets at a slant slides as it would on the face; where
  the link's root lies behind that plane (the link passes beside the face to reach it), a plane
  of the simulator's own through the tip, which clears the link (its normal not the face's).

A round link touches with its surface, its radius a off its axis (``scene.touch``), while the
simulator's link touches with its axis: each obstacle, the object itself or a local one, is
the surface grown by a (a cylinder, a capsule or a ball of radius R + a about the same axis or
centre, a capped cylinder also a longer at each end with its rim rounded by a; a box, a cone
or a torus grown by a, its edges, rim and apex rounded by it; the tip's plane a from the
face), which the axis meets where the link's surface meets the surface.

The simulator's manoeuvre touches at the angles (0, 0) of its absolute frame, so the recording's
frame is the base's turned to the touch angles: R = R_base M(theta)^T, with M(theta) the motor
frame's rows (``simulator.contact.motor_frame``), written as the recording's ``base_pose``; the
recording's angles are relative to that frame. The physics is exact for an azimuthal sweep at
elevation 0 under a level base (a turn about the vertical); otherwise the simulated gravity acts
along the turned frame's -Z, so the sag across the link is g where a physical link's is
g cos(theta2) (the scene's link shape, ``scene.sweep.LinkShape``, sags as the simulated one, so
that the simulated contact lies on the touched surface), and a sweep at elevation theta2 is
simulated in the plane tangent to its cone at the touch.

A sweep the other way (towards -Y^m, or a vertical sweep down) is simulated as such
(``Scenario.sweep_direction = -1``): the obstacle lies on the other side of the link, and a
vertical sweep down has the link's weight helping the push onto the obstacle below it.

The simulator's local obstacles turn at most :data:`MAX_TILT` out of the sweep's plane (about
the friction cone of mu = 0.6); a surface turned further, up to :data:`GLANCING_ANGLE`, is
simulated with the local obstacle turned by :data:`MAX_TILT`: the same touched point, the push
held as if the surface faced the sweep more (a real link may slide there). An object placed
itself is as it is: beyond the friction cone the link slides along it, as on a real object.
A touch the simulator cannot
represent is reported instead of simulated: the normal turned more than
:data:`GLANCING_ANGLE` (``glancing``: the link would slide over it), or x_c below the
simulator's smallest contact point (``near_head``). The simulator has one obstacle: a run
whose link, holding its push at the end, reaches into another object of the scene by more
than :data:`SECOND_OBJECT_DEPTH` went through it, where a real link would touch it too, and
is reported instead of kept (``second_object``, naming that object).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from sensing_antenna.antenna import Antenna
from sensing_antenna.mapping.pose import BasePose
from sensing_antenna.mapping.primitives import PRIMITIVES
from sensing_antenna.recording import Recording
from sensing_antenna.scene.file import Scene
from sensing_antenna.scene.objects import SceneObject
from sensing_antenna.scene.sweep import LinkShape, Sweep
from sensing_antenna.scene.touch import MAX_RADIUS, SweepGeometry, Touch, first_touch
from sensing_antenna.simulator import Scenario
from sensing_antenna.simulator.contact import motor_frame
from sensing_antenna.simulator.device import DeviceImperfections
from sensing_antenna.simulator.run import (
    SimulationDetail,
    device_link,
    minimum_contact_point,
    simulate_detailed,
)
from sensing_antenna.simulator.scenario import DEFAULT_CONTACT_STIFFNESS

__all__ = [
    "BALL_RATIO",
    "GLANCING_ANGLE",
    "MAX_TILT",
    "OUTCOMES",
    "SECOND_OBJECT_DEPTH",
    "GlancingTouchError",
    "SweepOutcome",
    "simulate_sweep",
    "touch_scenario",
]

#: A surface whose largest principal radius is at most this many times its smallest is curved
#: every way at least half as much as the most, and its equivalent obstacle a ball of the radius
#: along the link (a mesh's corner or rounded part); beyond, a cylinder, straight across (a
#: mesh's edge met at any angle, its cylindrical part). Radii are capped at 10 m:
#: a flat face gives a 10 m ball.
BALL_RATIO = 2.0

#: Largest angle of the surface's normal out of the sweep's direction (rad) the simulator's
#: obstacles are turned by: just inside the scenario's limit (``Scenario.obstacle_tilt`` must
#: stay below 0.5 rad in magnitude, about the friction cone of mu = 0.6).
MAX_TILT = 0.49

#: A surface turned further than this (rad) out of the sweep's direction is ``glancing``: the
#: link would slide over it rather than be held by it (57 degrees).
GLANCING_ANGLE = 1.0

#: What a sweep can end in.
OUTCOMES = ("touch", "free", "glancing", "near_head", "inside", "second_object")

#: How far (m) the simulated link, as it holds its push, may reach into an object it was not
#: simulated against before the sweep is ``second_object``: 0.5 mm, beyond the penalty contact
#: and the hold's last ringing.
SECOND_OBJECT_DEPTH = 5e-4

_DEFAULTS = Scenario(case="free")
_DEFAULT_SPEED = _DEFAULTS.sweep_speed


@dataclass(frozen=True)
class SweepOutcome:
    """A sweep's result.

    Attributes
    ----------
    sweep : Sweep
    outcome : str
        ``touch`` (simulated: ``recording`` holds it), ``free`` (nothing within the reach: the
        swept region is free space), ``glancing``, ``near_head``, ``inside`` or
        ``second_object`` (module docstring; nothing simulated, or nothing kept).
    touch : Touch or None
        The geometric first touch.
    scenario : Scenario or None
        The simulated manoeuvre.
    recording : Recording or None
        Its recording, with ``base_pose`` metadata (the turned frame).
    frame : BasePose or None
        The recording's absolute frame in the world.
    reason : str or None
        Why nothing was simulated.
    sweep_time : float
        How long the head swept (s): from the start angle to the touch (or the end) at the
        scenario's cruise speed, plus the recording after the touch; a free sweep's whole
        travel.
    """

    sweep: Sweep
    outcome: str
    touch: Touch | None = None
    scenario: Scenario | None = None
    recording: Recording | None = None
    frame: BasePose | None = None
    reason: str | None = None
    sweep_time: float = 0.0


class GlancingTouchError(ValueError):
    """The touched surface turns too far out of the sweep's direction to be simulated."""


def touch_scenario(
    touch: Touch,
    sweep: Sweep,
    scene: Scene,
    seed: int = 0,
    **scenario_fields: Any,
) -> tuple[Scenario, BasePose]:
    """The simulator's scenario for a touch and the recording's frame in the world (module
    docstring); the touch's ``link_radius`` (m) grows the obstacle, as the simulated link
    touches with its axis.

    Raises :class:`GlancingTouchError` with the reason when the touch is ``glancing``.
    """
    base = scene.base(sweep.base)
    rotation = base.rotation @ motor_frame(*touch.angles).T
    frame = BasePose(rotation, base.position)
    # in the recording's frame (X, Y, Z = X^m, Y^m, Z^m); d the sweep's direction
    normal = rotation.T @ touch.normal
    tangent = rotation.T @ touch.tangent
    d = float(sweep.direction)
    if sweep.case == "azimuthal":
        # the post's normal is -d Y cos(t) + Z sin(t), its axis Z cos(t) + d Y sin(t)
        # (simulator.contact.place_obstacle)
        tilt = math.atan2(normal[2], -d * normal[1])
        axis = np.array([0.0, d * math.sin(tilt), math.cos(tilt)])
        kind = "post"
    else:
        # the bar's normal is -d Z cos(t) + Y sin(t), its axis Y cos(t) + d Z sin(t)
        tilt = math.atan2(normal[1], -d * normal[2])
        axis = np.array([0.0, math.cos(tilt), d * math.sin(tilt)])
        kind = "bar"
    # the sagged link crosses that axis at an angle phi off the perpendicular; a cylinder of
    # radius R curves by cos(phi)^2 / R along it (Euler), so R = R_along cos(phi)^2
    along_axis = float(axis @ tangent)
    radius = touch.radius * (1.0 - along_axis**2)
    smallest, largest = touch.principal_radii
    if largest <= BALL_RATIO * smallest:
        # curved every way: a ball of the radius along the link, on which a link sliding
        # across stays on the surface (a cylinder is straight along its axis)
        kind = "ball"
        radius = touch.radius
    # the simulator's link touches with its axis: its obstacle is the surface grown by the
    # link's radius, which the axis meets where the link's surface meets the surface
    radius = min(radius + touch.link_radius, MAX_RADIUS)
    if abs(tilt) >= GLANCING_ANGLE and not touch.tip:
        raise GlancingTouchError(
            f"the surface's normal is {abs(tilt):.2f} rad out of the sweep's direction, more than"
            f" {GLANCING_ANGLE} rad (the link would slide over it)"
        )
    # beyond the simulator's largest tilt a local obstacle is turned by that much: the same
    # touched point, a push held as if the surface faced the sweep more
    tilt = max(-MAX_TILT, min(MAX_TILT, tilt))
    obstacle: dict[str, Any] = {"obstacle": kind, "obstacle_radius": radius, "obstacle_tilt": tilt}
    if (placed := _touched_shape(touch, scene, frame)) is not None:
        # the object itself is not turned: the link slides where friction cannot hold it
        obstacle = placed | {"obstacle_tilt": 0.0}
    elif touch.tip:
        # the face's plane; where it would cut the link, a plane of the simulator's own through
        # the tip (its normal not the face's: the touched point is the same)
        obstacle = _tip_plane(touch, frame) or {
            "obstacle": "plane",
            "obstacle_radius": radius,
            "obstacle_tilt": 0.0,
        }
    towards = ""
    if sweep.direction == -1:
        towards = " towards -Y" if sweep.case == "azimuthal" else " down"
    description = (
        f"scene {scene.name}: {sweep.case} sweep{towards} touching {touch.object_name}"
        f" at x_c = {touch.x_c:.4f} m"
    )
    scenario = Scenario(
        case=sweep.case,
        sweep_direction=sweep.direction,
        contact_point=touch.x_c,
        seed=seed,
        description=description,
        **obstacle,
        **scenario_fields,
    )
    return scenario, frame


def _tip_plane(touch: Touch, frame: BasePose) -> dict[str, Any] | None:
    """The plane of the surface at a tip's touch of a user's mesh, as the simulator's obstacle
    placed in the recording's frame (``frame``): through the touched point grown by the link's
    radius (where the tip's axis meets it), along the surface's normal there. None when the
    link's root lies behind that plane: the link then passes beside the face to reach it, and
    the plane, which has no edge, would cut the link there."""
    grown = touch.surface_point + touch.link_radius * touch.normal
    if not float(touch.normal @ (frame.position - grown)) > 0.0:
        return None
    to_frame = frame.rotation.T
    point = to_frame @ (grown - frame.position)
    return {"obstacle": "plane", "obstacle_placement": (*point, *(to_frame @ touch.normal))}


def _met_object(touch: Touch, scene: Scene) -> SceneObject:
    """The object ``touch`` met: of those of its name (names need not be unique), the one
    whose surface is nearest its point."""
    named = [obj for obj in scene.objects if obj.name == touch.object_name]
    return min(named, key=lambda obj: abs(float(obj.signed_distance(touch.surface_point)[0])))


def _touched_shape(touch: Touch, scene: Scene, frame: BasePose) -> dict[str, Any] | None:
    """The touched object itself as the simulator's obstacle (module docstring): the
    scenario's fields ``obstacle`` (``ball``, ``capsule``, ``cylinder``, ``box``, ``cone`` or
    ``torus``), ``obstacle_placement`` in the recording's frame (``frame``), and its sizes: a
    ball's, a capsule's or a capped cylinder's ``obstacle_radius`` grown by the link's radius
    (m), the capsule's segment or the cylinder's height grown by twice the link's radius as
    ``obstacle_length`` (m), or a box's, a cone's or a torus's own ``obstacle_sizes`` (the
    simulator grows it); None for a user's mesh."""
    touched = _met_object(touch, scene)
    if touched.shape == "mesh":
        return None
    p = touched.parameters
    grown = touch.link_radius
    to_frame = frame.rotation.T
    centre = tuple(to_frame @ (p[:3] - frame.position))
    if touched.shape == "sphere":
        # a ball's direction is only its outward normal at the touch
        return {
            "obstacle": "ball",
            "obstacle_radius": float(p[3]) + grown,
            "obstacle_placement": (*centre, *(to_frame @ touch.normal)),
        }
    axes = to_frame @ Rotation.from_rotvec(p[3:6]).as_matrix()
    placement = (*centre, *axes[:, 2])
    if touched.shape in ("capsule", "cylinder"):
        # a capsule grown by a is a capsule of the same segment; a capped cylinder grown by a
        # is one of radius and height grown by a with its rim rounded by a, as the simulator
        # makes it
        length = float(p[7]) + (2.0 * grown if touched.shape == "cylinder" else 0.0)
        return {
            "obstacle": touched.shape,
            "obstacle_radius": float(p[6]) + grown,
            "obstacle_length": length,
            "obstacle_placement": placement,
        }
    if touched.shape == "box":
        placement = (*placement, *axes[:, 0])
    # a box, a cone or a torus: its own sizes, no radius (the scenario's default stays)
    sizes = tuple(float(v) for v in PRIMITIVES[touched.shape].sizes(p))
    return {"obstacle": touched.shape, "obstacle_sizes": sizes, "obstacle_placement": placement}


def simulate_sweep(
    device: Antenna,
    scene: Scene,
    sweep: Sweep,
    seed: int = 0,
    shape: LinkShape | None = None,
    imperfections: DeviceImperfections | None = None,
    **scenario_fields: Any,
) -> SweepOutcome:
    """Run ``sweep`` of ``device`` in ``scene`` (module docstring).

    Parameters
    ----------
    device : Antenna
        The simulated device (its link and motors).
    scene : Scene
    sweep : Sweep
    seed : int
        The scenario's seed (sensor noise).
    shape : LinkShape, optional
        The link's sagged shape (built from ``device`` and ``imperfections`` when None; pass
        one to reuse it, built with the same imperfections' link).
    imperfections : DeviceImperfections, optional
        The simulated device's departures from ``device`` in this manoeuvre (the scenario's
        ``device``); None: the nominal device.
    **scenario_fields
        Further :class:`~sensing_antenna.simulator.Scenario` fields (noise_scale, ...).

    Raises
    ------
    ValueError
        ``shape`` is another link's (its radius or length not the device's, or its build not
        ``imperfections``'), or ``imperfections`` bow the link: the geometric touch and the
        simulated one would not meet.
    """
    shape = shape if shape is not None else LinkShape(device.link, device=imperfections)
    if imperfections is not None and any(imperfections.bow):
        raise ValueError(
            "simulate_sweep: a bowed link (imperfections.bow) is not simulated in scenes: the"
            " scene's link shape is straight, and the geometric touch would miss the simulated one"
        )
    if imperfections is not None:
        scenario_fields["device"] = imperfections
    built = None if shape.device is None else shape.device.link_part
    if built != (None if imperfections is None else imperfections.link_part):
        raise ValueError(
            "simulate_sweep: the shape's link is not the device's as built (its tip mass, clamp,"
            " taper or joint): the geometric touch and the simulated one would not meet"
        )
    for name in ("radius", "length"):
        if getattr(shape.link, name) != getattr(device.link, name):
            raise ValueError(
                f"simulate_sweep: the shape's link {name} {getattr(shape.link, name)} m is not"
                f" the device's {getattr(device.link, name)} m"
            )
    speed = float(scenario_fields.get("sweep_speed", _DEFAULT_SPEED))
    geometry: SweepGeometry = first_touch(scene, sweep, shape)
    if geometry.inside_at_start:
        return SweepOutcome(
            sweep, "inside", reason="the link cuts an object at the sweep's start angle"
        )
    touch = geometry.touch
    if touch is None:
        return SweepOutcome(sweep, "free", sweep_time=(sweep.end - sweep.start) / speed)
    approach = abs(touch.angle - sweep.origin) / speed
    link = device_link(device.link)
    smallest = minimum_contact_point(
        link, float(scenario_fields.get("contact_stiffness") or DEFAULT_CONTACT_STIFFNESS)
    )
    if touch.x_c < smallest:
        return SweepOutcome(
            sweep,
            "near_head",
            touch,
            reason=f"x_c = {touch.x_c:.3f} m is below the simulator's smallest {smallest:.3f} m",
            sweep_time=approach,
        )
    try:
        scenario, frame = touch_scenario(touch, sweep, scene, seed, **scenario_fields)
    except GlancingTouchError as exc:
        return SweepOutcome(sweep, "glancing", touch, reason=str(exc), sweep_time=approach)
    detail = simulate_detailed(device, scenario)
    pressed = _second_object(detail, scene, frame, touch)
    if pressed:
        return SweepOutcome(sweep, "second_object", touch, reason=pressed, sweep_time=approach)
    recording = detail.recording
    metadata = dict(recording.metadata)
    metadata["base_pose"] = frame.to_json()
    metadata["true_object"] = touch.object_name
    metadata["true_surface_point"] = json.dumps([float(v) for v in touch.surface_point])
    recording = replace(recording, metadata=metadata)
    # the recording starts approach_time before the touch (the simulator's own approach)
    touch_time = float(recording.metadata.get("true_t_contact", "nan"))
    after = recording.t[-1] - (touch_time if math.isfinite(touch_time) else 0.0)
    return SweepOutcome(
        sweep,
        "touch",
        touch,
        scenario,
        recording,
        frame,
        sweep_time=approach + float(after),
    )


def _second_object(detail: SimulationDetail, scene: Scene, frame: BasePose, touch: Touch) -> str:
    """Why the simulated link, as it holds its push at the run's end, reaches into an object of
    ``scene`` other than the one ``touch`` met (:func:`_met_object`) by more than
    :data:`SECOND_OBJECT_DEPTH`; "" when it does not. The simulator has one obstacle, so such a
    run pushed the link through the other one."""
    met = _met_object(touch, scene)
    others = [obj for obj in scene.objects if obj is not met]
    if not others:
        return ""
    model = detail.link_model
    x = np.linspace(0.0, model.length, 8 * model.n_elements + 1)[1:]
    rows = np.array([model.shape_at(float(s)) for s in x])
    v_q, w_q = detail.final_deflection
    v, w = rows @ v_q, rows @ w_q
    along = x
    if detail.scenario.link_model == "nonlinear":
        # an inextensible link's axis point at arc length x lies short of x along X^m
        slopes = np.array([model.slope_at(float(s)) for s in x])
        tilt = (slopes @ v_q) ** 2 + (slopes @ w_q) ** 2
        shortening = np.cumsum(1.0 - np.sqrt(np.clip(1.0 - tilt, 0.0, 1.0))) * (x[1] - x[0])
        along = x - shortening
    rows_m = motor_frame(*detail.true_theta[-1])
    points = frame.point_to_world(
        along[:, None] * rows_m[0] + v[:, None] * rows_m[1] + w[:, None] * rows_m[2]
    )
    for obj in others:
        gap = obj.signed_distance(points) - touch.link_radius
        k = int(np.argmin(gap))
        if gap[k] < -SECOND_OBJECT_DEPTH:
            return (
                f"the pushed link presses on '{obj.name}' too, {1000 * -gap[k]:.1f} mm into it"
                f" at {x[k]:.3f} m along the link: the simulator holds one contact at a time"
            )
    return ""
