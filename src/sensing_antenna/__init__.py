"""sensing-antenna: contact-point estimation for robotic sensing antennae.

Subpackages and modules, one concept each:

- :mod:`sensing_antenna.antenna`: antenna parameters as data (TOML, built-in ``paper-2021``).
- :mod:`sensing_antenna.beam`: contact-mode beam physics (frequencies, modes, statics, inverse).
- :mod:`sensing_antenna.recording`: the recording format (read, write, validate).
- :mod:`sensing_antenna.detection`: the contact and push detectors and their filters, run online
  by the simulator's controller and the estimators alike.
- :mod:`sensing_antenna.simulator`: the 2-DOF device simulator that writes recordings.
- :mod:`sensing_antenna.estimation`: the front end (t_c, t_1, contact frame, Estimator 2's ratio)
  and the methods (the paper's fusion, baselines, ``fast``).
- :mod:`sensing_antenna.calibration`: fitting T_e, the free-motion observer and the sensor's
  cross-talk.
- :mod:`sensing_antenna.campaign`: declarative experiment campaigns and their reports.
- :mod:`sensing_antenna.plotting`: every figure, kept apart from computation.
- :mod:`sensing_antenna.cli`: the ``antenna`` command; parses arguments and calls the library.

The names below are imported on first use, so that importing one light module (the command
line, :mod:`sensing_antenna.errors`) does not load NumPy.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sensing_antenna.antenna import Antenna, load_antenna, paper_antenna

__all__ = ["Antenna", "load_antenna", "paper_antenna"]
__version__ = "0.1.0"


def __getattr__(name: str) -> Any:
    if name not in __all__:
        raise AttributeError(f"module 'sensing_antenna' has no attribute {name!r}")
    return getattr(importlib.import_module("sensing_antenna.antenna"), name)


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
