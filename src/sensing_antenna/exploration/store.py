"""The on-disk layout of an exploration, written so that an interrupted one resumes.

::

    OUT/
      settings.json         the settings and the scene's fingerprint (a resume must use the
                            same; the budget may grow)
      calibration/          the calibration manoeuvres (posts at known x_c), when simulated
      calibrated.toml       the antenna the estimators use, written once the calibration is done
      recordings/NNN.csv    each touching manoeuvre's recording (with its base_pose)
      manoeuvres/NNN.json   each manoeuvre: the sweep, its outcome, the touch, the point
      manoeuvres.csv        every manoeuvre in one table, rebuilt from manoeuvres/
      scene.ply             the scene's objects (the true surface, for viewing)
      points.csv ... map.png  the map (``antenna map``'s files, docs/mapping.md)
      exploration.json      the summary ``antenna explore`` writes at the end
      .lock                 held while an exploration runs here

A manoeuvre's recording is written before its JSON file, each atomically (a temp file renamed),
so a manoeuvre exists complete or not at all: killing the exploration loses at most the one in
progress, which the next start redoes (its recording is rewritten).
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sensing_antenna.campaign.store import (
    CampaignStoreError,
    atomic_write_text,
    campaign_lock,
    remove_stale_temp_files,
)
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.mapping.points import ContactPoint
from sensing_antenna.scene.sweep import Sweep

__all__ = [
    "AIMS",
    "CALIBRATED_FILE",
    "ExplorationStoreError",
    "Manoeuvre",
    "exploration_lock",
    "load_manoeuvres",
    "point_from_dict",
    "point_to_dict",
    "write_manoeuvre",
    "write_manoeuvre_table",
    "write_settings",
]

SETTINGS_FILE = "settings.json"
CALIBRATED_FILE = "calibrated.toml"
RECORDINGS_DIR = "recordings"
MANOEUVRES_DIR = "manoeuvres"
TABLE_FILE = "manoeuvres.csv"

#: What may choose a manoeuvre's sweep (``Manoeuvre.aim``).
AIMS = ("plan", "recognition", "sizes")


class ExplorationStoreError(SensingAntennaError):
    """The output directory holds another exploration, or is in use."""


@dataclass(frozen=True)
class Manoeuvre:
    """One manoeuvre of an exploration, as stored.

    Attributes
    ----------
    index : int
        Its number, from 0.
    sweep : Sweep
    outcome : str
        ``touch``, ``free``, ``glancing``, ``near_head``, ``inside`` or ``second_object``
        (``scene.simulate``).
    reason : str or None
    touch : dict or None
        The geometric touch (``Touch.to_dict``: the true surface point and normal, SI).
    sweep_time : float
        The simulated time the head swept (s).
    seed : int
        The simulation's seed.
    recording : str or None
        The recording's path relative to the output directory.
    point : ContactPoint or None
        The estimated touched point (any status), for a touch.
    score : float
        The planner's score of the sweep (m; NaN for a grid sweep, and for one chosen before
        a surface could be fitted).
    aim : {"plan", "recognition", "sizes"}
        What chose the sweep: the strategy's plan (within the budget), or the sweeps after it
        while recognition abstains (``ExploreSettings.until_recognised``), or while the named
        object's sizes are not known well enough (``ExploreSettings.sizes_within``).
    """

    index: int
    sweep: Sweep
    outcome: str
    reason: str | None
    touch: dict[str, Any] | None
    sweep_time: float
    seed: int
    recording: str | None
    point: ContactPoint | None
    score: float
    aim: str = "plan"

    def __post_init__(self) -> None:
        if self.aim not in AIMS:
            raise ValueError(f"aim: {self.aim!r} is not one of {', '.join(AIMS)}")

    def to_dict(self) -> dict[str, Any]:
        """JSON-able fields."""
        return {
            "index": self.index,
            "sweep": self.sweep.to_dict(),
            "outcome": self.outcome,
            "reason": self.reason,
            "touch": self.touch,
            "sweep_time": self.sweep_time,
            "seed": self.seed,
            "recording": self.recording,
            "point": None if self.point is None else point_to_dict(self.point),
            "score": None if not np.isfinite(self.score) else self.score,
            "aim": self.aim,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Manoeuvre:
        """Inverse of :meth:`to_dict`."""
        sweep = data["sweep"]
        return cls(
            index=int(data["index"]),
            sweep=Sweep.from_dict(sweep),
            outcome=str(data["outcome"]),
            reason=data.get("reason"),
            touch=data.get("touch"),
            sweep_time=float(data["sweep_time"]),
            seed=int(data["seed"]),
            recording=data.get("recording"),
            point=None if data.get("point") is None else point_from_dict(data["point"]),
            score=float("nan") if data.get("score") is None else float(data["score"]),
            aim=str(data.get("aim", "plan")),
        )


def _finite_list(values: Any) -> Any:
    array = np.asarray(values, dtype=float)
    return [None if not np.isfinite(v) else float(v) for v in array.reshape(-1)]


def _array(values: Any, shape: tuple[int, ...]) -> np.ndarray:
    return np.array([np.nan if v is None else v for v in values], dtype=float).reshape(shape)


def point_to_dict(point: ContactPoint) -> dict[str, Any]:
    """A contact point's fields as JSON (NaN as null)."""
    return {
        "point": _finite_list(point.point),
        "covariance": _finite_list(point.covariance),
        "status": point.status.value,
        "source": point.source,
        "method": point.method,
        "x_c": _finite_number(point.x_c),
        "base_position": _finite_list(point.base_position),
        "reason": point.reason,
        "true_point": _finite_list(point.true_point),
        "tangent": _finite_list(point.tangent),
        "tangent_std": _finite_number(point.tangent_std),
        "link_beyond": _finite_number(point.link_beyond),
        "held_back_by_width": point.held_back_by_width,
    }


