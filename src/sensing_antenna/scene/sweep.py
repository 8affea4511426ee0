"""A sweep of the head and where its gravity-sagged link lies at each angle.

A sweep turns one joint across its range [``start``, ``end``] with the other held at ``fixed``,
from one of the scene's base poses: azimuthal, theta1 across with theta2 = ``fixed``, from
``start`` up to ``end`` (``direction`` +1: the link moves towards +Y^m) or from ``end`` down to
``start`` (-1: towards -Y^m); vertical, theta2 with theta1 = ``fixed``, up from ``start``
(+1: towards +Z^m, lifting the link) or down from ``end`` (-1: towards -Z^m, lowering it onto
what lies below, its weight helping the push). A sweeping line first touches a convex object on
the side it comes from, so the two directions of a sweep see opposite sides of it.

The link at angles (theta1, theta2) is the straight line x X^m sagged by its own weight,
p(x) = x X^m + g w_1(x) Z^m in the absolute frame (recording format), w_1 the static deflection
of the simulator's finite-element link under a unit transverse acceleration (m per m/s^2,
negative: the load is along -Z^m): the sag the simulator starts its manoeuvres from. The
simulator touches in a frame turned to the touch's angles (``scene.simulate``), where the whole
of g acts across the link, so the sag is g w_1 at every elevation (a level link's; a physical
link's is g cos(theta2) w_1): the geometric touch and the simulated one then meet the surface at
the same point.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import STANDARD_GRAVITY, Link
from sensing_antenna.mapping.pose import BasePose
from sensing_antenna.simulator.contact import motor_frame
from sensing_antenna.simulator.device import DeviceImperfections
from sensing_antenna.simulator.link import build_link_model
from sensing_antenna.simulator.run import device_link

__all__ = [
    "MAX_AZIMUTH",
    "MAX_ELEVATION",
    "SWEEP_CASES",
    "SWEEP_DIRECTIONS",
    "LinkShape",
    "Sweep",
    "facing_region",
]

FloatArray = NDArray[np.float64]

SWEEP_CASES = ("azimuthal", "vertical")

#: The directions a sweep may run in: +1 from ``start`` to ``end``, -1 from ``end`` to ``start``.
SWEEP_DIRECTIONS = (1, -1)

#: Limits (rad) of the angles a region is explored over, either way: the azimuth theta1 within
#: a half-turn (every heading once), the elevation theta2 within 1.2 rad (69 degrees), short of
#: the vertical, where turning the azimuth no longer moves the link.
MAX_AZIMUTH = math.pi
MAX_ELEVATION = 1.2


@dataclass(frozen=True)
class Sweep:
    """One sweep of the head.

    Attributes
    ----------
    base : int
        Index of the scene's base pose the head sits at.
    case : {"azimuthal", "vertical"}
    fixed : float
        The held joint's angle (rad): theta2 of an azimuthal sweep, theta1 of a vertical one.
    start, end : float
        The swept joint's range (rad), start < end.
    direction : {1, -1}
        +1: from ``start`` to ``end`` (towards +Y^m, or +Z^m for a vertical sweep); -1: from
        ``end`` to ``start`` (towards -Y^m, or -Z^m).
    """

    base: int
    case: Literal["azimuthal", "vertical"]
    fixed: float
    start: float
    end: float
    direction: int = 1

    def __post_init__(self) -> None:
        if isinstance(self.base, bool) or not isinstance(self.base, int | np.integer):
            raise TypeError(
                "base is the index of a base pose in the scene's bases (an int), got "
                f"{type(self.base).__name__}"
            )
        if self.base < 0:
            raise ValueError(f"base is an index into the scene's bases (>= 0), got {self.base}")
        object.__setattr__(self, "base", int(self.base))
        if self.case not in SWEEP_CASES:
            raise ValueError(f"case must be one of {', '.join(SWEEP_CASES)}, got {self.case!r}")
        if not self.start < self.end:
            raise ValueError("a sweep's range runs from start to a larger end")
        if isinstance(self.direction, bool) or self.direction not in SWEEP_DIRECTIONS:
            raise ValueError(f"direction must be +1 or -1, got {self.direction!r}")

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Sweep:
        """The sweep of :meth:`to_dict`'s fields (``direction`` +1 when absent)."""
        return cls(
            int(data["base"]),
            data["case"],
            float(data["fixed"]),
            float(data["start"]),
            float(data["end"]),
            data.get("direction", 1),
        )

    @property
    def origin(self) -> float:
        """The swept joint's angle where the sweep begins (rad)."""
        return self.start if self.direction == 1 else self.end

    @property
    def finish(self) -> float:
        """The swept joint's angle where the sweep ends when it touches nothing (rad)."""
        return self.end if self.direction == 1 else self.start

    def swept_angles(self, step: float) -> NDArray[np.float64]:
        """The swept joint's angles every ``step`` (rad) in the order the sweep passes them."""
        if self.direction == 1:
            return np.arange(self.start, self.end + 1e-12, step)
        return np.arange(self.end, self.start - 1e-12, -step)

    def angles(self, swept: float) -> tuple[float, float]:
        """(theta1, theta2) (rad) when the swept joint is at ``swept``."""
        if self.case == "azimuthal":
            return (swept, self.fixed)
        return (self.fixed, swept)

    @property
    def label(self) -> str:
        """Short text for progress lines."""
        held = "elevation" if self.case == "azimuthal" else "azimuth"
        axis = "Y" if self.case == "azimuthal" else "Z"
        return (
            f"base {self.base} {self.case} towards {'+' if self.direction == 1 else '-'}{axis}"
            f" at {held} {self.fixed:+.3f} rad"
        )

    def to_dict(self) -> dict[str, object]:
        """JSON-able fields."""
        return {
            "base": self.base,
            "case": self.case,
            "fixed": self.fixed,
            "start": self.start,
            "end": self.end,
            "direction": self.direction,
        }


