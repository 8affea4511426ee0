"""Does the fast method's 95 % interval hold the contact, on the exploration's recordings?

The recordings kept by ``eval_explore.py --keep DIR`` are touches the campaigns do not make:
spheres, cylinders, capsules, boxes, cones and tori met at any angle across the sweep, the
simulator's geometrically exact link, pushes of 6 to 10 % deflection. Each is estimated again
with the exploration's calibrated antenna (``DIR/calibrated.toml``) by the ``fast`` method (the
one with an interval) and, for every ``ok`` answer, scored against where the link touched at the
answer's instant (its ``t_point``): the error (m), whether the interval holds it, and by the
simulated obstacle's kind. The recording's ``true_xc`` is the abscissa at its last sample in
contact, and a contact may slide centimetres along a curved object after the answer's window;
the abscissa at ``t_point`` is ``true_xc`` less the contact track's displacement from then to
that last sample along the link's direction X^m at ``t_point`` (a rigid link's: the slope the
push gives the link at the contact, a few degrees, errs by about that angle times the slide
across the link, 1 mm for 2 cm at 3 degrees). A recording
without the track is scored against ``true_xc``. ``--every N`` takes every N-th recording (in
name order).

Run: ``python benchmarks/eval_explore_intervals.py DIR [DIR ...] [--every 4] [--strategies grid
next-best] [--out FILE]`` (the stored results: the two halves of ``explore.json``'s explorations,
``--strategies grid``). Prints a table and writes ``benchmarks/results/explore_intervals.json``
(recordings named by their DIR's name and their path in it).
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

from sensing_antenna import load_antenna  # noqa: E402
from sensing_antenna.estimation import estimate  # noqa: E402
from sensing_antenna.mapping.points import Z_95  # noqa: E402
from sensing_antenna.recording import (  # noqa: E402
    IN_CONTACT_COLUMN,
    read_recording,
    tracked_contact,
)
from sensing_antenna.simulator.contact import motor_frame  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "explore_intervals.json"


def score(path: Path, kept: Path, antenna: Any) -> dict[str, Any]:
    """One recording's answer and its error against the simulator's contact."""
    recording = read_recording(path)
    truth = float(recording.metadata.get("true_xc", math.nan))
    obstacle = json.loads(recording.metadata.get("true_obstacle") or "null")
    kind = obstacle.get("kind", "unknown") if isinstance(obstacle, dict) else "unknown"
    answer = estimate(recording.without_ground_truth(), antenna, "fast")
    low, high = answer.interval if answer.interval is not None else (math.nan, math.nan)
    end = truth
    truth = at_instant(recording, truth, answer.diagnostics.get("t_point"))
    return {
        "recording": str(path.relative_to(kept)),
        "obstacle": kind,
        "status": str(answer.status.value),
        "true_xc_end": end,
        "true_xc": truth,
        "x_c": float(answer.x_c),
        "error_m": float(answer.x_c) - truth,
        "interval": [low, high],
        "holds": bool(low <= truth <= high),
        "deflection_ratio": float(answer.diagnostics.get("deflection_ratio", math.nan)),
    }


def at_instant(recording: Any, true_xc: float, t_point: float | None) -> float:
    """The contact's abscissa (m) at ``t_point`` (s) from ``true_xc`` at the last sample in
    contact (module docstring)."""
    if IN_CONTACT_COLUMN not in recording.extra or t_point is None:
        return true_xc
    touching = np.flatnonzero(recording.extra[IN_CONTACT_COLUMN] > 0.5)
    here = tracked_contact(recording, t_point)
    if here is None or not touching.size:
        return true_xc
    last = tracked_contact(recording, float(recording.t[touching[-1]]))
    k = int(np.argmin(np.abs(recording.t - t_point)))
    along = motor_frame(*recording.theta[k])[0]
    return float(true_xc - (last - here) @ along)


def summarise(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """Coverage and errors of the ``ok`` answers with an interval."""
    scored = [
        r
        for r in rows
        if r["status"] == "ok" and math.isfinite(r["interval"][0]) and math.isfinite(r["true_xc"])
    ]
    if not scored:
        return {"ok": 0}
    error = np.array([r["error_m"] for r in scored])
    sigma = np.array([(r["interval"][1] - r["interval"][0]) / (2 * Z_95) for r in scored])
    centred = error - np.median(error)
    return {
        "ok": len(scored),
        "holds": int(sum(r["holds"] for r in scored)),
        "coverage": float(np.mean([r["holds"] for r in scored])),
        "error_median_m": float(np.median(error)),
        "error_robust_std_m": float(1.4826 * np.median(np.abs(centred))),
        "interval_std_median_m": float(np.median(sigma)),
        "over_1cm": int(np.sum(np.abs(error) > 0.01)),
        "max_abs_error_m": float(np.max(np.abs(error))),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("kept", type=Path, nargs="+", help="directories of eval_explore.py --keep")
    parser.add_argument("--every", type=int, default=4, help="every N-th recording (N >= 1)")
    parser.add_argument(
        "--strategies", nargs="+", default=["grid", "next-best"], help="explorations to read"
    )
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args()
    if args.every < 1:
        parser.error("--every must be at least 1")
    # each directory's own preparation; every N-th of its recordings, in name order
    jobs = []
    for kept in args.kept:
        antenna = load_antenna(kept / "calibrated.toml")
        paths = sorted(
            path
            for strategy in args.strategies
            for path in kept.glob(f"scene*-{strategy}/recordings/*.csv")
        )
        jobs += [(path, kept, antenna) for path in paths[:: args.every]]
    rows = []
    for i, (path, kept, antenna) in enumerate(jobs):
        row = score(path, kept, antenna)
        rows.append(row | {"recording": f"{kept.name}/{row['recording']}"})
        print(f"\r{i + 1}/{len(jobs)} recordings", end="", flush=True)
    print()
    kinds = sorted({r["obstacle"] for r in rows})
    total = {"all": summarise(rows)}
    total |= {k: summarise([r for r in rows if r["obstacle"] == k]) for k in kinds}
    print(
        f"{'obstacle':10s} {'ok':>5s} {'holds':>6s} {'median err':>11s} {'robust std':>11s} "
        f"{'interval sd':>12s} {'>1 cm':>6s} {'max':>8s}"
    )
    for name, t in total.items():
        if t["ok"]:
            print(
                f"{name:10s} {t['ok']:5d} {100 * t['coverage']:5.0f}% "
                f"{1e3 * t['error_median_m']:8.2f} mm {1e3 * t['error_robust_std_m']:8.2f} mm "
                f"{1e3 * t['interval_std_median_m']:9.2f} mm {t['over_1cm']:6d} "
                f"{1e3 * t['max_abs_error_m']:5.1f} mm"
            )
    result = {
        "date": datetime.date.today().isoformat(),
        "settings": {
            "kept": [kept.name for kept in args.kept],
            "strategies": args.strategies,
            "every": args.every,
            "method": "fast",
        },
        "total": total,
        "rows": rows,
    }
    args.out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
