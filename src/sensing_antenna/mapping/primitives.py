"""The primitive shape classes a map is recognised as: parameters, signed distance, mesh.

Each class is a :class:`Primitive`: a parameter vector (pose and size, SI units), its signed
distance d(p) (m, positive outside, negative inside; exact for every class, so that least
squares on d is the orthogonal fit), the sizes it reports, and the trimesh mesh it stands for.
Poses are a centre c (m) and a rotation vector w (rad, R = exp([w]x)); the class's axis is the
local Z. Sizes:

========  ====================================  ==========================================
class     parameters                            sizes
========  ====================================  ==========================================
plane     normal angles (2), offset (1)         none (unbounded)
sphere    centre (3), radius                    radius
cylinder  centre (3), rotation (3), radius,     radius, height
          height
capsule   centre (3), rotation (3), radius,     radius, length of the axis segment
          segment length
cone      base centre (3), rotation (3), base   base radius, height (apex on +Z)
          radius, height
torus     centre (3), rotation (3), hole        major radius, minor radius
          R - r >= 0, minor r
box       centre (3), rotation (3), extents (3) the three edge lengths
========  ====================================  ==========================================

The torus is a ring (R >= r, as scene files require): its major radius is parametrised as the
minor radius plus the hole's radius R - r, bounded below (``recognition.MIN_SIZE`` in the fit),
so that the fit cannot shrink the ring to a sphere with dimples at its poles.

``dof`` is the number of independent parameters (a rotation about a symmetry axis is not one),
the k of a model-selection score.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import trimesh
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

__all__ = [
    "PRIMITIVES",
    "Growth",
    "Primitive",
    "distance_gradient",
    "local_coordinates",
    "primitive",
]

FloatArray = NDArray[np.float64]

#: One way a shape grows (:meth:`Primitive.growths`): the sizes it changes (indices into
#: ``size_names``) and the parameter vector's change per metre of growth.
Growth = tuple[tuple[int, ...], FloatArray]


@dataclass(frozen=True)
class Primitive:
    """One shape class.

    Attributes
    ----------
    name : str
        ``plane``, ``sphere``, ...
    parameter_names : tuple of str
        Names of the parameter vector's entries.
    dof : int
        Independent parameters (the k of BIC).
    size_names : tuple of str
        The sizes :meth:`sizes` returns.
    holds : tuple of str
        The classes whose every shape this class's parameters also give, as a special case (a
        capsule whose segment has no length is a sphere).
    """

    name: str
    parameter_names: tuple[str, ...]
    dof: int
    size_names: tuple[str, ...]
    _distance: Callable[[FloatArray, FloatArray], FloatArray]
    _sizes: Callable[[FloatArray], FloatArray]
    _mesh: Callable[[FloatArray], trimesh.Trimesh] | None
    _size_entries: Callable[[FloatArray], FloatArray] = lambda sizes: sizes
    _growths: Callable[[FloatArray], tuple[Growth, ...]] = lambda parameters: ()
    _canonical: Callable[[FloatArray], FloatArray] | None = None
    holds: tuple[str, ...] = ()

    def signed_distance(self, parameters: FloatArray, points: FloatArray) -> FloatArray:
        """d(p) (m): shape (n,) for one parameter vector and points of shape (n, 3) (m); for
        a batch of B parameter vectors, shape (B, p), points of shape (B, n, 3), each vector's
        distance at its own points, shape (B, n) (one call for the B columns of a Jacobian)."""
        x = np.asarray(parameters, dtype=float)
        q = np.asarray(points, dtype=float)
        if x.ndim == 2:
            if q.ndim != 3 or len(q) != len(x):
                shape = f"({len(x)}, n, 3)"
                raise ValueError(f"{len(x)} parameter vectors need points of shape {shape}")
            return self._distance(x[:, None, :], q)
        return self._distance(x, q)

    def sizes(self, parameters: FloatArray) -> FloatArray:
        """The class's sizes (m), in the order of ``size_names``."""
        return self._sizes(np.asarray(parameters, dtype=float))

    def size_parameters(self, sizes: FloatArray) -> FloatArray:
        """The parameter vector's entries after the pose for sizes (m) in the order of
        ``size_names``: the inverse of :meth:`sizes` (a torus's hole is major - minor)."""
        return np.asarray(self._size_entries(np.asarray(sizes, dtype=float)), dtype=float)

    def canonical(self, parameters: FloatArray) -> FloatArray:
        """The same shape's parameter vector in one form: a rotation vector of at most pi
        rad, and a box's extents in increasing order (its axes permuted to match), so that
        one shape reads one way whatever the fit started from."""
        parameters = np.array(parameters, dtype=float)
        if self._canonical is not None:
            return np.asarray(self._canonical(parameters))
        return parameters

    def growths(self, parameters: FloatArray) -> tuple[Growth, ...]:
        """Each way the shape can grow at one end of a size while the rest of it stays: the
        sizes it changes (indices into ``size_names``) and the parameter vector's change per
        metre the end moves outward along the shape's axis. A box's extent grows at either
        face, a cylinder's height at either cap and its radius at its side, a capsule's length
        at either end, a cone at its base along its slant (its radius and height together; the
        base's rim moves sqrt(1 + (R / h)^2) m per metre); a sphere's or a torus's sizes have
        no ends."""
        return self._growths(np.asarray(parameters, dtype=float))

    def mesh(self, parameters: FloatArray) -> trimesh.Trimesh | None:
        """The shape as a trimesh mesh (None for the unbounded plane)."""
        return None if self._mesh is None else self._mesh(np.asarray(parameters, dtype=float))

    def normals(self, parameters: FloatArray, points: FloatArray, step: float = 1e-5) -> FloatArray:
        """Unit gradient of d at the points (central differences of ``step`` m), shape (n, 3)."""
        gradient = distance_gradient(
            lambda q: self.signed_distance(parameters, q), np.asarray(points, dtype=float), step
        )
        norm = np.linalg.norm(gradient, axis=1, keepdims=True)
        return np.asarray(gradient / np.where(norm > 0, norm, 1.0))


