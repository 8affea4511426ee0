"""The report's section on the second device: both devices beside the paper's Tables 3 and 4.

Formatting only: every number comes from :class:`~.summary.CampaignSummary` (its
``second_device`` and ``devices``). Lengths in cm, as in the paper's tables.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

from sensing_antenna.accuracy import PointStats
from sensing_antenna.campaign.devices import DeviceCaseTable, DeviceMethodRow, TwoDevices
from sensing_antenna.campaign.report_sections import (
    bound_cells,
    cm,
    figure_lines,
    markdown_table,
)
from sensing_antenna.campaign.schema import CampaignSpec
from sensing_antenna.campaign.store import SECOND_DEVICE_DIR
from sensing_antenna.campaign.summary import CampaignSummary
from sensing_antenna.campaign.targets import BOUND_RATIO_TARGET

__all__ = ["devices_section"]

_TABLES = {"azimuthal": "Table 3", "vertical": "Table 4"}


def _statuses(counts: Mapping[str, int]) -> str:
    ordered = sorted(counts.items(), key=lambda kv: (-kv[1], kv[0]))
    return ", ".join(f"{k} {v}" for k, v in ordered) or "-"


def _errors(row: DeviceMethodRow) -> str:
    return f"{cm(row.mean_abs_error)} / {cm(row.max_abs_error)} / {cm(row.std_error)}"


def _method_rows(both: TwoDevices) -> list[list[str]]:
    rows = []
    for index, first in enumerate(both.methods[0]):
        cells = [first.case, f"**{first.method}**" if first.method == "paper" else first.method]
        for device in both.methods:
            row = device[index]
            cells += [
                f"{row.n_ok}/{row.n_runs}",
                f"{row.n_estimates}/{row.n_runs}",
                _errors(row),
                f"{cm(row.ok_mean_abs_error)} / {cm(row.ok_max_abs_error)}",
                _statuses(row.status_counts),
            ]
        rows.append(cells)
    return rows


def _paper_text(summary: CampaignSummary) -> str:
    parts = [
        f"{p.case} {cm(p.mean_abs_error)} / {cm(p.max_error)} cm over {p.n_runs} experiments"
        for p in summary.paper_overall
        if p.n_runs
    ]
    if not parts:
        return ""
    return (
        " The paper's real device, mean of its per-point mean |e| / its largest e_max: "
        + "; ".join(parts)
        + "."
    )


def _point_cells(stats: PointStats | None) -> list[str]:
    if stats is None:
        return ["-"] * 4
    return [
        cm(stats.mean_estimate),
        cm(stats.mean_abs_error),
        cm(stats.max_error),
        cm(stats.std_error),
    ]


def _case_lines(table: DeviceCaseTable, labels: tuple[str, ...]) -> list[str]:
    header = ["x_c (cm)"]
    for label in labels:
        header += [
            f"{label}: mean x_c,e",
            "mean abs e",
            "max abs e",
            "std e",
            "ok",
        ]
    header += ["paper: mean x_c,e", "paper: mean abs e", "paper: max abs e", "paper: std e"]
    rows = []
    for row in table.rows:
        cells = [cm(row.x_c, 0)]
        for stats, n_ok in zip(row.devices, row.n_ok, strict=True):
            n = stats.n_runs if stats is not None else 0
            cells += [*_point_cells(stats), f"{n_ok}/{n}"]
        paper = row.paper
        cells += (
            [
                cm(paper.mean_estimate, 1),
                cm(paper.mean_abs_error, 1),
                cm(paper.max_error, 1),
                cm(paper.std_error, 2),
            ]
            if paper
            else ["-"] * 4
        )
        rows.append(cells)
    title = _TABLES.get(table.case)
    return [
        f"### {table.case} movement, method {table.method}"
        + (f", beside {title} of the paper" if title else ""),
        "",
        *markdown_table(header, rows),
        "",
    ]


def _preparation_text(summary: CampaignSummary) -> str:
    second = summary.second_device
    if second is None or second.calibration is None:
        return "It was not calibrated (the spec has no calibration step)."
    check = second.calibration
    calibration = check.calibration
    scatter = calibration.relative_scatter
    main = summary.calibration
    return (
        f"Its calibration gave T_e = {calibration.t_e:.4f} s/m^2 ({check.n_used}/"
        f"{check.n_points} points, rms residual {calibration.rms_residual:.3g} rad/s"
        + (f", scatter {100 * scatter:.3f} %" if math.isfinite(scatter) else "")
        + ")"
        + (
            f"; the main device's, T_e = {main.calibration.t_e:.4f} s/m^2 (rms residual "
            f"{main.calibration.rms_residual:.3g} rad/s)"
            if main is not None
            else ""
        )
        + f". Stored in `{SECOND_DEVICE_DIR}/`."
    )


def _spread_text(spec: CampaignSpec) -> str:
    if spec.device.profile != "realistic" or not spec.calibration.enabled:
        return ""
    return (
        " The realistic profile builds one device for the campaign, and its calibration "
        "recordings are manoeuvres of that device, each with a set-up of its own: the "
        "calibration learns the build, not the set-up (docs/campaigns.md, Second device)."
    )


def _bound_lines(summary: CampaignSummary, labels: tuple[str, ...]) -> list[str]:
    """The fast method's median t_e - t_1 against its median information bound on each device
    (all main runs); nothing without ``fast``."""
    rows = []
    for label, device in zip(labels, (summary, summary.second_device), strict=True):
        overall = (
            next((t for t in device.targets if t.case is None and t.noise_scale is None), None)
            if device is not None
            else None
        )
        if overall is not None:
            rows.append([label, str(overall.n_runs), *bound_cells(overall)])
    if not rows:
        return []
    return [
        "The fast method's median t_e - t_1 against the median information bound of its own "
        "model on each device, all main runs (as in the targets section above; a run where no "
        "window qualifies before the cap counts at the cap):",
        "",
        *markdown_table(
            [
                "device",
                "n",
                "fast: median t_e - t_1 (s)",
                "median bound (s)",
                "t_e / bound",
                f"at most {BOUND_RATIO_TARGET:g} x bound",
            ],
            rows,
        ),
        "",
    ]


def devices_section(
    spec: CampaignSpec, summary: CampaignSummary, figure: Path | None, out_dir: Path
) -> list[str]:
    """Both devices on the same manoeuvres beside the paper's Tables 3 and 4, and the figure of
    every run's error against x_c; nothing without a second device."""
    both = summary.devices
    if both is None:
        return []
    first, second = both.labels[0], both.labels[1]
    identify = (
        "its free-motion observer identified on free sweeps of it, "
        if spec.free_motion.identify
        else ""
    )
    lines = [
        "## Both devices beside Tables 3 and 4",
        "",
        f"The main runs ({spec.n_main_runs}: the cases, contact points and repeats above) were "
        f"run again on a second device: the same hardware as `[device]` with imperfections "
        f"**{second}** instead of **{first}** (docs/simulator.md), the same manoeuvres and "
        "seeds (so the same sensor noise), and a preparation of its own, made as the main "
        f"device's is, with the same seeds: {identify}T_e calibrated on its own recordings. "
        f"{_preparation_text(summary)}{_spread_text(spec)} The sections above cover the main "
        f"device ({first}) only.",
        "",
        "Per case and method: `ok` runs, runs with an estimate, the mean / max absolute error "
        "and the standard deviation of the error over every estimate (any status), the same "
        "mean / max over the `ok` runs only, and what became of every run, in cm against the "
        f"nominal x_c as in the paper's tables.{_paper_text(summary)}",
        "",
    ]
    header = ["case", "method"]
    for label in both.labels:
        header += [
            f"{label}: ok",
            "n",
            "mean / max / std (cm)",
            "ok only: mean / max (cm)",
            "statuses",
        ]
    lines += [*markdown_table(header, _method_rows(both)), ""]
    lines += _bound_lines(summary, both.labels)
    lines += [
        "Per contact point, in the layout of Tables 3 and 4 (cm; e = x_c,e - x_c; std with "
        "ddof = 1; ok: runs with status `ok` / runs). The statistics are over every run with "
        "an estimate, whatever its status.",
        "",
    ]
    for table in both.cases:
        lines += _case_lines(table, both.labels)
    if figure is not None:
        lines += [
            "Every run's error against the contact abscissa, per method, on each device "
            "(filled markers: status `ok`; hollow: any other status; runs without an estimate "
            "are not drawn).",
            "",
            *figure_lines(figure, out_dir),
        ]
    return lines
