"""The campaign report: one Markdown file with tables and figures, rebuilt from the stored runs.

:func:`build_report` reads a campaign directory (see :mod:`~sensing_antenna.campaign.store`),
rewrites ``runs.csv``, computes the summary (:mod:`~sensing_antenna.campaign.summary`), draws the
figures into ``figures/`` and writes ``report.md`` with relative image links. This module only
formats and lays out; lengths are shown in cm (the display edge), everything stored stays SI.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from sensing_antenna.antenna import Antenna
from sensing_antenna.calibration.frequency import MIN_TIP_MASS_POINTS
from sensing_antenna.campaign.figures import ReportFigures, draw_figures
from sensing_antenna.campaign.report_devices import devices_section
from sensing_antenna.campaign.report_sections import (
    case_section,
    cm,
    failures_section,
    figure_lines,
    interval_section,
    level,
    markdown_table,
    noise_section,
    status_section,
    summary_section,
    targets_section,
    truth_section,
)
from sensing_antenna.campaign.schema import CampaignSpec
from sensing_antenna.campaign.store import (
    CALIBRATION_FILE,
    CSV_FILE,
    DEVICE_FILE,
    RUNS_DIR,
    SECOND_DEVICE_DIR,
    CampaignStoreError,
    atomic_write_text,
    load_campaign_results,
    read_calibration,
    read_manifest,
    read_stored_antenna,
    read_stored_device,
    write_runs_csv,
)
from sensing_antenna.campaign.summary import (
    PAPER_T,
    PAPER_T_E,
    CalibrationCheck,
    CampaignSummary,
    summarize_campaign,
)
from sensing_antenna.estimation.front.evidence import TWO_FREQUENCY_GRID_STEP
from sensing_antenna.estimation.methods.fast import FastConfig
from sensing_antenna.simulator.device import DeviceImperfections

__all__ = ["FIGURES_DIR", "REPORT_FILE", "build_report", "render_report"]

REPORT_FILE = "report.md"
FIGURES_DIR = "figures"
#: Ids of left-out run files the report names before it only counts the rest.
_FOREIGN_SHOWN = 10


def _antenna_lines(model: Antenna, device: Antenna, summary: CampaignSummary) -> list[str]:
    link = model.link
    used = (
        f"calibrated T_e = {link.t_param:.4f} s/m^2"
        if link.calibrated_t is not None
        else f"theoretical T = {link.t_param:.4f} s/m^2"
    )
    differences = [
        f"{d.name} = {d.device:.6g} (model {d.model:.6g})" for d in summary.device.differences
    ]
    return [
        f"- Model (what the estimators know): {model.name}, E = {link.youngs_modulus / 1e9:.5g} "
        f"GPa, rho = {link.linear_density:.4g} kg/m, I = {link.area_moment:.4g} m^4, "
        f"l = {link.length:g} m, theoretical T = {summary.device.model_t:.4f} s/m^2; the "
        f"frequency model uses the {used}",
        f"- Device (the simulated hardware): {device.name}, E = "
        f"{device.link.youngs_modulus / 1e9:.5g} GPa, T = {summary.device.device_t:.4f} s/m^2"
        + (
            f"; differs from the model in {'; '.join(differences)} ([{DEVICE_FILE}]({DEVICE_FILE}))"
            if differences
            else " (the same hardware parameters as the model)"
        ),
    ]


def _imperfection_lines(spec: CampaignSpec, length: float) -> list[str]:
    """The device's imperfections the model does not know, when the spec sets any (``length``:
    the device's link, m)."""
    if not spec.device.has_imperfections:
        return []
    fixed = ", ".join(f"{k} = {v}" for k, v in sorted(spec.device.imperfections.items()))
    profile = spec.device.profile
    if profile == "realistic":
        built = spec.device.as_built(length, spec.base_seed)
        profile = (
            f"realistic (device build {spec.device.build_of(spec.base_seed)}: "
            f"{_built_link(built)}; its set-up drawn per manoeuvre from its seed)"
        )
    return [f"- Device imperfections: profile {profile}" + (f"; set: {fixed}" if fixed else "")]


