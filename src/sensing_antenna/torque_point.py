"""Torques a sensor takes about its own origin: the recording format's ``torque_point``.

The format's torques are the link's on the head about the base point O. An F/T sensor reports
them about its own origin S, which a mount may put a few centimetres from O along the link or
beside it. A recording (or a stream) whose torques are about S says so in its metadata,

    # torque_point: [S_x, S_y, S_z]

S - O in metres on the motor axes (fixed to the head, as the sensor is), and the reader moves
them to O: Gamma_O = Gamma_S + (S - O) x F, F the force read with them. Unstated, S = O.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "MAX_TORQUE_POINT",
    "MOVED_KEY",
    "TORQUE_POINT_KEY",
    "key_problem",
    "metadata_line",
    "moved_metadata",
    "point_problem",
    "torque_point_problem",
    "torques_about_base",
]

FloatArray = NDArray[np.float64]

#: The metadata key that names the point the torques are taken about.
TORQUE_POINT_KEY = "torque_point"
#: The key a reader leaves in its place once it has moved the torques to O (the point, as
#: read): the recording it gives is about O, and a copy written from it is read as such.
MOVED_KEY = "torques_moved_from"
#: Farthest a sensor's origin may lie from O (m): a sensor sits on the head, within
#: centimetres of the link's clamp; a point metres away is a number in another unit.
MAX_TORQUE_POINT = 1.0


def torque_point_problem(text: str) -> tuple[FloatArray | None, str | None]:
    """The point S - O (m, shape (3,)) a ``torque_point`` value states, or what is wrong with
    it: (point, None) or (None, problem)."""
    try:  # every number a float: an integer of 400 digits is inf, refused below
        value: Any = json.loads(text, parse_int=float, parse_constant=float)
    except (json.JSONDecodeError, RecursionError, ValueError, OverflowError):
        value = None
    if not (
        isinstance(value, list)
        and len(value) == 3
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
    ):
        return None, f"must be three numbers [x, y, z] (m, motor axes), got {text!r}"
    point = np.array(value, dtype=float)
    problem = point_problem(point)
    return (None, problem) if problem is not None else (point, None)


def point_problem(point: FloatArray) -> str | None:
    """What is wrong with ``point`` (S - O, m, shape (3,)) as a sensor's origin, or None."""
    if not np.all(np.isfinite(point)):
        return f"must be finite, got {point.tolist()}"
    distance = math.hypot(*point)
    if distance > MAX_TORQUE_POINT:
        return (
            f"{distance:.4g} m from O, more than {MAX_TORQUE_POINT:g} m: in metres? (a sensor "
            "sits on the head)"
        )
    return None


def key_problem(keys: Iterable[str]) -> tuple[str, str] | None:
    """(key, problem) for metadata keys that would leave the torques where they are or say two
    things of them: a spelling of ``torque_point`` other than its own (``torque-point``, as the
    import's flag is spelled; another case), or ``torque_point`` beside :data:`MOVED_KEY`."""
    names = list(keys)
    for key in names:
        if key != TORQUE_POINT_KEY and key.lower().replace("-", "_") == TORQUE_POINT_KEY:
            return key, f"is spelled {TORQUE_POINT_KEY!r} (as written, the torques are not moved)"
    if TORQUE_POINT_KEY in names and MOVED_KEY in names:
        return MOVED_KEY, (
            f"beside {TORQUE_POINT_KEY!r}: one says the torques are about O already, the other "
            "about another point"
        )
    return None


def metadata_line(point: ArrayLike) -> str:
    """The metadata line that states ``point`` (S - O on the motor axes, m, shape (3,)) to the
    millimetre: ``# torque_point: [0.025, 0.000, 0.000]``."""
    numbers = ", ".join(f"{float(v):.3f}" for v in np.asarray(point).reshape(3))
    return f"# {TORQUE_POINT_KEY}: [{numbers}]"


def torques_about_base(force: FloatArray, torque: FloatArray, point: FloatArray) -> FloatArray:
    """Torques (N m, shape (n, 3)) about O of a wrench read as ``force`` (N) and ``torque``
    (N m, about ``point`` S - O, m), all on the motor axes: Gamma_S + (S - O) x F."""
    return np.asarray(torque + np.cross(point, force), dtype=float)


def moved_metadata(metadata: Mapping[str, str]) -> dict[str, str]:
    """``metadata`` of a recording whose torques were moved to O: ``torque_point`` replaced by
    :data:`MOVED_KEY`, in its place."""
    return {
        (MOVED_KEY if key == TORQUE_POINT_KEY else key): value for key, value in metadata.items()
    }
