"""Figures 8 and 9 of the paper: natural frequencies vs contact point, and the f2 - f1 curve."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from sensing_antenna.antenna import Antenna, Link, paper_antenna
from sensing_antenna.beam import natural_frequencies
from sensing_antenna.plotting import save_figure

__all__ = ["PAPER_FUNDAMENTAL_RANGE", "PAPER_T_E", "figure8", "figure9", "plot_sensing_curves"]

#: Section 5.1 / Figure 10: measured fundamental frequencies (rad/s) for x_c in [0.3, 0.98] m.
PAPER_FUNDAMENTAL_RANGE = (31.4, 106.8)
#: Contact points (m) over which the paper measured that range.
PAPER_CONTACT_RANGE = (0.3, 0.98)
#: Calibrated T_e of Section 5.1 (s / m^2).
PAPER_T_E = 0.2124
_SAMPLES = 1500


def _nearest_self_approach(x: np.ndarray, points: np.ndarray) -> int:
    """Index of the point nearest to the curve's end, away from the end's own neighbourhood."""
    distance = np.hypot(*(points - points[-1]).T)
    far = np.abs(x - x[-1]) > 0.1 * (x[-1] - x[0])
    return int(np.argmin(np.where(far, distance, np.inf)))


def _is_papers_link(link: Link) -> bool:
    """Whether ``link`` is the paper's (Table 2), whatever its T_e: the paper's measurements
    belong on its figure only then."""
    paper = paper_antenna().link
    return link.second_moment == paper.second_moment and all(
        math.isclose(getattr(link, name), getattr(paper, name), rel_tol=1e-9)
        for name in ("length", "radius", "youngs_modulus", "linear_density", "tip_mass")
    )


def figure8(antenna: Antenna) -> Figure:
    """Figure 8: f1, f2 and f3 (Hz) against x_c (m), with the link's T or its calibrated T_e
    (labelled so); on the paper's link also f1 with the paper's calibrated T_e = 0.2124 (unless
    that is the link's) and the band the paper measured in Section 5.1 (omega_1 in
    [31.4, 106.8] rad/s for x_c in [0.3, 0.98] m)."""
    link = antenna.link
    x = np.linspace(link.length / _SAMPLES, link.length, _SAMPLES)
    hz = natural_frequencies(link, x, 3) / (2.0 * math.pi)
    t_name = "T" if link.calibrated_t is None else "T_e"
    fig, ax = plt.subplots(figsize=(7.0, 4.8))
    for i in range(3):
        ax.plot(x, hz[:, i], label=f"f{i + 1} ({t_name} = {link.t_param:.4f} s/m$^2$)")
    if _is_papers_link(link):
        if not math.isclose(link.t_param, PAPER_T_E):
            calibrated = antenna.with_calibrated_t(PAPER_T_E).link
            hz_cal = natural_frequencies(calibrated, x, 1)[:, 0] / (2.0 * math.pi)
            ax.plot(x, hz_cal, "k--", lw=1.2, label=f"f1 with the paper's T_e = {PAPER_T_E}")
        low, high = (w / (2.0 * math.pi) for w in PAPER_FUNDAMENTAL_RANGE)
        x0, x1 = PAPER_CONTACT_RANGE
        ax.fill_between(
            [x0, x1], low, high, color="tab:gray", alpha=0.2, label="the paper's measured f1 band"
        )
    ax.set_xlabel("contact point x_c [m]")
    ax.set_ylabel("natural frequency [Hz]")
    ax.set_title(f"Figure 8: natural frequencies in contact mode ({antenna.name})")
    ax.set_xlim(0.0, link.length)
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    return fig


def figure9(antenna: Antenna) -> Figure:
    """Figure 9: the sensing curve f2 - f1 against f1 (Hz), coloured by x_c, with the end
    x_c = l and the point where the curve passes closest to it (x_c ~ 0.615 m in the paper)."""
    link = antenna.link
    x = np.linspace(link.length / _SAMPLES, link.length, _SAMPLES)
    hz = natural_frequencies(link, x, 2) / (2.0 * math.pi)
    points = np.stack([hz[:, 0], hz[:, 1] - hz[:, 0]], axis=1)
    near = _nearest_self_approach(x, points)
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    sc = ax.scatter(points[:, 0], points[:, 1], c=x, s=3, cmap="viridis")
    ax.plot(points[:, 0], points[:, 1], color="0.6", lw=0.6, zorder=0)
    fig.colorbar(sc, ax=ax, label="x_c [m]")
    ax.plot(*points[-1], "rs", label=f"x_c = {x[-1]:.3g} m (end)")
    gap = float(np.hypot(*(points[near] - points[-1])))
    ax.plot(*points[near], "r^", label=f"x_c = {x[near]:.3f} m, {gap:.2f} Hz away")
    ax.set_xlabel("f1 [Hz]")
    ax.set_ylabel("f2 - f1 [Hz]")
    ax.set_title(f"Figure 9: sensing curve f2 - f1 ({antenna.name})")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return fig


def plot_sensing_curves(antenna: Antenna, out_dir: str | Path) -> list[Path]:
    """Write :func:`figure8` and :func:`figure9` of ``antenna`` as ``figure8.png`` and
    ``figure9.png`` in ``out_dir`` (created if missing); returns their paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    return [
        save_figure(figure8(antenna), out / "figure8.png"),
        save_figure(figure9(antenna), out / "figure9.png"),
    ]
