"""The result sections of a campaign report, rendered from its summary as Markdown lines.

Formatting only: every number comes from :class:`~.summary.CampaignSummary`. Lengths are shown
in cm or mm and times in s (the display edge); everything computed stays SI.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

from sensing_antenna.accuracy import FrequencyErrorSummary
from sensing_antenna.campaign.schema import CampaignSpec, same_noise_level
from sensing_antenna.campaign.summary import CampaignSummary, FailedRun
from sensing_antenna.campaign.tables import (
    CaseTable,
    IntervalSummary,
    MethodSummary,
    NoiseLevelErrors,
)
from sensing_antenna.campaign.targets import (
    BOUND_RATIO_TARGET,
    COVERAGE_TARGET,
    DELAY_RATIO_TARGET,
    MAE_TARGET,
    MAX_ERROR_TARGET,
    OK_ERROR_LIMIT,
    Target,
    TargetSummary,
)

__all__ = [
    "bound_cells",
    "bound_sentence",
    "case_section",
    "cm",
    "failures_section",
    "figure_lines",
    "interval_section",
    "level",
    "markdown_table",
    "mm",
    "noise_section",
    "status_section",
    "summary_section",
    "targets_section",
    "truth_section",
]

_CASE_TITLES = {
    "azimuthal": "Case 1: azimuthal movement (Table 3 of the paper)",
    "vertical": "Case 2: vertical movement (Table 4 of the paper)",
}


def cm(value: float, digits: int = 2) -> str:
    """A length in m shown in cm; "-" when not finite."""
    return "-" if not math.isfinite(value) else f"{value * 100.0:.{digits}f}"


def mm(value: float, digits: int = 2) -> str:
    """A length in m shown in mm; "-" when not finite."""
    return "-" if not math.isfinite(value) else f"{value * 1000.0:.{digits}f}"


def _seconds(value: float) -> str:
    return "-" if not math.isfinite(value) else f"{value:.3f}"


def _percent(value: float, length: float) -> str:
    return "-" if not math.isfinite(value) else f"{100.0 * value / length:.1f} %"


def level(value: float) -> str:
    """A noise level as the report shows it."""
    return f"{value:g}"


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    """A Markdown table's lines."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines.extend("| " + " | ".join(row) + " |" for row in rows)
    return lines


def figure_lines(figure: Path, out_dir: Path) -> list[str]:
    """An image link relative to ``out_dir``, and a blank line."""
    return [f"![{figure.stem}]({figure.relative_to(out_dir).as_posix()})", ""]


def summary_section(spec: CampaignSpec, summary: CampaignSummary, length: float) -> list[str]:
    """Every method on both cases beside the paper's overall numbers."""
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
            s = summary.method_summary(case, method)
            row += [
                f"{cm(s.mean_abs_error)} ({_percent(s.mean_abs_error, length)})",
                f"{cm(s.max_abs_error)} ({_percent(s.max_abs_error, length)})",
                f"{s.n_estimates}/{s.n_runs}",
                f"{cm(s.ok_mean_abs_error)} / {cm(s.ok_max_abs_error)}, "
                f"{s.status_counts.get('ok', 0)}",
            ]
        rows.append(row)
    paper_row = ["paper, real device (Tables 3, 4)"]
    for paper in summary.paper_overall:
        mean, worst = paper.mean_abs_error, paper.max_error
        paper_row += [
            f"{cm(mean)} ({_percent(mean, length)})",
            f"{cm(worst)} ({_percent(worst, length)})",
            str(paper.n_runs) if paper.n_runs else "-",
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
        *markdown_table(header, rows),
        "",
    ]


def status_section(summaries: Sequence[MethodSummary]) -> list[str]:
    """Runs per status, per case and method."""
    statuses = sorted({k for s in summaries for k in s.status_counts})
    rows = [
        [s.case, s.method, *[str(s.status_counts.get(k, 0)) for k in statuses]] for s in summaries
    ]
    return [
        "## Status counts",
        "",
        "How many runs ended in each status (``run-failed``: the simulation itself failed; "
        "``error``: the estimator raised).",
        "",
        *markdown_table(["case", "method", *statuses], rows),
        "",
    ]


