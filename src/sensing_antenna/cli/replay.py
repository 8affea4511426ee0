"""``antenna replay``: a recording sent at its own pace, to standard output or UDP
(docs/live.md)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from sensing_antenna.cli.arguments import number


def register(subparsers: Any) -> None:
    """Add ``antenna replay``."""
    parser = subparsers.add_parser(
        "replay",
        help="send a recording at its own pace to standard output or UDP",
        description=(
            "Sends a recording (the format of docs/recording-format.md) as a device would: "
            "its metadata and header, then each sample when its time comes, as CSV lines on "
            "standard output or as UDP datagrams (the wire formats of docs/live.md), for "
            "antenna listen. --speed 2 plays twice as fast; --speed 0 as fast as the output "
            "takes it."
        ),
    )
    parser.add_argument("recording", type=Path, help="recording in the sensing-antenna format")
    parser.add_argument(
        "--speed",
        type=number(low=0.0, what="factor"),
        default=1.0,
        help="pace relative to the recording's time stamps (0: no pace)",
    )
    parser.add_argument(
        "--udp",
        metavar="HOST:PORT",
        help="send UDP datagrams to this address (default: standard output)",
    )
    parser.set_defaults(func=_run)


#: The longest paced replay (s): a day; a slower --speed is a typing error.
MAX_REPLAY_S = 86400.0


def _run(args: argparse.Namespace) -> int:
    import socket

    from sensing_antenna.cli.arguments import ArgumentError
    from sensing_antenna.live.inputs import parse_address
    from sensing_antenna.live.replay import replay_datagrams, replay_lines
    from sensing_antenna.live.wire import WireError
    from sensing_antenna.recording import read_recording

    address = None
    if args.udp is not None:
        try:
            address = parse_address(args.udp)
        except WireError as exc:
            raise ArgumentError("--udp", str(exc)) from None
        if address[1] == 0:
            raise ArgumentError(
                "--udp", "port 0 is no destination: give the port antenna listen prints"
            )
    recording = read_recording(args.recording)
    span = float(recording.t[-1] - recording.t[0])
    if args.speed > 0 and not span / args.speed <= MAX_REPLAY_S:
        raise ArgumentError(
            "--speed",
            f"{args.speed:g} would take {span / args.speed:.3g} s to replay the recording's "
            f"{span:.3g} s, more than a day ({MAX_REPLAY_S:g} s); 0 sends it unpaced",
        )
    if address is None:
        replay_lines(recording, sys.stdout.write, sys.stdout.flush, args.speed)
        return 0
    family = socket.AF_INET6 if ":" in address[0] else socket.AF_INET
    with socket.socket(family, socket.SOCK_DGRAM) as sock:
        try:
            socket.getaddrinfo(*address, family, socket.SOCK_DGRAM)
        except OSError as exc:
            raise ArgumentError(
                "--udp", f"cannot send to {args.udp}: {exc.strerror or exc}"
            ) from None
        replay_datagrams(recording, sock, address, args.speed)
    return 0
