"""Every number a campaign report shows, computed once from the stored runs (SI units).

:func:`summarize_campaign` turns a spec, its run results, the model and device antennas and the
calibration into a :class:`CampaignSummary`; :mod:`~sensing_antenna.campaign.report` only
formats it, and the figures draw its point tables and per-run arrays.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields, replace

from sensing_antenna.accuracy import FrequencyErrorSummary, PointTable, RunPoints
from sensing_antenna.antenna import Antenna
from sensing_antenna.calibration.frequency import FrequencyCalibration
from sensing_antenna.campaign.devices import TwoDevices, compare_devices, device_label
from sensing_antenna.campaign.records import RUN_FAILED, CampaignRow, RunResult
from sensing_antenna.campaign.runs import second_device_run_ids
from sensing_antenna.campaign.schema import CampaignSpec
from sensing_antenna.campaign.tables import (
    CaseTable,
    ContactOffset,
    IntervalSummary,
    MethodSummary,
    NoiseLevelErrors,
    PaperOverall,
    case_table,
    contact_offset,
    frequency_error_summaries,
    interval_summaries,
    main_rows,
    method_summaries,
    noise_level_errors,
    paper_overall,
    paper_table,
    point_table,
    run_points,
)
from sensing_antenna.campaign.targets import TargetSummary, target_summaries
from sensing_antenna.simulator.scenario import N_ELEMENTS

__all__ = [
    "PAPER_T",
    "PAPER_T_E",
    "CalibrationCheck",
    "CampaignSummary",
    "DeviceComparison",
    "FailedRun",
    "ParameterDifference",
    "campaign_rows",
    "summarize_campaign",
]

#: Section 5.1 of the paper: theoretical T from Table 2 and the calibrated T_e (s/m^2); the paper
#: quotes their relative difference as 7 %.
PAPER_T = 0.2282
PAPER_T_E = 0.2124

#: Antenna sections whose parameters describe the hardware (compared between device and model).
_HARDWARE_SECTIONS = ("link", "azimuth_motor", "elevation_motor")
#: Link and motor fields that belong to the model (found by calibration), not to the hardware.
_MODEL_FIELDS = (
    "calibrated_t",
    "calibration_scatter",
    "mode2_scatter",
    "weight_tip_mass",
    "held_compliance",
)


@dataclass(frozen=True)
class ParameterDifference:
    """A hardware parameter in which the device differs from the model (SI)."""

    name: str
    device: float
    model: float


@dataclass(frozen=True)
class DeviceComparison:
    """The simulated device against the model the estimators know.

    Attributes
    ----------
    differences : tuple of ParameterDifference
        Every hardware parameter (``section.field``) that differs; empty: the same hardware.
    model_t, device_t : float
        Theoretical T = sqrt(rho / (E I)) of each (s/m^2).
    relative_t : float
        (device T - model T) / model T.
    """

    differences: tuple[ParameterDifference, ...]
    model_t: float
    device_t: float
    relative_t: float


@dataclass(frozen=True)
class CalibrationCheck:
    """The calibration of Section 5.1 with what only a simulation can check, and the paper's.

    Attributes
    ----------
    calibration : FrequencyCalibration
    n_used, n_points : int
        Calibration recordings used by the fit, of all.
    device_t : float
        The device's true T (s/m^2).
    t_e_vs_device : float
        (T_e - device T) / device T.
    paper_relative_difference : float
        (T_e - T) / T of the paper (Section 5.1: :data:`PAPER_T_E` against :data:`PAPER_T`).
    applied_scatter : float or None
        The relative scatter the model carries (``link.calibration_scatter``), None if none.
    applied_mode2_scatter : float or None
        The second contact mode's (``link.mode2_scatter``), None if none.
    """

    calibration: FrequencyCalibration
    n_used: int
    n_points: int
    device_t: float
    t_e_vs_device: float
    paper_relative_difference: float
    applied_scatter: float | None
    applied_mode2_scatter: float | None = None


@dataclass(frozen=True)
class FailedRun:
    """A run whose simulation raised."""

    run_id: str
    seed: int
    error: str


@dataclass(frozen=True)
class CampaignSummary:
    """Everything a campaign report shows (SI: m, s, rad/s).

    The comparisons, point tables, intervals and figures cover the main runs (the noise level
    of ``[scenario]``); ``noise`` and ``frequency`` cover every level, ``targets`` the main runs
    and then each level.

    Attributes
    ----------
    n_results, n_failed : int
        Runs stored, and those failed.
    failed : tuple of FailedRun
    methods : tuple of MethodSummary
        Per case and method, in the spec's order.
    paper_overall : tuple of PaperOverall
        The paper's overall errors per case of the spec.
    contact_offset : ContactOffset
        Contact abscissa minus nominal x_c over the main runs.
    intervals : tuple of IntervalSummary
        Per case and method.
    targets : tuple of TargetSummary
        The fast method against its targets; empty when ``fast`` is not among the methods.
    noise : tuple of NoiseLevelErrors
        Per noise level and method; empty without a noise sweep.
    frequency : tuple of FrequencyErrorSummary
        omega_1 against the device's fundamental per level and method; empty without a sweep.
    cases : tuple of CaseTable
        Per case, in the layout of Tables 3 and 4.
    point_tables : tuple of PointTable
        Per case and method.
    paper_tables : tuple of PointTable
        Tables 3 and 4 of the paper for the spec's cases (empty points where it has none).
    run_points : tuple of RunPoints
        Every main run per case and method.
    device : DeviceComparison
    calibration : CalibrationCheck or None
    second_device : CampaignSummary or None
        The second device's runs alone, summarised as the campaign of
        ``spec.second_device_spec()`` with its own model, device and calibration; None
        without a second device. Every other field covers the main device's runs only.
    devices : TwoDevices or None
        Both devices' main runs side by side; None without a second device.
    """

    n_results: int
    n_failed: int
    failed: tuple[FailedRun, ...]
    methods: tuple[MethodSummary, ...]
    paper_overall: tuple[PaperOverall, ...]
    contact_offset: ContactOffset
    intervals: tuple[IntervalSummary, ...]
    targets: tuple[TargetSummary, ...]
    noise: tuple[NoiseLevelErrors, ...]
    frequency: tuple[FrequencyErrorSummary, ...]
    cases: tuple[CaseTable, ...]
    point_tables: tuple[PointTable, ...]
    paper_tables: tuple[PointTable, ...]
    run_points: tuple[RunPoints, ...]
    device: DeviceComparison
    calibration: CalibrationCheck | None
    second_device: CampaignSummary | None = None
    devices: TwoDevices | None = None

    def method_summary(self, case: str, method: str) -> MethodSummary:
        """The summary of ``method`` in ``case``."""
        return next(s for s in self.methods if s.case == case and s.method == method)


def campaign_rows(results: Sequence[RunResult]) -> list[CampaignRow]:
    """Every run x method row, ordered by run index, each run's rows in method order."""
    return [row for result in sorted(results, key=lambda r: r.index) for row in result.rows]


