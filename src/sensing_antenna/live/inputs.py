"""The readers of a live stream: CSV lines (standard input) and UDP datagrams.

Each reads the wire format of :mod:`.wire`, starts a :class:`~.listener.Listener` for every
recording the stream carries (through the caller's ``make``), hands it the samples with the
wall time they arrived, and closes it when the recording ends. A reader only parses: the
estimates run in each listener's worker thread.

Standard input is trusted as a file is: a malformed line or a time that does not increase
stops the reader with a :class:`~sensing_antenna.recording.RecordingError` naming the line.
Read through :func:`paced_lines`, a recording whose writer falls silent without closing the
pipe ends after :data:`IDLE_END`, as over UDP. A
UDP port receives whatever anyone sends it: a datagram not in the format, a malformed line, a
datagram whose turn has gone, a time that does not increase or one that jumps ahead beyond any
filling (an outlier stamp, which would leave every good sample after it behind), a recording
first heard after its start is left out with a :class:`~.events.SkippedEvent` saying why, and
listening goes on. Datagrams out of order wait for their turn (:data:`REORDER_DEPTH`). A
stream its sender began again under the same name (its first header, then datagrams numbered
from 0 again) ends the recording and begins the next. Ctrl-C or a stop signal ends the
recording being received with its final events (:data:`INTERRUPTED_WAIT`).
"""

from __future__ import annotations

import contextlib
import itertools
import os
import queue
import socket
import threading
import time
from collections.abc import Callable, Iterable, Iterator

from sensing_antenna.errors import interruption_of
from sensing_antenna.estimation.front.steps import MAX_FILLED, OUTLIER_PERIODS
from sensing_antenna.live.events import Event, SkippedEvent
from sensing_antenna.live.listener import Listener
from sensing_antenna.live.wire import (
    MAX_DATAGRAM_BYTES,
    Datagram,
    StreamHeader,
    UnreadReadings,
    WireError,
    decode_datagram,
    parse_sample,
    read_header,
)
from sensing_antenna.recording import RecordingError

__all__ = [
    "IDLE_END",
    "INTERRUPTED_WAIT",
    "RECEIVE_BUFFER",
    "REORDER_DEPTH",
    "REORDER_WAIT",
    "MakeListener",
    "listen_lines",
    "listen_udp",
    "paced_lines",
    "parse_address",
]

#: A recording whose sender fell silent for this long (s) is closed as if it had ended: a UDP
#: sender that stopped without its ``end`` datagram (the datagram lost, the program killed), a
#: writer to standard input that stalled without closing the pipe (:func:`paced_lines`).
IDLE_END = 2.0

#: How often (s) :func:`paced_lines` says that no line came.
_PAUSE = 0.2

#: Reads of standard input (64 KiB each) :func:`paced_lines` holds ahead of its reader.
_QUEUED_READS = 64

#: The longest line (bytes) :func:`paced_lines` gathers: a recording's line is some hundred
#: bytes, so longer is no recording (binary data, a stream without line ends).
_LONGEST_LINE = 1 << 20

#: After Ctrl-C or a stop signal, the longest wait (s) for the recording's final estimate and
#: end event: a reader of the events that stopped reading (its pipe full) must not hold the
#: process (a fast method's final estimate takes well under a second).
INTERRUPTED_WAIT = 2.0

#: A UDP datagram that arrives before one numbered below it waits for it, with those after it
#: (the stream's ``end`` too), until more than this many wait or the first waited
#: :data:`REORDER_WAIT`: a network delivers datagrams out of order, mostly by a place or two
#: (left out, a late datagram's samples would be put back by interpolation). Then the missing
#: one counts as lost.
REORDER_DEPTH = 8

#: The longest a datagram waits (s) for one numbered below it (:data:`REORDER_DEPTH`).
REORDER_WAIT = 0.02

#: Receive buffer (bytes) :func:`listen_udp` asks of its socket when it has less: 4 MiB hold
#: several seconds of a 1 kHz stream sent as fast as it can be (a replay, a burst after a
#: pause), which the system's default (about 200 kB on Linux) drops while an estimate runs.
RECEIVE_BUFFER = 1 << 22

#: Samples left out in a row for their time stamps after which the stream is left out: its
#: samples no longer follow one time line (the sender's clock stepped, or an outlier came first).
_MAX_REJECTED = 50

#: How a reader starts the listener of a recording: ``make(header, number)``, number from 1.
MakeListener = Callable[[StreamHeader, int], Listener]


