"""Speed of ``simulate``: a 3 s recording should take well under 0.5 s.

Prints a table and writes ``benchmarks/results/simulator.json``. Run: ``python
benchmarks/bench_simulator.py``. The first call compiles (or loads from cache) the numba loop and
is reported separately.
"""

from __future__ import annotations

import json
import platform
import time
from pathlib import Path

from sensing_antenna.antenna import paper_antenna
from sensing_antenna.simulator import Scenario, simulate

TARGET_S = 0.5
REPEATS = 3


def main() -> None:
    antenna = paper_antenna()
    start = time.perf_counter()
    simulate(antenna, Scenario(case="azimuthal", contact_point=0.5, duration=0.5))
    warmup = time.perf_counter() - start
    rows = []
    for case, x_c in (("free", None), ("azimuthal", 0.3), ("azimuthal", 0.8), ("vertical", 0.55)):
        times = []
        for seed in range(REPEATS):
            scenario = Scenario(case=case, contact_point=x_c, seed=seed, duration=3.0)
            begin = time.perf_counter()
            simulate(antenna, scenario)
            times.append(time.perf_counter() - begin)
        rows.append(
            {"case": case, "x_c": x_c, "best_s": min(times), "mean_s": sum(times) / len(times)}
        )
    print(f"first call (compile or cache load): {warmup:.2f} s")
    print(f"{'case':<10} {'x_c (m)':>8} {'best (s)':>9} {'mean (s)':>9}   target < {TARGET_S} s")
    for row in rows:
        xc = "-" if row["x_c"] is None else f"{row['x_c']:.2f}"
        print(f"{row['case']:<10} {xc:>8} {row['best_s']:>9.3f} {row['mean_s']:>9.3f}")
    result = {
        "benchmark": "simulate, 3 s recording, default scenario (16 elements, 2 substeps)",
        "target_s": TARGET_S,
        "warmup_s": warmup,
        "runs": rows,
        "machine": {"python": platform.python_version(), "processor": platform.processor()},
        "note": "measured on a shared 2-core machine under load from other work",
    }
    path = Path(__file__).parent / "results" / "simulator.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
