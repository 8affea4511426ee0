"""``antenna explore``: sweeps of the simulated device in a scene, mapped and recognised."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

from sensing_antenna.cli.arguments import ArgumentError, integer, number
from sensing_antenna.cli.map import add_map_options

#: ``exploration.plan.STRATEGIES``, ``scene.file.BUILTIN_SCENES`` and
#: ``simulator.DEVICE_PROFILES``, written out: importing them would load trimesh and
#: scikit-learn for every command's start.
STRATEGIES = ("grid", "next-best")
BUILTIN_SCENES = ("post", "sphere", "box", "cylinder")
DEVICE_PROFILES = ("nominal", "realistic")
#: ``exploration.run.DEFAULT_BUILD``, written out for the same reason.
DEFAULT_BUILD = 2021

#: A base tilted further off level than this (degrees) is warned of: the simulated gravity acts
#: along the base's -Z.
LEVEL_TOLERANCE_DEG = 0.1


def register(subparsers: Any) -> None:
    """Add ``antenna explore``."""
    parser = subparsers.add_parser(
        "explore",
        help="explore a scene with the simulated device: sweeps, contacts, surface, object",
        description=(
            "Prepares the simulated device as a lab prepares its own (its observer and contact "
            "threshold identified on two free sweeps, T_e calibrated on five smooth posts at known "
            "points), then runs sweeps of the head in SCENE (a built-in scene or a scene file): "
            "each sweep's first touch is simulated with the simulator's contact physics, written "
            "as a recording with its base_pose, estimated and placed in the world with its "
            "covariance; a sweep that touches nothing is free space. The strategy chooses the "
            "sweeps: a fixed grid, or next-best (where the surface fitted so far is least known). "
            "Then the map of antenna map (points, surface, recognised object) is written into "
            "--out. Interrupted, the same command resumes (docs/explore.md)."
        ),
    )
    parser.add_argument(
        "scene", help=f"scene file (TOML) or built-in scene ({', '.join(BUILTIN_SCENES)})"
    )
    parser.add_argument("--out", type=Path, required=True, help="output directory")
    parser.add_argument(
        "--method", choices=("paper", "fast"), default="paper", help="the estimation method"
    )
    parser.add_argument(
        "--strategy", choices=STRATEGIES, default="grid", help="how the sweeps are chosen"
    )
    parser.add_argument(
        "--budget",
        type=integer(1),
        default=None,
        help="most manoeuvres (sweeps); default: the scene's grid size",
    )
    parser.add_argument(
        "--until-recognised",
        type=integer(0),
        default=0,
        metavar="N",
        help=(
            "after the budget, while the object is not recognised, up to N more sweeps, aimed "
            "at telling the two leading shapes apart (with --sizes-within, also while its "
            "sizes are not known)"
        ),
    )
    parser.add_argument(
        "--sizes-within",
        type=number(0.0, 1.0, low_open=True, what="share"),
        default=None,
        metavar="SHARE",
        help=(
            "with --until-recognised: go on also while the named object's sizes are not each "
            "known to within this share of themselves (twice the standard deviation; 0.05: 5 %%)"
        ),
    )
    parser.add_argument(
        "--antenna", default="paper-2021", help="the simulated device: built-in name or TOML file"
    )
    parser.add_argument(
        "--seed", type=integer(0, 2**31 - 1), default=0, help="seed of the first manoeuvre"
    )
    parser.add_argument(
        "--link",
        choices=("nonlinear", "linear"),
        default="nonlinear",
        help="the simulated link: geometrically exact (default) or small-deflection",
    )
    parser.add_argument(
        "--device-profile",
        choices=DEVICE_PROFILES,
        default="nominal",
        help=(
            "the simulated device's imperfections, which the estimators are not told of: none "
            "(default), or a realistic build (tip mass, clamp, taper, joint, sensor cross-talk, "
            "drift, encoder zero; docs/simulator.md), calibrated first as a lab would"
        ),
    )
    parser.add_argument(
        "--device-build",
        type=integer(0, 2**31 - 1),
        default=None,
        metavar="N",
        help=(
            f"which realistic device (the seed of its build; default {DEFAULT_BUILD}, the "
            "default campaign's)"
        ),
    )
    add_map_options(parser, "the map and the planner's surface")
    parser.add_argument(
        "--quiet", action="store_true", help="no line per manoeuvre, no progress bar"
    )
    parser.add_argument(
        "--no-progress",
        action="store_true",
        help="no progress bar on stderr (the line per manoeuvre stays)",
    )
    parser.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    from sensing_antenna.antenna import load_antenna
    from sensing_antenna.cli.map import read_objects, recognition_progress, report_map
    from sensing_antenna.exploration import ExploreSettings, Manoeuvre, explore
    from sensing_antenna.exploration.run import stopped_as_stored
    from sensing_antenna.exploration.store import CALIBRATED_FILE
    from sensing_antenna.scene import load_scene
    from sensing_antenna.simulator.run import sampling_warning

    if args.device_profile == "nominal" and args.device_build is not None:
        raise ArgumentError(
            "--device-build", "a realistic device's build: give --device-profile realistic too"
        )
    if args.sizes_within is not None and args.until_recognised == 0:
        raise ArgumentError(
            "--sizes-within",
            "the sizes are swept for after the budget only: give --until-recognised N too",
        )
    scene = load_scene(args.scene)
    device = load_antenna(args.antenna)
    coarse = sampling_warning(device)
    if coarse is not None:  # before the banner: nothing will be explored
        raise ArgumentError(
            "--antenna",
            f"{device.name}: link: {coarse}; antenna explore simulates a device sampled at 1 kHz",
        )
    meshes = read_objects(args.objects, "antenna explore", args.objects_unit)
    settings = ExploreSettings(
        method=args.method,
        strategy=args.strategy,
        budget=args.budget,
        seed=args.seed,
        include_uncertain=args.include_uncertain,
        link=args.link,
        until_recognised=args.until_recognised,
        sizes_within=args.sizes_within,
        device_profile=args.device_profile,
        device_build=args.device_build,
    )

    def show(manoeuvre: Manoeuvre, most: int) -> None:
        point = manoeuvre.point
        what = manoeuvre.outcome
        if point is not None:
            what += f", {point.status.value}"
            if point.usable:
                x, y, z = point.point
                what += f" at ({x:.3f}, {y:.3f}, {z:.3f}) m, std {1000 * point.std:.1f} mm"
        elif manoeuvre.reason:
            what += f" ({manoeuvre.reason})"
        print(f"[{manoeuvre.index + 1}/{most}] {manoeuvre.sweep.label}: {what}", flush=True)

    prepared = (args.out / CALIBRATED_FILE).exists()
    print(
        f"exploring scene {scene.name} ({len(scene.objects)} objects, {len(scene.bases)} base"
        f" poses) with the {args.method} method, {args.strategy} strategy"
        + (
            ""
            if prepared
            else "; the first start prepares the simulated device (identifies its observer, "
            "calibrates T_e"
            + (", its tip mass and sensor" if args.device_profile == "realistic" else "")
            + ")"
        ),
        file=sys.stderr,
    )
    nearest = min(float(scene.signed_distance(base.position)[0]) for base in scene.bases)
    out_of_reach = nearest > device.link.length
    if out_of_reach:
        # ten reaches and more: a scene written in cm or mm reads 100 or 1000 times too far
        unit = (
            "; the scene's positions in cm or mm? they are in m"
            if nearest > 10 * device.link.length
            else ""
        )
        print(
            f"antenna explore: warning: no object lies within the link's reach"
            f" ({device.link.length:g} m) of a base (the nearest {nearest:.3g} m away): every"
            f" sweep will be free{unit}",
            file=sys.stderr,
        )

    for index, base in enumerate(scene.bases):
        # the simulated gravity acts along the base's -Z: a tilted base tilts it (docs/explore.md)
        tilt = math.degrees(math.acos(min(1.0, max(-1.0, float(base.rotation[2, 2])))))
        if tilt > LEVEL_TOLERANCE_DEG:
            print(
                f"antenna explore: warning: base {index} is tilted {tilt:.1f} deg off level: the"
                ' simulated gravity tilts with it (docs/explore.md, "Scenes"); keep bases level'
                " and raise or lower them instead",
                file=sys.stderr,
            )

    def resuming(stored: int) -> None:
        beyond = args.budget is not None and stored > args.budget
        print(
            f"{args.out} holds {stored} stored manoeuvres of this exploration: resuming after "
            "them"
            + (f"; more than --budget {args.budget}: the map takes all {stored}" if beyond else ""),
            file=sys.stderr,
        )

    def mapping(n_points: int) -> None:
        print(
            f"mapping the {n_points} estimated contacts: the surface and the shape classes",
            file=sys.stderr,
            flush=True,
        )

    with recognition_progress(not (args.quiet or args.no_progress), meshes) as bar:
        result = explore(
            scene,
            device,
            args.out,
            settings,
            None if args.quiet else show,
            meshes,
            mapping,
            resuming,
            bar,
        )
    summary = result.summary()
    (args.out / "exploration.json").write_text(json.dumps(summary, indent=2) + "\n")
    outcomes = ", ".join(f"{k} {v}" for k, v in sorted(summary["outcomes"].items()))
    after = ", ".join(f"{k} {v}" for k, v in sorted(summary["aims"].items()) if k != "plan")
    print(
        f"{summary['manoeuvres']} manoeuvres ({outcomes}"
        + (f"; after the budget, aimed at {after}" if after else "")
        + f"), {summary['sweep_time_s']:.0f} s of sweeping"
    )
    if summary["manoeuvres"] and set(summary["outcomes"]) == {"free"} and not out_of_reach:
        print(
            f"antenna explore: warning: none of the {summary['manoeuvres']} sweeps touched an "
            "object: it lies outside the sweeps' angles from every base (behind the head, or "
            "beyond the elevation the sweeps reach); move a base or the object",
            file=sys.stderr,
        )
    with stopped_as_stored(args.out, lambda: len(result.manoeuvres)):
        report_map(result.contact_map, args.out, scene.mesh, antenna_hints=False)
    print(f"  {args.out / 'manoeuvres.csv'}\n  {args.out / 'scene.ply'}")
    return 0
