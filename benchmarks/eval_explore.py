"""Exploration on simulated scenes: grid against next-best, on the simulator's own contacts.

Each scene holds one primitive (sphere, cylinder, capsule, cone, torus or box, in turn), its
largest dimension drawn in 4 to 20 cm, a random orientation, its centre 0.3 to 0.95 m from the
head at an azimuth within +-60 degrees and a height within +-10 cm of the head's. The head sits
at ``--bases`` level base poses around the object (a head on a robot that moves round it): the
origin, and two poses turned about the vertical through the object's centre by 120 and 240
degrees from it, each facing the object from 0.55 m (``--distance``: where the robot puts the
head, inside the link's best range), the second seeing it from above (its line of sight 0.5
rad below the horizontal) and the third from below (0.5 rad above; ``--sight``). A
sweeping line first touches a convex object where it is tangent to it, on the object's outline
seen from the base; bases at one height see outlines in level-sighted planes, which a sphere,
a cylinder or a torus may all pass through, while the outlines seen from above and below lie in
planes tilted by 0.5 rad the other ways. Each base explores its own region, the object's
angular extent seen from it, widened by 0.05 rad, the elevations shifted by the link's sag at
each point's distance; the grid has, per base, ``--sweeps`` elevations each swept both ways
(azimuthal sweeps towards +Y^m and back towards -Y^m, which touch opposite sides of the
outline) and as many vertical sweeps (up and down in turn): 3 (2 x 4 + 4) = 36 sweeps by
default, as many as the one-way grid of 6 azimuthal and 6 vertical sweeps per base, so that the
contacts stay below 40 per object.

Each scene is explored twice with ``exploration.explore`` (every sweep simulated: first touch,
contact physics, recording, estimate with ``--method``), once per strategy with the grid's size as
the budget, on the antenna of one preparation (the observer identified on free sweeps, then the
five smooth posts; made once and copied into each run's directory), with the simulator's
geometrically exact link (``--link linear``: the small-deflection one). ``--device-profile
realistic`` explores with one build of the realistic profile (``--device-build``), prepared as
``exploration.prepare_device`` prepares it; what the preparation made of it (T_e, tip mass,
sensor correction and its fit) goes into the results' settings. Per scene and strategy: the
contacts (sweeps that touched), the points used (status ok), the RMS and largest distance of the
points to the true surface, the RMS of the fitted surface to the true one near the points (mesh
vertices within 1 cm of a contact), a Chamfer distance between that surface and the true surface's
patch near the points, and the whole object's RMS distance to the fitted surface with the fraction
of its area within 5 mm of it (a map that never touched a side is far from it there), after every 3
sweeps and at the end; the contacts each strategy needs to bring the whole object's RMS to 5 mm (the
two strategies compared scene by scene on it), with the implicit surface and with the map's surface
of the whole object (the named class's fitted shape where recognition names one, recognised with the
swept links so far at each checkpoint up to the first that reaches the target, the implicit surface
where not), and the named shape's whole-object RMS at the end; the recognition (right, abstained,
confidently wrong) and the size error of the true class's fit (each size's error also over the
standard deviation the fit reports, and whether the fit claims every size to 5 %, twice its
standard deviation within 5 % of it, while being off by more), the Mahalanobis distance of each
``ok`` point's true contact point under its covariance and its distance to the true surface over
its sigma along the normal, how far the true object disagrees with the swept links
recognition weighs (its residual per free sweep and per touching link, the worst and the count
beyond 2: swept links the truth contradicts would refute the right class), and the simulated
sweeping time. Prints a table and writes ``benchmarks/results/explore.json`` after every exploration
(a run stopped early keeps the scenes it finished). ``--keep DIR`` keeps each exploration's
directory there (its recordings and points, for ``antenna map``); an exploration already there is
resumed, and a finished one re-scored: its map rebuilt with the current code from its stored points
(exact for the grid, whose sweeps do not depend on the map; next-best's were chosen by the code that
ran them), ``resumed`` in its row, ``run_s`` the re-score's time.

Run: ``python benchmarks/eval_explore.py [--scenes 12] [--first 0] [--sweeps 4] [--bases 3]
[--strategies grid next-best] [--method fast] [--link nonlinear]
[--device-profile nominal|realistic] [--device-build N] [--seed 0] [--out FILE] [--keep DIR]``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # one core, set before numpy loads

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import datetime  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import shutil  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
import trimesh  # noqa: E402
from scipy.spatial import cKDTree  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

from sensing_antenna import paper_antenna  # noqa: E402
from sensing_antenna.antenna import antenna_to_toml  # noqa: E402
from sensing_antenna.cli.arguments import integer, number  # noqa: E402
from sensing_antenna.exploration import ExploreSettings, explore, prepare_device  # noqa: E402
from sensing_antenna.exploration.run import DEFAULT_BUILD, swept_links  # noqa: E402
from sensing_antenna.exploration.store import AIMS, CALIBRATED_FILE  # noqa: E402
from sensing_antenna.mapping import PRIMITIVES, UNDECIDED, BasePose  # noqa: E402
from sensing_antenna.mapping.contact_map import fit_surface, recognise_points  # noqa: E402
from sensing_antenna.scene import (  # noqa: E402
    ExploreRegion,
    LinkShape,
    Scene,
    facing_region,
    primitive_object,
)
from sensing_antenna.simulator import DEVICE_PROFILES  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "explore.json"
CLASSES = ("sphere", "cylinder", "capsule", "cone", "torus", "box")
STRATEGIES = ("grid", "next-best")
#: The surface is scored where the points are: mesh vertices within this of a contact (m).
NEAR = 0.01
#: The whole object is scored on every this-many-th of the 20,000 samples of its surface.
OBJECT_STRIDE = 5
#: A part of the true surface within this of the fitted one is covered by the map (m).
COVERED = 0.005
#: The whole-object RMS the strategies are compared at: the contacts each needs to reach it (m).
TARGET_RMS = 0.005
#: The size target: every size of a right answer within this of the truth (relative).
SIZE_TOLERANCE = 0.05
#: Checkpoints along each exploration: after every this-many sweeps, and at the end.
CHECK_EVERY = 3
#: Widening of the explored region beyond the object's angular extent (rad).
MARGIN = 0.05
#: Elevation (rad) of the line of sight from the second base to the object's centre (from
#: above: minus this) and from the third (from below: plus this); ``--sight 0`` puts every base
#: at the first's height.
SIGHT = 0.5
#: Distance (m) from the object's centre at which the robot places the second and third bases:
#: away from the sensing curve's top (x_c near 0.77 m for the paper's link), where omega_1
#: hardly changes with x_c and the frequency-based estimates come back uncertain, and from the
#: far end, where the points err most; ``--distance 0`` keeps the first base's distance.
WORKING_DISTANCE = 0.55


def make_object(
    name: str, size: float, rng: np.random.Generator
) -> tuple[list[float], dict[str, Any]]:
    """The class's sizes in ``mapping.primitives`` order, largest dimension ``size`` (m), and
    the true sizes by name (box extents sorted)."""
    if name == "sphere":
        return [size / 2], {"radius": size / 2}
    if name == "cylinder":
        radius = size * rng.uniform(0.2, 0.45)
        return [radius, size], {"radius": radius, "height": size}
    if name == "capsule":
        radius = size * rng.uniform(0.15, 0.3)
        return [radius, size - 2 * radius], {"radius": radius, "length": size - 2 * radius}
    if name == "cone":
        radius = size * rng.uniform(0.25, 0.5)
        return [radius, size], {"radius": radius, "height": size}
    if name == "torus":
        major = size / 2 * rng.uniform(0.55, 0.75)
        minor = size / 2 - major
        return [major, minor], {"major_radius": major, "minor_radius": minor}
    extents = [size, size * rng.uniform(0.4, 1.0), size * rng.uniform(0.4, 1.0)]
    return extents, {"extents": sorted(extents)}


def base_poses(
    centre: np.ndarray, n_bases: int, sight: float = SIGHT, working: float = WORKING_DISTANCE
) -> tuple[BasePose, ...]:
    """``n_bases`` level base poses around the object (centre ``centre``, m, shape (3,)), the
    first at the origin, base k turned about the vertical through the centre by 2 pi k /
    n_bases and facing it from ``working`` (m; 0: the first's distance), its line of sight to
    the centre at the elevation 0, -sight, +sight (rad) by k mod 3 (the first keeps its own;
    ``sight`` 0: every base at the first's height)."""
    azimuth = math.atan2(centre[1], centre[0])
    first = float(np.linalg.norm(centre))
    poses = []
    for k in range(n_bases):
        yaw = azimuth + 2 * math.pi * k / n_bases
        level = math.asin(centre[2] / first)
        elevation = (level, level - sight, level + sight)[k % 3] if sight else level
        direction = np.array(
            [
                math.cos(elevation) * math.cos(yaw),
                math.cos(elevation) * math.sin(yaw),
                math.sin(elevation),
            ]
        )
        distance = working if working > 0 else first
        position = np.zeros(3) if k == 0 else centre - distance * direction
        rotation = np.array(
            [[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0], [0, 0, 1]]
        )
        poses.append(BasePose(rotation, position))
    return tuple(poses)


def make_scene(
    index: int,
    seed: int,
    sweeps: int,
    shape: LinkShape,
    n_bases: int = 3,
    sight: float = SIGHT,
    working: float = WORKING_DISTANCE,
) -> tuple[Scene, dict[str, Any]]:
    rng = np.random.default_rng([seed, index])
    name = CLASSES[index % len(CLASSES)]
    size = rng.uniform(0.04, 0.20)
    sizes, truth = make_object(name, size, rng)
    azimuth = rng.uniform(-math.pi / 3, math.pi / 3)
    distance = rng.uniform(0.3, 0.95)
    height = rng.uniform(-0.1, 0.1)
    centre = np.array([distance * math.cos(azimuth), distance * math.sin(azimuth), height])
    rotation = Rotation.random(random_state=rng).as_rotvec()
    obj = primitive_object(name, name, sizes, centre, rotation)
    if name == "cone":
        # a cone's origin is its base centre: put its bounding box's centre where drawn
        shift = centre - obj.mesh.bounds.mean(axis=0)
        obj = primitive_object(name, name, sizes, centre + shift, rotation)
    bases = base_poses(centre, n_bases, sight, working)
    regions = tuple(
        ExploreRegion(*facing_region(obj.mesh.vertices, base, shape, MARGIN), sweeps, sweeps)
        for base in bases
    )
    scene = Scene(f"scene{index}", (obj,), bases, regions[0], base_regions=regions)
    info = {"class": name, "size_m": size, "distance_m": distance, "truth": truth}
    return scene, info


def size_error(name: str, fitted: dict[str, float], truth: dict[str, Any]) -> float:
    """Largest relative error over the class's sizes (box extents sorted)."""
    return size_scores(name, fitted, {}, truth)[0]


def matched_sizes(
    name: str, fitted: dict[str, float], std: dict[str, float], truth: dict[str, Any]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The fitted sizes, their standard deviations (NaN where ``std`` has none) and the true
    sizes, matched (m): a box's extents sorted by size (its axes are its own), the others by
    name."""
    if name == "box":
        order = np.argsort(list(fitted.values()))
        return (
            np.array(list(fitted.values()))[order],
            np.array([std.get(k, math.nan) for k in fitted])[order],
            np.sort(truth["extents"]),
        )
    keys = list(truth)
    return (
        np.array([fitted[k] for k in keys]),
        np.array([std.get(k, math.nan) for k in keys]),
        np.array([truth[k] for k in keys]),
    )


def size_scores(
    name: str, fitted: dict[str, float], std: dict[str, float], truth: dict[str, Any]
) -> tuple[float, list[float | None], bool]:
    """The size error (:func:`size_error`), each size's error over its standard deviation (None
    where the fit left it free), and whether the fit claims every size to 5 % (twice its
    standard deviation within 5 % of it: the sizes a user may trust to 5 %)."""
    got, sd, true = matched_sizes(name, fitted, std, truth)
    z = [
        float((g - t) / s) if math.isfinite(s) and s > 0 else None
        for g, s, t in zip(got, sd, true, strict=True)
    ]
    claimed = bool(np.all(np.isfinite(sd) & (2 * sd <= SIZE_TOLERANCE * got)))
    return float(np.max(np.abs(got / true - 1))), z, claimed


def surface_scores(
    points: list[Any], mesh: trimesh.Trimesh, samples: np.ndarray
) -> dict[str, float]:
    """RMS of the fitted surface near the points to the true one, a Chamfer distance, and the
    whole object's RMS distance to the fitted surface and the fraction of its area within
    :data:`COVERED` of it (the parts never touched count by how far the map is from them);
    ``samples`` are points on the true surface, uniform by area (m, shape (n, 3))."""
    surface = fit_surface(points)
    nan = {
        "surface_rms_m": math.nan,
        "chamfer_m": math.nan,
        "object_rms_m": math.nan,
        "covered": 0.0,
    }
    if surface is None:
        return nan
    zero_level, _ = surface.mesh()
    used = np.array([p.point for p in points if p.status.value == "ok" and p.usable])
    if not len(zero_level.vertices):
        return nan
    near = zero_level.vertices[cKDTree(used).query(zero_level.vertices)[0] < NEAR]
    if not len(near):
        return nan
    _, distance, _ = trimesh.proximity.closest_point(mesh, near)
    # Chamfer: the mean of the two one-sided mean distances between the fitted patch and the
    # true surface's patch near the points
    true_patch = samples[cKDTree(used).query(samples)[0] < NEAR]
    chamfer = math.nan
    if len(true_patch):
        there = cKDTree(near).query(true_patch)[0]
        chamfer = 0.5 * (float(np.mean(distance)) + float(np.mean(there)))
    # the whole true surface, sampled uniformly by area, to the fitted zero level
    _, whole, _ = trimesh.proximity.closest_point(zero_level, samples[::OBJECT_STRIDE])
    return {
        "surface_rms_m": float(np.sqrt(np.mean(distance**2))),
        "chamfer_m": chamfer,
        "object_rms_m": float(np.sqrt(np.mean(whole**2))),
        "covered": float(np.mean(whole <= COVERED)),
    }


def whole_rms(mesh: trimesh.Trimesh, samples: np.ndarray) -> float:
    """RMS distance (m) of the true surface's ``samples`` (m, shape (n, 3)) to ``mesh``."""
    _, distance, _ = trimesh.proximity.closest_point(mesh, samples)
    return float(np.sqrt(np.mean(distance**2)))


def object_progress(
    scene: Scene,
    result: Any,
    out: Path,
    progress: list[dict[str, Any]],
    samples: np.ndarray,
) -> int | None:
    """The contacts after which the map's surface of the whole object first lies within
    :data:`TARGET_RMS` of the true surface (RMS over its ``samples``): the named object's fitted
    shape (the map's ``object.ply``, recognised with the swept links so far, as the map
    recognises) where recognition names one, the implicit surface where not; None when it never
    does. Each checkpoint of ``progress`` it reaches gets ``shape_rms_m``, the named shape's RMS
    (NaN when none is named); recognising is costly, so the checkpoints stop at the first that
    reaches the target."""
    manoeuvres = result.manoeuvres
    include_uncertain = result.settings.include_uncertain
    recorded: dict[int, Any] = {}
    for check in progress:
        k = check["sweeps"]
        if k == len(manoeuvres):
            recognition = result.contact_map.recognition
        else:
            points = [m.point for m in manoeuvres[:k] if m.point is not None]
            swept = swept_links(manoeuvres[:k], scene, result.antenna, out, recorded)
            recognition = recognise_points(points, include_uncertain, swept=swept)
        named = None if recognition is None else recognition.named
        mesh = None if named is None else named.mesh
        check["shape_rms_m"] = math.nan if mesh is None else whole_rms(mesh, samples)
        surface_rms = check["shape_rms_m"] if mesh is not None else check["object_rms_m"]
        if surface_rms <= TARGET_RMS:
            return int(check["contacts"])
    return None


def mahalanobis(points: list[Any]) -> list[float]:
    """Each point's Mahalanobis distance to the simulator's true contact point under its own
    covariance (points without a truth left out); a calibrated 3-D covariance gives a median
    of 1.54, the chi distribution's with 3 degrees of freedom."""
    distances = []
    for p in points:
        if np.all(np.isfinite(p.true_point)):
            error = p.point - p.true_point
            distances.append(float(math.sqrt(error @ np.linalg.solve(p.covariance, error))))
    return distances


def surface_z(points: list[Any], mesh: trimesh.Trimesh) -> list[float]:
    """Each point's signed distance to the true surface over its own standard deviation along
    the surface's normal there (n^T Sigma n)^(1/2), positive outside: what the covariance claims
    where the map and recognition read it. The simulator's contact can slide along the surface
    during and after the estimate's window, which moves the true contact point but not the
    surface; a calibrated normal sigma gives a median |z| of 0.674 (the half-normal's) where the
    surface is flat on the scale of the errors (an error e along a surface of radius R adds
    about e^2 / (2 R) outward; near a box's edge the nearest face's normal need not be the
    error's direction)."""
    if not points:
        return []
    located = np.array([p.point for p in points])
    covariances = np.array([p.covariance for p in points])
    closest, _, faces = trimesh.proximity.closest_point(mesh, located)
    normals = mesh.face_normals[faces]
    signed = np.einsum("ni,ni->n", located - closest, normals)
    sigma = np.sqrt(np.einsum("ni,nij,nj->n", normals, covariances, normals))
    return [float(z) for z in signed / sigma]


def swept_truth(scene: Scene, result: Any, out: Path) -> dict[str, Any]:
    """How far the true object disagrees with the swept links recognition weighs: its residual
    r_j per free sweep and per touching link (``mapping.free_space``), the worst of each, and
    how many sweeps it is below -2 in and how many touches above 2 (each about 2 % of them if
    the samples' sigma is right and Gaussian, fewer when it is generous)."""
    free, touched = swept_links(result.manoeuvres, scene, result.antenna, out)
    obj = scene.objects[0]
    shape = PRIMITIVES[obj.shape]
    r_free = free.residuals(shape.signed_distance(obj.parameters, free.samples))
    r_touch = touched.residuals(shape.signed_distance(obj.parameters, touched.samples))
    return {
        "free_sweeps": int(free.n_sweeps),
        "free_truth_min_r": float(r_free.min()) if len(r_free) else math.nan,
        "free_truth_below_2": int(np.sum(r_free < -2.0)),
        "touch_links": int(touched.n_sweeps),
        "touch_truth_max_r": float(r_touch.max()) if len(r_touch) else math.nan,
        "touch_truth_above_2": int(np.sum(r_touch > 2.0)),
    }


def run(
    scene: Scene,
    info: dict[str, Any],
    strategy: str,
    method: str,
    calibrated: Path,
    seed: int,
    workdir: Path,
    link: str = "nonlinear",
    until_recognised: int = 0,
    device_profile: str = "nominal",
    device_build: int | None = None,
    sizes_within: float | None = None,
) -> dict[str, Any]:
    out = workdir / f"{scene.name}-{strategy}"
    resumed = out.exists()
    out.mkdir(parents=True, exist_ok=True)
    if not (out / CALIBRATED_FILE).exists():
        shutil.copy(calibrated, out / CALIBRATED_FILE)
    start = time.perf_counter()
    result = explore(
        scene,
        paper_antenna(),
        out,
        ExploreSettings(
            method,
            strategy,
            seed=seed,
            link=link,
            until_recognised=until_recognised,
            sizes_within=sizes_within,
            device_profile=device_profile,
            device_build=device_build,
        ),
    )
    elapsed = time.perf_counter() - start
    manoeuvres = result.manoeuvres
    summary = result.summary()
    mesh = scene.objects[0].mesh
    used = [p for p in result.contact_map.used]
    row: dict[str, Any] = {
        "strategy": strategy,
        "sweeps": len(manoeuvres),
        "contacts": sum(m.outcome == "touch" for m in manoeuvres),
        "used": len(used),
        "outcomes": summary["outcomes"],
        "sweep_time_s": summary["sweep_time_s"],
        "run_s": elapsed,
        "aims": {aim: summary["aims"].get(aim, 0) for aim in AIMS},
        "resumed": resumed,
    }
    if used:
        _, distance, _ = trimesh.proximity.closest_point(mesh, np.array([p.point for p in used]))
        row["point_rms_m"] = float(np.sqrt(np.mean(distance**2)))
        row["point_max_m"] = float(np.max(distance))
    else:
        row["point_rms_m"] = row["point_max_m"] = math.nan
    row["mahalanobis"] = mahalanobis(used)
    row["surface_z"] = surface_z(used, mesh)
    row.update(swept_truth(scene, result, out))
    progress = []
    samples, _ = trimesh.sample.sample_surface(mesh, 20000, seed=0)
    checkpoints = sorted({*range(CHECK_EVERY, len(manoeuvres), CHECK_EVERY), len(manoeuvres)})
    for k in checkpoints:
        points = [m.point for m in manoeuvres[:k] if m.point is not None]
        scores = surface_scores(points, mesh, samples)
        progress.append(
            {
                "sweeps": k,
                "contacts": sum(m.outcome == "touch" for m in manoeuvres[:k]),
                "used": sum(p.status.value == "ok" for p in points),
                **scores,
            }
        )
    row["progress"] = progress
    row.update({k: v for k, v in progress[-1].items() if k.endswith("_m") or k == "covered"})
    reached = [c["contacts"] for c in progress if c["object_rms_m"] <= TARGET_RMS]
    row["contacts_to_target"] = reached[0] if reached else None
    row["contacts_to_object_target"] = object_progress(
        scene, result, out, progress, samples[::OBJECT_STRIDE]
    )
    recognition = result.contact_map.recognition
    named = None if recognition is None else recognition.named
    row["shape_rms_m"] = (
        math.nan
        if named is None or named.mesh is None
        else whole_rms(named.mesh, samples[::OBJECT_STRIDE])
    )
    if recognition is None:
        row.update(
            decision=None,
            right=False,
            abstained=False,
            confident_wrong=False,
            confidence=math.nan,
            size_error=math.nan,
            size_z=[],
            size_claimed=False,
        )
    else:
        name = info["class"]
        fit = next(f for f in recognition.fits if f.name == name)
        row.update(
            decision=recognition.decision,
            right=recognition.decision == name,
            abstained=recognition.decision == UNDECIDED,
            confident_wrong=recognition.decision not in (name, UNDECIDED),
            confidence=recognition.confidence,
            overdispersion=recognition.overdispersion,
            candidates=list(recognition.candidates),
            rival=recognition.rival,
        )
        error, z, claimed = size_scores(name, dict(fit.sizes), dict(fit.size_std), info["truth"])
        row.update(
            size_error=error,
            sizes=dict(fit.sizes),
            size_std={k: v if math.isfinite(v) else None for k, v in fit.size_std.items()},
            size_at_least=dict(fit.size_at_least),
            size_z=z,
            size_claimed=claimed,
        )
    return row


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    def mean(key: str) -> float | None:
        values = [r[key] for r in rows if isinstance(r[key], float) and math.isfinite(r[key])]
        return float(np.mean(values)) if values else None

    recognised = [r for r in rows if r["decision"] is not None]
    distances = [d for r in rows for d in r["mahalanobis"]]
    normal_z = np.abs([z for r in rows for z in r.get("surface_z", [])])
    return {
        "scenes": len(rows),
        "mean_contacts": float(np.mean([r["contacts"] for r in rows])),
        "mean_used": float(np.mean([r["used"] for r in rows])),
        "mean_point_rms_m": mean("point_rms_m"),
        "mean_point_max_m": mean("point_max_m"),
        "mean_surface_rms_m": mean("surface_rms_m"),
        "mean_chamfer_m": mean("chamfer_m"),
        "mean_object_rms_m": mean("object_rms_m"),
        "mean_covered": mean("covered"),
        "reached_target": sum(r["contacts_to_target"] is not None for r in rows),
        "mean_contacts_to_target": mean_reached(rows, "contacts_to_target"),
        # over the scenes whose map names a bounded object, ``named`` of them
        "named": sum(math.isfinite(r["shape_rms_m"]) for r in rows),
        "mean_shape_rms_m": mean("shape_rms_m"),
        "reached_object_target": sum(r.get("contacts_to_object_target") is not None for r in rows),
        "mean_contacts_to_object_target": mean_reached(rows, "contacts_to_object_target"),
        "recognised": len(recognised),
        "right": sum(r["right"] for r in rows),
        "abstained": sum(r["abstained"] for r in rows),
        "confident_wrong": sum(r["confident_wrong"] for r in rows),
        **size_summary([r for r in rows if r["right"]]),
        "median_size_error_when_right": float(
            np.median([r["size_error"] for r in rows if r["right"]])
        )
        if any(r["right"] for r in rows)
        else None,
        "median_mahalanobis": float(np.median(distances)) if distances else None,
        "mahalanobis_quantiles": {
            str(q): float(np.quantile(distances, q)) for q in (0.1, 0.5, 0.9, 0.99)
        }
        if distances
        else None,
        "median_abs_surface_z": float(np.median(normal_z)) if normal_z.size else None,
        "surface_z_rms": float(np.sqrt(np.mean(normal_z**2))) if normal_z.size else None,
        "free_sweeps": sum(r.get("free_sweeps", 0) for r in rows),
        "free_truth_below_2": sum(r.get("free_truth_below_2", 0) for r in rows),
        "touch_links": sum(r.get("touch_links", 0) for r in rows),
        "touch_truth_above_2": sum(r.get("touch_truth_above_2", 0) for r in rows),
        "mean_sweep_time_s": mean("sweep_time_s"),
        "mean_run_s": mean("run_s"),
    }


def mean_reached(rows: list[dict[str, Any]], key: str) -> float | None:
    """The mean of ``key`` (contacts to a target) over the rows that reached it."""
    reached = [r[key] for r in rows if r.get(key) is not None]
    return float(np.mean(reached)) if reached else None


def size_summary(right: list[dict[str, Any]]) -> dict[str, Any]:
    """Over the right answers: sizes within 5 %, the sizes' errors over their standard
    deviations, and the answers that claim every size to 5 % (twice its standard deviation)
    against those of them that are off by more."""
    z = np.abs([v for r in right for v in r.get("size_z", []) if v is not None])
    claimed = [r for r in right if r.get("size_claimed")]
    return {
        "size_within_5": sum(r["size_error"] <= SIZE_TOLERANCE for r in right),
        "size_z_median_abs": float(np.median(z)) if z.size else None,
        "size_z_within_2": float(np.mean(z <= 2)) if z.size else None,
        # sizes with no deviation: not measured, or only a lower bound (``size_at_least``)
        "size_free": sum(v is None for r in right for v in r.get("size_z", [])),
        "size_at_least": sum(len(r.get("size_at_least", {})) for r in right),
        "size_claimed": len(claimed),
        "size_claimed_but_off": sum(r["size_error"] > SIZE_TOLERANCE for r in claimed),
    }


def print_target(rows: list[dict[str, Any]]) -> None:
    """The contacts each strategy needs for a whole-object RMS of 5 mm, scene by scene: of the
    implicit surface, and of the map's surface of the whole object (the named shape where
    recognition names one)."""
    for key, surface in (
        ("contacts_to_target", "the implicit surface"),
        ("contacts_to_object_target", "the named shape, else the implicit surface"),
    ):
        print_pairs(rows, key, surface)


def print_pairs(rows: list[dict[str, Any]], key: str, surface: str) -> None:
    """How many scenes each strategy brings to the target with ``surface``, and the ratio of
    their contacts (``key``) where both do."""
    need: dict[int, dict[str, int | None]] = {}
    for r in rows:
        need.setdefault(r["scene"], {})[r["strategy"]] = r.get(key)
    pairs = [
        (n["grid"], n["next-best"])
        for n in need.values()
        if n.get("grid") is not None and n.get("next-best") is not None
    ]
    print(f"\nwhole-object RMS <= {1000 * TARGET_RMS:.0f} mm, {surface}:")
    for strategy in STRATEGIES:
        got = [n[strategy] for n in need.values() if strategy in n]
        reached = [c for c in got if c is not None]
        print(f"  {strategy:9s} reached in {len(reached)} of {len(got)} scenes")
    if pairs:
        ratio = [b / a for a, b in pairs if a]
        print(
            f"  both reached it in {len(pairs)} scenes: next-best / grid contacts,"
            f" median {np.median(ratio):.2f}, at most half in"
            f" {sum(x <= 0.5 for x in ratio)}"
        )


def write_results(
    args: argparse.Namespace,
    rows: list[dict[str, Any]],
    totals: dict[str, Any] | None = None,
) -> None:
    """The settings, the totals per strategy and every row, as JSON in ``args.out``."""
    if totals is None:
        totals = {
            s: summarise([r for r in rows if r["strategy"] == s])
            for s in args.strategies
            if any(r["strategy"] == s for r in rows)
        }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(
        json.dumps(
            {
                "date": datetime.date.today().isoformat(),
                "settings": vars(args)
                | {"out": str(args.out), "keep": args.keep and str(args.keep)},
                "total": totals,
                "scenes": rows,
            },
            indent=1,
            default=float,
        )
        + "\n"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenes", type=int, default=12)
    parser.add_argument("--first", type=int, default=0, help="index of the first scene")
    parser.add_argument(
        "--sweeps",
        type=int,
        default=4,
        help="grid elevations (each swept both ways) and vertical sweeps per base",
    )
    parser.add_argument("--bases", type=int, default=3, help="base poses around the object")
    parser.add_argument("--strategies", nargs="+", choices=STRATEGIES, default=list(STRATEGIES))
    parser.add_argument("--method", choices=("paper", "fast"), default="fast")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--link", choices=("nonlinear", "linear"), default="nonlinear")
    parser.add_argument(
        "--device-profile",
        choices=DEVICE_PROFILES,
        default="nominal",
        help="the simulated device's imperfections (ExploreSettings.device_profile)",
    )
    parser.add_argument(
        "--device-build",
        type=integer(0),
        default=None,
        help=f"a realistic device's build seed (default {DEFAULT_BUILD})",
    )
    parser.add_argument(
        "--sight", type=float, default=SIGHT, help="the raised and lowered bases' sight (rad)"
    )
    parser.add_argument(
        "--distance",
        type=float,
        default=WORKING_DISTANCE,
        help="the other bases' distance from the object (m; 0: the first base's)",
    )
    parser.add_argument(
        "--until-recognised",
        type=integer(0),
        default=0,
        metavar="N",
        help="after the budget, up to N more sweeps while recognition abstains",
    )
    parser.add_argument(
        "--sizes-within",
        type=number(0.0, 1.0, low_open=True, what="share"),
        default=None,
        metavar="SHARE",
        help=(
            "with --until-recognised: go on also while the named object's sizes are not each "
            "known to within this share of themselves (twice the standard deviation)"
        ),
    )
    parser.add_argument("--out", type=Path, default=RESULTS)
    parser.add_argument(
        "--keep",
        type=Path,
        default=None,
        help="keep each exploration's directory in this one (one already there is resumed)",
    )
    args = parser.parse_args()
    if args.sizes_within is not None and args.until_recognised == 0:
        parser.error(
            "--sizes-within: the sizes are swept for after the budget: give --until-recognised N"
        )
    device = paper_antenna()
    shape = LinkShape(device.link)
    rows: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory(prefix="eval-explore-") as folder:
        workdir = Path(folder) if args.keep is None else args.keep
        workdir.mkdir(parents=True, exist_ok=True)
        calibrated = workdir / "calibrated.toml"
        prepared = prepare_device(
            device,
            workdir / "calibration",
            link=args.link,
            device_profile=args.device_profile,
            device_build=args.device_build,
        )
        calibrated.write_text(antenna_to_toml(prepared))
        # what the preparation made of the device, kept with the results
        sensor = workdir / "calibration" / "sensor.txt"
        args.preparation = {
            "calibrated_t": prepared.link.calibrated_t,
            "tip_mass_kg": prepared.link.tip_mass,
            "calibration_scatter": prepared.link.calibration_scatter,
            "sensor": dataclasses.asdict(prepared.sensor),
            "sensor_fit": sensor.read_text().strip() if sensor.is_file() else None,
        }
        for index in range(args.first, args.first + args.scenes):
            scene, info = make_scene(
                index, args.seed, args.sweeps, shape, args.bases, args.sight, args.distance
            )
            for strategy in args.strategies:
                row = {
                    "scene": index,
                    **info,
                    **run(
                        scene,
                        info,
                        strategy,
                        args.method,
                        calibrated,
                        args.seed,
                        workdir,
                        args.link,
                        args.until_recognised,
                        args.device_profile,
                        args.device_build,
                        args.sizes_within,
                    ),
                }
                rows.append(row)
                # written after every exploration: a run stopped early keeps its scenes
                write_results(args, rows)
                print(
                    f"{index:3d} {info['class']:9s} {100 * info['size_m']:5.1f} cm"
                    f" {info['distance_m']:.2f} m {strategy:9s}: {row['contacts']:2d} contacts"
                    f" ({row['used']:2d} ok), points {1000 * row['point_rms_m']:.1f} mm,"
                    f" surface {1000 * row['surface_rms_m']:.1f} mm -> {row['decision']}"
                    f" ({row['run_s']:.0f} s)",
                    flush=True,
                )
    totals = {s: summarise([r for r in rows if r["strategy"] == s]) for s in args.strategies}
    print()
    print(
        f"{'strategy':9s} {'contacts':>8s} {'ok':>5s} {'points RMS':>10s} {'surface RMS':>11s}"
        f" {'Chamfer':>8s} {'right':>5s} {'abst.':>5s} {'wrong':>5s} {'Mahal.':>6s}"
        f" {'|z| n':>6s}"
    )
    for strategy, s in totals.items():

        def mm(value: float | None) -> str:
            return "-" if value is None else f"{1000 * value:.2f}"

        print(
            f"{strategy:9s} {s['mean_contacts']:8.1f} {s['mean_used']:5.1f}"
            f" {mm(s['mean_point_rms_m']):>7s} mm {mm(s['mean_surface_rms_m']):>8s} mm"
            f" {mm(s['mean_chamfer_m']):>5s} mm {s['right']:5d} {s['abstained']:5d}"
            f" {s['confident_wrong']:5d} {s['median_mahalanobis'] or math.nan:6.2f}"
            f" {s['median_abs_surface_z'] or math.nan:6.2f}"
        )
    print("\nsizes of the right answers:")
    for strategy, s in totals.items():
        print(
            f"  {strategy:9s} within 5 % {s['size_within_5']} of {s['right']};"
            f" error over std: median |z| {s['size_z_median_abs'] or math.nan:.2f},"
            f" within 2 {s['size_z_within_2'] or math.nan:.2f}, free {s['size_free']};"
            f" claimed to 5 % {s['size_claimed']}, of which off by more"
            f" {s['size_claimed_but_off']}"
        )
    print_target(rows)
    write_results(args, rows, totals)
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
