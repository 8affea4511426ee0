"""Benchmark: the default campaign end to end (Section 5.6 plus its noise sweep); target 60 s.

Usage::

    python benchmarks/bench_campaign.py [--workers N] [--spec FILE] [--keep DIR] [--note TEXT]
        [--out FILE]

Prints a table and writes ``benchmarks/results/campaign.json`` (or ``--out FILE``). The campaign
runs into a fresh temporary directory (or ``--keep DIR``, which must not hold a finished campaign),
so every run is simulated and estimated; the time is split into preparation (observer identification
on the device, then the T_e calibration of Section 5.1: 15 simulated recordings, inline), the runs
(wall clock, with the per-run times summed over workers: simulation, the estimation front end (once
per recording) and each method's conclusion) and the report. With a second device its preparation
(made the same way) is counted in the preparation and its calibration recorded apart.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

from sensing_antenna.campaign.parsing import load_campaign_spec
from sensing_antenna.campaign.report import build_report
from sensing_antenna.campaign.runner import run_campaign
from sensing_antenna.campaign.schema import CampaignSpec
from sensing_antenna.campaign.simulated import prepare_campaign
from sensing_antenna.campaign.store import Preparation, load_run_results

#: The target of the task: the default campaign in under 60 s on 2 cores.
TARGET_S = 60.0
RESULTS = Path(__file__).resolve().parent / "results" / "campaign.json"


def _stats(values: list[float]) -> dict[str, float]:
    if not values:
        return {"n": 0}
    return {
        "n": len(values),
        "total_s": sum(values),
        "mean_s": statistics.fmean(values),
        "median_s": statistics.median(values),
        "max_s": max(values),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=None, help="default: all cores")
    parser.add_argument("--spec", default=None, help="campaign TOML (default: paper-2021)")
    parser.add_argument("--keep", type=Path, default=None, help="campaign directory to keep")
    parser.add_argument(
        "--note", default="", help="what else ran on the machine meanwhile, kept in the results"
    )
    parser.add_argument("--out", type=Path, default=RESULTS, help="results file (JSON)")
    args = parser.parse_args()

    spec = load_campaign_spec(args.spec)
    workers = args.workers or os.cpu_count() or 1
    with tempfile.TemporaryDirectory(prefix="bench-campaign-") as tmp:
        out = args.keep or Path(tmp)
        prepared: dict[str, float] = {}
        second: dict[str, float] = {}

        def timed_prepare(s: CampaignSpec) -> Preparation:
            begin = time.perf_counter()
            preparation = prepare_campaign(s)
            prepared["s"] = prepared.get("s", 0.0) + time.perf_counter() - begin
            # the second device's preparation (a spec with one) is recorded apart
            record = second if s is not spec else prepared
            if preparation.calibration is not None:
                record["t_e"] = preparation.calibration.t_e
                record["t_e_std_error"] = preparation.calibration.t_e_std_error
                record["device_t"] = preparation.device.link.theoretical_t
            return preparation

        start = time.perf_counter()
        outcome = run_campaign(
            spec, out, workers=workers, prepare_antenna=timed_prepare, progress=False
        )
        runs_done = time.perf_counter()
        build_report(out)
        end = time.perf_counter()
        results = list(load_run_results(out, spec.methods).values())

    ok = [r for r in results if r.status == "ok"]
    simulate = [r.rows[0].simulate_s for r in ok]
    front_end = [r.rows[0].front_end_s for r in ok]
    # a method's own time: its estimate_s less the front end's, which it shares with the others
    per_method: dict[str, list[float]] = {}
    for r in ok:
        for row in r.rows:
            per_method.setdefault(row.method, []).append(row.estimate_s - row.front_end_s)
    prepare_s = prepared.get("s", 0.0)
    record = {
        "campaign": spec.name,
        "n_runs": outcome.n_runs,
        "n_executed": outcome.n_executed,
        "n_failed": outcome.n_failed,
        "workers": workers,
        "cpu_count": os.cpu_count(),
        "python": platform.python_version(),
        "wall_s": end - start,
        "prepare_s": prepare_s,
        "calibration": {k: v for k, v in prepared.items() if k != "s"},
        "second_device_calibration": second,
        "n_second_device_runs": spec.n_second_device_runs,
        "n_calibration_recordings": spec.calibration.n_recordings
        if spec.calibration.enabled
        else 0,
        "runs_wall_s": runs_done - start - prepare_s,
        "report_s": end - runs_done,
        "target_s": TARGET_S,
        "target_met": (end - start) < TARGET_S,
        "simulate": _stats(simulate),
        "front_end": _stats(front_end),
        "conclude": {method: _stats(values) for method, values in per_method.items()},
        # what else ran on the machine, as the one who measured says (--note)
        "note": args.note,
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")

    print(f"campaign {spec.name}: {outcome.n_runs} runs on {workers} workers")
    print(f"{'part':<28}{'seconds':>10}")
    print(f"{'total (wall)':<28}{record['wall_s']:>10.2f}")
    print(f"{'  prepare (id. + calib.)':<28}{prepare_s:>10.2f}")
    print(f"{'  runs (wall)':<28}{record['runs_wall_s']:>10.2f}")
    print(f"{'  report and figures':<28}{record['report_s']:>10.2f}")
    print(f"{'simulate, summed over runs':<28}{sum(simulate):>10.2f}")
    print(f"{'front end, summed':<28}{sum(front_end):>10.2f}")
    for method, values in per_method.items():
        print(f"{'conclude ' + method + ', summed':<28}{sum(values):>10.2f}")
    print(f"target < {TARGET_S:.0f} s: {'met' if record['target_met'] else 'NOT met'}")
    print(f"failed runs: {outcome.n_failed}")
    if "t_e" in prepared:
        print(f"T_e = {prepared['t_e']:.5f} (device T = {prepared['device_t']:.5f})")
    if "t_e" in second:
        print(f"second device: T_e = {second['t_e']:.5f} (device T = {second['device_t']:.5f})")
    print(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
