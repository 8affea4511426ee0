"""Tables of a campaign, computed from its rows: per point (Tables 3 and 4), per method, per level.

Every function takes :class:`~sensing_antenna.campaign.records.CampaignRow` objects and returns
typed summaries in SI (m, s, rad/s). Statistics are over the runs where a method returned a
finite value; the per-point columns follow the paper (Section 5.6): mean estimate, mean absolute
error, maximum absolute error and standard deviation of the signed error. The paper's own tables
ship with the package (``data/paper-2021-table3-azimuthal.csv`` and
``data/paper-2021-table4-vertical.csv``, copied from Tables 3 and 4 of Mérida-Calvo,
Feliu-Talegón and Feliu-Batlle, Sensors 2021) and are read by :func:`paper_table`.
"""

from __future__ import annotations

import csv
import io
import math
import statistics
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from importlib import resources

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.accuracy import FrequencyErrorSummary, PointStats, PointTable, RunPoints
from sensing_antenna.antenna import Link
from sensing_antenna.campaign.records import CampaignRow
from sensing_antenna.campaign.schema import noise_level_key, same_noise_level
from sensing_antenna.simulator.device import DeviceImperfections
from sensing_antenna.simulator.scenario import N_ELEMENTS

__all__ = [
    "FIXED_DELAY_TOLERANCE",
    "PAPER_EXPERIMENTS_PER_POINT",
    "PAPER_TABLE_FILES",
    "CaseRow",
    "CaseTable",
    "ContactOffset",
    "IntervalSummary",
    "MethodSummary",
    "NoiseLevelErrors",
    "PaperOverall",
    "case_table",
    "contact_offset",
    "frequency_error_summaries",
    "interval_summaries",
    "main_rows",
    "method_summaries",
    "noise_level_errors",
    "noise_levels",
    "paper_overall",
    "paper_row_at",
    "paper_table",
    "point_table",
    "rows_at_level",
    "run_points",
    "select",
    "truth",
]

#: Package data files holding Tables 3 (Case 1, azimuthal) and 4 (Case 2, vertical) of the paper.
PAPER_TABLE_FILES = {
    "azimuthal": "data/paper-2021-table3-azimuthal.csv",
    "vertical": "data/paper-2021-table4-vertical.csv",
}
#: Experiments per contact point behind the paper's Tables 3 and 4 (Section 5.6).
PAPER_EXPERIMENTS_PER_POINT = 5

#: Contact points of the paper and of a campaign are matched to this tolerance (m): the paper
#: lists them in whole centimetres.
_POINT_MATCH_TOLERANCE = 1e-4