@dataclass(frozen=True)
class LinkShape:
    """The link's static sagged shape, sampled along its length.

    Parameters
    ----------
    link : Link
        The device's link (a calibrated one is built with the E I its T_e gives, as the
        simulator builds it).
    n_elements : int
        Finite elements (the simulator's default, 16).
    spacing : float
        Distance between the samples along the link (m).
    start_fraction : float
        The first sample's abscissa as a fraction of l (the simulator's contact search starts
        at 2 % of l).
    gravity : float
        g (m/s^2).
    device : DeviceImperfections, optional
        The simulated device's departures from ``link`` (``simulator.DeviceImperfections``):
        its build (tip mass, clamp, taper, joint) sags the link as the simulator's does; its
        sensor and encoders do not move it. None: the uniform, rigidly clamped link.
    """

    link: Link
    n_elements: int = 16
    spacing: float = 0.002
    start_fraction: float = 0.02
    gravity: float = STANDARD_GRAVITY
    device: DeviceImperfections | None = None

    @cached_property
    def abscissae(self) -> FloatArray:
        """x of the samples (m), shape (n,), the tip last."""
        length = self.link.length
        n = max(2, math.ceil(length * (1.0 - self.start_fraction) / self.spacing) + 1)
        return np.linspace(self.start_fraction * length, length, n)

    @cached_property
    def _unit_sag(self) -> tuple[FloatArray, FloatArray]:
        model = build_link_model(device_link(self.link), self.n_elements, self.device)
        # K q = -1 * m_t: the deflection under a unit acceleration along -Z^m
        q = np.linalg.solve(model.stiffness, -model.translation_load)
        x = self.abscissae
        w = np.array([float(model.shape_at(float(xi)) @ q) for xi in x])
        slope = np.array([float(model.slope_at(float(xi)) @ q) for xi in x])
        return w, slope

    def sag(self) -> FloatArray:
        """w(x) along Z^m (m), shape (n,), the same at every elevation (module docstring)."""
        return self.gravity * self._unit_sag[0]

    def points(self, theta: tuple[float, float], base: BasePose) -> FloatArray:
        """The samples in the world (m), shape (n, 3)."""
        x_m, _, z_m = motor_frame(*theta)
        local = np.outer(self.abscissae, x_m) + np.outer(self.sag(), z_m)
        return base.point_to_world(local)

    def point_at(self, x: float, theta: tuple[float, float], base: BasePose) -> FloatArray:
        """p(x) in the world (m), shape (3,), the sag interpolated between samples."""
        x_m, _, z_m = motor_frame(*theta)
        w = float(np.interp(x, self.abscissae, self.sag()))
        return base.point_to_world(x * x_m + w * z_m)

    def tangent_at(self, x: float, theta: tuple[float, float], base: BasePose) -> FloatArray:
        """Unit tangent dp/dx in the world, shape (3,)."""
        x_m, _, z_m = motor_frame(*theta)
        slope = self.gravity * float(np.interp(x, self.abscissae, self._unit_sag[1]))
        t = x_m + slope * z_m
        return np.asarray(base.rotation @ (t / np.linalg.norm(t)))

    @property
    def reach(self) -> float:
        """Largest distance (m) of a sample from the head's base point, at any elevation: a
        bound on how fast a link point moves per radian of either joint."""
        sag = np.abs(self.gravity * self._unit_sag[0])
        return float(np.max(np.hypot(self.abscissae, sag)) + sag.max())


def facing_region(
    points: NDArray[np.floating], base: BasePose, shape: LinkShape, margin: float = 0.05
) -> tuple[tuple[float, float], tuple[float, float]]:
    """The angles under which ``base`` sees ``points`` (m, world, shape (n, 3); e.g. an object's
    mesh vertices): theta1 and theta2 from, to (rad), widened by ``margin`` (rad), the elevations
    raised by the link's sag at each point's distance r (the link at theta2 passes w(r) < 0
    across itself, along Z^m: its point at r lies w(r) / r rad below theta2) and kept within
    +-:data:`MAX_ELEVATION`."""
    local = (np.asarray(points, dtype=float) - base.position) @ base.rotation  # R^T (p - O)
    reach = np.linalg.norm(local, axis=1)
    sag = np.interp(reach, shape.abscissae, shape.sag())
    azimuths = np.arctan2(local[:, 1], local[:, 0])
    elevations = np.arctan2(local[:, 2], np.hypot(local[:, 0], local[:, 1])) - sag / reach
    return (
        (float(azimuths.min()) - margin, float(azimuths.max()) + margin),
        (
            max(float(elevations.min()) - margin, -MAX_ELEVATION),
            min(float(elevations.max()) + margin, MAX_ELEVATION),
        ),
    )
