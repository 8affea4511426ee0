"""Timed streams from a log put onto a recording's one uniform clock, with rates and gaps.

A lab's log holds the force/torque sensor and the joint angles as separate streams, each with its
own time stamps, rate, jitter and dropped messages. A recording has one clock.

Each stream's own clock is read from its stamps first (:func:`sample_clock`): the sensor samples
at a steady rate, message i is its sample n_i (n_i - i the messages dropped before it), and its
stamp is that sample's instant plus jitter (a logger's, or a recorder's latency, which may be
several periods and come in bursts). The period is the median of the steps over 64 messages,
divided by the samples they span; a drop is a lasting rise of the stamps against the messages'
count, where a running median of the stamps' lead over that count rises by half a period beyond
its noise and stays up (a recorder that stalls and catches up does not drop); the two are
read in turn until they agree; stamps whose every step lies near a whole number of periods
(jitter of up to a fifth of a period) have each step's drops counted by its own length instead,
as long as no stall then shows. The line through the stamps against their sample numbers then
gives the period and each message's instant without its jitter. A drop shorter than the jitter
cannot be told and is not counted; stamps that fall back for good (a clock set back while
recording) cannot be put in order and are refused.

:func:`put_on_clock` lays a grid of step T_s (by default the wrench stream's period) over the time
both streams cover, starting at the first wrench message in it, and fills each slot k (time
k T_s):

- the wrench with the sensor's own sample: the message whose instant is nearest to the slot,
  when it lies within T_s / 2 (stamp jitter moves no value; nothing is interpolated). A slot with
  none (a dropped message) takes the straight line between the messages either side;
- the joint angles by linear interpolation between the messages either side, at their samples'
  instants (at their stamps when they do not come at a steady rate; joint states usually come
  slower than the sensor, and the angles move smoothly);
- a slot inside a gap of either stream, missing for longer than ``max_gap`` periods T_s of the
  clock, is left out: the recording then shows the missing samples and the estimators treat them as
  dropped (docs/recording-format.md), instead of estimating from straight lines drawn across the
  gap.

Time stamps are integer nanoseconds throughout, so a stream written at the grid's own instants
comes out with its values unchanged, to the bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import median_filter

from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.recording import MAX_SAMPLES

__all__ = [
    "FASTEST_SENSOR_PERIOD",
    "STEADY_PERIODS",
    "ClockReport",
    "ClockedStreams",
    "ImporterError",
    "SampleClock",
    "Stream",
    "StreamReport",
    "put_on_clock",
    "sample_clock",
]


#: The report says how much of the wrench the joints leave out beyond this many periods.
_TRIM_NOTED = 10

#: Messages over which a stream's period is read: steps over this many messages, divided by it,
#: carry the stamps' jitter divided as much.
_PERIOD_LAG = 64
#: Messages in the running median that follows a stream's stamps against its sample count.
_LEVEL_WINDOW = 31
#: Below this noise of the lead's running median (periods) the stamps have no jitter to speak
#: of, and a step's own length tells the drops in it.
_CLEAN_NOISE = 0.05
#: A stream whose stamps lie farther than this many periods from their line is not a
#: sensor's samples at a steady rate (a recorder's latency and bursts stay within a few).
STEADY_PERIODS = 8.0
#: Joint angles that change by no more than this across a silence stood still (rad): the
#: estimators' floor of the head's rest tolerance.
_STILL = 1.0e-4
#: Stamps whose every step lies within this fraction of a period of a whole number of periods
#: have their drops counted step by step: jitter of up to about a fifth of a period on each
#: stamp, whose steps then never come near half-way between two counts.
_CLEAN_STEP = 0.45
#: Most passes of the steps' period and the drops counted on it (they settle in two or three).
_PASSES = 4
#: Messages a stream is split after, evenly spread, to look for stamps lower for good.
_FALL_SPLITS = 100
#: A drop is counted where that running median rises by half a period and this many of its own
#: standard deviations: stamps' jitter does not count drops.
_LEVEL_SIGMAS = 4.0

_NS = 1e9  # nanoseconds per second


#: Shortest sample period (s) a log's wrench stream may have: force/torque sensors read at up to
#: tens of kHz; a shorter period is stamps in another unit than nanoseconds.
FASTEST_SENSOR_PERIOD = 1e-5


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
    """Rate, drops and gaps of one stream.

    Parameters
    ----------
    name, kind : str
        As in :class:`Stream`.
    n_messages : int
        Messages in the stream.
    period : float
        The stream's sample period read from its stamps (s, :func:`sample_clock`).
    n_missing : int
        Samples its stamps show missing between its first and last message.
    largest_step : float
        Largest step between consecutive stamps (s).
    n_gaps : int
        Runs missing for longer than ``max_gap`` periods of the clock (for the joints, across
        which the angles moved; none for joints not ``steady``).
    jitter : float
        Largest distance of a stamp from its sample's instant on the stream's own clock (s).
    steady : bool
        Whether the stamps lie within :data:`STEADY_PERIODS` periods of that clock.
    n_still : int
        Of ``n_missing``, those in silences across which the angles stood still (a joint
        publisher that sends on change, or messages lost while the head rested): no gaps.
    """

    name: str
    kind: str
    n_messages: int
    period: float
    n_missing: int
    largest_step: float
    n_gaps: int
    jitter: float
    steady: bool = True
    n_still: int = 0

    @property
    def rate(self) -> float:
        """1 / period (Hz)."""
        return 1.0 / self.period

    def line(self) -> str:
        """One line for a person: count, rate, missing samples, largest step, gaps, jitter."""
        if not self.steady:
            return (
                f"{self.name} ({self.kind}): {self.n_messages} messages, not at a steady rate"
                f" (about {self.rate:.6g} Hz, stamps up to {self.jitter:.3g} s off its line),"
                f" largest step {self.largest_step:.6g} s, {self.n_gaps} gap(s)"
            )
        return (
            f"{self.name} ({self.kind}): {self.n_messages} messages, rate {self.rate:.6g} Hz"
            f" (its stamps' line), {self.n_missing} missing"
            + (
                f" ({self.n_still} of them while the angles stood still: no gap, the angles held)"
                if self.n_still
                else ""
            )
            + ", largest step"
            f" {self.largest_step:.6g} s, {self.n_gaps} gap(s), stamps within"
            f" {self.jitter:.3g} s of its clock"
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
        Largest distance between the instant of a wrench message used as it is and its slot
        (s): 0 on the wrench's own clock.
    max_gap : float
        The gap threshold used (periods of the clock).
    trimmed : tuple of float
        Time (s) of the wrench stream before the grid's first slot and after its last: where
        the joints do not cover it.
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
    trimmed: tuple[float, float] = (0.0, 0.0)

    def lines(self) -> list[str]:
        """Lines for a person: each stream, the clock, the samples filled and left out."""
        span = (self.n_slots - 1) * self.period
        lines = [
            f"wrench {self.wrench.line()}",
            f"joints {self.joints.line()}",
            f"clock: {self.n_samples} samples every {self.period:.6g} s"
            f" ({1.0 / self.period:.6g} Hz) over {span:.6g} s",
            f"{self.n_interpolated} sample(s) without their own wrench message, interpolated;"
            f" {self.n_left_out} left out in gaps longer than {self.max_gap:g} samples",
        ]
        before, after = self.trimmed
        if max(before, after) > _TRIM_NOTED * self.period:
            lines.append(
                f"the wrench's first {before:.3g} s and last {after:.3g} s left out: the joints"
                " do not cover them"
                + (
                    " (a recording needs the rest before the sweep)"
                    if before > _TRIM_NOTED * self.period
                    else ""
                )
            )
        if self.period < 0.99 * self.wrench.period:
            lines.append(
                f"the clock's {1.0 / self.period:.6g} Hz is above the wrench's own"
                f" {self.wrench.rate:.6g} Hz: the samples between its messages are interpolated"
            )
        return lines


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
    commands : ndarray, shape (m, 2), or None
        The motor commands u1, u2 (V) in force at those slots (the last sent at or before
        each), when a commands stream was given.
    """

    t: NDArray[np.float64]
    wrench: NDArray[np.float64]
    joints: NDArray[np.float64]
    report: ClockReport
    commands: NDArray[np.float64] | None = None


