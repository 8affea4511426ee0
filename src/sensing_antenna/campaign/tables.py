"""Tables of a campaign: per-point statistics in the layout of Tables 3 and 4, method summaries.

Statistics are computed in SI (m) over the runs where a method returned a finite estimate; the
columns follow the paper (Section 5.6): mean estimate, mean absolute error, maximum absolute
error and standard deviation of the (signed) error at each contact point. The paper's own tables
ship with the package (``data/paper-2021-table3-azimuthal.csv`` and
``data/paper-2021-table4-vertical.csv``, copied from Tables 3 and 4 of Feliu-Talegon et al.,
Sensors 2021) and are read by :func:`paper_table`.
"""

from __future__ import annotations

import csv
import io
import math
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.campaign.records import RunResult, result_rows

__all__ = [
    "PAPER_TABLE_FILES",
    "IntervalSummary",
    "MethodSummary",
    "PaperRow",
    "PointStats",
    "campaign_rows",
    "interval_summaries",
    "method_summaries",
    "paper_row_at",
    "paper_table",
    "point_table",
]

#: Package data files holding Tables 3 (Case 1, azimuthal) and 4 (Case 2, vertical) of the paper.
PAPER_TABLE_FILES = {
    "azimuthal": "data/paper-2021-table3-azimuthal.csv",
    "vertical": "data/paper-2021-table4-vertical.csv",
}

#: Contact points of the paper and of a campaign are matched to this tolerance (m): the paper
#: lists them in whole centimetres.
_POINT_MATCH_TOLERANCE = 1e-4


@dataclass(frozen=True)
class PointStats:
    """Statistics of one method at one contact point of one case (SI units: m).

    Attributes
    ----------
    x_c : float
        True contact point (m).
    n_runs : int
        Runs at this point (including failed ones and runs without an estimate).
    n_estimates : int
        Runs with a finite estimate; the statistics are over these.
    mean_estimate, mean_abs_error, max_error, std_error : float
        Mean estimate, mean |error|, max |error| and sample standard deviation (ddof = 1) of the
        signed error, all in m; NaN without estimates (std: with fewer than 2).
    """

    x_c: float
    n_runs: int
    n_estimates: int
    mean_estimate: float
    mean_abs_error: float
    max_error: float
    std_error: float


@dataclass(frozen=True)
class PaperRow:
    """One row of Table 3 or 4 of the paper, converted to SI (m)."""

    x_c: float
    mean_estimate: float
    mean_abs_error: float
    max_error: float
    std_error: float


@dataclass(frozen=True)
class MethodSummary:
    """One method over one case: error statistics (m) and how many runs ended in each status.

    Attributes
    ----------
    case, method : str
    n_runs : int
        Runs of this case.
    n_estimates : int
        Runs with a finite estimate.
    mean_abs_error, max_abs_error, rms_error : float
        Over all estimates of the case (m); NaN without estimates.
    status_counts : mapping of str to int
        Runs per status (the estimator's status, ``run-failed`` or ``error``).
    ok_mean_abs_error, ok_max_abs_error : float
        The same over the runs whose status is ``ok`` only (m); NaN without such runs.
    """

    case: str
    method: str
    n_runs: int
    n_estimates: int
    mean_abs_error: float
    max_abs_error: float
    rms_error: float
    status_counts: Mapping[str, int]
    ok_mean_abs_error: float = math.nan
    ok_max_abs_error: float = math.nan


@dataclass(frozen=True)
class IntervalSummary:
    """Per case and method: the 95 % intervals (if the method gives any) and the estimation time.

    Attributes
    ----------
    case, method : str
    n_intervals : int
        Runs with a finite interval.
    n_covering : int
        Of those, runs whose interval contains the true x_c.
    median_width : float
        Median interval width (m); NaN without intervals.
    n_timed : int
        Runs with finite t_1 and t_e.
    median_time_to_estimate : float
        Median of t_e - t_1 (s), how long after the push the estimate was available; NaN when
        never.
    """

    case: str
    method: str
    n_intervals: int
    n_covering: int
    median_width: float
    n_timed: int
    median_time_to_estimate: float

    @property
    def coverage(self) -> float:
        """Fraction of intervals containing the true x_c (dimensionless); NaN without any."""
        return self.n_covering / self.n_intervals if self.n_intervals else math.nan


def campaign_rows(results: Iterable[RunResult], methods: Sequence[str]) -> list[dict[str, Any]]:
    """Every run x method row (see :data:`~sensing_antenna.campaign.records.CSV_COLUMNS`)."""
    rows: list[dict[str, Any]] = []
    for result in sorted(results, key=lambda r: r.index):
        rows.extend(result_rows(result, methods))
    return rows


def _select(rows: Iterable[Mapping[str, Any]], case: str, method: str) -> list[Mapping[str, Any]]:
    return [r for r in rows if r["case"] == case and r["method"] == method]


