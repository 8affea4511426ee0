"""Figures, kept apart from computation. Every function writes PNG files and returns their paths.

Matplotlib is used with the non-interactive Agg backend so plots work on machines without a screen.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
