"""Figures 11 to 14 of the paper for one estimate: contact instant, push, Estimator 1, Estimator 2.

- Figure 11: measured and estimated coupling torques, the residual, the threshold and t_c.
- Figure 12: |F - F_g| and its Eq. 20 filtered version, the motor angles, t_1.
- Figure 13: the torque about Y^c and Z^c over Delta t_e1 after t_1, and its spectrum with the
  searched band and the peak.
- Figure 14: the torque/force ratio x_c(t) converging, with the ratio estimate and the final x_c.

Everything is drawn from the estimate and its front-end trace
(:class:`~sensing_antenna.estimation.front.outcome.FrontTrace`): nothing is detected, filtered
or estimated again here.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from sensing_antenna.antenna import Antenna
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.front.outcome import FrontTrace
from sensing_antenna.estimation.front.ratio import contact_loads
from sensing_antenna.estimation.methods.paper.frequency import power_spectrum
from sensing_antenna.estimation.pipeline import estimate
from sensing_antenna.estimation.result import ContactEstimate
from sensing_antenna.plotting import save_figure
from sensing_antenna.recording import Recording

__all__ = ["plot_contact_estimate", "plot_estimate"]

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
    """Estimate a recording and draw Figures 11 to 14 (:func:`plot_contact_estimate`).

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
        The PNG files written.
    """
    cfg = config if config is not None else EstimatorConfig()
    result = estimate(recording, antenna, method=method, config=cfg)
    return plot_contact_estimate(result, antenna, out_dir, cfg.zero_padding)


def plot_contact_estimate(
    result: ContactEstimate, antenna: Antenna, out_dir: str | Path, zero_padding: int = 16
) -> list[Path]:
    """Draw Figures 11 to 14 from an estimate and its front-end trace; returns the PNG paths.

    Parameters
    ----------
    result : ContactEstimate
        From :func:`~sensing_antenna.estimation.estimate` or the online estimator (which attach
        the trace).
    antenna : Antenna
        The antenna it was estimated with (gravity loads of Figure 12, link length of Figure 14).
    out_dir : str or Path
        Output directory, created if missing.
    zero_padding : int
        Zero-padding factor of the spectrum of Figure 13 (``EstimatorConfig.zero_padding``).

    Returns
    -------
    list of Path
        ``figure11-contact.png``, ``figure12-push.png`` and, when the front end reached t_e,
        ``figure13-frequency.png`` and ``figure14-ratio.png``.

    Raises
    ------
    ValueError
        When the estimate carries no trace.
    """
    trace = result.trace
    if trace is None:
        raise ValueError(f"the {result.method} estimate carries no front-end trace to draw")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = [_figure11(trace, result, out), _figure12(trace, antenna, result, out)]
    if trace.frame is not None and trace.spectrum is not None:
        paths.append(_figure13(trace, result, zero_padding, out))
        paths.append(_figure14(trace, antenna, result, out))
    return paths


def _title(result: ContactEstimate) -> str:
    x_c = "-" if not math.isfinite(result.x_c) else f"{_CM * result.x_c:.1f} cm"
    return f"{result.method}: x_c = {x_c}, status {result.status.value}"


def _figure11(trace: FrontTrace, result: ContactEstimate, out: Path) -> Path:
    fig, (ax_t, ax_r) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for k, name in ((1, "y"), (2, "z")):
        (line,) = ax_t.plot(trace.t, trace.torque[:, k], lw=1.0, label=f"measured Gamma_{name}")
        ax_t.plot(
            trace.t,
            trace.estimated_torque[:, k],
            "--",
            color=line.get_color(),
            lw=1.0,
            label=f"estimated Gamma_{name} (Eq. 15 + gravity)",
        )
    ax_t.set_ylabel("coupling torque (N m)")
    ax_t.legend(fontsize=7)
    ax_t.set_title("Figure 11 - " + _title(result), fontsize=9)
    ax_r.plot(trace.t, trace.filtered_residual_norm, lw=1.0, label="|filtered residual|")
    ax_r.axhline(trace.contact_threshold, color="k", lw=0.8, label="threshold")
    # on a log axis: an identified threshold lies far below the push's residual
    ax_r.set_yscale("log", nonpositive="mask")
    ax_r.set_ylim(bottom=trace.contact_threshold / 30.0)
    _mark(ax_r, result.t_c, "t_c", "C3")
    ax_r.set_xlabel("t (s)")
    ax_r.set_ylabel("residual (N m, log)")
    ax_r.legend(fontsize=7)
    return save_figure(fig, out / "figure11-contact.png")


def _figure12(trace: FrontTrace, antenna: Antenna, result: ContactEstimate, out: Path) -> Path:
    # Section 4.2: R = F - F_g^m, with the offset the front end removed
    reaction, _ = contact_loads(trace.theta, trace.force, trace.torque, antenna)
    fig, (ax_f, ax_a) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    ax_f.plot(
        trace.t,
        np.linalg.norm(reaction - trace.load_offset[:3], axis=1),
        lw=0.7,
        label="|F - F_g|",
    )
    ax_f.plot(trace.t, np.linalg.norm(trace.reaction_f, axis=1), lw=1.5, label="filtered (Eq. 20)")
    _mark(ax_f, result.t_c, "t_c", "C3")
    _mark(ax_f, result.t_1, "t_1 (head at rest)", "C2")
    ax_f.set_ylabel("contact force (N)")
    ax_f.legend(fontsize=7)
    ax_f.set_title("Figure 12 - " + _title(result), fontsize=9)
    ax_a.plot(trace.t, trace.theta[:, 0], label="theta1")
    ax_a.plot(trace.t, trace.theta[:, 1], label="theta2")
    _mark(ax_a, result.t_1, "t_1", "C2")
    ax_a.set_xlabel("t (s)")
    ax_a.set_ylabel("motor angle (rad)")
    ax_a.legend(fontsize=7)
    return save_figure(fig, out / "figure12-push.png")


def _figure13(trace: FrontTrace, result: ContactEstimate, zero_padding: int, out: Path) -> Path:
    assert trace.frame is not None and trace.spectrum is not None
    window = trace.spectrum
    # the torque about Y^c and Z^c (rows of the contact frame in motor coordinates)
    projected = trace.torque[window] @ trace.frame.axes_m[1:].T
    t = trace.t[window]
    fig, (ax_t, ax_s) = plt.subplots(2, 1, figsize=(7, 6))
    ax_t.plot(t, projected[:, 0], lw=1.0, label="Gamma about Y^c")
    ax_t.plot(t, projected[:, 1], lw=1.0, label="Gamma about Z^c")
    ax_t.set_xlabel("t (s)")
    ax_t.set_ylabel("torque (N m)")
    ax_t.legend(fontsize=7)
    ax_t.set_title("Figure 13 - " + _title(result), fontsize=9)
    if projected.shape[0] >= 4:
        omega, power = power_spectrum(projected, trace.sample_period, zero_padding)
        # the searched band and as much again beyond it (a short link rings at hundreds of
        # rad/s), at least up to 400 rad/s
        keep = omega <= max(400.0, 2.0 * trace.band[1])
        ax_s.semilogy(omega[keep], power[keep, 0], lw=1.0, label="about Y^c")
        ax_s.semilogy(omega[keep], power[keep, 1], lw=1.0, label="about Z^c")
        ax_s.axvspan(trace.band[0], trace.band[1], color="0.9", label="searched band")
        if math.isfinite(result.omega1):
            ax_s.axvline(
                result.omega1, color="C3", ls="--", label=f"omega_1 = {result.omega1:.2f} rad/s"
            )
    ax_s.set_xlabel("omega (rad/s)")
    ax_s.set_ylabel("power (N^2 m^2)")
    ax_s.legend(fontsize=7)
    return save_figure(fig, out / "figure13-frequency.png")


def _figure14(trace: FrontTrace, antenna: Antenna, result: ContactEstimate, out: Path) -> Path:
    after = slice(trace.contact_index, None)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(trace.t[after], _CM * trace.ratio[after], lw=1.0, label="x_c(t), Estimator 2")
    if math.isfinite(result.ratio_estimate):
        ax.axhline(_CM * result.ratio_estimate, color="C1", ls=":", label="ratio estimate at t_e")
    if math.isfinite(result.x_c):
        ax.axhline(_CM * result.x_c, color="C3", label="fused x_c")
    for c in result.candidates:
        ax.axhline(_CM * c, color="0.6", lw=0.8, ls="--")
    _mark(ax, result.t_1, "t_1", "C2")
    _mark(ax, result.t_e, "t_e", "k")
    ax.set_ylim(0.0, 1.5 * _CM * antenna.link.length)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("x_c (cm)")
    ax.legend(fontsize=7)
    ax.set_title("Figure 14 - " + _title(result), fontsize=9)
    return save_figure(fig, out / "figure14-ratio.png")
