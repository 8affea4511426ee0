"""A map: contact points from recordings, the surface through them, and what object they are.

:func:`points_from_recordings` estimates each recording and places its point in the world
(the recording's ``base_pose``); :func:`swept_from_recordings` finds where each recording's link
swept untouched and where it touched (``mapping.free_space``);
:func:`map_inputs_from_recordings` does both, reading each recording once. :func:`build_map`
keeps the points that may enter a map (status ``ok``, and ``uncertain`` when asked), fits the
implicit surface when there are enough of them and recognises the object when there are enough
for every class. When recognition names the object, its fitted shape is the map's surface of the
whole object (:class:`ObjectSurface`), the implicit surface that of the touched parts.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from sensing_antenna.antenna import Antenna
from sensing_antenna.errors import FieldError, SensingAntennaError
from sensing_antenna.mapping.free_space import (
    FreeSpace,
    Piece,
    Touches,
    free_space,
    recording_links,
    touches,
)
from sensing_antenna.mapping.points import (
    ContactPoint,
    PointUncertainty,
    contact_point_from_estimate,
    select_points,
)
from sensing_antenna.mapping.pose import BasePose, base_pose_from_metadata
from sensing_antenna.mapping.recognition import (
    ClassFit,
    LinkLines,
    Recognition,
    recognise,
    shape_size,
)
from sensing_antenna.mapping.surface import MIN_SURFACE_POINTS, ImplicitSurface

if TYPE_CHECKING:
    from sensing_antenna.recording import Recording

__all__ = [
    "MIN_RECOGNITION_POINTS",
    "UNHELD_FRACTION",
    "ContactMap",
    "ObjectSurface",
    "build_map",
    "fit_surface",
    "link_lines",
    "map_inputs_from_recordings",
    "points_from_recordings",
    "recognise_points",
    "swept_from_recordings",
    "touch_reach",
    "touched",
]

FloatArray = NDArray[np.float64]

#: Fewest points recognition is tried on: one more than the box's 9 parameters.
MIN_RECOGNITION_POINTS = 10


#: Where the named object's surface deviates by this fraction of its size or more, the
#: evidence does not hold it (an untouched end, a hidden face).
UNHELD_FRACTION = 0.1


def touch_reach(points: FloatArray, least: float) -> float:
    """How far from a contact point (m) a shape counts as touched: ``least`` (m), or the
    points' median spacing (each one's distance to its nearest other) when larger, so that the
    area between neighbouring touches counts; ``points`` (m, shape (n, 3))."""
    if len(points) < 2:
        return least
    from scipy.spatial import cKDTree

    spacing, _ = cKDTree(np.asarray(points, dtype=float)).query(points, k=2)
    return max(least, float(np.median(spacing[:, 1])))


def touched(points: FloatArray, where: FloatArray, reach: float) -> NDArray[np.bool_]:
    """Which of ``where`` (m, shape (k, 3)) lie within ``reach`` (m, :func:`touch_reach`) of
    one of ``points`` (m, shape (n, 3)); none without points."""
    if not len(points):
        return np.zeros(len(where), dtype=bool)
    from scipy.spatial import cKDTree

    distance, _ = cKDTree(np.asarray(points, dtype=float)).query(where)
    return np.asarray(distance <= reach)


@dataclass(frozen=True)
class ObjectSurface:
    """The named object's fitted surface, the whole object, with where it is held.

    Attributes
    ----------
    name : str
        The named class (``mesh:NAME`` for a user mesh).
    mesh : trimesh.Trimesh
        The fitted shape (world frame, m), its faces split to edges of at most a twentieth of
        its size, so that faces, not only edges and corners, carry vertices.
    std : array, shape (n_vertices,)
        Standard deviation of where the surface lies at each vertex (m;
        :meth:`ClassFit.distance_std`): inf where no evidence holds it (an end no touch
        reached), NaN throughout for a user mesh (its registration carries none) or a fit
        whose covariance is not finite.
    size : float
        The object's size, the largest extent of its mesh's oriented bounding box (m), whatever
        its pose.
    """

    name: str
    mesh: trimesh.Trimesh
    std: FloatArray
    size: float

    @classmethod
    def of(cls, fit: ClassFit) -> ObjectSurface:
        """The surface of ``fit`` (its mesh must have faces)."""
        assert fit.mesh is not None
        size = shape_size(fit.mesh)
        vertices, faces = trimesh.remesh.subdivide_to_size(
            fit.mesh.vertices, fit.mesh.faces, max_edge=size / 20
        )
        mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
        return cls(fit.name, mesh, fit.distance_std(mesh.vertices), size)

    @property
    def unheld(self) -> float:
        """The deviation (m) from which the evidence does not hold the surface:
        :data:`UNHELD_FRACTION` of its size."""
        return UNHELD_FRACTION * self.size

    def vertex_areas(self) -> FloatArray:
        """The area each vertex stands for, a third of its faces' (m^2, shape (n_vertices,))."""
        areas = np.zeros(len(self.mesh.vertices))
        np.add.at(areas, self.mesh.faces.ravel(), np.repeat(self.mesh.area_faces / 3.0, 3))
        return areas

    def touch_reach(self, points: FloatArray) -> float:
        """How far from one of ``points`` (m, shape (n, 3)) this surface counts as touched (m,
        :func:`touch_reach` at :attr:`unheld`)."""
        return touch_reach(points, self.unheld)

    def touched_share(self, points: FloatArray) -> float:
        """The share of the surface's area within :meth:`touch_reach` of one of ``points`` (m,
        shape (n, 3)): where the touches were, not the class's shape carried past them; 0
        without points."""
        if not len(points):
            return 0.0
        areas = self.vertex_areas()
        near = touched(points, np.asarray(self.mesh.vertices), self.touch_reach(points))
        return float(areas[near].sum() / areas.sum())

    def summary(self, points: FloatArray | None = None) -> dict[str, Any]:
        """JSON-able: the class, the faces, the size (m), the share of its area near a touch
        (:meth:`touched_share` of the contact ``points``, and :meth:`touch_reach`, m; null
        without them), and where the
        surface is held (its deviation below :attr:`unheld`; a vertex without a finite one is
        not): that share of the area, and the deviation's median and 90th percentile there by
        area (m); the three null when no vertex has a deviation (a user mesh), the two quantiles
        when none is held."""
        summary: dict[str, Any] = {
            "class": self.name,
            "faces": len(self.mesh.faces),
            "size_m": self.size,
            "touched_share": None if points is None else self.touched_share(points),
            "touch_reach_m": None if points is None else self.touch_reach(points),
            "held_share": None,
            "held_std_median_m": None,
            "held_std_p90_m": None,
        }
        if np.all(np.isnan(self.std)):
            return summary
        areas = self.vertex_areas()
        held = self.std < self.unheld
        summary["held_share"] = float(areas[held].sum() / areas.sum())
        if held.any():
            order = np.argsort(self.std[held])
            cumulative = np.cumsum(areas[held][order]) / areas[held].sum()
            quantile = [
                float(self.std[held][order][np.searchsorted(cumulative, q)]) for q in (0.5, 0.9)
            ]
            summary["held_std_median_m"], summary["held_std_p90_m"] = quantile
        return summary


