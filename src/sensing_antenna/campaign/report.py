"""The campaign report: one Markdown file with tables and figures, rebuilt from the stored runs.

:func:`build_report` reads a campaign directory (see :mod:`~sensing_antenna.campaign.store`),
rewrites ``runs.csv``, draws the figures into ``figures/`` and writes ``report.md`` with relative
image links. Lengths are shown in cm (the display edge); everything stored stays SI.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import fields
from pathlib import Path
from typing import Any

from sensing_antenna.antenna import Antenna, load_antenna
from sensing_antenna.calibration.frequency import FrequencyCalibration
from sensing_antenna.campaign.records import RUN_FAILED, RunResult
from sensing_antenna.campaign.spec import CampaignSpec
from sensing_antenna.campaign.store import (
    CALIBRATION_FILE,
    CSV_FILE,
    DEVICE_FILE,
    CampaignStoreError,
    atomic_write_text,
    load_run_results,
    read_calibration,
    read_manifest,
    read_stored_antenna,
    write_runs_csv,
)
from sensing_antenna.campaign.tables import (
    IntervalSummary,
    MethodSummary,
    campaign_rows,
    interval_summaries,
    method_summaries,
    paper_row_at,
    paper_table,
    point_table,
)

__all__ = ["FIGURES_DIR", "REPORT_FILE", "build_report", "render_report"]

REPORT_FILE = "report.md"
FIGURES_DIR = "figures"

_CM = 100.0

#: Section 5.1 of the paper: theoretical T from Table 2 and the calibrated T_e (s/m^2); the paper
#: quotes their relative difference as 7 %.
PAPER_T = 0.2282
PAPER_T_E = 0.2124
_CASE_TITLES = {
    "azimuthal": "Case 1: azimuthal movement (Table 3 of the paper)",
    "vertical": "Case 2: vertical movement (Table 4 of the paper)",
}


def _cm(value: float, digits: int = 2) -> str:
    return "-" if not math.isfinite(value) else f"{value * _CM:.{digits}f}"


def _table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines.extend("| " + " | ".join(row) + " |" for row in rows)
    return lines


def _paper_overall(case: str) -> tuple[float, float]:
    """Mean of the per-point mean |e| (equal runs per point) and the largest max error (m)."""
    table = paper_table(case)
    if not table:
        return math.nan, math.nan
    return (
        sum(r.mean_abs_error for r in table) / len(table),
        max(r.max_error for r in table),
    )


def _summary_section(
    spec: CampaignSpec, summaries: Sequence[MethodSummary], length: float
) -> list[str]:
    header = ["method"]
    for case in spec.cases:
        header += [
            f"{case}: mean abs error (cm)",
            f"{case}: max abs error (cm)",
            f"{case}: n",
            f"{case}, status ok only: mean / max (cm), n",
        ]
    rows = []
    for method in spec.methods:
        row = [f"**{method}**" if method == "paper" else method]
        for case in spec.cases:
            s = next(x for x in summaries if x.case == case and x.method == method)
            row += [
                f"{_cm(s.mean_abs_error)} ({_percent(s.mean_abs_error, length)})",
                f"{_cm(s.max_abs_error)} ({_percent(s.max_abs_error, length)})",
                f"{s.n_estimates}/{s.n_runs}",
                f"{_cm(s.ok_mean_abs_error)} / {_cm(s.ok_max_abs_error)}, "
                f"{s.status_counts.get('ok', 0)}",
            ]
        rows.append(row)
    paper_row = ["paper, real device (Tables 3, 4)"]
    for case in spec.cases:
        mean, worst = _paper_overall(case)
        paper_row += [
            f"{_cm(mean)} ({_percent(mean, length)})",
            f"{_cm(worst)} ({_percent(worst, length)})",
            str(5 * len(paper_table(case))) if math.isfinite(mean) else "-",
            "-",
        ]
    rows.append(paper_row)
    return [
        "## Methods compared on the same recordings",
        "",
        "Errors over every run with a finite estimate, in cm and in % of the link length "
        f"l = {length:g} m; n is runs with an estimate / runs. An estimate may come with a status "
        "other than ok, which says not to trust it blindly; the last column of each case keeps "
        "only the runs with status ok. The paper reports about 1 % "
        "typical error for its method and about 3 % for earlier methods (Section 5.6).",
        "",
        *_table(header, rows),
        "",
    ]


def _percent(value: float, length: float) -> str:
    return "-" if not math.isfinite(value) else f"{100.0 * value / length:.1f} %"


def _status_section(spec: CampaignSpec, summaries: Sequence[MethodSummary]) -> list[str]:
    statuses = sorted({k for s in summaries for k in s.status_counts})
    rows = []
    for s in summaries:
        rows.append([s.case, s.method, *[str(s.status_counts.get(k, 0)) for k in statuses]])
    return [
        "## Status counts",
        "",
        "How many runs ended in each status (``run-failed``: the simulation itself failed; "
        "``error``: the estimator raised).",
        "",
        *_table(["case", "method", *statuses], rows),
        "",
    ]


def _case_section(
    case: str, rows: Sequence[Mapping[str, Any]], methods: Sequence[str]
) -> list[str]:
    main = "paper" if "paper" in methods else methods[0]
    ours = point_table(rows, case, main)
    baselines = [m for m in methods if m != main]
    baseline_tables = {m: {p.x_c: p for p in point_table(rows, case, m)} for m in baselines}
    header = [
        "x_c (cm)",
        "mean x_c,e",
        "mean abs e",
        "max e",
        "std e",
        "paper: mean x_c,e",
        "paper: mean abs e",
        "paper: max e",
        "paper: std e",
        *[f"{m}: mean abs e" for m in baselines],
        "n",
    ]
    lines = []
    for p in ours:
        paper = paper_row_at(case, p.x_c)
        paper_cells = (
            [
                _cm(paper.mean_estimate, 1),
                _cm(paper.mean_abs_error, 1),
                _cm(paper.max_error, 1),
                _cm(paper.std_error, 2),
            ]
            if paper
            else ["-"] * 4
        )
        base_cells = []
        for m in baselines:
            b = baseline_tables[m].get(p.x_c)
            base_cells.append(_cm(b.mean_abs_error) if b else "-")
        lines.append(
            [
                _cm(p.x_c, 0),
                _cm(p.mean_estimate),
                _cm(p.mean_abs_error),
                _cm(p.max_error),
                _cm(p.std_error),
                *paper_cells,
                *base_cells,
                f"{p.n_estimates}/{p.n_runs}",
            ]
        )
    return [
        f"## {_CASE_TITLES.get(case, case)}",
        "",
        f"Method **{main}**, all values in cm; e = x_c,e - x_c; std with ddof = 1. The paper's "
        "numbers are from the real device (5 experiments per point).",
        "",
        *_table(header, lines),
        "",
    ]


def _failures_section(results: Sequence[RunResult]) -> list[str]:
    failed = [r for r in results if r.status == RUN_FAILED]
    if not failed:
        return []
    rows = [[r.run_id, str(r.seed), r.error.replace("|", "/")] for r in failed]
    return ["## Failed runs", "", *_table(["run", "seed", "error"], rows), ""]


def _differences(device: Antenna, model: Antenna) -> list[str]:
    """``section.field: device vs model`` for every hardware parameter that differs."""
    found = []
    for section in ("link", "azimuth_motor", "elevation_motor"):
        a, b = getattr(device, section), getattr(model, section)
        for f in fields(a):
            if f.name == "calibrated_t":
                continue
            x, y = getattr(a, f.name), getattr(b, f.name)
            if x != y:
                found.append(f"{section}.{f.name} = {x:.6g} (model {y:.6g})")
    return found


def _antenna_lines(model: Antenna, device: Antenna) -> list[str]:
    link = model.link
    t_model = link.theoretical_t
    t_device = device.link.theoretical_t
    used = (
        f"calibrated T_e = {link.t_param:.4f} s/m^2"
        if link.calibrated_t is not None
        else f"theoretical T = {link.t_param:.4f} s/m^2"
    )
    lines = [
        f"- Model (what the estimators know): {model.name}, E = {link.youngs_modulus / 1e9:.5g} "
        f"GPa, rho = {link.linear_density:.4g} kg/m, I = {link.area_moment:.4g} m^4, "
        f"l = {link.length:g} m, theoretical T = {t_model:.4f} s/m^2; the frequency model uses "
        f"the {used}",
        f"- Device (the simulated hardware): {device.name}, E = "
        f"{device.link.youngs_modulus / 1e9:.5g} GPa, T = {t_device:.4f} s/m^2"
        + (
            f"; differs from the model in {'; '.join(_differences(device, model))}"
            f" ([{DEVICE_FILE}]({DEVICE_FILE}))"
            if _differences(device, model)
            else " (the same hardware parameters as the model)"
        ),
    ]
    return lines


def _plain_statement(
    model: Antenna, device: Antenna, calibration: FrequencyCalibration | None
) -> list[str]:
    t_model = model.link.theoretical_t
    t_device = device.link.theoretical_t
    if not _differences(device, model):
        text = (
            "The simulated device has exactly the parameters of the model the estimators use, "
            "so the estimators see no model error."
        )
        if calibration is not None:
            text += " The calibration step still fits T_e from recordings, as on a real device."
        return [text, ""]
    text = (
        f"The simulated device is not the nominal model: its T is {t_device:.4f} s/m^2, "
        f"{100 * (t_device - t_model) / t_model:+.1f} % from the model's {t_model:.4f}. The "
        "estimators are never told the device's parameters. "
    )
    if calibration is not None:
        text += (
            "As in the paper (Section 5.1), the campaign first calibrates T_e from contact "
            "recordings on the device at known points, and every estimator uses the model with "
            f"that T_e ({calibration.t_e:.4f} s/m^2)."
        )
    else:
        text += (
            "There is no calibration step, so the estimators use the model's theoretical T: "
            "the errors include the model error."
        )
    return [text, ""]


def _calibration_section(
    calibration: FrequencyCalibration | None,
    spec: CampaignSpec,
    device: Antenna,
    figure: Path | None,
    out_dir: Path,
) -> list[str]:
    if calibration is None:
        return []
    step = spec.calibration
    used = int(calibration.used.sum())
    total = calibration.contact_points.size
    se = calibration.t_e_std_error
    t_e_text = f"{calibration.t_e:.4f}" + (f" +- {se:.4f}" if math.isfinite(se) else "")
    paper_rel = (PAPER_T_E - PAPER_T) / PAPER_T
    rows = [
        [
            "this campaign (simulated device)",
            f"{calibration.t_theoretical:.4f}",
            t_e_text,
            f"{100 * calibration.relative_difference:+.1f} %",
            f"{calibration.rms_residual:.3g}",
            f"{used}/{total}",
        ],
        [
            "paper, real device (Section 5.1)",
            f"{PAPER_T:.4f}",
            f"{PAPER_T_E:.4f}",
            f"{100 * paper_rel:+.1f} % (quoted as 7 %)",
            "-",
            "15 points",
        ],
    ]
    t_device = device.link.theoretical_t
    lines = [
        "## Calibration of the frequency model (Section 5.1)",
        "",
        f"Before the runs, {calibration.contact_points.size} contact manoeuvres were simulated on "
        f"the device ({step.case} case, x_c from {_cm(min(step.contact_points), 0)} to "
        f"{_cm(max(step.contact_points), 0)} cm, {step.repeats} repeat(s) each, seeds on their "
        "own stream). omega_1 was measured in each with the wide calibration band and T_e fitted "
        f"to the model's beta_1(x_c)^2 (loss {calibration.loss}). The contact points are known "
        "(a calibration); nothing else about the device is. Every estimator uses T_e. "
        f"Stored in [{CALIBRATION_FILE}]({CALIBRATION_FILE}).",
        "",
        *_table(
            [
                "",
                "T, model (s/m^2)",
                "T_e (s/m^2)",
                "(T_e - T) / T",
                "rms residual (rad/s)",
                "points used",
            ],
            rows,
        ),
        "",
        f"Check available on the simulator only: the device's true T is {t_device:.4f} s/m^2; "
        f"T_e is {100 * (calibration.t_e - t_device) / t_device:+.2f} % from it.",
        "",
    ]
    if calibration.notes:
        lines += ["Points left out of the fit:", ""]
        lines += [f"- {note}" for note in calibration.notes]
        lines.append("")
    if figure is not None:
        lines += [f"![{figure.stem}]({figure.relative_to(out_dir).as_posix()})", ""]
    return lines


def _interval_section(summaries: Sequence[IntervalSummary]) -> list[str]:
    rows = []
    for s in summaries:
        coverage = (
            f"{s.n_covering}/{s.n_intervals} ({100 * s.coverage:.0f} %)" if s.n_intervals else "-"
        )
        width = _cm(s.median_width) if s.n_intervals else "-"
        delay = (
            f"{s.median_time_to_estimate:.3f}" if math.isfinite(s.median_time_to_estimate) else "-"
        )
        rows.append([s.case, s.method, delay, coverage, width])
    return [
        "## Time to estimate and uncertainty",
        "",
        "Median time from the push (t_1) to the estimate (t_e), and, for methods that give a 95 % "
        "interval of x_c, how often it contains the true x_c and its median width.",
        "",
        *_table(
            [
                "case",
                "method",
                "median t_e - t_1 (s)",
                "95 % interval contains x_c",
                "median width (cm)",
            ],
            rows,
        ),
        "",
    ]


def render_report(
    spec: CampaignSpec,
    antenna: Antenna,
    results: Sequence[RunResult],
    figures: Sequence[Path],
    out_dir: Path,
    device: Antenna | None = None,
    calibration: FrequencyCalibration | None = None,
    calibration_figure: Path | None = None,
) -> str:
    """The Markdown text of the report (figure links relative to ``out_dir``).

    Parameters
    ----------
    spec : CampaignSpec
    antenna : Antenna
        The model the estimators used (with identified observer and T_e, if any).
    results : sequence of RunResult
    figures : sequence of Path
        Campaign figures (method comparison, Figures 16 to 18).
    out_dir : Path
        Campaign directory; links are relative to it.
    device : Antenna, optional
        The simulated hardware; None: the same as ``antenna``.
    calibration : FrequencyCalibration, optional
        The calibration step's result, for its section.
    calibration_figure : Path, optional
        Figure 10 of the calibration.
    """
    device = device if device is not None else antenna
    rows = campaign_rows(results, spec.methods)
    summaries = method_summaries(rows, spec.cases, spec.methods)
    n_failed = sum(1 for r in results if r.status == RUN_FAILED)
    obs = antenna.observer
    lines = [
        f"# Campaign {spec.name}",
        "",
        spec.description,
        "",
        f"- Runs stored: {len(results)} of {spec.n_runs}; failed: {n_failed}"
        + ("" if len(results) == spec.n_runs else " (campaign incomplete: run it again to finish)"),
        f"- Cases: {', '.join(spec.cases)}; repeats: {spec.repeats}; base seed: {spec.base_seed}",
        "- Contact points (cm): " + ", ".join(_cm(x, 0) for x in spec.contact_points),
        f"- Methods: {', '.join(spec.methods)} (each estimates the same recordings)",
        *_antenna_lines(antenna, device),
        f"- Free-motion observer (Eq. 15): gain {obs.gain:.4g} N m/rad, omega "
        f"{obs.natural_frequency:.4g} rad/s, damping {obs.damping:.4g} 1/s, contact threshold "
        f"{obs.contact_threshold:.4g} N m"
        + (
            " (identified on a simulated free motion of the device; used by the device's "
            "controller and by the estimators)"
            if spec.free_motion.identify
            else ""
        ),
        "- Scenario: "
        + (", ".join(f"{k} = {v}" for k, v in sorted(spec.scenario.items())) or "defaults"),
        f"- Per-run results: [{CSV_FILE}]({CSV_FILE}) (SI units, one row per run and method)",
        "",
        *_plain_statement(antenna, device, calibration),
        "The recordings are simulated; the paper's numbers come from its real device, so the "
        "comparison shows whether the method behaves as reported, not a reproduction of the "
        "device.",
        "",
        *_calibration_section(calibration, spec, device, calibration_figure, out_dir),
        *_summary_section(spec, summaries, antenna.link.length),
        *_status_section(spec, summaries),
        *_interval_section(interval_summaries(rows, spec.cases, spec.methods)),
        "## Figures",
        "",
    ]
    for path in figures:
        rel = path.relative_to(out_dir).as_posix()
        lines += [f"![{path.stem}]({rel})", ""]
    for case in spec.cases:
        lines += _case_section(case, rows, spec.methods)
    lines += _failures_section(results)
    return "\n".join(lines).rstrip() + "\n"


def build_report(out_dir: str | Path, *, figures: bool = True) -> Path:
    """Rebuild ``runs.csv``, the figures and ``report.md`` from a campaign directory.

    Parameters
    ----------
    out_dir : str or Path
        A directory written by :func:`~sensing_antenna.campaign.runner.run_campaign`.
    figures : bool
        Draw the figures (needs matplotlib; the frequency figure needs the beam model).

    Returns
    -------
    Path
        The report file.
    """
    directory = Path(out_dir)
    spec = read_manifest(directory)
    antenna = read_stored_antenna(directory)
    if antenna is None:
        raise CampaignStoreError(f"{directory / 'antenna.toml'}: no such file")
    device_path = directory / DEVICE_FILE
    device = load_antenna(device_path) if device_path.is_file() else antenna
    stored_calibration = read_calibration(directory)
    calibration = stored_calibration[1] if stored_calibration is not None else None
    stored = load_run_results(directory)
    results = sorted(stored.values(), key=lambda r: r.index)
    write_runs_csv(directory / CSV_FILE, results, spec.methods)
    paths: list[Path] = []
    calibration_figure = None
    if figures and calibration is not None:
        from sensing_antenna.plotting.calibration import plot_calibration

        calibration_figure = plot_calibration(calibration, antenna.link, directory / FIGURES_DIR)
    if figures and results:
        from sensing_antenna.plotting.campaign import plot_campaign

        rows = campaign_rows(results, spec.methods)
        paths = plot_campaign(rows, spec.cases, spec.methods, antenna, directory / FIGURES_DIR)
    report = directory / REPORT_FILE
    text = render_report(
        spec, antenna, results, paths, directory, device, calibration, calibration_figure
    )
    atomic_write_text(report, text)
    return report
