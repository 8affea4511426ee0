"""One recording received live: :class:`Listener`.

The reader of the input (standard input, a UDP socket) hands each sample it parsed to
:meth:`Listener.put`, which only queues it with the wall time it was received. A worker thread
takes everything queued since its last turn and feeds it as one block to the
:class:`~sensing_antenna.estimation.online.OnlineEstimator` (asked at every evaluation instant
of the block, so the estimate is that of ``antenna estimate`` on the same samples however they
were cut into blocks), writes it to the recording file if any, and gives the events
(:mod:`.events`) to a callback. The reader therefore never waits for an estimate: a slow
evaluation makes the next block longer, not the reader slower. When nothing is queued the worker
lets the estimator prepare its next evaluation
(:meth:`~sensing_antenna.estimation.online.OnlineEstimator.prepare`: ``fast`` fits the shorter
windows that evaluation reads), one step at a time, so the evaluation at the instant that becomes
sure does little more than its own window's fit.
"""

from __future__ import annotations

import math
import queue
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Antenna
from sensing_antenna.detection.contact import ContactDetector
from sensing_antenna.detection.contact_watch import ContactWatch, lost_before_rest
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.front.evidence import search_band
from sensing_antenna.estimation.front.steps import (
    DeclaredPeriodCheck,
    StreamGrid,
    fill_missing,
    sampling_problem,
)
from sensing_antenna.estimation.methods import EstimationMethod
from sensing_antenna.estimation.online import OnlineEstimator
from sensing_antenna.estimation.result import ContactEstimate
from sensing_antenna.history import GrowingArray
from sensing_antenna.live.events import (
    ContactEvent,
    ContactLostEvent,
    EndEvent,
    EstimateEvent,
    Event,
    PushEvent,
    SkippedEvent,
)
from sensing_antenna.live.record import RecordWriter
from sensing_antenna.live.wire import StreamHeader, WireError
from sensing_antenna.recording import (
    RecordingError,
    stated_torque_point,
)
from sensing_antenna.torque_point import torques_about_base

__all__ = ["Listener"]


_END = "end"
_ABORT = "abort"


