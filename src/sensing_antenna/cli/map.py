"""``antenna map``: contact points from recordings, the surface through them, the object."""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from sensing_antenna.cli.arguments import distinct_files
from sensing_antenna.cli.estimate import (
    DEFAULT_ANTENNA,
    METHOD_NAMES,
    other_antennas,
)

if TYPE_CHECKING:
    from sensing_antenna.recording import Recording


def register(subparsers: Any) -> None:
    """Add ``antenna map``."""
    parser = subparsers.add_parser(
        "map",
        help="map touched points from recordings: surface and recognised object",
        description=(
            "Estimates the contact point of each recording, places it in the world with its "
            "covariance (the recording's base_pose metadata; none: the recording's own frame), "
            "fits a Gaussian-process implicit surface through the points with status ok (and "
            "uncertain ones whose interval's width was their one fault), and "
            "fits every shape class (sphere, cylinder, box, cone, capsule, torus, plane) and "
            "any --objects meshes, naming the best or abstaining when two explain the points "
            "equally. Writes points.csv, recognition.json, report.md and map.png into --out, "
            "and as far as the points allow points.ply (the points used), surface.ply (4 points "
            "or more), object.ply (the named object's fitted shape, when one is named) and "
            "map.html (an interactive 3D view, self-contained; docs/mapping.md)."
        ),
    )
    parser.add_argument("recordings", nargs="+", type=Path, help="recordings (CSV)")
    parser.add_argument(
        "--antenna", default=None, help=f"built-in name or TOML file (default {DEFAULT_ANTENNA})"
    )
    parser.add_argument(
        "--method", choices=METHOD_NAMES, default="paper", help="the estimation method"
    )
    parser.add_argument("--out", type=Path, required=True, help="output directory")
    add_map_options(parser, "the map (without it, only those whose one fault is their width)")
    parser.add_argument(
        "--t1",
        choices=("rest", "push"),
        default="rest",
        help="t_1 from the head coming to rest or from the push criterion (as antenna estimate)",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    parser.set_defaults(func=_run)


#: The units ``--objects-unit`` reads a mesh file's coordinates in, as metres per unit.
OBJECTS_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}

#: How ``--objects`` meshes in other units are to be read, for the size check's message.
OBJECTS_UNIT_HINT = "read in {unit}; give the file's unit with --objects-unit {units}"


def read_objects(paths: Any, command: str, unit: str = "m") -> dict[str, Any]:
    """The ``--objects`` meshes by file stem, their coordinates read in ``unit`` (a key of
    :data:`OBJECTS_UNITS`) and scaled to metres; one that is not closed is read with a warning
    on stderr (a scan open where it stood: points on its missing faces count against it)."""
    from sensing_antenna.scene.objects import read_mesh

    scale = OBJECTS_UNITS[unit]
    hint = OBJECTS_UNIT_HINT.format(unit=unit, units="|".join(OBJECTS_UNITS))
    meshes = {}
    for path in paths:
        mesh = read_mesh(path, scale, unit_hint=hint, closed=False)
        if scale != 1.0:
            mesh.apply_scale(scale)
        if not mesh.is_watertight:
            print(
                f"{command}: warning: {path}: the mesh is not closed (watertight): points on"
                " its missing faces count against it (trimesh's fill_holes may close it)",
                file=sys.stderr,
            )
        meshes[path.stem] = mesh
    return meshes


def recognition_progress(enabled: bool, meshes: Any) -> Any:
    """The bar of recognition's fits, one step per shape class and ``--objects`` mesh, opened
    at the first (``Progress.bar_from_first``): call it with each class fitted."""
    from sensing_antenna.campaign.progress import Progress
    from sensing_antenna.mapping import PRIMITIVES

    shapes = len(PRIMITIVES) + len(meshes or {})
    return Progress(enabled).bar_from_first(shapes, "recognising", "shape")


def add_map_options(parser: Any, uncertain_into: str) -> None:
    """``--objects`` and ``--include-uncertain``, shared with ``antenna explore``."""
    parser.add_argument(
        "--objects",
        nargs="+",
        type=Path,
        default=(),
        metavar="MESH",
        help="meshes (STL, OBJ, PLY; closed, else a warning) to register to the points "
        "beside the shape classes",
    )
    parser.add_argument(
        "--objects-unit",
        choices=tuple(OBJECTS_UNITS),
        default="m",
        help="the unit of the --objects files' coordinates (a CAD export is often in mm)",
    )
    parser.add_argument(
        "--include-uncertain",
        action="store_true",
        help=f"let every point with status uncertain into {uncertain_into}",
    )


