"""Speed and memory of ``simulate``: the target is a 3 s manoeuvre in under 0.3 s on one core,
with peak memory proportional to the recording.

Prints a table and writes ``benchmarks/results/simulator.json``. Run: ``python
benchmarks/bench_simulator.py``. The first call compiles (or loads from cache) the numba loop and
is reported separately. Peak memory is the largest Python allocation during one call
(``tracemalloc``, which sees numpy buffers), measured in separate runs from the timings because
tracing slows the Python parts down; numba's compiled code allocates through numpy and is traced.
"""

from __future__ import annotations

import json
import platform
import time
import tracemalloc
from pathlib import Path

from sensing_antenna.antenna import paper_antenna
from sensing_antenna.detection.push import PushCriterion
from sensing_antenna.simulator import Scenario, simulate
from sensing_antenna.simulator.scenario import LINK_MODELS

TARGET_S = 0.3
DURATION_S = 3.0
REPEATS = 3
CASES = (("free", None), ("azimuthal", 0.3), ("azimuthal", 0.8), ("vertical", 0.55))
#: Pushes of 0.28 rad past the first touch (31 to 33 % deflection at 0.5 and 0.9 m), the depth of
#: the deepest PyElastica reference recordings, timed for both link models.
DEEP_PUSH = 0.28
DEEP_CASES = (("azimuthal", 0.5), ("azimuthal", 0.9))


def _peak_bytes(scenario: Scenario) -> int:
    antenna = paper_antenna()
    tracemalloc.start()
    try:
        simulate(antenna, scenario)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return int(peak)


def main() -> None:
    antenna = paper_antenna()
    start = time.perf_counter()
    simulate(antenna, Scenario(case="azimuthal", contact_point=0.5, duration=0.5))
    warmup = time.perf_counter() - start
    rows = []
    simulate(
        antenna, Scenario(case="azimuthal", contact_point=0.5, duration=0.5, link_model="nonlinear")
    )
    runs = [(case, x_c, None, link_model) for link_model in LINK_MODELS for case, x_c in CASES]
    runs += [
        (case, x_c, DEEP_PUSH, link_model) for link_model in LINK_MODELS for case, x_c in DEEP_CASES
    ]
    for case, x_c, push, link_model in runs:
        criterion = None if push is None else PushCriterion(kind="rotation", threshold=push)
        times = []
        for seed in range(REPEATS):
            scenario = Scenario(
                case=case,
                contact_point=x_c,
                seed=seed,
                duration=DURATION_S,
                push=criterion,
                link_model=link_model,
            )
            begin = time.perf_counter()
            simulate(antenna, scenario)
            times.append(time.perf_counter() - begin)
        peaks = {
            f"peak_mib_{duration:g}s": _peak_bytes(
                Scenario(
                    case=case,
                    contact_point=x_c,
                    duration=duration,
                    push=criterion,
                    link_model=link_model,
                )
            )
            / 2**20
            for duration in (3.0, 6.0)
        }
        rows.append(
            {
                "case": case,
                "x_c": x_c,
                "push_rad": push,
                "link_model": link_model,
                "best_s": min(times),
                "mean_s": sum(times) / len(times),
                **peaks,
            }
        )
    print(f"first call (compile or cache load): {warmup:.2f} s")
    print(
        f"{'link':<10} {'case':<10} {'x_c (m)':>8} {'push':>5} {'best (s)':>9} {'mean (s)':>9}"
        f" {'peak 3 s (MiB)':>15} {'peak 6 s (MiB)':>15}   target < {TARGET_S} s per 3 s"
    )
    for row in rows:
        xc = "-" if row["x_c"] is None else f"{row['x_c']:.2f}"
        push = "dflt" if row["push_rad"] is None else f"{row['push_rad']:.2f}"
        print(
            f"{row['link_model']:<10} {row['case']:<10} {xc:>8} {push:>5}"
            f" {row['best_s']:>9.3f} {row['mean_s']:>9.3f}"
            f" {row['peak_mib_3s']:>15.2f} {row['peak_mib_6s']:>15.2f}"
        )
    result = {
        "benchmark": (
            "simulate, 3 s recording, default scenario (16 elements, 2 substeps), linear and"
            " nonlinear link, default push and 0.28 rad past the touch"
        ),
        "target_s": TARGET_S,
        "warmup_s": warmup,
        "runs": rows,
        "memory": "tracemalloc peak of one simulate() call, MiB, for 3 s and 6 s recordings",
        "machine": {"python": platform.python_version(), "processor": platform.processor()},
        "note": "measured on a shared 2-core machine under load from other work",
    }
    path = Path(__file__).parent / "results" / "simulator.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