def _close_quietly(listener: Listener | None) -> None:
    if listener is not None:
        with contextlib.suppress(Exception):
            listener.close("interrupted", finish=False)


def _close_interrupted(exc: BaseException, close: Callable[[str, float], None]) -> bool:
    """When ``exc`` is an interruption (Ctrl-C, a stop signal), end the recording being
    received as its input's end would (``close(reason, wait)``: its final estimate if none was
    declared, and its ``end`` event), so that every recording begun has its end said; True
    when it did. Waited for :data:`INTERRUPTED_WAIT` at most; a second interruption while it
    finishes, or a longer wait, leaves it unfinished."""
    interrupt = interruption_of(exc)
    if interrupt is None:
        return False
    with contextlib.suppress(Exception):
        close(str(interrupt) or "interrupted", INTERRUPTED_WAIT)  # a stop signal's says which
    return True


def listen_lines(
    lines: Iterable[bytes | str | None],
    make: MakeListener,
    source: str = "<stdin>",
    count: int | None = None,
    clock: Callable[[], float] = time.perf_counter,
    on_event: Callable[[Event], None] | None = None,
    idle: float | None = None,
) -> int:
    """Read CSV lines until they end (or ``count`` recordings ended); returns the number of
    recordings ended. ``lines`` keep their line ends, as a file or a pipe gives them: the one
    without is the input's last, possibly cut short. With ``on_event``, a sample whose reading
    in a named column is NaN or infinite (a reading the device did not get) is left out with a
    :class:`~.events.SkippedEvent` to it, and put back from its neighbours by the estimator as a
    sample that never came; without, it stops the reader as any malformed line does.

    A None among ``lines`` is a pause in the input (:func:`paced_lines`): with ``idle`` (s), a
    recording with samples whose last line came longer ago than that on ``clock`` ends (``no
    sample for 2 s``), and the samples that follow it up to the next ``#`` line are left out,
    said once to ``on_event``: they belong to a recording already ended.

    Raises
    ------
    RecordingError
        At the first malformed line, naming ``source`` and the line: the recording being
        received is closed without a final estimate, unless the line is the input's last, cut
        short (no line end): the recording then ends before it, with its final estimate.
    """
    pending: list[str] = []
    pending_first = 0
    current: Listener | None = None
    ended = 0
    last_t: float | None = None
    heard = clock()  # when the last line came
    silenced = told = False  # a recording ended for its silence: its samples left out up to
    # the next '#' line, said once
    number = 0
    try:
        for raw in lines:
            received = clock()
            if raw is None:
                # a recording's silence counts from its samples: a header may wait for the first
                if (
                    current is not None
                    and last_t is not None
                    and idle is not None
                    and received - heard > idle
                ):
                    current.close(f"no sample for {idle:g} s")
                    current, ended, silenced, told = None, ended + 1, True, False
                    if count is not None and ended >= count:
                        return ended
                continue
            number, heard = number + 1, received
            text = _text(raw, source, number)
            line = text.rstrip("\r\n")
            if not line.strip():
                continue
            if line.startswith("#"):
                silenced = False
                if current is not None:
                    current.close("a '#' line after the samples")
                    current, ended = None, ended + 1
                    if count is not None and ended >= count:
                        return ended
                if not pending:
                    pending_first = number
                pending.append(line)
                continue
            if silenced:
                if not told and on_event is not None:
                    on_event(
                        SkippedEvent(
                            ended,
                            f"{source}:{number}: samples after the recording ended for its"
                            " silence: left out up to the next '#' line",
                        )
                    )
                told = True
                continue
            if current is None:
                first = pending_first if pending else number
                header = read_header([*pending, line], source, first_line=first)
                pending = []
                current, last_t = make(header, ended + 1), None
                continue
            try:
                values = parse_sample(line, current.header, number, on_event is not None)
            except UnreadReadings as exc:
                assert on_event is not None  # raised only when asked for (glitches)
                on_event(SkippedEvent(ended + 1, f"{source}:{number}: {_left_out(exc.columns)}"))
                continue
            except RecordingError as exc:
                if text.endswith("\n"):
                    raise
                # the input's last line, cut short (a logger stopped mid-line): the recording
                # ends before it, with its final estimate, and the line is named
                current.close("end of input")
                current, ended = None, ended + 1
                raise RecordingError(
                    source,
                    number,
                    exc.field,
                    f"{exc.problem} (truncated last line: left out, the recording ended before it)",
                ) from None
            t = values[current.header.required("t")]
            if last_t is not None and not t > last_t:
                raise RecordingError(
                    source, number, "t", f"time {t!r} s does not increase (previous {last_t!r} s)"
                )
            last_t = t
            current.put([values], received)
        if current is None and pending and not ended:
            # after a recording, '#' lines the input ends with are a footer, as in a file
            raise RecordingError(
                source, pending_first + len(pending), None, "no header after the metadata"
            )
        if current is not None:
            current.close("end of input")
            current, ended = None, ended + 1
        return ended
    except BaseException as exc:
        listener = current
        if listener is not None and _close_interrupted(
            exc, lambda reason, wait: listener.close(reason, wait=wait)
        ):
            current = None
        raise
    finally:
        _close_quietly(current)


