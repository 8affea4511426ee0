"""Speed targets of the beam model (one core).

Targets: a 1000-point sensing curve with 3 modes (``natural_frequencies``) under 50 ms, and one
inverse lookup (``SensingCurve.contact_points``) under 0.1 ms with 1e-6 relative accuracy.
Prints a table and writes ``benchmarks/results/beam.json``.
Run: ``python benchmarks/bench_beam.py``.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # one core, set before numpy loads

import json  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from sensing_antenna.antenna import load_antenna  # noqa: E402
from sensing_antenna.beam import SensingCurve, natural_frequencies  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results" / "beam.json"
CURVE_TARGET_S = 0.050
LOOKUP_TARGET_S = 1e-4
ACCURACY_TARGET = 1e-6


def best_time(func: Callable[[], object], repeat: int, number: int) -> float:
    """Best mean time per call (s) over ``repeat`` runs of ``number`` calls."""
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        for _ in range(number):
            func()
        best = min(best, (time.perf_counter() - start) / number)
    return best


def main() -> None:
    link = load_antenna("paper-2021-calibrated").link
    x_c = np.linspace(link.length / 1000, link.length, 1000)
    t_curve = best_time(lambda: natural_frequencies(link, x_c, 3), repeat=7, number=1)
    t_build = best_time(lambda: SensingCurve.from_link(link), repeat=3, number=1)
    curve = SensingCurve.from_link(link)

    rng = np.random.default_rng(2021)
    truth = rng.uniform(0.3, link.length, 200)
    omega = natural_frequencies(link, truth, 1)[:, 0]
    t_lookup = best_time(lambda: curve.contact_points(float(omega[0])), repeat=5, number=2000)
    t_invert = best_time(lambda: curve.invert(omega), repeat=5, number=20) / omega.size

    # accuracy: frequency residual of every candidate against the exact solver, and x_c error
    residual = 0.0
    x_error = 0.0
    for w, x in zip(omega, truth, strict=True):
        candidates = curve.contact_points(float(w))
        exact = natural_frequencies(link, [c.x_c for c in candidates], 1)[:, 0]
        residual = max(residual, float(np.max(np.abs(exact / w - 1.0))))
        x_error = max(x_error, min(abs(c.x_c - x) for c in candidates) / link.length)

    rows = [
        ("1000-point curve, 3 modes", t_curve, CURVE_TARGET_S),
        ("SensingCurve.from_link (2001 nodes)", t_build, None),
        ("contact_points, one lookup", t_lookup, LOOKUP_TARGET_S),
        ("invert, per frequency (batch of 200)", t_invert, None),
    ]
    print(f"{'case':40s} {'time':>12s} {'target':>12s} {'ok':>4s}")
    for name, value, target in rows:
        tgt = f"{target * 1e3:9.3f} ms" if target else "-"
        ok = "yes" if target is None or value < target else "NO"
        print(f"{name:40s} {value * 1e3:9.4f} ms {tgt:>12s} {ok:>4s}")
    print(f"{'lookup omega residual (max rel.)':40s} {residual:12.2e} {ACCURACY_TARGET:12.0e}")
    print(f"{'lookup x_c error / l (max)':40s} {x_error:12.2e}")

    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    payload = {
        "machine": {"python": platform.python_version(), "processor": platform.processor()},
        "note": "shared 2-core machine under load; best of repeated runs",
        "curve_1000_points_3_modes_s": t_curve,
        "curve_target_s": CURVE_TARGET_S,
        "sensing_curve_build_s": t_build,
        "lookup_s": t_lookup,
        "lookup_target_s": LOOKUP_TARGET_S,
        "invert_per_frequency_s": t_invert,
        "lookup_relative_omega_residual": residual,
        "lookup_x_c_error_over_length": x_error,
        "accuracy_target": ACCURACY_TARGET,
    }
    RESULTS.write_text(json.dumps(payload, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {RESULTS}")


if __name__ == "__main__":
    main()