def point_from_dict(data: dict[str, Any]) -> ContactPoint:
    """Inverse of :func:`point_to_dict`."""
    return ContactPoint(
        point=_array(data["point"], (3,)),
        covariance=_array(data["covariance"], (3, 3)),
        status=data["status"],
        source=data["source"],
        method=data["method"],
        x_c=_number(data["x_c"]),
        base_position=_array(data["base_position"], (3,)),
        reason=data.get("reason"),
        true_point=_array(data["true_point"], (3,)),
        tangent=_array(data.get("tangent", [None] * 3), (3,)),
        tangent_std=_number(data.get("tangent_std")),
        link_beyond=_number(data.get("link_beyond")),
        held_back_by_width=bool(data.get("held_back_by_width", False)),
    )


def _number(value: Any) -> float:
    return float("nan") if value is None else float(value)


def _finite_number(value: float) -> float | None:
    return float(value) if np.isfinite(value) else None


@contextlib.contextmanager
def exploration_lock(out: Path) -> Iterator[None]:
    """Hold ``out`` (the campaigns' lock: one process per directory); stale temp files of
    writers that are gone are removed."""
    out.mkdir(parents=True, exist_ok=True)
    try:
        with campaign_lock(out):
            remove_stale_temp_files(out)
            for sub in (RECORDINGS_DIR, MANOEUVRES_DIR):
                if (out / sub).is_dir():
                    remove_stale_temp_files(out / sub)
            yield
    except CampaignStoreError as exc:
        raise ExplorationStoreError(
            str(exc).replace("another campaign", "another process")
        ) from None


