"""Recordings: the CSV format of ``docs/recording-format.md`` (version 1).

A recording holds the two motor angles and the six force/torque components at the base of the link,
one row per sample, plus ``# key: value`` metadata lines before the header. Forces and torques are
exerted BY the link ON the head, in the motor frame, torque about the base point O (SI units).

The reader never guesses: every malformed file raises :class:`RecordingError` naming the file,
the line (1-based) and the column or metadata key. Irregular sampling is not an error; it is
described by :class:`SamplingDiagnostics` (``Recording.sampling``), and :func:`resample_uniform`
puts a recording on a uniform grid for estimators that need one.

Ground truth written by simulators (metadata keys starting with ``true_``, plus ``seed`` and
``simulation``) must never be read by estimators; :meth:`Recording.without_ground_truth` drops it.

Sizes are bounded before anything large is allocated: a file above :data:`MAX_FILE_BYTES` (or a
stream that does not end) is refused while it is read, a NUL byte at once, and time stamps that
span more than :data:`MAX_SAMPLES` sample periods, or more than :data:`MAX_PERIODS_PER_SAMPLE`
periods per sample (an outlier time stamp or a gap), are refused naming the step at fault.
"""

from __future__ import annotations

import codecs
import difflib
import math
import os
import stat
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.errors import SensingAntennaError, format_value
from sensing_antenna.torque_point import (
    TORQUE_POINT_KEY,
    key_problem,
    moved_metadata,
    torque_point_problem,
    torques_about_base,
)

__all__ = [
    "CLOCK_TOLERANCE",
    "COMMAND_COLUMNS",
    "CONTACT_POINT_COLUMNS",
    "CONTACT_TRACK_COLUMNS",
    "FORMAT_NAME",
    "GROUND_TRUTH_KEYS",
    "GROUND_TRUTH_PREFIX",
    "IN_CONTACT_COLUMN",
    "MAX_FILE_BYTES",
    "MAX_PERIODS_PER_SAMPLE",
    "MAX_SAMPLES",
    "MIN_SAMPLE_PERIOD",
    "NAMED_COLUMNS",
    "PERIOD_CHECK_STEPS",
    "REFERENCE_COLUMNS",
    "REQUIRED_COLUMNS",
    "Recording",
    "RecordingError",
    "SamplingDiagnostics",
    "check_sampling",
    "clock_disagrees",
    "is_ground_truth_key",
    "not_finite",
    "other_separator",
    "parse_header",
    "parse_metadata",
    "parse_number",
    "read_recording",
    "resample_uniform",
    "sample_period_problem",
    "stated_torque_point",
    "tracked_contact",
    "write_recording",
]

#: Value of the ``format`` metadata key written by :func:`write_recording`.
FORMAT_NAME = "sensing-antenna-recording/1"
_FORMAT_FAMILY = "sensing-antenna-recording/"

#: Required columns, in the order :func:`write_recording` writes them.
REQUIRED_COLUMNS = ("t", "theta1", "theta2", "fx", "fy", "fz", "tx", "ty", "tz")

#: Optional columns of the motor commands: the voltages u_1, u_2 of Eq. 1 (V), each applied from
#: its sample's time until the next sample's. Read by ``antenna identify --servo``; a recording
#: without them is read as before.
COMMAND_COLUMNS = ("u1", "u2")

#: Optional ground-truth columns of a simulated contact's track (the simulator writes them):
#: where the link touched at every sample (m, absolute frame; docs/recording-format.md) ...
CONTACT_POINT_COLUMNS = ("true_contact_x", "true_contact_y", "true_contact_z")
#: ... and 1 while in contact (0 before the touch and after a release, where the point's
#: columns hold 0).
IN_CONTACT_COLUMN = "true_in_contact"
CONTACT_TRACK_COLUMNS = (*CONTACT_POINT_COLUMNS, IN_CONTACT_COLUMN)

#: Optional columns of the commanded angles theta*_1, theta*_2 (rad; the simulator writes them,
#: ``antenna plot recording`` draws them).
REFERENCE_COLUMNS = ("theta1_ref", "theta2_ref")

#: Columns this format names: a cell of one that is not a finite number is an error, where a
#: column the format does not name with such a cell (a logger's state, a reading it did not
#: always take) is left out whole.
NAMED_COLUMNS = frozenset(
    (*REQUIRED_COLUMNS, *COMMAND_COLUMNS, *CONTACT_TRACK_COLUMNS, *REFERENCE_COLUMNS)
)

#: Metadata keys that hold ground truth besides those starting with :data:`GROUND_TRUTH_PREFIX`.
GROUND_TRUTH_KEYS = frozenset({"seed", "simulation"})
#: Prefix of ground-truth metadata keys and extra columns (``true_xc``).
GROUND_TRUTH_PREFIX = "true_"

#: A recording is "irregular" when a time step departs from a multiple of the nominal period by
#: more than this fraction of the period (1 %: at 1 kHz, 10 microseconds of jitter), or when
#: samples are missing. Decimal time stamps written with 6 or more significant digits stay far
#: below it.
JITTER_TOLERANCE = 0.01

