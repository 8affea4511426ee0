"""The campaign report: one Markdown file with tables and figures, rebuilt from the stored runs.

:func:`build_report` reads a campaign directory (see :mod:`~sensing_antenna.campaign.store`),
rewrites ``runs.csv``, draws the figures into ``figures/`` and writes ``report.md`` with relative
image links. Lengths are shown in cm (the display edge); everything stored stays SI.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Mapping, Sequence
from dataclasses import fields
from pathlib import Path
from typing import Any

from sensing_antenna.antenna import Antenna, load_antenna
from sensing_antenna.calibration.frequency import FrequencyCalibration
from sensing_antenna.campaign.records import RUN_FAILED, RunResult, float_or_nan
from sensing_antenna.campaign.schema import CampaignSpec
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
    COVERAGE_TARGET,
    DELAY_RATIO_TARGET,
    MAE_TARGET,
    MAX_ERROR_TARGET,
    OK_ERROR_LIMIT,
    FrequencyErrorSummary,
    IntervalSummary,
    MethodSummary,
    TargetSummary,
    campaign_rows,
    frequency_error_summaries,
    interval_summaries,
    main_rows,
    method_summaries,
    noise_levels,
    paper_row_at,
    paper_table,
    point_table,
    rows_at_level,
    same_level,
    target_summary,
)

__all__ = ["FIGURES_DIR", "REPORT_FILE", "build_report", "render_report"]

REPORT_FILE = "report.md"
FIGURES_DIR = "figures"

_CM = 100.0
_MM = 1000.0

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


def _mm(value: float, digits: int = 2) -> str:
    return "-" if not math.isfinite(value) else f"{value * _MM:.{digits}f}"


def _seconds(value: float) -> str:
    return "-" if not math.isfinite(value) else f"{value:.3f}"


def _level(value: float) -> str:
    return f"{value:g}"


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
            if f.name in ("calibrated_t", "calibration_scatter"):
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


def _scatter_lines(calibration: FrequencyCalibration, applied: float | None) -> list[str]:
    scatter = calibration.relative_scatter
    if not math.isfinite(scatter):
        return []
    dropped = calibration.wrong_peaks
    text = (
        f"The measured omega_1 scatter by {100 * scatter:.3f} % (rms, relative) about the "
        "calibrated model: the departure along the link that one T_e cannot absorb"
        + (f" ({dropped} wrong peak(s) left out)" if dropped else "")
        + ". "
    )
    if applied is None:
        text += (
            "The model the runs used does not carry it (prepared before it was measured), so "
            "the fast method's floor on omega_1 was its default."
        )
    else:
        text += (
            f"The model carries it as `calibration_scatter` ({100 * applied:.3f} %), and the "
            "fast method's model floor on omega_1 is at least this."
        )
    return [text, ""]


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
    model: Antenna,
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
        *_scatter_lines(calibration, model.link.calibration_scatter),
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
        nominal = (
            f"{s.n_covering_nominal}/{s.n_intervals} ({100 * s.coverage_nominal:.0f} %)"
            if s.n_intervals
            else "-"
        )
        width = _cm(s.median_width) if s.n_intervals else "-"
        delay = (
            f"{s.median_time_to_estimate:.3f}" if math.isfinite(s.median_time_to_estimate) else "-"
        )
        rows.append([s.case, s.method, delay, coverage, nominal, width])
    judged_nominal = sum(s.n_judged_nominal for s in summaries)
    note = (
        f" {judged_nominal} interval(s) of runs without a known contact abscissa (stored before "
        "it was recorded) are judged against the nominal x_c instead."
        if judged_nominal
        else ""
    )
    return [
        "## Time to estimate and uncertainty",
        "",
        "Median time from the push (t_1) to the estimate (t_e), and, for methods that give a 95 % "
        "interval of x_c, how often it contains the contact abscissa (where the link touches: "
        "the interval is a claim about that point) and, for comparison, the nominal x_c; and "
        f"its median width.{note}",
        "",
        *_table(
            [
                "case",
                "method",
                "median t_e - t_1 (s)",
                "95 % interval contains the contact abscissa",
                "contains the nominal x_c",
                "median width (cm)",
            ],
            rows,
        ),
        "",
    ]


def _truth_section(
    rows: Sequence[Mapping[str, Any]], summaries: Sequence[MethodSummary]
) -> list[str]:
    """Errors against the nominal x_c and against the contact abscissa, side by side."""
    offsets = []
    seen: set[str] = set()
    for row in rows:
        if row["run_id"] in seen:
            continue
        seen.add(row["run_id"])
        contact, nominal = float_or_nan(row.get("x_c_contact_m")), float_or_nan(row["x_c_true_m"])
        if math.isfinite(contact):
            offsets.append(contact - nominal)
    if offsets:
        ordered = sorted(offsets)
        median = statistics.median(ordered)
        where = (
            f"On the {len(offsets)} main runs with a known contact abscissa it lies "
            f"{_mm(abs(median))} mm {'nearer the base than' if median < 0 else 'beyond'} the "
            f"nominal x_c (median; from {_mm(ordered[0])} to {_mm(ordered[-1])} mm)."
        )
    else:
        where = "No stored run records its contact abscissa (runs made before it was recorded)."
    table_rows = []
    for s in summaries:
        table_rows.append(
            [
                s.case,
                s.method,
                _mm(s.mean_abs_error),
                _mm(s.max_abs_error),
                _mm(s.contact_mean_abs_error),
                _mm(s.contact_max_abs_error),
                f"{s.n_contact}/{s.n_runs}",
            ]
        )
    return [
        "## Nominal x_c and the contact abscissa",
        "",
        "The tables above and the per-case tables in the layout of Tables 3 and 4 measure errors "
        "against the **nominal x_c** (where the undeflected link meets the obstacle), as the "
        "paper did. The link actually touches at the **contact abscissa** the simulator reports "
        f"(ground truth `true_xc`, at the last in-contact sample). {where} The 95 % intervals "
        "are a claim about where the link touches, so their coverage is judged against the "
        "contact abscissa. Errors against both, in mm, over every run with an estimate:",
        "",
        *_table(
            [
                "case",
                "method",
                "mean abs e, nominal (mm)",
                "max e, nominal (mm)",
                "mean abs e, contact (mm)",
                "max e, contact (mm)",
                "n (contact known)",
            ],
            table_rows,
        ),
        "",
    ]


def _statuses(counts: Mapping[str, int]) -> str:
    return ", ".join(f"{k} {v}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1])) or "-"


def _target_row(t: TargetSummary, default_noise: bool) -> list[str]:
    ratio = f"{t.delay_ratio:.2f}" if math.isfinite(t.delay_ratio) else "-"
    coverage = "-"
    if t.n_intervals:
        low, high = t.coverage_interval
        coverage = (
            f"{t.n_covering}/{t.n_intervals} ({100 * t.coverage:.0f} %, "
            f"{100 * low:.1f} to {100 * high:.1f} %)"
        )
    missed = t.missed(default_noise)
    mine, ref = t.errors, t.ref_errors
    return [
        t.label,
        str(t.n_runs),
        f"{_seconds(t.median_delay)} / {_seconds(t.ref_median_delay)}",
        ratio,
        f"{_mm(mine.contact.mae)} / {_mm(ref.contact.mae)}",
        f"{_mm(mine.contact.max)} / {_mm(ref.contact.max)}",
        f"{_mm(mine.nominal.mae)} / {_mm(ref.nominal.mae)}",
        f"{_mm(mine.nominal.max)} / {_mm(ref.nominal.max)}",
        coverage,
        str(t.n_ok_over_limit),
        _statuses(t.status_counts),
        "all met" if not missed else "missed: " + "; ".join(missed),
    ]


def _targets_section(
    spec: CampaignSpec, main: Sequence[Mapping[str, Any]], every: Sequence[Mapping[str, Any]]
) -> list[str]:
    """The fast method against the targets of issue 6, per case, overall and per noise level."""
    if "fast" not in spec.methods:
        return []
    reference = "paper"
    groups = [
        (f"{case} (main runs)", [r for r in main if r["case"] == case]) for case in spec.cases
    ]
    groups.append(("all main runs", list(main)))
    table = [_target_row(target_summary(g, label, "fast", reference), True) for label, g in groups]
    if spec.noise_sweep.enabled:
        for level in noise_levels(every, spec.noise_scale):
            selected = rows_at_level(every, level, spec.noise_scale)
            default = same_level(level, spec.noise_scale)
            label = f"noise {_level(level)}" + (" (main runs)" if default else "")
            table.append(_target_row(target_summary(selected, label, "fast", reference), default))
    low, high = COVERAGE_TARGET
    return [
        "## Fast method against the targets of issue 6",
        "",
        f"Each cell is fast / {reference} on the same recordings. Targets: median t_e - t_1 at "
        f"most {DELAY_RATIO_TARGET:.0%} of the paper method's; mean absolute and maximum error no "
        f"worse than the paper method's, and at most {_mm(MAE_TARGET, 0)} mm and "
        f"{_mm(MAX_ERROR_TARGET, 0)} mm at the default noise; the contact abscissa inside the "
        f"95 % interval in {low:.0%} to {high:.0%} of runs; no run reported ok with an error "
        f"over {_cm(OK_ERROR_LIMIT, 0)} cm. Errors over every run with an estimate (any status), "
        "in mm, against the contact abscissa (the targets) and the nominal x_c; coverage and the "
        "ok count against the contact abscissa, coverage with its exact 95 % confidence "
        "interval (Clopper-Pearson: what the run count alone leaves open). Computed from the "
        "stored runs.",
        "",
        *_table(
            [
                "runs",
                "n",
                "median t_e - t_1 (s)",
                "ratio",
                "MAE, contact (mm)",
                "max, contact (mm)",
                "MAE, nominal (mm)",
                "max, nominal (mm)",
                "coverage (contact)",
                f"ok with error > {_cm(OK_ERROR_LIMIT, 0)} cm",
                "fast statuses",
                "targets",
            ],
            table,
        ),
        "",
    ]


def _noise_section(
    spec: CampaignSpec,
    every: Sequence[Mapping[str, Any]],
    frequency: Sequence[FrequencyErrorSummary],
    figure: Path | None,
    out_dir: Path,
) -> list[str]:
    if not spec.noise_sweep.enabled:
        return []
    levels = noise_levels(every, spec.noise_scale)
    rows = []
    for level in levels:
        at_level = rows_at_level(every, level, spec.noise_scale)
        for method in spec.methods:
            mine = [r for r in at_level if r["method"] == method]
            errors = [abs(float_or_nan(r.get("error_contact_m"))) for r in mine]
            errors = [e for e in errors if math.isfinite(e)]
            delays = sorted(
                d
                for d in (float_or_nan(r["t_e_s"]) - float_or_nan(r["t_1_s"]) for r in mine)
                if math.isfinite(d)
            )
            n_ok = sum(1 for r in mine if r["status"] == "ok")
            rows.append(
                [
                    _level(level) + (" (main)" if same_level(level, spec.noise_scale) else ""),
                    method,
                    f"{len(errors)}/{len(mine)}",
                    _mm(sum(errors) / len(errors)) if errors else "-",
                    _mm(max(errors)) if errors else "-",
                    _seconds(statistics.median(delays)) if delays else "-",
                    str(n_ok),
                ]
            )
    frequency_rows = [
        [
            _level(f.noise_scale),
            f.method,
            str(f.n),
            f"{100 * f.rms_relative_error:.3f}",
            f"{100 * f.median_abs_relative_error:.3f}",
            "-"
            if not math.isfinite(f.median_relative_crb)
            else f"{100 * f.median_relative_crb:.4f}",
            "-" if not math.isfinite(f.median_relative_se) else f"{100 * f.median_relative_se:.4f}",
        ]
        for f in frequency
    ]
    sweep = spec.noise_sweep
    lines = [
        "## Noise sweep",
        "",
        f"Extra runs at sensor noise levels {', '.join(_level(x) for x in sweep.noise_scales)} "
        "(multiples of the simulator's nominal F/T noise and bias, `Scenario.noise_scale`): "
        f"cases {', '.join(spec.sweep_cases)}, contact points (cm) "
        f"{', '.join(_cm(x, 0) for x in spec.sweep_contact_points)}, {spec.sweep_repeats} "
        f"repeat(s), {spec.n_sweep_runs} runs, seeds on their own stream; every method estimates "
        f"the same recordings. The main runs count as level {_level(spec.noise_scale)} (with "
        "their own contact points and repeats, so that level has more runs). The tables and "
        "figures above use the main runs only. Errors against the contact abscissa, in mm:",
        "",
        *_table(
            [
                "noise",
                "method",
                "n",
                "mean abs e (mm)",
                "max e (mm)",
                "median t_e - t_1 (s)",
                "status ok",
            ],
            rows,
        ),
        "",
    ]
    if frequency_rows:
        lines += [
            "omega_1 against the device's contact-mode fundamental at each run's contact "
            "abscissa (`beam.natural_frequencies` of the device's link), relative, in %, over "
            "every run with an omega_1 (any status). CRB: median over runs of the Cramer-Rao "
            "bound of omega_1 the method reports for its own fit (`fast`: the window it declared "
            "on); SE: median of its reported standard error, which adds the drift check's term. "
            "For a fixed record the bound is proportional to the noise, but `fast` stops when "
            "sure, so its record lengthens with the noise and its bound stays nearly level; "
            "the error cannot fall below the model bias (the simulator's compliant contact and "
            "finite elements against the pinned-contact beam model, and the unmodelled modes "
            "of docs/fast.md); the paper method's 1 s spectrum has no bound reported here.",
            "",
            *_table(
                [
                    "noise",
                    "method",
                    "n",
                    "RMS rel. error (%)",
                    "median abs rel. error (%)",
                    "CRB (median, %)",
                    "SE (median, %)",
                ],
                frequency_rows,
            ),
            "",
        ]
    if figure is not None:
        lines += [f"![{figure.stem}]({figure.relative_to(out_dir).as_posix()})", ""]
    return lines


def _frequency_summaries(
    spec: CampaignSpec, every: Sequence[Mapping[str, Any]], device: Antenna
) -> list[FrequencyErrorSummary]:
    """omega_1 errors per noise level against the device's link; none without a noise sweep."""
    if not spec.noise_sweep.enabled:
        return []
    return frequency_error_summaries(every, device.link, spec.methods, spec.noise_scale)


