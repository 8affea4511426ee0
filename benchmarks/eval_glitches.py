"""What corrupted force/torque samples (a sensor bus's glitches) do to the estimates.

A measurement: simulated contacts of the paper antenna (the estimators given the device's own T),
each recorded once clean and then many times with a burst of corrupted samples: one channel of the
push's force, one of its torque, or all six, set to 5, 50 or 10^4 times the channel's largest clean
value, sign-flipped, or zeroed, for 1 to 30 samples in a row, at instants from the initial rest to
just before the paper method's t_e (2 s). The kind ``hold`` repeats the reading before the burst
instead (a sensor or driver that stalled and sent its last reading again), and ``drop`` takes the
samples out of the recording, every column with its time stamp (a bus that lost them). For each
burst length and method it counts the clean ``ok`` answers that stay ``ok`` within 2 mm of the
clean answer, move further while ``ok`` (more than 2 mm, more than 2 cm), or turn into another
status (with the statuses and the most common reasons), and how many answers name the samples they
put back or filled in.

Usage::

    python benchmarks/eval_glitches.py [--lengths 1 2 3 5 10 20 30] [--instants 8] [--workers 2]
        [--kinds x5 x50 x1e4 flip zero hold] [--max-gap N] [--json benchmarks/results/glitches.json]

``--kinds drop --max-gap N`` measures lost samples with the estimators' ``max_gap`` set to N;
``--kinds hold`` stalled readings (``glitches_hold.json``).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from machine import machine_info
from sensing_antenna.antenna import load_antenna
from sensing_antenna.estimation import EstimatorConfig, conclude, gather
from sensing_antenna.recording import Recording
from sensing_antenna.simulator import Scenario, simulate

METHODS = ("paper", "ratio", "two-frequency", "fast")
CONTACTS = (
    ("azimuthal", 0.30),
    ("azimuthal", 0.55),
    ("azimuthal", 0.80),
    ("azimuthal", 0.95),
    ("vertical", 0.40),
    ("vertical", 0.65),
    ("vertical", 0.90),
)
KINDS = ("x5", "x50", "x1e4", "flip", "zero")
DROP = "drop"
HOLD = "hold"
MOVED = 0.002  # m: an ok answer further than this from the clean one has moved
WRONG = 0.02  # m: ... and further than this is wrong
KEPT = 0.0005  # m: the results file keeps the estimates that moved further (or changed status)
RESULTS = Path(__file__).parent / "results" / "glitches.json"
RESULTS_DROP = RESULTS.with_name("glitches_drop.json")
RESULTS_HOLD = RESULTS.with_name("glitches_hold.json")


def corrupt(
    recording: Recording, start: int, length: int, channels: list[int], kind: str
) -> Recording:
    """``recording`` with samples ``start .. start + length - 1`` of ``channels`` corrupted
    (or, for ``kind`` ``drop``, those samples taken out)."""
    loads = np.hstack([recording.force, recording.torque])
    rows = slice(start, start + length)
    if kind == DROP:
        kept = np.ones(len(recording.t), dtype=bool)
        kept[rows] = False
        return Recording(
            t=recording.t[kept],
            theta=recording.theta[kept],
            force=recording.force[kept],
            torque=recording.torque[kept],
            metadata=dict(recording.metadata),
        )
    for c in channels:
        largest = float(np.max(np.abs(loads[:, c])))
        if kind == "flip":
            loads[rows, c] = -loads[rows, c]
        elif kind == "zero":
            loads[rows, c] = 0.0
        elif kind == HOLD:
            loads[rows, c] = loads[max(start - 1, 0), c]
        else:
            loads[rows, c] = float(kind[1:]) * largest
    return Recording(
        t=recording.t,
        theta=recording.theta,
        force=loads[:, :3],
        torque=loads[:, 3:],
        metadata=dict(recording.metadata),
    )


def _estimates(
    recording: Recording, model: Any, config: EstimatorConfig
) -> dict[str, tuple[str, float, str, int]]:
    """Per method: (status, x_c, reason, samples put back or filled in); an exception is the
    status ``error`` with its text, so one does not lose the rest of the measurement."""
    try:
        evidence = gather(recording, model, config)
    except Exception as exc:  # a bug to report, in every method's row
        return {method: ("error", math.nan, repr(exc), 0) for method in METHODS}
    out = {}
    for method in METHODS:
        try:
            result = conclude(evidence, method)
        except Exception as exc:
            out[method] = ("error", math.nan, repr(exc), 0)
            continue
        repaired = len(result.diagnostics.get("repaired_samples", []) or [])
        dropped = int((result.diagnostics.get("sampling") or {}).get("n_dropped", 0))
        out[method] = (
            result.status.value,
            float(result.x_c),
            result.reason or "",
            repaired or dropped,
        )
    return out


def run_contact(
    args: tuple[str, float, list[int], int, list[str], int | None],
) -> list[dict[str, Any]]:
    """Every glitch of one contact: one row per (glitch, method)."""
    case, x_c, lengths, instants, kinds, max_gap = args
    config = EstimatorConfig() if max_gap is None else EstimatorConfig(max_gap=max_gap)
    antenna = load_antenna("paper-2021")
    model = antenna.self_calibrated()
    seed = round(1000 * x_c) + (0 if case == "azimuthal" else 7)
    clean = simulate(antenna, Scenario(case=case, contact_point=x_c, seed=seed))
    clean = clean.without_ground_truth()
    reference = _estimates(clean, model, config)
    loads = np.hstack([clean.force, clean.torque])
    spread = np.ptp(loads, axis=0)
    groups = {
        "force": [int(np.argmax(spread[:3]))],
        "torque": [3 + int(np.argmax(spread[3:]))],
        "all": list(range(6)),
    }
    end = float(np.searchsorted(clean.t, 2.0))  # before the paper method's t_e (t_1 + 1 s)
    starts = np.linspace(0.2 / clean.sample_period, end - 12, instants).astype(int)
    rows = []
    for length in lengths:
        for group, channels in groups.items():
            for kind in kinds:
                if kind == DROP and group != "all":
                    continue  # a lost sample is lost on every channel
                for start in starts:
                    glitched = corrupt(clean, int(start), length, channels, kind)
                    for method, (status, x, reason, repaired) in _estimates(
                        glitched, model, config
                    ).items():
                        ref_status, ref_x, _, _ = reference[method]
                        rows.append(
                            {
                                "case": case,
                                "x_c": x_c,
                                "length": length,
                                "channels": group,
                                "kind": kind,
                                "t": float(clean.t[int(start)]),
                                "method": method,
                                "clean_status": ref_status,
                                "clean_x": ref_x,
                                "status": status,
                                "x": x,
                                "reason": reason,
                                "repaired": repaired,
                            }
                        )
    return rows


def _reason_key(reason: str) -> str:
    """A reason without its numbers, to count alike reasons together."""
    words = [
        w
        for w in reason.replace("(", " ").replace(")", " ").split()
        if not any(ch.isdigit() for ch in w)
    ]
    return " ".join(words[:10])


def summarise(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per (length, method), over the glitches of clean ``ok`` answers."""
    table = []
    for length in sorted({r["length"] for r in rows}):
        for method in METHODS:
            group = [
                r
                for r in rows
                if r["length"] == length and r["method"] == method and r["clean_status"] == "ok"
            ]
            ok = [r for r in group if r["status"] == "ok"]
            shift = [abs(r["x"] - r["clean_x"]) for r in ok]
            turned = [r for r in group if r["status"] != "ok"]
            table.append(
                {
                    "length": length,
                    "method": method,
                    "glitched": len(group),
                    "ok_same": sum(1 for s in shift if s <= MOVED),
                    "ok_moved": sum(1 for s in shift if not s <= MOVED),
                    "ok_wrong": sum(1 for s in shift if not s <= WRONG),
                    "ok_max_shift_mm": 1e3 * max(shift, default=0.0),
                    "not_ok": len(turned),
                    "statuses": dict(Counter(r["status"] for r in turned).most_common()),
                    "reasons": dict(
                        Counter(_reason_key(r["reason"]) for r in turned).most_common(5)
                    ),
                    "named_repairs": sum(1 for r in group if r["repaired"]),
                }
            )
    return table


