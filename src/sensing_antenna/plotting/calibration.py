"""Figure 10: calibration of the frequency-contact point function (Section 5.1)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from sensing_antenna.antenna import Link
from sensing_antenna.calibration.frequency import FrequencyCalibration, model_beta1_squared
from sensing_antenna.plotting import save_figure

__all__ = ["plot_calibration"]

_CM = 100.0


def plot_calibration(calibration: FrequencyCalibration, link: Link, out_dir: str | Path) -> Path:
    """Measured omega_1 vs x_c with the fitted curve (T_e) and the theoretical one (T).

    Parameters
    ----------
    calibration : FrequencyCalibration
    link : Link
        The link of the model (its length sets the curve's range).
    out_dir : str or Path
        Directory for ``figure10-calibration.png`` (created if missing).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    grid = np.linspace(0.25 * link.length, link.length, 200)
    k = model_beta1_squared(link, grid)
    fig, (ax, ax_r) = plt.subplots(
        2, 1, figsize=(6.5, 5.5), sharex=True, gridspec_kw={"height_ratios": [3, 1]}
    )
    ax.plot(grid * _CM, k / calibration.t_e, lw=1.5, label=f"fitted, T_e = {calibration.t_e:.4f}")
    ax.plot(
        grid * _CM,
        k / calibration.t_theoretical,
        "--",
        color="0.5",
        lw=1,
        label=f"theoretical, T = {calibration.t_theoretical:.4f}",
    )
    used = calibration.used
    wrong = calibration.wrong_peak_points & ~used
    missing = ~used & ~wrong
    x = calibration.contact_points * _CM
    ax.plot(x[used], calibration.omega1_measured[used], "o", mfc="none", label="measured")
    if np.any(wrong):
        ax.plot(
            x[wrong],
            calibration.omega1_measured[wrong],
            "r^",
            label="left out: a wrong peak or a wrong known point",
        )
    if np.any(missing):
        ax.plot(x[missing], np.zeros(int(np.sum(missing))), "rx", label="no frequency found")
    ax.set_ylabel("omega_1 (rad/s)")
    ax.set_title("Figure 10: calibration of the frequency-contact point function")
    ax.legend()
    ax_r.axhline(0.0, color="0.6", lw=1)
    ax_r.plot(x[used], calibration.residuals[used], "o", mfc="none")
    ax_r.set_xlabel("contact point x_c (cm)")
    ax_r.set_ylabel("residual (rad/s)")
    return save_figure(fig, out / "figure10-calibration.png")