def point_table(rows: Iterable[Mapping[str, Any]], case: str, method: str) -> list[PointStats]:
    """Per-contact-point statistics of ``method`` in ``case`` (Tables 3 and 4 layout), by x_c."""
    selected = _select(rows, case, method)
    points = sorted({float(r["x_c_true_m"]) for r in selected})
    table = []
    for x_c in points:
        at_point = [r for r in selected if float(r["x_c_true_m"]) == x_c]
        estimates = np.array([float(r["x_c_estimate_m"]) for r in at_point], dtype=float)
        estimates = estimates[np.isfinite(estimates)]
        errors = estimates - x_c
        n = estimates.size
        table.append(
            PointStats(
                x_c=x_c,
                n_runs=len(at_point),
                n_estimates=n,
                mean_estimate=float(np.mean(estimates)) if n else math.nan,
                mean_abs_error=float(np.mean(np.abs(errors))) if n else math.nan,
                max_error=float(np.max(np.abs(errors))) if n else math.nan,
                std_error=float(np.std(errors, ddof=1)) if n >= 2 else math.nan,
            )
        )
    return table


def method_summaries(
    rows: Iterable[Mapping[str, Any]], cases: Sequence[str], methods: Sequence[str]
) -> list[MethodSummary]:
    """One :class:`MethodSummary` per case and method, in the given order."""
    all_rows = list(rows)
    summaries = []
    for case in cases:
        for method in methods:
            selected = _select(all_rows, case, method)
            all_errors = np.array([float(r["error_m"]) for r in selected], dtype=float)
            is_ok = np.array([r["status"] == "ok" for r in selected], dtype=bool)
            errors = all_errors[np.isfinite(all_errors)]
            ok_errors = np.abs(all_errors[is_ok & np.isfinite(all_errors)])
            n = errors.size
            summaries.append(
                MethodSummary(
                    case=case,
                    method=method,
                    n_runs=len(selected),
                    n_estimates=n,
                    mean_abs_error=float(np.mean(np.abs(errors))) if n else math.nan,
                    max_abs_error=float(np.max(np.abs(errors))) if n else math.nan,
                    rms_error=float(np.sqrt(np.mean(errors**2))) if n else math.nan,
                    status_counts=dict(Counter(str(r["status"]) for r in selected)),
                    ok_mean_abs_error=float(np.mean(ok_errors)) if ok_errors.size else math.nan,
                    ok_max_abs_error=float(np.max(ok_errors)) if ok_errors.size else math.nan,
                )
            )
    return summaries


def _column(rows: Sequence[Mapping[str, Any]], name: str) -> NDArray[np.float64]:
    """One column as floats; a missing or empty cell is NaN."""
    values = []
    for row in rows:
        try:
            values.append(float(row.get(name, math.nan)))
        except (TypeError, ValueError):
            values.append(math.nan)
    return np.array(values, dtype=float)


def interval_summaries(
    rows: Iterable[Mapping[str, Any]], cases: Sequence[str], methods: Sequence[str]
) -> list[IntervalSummary]:
    """One :class:`IntervalSummary` per case and method, in the given order."""
    all_rows = list(rows)
    summaries = []
    for case in cases:
        for method in methods:
            selected = _select(all_rows, case, method)
            low = _column(selected, "interval_low_m")
            high = _column(selected, "interval_high_m")
            truth = _column(selected, "x_c_true_m")
            has = np.isfinite(low) & np.isfinite(high)
            covering = has & (low <= truth) & (truth <= high)
            delay = _column(selected, "t_e_s") - _column(selected, "t_1_s")
            delay = delay[np.isfinite(delay)]
            summaries.append(
                IntervalSummary(
                    case=case,
                    method=method,
                    n_intervals=int(has.sum()),
                    n_covering=int(covering.sum()),
                    median_width=float(np.median(high[has] - low[has])) if has.any() else math.nan,
                    n_timed=int(delay.size),
                    median_time_to_estimate=float(np.median(delay)) if delay.size else math.nan,
                )
            )
    return summaries


def paper_table(case: str) -> list[PaperRow]:
    """Table 3 (``"azimuthal"``) or Table 4 (``"vertical"``) of the paper, in m.

    Returns an empty list for a case the paper has no table for.
    """
    name = PAPER_TABLE_FILES.get(case)
    if name is None:
        return []
    text = resources.files("sensing_antenna").joinpath(name).read_text("utf-8")
    lines = [line for line in text.splitlines() if line and not line.startswith("#")]
    cm = 0.01
    rows = []
    for record in csv.DictReader(io.StringIO("\n".join(lines))):
        rows.append(
            PaperRow(
                x_c=float(record["xc"]) * cm,
                mean_estimate=float(record["mean_estimate"]) * cm,
                mean_abs_error=float(record["mean_abs_error"]) * cm,
                max_error=float(record["max_error"]) * cm,
                std_error=float(record["std_error"]) * cm,
            )
        )
    return rows


def paper_row_at(case: str, x_c: float) -> PaperRow | None:
    """The paper's row at contact point ``x_c`` (m), or None if the paper has none there."""
    for row in paper_table(case):
        if abs(row.x_c - x_c) <= _POINT_MATCH_TOLERANCE:
            return row
    return None
