"""Scene files: the objects, the antenna's base poses and the region the head may sweep (TOML).

::

    name = "a sphere"                     # optional
    description = "free text"             # optional

    [[objects]]                           # one table per object, at least one
    name = "ball"                         # optional (default: object1, object2, ...)
    shape = "sphere"                      # sphere, cylinder, capsule, cone, torus, box or mesh
    radius = 0.06                         # the shape's sizes (m), below
    position = [0.6, 0.1, 0.0]            # m, world frame (a cone: its base centre)
    rotation = [0.0, 0.0, 0.0]            # optional rotation vector (rad, at most a turn)

    [[objects]]
    shape = "mesh"
    file = "mug.stl"                      # STL, OBJ or PLY, closed; relative to the scene file
    scale = 0.001                         # optional: the file's unit in m (mm here)
    position = [0.5, -0.2, 0.0]

    [[bases]]                             # the antenna's base poses; default: one, the origin
    position = [0.0, 0.0, 0.0]            # the head's base point O (m)
    yaw = 0.0                             # rad about Z, within a turn; or quaternion [w, x, y, z]
    azimuth = [-0.3, 0.3]                 # optional: this base's own explored angles (rad),
    elevation = [-0.8, -0.4]              # each defaulting to [explore]'s

    [explore]                             # the region swept (defaults below)
    azimuth = [-0.6, 0.6]                 # theta1 range (rad): azimuthal sweeps run across it
    elevation = [-0.35, 0.35]             # theta2 range (rad): vertical sweeps run across it
    azimuthal_sweeps = 5                  # the grid's elevations per base, each swept both ways
    vertical_sweeps = 5                   # the grid's azimuths per base, swept up and down in turn

Sizes: sphere ``radius``; cylinder ``radius``, ``height``; capsule ``radius``, ``length`` (of
the axis segment); cone ``radius`` (base), ``height``; torus ``major_radius``,
``minor_radius``; box ``extents = [x, y, z]``; each from 1 mm to 10 m (a mesh's largest extent
too, after ``scale``). Every error names the file, the field and the problem in one line
(:class:`SceneError`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import trimesh

from sensing_antenna.errors import FieldError, SensingAntennaError, format_value
from sensing_antenna.mapping.pose import MAX_BASE_DISTANCE, BasePose
from sensing_antenna.scene.objects import (
    MAX_OBJECT_SIZE,
    MIN_OBJECT_SIZE,
    SIZE_KEYS,
    SceneObject,
    mesh_object,
    primitive_object,
    read_mesh,
)
from sensing_antenna.scene.sweep import MAX_AZIMUTH, MAX_ELEVATION
from sensing_antenna.toml_files import parse_toml_file, parse_toml_text

__all__ = [
    "BUILTIN_SCENES",
    "MAX_OBJECT_SIZE",
    "ExploreRegion",
    "Scene",
    "SceneError",
    "load_scene",
]

#: Scenes shipped with the package (``antenna explore sphere``).
BUILTIN_SCENES = ("post", "sphere", "box", "cylinder")

#: Largest angle (rad) of a yaw or an object's rotation vector: one turn reaches every
#: orientation, and a larger number is most likely in degrees (90 for a quarter turn).
ANGLE_LIMIT = 2.0 * math.pi

#: Most objects, bases and grid sweeps a scene may ask for (a scene is hand-written).
_MAX_COUNT = 100

_POSE_KEYS = ("name", "shape", "position", "rotation")


class SceneError(FieldError):
    """A scene file is unreadable or one of its fields is invalid (names file and field)."""


@dataclass(frozen=True)
class ExploreRegion:
    """The angles a head may sweep (rad) and the grid of sweeps per base.

    Attributes
    ----------
    azimuth : (float, float)
        theta1 range (rad): an azimuthal sweep runs across it, either way.
    elevation : (float, float)
        theta2 from, to (rad): a vertical sweep runs across it, up or down.
    azimuthal_sweeps, vertical_sweeps : int
        The grid's elevations (each swept both ways by azimuthal sweeps) and azimuths (vertical
        sweeps) per base.
    """

    azimuth: tuple[float, float] = (-0.6, 0.6)
    elevation: tuple[float, float] = (-0.35, 0.35)
    azimuthal_sweeps: int = 5
    vertical_sweeps: int = 5


@dataclass(frozen=True)
class Scene:
    """Objects, base poses and the explored region.

    Attributes
    ----------
    name : str
    objects : tuple of SceneObject
    bases : tuple of BasePose
        Where the antenna's absolute frame sits for each group of manoeuvres (a head on a
        robot); the simulated gravity acts along each base's -Z.
    region : ExploreRegion
    source : str
        The file it came from (or the built-in's name).
    base_regions : tuple of (ExploreRegion or None)
        A base's own explored angles (its grid counts are ``region``'s), by base index; a base
        without one (None, or beyond the tuple) explores ``region``.
    """

    name: str
    objects: tuple[SceneObject, ...]
    bases: tuple[BasePose, ...]
    region: ExploreRegion
    source: str = ""
    base_regions: tuple[ExploreRegion | None, ...] = ()

    def base(self, index: int) -> BasePose:
        """The base pose of index ``index``; a ValueError names the indices there are."""
        n = len(self.bases)
        if not 0 <= index < n:
            raise ValueError(
                f"base {index}: scene {self.name!r} has {n} base pose{'s' if n != 1 else ''}"
                f" (indices 0 to {n - 1})"
            )
        return self.bases[index]

    def region_of(self, base: int) -> ExploreRegion:
        """The region base ``base`` (index) explores."""
        self.base(base)
        own = self.base_regions[base] if base < len(self.base_regions) else None
        return self.region if own is None else own

    def signed_distance(self, points: Any) -> np.ndarray:
        """Distance (m) of points (n, 3) to the nearest object, negative inside one."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        return np.min([obj.signed_distance(p) for obj in self.objects], axis=0)

    @property
    def mesh(self) -> trimesh.Trimesh:
        """Every object's mesh in one (world frame, m)."""
        mesh = trimesh.util.concatenate([obj.mesh for obj in self.objects])
        assert isinstance(mesh, trimesh.Trimesh)
        return mesh