def truth_section(summary: CampaignSummary) -> list[str]:
    """Errors against the nominal x_c and against the contact abscissa, side by side."""
    offset = summary.contact_offset
    if offset.n:
        where = (
            f"On the {offset.n} main runs with a known contact abscissa it lies "
            f"{mm(abs(offset.median))} mm "
            f"{'nearer the base than' if offset.median < 0 else 'beyond'} the "
            f"nominal x_c (median; from {mm(offset.low)} to {mm(offset.high)} mm)."
        )
    else:
        where = "No stored run records its contact abscissa."
    rows = [
        [
            s.case,
            s.method,
            mm(s.mean_abs_error),
            mm(s.max_abs_error),
            mm(s.contact_mean_abs_error),
            mm(s.contact_max_abs_error),
            f"{s.n_contact}/{s.n_runs}",
            mm(s.point_mean_error),
            mm(s.point_max_error),
        ]
        for s in summary.methods
    ]
    return [
        "## Nominal x_c and the contact abscissa",
        "",
        "The tables above and the per-case tables in the layout of Tables 3 and 4 measure errors "
        "against the **nominal x_c** (where the undeflected link meets the obstacle), as the "
        "paper did. The link actually touches at the **contact abscissa** the simulator reports "
        f"(ground truth `true_xc`, at the last in-contact sample). {where} The 95 % intervals "
        "are a claim about where the link touches, so their coverage is judged against the "
        "contact abscissa. Errors against both, in mm, over every run with an estimate; and "
        "the distance from the estimated touched point in 3D (the abscissa along the link at "
        "the motor angles of the instant the point describes, bent by the push and sagged by "
        "the weight, on the link's surface) to where the link touched at that instant (ground "
        "truth: the recording's contact track at the estimate's `t_point`):",
        "",
        *markdown_table(
            [
                "case",
                "method",
                "mean abs e, nominal (mm)",
                "max abs e, nominal (mm)",
                "mean abs e, contact (mm)",
                "max abs e, contact (mm)",
                "n (contact known)",
                "mean 3D e (mm)",
                "max 3D e (mm)",
            ],
            rows,
        ),
        "",
    ]


def _join(names: Sequence[str]) -> str:
    return ", ".join(names[:-1]) + " and " + names[-1] if len(names) > 1 else names[0]