def distance_gradient(
    distance: Callable[[FloatArray], FloatArray], points: FloatArray, step: float
) -> FloatArray:
    """Gradient of a distance function of (m, 3) points at the points (m), by central
    differences of ``step`` m, shape (n, 3)."""
    offsets = step * np.concatenate([np.eye(3), -np.eye(3)])
    shifted = (np.asarray(points, dtype=float)[:, None, :] + offsets).reshape(-1, 3)
    values = np.asarray(distance(shifted), dtype=float).reshape(-1, 6)
    return np.asarray((values[:, :3] - values[:, 3:]) / (2.0 * step))


def local_coordinates(parameters: FloatArray, points: FloatArray) -> FloatArray:
    """Points (m, shape (n, 3)) in a posed shape's own frame: R^T (p - c), with the centre c =
    parameters[0:3] and R the rotation of the rotation vector w = parameters[3:6] (rad). For a
    batch, parameters of shape (B, 1, p) and points (B, n, 3): shape (B, n, 3)."""
    return np.asarray((points - parameters[..., 0:3]) @ _rotation(parameters))


def _rotation(parameters: FloatArray) -> FloatArray:
    """R (read-only, shape (3, 3)) of the rotation vector parameters[3:6] (rad); for a batch
    of shape (B, 1, p), shape (B, 3, 3)."""
    if parameters.ndim > 1:  # a batch's poses are each met once: not worth keeping
        return np.asarray(Rotation.from_rotvec(parameters[:, 0, 3:6]).as_matrix())
    return _rotation_of(np.ascontiguousarray(parameters[3:6], dtype=float).tobytes())


@functools.lru_cache(maxsize=32)
def _rotation_of(rotation_vector: bytes) -> FloatArray:
    # a fit evaluates one pose many times over (each distance of one residual evaluation, the
    # normals' six differences): built once per pose
    matrix = Rotation.from_rotvec(np.frombuffer(rotation_vector, dtype=float).copy()).as_matrix()
    matrix.setflags(write=False)
    return matrix


def _transform(parameters: FloatArray) -> FloatArray:
    matrix = np.eye(4)
    matrix[:3, :3] = _rotation(parameters)
    matrix[:3, 3] = parameters[0:3]
    return matrix


# Each class's distance takes one parameter vector (p,) and points (n, 3), or a batch of them
# (B, 1, p) and points (B, n, 3): parameters are read as parameters[..., i], points' coordinates
# along the last axis.


def _plane_normal(parameters: FloatArray) -> FloatArray:
    polar, azimuth = parameters[..., 0], parameters[..., 1]
    return np.stack(
        [np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)],
        axis=-1,
    )


def _plane(parameters: FloatArray, points: FloatArray) -> FloatArray:
    # d = n . p - offset
    column = np.swapaxes(np.atleast_2d(_plane_normal(parameters)), -1, -2)
    return np.asarray((points @ column)[..., 0] - parameters[..., 2])