#: The time stamps' clock may run off the sample period by this fraction (0.1 %) before the stamps
#: are trusted over the period: a frequency read on samples taken as one period apart is off by as
#: much as the two clocks disagree, and the fast method's frequency floor is 0.3 %.
CLOCK_TOLERANCE = 1e-3

#: ``sample_period`` metadata counts as consistent with the data when the median time step is
#: within this fraction of it (2 %).
PERIOD_CONSISTENCY = 0.02

#: The time steps from which a stream's period is read and compared with the one declared
#: before its samples came (the estimators' and the contact detector's checks).
PERIOD_CHECK_STEPS = 20

#: Largest file :func:`read_recording` reads (bytes): 256 MiB. One sample of the simulator's
#: fifteen columns at full precision takes about 250 bytes, so this holds more than 15 minutes at
#: 1 kHz, where one manoeuvre lasts seconds; reading takes about four times the file's size in
#: memory (text, lines, arrays), so the limit keeps that near a gigabyte and stops a stream that
#: never ends (a device such as ``/dev/zero``, a pipe) before it exhausts memory.
MAX_FILE_BYTES = 256 * 2**20

#: Largest number of samples a recording may hold or span on its sample period: 10 million,
#: 2.8 hours at 1 kHz. Resampling onto the uniform grid allocates this many values per column
#: (80 MB each, 720 MB for the nine required columns), so the bound holds every estimator's
#: memory whatever the time stamps say.
MAX_SAMPLES = 10_000_000

#: A recording's time span may hold at most this many sample periods per sample it has (100: at
#: least 1 % of the grid's samples present). Dropped samples are handled (the sampling
#: diagnostics, the estimators' gap check), but a file whose span is mostly empty has an outlier
#: time stamp or a gap its resampling would fill with straight lines.
MAX_PERIODS_PER_SAMPLE = 100

#: Shortest sample period accepted (s): 1 us. No force/torque sensor samples that fast (the
#: fastest read at tens of kHz), and the detectors' filters lose their precision far below it
#: (a 5 rad/s low-pass at 1e-17 s has a pole of 1 in floating point); a shorter period is time
#: stamps in another unit than seconds.
MIN_SAMPLE_PERIOD = 1e-6

#: Bytes read at a time: a NUL byte, invalid UTF-8 or a size above the limit is found within one
#: chunk of where it starts.
_CHUNK_BYTES = 2**20


def is_ground_truth_key(key: str) -> bool:
    """True if a metadata key (or extra column name) holds ground truth estimators must not read."""
    return key.startswith(GROUND_TRUTH_PREFIX) or key in GROUND_TRUTH_KEYS


class RecordingError(SensingAntennaError, ValueError):
    """A recording file or object is malformed.

    Attributes
    ----------
    path : str or None
        File concerned (None for a recording built in memory).
    line : int or None
        1-based line number in the file, when one line is at fault.
    field : str or None
        Column name or metadata key at fault, when known (the message says which).
    problem : str
        What is wrong.
    """

    def __init__(
        self,
        path: str | None,
        line: int | None,
        field: str | None,
        problem: str,
        *,
        metadata: bool = False,
    ) -> None:
        self.path = path
        self.line = line
        self.field = field
        self.problem = problem
        where = path if path is not None else "<recording>"
        if line is not None:
            where += f":{line}"
        what = ""
        if field is not None:
            what = f" {'metadata key' if metadata else 'column'} {field!r}:"
        super().__init__(f"{where}:{what} {problem}")


@dataclass(frozen=True)
class SamplingDiagnostics:
    """How regular the time stamps of a recording are.

    Parameters
    ----------
    nominal_period : float
        Nominal sample period T_s (s) the steps are compared with.
    median_period : float
        Median time step (s).
    max_jitter : float
        Largest departure of a time step from the nearest multiple of the nominal period (s).
    n_dropped : int
        Number of missing samples (a step of k periods counts k - 1).
    irregular : bool
        True when samples are missing, the jitter exceeds ``JITTER_TOLERANCE`` of the period,
        or the stamps' clock runs off the period (:func:`clock_disagrees`).
    mean_period : float
        The stamps' span over the periods it holds, dropped samples counted (s).
    """

    nominal_period: float
    median_period: float
    max_jitter: float
    n_dropped: int
    irregular: bool
    mean_period: float


def clock_disagrees(span: float, intervals: int, period: float) -> bool:
    """True when ``intervals`` sample periods of ``period`` (s) cannot be the ``span`` (s) their
    time stamps cover: beyond :data:`CLOCK_TOLERANCE` of them and half a period more (the
    span's two stamps may each be a quarter period early or late)."""
    expected = intervals * period
    return abs(span - expected) > CLOCK_TOLERANCE * expected + 0.5 * period