class Listener:
    """One recording received live (module docstring).

    Parameters
    ----------
    header : StreamHeader
        The stream's metadata (``sample_period``, T_s in s) and columns.
    antenna : Antenna
    on_event : callable
        Called in the worker thread with each :data:`~.events.Event`, in order.
    method : str or EstimationMethod
        As for :class:`~sensing_antenna.estimation.online.OnlineEstimator`.
    config : EstimatorConfig, optional
    record : RecordWriter, optional
        Where the samples received are written; closed by :meth:`close`.
    number : int
        The recording's number in its stream (from 1), carried by its events.
    clock : callable
        Wall clock (s) the receipt and emission times are read from.

    Attributes
    ----------
    dropped : int
        Samples missing so far (time steps of k sample periods count k - 1).
    late : int
        Samples received whose place on the stream's grid was taken (a repeated or late time
        stamp), left out of the estimate.
    lags : list of float
        For each block the worker took, the wall time (s) from the receipt of its first sample
        to the end of its processing (estimator, events, recording): how far the worker runs
        behind the input.

    Notes
    -----
    An exception in the worker (a closed output, an unwritable recording) stops it; the next
    :meth:`put` or :meth:`close` raises it in the reader's thread.
    """

    def __init__(
        self,
        header: StreamHeader,
        antenna: Antenna,
        on_event: Callable[[Event], None],
        method: str | EstimationMethod = "paper",
        config: EstimatorConfig | None = None,
        record: RecordWriter | None = None,
        number: int = 1,
        clock: Callable[[], float] = time.perf_counter,
    ) -> None:
        self.header = header
        self.number = number
        self._on_event = on_event
        self._record = record
        self._clock = clock
        ts = header.sample_period
        # a period the antenna's vibration cannot be read at: said of the stream's metadata,
        # before the estimator's filters refuse it in the antenna's terms
        settings = EstimatorConfig() if config is None else config
        coarse = sampling_problem(ts, search_band(antenna.link, settings)[1], settings)
        if coarse is not None:
            raise RecordingError(header.source, None, "sample_period", coarse, metadata=True)
        self._estimator = OnlineEstimator(antenna, ts, method, config)
        # a detector of its own, the front end's twin, for the residual after t_c (contact lost)
        self._residual = ContactDetector(antenna, ts, check_input=False)  # the samples filled
        # contact lost, and a touch again: the residual from t_c, averaged over a free period
        self._watch = ContactWatch.for_antenna(antenna, self._residual.threshold, ts)
        self._watching = True  # until a touch again, or a contact lost before t_1
        self._columns = [
            [header.required(name) for name in names]
            for names in (("t",), ("theta1", "theta2"), ("fx", "fy", "fz"), ("tx", "ty", "tz"))
        ]
        # the torques about O of a sensor that takes them about its own origin (checked with
        # the header); the recording keeps them as received, with the point
        self._torque_point = stated_torque_point(header.metadata, header.source)
        self._t = GrowingArray()  # with the samples missing put back
        self._received = GrowingArray()
        self._period = DeclaredPeriodCheck(header.sample_period)  # on the first stamps
        self._last: tuple[float, NDArray[np.float64]] | None = None
        self._grid: StreamGrid | None = None  # where the samples were placed (fill_missing)
        self.dropped = 0
        self.late = 0
        self.lags: list[float] = []
        self._said: set[str] = set()
        self._queue: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._step_time = 0.0  # wall time of the estimator's last preparing step (s)
        self.error: BaseException | None = None
        self._done = threading.Event()  # the worker has stopped
        self._closing = False  # its end asked (close)
        self._abandoned = False  # its events are no longer wanted (close gave up waiting)
        self._thread = threading.Thread(target=self._work, name="antenna-listen", daemon=True)
        self._thread.start()

    @property
    def samples(self) -> int:
        """Samples the worker has taken so far (as received: without those put back, with
        those left out late)."""
        return self._t.size - self.dropped + self.late

    @property
    def result(self) -> ContactEstimate | None:
        """The estimate once declared."""
        return self._estimator.result

    def put(
        self, rows: NDArray[np.float64] | list[list[float]], received: float | None = None
    ) -> None:
        """Queue samples that arrived together (shape (k, n_columns), the header's order),
        received at ``received`` (s on the listener's clock; now when None). Never waits.

        Raises
        ------
        ValueError
            When a row does not hold one number per column of the header.
        """
        if self.error is not None:
            raise self.error
        width = len(self.header.columns)
        try:
            shape: tuple[int, ...] | str = np.shape(rows)
        except ValueError:
            shape = "rows of different lengths"
        if shape in ((0,), (0, width)):
            return  # nothing arrived
        if not (isinstance(shape, tuple) and len(shape) == 2 and shape[1] == width):
            raise ValueError(
                f"{self.header.source}: put takes rows of {width} numbers (the columns "
                f"{', '.join(self.header.columns)}), got "
                + (f"an array of shape {shape}" if isinstance(shape, tuple) else shape)
            )
        self._queue.put((rows, self._clock() if received is None else received))

    def close(
        self, reason: str = "end of input", finish: bool = True, wait: float | None = None
    ) -> None:
        """End the recording: the worker takes what is queued, then (``finish``) gives the
        final estimate if none was declared and the end event. Waits for the worker, at most
        ``wait`` s (None: as long as it takes). Past that, or when such a bounded wait is
        interrupted, the recording is abandoned: its worker gives no event more. Called again
        after an interrupted wait, it waits for the end asked first; a recording abandoned is
        not waited for."""
        if self._abandoned:
            return
        if not self._closing:
            self._closing = True
            self._queue.put((_END if finish else _ABORT, reason))
        try:
            done = self._done.wait(wait)
        except BaseException:
            if wait is not None:
                self._abandoned = True
            raise
        if not done:
            self._abandoned = True
            return
        if self._record is not None:
            self._record.close()
        if self.error is not None:
            raise self.error

    def _work(self) -> None:
        try:
            while True:
                try:
                    first = self._queue.get_nowait()
                except queue.Empty:
                    # idle: a step of the coming evaluations' work (one window fit), then look
                    # again; work for later evaluations than the next waits when the next is
                    # due within 1.5 times the last step's time (a loaded machine stretches it)
                    started = self._clock()
                    if self._estimator.prepare(1.5 * self._step_time):
                        self._step_time = self._clock() - started
                        continue
                    first = self._queue.get()
                items = [first]
                while True:
                    try:
                        items.append(self._queue.get_nowait())
                    except queue.Empty:
                        break
                stop = next((k for k, item in enumerate(items) if isinstance(item[0], str)), None)
                blocks = items if stop is None else items[:stop]
                if blocks:
                    self._feed(blocks)
                if stop is not None:
                    if items[stop][0] == _END:
                        self._finish(str(items[stop][1]))
                    return
        except BaseException as exc:  # handed to the reader's thread
            self.error = exc
        finally:
            self._done.set()

    def _feed(self, blocks: list[tuple[Any, float]]) -> None:
        arrays = [
            np.asarray(rows, dtype=np.float64).reshape(-1, len(self.header.columns))
            for rows, _ in blocks
        ]
        rows = np.concatenate(arrays) if len(arrays) > 1 else arrays[0]
        if rows.shape[0] == 0:
            return
        received = np.repeat([when for _, when in blocks], [a.shape[0] for a in arrays])
        if self._record is not None:
            self._record.write(rows)
        if self._torque_point is not None:
            forces, torques = self._columns[2], self._columns[3]
            rows = rows.copy()
            rows[:, torques] = torques_about_base(
                rows[:, forces], rows[:, torques], self._torque_point
            )
        t = rows[:, self._columns[0][0]]
        self._check_period(t)
        # the samples as the estimator holds them, missing ones put back: the instants it
        # reports are indices into these (after an outlier time stamp, which ends its run, the
        # rest as they came, for the contact's loss)
        filled = fill_missing(
            t,
            rows,
            self.header.sample_period,
            self._estimator.config.gap_limit(self.header.sample_period),
            self._last,
            self._grid,
        )
        if filled.t.size:  # the last sample kept (a late one is left out), as the estimator's
            self._last = (float(filled.t[-1]), filled.values[-1])
        self._grid = filled.grid
        first = self._t.size
        self._t.extend(filled.t)
        self._t.extend(t[filled.taken :])
        self._received.extend(received[filled.origin])
        self._received.extend(received[filled.taken :])
        self.dropped += int(filled.filled.sum())
        self.late += int(filled.late_at.size)
        residual_rows = np.vstack([filled.values, rows[filled.taken :]])
        theta, force, torque = (rows[:, columns] for columns in self._columns[1:])
        estimator = self._estimator
        result = None
        if estimator.result is None:
            result = estimator.update_block(t, theta, force, torque, every_instant=True)
        self._residual.update_block(
            residual_rows[:, self._columns[0][0]],
            *(residual_rows[:, columns] for columns in self._columns[1:]),
        )
        self._say_instants(first)
        if result is not None:
            self._say_estimate(result, first)
        self._watch_contact(first)
        self.lags.append(self._latency(first))

    def _check_period(self, t: NDArray[np.float64], final: bool = False) -> None:
        """Refuse a stream whose time stamps do not step by its declared ``sample_period``
        (:func:`~sensing_antenna.estimation.front.steps.declared_period_problem`): the
        estimator was built for T_s before the samples came, and a file read whole would use
        the steps instead (:class:`~sensing_antenna.estimation.front.steps.DeclaredPeriodCheck`:
        on the first stamps, or at the end, ``final``, on those a shorter stream has; ``t`` the
        block's stamps, s)."""
        problem = self._period.feed(t, final)
        if problem is not None:
            ts = self.header.sample_period
            raise WireError(
                f"{self.header.source}: sample_period: the stream declares {ts!r} s, but"
                f" {problem}: the estimates need the period the samples have"
            )

    def _latency(self, index: int) -> float:
        return self._clock() - float(self._received.values[index])

    def _emit(self, event: Event) -> None:
        if not self._abandoned:
            self._on_event(event)

    def _say_instants(self, first: int) -> None:
        estimator, t = self._estimator, self._t.values
        contact, rest = estimator.contact_index, estimator.rest_index
        if contact is not None and "contact" not in self._said:
            self._said.add("contact")
            at = max(first, contact)
            self._emit(
                ContactEvent(
                    self.number,
                    float(t[contact]),
                    self._latency(at),
                    estimator.input_problem,
                    estimator.tare,
                )
            )
        if rest is not None and "push" not in self._said:
            self._said.add("push")
            at = max(first, rest)
            self._emit(PushEvent(self.number, float(t[rest]), self._latency(at)))

    def _say_estimate(self, result: ContactEstimate, first: int) -> None:
        at = first
        if math.isfinite(result.t_e):
            at = max(first, int(np.searchsorted(self._t.values[: self._t.size], result.t_e)))
        self._emit(EstimateEvent(self.number, result, self._latency(min(at, self._t.size - 1))))

    def _watch_contact(self, first: int) -> None:
        """The contact lost and a touch again (:class:`~sensing_antenna.detection.contact_watch.
        ContactWatch`), each said once: lost as a ``contact_lost`` event, a touch again as a
        ``skipped`` one (a recording holds one contact, the first's estimate stands). A contact
        lost before the head rested at t_1 was no touch: nothing is said (the estimate's status
        says it), and the watch ends."""
        contact = self._estimator.contact_index
        if contact is None or not self._watching:
            return
        detection = self._residual.detection()
        done = contact + self._watch.rows  # samples watched so far
        stop = self._t.size
        changes = self._watch.feed(detection.residual[done:stop], self._t.values[done:stop])
        for change in changes:
            latency = self._latency(max(first, contact + change.row))
            if change.kind == "lost":
                rest = self._estimator.rest_index
                if rest is None or lost_before_rest([change], float(self._t.values[rest])):
                    # lost before the head rested: t_c was no touch (the estimate says so), and
                    # the touch the watch would call a second is the one estimated
                    self._watching = False
                    return
                self._emit(ContactLostEvent(self.number, change.t, latency))
                continue
            self._watching = False
            self._emit(
                SkippedEvent(
                    self.number,
                    f"a second contact, known at t = {change.t:.3f} s, after the first was "
                    "lost: not estimated (a recording holds one contact: send each sweep as a "
                    "recording of its own)",
                    latency,
                )
            )

    def _finish(self, reason: str) -> None:
        self._check_period(np.empty(0), final=True)
        estimator = self._estimator
        last = self._t.size - 1
        if estimator.result is None:
            result = estimator.finalize()
            self._say_instants(max(last, 0))
            latency = self._latency(last) if last >= 0 else 0.0
            self._emit(EstimateEvent(self.number, result, latency))
        t_last = float(self._t.values[last]) if last >= 0 else math.nan
        latency = self._latency(last) if last >= 0 else 0.0
        self._emit(EndEvent(self.number, self.samples, self.dropped, t_last, reason, latency))