def _built_link(built: DeviceImperfections) -> str:
    """What a build adds to the link, in a few words (SI)."""
    clamp = (
        "a rigid clamp"
        if built.clamp_stiffness is None
        else f"a clamp of {built.clamp_stiffness:.3g} N m/rad"
    )
    joint = (
        f", a joint of {100 * built.joint_length:.2g} cm at {built.joint_start:.3g} m (E I x "
        f"{built.joint_stiffness_factor:.3g}, rho x {built.joint_density_factor:.3g})"
        if built.joint_length > 0.0
        else ""
    )
    return (
        f"{1e6 * built.tip_mass:.3g} mg at the tip, {clamp}, E I tapering to "
        f"{built.stiffness_taper:.3g} of the root's{joint}"
    )


def _plain_statement(summary: CampaignSummary, spec: CampaignSpec) -> list[str]:
    device, check = summary.device, summary.calibration
    if spec.device.has_imperfections:
        return [
            "The simulated device carries imperfections the model does not know (see "
            "Settings, device imperfections; docs/simulator.md): the estimators are never told "
            "of them, and the errors include what they do.",
            "",
        ]
    if not device.differences:
        text = (
            "The simulated device has exactly the parameters of the model the estimators use, "
            "so the estimators see no model error."
        )
        if check is not None:
            text += " The calibration step still fits T_e from recordings, as on a real device."
        return [text, ""]
    text = (
        f"The simulated device is not the nominal model: its T is {device.device_t:.4f} s/m^2, "
        f"{100 * device.relative_t:+.1f} % from the model's {device.model_t:.4f}. The "
        "estimators are never told the device's parameters. "
    )
    if check is not None:
        text += (
            "As in the paper (Section 5.1), the campaign first calibrates T_e from contact "
            "recordings on the device at known points, and every estimator uses the model with "
            f"that T_e ({check.calibration.t_e:.4f} s/m^2)."
        )
    else:
        text += (
            "There is no calibration step, so the estimators use the model's theoretical T: "
            "the errors include the model error."
        )
    return [text, ""]


def _tip_mass_lines(asked: bool, fitted: float | None) -> list[str]:
    """What became of the tip mass the spec asked to fit with T_e (``tip_mass = true``)."""
    if not asked:
        return []
    if fitted is not None:
        return [f"The tip mass, fitted with T_e: {1e3 * fitted:.4g} g (the model's tip_mass).", ""]
    return [
        f"The tip mass (`tip_mass = true`) was not fitted: fewer than {MIN_TIP_MASS_POINTS} "
        "points that agree with one another; the model keeps the antenna's link.tip_mass.",
        "",
    ]


def _scatter_lines(check: CalibrationCheck) -> list[str]:
    calibration = check.calibration
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
    if check.applied_scatter is None:
        text += (
            "The model the runs used does not carry it, so the fast method's floor on omega_1 "
            "was its default."
        )
    else:
        text += (
            f"The model carries it as `calibration_scatter` ({100 * check.applied_scatter:.3f} "
            "%), and the fast method's model floor on omega_1 is at least this."
        )
    return [text, "", *_mode2_lines(check), ""]


def _mode2_lines(check: CalibrationCheck) -> list[str]:
    """What the calibration measured of the second contact mode, in one paragraph."""
    calibration = check.calibration
    if calibration.omega2_measured is None:
        return ["The calibration did not look for the second contact mode."]
    count = calibration.mode2_points
    scatter = calibration.mode2_scatter
    if not math.isfinite(scatter) or check.applied_mode2_scatter is None:
        return [
            f"The second contact mode was found near the model's at {count} of "
            f"{check.n_used} points used: too few for its scatter, so the fast method does not "
            "use omega_2 at its cap."
        ]
    return [
        f"The measured omega_2 scatter by {100 * scatter:.3f} % (rms, relative, {count} "
        "points, its mean included) about the calibrated model. The model carries it as "
        f"`mode2_scatter` ({100 * check.applied_mode2_scatter:.3f} %): at its cap the fast "
        "method may narrow an interval the fundamental leaves too wide with omega_2, within "
        'this (docs/fast.md, "The second mode at the cap").'
    ]


