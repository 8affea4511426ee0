"""A contact point's covariance against its error, on the linear and the geometrically exact link.

The touches are the first touches of ``eval_explore.py``'s scenes (its grid sweeps from every
base), each simulated twice, with the simulator's linear link (``link_model = "linear"``) and
with its geometrically exact link (the one ``antenna explore`` simulates by default), and
estimated with ``--method`` after the README's calibration. For every ``ok`` estimate: the
Mahalanobis distance of the simulator's true contact point under the point's covariance
(``mapping.contact_point_from_estimate``; a calibrated 3-D covariance gives a median of 1.54 and
a 90th percentile of 2.50, the chi distribution's with 3 degrees of freedom), the true point
taken where the simulated contact was at the instant the point describes (the estimate's
``t_point``, read from the recording's contact track), and, beside it, the same distance to
where the contact ended and how far it slid from the one to the other; and the error's
parts along the link X^m, along the push across it, across the bending plane and along the
touched surface's normal, each with the covariance's standard deviation in that direction.
Each link is prepared on itself as ``antenna explore`` prepares it (the observer identified on
free sweeps, then five smooth posts).

The linear link is linear in its deflection: its points do not move along X^m (docs/simulator.md),
while a real link, inextensible, shortens by delta = x_c - p . X^m as it bends, about 3 y_c^2 /
(5 x_c), which the estimators' elastica places the point with. The exact link has it.

Run: ``python benchmarks/eval_point_covariance.py [--scenes 6] [--method fast] [--seed 0]``.
Prints a table and writes ``benchmarks/results/point_covariance.json``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # one core, set before numpy loads

import argparse  # noqa: E402
import datetime  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

from eval_explore import make_scene  # noqa: E402
from sensing_antenna import paper_antenna  # noqa: E402
from sensing_antenna.campaign.simulated import knowing_weight  # noqa: E402
from sensing_antenna.estimation import estimate  # noqa: E402
from sensing_antenna.exploration import grid_sweeps, prepare_device  # noqa: E402
from sensing_antenna.mapping import (  # noqa: E402
    BasePose,
    PointUncertainty,
    contact_point_from_estimate,
)
from sensing_antenna.recording import tracked_contact  # noqa: E402
from sensing_antenna.scene import LinkShape, simulate_sweep  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "point_covariance.json"
LINKS = ("linear", "nonlinear")
#: The error's parts: along the link, along the push, across the bending plane, and along the
#: touched surface's normal (the only part recognition and the surface weigh).
PARTS = ("along", "push", "binormal", "normal")
#: Other deflection uncertainties rho the points' covariances are also computed with (the
#: default is ``PointUncertainty``'s).
RHOS = (0.05, 0.02)


def measure(outcome: Any, antenna: Any, method: str) -> dict[str, float] | None:
    """The Mahalanobis distance and the error's parts of one sweep's estimate (m)."""
    recording = outcome.recording
    result = estimate(recording.without_ground_truth(), antenna, method=method)
    if result.status.value != "ok" or result.trace is None or result.trace.frame is None:
        return None
    # where the link touched at the instant the point describes (the recording's contact
    # track), and where it ended
    truth = tracked_contact(recording, result.diagnostics["t_point"])
    ended = tracked_contact(recording, recording.t[-1])
    assert truth is not None and ended is not None
    point = contact_point_from_estimate(result, antenna, BasePose.identity())
    error = point.point - truth
    # the push and the bending plane as the point was placed: Y^c along the answer's reaction
    x_m = result.trace.frame.motor_axes_a[0]
    y_c = np.asarray(result.diagnostics["axes_c_absolute"])[1]
    push = y_c - (y_c @ x_m) * x_m
    push /= np.linalg.norm(push)
    binormal = np.cross(x_m, push)
    # the touched surface's outward normal in the recording's frame: what recognition weighs
    normal = outcome.frame.rotation.T @ outcome.touch.normal
    row = {"x_c": float(result.x_c)}
    row["mahalanobis"] = float(math.sqrt(error @ np.linalg.solve(point.covariance, error)))
    row["slide_after_m"] = float(np.linalg.norm(ended - truth))
    late = point.point - ended
    row["mahalanobis_ended"] = float(math.sqrt(late @ np.linalg.solve(point.covariance, late)))
    axes = (("along", x_m), ("push", push), ("binormal", binormal), ("normal", normal))
    for name, axis in axes:
        row[f"error_{name}_m"] = float(error @ axis)
        row[f"std_{name}_m"] = float(math.sqrt(axis @ point.covariance @ axis))
    # the same point under other deflection uncertainties rho: the normal's std and the
    # Mahalanobis distance
    for rho in RHOS:
        other = contact_point_from_estimate(
            result,
            antenna,
            BasePose.identity(),
            uncertainty=PointUncertainty(deflection_relative_std=rho),
        )
        row[f"std_normal_rho{rho:g}_m"] = float(math.sqrt(normal @ other.covariance @ normal))
        row[f"mahalanobis_rho{rho:g}"] = float(
            math.sqrt(error @ np.linalg.solve(other.covariance, error))
        )
    return row


def summarise(rows: list[dict[str, float]]) -> dict[str, Any]:
    distances = np.array([r["mahalanobis"] for r in rows])
    ended = np.array([r["mahalanobis_ended"] for r in rows])
    slide = np.array([r["slide_after_m"] for r in rows])
    summary: dict[str, Any] = {
        "points": len(rows),
        "mahalanobis_quantiles": {
            str(q): float(np.quantile(distances, q)) for q in (0.1, 0.5, 0.9, 0.99)
        },
        "ended": {
            "mahalanobis_quantiles": {
                str(q): float(np.quantile(ended, q)) for q in (0.1, 0.5, 0.9, 0.99)
            },
            "slide_median_m": float(np.median(slide)),
            "slide_p90_m": float(np.quantile(slide, 0.9)),
        },
    }
    for name in PARTS:
        error = np.array([r[f"error_{name}_m"] for r in rows])
        std = np.array([r[f"std_{name}_m"] for r in rows])
        summary[name] = {
            "error_mean_m": float(np.mean(error)),
            "error_rms_m": float(np.sqrt(np.mean(error**2))),
            "std_median_m": float(np.median(std)),
            "z_rms": float(np.sqrt(np.mean((error / std) ** 2))),
        }
    error = np.array([r["error_normal_m"] for r in rows])
    for rho in RHOS:
        std = np.array([r[f"std_normal_rho{rho:g}_m"] for r in rows])
        others = np.array([r[f"mahalanobis_rho{rho:g}"] for r in rows])
        summary[f"rho{rho:g}"] = {
            "normal_std_median_m": float(np.median(std)),
            "normal_z_rms": float(np.sqrt(np.mean((error / std) ** 2))),
            "mahalanobis_median": float(np.median(others)),
        }
    return summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenes", type=int, default=6)
    parser.add_argument("--method", choices=("paper", "fast"), default="fast")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args()
    device = paper_antenna()
    shape = LinkShape(device.link)
    # each link prepared on itself (observer identified, T_e calibrated), as a device is
    # prepared before it measures; the device's controller detects with what was identified
    antennas = {link: prepare_device(device, link=link) for link in LINKS}
    devices = {link: knowing_weight(device, antennas[link]) for link in LINKS}
    rows: dict[str, list[dict[str, float]]] = {link: [] for link in LINKS}
    for index in range(args.scenes):
        scene, _ = make_scene(index, args.seed, 6, shape, 3)
        for k, sweep in enumerate(grid_sweeps(scene)):
            for link in LINKS:
                outcome = simulate_sweep(
                    devices[link], scene, sweep, seed=args.seed + k, shape=shape, link_model=link
                )
                if outcome.recording is None:
                    continue
                row = measure(outcome, antennas[link], args.method)
                if row is not None:
                    rows[link].append(row | {"scene": index, "sweep": k})
        counts = " and ".join(str(len(rows[link])) for link in LINKS)
        print(f"scene {index}: {counts} ok points so far", flush=True)
    totals = {link: summarise(rows[link]) for link in LINKS}
    print(f"\n{'link':9s} {'points':>6s} {'Mahalanobis p10/p50/p90':>24s}   error RMS / std (mm)")
    for link, s in totals.items():
        q = s["mahalanobis_quantiles"]
        parts = "  ".join(
            f"{name} {1000 * s[name]['error_rms_m']:.2f} / {1000 * s[name]['std_median_m']:.2f}"
            for name in PARTS
        )
        quantiles = f"{q['0.1']:8.2f} {q['0.5']:6.2f} {q['0.9']:6.2f}"
        print(f"{link:9s} {s['points']:6d} {quantiles}   {parts}")
        e = s["ended"]
        q = e["mahalanobis_quantiles"]
        print(
            f"{'':9s} to where the contact ended: Mahalanobis {q['0.1']:.2f} {q['0.5']:.2f}"
            f" {q['0.9']:.2f}; slid {1000 * e['slide_median_m']:.2f} mm (median),"
            f" {1000 * e['slide_p90_m']:.2f} mm (90 %) after the point's instant"
        )
        for rho in RHOS:
            r = s[f"rho{rho:g}"]
            print(
                f"{'':9s} rho {rho:g}: normal std {1000 * r['normal_std_median_m']:.2f} mm,"
                f" error / std RMS {r['normal_z_rms']:.2f}, Mahalanobis median"
                f" {r['mahalanobis_median']:.2f}"
            )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(
        json.dumps(
            {
                "date": datetime.date.today().isoformat(),
                "settings": vars(args) | {"out": str(args.out)},
                "total": totals,
                "points": rows,
            },
            indent=1,
        )
        + "\n"
    )
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