def compare_device(device: Antenna, model: Antenna) -> DeviceComparison:
    """Every hardware parameter in which ``device`` differs from ``model``, and their T."""
    found = []
    for section in _HARDWARE_SECTIONS:
        a, b = getattr(device, section), getattr(model, section)
        for f in fields(a):
            if f.name in _MODEL_FIELDS:
                continue
            x, y = getattr(a, f.name), getattr(b, f.name)
            if x != y:
                found.append(ParameterDifference(f"{section}.{f.name}", x, y))
    t_model, t_device = model.link.theoretical_t, device.link.theoretical_t
    return DeviceComparison(tuple(found), t_model, t_device, (t_device - t_model) / t_model)


def check_calibration(
    calibration: FrequencyCalibration, model: Antenna, device: Antenna
) -> CalibrationCheck:
    """The calibration beside the device's true T and the paper's figures."""
    device_t = device.link.theoretical_t
    return CalibrationCheck(
        calibration=calibration,
        n_used=int(calibration.used.sum()),
        n_points=int(calibration.contact_points.size),
        device_t=device_t,
        t_e_vs_device=(calibration.t_e - device_t) / device_t,
        paper_relative_difference=(PAPER_T_E - PAPER_T) / PAPER_T,
        applied_scatter=model.link.calibration_scatter,
        applied_mode2_scatter=model.link.mode2_scatter,
    )


