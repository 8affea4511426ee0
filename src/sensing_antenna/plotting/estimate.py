"""Figures 11 to 14 of the paper for one recording: contact instant, push, Estimator 1, Estimator 2.

- Figure 11: measured and estimated coupling torques, the residual, the threshold and t_c.
- Figure 12: |F - F_g| and its Eq. 20 filtered version, the motor angles, t_1.
- Figure 13: the torque about Y^c and Z^c over Delta t_e1 after t_1, and its spectrum with the
  searched band and the peak.
- Figure 14: the torque/force ratio x_c(t) converging, with the ratio estimate and the final x_c.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from sensing_antenna.antenna import Antenna
from sensing_antenna.detection.contact import detect_contact
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.front.contact_frame import motor_axes
from sensing_antenna.estimation.front.ratio import (
    contact_loads,
    filtered_contact_loads,
    perpendicular_ratio,
)
from sensing_antenna.estimation.methods.paper.frequency import power_spectrum
from sensing_antenna.estimation.pipeline import estimate
from sensing_antenna.estimation.result import ContactEstimate
from sensing_antenna.plotting import save_figure
from sensing_antenna.recording import Recording, resample_uniform

__all__ = ["plot_estimate"]

_CM = 100.0


def _mark(ax: plt.Axes, t: float, label: str, color: str) -> None:
    if math.isfinite(t):
        ax.axvline(t, color=color, ls="--", lw=1.0, label=label)


def plot_estimate(
    recording: Recording,
    antenna: Antenna,
    out_dir: str | Path,
    method: str = "paper",
    config: EstimatorConfig | None = None,
) -> list[Path]:
    """Draw Figures 11 to 14 for a recording; returns the PNG paths.

    Parameters
    ----------
    recording : Recording
    antenna : Antenna
    out_dir : str or Path
        Output directory, created if missing.
    method : str
        Estimation method whose result is drawn.
    config : EstimatorConfig, optional

    Returns
    -------
    list of Path
        ``figure11-contact.png``, ``figure12-push.png`` and, when the pipeline got that far,
        ``figure13-frequency.png`` and ``figure14-ratio.png``.
    """
    cfg = config if config is not None else EstimatorConfig()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rec = resample_uniform(recording) if recording.sampling.irregular else recording
    result = estimate(rec, antenna, method=method, config=cfg)
    paths = [_figure11(rec, antenna, result, out), _figure12(rec, antenna, result, cfg, out)]
    if "axes_c_absolute" in result.diagnostics:
        paths.append(_figure13(rec, result, cfg, out))
        paths.append(_figure14(rec, antenna, result, cfg, out))
    return paths


def _title(result: ContactEstimate) -> str:
    x_c = "-" if not math.isfinite(result.x_c) else f"{_CM * result.x_c:.1f} cm"
    return f"{result.method}: x_c = {x_c}, status {result.status.value}"


def _figure11(rec: Recording, antenna: Antenna, result: ContactEstimate, out: Path) -> Path:
    detection = detect_contact(rec, antenna)
    fig, (ax_t, ax_r) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for k, name in ((1, "y"), (2, "z")):
        (line,) = ax_t.plot(rec.t, rec.torque[:, k], lw=1.0, label=f"measured Gamma_{name}")
        ax_t.plot(
            detection.t,
            detection.estimated_torque[:, k],
            "--",
            color=line.get_color(),
            lw=1.0,
            label=f"estimated Gamma_{name} (Eq. 15 + gravity)",
        )
    ax_t.set_ylabel("coupling torque (N m)")
    ax_t.legend(fontsize=7)
    ax_t.set_title("Figure 11 - " + _title(result), fontsize=9)
    ax_r.plot(detection.t, detection.filtered_residual_norm, lw=1.0, label="|filtered residual|")
    ax_r.axhline(detection.threshold, color="k", lw=0.8, label="threshold")
    _mark(ax_r, result.t_c, "t_c", "C3")
    ax_r.set_xlabel("t (s)")
    ax_r.set_ylabel("residual (N m)")
    ax_r.legend(fontsize=7)
    return save_figure(fig, out / "figure11-contact.png")


def _offset(result: ContactEstimate) -> np.ndarray:
    return np.asarray(result.diagnostics.get("load_offset", np.zeros(6)), dtype=float)


def _figure12(
    rec: Recording, antenna: Antenna, result: ContactEstimate, cfg: EstimatorConfig, out: Path
) -> Path:
    offset = _offset(result)
    reaction, _ = contact_loads(rec.theta, rec.force, rec.torque, antenna)
    reaction_f, _ = filtered_contact_loads(
        rec.theta, rec.force, rec.torque, antenna, cfg.lowpass_cutoff, rec.sample_period, offset
    )
    fig, (ax_f, ax_a) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    ax_f.plot(rec.t, np.linalg.norm(reaction - offset[:3], axis=1), lw=0.7, label="|F - F_g|")
    ax_f.plot(rec.t, np.linalg.norm(reaction_f, axis=1), lw=1.5, label="filtered (Eq. 20)")
    _mark(ax_f, result.t_c, "t_c", "C3")
    _mark(ax_f, result.t_1, "t_1 (head at rest)", "C2")
    ax_f.set_ylabel("contact force (N)")
    ax_f.legend(fontsize=7)
    ax_f.set_title("Figure 12 - " + _title(result), fontsize=9)
    ax_a.plot(rec.t, rec.theta[:, 0], label="theta1")
    ax_a.plot(rec.t, rec.theta[:, 1], label="theta2")
    _mark(ax_a, result.t_1, "t_1", "C2")
    ax_a.set_xlabel("t (s)")
    ax_a.set_ylabel("motor angle (rad)")
    ax_a.legend(fontsize=7)
    return save_figure(fig, out / "figure12-push.png")


def _axes_m(result: ContactEstimate) -> np.ndarray:
    axes_a = np.asarray(result.diagnostics["axes_c_absolute"], dtype=float)
    theta = np.asarray(result.diagnostics["theta_at_t1"], dtype=float)
    return axes_a @ motor_axes(theta).T


def _figure13(rec: Recording, result: ContactEstimate, cfg: EstimatorConfig, out: Path) -> Path:
    ts = rec.sample_period
    start = round(float(result.t_1 - rec.t[0]) / ts)
    stop = min(start + round(cfg.spectrum_window / ts), rec.n_samples)
    projected = rec.torque[start:stop] @ _axes_m(result)[1:].T
    fig, (ax_t, ax_s) = plt.subplots(2, 1, figsize=(7, 6))
    ax_t.plot(rec.t[start:stop], projected[:, 0], lw=1.0, label="Gamma about Y^c")
    ax_t.plot(rec.t[start:stop], projected[:, 1], lw=1.0, label="Gamma about Z^c")
    ax_t.set_xlabel("t (s)")
    ax_t.set_ylabel("torque (N m)")
    ax_t.legend(fontsize=7)
    ax_t.set_title("Figure 13 - " + _title(result), fontsize=9)
    if stop - start >= 4:
        omega, power = power_spectrum(projected, ts, cfg.zero_padding)
        keep = omega <= 400.0
        ax_s.semilogy(omega[keep], power[keep, 0], lw=1.0, label="about Y^c")
        ax_s.semilogy(omega[keep], power[keep, 1], lw=1.0, label="about Z^c")
        band = result.diagnostics.get("band")
        if band is not None:
            ax_s.axvspan(band[0], band[1], color="0.9", label="searched band")
        if math.isfinite(result.omega1):
            component = result.diagnostics.get("torque_component")
            ax_s.axvline(
                result.omega1,
                color="C3",
                ls="--",
                label=f"omega_1 = {result.omega1:.2f} rad/s ({component})",
            )
    ax_s.set_xlabel("omega (rad/s)")
    ax_s.set_ylabel("power (N^2 m^2)")
    ax_s.legend(fontsize=7)
    return save_figure(fig, out / "figure13-frequency.png")


def _figure14(
    rec: Recording, antenna: Antenna, result: ContactEstimate, cfg: EstimatorConfig, out: Path
) -> Path:
    reaction_f, torque_f = filtered_contact_loads(
        rec.theta,
        rec.force,
        rec.torque,
        antenna,
        cfg.lowpass_cutoff,
        rec.sample_period,
        _offset(result),
    )
    ratio = perpendicular_ratio(reaction_f, torque_f, antenna.link.flexural_rigidity)
    after = rec.t >= result.t_c
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(rec.t[after], _CM * ratio[after], lw=1.0, label="x_c(t), Estimator 2")
    if math.isfinite(result.ratio_estimate):
        ax.axhline(_CM * result.ratio_estimate, color="C1", ls=":", label="ratio estimate at t_e")
    if math.isfinite(result.x_c):
        ax.axhline(_CM * result.x_c, color="C3", label="fused x_c")
    for c in result.candidates:
        ax.axhline(_CM * c, color="0.6", lw=0.8, ls="--")
    _mark(ax, result.t_1, "t_1", "C2")
    _mark(ax, result.t_e, "t_e", "k")
    top = 1.5 * _CM * antenna.link.length
    ax.set_ylim(0.0, top)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("x_c (cm)")
    ax.legend(fontsize=7)
    ax.set_title("Figure 14 - " + _title(result), fontsize=9)
    return save_figure(fig, out / "figure14-ratio.png")
