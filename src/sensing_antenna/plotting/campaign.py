"""Figures of a campaign (Section 5.6): Figures 16 and 17, Figure 18 and a method comparison.

Every function takes the run x method rows of a campaign (dicts with the columns of
:data:`~sensing_antenna.campaign.records.CSV_COLUMNS`, SI units), writes PNG files into an output
directory (created if missing) and returns their paths. Lengths are shown in cm and frequencies in
rad/s, as in the paper.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from sensing_antenna.antenna import Antenna
from sensing_antenna.campaign.records import float_or_nan
from sensing_antenna.campaign.tables import FrequencyErrorSummary, paper_table, point_table
from sensing_antenna.plotting import save_figure

__all__ = [
    "CASE_FIGURES",
    "plot_campaign",
    "plot_case_estimates",
    "plot_error_and_delay",
    "plot_frequencies",
    "plot_frequency_error_vs_noise",
    "plot_method_errors",
]

#: Figure number of the paper for each case (estimated vs real x_c, absolute errors).
CASE_FIGURES = {"azimuthal": 16, "vertical": 17}

_CM = 100.0
#: Lowest error drawn on the log axis of the error-versus-x_c figure (cm): 10 micrometres, far
#: below any physical resolution of the device.
_ERROR_FLOOR_CM = 1e-3
_METHOD_STYLE = {
    "paper": {"color": "tab:blue", "marker": "o"},
    "ratio": {"color": "tab:orange", "marker": "s"},
    "two-frequency": {"color": "tab:green", "marker": "^"},
    "fast": {"color": "tab:red", "marker": "D"},
}


def _finite(rows: Iterable[Mapping[str, Any]], case: str, method: str, column: str) -> Any:
    selected = [r for r in rows if r["case"] == case and r["method"] == method]
    x = np.array([float(r["x_c_true_m"]) for r in selected], dtype=float)
    y = np.array([float(r[column]) for r in selected], dtype=float)
    keep = np.isfinite(y)
    return x[keep], y[keep]


def plot_case_estimates(
    rows: Sequence[Mapping[str, Any]], case: str, out_dir: str | Path, method: str = "paper"
) -> Path:
    """Figure 16 (azimuthal) or 17 (vertical): (a) estimated vs real x_c, (b) absolute errors."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    x, estimate = _finite(rows, case, method, "x_c_estimate_m")
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(10, 4.2))
    line = np.array([0.0, max(1.0, float(x.max(initial=0.0)))])
    ax_a.plot(line * _CM, line * _CM, color="0.6", lw=1, label="x_c,e = x_c")
    ax_a.plot(x * _CM, estimate * _CM, "o", ms=4, mfc="none", label=f"{method} ({x.size} runs)")
    ax_a.set_xlabel("real contact point x_c (cm)")
    ax_a.set_ylabel("estimated contact point x_c,e (cm)")
    ax_a.set_title("(a) estimated vs real")
    ax_a.legend(loc="upper left")
    ax_b.plot(x * _CM, np.abs(estimate - x) * _CM, "o", ms=4, mfc="none", label="this campaign")
    paper = paper_table(case)
    if paper:
        ax_b.plot(
            [p.x_c * _CM for p in paper],
            [p.max_error * _CM for p in paper],
            "k_",
            ms=12,
            label="paper: max error",
        )
    ax_b.set_xlabel("real contact point x_c (cm)")
    ax_b.set_ylabel("absolute error |x_c,e - x_c| (cm)")
    ax_b.set_title("(b) absolute errors")
    ax_b.legend(loc="upper left")
    number = CASE_FIGURES.get(case)
    title = f"Figure {number}: " if number else ""
    fig.suptitle(f"{title}{case} movement, method {method}")
    return save_figure(fig, out / f"figure{number or ''}-{case}-{method}.png")


