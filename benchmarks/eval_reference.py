"""The four estimators on the reference recordings of an independent rod engine (PyElastica).

The recordings (``benchmarks/reference/rod/recordings``, made once by
``benchmarks/reference/rod/generate.py``; docs/simulator.md, "An independent reference") are read
as plain files: no rod engine is needed here. Two models of the antenna are given to the
estimators, as a lab would have them:

- ``calibrated``: T_e fitted by ``calibrate_from_recordings`` on a subset of the rod recordings
  (``CALIBRATION``) at their known contact points (``true_xc``); the estimates are made on the
  other recordings only;
- ``self``: ``Antenna.self_calibrated()``, the simulation-study shortcut (the paper link's own
  T at 0.1 %), on every recording.

Each estimate is scored against ``true_xc``, where the rod touched. Prints a table per model and
writes ``benchmarks/results/reference.json``.

Usage::

    python benchmarks/eval_reference.py [--json benchmarks/results/reference.json]
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from sensing_antenna import paper_antenna
from sensing_antenna.calibration.frequency import calibrate_from_recordings
from sensing_antenna.estimation import METHODS, estimate
from sensing_antenna.recording import read_recording

HERE = Path(__file__).resolve().parent
RECORDINGS = HERE / "reference" / "rod" / "recordings"
#: Recordings the ``calibrated`` model is fitted on (a lab's calibration set: known contacts at
#: a few points along the link, the default push).
CALIBRATION = ("xc040-push003", "xc060-push003", "xc080-push003")
#: An ``ok`` estimate further than this from the truth is a wrong answer given as right (m).
WRONG_OK = 0.02


def _number(text: str | None) -> float:
    try:
        return float(text) if text is not None else math.nan
    except ValueError:
        return math.nan


def _case(text: str | None) -> str:
    """The manoeuvre (``azimuthal`` or ``vertical``) from the recording's simulation record."""
    try:
        return str(json.loads(text or "{}").get("scenario", {}).get("case", "unknown"))
    except (ValueError, AttributeError):
        return "unknown"


def _point(text: str | None) -> np.ndarray:
    try:
        return np.asarray(json.loads(text), dtype=float) if text else np.full(3, np.nan)
    except ValueError:
        return np.full(3, np.nan)


def run() -> dict[str, Any]:
    paths = sorted(RECORDINGS.glob("*.csv"))
    recordings = {path.stem: read_recording(path) for path in paths}
    antenna = paper_antenna()
    subset = [name for name in CALIBRATION if name in recordings]
    calibration = calibrate_from_recordings(
        [recordings[name] for name in subset],
        antenna,
        [_number(recordings[name].metadata.get("true_xc")) for name in subset],
        sources=subset,
    )
    models = {
        "calibrated": (calibration.apply(antenna), [n for n in recordings if n not in subset]),
        "self": (antenna.self_calibrated(), list(recordings)),
    }
    rows: list[dict[str, Any]] = []
    for model_name, (model, names) in models.items():
        for name in names:
            recording = recordings[name]
            truth = _number(recording.metadata.get("true_xc"))
            ratio = _number(recording.metadata.get("true_deflection_ratio"))
            true_point = _point(recording.metadata.get("true_contact_point"))
            case = _case(recording.metadata.get("simulation"))
            blind = recording.without_ground_truth()
            for method in sorted(METHODS):
                result = estimate(blind, model, method=method)
                rows.append(
                    {
                        "model": model_name,
                        "recording": name,
                        "case": case,
                        "true_xc": truth,
                        "deflection_ratio": ratio,
                        "method": method,
                        "status": result.status.value,
                        "x_c": result.x_c,
                        "error": result.x_c - truth,
                        "ratio_estimate": result.ratio_estimate,
                        "ratio_error": result.ratio_estimate - truth,
                        "point_error": float(np.linalg.norm(result.contact_point - true_point)),
                        "interval": list(result.interval) if result.interval else None,
                        "interval_holds": (
                            result.interval[0] <= truth <= result.interval[1]
                            if result.interval
                            else None
                        ),
                        "reason": result.reason,
                    }
                )
    return {
        "recordings": str(RECORDINGS.relative_to(HERE.parent)),
        "calibration": {
            "recordings": subset,
            "t_e": calibration.t_e,
            "t_theoretical": calibration.t_theoretical,
            "relative_difference": calibration.relative_difference,
            "relative_scatter": calibration.relative_scatter,
        },
        "rows": rows,
        "summary": _summary(rows),
    }


