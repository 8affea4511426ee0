"""The paper antenna's link as a PyElastica Cosserat rod, for the reference recordings.

A tool of ``generate.py`` and ``checks.py`` only: it needs PyElastica (``requirements.txt``
beside it), which the package itself never imports. SI units throughout.

The rod's first element is held by the head: its directors are imposed from the head's angles
(theta1, theta2) and its first node sits half an element behind O, so that the element's
midpoint, where the discrete rod's clamp acts, is O and the free link is l long (a kinematic
base). Measured by checks.py: with the first node at O instead, the cantilever is effectively
half an element shorter and its tip deflection 3 % smaller. PyElastica's
directors are rows d1, d2, d3 of ``director_collection`` (lab to material); d3 is the tangent
X^m, d1 = Z^m, d2 = -Y^m. The sensor is the section force n(0) and moment m(0) of the rod at O,
the wrench that the link exerts on the head, resolved on the motor axes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import elastica as ea
import numpy as np
from numba import njit

GRAVITY = 9.81


@dataclass(frozen=True)
class RodLink:
    """The link's data (the paper's Table 2 by default)."""

    length: float = 0.98
    radius: float = 1.0e-3
    youngs_modulus: float = 115e9
    linear_density: float = 4.7e-3

    @property
    def density(self) -> float:
        """Volume density (kg/m^3) that gives the linear density on the rod's circular section."""
        return self.linear_density / (math.pi * self.radius**2)

    @property
    def flexural_rigidity(self) -> float:
        return self.youngs_modulus * math.pi * self.radius**4 / 4.0


def motor_axes(theta1: float, theta2: float) -> np.ndarray:
    """3x3 matrix whose columns are X^m, Y^m, Z^m in the absolute frame."""
    c1, s1, c2, s2 = math.cos(theta1), math.sin(theta1), math.cos(theta2), math.sin(theta2)
    xm = np.array([c2 * c1, c2 * s1, s2])
    ym = np.array([-s1, c1, 0.0])
    zm = np.cross(xm, ym)
    return np.column_stack([xm, ym, zm])


def base_directors(theta1: float, theta2: float) -> np.ndarray:
    """PyElastica director matrix (rows d1, d2, d3) of the base element."""
    axes = motor_axes(theta1, theta2)
    return np.vstack([axes[:, 2], -axes[:, 1], axes[:, 0]])


class KinematicBase(ea.ConstraintBase):
    """Holds node 0 at O and imposes the base element's rotation from the head's angles.

    ``angles(t) -> (theta1, theta2, dtheta1, dtheta2)`` (rad, rad/s).
    """

    def __init__(self, angles: Callable[[float], tuple[float, float, float, float]], **kwargs):
        super().__init__(**kwargs)
        self.angles = angles

    def constrain_values(self, system, time) -> None:
        t1, t2, _, _ = self.angles(float(time))
        behind = 0.5 * float(system.rest_lengths[0])
        system.position_collection[:, 0] = -behind * motor_axes(t1, t2)[:, 0]
        system.director_collection[:, :, 0] = base_directors(t1, t2)

    def constrain_rates(self, system, time) -> None:
        t1, t2, w1, w2 = self.angles(float(time))
        axes = motor_axes(t1, t2)
        omega_lab = w1 * np.array([0.0, 0.0, 1.0]) - w2 * axes[:, 1]
        behind = 0.5 * float(system.rest_lengths[0])
        system.velocity_collection[:, 0] = np.cross(omega_lab, -behind * axes[:, 0])
        system.omega_collection[:, 0] = base_directors(t1, t2) @ omega_lab


class PinnedNode(ea.ConstraintBase):
    """Holds one node's displacement across the rod (a pin at that node), for the checks."""

    def __init__(self, node: int, **kwargs):
        super().__init__(**kwargs)
        self.node = node

    def constrain_values(self, system, time) -> None:
        system.position_collection[1:, self.node] = 0.0

    def constrain_rates(self, system, time) -> None:
        system.velocity_collection[1:, self.node] = 0.0


