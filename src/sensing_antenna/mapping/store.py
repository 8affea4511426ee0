"""A map's directory: points.csv, points.ply, surface.ply, object.ply, recognition.json,
report.md.

points.csv has one row per recording: ``source, method, status, x, y, z`` (m, world frame), the
covariance's six entries ``cov_xx, cov_xy, cov_xz, cov_yy, cov_yz, cov_zz`` (m^2), ``std``
(the worst-direction sigma, m), ``x_c`` (m), the link's unit tangent at the contact
``tangent_x, tangent_y, tangent_z`` (world frame) and its angular ``tangent_std`` (rad),
``used`` (whether it entered the map),
``true_x, true_y, true_z`` (ground truth when the recording had it),
``held_back_by_width`` (an ``uncertain`` estimate whose one fault is its interval's width) and
``reason``. The PLY
files colour points and surface vertices by their standard deviation, blue (smallest) to red
(largest). object.ply, written when recognition names a bounded object, is the named class's
fitted shape, the whole object (:class:`~sensing_antenna.mapping.contact_map.ObjectSurface`);
its vertices are coloured by the standard deviation of where the shape lies there, from blue at
0 to red at a tenth of the object's size and beyond (where the evidence does not hold it), grey
for a user mesh, whose registration carries none.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from numpy.typing import NDArray

from sensing_antenna.mapping.contact_map import UNHELD_FRACTION, ContactMap, ObjectSurface
from sensing_antenna.mapping.recognition import PRIMITIVES

__all__ = ["POINT_COLUMNS", "std_colours", "write_map"]

#: The columns of points.csv, in order.
POINT_COLUMNS = (
    "source",
    "method",
    "status",
    "x",
    "y",
    "z",
    "cov_xx",
    "cov_xy",
    "cov_xz",
    "cov_yy",
    "cov_yz",
    "cov_zz",
    "std",
    "x_c",
    "tangent_x",
    "tangent_y",
    "tangent_z",
    "tangent_std",
    "used",
    "true_x",
    "true_y",
    "true_z",
    "held_back_by_width",
    "reason",
)


#: Colour (RGBA) of what carries no deviation: a registered user mesh, the true surface.
GREY = (150, 150, 150, 255)


def std_colours(values: NDArray[np.float64], top: float | None = None) -> NDArray[np.uint8]:
    """RGBA rows from blue to red of ``values``: from the smallest to the largest finite one
    (the others grey), or, with ``top`` (> 0), from 0 to ``top`` and beyond (inf red, NaN
    grey)."""
    if top is not None and not top > 0:
        raise ValueError(f"top must be > 0, not {top}")
    v = np.asarray(values, dtype=float)
    known = np.isfinite(v) if top is None else ~np.isnan(v)
    if top is not None:
        t = np.clip(np.where(known, v, 0.0) / top, 0.0, 1.0)
    else:
        low = float(v[known].min()) if known.any() else 0.0
        span = float(np.ptp(v[known])) if known.any() else 0.0
        t = (np.where(known, v, low) - low) / span if span > 0 else np.zeros_like(v)
    rgba = np.stack([255 * t, 64 * np.ones_like(t), 255 * (1 - t), 255 * np.ones_like(t)], axis=1)
    rgba[~known] = GREY
    return np.asarray(rgba.round(), dtype=np.uint8)


def _number(value: float) -> str:
    return "" if not math.isfinite(value) else f"{value:.9g}"


#: A map's files written only when it holds what they show: those a previous map in the same
#: directory wrote (recognition.json's ``files``) are removed first, so that none contradicts
#: the new report.
SOMETIMES_WRITTEN = ("points.ply", "surface.ply", "object.ply", "map.html")


def write_map(
    contact_map: ContactMap,
    out: Path,
    also: tuple[Path, ...] = (),
    notes: Sequence[str] = (),
) -> list[Path]:
    """Write the map's files into ``out`` (created), after removing those of
    :data:`SOMETIMES_WRITTEN` a previous map wrote there and this one has not (``also``: the
    files of this map its caller wrote already); returns the paths written. recognition.json
    lists them all (``files``); report.md ends with ``notes`` (what was said of the inputs:
    recordings left out, base poses)."""
    out.mkdir(parents=True, exist_ok=True)
    kept = {p.name for p in also}
    for name in _previous_files(out):
        if name in SOMETIMES_WRITTEN and name not in kept:
            (out / name).unlink(missing_ok=True)
    written = []
    used = {id(p) for p in contact_map.used}
    path = out / "points.csv"
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(POINT_COLUMNS)
        for p in contact_map.points:
            c = p.covariance
            writer.writerow(
                [
                    p.source,
                    p.method,
                    p.status.value,
                    *(_number(v) for v in p.point),
                    *(
                        _number(c[i, j])
                        for i, j in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
                    ),
                    _number(p.std),
                    _number(p.x_c),
                    *(_number(v) for v in p.tangent),
                    _number(p.tangent_std),
                    "true" if id(p) in used else "false",
                    *(_number(v) for v in p.true_point),
                    "true" if p.held_back_by_width else "false",
                    p.reason or "",
                ]
            )
    written.append(path)
    if contact_map.used:
        cloud = trimesh.PointCloud(
            np.array([p.point for p in contact_map.used]),
            colors=std_colours(np.array([p.std for p in contact_map.used])),
        )
        path = out / "points.ply"
        cloud.export(path)
        written.append(path)
    mesh = contact_map.surface_mesh
    if mesh is not None and len(mesh.faces):
        mesh = trimesh.Trimesh(
            vertices=mesh.vertices,
            faces=mesh.faces,
            vertex_colors=std_colours(contact_map.surface_std),
            process=False,
        )
        path = out / "surface.ply"
        mesh.export(path)
        written.append(path)
    surface = contact_map.object_surface()
    if surface is not None:
        path = out / "object.ply"
        _object_mesh(surface).export(path)
        written.append(path)
    path = out / "recognition.json"
    files = sorted({p.name for p in (*written, *also)} | {"recognition.json", "report.md"})
    summary = {**contact_map.summary(), "files": files}
    path.write_text(json.dumps(summary, indent=2, allow_nan=False) + "\n")
    written.append(path)
    path = out / "report.md"
    path.write_text(report(contact_map, notes))
    written.append(path)
    return written


#: What a named class is of: a straight link meets an object first where it is tangent to it,
#: so its contacts and free sweeps see the object's convex hull only.
HULL_NOTE = (
    "The class is the one of the object's convex hull, which is all a straight link touches: a"
    " concave object (two balls side by side, a groove, a bowl seen from outside) is named as"
    " its hull's class (docs/mapping.md)."
)


#: Overdispersion (the best class's reduced chi^2) beyond which the points are said to lie
#: farther from every class than their covariances allow: 4, residuals twice their deviations
#: (docs/mapping.md has what it was on right and on misplaced points).
OVERDISPERSED = 4.0


def overdispersed(recognition: Any) -> str:
    """What points farther from every class than their covariances allow say: when no class
    fits them (:attr:`~.recognition.Recognition.none_fits`: recognition then names none), or the
    overdispersion is beyond :data:`OVERDISPERSED`; else ""."""
    c = float(recognition.overdispersion)
    chance = float(recognition.fit_chance)
    refused = bool(recognition.none_fits)
    if not (refused or c > OVERDISPERSED):
        return ""
    far = (
        f"the points lie {math.sqrt(c):.1f} times farther from the best-fitting class than"
        " their deviations say"
    )
    if refused:
        far += f", which chance makes in {_odds(chance, 'set of points')}, so no class is named"
    return (
        f"{far}: the object is none of the classes, or points are misplaced (a base pose, a"
        " calibration)"
    )


def _odds(chance: float, what: str) -> str:
    """``chance`` in words: "one <what> in N" (two figures), or "fewer than one <what> in a
    million"."""
    if chance < 1e-6:
        return f"fewer than one {what} in a million"
    return f"one {what} in {round(1 / chance, -int(math.log10(1 / chance)) + 1):,.0f}"