def load_scene(name_or_path: str | Path) -> Scene:
    """A built-in scene (:data:`BUILTIN_SCENES`) by name, or a scene file (a file of that name
    comes first; a directory of that name, such as an exploration's output, does not).

    Raises
    ------
    SceneError
        One line naming the file, the field and the problem.
    """
    text = str(name_or_path)
    if text in BUILTIN_SCENES and not Path(text).is_file():
        source = f"built-in scene {text}"
        data_text = (
            resources.files("sensing_antenna")
            .joinpath(f"data/scene-{text}.toml")
            .read_text("utf-8")
        )
        data = parse_toml_text(data_text, lambda f, p: SceneError(f, p, source))
        return _build(data, source, None)
    path = Path(name_or_path)
    if not path.is_file():
        known = ", ".join(BUILTIN_SCENES)
        what = "a directory, not a scene file" if path.is_dir() else "no such file"
        raise SceneError("file", f"{what} (built-in scenes: {known})", str(path))
    data = parse_toml_file(path, lambda f, p: SceneError(f, p, str(path)))
    return _build(data, str(path), path.parent)


def _build(data: Mapping[str, Any], source: str, folder: Path | None) -> Scene:
    def fail(field_name: str, problem: str) -> SceneError:
        return SceneError(field_name, problem, source)

    unknown = set(data) - {"name", "description", "objects", "bases", "explore"}
    if unknown:
        raise fail(
            sorted(unknown)[0], "unknown key (known: name, description, objects, bases, explore)"
        )
    name = data.get("name", Path(source).stem)
    if not isinstance(name, str) or not name.isprintable() or not name:
        # one line: it goes into every recording's description
        raise fail("name", f"must be a line of text, got {format_value(name)}")
    tables = data.get("objects")
    if not isinstance(tables, list) or not tables:
        raise fail("objects", "missing: a scene needs at least one [[objects]] table")
    if len(tables) > _MAX_COUNT:
        raise fail("objects", f"{len(tables)} objects, more than {_MAX_COUNT}")
    objects = tuple(
        _object(table, f"objects[{i}]", i, folder, fail) for i, table in enumerate(tables)
    )
    base_tables = data.get("bases", [{}])
    if not isinstance(base_tables, list) or not base_tables or len(base_tables) > _MAX_COUNT:
        raise fail("bases", f"must be 1 to {_MAX_COUNT} [[bases]] tables")
    region = _region(data.get("explore", {}), fail)
    parsed = [_base(table, f"bases[{i}]", region, fail) for i, table in enumerate(base_tables)]
    bases = tuple(pose for pose, _ in parsed)
    base_regions = tuple(own for _, own in parsed)
    for i, base in enumerate(bases):
        for k, obj in enumerate(objects):
            if float(obj.signed_distance(base.position.reshape(1, 3))[0]) < 0.0:
                # the field that put it there: the base's position, its table (the origin by
                # default), or the object when the scene gives no bases
                where = f"objects[{k}]"
                if "bases" in data:
                    own = "position" in base_tables[i]
                    where = f"bases[{i}].position" if own else f"bases[{i}]"
                raise fail(
                    where,
                    f"the base point {format_value([float(x) for x in base.position])} of"
                    f" bases[{i}] lies inside objects[{k}] ({obj.name!r}): a size or position"
                    " in another unit than m?",
                )
    return Scene(name, objects, bases, region, source, base_regions)


