"""The antenna base's pose in the world: where a recording's absolute frame sits.

A recording's points are in its absolute frame O-X^a Y^a Z^a (origin at the base point O, Z^a
up; docs/recording-format.md). A map gathers recordings made from several base poses (a head on
a robot), so each recording may say where its absolute frame is in the world with the optional
metadata key ``base_pose``: JSON with ``position`` (m, world frame) and either ``quaternion``
(``[w, x, y, z]``, unit up to rounding) or ``rotation`` (3 x 3, rows, the absolute frame's axes
in world coordinates as columns). Absent, the absolute frame is the world frame.

A world point is p_w = R p_a + t.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.errors import FieldError

__all__ = ["BASE_POSE_KEY", "BasePose", "base_pose_from_metadata", "quaternion_order_hint"]

#: The recording metadata key holding the base pose.
BASE_POSE_KEY = "base_pose"

#: How far from orthonormal a given rotation may be (largest entry of R R^T - I); it is then
#: made orthonormal (the nearest rotation). 0.003: a rotation printed with three decimals, as a
#: robot's log often does, is off by up to about 0.0015; one printed with two (its point a few
#: mm off at the link's reach), a reflection, a typo or a scaled matrix by more.
ORTHONORMAL_TOLERANCE = 0.003

#: Largest magnitude of any number of a pose: a rotation's entries and a unit quaternion's are
#: at most 1, a position beyond 100 m is refused with its own message; this bound keeps every
#: product the checks form (a determinant cubes the entries) far from overflow, and a number
#: beyond it is no pose's.
MAX_POSE_NUMBER = 1e6

#: Farthest a base may sit from the world's origin (m): 100 m holds a robot's workspace in any
#: lab or field frame a map of centimetre-sized contacts would use, and refuses a position in
#: millimetres (a base 0.2 m away written as 200).
MAX_BASE_DISTANCE = 100.0

#: How far from unit norm a given quaternion may be; it is then normalised. 1 %: a quaternion
#: written with three decimals is off by up to about 0.2 %, while one that is not a rotation at
#: all (a typo, another convention's scaling) is off by far more.
QUATERNION_NORM_TOLERANCE = 0.01

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class BasePose:
    """A rigid pose of the antenna's absolute frame in the world.

    Attributes
    ----------
    rotation : array, shape (3, 3)
        R, world coordinates of the absolute frame's axes as columns (orthonormal, det +1;
        one within :data:`ORTHONORMAL_TOLERANCE` is made so).
    position : array, shape (3,)
        t, the base point O in the world frame (m).
    """

    rotation: FloatArray
    position: FloatArray

    def __post_init__(self) -> None:
        rotation = np.array(self.rotation, dtype=float).reshape(3, 3)
        position = np.array(self.position, dtype=float).reshape(3)
        if not (np.all(np.isfinite(rotation)) and np.all(np.isfinite(position))):
            raise FieldError(BASE_POSE_KEY, "rotation and position must be finite numbers")
        # hypot scales by the largest coordinate: the plain norm of 1e300 overflows
        distance = math.hypot(*(float(x) for x in position))
        if distance > MAX_BASE_DISTANCE:
            raise FieldError(
                BASE_POSE_KEY,
                f"position is {distance:.4g} m from the world's origin, more than "
                f"{MAX_BASE_DISTANCE:g} m: in metres? (millimetres read as metres land here)",
            )
        error = float(np.abs(rotation @ rotation.T - np.eye(3)).max())
        determinant = float(np.linalg.det(rotation))
        if error > ORTHONORMAL_TOLERANCE or determinant < 0:
            raise FieldError(
                BASE_POSE_KEY,
                "rotation must be orthonormal with determinant +1 (within"
                f" {ORTHONORMAL_TOLERANCE:g}, then made so):"
                f" R R^T is up to {error:.3g} off the identity, determinant {determinant:.4g}",
            )
        # the nearest rotation (polar decomposition): a printed matrix's rounding taken off
        left, _, right = np.linalg.svd(rotation)
        rotation = left @ right
        rotation.setflags(write=False)
        position.setflags(write=False)
        object.__setattr__(self, "rotation", rotation)
        object.__setattr__(self, "position", position)

    @classmethod
    def identity(cls) -> BasePose:
        """The absolute frame is the world frame."""
        return cls(np.eye(3), np.zeros(3))

    @classmethod
    def from_matrix(cls, matrix: ArrayLike) -> BasePose:
        """From a 4 x 4 homogeneous transform (world from absolute frame)."""
        m = np.asarray(matrix, dtype=float)
        if m.shape != (4, 4):
            raise FieldError(BASE_POSE_KEY, f"a 4 x 4 matrix is needed, got shape {m.shape}")
        return cls(m[:3, :3], m[:3, 3])

    @classmethod
    def from_quaternion(cls, position: ArrayLike, quaternion: Sequence[float]) -> BasePose:
        """From a position (m) and a unit quaternion ``[w, x, y, z]`` (normalised when within
        :data:`QUATERNION_NORM_TOLERANCE` of unit norm, as a printed one is)."""
        q = np.asarray(quaternion, dtype=float)
        if q.shape != (4,) or not np.all(np.isfinite(q)):
            raise FieldError(BASE_POSE_KEY, "quaternion must be four numbers [w, x, y, z]")
        norm = math.hypot(*(float(v) for v in q))  # no overflow on 1e300 entries
        if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
            raise FieldError(
                BASE_POSE_KEY,
                f"quaternion must be of unit norm (within 1 %, then normalised), got {norm:.6g}",
            )
        w, x, y, z = q / norm
        # rotation matrix of a unit quaternion (Hamilton convention)
        rotation = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
            ]
        )
        return cls(rotation, np.asarray(position, dtype=float))

    @property
    def matrix(self) -> FloatArray:
        """The 4 x 4 homogeneous transform, world from absolute frame."""
        m = np.eye(4)
        m[:3, :3] = self.rotation
        m[:3, 3] = self.position
        return m

    def point_to_world(self, point_a: ArrayLike) -> FloatArray:
        """p_w = R p_a + t, shape (..., 3) (m)."""
        return np.asarray(point_a, dtype=float) @ self.rotation.T + self.position

    def covariance_to_world(self, covariance_a: ArrayLike) -> FloatArray:
        """Sigma_w = R Sigma_a R^T, shape (3, 3) (m^2)."""
        return np.asarray(self.rotation @ np.asarray(covariance_a, dtype=float) @ self.rotation.T)

    def to_json(self) -> str:
        """The metadata value: ``{"position": [...], "rotation": [[...], ...]}``."""
        return json.dumps({"position": self.position.tolist(), "rotation": self.rotation.tolist()})


def base_pose_from_metadata(metadata: Mapping[str, str], source: str | None = None) -> BasePose:
    """The ``base_pose`` of a recording's metadata; identity when the key is absent.

    Raises
    ------
    FieldError
        One line naming the source and the key when the value is not a valid pose.
    """
    text = metadata.get(BASE_POSE_KEY)
    if text is None:
        return BasePose.identity()
    try:
        data: Any = json.loads(text, object_pairs_hook=_unique_keys)
    except json.JSONDecodeError as exc:
        raise FieldError(BASE_POSE_KEY, f"not JSON ({exc.msg})", source) from None
    except RecursionError:
        raise FieldError(BASE_POSE_KEY, "not a pose (JSON nested too deep)", source) from None
    except _DuplicateKey as exc:
        raise FieldError(BASE_POSE_KEY, str(exc), source) from None
    except ValueError:  # an integer of thousands of digits
        raise FieldError(BASE_POSE_KEY, "not a pose (a number too long)", source) from None
    try:
        return _pose_from_json(data)
    except FieldError as exc:
        raise FieldError(BASE_POSE_KEY, exc.problem, source) from None


def quaternion_order_hint(metadata: Mapping[str, str]) -> str | None:
    """A line when a ``base_pose`` quaternion reads, in the format's ``[w, x, y, z]``, as a half
    turn (its first number under 0.1: more than 168 degrees) while in the ``[x, y, z, w]`` order
    of ROS and scipy it is a turn of under 90 degrees: as a base tilted more than 30 degrees
    from the world's vertical against a level one turned about the vertical (its second number
    under 0.1 too), else as the two turns' angles (the identity written in ROS's order reads as
    a base turned half round); None otherwise, or when the pose is none (its own error says
    so)."""
    try:
        data = json.loads(metadata.get(BASE_POSE_KEY, ""))
        q = np.asarray(data["quaternion"], dtype=float)
    except (ValueError, TypeError, KeyError, IndexError, RecursionError):
        return None
    if q.shape != (4,) or not np.all(np.isfinite(q)) or not np.linalg.norm(q) > 0.0:
        return None
    w, x, y, z = q / np.linalg.norm(q)
    # each order's angle of turn, 2 acos |scalar part|
    ours, theirs = (math.degrees(2.0 * math.acos(min(1.0, abs(c)))) for c in (w, z))
    if not abs(w) < 0.1:
        return None
    # read as [w, x, y, z], Z^a's world z is 1 - 2 (x^2 + y^2)
    tilt = math.degrees(math.acos(min(1.0, max(-1.0, 1.0 - 2.0 * (x * x + y * y)))))
    if not (abs(x) < 0.1 and tilt > 30.0):
        if not theirs < 90.0:
            return None
        return (
            f"its base_pose quaternion {_listed(q)} reads as [w, x, y, z] (the format's order) "
            f"as a base turned {ours:.0f} degrees; in the [x, y, z, w] order of ROS and scipy "
            f"it would be turned {theirs:.0f} degrees"
        )
    # read as [x, y, z, w]: a turn of 2 atan2(y, z) about the vertical, nearly
    turn = math.degrees(2.0 * math.atan2(y, z))
    return (
        f"its base_pose quaternion {_listed(q)} reads as [w, x, y, z] (the format's order) as a "
        f"base tilted {tilt:.0f} degrees from the vertical; in the [x, y, z, w] order of ROS "
        f"and scipy it would be a level base turned {turn:.0f} degrees about the vertical"
    )


def _listed(values: FloatArray) -> str:
    # to three digits, a rounding residue (6.12e-17) as 0
    return "[" + ", ".join(f"{float(v) if abs(v) >= 5e-4 else 0.0:.3g}" for v in values) + "]"


def _pose_from_json(data: Any) -> BasePose:
    if not isinstance(data, dict):
        raise FieldError(BASE_POSE_KEY, "must be a JSON object with position and rotation")
    unknown = set(data) - {"position", "quaternion", "rotation"}
    if unknown:
        ros = (
            " (a ROS pose's orientation {x, y, z, w} is written here as quaternion [w, x, y, z])"
            if "orientation" in unknown
            else ""
        )
        raise FieldError(
            BASE_POSE_KEY,
            f"unknown field(s) {', '.join(sorted(unknown))}: it holds position, and quaternion"
            f" or rotation{ros}",
        )
    listed = "" if not isinstance(data.get("position"), dict) else " as a list [x, y, z]"
    position = _numbers(data.get("position"), (3,), f"position: three numbers (m){listed}")
    if ("quaternion" in data) == ("rotation" in data):
        raise FieldError(BASE_POSE_KEY, "give exactly one of quaternion and rotation")
    if "quaternion" in data:
        quaternion = _numbers(data["quaternion"], (4,), "quaternion: four numbers [w, x, y, z]")
        return BasePose.from_quaternion(position, quaternion.tolist())
    rotation = _numbers(data["rotation"], (3, 3), "rotation: a 3 x 3 list of rows")
    return BasePose(rotation, position)


class _DuplicateKey(ValueError):
    """A JSON object gives a key twice."""


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """A JSON object's fields, refusing a key given twice (JSON would keep the last)."""
    data: dict[str, Any] = {}
    for key, value in pairs:
        if key in data:
            raise _DuplicateKey(f"{key}: given twice")
        data[key] = value
    return data


def _numbers(value: Any, shape: tuple[int, ...], what: str) -> FloatArray:
    # JSON numbers only, nested as the shape says: true, false and "0" are not coordinates
    rows = value if len(shape) == 2 and isinstance(value, list) else [value]
    if not all(
        isinstance(row, list)
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in row)
        for row in rows
    ):
        raise FieldError(BASE_POSE_KEY, f"{what} expected")
    try:
        array = np.array(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise FieldError(BASE_POSE_KEY, f"{what} expected") from None
    if array.shape != shape:
        raise FieldError(BASE_POSE_KEY, f"{what} expected")
    if not np.all(np.isfinite(array)):
        raise FieldError(BASE_POSE_KEY, f"{what} expected, finite")
    if not float(np.abs(array).max()) <= MAX_POSE_NUMBER:
        raise FieldError(BASE_POSE_KEY, f"{what} expected, each within +-{MAX_POSE_NUMBER:g}")
    return array
