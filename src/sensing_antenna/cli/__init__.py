"""The ``antenna`` command. It only parses arguments and calls the library.

Each command lives in its own module exposing ``register(subparsers)``; the module sets
``func`` on its parser, a callable ``(args) -> int`` returning the exit code. Two more defaults a
command may set with ``set_defaults``:

``flags``
    ``{library field name: flag}``: an error the library raises about a field the command filled
    from a flag (``ScenarioError`` about ``contact_point``) is reported under the flag (``--xc``).

How a command ends, whichever it is:

- 0 on success (or the command's own code);
- 2 on bad input, one line on stderr: an error derived from
  :class:`~sensing_antenna.errors.SensingAntennaError`, an argument error, an operating-system
  error such as an unwritable output path, or not enough memory for what was asked;
- on Ctrl-C, one line on stderr (the interruption's own ``message`` when it carries one, as a
  stopped campaign says what it keeps), then the ``KeyboardInterrupt`` goes on up without its
  traceback: the process ends by SIGINT as Python ends any interrupted program, after its
  clean-ups, so the shell reports 130 (128 + SIGINT) and a shell loop or script running the
  command stops as well (bash goes on when a program exits normally after Ctrl-C);
- 143 (128 + SIGTERM) when asked to stop, one line on stderr; SIGTERM raises
  :class:`~sensing_antenna.errors.Terminated` where the command is, so clean-ups run as for
  Ctrl-C (any interruption that carries another ``signal_number`` ends with 128 + it); one that
  lands in a finalizer, where Python drops exceptions, is raised again a moment later, and one
  dropped anywhere else still ends the command when it returns;
- quietly with 141 (128 + SIGPIPE) when whatever reads the output closes it
  (``antenna beam ... | head -2``), what a shell reports for a program stopped by a closed pipe.
"""

from __future__ import annotations

import argparse
import contextlib
import difflib
import importlib
import os
import signal
import sys
from collections.abc import Iterator, Mapping, Sequence
from types import FrameType
from typing import Any, NoReturn

from sensing_antenna.errors import (
    SensingAntennaError,
    Terminated,
    forget_signals,
    interruption_of,
    note_signal,
    raise_if_signalled,
)

#: Command modules, in the order ``antenna --help`` lists them.
COMMAND_MODULES = (
    "beam",
    "simulate",
    "importer",
    "identify",
    "estimate",
    "listen",
    "replay",
    "calibrate",
    "campaign",
    "map",
    "explore",
    "plot",
)

#: Exit code for bad input: arguments, files, fields.
EXIT_BAD_INPUT = 2
#: Exit code when the reader of the output closed it.
EXIT_CLOSED_PIPE = 128 + 13  # SIGPIPE (signal.SIGPIPE does not exist on Windows)

#: The name of the distribution whose version ``antenna --version`` prints.
DISTRIBUTION = "sensing-antenna"


class HelpFormatter(argparse.HelpFormatter):
    """Help with each option's default, when it has one worth showing.

    Like ``argparse.ArgumentDefaultsHelpFormatter``, but an option without a value (None) or a
    switch (False) says nothing: its help says what happens without it.
    """

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        default = action.default
        if (
            "%(default)" in text
            or default is None
            or default is False
            or default is argparse.SUPPRESS
            or not action.option_strings
        ):
            return text
        return f"{text} (default: %(default)s)"


class OneLineParser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line on stderr, exit code 2, naming the flag.

    Argument errors read ``--flag: problem``, the form of the errors commands raise about
    their arguments once running (:class:`~sensing_antenna.cli.arguments.ArgumentError`).
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", HelpFormatter)
        self.option_names: list[str] = []
        self.commands: dict[str, OneLineParser] = {}
        # What an argument beyond the positional ones most likely meant (a second file to a
        # command that reads one), said after "unrecognized arguments"; "" for nothing
        self.extra_positional_hint = ""
        super().__init__(*args, **kwargs)

    def add_subparsers(self, **kwargs: Any) -> Any:
        """``ArgumentParser.add_subparsers``, remembering the commands for :meth:`leaf`."""
        action = super().add_subparsers(**kwargs)
        self.commands = action.choices
        return action

    def leaf(self, argv: Sequence[str]) -> OneLineParser:
        """The (sub)command parser that ``argv`` reaches, following its command names."""
        parser = self
        for token in argv:
            child = parser.commands.get(token)
            if isinstance(child, OneLineParser):
                parser = child
        return parser

    def add_argument(self, *args: Any, **kwargs: Any) -> argparse.Action:
        """``ArgumentParser.add_argument``, remembering the option's names for suggestions."""
        action = super().add_argument(*args, **kwargs)
        self.option_names.extend(action.option_strings)
        return action

    def error(self, message: str) -> NoReturn:
        message = message.removeprefix("argument ")
        if message.endswith(": expected one argument"):
            # no value, or one that begins with '-' (a sign, a flipped axis): read as an option
            flag = message.split(":", 1)[0].split("/")[-1]
            message += (
                f" (none followed it, or it began with '-', which reads as an option: write "
                f"{flag}=VALUE)"
            )
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")

    def reject_unknown(self, extras: Sequence[str]) -> NoReturn:
        """Error on arguments the command does not take, suggesting a close option name."""
        message = f"unrecognized arguments: {' '.join(extras)}"
        if self.extra_positional_hint and not any(extra.startswith("-") for extra in extras):
            message += f" ({self.extra_positional_hint})"
        for extra in extras:
            if extra.startswith("--"):
                close = difflib.get_close_matches(extra.split("=", 1)[0], self.option_names, n=1)
                if close:
                    message += f" (did you mean {close[0]}?)"
                    break
        self.error(message)