def summarize_campaign(
    spec: CampaignSpec,
    results: Sequence[RunResult],
    model: Antenna,
    device: Antenna | None = None,
    calibration: FrequencyCalibration | None = None,
    *,
    second_model: Antenna | None = None,
    second_device: Antenna | None = None,
    second_calibration: FrequencyCalibration | None = None,
) -> CampaignSummary:
    """Compute everything the report shows from the stored runs.

    Parameters
    ----------
    spec : CampaignSpec
    results : sequence of RunResult
        The stored runs (any order), the second device's included.
    model : Antenna
        The model the estimators used (with identified observer and T_e, if any).
    device : Antenna, optional
        The simulated hardware; None: the same as ``model``.
    calibration : FrequencyCalibration, optional
        The calibration step's result.
    second_model, second_device, second_calibration : optional
        The same for the second device (its own preparation); None: the main device's
        model and hardware, no calibration. Used only when the spec has a second device.
    """
    device = device if device is not None else model
    second_ids = second_device_run_ids(spec)
    if second_ids:
        second_spec = spec.second_device_spec()
        theirs = [r for r in results if r.run_id in second_ids]
        results = [r for r in results if r.run_id not in second_ids]
        mine = _summarize(spec, results, model, device, calibration)
        second = _summarize(
            second_spec,
            theirs,
            second_model or model,
            second_device or device,
            second_calibration,
        )
        labels = [device_label(spec.device), device_label(second_spec.device)]
        if labels[0] == labels[1]:
            labels = [f"{labels[0]}, main", f"{labels[1]}, second"]
        both = compare_devices(
            labels,
            [main_rows(campaign_rows(results), spec.noise_scale), campaign_rows(theirs)],
            spec.cases,
            spec.methods,
        )
        return replace(mine, second_device=second, devices=both)
    return _summarize(spec, results, model, device, calibration)


def _summarize(
    spec: CampaignSpec,
    results: Sequence[RunResult],
    model: Antenna,
    device: Antenna,
    calibration: FrequencyCalibration | None,
) -> CampaignSummary:
    """The summary of ``results``, all runs of ``spec``'s main device."""
    every = campaign_rows(results)
    rows = main_rows(every, spec.noise_scale)
    cases, methods = spec.cases, spec.methods
    sweep = spec.noise_sweep.enabled
    # the link as built: what the device's build adds to its file (a tip mass, a clamp, ...)
    built = spec.device.as_built(device.link.length, spec.base_seed)
    link = replace(device.link, tip_mass=device.link.tip_mass + built.tip_mass)
    return CampaignSummary(
        n_results=len(results),
        n_failed=sum(1 for r in results if r.status == RUN_FAILED),
        failed=tuple(
            FailedRun(r.run_id, r.seed, r.error)
            for r in sorted(results, key=lambda r: r.index)
            if r.status == RUN_FAILED
        ),
        methods=tuple(method_summaries(rows, cases, methods)),
        paper_overall=tuple(paper_overall(case) for case in cases),
        contact_offset=contact_offset(rows),
        intervals=tuple(interval_summaries(rows, cases, methods)),
        targets=tuple(target_summaries(every, cases, spec.noise_scale, sweep))
        if "fast" in methods
        else (),
        noise=tuple(noise_level_errors(every, methods, spec.noise_scale)) if sweep else (),
        frequency=tuple(
            frequency_error_summaries(
                every,
                device.link,
                methods,
                spec.noise_scale,
                built.link_part,
                int(spec.scenario.get("n_elements", N_ELEMENTS)),
            )
        )
        if sweep
        else (),
        cases=tuple(case_table(rows, case, methods) for case in cases),
        point_tables=tuple(point_table(rows, c, m) for c in cases for m in methods),
        paper_tables=tuple(paper_table(case) for case in cases),
        run_points=tuple(run_points(rows, c, m) for c in cases for m in methods),
        device=compare_device(replace(device, link=link), model),
        calibration=check_calibration(calibration, model, device)
        if calibration is not None
        else None,
    )