def check_sampling(
    t: ArrayLike, nominal: float | None = None, tolerance: float = JITTER_TOLERANCE
) -> SamplingDiagnostics:
    """Diagnose jitter and dropped samples in strictly increasing time stamps.

    Parameters
    ----------
    t : array_like, shape (n,)
        Sample times (s), strictly increasing, n >= 2.
    nominal : float, optional
        Nominal period (s); the median time step when None.
    tolerance : float
        Jitter above ``tolerance * nominal`` makes the sampling irregular (dimensionless).

    Returns
    -------
    SamplingDiagnostics
    """
    times = np.asarray(t, dtype=np.float64)
    if times.ndim != 1 or times.size < 2:
        raise ValueError("check_sampling needs at least two time stamps in a 1-D array")
    steps = np.diff(times)
    median = float(np.median(steps))
    period = median if nominal is None else float(nominal)
    if not (math.isfinite(period) and period > 0):
        raise ValueError(f"nominal period must be finite and > 0, got {format_value(period)}")
    multiples = np.maximum(np.rint(steps / period), 1.0)
    jitter = float(np.max(np.abs(steps - multiples * period)))
    dropped = int(np.sum(multiples - 1.0))
    intervals = steps.shape[0] + dropped
    span = float(times[-1] - times[0])
    return SamplingDiagnostics(
        nominal_period=period,
        median_period=median,
        max_jitter=jitter,
        n_dropped=dropped,
        irregular=(
            dropped > 0 or jitter > tolerance * period or clock_disagrees(span, intervals, period)
        ),
        mean_period=span / intervals,
    )


def sample_period_problem(period: float) -> str | None:
    """Why ``period`` (s) is no sensor's sample period ("<period> s, shorter than ..."), or
    None. With the period's own 2 % slack (:data:`PERIOD_CONSISTENCY`): time stamps far from
    zero step by a period rounded."""
    if period < (1.0 - PERIOD_CONSISTENCY) * MIN_SAMPLE_PERIOD:
        return (
            f"{format_value(period)} s, shorter than {MIN_SAMPLE_PERIOD:g} s, faster than any "
            "force/torque sensor"
        )
    return None


def _time_span_problem(t: NDArray[np.float64], period: float) -> tuple[int, str] | None:
    """Why strictly increasing time stamps ``t`` (s) cannot be put on a grid of step ``period``
    (s) of at least :data:`MIN_SAMPLE_PERIOD` within :data:`MAX_SAMPLES` and
    :data:`MAX_PERIODS_PER_SAMPLE`, or None when they can.

    Returns the index of the sample at fault (the one after the largest step, or the first sample
    when the largest step is the first) and the problem.
    """
    n = t.shape[0]
    too_short = sample_period_problem(period)
    if too_short is not None:
        return 1, f"a sample period of {too_short}: time stamps in another unit than seconds?"
    span = float(t[-1]) - float(t[0])
    periods = span / period
    if n <= MAX_SAMPLES and periods < min(MAX_SAMPLES, MAX_PERIODS_PER_SAMPLE * n):
        return None
    if n > MAX_SAMPLES:
        return n - 1, f"{n} samples, more than the limit of {MAX_SAMPLES}"
    if not math.isfinite(periods):
        first, last = format_value(t[0]), format_value(t[-1])
        return n - 1, f"time stamps from {first} to {last} s: no finite span"
    with np.errstate(over="ignore"):
        steps = np.diff(t)
    k = int(np.argmax(steps)) + 1
    limit = (
        f"the limit of {MAX_SAMPLES} samples"
        if periods >= MAX_SAMPLES
        else f"{MAX_PERIODS_PER_SAMPLE} per sample for its {n} samples"
    )
    problem = (
        f"time jumps from {format_value(t[k - 1])} to {format_value(t[k])} s,"
        f" {steps[k - 1] / period:.4g} sample periods of {format_value(period)} s in one step:"
        " an outlier time stamp or a gap"
        f" (the recording spans {periods:.4g} periods, more than {limit})"
    )
    return (0 if k == 1 else k), problem


def _frozen_array(values: ArrayLike, shape_tail: tuple[int, ...], name: str) -> NDArray[np.float64]:
    array = np.array(values, dtype=np.float64, copy=True)
    if array.ndim != 1 + len(shape_tail) or array.shape[1:] != shape_tail:
        expected = "(n" + "".join(f", {k}" for k in shape_tail) + ")"
        raise RecordingError(None, None, name, f"shape must be {expected}, got {array.shape}")
    finite = np.isfinite(array).reshape(array.shape[0], -1).all(axis=1)
    if not finite.all():
        row = int(np.flatnonzero(~finite)[0])
        value = array[row].tolist() if array.ndim > 1 else float(array[row])
        raise RecordingError(
            None, None, name, f"NaN or infinite value at row {row} (from 0): {value}"
        )
    array.flags.writeable = False
    return array


def _is_one_line(text: str) -> bool:
    """True unless ``text`` holds a NUL byte (binary content to the reader) or a character at
    which :meth:`str.splitlines`, and so the reader, breaks lines: line feed, carriage return,
    form feed, U+2028 and the others."""
    return "\0" not in text and (not text or text.splitlines() == [text])


def _check_name(name: str, what: str) -> None:
    if (
        not isinstance(name, str)
        or not name
        or name != name.strip()
        or "," in name
        or not _is_one_line(name)
        or name.startswith("#")
    ):
        raise RecordingError(None, None, None, f"invalid {what} {name!r}")


