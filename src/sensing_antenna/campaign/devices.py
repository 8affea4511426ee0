"""The same runs on two devices, side by side: per method and case, per contact point (SI).

A campaign with a ``[second_device]`` runs its main manoeuvres (same cases, contact points,
repeats and seeds) on a second device. :func:`compare_devices` takes the rows of both and
computes what the report puts beside the paper's Tables 3 and 4: per case and method the runs
with an estimate, the ``ok`` runs and the status mix, and the mean, maximum and standard
deviation of the error; per case and contact point the same for the paper method (else the
first) with the paper's values at that point; and every run as arrays for the error figure.
Errors are against the nominal x_c, as in the paper's tables (the figure uses the contact
abscissa, :func:`~sensing_antenna.campaign.tables.run_points`).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from sensing_antenna.accuracy import PointStats, RunPoints
from sensing_antenna.campaign.records import CampaignRow
from sensing_antenna.campaign.schema import DeviceSpec
from sensing_antenna.campaign.tables import paper_row_at, point_table, run_points, select

__all__ = [
    "DeviceCaseRow",
    "DeviceCaseTable",
    "DeviceMethodRow",
    "TwoDevices",
    "compare_devices",
    "device_label",
]


@dataclass(frozen=True)
class DeviceMethodRow:
    """One method over one case on one device; errors against the nominal x_c (m).

    Attributes
    ----------
    case, method : str
    n_runs, n_estimates, n_ok : int
        Runs, runs with a finite estimate, runs with status ``ok``.
    mean_abs_error, max_abs_error, std_error : float
        Over every estimate (any status): mean and max |e| and the standard deviation of e
        (ddof = 1); NaN without enough estimates.
    ok_mean_abs_error, ok_max_abs_error : float
        Over the ``ok`` runs only; NaN without any.
    status_counts : mapping of str to int
        Runs per status.
    """

    case: str
    method: str
    n_runs: int
    n_estimates: int
    n_ok: int
    mean_abs_error: float
    max_abs_error: float
    std_error: float
    ok_mean_abs_error: float
    ok_max_abs_error: float
    status_counts: Mapping[str, int]


@dataclass(frozen=True)
class DeviceCaseRow:
    """One contact point: the method's statistics and ``ok`` runs on each device (in the order
    of :attr:`TwoDevices.labels`) and the paper's at that point (None where it has none)."""

    x_c: float
    devices: tuple[PointStats | None, ...]
    n_ok: tuple[int, ...]
    paper: PointStats | None


@dataclass(frozen=True)
class DeviceCaseTable:
    """A case in the layout of Tables 3 and 4, ``method`` on both devices beside the paper."""

    case: str
    method: str
    rows: tuple[DeviceCaseRow, ...]


@dataclass(frozen=True)
class TwoDevices:
    """The main device and the second device on the same manoeuvres.

    Attributes
    ----------
    labels : tuple of str
        Short names of the two devices, main first (:func:`device_label`).
    methods : tuple of tuple of DeviceMethodRow
        Per device, per case and method.
    cases : tuple of DeviceCaseTable
        Per case.
    run_points : tuple of tuple of RunPoints
        Per device, every run per case and method (with ``ok``).
    """

    labels: tuple[str, ...]
    methods: tuple[tuple[DeviceMethodRow, ...], ...]
    cases: tuple[DeviceCaseTable, ...]
    run_points: tuple[tuple[RunPoints, ...], ...]


def device_label(device: DeviceSpec) -> str:
    """A device's imperfections in a few words: its profile and the fields it sets."""
    fixed = ", ".join(f"{k} = {v}" for k, v in sorted(device.imperfections.items()))
    return device.profile + (f" ({fixed})" if fixed else "")


def _method_row(rows: Sequence[CampaignRow], case: str, method: str) -> DeviceMethodRow:
    selected = select(rows, case, method)
    errors = np.array([r.error_m for r in selected], dtype=float)
    ok = np.array([r.status == "ok" for r in selected], dtype=bool)
    finite = np.isfinite(errors)
    e, ok_e = errors[finite], np.abs(errors[finite & ok])
    return DeviceMethodRow(
        case=case,
        method=method,
        n_runs=len(selected),
        n_estimates=int(e.size),
        n_ok=int(ok.sum()),
        mean_abs_error=float(np.mean(np.abs(e))) if e.size else math.nan,
        max_abs_error=float(np.max(np.abs(e))) if e.size else math.nan,
        std_error=float(np.std(e, ddof=1)) if e.size >= 2 else math.nan,
        ok_mean_abs_error=float(np.mean(ok_e)) if ok_e.size else math.nan,
        ok_max_abs_error=float(np.max(ok_e)) if ok_e.size else math.nan,
        status_counts=dict(Counter(r.status for r in selected)),
    )


def _case_table(
    devices: Sequence[Sequence[CampaignRow]], case: str, method: str
) -> DeviceCaseTable:
    tables = [{p.x_c: p for p in point_table(rows, case, method).points} for rows in devices]
    points = sorted({x for table in tables for x in table})
    result = []
    for x_c in points:
        ok = tuple(
            sum(1 for r in select(rows, case, method) if r.x_c_true_m == x_c and r.status == "ok")
            for rows in devices
        )
        stats = tuple(table.get(x_c) for table in tables)
        result.append(DeviceCaseRow(x_c, stats, ok, paper_row_at(case, x_c)))
    return DeviceCaseTable(case=case, method=method, rows=tuple(result))


def compare_devices(
    labels: Sequence[str],
    devices: Sequence[Sequence[CampaignRow]],
    cases: Sequence[str],
    methods: Sequence[str],
) -> TwoDevices:
    """The devices' main runs side by side.

    Parameters
    ----------
    labels : sequence of str
        Names of the devices, main first.
    devices : sequence of sequence of CampaignRow
        Each device's rows of its main runs (the same manoeuvres), in the order of ``labels``.
    cases, methods : sequence of str
        The campaign's, in order; the per-point tables are of the paper method (else the
        first).
    """
    main = "paper" if "paper" in methods else methods[0]
    return TwoDevices(
        labels=tuple(labels),
        methods=tuple(
            tuple(_method_row(rows, c, m) for c in cases for m in methods) for rows in devices
        ),
        cases=tuple(_case_table(devices, case, main) for case in cases),
        run_points=tuple(
            tuple(run_points(rows, c, m) for c in cases for m in methods) for rows in devices
        ),
    )
