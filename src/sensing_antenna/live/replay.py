"""A recording sent at its own pace (``antenna replay``): to a text stream as CSV lines, or
over UDP as datagrams (the wire formats of :mod:`.wire`), for tests and demonstrations.

Sample k leaves at (t_k - t_0) / speed seconds after the first; ``speed`` 0 sends everything
as fast as the output takes it. The metadata lines and the header go first; over UDP they are
repeated every :data:`HEADER_REPEAT` seconds of the recording, so that a listener started late
joins, and the ``end`` datagram closes the stream (sent :data:`END_REPEAT` times: one may be
lost).
"""

from __future__ import annotations

import secrets
import socket
import time
from collections.abc import Callable, Iterator

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.live.wire import Datagram, StreamHeader, format_sample, pack_samples
from sensing_antenna.recording import REQUIRED_COLUMNS, Recording

__all__ = [
    "END_REPEAT",
    "HEADER_REPEAT",
    "replay_datagrams",
    "replay_lines",
    "stream_of",
]

#: Interval (s of the recording) at which a UDP replay sends the header again.
HEADER_REPEAT = 1.0
#: How many times a UDP replay sends its ``end`` datagram.
END_REPEAT = 3
#: Lines written at a time when there is no pace to keep (speed 0).
_CHUNK = 1000


def stream_of(
    recording: Recording, source: str = "<replay>"
) -> tuple[StreamHeader, NDArray[np.float64]]:
    """The header a recording is sent with (``sample_period`` added when the file had none:
    the recording's own) and its samples, shape (n, n_columns) in the header's order."""
    metadata = dict(recording.metadata)
    metadata.setdefault("sample_period", repr(recording.sample_period))
    columns = (*REQUIRED_COLUMNS, *recording.extra)
    rows = np.column_stack(
        [
            recording.t,
            recording.theta,
            recording.force,
            recording.torque,
            *[values[:, None] for values in recording.extra.values()],
        ]
    )
    return StreamHeader(metadata, columns, source), rows


def _paced(
    t: NDArray[np.float64],
    speed: float,
    clock: Callable[[], float],
    sleep: Callable[[float], None],
) -> Iterator[tuple[int, int]]:
    """(start, stop) ranges of samples that are due, waiting between them as the pace says."""
    n = t.shape[0]
    if speed == 0:
        for start in range(0, n, _CHUNK):
            yield start, min(n, start + _CHUNK)
        return
    offsets = (t - t[0]) / speed
    begin = clock()
    sent = 0
    while sent < n:
        now = clock() - begin
        due = int(np.searchsorted(offsets, now, side="right"))
        if due > sent:
            yield sent, due
            sent = due
        else:
            sleep(max(0.0, float(offsets[sent]) - now))


def replay_lines(
    recording: Recording,
    write: Callable[[str], object],
    flush: Callable[[], object],
    speed: float = 1.0,
    clock: Callable[[], float] = time.perf_counter,
    sleep: Callable[[float], None] = time.sleep,
) -> int:
    """Write a recording as CSV lines at its pace; returns the number of samples sent."""
    header, rows = stream_of(recording)
    write("\n".join(header.lines()) + "\n")
    flush()
    for start, stop in _paced(recording.t, speed, clock, sleep):
        write("".join(format_sample(row) + "\n" for row in rows[start:stop].tolist()))
        flush()
    return rows.shape[0]


def replay_datagrams(
    recording: Recording,
    sock: socket.socket,
    address: tuple[str, int],
    speed: float = 1.0,
    stream: str | None = None,
    clock: Callable[[], float] = time.perf_counter,
    sleep: Callable[[float], None] = time.sleep,
) -> int:
    """Send a recording over UDP at its pace; returns the number of samples datagrams sent."""
    name = stream if stream is not None else secrets.token_hex(4)
    header, rows = stream_of(recording)
    header_lines = tuple(header.lines())
    seq = 0
    sock.sendto(Datagram("header", name, seq, header_lines).encode(), address)
    next_header = float(recording.t[0]) + HEADER_REPEAT
    for start, stop in _paced(recording.t, speed, clock, sleep):
        lines = [format_sample(row) for row in rows[start:stop].tolist()]
        for datagram in pack_samples(lines, name, seq):
            sock.sendto(datagram.encode(), address)
            seq += 1
        if recording.t[stop - 1] >= next_header:
            sock.sendto(Datagram("header", name, seq, header_lines).encode(), address)
            next_header += HEADER_REPEAT
    for _ in range(END_REPEAT):
        sock.sendto(Datagram("end", name, seq).encode(), address)
    return seq
