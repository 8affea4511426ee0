"""The campaign report: one Markdown file with tables and figures, rebuilt from the stored runs.

:func:`build_report` reads a campaign directory (see :mod:`~sensing_antenna.campaign.store`),
rewrites ``runs.csv``, draws the figures into ``figures/`` and writes ``report.md`` with relative
image links. Lengths are shown in cm (the display edge); everything stored stays SI.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from sensing_antenna.antenna import Antenna
from sensing_antenna.campaign.records import RUN_FAILED, RunResult
from sensing_antenna.campaign.spec import CampaignSpec
from sensing_antenna.campaign.store import (
    CSV_FILE,
    CampaignStoreError,
    atomic_write_text,
    load_run_results,
    read_manifest,
    read_stored_antenna,
    write_runs_csv,
)
from sensing_antenna.campaign.tables import (
    MethodSummary,
    campaign_rows,
    method_summaries,
    paper_row_at,
    paper_table,
    point_table,
)

__all__ = ["FIGURES_DIR", "REPORT_FILE", "build_report", "render_report"]

REPORT_FILE = "report.md"
FIGURES_DIR = "figures"

_CM = 100.0
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


def render_report(
    spec: CampaignSpec,
    antenna: Antenna,
    results: Sequence[RunResult],
    figures: Sequence[Path],
    out_dir: Path,
) -> str:
    """The Markdown text of the report (figure links relative to ``out_dir``)."""
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
        f"- Antenna: {antenna.name}; T used by the frequency model: {antenna.link.t_param:.4f} "
        f"s/m^2 (theoretical {antenna.link.theoretical_t:.4f})",
        f"- Free-motion observer (Eq. 15): gain {obs.gain:.4g} N m s^2/rad, omega "
        f"{obs.natural_frequency:.4g} rad/s, damping {obs.damping:.4g} 1/s, contact threshold "
        f"{obs.contact_threshold:.4g} N m"
        + (" (identified on a simulated free motion)" if spec.free_motion.identify else ""),
        "- Scenario: "
        + (", ".join(f"{k} = {v}" for k, v in sorted(spec.scenario.items())) or "defaults"),
        f"- Per-run results: [{CSV_FILE}]({CSV_FILE}) (SI units, one row per run and method)",
        "",
        "The recordings are simulated; the paper's numbers come from its real device, so the "
        "comparison shows whether the method behaves as reported, not a reproduction of the "
        "device.",
        "",
        *_summary_section(spec, summaries, antenna.link.length),
        *_status_section(spec, summaries),
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
    stored = load_run_results(directory)
    results = sorted(stored.values(), key=lambda r: r.index)
    write_runs_csv(directory / CSV_FILE, results, spec.methods)
    paths: list[Path] = []
    if figures and results:
        from sensing_antenna.plotting.campaign import plot_campaign

        rows = campaign_rows(results, spec.methods)
        paths = plot_campaign(rows, spec.cases, spec.methods, antenna, directory / FIGURES_DIR)
    report = directory / REPORT_FILE
    atomic_write_text(report, render_report(spec, antenna, results, paths, directory))
    return report
