"""How early could ``--method fast`` declare? Its delay against an information bound.

The fast method's target is a median t_e - t_1 of at most 25 % of the paper method's
(``campaign.targets.DELAY_RATIO_TARGET``). This script asks how much of the fast method's delay
is the information in the record and how much is its own caution. For every case, contact point
of the paper's grid and seed, one recording of the paper antenna is simulated and the fast
method's growing window is evaluated at every instant of its grid from ``first_window`` after t_1
to the cap (:meth:`FastMethod.history`), without stopping.
Four instants are read off each history, as t - t_1 (s):

- ``declared``: the first sure window after the pipeline's hold, the method's own t_e (sure at
  the tolerance, or settled within ``settled_margin`` of the floors' width);
- ``no_hold``: the first sure window at any time (the hold of ``frame_window`` after t_1, where
  the pipeline builds its contact frame, lifted);
- ``width``: the first window whose 95 % interval is narrower than the tolerance, every other
  check (periods in the window, drift, peak margin, ratio agreement) ignored; floors kept;
- ``bound``: the same with the standard error of omega_1 at its Cramer-Rao bound for the
  window's fitted model and noise, no model floors: the earliest instant the record's
  fundamental and torque/force ratio could give a 5 mm interval to an efficient estimator
  that trusted the linear model completely (``estimation.methods.fast.bound_delay``, the
  function campaigns report it with).

A window that never qualifies before the cap counts as the cap. The medians are compared with
the paper method's median t_e - t_1 on the same recordings. ``tolerance_<x>mm`` is the
declaration had the tolerance been x mm instead of 5 (every other check kept): what delay each
tolerance buys. Beside them, ``higher`` is the
declaration of the fast method with its opt-in higher contact mode (``higher_modes=True``):
whether the second mode, as the pinned-contact model gives it, would buy the missing time, and
at what error (truth: the simulator's ``true_xc``).

``--campaign SPEC`` (``paper-2021`` for the built-in one, whose nominal second device it takes)
runs on that campaign's device and scenario with the model its preparation gives (observer
identified, T_e calibrated on the device), instead of the paper antenna simulated and estimated
with the same model. Results go to
``benchmarks/results/fast_bound.json`` (``fast_bound_<spec>.json`` with ``--campaign``) and a
figure of the instants against x_c beside it (``.png``).

Usage::

    python benchmarks/fast_bound.py             # full grid, noise 1, 2 seeds (about 2 min)
    python benchmarks/fast_bound.py --quick     # 4 positions, 1 seed
    python benchmarks/fast_bound.py --campaign paper-2021   # its calibrated device (3 min)
    python benchmarks/fast_bound.py --push-phase --out benchmarks/results/fast_bound_push.json
                                                # windows also through the push (opt-in)
    python benchmarks/fast_bound.py --set max_modes=2 --out /tmp/fb.json   # any FastConfig field

Set OMP_NUM_THREADS=1 on a shared machine: the fits are small and BLAS threads only contend.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from eval_fast import GRID, QUICK_GRID
from fast_settings import add_fast_arguments, fast_settings
from sensing_antenna.antenna import Antenna, paper_antenna
from sensing_antenna.campaign.parsing import load_campaign_spec
from sensing_antenna.campaign.simulated import make_scenario, prepare_campaign
from sensing_antenna.estimation import Evidence, estimate, gather
from sensing_antenna.estimation.methods.fast import FastConfig, FastMethod, bound_delay
from sensing_antenna.simulator import simulate

OUT = Path(__file__).parent / "results" / "fast_bound.json"
INSTANTS = ("declared", "no_hold", "width", "bound")
#: Tolerances (m) at which the declaration is also read off the history (the default is 5 mm).
TOLERANCES = (0.0025, 0.0075, 0.01, 0.015)
#: Instants plotted: the four and the declaration with the higher contact mode on.
PLOTTED = (*INSTANTS, "higher")
#: Instants summarised: those and the declaration at each of TOLERANCES.
REPORTED = (*PLOTTED, *(f"tolerance_{1e3 * t:g}mm" for t in TOLERANCES))


@dataclass(frozen=True)
class Setup:
    """What every run shares: the model the estimators use, the simulated device, the scenario."""

    model: Antenna
    device: Antenna
    scenario: dict[str, Any]
    config: FastConfig = field(default_factory=FastConfig)


def paper_setup(noise: float) -> Setup:
    """The paper antenna, simulated, and estimated with its own T as a calibration gives it
    (with the scatter calibrations of the simulated device measure, the fast method's floor)."""
    antenna = paper_antenna()
    model = antenna.self_calibrated()
    return Setup(model, antenna, {"noise_scale": noise})


def campaign_setup(spec_name: str, noise: float) -> Setup:
    """A campaign's device and scenario, and the model its preparation gives."""
    spec = load_campaign_spec(None if spec_name == "paper-2021" else spec_name)
    if spec_name == "paper-2021" and spec.second_device.enabled:
        spec = spec.second_device_spec()  # the built-in one's nominal device, as measured
    preparation = prepare_campaign(spec)
    return Setup(preparation.model, preparation.device, {**spec.scenario, "noise_scale": noise})


def _covers(interval: tuple[float, float] | None, truth: float) -> bool:
    return interval is not None and interval[0] <= truth <= interval[1]


def run_one(setup: Setup, case: str, x_c: float, seed: int) -> dict[str, Any]:
    """The instants (s after t_1) of one recording, the paper method's delay and the errors."""
    antenna = setup.model
    recorded = simulate(setup.device, make_scenario(case, x_c, seed, dict(setup.scenario)))
    truth = float(recorded.metadata["true_xc"])
    recording = recorded.without_ground_truth()
    config = setup.config
    start = time.perf_counter()
    fast = estimate(recording, antenna, FastMethod(config))
    paper = estimate(recording, antenna, "paper")
    higher = estimate(recording, antenna, FastMethod(replace(config, higher_modes=True)))
    row: dict[str, Any] = {
        "case": case,
        "x_nominal": x_c,
        "seed": seed,
        "noise": float(setup.scenario.get("noise_scale", 1.0)),
        "truth": truth,
        "status": fast.status.value,
        "paper_delay": paper.t_e - paper.t_1,
        "fast_delay": fast.t_e - fast.t_1,
        "fast_error": fast.x_c - truth,
        "fast_covered": _covers(fast.interval, truth),
        "higher": higher.t_e - higher.t_1,
        "higher_status": higher.status.value,
        "higher_error": higher.x_c - truth,
        "higher_covered": _covers(higher.interval, truth),
    }
    evidence = gather(recording, antenna)
    if not isinstance(evidence, Evidence):
        row.update({name: math.nan for name in INSTANTS})
        return row
    t_1 = float(evidence.t[evidence.rest_index])
    history = FastMethod(config).history(evidence, from_t1=True)
    cap = config.cap

    def first(test: Any) -> float:
        for w in history:
            if test(w):
                return float(evidence.t[w.end_index]) - t_1
        return cap

    row["declared"] = first(lambda w: w.sure and w.end_index >= evidence.hold_end)
    if abs(row["declared"] - row["fast_delay"]) > 0.5 * recording.sample_period:
        # The history must hold the method's own declaration; a mismatch is a bug, not a result
        raise RuntimeError(
            f"history declares at {row['declared']}, the method at {row['fast_delay']}"
        )
    if any(
        w.sure != (w.checks_passed and (w.posterior.width <= config.tolerance or w.settled))
        or (w.settled and not config.tolerance < w.posterior.width <= config.cap_tolerance)
        for w in history
    ):
        raise RuntimeError("a window's sure flag is not its checks and its width (or settled)")
    for tolerance in TOLERANCES:
        row[f"tolerance_{1e3 * tolerance:g}mm"] = first(
            lambda w, t=tolerance: (
                w.checks_passed and w.posterior.width <= t and w.end_index >= evidence.hold_end
            )
        )
    row["no_hold"] = first(lambda w: w.sure)
    row["width"] = first(lambda w: w.posterior.width <= config.tolerance)
    bound = bound_delay(evidence, config, windows=history)
    row["bound"] = cap if math.isnan(bound) else bound
    row["cpu"] = time.perf_counter() - start
    return row


def _job(args: tuple[Setup, str, float, int]) -> dict[str, Any]:
    return run_one(*args)


def summarise(rows: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Medians of the instants over ``rows`` as fractions of the paper method's median; errors."""
    paper = statistics.median(r["paper_delay"] for r in rows)
    summary: dict[str, Any] = {"runs": len(rows), "paper_median_delay": paper}
    for name in REPORTED:
        values = [r[name] for r in rows if math.isfinite(r[name])]
        median = statistics.median(values) if values else math.nan
        summary[name] = {
            "median": median,
            "fraction_of_paper": median / paper,
            "at_most_25_percent": sum(v <= 0.25 * paper for v in values) / max(1, len(values)),
        }
    for method in ("fast", "higher"):
        errors = [abs(r[f"{method}_error"]) for r in rows if math.isfinite(r[f"{method}_error"])]
        declared = [r for r in rows if r["status" if method == "fast" else "higher_status"] == "ok"]
        summary[f"{method}_accuracy"] = {
            "mean_abs_error": statistics.fmean(errors) if errors else math.nan,
            "max_abs_error": max(errors, default=math.nan),
            "ok_over_2cm": sum(abs(r[f"{method}_error"]) > 0.02 for r in declared),
            "coverage": statistics.fmean(r[f"{method}_covered"] for r in rows),
        }
    return summary


def plot(rows: Sequence[dict[str, Any]], path: Path) -> None:
    """t - t_1 of the plotted instants against x_c, one panel per case (medians over seeds)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cases = sorted({r["case"] for r in rows})
    fig, axes = plt.subplots(1, len(cases), figsize=(5.5 * len(cases), 4), sharey=True)
    for ax, case in zip(np.atleast_1d(axes), cases, strict=True):
        points = sorted({r["x_nominal"] for r in rows if r["case"] == case})
        for name, style in zip(PLOTTED, ("o-", "s--", "^:", "v-", "x-."), strict=True):
            medians = [
                statistics.median(
                    r[name] for r in rows if r["case"] == case and r["x_nominal"] == x
                )
                for x in points
            ]
            ax.plot(points, medians, style, label=name)
        paper = statistics.median(r["paper_delay"] for r in rows)
        ax.axhline(0.25 * paper, color="k", lw=0.8, label="25 % of the paper's t_e - t_1")
        ax.set_title(f"{case}: fast method's delay and its information bound")
        ax.set_xlabel("contact point x_c (m)")
        ax.grid(alpha=0.3)
    np.atleast_1d(axes)[0].set_ylabel("t - t_1 (s)")
    np.atleast_1d(axes)[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="4 positions, 1 seed")
    parser.add_argument("--seeds", type=int, default=2, help="seeds per point")
    parser.add_argument("--seed-base", type=int, default=400, help="first seed")
    parser.add_argument("--noise", type=float, default=1.0, help="sensor noise scale")
    parser.add_argument("--workers", type=int, default=None, help="processes (default: cores)")
    parser.add_argument(
        "--campaign",
        default=None,
        help="campaign spec (file, or paper-2021): its device, scenario and prepared model",
    )
    add_fast_arguments(parser)
    parser.add_argument("--out", type=Path, default=None, help="JSON output")
    args = parser.parse_args()
    config, settings = fast_settings(args)  # before the campaign's preparation: fail early
    grid = QUICK_GRID if args.quick else GRID
    seeds = range(1) if args.quick else range(args.seeds)
    if args.campaign is None:
        setup, out = paper_setup(args.noise), OUT
    else:
        print(f"preparing campaign {args.campaign} (observer identification, T_e calibration)")
        setup = campaign_setup(args.campaign, args.noise)
        out = OUT.with_name(f"fast_bound_{Path(args.campaign).stem}.json")
        model_t, device_t = setup.model.link.t_param, setup.device.link.t_param
        print(f"model T = {model_t:.5f} s/m^2, device T = {device_t:.5f} s/m^2")
    out = args.out or out
    setup = replace(setup, config=config)
    jobs = [
        (setup, case, float(x), args.seed_base + s)
        for case in ("azimuthal", "vertical")
        for x in grid
        for s in seeds
    ]
    rows: list[dict[str, Any]] = []
    with ProcessPoolExecutor(args.workers) as pool:
        for k, row in enumerate(pool.map(_job, jobs), start=1):
            rows.append(row)
            print(
                f"[{k}/{len(jobs)}] {row['case']:9} x={row['x_nominal']:.2f} seed {row['seed']}: "
                + " ".join(f"{n}={row[n]:.3f}" for n in PLOTTED),
                flush=True,
            )
    summary = summarise(rows)
    print(f"\npaper method: median t_e - t_1 = {summary['paper_median_delay']:.3f} s")
    print(f"{'instant':18} {'median s':>9} {'/ paper':>8} {'runs <= 25 %':>12}")
    for name in REPORTED:
        s = summary[name]
        print(
            f"{name:18} {s['median']:9.3f} {s['fraction_of_paper']:8.3f} "
            f"{s['at_most_25_percent']:12.2f}"
        )
    for method in ("fast", "higher"):
        a = summary[f"{method}_accuracy"]
        print(
            f"{method:9} MAE {1e3 * a['mean_abs_error']:.2f} mm, max {1e3 * a['max_abs_error']:.2f}"
            f" mm, ok over 2 cm: {a['ok_over_2cm']}, coverage {a['coverage']:.3f}"
        )
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(
        json.dumps({"summary": summary, "settings": settings, "rows": rows}, indent=1) + "\n"
    )
    plot(rows, out.with_suffix(".png"))
    print(f"wrote {out} and {out.with_suffix('.png')}")


if __name__ == "__main__":
    main()