#: The chance (:attr:`ClassFit.wrong_chance`) below which the points the best class's fit counts
#: wrong are more than wrong estimates make: one map in a thousand of one object.
WRONG_CHANCE = 1e-3


def unexplained(recognition: Any) -> str:
    """What the best fit's points counted wrong say when wrong estimates alone would make that
    many less often than :data:`WRONG_CHANCE`, or ""."""
    best = recognition.best
    chance = best.wrong_chance
    if not chance < WRONG_CHANCE:
        return ""
    odds = _odds(chance, "map")
    return (
        f"{best.n_wrong} of {best.n_points} points lie farther from the"
        f" {best.name.replace('mesh:', 'mesh ')} than its"
        f" fit allows, where wrong estimates make that many in {odds}: the points are of more"
        " than one object, or some are misplaced (a base pose, a calibration)"
    )


def crossed(recognition: Any) -> str:
    """What the best fit's swept links beyond their outlier cap say (:attr:`ClassFit.n_crossed`:
    recognition then names no class), or ""."""
    best = recognition.best
    if best.n_crossed <= 0:
        return ""
    many = best.n_crossed > 1
    name = best.name.replace("mesh:", "mesh ")
    return (
        f"{best.n_crossed} swept link{'s' if many else ''} contradict{'' if many else 's'} the"
        f" best-fitting {name} beyond what {'their' if many else 'its'} deviations allow (a"
        " link passed through it untouched, or touched nowhere near it), so no class is named:"
        " the object is not one such shape (two objects, a gap between its parts), or a sweep"
        " missed a light contact"
    )