@dataclass(frozen=True, eq=False)
class Recording:
    """One manoeuvre: motor angles and base force/torque sampled over time.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times (s), strictly increasing, n >= 2.
    theta : ndarray, shape (n, 2)
        Motor angles (rad): theta1 azimuth, theta2 elevation.
    force : ndarray, shape (n, 3)
        Force by the link on the head, motor frame (N).
    torque : ndarray, shape (n, 3)
        Torque by the link on the head about O, motor frame (N m).
    metadata : Mapping[str, str]
        ``# key: value`` lines, values as text, order kept.
    extra : Mapping[str, ndarray]
        Extra columns, shape (n,) each (``theta1_ref``), order kept.
    source : str or None
        File the recording was read from; not part of equality.

    Equality compares every array exactly, the metadata (with order) and the extra columns.
    """

    t: NDArray[np.float64]
    theta: NDArray[np.float64]
    force: NDArray[np.float64]
    torque: NDArray[np.float64]
    metadata: Mapping[str, str] = field(default_factory=dict)
    extra: Mapping[str, NDArray[np.float64]] = field(default_factory=dict)
    source: str | None = None

    def __post_init__(self) -> None:
        t = _frozen_array(self.t, (), "t")
        n = t.shape[0]
        if n < 2:
            raise RecordingError(self.source, None, "t", f"need at least 2 samples, got {n}")
        with np.errstate(over="ignore"):
            steps = np.diff(t)
        if not np.all(steps > 0):
            k = int(np.argmin(steps > 0)) + 1
            raise RecordingError(self.source, None, "t", f"not strictly increasing at sample {k}")
        arrays = {"t": t}
        for name, tail in (("theta", (2,)), ("force", (3,)), ("torque", (3,))):
            arrays[name] = _frozen_array(getattr(self, name), tail, name)
            if arrays[name].shape[0] != n:
                raise RecordingError(
                    self.source, None, name, f"has {arrays[name].shape[0]} samples, t has {n}"
                )
        metadata: dict[str, str] = {}
        for key, value in self.metadata.items():
            _check_name(key, "metadata key")
            if ":" in key:
                raise RecordingError(
                    self.source, None, key, "key must not contain ':'", metadata=True
                )
            text = str(value)
            if text != text.strip() or not _is_one_line(text):
                raise RecordingError(
                    self.source,
                    None,
                    key,
                    "value must be one line without edge spaces",
                    metadata=True,
                )
            metadata[key] = text
        if TORQUE_POINT_KEY in metadata:
            raise RecordingError(
                self.source,
                None,
                TORQUE_POINT_KEY,
                "a Recording holds torques about O: read_recording moves a file's to O, "
                "sensing_antenna.torque_point.torques_about_base moves any",
                metadata=True,
            )
        extra: dict[str, NDArray[np.float64]] = {}
        for name, values in self.extra.items():
            _check_name(name, "column name")
            if name in REQUIRED_COLUMNS:
                raise RecordingError(self.source, None, name, "extra column shadows a required one")
            extra[name] = _frozen_array(values, (), name)
            if extra[name].shape[0] != n:
                raise RecordingError(
                    self.source, None, name, f"has {extra[name].shape[0]} samples, t has {n}"
                )
        for name, array in arrays.items():
            object.__setattr__(self, name, array)
        object.__setattr__(self, "metadata", MappingProxyType(metadata))
        object.__setattr__(self, "extra", MappingProxyType(extra))
        span = _time_span_problem(t, self.sample_period)
        if span is not None:
            k, problem = span
            raise RecordingError(self.source, None, "t", f"sample {k}: {problem}")

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Recording):
            return NotImplemented
        return (
            all(
                np.array_equal(getattr(self, name), getattr(other, name))
                for name in ("t", "theta", "force", "torque")
            )
            and list(self.metadata.items()) == list(other.metadata.items())
            and list(self.extra) == list(other.extra)
            and all(np.array_equal(v, other.extra[k]) for k, v in self.extra.items())
        )

    __hash__ = None  # type: ignore[assignment]

    @property
    def n_samples(self) -> int:
        """Number of samples n."""
        return int(self.t.shape[0])

    @property
    def duration(self) -> float:
        """t[-1] - t[0] (s)."""
        return float(self.t[-1] - self.t[0])

    @property
    def nominal_period(self) -> float | None:
        """The ``sample_period`` metadata value (s), or None when absent."""
        text = self.metadata.get("sample_period")
        if text is None:
            return None
        value = _parse_period(text)
        if value is None:
            raise RecordingError(
                self.source,
                None,
                "sample_period",
                f"must be a number > 0, got {text!r}",
                metadata=True,
            )
        return value

    @property
    def sample_period(self) -> float:
        """Sample period T_s (s): the metadata value when present and consistent with the data
        (median step within ``PERIOD_CONSISTENCY``), else the median time step."""
        return _period_of(self.t, self.nominal_period)

    @property
    def period_problem(self) -> str | None:
        """Why the ``sample_period`` metadata is not the period the estimators use, or None:
        the time stamps' median step lies more than ``PERIOD_CONSISTENCY`` from it, and the
        step is used (a file's stamps are the record of when each sample was taken)."""
        nominal = self.nominal_period
        used = self.sample_period
        if nominal is None or used == nominal:
            return None
        return (
            f"field 'sample_period': {format_value(nominal)} s in the metadata, while the time "
            f"stamps' median step is {used:.6g} s ({used / nominal:.3g} times it); "
            "the estimators use the step: correct the metadata or the time stamps"
        )

    @property
    def sampling(self) -> SamplingDiagnostics:
        """Jitter and dropped samples relative to :attr:`sample_period`."""
        return check_sampling(self.t, self.sample_period)

    def without_ground_truth(self) -> Recording:
        """A copy without ground-truth metadata keys and extra columns (see
        :func:`is_ground_truth_key`)."""
        return Recording(
            t=self.t,
            theta=self.theta,
            force=self.force,
            torque=self.torque,
            metadata={k: v for k, v in self.metadata.items() if not is_ground_truth_key(k)},
            extra={k: v for k, v in self.extra.items() if not is_ground_truth_key(k)},
            source=self.source,
        )

    def with_metadata(self, **values: Any) -> Recording:
        """A copy with metadata keys set (existing keys keep their place, new ones go last)."""
        metadata = dict(self.metadata)
        metadata.update({k: str(v) for k, v in values.items()})
        return Recording(
            t=self.t,
            theta=self.theta,
            force=self.force,
            torque=self.torque,
            metadata=metadata,
            extra=self.extra,
            source=self.source,
        )


