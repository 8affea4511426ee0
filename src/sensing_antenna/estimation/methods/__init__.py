"""The registry of estimation methods: what ``--method`` may name.

A method is an object with a ``name`` and ``conclude(evidence) -> ContactEstimate``; a method that
can stop earlier (``fast``) also has ``due(samples_since_t1, sample_period)`` (cheap: is this an
evaluation instant?) and ``ready(evidence)``; one that keeps state over a manoeuvre online has
``session()``, which gives a fresh object with ``name``, ``due``, ``ready``, ``conclude`` and
``session`` (the online estimator takes one per manoeuvre). A new method is added to
``_BUILTIN_METHODS``; the command line lists whatever :data:`METHODS` holds.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Protocol

from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.estimation.front.evidence import Evidence
from sensing_antenna.estimation.methods.baselines import RatioMethod, TwoFrequencyMethod
from sensing_antenna.estimation.methods.fast.method import FastMethod
from sensing_antenna.estimation.methods.paper.fusion import PaperMethod
from sensing_antenna.estimation.result import ContactEstimate

__all__ = ["METHODS", "EstimationMethod", "UnknownMethodError", "resolve_method"]


class EstimationMethod(Protocol):
    """A way to turn the evidence at t_e into an estimate."""

    @property
    def name(self) -> str:
        """Name used by ``--method``."""
        ...

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        """The estimate from the evidence at t_e."""
        ...


_BUILTIN_METHODS: tuple[EstimationMethod, ...] = (
    PaperMethod(),
    RatioMethod(),
    TwoFrequencyMethod(),
    FastMethod(),
)

#: Available methods by name (read-only).
METHODS: Mapping[str, EstimationMethod] = MappingProxyType({m.name: m for m in _BUILTIN_METHODS})


class UnknownMethodError(SensingAntennaError, ValueError):
    """The requested estimation method does not exist."""


def resolve_method(method: str | EstimationMethod) -> EstimationMethod:
    """The method object for a name of :data:`METHODS` (objects are returned as given).

    Raises
    ------
    UnknownMethodError
        For an unknown name.
    """
    if not isinstance(method, str):
        return method
    try:
        return METHODS[method]
    except KeyError:
        raise UnknownMethodError(
            f"method: unknown {method!r}; known: {', '.join(sorted(METHODS))}"
        ) from None