@dataclass(frozen=True)
class ContactMap:
    """Everything a map holds.

    Attributes
    ----------
    points : tuple of ContactPoint
        Every point, whatever its status.
    used : tuple of ContactPoint
        Those that entered the surface and the recognition.
    surface : ImplicitSurface or None
        The fitted surface (None with fewer than :data:`MIN_SURFACE_POINTS` points).
    surface_mesh : trimesh.Trimesh or None
        Its zero level.
    surface_std : array, shape (n_vertices,)
        Predictive std of the surface function at the mesh's vertices (m).
    recognition : Recognition or None
        None with fewer than :data:`MIN_RECOGNITION_POINTS` points.
    include_uncertain : bool
        Whether ``uncertain`` points were used.
    """

    points: tuple[ContactPoint, ...]
    used: tuple[ContactPoint, ...]
    surface: ImplicitSurface | None
    surface_mesh: trimesh.Trimesh | None
    surface_std: FloatArray
    recognition: Recognition | None
    include_uncertain: bool

    @property
    def point_errors(self) -> FloatArray:
        """Distance of each used point to its ground truth (m), NaN where unknown."""
        return np.array([float(np.linalg.norm(p.point - p.true_point)) for p in self.used])

    def object_surface(self) -> ObjectSurface | None:
        """The named object's fitted surface, the whole object; None when no object is named
        or the named class is unbounded (the plane). Made once per map."""
        return self._object_surface

    @cached_property
    def _object_surface(self) -> ObjectSurface | None:
        fit = None if self.recognition is None else self.recognition.named
        if fit is None or fit.mesh is None or not len(fit.mesh.faces):
            return None
        return ObjectSurface.of(fit)

    def summary(self) -> dict[str, Any]:
        """JSON-able counts and results (SI units)."""
        errors = self.point_errors
        known = errors[np.isfinite(errors)]
        statuses: dict[str, int] = {}
        for p in self.points:
            statuses[p.status.value] = statuses.get(p.status.value, 0) + 1
        return {
            "n_recordings": len(self.points),
            "n_used": len(self.used),
            "include_uncertain": self.include_uncertain,
            "statuses": statuses,
            "median_point_std_m": float(np.median([p.std for p in self.used]))
            if self.used
            else None,
            "point_error_rms_m": float(np.sqrt(np.mean(known**2))) if known.size else None,
            "surface_length_scale_m": None
            if self.surface is None
            else float(self.surface.length_scale_),
            "surface_faces": 0 if self.surface_mesh is None else len(self.surface_mesh.faces),
            "recognition": None if self.recognition is None else self.recognition.to_dict(),
            "object_surface": None
            if self._object_surface is None
            else self._object_surface.summary(np.array([p.point for p in self.used])),
        }