def _period_of(t: NDArray[np.float64], nominal: float | None) -> float:
    """The sample period (s) of time stamps ``t``: ``nominal`` when the median step is within
    ``PERIOD_CONSISTENCY`` of it, else the median step."""
    with np.errstate(over="ignore"):
        median = float(np.median(np.diff(t)))
    if nominal is not None and abs(median - nominal) <= PERIOD_CONSISTENCY * nominal:
        return nominal
    return median


def _parse_period(text: str) -> float | None:
    try:
        value = parse_number(text)
    except ValueError:
        return None
    return value if math.isfinite(value) and value > 0 else None


def parse_metadata(lines: list[str], source: str) -> tuple[dict[str, str], int]:
    """Metadata from the leading ``#`` lines of ``lines`` (a file's, or a stream's); returns it
    and the index of the header line. Errors name ``source`` and the 1-based line."""
    metadata: dict[str, str] = {}
    index = 0
    while index < len(lines) and lines[index].startswith("#"):
        body = lines[index][1:]
        key, sep, value = body.partition(":")
        key = key.strip()
        if not sep or not key:
            looks_like_header = "," in body and body.split(",")[0].strip() in ("t", "time")
            raise RecordingError(
                source,
                index + 1,
                None,
                "metadata line must read '# key: value'"
                + (
                    " (the header written as a comment? numpy.savetxt writes '# ' before it "
                    "unless given comments='')"
                    if looks_like_header
                    else ""
                ),
            )
        if key in metadata:
            raise RecordingError(source, index + 1, key, "duplicate metadata key", metadata=True)
        metadata[key] = value.strip()
        index += 1
    _check_known_metadata(metadata, lines, source)
    return metadata, index


def _check_known_metadata(metadata: Mapping[str, str], lines: list[str], source: str) -> None:
    def line_of(key: str) -> int:
        for number, text in enumerate(lines, start=1):
            if text.startswith("#") and text[1:].partition(":")[0].strip() == key:
                return number
        return 0  # pragma: no cover - the key came from these lines

    fmt = metadata.get("format")
    if fmt is not None and fmt != FORMAT_NAME:
        problem = (
            f"unsupported version {fmt!r} (this reader knows {FORMAT_NAME!r})"
            if fmt.startswith(_FORMAT_FAMILY)
            else f"not a sensing-antenna recording ({fmt!r})"
        )
        raise RecordingError(source, line_of("format"), "format", problem, metadata=True)
    period = metadata.get("sample_period")
    if period is not None and _parse_period(period) is None:
        raise RecordingError(
            source,
            line_of("sample_period"),
            "sample_period",
            f"must be a number > 0 ({period!r})",
            metadata=True,
        )
    keys = key_problem(metadata)
    if keys is not None:
        raise RecordingError(source, line_of(keys[0]), keys[0], keys[1], metadata=True)
    if TORQUE_POINT_KEY in metadata:
        stated_torque_point(metadata, source, line_of(TORQUE_POINT_KEY))


def stated_torque_point(
    metadata: Mapping[str, str], source: str | None, line: int | None = None
) -> NDArray[np.float64] | None:
    """The point S - O (m, shape (3,)) a file's or a stream's ``torque_point`` states, None
    without one (docs/recording-format.md).

    Raises
    ------
    RecordingError
        Naming ``source``, ``line`` and the key, when the value is no point on the head.
    """
    text = metadata.get(TORQUE_POINT_KEY)
    if text is None:
        return None
    point, problem = torque_point_problem(text)
    if point is None:
        raise RecordingError(source, line, TORQUE_POINT_KEY, str(problem), metadata=True)
    return point


def other_separator(names: Sequence[str]) -> str | None:
    """What separates a CSV header's names when it reads as one column at its commas
    ("semicolons", as a European spreadsheet writes, "tabs" or "spaces"), else None."""
    if len(names) != 1:
        return None
    for separator, called in ((";", "semicolons"), ("\t", "tabs"), (" ", "spaces")):
        if separator in names[0]:
            return called
    return None