class _VersionAction(argparse.Action):
    """``--version``: the installed package's version, looked up only when asked."""

    def __init__(self, option_strings: Sequence[str], dest: str, **kwargs: Any) -> None:
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser: argparse.ArgumentParser, *args: Any, **kwargs: Any) -> None:
        from importlib import metadata

        try:
            version = metadata.version(DISTRIBUTION)
        except metadata.PackageNotFoundError:
            version = f"unknown ({DISTRIBUTION} is not installed)"
        print(f"{parser.prog} {version}")
        parser.exit(0)


def build_parser() -> OneLineParser:
    """The full ``antenna`` parser with every available command registered."""
    parser = OneLineParser(
        prog="antenna",
        description=(
            "Sensing-antenna toolkit: the beam model of a flexible link touching an object, a "
            "simulated 2-DOF head with a force/torque sensor, the contact-point estimators, "
            "calibration of an antenna, and experiment campaigns. Each command has its own "
            "help: antenna COMMAND --help."
        ),
    )
    parser.add_argument(
        "--version", action=_VersionAction, help="print the package's version and exit"
    )
    subparsers = parser.add_subparsers(
        dest="command", metavar="COMMAND", parser_class=OneLineParser
    )
    for name in COMMAND_MODULES:
        importlib.import_module(f"sensing_antenna.cli.{name}").register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``antenna`` console script; returns the exit code.

    On Ctrl-C it says so in one line and lets the ``KeyboardInterrupt`` go on, without its
    traceback (see the module's docstring).
    """
    parser = build_parser()
    prog = parser.prog
    args = argparse.Namespace()
    try:
        with _terminate_raises():
            args, extras = parser.parse_known_args(argv)
            if not hasattr(args, "func"):
                if extras:
                    parser.reject_unknown(extras)
                parser.print_help()
                return EXIT_BAD_INPUT
            leaf = parser.leaf(sys.argv[1:] if argv is None else argv)
            if extras:
                leaf.reject_unknown(extras)
            prog = leaf.prog  # "antenna import rosbag", as argparse's own errors name it
            forget_signals()
            try:
                code = int(args.func(args))
                # a stop the command's code dropped on its way up still stops it here
                raise_if_signalled()
            except SensingAntennaError as exc:
                _say(f"{prog}: error: {_named_by_flag(exc, getattr(args, 'flags', {}))}")
                return EXIT_BAD_INPUT
            except (SystemError, RuntimeError) as exc:
                # a compiled function (numba's) turns an interruption inside it into the first,
                # a class being made as a module is imported (its fields' __set_name__) into
                # the second
                interrupt = interruption_of(exc)
                if interrupt is None:
                    raise
                raise interrupt from None
            sys.stdout.flush()  # a closed pipe shows here rather than at the interpreter's exit
            return code
    except KeyboardInterrupt as exc:
        number = int(getattr(exc, "signal_number", signal.SIGINT))
        how = getattr(exc, "message", None) or (
            "interrupted"
            if number == signal.SIGINT
            else f"stopped by {signal.Signals(number).name}"
        )
        _say(f"{prog}: {how}")
        if number != signal.SIGINT:
            return 128 + number
        # the interpreter ends by SIGINT only for a plain KeyboardInterrupt, not a subclass
        interrupt = exc if type(exc) is KeyboardInterrupt else KeyboardInterrupt()
        _without_traceback(interrupt)
        raise interrupt from None
    except BrokenPipeError:
        if not _stdout_closed():
            _say(f"{prog}: error: broken pipe")
            return EXIT_BAD_INPUT
        _discard_stdout()
        return EXIT_CLOSED_PIPE
    except OSError as exc:  # unwritable output, missing directory, disk full, ...
        where = f"{exc.filename}: " if exc.filename else ""
        why = exc.strerror or str(exc)
        if isinstance(exc, FileExistsError | NotADirectoryError) and exc.filename is not None:
            # mkdir met a file: the output directory named, or one on its path, is a file
            why = f"{why} (a file where a directory is to be made?)"
        _say(f"{prog}: error: {where}{why}")
        return EXIT_BAD_INPUT
    except MemoryError as exc:
        _say(f"{prog}: error: not enough memory" + (f" ({exc})" if str(exc) else ""))
        return EXIT_BAD_INPUT


def _named_by_flag(exc: SensingAntennaError, flags: Mapping[str, str]) -> str:
    """The message of ``exc``, under the flag that gave the field when the command says so."""
    field = getattr(exc, "field_name", None)
    if not isinstance(field, str) or field not in flags or getattr(exc, "source", None):
        return str(exc)
    problem = getattr(exc, "problem", None) or str(exc).split(": ", 1)[-1]
    return f"{flags[field]}: {problem}"


def _without_traceback(interrupt: BaseException) -> None:
    """Let ``interrupt`` end the interpreter without printing its traceback (already said)."""
    previous = sys.excepthook

    def hook(kind: type[BaseException], value: BaseException, traceback: Any) -> None:
        if value is not interrupt:
            previous(kind, value, traceback)

    sys.excepthook = hook


def _say(line: str) -> None:
    """One line on stderr, after whatever the command wrote there (a progress bar)."""
    with contextlib.suppress(OSError, ValueError):
        sys.stderr.flush()
    print(line, file=sys.stderr)


#: Delay (s) after which an interruption Python dropped in a finalizer is raised again: long
#: enough for the finalizer to have returned (the dropped exception ended it), short against
#: any command.
REDELIVERY = 0.01


@contextlib.contextmanager
def _terminate_raises() -> Iterator[None]:
    """Within: SIGTERM raises :class:`Terminated` in this process (the main thread), and an
    interruption Python drops in a finalizer is delivered again.

    Left alone when SIGTERM is already handled or ignored (by whoever started us), or when not
    in the main thread. A process forked inside (a worker of a pool) inherits the handler; there
    SIGTERM keeps its default meaning: the process ends at once.
    """
    owner = os.getpid()

    def handler(number: int, frame: FrameType | None) -> None:
        if os.getpid() != owner:
            signal.signal(number, signal.SIG_DFL)
            os.kill(os.getpid(), number)
            return
        note_signal(number)
        raise Terminated(number)

    def redeliver(number: int, frame: FrameType | None) -> None:
        raise_if_signalled()

    def unraisable(event: Any) -> None:
        # an interruption raised inside a finalizer (a __del__, a weakref callback, the garbage
        # collector) is dropped by Python, which prints it and goes on: recorded as a stop
        # signal, it is raised again a moment later (REDELIVERY s), back where the command can
        # unwind, without the dropped traceback
        if (
            isinstance(event.exc_value, KeyboardInterrupt)
            and os.getpid() == owner
            and alarm is not None
        ):
            note_signal(int(getattr(event.exc_value, "signal_number", signal.SIGINT)))
            signal.signal(signal.SIGALRM, redeliver)
            signal.setitimer(signal.ITIMER_REAL, REDELIVERY)
            return
        dropped_hook(event)

    try:
        if signal.getsignal(signal.SIGTERM) != signal.SIG_DFL:
            yield
            return
        previous = signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread: signals are not ours to handle
        yield
        return
    dropped_hook = sys.unraisablehook
    sys.unraisablehook = unraisable
    # the alarm's handler before ours; None where there are no timers (not POSIX)
    alarm = signal.getsignal(signal.SIGALRM) if hasattr(signal, "setitimer") else None
    try:
        yield
    finally:
        sys.unraisablehook = dropped_hook
        if alarm is not None and signal.getsignal(signal.SIGALRM) is redeliver:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            signal.signal(signal.SIGALRM, alarm)
        signal.signal(signal.SIGTERM, previous)


def _stdout_closed() -> bool:
    """True when the reader of stdout has gone (or stdout is no file whose state is known)."""
    try:
        import select

        poller = select.poll()
        poller.register(sys.stdout.fileno(), select.POLLOUT)
        return any(events & select.POLLERR for _, events in poller.poll(0))
    except (AttributeError, OSError, ValueError):  # no poll (Windows), or not a real file
        return True


def _discard_stdout() -> None:
    """Send the rest of stdout to the null device, so the interpreter's exit says nothing."""
    with contextlib.suppress(AttributeError, OSError, ValueError):
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, sys.stdout.fileno())
        os.close(null)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