def interval_section(summaries: Sequence[IntervalSummary]) -> list[str]:
    """Time to the estimate and the coverage and width of the 95 % intervals.

    A method without intervals whose t_e - t_1 is the same in every run has no row: the
    sentence above the table gives its fixed delay instead (a column of equal numbers says
    nothing about the method); likewise a method with neither times nor intervals.
    """
    shown = [s for s in summaries if s.n_intervals or (s.n_timed and not s.fixed_delay)]
    fixed: dict[str, list[str]] = {}
    for s in summaries:
        if s in shown:
            continue
        key = f"{s.median_time_to_estimate:.3f}" if s.n_timed else ""
        if s.method not in fixed.setdefault(key, []):
            fixed[key].append(s.method)
    notes = []
    for delay, methods in fixed.items():
        if delay:
            notes.append(
                f"{_join(methods)} conclude{'s' if len(methods) == 1 else ''} {delay} s after "
                "the push in every run (t_e - t_1 is fixed: the end of the spectrum window, "
                "`EstimatorConfig.spectrum_window`) and give no interval, so the table has no "
                "row for them."
            )
        else:
            notes.append(f"{_join(methods)}: no t_1, t_e or interval recorded.")
    rows = []
    for s in shown:
        coverage = (
            f"{s.n_covering}/{s.n_intervals} ({100 * s.coverage:.0f} %)" if s.n_intervals else "-"
        )
        nominal = (
            f"{s.n_covering_nominal}/{s.n_intervals} ({100 * s.coverage_nominal:.0f} %)"
            if s.n_intervals
            else "-"
        )
        width = cm(s.median_width) if s.n_intervals else "-"
        rows.append(
            [s.case, s.method, _seconds(s.median_time_to_estimate), coverage, nominal, width]
        )
    judged_nominal = sum(s.n_judged_nominal for s in summaries)
    note = (
        f" {judged_nominal} interval(s) of runs without a known contact abscissa are judged "
        "against the nominal x_c instead."
        if judged_nominal
        else ""
    )
    lines = [
        "## Time to estimate and uncertainty",
        "",
        "Median time from the push (t_1) to the estimate (t_e), and, for methods that give a 95 % "
        "interval of x_c, how often it contains the contact abscissa (where the link touches: "
        "the interval is a claim about that point) and, for comparison, the nominal x_c; and "
        f"its median width.{note}",
        "",
    ]
    if notes:
        lines += [" ".join(notes), ""]
    if rows:
        lines += [
            *markdown_table(
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
    return lines


def _statuses(counts: Mapping[str, int]) -> str:
    return ", ".join(f"{k} {v}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1])) or "-"


#: How each missed target reads in the report.
_TARGET_TEXT = {
    Target.DELAY_RATIO: f"t_e ratio > {DELAY_RATIO_TARGET:g}",
    Target.BOUND_RATIO: f"t_e > {BOUND_RATIO_TARGET:g} x bound",
    Target.MAE: f"MAE > {MAE_TARGET * 1e3:g} mm",
    Target.MAE_VS_REFERENCE: "MAE > paper's",
    Target.MAX: f"max > {MAX_ERROR_TARGET * 1e3:g} mm",
    Target.MAX_VS_REFERENCE: "max > paper's",
    Target.COVERAGE: f"coverage outside {COVERAGE_TARGET[0]:.0%}-{COVERAGE_TARGET[1]:.0%}",
    Target.OK_OVER_LIMIT: f"ok with error > {OK_ERROR_LIMIT * 100:g} cm",
}


def _target_label(t: TargetSummary) -> str:
    if t.case is not None:
        return f"{t.case} (main runs)"
    if t.noise_scale is None:
        return "all main runs"
    return f"noise {level(t.noise_scale)}" + (" (main runs)" if t.at_main_level else "")


def _ratio(value: float) -> str:
    return f"{value:.2f}" if math.isfinite(value) else "-"


def _bound(t: TargetSummary) -> str:
    """The median information bound (s), with the runs counted at the cap."""
    if not math.isfinite(t.median_bound):
        return "-"
    return _seconds(t.median_bound) + (f" ({t.n_bound_at_cap} at cap)" if t.n_bound_at_cap else "")


def _bound_judged(t: TargetSummary) -> str:
    """Whether the bound target is met ("met", "missed"; "-" without a bound)."""
    if not math.isfinite(t.bound_ratio):
        return "-"
    return "met" if t.bound_ratio <= BOUND_RATIO_TARGET else "missed"


def bound_sentence(t: TargetSummary) -> str:
    """The method's median t_e - t_1 against its median information bound, and the target."""
    if not math.isfinite(t.bound_ratio):
        return (
            "no bound: not computed on these runs (`fast_bound = false`), or no window of any "
            f"run qualified before the cap; the target ({BOUND_RATIO_TARGET:g}) is not judged."
        )
    at_cap = (
        f", {t.n_bound_at_cap} of {t.n_runs} runs counted at the cap" if t.n_bound_at_cap else ""
    )
    return (
        f"median t_e - t_1 {_seconds(t.median_delay)} s against a median information bound of "
        f"{_seconds(t.median_bound)} s{at_cap}: {t.bound_ratio:.2f} times it, target at most "
        f"{BOUND_RATIO_TARGET:g}: **{_bound_judged(t)}**."
    )


def bound_cells(t: TargetSummary) -> list[str]:
    """The method's median t_e - t_1 (s), its median information bound (s), their ratio and
    whether the target is met ("-" without a bound)."""
    return [_seconds(t.median_delay), _bound(t), _ratio(t.bound_ratio), _bound_judged(t)]


def _target_row(t: TargetSummary) -> list[str]:
    ratio = _ratio(t.delay_ratio)
    coverage = "-"
    if t.n_intervals:
        low, high = t.coverage_interval
        coverage = (
            f"{t.n_covering}/{t.n_intervals} ({100 * t.coverage:.0f} %, "
            f"{100 * low:.1f} to {100 * high:.1f} %)"
        )
    missed = [_TARGET_TEXT[target] for target in t.missed]
    mine, ref = t.errors, t.ref_errors
    return [
        _target_label(t),
        str(t.n_runs),
        f"{_seconds(t.median_delay)} / {_seconds(t.ref_median_delay)}",
        ratio,
        _bound(t),
        _ratio(t.bound_ratio),
        f"{mm(mine.contact.mae)} / {mm(ref.contact.mae)}",
        f"{mm(mine.contact.max)} / {mm(ref.contact.max)}",
        f"{mm(mine.nominal.mae)} / {mm(ref.nominal.mae)}",
        f"{mm(mine.nominal.max)} / {mm(ref.nominal.max)}",
        coverage,
        str(t.n_ok_over_limit),
        _statuses(t.status_counts),
        "all met" if not missed else "missed: " + "; ".join(missed),
    ]


def targets_section(targets: Sequence[TargetSummary]) -> list[str]:
    """The fast method against its targets, per case, overall and per noise level, and its
    delay against the information bound over all main runs."""
    if not targets:
        return []
    low, high = COVERAGE_TARGET
    overall = next(t for t in targets if t.case is None and t.noise_scale is None)
    return [
        "## Fast method against its targets",
        "",
        "Each cell is fast / paper on the same recordings. Targets: median t_e - t_1 at "
        f"most {DELAY_RATIO_TARGET:.0%} of the paper method's, and at most "
        f"{BOUND_RATIO_TARGET:g} times the median information bound of the method's own model "
        "(docs/fast.md: the first window whose 95 % interval would be within the tolerance with "
        "omega_1's standard error at its Cramer-Rao bound and no model floors, every other check "
        "ignored; a run where no window qualifies before the cap counts at the cap, and the "
        "bound column says how many did); mean absolute and maximum error no "
        f"worse than the paper method's, and at most {mm(MAE_TARGET, 0)} mm and "
        f"{mm(MAX_ERROR_TARGET, 0)} mm at the default noise; the contact abscissa inside the "
        f"95 % interval in {low:.0%} to {high:.0%} of runs; no run reported ok with an error "
        f"over {cm(OK_ERROR_LIMIT, 0)} cm. Errors over every run with an estimate (any status), "
        "in mm, against the contact abscissa (the targets) and the nominal x_c; coverage and the "
        "ok count against the contact abscissa, coverage with its exact 95 % confidence "
        "interval (Clopper-Pearson: what the run count alone leaves open). Computed from the "
        "stored runs.",
        "",
        *markdown_table(
            [
                "runs",
                "n",
                "median t_e - t_1 (s)",
                "ratio",
                "median bound (s)",
                "t_e / bound",
                "MAE, contact (mm)",
                "max, contact (mm)",
                "MAE, nominal (mm)",
                "max, nominal (mm)",
                "coverage (contact)",
                f"ok with error > {cm(OK_ERROR_LIMIT, 0)} cm",
                "fast statuses",
                "targets",
            ],
            [_target_row(t) for t in targets],
        ),
        "",
        "Against the information bound, all main runs: " + bound_sentence(overall),
        "",
    ]


def _noise_row(n: NoiseLevelErrors, main: float, with_delay: bool) -> list[str]:
    return [
        level(n.noise_scale) + (" (main)" if same_noise_level(n.noise_scale, main) else ""),
        n.method,
        f"{n.n_estimates}/{n.n_runs}",
        mm(n.mean_abs_error),
        mm(n.max_abs_error),
        *([_seconds(n.median_delay)] if with_delay else []),
        _statuses(n.status_counts),
    ]


def _frequency_row(f: FrequencyErrorSummary, with_bounds: bool) -> list[str]:
    def percent(value: float, digits: int) -> str:
        return "-" if not math.isfinite(value) else f"{100 * value:.{digits}f}"

    bounds = [percent(f.median_relative_crb, 4), percent(f.median_relative_se, 4)]
    return [
        level(f.noise_scale),
        f.method,
        str(f.n),
        percent(f.rms_relative_error, 3),
        percent(f.median_abs_relative_error, 3),
        *(bounds if with_bounds else []),
    ]


def noise_section(
    spec: CampaignSpec, summary: CampaignSummary, figure: Path | None, out_dir: Path
) -> list[str]:
    """The noise sweep: every method's error per level, and omega_1 against the truth.

    The statuses of each row say why runs have no estimate (e.g. ``push_not_reached``). The
    t_e - t_1 column is left out when every run of every method has the same delay (then a
    sentence gives it), and the bound columns when no method reports a Cramer-Rao bound or
    standard error.
    """
    if not spec.noise_sweep.enabled:
        return []
    sweep = spec.noise_sweep
    timed = [n for n in summary.noise if math.isfinite(n.median_delay)]
    delays = {f"{n.median_delay:.3f}" for n in timed}
    with_delay = bool(timed) and not (all(n.fixed_delay for n in timed) and len(delays) == 1)
    delay_note = (
        f" t_e - t_1 is {delays.pop()} s in every run of every method (a fixed time after the "
        "push: the end of the spectrum window, `EstimatorConfig.spectrum_window`), so it has "
        "no column."
        if timed and not with_delay
        else ""
    )
    lines = [
        "## Noise sweep",
        "",
        f"Extra runs at sensor noise levels {', '.join(level(x) for x in sweep.noise_scales)} "
        "(multiples of the simulator's nominal F/T noise and bias, `Scenario.noise_scale`): "
        f"cases {', '.join(spec.sweep_cases)}, contact points (cm) "
        f"{', '.join(cm(x, 0) for x in spec.sweep_contact_points)}, {spec.sweep_repeats} "
        f"repeat(s), {spec.n_sweep_runs} runs, seeds on their own stream; every method estimates "
        f"the same recordings. The main runs count as level {level(spec.noise_scale)} (with "
        "their own contact points and repeats, so that level has more runs). The tables and "
        "figures above use the main runs only. Errors against the contact abscissa, in mm, over "
        "the runs with an estimate (n: runs with an estimate / runs); the statuses say what "
        f"became of every run, those without an estimate included.{delay_note}",
        "",
        *markdown_table(
            [
                "noise",
                "method",
                "n",
                "mean abs e (mm)",
                "max abs e (mm)",
                *(["median t_e - t_1 (s)"] if with_delay else []),
                "statuses",
            ],
            [_noise_row(n, spec.noise_scale, with_delay) for n in summary.noise],
        ),
        "",
    ]
    if summary.frequency:
        with_bounds = any(
            math.isfinite(f.median_relative_crb) or math.isfinite(f.median_relative_se)
            for f in summary.frequency
        )
        bounds_text = (
            "CRB: median over runs of the Cramer-Rao bound of omega_1 the method reports for its "
            "own fit (`fast`: the window it declared on); SE: median of its reported standard "
            "error, which adds the drift check's term. For a fixed record the bound is "
            "proportional to the noise, but `fast` stops when sure, so its record lengthens "
            "with the noise and its bound stays nearly level; the error cannot fall below the "
            "model bias (the simulator's compliant contact against the pin, the push's bend, "
            "and the unmodelled modes of docs/fast.md); the paper method's 1 s spectrum has no "
            "bound reported here."
            if with_bounds
            else "None of these methods reports a Cramer-Rao bound or a standard error of "
            "omega_1 (`fast` does), so there are no bound columns; the error cannot fall below "
            "the model bias (the simulator's compliant contact against the pin, the push's "
            "bend)."
        )
        lines += [
            "omega_1 against the device's contact-mode fundamental at each run's contact "
            "abscissa (the simulator's finite-element model of the device's link, with the tip "
            "mass, clamp, taper and joint of its build, pinned there), relative, in %, over "
            f"every run with an omega_1 (any status). {bounds_text}",
            "",
            *markdown_table(
                [
                    "noise",
                    "method",
                    "n",
                    "RMS rel. error (%)",
                    "median abs rel. error (%)",
                    *(["CRB (median, %)", "SE (median, %)"] if with_bounds else []),
                ],
                [_frequency_row(f, with_bounds) for f in summary.frequency],
            ),
            "",
        ]
    if figure is not None:
        lines += figure_lines(figure, out_dir)
    return lines


def case_section(table: CaseTable) -> list[str]:
    """One case in the layout of Tables 3 and 4, the paper's values and the baselines beside."""
    header = [
        "x_c (cm)",
        "mean x_c,e",
        "mean abs e",
        "max abs e",
        "std e",
        "paper: mean x_c,e",
        "paper: mean abs e",
        "paper: max abs e",
        "paper: std e",
        *[f"{m}: mean abs e" for m in table.baselines],
        "n",
    ]
    lines = []
    for row in table.rows:
        p, paper = row.ours, row.paper
        paper_cells = (
            [
                cm(paper.mean_estimate, 1),
                cm(paper.mean_abs_error, 1),
                cm(paper.max_error, 1),
                cm(paper.std_error, 2),
            ]
            if paper
            else ["-"] * 4
        )
        lines.append(
            [
                cm(p.x_c, 0),
                cm(p.mean_estimate),
                cm(p.mean_abs_error),
                cm(p.max_error),
                cm(p.std_error),
                *paper_cells,
                *[cm(value) for value in row.baseline_mean_abs_error],
                f"{p.n_estimates}/{p.n_runs}",
            ]
        )
    return [
        f"## {_CASE_TITLES.get(table.case, table.case)}",
        "",
        f"Method **{table.method}**, all values in cm; e = x_c,e - x_c; max abs e is the largest "
        "|e| (the paper's e_max); std with ddof = 1. The paper's numbers are from the real "
        "device (5 experiments per point).",
        "",
        *markdown_table(header, lines),
        "",
    ]


def failures_section(failed: Sequence[FailedRun]) -> list[str]:
    """The runs whose simulation raised, with their seeds and errors."""
    if not failed:
        return []
    rows = [[r.run_id, str(r.seed), r.error.replace("|", "/")] for r in failed]
    return ["## Failed runs", "", *markdown_table(["run", "seed", "error"], rows), ""]