def points_from_recordings(
    paths: Sequence[Path],
    antenna: Antenna,
    method: Any = "paper",
    uncertainty: PointUncertainty | None = None,
    config: Any = None,
) -> list[ContactPoint]:
    """Estimate each recording and place its touched point in the world.

    Each recording's ``base_pose`` metadata (docs/recording-format.md) places its absolute frame;
    its ground truth is kept (never used by the map): the contact track at the estimate's
    ``t_point`` when it has one, else its ``true_contact_point``.

    Raises
    ------
    RecordingError, FieldError
        One line naming the file when a recording or its base pose is malformed.
    """
    from sensing_antenna.recording import read_recording

    points = []
    for path in paths:
        recording = read_recording(path)
        pose = base_pose_from_metadata(recording.metadata, str(path))
        points.append(_point(recording, path, pose, antenna, method, uncertainty, config))
    return points


def swept_from_recordings(
    paths: Sequence[Path],
    antenna: Antenna,
    points: Sequence[ContactPoint] | None = None,
) -> tuple[FreeSpace, Touches]:
    """Where the recordings' links swept untouched, and where they touched when their points
    (``points``, in the same order) are not ``ok`` (``mapping.free_space.recording_links``:
    the angles before the onset of the detected contact, short of it by the onset turn of a
    contact at an ``ok`` point's x_c, and the link when the contact was detected).

    Raises
    ------
    RecordingError, FieldError
        One line naming the file when a recording or its base pose is malformed.
    """
    from sensing_antenna.recording import read_recording

    links = [
        recording_links(
            read_recording(path),
            antenna,
            points[k] if points is not None and k < len(points) else None,
        )
        for k, path in enumerate(paths)
    ]
    return _swept(links, antenna)


def map_inputs_from_recordings(
    paths: Sequence[Path],
    antenna: Antenna,
    method: Any = "paper",
    uncertainty: PointUncertainty | None = None,
    config: Any = None,
    progress: Callable[[Path], None] | None = None,
    unreadable: Callable[[Path, SensingAntennaError], None] | None = None,
    read: Callable[[Path, Recording], None] | None = None,
) -> tuple[list[ContactPoint], tuple[FreeSpace, Touches]]:
    """:func:`points_from_recordings` and :func:`swept_from_recordings` of the same recordings,
    each read once; ``progress`` is called with each path when it is done, ``read`` with each
    recording's path and the recording once it is read. With ``unreadable``, a recording that cannot
    be read or whose base pose is malformed is handed to it with the error (one line naming the
    file) and left out; without, the error is raised.

    Raises
    ------
    RecordingError, FieldError
        Without ``unreadable``: one line naming the file when a recording or its base pose is
        malformed.
    """
    from sensing_antenna.recording import RecordingError, read_recording

    points: list[ContactPoint] = []
    links = []
    for path in paths:
        try:
            recording = read_recording(path)
            pose = base_pose_from_metadata(recording.metadata, str(path))
        except (RecordingError, FieldError) as exc:
            if unreadable is None:
                raise
            unreadable(path, exc)
            if progress is not None:
                progress(path)
            continue
        if read is not None:
            read(path, recording)
        point = _point(recording, path, pose, antenna, method, uncertainty, config)
        points.append(point)
        links.append(recording_links(recording, antenna, point))
        if progress is not None:
            progress(path)
    return points, _swept(links, antenna)


def _point(
    recording: Recording,
    path: Path,
    pose: BasePose,
    antenna: Antenna,
    method: Any,
    uncertainty: PointUncertainty | None,
    config: Any,
) -> ContactPoint:
    """The recording's touched point in the world at its base ``pose``
    (:func:`points_from_recordings`)."""
    from sensing_antenna.estimation.pipeline import estimate
    from sensing_antenna.recording import tracked_contact

    result = estimate(recording.without_ground_truth(), antenna, method=method, config=config)
    truth = tracked_contact(recording, result.diagnostics.get("t_point"))
    if truth is None:
        truth = _true_point(recording.metadata.get("true_contact_point"))
    return contact_point_from_estimate(result, antenna, pose, str(path), uncertainty, truth)


