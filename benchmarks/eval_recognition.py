"""Recognition and surface accuracy of the mapping alone, on random one-object scenes.

Each scene holds one primitive (sphere, cylinder, capsule, cone, torus or box, in turn), its
largest dimension drawn in 4 to 20 cm, at a random orientation, its centre 0.3 to 0.95 m from
the origin (the antenna's base) within the head's reach (azimuth within +-90 degrees, elevation
within +-30 degrees). The contacts are points of the object's side facing the origin (faces
whose outward normal points towards it), drawn uniformly on that side, each moved by Gaussian
noise of the covariance :mod:`sensing_antenna.mapping.points` gives a ``fast`` estimate there:
its median 95 % interval on the default campaign (FAST_INTERVAL_WIDTH), 2000-count encoders, a push
deflection of ``--deflection-ratio`` times x_c in an unknown direction, the link's radius.
The contacts are not simulated (no sweeps, no estimator): this measures the map and the
recognition given points with the estimates' uncertainty, without the links' lines (points
drawn on a side carry no sweep; ``eval_explore.py`` has them).

Per scene: the decision, whether it is right, abstained or confidently wrong; the size error of
the true class's fit (largest relative error over its sizes; box extents compared sorted); the
RMS distance of the points and of the surface mesh near them (vertices within 1 cm of a
contact) to the true mesh. Prints a table per class and in total; writes
``benchmarks/results/recognition.json``.

Run: ``python benchmarks/eval_recognition.py [--scenes 60] [--contacts 30] [--seed 0]``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # one core, set before numpy loads

import argparse  # noqa: E402
import datetime  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
import trimesh  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

from eval_explore import CLASSES, make_object, size_error  # noqa: E402
from sensing_antenna.antenna import load_antenna  # noqa: E402
from sensing_antenna.estimation.result import ContactEstimate, Status  # noqa: E402
from sensing_antenna.mapping import (  # noqa: E402
    UNDECIDED,
    ImplicitSurface,
    contact_point_from_estimate,
    recognise,
)
from sensing_antenna.scene import primitive_object  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "recognition.json"
#: Median width of the fast method's 95 % interval on the default campaign (m).
FAST_INTERVAL_WIDTH = 0.00525
#: The surface is scored where the points are: mesh vertices within this of a contact (m).
NEAR = 0.01


def place(mesh: Any, rng: np.random.Generator) -> np.ndarray:
    """Random orientation; centre 0.3 to 0.95 m away within the head's reach."""
    azimuth = rng.uniform(-math.pi / 2, math.pi / 2)
    elevation = rng.uniform(-math.pi / 6, math.pi / 6)
    distance = rng.uniform(0.3, 0.95)
    direction = np.array(
        [
            math.cos(elevation) * math.cos(azimuth),
            math.cos(elevation) * math.sin(azimuth),
            math.sin(elevation),
        ]
    )
    matrix = np.eye(4)
    matrix[:3, :3] = Rotation.random(random_state=rng).as_matrix()
    matrix[:3, 3] = distance * direction
    mesh.apply_transform(matrix)
    return matrix


