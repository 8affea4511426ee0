"""The wire formats of a live stream (docs/live.md): CSV lines and UDP datagrams.

**CSV lines** are the recording format (docs/recording-format.md) sent line by line: the
``# key: value`` metadata lines, the header, then one sample per line. A stream may carry
several recordings one after the other: a ``#`` line after samples starts the next one. A live
stream must give ``sample_period`` in its metadata: the estimator needs T_s before the samples.

**UDP datagrams** are UTF-8 text: a first line ``sensing-antenna-udp/1 KIND STREAM SEQ``, then
lines of the CSV form. ``KIND`` is ``header`` (the metadata lines and the header; repeated by
the sender so that a listener may join at any time), ``samples`` (one or more sample lines) or
``end`` (the recording is over; no lines). ``STREAM`` names one recording (the sender picks a
new one for each); ``SEQ`` counts the ``samples`` datagrams of the stream from 0 (a ``header``
or ``end`` datagram carries the number of the next ``samples`` datagram), so a listener tells a
lost or late datagram from the next one.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType

from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.recording import (
    FORMAT_NAME,
    NAMED_COLUMNS,
    RecordingError,
    not_finite,
    parse_header,
    parse_metadata,
    parse_number,
    sample_period_problem,
)

__all__ = [
    "DATAGRAM_FORMAT",
    "DATAGRAM_KINDS",
    "MAX_DATAGRAM_BYTES",
    "SAMPLE_DATAGRAM_BYTES",
    "Datagram",
    "StreamHeader",
    "UnreadReadings",
    "WireError",
    "decode_datagram",
    "format_sample",
    "pack_samples",
    "parse_sample",
    "read_header",
]

#: First word of every datagram: the format's name and version.
DATAGRAM_FORMAT = "sensing-antenna-udp/1"
#: What a datagram may carry.
DATAGRAM_KINDS = ("header", "samples", "end")
#: Largest UDP payload over IPv4 (bytes): 65535 minus the IP and UDP headers.
MAX_DATAGRAM_BYTES = 65507
#: Size (bytes) up to which a sender packs sample lines into one datagram: one Ethernet frame's
#: payload less the IP and UDP headers and a margin, so that a datagram is never fragmented
#: (four to five lines of the simulator's fifteen columns at full precision).
SAMPLE_DATAGRAM_BYTES = 1400


class WireError(SensingAntennaError, ValueError):
    """A datagram or stream that does not follow the wire format (the message says why)."""


@dataclass(frozen=True)
class StreamHeader:
    """What a stream says before its samples.

    Parameters
    ----------
    metadata : Mapping[str, str]
        The ``# key: value`` lines, order kept; ``sample_period`` among them.
    columns : tuple of str
        The header's column names, in the order of the sample lines.
    source : str
        Where the stream comes from (``<stdin>``, ``udp:HOST:PORT``), for messages.
    """

    metadata: Mapping[str, str]
    columns: tuple[str, ...]
    source: str = "<stream>"
    positions: Mapping[str, int] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "metadata", MappingProxyType(dict(self.metadata)))
        object.__setattr__(
            self, "positions", MappingProxyType({n: k for k, n in enumerate(self.columns)})
        )

    @property
    def sample_period(self) -> float:
        """T_s (s), the ``sample_period`` metadata value."""
        return float(self.metadata["sample_period"])

    def required(self, name: str) -> int:
        """Position of a required column (``t``, ``theta1``, ...) in a sample line."""
        return self.positions[name]

    def lines(self) -> list[str]:
        """The metadata lines (``format`` and ``sample_period`` first) and the header."""
        out = [f"# format: {FORMAT_NAME}", f"# sample_period: {self.metadata['sample_period']}"]
        out += [
            f"# {key}: {value}" if value else f"# {key}:"
            for key, value in self.metadata.items()
            if key not in ("format", "sample_period")
        ]
        return [*out, ",".join(self.columns)]


def read_header(lines: Sequence[str], source: str, first_line: int = 1) -> StreamHeader:
    """The header of a stream from its metadata lines and header line (the last of ``lines``).

    ``first_line`` is the 1-based number of ``lines[0]`` in the stream, for messages.

    Raises
    ------
    RecordingError
        As the recording reader does for the same lines, naming the stream's line; or when
        ``sample_period`` is missing (a live stream needs it before its samples).
    """
    shift = first_line - 1
    rows = list(lines)
    try:
        metadata, index = parse_metadata(rows, source)
    except RecordingError as exc:
        line = None if exc.line is None else exc.line + shift
        raise RecordingError(source, line, exc.field, exc.problem, metadata=True) from None
    if index >= len(rows):
        raise RecordingError(source, first_line + index, None, "no header after the metadata")
    try:
        columns = parse_header(rows[index], index + 1, source)
    except RecordingError as exc:
        raise RecordingError(source, first_line + index, exc.field, exc.problem) from None
    if "sample_period" not in metadata:
        raise RecordingError(
            source,
            first_line + index,
            "sample_period",
            "missing: a live stream gives its sample period before its samples",
            metadata=True,
        )
    too_short = sample_period_problem(float(metadata["sample_period"]))
    if too_short is not None:
        raise RecordingError(
            source,
            first_line + index,
            "sample_period",
            f"{too_short}: in another unit than seconds?",
            metadata=True,
        )
    return StreamHeader(metadata, tuple(columns), source)


class UnreadReadings(RecordingError):
    """A sample line whose named ``columns`` (all of them, in the header's order) hold NaN or
    infinite numbers, every other cell read: readings the device did not get
    (:func:`parse_sample` with ``glitches``)."""

    def __init__(self, source: str | None, line: int | None, columns: list[str]) -> None:
        super().__init__(source, line, columns[0], "not a finite number")
        self.columns = tuple(columns)


def parse_sample(
    line: str, header: StreamHeader, number: int | None = None, glitches: bool = False
) -> list[float]:
    """The numbers of one sample line, in the header's column order. A cell that is not a finite
    number in a column the format does not name (a logger's state name, a reading not taken;
    :data:`~sensing_antenna.recording.NAMED_COLUMNS`) is NaN: a file read back leaves that
    column out.

    Raises
    ------
    RecordingError
        Naming the stream, the line ``number`` and the column: a wrong number of cells, a cell
        of a named column that is not a number, NaN or infinite.
    UnreadReadings
        With ``glitches``, in place of the last: a line whose named columns' cells are all
        numbers but some NaN or infinite (a reading the device did not get; the caller may
        leave the sample out), naming them all.
    """
    cells = line.split(",")
    if len(cells) != len(header.columns):
        problem = f"expected {len(header.columns)} cells, found {len(cells)}"
        raise RecordingError(header.source, number, None, problem)
    values = []
    unread = []
    for name, cell in zip(header.columns, cells, strict=True):
        try:
            value = parse_number(cell)
        except ValueError:
            value = None
        if value is None or not math.isfinite(value):
            if name not in NAMED_COLUMNS:
                values.append(math.nan)
                continue
            if glitches and value is not None:
                unread.append(name)
                continue
            problem = f"not a number ({cell.strip()!r})" if value is None else not_finite(value)
            raise RecordingError(header.source, number, name, problem)
        values.append(value)
    if unread:
        raise UnreadReadings(header.source, number, unread)
    return values


def format_sample(values: Iterable[float]) -> str:
    """One sample line, every number at ``repr`` precision (read back exactly)."""
    return ",".join(map(repr, values))


@dataclass(frozen=True)
class Datagram:
    """One UDP datagram of the wire format (module docstring).

    Parameters
    ----------
    kind : str
        ``header``, ``samples`` or ``end``.
    stream : str
        Name of the recording the datagram belongs to (no spaces).
    seq : int
        Number of this ``samples`` datagram in its stream (from 0), or of the next one.
    lines : tuple of str
        Metadata and header lines, or sample lines, or none.
    """

    kind: str
    stream: str
    seq: int
    lines: tuple[str, ...] = ()

    def encode(self) -> bytes:
        """The datagram's bytes."""
        first = f"{DATAGRAM_FORMAT} {self.kind} {self.stream} {self.seq}"
        data = "\n".join([first, *self.lines]).encode("utf-8")
        if len(data) > MAX_DATAGRAM_BYTES:
            raise WireError(
                f"a {self.kind} datagram of {len(data)} bytes is larger than UDP allows"
                f" ({MAX_DATAGRAM_BYTES})"
            )
        return data


def decode_datagram(data: bytes) -> Datagram:
    """A datagram from its bytes; :class:`WireError` saying what is wrong otherwise."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise WireError("datagram: not UTF-8 text") from None
    lines = text.splitlines()
    words = lines[0].split() if lines else []
    if len(words) != 4 or words[0] != DATAGRAM_FORMAT:
        start = (lines[0] if lines else "")[:40]
        raise WireError(
            f"datagram: does not begin with '{DATAGRAM_FORMAT} KIND STREAM SEQ' ({start!r})"
        )
    _, kind, stream, seq = words
    if kind not in DATAGRAM_KINDS:
        raise WireError(f"datagram: unknown kind {kind!r} (one of {', '.join(DATAGRAM_KINDS)})")
    if not seq.isdigit():
        raise WireError(f"datagram: sequence number must be an integer >= 0, got {seq!r}")
    return Datagram(kind, stream, int(seq), tuple(line for line in lines[1:] if line))


def pack_samples(
    lines: Sequence[str], stream: str, seq: int, max_bytes: int = SAMPLE_DATAGRAM_BYTES
) -> list[Datagram]:
    """Sample lines packed into ``samples`` datagrams of at most ``max_bytes`` each (at least
    one line each), numbered from ``seq``."""
    out: list[Datagram] = []
    batch: list[str] = []
    size = len(f"{DATAGRAM_FORMAT} samples {stream} {seq + len(lines)}")
    used = size
    for line in lines:
        if batch and used + 1 + len(line) > max_bytes:
            out.append(Datagram("samples", stream, seq + len(out), tuple(batch)))
            batch, used = [], size
        batch.append(line)
        used += 1 + len(line)
    if batch:
        out.append(Datagram("samples", stream, seq + len(out), tuple(batch)))
    return out