@njit(cache=True)
def _post_contact(x, v, axis_point, axis_dir, reach, stiffness, damping, mu, forces, state, out):
    """Penalty contact of the rod's segments with a cylinder (infinite axis); adds to ``forces``.

    Normal: per segment, stiffness * penetration - damping * approach speed, never pulling.
    Friction: a stick spring (stiffness, damping) from a material point of the rod to the point of
    the post where it stuck, capped at mu F_n; past the cap the rod slides and the anchor follows.
    state: [in contact, anchor arc coordinate (elements), anchor point x3].
    out: [total normal force, contact arc coordinate (elements), contact point x3, sliding].
    """
    n = x.shape[1] - 1
    fn_total = 0.0
    c_num = 0.0
    q_num = np.zeros(3)
    n_num = np.zeros(3)
    for i in range(n):
        a = x[:, i]
        seg = x[:, i + 1] - a
        w0 = a - axis_point
        bb = np.dot(seg, axis_dir)
        aa = np.dot(seg, seg)
        den = aa - bb * bb
        s = (bb * np.dot(w0, axis_dir) - np.dot(seg, w0)) / den if den > 1e-14 else 0.0
        s = min(max(s, 0.0), 1.0)
        q = a + s * seg
        rel = q - axis_point
        radial = rel - np.dot(rel, axis_dir) * axis_dir
        dist = math.sqrt(np.dot(radial, radial))
        pen = reach - dist
        if pen <= 0.0 or dist < 1e-12:
            continue
        normal = radial / dist
        vel = (1.0 - s) * v[:, i] + s * v[:, i + 1]
        fn = stiffness * pen - damping * np.dot(vel, normal)
        if fn <= 0.0:
            continue
        forces[:, i] += (1.0 - s) * fn * normal
        forces[:, i + 1] += s * fn * normal
        fn_total += fn
        c_num += fn * (i + s)
        q_num += fn * q
        n_num += fn * normal
    out[:] = 0.0
    if fn_total <= 0.0:
        state[0] = 0.0
        return
    c = c_num / fn_total
    out[0] = fn_total
    out[1] = c
    out[2:5] = q_num / fn_total
    normal = n_num / math.sqrt(np.dot(n_num, n_num))
    if state[0] == 0.0:
        i = min(int(c), n - 1)
        s = c - i
        state[0] = 1.0
        state[1] = c
        state[2:5] = (1.0 - s) * x[:, i] + s * x[:, i + 1]
    i = min(int(state[1]), n - 1)
    s = state[1] - i
    p = (1.0 - s) * x[:, i] + s * x[:, i + 1]
    vp = (1.0 - s) * v[:, i] + s * v[:, i + 1]
    d = p - state[2:5]
    d = d - np.dot(d, normal) * normal
    vt = vp - np.dot(vp, normal) * normal
    ft = -stiffness * d - damping * vt
    size = math.sqrt(np.dot(ft, ft))
    limit = mu * fn_total
    if size > limit:
        ft = ft * (limit / size)
        i = min(int(c), n - 1)
        s = c - i
        p = (1.0 - s) * x[:, i] + s * x[:, i + 1]
        state[1] = c
        state[2:5] = p + ft / stiffness
        out[5] = 1.0
    forces[:, i] += (1.0 - s) * ft
    forces[:, i + 1] += s * ft