def contacts(
    mesh: Any, n: int, antenna: Any, deflection_ratio: float, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """n noisy points of the side facing the origin, their covariances, the true points."""
    candidates, faces = trimesh.sample.sample_surface(mesh, 40 * n, seed=int(rng.integers(2**31)))
    facing = np.einsum("ni,ni->n", mesh.face_normals[faces], -candidates) > 0
    chosen = candidates[facing]
    chosen = chosen[rng.permutation(len(chosen))[:n]]
    points = np.empty_like(chosen)
    covariances = np.empty((len(chosen), 3, 3))
    for i, p in enumerate(chosen):
        x_c = float(np.linalg.norm(p))
        estimate = ContactEstimate(
            status=Status.OK,
            reason=None,
            method="fast",
            x_c=x_c,
            contact_point=p,
            interval=(x_c - FAST_INTERVAL_WIDTH / 2, x_c + FAST_INTERVAL_WIDTH / 2),
            diagnostics={"deflection_ratio": deflection_ratio},
        )
        covariance = contact_point_from_estimate(estimate, antenna).covariance
        covariances[i] = covariance
        points[i] = rng.multivariate_normal(p, covariance)
    return points, covariances, chosen


def run_scene(
    index: int, n_contacts: int, deflection_ratio: float, antenna: Any, seed: int
) -> dict[str, Any]:
    rng = np.random.default_rng([seed, index])
    name = CLASSES[index % len(CLASSES)]
    size = rng.uniform(0.04, 0.20)
    sizes, truth = make_object(name, size, rng)
    mesh = primitive_object(name, name, sizes).mesh
    place(mesh, rng)
    points, covariances, _ = contacts(mesh, n_contacts, antenna, deflection_ratio, rng)
    start = time.perf_counter()
    result = recognise(points, covariances, outward=-points.mean(axis=0), rng=rng)
    recognition_s = time.perf_counter() - start
    fit = next(f for f in result.fits if f.name == name)
    _, point_distance, _ = trimesh.proximity.closest_point(mesh, points)
    start = time.perf_counter()
    surface = ImplicitSurface().fit(points, covariances, np.zeros(3))
    zero_level, _ = surface.mesh()
    surface_s = time.perf_counter() - start
    surface_rms = math.nan
    if len(zero_level.vertices):
        gap = np.min(np.linalg.norm(zero_level.vertices[:, None] - points[None], axis=2), axis=1)
        near = zero_level.vertices[gap < NEAR]
        if len(near):
            _, distance, _ = trimesh.proximity.closest_point(mesh, near)
            surface_rms = float(np.sqrt(np.mean(distance**2)))
    return {
        "scene": index,
        "class": name,
        "size_m": size,
        "distance_m": float(np.linalg.norm(mesh.centroid)),
        "n_contacts": len(points),
        "decision": result.decision,
        "candidates": list(result.candidates),
        "delta_score": result.delta_score,
        "confidence": result.confidence,
        "right": result.decision == name,
        "abstained": result.decision == UNDECIDED,
        "confident_wrong": result.decision not in (name, UNDECIDED),
        "size_error": size_error(name, fit.sizes, truth),
        "sizes_fitted": dict(fit.sizes),
        "point_rms_m": float(np.sqrt(np.mean(point_distance**2))),
        "median_point_sigma_m": float(np.median(np.sqrt(np.linalg.eigvalsh(covariances)[:, -1]))),
        "surface_rms_m": surface_rms,
        "recognition_s": recognition_s,
        "surface_s": surface_s,
    }


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    right = [r for r in rows if r["right"]]
    surface = [r["surface_rms_m"] for r in rows if math.isfinite(r["surface_rms_m"])]
    return {
        "scenes": len(rows),
        "accuracy": len(right) / len(rows),
        "abstained": sum(r["abstained"] for r in rows),
        "confident_wrong": sum(r["confident_wrong"] for r in rows),
        "median_size_error": float(np.median([r["size_error"] for r in rows])),
        "size_error_within_5pc_when_right": sum(r["size_error"] < 0.05 for r in right),
        "mean_point_rms_m": float(np.mean([r["point_rms_m"] for r in rows])),
        "mean_surface_rms_m": float(np.mean(surface)) if surface else None,
        "mean_recognition_s": float(np.mean([r["recognition_s"] for r in rows])),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenes", type=int, default=60)
    parser.add_argument("--contacts", type=int, default=30, help="contacts per object")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--deflection-ratio", type=float, default=0.05, help="y_c / x_c of the pushes"
    )
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args()
    antenna = load_antenna("paper-2021")
    rows = []
    for index in range(args.scenes):
        rows.append(run_scene(index, args.contacts, args.deflection_ratio, antenna, args.seed))
        r = rows[-1]
        print(
            f"{index:3d} {r['class']:9s} {100 * r['size_m']:5.1f} cm -> {r['decision']:9s}"
            f" dscore {r['delta_score']:7.1f} size err {100 * r['size_error']:5.1f} %"
            f" points {1000 * r['point_rms_m']:.2f} mm surface {1000 * r['surface_rms_m']:.2f} mm",
            flush=True,
        )
    by_class = {
        name: summarise([r for r in rows if r["class"] == name])
        for name in CLASSES
        if any(r["class"] == name for r in rows)
    }
    total = summarise(rows)
    print()
    print(
        f"{'class':9s} {'n':>3s} {'right':>6s} {'abst.':>5s} {'conf. wrong':>11s}"
        f" {'med size err':>12s} {'points RMS':>10s} {'surface RMS':>11s}"
    )
    for name, s in [*by_class.items(), ("total", total)]:
        surface = (
            "-" if s["mean_surface_rms_m"] is None else f"{1000 * s['mean_surface_rms_m']:.2f}"
        )
        print(
            f"{name:9s} {s['scenes']:3d} {100 * s['accuracy']:5.0f}% {s['abstained']:5d}"
            f" {s['confident_wrong']:11d} {100 * s['median_size_error']:11.1f}%"
            f" {1000 * s['mean_point_rms_m']:7.2f} mm {surface:>8s} mm"
        )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(
        json.dumps(
            {
                "date": datetime.date.today().isoformat(),
                "settings": {
                    "scenes": args.scenes,
                    "contacts": args.contacts,
                    "seed": args.seed,
                    "deflection_ratio": args.deflection_ratio,
                    "fast_interval_width_m": FAST_INTERVAL_WIDTH,
                },
                "total": total,
                "by_class": by_class,
                "scenes": rows,
            },
            indent=1,
        )
        + "\n"
    )
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