def _swept(
    links: Sequence[tuple[Piece, Piece | None]], antenna: Antenna
) -> tuple[FreeSpace, Touches]:
    """The free space of every recording's links and the touches of those with a touching
    link."""
    free = [[recorded] for recorded, _ in links]
    touched = [[touching] for _, touching in links if touching is not None]
    return free_space(free, antenna), touches(touched, antenna)


def build_map(
    points: Sequence[ContactPoint],
    include_uncertain: bool = False,
    meshes: Mapping[str, trimesh.Trimesh] | None = None,
    surface: ImplicitSurface | None = None,
    rng: np.random.Generator | None = None,
    swept: Sequence[FreeSpace] = (),
    recognition: Recognition | None = None,
    class_fitted: Callable[[str], None] | None = None,
) -> ContactMap:
    """The map from points (module docstring); the surface and recognition when possible,
    recognition also weighing ``swept``, where links swept untouched and where they touched.
    ``surface`` (its settings) is fitted to the points as :func:`fit_surface` fits it;
    ``recognition``, when given, is one already made of the same points, swept links and
    meshes, and is kept (``rng`` then unused); otherwise ``class_fitted`` is called with each
    class's name as recognition fits it (:func:`.recognition.recognise`)."""
    used = select_points(list(points), include_uncertain)
    fitted = fit_surface(used, True, surface)
    mesh = None
    std = np.zeros(0)
    if fitted is not None:
        mesh, std = fitted.mesh()
    if recognition is None:
        recognition = recognise_points(used, True, meshes, rng, swept, class_fitted)
    return ContactMap(
        points=tuple(points),
        used=tuple(used),
        surface=fitted,
        surface_mesh=mesh,
        surface_std=std,
        recognition=recognition,
        include_uncertain=include_uncertain,
    )


def fit_surface(
    points: Sequence[ContactPoint],
    include_uncertain: bool = False,
    surface: ImplicitSurface | None = None,
) -> ImplicitSurface | None:
    """The implicit surface through the points a map uses (None with fewer than
    :data:`MIN_SURFACE_POINTS`), each point's base the outer side."""
    used = select_points(list(points), include_uncertain)
    if len(used) < MIN_SURFACE_POINTS:
        return None
    p = np.array([c.point for c in used]).reshape(-1, 3)
    cov = np.array([c.covariance for c in used]).reshape(-1, 3, 3)
    bases = np.array([c.base_position for c in used]).reshape(-1, 3)
    return (surface if surface is not None else ImplicitSurface()).fit(p, cov, bases)


def recognise_points(
    points: Sequence[ContactPoint],
    include_uncertain: bool = False,
    meshes: Mapping[str, trimesh.Trimesh] | None = None,
    rng: np.random.Generator | None = None,
    swept: Sequence[FreeSpace] = (),
    class_fitted: Callable[[str], None] | None = None,
) -> Recognition | None:
    """The recognition of the points a map uses (None with fewer than
    :data:`MIN_RECOGNITION_POINTS`), the mean direction to their bases the outer side;
    ``class_fitted`` as in :func:`.recognition.recognise`."""
    used = select_points(list(points), include_uncertain)
    if len(used) < MIN_RECOGNITION_POINTS:
        return None
    p = np.array([c.point for c in used]).reshape(-1, 3)
    cov = np.array([c.covariance for c in used]).reshape(-1, 3, 3)
    bases = np.array([c.base_position for c in used]).reshape(-1, 3)
    outward = (bases - p).mean(axis=0)
    return recognise(
        p,
        cov,
        meshes=meshes,
        outward=outward,
        rng=rng,
        lines=link_lines(used),
        swept=swept,
        class_fitted=class_fitted,
    )


def link_lines(points: Sequence[ContactPoint]) -> LinkLines | None:
    """The link's line at each point, for the recognition's tangency residual; None when no
    point knows its tangent (points stored before they carried one)."""
    if not any(np.all(np.isfinite(c.tangent)) and math.isfinite(c.tangent_std) for c in points):
        return None
    return LinkLines(
        tangents=np.array([c.tangent for c in points]).reshape(-1, 3),
        std=np.array([c.tangent_std for c in points]),
        behind=np.array([c.x_c for c in points]),
        beyond=np.array([c.link_beyond for c in points]),
    )


def _true_point(text: str | None) -> FloatArray | None:
    if text is None:
        return None
    try:
        value = np.array(json.loads(text), dtype=float).reshape(3)
    except (ValueError, TypeError):
        return None
    return value if all(math.isfinite(v) for v in value) else None