def print_table(table: list[dict[str, Any]]) -> None:
    header = (
        f"{'len':>3} {'method':<14} {'glitched':>8} {'ok same':>7} {'ok >2mm':>7} "
        f"{'ok >2cm':>7} {'max mm':>8} {'not ok':>6} {'put back':>8}"
    )
    print(header)
    print("-" * len(header))
    for row in table:
        print(
            f"{row['length']:>3} {row['method']:<14} {row['glitched']:>8} {row['ok_same']:>7} "
            f"{row['ok_moved']:>7} {row['ok_wrong']:>7} {row['ok_max_shift_mm']:>8.1f} "
            f"{row['not_ok']:>6} {row['named_repairs']:>8}"
        )


def _changed(row: dict[str, Any]) -> bool:
    """Whether an estimate's status or x_c differs from the clean recording's (by ``KEPT``)."""
    return row["status"] != row["clean_status"] or not abs(row["x"] - row["clean_x"]) <= KEPT


def _short(value: Any) -> Any:
    """Floats to 7 significant digits; not finite as null."""
    if isinstance(value, float):
        return float(f"{value:.7g}") if math.isfinite(value) else None
    return value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--lengths", type=int, nargs="+", default=[1, 2, 3, 5, 10, 20, 30])
    parser.add_argument("--instants", type=int, default=8)
    parser.add_argument("--kinds", nargs="+", default=list(KINDS), choices=[*KINDS, HOLD, DROP])
    parser.add_argument("--max-gap", type=int, default=None)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument(
        "--json",
        type=Path,
        default=None,
        help=f"default {RESULTS.name}; {RESULTS_DROP.name} for --kinds drop, {RESULTS_HOLD.name} "
        "for --kinds hold",
    )
    parser.add_argument("--note", default="")
    args = parser.parse_args()
    if args.json is None:
        args.json = {(DROP,): RESULTS_DROP, (HOLD,): RESULTS_HOLD}.get(tuple(args.kinds), RESULTS)
    start = time.perf_counter()
    jobs = [
        (case, x_c, args.lengths, args.instants, args.kinds, args.max_gap) for case, x_c in CONTACTS
    ]
    rows: list[dict[str, Any]] = []
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        for (case, x_c), contact_rows in zip(CONTACTS, pool.map(run_contact, jobs), strict=True):
            rows.extend(contact_rows)
            print(f"  {case} {x_c:.2f} m: done ({time.perf_counter() - start:.0f} s)", flush=True)
    table = summarise(rows)
    print_table(table)
    for row in table:
        if row["not_ok"]:
            print(f"{row['length']:>3} {row['method']:<14} {row['statuses']}")
            for reason, count in row["reasons"].items():
                print(f"      {count:>4}  {reason}")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    fields = (
        "case",
        "x_c",
        "length",
        "channels",
        "kind",
        "t",
        "method",
        "clean_status",
        "clean_x",
        "status",
        "x",
        "repaired",
    )
    changed = [r for r in rows if _changed(r)]
    payload = {
        "note": args.note,
        "lengths": args.lengths,
        "instants": args.instants,
        "kinds": args.kinds,
        "max_gap": args.max_gap if args.max_gap is not None else EstimatorConfig().gap_limit(0.001),
        "machine": machine_info(),
        "seconds": time.perf_counter() - start,
        "moved_m": MOVED,
        "wrong_m": WRONG,
        "summary": table,
        "rows_kept": f"the {len(changed)} of {len(rows)} estimates whose status changed or "
        f"whose x_c moved by more than {1e3 * KEPT:g} mm",
        "row_fields": list(fields),
        "rows": [[_short(r[f]) for f in fields] for r in changed],
    }
    text = json.dumps({k: v for k, v in payload.items() if k != "rows"}, indent=1)
    lines = ",\n".join(json.dumps(row, allow_nan=False) for row in payload["rows"])
    args.json.write_text(text[:-2] + ',\n "rows": [\n' + lines + "\n ]\n}\n")
    print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
