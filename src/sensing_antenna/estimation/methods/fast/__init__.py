"""The fast method: the contact point from a short record, declared as soon as it is sure.

Where things live (each module one idea):

- :mod:`.config`: :class:`FastConfig`, its validation, the model floor;
- :mod:`.method`: :class:`FastMethod`, the pipeline method (batch form);
- :mod:`.session`: :class:`FastSession`, the online form over one manoeuvre;
- :mod:`.search`: the growing-window search (:func:`scan`, :func:`evaluations`,
  :class:`ScanResult`);
- :mod:`.evaluation_grid`: the instants at which windows are evaluated;
- :mod:`.window`: one evaluation (:class:`WindowEstimate`, :func:`evaluate_window`);
- :mod:`.window_fit`: one window's fit and fundamental (fit cache, push phase, drift term);
- :mod:`.planes`: which bending plane each fitted mode vibrates in;
- :mod:`.checks`: what keeps a window from being declared, and the problems of an estimate;
- :mod:`.second_mode`: the second contact mode chooses between two branches;
- :mod:`.bound`: the information bound of the delay (:func:`bound_delay`), what the method's
  own model could do;
- :mod:`.conclude`: from the final window to the :class:`~.result.ContactEstimate`;
- :mod:`.curves`: the sensing curves on the posterior's grid;
- :mod:`.likelihood`: the posterior over x_c;
- :mod:`.static_fit`: the contact-load channels, the sensor bias, the static torque/force ratio;
- :mod:`.parametric`: the damped-sinusoid fit; :mod:`.model_order` its model order and degree
  by the BIC; :mod:`.pencil` its initial poles; :mod:`.crb` the Cramer-Rao bound;
- :mod:`.varpro`: the fit's compiled model, residual and Jacobian; :mod:`.trust_region` its
  solver.

The names below are imported lazily, so that importing :mod:`.config` alone does not compile the
fit's kernels.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from sensing_antenna.estimation.methods.fast.bound import bound_delay, bound_width
    from sensing_antenna.estimation.methods.fast.config import (
        FastConfig,
        FastConfigError,
        model_floor,
    )
    from sensing_antenna.estimation.methods.fast.curves import CurveTable, curve_table
    from sensing_antenna.estimation.methods.fast.evaluation_grid import evaluation_offsets
    from sensing_antenna.estimation.methods.fast.method import FastMethod
    from sensing_antenna.estimation.methods.fast.search import (
        ScanResult,
        evaluations,
        scan,
        scan_inputs,
    )
    from sensing_antenna.estimation.methods.fast.second_mode import second_mode_chooser
    from sensing_antenna.estimation.methods.fast.session import FastSession
    from sensing_antenna.estimation.methods.fast.window import (
        ScanInputs,
        WindowEstimate,
        evaluate_window,
    )
    from sensing_antenna.estimation.methods.fast.window_fit import PushPhase, push_phase

__all__ = [
    "CurveTable",
    "FastConfig",
    "FastConfigError",
    "FastMethod",
    "FastSession",
    "PushPhase",
    "ScanInputs",
    "ScanResult",
    "WindowEstimate",
    "bound_delay",
    "bound_width",
    "curve_table",
    "evaluate_window",
    "evaluation_offsets",
    "evaluations",
    "model_floor",
    "push_phase",
    "scan",
    "scan_inputs",
    "second_mode_chooser",
]

_WHERE = {
    "CurveTable": "curves",
    "FastConfig": "config",
    "FastConfigError": "config",
    "FastMethod": "method",
    "FastSession": "session",
    "PushPhase": "window_fit",
    "ScanInputs": "window",
    "ScanResult": "search",
    "WindowEstimate": "window",
    "bound_delay": "bound",
    "bound_width": "bound",
    "curve_table": "curves",
    "evaluate_window": "window",
    "evaluation_offsets": "evaluation_grid",
    "evaluations": "search",
    "model_floor": "config",
    "push_phase": "window_fit",
    "scan": "search",
    "scan_inputs": "search",
    "second_mode_chooser": "second_mode",
}


def __getattr__(name: str) -> Any:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(
            f"module 'sensing_antenna.estimation.methods.fast' has no attribute {name!r}"
        )
    return getattr(
        importlib.import_module(f"sensing_antenna.estimation.methods.fast.{module}"), name
    )


def __dir__() -> list[str]:
    return sorted(__all__)
