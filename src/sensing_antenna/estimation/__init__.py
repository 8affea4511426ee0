"""Contact-point estimation: a front end (contact instant, push, contact frame, Estimator 2's
ratio) and interchangeable methods (the paper's fusion, baselines, ``fast``).

Public entry points (imported lazily, so that importing one submodule does not load the whole
pipeline):

- :func:`estimate` (offline) and :class:`OnlineEstimator` (streaming), :data:`METHODS`;
- the two steps of ``estimate``: :func:`gather` (the front end on a recording: an
  :class:`Evidence` or an :class:`EarlyOutcome`) and :func:`conclude` (a method's estimate from
  it); :class:`FrontEnd`, the front end as a streaming object; :class:`FrontTrace`, what it saw;
- :func:`measure_omega1`, Estimator 1's frequency measurement alone (:func:`omega1_of` on
  evidence already gathered);
- :class:`ContactEstimate`, :class:`Status`, :class:`EstimatorConfig`;
- what a method is: :class:`EstimationMethod`, :class:`EarlyStopping`, :class:`Sessioned`;
- :class:`FastMethod` and :class:`FastConfig`, the fast method and its settings.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sensing_antenna.estimation.config import EstimatorConfig
    from sensing_antenna.estimation.front.evidence import Evidence
    from sensing_antenna.estimation.front.frontend import FrontEnd
    from sensing_antenna.estimation.front.outcome import EarlyOutcome, FrontTrace
    from sensing_antenna.estimation.methods import (
        METHODS,
        EarlyStopping,
        EstimationMethod,
        Sessioned,
    )
    from sensing_antenna.estimation.methods.fast import FastConfig, FastMethod
    from sensing_antenna.estimation.methods.paper.frequency import FrequencyMeasurement
    from sensing_antenna.estimation.online import OnlineEstimator
    from sensing_antenna.estimation.pipeline import (
        conclude,
        estimate,
        gather,
        measure_omega1,
        omega1_of,
    )
    from sensing_antenna.estimation.result import ContactEstimate, Status

__all__ = [
    "METHODS",
    "ContactEstimate",
    "EarlyOutcome",
    "EarlyStopping",
    "EstimationMethod",
    "EstimatorConfig",
    "Evidence",
    "FastConfig",
    "FastMethod",
    "FrequencyMeasurement",
    "FrontEnd",
    "FrontTrace",
    "OnlineEstimator",
    "Sessioned",
    "Status",
    "conclude",
    "estimate",
    "gather",
    "measure_omega1",
    "omega1_of",
]

_WHERE = {
    "METHODS": "methods",
    "EarlyStopping": "methods",
    "EstimationMethod": "methods",
    "Sessioned": "methods",
    "OnlineEstimator": "online",
    "conclude": "pipeline",
    "estimate": "pipeline",
    "measure_omega1": "pipeline",
    "omega1_of": "pipeline",
    "gather": "pipeline",
    "FrontEnd": "front.frontend",
    "EarlyOutcome": "front.outcome",
    "FrontTrace": "front.outcome",
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
