"""The registry of estimation methods (what ``--method`` may name) and what a method is.

A method is an :class:`EstimationMethod`: a ``name`` and ``conclude(evidence) -> ContactEstimate``.
Two optional abilities, each a protocol the online estimator checks once per manoeuvre:

- :class:`EarlyStopping` (``fast``): ``due(samples_since_t1, sample_period)`` (cheap: is this an
  evaluation instant?) and ``ready(evidence)`` (may it conclude from the samples so far?); the
  online estimator asks ``ready`` on the ``due`` cadence, and ``conclude`` on the evidence at t_e
  scans the same instants, so both forms stay identical.
- :class:`Sessioned` (``fast``): ``session()`` gives a fresh method that keeps state over one
  manoeuvre (its window fits); the online estimator takes one at every reset.
- :class:`Preparing` (``fast``'s session): ``wants_to_prepare(...)`` (cheap) and
  ``prepare(samples, antenna, hold_end)``, one step of the work its coming evaluations will
  need, done while the online estimator's caller has nothing to feed; it changes no answer.

A new method is added to ``_BUILTIN_METHODS``; the command line lists whatever :data:`METHODS`
holds.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Protocol, runtime_checkable

from sensing_antenna.antenna import Antenna
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.estimation.front.evidence import Evidence
from sensing_antenna.estimation.front.outcome import FrontTrace
from sensing_antenna.estimation.methods.baselines import RatioMethod, TwoFrequencyMethod
from sensing_antenna.estimation.methods.fast.method import FastMethod
from sensing_antenna.estimation.methods.paper.fusion import PaperMethod
from sensing_antenna.estimation.result import ContactEstimate

__all__ = [
    "METHODS",
    "EarlyStopping",
    "EstimationMethod",
    "Preparing",
    "Sessioned",
    "UnknownMethodError",
    "resolve_method",
]


@runtime_checkable
class EstimationMethod(Protocol):
    """A way to turn the evidence at t_e into an estimate."""

    @property
    def name(self) -> str:
        """Name used by ``--method``."""
        ...

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        """The estimate from the evidence at t_e."""
        ...


@runtime_checkable
class EarlyStopping(EstimationMethod, Protocol):
    """A method that may conclude before t_e, from the samples up to an earlier instant."""

    def due(self, samples_since_t1: int, sample_period: float) -> bool:
        """Whether the instant ``samples_since_t1`` samples after t_1 is one to ask ``ready`` at
        (T_s = ``sample_period`` in s); cheap."""
        ...

    def ready(self, evidence: Evidence) -> bool:
        """Whether the evidence up to its ``end_index`` suffices to conclude now."""
        ...


@runtime_checkable
class Sessioned(EstimationMethod, Protocol):
    """A method that keeps state over one manoeuvre when run online."""

    def session(self) -> EstimationMethod:
        """A fresh method for one manoeuvre (the online estimator takes one at every reset)."""
        ...


@runtime_checkable
class Preparing(EstimationMethod, Protocol):
    """A method (online: a session) that can do part of its next evaluation's work ahead of time,
    from the samples already fed, without changing any answer."""

    def wants_to_prepare(
        self,
        last_index: int,
        rest_index: int,
        hold_end: int,
        sample_period: float,
        step_time: float = 0.0,
    ) -> bool:
        """Whether :meth:`prepare` has work once the samples up to ``last_index`` have arrived
        (t_1 at ``rest_index``, evaluations from ``hold_end`` on, T_s in s; ``step_time``: how
        long a step is expected to take, in s); cheap."""
        ...

    def prepare(
        self, samples: FrontTrace, antenna: Antenna, hold_end: int, step_time: float = 0.0
    ) -> bool:
        """One step of that work on the samples fed so far; False when there is none."""
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
