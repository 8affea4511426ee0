"""The objects of a scene: a closed trimesh mesh at a pose, with its signed distance.

An object is a primitive of the shape classes recognition knows (``mapping.primitives``: sphere,
cylinder, capsule, cone, torus, box; the same parameters, so a scene's truth and a recognised
fit compare directly) or a user's mesh file (STL, OBJ, PLY, in metres). Either is placed by a
pose: a position (m, world frame) and a rotation vector (rad, R = exp([w]x)) applied about the
object's own origin (a primitive's centre; a cone's base centre, its apex on local +Z).

The signed distance d(p) (m, positive outside) is what the simulator's touch search uses: exact
for a primitive (the same function recognition fits), trimesh's closest-point distance to the
faces for a mesh, which must therefore be closed (watertight) for its inside to mean anything.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.mapping.primitives import PRIMITIVES
from sensing_antenna.scene.proximity import signed_distance

__all__ = [
    "MAX_MESH_EXTENT",
    "MAX_OBJECT_SIZE",
    "MIN_OBJECT_SIZE",
    "OBJECT_SHAPES",
    "SIZE_KEYS",
    "SceneObject",
    "mesh_object",
    "mesh_problem",
    "primitive_object",
    "read_mesh",
]

FloatArray = NDArray[np.float64]

#: The primitive shapes a scene may hold (``mesh`` is a user's file).
OBJECT_SHAPES = ("sphere", "cylinder", "capsule", "cone", "torus", "box")

#: Each primitive's sizes by name, in the order :func:`primitive_object` takes them (a box's
#: ``extents`` is its three edge lengths); the scene file's keys.
SIZE_KEYS: dict[str, tuple[str, ...]] = {
    "sphere": ("radius",),
    "cylinder": ("radius", "height"),
    "capsule": ("radius", "length"),
    "cone": ("radius", "height"),
    "torus": ("major_radius", "minor_radius"),
    "box": ("extents",),
}

#: Largest extent (m) of a user's mesh: 10 m, ten times an antenna's reach. A mesh written in
#: millimetres and read as metres is a thousand times too large.
MAX_MESH_EXTENT = 10.0

#: Smallest size (m) of an object: a primitive's every size and a mesh's largest extent. 1 mm:
#: smaller, a size in a scene file is most likely in the wrong unit; and a primitive's sizes
#: then stay within 1e-4 of each other (10 m at most), a ratio its mesh keeps non-empty
#: (trimesh merges vertices closer than 1e-8 of the mesh's own size).
MIN_OBJECT_SIZE = 1e-3

#: Largest size of a primitive (m): an object the antenna (1 m or so) can explore.
MAX_OBJECT_SIZE = 10.0


#: How a scene reads a mesh in other units, for :func:`mesh_problem`'s messages.
SCENE_SCALE_HINT = "a scene's scale = 0.001 reads it in millimetres"


def mesh_problem(
    mesh: trimesh.Trimesh, scale: float = 1.0, unit_hint: str = SCENE_SCALE_HINT
) -> str | None:
    """Why a user's mesh, its coordinates times ``scale`` in m, cannot be an object, or None:
    vertices that are not finite, a largest extent beyond :data:`MAX_MESH_EXTENT` or below
    :data:`MIN_OBJECT_SIZE` (the message ends with ``unit_hint``, how to read it in other
    units)."""
    vertices = np.asarray(mesh.vertices, dtype=float)
    if not np.all(np.isfinite(vertices)):
        return "vertices that are not finite numbers"
    extent = scale * float(np.max(vertices.max(axis=0) - vertices.min(axis=0)))
    if not extent >= MIN_OBJECT_SIZE:
        return (
            f"its largest extent is {extent:.4g} m, less than {MIN_OBJECT_SIZE:g} m: read in the "
            f"wrong unit? ({unit_hint})"
        )
    if extent > MAX_MESH_EXTENT:
        return (
            f"its largest extent is {extent:.4g} m, more than {MAX_MESH_EXTENT:g} m: in metres? "
            f"(a mesh in millimetres reads a thousand times too large; {unit_hint})"
        )
    return None


#: Why a mesh that is not closed cannot be a scene's object.
NOT_CLOSED = (
    "the mesh is not closed (watertight), so its inside is undefined (trimesh's fill_holes may"
    " close it)"
)


def read_mesh(
    path: Path, scale: float = 1.0, unit_hint: str = SCENE_SCALE_HINT, closed: bool = True
) -> trimesh.Trimesh:
    """The triangles of a user's mesh file (STL, OBJ, PLY; coordinates times ``scale`` in m),
    as trimesh reads them (not scaled); SensingAntennaError naming the file and the problem
    when it is missing, unreadable, empty, fails :func:`mesh_problem` (``unit_hint``) or, with
    ``closed``, is not closed (:data:`NOT_CLOSED`)."""
    if not path.is_file():
        raise SensingAntennaError(
            f"{path}: {'a directory, not a mesh file' if path.is_dir() else 'no such mesh file'}"
        )
    try:
        mesh = trimesh.load_mesh(path, force="mesh")
    except Exception as exc:  # trimesh raises many kinds on a malformed file
        raise SensingAntennaError(f"{path}: not a readable mesh ({exc})") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise SensingAntennaError(f"{path}: the file holds no triangles")
    problem = mesh_problem(mesh, scale, unit_hint)
    if problem is None and closed and not mesh.is_watertight:
        problem = NOT_CLOSED
    if problem is not None:
        at = "" if scale == 1.0 else f" at scale {scale:g}"
        raise SensingAntennaError(f"{path}{at}: {problem}")
    return mesh


#: Subdivision of the primitives' meshes used for figures and surface scores: finer than
#: recognition's so that a faceted mesh is within 0.1 mm of the exact surface for the
#: benchmark's sizes (a 256-gon's sagitta is 7.5e-5 of its radius).
_SECTIONS = 256


@dataclass(frozen=True)
class SceneObject:
    """One object of a scene.

    Attributes
    ----------
    name : str
        Its name in the scene file.
    shape : str
        A primitive class (:data:`OBJECT_SHAPES`) or ``mesh``.
    parameters : array, shape (k,)
        The primitive's parameter vector (``mapping.primitives``: centre, rotation vector,
        sizes; m, rad); empty for a mesh.
    mesh : trimesh.Trimesh
        The object's surface in the world frame (m).
    """

    name: str
    shape: str
    parameters: FloatArray
    mesh: trimesh.Trimesh = field(repr=False)

    @property
    def sizes(self) -> dict[str, float]:
        """The primitive's sizes by name (m); the mesh's bounding-box extents for a mesh."""
        if self.shape == "mesh":
            extents = self.mesh.extents
            return {f"extent_{axis}": float(v) for axis, v in zip("xyz", extents, strict=True)}
        shape = PRIMITIVES[self.shape]
        return dict(zip(shape.size_names, map(float, shape.sizes(self.parameters)), strict=True))

    def signed_distance(self, points: ArrayLike) -> FloatArray:
        """d (m), shape (n,), of points of shape (n, 3) (m): positive outside."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        if self.shape == "mesh":
            return signed_distance(self.mesh, p)
        return PRIMITIVES[self.shape].signed_distance(self.parameters, p)

    def normal(self, point: ArrayLike, step: float = 1e-6) -> FloatArray:
        """Outward unit normal (the gradient of d by central differences of ``step`` m)."""
        p = np.asarray(point, dtype=float).reshape(3)
        probes = p + np.vstack([np.eye(3) * step, -np.eye(3) * step])
        d = self.signed_distance(probes)
        gradient = (d[:3] - d[3:]) / (2.0 * step)
        return np.asarray(gradient / np.linalg.norm(gradient))