def _calibration_section(
    spec: CampaignSpec, check: CalibrationCheck | None, figure: Path | None, out_dir: Path
) -> list[str]:
    if check is None:
        return []
    calibration = check.calibration
    step = spec.calibration
    se = calibration.t_e_std_error
    t_e_text = f"{calibration.t_e:.4f}" + (f" +- {se:.4f}" if math.isfinite(se) else "")
    rows = [
        [
            "this campaign (simulated device)",
            f"{calibration.t_theoretical:.4f}",
            t_e_text,
            f"{100 * calibration.relative_difference:+.1f} %",
            f"{calibration.rms_residual:.3g}",
            f"{check.n_used}/{check.n_points}",
        ],
        [
            "paper, real device (Section 5.1)",
            f"{PAPER_T:.4f}",
            f"{PAPER_T_E:.4f}",
            f"{100 * check.paper_relative_difference:+.1f} % (quoted as 7 %)",
            "-",
            "15 points",
        ],
    ]
    lines = [
        "## Calibration of the frequency model (Section 5.1)",
        "",
        f"Before the runs, {check.n_points} contact manoeuvres were simulated on "
        f"the device ({step.case} case, x_c from {cm(min(step.contact_points), 0)} to "
        f"{cm(max(step.contact_points), 0)} cm, {step.repeats} repeat(s) each, seeds on their "
        "own stream). omega_1 was measured in each with the wide calibration band and T_e fitted "
        f"to the model's beta_1(x_c)^2 (loss {calibration.loss}). The contact points are known "
        "(a calibration); nothing else about the device is. Every estimator uses T_e. "
        f"Stored in [{CALIBRATION_FILE}]({CALIBRATION_FILE}).",
        "",
        *markdown_table(
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
        f"Check available on the simulator only: the device's true T is {check.device_t:.4f} "
        f"s/m^2; T_e is {100 * check.t_e_vs_device:+.2f} % from it.",
        "",
        *_tip_mass_lines(step.tip_mass, calibration.tip_mass),
        *_scatter_lines(check),
    ]
    if calibration.notes:
        lines += ["Points left out of the fit:", ""]
        lines += [f"- {note}" for note in calibration.notes]
        lines.append("")
    if figure is not None:
        lines += figure_lines(figure, out_dir)
    return lines


def _left_out_lines(foreign: Sequence[str]) -> list[str]:
    if not foreign:
        return []
    shown = ", ".join(f"`{run_id}`" for run_id in foreign[:_FOREIGN_SHOWN])
    more = f" and {len(foreign) - _FOREIGN_SHOWN} more" if len(foreign) > _FOREIGN_SHOWN else ""
    return [
        f"- Left out: {len(foreign)} run file(s) in `{RUNS_DIR}/` that are not runs of this spec "
        f"({shown}{more}); nothing in this report or in [{CSV_FILE}]({CSV_FILE}) comes from them"
    ]


def _settings_lines(
    spec: CampaignSpec,
    summary: CampaignSummary,
    model: Antenna,
    device: Antenna,
    foreign: Sequence[str],
) -> list[str]:
    obs = model.observer
    second = summary.second_device
    n_results = summary.n_results + (second.n_results if second is not None else 0)
    n_failed = summary.n_failed + (second.n_failed if second is not None else 0)
    parts = []
    if spec.noise_sweep.enabled or second is not None:
        parts.append(f"{spec.n_main_runs} main runs at noise {level(spec.noise_scale)}")
    if spec.noise_sweep.enabled:
        parts.append(f"{spec.n_sweep_runs} in the noise sweep")
    if second is not None:
        parts.append(f"{spec.n_second_device_runs} on the second device")
    return [
        f"- Runs stored: {n_results} of {spec.n_runs}; failed: {n_failed}"
        + (f" ({', '.join(parts)})" if parts else "")
        + ("" if n_results == spec.n_runs else " (campaign incomplete: run it again to finish)"),
        *_left_out_lines(foreign),
        f"- Cases: {', '.join(spec.cases)}; repeats: {spec.repeats}; base seed: {spec.base_seed}",
        "- Contact points (cm): " + ", ".join(cm(x, 0) for x in spec.contact_points),
        f"- Methods: {', '.join(spec.methods)} (each estimates the same recordings)",
        *_antenna_lines(model, device, summary),
        f"- Free-motion observer (Eq. 15): gain {obs.gain:.4g} N m/rad, omega "
        f"{obs.natural_frequency:.4g} rad/s, damping {obs.damping:.4g} 1/s, contact threshold "
        f"{obs.contact_threshold:.4g} N m"
        + (
            " (identified on simulated free sweeps of the device, "
            + ", ".join(spec.free_motion_cases())
            + "; used by the device's controller and by the estimators)"
            if spec.free_motion.identify
            else ""
        ),
        "- Scenario: "
        + (", ".join(f"{k} = {v}" for k, v in sorted(spec.scenario.items())) or "defaults"),
        *_imperfection_lines(spec, device.link.length),
        f"- Per-run results: [{CSV_FILE}]({CSV_FILE}) (SI units, one row per run and method)",
    ]


def render_report(
    spec: CampaignSpec,
    summary: CampaignSummary,
    model: Antenna,
    device: Antenna | None = None,
    figures: ReportFigures | None = None,
    out_dir: Path | None = None,
    foreign_run_files: Sequence[str] = (),
) -> str:
    """The Markdown text of the report.

    Parameters
    ----------
    spec : CampaignSpec
    summary : CampaignSummary
        Every number the report shows (:func:`~.summary.summarize_campaign`).
    model : Antenna
        The model the estimators used (with identified observer and T_e, if any).
    device : Antenna, optional
        The simulated hardware; None: the same as ``model``.
    figures : ReportFigures, optional
        The figures to link; None: none.
    out_dir : Path, optional
        Campaign directory the figure links are relative to (needed with figures).
    foreign_run_files : sequence of str
        Ids of run files in the directory that are not runs of the spec (left out; said so).

    The method comparison, status counts, intervals, figures and the tables per case cover the
    main runs only (the noise level of ``[scenario]``); the noise sweep has its own section.
    """
    device = device if device is not None else model
    figures = figures if figures is not None else ReportFigures()
    where = out_dir if out_dir is not None else Path()
    lines = [
        f"# Campaign {spec.name}",
        "",
        spec.description,
        "",
        *_settings_lines(spec, summary, model, device, foreign_run_files),
        "",
        *_plain_statement(summary, spec),
        "The recordings are simulated; the paper's numbers come from its real device, so the "
        "comparison shows whether the method behaves as reported, not a reproduction of the "
        "device.",
        "",
        *_calibration_section(spec, summary.calibration, figures.calibration, where),
        *summary_section(spec, summary, model.link.length),
        *status_section(summary.methods),
        *truth_section(summary),
        *interval_section(summary.intervals),
        *targets_section(summary.targets),
        *noise_section(spec, summary, figures.noise, where),
        *devices_section(spec, summary, figures.devices, where),
        "## Figures",
        "",
        "Main runs only (noise level of `[scenario]`). The two-frequency method answers on its "
        f"curve's {1e3 * TWO_FREQUENCY_GRID_STEP:g} mm grid and `fast` on its posterior's "
        f"{1e3 * FastConfig().grid_step:g} mm grid, which hold the nominal points: an error "
        "drawn at zero is a grid point on the contact, not an exact answer.",
        "",
    ]
    for path in figures.campaign:
        lines += figure_lines(path, where)
    for table in summary.cases:
        lines += case_section(table)
    failed = summary.failed
    if summary.second_device is not None:
        failed += summary.second_device.failed
    lines += failures_section(failed)
    return "\n".join(lines).rstrip() + "\n"


def build_report(out_dir: str | Path, *, figures: bool = True) -> Path:
    """Rebuild ``runs.csv``, the figures and ``report.md`` from a campaign directory.

    Parameters
    ----------
    out_dir : str or Path
        A directory written by :func:`~sensing_antenna.campaign.runner.run_campaign`.
    figures : bool
        Draw the figures (needs matplotlib).

    Returns
    -------
    Path
        The report file.
    """
    directory = Path(out_dir)
    spec = read_manifest(directory)
    model = read_stored_antenna(directory)
    if model is None:
        raise CampaignStoreError(f"{directory / 'antenna.toml'}: no such file")
    device = read_stored_device(directory) or model
    kept = read_calibration(directory)
    calibration = kept[1] if kept is not None else None
    stored = load_campaign_results(directory, spec)
    results = list(stored.results.values())
    write_runs_csv(directory / CSV_FILE, results)
    second_model = second_device = second_calibration = None
    if spec.second_device.enabled:
        folder = directory / SECOND_DEVICE_DIR
        second_model = read_stored_antenna(folder)
        second_device = read_stored_device(folder) or second_model
        kept = read_calibration(folder)
        second_calibration = kept[1] if kept is not None else None
    summary = summarize_campaign(
        spec,
        results,
        model,
        device,
        calibration,
        second_model=second_model,
        second_device=second_device,
        second_calibration=second_calibration,
    )
    drawn = (
        draw_figures(summary, spec.methods, model, directory / FIGURES_DIR)
        if figures
        else ReportFigures()
    )
    report = directory / REPORT_FILE
    text = render_report(spec, summary, model, device, drawn, directory, stored.foreign)
    atomic_write_text(report, text)
    return report
