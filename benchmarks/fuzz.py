"""The long fuzz run: thousands of inputs through the reader, the estimators, identify,
calibrate, antenna files, campaign specs, scene files and the command line.

The inputs and the judges are those of the test suite's fuzz tests (``tests/fuzz_inputs.py``):
hypothesis strategies draw the inputs, and each input's outcome is ``ok``, an estimate's status,
a one-line ``error``, or a finding (a traceback, a warning, an error of several lines, an ``ok``
outside (0, l] or from an input failing the plausibility layer's units check, a best guess off
the link, a command that ends other than with 0 or 2 and one line). Target: no finding.

Prints a table (per area, and per method for the estimators: inputs, then outcomes by kind),
the first findings of each kind, and writes ``benchmarks/results/fuzz.json`` with the date and
the machine.
Run: ``OMP_NUM_THREADS=1 python benchmarks/fuzz.py`` (10,000 inputs, about 7 minutes on one
core of a shared machine); ``--inputs N`` for another total, ``--seed S`` for other inputs,
``--areas reader,cli`` for some areas only.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # one core, set before numpy loads

import argparse  # noqa: E402
import collections  # noqa: E402
import datetime  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

from hypothesis import HealthCheck, Phase, given, seed, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from tqdm import tqdm  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import fuzz_inputs as fz  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "fuzz.json"

#: Share of the inputs each area gets: the cheap areas get many, the estimators (every method
#: on a 3.5 s recording) and the command line fewer.
SHARES = {
    "reader": 0.225,
    "antenna file": 0.125,
    "campaign spec": 0.125,
    "estimators": 0.2,
    "identify": 0.075,
    "calibrate": 0.075,
    "cli": 0.1,
    "scene file": 0.075,
}
#: Findings of each kind kept per area in the JSON (the first ones met).
KEPT_FINDINGS = 5


def areas(bases: fz.Bases, files: fz.CliFiles) -> dict[str, tuple[Any, Callable[[Any], Any]]]:
    """Each area's strategy and runner."""
    return {
        "reader": (fz.recording_texts(), fz.run_reader),
        "antenna file": (fz.antenna_files(), fz.run_antenna_file),
        "campaign spec": (fz.campaign_files(), fz.run_campaign_file),
        "estimators": (fz.perturbations(), lambda p: fz.run_estimators(bases, p)),
        "identify": (fz.identify_inputs(), lambda c: fz.run_identify(bases, c)),
        "calibrate": (fz.calibrate_inputs(), lambda c: fz.run_calibrate(bases, c)),
        "cli": (fz.cli_arguments(files.paths), lambda argv: fz.run_cli(argv, files.folder)),
        "scene file": (fz.scene_files(), fz.run_scene_file),
    }