def _check_stream(
    stream: Stream, source: str, role: str, columns: str, width: int, other: int
) -> None:
    """Refuse a stream whose stamps are not whole nanoseconds in order, or whose values are not
    ``width`` per stamp (``columns``), as the ``role`` stream of :func:`put_on_clock`, whose
    other stream has ``other`` per stamp."""
    stamps, values = stream.stamps, stream.values
    if not (isinstance(stamps, np.ndarray) and isinstance(values, np.ndarray)):
        raise ImporterError(
            f"{source}: {stream.name!r}: stamps and values must be numpy arrays, got"
            f" {type(stamps).__name__} and {type(values).__name__}"
        )
    if stamps.ndim != 1 or stamps.dtype.kind != "i":
        hint = {
            "M": ": .astype('datetime64[ns]').astype(np.int64) gives them",
            "u": ": .astype(np.int64) gives them (differences of unsigned stamps wrap)",
            "f": ": seconds or nanoseconds in floats? (a float64 holds an epoch in ns only to"
            " about 0.2 us)",
        }.get(stamps.dtype.kind, "")
        raise ImporterError(
            f"{source}: {stream.name!r}: stamps must be whole nanoseconds, a 1-D int64 array,"
            f" got {stamps.dtype} of shape {stamps.shape}{hint}"
        )
    if values.shape != (stamps.shape[0], width):
        swapped = values.ndim == 2 and values.shape[1] == other
        raise ImporterError(
            f"{source}: {stream.name!r}: values of shape {values.shape} for {stamps.shape[0]}"
            f" stamps, where the {role} stream has {width} per stamp, {columns}"
            + (" (the wrench and the joints passed the other way round?)" if swapped else "")
        )
    if stamps.shape[0] < 2:
        raise ImporterError(
            f"{source}: {stream.name!r}: {stamps.shape[0]} message(s), at least 2 needed"
        )
    steps = np.diff(stamps)
    if not np.all(steps > 0):
        k = int(np.argmin(steps > 0))
        if steps[k] == 0:
            problem = f"have the same stamp, {int(stamps[k])} ns"
        else:
            problem = (
                f"are not in time order ({int(stamps[k])} ns, then {int(stamps[k + 1])} ns):"
                " sort the messages by stamp"
            )
        raise ImporterError(f"{source}: {stream.name!r}: messages {k} and {k + 1} {problem}")