def _rotation(rotation: ArrayLike) -> FloatArray:
    return np.asarray(Rotation.from_rotvec(np.array(rotation, dtype=float)).as_matrix())


def _fine_mesh(shape: str, parameters: FloatArray) -> trimesh.Trimesh:
    # meshed at unit size and scaled: trimesh's tolerances are absolute, and would merge the
    # vertices of a millimetre's section
    sizes = PRIMITIVES[shape].sizes(parameters)
    unit = float(np.max(sizes))
    sizes = sizes / unit
    if shape == "sphere":
        mesh = trimesh.creation.icosphere(subdivisions=5, radius=1.0)
        return mesh.apply_scale(unit).apply_translation(parameters[0:3])
    if shape == "cylinder":
        mesh = trimesh.creation.cylinder(radius=sizes[0], height=sizes[1], sections=_SECTIONS)
    elif shape == "capsule":
        mesh = trimesh.creation.capsule(height=sizes[1], radius=sizes[0], count=[64, 64])
    elif shape == "cone":
        mesh = trimesh.creation.cone(radius=sizes[0], height=sizes[1], sections=_SECTIONS)
    elif shape == "torus":
        mesh = trimesh.creation.torus(
            major_radius=sizes[0], minor_radius=sizes[1], major_sections=128, minor_sections=64
        )
    else:
        mesh = trimesh.creation.box(extents=sizes)
    matrix = np.eye(4)
    matrix[:3, :3] = _rotation(parameters[3:6])
    matrix[:3, 3] = parameters[0:3]
    return mesh.apply_scale(unit).apply_transform(matrix)