def paced_lines(fd: int, pause: float = _PAUSE, source: str = "<stdin>") -> Iterator[bytes | None]:
    """The lines read from the file descriptor ``fd`` (standard input: 0) as they come, each
    with its line end (the last without one when the input ends without it), and None each
    ``pause`` (s) in which none came, for :func:`listen_lines` to notice a writer gone silent.

    A thread of its own reads the descriptor (``os.read``, no buffered file object whose lock
    it could hold when the program ends), at most :data:`_QUEUED_READS` reads ahead of the
    lines taken (a file given whole is not held in memory); bytes that come without ending a
    line are no pause. An error reading it, or a line longer than :data:`_LONGEST_LINE`
    (a :class:`~sensing_antenna.recording.RecordingError` naming ``source``), is raised here.
    """
    arrived: queue.Queue[list[bytes] | BaseException | None] = queue.Queue(_QUEUED_READS)

    def read() -> None:
        pieces: list[bytes] = []  # of the line not yet ended
        gathered = 0
        try:
            while chunk := os.read(fd, 1 << 16):
                *ended, rest = chunk.split(b"\n")
                if ended:
                    ended[0] = b"".join([*pieces, ended[0]])
                    pieces, gathered = [], 0
                # a read that ended no line still says the writer writes (no pause)
                arrived.put([line + b"\n" for line in ended])
                if rest:
                    pieces.append(rest)
                    gathered += len(rest)
                    if gathered > _LONGEST_LINE:
                        raise RecordingError(
                            source,
                            None,
                            None,
                            f"a line of more than {_LONGEST_LINE:,} bytes without its end: not"
                            " the recording format (binary data, or no line ends)",
                        )
            if pieces:
                arrived.put([b"".join(pieces)])
            arrived.put(None)
        except BaseException as exc:  # passed on to the reader of the lines
            arrived.put(exc)

    threading.Thread(target=read, name="stdin-lines", daemon=True).start()
    while True:
        try:
            item = arrived.get(timeout=pause)
        except queue.Empty:
            yield None
            continue
        if item is None:
            return
        if isinstance(item, BaseException):
            raise item
        yield from item


def _left_out(columns: tuple[str, ...]) -> str:
    """Why a sample whose named ``columns`` are NaN or infinite is left out, and what then."""
    named = ", ".join(repr(name) for name in columns)
    return (
        f"column{'s' if len(columns) > 1 else ''} {named} not a finite number: the sample is left"
        " out, and put back from its neighbours as one that never came"
    )


def _text(raw: bytes | str, source: str, number: int) -> str:
    """A line as text: UTF-8, no NUL byte (binary content)."""
    if isinstance(raw, bytes):
        try:
            raw = raw.decode("utf-8-sig" if number == 1 else "utf-8")
        except UnicodeDecodeError:
            raise RecordingError(source, number, None, "not UTF-8 text") from None
    if "\0" in raw:
        raise RecordingError(source, number, None, "NUL byte: binary content, not CSV lines")
    return raw


def parse_address(text: str) -> tuple[str, int]:
    """``HOST:PORT`` as (host, port); :class:`WireError` when it is not one."""
    host, sep, port = text.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 <= int(port) <= 65535:
        raise WireError(f"address must read HOST:PORT with a port from 0 to 65535, got {text!r}")
    return host.strip("[]"), int(port)


