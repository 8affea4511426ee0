"""The figures of a campaign report, drawn from its summary (imports matplotlib when called).

Which figures a campaign gets: the error of every method against x_c; with ``fast`` among the
methods, the error and t_e - t_1 of every run; Figures 16 and 17 per case for the paper method
(else the first); Figure 18 when the paper method ran; Figure 10 after a calibration; with a
noise sweep, the omega_1 error against the noise level; with a second device, the error of every
run against x_c on both devices.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from sensing_antenna.antenna import Antenna
from sensing_antenna.campaign.summary import CampaignSummary

__all__ = ["ReportFigures", "draw_figures"]


@dataclass(frozen=True)
class ReportFigures:
    """Paths of a report's figures.

    Attributes
    ----------
    campaign : tuple of Path
        The method comparisons and Figures 16 to 18, in the report's order.
    calibration : Path or None
        Figure 10, when the campaign calibrated.
    noise : Path or None
        omega_1 error against the noise level, when the campaign has a noise sweep.
    devices : Path or None
        Every run's error against x_c on both devices, when the campaign has a second device.
    """

    campaign: tuple[Path, ...] = ()
    calibration: Path | None = None
    noise: Path | None = None
    devices: Path | None = None


def draw_figures(
    summary: CampaignSummary, methods: tuple[str, ...], model: Antenna, out_dir: Path
) -> ReportFigures:
    """Draw every figure the summary calls for into ``out_dir`` (created if missing).

    Parameters
    ----------
    summary : CampaignSummary
    methods : tuple of str
        The campaign's methods, in order.
    model : Antenna
        The model the estimators used (Figures 10 and 18 draw its sensing curve).
    out_dir : Path
    """
    from sensing_antenna.plotting.calibration import plot_calibration
    from sensing_antenna.plotting.campaign import (
        plot_case_estimates,
        plot_error_and_delay,
        plot_errors_by_device,
        plot_frequencies,
        plot_frequency_error_vs_noise,
        plot_method_errors,
    )

    calibration = None
    if summary.calibration is not None:
        calibration = plot_calibration(summary.calibration.calibration, model.link, out_dir)
    if not summary.n_results:
        return ReportFigures(calibration=calibration)
    main = "paper" if "paper" in methods else methods[0]
    paths = [plot_method_errors(summary.point_tables, summary.paper_tables, out_dir)]
    if "fast" in methods:
        paths.append(plot_error_and_delay(summary.run_points, out_dir))
    papers = {table.case: table for table in summary.paper_tables}
    for points in summary.run_points:
        if points.method == main:
            paths.append(plot_case_estimates(points, papers.get(points.case), out_dir))
    if "paper" in methods:
        measured = [p for p in summary.run_points if p.method == "paper"]
        paths.append(plot_frequencies(measured, model.link, out_dir))
    noise = None
    if summary.frequency:
        noise = plot_frequency_error_vs_noise(summary.frequency, out_dir)
    devices = None
    if summary.devices is not None:
        devices = plot_errors_by_device(
            summary.devices.labels, summary.devices.run_points, summary.paper_tables, out_dir
        )
    return ReportFigures(tuple(paths), calibration, noise, devices)