class PostContact(ea.NoForces):
    """A rigid cylinder (the post) touched by the rod: penalty contact with stick-slip friction.

    ``stiffness`` (N/m) and ``damping`` (N s/m) serve normal and tangential directions, as in
    the project's simulator; ``mu`` is the Coulomb coefficient. ``out`` (6 floats), updated at
    every step: total normal force (N), contact arc coordinate (in elements from the first
    node), contact point (m, x3), 1 when sliding.
    """

    def __init__(
        self,
        axis_point: np.ndarray,
        axis_dir: np.ndarray,
        radius: float,
        rod_radius: float,
        stiffness: float,
        damping: float,
        mu: float,
        out: np.ndarray | None = None,
    ) -> None:
        super().__init__()
        self.axis_point = np.asarray(axis_point, dtype=float)
        d = np.asarray(axis_dir, dtype=float)
        self.axis_dir = d / np.linalg.norm(d)
        self.reach = radius + rod_radius
        self.stiffness = stiffness
        self.damping = damping
        self.mu = mu
        self.state = np.zeros(5)
        self.out = out if out is not None else np.zeros(6)

    def apply_forces(self, system, time=0.0) -> None:
        _post_contact(
            system.position_collection,
            system.velocity_collection,
            self.axis_point,
            self.axis_dir,
            self.reach,
            self.stiffness,
            self.damping,
            self.mu,
            system.external_forces,
            self.state,
            self.out,
        )


class RodSystem(ea.BaseSystemCollection, ea.Constraints, ea.Forcing, ea.Damping):
    """The simulation collection."""


def element_length(link: RodLink, n_elements: int) -> float:
    """Length of one element (m): n - 1/2 of them span the free link."""
    return link.length / (n_elements - 0.5)


def arc_length(link: RodLink, n_elements: int, coordinate: float) -> float:
    """Arc length from O (m) of a point ``coordinate`` elements from the rod's first node."""
    return (coordinate - 0.5) * element_length(link, n_elements)


def straight_rod(link: RodLink, n_elements: int, theta1: float = 0.0, theta2: float = 0.0):
    """The undeformed rod along X^m(theta1, theta2), from half an element behind O to l."""
    axes = motor_axes(theta1, theta2)
    dx = element_length(link, n_elements)
    return ea.CosseratRod.straight_rod(
        n_elements,
        -0.5 * dx * axes[:, 0],
        axes[:, 0],
        axes[:, 2],
        link.length + 0.5 * dx,
        link.radius,
        link.density,
        youngs_modulus=link.youngs_modulus,
    )


def base_wrench(rod) -> tuple[np.ndarray, np.ndarray]:
    """Force (N) and moment about O (N m) that the rod exerts on the head, absolute frame.

    n(0) and m(0) of the rod's section at O, the first element's midpoint: the element's stress,
    and the first Voronoi couple (at the second node, half an element out) carried down to O,
    m(0) = m(l_0 / 2) + (l_0 / 2) t x n.
    """
    q0 = rod.director_collection[:, :, 0]
    n0 = rod.internal_stress[:, 0] / rod.dilatation[0]
    t0 = q0 @ rod.tangents[:, 0]
    m_v = rod.internal_couple[:, 0] / rod.voronoi_dilatation[0] ** 3
    moment_mat = m_v + 0.5 * rod.rest_lengths[0] * rod.dilatation[0] * np.cross(t0, n0)
    return q0.T @ n0, q0.T @ moment_mat


def to_motor_frame(vec: np.ndarray, theta1: float, theta2: float) -> np.ndarray:
    return motor_axes(theta1, theta2).T @ vec


def scale_fast_modes(rod, factor: float) -> None:
    """Divides the shear and axial stiffness and multiplies the rotary inertia by ``factor``.

    These set the fastest waves of the rod (axial, shear, rotational), hence the explicit time
    step, and play almost no part in the bending the sensor reads: the shear and axial strains
    stay below 1e-3 and the rotary inertia (r/2)^2 stays far below the squared wavelengths of the
    modes that matter. checks.py measures what remains of the change on the contact frequencies.
    """
    rod.shear_matrix[:] /= factor
    rod.mass_second_moment_of_inertia[:] *= factor
    rod.inv_mass_second_moment_of_inertia[:] /= factor
