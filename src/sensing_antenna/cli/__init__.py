"""The ``antenna`` command. It only parses arguments and calls the library.

Each command lives in its own module exposing ``register(subparsers)``; the module sets
``func`` on its parser, a callable ``(args) -> int`` returning the exit code. Errors derived from
:class:`~sensing_antenna.errors.SensingAntennaError`, and operating-system errors such as an
unwritable output path, are printed as one line, exit code 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence
from typing import NoReturn

from sensing_antenna.errors import SensingAntennaError

#: Command modules, in the order ``antenna --help`` lists them.
COMMAND_MODULES = (
    "beam",
    "simulate",
    "identify",
    "estimate",
    "calibrate",
    "campaign",
    "plot",
)


class OneLineParser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line on stderr and exit code 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    """The full ``antenna`` parser with every available command registered."""
    parser = OneLineParser(
        prog="antenna",
        description="Sensing-antenna toolkit: beam model, simulator, estimators, campaigns.",
    )
    subparsers = parser.add_subparsers(
        dest="command", metavar="COMMAND", parser_class=OneLineParser
    )
    for name in COMMAND_MODULES:
        importlib.import_module(f"sensing_antenna.cli.{name}").register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``antenna`` console script; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not hasattr(args, "func"):
        parser.print_help()
        return 2
    try:
        return int(args.func(args))
    except SensingAntennaError as exc:
        print(f"antenna {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # unwritable output, missing directory, disk full, ...
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"antenna {args.command}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # pragma: no cover - e.g. piping into head
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
