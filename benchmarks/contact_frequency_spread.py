"""How far a gently pushed link rings off the pinned sensing curve, by how the contact holds it.

The evidence for the fast method's ``frequency_floor`` (docs/fast.md, "Posterior and floors"):
the paper antenna, its observer identified on two free sweeps (as ``antenna explore`` prepares
it, so that the push past the touch bends the link about 3 % of x_c), pushed with the
simulator's geometrically exact link against posts and balls of 3 mm to 3 cm radius with
friction coefficients 0, 0.3 and 0.6, at x_c = 0.35, 0.5, 0.6 and 0.9 m (one seed each). For
every contact that held to the end, against the sensing curve at the recording's ``true_xc``,
in per cent: omega_1 as the fast method reads it on the window it would answer from with the
sensing curve trusted to 0.1 % (``frequency_floor`` 0.001: windows 0.2 to 1 s after t_1,
while the contact settles), and as Estimator 1 reads it over the whole hold (the paper
method's spectrum). A reading more than 2 % off is another vibration (the link slid off the
obstacle or bounced on it) and is counted apart. A calibration absorbs its own posts' offset,
one draw from the spread, and a contact elsewhere is another, so the two differ by sqrt(2)
times the spread's standard deviation.

Usage::

    python benchmarks/contact_frequency_spread.py [--out FILE]

Prints a line per contact and the summary; writes
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
from sensing_antenna.calibration.observer import identify_free_motion
from sensing_antenna.campaign.simulated import knowing_weight
from sensing_antenna.estimation import estimate, measure_omega1
from sensing_antenna.estimation.methods.fast import FastConfig, FastMethod
from sensing_antenna.simulator import Scenario, simulate

RESULTS = Path(__file__).resolve().parent / "results" / "contact_frequency_spread.json"
CONTACTS = (0.35, 0.5, 0.6, 0.9)
OBSTACLES = ("post", "ball")
FRICTIONS = (0.0, 0.3, 0.6)
RADII = (0.003, 0.01, 0.03)
SEED = 11
#: The fast method trusting the sensing curve to 0.1 %, as it did before its floor allowed for
#: how the contact holds the link: the windows it then answers from.
TRUSTING = FastMethod(FastConfig(frequency_floor=0.001))
#: A reading farther than this off the curve (per cent) is another vibration.
OTHER_VIBRATION = 2.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args()
    device = paper_antenna()
    free = [
        simulate(device, Scenario(case=case, seed=900 + k, duration=4.0, link_model="nonlinear"))
        for k, case in enumerate(("free", "free-vertical"))
    ]
    fit = identify_free_motion([run.without_ground_truth() for run in free], device)
    model = fit.apply(device.self_calibrated())
    pushing = knowing_weight(device, model)
    curve = SensingCurve.from_link(device.link)
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
                    }
                    rows.append(row)
                    print(
                        f"x_c {x_c:.2f} {obstacle:4s} mu {friction:.1f} R {1000 * radius:4.0f} mm:"
                        f" fast {early:+7.2f} % (window {fast.t_e - fast.t_1:.2f} s), hold"
                        f" {offset:+7.2f} % {'held' if held else 'left the obstacle'}",
                        flush=True,
                    )
    summary: dict[str, Any] = {"contacts": len(rows)}
    for key, name in (("fast_offset_percent", "fast"), ("offset_percent", "hold")):
        read = np.array([r[key] for r in rows if r["held"] and r[key] is not None])
        kept = read[np.abs(read) < OTHER_VIBRATION]
        spread = float(kept.std(ddof=1))
        summary[name] = {
            "held": int(read.size),
            "other_vibration": int(read.size - kept.size),
            "mean_percent": float(kept.mean()),
            "std_percent": spread,
            "min_percent": float(kept.min()),
            "max_percent": float(kept.max()),
            "calibration_difference_percent": math.sqrt(2.0) * spread,
        }
        print(
            f"{name}: {read.size} of {len(rows)} contacts held, {read.size - kept.size} read "
            f"another vibration; offset mean {kept.mean():+.2f} %, standard deviation "
            f"{spread:.2f} % ({kept.min():+.2f} to {kept.max():+.2f} %); against a "
            f"calibration's: sqrt(2) x {spread:.2f} = {math.sqrt(2.0) * spread:.2f} %"
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