def _run(args: argparse.Namespace) -> int:
    distinct_files(args.recordings)
    # the directories --out makes (itself and missing parents), removed again if left empty
    made = [p for p in (args.out, *args.out.parents) if not p.exists()]
    args.out.mkdir(parents=True, exist_ok=True)  # a file in its way: said before estimating
    try:
        _map_into(args)
    except BaseException:
        for path in made:  # deepest first: a map that failed leaves no empty directory behind
            with contextlib.suppress(OSError):
                path.rmdir()
        raise
    return 0


def _map_into(args: argparse.Namespace) -> None:
    """Estimate, build and write the map of ``args.recordings`` into ``args.out`` (made)."""
    from sensing_antenna.antenna import load_antenna
    from sensing_antenna.campaign.progress import Progress
    from sensing_antenna.errors import SensingAntennaError
    from sensing_antenna.estimation.config import EstimatorConfig
    from sensing_antenna.mapping import build_map, map_inputs_from_recordings
    from sensing_antenna.mapping.points import isolated_points
    from sensing_antenna.mapping.pose import BASE_POSE_KEY, quaternion_order_hint

    meshes = read_objects(args.objects, "antenna map", args.objects_unit)
    antenna = load_antenna(DEFAULT_ANTENNA if args.antenna is None else args.antenna)
    named: dict[str, list[str]] = {}  # the antenna each recording names, to its sources
    unposed: list[str] = []  # recordings without a base pose: in the antenna's own frame
    contradicted: list[tuple[Path, str]] = []  # sample_period against the stamps: after the bar
    ordered: list[str] = []  # quaternions that read level in another order: after the bar

    def read(path: Path, recording: Recording) -> None:
        metadata = recording.metadata
        named.setdefault(metadata.get("antenna", ""), []).append(str(path))
        if not metadata.get(BASE_POSE_KEY, "").strip():
            unposed.append(str(path))
            # a key written otherwise (base_pos, Base-Pose) is not read: said of every file
            near = [key for key in metadata if _spelled_like(key, BASE_POSE_KEY)]
            if near:
                ordered.append(
                    f"antenna map: note: {path}: metadata key '{near[0]}' is not read: "
                    f"'{BASE_POSE_KEY}'? (the point is placed with the base at the world's "
                    "origin)"
                )
        order = quaternion_order_hint(metadata)
        if order is not None:
            ordered.append(f"antenna map: note: {path}: {order} (the order?)")
        problem = recording.period_problem
        if problem is not None:
            contradicted.append((path, problem))

    with Progress(not args.no_progress).bar(
        len(args.recordings), f"estimating ({args.method})", unit="recording"
    ) as bar:
        left_out: list[str] = []
        points, swept = map_inputs_from_recordings(
            args.recordings,
            antenna,
            args.method,
            config=EstimatorConfig(t1_source=args.t1),
            progress=lambda _: bar.update(1),
            unreadable=lambda _, exc: left_out.append(str(exc)),
            read=read,
        )
    # the notes on the inputs, said on stderr and kept in report.md
    said = [f"antenna map: warning: {path}: {problem}" for path, problem in contradicted]
    if args.antenna is None:  # the default: recordings of another antenna are warned of
        said += [f"antenna map: warning: {text}" for text in other_antennas(named, antenna.name)]
    said += [*ordered, *note_unposed(unposed, sum(len(paths) for paths in named.values()))]
    if not points:
        more = f" (and {len(left_out) - 1} more unreadable)" if len(left_out) > 1 else ""
        raise SensingAntennaError(f"{left_out[0]}{more}")
    said += [f"antenna map: warning: left out {problem}" for problem in left_out]
    said += [
        f"antenna map: note: the point of {point.source} lies {distance:.3g} m from every"
        f" other, where the points lie {1e3 * spacing:.3g} mm apart: its base_pose (a"
        " position in cm or mm, a rotation transposed or a quaternion's order)?"
        for point, distance, spacing in isolated_points(points, antenna.link.length)
    ]
    for line in said:
        print(line, file=sys.stderr)
    with recognition_progress(not args.no_progress, meshes) as bar:
        contact_map = build_map(
            points, args.include_uncertain, meshes=meshes, swept=swept, class_fitted=bar
        )
    report_map(contact_map, args.out, notes=[line.removeprefix("antenna map: ") for line in said])


