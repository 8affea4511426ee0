"""Figures of one recording: motor angles, forces and torques over time, torque spectrum.

In the style of the paper's Figures 11, 12, 13 and 20: time in s, angles in degrees (display
edge), forces in N and torques in N m in the motor frame; the spectrum (Figures 13b and 19) is the
magnitude of the FFT of each torque component after the motors stop.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from sensing_antenna.plotting import save_figure
from sensing_antenna.recording import Recording

__all__ = ["plot_recording"]


def _stop_time(recording: Recording) -> float | None:
    text = recording.metadata.get("true_t_stop")
    try:
        value = float(text) if text is not None else math.nan
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def plot_recording(recording: Recording, out_dir: str | Path) -> list[Path]:
    """Draw angles, forces, torques and the torque spectrum of ``recording`` as PNG files.

    Parameters
    ----------
    recording : Recording
    out_dir : str or Path
        Output directory, created if missing.

    Returns
    -------
    list of Path
        The PNG files written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t = recording.t
    stop = _stop_time(recording)
    title = recording.metadata.get("description", recording.source or "recording")
    paths: list[Path] = []

    fig, ax = plt.subplots(figsize=(7, 3.5))
    for j, name in enumerate(("theta1", "theta2")):
        ax.plot(t, np.degrees(recording.theta[:, j]), label=name)
        if f"{name}_ref" in recording.extra:
            ax.plot(t, np.degrees(recording.extra[f"{name}_ref"]), "--", label=f"{name} ref")
    _finish(ax, "motor angle (deg)", title, stop)
    paths.append(save_figure(fig, out / "angles.png", dpi=110))

    for name, data, unit in (("force", recording.force, "N"), ("torque", recording.torque, "N m")):
        fig, axes = plt.subplots(3, 1, figsize=(7, 6), sharex=True)
        for i, axis_name in enumerate("xyz"):
            axes[i].plot(t, data[:, i], lw=0.8)
            _finish(axes[i], f"{name[0].upper()}_{axis_name}^m ({unit})", None, stop)
        axes[0].set_title(f"{name} by the link on the head (motor frame): {title}", fontsize=9)
        axes[-1].set_xlabel("t (s)")
        paths.append(save_figure(fig, out / f"{name}.png", dpi=110))

    start = int(np.searchsorted(t, stop)) + 100 if stop is not None else t.size // 2
    if t.size - start >= 64:
        period = float(np.median(np.diff(t)))
        fig, ax = plt.subplots(figsize=(7, 3.5))
        for i, axis_name in enumerate("xyz"):
            x = recording.torque[start:, i] - recording.torque[start:, i].mean()
            spectrum = np.abs(np.fft.rfft(x * np.hanning(x.size), 8 * x.size))
            omega = 2 * math.pi * np.fft.rfftfreq(8 * x.size, period)
            keep = omega < 300.0
            ax.plot(omega[keep], spectrum[keep], label=f"torque {axis_name}")
        ax.set_xlabel("omega (rad/s)")
        ax.set_ylabel("|FFT| (N m)")
        ax.set_title("torque spectrum after the stop", fontsize=9)
        ax.legend(fontsize=8)
        paths.append(save_figure(fig, out / "torque_spectrum.png", dpi=110))
    return paths


def _finish(ax: plt.Axes, ylabel: str, title: str | None, stop: float | None) -> None:
    if stop is not None:
        ax.axvline(stop, color="k", lw=0.6, ls=":")
    ax.set_ylabel(ylabel, fontsize=8)
    ax.grid(alpha=0.3)
    if title is not None:
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("t (s)")
        ax.legend(fontsize=8)