@dataclass(frozen=True)
class SampleClock:
    """A stream's own clock, read from its stamps (:func:`sample_clock`).

    Parameters
    ----------
    period : float
        Sample period (ns).
    numbers : ndarray of int64, shape (n,)
        Each message's sample number, the first's 0: increasing, by more than one after a drop.
    instants : ndarray, shape (n,)
        Each message's sample instant (ns from the first stamp), on the line through the
        stamps against their numbers: the stamps without their jitter.
    offsets : ndarray, shape (n,)
        Each stamp less its instant (ns).
    fall : float
        The largest lasting fall of the stamps below their instants' line (ns): 0 on a steady
        clock (jitter, a drop, a stall and its catching up never lower the stamps for good); a
        clock set back while recording does.
    """

    period: float
    numbers: NDArray[np.int64]
    instants: NDArray[np.float64]
    offsets: NDArray[np.float64]
    fall: float

    @property
    def jitter(self) -> float:
        """The largest distance of a stamp from its instant (ns)."""
        return float(np.max(np.abs(self.offsets)))

    def steady(self) -> bool:
        """Whether the stamps lie within :data:`STEADY_PERIODS` periods of their instants: the
        messages are a sensor's samples at a steady rate (a publisher that sends on change, or
        at a changing rate, is not)."""
        return self.jitter <= STEADY_PERIODS * self.period