def parse_header(line: str, number: int, source: str) -> list[str]:
    """The column names of a header ``line`` (line ``number`` of ``source``): none empty or
    repeated, the nine required ones present."""
    names = [cell.strip() for cell in line.split(",")]
    called = other_separator(names)
    if called is not None:
        raise RecordingError(
            source,
            number,
            None,
            f"the header is one column separated by {called}; columns are separated "
            "by commas (docs/recording-format.md)",
        )
    seen: set[str] = set()
    if not line.strip():
        raise RecordingError(
            source, number, None, "blank line where the header is due (it follows the metadata)"
        )
    for position, name in enumerate(names):
        if not name:
            where = (
                " (a first column without a name: an index, as pandas writes unless given "
                "index=False?)"
                if position == 0
                else " (a trailing comma?)"
                if position == len(names) - 1
                else ""
            )
            raise RecordingError(source, number, None, f"empty column name in header{where}")
        if name in seen:
            raise RecordingError(source, number, name, "duplicate column")
        seen.add(name)
    missing = [name for name in REQUIRED_COLUMNS if name not in seen]
    if missing:
        name = missing[0]
        hints = [_near(other, names) for other in missing]
        others = ""
        if len(missing) > 1:
            others = f"; missing too: {', '.join(missing[1:])}"
        if all(hints):
            if len(missing) > 1:
                others += " (each written otherwise: the names are the format's own)"
        elif len(missing) * 2 > len(REQUIRED_COLUMNS):
            others += (
                " (a log in another format? docs/import.md converts one: ROS bags with "
                "'antenna import', any other log from Python)"
            )
        raise RecordingError(
            source,
            number,
            name,
            f"required column missing from header{hints[0]}{others}",
        )
    return names


def _near(name: str, names: list[str]) -> str:
    """ " (found 'T', ...: ...)" when a header name is ``name`` written otherwise (quoted, in
    another case, with a unit) or misspelt (a name the format does not know, near ``name``),
    else "" """
    spelled = {"t": ("time", "timestamp", "time_s", "stamp")}.get(name, ())
    for found in names:
        bare = found.strip("\"' ").split("[")[0].split("(")[0].strip().lower()
        if bare in spelled or (spelled and bare.startswith(("time", "stamp"))):
            return f" (found {found!r}: the time column is named 't', in s)"
        if bare == name and found != name:
            return (
                f" (found {found!r}: names are written bare and in lower case, without quotes"
                " or units; the units are the format's, docs/recording-format.md)"
            )
    unknown = [found for found in names if found not in NAMED_COLUMNS]
    close = difflib.get_close_matches(name, unknown, n=1, cutoff=0.75)
    if close:
        return f" (found {close[0]!r}: is it '{name}'? the names are the format's own)"
    return ""


def _numeric_columns(
    rows: list[str], numbers: Sequence[int], names: list[str], source: str
) -> tuple[NDArray[np.float64], list[str]]:
    """The table and its column names (slow path, only after the fast parse failed): every
    column but those the format does not name (:data:`NAMED_COLUMNS`) with a cell that is not a
    number. A row of the wrong length, a '#' line among the samples or a named column's cell
    that is not a number is refused, naming its line (``numbers``, each row's)."""
    named = [name in NAMED_COLUMNS for name in names]
    text_columns: set[int] = set()
    table = np.empty((len(rows), len(names)))
    for offset, row in enumerate(rows):
        cells = row.split(",")
        number = numbers[offset]
        if row.lstrip().startswith("#"):
            raise RecordingError(
                source,
                number,
                None,
                "a '#' line among the samples: metadata go before the header, and a file "
                "holds one recording",
            )
        if len(cells) != len(names):
            raise RecordingError(
                source,
                number,
                None,
                f"expected {len(names)} cells, found {len(cells)}"
                + (" (truncated last row)" if offset == len(rows) - 1 else ""),
            )
        for k, (name, cell) in enumerate(zip(names, cells, strict=True)):
            if k in text_columns:
                continue
            try:
                table[offset, k] = parse_number(cell)
            except ValueError:
                if named[k]:
                    raise RecordingError(
                        source, number, name, f"not a number ({cell.strip()!r})"
                    ) from None
                text_columns.add(k)
    kept = [k for k in range(len(names)) if k not in text_columns]
    return table[:, kept], [names[k] for k in kept]


def not_finite(value: float) -> str:
    """The problem of a named column's cell holding NaN or an infinity, as every reader words
    it."""
    return f"{format_value(value)} is not a finite number"


def parse_number(cell: str) -> float:
    """A cell's number as the whole-file reader (NumPy's) takes it, else ValueError: Python's
    ``float`` would also take digit groups (``1_000``) and other scripts' digits, a typo read
    as a value."""
    if "_" in cell or not cell.isascii():
        raise ValueError(cell)
    return float(cell)


#: The first bytes of compressed files a lab might give for a recording, and what they are.
_COMPRESSED = (
    (b"\x1f\x8b", "a gzip-compressed file"),
    (b"PK\x03\x04", "a zip archive (a spreadsheet's .xlsx is one: save it as CSV)"),
    (b"\xfd7zXZ\x00", "an xz-compressed file"),
)