def _sphere(parameters: FloatArray, points: FloatArray) -> FloatArray:
    # d = |p - c| - r
    return np.asarray(np.linalg.norm(points - parameters[..., 0:3], axis=-1) - parameters[..., 3])


def _cylinder(parameters: FloatArray, points: FloatArray) -> FloatArray:
    # the exact distance to a capped cylinder: q = (rho - r, |z| - h / 2)
    local = local_coordinates(parameters, points)
    radius, height = parameters[..., 6], parameters[..., 7]
    q_rho = np.hypot(local[..., 0], local[..., 1]) - radius
    q_z = np.abs(local[..., 2]) - 0.5 * height
    outside = np.hypot(np.maximum(q_rho, 0.0), np.maximum(q_z, 0.0))
    return np.asarray(outside + np.minimum(np.maximum(q_rho, q_z), 0.0))


def _capsule(parameters: FloatArray, points: FloatArray) -> FloatArray:
    # distance to the axis segment [-L/2, L/2] along Z, minus r
    local = local_coordinates(parameters, points)
    radius, length = parameters[..., 6], parameters[..., 7]
    z = np.clip(local[..., 2], -0.5 * length, 0.5 * length)
    axis = np.stack([0 * z, 0 * z, z], axis=-1)
    return np.asarray(np.linalg.norm(local - axis, axis=-1) - radius)


def _cone(parameters: FloatArray, points: FloatArray) -> FloatArray:
    # the cross-section is the triangle (0, 0), (R, 0), (0, h) in (rho, z): distance to its
    # base (0, 0)-(R, 0) and its slant edge (R, 0)-(0, h), negative inside the triangle
    local = local_coordinates(parameters, points)
    radius, height = parameters[..., 6], parameters[..., 7]
    rho = np.hypot(local[..., 0], local[..., 1])
    z = local[..., 2]
    base = np.hypot(rho - np.clip(rho, 0.0, radius), z)
    # the slant from (R, 0) along (-R, h): t the nearest point's fraction of it
    t = np.clip(((radius - rho) * radius + z * height) / (radius**2 + height**2), 0.0, 1.0)
    slant = np.hypot(rho - radius * (1.0 - t), z - height * t)
    distance = np.minimum(base, slant)
    inside = (z >= 0.0) & (rho * height + z * radius <= radius * height)
    return np.asarray(np.where(inside, -distance, distance))


def _torus(parameters: FloatArray, points: FloatArray) -> FloatArray:
    # d = sqrt((rho - R)^2 + z^2) - r
    local = local_coordinates(parameters, points)
    minor = parameters[..., 7]
    major = parameters[..., 6] + minor
    rho = np.hypot(local[..., 0], local[..., 1])
    return np.asarray(np.hypot(rho - major, local[..., 2]) - minor)


def _box(parameters: FloatArray, points: FloatArray) -> FloatArray:
    # the exact box distance: q = |p| - e / 2; |max(q, 0)| + min(max_i q_i, 0)
    local = local_coordinates(parameters, points)
    q = np.abs(local) - 0.5 * parameters[..., 6:9]
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=-1)
    return np.asarray(outside + np.minimum(q.max(axis=-1), 0.0))


def _axis_ends(size: int, axis: int) -> Callable[[FloatArray], tuple[Growth, ...]]:
    """The growths of a size measured along the shape's own ``axis`` between two ends, the
    centre halfway: the parameter at 6 + ``size`` grows and the centre follows the moving end
    by half."""

    def growths(parameters: FloatArray) -> tuple[Growth, ...]:
        direction = _rotation(parameters)[:, axis]
        ends = []
        for sense in (1.0, -1.0):
            change = np.zeros(len(parameters))
            change[0:3] = 0.5 * sense * direction
            change[6 + size] = 1.0
            ends.append(((size,), change))
        return tuple(ends)

    return growths


def _box_growths(parameters: FloatArray) -> tuple[Growth, ...]:
    return tuple(g for axis in range(3) for g in _axis_ends(axis, axis)(parameters))


def _cylinder_growths(parameters: FloatArray) -> tuple[Growth, ...]:
    # the height at either cap, and the radius: the side moves out by one metre per metre
    radial = np.zeros(len(parameters))
    radial[6] = 1.0
    return (*_axis_ends(1, 2)(parameters), ((0,), radial))


def _cone_growth(parameters: FloatArray) -> tuple[Growth, ...]:
    # the base moves out along -Z by one metre and the slant goes on: the radius grows by R / h
    change = np.zeros(len(parameters))
    change[0:3] = -_rotation(parameters)[:, 2]
    change[6] = parameters[6] / parameters[7]
    change[7] = 1.0
    return (((0, 1), change),)


