"""Figures of one recording: motor angles, forces and torques over time, torque spectrum.

In the style of the paper's Figures 11, 12, 13 and 20: time in s, angles in degrees (display
edge), forces in N and torques in N m about O in the motor frame (a recording whose torques
were moved there from the sensor's own point says so in the title); the spectrum (Figures 13b
and 19) is the magnitude of the FFT of each torque component after the motors stop.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from sensing_antenna.plotting import save_figure
from sensing_antenna.recording import REQUIRED_COLUMNS, Recording, RecordingError, resample_uniform
from sensing_antenna.torque_point import MOVED_KEY

__all__ = ["PLOT_LIMIT", "plot_recording"]

#: Largest magnitude drawn (1e300, in the columns' SI units): below it the figure's arithmetic
#: (degrees, axis margins and tick spacing, the spectrum's sums over up to
#: ``recording.MAX_SAMPLES`` samples) stays finite, and no reading in SI units comes near it.
#: A recording beyond it is refused rather than clipped: a clipped curve would look like a real
#: reading at the clip level, and the message names the sample the figure would have shown.
PLOT_LIMIT = 1e300


def _check_plottable(recording: Recording) -> None:
    """Raise RecordingError naming the first column and sample beyond :data:`PLOT_LIMIT`."""
    columns = {
        "t": recording.t,
        **{name: recording.theta[:, j] for j, name in enumerate(REQUIRED_COLUMNS[1:3])},
        **{name: recording.force[:, j] for j, name in enumerate(REQUIRED_COLUMNS[3:6])},
        **{name: recording.torque[:, j] for j, name in enumerate(REQUIRED_COLUMNS[6:9])},
        **{
            name: recording.extra[name]
            for name in ("theta1_ref", "theta2_ref")
            if name in recording.extra
        },
    }
    for name, values in columns.items():
        beyond = np.flatnonzero(np.abs(values) > PLOT_LIMIT)
        if beyond.size:
            k = int(beyond[0])
            raise RecordingError(
                recording.source,
                None,
                name,
                f"{float(values[k])!r} at sample {k} (t = {float(recording.t[k])!r} s) is beyond"
                f" +-{PLOT_LIMIT:g}: too large to plot",
            )


def _stop_time(recording: Recording) -> float | None:
    text = recording.metadata.get("true_t_stop")
    try:
        value = float(text) if text is not None else math.nan
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _about(recording: Recording, name: str) -> str:
    """Where the plotted torques are taken: about O, and from where they were moved."""
    if name != "torque":
        return ""
    moved = recording.metadata.get(MOVED_KEY)
    return " about O" if moved is None else f" about O (moved from the sensor's point {moved} m)"


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

    Raises
    ------
    RecordingError
        When a plotted column holds a magnitude above :data:`PLOT_LIMIT`, naming the column and
        the sample.
    """
    _check_plottable(recording)
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
        # on two lines: a long description would run past the figure's edge
        axes[0].set_title(
            f"{name}{_about(recording, name)} by the link on the head (motor frame)\n{title}",
            fontsize=9,
        )
        axes[-1].set_xlabel("t (s)")
        paths.append(save_figure(fig, out / f"{name}.png", dpi=110))

    # the spectrum on the uniform grid, as the estimators read an irregular recording
    uniform = resample_uniform(recording) if recording.sampling.irregular else recording
    start = (
        int(np.searchsorted(uniform.t, stop)) + 100 if stop is not None else uniform.n_samples // 2
    )
    if uniform.n_samples - start >= 64:
        period = uniform.sample_period
        fig, ax = plt.subplots(figsize=(7, 3.5))
        for i, axis_name in enumerate("xyz"):
            x = uniform.torque[start:, i] - uniform.torque[start:, i].mean()
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