#: Delays t_e - t_1 of one method that differ by less than this (s) are one fixed delay: a
#: method that concludes a fixed time after the push. A microsecond, far below the 1 ms sample
#: period and far above the round-off of a difference of two times.
FIXED_DELAY_TOLERANCE = 1e-6


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
        Over all estimates of the case, against the nominal x_c (m); NaN without estimates.
    status_counts : mapping of str to int
        Runs per status (the estimator's status, ``run-failed`` or ``error``).
    ok_mean_abs_error, ok_max_abs_error : float
        The same over the runs whose status is ``ok`` only (m); NaN without such runs.
    contact_mean_abs_error, contact_max_abs_error : float
        Mean and max |estimate - contact abscissa| (m) over the runs whose contact abscissa is
        known; NaN without any.
    n_contact : int
        Runs with a finite estimate and a known contact abscissa.
    point_mean_error, point_max_error : float
        Mean and max distance (m) from the estimated touched point in 3D to where the link
        touched, over the runs with both; NaN without any.
    n_point : int
        Runs with both points known.
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
    contact_mean_abs_error: float = math.nan
    contact_max_abs_error: float = math.nan
    n_contact: int = 0
    point_mean_error: float = math.nan
    point_max_error: float = math.nan
    n_point: int = 0


@dataclass(frozen=True)
class IntervalSummary:
    """Per case and method: the 95 % intervals (if the method gives any) and the estimation time.

    Attributes
    ----------
    case, method : str
    n_intervals : int
        Runs with a finite interval.
    n_covering : int
        Of those, runs whose interval contains where the link touched (the contact abscissa; the
        nominal x_c for runs without one, counted in ``n_judged_nominal``).
    median_width : float
        Median interval width (m); NaN without intervals.
    n_timed : int
        Runs with finite t_1 and t_e.
    median_time_to_estimate : float
        Median of t_e - t_1 (s), how long after the push the estimate was available; NaN when
        never.
    n_judged_nominal : int
        Intervals of runs without a known contact abscissa.
    n_covering_nominal : int
        Intervals containing the nominal x_c.
    shortest_time_to_estimate, longest_time_to_estimate : float
        Smallest and largest t_e - t_1 (s); NaN when never timed.
    """

    case: str
    method: str
    n_intervals: int
    n_covering: int
    median_width: float
    n_timed: int
    median_time_to_estimate: float
    n_judged_nominal: int = 0
    n_covering_nominal: int = 0
    shortest_time_to_estimate: float = math.nan
    longest_time_to_estimate: float = math.nan

    @property
    def fixed_delay(self) -> bool:
        """Whether every timed run has the same t_e - t_1 (:data:`FIXED_DELAY_TOLERANCE`)."""
        spread = self.longest_time_to_estimate - self.shortest_time_to_estimate
        return self.n_timed > 0 and spread <= FIXED_DELAY_TOLERANCE

    @property
    def coverage(self) -> float:
        """Fraction of intervals containing the contact abscissa (dimensionless); NaN if none."""
        return self.n_covering / self.n_intervals if self.n_intervals else math.nan

    @property
    def coverage_nominal(self) -> float:
        """Fraction of intervals containing the nominal x_c (dimensionless); NaN if none."""
        return self.n_covering_nominal / self.n_intervals if self.n_intervals else math.nan


@dataclass(frozen=True)
class NoiseLevelErrors:
    """One method at one noise level: |estimate - contact abscissa| (m), delay (s), statuses.

    Attributes
    ----------
    noise_scale : float
    method : str
    n_runs : int
        Runs at this level.
    n_estimates : int
        Runs with a finite error against a known contact abscissa.
    mean_abs_error, max_abs_error : float
        Over those (m); NaN without any.
    median_delay : float
        Median t_e - t_1 (s); NaN when never timed.
    n_ok : int
        Runs with status ``ok``.
    status_counts : mapping of str to int
        Runs per status (the estimator's, ``run-failed`` or ``error``): why runs have no
        estimate, e.g. ``push_not_reached``.
    fixed_delay : bool
        Whether every timed run has the same t_e - t_1 (:data:`FIXED_DELAY_TOLERANCE`).
    """

    noise_scale: float
    method: str
    n_runs: int
    n_estimates: int
    mean_abs_error: float
    max_abs_error: float
    median_delay: float
    n_ok: int
    status_counts: Mapping[str, int] = field(default_factory=dict)
    fixed_delay: bool = False


@dataclass(frozen=True)
class ContactOffset:
    """Contact abscissa minus nominal x_c over the runs that know it (m); NaN without any.

    Attributes
    ----------
    n : int
        Runs with a known contact abscissa.
    median, low, high : float
        Median, smallest and largest offset (m).
    """

    n: int
    median: float
    low: float
    high: float


@dataclass(frozen=True)
class PaperOverall:
    """The paper's overall figures for one case (m): mean of its per-point mean |error| (equal
    runs per point) and its largest maximum error; ``n_runs`` experiments in all."""

    case: str
    mean_abs_error: float
    max_error: float
    n_runs: int


@dataclass(frozen=True)
class CaseRow:
    """One contact point of a case table: the main method's statistics, the paper's at that
    point (None where it has none) and each baseline's mean |error| (m; NaN without)."""

    ours: PointStats
    paper: PointStats | None
    baseline_mean_abs_error: tuple[float, ...]


@dataclass(frozen=True)
class CaseTable:
    """A case in the layout of Tables 3 and 4: ``method`` per point, beside the paper and the
    ``baselines`` (in the order of ``CaseRow.baseline_mean_abs_error``)."""

    case: str
    method: str
    baselines: tuple[str, ...]
    rows: tuple[CaseRow, ...]


def select(
    rows: Iterable[CampaignRow], case: str | None = None, method: str | None = None
) -> list[CampaignRow]:
    """The rows of ``case`` and ``method`` (None: any)."""
    return [
        r
        for r in rows
        if (case is None or r.case == case) and (method is None or r.method == method)
    ]


def _level(row: CampaignRow, main: float) -> float:
    """The row's noise level; ``main`` for a row without one."""
    return row.noise_scale if math.isfinite(row.noise_scale) else main


def rows_at_level(rows: Iterable[CampaignRow], level: float, main: float) -> list[CampaignRow]:
    """The rows at noise ``level`` (to 0.01); a row without a level counts as ``main``."""
    return [row for row in rows if same_noise_level(_level(row, main), level)]


def main_rows(rows: Iterable[CampaignRow], noise_scale: float) -> list[CampaignRow]:
    """The rows of the main runs: those at ``noise_scale`` (the ``[scenario]`` level).

    A row without a noise level (its run file did not record one) is a main run.
    """
    return rows_at_level(rows, noise_scale, noise_scale)


def noise_levels(rows: Iterable[CampaignRow], main: float) -> list[float]:
    """Distinct noise levels of the rows, ascending; a row without one counts as ``main``."""
    levels: dict[int, float] = {}
    for row in rows:
        level = _level(row, main)
        levels.setdefault(noise_level_key(level), level)
    return [levels[k] for k in sorted(levels)]


def _column(rows: Sequence[CampaignRow], name: str) -> NDArray[np.float64]:
    """One float field of the rows, shape (n_rows,)."""
    return np.array([getattr(row, name) for row in rows], dtype=float)


def _stats(x_c: float, n_runs: int, estimates: NDArray[np.float64]) -> PointStats:
    estimates = estimates[np.isfinite(estimates)]
    errors = estimates - x_c
    n = estimates.size
    return PointStats(
        x_c=x_c,
        n_runs=n_runs,
        n_estimates=n,
        mean_estimate=float(np.mean(estimates)) if n else math.nan,
        mean_abs_error=float(np.mean(np.abs(errors))) if n else math.nan,
        max_error=float(np.max(np.abs(errors))) if n else math.nan,
        std_error=float(np.std(errors, ddof=1)) if n >= 2 else math.nan,
    )


def point_table(rows: Iterable[CampaignRow], case: str, method: str) -> PointTable:
    """Per-contact-point statistics of ``method`` in ``case`` (Tables 3 and 4 layout), by x_c."""
    selected = select(rows, case, method)
    points = sorted({r.x_c_true_m for r in selected})
    table = []
    for x_c in points:
        at_point = [r for r in selected if r.x_c_true_m == x_c]
        table.append(_stats(x_c, len(at_point), _column(at_point, "x_c_estimate_m")))
    return PointTable(case=case, method=method, points=tuple(table))


def method_summaries(
    rows: Iterable[CampaignRow], cases: Sequence[str], methods: Sequence[str]
) -> list[MethodSummary]:
    """One :class:`MethodSummary` per case and method, in the given order."""
    all_rows = list(rows)
    summaries = []
    for case in cases:
        for method in methods:
            selected = select(all_rows, case, method)
            all_errors = _column(selected, "error_m")
            is_ok = np.array([r.status == "ok" for r in selected], dtype=bool)
            errors = all_errors[np.isfinite(all_errors)]
            ok_errors = np.abs(all_errors[is_ok & np.isfinite(all_errors)])
            contact = np.abs(_column(selected, "error_contact_m"))
            contact = contact[np.isfinite(contact)]
            point = _column(selected, "point_error_m")
            point = point[np.isfinite(point)]
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
                    status_counts=dict(Counter(r.status for r in selected)),
                    ok_mean_abs_error=float(np.mean(ok_errors)) if ok_errors.size else math.nan,
                    ok_max_abs_error=float(np.max(ok_errors)) if ok_errors.size else math.nan,
                    contact_mean_abs_error=float(np.mean(contact)) if contact.size else math.nan,
                    contact_max_abs_error=float(np.max(contact)) if contact.size else math.nan,
                    n_contact=int(contact.size),
                    point_mean_error=float(np.mean(point)) if point.size else math.nan,
                    point_max_error=float(np.max(point)) if point.size else math.nan,
                    n_point=int(point.size),
                )
            )
    return summaries


