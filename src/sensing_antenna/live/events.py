"""What a listener says while samples arrive: one typed record per event.

Every event names the recording it belongs to (counted from 1 in a stream) and carries its
``latency``: the wall time (s) from the receipt of the sample the event is at (t_c, t_1, t_e,
the end of the quiet run that lost the contact, the last sample) to the event's emission. When
the event became known only at a later sample of the same block of samples (t_1 is known once
the head has rested over a window), the latency counts from the first sample of that block, so
it never undercounts. ``to_dict`` gives the JSON object of ``antenna listen`` (SI units).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, TypeAlias

from sensing_antenna.estimation.result import ContactEstimate

__all__ = [
    "ContactEvent",
    "ContactLostEvent",
    "EndEvent",
    "EstimateEvent",
    "Event",
    "PushEvent",
    "SkippedEvent",
]


def _plain(value: float) -> float | None:
    return value if math.isfinite(value) else None


@dataclass(frozen=True)
class ContactEvent:
    """Contact detected: t_c (s), the contact detector's instant, ``input_problem``: why the
    samples up to t_c are not in the format's units and signs (angles in degrees, torques in N
    mm), when they are not, in which case the contact may be no touch at all, and ``tare``:
    how the sensor was tared (``rest``, ``approach``, or ``none`` when the samples began too
    soon before t_c to tare on, a stream joined in the sweep, whose contact may be the contact
    detector's start rather than a touch)."""

    recording: int
    t_c: float
    latency: float
    input_problem: str | None = None
    tare: str | None = None

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of the event."""
        return {
            "event": "contact",
            "recording": self.recording,
            "t_c": self.t_c,
            "input_problem": self.input_problem,
            "tare": self.tare,
            "latency": self.latency,
        }


@dataclass(frozen=True)
class PushEvent:
    """Push reached: t_1 (s), the head at rest against the contact (or the push criterion's
    decision, with ``t1_source = "push"``)."""

    recording: int
    t_1: float
    latency: float

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of the event."""
        return {
            "event": "push",
            "recording": self.recording,
            "t_1": self.t_1,
            "latency": self.latency,
        }


@dataclass(frozen=True)
class EstimateEvent:
    """The estimate declared (once per recording), at t_e or at the end of the samples."""

    recording: int
    estimate: ContactEstimate
    latency: float

    @property
    def x_c(self) -> float:
        """Contact point along the link (m); NaN without one."""
        return self.estimate.x_c

    @property
    def status(self) -> str:
        """The estimate's status (``ok`` or why not)."""
        return self.estimate.status.value

    @property
    def t_e(self) -> float:
        """Instant the estimate is declared at (s)."""
        return self.estimate.t_e

    @property
    def method(self) -> str:
        """Name of the method."""
        return self.estimate.method

    @property
    def interval(self) -> tuple[float, float] | None:
        """95 % interval of x_c (m), for methods that give one."""
        return self.estimate.interval

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of the event: the estimate's ``to_dict`` with the event's fields."""
        return {
            "event": "estimate",
            "recording": self.recording,
            "latency": self.latency,
            **self.estimate.to_dict(),
        }


@dataclass(frozen=True)
class ContactLostEvent:
    """Contact lost at about ``t`` (s): the contact detector's residual, averaged over a period
    of the link's free mode, fell to a fifth of the push's and to its threshold
    (:data:`~sensing_antenna.detection.contact_watch.CONTACT_LOST_SHARE`), a free period or
    less after ``t``."""

    recording: int
    t: float
    latency: float

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of the event."""
        return {
            "event": "contact_lost",
            "recording": self.recording,
            "t": self.t,
            "latency": self.latency,
        }


@dataclass(frozen=True)
class EndEvent:
    """The recording is over: samples received, samples missing (time steps of k sample
    periods count k - 1), the last time stamp (s) and why it ended."""

    recording: int
    samples: int
    dropped: int
    t_last: float
    reason: str
    latency: float

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of the event."""
        return {
            "event": "end",
            "recording": self.recording,
            "samples": self.samples,
            "dropped": self.dropped,
            "t_last": _plain(self.t_last),
            "reason": self.reason,
            "latency": self.latency,
        }


@dataclass(frozen=True)
class SkippedEvent:
    """Input left aside without stopping (a datagram not in the wire format, a late one)."""

    recording: int
    reason: str
    latency: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of the event."""
        return {
            "event": "skipped",
            "recording": self.recording,
            "reason": self.reason,
            "latency": self.latency,
        }


#: Any event of a listener.
Event: TypeAlias = (
    ContactEvent | PushEvent | EstimateEvent | ContactLostEvent | EndEvent | SkippedEvent
)