def _table(value: object, where: str, fail: Any) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise fail(where, f"must be a table, got {format_value(value)}")
    return value


def _number(
    value: object, where: str, fail: Any, low: float | None = None, high: float | None = None
) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise fail(where, f"must be a finite number, got {format_value(value)}")
    if low is not None and not value > low:
        raise fail(where, f"must be > {low:g}, got {format_value(value)}")
    if high is not None and value > high:
        raise fail(where, f"must be at most {high:g}, got {format_value(value)}")
    return float(value)


def _angle(value: object, where: str, fail: Any) -> float:
    """An angle (rad) within one turn either way: beyond it, most likely degrees."""
    angle = _number(value, where, fail)
    if abs(angle) > ANGLE_LIMIT:
        raise fail(
            where,
            f"must be within +-{ANGLE_LIMIT:.4f} rad (one turn), got {format_value(value)}: "
            "in radians?",
        )
    return angle


def _vector(value: object, n: int, where: str, fail: Any, limit: float | None = None) -> np.ndarray:
    if not isinstance(value, list) or len(value) != n:
        raise fail(where, f"must be a list of {n} numbers, got {format_value(value)}")
    numbers = np.array([_number(v, where, fail) for v in value])
    # hypot scales by the largest entry: the plain norm of 1e300 overflows (with a warning)
    if limit is not None and math.hypot(*numbers) > limit:
        raise fail(where, f"more than {limit:g} m from the origin: in metres?")
    return numbers


def _object(value: object, where: str, index: int, folder: Path | None, fail: Any) -> SceneObject:
    table = _table(value, where, fail)
    shape = table.get("shape")
    known = (*SIZE_KEYS, "mesh")
    if shape not in known:
        raise fail(
            f"{where}.shape", f"must be one of {', '.join(known)}, got {format_value(shape)}"
        )
    allowed = set(_POSE_KEYS) | (
        {"file", "scale"} if shape == "mesh" else set(SIZE_KEYS[str(shape)])
    )
    unknown = set(table) - allowed
    if unknown:
        key = sorted(unknown)[0]
        raise fail(
            f"{where}.{key}", f"unknown key for a {shape} (known: {', '.join(sorted(allowed))})"
        )
    name = table.get("name", f"object{index + 1}")
    if not isinstance(name, str) or not name.isprintable() or not name:
        raise fail(f"{where}.name", f"must be a line of text, got {format_value(name)}")
    if "position" not in table:
        raise fail(f"{where}.position", "missing")
    position = _vector(table["position"], 3, f"{where}.position", fail, MAX_BASE_DISTANCE)
    rotation = _vector(table.get("rotation", [0.0, 0.0, 0.0]), 3, f"{where}.rotation", fail)
    turn = math.hypot(*rotation)
    if turn > ANGLE_LIMIT:
        raise fail(
            f"{where}.rotation",
            f"turns by {turn:.4g} rad, more than one turn ({ANGLE_LIMIT:.4f}): in radians?",
        )
    if shape == "mesh":
        scale = _number(table.get("scale", 1.0), f"{where}.scale", fail, 0.0, 1.0)
        mesh = _mesh_file(table.get("file"), f"{where}.file", folder, fail, scale)
        return mesh_object(name, mesh, position, rotation, scale)
    sizes: list[float] = []
    for key in SIZE_KEYS[str(shape)]:
        if key not in table:
            raise fail(
                f"{where}.{key}", f"missing (a {shape} needs {', '.join(SIZE_KEYS[str(shape)])})"
            )
        if key == "extents":
            if not isinstance(table[key], list) or len(table[key]) != 3:
                raise fail(
                    f"{where}.extents",
                    f"must be a list of 3 numbers, got {format_value(table[key])}",
                )
            sizes.extend(_size(v, f"{where}.extents", fail) for v in table[key])
        else:
            sizes.append(_size(table[key], f"{where}.{key}", fail))
    if shape == "torus" and not sizes[1] < sizes[0]:
        raise fail(f"{where}.minor_radius", "must be smaller than major_radius")
    return primitive_object(name, str(shape), sizes, position, rotation)