def recognition_warnings(recognition: Any) -> list[str]:
    """What the map says of its recognition beyond the decision, in order: the points' spread
    (:func:`overdispersed`), the points counted wrong (:func:`unexplained`) and the swept links
    beyond their cap (:func:`crossed`); those that have something to say."""
    return [text for warn in (overdispersed, unexplained, crossed) if (text := warn(recognition))]


#: Points counted wrong by the best class that the report names, farthest first.
NAMED_WRONG = 5


def _counted_wrong(contact_map: ContactMap) -> list[str]:
    """A line naming the recordings whose points the named class counts wrong (at most
    :data:`NAMED_WRONG`, farthest from its fit first), with their distance from it; none when
    recognition names no class or its fit counts none wrong."""
    recognition = contact_map.recognition
    if recognition is None or recognition.undecided or not recognition.best.wrong:
        return []
    best = recognition.best
    at = np.array([contact_map.used[k].point for k in best.wrong]).reshape(-1, 3)
    distance = best.distances(at)
    order = np.argsort(-distance)[:NAMED_WRONG]
    named = "; ".join(
        f"{contact_map.used[best.wrong[k]].source} ({1000 * distance[k]:.0f} mm from it)"
        for k in order
    )
    more = len(best.wrong) - len(order)
    return [
        f"Points the {best.name.replace('mesh:', 'mesh ')}'s fit counts as wrong estimates (too"
        f" far from it, or their links' lines from it, to be of it; left out of its shape):"
        f" {named}"
        + (f"; and {more} more" if more > 0 else "")
        + ". Their base poses, or their estimates, to check."
    ]


def _member_note(recognition: Any) -> list[str]:
    """A line when a user mesh is named with a class that fits the same points with sizes the
    points do not measure, or only bound: what of the mesh they hold; none otherwise."""
    best = recognition.best
    if best.name in PRIMITIVES or recognition.undecided:
        return []
    fits = {f.name: f for f in recognition.fits}
    loose = [
        fits[name]
        for name in recognition.same_shape
        if name in PRIMITIVES
        and (
            fits[name].size_at_least
            or any(not math.isfinite(v) for v in fits[name].size_std.values())
        )
    ]
    return [
        f"The {f.name} class fits the same points with {f.sizes_text()}: the mesh is one such"
        f" {f.name}, and the points hold no more of its size than that."
        for f in loose
    ]


def _previous_files(out: Path) -> list[str]:
    """The files a previous map in ``out`` wrote (its recognition.json's ``files``), or none."""
    try:
        files = json.loads((out / "recognition.json").read_text("utf-8")).get("files", [])
    except (OSError, ValueError, AttributeError):
        return []
    return [name for name in files if isinstance(name, str)] if isinstance(files, list) else []


def _object_mesh(surface: ObjectSurface) -> trimesh.Trimesh:
    """The named object's mesh, coloured by its deviation from 0 (blue) to where the evidence
    no longer holds it (red)."""
    return trimesh.Trimesh(
        vertices=surface.mesh.vertices,
        faces=surface.mesh.faces,
        vertex_colors=std_colours(surface.std, surface.unheld),
        process=False,
    )


def _object_line(contact_map: ContactMap, summary: dict[str, Any] | None) -> str:
    surface = contact_map.object_surface()
    if surface is None or summary is None:
        named = None if contact_map.recognition is None else contact_map.recognition.named
        why = "recognition names no object" if named is None else f"the {named.name} is unbounded"
        return f"Object surface: none ({why})."
    line = f"Object surface: the {surface.name}'s fitted shape (object.ply)"
    if summary.get("touched_share") is not None:
        line += (
            f"; {100 * summary['touched_share']:.0f} % of its area within "
            f"{1000 * summary['touch_reach_m']:.1f} mm of a contact point (the rest is the "
            "class's shape carried past the touches, as sure as the class is right)"
        )
    if summary["held_share"] is None:
        return line + "; it carries no deviation (a registered mesh, or a fit not held at all)."
    line += (
        f"; {100 * summary['held_share']:.0f} % of its area held by the fit (deviation"
        f" below {1000 * surface.unheld:.1f} mm, {UNHELD_FRACTION:g} of its size)"
    )
    if summary["held_std_median_m"] is None:
        return line + "."
    return (
        line + f", with a standard deviation of {1000 * summary['held_std_median_m']:.2f} mm"
        f" there (median by area; 90 %: {1000 * summary['held_std_p90_m']:.2f} mm)."
    )


