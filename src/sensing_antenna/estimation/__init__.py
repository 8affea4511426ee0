"""Contact-point estimation: contact instant, push, Estimators 1 and 2, fusion, baselines.

Public entry points (imported lazily, so that importing one submodule such as
``sensing_antenna.detection.filters`` does not load the whole pipeline):

- :func:`estimate` (offline) and :class:`OnlineEstimator` (streaming), :data:`METHODS`;
- :func:`measure_omega1`, Estimator 1's frequency measurement alone;
- :class:`ContactEstimate`, :class:`Status`, :class:`EstimatorConfig`;
- :class:`FastMethod` and :class:`FastConfig`, the fast method and its settings.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sensing_antenna.estimation.config import EstimatorConfig
    from sensing_antenna.estimation.front.evidence import Evidence
    from sensing_antenna.estimation.methods.fast import FastConfig, FastMethod
    from sensing_antenna.estimation.methods.paper.frequency import FrequencyMeasurement
    from sensing_antenna.estimation.pipeline import (
        METHODS,
        OnlineEstimator,
        estimate,
        gather,
        measure_omega1,
    )
    from sensing_antenna.estimation.result import ContactEstimate, Status

__all__ = [
    "METHODS",
    "ContactEstimate",
    "EstimatorConfig",
    "Evidence",
    "FastConfig",
    "FastMethod",
    "FrequencyMeasurement",
    "OnlineEstimator",
    "Status",
    "estimate",
    "gather",
    "measure_omega1",
]

_WHERE = {
    "METHODS": "pipeline",
    "OnlineEstimator": "pipeline",
    "estimate": "pipeline",
    "gather": "pipeline",
    "measure_omega1": "pipeline",
    "ContactEstimate": "result",
    "Status": "result",
    "EstimatorConfig": "config",
    "Evidence": "front.evidence",
    "FrequencyMeasurement": "methods.paper.frequency",
    "FastMethod": "methods.fast",
    "FastConfig": "methods.fast",
}


def __getattr__(name: str) -> Any:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'sensing_antenna.estimation' has no attribute {name!r}")
    return getattr(importlib.import_module(f"sensing_antenna.estimation.{module}"), name)


def __dir__() -> list[str]:
    return sorted(__all__)