def _size(value: object, where: str, fail: Any) -> float:
    """A primitive's size (m), from :data:`~.objects.MIN_OBJECT_SIZE` to :data:`MAX_OBJECT_SIZE`."""
    size = _number(value, where, fail, 0.0)
    if size > MAX_OBJECT_SIZE:
        raise fail(
            where, f"must be at most {MAX_OBJECT_SIZE:g} m, got {format_value(value)}: in metres?"
        )
    if size < MIN_OBJECT_SIZE:
        raise fail(
            where, f"must be at least {MIN_OBJECT_SIZE:g} m, got {format_value(value)}: in metres?"
        )
    return size


def _mesh_file(
    value: object, where: str, folder: Path | None, fail: Any, scale: float
) -> trimesh.Trimesh:
    if not isinstance(value, str) or not value:
        raise fail(where, f"must name a mesh file (STL, OBJ, PLY), got {format_value(value)}")
    path = Path(value)
    if not path.is_absolute() and folder is not None:
        path = folder / path
    try:
        return read_mesh(path, scale)
    except SensingAntennaError as exc:
        raise fail(where, str(exc)) from None


def _base(
    value: object, where: str, region: ExploreRegion, fail: Any
) -> tuple[BasePose, ExploreRegion | None]:
    """The base's pose, and its own region when it gives angles (None: the scene's)."""
    table = _table(value, where, fail)
    known = ("position", "yaw", "quaternion", "azimuth", "elevation")
    unknown = set(table) - set(known)
    if unknown:
        raise fail(f"{where}.{sorted(unknown)[0]}", f"unknown key (known: {', '.join(known)})")
    own = None
    if "azimuth" in table or "elevation" in table:
        azimuth, elevation = _ranges(table, where, region, fail)
        own = ExploreRegion(azimuth, elevation, region.azimuthal_sweeps, region.vertical_sweeps)
    return _base_pose(table, where, fail), own


def _base_pose(table: Mapping[str, Any], where: str, fail: Any) -> BasePose:
    if "yaw" in table and "quaternion" in table:
        raise fail(f"{where}.quaternion", "give yaw or quaternion, not both")
    position = _vector(
        table.get("position", [0.0, 0.0, 0.0]), 3, f"{where}.position", fail, MAX_BASE_DISTANCE
    )
    try:
        if "quaternion" in table:
            quaternion = _vector(table["quaternion"], 4, f"{where}.quaternion", fail)
            return BasePose.from_quaternion(position, list(quaternion))
    except FieldError as exc:
        raise fail(f"{where}.quaternion", exc.problem) from None
    yaw = _angle(table.get("yaw", 0.0), f"{where}.yaw", fail)
    c, s = math.cos(yaw), math.sin(yaw)
    return BasePose(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), position)


def _ranges(
    table: Mapping[str, Any], where: str, defaults: ExploreRegion, fail: Any
) -> list[tuple[float, float]]:
    """The azimuth and elevation ranges (rad) of ``table``, each defaulting to ``defaults``'."""
    ranges = []
    for key, limit in (("azimuth", MAX_AZIMUTH), ("elevation", MAX_ELEVATION)):
        low, high = _vector(table.get(key, list(getattr(defaults, key))), 2, f"{where}.{key}", fail)
        if not -limit <= low < high <= limit:
            raise fail(
                f"{where}.{key}",
                f"must be [from, to] with -{limit:.3g} <= from < to <= {limit:.3g} rad, got"
                f" [{low:g}, {high:g}]",
            )
        ranges.append((float(low), float(high)))
    return ranges


def _region(value: object, fail: Any) -> ExploreRegion:
    table = _table(value, "explore", fail)
    defaults = ExploreRegion()
    unknown = set(table) - {"azimuth", "elevation", "azimuthal_sweeps", "vertical_sweeps"}
    if unknown:
        raise fail(
            f"explore.{sorted(unknown)[0]}",
            "unknown key (known: azimuth, elevation, azimuthal_sweeps, vertical_sweeps)",
        )
    ranges = _ranges(table, "explore", defaults, fail)
    counts = []
    for key in ("azimuthal_sweeps", "vertical_sweeps"):
        count = table.get(key, getattr(defaults, key))
        if isinstance(count, bool) or not isinstance(count, int) or not 0 <= count <= _MAX_COUNT:
            raise fail(
                f"explore.{key}",
                f"must be an integer from 0 to {_MAX_COUNT}, got {format_value(count)}",
            )
        counts.append(count)
    if counts == [0, 0]:
        raise fail(
            "explore.azimuthal_sweeps", "the grid needs at least one sweep (both counts are 0)"
        )
    return ExploreRegion(ranges[0], ranges[1], counts[0], counts[1])