class _UdpStream:
    """The recording a UDP reader is receiving: its listener, stream name, next sequence number,
    last time stamp and datagrams lost."""

    def __init__(self, listener: Listener, datagram: Datagram) -> None:
        self.listener = listener
        self.name = datagram.stream
        self.expected = datagram.seq
        self.last_t: float | None = None
        self.lost = 0
        self.heard = 0.0
        self.rejected = 0  # samples left out in a row for their time stamps
        self.again: Datagram | None = None  # a first header after samples of the stream
        self.held: list[tuple[Datagram, float]] = []  # datagrams numbered below, since then
        self.first: dict[int, tuple[str, ...]] = {}  # the lines of its first datagrams taken
        self.ahead: dict[int, tuple[Datagram, float]] = {}  # waiting for one numbered below
        self.ended = False  # its end came in its turn, after the datagrams that waited

    @property
    def reached(self) -> int:
        """The number after the highest of the stream's datagrams heard (taken or waiting)."""
        return max(self.expected, max(self.ahead, default=-1) + 1)

    def close(self, reason: str, wait: float | None = None) -> None:
        if self.lost:
            reason += f"; {self.lost} datagram{'' if self.lost == 1 else 's'} of samples lost"
        self.listener.close(reason, wait=wait)


def listen_udp(
    sock: socket.socket,
    make: MakeListener,
    on_event: Callable[[Event], None],
    count: int | None = None,
    idle: float = IDLE_END,
    clock: Callable[[], float] = time.perf_counter,
) -> int:
    """Receive datagrams on a bound socket until ``count`` recordings ended (forever when
    None; streams left out are not counted, though they keep their numbers); returns the
    number ended. ``on_event`` receives the reader's own :class:`~.events.SkippedEvent`s (from
    this thread: the listeners' events come from theirs)."""
    if sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) < RECEIVE_BUFFER:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, RECEIVE_BUFFER)
    host, port = sock.getsockname()[:2]
    source = f"udp:{host}:{port}"
    current: _UdpStream | None = None
    numbered = 0  # streams joined, each with its recording's number
    ended = 0  # recordings ended, not counting streams left out (what ``count`` counts)
    refused: set[str] = set()  # streams left out, ignored until their end
    joined: set[str] = set()  # streams heard (one that resumes after the idle end is known)
    sock.settimeout(min(idle, 0.2))  # shorter while datagrams wait (REORDER_WAIT)

    def skip(reason: str, number: int = 0) -> None:
        """A ``skipped`` event for what belongs to no recording (0) or to recording
        ``number``."""
        on_event(SkippedEvent(number, reason))

    def skip_current(reason: str) -> None:
        """A ``skipped`` event for the recording being received (the last joined)."""
        skip(reason, numbered)

    def leave_out(name: str, exc: Exception, number: int = 0) -> None:
        """Say why the stream ``name`` (recording ``number``, 0 when never joined) is left
        out, and ignore it until its end."""
        skip(f"{exc}: the stream is left out", number)
        refused.add(name)

    def join(datagram: Datagram, received: float, ending: str) -> bool:
        """Begin the recording whose header ``datagram`` is, ending the one being received
        (``ending``: its end's reason) unless the header is refused; False when that end
        reached ``count``."""
        nonlocal current, numbered, ended
        name = datagram.stream
        try:
            header = read_header(list(datagram.lines), f"{source} stream {name}")
        except RecordingError as exc:
            skip(str(exc))
            return True
        if datagram.seq > 0 and name not in joined:
            # heard first after samples were sent (listening began late, or the first header
            # was lost): the recording's start, its rest and its contact, is gone. Never
            # joined, it takes no recording's number (0) nor a --count
            skip(
                f"stream {name}: first heard at its samples datagram {datagram.seq}: its "
                "start (the rest, the contact) was missed; left out, the next recording is "
                "heard"
            )
            refused.add(name)
            return True
        if current is not None:
            ended += finish(current, ending)
            current = None
            if count is not None and ended >= count:
                return False
        refused.discard(name)  # its previous recording refused at its end
        try:
            listener = make(header, numbered + 1)
        except RecordingError as exc:  # its header refused for this antenna
            leave_out(name, exc)
            return True
        numbered += 1
        current = _UdpStream(listener, datagram)
        current.heard = received
        joined.add(name)
        return True

    def take(datagram: Datagram | None, received: float, flush: bool = False) -> None:
        """The samples of ``datagram`` to the recording being received, in their order
        (:data:`REORDER_DEPTH`; None: those waiting whose wait is over at ``received``, all
        of them with ``flush``); the stream left out when its time stamps no longer follow one
        time line."""
        nonlocal current
        assert current is not None
        try:
            if datagram is not None:
                _arrive(current, datagram, received, skip_current)
            _release(current, received, skip_current, flush)
        except WireError as exc:
            leave_out(current.name, exc, numbered)
            _close_quietly(current.listener)
            current = None

    def finish(stream: _UdpStream, reason: str) -> int:
        """End ``stream`` (the datagrams waiting taken first): 1, or 0 when the listener
        refused it (its period, say): skipped, not fatal (other streams may follow) and not
        counted."""
        try:
            _release(stream, clock(), skip_current, flush=True)
        except WireError as exc:
            leave_out(stream.name, exc, numbered)
            _close_quietly(stream.listener)
            return 0
        try:
            stream.close(reason)
        except WireError as exc:
            leave_out(stream.name, exc, numbered)
            return 0
        return 1

    try:
        timeout = min(idle, 0.2)
        while count is None or ended < count:
            if current is not None and current.ended:
                ended += finish(current, "end of stream")
                current = None
                continue
            waiting = current is not None and bool(current.ahead)
            if timeout != (wanted := REORDER_WAIT if waiting else min(idle, 0.2)):
                sock.settimeout(timeout := wanted)
            try:
                data = sock.recv(MAX_DATAGRAM_BYTES + 1)
            except TimeoutError:
                if current is not None and clock() - current.heard > idle:
                    ended += finish(current, f"no datagram for {idle:g} s")
                    current = None
                elif current is not None and current.ahead:
                    take(None, clock())
                continue
            received = clock()
            try:
                datagram = decode_datagram(data)
            except WireError as exc:
                skip(str(exc))
                continue
            if current is not None and current.ahead:
                take(None, received)  # the wait is over whatever stream's datagram came
            if datagram.stream in refused:
                if datagram.kind == "end":
                    refused.discard(datagram.stream)
                continue  # a stream left out: its repeated headers do not join it again
            ours = current is not None and datagram.stream == current.name
            if ours:
                assert current is not None
                current.heard = received
                if datagram.kind == "header" and datagram.seq == 0 < current.reached:
                    # a stream's first header after samples of it: a copy come late, or the
                    # sender began the stream again under its name, as its next samples tell
                    try:
                        read_header(list(datagram.lines), f"{source} stream {datagram.stream}")
                    except RecordingError as exc:
                        skip_current(str(exc))
                    else:
                        current.again, current.held = datagram, []
                    continue
                if current.again is not None:
                    again, held = current.again, current.held
                    if datagram.kind != "header" and datagram.seq < current.reached:
                        held.append((datagram, received))
                        if datagram.kind == "samples" and not _begun_again(held, current.first):
                            continue  # held until their numbers or lines tell
                        if not join(again, received, "the stream began again (datagrams from 0)"):
                            break
                        if current is None or current.name != datagram.stream:
                            continue
                        for late, when in held:  # the new recording's first datagrams
                            if current is None:
                                break
                            if late.kind == "end":
                                ended += finish(current, "end of stream")
                                current = None
                            else:
                                take(late, when)
                        continue
                    # the stream's own numbers go on: the header was a copy come late, and the
                    # datagrams held arrived late
                    current.again, current.held = None, []
                    for late, when in held:
                        take(late, when)
                    if current is None:
                        continue
            if datagram.kind == "header" and not ours:
                if not join(datagram, received, "another stream began"):
                    break
            elif not ours or datagram.kind == "header":
                continue  # a repeated header, or samples of a stream not joined
            elif datagram.kind == "end":
                assert current is not None
                if datagram.seq > current.expected:
                    # samples numbered below it are missing: it waits its turn as they do (a
                    # repeated end already waiting adds nothing)
                    current.ahead.setdefault(datagram.seq, (datagram, received))
                    take(None, received)
                else:
                    take(None, received, flush=True)
                    if current is not None:
                        current.lost += max(0, datagram.seq - current.expected)
                        ended += finish(current, "end of stream")
                        current = None
            else:
                take(datagram, received)
        return ended
    except BaseException as exc:
        if current is not None and interruption_of(exc) is not None:
            with contextlib.suppress(Exception):
                take(None, clock(), flush=True)  # the datagrams waiting are the recording's
        if current is not None and _close_interrupted(exc, current.close):
            current = None
        raise
    finally:
        _close_quietly(None if current is None else current.listener)


