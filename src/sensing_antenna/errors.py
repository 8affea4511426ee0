"""Exception types shared by the whole package, and how messages show values.

Every error a user can cause (bad file, bad field, bad argument) derives from
:class:`SensingAntennaError`, so the command line can print it as one line without a traceback.
:class:`Terminated` is how a command stops when the operating system asks it to (SIGTERM): it
unwinds like Ctrl-C's ``KeyboardInterrupt``, so the same clean-up code handles both.
"""

from __future__ import annotations

import signal
from collections.abc import Iterable
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # numpy is not loaded for the command line's parsing
    import numpy as np
    from numpy.typing import NDArray

#: Stop signals received, in order (signal numbers): a handler records one before it raises, so
#: that a stop whose exception was swallowed on its way up is still seen
#: (:func:`raise_if_signalled`).
_RECEIVED: list[int] = []


def note_signal(number: int) -> None:
    """Record that the stop signal ``number`` arrived (called by signal handlers)."""
    _RECEIVED.append(number)


def forget_signals() -> None:
    """Forget the stop signals recorded so far (a new piece of work starts)."""
    _RECEIVED.clear()


def raise_if_signalled() -> None:
    """Raise the interruption of a stop signal that arrived but was lost on the way.

    A signal handler's exception is raised wherever the main thread happens to be, and a few
    places drop it: compiled code calling back into Python (numba unpickling a constant) ends
    the callback's error and goes on. Loops that must stop check here between steps.
    """
    if _RECEIVED:
        number = _RECEIVED.pop()
        _RECEIVED.clear()
        if number == signal.SIGINT:
            raise KeyboardInterrupt
        raise Terminated(number)


def interruption_of(exc: BaseException) -> KeyboardInterrupt | None:
    """The interruption (Ctrl-C, or a stop signal's :class:`Terminated`) ``exc`` is or was
    raised from or while handling, or None. A compiled function (numba's) interrupted inside
    raises a ``SystemError`` from the ``KeyboardInterrupt``: callers that catch errors by kind
    ask here before they take it for a failure."""
    seen: set[int] = set()
    cause: BaseException | None = exc
    while cause is not None and id(cause) not in seen:
        if isinstance(cause, KeyboardInterrupt):
            return cause
        seen.add(id(cause))
        cause = cause.__cause__ or cause.__context__
    return None


class SensingAntennaError(Exception):
    """Base class for errors caused by input: files, fields, arguments."""


class FieldError(SensingAntennaError, ValueError):
    """A named field of a configuration file is missing, unknown or invalid.

    The message reads ``<source>: <field>: <problem>``; the parts stay available as attributes.
    A field name that is not all printable (a TOML key with a line break or a control character
    in it) is shown quoted with its escapes, so the message stays one line that shows the key.
    """

    def __init__(self, field_name: str, problem: str, source: str | None = None) -> None:
        self.field_name = field_name
        self.problem = problem
        self.source = source
        where = f"{source}: " if source else ""
        shown = field_name if field_name.isprintable() else repr(field_name)
        super().__init__(f"{where}{shown}: {problem}")


class Terminated(KeyboardInterrupt):
    """The process was asked to stop by a signal other than Ctrl-C (SIGTERM).

    The command line raises it in the main thread when the signal arrives. It derives from
    ``KeyboardInterrupt``, so ``finally`` blocks and ``except KeyboardInterrupt`` clean-ups run
    for it as for Ctrl-C; the command then exits with 128 + ``signal_number`` (143 for SIGTERM).
    """

    def __init__(self, signal_number: int) -> None:
        self.signal_number = signal_number
        super().__init__(f"terminated by signal {signal_number}")


def format_value(value: object) -> str:
    """A value as an error message shows it: as Python writes it, whatever array library made it.

    A NumPy scalar or 0-d array is shown as the Python number it holds (``nan``, ``-0.3``, ``2``,
    ``True``), never as ``np.float64(nan)``; anything else by ``repr`` (strings quoted, so an
    empty or blank value is visible). NumPy is not imported.
    """
    item = getattr(value, "item", None)
    if type(value).__module__ == "numpy" and callable(item) and getattr(value, "ndim", 1) == 0:
        value = item()
    return repr(value)


def refuse_non_finite(named: Iterable[tuple[str, NDArray[np.float64]]], output: str) -> None:
    """Raise a ValueError naming the first input of a streaming object (a name and its samples,
    rows of shape (n, k)) with a NaN or infinite value, and its row, before any state moves:
    the ``output`` was not computed."""
    import numpy as np

    for name, values in named:
        bad = np.flatnonzero(~np.all(np.isfinite(values), axis=1))
        if bad.size:
            where = f" at row {bad[0]}" if values.shape[0] > 1 else ""
            raise ValueError(
                f"{name}: {values[bad[0]].tolist()}{where} is not finite (a glitch of the "
                f"encoders or the sensor?): the {output} was not computed, the state is "
                "unchanged"
            )