def _read_text(path: str | Path, source: str) -> str:
    """The file's text, read in chunks: refused at the first NUL byte, invalid UTF-8 or byte
    beyond :data:`MAX_FILE_BYTES` (a regular file above it before reading anything)."""
    decoder = codecs.getincrementaldecoder("utf-8-sig")()
    parts: list[str] = []
    size = 0
    newlines = 0
    try:
        with open(path, "rb") as stream:
            status = os.fstat(stream.fileno())
            if stat.S_ISREG(status.st_mode) and status.st_size > MAX_FILE_BYTES:
                raise RecordingError(
                    source,
                    None,
                    None,
                    f"file of {status.st_size} bytes is larger than the reader's limit of"
                    f" {MAX_FILE_BYTES} bytes ({MAX_FILE_BYTES // 2**20} MiB)",
                )
            while chunk := stream.read(_CHUNK_BYTES):
                size += len(chunk)
                if size > MAX_FILE_BYTES:
                    raise RecordingError(
                        source,
                        None,
                        None,
                        f"more than the reader's limit of {MAX_FILE_BYTES} bytes"
                        f" ({MAX_FILE_BYTES // 2**20} MiB) and not a regular file"
                        " (a stream or device that does not end?)",
                    )
                if size == len(chunk):
                    for magic, what in _COMPRESSED:
                        if chunk.startswith(magic):
                            raise RecordingError(
                                source, None, None, f"{what}: not read, extract it first"
                            )
                nul = chunk.find(b"\0")
                if nul >= 0:
                    line = newlines + chunk.count(b"\n", 0, nul) + 1
                    raise RecordingError(
                        source, line, None, "not a recording: binary content (a NUL byte)"
                    )
                try:
                    parts.append(decoder.decode(chunk))
                except UnicodeDecodeError as exc:
                    # exc.object is the decoder's undecoded tail (no line feed) plus this chunk
                    line = newlines + exc.object[: exc.start].count(b"\n") + 1
                    raise RecordingError(source, line, None, "not UTF-8 text") from exc
                newlines += chunk.count(b"\n")
    except OSError as exc:
        raise RecordingError(source, None, None, f"cannot read file ({exc.strerror})") from exc
    try:
        parts.append(decoder.decode(b"", final=True))
    except UnicodeDecodeError as exc:
        raise RecordingError(source, newlines + 1, None, "not UTF-8 text (cut off)") from exc
    return "".join(parts)


def read_recording(path: str | Path) -> Recording:
    """Read a recording file (format: ``docs/recording-format.md``).

    Parameters
    ----------
    path : str or Path
        CSV file, UTF-8, any line endings.

    Returns
    -------
    Recording
        With ``source`` set to ``str(path)``.

    Raises
    ------
    RecordingError
        For a missing or unreadable file, a file above :data:`MAX_FILE_BYTES` or with a NUL byte,
        bad metadata, a missing required column, a non-numeric, NaN or infinite cell, a wrong
        number of cells (truncated row), non-increasing time, time stamps that span too many
        sample periods (:data:`MAX_SAMPLES`, :data:`MAX_PERIODS_PER_SAMPLE`), an empty file or a
        header without rows; the message names the file, the line and the field.
    """
    source = str(path)
    text = _read_text(path, source)
    lines = text.splitlines()
    while lines and not lines[-1].strip():
        lines.pop()
    if not lines:
        raise RecordingError(source, None, None, "empty file")
    metadata, header_index = parse_metadata(lines, source)
    if header_index == len(lines):
        raise RecordingError(source, None, None, "no header row after the metadata")
    names = parse_header(lines[header_index], header_index + 1, source)
    rows = lines[header_index + 1 :]
    # a logger's footer: '#' lines after the last sample say nothing the samples need
    while rows and rows[-1].lstrip().startswith("#"):
        rows.pop()
        while rows and not rows[-1].strip():
            rows.pop()
    # a blank line among the samples (nothing, or only spaces) holds no sample: left out, each
    # other row keeping its own line number (rebuilt only when a file has one)
    numbers: Sequence[int] = range(header_index + 2, header_index + 2 + len(rows))
    if not all(rows) or any(row.isspace() for row in rows):
        kept = [k for k, row in enumerate(rows) if row and not row.isspace()]
        numbers, rows = [numbers[k] for k in kept], [rows[k] for k in kept]
    if not rows:
        raise RecordingError(source, header_index + 1, None, "header but no data rows")
    try:
        data = np.loadtxt(rows, delimiter=",", dtype=np.float64, comments=None, ndmin=2)
    except ValueError:
        data = None
    if data is None or data.shape[1] != len(names):
        # a row of the wrong length or a cell not a number: named, unless it lies in a column
        # no reader needs (a logger's state or text column), which is left out whole
        data, names = _numeric_columns(rows, numbers, names, source)
    extra_bad = [
        k
        for k, name in enumerate(names)
        if name not in NAMED_COLUMNS and not np.all(np.isfinite(data[:, k]))
    ]
    if extra_bad:  # NaN or infinite in a column the format does not name: left out whole
        kept = [k for k in range(len(names)) if k not in extra_bad]
        data, names = data[:, kept], [names[k] for k in kept]
    finite = np.isfinite(data)
    if not np.all(finite):
        row, col = np.argwhere(~finite)[0]
        raise RecordingError(
            source,
            numbers[int(row)],
            names[col],
            not_finite(data[row, col]),
        )
    column = {name: data[:, k] for k, name in enumerate(names)}
    t = column["t"]
    if t.shape[0] < 2:
        raise RecordingError(source, numbers[0], None, "need at least 2 data rows")
    with np.errstate(over="ignore"):
        bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        k = int(bad[0]) + 1
        raise RecordingError(
            source,
            numbers[k],
            "t",
            f"time does not increase ({format_value(t[k])} after {format_value(t[k - 1])})",
        )
    nominal = metadata.get("sample_period")
    span = _time_span_problem(t, _period_of(t, None if nominal is None else _parse_period(nominal)))
    if span is not None:
        k, problem = span
        raise RecordingError(source, numbers[k], "t", problem)
    force = np.column_stack([column["fx"], column["fy"], column["fz"]])
    torque = np.column_stack([column["tx"], column["ty"], column["tz"]])
    point = stated_torque_point(metadata, source)  # its value checked by parse_metadata
    if point is not None:
        torque = torques_about_base(force, torque, point)
        metadata = moved_metadata(metadata)
    return Recording(
        t=t,
        theta=np.column_stack([column["theta1"], column["theta2"]]),
        force=force,
        torque=torque,
        metadata=metadata,
        extra={name: column[name] for name in names if name not in REQUIRED_COLUMNS},
        source=source,
    )


