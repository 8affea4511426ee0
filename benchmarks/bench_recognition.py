"""CPU time of one recognition of an exploration's map, against the time the device sweeps.

The next-best strategy recognises the points so far before every
``exploration.run.RECOGNITION_EVERY``-th manoeuvre, and the head waits for it. The target is a
recognition within the simulated sweeping time of RECOGNITION_EVERY manoeuvres (their mean over
the explorations measured here): the wait then costs at most as much as those sweeps, and a
recognition run beside them would not hold the head up at all. The maps timed are the grid's
final ones (every manoeuvre of the budget), larger than any the planner recognises on the way,
and the planner's own surface fit and choice of sweep come on top.

The maps are those of ``eval_explore.py``'s scenes (one object each, the same drawing, seed and
three bases), each explored here with the grid strategy and the fast method on the prepared
device (preparation and explorations not timed; about a minute each). Each map's recognition is
what the exploration ends with: every ``ok`` point with its link's line, the links the sweeps
swept untouched and those that touched (``exploration.run.swept_links``), every class fitted.
It runs ``--repeat`` times and the smallest process time counts, since the machine is shared.
One BLAS thread unless ``OMP_NUM_THREADS`` says otherwise (set before numpy loads).

Prints each map's contacts, points and CPU time and the median against the target; writes
``benchmarks/results/recognition_cpu.json`` (with each map's class named, which must be the one
the exploration's own map named).

Usage::

    python benchmarks/bench_recognition.py                  # scenes 0 to 5, one per class
    python benchmarks/bench_recognition.py --scenes 5 11 --repeat 2 --out /tmp/rec.json
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # one BLAS thread, set before numpy loads

import argparse  # noqa: E402
import datetime  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

from eval_explore import make_scene  # noqa: E402
from machine import machine_info  # noqa: E402
from sensing_antenna import paper_antenna  # noqa: E402
from sensing_antenna.antenna import antenna_to_toml  # noqa: E402
from sensing_antenna.cli.arguments import integer  # noqa: E402
from sensing_antenna.exploration import ExploreSettings, explore, prepare_device  # noqa: E402
from sensing_antenna.exploration.run import RECOGNITION_EVERY, swept_links  # noqa: E402
from sensing_antenna.exploration.store import CALIBRATED_FILE  # noqa: E402
from sensing_antenna.mapping import select_points  # noqa: E402
from sensing_antenna.mapping.contact_map import recognise_points  # noqa: E402
from sensing_antenna.scene import LinkShape  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "recognition_cpu.json"
#: Grid sweeps per base in each direction, as in eval_explore.py
SWEEPS = 4


def explored(index: int, seed: int, calibrated: Path, workdir: Path) -> dict[str, Any]:
    """Scene ``index`` explored with the grid: its class, the map's points and swept links,
    the class its map named (None: too few points) and the simulated sweeping time per
    manoeuvre (s)."""
    device = paper_antenna()
    scene, info = make_scene(index, seed, SWEEPS, LinkShape(device.link))
    out = workdir / scene.name
    out.mkdir(parents=True)
    (out / CALIBRATED_FILE).write_text(calibrated.read_text())
    result = explore(scene, device, out, ExploreSettings("fast", "grid", seed=seed))
    manoeuvres = result.manoeuvres
    recognition = result.contact_map.recognition
    return {
        "class": info["class"],
        "explore_named": _named(recognition),
        "points": [m.point for m in manoeuvres if m.point is not None],
        "swept": swept_links(manoeuvres, scene, result.antenna, out),
        "include_uncertain": result.settings.include_uncertain,
        "sweep_s": result.summary()["sweep_time_s"] / max(len(manoeuvres), 1),
    }


def _named(recognition: Any) -> str | None:
    """The class a recognition names, ``undecided``, or None without one."""
    if recognition is None:
        return None
    return str(recognition.named.name) if recognition.named is not None else "undecided"


def recognition_cpu(case: dict[str, Any], repeat: int) -> tuple[float, str | None]:
    """(smallest process time of ``repeat`` recognitions of the map (s), the class named)."""
    best, named = math.inf, None
    for _ in range(repeat):
        start = time.process_time()
        recognition = recognise_points(
            case["points"], case["include_uncertain"], swept=case["swept"]
        )
        best = min(best, time.process_time() - start)
        named = _named(recognition)
    return best, named


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", type=integer(0), default=list(range(6)))
    parser.add_argument("--seed", type=integer(0), default=0)
    parser.add_argument("--repeat", type=integer(1), default=1, help="recognitions per map")
    parser.add_argument("--out", type=Path, default=RESULTS, help="JSON output")
    args = parser.parse_args()
    rows: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory(prefix="bench-recognition-") as folder:
        workdir = Path(folder)
        print("preparing the device (observer, T_e)", flush=True)
        prepared = prepare_device(paper_antenna(), workdir / "calibration")
        calibrated = workdir / CALIBRATED_FILE
        calibrated.write_text(antenna_to_toml(prepared))
        for index in dict.fromkeys(args.scenes):  # each scene once
            start = time.perf_counter()
            case = explored(index, args.seed, calibrated, workdir)
            took = time.perf_counter() - start
            used = len(select_points(case["points"], case["include_uncertain"]))
            cpu, named = recognition_cpu(case, args.repeat)
            row = {
                "scene": index,
                "class": case["class"],
                "contacts": len(case["points"]),
                "used": used,
                "cpu_s": cpu,
                "named": named,
                "explore_named": case["explore_named"],
                "sweep_s": case["sweep_s"],
            }
            rows.append(row)
            print(
                f"scene {index:3d} {case['class']:9s} {len(case['points']):3d} contacts "
                f"({used:2d} ok; explored in {took:.0f} s): recognition {cpu:6.1f} s CPU "
                f"-> {named}",
                flush=True,
            )
    timed = [r["cpu_s"] for r in rows if r["named"] is not None]
    target = RECOGNITION_EVERY * statistics.fmean(r["sweep_s"] for r in rows)
    median = statistics.median(timed) if timed else None
    met = None if median is None else bool(median <= target)
    if median is None:
        print("\nno map had enough points to recognise: nothing timed")
    else:
        print(
            f"\nrecognition CPU per map (s, smallest of {args.repeat}): median {median:.1f}, "
            f"largest {max(timed):.1f}, over {len(timed)} maps; target {target:.1f} "
            f"({RECOGNITION_EVERY} manoeuvres' sweeping time): {'met' if met else 'not met'}"
        )
    differ = [r["scene"] for r in rows if r["named"] != r["explore_named"]]
    if differ:
        print(f"scenes {differ}: named otherwise than by the exploration's own map")
    record = {
        "date": datetime.date.today().isoformat(),
        "machine": machine_info(),
        "omp_num_threads": os.environ.get("OMP_NUM_THREADS"),
        "seed": args.seed,
        "repeat": args.repeat,
        "recognition_every": RECOGNITION_EVERY,
        "target_s": target,
        "median_cpu_s": median,
        "met": met,
        "maps": rows,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=1) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
