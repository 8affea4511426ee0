"""Figures, kept apart from computation. Every function writes PNG files and returns their paths.

Matplotlib is used with the non-interactive Agg backend so plots work on machines without a screen.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt

__all__ = ["save_figure"]


def save_figure(fig: Any, path: Path, dpi: int = 120, tight: bool = True) -> Path:
    """Lay out (``tight``: Matplotlib's tight layout; False keeps the figure's own), write and
    close a figure; returns ``path``."""
    if tight:
        fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
