"""What the commands' arguments may be: argparse types, and the checks that need the antenna.

A bad argument is reported under the flag the user typed (``--xc``, ``--modes``) with the allowed
range, whether argparse finds it while parsing (the types here) or the command finds it once the
antenna is loaded (:func:`check_contact_points`). Nothing here imports NumPy: argument errors
answer at once (docs/develop.md, "The command line").
"""

from __future__ import annotations

import argparse
import math
import os
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from sensing_antenna.errors import FieldError, format_value


class ArgumentError(FieldError):
    """A command-line argument is invalid; ``field_name`` is the flag as typed (``--xc``)."""


def _bound_text(low: float | None, high: float | None, low_open: bool, unit: str) -> str:
    suffix = f" {unit}" if unit else ""
    if low is not None and high is not None:
        opening = "(" if low_open else "["
        return f"in {opening}{low:g}, {high:g}]{suffix}"
    if low is not None:
        return f"{'>' if low_open else '>='} {low:g}{suffix}"
    if high is not None:
        return f"<= {high:g}{suffix}"
    return unit and f"({unit})"


def number(
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    unit: str = "",
    what: str = "number",
    finite: bool = True,
) -> Callable[[str], float]:
    """An argparse ``type``: a finite float with ``low (<|<=) value <= high``.

    The error reads ``must be a finite <what> <range> <unit>, got <value>``. With
    ``finite=False`` nan and infinities pass too (``--xc``: the command checks the value against
    the range of the antenna it loads, and names it there).
    """
    adjective = "finite " if finite else ""
    bounds = _bound_text(low, high, low_open, unit)
    requirement = f"must be a {adjective}{what} {bounds}".rstrip()

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{requirement}, got {text!r}") from None
        too_low = low is not None and (value <= low if low_open else value < low)
        too_high = high is not None and value > high
        if (finite and not math.isfinite(value)) or too_low or too_high:
            raise argparse.ArgumentTypeError(f"{requirement}, got {format_value(value)}")
        return value

    return parse


def integer(low: int | None = None, high: int | None = None) -> Callable[[str], int]:
    """An argparse ``type``: an integer with ``low <= value <= high``."""
    if low is not None and high is not None:
        requirement = f"must be an integer from {low} to {high}"
    else:
        requirement = f"must be an integer {_bound_text(low, high, False, '')}".rstrip()

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{requirement}, got {text!r}") from None
        if (low is not None and value < low) or (high is not None and value > high):
            raise argparse.ArgumentTypeError(f"{requirement}, got {value}")
        return value

    return parse


def add_actions(parser: argparse.ArgumentParser, dest: str, metavar: str) -> Any:
    """Subcommands of a command (``campaign run``); without one, an error that lists them.

    Returns the object whose ``add_parser`` adds each subcommand.
    """
    actions = parser.add_subparsers(dest=dest, metavar=metavar, parser_class=type(parser))

    def missing(args: argparse.Namespace) -> int:
        names = ", ".join(actions.choices)
        parser.error(f"{metavar}: missing; one of {names} (see {parser.prog} --help)")

    parser.set_defaults(func=missing)
    return actions


def check_contact_points(link: Any, values: Iterable[float], flag: str = "--xc") -> None:
    """Raise :class:`ArgumentError` under ``flag`` unless every value lies in (0, l] m.

    ``link`` is the :class:`~sensing_antenna.antenna.Link` of the antenna in use; its own rule
    (:meth:`~sensing_antenna.antenna.Link.check_contact_point`) decides, so the range named is
    the one every command and the library apply.
    """
    for value in values:
        try:
            link.check_contact_point(value)
        except FieldError as exc:
            raise ArgumentError(flag, exc.problem) from exc


def antenna_name(name: str | None, out: Path) -> str:
    """The name of an antenna a command writes to ``out``: ``name`` (``--name``) or out's stem.

    Raises
    ------
    ArgumentError
        Under ``--name`` or ``--out`` when the name is blank or not one line of printable text
        (a newline, tab or other control character would not survive a one-line TOML string).
    """
    flag, value = ("--name", name) if name is not None else ("--out", out.stem)
    if not value.strip() or not value.isprintable():
        problem = f"an antenna name must be one line of printable text, got {value!r}"
        if flag == "--out":
            problem = f"the file name gives the antenna's name: {problem}; give --name"
        raise ArgumentError(flag, problem)
    return value


def printable(text: str) -> str:
    """``text`` on one line: characters that are not printable shown as escapes (``\\n``)."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def distinct_files(paths: Iterable[Path], what: str = "recordings") -> list[Path]:
    """``paths`` as given, refusing one file given twice (the same file by two spellings
    included): it would count twice."""
    given = list(paths)
    seen: dict[object, Path] = {}
    for path in given:
        try:  # the file itself, whatever links lead to it
            status = os.stat(path)
            key: object = (status.st_dev, status.st_ino)
        except OSError:  # not there: its reader names it
            key = os.path.realpath(path)
        if key in seen:
            same = "" if str(seen[key]) == str(path) else f" (as {printable(str(seen[key]))})"
            raise ArgumentError(
                what, f"{printable(str(path))} given twice{same}: it would count twice"
            )
        seen[key] = path
    return given