def report(contact_map: ContactMap, notes: Sequence[str] = ()) -> str:
    """A short Markdown report of the map (lengths in mm for reading), ending with ``notes``
    on its inputs when there are any."""
    s = contact_map.summary()
    statuses = ", ".join(f"{k} {v}" for k, v in sorted(s["statuses"].items()))
    lines = [
        "# Contact map",
        "",
        f"{s['n_recordings']} recordings"
        + (f" ({statuses})" if statuses else "")
        + f"; {s['n_used']} points used"
        + (
            " (ok and uncertain)"
            if s["include_uncertain"]
            else " (status ok, or uncertain by their interval's width alone)"
        )
        + ".",
    ]
    if s["median_point_std_m"] is not None:
        lines.append(
            f"Median worst-direction sigma of a point: {1000 * s['median_point_std_m']:.2f} mm."
        )
    if s["point_error_rms_m"] is not None:
        lines.append(
            "Distance of the points to the true contact points the recordings carry (RMS; "
            "along the surface as well as across it, so more than their distance to the "
            f"object's surface): {1000 * s['point_error_rms_m']:.2f} mm."
        )
    if s["surface_faces"]:
        lines.append(
            f"Surface: {s['surface_faces']} faces, GP length scale "
            f"{1000 * s['surface_length_scale_m']:.1f} mm (surface.ply)."
        )
    else:
        lines.append("Surface: none (too few points, or no zero level in the grid).")
    lines.append(_object_line(contact_map, s["object_surface"]))
    recognition = contact_map.recognition
    lines.append("")
    if recognition is None:
        lines.append("Recognition: not attempted (fewer than 10 points).")
    else:
        runner_up = "" if recognition.runner_up is None else f" ({recognition.runner_up})"
        lines += [
            f"Recognition: **{recognition.decision}**"
            + (
                f" (between {recognition.candidates[0]} and {recognition.candidates[1]})"
                if recognition.undecided
                else f" (confidence {recognition.confidence:.3f})"
            )
            + (
                f"; score gap to the best of another shape{runner_up}"
                f" {recognition.delta_score:.1f} (abstains below {recognition.threshold:g})"
                if math.isfinite(recognition.delta_score)
                else "; no runner-up of another shape"
            )
            + (
                f"; the best's weight {recognition.confidence:.3f} is below the"
                f" {recognition.confidence_floor:.3f} a decision needs"
                if recognition.undecided
                and recognition.rival is None
                and recognition.delta_score >= recognition.threshold
                and recognition.confidence < recognition.confidence_floor
                else ""
            )
            + (
                f"; {recognition.rival} explains the points as well and is another shape"
                if recognition.rival is not None
                else ""
            )
            + (
                f"; {', '.join(recognition.same_shape)} fitted the same shape and"
                f" {'counts' if len(recognition.same_shape) == 1 else 'count'} with it"
                if recognition.same_shape
                else ""
            )
            + ".",
            *(f"{text[:1].upper()}{text[1:]}." for text in recognition_warnings(recognition)),
            # a user's mesh is the object's own shape, concave parts and all
            *(
                ()
                if recognition.undecided or recognition.best.name not in PRIMITIVES
                else (HULL_NOTE,)
            ),
            *_member_note(recognition),
            *_counted_wrong(contact_map),
            "",
            "chi^2 counts the points, the links' lines and the swept links (docs/mapping.md),"
            " each at most its outlier cap; the lines' and the swept links' own sums of squares,"
            " uncapped, are beside it.",
            "",
            "A size is given with its standard deviation; one with an end never touched as a"
            " lower bound (at least), one the points do not hold as not measured.",
            "",
            "| class | RMS (mm) | chi^2 | lines | swept | score | weight | sizes |",
            "|---|---|---|---|---|---|---|---|",
        ]
        for fit in recognition.fits:
            lines.append(
                f"| {fit.name} | {1000 * fit.rms:.2f} | {fit.chi2:.1f} | {fit.line_chi2:.1f} | "
                f"{fit.swept_chi2:.1f} | {fit.score:.1f} | {fit.weight:.3f} | "
                f"{fit.sizes_text()} |"
            )
    if notes:
        lines += ["", "## The inputs", "", *(f"- {note}" for note in notes)]
    return "\n".join(lines) + "\n"
