"""Timed streams from a log put onto a recording's one uniform clock, with rates and gaps.

A lab's log holds the force/torque sensor and the joint angles as separate streams, each with its
own time stamps, rate, jitter and dropped messages. A recording has one clock. :func:`put_on_clock`
lays a grid of step T_s (by default the wrench stream's span over the number of sample periods it
holds, which stamp jitter barely moves) over the time both streams cover, starting at the first
wrench message in it, and fills each slot k (time k T_s):

- the wrench with the sensor's own sample: the message whose stamp is nearest to the slot, when
  it lies within T_s / 2 (stamp jitter moves no value; nothing is interpolated). A slot with
  none (a dropped message) takes the straight line between the messages either side;
- the joint angles by linear interpolation between the messages either side (joint states
  usually come slower than the sensor, and the angles move smoothly);
- a slot inside a gap of either stream, a step between two messages longer than ``max_gap``
  times that stream's median step, is left out: the recording then shows the missing samples
  and the estimators treat them as dropped (docs/recording-format.md), instead of estimating
  from straight lines drawn across the gap.

Time stamps are integer nanoseconds throughout, so a stream written at the grid's own instants
comes out with its values unchanged, to the bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.recording import MAX_SAMPLES

__all__ = [
    "DEFAULT_MAX_GAP",
    "ClockReport",
    "ClockedStreams",
    "ImporterError",
    "Stream",
    "StreamReport",
    "put_on_clock",
]

#: A step longer than this many median steps of its stream is a gap whose slots are left out
#: (3: the estimators give ``bad_input`` for more than three samples missing in a row after the
#: push, so a shorter hole is bridged and a longer one shown).
DEFAULT_MAX_GAP = 3.0

_NS = 1e9  # nanoseconds per second


class ImporterError(SensingAntennaError, ValueError):
    """A log cannot be made into a recording; the message names the file and the stream."""


@dataclass(frozen=True)
class Stream:
    """One stream of a log: time stamps and the values at them.

    Parameters
    ----------
    name : str
        The stream's name in the log (a ROS topic).
    kind : str
        What it carries (a ROS message type).
    stamps : ndarray of int64, shape (n,)
        Time stamps (ns), strictly increasing, n >= 2.
    values : ndarray, shape (n, k)
        The values at each stamp (SI units).
    """

    name: str
    kind: str
    stamps: NDArray[np.int64]
    values: NDArray[np.float64]


@dataclass(frozen=True)
class StreamReport:
    """Rates and gaps of one stream.

    Parameters
    ----------
    name, kind : str
        As in :class:`Stream`.
    n_messages : int
        Messages in the stream.
    median_period : float
        Median step between consecutive stamps (s).
    largest_step : float
        Largest step between consecutive stamps (s).
    n_gaps : int
        Steps longer than ``max_gap`` median steps.
    """

    name: str
    kind: str
    n_messages: int
    median_period: float
    largest_step: float
    n_gaps: int

    @property
    def median_rate(self) -> float:
        """1 / median_period (Hz)."""
        return 1.0 / self.median_period

    def line(self) -> str:
        """One line for a person: count, rate, largest gap."""
        periods = self.largest_step / self.median_period
        return (
            f"{self.name} ({self.kind}): {self.n_messages} messages, median rate"
            f" {self.median_rate:.6g} Hz, largest step {self.largest_step:.6g} s"
            f" ({periods:.3g} median steps), {self.n_gaps} gap(s)"
        )


@dataclass(frozen=True)
class ClockReport:
    """How two streams were put on one clock.

    Parameters
    ----------
    wrench, joints : StreamReport
        The two streams' rates and gaps.
    period : float
        T_s (s).
    origin_ns : int
        Stamp (ns) of the grid's slot 0, t = 0.
    n_slots : int
        Slots of the grid over the time both streams cover, kept or not.
    n_samples : int
        Slots kept: the samples of the recording.
    n_interpolated : int
        Samples without a wrench message within T_s / 2, filled by a straight line.
    n_left_out : int
        Slots left out, inside a gap of either stream.
    largest_offset : float
        Largest distance between a wrench message used as it is and its slot (s): the stamps'
        jitter against the clock.
    max_gap : float
        The gap threshold used (median steps).
    """

    wrench: StreamReport
    joints: StreamReport
    period: float
    origin_ns: int
    n_slots: int
    n_samples: int
    n_interpolated: int
    n_left_out: int
    largest_offset: float
    max_gap: float

    def lines(self) -> list[str]:
        """Lines for a person: each stream, the clock, the samples filled and left out."""
        span = (self.n_slots - 1) * self.period
        return [
            f"wrench {self.wrench.line()}",
            f"joints {self.joints.line()}",
            f"clock: {self.n_samples} samples every {self.period:.6g} s"
            f" ({1.0 / self.period:.6g} Hz) over {span:.6g} s; wrench stamps within"
            f" {self.largest_offset:.3g} s of it",
            f"{self.n_interpolated} sample(s) without their own wrench message, interpolated;"
            f" {self.n_left_out} left out in gaps longer than {self.max_gap:g} median steps",
        ]


@dataclass(frozen=True)
class ClockedStreams:
    """The wrench and the joints on one uniform clock.

    Parameters
    ----------
    t : ndarray, shape (m,)
        Times of the slots kept (s), k T_s from the grid's origin.
    wrench : ndarray, shape (m, w)
        The wrench stream's values at those slots.
    joints : ndarray, shape (m, j)
        The joint stream's values at those slots.
    report : ClockReport
    """

    t: NDArray[np.float64]
    wrench: NDArray[np.float64]
    joints: NDArray[np.float64]
    report: ClockReport


def _check_stream(stream: Stream, source: str) -> None:
    stamps = stream.stamps
    if stamps.shape[0] < 2:
        raise ImporterError(
            f"{source}: {stream.name!r}: {stamps.shape[0]} message(s), at least 2 needed"
        )
    steps = np.diff(stamps)
    if not np.all(steps > 0):
        k = int(np.argmin(steps > 0))
        raise ImporterError(
            f"{source}: {stream.name!r}: messages {k} and {k + 1} (in time order) have the same"
            f" stamp, {int(stamps[k])} ns"
        )


def _report(stream: Stream, max_gap: float) -> StreamReport:
    steps = np.diff(stream.stamps)
    median = float(np.median(steps))
    return StreamReport(
        name=stream.name,
        kind=stream.kind,
        n_messages=int(stream.stamps.shape[0]),
        median_period=median / _NS,
        largest_step=float(np.max(steps)) / _NS,
        n_gaps=int(np.sum(steps > max_gap * median)),
    )


def _in_gap(
    stamps: NDArray[np.float64], slots: NDArray[np.float64], limit: float
) -> NDArray[np.bool_]:
    """For each slot time, whether it lies strictly between two stamps more than ``limit``
    apart (all in ns relative to the origin)."""
    after = np.searchsorted(stamps, slots, side="right")
    inside = (after > 0) & (after < stamps.shape[0])
    before = np.clip(after - 1, 0, stamps.shape[0] - 1)
    following = np.clip(after, 0, stamps.shape[0] - 1)
    return inside & (stamps[following] - stamps[before] > limit) & (slots > stamps[before])


def put_on_clock(
    wrench: Stream,
    joints: Stream,
    *,
    source: str,
    period: float | None = None,
    max_gap: float = DEFAULT_MAX_GAP,
) -> ClockedStreams:
    """Lay the wrench and joint streams on one uniform clock (see the module's docstring).

    Parameters
    ----------
    wrench, joints : Stream
        The force/torque stream (the clock's reference) and the joint angles.
    source : str
        The log's name, for messages.
    period : float, optional
        T_s (s); when None, the wrench stream's span over the number of periods it holds
        (each step counted as the whole number of median steps nearest to it).
    max_gap : float
        Steps longer than this many median steps of their stream are gaps (> 1).

    Returns
    -------
    ClockedStreams

    Raises
    ------
    ImporterError
        A stream with fewer than two messages or two at the same stamp; streams that do not
        overlap in time; a grid with more than :data:`~sensing_antenna.recording.MAX_SAMPLES`
        slots; fewer than two slots kept.
    """
    for stream in (wrench, joints):
        _check_stream(stream, source)
    if not (math.isfinite(max_gap) and max_gap > 1.0):
        raise ValueError(f"max_gap must be a finite number > 1, got {max_gap!r}")
    wrench_report, joints_report = _report(wrench, max_gap), _report(joints, max_gap)
    start = max(int(wrench.stamps[0]), int(joints.stamps[0]))
    end = min(int(wrench.stamps[-1]), int(joints.stamps[-1]))
    if start >= end:
        raise ImporterError(
            f"{source}: {wrench.name!r} ({_span(wrench)}) and {joints.name!r} ({_span(joints)})"
            " do not overlap in time"
        )
    step = _mean_period(wrench.stamps) if period is None else float(period)
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"period must be finite and > 0, got {step!r}")
    step_ns = step * _NS
    first = int(np.searchsorted(wrench.stamps, start, side="left"))
    origin = int(wrench.stamps[first])
    periods = (end - origin) / step_ns
    if periods >= MAX_SAMPLES:
        raise ImporterError(
            f"{source}: {(end - origin) / _NS:.6g} s of overlap at {step:.6g} s per sample"
            f" is {periods:.4g} samples, more than the limit of {MAX_SAMPLES}"
        )
    n_slots = math.floor(periods + 1e-9) + 1
    slot_ns = np.arange(n_slots, dtype=np.float64) * step_ns
    wrench_ns = (wrench.stamps - origin).astype(np.float64)
    joints_ns = (joints.stamps - origin).astype(np.float64)

    # the wrench message nearest each slot, when within T_s / 2 (the first of a tie)
    nearest = np.rint(wrench_ns / step_ns)
    offset = np.abs(wrench_ns - nearest * step_ns)
    usable = np.flatnonzero((nearest >= 0) & (nearest < n_slots) & (offset <= step_ns / 2))
    order = usable[np.lexsort((offset[usable], nearest[usable]))]
    slot_of = nearest[order].astype(np.int64)
    keep_first = np.ones(order.shape[0], dtype=bool)
    keep_first[1:] = slot_of[1:] != slot_of[:-1]
    own_message = np.full(n_slots, -1, dtype=np.int64)
    own_message[slot_of[keep_first]] = order[keep_first]
    has_own = own_message >= 0

    wrench_values = np.column_stack(
        [np.interp(slot_ns, wrench_ns, column) for column in wrench.values.T]
    )
    wrench_values[has_own] = wrench.values[own_message[has_own]]
    joint_values = np.column_stack(
        [np.interp(slot_ns, joints_ns, column) for column in joints.values.T]
    )
    wrench_limit = max_gap * wrench_report.median_period * _NS
    joints_limit = max_gap * joints_report.median_period * _NS
    left_out = (~has_own & _in_gap(wrench_ns, slot_ns, wrench_limit)) | _in_gap(
        joints_ns, slot_ns, joints_limit
    )
    kept = np.flatnonzero(~left_out)
    if kept.shape[0] < 2:
        raise ImporterError(
            f"{source}: {kept.shape[0]} sample(s) outside the streams' gaps, at least 2 needed"
        )
    used = own_message[has_own]
    largest_offset = float(np.max(offset[used])) / _NS if used.size else 0.0
    report = ClockReport(
        wrench=wrench_report,
        joints=joints_report,
        period=step,
        origin_ns=origin,
        n_slots=n_slots,
        n_samples=int(kept.shape[0]),
        n_interpolated=int(np.sum(~has_own[kept])),
        n_left_out=int(np.sum(left_out)),
        largest_offset=largest_offset,
        max_gap=max_gap,
    )
    return ClockedStreams(
        t=kept.astype(np.float64) * step,
        wrench=wrench_values[kept],
        joints=joint_values[kept],
        report=report,
    )


def _mean_period(stamps: NDArray[np.int64]) -> float:
    """A stream's sample period (s): its span over the number of periods it holds, each step
    counted as the whole number of median steps nearest to it (a dropped message makes a step
    of two). Stamp jitter enters only through the first and last stamps, so the error is at most
    twice the jitter over the span; the median of jittered steps can be off by far more, and a
    clock that runs fast or slow slips past the sensor's samples over a long log."""
    steps = np.diff(stamps)
    median = float(np.median(steps))
    periods = np.maximum(np.rint(steps / median), 1.0)
    return float(stamps[-1] - stamps[0]) / float(np.sum(periods)) / _NS


def _span(stream: Stream) -> str:
    return f"{int(stream.stamps[0]) / _NS:.9f} to {int(stream.stamps[-1]) / _NS:.9f} s"