def primitive_object(
    name: str,
    shape: str,
    sizes: ArrayLike | Mapping[str, ArrayLike],
    position: ArrayLike = (0.0, 0.0, 0.0),
    rotation: ArrayLike = (0.0, 0.0, 0.0),
) -> SceneObject:
    """A primitive at a pose.

    Parameters
    ----------
    name : str
    shape : str
        One of :data:`OBJECT_SHAPES`.
    sizes : array or mapping of str to float
        The shape's sizes (m), in the order of :data:`SIZE_KEYS` or by those names: sphere
        ``radius``; cylinder ``radius``, ``height``; capsule ``radius``, ``length`` (of the
        axis segment); cone ``radius`` (of the base), ``height``; torus ``major_radius``,
        ``minor_radius``; box ``extents`` (its three edges, along its local x, y, z).
    position : array, shape (3,)
        Centre (a cone's base centre) in the world (m).
    rotation : array, shape (3,)
        Rotation vector of its local axes (rad).
    """
    if shape not in OBJECT_SHAPES:
        raise ValueError(f"unknown shape {shape!r} (known: {', '.join(OBJECT_SHAPES)})")
    s = PRIMITIVES[shape].size_parameters(_size_vector(shape, sizes))
    if shape == "sphere":
        parameters = np.concatenate([np.asarray(position, dtype=float), s])
    else:
        parameters = np.concatenate(
            [np.asarray(position, dtype=float), np.asarray(rotation, dtype=float), s]
        )
    return SceneObject(name, shape, parameters, _fine_mesh(shape, parameters))


def _size_vector(shape: str, sizes: ArrayLike | Mapping[str, ArrayLike]) -> FloatArray:
    """``primitive_object``'s sizes (m) as one vector in :data:`SIZE_KEYS` order; a ValueError
    names the sizes the shape takes when they are not those."""
    keys = SIZE_KEYS[shape]
    names = PRIMITIVES[shape].size_names  # as SceneObject.sizes names them
    takes = f"a {shape} takes {', '.join(keys)}"
    values: Any = sizes
    if isinstance(sizes, Mapping):
        given = set(sizes)
        if given not in (set(keys), set(names)):
            raise ValueError(f"sizes: {takes}, got {', '.join(map(str, sizes)) or 'none'}")
        values = [sizes[key] for key in (keys if given == set(keys) else names)]
    try:
        vector = np.hstack([np.asarray(v, dtype=float).reshape(-1) for v in np.atleast_1d(values)])
    except (TypeError, ValueError):
        raise ValueError(f"sizes: {takes} (m), got {sizes!r}") from None
    if vector.size != len(names):
        raise ValueError(f"sizes: {takes} ({len(names)} numbers, m), got {vector.size}")
    if not np.all(np.isfinite(vector) & (vector > 0.0)):
        raise ValueError(f"sizes: {takes}, each a length > 0 (m), got {sizes!r}")
    if not np.all((vector >= MIN_OBJECT_SIZE) & (vector <= MAX_OBJECT_SIZE)):
        raise ValueError(
            f"sizes: {takes}, each from {MIN_OBJECT_SIZE:g} to {MAX_OBJECT_SIZE:g} m, got"
            f" {sizes!r}: in metres?"
        )
    if shape == "torus" and not vector[1] < vector[0]:
        raise ValueError("sizes: a torus's minor_radius must be smaller than its major_radius")
    return vector


def mesh_object(
    name: str,
    mesh: trimesh.Trimesh,
    position: ArrayLike = (0.0, 0.0, 0.0),
    rotation: ArrayLike = (0.0, 0.0, 0.0),
    scale: float = 1.0,
) -> SceneObject:
    """A user's mesh (m, its own frame) scaled, turned about its origin and moved to a pose."""
    matrix = np.eye(4)
    matrix[:3, :3] = _rotation(rotation) * scale
    matrix[:3, 3] = np.asarray(position, dtype=float)
    placed = mesh.copy().apply_transform(matrix)
    empty = np.zeros(0)
    return SceneObject(name, "mesh", empty, placed)