#: After a stream's first header came again, datagrams numbered below those already heard:
#: this many with consecutive numbers, the smallest below it (in any order of arrival), or one
#: of its first datagrams with other lines than it had, tell the sender began the stream again.
#: Others are copies and late datagrams of the stream, which a network delivers too.
_BEGUN_AGAIN = 3


def _begun_again(held: list[tuple[Datagram, float]], first: dict[int, tuple[str, ...]]) -> bool:
    """Whether the datagrams ``held`` since a stream's first header came again (in the order
    they arrived) are the stream begun again (:data:`_BEGUN_AGAIN`); ``first``: the lines of
    the stream's first datagrams, by number."""
    numbers = sorted({datagram.seq for datagram, _ in held})[:_BEGUN_AGAIN]
    other = any(d.seq in first and d.lines != first[d.seq] for d, _ in held)
    # in any order of arrival (the network's), consecutive from below the count
    return other or (
        len(numbers) == _BEGUN_AGAIN
        and numbers[0] < _BEGUN_AGAIN
        and all(b == a + 1 for a, b in itertools.pairwise(numbers))
    )


def _arrive(
    current: _UdpStream, datagram: Datagram, received: float, skip: Callable[[str], None]
) -> None:
    """A samples datagram of the stream: taken when its turn has come or gone, else waiting
    for those numbered below it (:data:`REORDER_DEPTH`)."""
    if datagram.seq <= current.expected:
        _receive_samples(current, datagram, received, skip)
    elif datagram.seq in current.ahead:
        skip(f"stream {current.name}: datagram {datagram.seq} arrived again: left out")
    else:
        current.ahead[datagram.seq] = (datagram, received)