def _summary(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    out = []
    for model in sorted({r["model"] for r in rows}):
        for case in sorted({r["case"] for r in rows}):
            for method in sorted({r["method"] for r in rows}):
                mine = [
                    r
                    for r in rows
                    if r["model"] == model and r["case"] == case and r["method"] == method
                ]
                if not mine:
                    continue
                ok = [r for r in mine if r["status"] == "ok"]
                errors = [abs(r["error"]) for r in ok if math.isfinite(r["error"])]
                held = [r["interval_holds"] for r in mine if r["interval_holds"] is not None]
                out.append(
                    {
                        "model": model,
                        "case": case,
                        "method": method,
                        "runs": len(mine),
                        "ok": len(ok),
                        "ok_wrong_over_2cm": sum(e > WRONG_OK for e in errors),
                        "ok_mean_abs_error": sum(errors) / len(errors) if errors else None,
                        "ok_max_abs_error": max(errors) if errors else None,
                        "interval_holds": f"{sum(held)}/{len(held)}" if held else None,
                        "statuses": {
                            s: sum(r["status"] == s for r in mine)
                            for s in sorted({r["status"] for r in mine})
                        },
                    }
                )
    return out


def _cm(value: float) -> str:
    return f"{100 * value:7.2f}" if math.isfinite(value) else "      -"


def print_table(result: dict[str, Any]) -> None:
    cal = result["calibration"]
    print(
        f"calibration on {', '.join(cal['recordings'])}: T_e {cal['t_e']:.6g},"
        f" {100 * cal['relative_difference']:+.2f} % from T,"
        f" scatter {100 * cal['relative_scatter']:.2f} %"
    )
    for model in ("calibrated", "self"):
        print(f"\nmodel: {model}")
        print(
            f"{'recording':22} {'true cm':>7} {'y/x':>5} {'method':13} {'status':16}"
            f" {'x_c cm':>7} {'err cm':>7}  interval cm"
        )
        for r in result["rows"]:
            if r["model"] != model:
                continue
            interval = (
                f"{100 * r['interval'][0]:.2f} to {100 * r['interval'][1]:.2f}"
                if r["interval"]
                else ""
            )
            print(
                f"{r['recording']:22} {_cm(r['true_xc'])} {r['deflection_ratio']:5.3f}"
                f" {r['method']:13} {r['status']:16} {_cm(r['x_c'])} {_cm(r['error'])}  {interval}"
            )
    print()
    for s in result["summary"]:
        mean, worst = s["ok_mean_abs_error"], s["ok_max_abs_error"]
        print(
            f"{s['model']:10} {s['case']:9} {s['method']:13} ok {s['ok']}/{s['runs']},"
            f" ok over 2 cm {s['ok_wrong_over_2cm']},"
            f" mean |err| of ok {'-' if mean is None else f'{100 * mean:.2f} cm'},"
            f" max {'-' if worst is None else f'{100 * worst:.2f} cm'},"
            f" intervals hold {s['interval_holds']}, {s['statuses']}"
        )


def _clean(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_clean(v) for v in value]
    return value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", default=str(HERE / "results" / "reference.json"))
    args = parser.parse_args()
    result = run()
    print_table(result)
    Path(args.json).write_text(json.dumps(_clean(result), indent=2) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