def write_settings(out: Path, settings: dict[str, Any]) -> None:
    """Record the settings in ``out``; refuse a directory holding another exploration's."""
    path = out / SETTINGS_FILE
    if path.is_file():
        try:
            stored = json.loads(path.read_text("utf-8"))
        except (OSError, ValueError) as exc:
            raise ExplorationStoreError(f"{path}: unreadable ({exc})") from None
        if stored != settings:
            changed = sorted(
                k for k in set(stored) | set(settings) if stored.get(k) != settings.get(k)
            )
            stored_here = (
                "the manoeuvres stored here come"
                if any((out / MANOEUVRES_DIR).glob("*"))
                else "this directory was begun"
            )
            raise ExplorationStoreError(
                f"{path}: {', '.join(_change(k, stored.get(k), settings.get(k)) for k in changed)}:"
                f" {stored_here} with other settings; run with the same ones to resume, or use"
                " another output directory"
            )
        return
    atomic_write_text(path, json.dumps(settings, indent=2, sort_keys=True) + "\n")


def _change(key: str, stored: Any, given: Any) -> str:
    """A setting that differs, with both values when they are short (a device file is not)."""
    if key == "scene_fingerprint":
        return "the scene's objects, base poses or explored region (scene_fingerprint)"
    if max(len(json.dumps(stored)), len(json.dumps(given))) > 40:
        return key
    return f"{key} {json.dumps(stored)} stored, {json.dumps(given)} given"


def write_manoeuvre(out: Path, manoeuvre: Manoeuvre) -> Path:
    """Write one manoeuvre's JSON file atomically; returns its path."""
    folder = out / MANOEUVRES_DIR
    folder.mkdir(exist_ok=True)
    path = folder / f"{manoeuvre.index:03d}.json"
    atomic_write_text(path, json.dumps(manoeuvre.to_dict(), indent=1) + "\n")
    return path


def load_manoeuvres(out: Path) -> list[Manoeuvre]:
    """The manoeuvres stored in ``out``, in order, up to the first missing number."""
    folder = out / MANOEUVRES_DIR
    found: list[Manoeuvre] = []
    while True:
        path = folder / f"{len(found):03d}.json"
        if not path.is_file():
            return found
        try:
            found.append(Manoeuvre.from_dict(json.loads(path.read_text("utf-8"))))
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise ExplorationStoreError(f"{path}: unreadable manoeuvre ({exc})") from None


_TABLE_COLUMNS = (
    "index",
    "base",
    "case",
    "fixed",
    "direction",
    "outcome",
    "touch_angle",
    "true_x_c",
    "object",
    "status",
    "x",
    "y",
    "z",
    "std",
    "error",
    "sweep_time",
    "score",
    "aim",
    "recording",
    "reason",
)


def write_manoeuvre_table(out: Path, manoeuvres: Sequence[Manoeuvre]) -> Path:
    """``manoeuvres.csv``: one row per manoeuvre (SI units; ``error`` the estimated point's
    distance to the true touched point, m)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(_TABLE_COLUMNS)
    for m in manoeuvres:
        touch = m.touch or {}
        point = m.point
        error = (
            float(np.linalg.norm(point.point - point.true_point)) if point is not None else np.nan
        )
        writer.writerow(
            [
                m.index,
                m.sweep.base,
                m.sweep.case,
                f"{m.sweep.fixed:.6g}",
                f"{m.sweep.direction:+d}",
                m.outcome,
                "" if "angle" not in touch else f"{touch['angle']:.6g}",
                "" if "x_c" not in touch else f"{touch['x_c']:.6g}",
                touch.get("object", ""),
                "" if point is None else point.status.value,
                *(["", "", ""] if point is None else [f"{v:.6g}" for v in point.point]),
                "" if point is None else f"{point.std:.6g}",
                "" if not np.isfinite(error) else f"{error:.6g}",
                f"{m.sweep_time:.4g}",
                "" if not np.isfinite(m.score) else f"{m.score:.6g}",
                m.aim,
                m.recording or "",
                m.reason or (point.reason if point is not None and point.reason else ""),
            ]
        )
    path = out / TABLE_FILE
    atomic_write_text(path, buffer.getvalue())
    return path
