"""The fast method on a device changed after its calibration, with the estimators not told.

The default campaign's realistic device is identified and calibrated as the campaign does it
(``campaign.simulated.prepare_campaign``: observer, payload, T_e with an effective tip mass,
omega_1's and omega_2's scatters, the sensor's cross-talk). Then the device changes and is not
calibrated again: a clamp that gives more, a joint that softens, an obstacle softer or stiffer
than the calibration posts, glue at the tip. Each change is measured on contacts around the top
of the sensing curve, where the fast method's answers at the cap rest on omega_2, and beyond it.
Per change: the runs ``ok``, the largest error of an ``ok`` run, how many ``ok`` runs' intervals
hold the contact, and the same for the answers omega_2 narrowed (``second_mode_narrowing``).
The worst outcome is an ``ok`` run far off; every ``ok`` should stay within the method's 1 cm.

Usage::

    python benchmarks/eval_changed_device.py [--points 0.6 0.7 0.75 0.8 0.9] [--json FILE]

Prints a table and writes ``benchmarks/results/changed_device.json``.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from importlib.resources import files
from pathlib import Path
from typing import Any

from sensing_antenna.campaign.parsing import load_campaign_spec
from sensing_antenna.campaign.runs import with_device
from sensing_antenna.campaign.simulated import make_scenario, prepare_campaign
from sensing_antenna.estimation import estimate
from sensing_antenna.estimation.methods.fast import FastMethod
from sensing_antenna.simulator import simulate

RESULTS = Path(__file__).parent / "results" / "changed_device.json"
POINTS = (0.6, 0.65, 0.7, 0.72, 0.75, 0.77, 0.78, 0.8, 0.82, 0.85, 0.9, 0.95)
#: Seeds of the runs (their own, apart from the campaign's streams).
SEED = 5000

#: (label, DeviceImperfections fields replaced, Scenario fields replaced)
CHANGES: tuple[tuple[str, dict[str, float], dict[str, float]], ...] = (
    ("none", {}, {}),
    ("clamp 40 N m/rad", {"clamp_stiffness": 40.0}, {}),
    ("joint stiffness x 0.7", {"joint_stiffness_factor": 0.7}, {}),
    ("contact 3 kN/m", {}, {"contact_stiffness": 3000.0}),
    ("contact 30 kN/m", {}, {"contact_stiffness": 30000.0}),
    ("glue 0.3 g", {"tip_mass": 3e-4}, {}),
)


def run(points: tuple[float, ...]) -> dict[str, Any]:
    spec = load_campaign_spec(str(files("sensing_antenna.data") / "campaign-paper-2021.toml"))
    preparation = prepare_campaign(spec)
    model, device = preparation.model, preparation.device
    rows: list[dict[str, Any]] = []
    for label, fields, scenario in CHANGES:
        start = time.perf_counter()
        for case in ("azimuthal", "vertical"):
            for i, x_c in enumerate(points):
                seed = SEED + i + (100 if case == "vertical" else 0)
                extra = with_device(spec, spec.scenario, seed, device.link.length)
                built = extra["device"]
                changed = dict(fields)
                if "tip_mass" in changed:  # glue adds to what the device carries
                    changed["tip_mass"] += built.tip_mass
                extra["device"] = dataclasses.replace(built, **changed)
                extra.update(scenario)
                recording = simulate(device, make_scenario(case, x_c, seed, extra))
                true_xc = float(recording.metadata["true_xc"])
                result = estimate(recording.without_ground_truth(), model, FastMethod())
                low, high = result.interval if result.interval else (math.nan, math.nan)
                narrowing = result.diagnostics.get("second_mode_narrowing", {})
                rows.append(
                    {
                        "change": label,
                        "case": case,
                        "x_c": x_c,
                        "status": result.status.value,
                        "error_m": result.x_c - true_xc,
                        "width_m": high - low,
                        "covered": bool(low <= true_xc <= high),
                        "narrowed": "interval_before" in narrowing,
                    }
                )
        print(f"{label}: {time.perf_counter() - start:.0f} s", flush=True)
    return {
        "mode2_scatter": model.link.mode2_scatter,
        "calibration_scatter": model.link.calibration_scatter,
        "rows": rows,
    }


def summary(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    table = []
    for label, _, _ in CHANGES:
        mine = [r for r in rows if r["change"] == label]
        ok = [r for r in mine if r["status"] == "ok"]
        narrowed = [r for r in ok if r["narrowed"]]
        errors = [abs(r["error_m"]) for r in ok]
        table.append(
            {
                "change": label,
                "runs": len(mine),
                "ok": len(ok),
                "ok_max_error_m": max(errors) if errors else math.nan,
                "ok_over_1cm": sum(e > 0.01 for e in errors),
                "ok_covered": sum(r["covered"] for r in ok),
                "narrowed_ok": len(narrowed),
                "narrowed_covered": sum(r["covered"] for r in narrowed),
            }
        )
    return table


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=float, nargs="+", default=list(POINTS))
    parser.add_argument("--json", type=Path, default=RESULTS)
    args = parser.parse_args()
    result = run(tuple(args.points))
    table = summary(result["rows"])
    print(
        f"model: calibration_scatter {100 * (result['calibration_scatter'] or math.nan):.3f} %, "
        f"mode2_scatter {100 * (result['mode2_scatter'] or math.nan):.3f} %"
    )
    print(
        f"{'change':24} {'runs':>4} {'ok':>4} {'ok max (mm)':>11} {'ok > 1 cm':>9} "
        f"{'ok covered':>10} {'narrowed ok':>11} {'covered':>7}"
    )
    for t in table:
        print(
            f"{t['change']:24} {t['runs']:4d} {t['ok']:4d} {1000 * t['ok_max_error_m']:11.1f} "
            f"{t['ok_over_1cm']:9d} {t['ok_covered']:10d} {t['narrowed_ok']:11d} "
            f"{t['narrowed_covered']:7d}"
        )
    args.json.parent.mkdir(parents=True, exist_ok=True)
    data = {"date": time.strftime("%Y-%m-%d"), "summary": table, **result}
    args.json.write_text(json.dumps(data, indent=1, default=float) + "\n", encoding="utf-8")
    print(args.json)


if __name__ == "__main__":
    main()