def _antenna_hint(summary: dict[str, Any]) -> None:
    """One line on which antenna file to give when no point of the map (``summary``) is usable
    for want of the device's own observer, threshold or calibration."""
    if summary["n_used"] != 0:
        return
    if summary["statuses"].get("uncertain"):
        print(
            "  no estimate is ok: an antenna that is not calibrated answers uncertain (give "
            "--antenna the file antenna calibrate wrote), or let such points in with "
            "--include-uncertain; each point's reason is in points.csv"
        )
    elif set(summary["statuses"]) == {"no_contact"}:
        print(
            "  no recording shows a contact: if the link touched, these may be another device's "
            "recordings, whose touches this antenna's observer and threshold miss (give "
            "--antenna the file antenna identify or calibrate wrote for that device); each "
            "point's reason is in points.csv"
        )


def _spelled_like(key: str, name: str) -> bool:
    """Whether the metadata ``key`` is ``name`` written otherwise: in other capitals or
    separators, or a letter or two off (difflib's ratio 0.8 and more)."""
    import difflib

    plain = key.strip().lower().replace("-", "_").replace(" ", "_")
    return key != name and bool(difflib.get_close_matches(plain, [name], n=1, cutoff=0.8))


def note_unposed(unposed: list[str], count: int) -> list[str]:
    """The line to say when some of the ``count`` recordings read have a ``base_pose`` and
    ``unposed`` have none (theirs is taken as the world's origin, unturned); none otherwise."""
    if not unposed or len(unposed) == count:
        return []
    more = f" and {len(unposed) - 1} more" if len(unposed) > 1 else ""
    verb, theirs = ("has", "its point is") if len(unposed) == 1 else ("have", "their points are")
    return [
        f"antenna map: note: {len(unposed)} of {count} recordings {verb} no base_pose "
        f"({unposed[0]}{more}): {theirs} placed with the antenna's base at the world's origin, "
        "unturned (docs/recording-format.md)"
    ]


def report_map(
    contact_map: Any,
    out: Path,
    truth: Any = None,
    antenna_hints: bool = True,
    notes: Sequence[str] = (),
) -> None:
    """Write a map's files, figure and interactive view into ``out`` and print its summary
    (``antenna map`` and ``antenna explore`` share it); ``truth``, the true surface's mesh when
    known, is drawn in the view; ``antenna_hints``: say which antenna file to give when no
    point is usable (``antenna map``'s ``--antenna``); ``notes``, what was said of the inputs,
    kept in report.md."""
    from sensing_antenna.mapping import write_map
    from sensing_antenna.mapping.store import recognition_warnings
    from sensing_antenna.mapping.view import write_map_html
    from sensing_antenna.plotting.mapping import plot_map

    out.mkdir(parents=True, exist_ok=True)
    views = [plot_map(contact_map, out / "map.png")]
    html = write_map_html(contact_map, out / "map.html", truth)
    if html is not None:
        views.append(html)
    written = [*write_map(contact_map, out, tuple(views), notes), *views]
    summary = contact_map.summary()
    recognition = contact_map.recognition
    if recognition is None:
        decision = "not recognised (fewer than 10 points)"
    elif recognition.undecided:
        decision = f"undecided ({' or '.join(recognition.candidates)})"
    else:
        decision = f"{recognition.decision} ({recognition.best.sizes_text()})"
    statuses = ", ".join(f"{k} {v}" for k, v in sorted(summary["statuses"].items()))
    print(
        f"{summary['n_used']} of {summary['n_recordings']} points used"
        + (f" ({statuses})" if statuses else "")
        + "; "
        f"surface faces {summary['surface_faces']}; object {decision}"
    )
    for text in [] if recognition is None else recognition_warnings(recognition):
        print(f"  {text}")
    if antenna_hints:
        _antenna_hint(summary)
    for path in written:
        print(f"  {path}")
