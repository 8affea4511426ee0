"""numba's ``njit`` for the package's compiled kernels, with stop signals held while numba compiles.

A kernel is compiled (or loaded from numba's on-disk cache) the first time it is called with
new argument types, which on a fresh machine takes seconds. A Ctrl-C or SIGTERM whose Python
handler raises inside that compilation can land in a callback LLVM makes into Python, where
the exception is dropped half-way: numba is left with a function it believes compiled and has
no code for, and the process ends with a ``RuntimeError`` from numba's cache or a
segmentation fault instead of the interruption.

So while the main thread asks for or holds numba's compiler lock, the Python handlers of the
stop signals (:data:`HELD_SIGNALS`) are replaced by one that only records the signal. The
recorded signals' own handlers are called at the next safe point: the start of a compiler pass
(Python code between LLVM's calls, where numba unwinds from a ``BaseException`` as from a
compile error), or the release of the outermost lock, where the handlers are put back. A stop
during a compilation thus takes effect within one pass. Handlers that are not Python functions
(the default action, ignored) are left alone: they cannot raise inside the compiler. The
handlers are swapped with the held signals blocked, so none is handled half-way through.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType
from typing import Any

from numba import njit
from numba.core import event
from numba.core.compiler_lock import global_compiler_lock

__all__ = ["njit"]

#: The signals whose Python handlers are held while numba compiles: Ctrl-C, SIGTERM, a closed
#: terminal's SIGHUP (a campaign stops on it) and the alarm by which the command line raises an
#: interruption Python dropped (where the platform has them).
HELD_SIGNALS = tuple(
    getattr(signal, name)
    for name in ("SIGINT", "SIGTERM", "SIGHUP", "SIGALRM")
    if hasattr(signal, name)
)

#: numba's events: its compiler lock asked for (start) and released (end), and one compiler
#: pass starting.
LOCK, PASS = "numba:compiler_lock", "numba:run_pass"


@contextlib.contextmanager
def _signals_blocked() -> Iterator[None]:
    """Within: the held signals wait in the kernel (where the platform can block them)."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, HELD_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


class _StopsWaitForTheCompiler(event.Listener):
    """Listener of numba's compiler lock and passes: holds stop signals in the main thread while
    it asks for or holds the lock, and runs the handlers of those that arrived at the next
    pass or once the outermost lock is released."""

    def __init__(self) -> None:
        self._handlers: dict[int, Any] = {}
        self._arrived: list[int] = []

    def _record(self, number: int, frame: FrameType | None) -> None:
        self._arrived.append(number)

    def _handle_arrived(self, handlers: dict[int, Any]) -> None:
        """Run the handler of each signal recorded, in order, once (the first that raises
        ends it)."""
        arrived, self._arrived = self._arrived, []
        for number in dict.fromkeys(arrived):
            handler = handlers.get(number)
            if handler is not None:
                handler(number, None)

    def on_start(self, ev: Any) -> None:
        if threading.current_thread() is not threading.main_thread():
            return
        if ev.kind == PASS:
            self._handle_arrived(self._handlers)
            return
        if self._handlers or global_compiler_lock.is_locked():
            return  # a nested compilation: already held
        self._arrived = []
        with _signals_blocked():
            for number in HELD_SIGNALS:
                handler = signal.getsignal(number)
                if callable(handler) and handler != self._record:
                    self._handlers[number] = handler
                    signal.signal(number, self._record)

    def on_end(self, ev: Any) -> None:
        if ev.kind == PASS or threading.current_thread() is not threading.main_thread():
            return
        if global_compiler_lock.is_locked():
            return  # an inner release: the outermost puts the handlers back
        handlers, self._handlers = self._handlers, {}
        with _signals_blocked():
            for number, handler in handlers.items():
                signal.signal(number, handler)
        self._handle_arrived(handlers)


_LISTENER = _StopsWaitForTheCompiler()
event.register(LOCK, _LISTENER)
event.register(PASS, _LISTENER)