def truth(rows: Sequence[CampaignRow]) -> NDArray[np.float64]:
    """Where each run's link touched (m): the contact abscissa, the nominal x_c when unknown."""
    return np.array([row.truth_m for row in rows], dtype=float)


def interval_summaries(
    rows: Iterable[CampaignRow], cases: Sequence[str], methods: Sequence[str]
) -> list[IntervalSummary]:
    """One :class:`IntervalSummary` per case and method, in the given order."""
    all_rows = list(rows)
    summaries = []
    for case in cases:
        for method in methods:
            selected = select(all_rows, case, method)
            low = _column(selected, "interval_low_m")
            high = _column(selected, "interval_high_m")
            nominal = _column(selected, "x_c_true_m")
            contact = _column(selected, "x_c_contact_m")
            touched = truth(selected)
            has = np.isfinite(low) & np.isfinite(high)
            covering = has & (low <= touched) & (touched <= high)
            covering_nominal = has & (low <= nominal) & (nominal <= high)
            delay = _column(selected, "t_e_s") - _column(selected, "t_1_s")
            delay = delay[np.isfinite(delay)]
            timed = delay.size > 0
            summaries.append(
                IntervalSummary(
                    case=case,
                    method=method,
                    n_intervals=int(has.sum()),
                    n_covering=int(covering.sum()),
                    median_width=float(np.median(high[has] - low[has])) if has.any() else math.nan,
                    n_timed=int(delay.size),
                    median_time_to_estimate=float(np.median(delay)) if delay.size else math.nan,
                    n_judged_nominal=int((has & ~np.isfinite(contact)).sum()),
                    n_covering_nominal=int(covering_nominal.sum()),
                    shortest_time_to_estimate=float(delay.min()) if timed else math.nan,
                    longest_time_to_estimate=float(delay.max()) if timed else math.nan,
                )
            )
    return summaries