def render_report(
    spec: CampaignSpec,
    antenna: Antenna,
    results: Sequence[RunResult],
    figures: Sequence[Path],
    out_dir: Path,
    device: Antenna | None = None,
    calibration: FrequencyCalibration | None = None,
    calibration_figure: Path | None = None,
    noise_figure: Path | None = None,
    frequency: Sequence[FrequencyErrorSummary] | None = None,
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
    noise_figure : Path, optional
        omega_1 error against the noise level (noise sweep).
    frequency : sequence of FrequencyErrorSummary, optional
        The noise sweep's omega_1 errors if already computed (for the figure); None: computed
        here.

    The method comparison, status counts, intervals, figures and the tables per case use the
    main runs only (the noise level of ``[scenario]``); the noise sweep has its own section.
    """
    device = device if device is not None else antenna
    every = campaign_rows(results, spec.methods)
    rows = main_rows(every, spec.noise_scale)
    summaries = method_summaries(rows, spec.cases, spec.methods)
    if frequency is None:
        frequency = _frequency_summaries(spec, every, device)
    n_failed = sum(1 for r in results if r.status == RUN_FAILED)
    obs = antenna.observer
    lines = [
        f"# Campaign {spec.name}",
        "",
        spec.description,
        "",
        f"- Runs stored: {len(results)} of {spec.n_runs}; failed: {n_failed}"
        + (
            f" ({spec.n_main_runs} main runs at noise {_level(spec.noise_scale)}, "
            f"{spec.n_sweep_runs} in the noise sweep)"
            if spec.noise_sweep.enabled
            else ""
        )
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
        *_calibration_section(calibration, spec, antenna, device, calibration_figure, out_dir),
        *_summary_section(spec, summaries, antenna.link.length),
        *_status_section(spec, summaries),
        *_truth_section(rows, summaries),
        *_interval_section(interval_summaries(rows, spec.cases, spec.methods)),
        *_targets_section(spec, rows, every),
        *_noise_section(spec, every, frequency, noise_figure, out_dir),
        "## Figures",
        "",
        "Main runs only (noise level of `[scenario]`).",
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
    every = campaign_rows(results, spec.methods)
    frequency = _frequency_summaries(spec, every, device)
    paths: list[Path] = []
    calibration_figure = None
    noise_figure = None
    if figures and calibration is not None:
        from sensing_antenna.plotting.calibration import plot_calibration

        calibration_figure = plot_calibration(calibration, antenna.link, directory / FIGURES_DIR)
    if figures and results:
        from sensing_antenna.plotting.campaign import plot_campaign

        rows = main_rows(every, spec.noise_scale)
        paths = plot_campaign(rows, spec.cases, spec.methods, antenna, directory / FIGURES_DIR)
        if frequency:
            from sensing_antenna.plotting.campaign import plot_frequency_error_vs_noise

            noise_figure = plot_frequency_error_vs_noise(frequency, directory / FIGURES_DIR)
    report = directory / REPORT_FILE
    text = render_report(
        spec,
        antenna,
        results,
        paths,
        directory,
        device,
        calibration,
        calibration_figure,
        noise_figure=noise_figure,
        frequency=frequency,
    )
    atomic_write_text(report, text)
    return report
