"""``antenna listen``: estimates while the samples arrive (docs/live.md)."""

from __future__ import annotations

import argparse
import contextlib
import sys
import threading
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from sensing_antenna.cli import EXIT_BAD_INPUT
from sensing_antenna.cli.arguments import integer
from sensing_antenna.cli.estimate import DEFAULT_ANTENNA, METHOD_NAMES, warn_of_other_antennas


def register(subparsers: Any) -> None:
    """Add ``antenna listen``."""
    parser = subparsers.add_parser(
        "listen",
        help="estimate while the samples of a device arrive (standard input or UDP)",
        description=(
            "Reads samples as they arrive, CSV lines on standard input or UDP datagrams on a "
            "port (the wire formats of docs/live.md: the recording format's metadata, header "
            "and one sample per line), runs the online estimator in a worker thread, and "
            "writes one JSON line per event: contact (t_c), push (t_1), estimate (x_c, "
            "interval, status, t_e), contact_lost, end, and skipped input; each with its "
            "latency, the wall time from the receipt of the sample it is at to the line."
        ),
    )
    parser.add_argument(
        "--udp",
        metavar="HOST:PORT",
        help="receive UDP datagrams bound to this address (default: standard input)",
    )
    parser.add_argument("--method", choices=METHOD_NAMES, default="paper", help="as for estimate")
    parser.add_argument("--t1", choices=("rest", "push"), default="rest", help="as for estimate")
    parser.add_argument(
        "--antenna",
        default=None,
        help=f"built-in name or TOML file (default {DEFAULT_ANTENNA}; a stream whose 'antenna' "
        "metadata names another is warned of)",
    )
    parser.add_argument(
        "--record",
        type=Path,
        metavar="FILE",
        help="keep what was received as a recording (the stream's next recordings in "
        "FILE-2, FILE-3, ... before the suffix; default: not kept)",
    )
    parser.add_argument(
        "--count",
        type=integer(low=1),
        metavar="N",
        help="stop after N recordings ended (default: when the input ends; over UDP, on Ctrl-C)",
    )
    parser.add_argument(
        "--warm-up",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="before listening, run one simulated manoeuvre of the antenna through the method, "
        "so that the first recording's events do not wait for the method's kernels to load "
        "(about a second)",
    )
    parser.set_defaults(func=_run)


def _run(args: argparse.Namespace) -> int:
    import json
    import socket

    from threadpoolctl import threadpool_limits

    from sensing_antenna.antenna import load_antenna
    from sensing_antenna.cli.arguments import ArgumentError
    from sensing_antenna.errors import SensingAntennaError
    from sensing_antenna.estimation.config import EstimatorConfig
    from sensing_antenna.live.events import Event
    from sensing_antenna.live.inputs import (
        IDLE_END,
        listen_lines,
        listen_udp,
        paced_lines,
        parse_address,
    )
    from sensing_antenna.live.listener import Listener
    from sensing_antenna.live.record import RecordWriter, numbered_path, record_path_problem
    from sensing_antenna.live.warm_up import freeze_heap, warm_up
    from sensing_antenna.live.wire import StreamHeader, WireError
    from sensing_antenna.recording import RecordingError

    # one BLAS thread: the estimates' matrices are small, and a second thread only waits for a
    # core that another process holds, delaying the answer (docs/live.md, "Latency")
    threadpool_limits(limits=1)
    if args.record is not None:
        problem = record_path_problem(args.record)
        if problem is not None:
            raise ArgumentError("--record", problem)
    antenna = load_antenna(DEFAULT_ANTENNA if args.antenna is None else args.antenna)
    config = EstimatorConfig(t1_source=args.t1)
    lock = threading.Lock()

    def emit(event: Event) -> None:
        line = json.dumps(event.to_dict(), allow_nan=False)
        with lock:
            sys.stdout.write(line + "\n")
            sys.stdout.flush()

    def make(header: StreamHeader, number: int) -> Listener:
        if args.antenna is None:  # the default: another antenna's stream is warned of
            which = f"{header.source} recording {number}"
            warn_of_other_antennas({header.metadata.get("antenna", ""): [which]}, antenna.name)
        record = None
        if args.record is not None:
            kept = numbered_path(args.record, number)
            try:
                record = RecordWriter(kept, header)
            except OSError as exc:  # a file made since the start, a folder removed: this stream
                raise RecordingError(
                    header.source, None, "--record", f"{kept}: {exc.strerror or exc}"
                ) from None
        try:
            return Listener(header, antenna, emit, args.method, config, record, number)
        except SensingAntennaError:
            if record is not None:  # a stream refused before any sample: no recording of it
                record.close()
                record.path.unlink(missing_ok=True)
            raise

    def ready() -> None:
        if not args.warm_up:
            freeze_heap()
            return
        try:
            warm_up(antenna, args.method, config)
        except SensingAntennaError as exc:  # a model the simulator refuses: listen anyway
            freeze_heap()
            print(f"antenna listen: warm-up skipped: {exc}", file=sys.stderr, flush=True)

    if args.udp is None:
        if sys.stdin is None:  # started with standard input closed
            print("antenna listen: error: <stdin>: closed, nothing to listen to", file=sys.stderr)
            return EXIT_BAD_INPUT
        ready()
        lines: Iterable[bytes | None] = sys.stdin.buffer
        idle = None
        with contextlib.suppress(AttributeError, OSError, ValueError):  # no descriptor: a test's
            lines, idle = paced_lines(sys.stdin.fileno()), IDLE_END
        if listen_lines(lines, make, "<stdin>", args.count, on_event=emit, idle=idle) == 0:
            # an input that ended before any header: nothing was listened to, say so, and fail
            # (a pipe whose writer failed before writing must not look like a success)
            print(
                "antenna listen: error: <stdin>: the input ended with no recording",
                file=sys.stderr,
            )
            return EXIT_BAD_INPUT
        return 0
    try:
        address = parse_address(args.udp)
    except WireError as exc:
        raise ArgumentError("--udp", str(exc)) from None
    with socket.socket(
        socket.AF_INET6 if ":" in address[0] else socket.AF_INET, socket.SOCK_DGRAM
    ) as sock:
        try:
            sock.bind(address)
        except OSError as exc:
            raise ArgumentError(
                "--udp", f"cannot listen on {args.udp}: {exc.strerror or exc}"
            ) from None
        ready()
        host, port = sock.getsockname()[:2]
        print(f"antenna listen: listening on udp {host}:{port}", file=sys.stderr, flush=True)
        listen_udp(sock, make, emit, args.count)
    return 0
