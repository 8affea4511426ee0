"""numba's ``njit`` for the package's compiled kernels, with stop signals held while numba compiles.

A kernel is compiled (or loaded from numba's on-disk cache) the first time it is called with
new argument types, which on a fresh machine takes seconds. A Ctrl-C or SIGTERM whose Python
handler raises inside that compilation can land in a callback LLVM makes into Python, where
the exception is dropped half-way: numba is left with a function it believes compiled and has
no code for, and the process ends with a ``RuntimeError`` from numba's cache or a
segmentation fault instead of the interruption.

So while the main thread holds numba's compiler lock, the Python handlers of SIGINT and SIGTERM
are replaced by one that only records the signal. The recorded signal's own handler is called
at the next safe point: the start of a compiler pass (Python code between LLVM's calls, where
numba unwinds from any exception as from a compile error), or the end of the outermost
compilation, where the handlers are put back. A stop during a compilation thus takes effect
within one pass. Handlers that are not Python functions (the default action, ignored) are left
alone: they cannot raise inside the compiler.
"""

from __future__ import annotations

import signal
import threading
from types import FrameType
from typing import Any

from numba import njit
from numba.core import event

__all__ = ["njit"]

#: The signals whose handlers are held while numba compiles.
HELD_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class _StopsWaitForTheCompiler(event.Listener):
    """Listener of numba's compiler lock and passes: holds stop signals in the main thread while
    the lock is held, and runs the handler of the first that arrived at the next pass or once
    the lock is released."""

    def __init__(self) -> None:
        self._depth = 0
        self._handlers: dict[int, Any] = {}
        self._arrived: list[int] = []

    def _record(self, number: int, frame: FrameType | None) -> None:
        self._arrived.append(number)

    def _handle_arrived(self, handlers: dict[int, Any]) -> None:
        arrived, self._arrived = self._arrived, []
        if arrived:
            handlers[arrived[0]](arrived[0], None)

    def on_start(self, ev: Any) -> None:
        if threading.current_thread() is not threading.main_thread():
            return
        if ev.kind == PASS:
            if self._depth > 0:
                self._handle_arrived(self._handlers)
            return
        self._depth += 1
        if self._depth > 1:
            return
        for number in HELD_SIGNALS:
            handler = signal.getsignal(number)
            if callable(handler):
                self._handlers[number] = handler
                signal.signal(number, self._record)

    def on_end(self, ev: Any) -> None:
        if ev.kind == PASS or threading.current_thread() is not threading.main_thread():
            return
        if self._depth == 0:
            return
        self._depth -= 1
        if self._depth > 0:
            return
        handlers, self._handlers = self._handlers, {}
        for number, handler in handlers.items():
            signal.signal(number, handler)
        self._handle_arrived(handlers)


#: numba's events: its compiler lock held, and one compiler pass running.
LOCK, PASS = "numba:compiler_lock", "numba:run_pass"

_listener = _StopsWaitForTheCompiler()
event.register(LOCK, _listener)
event.register(PASS, _listener)