def run_area(
    strategy: st.SearchStrategy[Any],
    runner: Callable[[Any], list[fz.Outcome]],
    n_inputs: int,
    seed_value: int,
    bar: tqdm,
) -> tuple[int, list[tuple[fz.Outcome, str]]]:
    """Up to ``n_inputs`` inputs drawn by hypothesis (fewer when it has drawn every input the
    strategy can make); returns the inputs tried and each outcome with its input's text."""
    seen: list[tuple[fz.Outcome, str]] = []
    tried = 0

    @seed(seed_value)
    @settings(
        max_examples=n_inputs,
        deadline=None,
        database=None,
        derandomize=False,
        phases=[Phase.generate],
        suppress_health_check=list(HealthCheck),
    )
    @given(strategy)
    def body(case: Any) -> None:
        nonlocal tried
        tried += 1
        bar.update(1)
        outcomes = runner(case)
        text = repr(case)
        seen.extend((outcome, text) for outcome in outcomes)

    body()
    return tried, seen


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--inputs", type=int, default=10_000, help="inputs in total")
    parser.add_argument("--seed", type=int, default=0, help="seed of the inputs")
    parser.add_argument(
        "--areas", default=",".join(SHARES), help="comma-separated areas (default: all)"
    )
    parser.add_argument("--out", type=Path, default=RESULTS, help="JSON to write")
    args = parser.parse_args()
    chosen = [name.strip() for name in args.areas.split(",") if name.strip()]
    unknown = sorted(set(chosen) - set(SHARES))
    if unknown:
        parser.error(f"--areas: unknown {', '.join(unknown)} (known: {', '.join(SHARES)})")
    total_share = sum(SHARES[name] for name in chosen)
    quota = {name: max(1, round(args.inputs * SHARES[name] / total_share)) for name in chosen}

    start = time.perf_counter()
    print("simulating the recordings the perturbations start from ...", flush=True)
    bases = fz.simulate_bases()
    rows: dict[tuple[str, str], collections.Counter[str]] = {}
    inputs: dict[str, int] = {}
    findings: dict[str, list[dict[str, str]]] = {}
    seconds: dict[str, float] = {}
    with tempfile.TemporaryDirectory(prefix="fuzz-cli-") as folder:
        files = fz.make_cli_files(bases, Path(folder))
        table = areas(bases, files)
        with tqdm(total=sum(quota.values()), unit="input", file=sys.stderr) as bar:
            for index, name in enumerate(chosen):
                bar.set_description(name)
                strategy, runner = table[name]
                began = time.perf_counter()
                tried, seen = run_area(strategy, runner, quota[name], args.seed + index, bar)
                seconds[name] = time.perf_counter() - began
                inputs[name] = tried
                for outcome, text in seen:
                    row = rows.setdefault((name, outcome.label), collections.Counter())
                    row[outcome.kind] += 1
                    if outcome.bad:
                        kept = findings.setdefault(name, [])
                        same = sum(1 for f in kept if f["kind"] == outcome.kind)
                        if same < KEPT_FINDINGS:
                            kept.append(
                                {
                                    "kind": outcome.kind,
                                    "label": outcome.label,
                                    "detail": outcome.detail,
                                    "input": text[:2000],
                                }
                            )
    wall = time.perf_counter() - start

    kinds_bad = sorted(fz.BAD_KINDS)
    print()
    header = f"{'area':<26}{'inputs':>7}{'ok':>7}{'error':>7}  {'statuses':<44}"
    header += "".join(f"{kind:>{max(len(kind), 6) + 2}}" for kind in kinds_bad)
    print(header)
    json_rows = []
    for (name, label), counter in rows.items():
        statuses = {
            kind: n
            for kind, n in sorted(counter.items())
            if kind not in fz.BAD_KINDS and kind not in (fz.OK, fz.ERROR)
        }
        area = f"{name} {label}".strip()
        line = f"{area:<26}{inputs[name]:>7}{counter[fz.OK]:>7}{counter[fz.ERROR]:>7}  "
        status_text = " ".join(f"{k}:{n}" for k, n in statuses.items()) or "-"
        line += f"{status_text:<44}"
        line += "".join(f"{counter[kind]:>{max(len(kind), 6) + 2}}" for kind in kinds_bad)
        print(line)
        json_rows.append(
            {
                "area": name,
                "method": label or None,
                "inputs": inputs[name],
                "ok": counter[fz.OK],
                "error": counter[fz.ERROR],
                "statuses": statuses,
                "findings": {kind: counter[kind] for kind in kinds_bad},
            }
        )
    n_inputs = sum(inputs.values())
    n_findings = sum(sum(r["findings"].values()) for r in json_rows)
    print(
        f"\n{n_inputs} inputs in {wall:.0f} s (seed {args.seed}); findings: {n_findings} (target 0)"
    )
    for name, kept in findings.items():
        for finding in kept:
            label = f" {finding['label']}" if finding["label"] else ""
            print(f"  {name}{label}: {finding['kind']}: {finding['detail'][:200]}")

    record = {
        "benchmark": "fuzz: inputs through every area, outcomes by kind",
        "date": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": {
            "python": platform.python_version(),
            "processor": platform.processor() or platform.machine(),
            "cpu_count": os.cpu_count(),
        },
        "seed": args.seed,
        "inputs_requested": args.inputs,
        "inputs": n_inputs,
        "findings": n_findings,
        "wall_s": wall,
        "seconds_per_area": seconds,
        "rows": json_rows,
        "first_findings": findings,
        "note": "measured on a shared 2-core machine under load from other work",
    }
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
