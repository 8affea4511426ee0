"""CPU time per recording of each estimation method, against the fast method's target of 0.15 s.

Two fixed sets of simulated recordings, generated here from fixed seeds:

- ``paper``: the built-in paper antenna for the simulator and the estimators, both cases,
  x_c = 0.30, 0.45, 0.60, 0.70, 0.78, 0.90, 0.98 m, noise scales 0.5, 1 and 2 (42 recordings);
- ``device``: the default campaign's calibrated nominal device (its second device, without
  the realistic profile's imperfections; its preparation runs first: observer
  identification and T_e calibration on the simulated device), the first repeat of every main
  run (both cases, 15 contact points: 30 recordings), each estimated with the run's model.

Each recording is estimated by every method (``estimate``, front end included) ``--repeat``
times; the smallest process time counts, since the machine is shared. One BLAS thread unless
``OMP_NUM_THREADS`` says otherwise (set before numpy loads). One estimate of each method runs
first, so loading (or compiling) the fast method's kernels is not counted.

Prints the mean, median and largest CPU time per recording of each method on each set and
writes ``benchmarks/results/fast_cpu.json`` (every recording's time and status).

Usage::

    python benchmarks/bench_fast_cpu.py                   # both sets, 3 repeats (about 2 min)
    python benchmarks/bench_fast_cpu.py --sets paper --repeat 1 --out /tmp/cpu.json
    python benchmarks/bench_fast_cpu.py --methods fast --set max_modes=2 --out /tmp/cpu.json
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
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

from fast_settings import add_fast_arguments, fast_settings  # noqa: E402
from machine import machine_info  # noqa: E402
from sensing_antenna.antenna import Antenna, paper_antenna  # noqa: E402
from sensing_antenna.estimation import estimate  # noqa: E402
from sensing_antenna.estimation.methods import EstimationMethod  # noqa: E402
from sensing_antenna.estimation.methods.fast import FastMethod  # noqa: E402
from sensing_antenna.recording import Recording  # noqa: E402
from sensing_antenna.simulator import Scenario, simulate  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "fast_cpu.json"
#: The fast method's target: CPU per recording (s)
TARGET_S = 0.15
METHODS = ("paper", "ratio", "two-frequency", "fast")
PAPER_POINTS = (0.30, 0.45, 0.60, 0.70, 0.78, 0.90, 0.98)
PAPER_NOISE = (0.5, 1.0, 2.0)
#: Seed of the first paper-antenna recording; the others follow in the order of the set
PAPER_SEED = 700

#: (name, recording, the antenna the estimators use) of every recording of a set
Item = tuple[str, Recording, Antenna]


def paper_set() -> list[Item]:
    """The paper-antenna recordings: both cases, :data:`PAPER_POINTS`, :data:`PAPER_NOISE`; the
    estimators get the device's own T as a calibration gives it (the fast method's floor as its
    scatter)."""
    antenna = paper_antenna()
    model = antenna.self_calibrated()
    items = []
    for case in ("azimuthal", "vertical"):
        for x_c in PAPER_POINTS:
            for noise in PAPER_NOISE:
                scenario = Scenario(
                    case=case, contact_point=x_c, seed=PAPER_SEED + len(items), noise_scale=noise
                )
                recording = simulate(antenna, scenario).without_ground_truth()
                items.append((f"{case}-{x_c:.2f}-n{noise:g}", recording, model))
    return items


def device_set() -> list[Item]:
    """The first repeat of the default campaign's main runs, on its calibrated device."""
    from sensing_antenna.campaign.parsing import load_campaign_spec
    from sensing_antenna.campaign.runs import expand_runs
    from sensing_antenna.campaign.simulated import make_scenario, prepare_campaign

    spec = load_campaign_spec(None)
    if spec.second_device.enabled:  # its nominal device: the one these figures are of
        spec = spec.second_device_spec()
    preparation = prepare_campaign(spec)
    items = []
    for run in expand_runs(spec, preparation.model, preparation.device):
        if run.repeat != 1 or "-n" in run.run_id:
            continue
        scenario = make_scenario(run.case, run.contact_point, run.seed, dict(run.scenario))
        device = run.device if run.device is not None else run.antenna
        recording = simulate(device, scenario).without_ground_truth()
        items.append((run.run_id, recording, run.antenna))
    return items


SETS: dict[str, Callable[[], list[Item]]] = {"paper": paper_set, "device": device_set}


def cpu_time(
    recording: Recording, antenna: Antenna, method: str | EstimationMethod, repeat: int
) -> tuple[float, str]:
    """(smallest process time of ``repeat`` estimates (s), the estimate's status)."""
    best, status = math.inf, ""
    for _ in range(repeat):
        start = time.process_time()
        result = estimate(recording, antenna, method)
        best = min(best, time.process_time() - start)
        status = result.status.value
    return best, status


def summary(times: list[float]) -> dict[str, float]:
    """Mean, median and largest of ``times`` (ms)."""
    return {
        "mean_ms": 1000 * statistics.fmean(times),
        "median_ms": 1000 * statistics.median(times),
        "max_ms": 1000 * max(times),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", nargs="+", choices=tuple(SETS), default=list(SETS))
    parser.add_argument("--methods", nargs="+", choices=METHODS, default=list(METHODS))
    parser.add_argument("--repeat", type=int, default=3, help="estimates per recording")
    add_fast_arguments(parser)
    parser.add_argument("--out", type=Path, default=RESULTS, help="JSON output")
    args = parser.parse_args()
    config, settings = fast_settings(args)
    methods: dict[str, str | EstimationMethod] = {
        name: FastMethod(config) if name == "fast" else name for name in args.methods
    }
    rows: list[dict[str, Any]] = []
    table: list[dict[str, Any]] = []
    for set_name in args.sets:
        start = time.perf_counter()
        items = SETS[set_name]()
        print(
            f"{set_name}: {len(items)} recordings simulated in {time.perf_counter() - start:.0f} s"
        )
        for name, method in methods.items():
            estimate(items[0][1], items[0][2], method)  # kernels loaded, tables built
            times = []
            for run_name, recording, antenna in items:
                cpu, status = cpu_time(recording, antenna, method, args.repeat)
                times.append(cpu)
                rows.append(
                    {
                        "set": set_name,
                        "recording": run_name,
                        "method": name,
                        "cpu_s": cpu,
                        "status": status,
                    }
                )
            table.append(
                {"set": set_name, "method": name, "recordings": len(items), **summary(times)}
            )
    print(
        f"\nCPU per recording (ms, smallest of {args.repeat}); target for fast: "
        f"{1000 * TARGET_S:.0f} ms"
    )
    print(f"{'set':7} {'method':14} {'runs':>4} {'mean':>7} {'median':>7} {'max':>7}")
    for row in table:
        print(
            f"{row['set']:7} {row['method']:14} {row['recordings']:4d} {row['mean_ms']:7.1f} "
            f"{row['median_ms']:7.1f} {row['max_ms']:7.1f}"
        )
    record = {
        "date": datetime.date.today().isoformat(),
        "machine": machine_info(),
        "omp_num_threads": os.environ.get("OMP_NUM_THREADS"),
        "repeat": args.repeat,
        "fast_settings": settings,
        "target_s": TARGET_S,
        "summary": table,
        "runs": rows,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=1) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
