"""Exploration: planned sweeps of the simulated device in a scene, each contact mapped.

Above ``scene/``, ``mapping/`` and the estimators, below ``cli/`` (docs/explore.md):

- :mod:`.plan`: the grid and the next-best sweep;
- :mod:`.store`: the output directory, written so that an exploration resumes;
- :mod:`.run`: :func:`explore`.
"""

from sensing_antenna.exploration.plan import (
    STRATEGIES,
    NextBestPlanner,
    candidate_sweeps,
    grid_sweeps,
)
from sensing_antenna.exploration.run import (
    Exploration,
    ExplorationInterrupted,
    ExploreSettings,
    explore,
    prepare_device,
)
from sensing_antenna.exploration.store import ExplorationStoreError, Manoeuvre

__all__ = [
    "STRATEGIES",
    "Exploration",
    "ExplorationInterrupted",
    "ExplorationStoreError",
    "ExploreSettings",
    "Manoeuvre",
    "NextBestPlanner",
    "candidate_sweeps",
    "explore",
    "grid_sweeps",
    "prepare_device",
]