def run_points(rows: Iterable[CampaignRow], case: str, method: str) -> RunPoints:
    """Every run of ``method`` in ``case`` as arrays (:class:`~sensing_antenna.accuracy.RunPoints`).

    The error is against the contact abscissa when the run knows it, else the nominal x_c.
    """
    selected = select(rows, case, method)
    contact = _column(selected, "error_contact_m")
    return RunPoints(
        case=case,
        method=method,
        x_c=_column(selected, "x_c_true_m"),
        estimate=_column(selected, "x_c_estimate_m"),
        error=np.where(np.isfinite(contact), contact, _column(selected, "error_m")),
        delay=_column(selected, "t_e_s") - _column(selected, "t_1_s"),
        omega1=_column(selected, "omega1_rad_s"),
        ok=np.array([row.status == "ok" for row in selected], dtype=bool),
    )


def noise_level_errors(
    rows: Iterable[CampaignRow], methods: Sequence[str], main: float
) -> list[NoiseLevelErrors]:
    """Per noise level (ascending) and method: errors against the contact abscissa, delays."""
    all_rows = list(rows)
    table = []
    for level in noise_levels(all_rows, main):
        at_level = rows_at_level(all_rows, level, main)
        for method in methods:
            mine = select(at_level, method=method)
            errors = [r.abs_error_contact_m for r in mine if math.isfinite(r.abs_error_contact_m)]
            delays = sorted(r.delay_s for r in mine if math.isfinite(r.delay_s))
            table.append(
                NoiseLevelErrors(
                    noise_scale=level,
                    method=method,
                    n_runs=len(mine),
                    n_estimates=len(errors),
                    mean_abs_error=sum(errors) / len(errors) if errors else math.nan,
                    max_abs_error=max(errors) if errors else math.nan,
                    median_delay=statistics.median(delays) if delays else math.nan,
                    n_ok=sum(1 for r in mine if r.status == "ok"),
                    status_counts=dict(Counter(r.status for r in mine)),
                    fixed_delay=bool(delays) and delays[-1] - delays[0] <= FIXED_DELAY_TOLERANCE,
                )
            )
    return table


def contact_offset(rows: Iterable[CampaignRow]) -> ContactOffset:
    """Contact abscissa minus nominal x_c, once per run, over runs that know it (m)."""
    offsets = []
    seen: set[str] = set()
    for row in rows:
        if row.run_id in seen:
            continue
        seen.add(row.run_id)
        if math.isfinite(row.x_c_contact_m):
            offsets.append(row.x_c_contact_m - row.x_c_true_m)
    if not offsets:
        return ContactOffset(0, math.nan, math.nan, math.nan)
    ordered = sorted(offsets)
    return ContactOffset(len(ordered), statistics.median(ordered), ordered[0], ordered[-1])


