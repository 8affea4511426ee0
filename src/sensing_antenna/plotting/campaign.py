"""Figures of a campaign (Section 5.6): Figures 16 and 17, Figure 18 and method comparisons.

Every function takes summaries of a campaign (:mod:`sensing_antenna.accuracy`: per-point tables
and per-run arrays, SI units), writes a PNG file into an output directory (created if missing)
and returns its path. Lengths are shown in cm and frequencies in rad/s, as in the paper.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from sensing_antenna.accuracy import FrequencyErrorSummary, PointTable, RunPoints
from sensing_antenna.antenna import Link
from sensing_antenna.plotting import save_figure

__all__ = [
    "CASE_FIGURES",
    "plot_case_estimates",
    "plot_error_and_delay",
    "plot_errors_by_device",
    "plot_frequencies",
    "plot_frequency_error_vs_noise",
    "plot_method_errors",
]

#: Figure number of the paper for each case (estimated vs real x_c, absolute errors).
CASE_FIGURES = {"azimuthal": 16, "vertical": 17}

_CM = 100.0
#: Errors in the error-versus-x_c figures are drawn on a symmetric-log axis (cm): linear from 0
#: to 10 micrometres, far below any physical resolution of the device, logarithmic above, so an
#: error of exactly zero (an estimate on the grid point of the truth) is drawn at 0, as it is.
_ERROR_LINEAR_BELOW_CM = 1e-3
#: Horizontal shift between methods in the per-device error figure (cm).
_DODGE_CM = 0.5
_METHOD_STYLE = {
    "paper": {"color": "tab:blue", "marker": "o"},
    "ratio": {"color": "tab:orange", "marker": "s"},
    "two-frequency": {"color": "tab:green", "marker": "^"},
    "fast": {"color": "tab:red", "marker": "D"},
}
_CASE_MARKERS = {"azimuthal": "o", "vertical": "x"}


def _style(method: str) -> dict[str, str | None]:
    return dict(_METHOD_STYLE.get(method, {"color": None, "marker": "."}))


def _join(names: Sequence[str]) -> str:
    return ", ".join(names[:-1]) + " and " + names[-1] if len(names) > 1 else names[0]


def _cases(items: Sequence[PointTable] | Sequence[RunPoints]) -> list[str]:
    return list(dict.fromkeys(item.case for item in items))


def _error_axis(ax: Any) -> None:
    """Absolute errors in cm: symmetric-log, linear below 10 um so that 0 is drawn at 0."""
    ax.set_yscale("symlog", linthresh=_ERROR_LINEAR_BELOW_CM, linscale=0.5)
    ax.set_ylim(bottom=0.0)
    # once per figure, in its bottom right corner: inside the axes a legend may cover it
    note = f"error axes: linear below {_ERROR_LINEAR_BELOW_CM:g} cm, log above"
    figure = ax.get_figure()
    if figure is not None and not any(text.get_text() == note for text in figure.texts):
        figure.text(0.995, 0.005, note, ha="right", va="bottom", fontsize="x-small", color="0.4")


def plot_case_estimates(points: RunPoints, paper: PointTable | None, out_dir: str | Path) -> Path:
    """Figure 16 (azimuthal) or 17 (vertical): (a) estimated vs real x_c, (b) absolute errors.

    Parameters
    ----------
    points : RunPoints
        Every run of one method in one case.
    paper : PointTable, optional
        The paper's table of that case; its maximum errors are drawn beside ours.
    out_dir : str or Path
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    keep = np.isfinite(points.estimate)
    x, estimate = points.x_c[keep], points.estimate[keep]
    case, method = points.case, points.method
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(10, 4.2))
    line = np.array([0.0, max(1.0, float(x.max(initial=0.0)))])
    ax_a.plot(line * _CM, line * _CM, color="0.6", lw=1, label="x_c,e = x_c")
    ax_a.plot(x * _CM, estimate * _CM, "o", ms=4, mfc="none", label=f"{method} ({x.size} runs)")
    ax_a.set_xlabel("real contact point x_c (cm)")
    ax_a.set_ylabel("estimated contact point x_c,e (cm)")
    ax_a.set_title("(a) estimated vs real")
    ax_a.legend(loc="upper left")
    ax_b.plot(x * _CM, np.abs(estimate - x) * _CM, "o", ms=4, mfc="none", label="this campaign")
    if paper is not None and paper.points:
        ax_b.plot(
            paper.x_c * _CM,
            paper.max_error * _CM,
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


def plot_frequencies(points: Sequence[RunPoints], link: Link, out_dir: str | Path) -> Path:
    """Figure 18: measured omega_1 vs x_c, one series per case, over the sensing curve of ``link``.

    Parameters
    ----------
    points : sequence of RunPoints
        The runs of the method whose omega_1 is drawn (the paper's), one entry per case.
    link : Link
        The model's link (its calibrated T_e when it has one).
    out_dir : str or Path
    """
    from sensing_antenna.beam import natural_frequencies

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    grid = np.linspace(0.2 * link.length, link.length, 200)
    curve = np.asarray(natural_frequencies(link, grid, 1), dtype=float)[..., 0]
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    name = "T_e" if link.calibrated_t is not None else "T"
    ax.plot(
        grid * _CM, curve, color="0.3", lw=1.5, label=f"sensing curve, {name} = {link.t_param:.4g}"
    )
    for series in points:
        keep = np.isfinite(series.omega1)
        if keep.any():
            marker = _CASE_MARKERS.get(series.case, ".")
            ax.plot(
                series.x_c[keep] * _CM,
                series.omega1[keep],
                marker,
                ms=5,
                mfc="none",
                label=f"measured, {series.case}",
            )
    ax.set_xlabel("contact point x_c (cm)")
    ax.set_ylabel("fundamental frequency omega_1 (rad/s)")
    ax.set_title("Figure 18: measured fundamental frequencies over the sensing curve")
    ax.legend()
    return save_figure(fig, out / "figure18-frequencies.png")


def plot_method_errors(
    tables: Sequence[PointTable], paper: Sequence[PointTable], out_dir: str | Path
) -> Path:
    """Mean absolute error vs x_c of every method (one panel per case), with the paper's.

    Parameters
    ----------
    tables : sequence of PointTable
        One per case and method; the panels follow the cases in order of appearance.
    paper : sequence of PointTable
        The paper's tables, drawn in the panel of their case.
    out_dir : str or Path
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cases = _cases(tables)
    fig, axes = plt.subplots(1, len(cases), figsize=(5.5 * len(cases), 4.2), squeeze=False)
    for ax, case in zip(axes[0], cases, strict=True):
        for table in (t for t in tables if t.case == case):
            style = _style(table.method)
            ax.plot(
                table.x_c * _CM,
                table.mean_abs_error * _CM,
                marker=style["marker"],
                color=style["color"],
                label=table.method,
            )
        for reference in (t for t in paper if t.case == case and t.points):
            ax.plot(
                reference.x_c * _CM,
                reference.mean_abs_error * _CM,
                "k--",
                lw=1,
                label="paper (real device)",
            )
        _error_axis(ax)
        ax.set_xlabel("real contact point x_c (cm)")
        ax.set_ylabel("mean absolute error (cm)")
        ax.set_title(f"{case} movement")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle("Error versus contact point, all methods on the same recordings")
    return save_figure(fig, out / "errors-by-method.png")


def plot_error_and_delay(points: Sequence[RunPoints], out_dir: str | Path) -> Path:
    """Per run and method: |x_c error| (top) and t_e - t_1 (bottom) against x_c, per case.

    The error is ``RunPoints.error`` (against where the link touched); the x axis is the
    nominal x_c, so the runs of one point line up. Runs without an error or a delay are left
    out.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cases = _cases(points)
    fig, axes = plt.subplots(
        2, len(cases), figsize=(5.5 * len(cases), 7.0), squeeze=False, sharex="col"
    )
    for col, case in enumerate(cases):
        ax_e, ax_t = axes[0][col], axes[1][col]
        for series in (p for p in points if p.case == case):
            keep = np.isfinite(series.error) & np.isfinite(series.delay)
            x = series.x_c[keep] * _CM
            style = _style(series.method)
            marker, color = style["marker"], style["color"]
            error = np.abs(series.error[keep]) * _CM
            ax_e.plot(x, error, marker, color=color, ms=4, mfc="none", label=series.method)
            ax_t.plot(
                x, series.delay[keep], marker, color=color, ms=4, mfc="none", label=series.method
            )
        _error_axis(ax_e)
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


def plot_errors_by_device(
    labels: Sequence[str],
    devices: Sequence[Sequence[RunPoints]],
    paper: Sequence[PointTable],
    out_dir: str | Path,
) -> Path:
    """|x_c error| of every run and method against x_c, one row of panels per device.

    Filled markers: runs whose status is ``ok``; hollow: the others (an estimate given with a
    status that says not to trust it). The error is ``RunPoints.error`` (against where the
    link touched), the x axis the nominal x_c, each method's markers shifted by a few
    millimetres so that methods do not hide each other. Runs without an estimate are left
    out; the paper's maximum error per point (its real device) is drawn in the panel of its
    case.

    Parameters
    ----------
    labels : sequence of str
        Name of each device (the rows' titles).
    devices : sequence of sequence of RunPoints
        Per device (in the order of ``labels``), one entry per case and method.
    paper : sequence of PointTable
        The paper's tables, drawn in the panel of their case.
    out_dir : str or Path
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cases = list(dict.fromkeys(p.case for points in devices for p in points))
    fig, axes = plt.subplots(
        len(devices),
        len(cases),
        figsize=(5.5 * len(cases), 3.8 * len(devices)),
        squeeze=False,
        sharex=True,
        sharey=True,
    )
    for row, (label, points) in enumerate(zip(labels, devices, strict=True)):
        for col, case in enumerate(cases):
            ax = axes[row][col]
            mine = [p for p in points if p.case == case]
            for k, series in enumerate(mine):
                shift = (k - (len(mine) - 1) / 2) * _DODGE_CM
                keep = np.isfinite(series.error)
                ok = series.ok if series.ok is not None else np.ones_like(keep)
                style = _style(series.method)
                marker, color = style["marker"], style["color"]
                for chosen, fill, suffix in ((ok, color, "ok"), (~ok, "none", "not ok")):
                    mask = keep & chosen
                    ax.plot(
                        series.x_c[mask] * _CM + shift,
                        np.abs(series.error[mask]) * _CM,
                        marker,
                        color=color,
                        mfc=fill,
                        ms=4,
                        label=f"{series.method}, {suffix} ({int(mask.sum())})",
                    )
            for reference in (t for t in paper if t.case == case and t.points):
                ax.plot(
                    reference.x_c * _CM,
                    reference.max_error * _CM,
                    "k_",
                    ms=12,
                    label="paper: max error",
                )
            _error_axis(ax)
            ax.set_title(f"{label}: {case} movement")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize="xx-small", ncol=2)
            if row == len(devices) - 1:
                ax.set_xlabel("real contact point x_c (cm)")
            if col == 0:
                ax.set_ylabel("|x_c,e - contact abscissa| (cm)")
    fig.suptitle("Error of every run against x_c on each device (filled: ok, hollow: not ok)")
    return save_figure(fig, out / "errors-by-device.png")


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
    elements against the pinned-contact beam model). The title names the methods whose bound is
    drawn, or says that none reports one.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig, axes = plt.subplots(1, 2, figsize=(11.0, 4.4), squeeze=False)
    methods = list(dict.fromkeys(s.method for s in summaries))
    bound = [
        m
        for m in methods
        if any(np.isfinite(s.median_relative_crb) for s in summaries if s.method == m)
    ]
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
    fig.suptitle(
        f"Frequency error against noise, beside the Cramer-Rao bound reported by {_join(bound)}"
        if bound
        else "Frequency error against noise (no method here reports a Cramer-Rao bound)"
    )
    return save_figure(fig, out / "frequency-error-vs-noise.png")
