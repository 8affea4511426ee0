"""How far a gently pushed link rings off its calibrated sensing curve, by how the contact holds it.

The evidence for the fast method's ``frequency_floor`` (docs/fast.md, "Posterior and floors"):
the paper antenna prepared as ``antenna explore`` prepares it (``prepare_device``: the observer
identified on two free sweeps, so that the push past the touch bends the link about 3 % of
x_c, then T_e calibrated on five smooth posts), pushed with the simulator's geometrically exact link
against posts and balls of 3 mm and 3 cm radius with friction coefficients 0, 0.3 and 0.6, at
x_c = 0.30 to 0.90 m every 5 cm (one seed each). For every contact that held to the end,
against the calibrated sensing curve at the recording's ``true_xc``, in per cent: omega_1 as
the fast method reads it on the window it answers ``ok`` from with the curve trusted to 0.1 %
(``frequency_floor`` 0.001: windows 0.2 to 1 s after t_1, while the contact settles; a wider
floor answers from later windows, which lie nearer), and as Estimator 1 reads it over the
whole hold (the paper method's spectrum, which the calibration reads). A reading more than
2 % off is another vibration (the link slid off the obstacle or bounced on it) and is counted
apart. The root mean square of the fast method's offsets is the model error its floor must
cover: the calibration's own error (one draw: the five posts' mean) is part of it.

Usage::

    python benchmarks/contact_frequency_spread.py [--out FILE]

Prints a line per contact and the summary (mean, standard deviation and root mean square of the
offsets, the root mean square by range of x_c, the early window's offset from the same
contact's hold by window length, the hold's mean by friction coefficient); writes
``benchmarks/results/contact_frequency_spread.json``.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from sensing_antenna import paper_antenna
from sensing_antenna.beam.sensing import SensingCurve
from sensing_antenna.campaign.simulated import knowing_weight
from sensing_antenna.estimation import estimate, measure_omega1
from sensing_antenna.estimation.methods.fast import FastConfig, FastMethod
from sensing_antenna.exploration.run import prepare_device
from sensing_antenna.simulator import Scenario, simulate

RESULTS = Path(__file__).resolve().parent / "results" / "contact_frequency_spread.json"
CONTACTS = tuple(round(0.30 + 0.05 * k, 2) for k in range(13))
OBSTACLES = ("post", "ball")
FRICTIONS = (0.0, 0.3, 0.6)
RADII = (0.003, 0.03)
SEED = 11
#: The fast method trusting the sensing curve to 0.1 %, as it did before its floor allowed for
#: how the contact holds the link: the windows it then answers from.
TRUSTING = FastMethod(FastConfig(frequency_floor=0.001))
#: A reading farther than this off the curve (per cent) is another vibration.
OTHER_VIBRATION = 2.0
#: Ranges of x_c (m) summarised apart: near the root, the middle, the top of the curve.
BANDS = ((0.30, 0.45), (0.50, 0.65), (0.70, 0.90))
#: Ranges of the answering window's length after t_1 (s) summarised apart.
WINDOWS = ((0.0, 0.35), (0.35, 0.5), (0.5, 0.7), (0.7, 1.01))


def on_curve(row: dict[str, Any], key: str) -> bool:
    """Whether the contact held and its reading ``key`` is the fundamental (not another
    vibration, not missing)."""
    value = row[key]
    return bool(row["held"]) and value is not None and abs(value) < OTHER_VIBRATION


def rms_summary(values: list[float]) -> dict[str, Any]:
    """Count and root mean square (per cent; None for no value) of ``values``."""
    read = np.array(values, dtype=float)
    return {
        "n": int(read.size),
        "rms_percent": float(np.sqrt(np.mean(read**2))) if read.size else None,
    }


def settling(rows: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Root mean square (per cent) of the early window's offset from the same contact's
    whole-hold offset, by the window's length (s): the part of the spread the settling
    contact adds, which a longer window averages away."""
    both = [
        r
        for r in rows
        if r["fast_status"] == "ok"
        and on_curve(r, "fast_offset_percent")
        and on_curve(r, "offset_percent")
    ]
    return {
        f"{low:.2f}-{high:.2f}": rms_summary(
            [
                r["fast_offset_percent"] - r["offset_percent"]
                for r in both
                if low <= r["fast_window_s"] < high
            ]
        )
        for low, high in WINDOWS
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args()
    device = paper_antenna()
    model = prepare_device(device)
    pushing = knowing_weight(device, model)
    curve = SensingCurve.from_link(model.link)
    rows: list[dict[str, Any]] = []
    for x_c in CONTACTS:
        for obstacle in OBSTACLES:
            for friction in FRICTIONS:
                for radius in RADII:
                    scenario = Scenario(
                        case="azimuthal",
                        contact_point=x_c,
                        seed=SEED,
                        link_model="nonlinear",
                        obstacle=obstacle,  # type: ignore[arg-type]
                        obstacle_radius=radius,
                        friction_coefficient=friction,
                    )
                    recording = simulate(pushing, scenario)
                    truth = float(recording.metadata["true_xc"])
                    held = recording.metadata["true_in_contact_at_end"] == "true"
                    blind = recording.without_ground_truth()
                    reference = float(curve.omega1(truth))
                    offset = 100.0 * (measure_omega1(blind, model).omega1 / reference - 1.0)
                    fast = estimate(blind, model, TRUSTING)
                    early = 100.0 * (fast.omega1 / reference - 1.0)
                    row = {
                        "x_c": x_c,
                        "obstacle": obstacle,
                        "friction": friction,
                        "radius_m": radius,
                        "true_xc": truth,
                        "held": held,
                        "deflection_ratio": float(recording.metadata["true_deflection_ratio"]),
                        "offset_percent": offset if math.isfinite(offset) else None,
                        "fast_offset_percent": early if math.isfinite(early) else None,
                        "fast_window_s": fast.t_e - fast.t_1,
                        "fast_status": fast.status.value,
                    }
                    rows.append(row)
                    print(
                        f"x_c {x_c:.2f} {obstacle:4s} mu {friction:.1f} R {1000 * radius:4.0f} mm:"
                        f" fast {early:+7.2f} % ({fast.status.value}, window"
                        f" {fast.t_e - fast.t_1:.2f} s), hold"
                        f" {offset:+7.2f} % {'held' if held else 'left the obstacle'}",
                        flush=True,
                    )
    summary: dict[str, Any] = {"contacts": len(rows)}
    for key, name in (("fast_offset_percent", "fast"), ("offset_percent", "hold")):
        read_at = [
            r
            for r in rows
            if r["held"] and r[key] is not None and (name == "hold" or r["fast_status"] == "ok")
        ]
        kept = [r for r in read_at if abs(r[key]) < OTHER_VIBRATION]
        read = np.array([r[key] for r in kept])
        rms = float(np.sqrt(np.mean(read**2)))
        bands = {
            f"{low:.2f}-{high:.2f}": rms_summary([r[key] for r in kept if low <= r["x_c"] <= high])
            for low, high in BANDS
        }
        summary[name] = {
            "held": len(read_at),
            "other_vibration": len(read_at) - len(kept),
            "mean_percent": float(read.mean()),
            "std_percent": float(read.std(ddof=1)),
            "rms_percent": rms,
            "min_percent": float(read.min()),
            "max_percent": float(read.max()),
            "rms_by_contact_point": bands,
        }
        print(
            f"{name}: {len(read_at)} of {len(rows)} contacts held (fast: answered ok), "
            f"{len(read_at) - len(kept)} read "
            f"another vibration; offset mean {read.mean():+.2f} %, standard deviation "
            f"{read.std(ddof=1):.2f} % ({read.min():+.2f} to {read.max():+.2f} %), root mean "
            f"square {rms:.2f} %; by x_c: "
            + ", ".join(
                f"{band} m {v['rms_percent']:.2f} % ({v['n']})"
                for band, v in bands.items()
                if v["n"]
            )
        )
    summary["settling"] = settling(rows)
    summary["hold_by_friction"] = {
        f"{mu:g}": float(
            np.mean(
                [
                    r["offset_percent"]
                    for r in rows
                    if r["friction"] == mu and on_curve(r, "offset_percent")
                ]
            )
        )
        for mu in FRICTIONS
    }
    print(
        "early window against the same contact's hold, root mean square by window length: "
        + ", ".join(
            f"{band} s {v['rms_percent']:.2f} % ({v['n']})"
            for band, v in summary["settling"].items()
            if v["n"]
        )
    )
    print(
        "hold's mean offset by friction coefficient: "
        + ", ".join(f"{mu}: {v:+.3f} %" for mu, v in summary["hold_by_friction"].items())
    )
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(
        json.dumps(
            {"date": datetime.date.today().isoformat(), "summary": summary, "contacts": rows},
            indent=1,
        )
        + "\n"
    )
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