def _release(
    current: _UdpStream, now: float, skip: Callable[[str], None], flush: bool = False
) -> None:
    """The datagrams waiting whose turn has come, in order; those numbered below them counted
    lost when :data:`REORDER_DEPTH` wait, the first waited :data:`REORDER_WAIT` at ``now``
    (s), or ``flush``."""
    ahead = current.ahead
    while ahead:
        first = min(ahead)
        over = (
            flush
            or len(ahead) > REORDER_DEPTH
            or now - min(when for _, when in ahead.values()) > REORDER_WAIT
        )
        if first != current.expected and not over:
            return
        datagram, received = ahead.pop(first)
        if datagram.kind == "end":
            # the stream's end in its turn: the datagrams numbered below it are lost
            current.lost += max(0, datagram.seq - current.expected)
            current.ended = True
            ahead.clear()
            return
        _receive_samples(current, datagram, received, skip)


def _receive_samples(
    current: _UdpStream, datagram: Datagram, received: float, skip: Callable[[str], None]
) -> None:
    """The samples of one datagram to the listener, or why (some of) they were left out."""
    if datagram.seq < current.expected:
        if datagram.seq == current.expected - 1:
            skip(f"stream {current.name}: datagram {datagram.seq} arrived again: left out")
        else:
            skip(
                f"stream {current.name}: datagram {datagram.seq} arrived after"
                f" {current.expected - 1}: left out"
            )
        return
    current.lost += datagram.seq - current.expected
    current.expected = datagram.seq + 1
    if datagram.seq < _BEGUN_AGAIN:
        current.first[datagram.seq] = datagram.lines
    header = current.listener.header
    position = header.required("t")
    period = header.sample_period
    rows = []
    n = len(datagram.lines)
    for k, line in enumerate(datagram.lines, start=1):
        # which sample line of the datagram was left out, when it holds more than one
        where = f"stream {current.name}: datagram {datagram.seq}" + (
            f" sample line {k} of {n}" if n > 1 else ""
        )
        try:
            values = parse_sample(line, header)
        except RecordingError as exc:
            skip(f"{where}: {exc.problem}" + (f" (column {exc.field!r})" if exc.field else ""))
            continue
        t = values[position]
        problem = None
        if current.last_t is not None and not t > current.last_t:
            problem = f"time {t!r} s does not increase (previous {current.last_t!r} s)"
        elif current.last_t is not None and (t - current.last_t) > OUTLIER_PERIODS * period:
            # more than the front end would put back: the stamp, not the samples after it
            problem = (
                f"time {t!r} s jumps from {current.last_t!r} s by more than {MAX_FILLED}"
                " samples: an outlier time stamp, left out"
            )
        if problem is not None:
            current.rejected += 1
            if current.rejected > _MAX_REJECTED:
                # not a stamp gone astray but a time line the samples no longer follow (the
                # sender's clock stepped, or the first stamp was the outlier)
                raise WireError(
                    f"{where}: {_MAX_REJECTED} time stamps in a row left out, the last {t!r} s "
                    f"after {current.last_t!r} s"
                )
            skip(f"{where}: {problem}")
            continue
        current.rejected = 0
        current.last_t = t
        rows.append(values)
    if rows:
        current.listener.put(rows, received)