def _canonical_pose(parameters: FloatArray) -> FloatArray:
    """The rotation vector as scipy writes it back (norm at most pi)."""
    parameters[3:6] = Rotation.from_rotvec(parameters[3:6]).as_rotvec()
    return parameters


def _canonical_box(parameters: FloatArray) -> FloatArray:
    """Extents in increasing order, the box's axes permuted with them (one axis reversed when
    the permutation would mirror the frame: a box is the same either way along an axis)."""
    order = np.argsort(parameters[6:9], kind="stable")
    axes = _rotation(parameters)[:, order].copy()
    if np.linalg.det(axes) < 0:
        axes[:, 0] *= -1.0
    parameters[3:6] = Rotation.from_matrix(axes).as_rotvec()
    parameters[6:9] = parameters[6:9][order]
    return parameters


def _cone_mesh(parameters: FloatArray) -> trimesh.Trimesh:
    mesh = trimesh.creation.cone(radius=parameters[6], height=parameters[7], sections=64)
    mesh.apply_transform(_transform(parameters))
    return mesh


def _with_pose(make: Callable[[FloatArray], trimesh.Trimesh]) -> Callable[..., trimesh.Trimesh]:
    def build(parameters: FloatArray) -> trimesh.Trimesh:
        mesh = make(parameters)
        mesh.apply_transform(_transform(parameters))
        return mesh

    return build


_POSE = ("cx", "cy", "cz", "wx", "wy", "wz")

#: Every class, by name, in the order reports list them.
PRIMITIVES: dict[str, Primitive] = {
    p.name: p
    for p in (
        Primitive(
            "plane", ("polar", "azimuth", "offset"), 3, (), _plane, lambda p: np.zeros(0), None
        ),
        Primitive(
            "sphere",
            ("cx", "cy", "cz", "radius"),
            4,
            ("radius",),
            _sphere,
            lambda p: p[3:4],
            lambda p: trimesh.creation.icosphere(subdivisions=3, radius=p[3]).apply_translation(
                p[0:3]
            ),
        ),
        Primitive(
            "cylinder",
            (*_POSE, "radius", "height"),
            7,
            ("radius", "height"),
            _cylinder,
            lambda p: p[6:8],
            _with_pose(lambda p: trimesh.creation.cylinder(radius=p[6], height=p[7], sections=64)),
            _growths=_cylinder_growths,
            _canonical=_canonical_pose,
        ),
        Primitive(
            "capsule",
            (*_POSE, "radius", "length"),
            7,
            ("radius", "length"),
            _capsule,
            lambda p: p[6:8],
            _with_pose(
                lambda p: trimesh.creation.capsule(height=p[7], radius=p[6], count=[32, 32])
            ),
            _growths=_axis_ends(1, 2),
            _canonical=_canonical_pose,
            holds=("sphere",),
        ),
        Primitive(
            "cone",
            (*_POSE, "radius", "height"),
            7,
            ("radius", "height"),
            _cone,
            lambda p: p[6:8],
            _cone_mesh,
            _growths=_cone_growth,
            _canonical=_canonical_pose,
        ),
        Primitive(
            "torus",
            (*_POSE, "hole", "minor_radius"),
            8,
            ("major_radius", "minor_radius"),
            _torus,
            lambda p: np.array([p[6] + p[7], p[7]]),
            _with_pose(
                lambda p: trimesh.creation.torus(
                    major_radius=p[6] + p[7],
                    minor_radius=p[7],
                    major_sections=64,
                    minor_sections=32,
                )
            ),
            lambda sizes: np.array([sizes[0] - sizes[1], sizes[1]]),
            _canonical=_canonical_pose,
        ),
        Primitive(
            "box",
            (*_POSE, "extent_x", "extent_y", "extent_z"),
            9,
            ("extent_x", "extent_y", "extent_z"),
            _box,
            lambda p: p[6:9],
            _with_pose(lambda p: trimesh.creation.box(extents=p[6:9])),
            _growths=_box_growths,
            _canonical=_canonical_box,
        ),
    )
}


def primitive(name: str) -> Primitive:
    """The class called ``name`` (KeyError naming the known ones otherwise)."""
    try:
        return PRIMITIVES[name]
    except KeyError:
        raise KeyError(f"unknown shape class {name!r} (known: {', '.join(PRIMITIVES)})") from None