def sample_clock(stamps: NDArray[np.int64]) -> SampleClock:
    """The clock of a stream whose messages are a sensor's samples at a steady rate, some
    dropped, each stamped with jitter (module docstring).

    Parameters
    ----------
    stamps : ndarray of int64, shape (n,)
        Time stamps (ns), strictly increasing, n >= 2.

    Returns
    -------
    SampleClock
    """
    s = (stamps - stamps[0]).astype(np.float64)
    n = s.shape[0]
    # a short stream's steps over fewer messages, so that most of them hold no drop
    lag = min(_PERIOD_LAG, max(1, n // 8))
    count = np.arange(n, dtype=np.int64)
    steps = np.diff(s)
    single = float(np.median(steps))
    mean = float(s[-1]) / (n - 1)
    ratio = steps / single if single > 0.0 else steps
    numbers = None
    line: tuple[float, float] | None = None  # slope and intercept of the stamps on the numbers
    if (
        2.0 * single > mean  # not bursts: fewer drops than messages
        and np.all(ratio > 1.0 - _CLEAN_STEP)
        and np.all(np.abs(ratio - np.rint(ratio)) < _CLEAN_STEP)
    ):
        # every step nearer a whole number of periods than half a period: each step's own
        # rounding counts its drops, however many (the running medians need most messages
        # without one), unless the stamps' running median then steps by half a period within
        # a window (a recorder that stalled by more than half a period and caught up would
        # have a drop counted, and the stamps after it lie a period early for good; a clock
        # whose rate drifts bends the stamps away from one line slowly, not in a step)
        stepped = np.concatenate([[0], np.cumsum(np.maximum(np.rint(steps / single), 1.0))])
        slope, intercept = np.polyfit(stepped, s, 1)
        width = _window(n)
        level = median_filter((s - (intercept + slope * stepped)) / slope, width, mode="nearest")
        if n <= width or np.max(np.abs(level[width:] - level[:-width])) < 0.5:
            numbers, line = stepped.astype(np.int64), (slope, intercept)
    if numbers is None or line is None:
        numbers = _counted(s, count, lag)
        fitted = np.polyfit(numbers.astype(np.float64), s, 1)
        line = (float(fitted[0]), float(fitted[1]))
    slope, intercept = line
    period = float(slope)
    instants = intercept + period * numbers.astype(np.float64)
    if np.max(np.abs(s - instants)) <= 1.0:  # stamps on their grid: kept to the nanosecond
        period = float(s[-1]) / float(numbers[-1])
        instants = period * numbers.astype(np.float64)
    offsets = s - instants
    # a clock set back is judged against the steps' period, which one step back hardly moves
    # (the line takes it up as a slope)
    steps_period = _steps_period(s, numbers, lag)
    fall = _fall(s / steps_period - numbers) * steps_period
    return SampleClock(period, numbers, instants, offsets, fall)


def _steps_period(s: NDArray[np.float64], numbers: NDArray[np.int64], lag: int) -> float:
    """The median step (ns) over ``lag`` messages of the spans without a drop in ``numbers``."""
    spans = numbers[lag:] - numbers[:-lag]
    clean = spans == lag
    if clean.any():
        return float(np.median((s[lag:] - s[:-lag])[clean] / lag))
    return float(np.median((s[lag:] - s[:-lag]) / spans))


def _counted(s: NDArray[np.float64], count: NDArray[np.int64], lag: int) -> NDArray[np.int64]:
    """Sample numbers of jittered stamps ``s`` (ns from the first): the drops counted on the
    steps' period, and the period read again without the spans they fall in, until the two
    agree."""
    numbers = count
    for _ in range(_PASSES):
        # the median step over ``lag`` messages, of the spans without a drop counted: drops
        # once counted do not move it (a line through stamps miscounted would take the
        # miscount up as a slope, and keep it)
        steps_period = _steps_period(s, numbers, lag)
        found = count + _drops(s, s / steps_period - count, steps_period)
        if np.array_equal(found, numbers):
            break
        numbers = found
    return numbers


def _window(n: int) -> int:
    """Messages in the running median of a stream of ``n``: odd, and a short stream's a quarter
    of it."""
    return min(_LEVEL_WINDOW, max(3, (n // 4) | 1))


def _level(values: NDArray[np.float64], width: int) -> tuple[NDArray[np.float64], float]:
    """The running median of ``values`` (periods) over ``width`` messages, and the noise a rise
    of it must exceed: :data:`_LEVEL_SIGMAS` standard deviations of a median of ``width``
    values of their robust spread about it."""
    level = median_filter(values, size=width, mode="mirror")
    spread = 1.4826 * float(np.median(np.abs(values - level)))
    return level, _LEVEL_SIGMAS * 1.2533 * spread / math.sqrt(width)


def _fall(offsets: NDArray[np.float64]) -> float:
    """How far (periods) the stamps' ``offsets`` (periods, from a steady clock of their sample
    numbers) lie lower after some message than before it, medians either side, at the split
    where they lie lowest: 0 unless beyond 2 periods and the offsets' noise. A clock set back
    while recording leaves its stamps lower for good; a drop is in the sample numbers, and a
    stall and its catching up are a bump that leaves the medians where they were."""
    n = offsets.shape[0]
    width = _window(n)
    if n < 2 * width:
        return 0.0
    _, noise = _level(offsets, width)
    splits = np.unique(np.linspace(width, n - width, _FALL_SPLITS).astype(np.int64))
    fall = max(float(np.median(offsets[:k]) - np.median(offsets[k:])) for k in splits)
    return fall if fall > max(2.0, 1.0 + 2.0 * noise) else 0.0


def _drops(s: NDArray[np.float64], lead: NDArray[np.float64], period: float) -> NDArray[np.int64]:
    """Samples dropped before each message (nondecreasing), from the stamps ``s`` (ns from the
    first), their ``lead`` over their count (in periods) and the ``period`` (ns).

    A drop raises the lead for good: the running median of the lead, half a window after a
    message against half a window before, rises by half a period and its noise across it; runs
    of such messages less than a window apart are one rise, counted if the level stays up a
    window longer (a recorder that stalls and catches up does not drop) and sized by the lead's
    medians either side. Within a run each step holds the drops its own length says, the rest
    of the rise at the run's longest step (a surplus taken from its shortest). Near the
    stream's ends, which the windows do not cover, stamps without jitter tell drops by their
    steps alone.
    """
    n = lead.shape[0]
    width = _window(n)
    half = width // 2
    level, noise = _level(lead, width)
    steps = np.diff(s)
    each = np.maximum(np.rint(steps / period) - 1.0, 0.0).astype(np.int64)  # into message k + 1
    drops = np.zeros(n, dtype=np.int64)
    index = np.arange(n)
    before, after = index - half - 1, index + half
    covered = (before >= 0) & (after <= n - 1)
    if noise < _CLEAN_NOISE:
        # near the ends, steps without jitter: their own lengths, taken out of the lead
        for k in np.flatnonzero(~covered[1:] & (each > 0)):
            drops[k + 1 :] += each[k]
        level = _level(lead - drops, width)[0]
    rise = np.zeros(n)
    rise[covered] = level[after[covered]] - level[before[covered]]
    rising = np.flatnonzero(rise >= 0.5 + noise)
    runs: list[list[int]] = []
    for message in rising.tolist():
        if runs and message - runs[-1][1] <= width:
            runs[-1][1] = message
        else:
            runs.append([message, message])
    for number, (low, high) in enumerate(runs):
        base = level[low - half - 1]
        kept = level[high + half : min(high + half + width, n)]
        lasting = float(np.min(kept)) - base
        if lasting < 0.5 + noise:
            continue
        # sized by the lead's medians either side, as far as the neighbouring runs
        start = runs[number - 1][1] + half if number else 0
        stop = runs[number + 1][0] - half if number + 1 < len(runs) else n
        before_lead = lead[start : low - half] - drops[start : low - half]
        after_lead = lead[high + half : stop] - drops[high + half : stop]
        total = round(float(np.median(after_lead) - np.median(before_lead)))
        if total < 1:
            continue
        first = max(low, 1)
        # the drops each step of the run holds by its own length; what they leave of the rise
        # at its longest step, what they hold beyond it taken from its shortest ones
        excess = steps[first - 1 : high] / period - 1.0
        own = np.maximum(np.rint(excess), 0.0).astype(np.int64)
        while int(own.sum()) > total:
            held = np.flatnonzero(own)
            own[held[int(np.argmin(excess[held]))]] -= 1
        own[int(np.argmax(excess))] += total - int(own.sum())
        for k in np.flatnonzero(own):
            drops[first + k :] += own[k]
    return drops


def _report(
    stream: Stream, clock: SampleClock, gaps: NDArray[np.bool_], still: int = 0
) -> StreamReport:
    steady = clock.steady()
    return StreamReport(
        name=stream.name,
        kind=stream.kind,
        n_messages=int(stream.stamps.shape[0]),
        period=clock.period / _NS,
        n_missing=int(clock.numbers[-1]) - (int(stream.stamps.shape[0]) - 1),
        largest_step=float(np.max(np.diff(stream.stamps))) / _NS,
        n_gaps=int(np.sum(gaps)),
        jitter=clock.jitter / _NS,
        steady=steady,
        n_still=still,
    )


def _in_gap(
    times: NDArray[np.float64], gaps: NDArray[np.bool_], slots: NDArray[np.float64]
) -> NDArray[np.bool_]:
    """For each slot time, whether it lies strictly between two messages (at ``times``, all in
    ns relative to the origin) whose step is a gap (``gaps``, one per step)."""
    after = np.searchsorted(times, slots, side="right")
    inside = (after > 0) & (after < times.shape[0])
    before = np.clip(after - 1, 0, times.shape[0] - 2)
    return inside & gaps[before] & (slots > times[np.clip(after - 1, 0, times.shape[0] - 1)])


def _gaps(clock: SampleClock, most: float) -> NDArray[np.bool_]:
    """Each step of a stream: whether more than ``most`` samples are missing in it."""
    return np.diff(clock.numbers) - 1 > most


def put_on_clock(
    wrench: Stream,
    joints: Stream,
    *,
    source: str,
    period: float | None = None,
    max_gap: float | None = None,
    commands: Stream | None = None,
) -> ClockedStreams:
    """Lay the wrench and joint streams on one uniform clock (see the module's docstring).

    Parameters
    ----------
    wrench, joints : Stream
        The force/torque stream (the clock's reference; values (n, 6): fx, fy, fz in N, tx, ty,
        tz in N m) and the joint angles (values (n, 2): theta1, theta2 in rad), stamps in
        integer nanoseconds.
    source : str
        The log's name, for messages.
    period : float, optional
        T_s (s); when None, the wrench stream's own period (:func:`sample_clock`).
    max_gap : float, optional
        A stream missing for longer than this many periods T_s of the clock is a gap (>= 0).
        None: the estimators' own limit at T_s (``EstimatorConfig().gap_limit``, 20 ms),
        beyond which a gap from the contact on gives ``bad_input``; so a shorter hole is bridged and
        a longer one shown, for every topic alike.
    commands : Stream, optional
        The motor commands (values (n, 2): u1, u2 in V), held from each to the next (a servo
        drive holds the last command it received): the clock then starts at the first. What
        ``antenna identify --servo`` fits the motors to.

    Returns
    -------
    ClockedStreams

    Raises
    ------
    ImporterError
        Stamps that are not integers, values of another shape, a wrench stream faster than any
        sensor (stamps in another unit than ns); a stream with fewer than two messages or two
        at the same stamp; streams that do not
        overlap in time; a grid with more than :data:`~sensing_antenna.recording.MAX_SAMPLES`
        slots; fewer than two slots kept.
    """
    _check_stream(wrench, source, "wrench", "fx, fy, fz (N), tx, ty, tz (N m)", 6, 2)
    _check_stream(joints, source, "joints", "theta1, theta2 (rad)", 2, 6)
    if commands is not None:
        _check_stream(commands, source, "commands", "u1, u2 (V)", 2, 6)
    if max_gap is not None and not (math.isfinite(max_gap) and max_gap >= 0.0):
        raise ValueError(f"max_gap must be a finite number >= 0, got {max_gap!r}")
    wrench_clock, joints_clock = sample_clock(wrench.stamps), sample_clock(joints.stamps)
    if wrench_clock.fall > 0.0:
        at = int(wrench.stamps[int(np.argmin(wrench_clock.offsets))] - wrench.stamps[0]) / _NS
        raise ImporterError(
            f"{source}: {wrench.name!r}: its stamps fall back by about"
            f" {wrench_clock.fall / _NS:.3g} s for good near {at:.4g} s after its first: a clock"
            " set back while recording; its samples cannot be put in order (if only one of the"
            " sensor's and the recorder's clocks stepped, the other's stamps may hold: --stamps)"
        )
    if wrench_clock.period < FASTEST_SENSOR_PERIOD * _NS:
        raise ImporterError(
            f"{source}: {wrench.name!r}: its stamps step by {wrench_clock.period:.4g} ns, a"
            f" sensor at {_NS / wrench_clock.period:.4g} Hz, faster than any force/torque sensor"
            f" reads ({1 / FASTEST_SENSOR_PERIOD:.0f} Hz): stamps in another unit than"
            " nanoseconds (microseconds read as ns give a thousand times the rate)?"
        )
    # the wrench messages at their samples' instants (their stamps without the jitter), ns
    instants = int(wrench.stamps[0]) + np.rint(wrench_clock.instants).astype(np.int64)
    start = max(int(instants[0]), int(joints.stamps[0]))
    end = min(int(instants[-1]), int(joints.stamps[-1]))
    if start >= end:
        raise ImporterError(
            f"{source}: {wrench.name!r} ({_span(wrench)}) and {joints.name!r} ({_span(joints)})"
            " do not overlap in time"
        )
    if commands is not None:
        if int(commands.stamps[0]) >= end:
            raise ImporterError(
                f"{source}: {commands.name!r} ({_span(commands)}) begins after the wrench and"
                f" the joints end ({end / _NS:.9f} s): no sample has a command"
            )
        start = max(start, int(commands.stamps[0]))
    step = wrench_clock.period / _NS if period is None else float(period)
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"period must be finite and > 0, got {step!r}")
    if max_gap is None:
        max_gap = float(EstimatorConfig().gap_limit(step))
    step_ns = step * _NS
    first = int(np.searchsorted(instants, start, side="left"))
    origin = int(instants[first])
    periods = (end - origin) / step_ns
    if periods >= MAX_SAMPLES:
        raise ImporterError(
            f"{source}: {(end - origin) / _NS:.6g} s of overlap at {step:.6g} s per sample"
            f" is {periods:.4g} samples, more than the limit of {MAX_SAMPLES}"
        )
    n_slots = math.floor(periods + 1e-6) + 1  # the instants are whole nanoseconds
    slot_ns = np.arange(n_slots, dtype=np.float64) * step_ns
    wrench_ns = (instants - origin).astype(np.float64)
    # the joints at their samples' instants too when they come at a steady rate (else at their
    # stamps: a publisher on change has no samples to place)
    joints_ns = (joints.stamps - origin).astype(np.float64)
    if joints_clock.steady():
        joints_ns = joints_clock.instants + float(int(joints.stamps[0]) - origin)

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
    # each stream's limit in its own samples: max_gap periods of the clock
    wrench_gaps = _gaps(wrench_clock, max_gap * step_ns / wrench_clock.period)
    left_out = ~has_own & _in_gap(wrench_ns, wrench_gaps, slot_ns)
    # where the angles did not move across it, a silence of the joints (a publisher that sends
    # on change) is no gap: the straight line between its ends is the path
    moved = np.max(np.abs(np.diff(joints.values, axis=0)), axis=1) > _STILL
    # a joint topic not at a steady rate has no samples to count missing: no gaps
    joints_gaps = (
        _gaps(joints_clock, max_gap * step_ns / joints_clock.period) & moved & joints_clock.steady()
    )
    left_out |= _in_gap(joints_ns, joints_gaps, slot_ns)
    kept = np.flatnonzero(~left_out)
    if kept.shape[0] < 2:
        raise ImporterError(
            f"{source}: {kept.shape[0]} sample(s) outside the streams' gaps, at least 2 needed"
        )
    used = own_message[has_own]
    largest_offset = float(np.max(offset[used])) / _NS if used.size else 0.0
    last_slot = origin + (n_slots - 1) * step_ns
    report = ClockReport(
        wrench=_report(wrench, wrench_clock, wrench_gaps),
        joints=_report(
            joints,
            joints_clock,
            joints_gaps,
            int(np.sum((np.diff(joints_clock.numbers) - 1)[~moved]))
            if joints_clock.steady()
            else 0,
        ),
        period=step,
        origin_ns=origin,
        n_slots=n_slots,
        n_samples=int(kept.shape[0]),
        n_interpolated=int(np.sum(~has_own[kept])),
        n_left_out=int(np.sum(left_out)),
        largest_offset=largest_offset,
        max_gap=max_gap,
        trimmed=(
            max(origin - int(instants[0]), 0) / _NS,
            max(int(instants[-1]) - last_slot, 0.0) / _NS,
        ),
    )
    held = None
    if commands is not None:
        # the last command sent at or before each slot (whole nanoseconds: no rounding)
        slot_at = origin + np.rint(slot_ns[kept]).astype(np.int64)
        held = commands.values[np.searchsorted(commands.stamps, slot_at, side="right") - 1]
    return ClockedStreams(
        t=kept.astype(np.float64) * step,
        wrench=wrench_values[kept],
        joints=joint_values[kept],
        report=report,
        commands=held,
    )


def _span(stream: Stream) -> str:
    return f"{int(stream.stamps[0]) / _NS:.9f} to {int(stream.stamps[-1]) / _NS:.9f} s"