def plot_frequencies(
    rows: Sequence[Mapping[str, Any]], antenna: Antenna, out_dir: str | Path
) -> Path:
    """Figure 18: measured omega_1 vs x_c in each case, over the sensing curve of ``antenna``."""
    from sensing_antenna.beam import natural_frequencies

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    link = antenna.link
    grid = np.linspace(0.2 * link.length, link.length, 200)
    curve = np.asarray(natural_frequencies(link, grid, 1), dtype=float)[..., 0]
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    name = "T_e" if link.calibrated_t is not None else "T"
    ax.plot(
        grid * _CM, curve, color="0.3", lw=1.5, label=f"sensing curve, {name} = {link.t_param:.4g}"
    )
    for case, marker in (("azimuthal", "o"), ("vertical", "x")):
        x, omega = _finite(rows, case, "paper", "omega1_rad_s")
        if x.size:
            ax.plot(x * _CM, omega, marker, ms=5, mfc="none", label=f"measured, {case}")
    ax.set_xlabel("contact point x_c (cm)")
    ax.set_ylabel("fundamental frequency omega_1 (rad/s)")
    ax.set_title("Figure 18: measured fundamental frequencies over the sensing curve")
    ax.legend()
    return save_figure(fig, out / "figure18-frequencies.png")


def plot_method_errors(
    rows: Sequence[Mapping[str, Any]],
    cases: Sequence[str],
    methods: Sequence[str],
    out_dir: str | Path,
) -> Path:
    """Mean absolute error vs x_c for every method (one panel per case), with the paper's."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, len(cases), figsize=(5.5 * len(cases), 4.2), squeeze=False)
    for ax, case in zip(axes[0], cases, strict=True):
        for method in methods:
            table = point_table(rows, case, method)
            style = _METHOD_STYLE.get(method, {"color": None, "marker": "."})
            ax.plot(
                [p.x_c * _CM for p in table],
                # errors below the display floor (e.g. an estimate that lands on a grid point of
                # the truth) are drawn on the floor, not as a dive to 1e-14 cm
                [max(p.mean_abs_error * _CM, _ERROR_FLOOR_CM) for p in table],
                marker=style["marker"],
                color=style["color"],
                label=method,
            )
        paper = paper_table(case)
        if paper:
            ax.plot(
                [p.x_c * _CM for p in paper],
                [p.mean_abs_error * _CM for p in paper],
                "k--",
                lw=1,
                label="paper (real device)",
            )
        ax.set_yscale("log")
        ax.set_ylim(bottom=_ERROR_FLOOR_CM)
        ax.set_xlabel("real contact point x_c (cm)")
        ax.set_ylabel("mean absolute error (cm)")
        ax.set_title(f"{case} movement")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle("Error versus contact point, all methods on the same recordings")
    return save_figure(fig, out / "errors-by-method.png")


def _per_run(rows: Iterable[Mapping[str, Any]], case: str, method: str) -> Any:
    """x_c, signed error and t_e - t_1 of every run of ``method`` with a finite estimate.

    The error is against the contact abscissa (where the link touched) when the row has one,
    else against the nominal x_c.
    """
    selected = [r for r in rows if r["case"] == case and r["method"] == method]
    x = np.array([float(r["x_c_true_m"]) for r in selected], dtype=float)
    error = np.array([float_or_nan(r.get("error_contact_m")) for r in selected], dtype=float)
    nominal = np.array([float(r["error_m"]) for r in selected], dtype=float)
    error = np.where(np.isfinite(error), error, nominal)
    delay = np.array([float(r["t_e_s"]) - float(r["t_1_s"]) for r in selected], dtype=float)
    keep = np.isfinite(error) & np.isfinite(delay)
    return x[keep], error[keep], delay[keep]


def plot_error_and_delay(
    rows: Sequence[Mapping[str, Any]],
    cases: Sequence[str],
    methods: Sequence[str],
    out_dir: str | Path,
) -> Path:
    """Per run and method: |x_c error| (top) and t_e - t_1 (bottom) against x_c, per case.

    The error is against the contact abscissa (the nominal x_c for runs without one); the x axis
    is the nominal x_c, so the runs of one point line up.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(
        2, len(cases), figsize=(5.5 * len(cases), 7.0), squeeze=False, sharex="col"
    )
    for col, case in enumerate(cases):
        ax_e, ax_t = axes[0][col], axes[1][col]
        for method in methods:
            x, error, delay = _per_run(rows, case, method)
            style = _METHOD_STYLE.get(method, {"color": None, "marker": "."})
            ax_e.plot(
                x * _CM,
                np.maximum(np.abs(error) * _CM, _ERROR_FLOOR_CM),
                style["marker"],
                color=style["color"],
                ms=4,
                mfc="none",
                label=method,
            )
            ax_t.plot(
                x * _CM,
                delay,
                style["marker"],
                color=style["color"],
                ms=4,
                mfc="none",
                label=method,
            )
        ax_e.set_yscale("log")
        ax_e.set_ylim(bottom=_ERROR_FLOOR_CM)
        ax_e.set_ylabel("|x_c,e - contact abscissa| (cm)")
        ax_e.set_title(f"{case} movement")
        ax_e.grid(True, which="both", alpha=0.3)
        ax_e.legend()
        ax_t.set_xlabel("real contact point x_c (cm)")
        ax_t.set_ylabel("t_e - t_1 (s)")
        ax_t.set_ylim(bottom=0.0)
        ax_t.grid(True, alpha=0.3)
    fig.suptitle("Error and time to estimate per run, all methods on the same recordings")
    return save_figure(fig, out / "error-and-delay-by-method.png")