def frequency_error_summaries(
    rows: Iterable[CampaignRow],
    link: Link,
    methods: Sequence[str],
    main: float,
    imperfections: DeviceImperfections | None = None,
    n_elements: int = N_ELEMENTS,
) -> list[FrequencyErrorSummary]:
    """omega_1 errors of every method that reports one, per noise level (ascending).

    ``link`` is the device's link (the simulated hardware), ``imperfections`` what its build
    adds to it (tip mass, clamp, taper, joint; None: nothing): the truth is the contact-mode
    fundamental of the simulator's finite-element model of that link pinned at each run's
    contact abscissa (the nominal x_c when unknown), of ``n_elements`` elements as the runs'.
    Methods without any finite omega_1 are left out.
    """
    from sensing_antenna.simulator.link import build_link_model

    model = build_link_model(link, n_elements, imperfections)
    all_rows = list(rows)
    summaries = []
    for level in noise_levels(all_rows, main):
        at_level = rows_at_level(all_rows, level, main)
        for method in methods:
            selected = select(at_level, method=method)
            omega = _column(selected, "omega1_rad_s")
            keep = np.isfinite(omega)
            if not keep.any():
                continue
            x = truth(selected)[keep]
            true = np.array([model.pinned_frequencies(float(v), 1)[0] for v in x])
            rel = omega[keep] / true - 1.0
            crb = _column(selected, "omega1_crb_rad_s")[keep] / true
            se = _column(selected, "omega1_se_rad_s")[keep] / true
            summaries.append(
                FrequencyErrorSummary(
                    method=method,
                    noise_scale=level,
                    n=int(rel.size),
                    rms_relative_error=float(np.sqrt(np.mean(rel**2))),
                    median_abs_relative_error=float(np.median(np.abs(rel))),
                    median_relative_crb=_nanmedian(crb),
                    median_relative_se=_nanmedian(se),
                )
            )
    return summaries


def _nanmedian(values: NDArray[np.float64]) -> float:
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if finite.size else math.nan


def paper_table(case: str) -> PointTable:
    """Table 3 (``"azimuthal"``) or Table 4 (``"vertical"``) of the paper, in m.

    Each point counts :data:`PAPER_EXPERIMENTS_PER_POINT` runs; a case the paper has no table
    for gives no points.
    """
    name = PAPER_TABLE_FILES.get(case)
    if name is None:
        return PointTable(case=case, method="paper, real device", points=())
    text = resources.files("sensing_antenna").joinpath(name).read_text("utf-8")
    lines = [line for line in text.splitlines() if line and not line.startswith("#")]
    cm = 0.01
    n = PAPER_EXPERIMENTS_PER_POINT
    points = tuple(
        PointStats(
            x_c=float(record["xc"]) * cm,
            n_runs=n,
            n_estimates=n,
            mean_estimate=float(record["mean_estimate"]) * cm,
            mean_abs_error=float(record["mean_abs_error"]) * cm,
            max_error=float(record["max_error"]) * cm,
            std_error=float(record["std_error"]) * cm,
        )
        for record in csv.DictReader(io.StringIO("\n".join(lines)))
    )
    return PointTable(case=case, method="paper, real device", points=points)


def paper_row_at(case: str, x_c: float) -> PointStats | None:
    """The paper's row at contact point ``x_c`` (m), or None if the paper has none there."""
    for row in paper_table(case).points:
        if abs(row.x_c - x_c) <= _POINT_MATCH_TOLERANCE:
            return row
    return None


def paper_overall(case: str) -> PaperOverall:
    """Mean of the paper's per-point mean |error| and its largest max error (m); NaN without a
    table."""
    points = paper_table(case).points
    if not points:
        return PaperOverall(case, math.nan, math.nan, 0)
    return PaperOverall(
        case=case,
        mean_abs_error=sum(p.mean_abs_error for p in points) / len(points),
        max_error=max(p.max_error for p in points),
        n_runs=sum(p.n_runs for p in points),
    )


def case_table(rows: Iterable[CampaignRow], case: str, methods: Sequence[str]) -> CaseTable:
    """``case`` in the layout of Tables 3 and 4: the paper method (else the first) per point,
    the paper's values at each point and every other method's mean |error|."""
    all_rows = list(rows)
    main = "paper" if "paper" in methods else methods[0]
    baselines = tuple(m for m in methods if m != main)
    by_point = {m: {p.x_c: p for p in point_table(all_rows, case, m).points} for m in baselines}
    table = []
    for point in point_table(all_rows, case, main).points:
        baseline = tuple(
            by_point[m][point.x_c].mean_abs_error if point.x_c in by_point[m] else math.nan
            for m in baselines
        )
        table.append(CaseRow(point, paper_row_at(case, point.x_c), baseline))
    return CaseTable(case=case, method=main, baselines=baselines, rows=tuple(table))