def _metadata_lines(recording: Recording) -> Iterable[str]:
    sample_period = recording.metadata.get("sample_period", repr(recording.sample_period))
    yield f"# format: {FORMAT_NAME}"
    yield f"# sample_period: {sample_period}"
    for key, value in recording.metadata.items():
        if key not in ("format", "sample_period"):
            yield f"# {key}: {value}" if value else f"# {key}:"


def write_recording(recording: Recording, path: str | Path) -> None:
    """Write a recording so that :func:`read_recording` gives it back exactly.

    ``# format`` and ``# sample_period`` come first (the metadata value if present, else the
    median step), then the other metadata in order, the header (required columns, then extra
    columns) and one row per sample with floats at ``repr`` precision. The same recording always
    gives the same bytes (``\\n`` line endings).

    Parameters
    ----------
    recording : Recording
    path : str or Path
        Destination file, overwritten.
    """
    table = np.column_stack(
        [
            recording.t,
            recording.theta,
            recording.force,
            recording.torque,
            *[values[:, None] for values in recording.extra.values()],
        ]
    )
    header = ",".join([*REQUIRED_COLUMNS, *recording.extra])
    body = "\n".join(",".join(map(repr, row)) for row in table.tolist())
    text = "\n".join([*_metadata_lines(recording), header, body]) + "\n"
    Path(path).write_text(text, encoding="utf-8", newline="")


def resample_uniform(recording: Recording, period: float | None = None) -> Recording:
    """Linear interpolation of every column onto a uniform time grid.

    Parameters
    ----------
    recording : Recording
    period : float, optional
        Grid step (s); :attr:`Recording.sample_period` when None.

    Returns
    -------
    Recording
        Samples at t[0] + k * period for every k with t[0] + k * period <= t[-1] (plus a rounding
        margin of 1e-9 periods); ``sample_period`` metadata set to the step; same source.

    Raises
    ------
    RecordingError
        When that grid would hold :data:`MAX_SAMPLES` samples or more (a recording's own sample
        period never does: the recording would have been refused).
    """
    step = recording.sample_period if period is None else float(period)
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"period must be finite and > 0, got {format_value(step)}")
    periods = recording.duration / step
    if periods >= MAX_SAMPLES:
        raise RecordingError(
            recording.source,
            None,
            "t",
            f"a grid of step {format_value(step)} s over {format_value(recording.duration)} s"
            f" would hold {periods + 1:.4g} samples, more than the limit of {MAX_SAMPLES}",
        )
    count = math.floor(periods + 1e-9) + 1
    grid = recording.t[0] + step * np.arange(count)
    grid[-1] = min(grid[-1], recording.t[-1])

    def interp(values: NDArray[np.float64]) -> NDArray[np.float64]:
        if values.ndim == 1:
            return np.interp(grid, recording.t, values)
        return np.column_stack([np.interp(grid, recording.t, col) for col in values.T])

    metadata = dict(recording.metadata)
    metadata["sample_period"] = repr(step)
    return Recording(
        t=grid,
        theta=interp(recording.theta),
        force=interp(recording.force),
        torque=interp(recording.torque),
        metadata=metadata,
        extra={k: interp(v) for k, v in recording.extra.items()},
        source=recording.source,
    )


def tracked_contact(recording: Recording, t: float | None) -> NDArray[np.float64] | None:
    """Where the link touched at the in-contact sample nearest ``t`` (s) by the recording's
    contact track (:data:`CONTACT_TRACK_COLUMNS`; a contact may open and close again), shape
    (3,) (m, absolute frame); None without a track, a finite ``t`` (an estimate's
    ``t_point`` may be missing) or any contact."""
    if not all(name in recording.extra for name in CONTACT_TRACK_COLUMNS):
        return None
    touching = np.flatnonzero(recording.extra[IN_CONTACT_COLUMN] > 0.5)
    if t is None or not (touching.size and math.isfinite(t)):
        return None
    k = int(touching[np.argmin(np.abs(recording.t[touching] - t))])
    return np.array([float(recording.extra[name][k]) for name in CONTACT_POINT_COLUMNS])