def plot_frequency_error_vs_noise(
    summaries: Sequence[FrequencyErrorSummary], out_dir: str | Path
) -> Path:
    """omega_1 error against the noise level for each method, beside the fast method's bound.

    Left: RMS, right: median of |omega_1 - omega_1,true| / omega_1,true over the runs of each
    level (log-log). Dotted: the median over runs of the Cramer-Rao bound of omega_1 reported by
    the methods that give one (``fast``: for its own window), dash-dotted: their reported
    standard error. For a fixed record the bound is proportional to the noise; the fast method
    stops when sure, so its record lengthens with the noise and its bound stays nearly level.
    The error cannot fall below the model bias (the simulator's compliant contact and finite
    elements against the pinned-contact beam model).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.4), squeeze=False)
    methods = list(dict.fromkeys(s.method for s in summaries))
    for ax, attr, title in (
        (axes[0][0], "rms_relative_error", "RMS relative error of omega_1"),
        (axes[0][1], "median_abs_relative_error", "median |relative error| of omega_1"),
    ):
        for method in methods:
            mine = sorted((s for s in summaries if s.method == method), key=lambda s: s.noise_scale)
            style = _METHOD_STYLE.get(method, {"color": None, "marker": "."})
            levels = np.array([s.noise_scale for s in mine], dtype=float)
            ax.plot(
                levels,
                [max(getattr(s, attr), 1e-7) for s in mine],
                marker=style["marker"],
                color=style["color"],
                label=method,
            )
            crb = np.array([s.median_relative_crb for s in mine], dtype=float)
            if np.isfinite(crb).any():
                ax.plot(
                    levels, crb, ":", color=style["color"], lw=2, label=f"{method}: CRB (median)"
                )
            se = np.array([s.median_relative_se for s in mine], dtype=float)
            if np.isfinite(se).any():
                ax.plot(
                    levels, se, "-.", color=style["color"], lw=1, label=f"{method}: reported SE"
                )
        positive = sorted({s.noise_scale for s in summaries if s.noise_scale > 0})
        if positive:
            ax.set_xscale("log")
            ax.set_xticks(positive, [f"{v:g}" for v in positive])
            ax.minorticks_off()
        ax.set_yscale("log")
        ax.set_xlabel("noise level (x the simulator's nominal sensor noise)")
        ax.set_ylabel("relative error of omega_1")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize="small")
    fig.suptitle("Frequency error against noise, beside the Cramer-Rao bound of the same record")
    return save_figure(fig, out / "frequency-error-vs-noise.png")


def plot_campaign(
    rows: Sequence[Mapping[str, Any]],
    cases: Sequence[str],
    methods: Sequence[str],
    antenna: Antenna,
    out_dir: str | Path,
) -> list[Path]:
    """Every campaign figure: the method comparison, Figures 16/17 per case, and Figure 18.

    With the ``fast`` method among ``methods``, also the error and t_e - t_1 of every run
    against x_c (:func:`plot_error_and_delay`).
    """
    main = "paper" if "paper" in methods else methods[0]
    paths = [plot_method_errors(rows, cases, methods, out_dir)]
    if "fast" in methods:
        paths.append(plot_error_and_delay(rows, cases, methods, out_dir))
    paths += [plot_case_estimates(rows, case, out_dir, main) for case in cases]
    if "paper" in methods:
        paths.append(plot_frequencies(rows, antenna, out_dir))
    return paths
