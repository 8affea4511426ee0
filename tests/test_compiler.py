"""A stop signal that arrives while numba compiles a kernel stops the compilation cleanly."""

from __future__ import annotations

import os
import signal
import sys
from typing import Any

import pytest
from numba.core import event

from sensing_antenna.compiler import njit

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")


class _SignalsOnce(event.Listener):
    """Sends each of ``numbers`` to this process at the first start of the events it hears."""

    def __init__(self, *numbers: int) -> None:
        self.numbers = numbers
        self.sent = False

    def on_start(self, ev: Any) -> None:
        if not self.sent:
            self.sent = True
            for number in self.numbers:
                os.kill(os.getpid(), number)

    def on_end(self, ev: Any) -> None:
        pass


class _Stopped(Exception):
    pass


def _raise_stopped(number: int, frame: Any) -> None:
    raise _Stopped(number)


class _InsideLLVM(event.Listener):
    """How deep numba is in calls to LLVM (its LLVM lock held), where LLVM calls back into
    Python and an exception raised there is dropped."""

    def __init__(self) -> None:
        self.depth = 0

    def on_start(self, ev: Any) -> None:
        self.depth += 1

    def on_end(self, ev: Any) -> None:
        self.depth -= 1


@pytest.mark.parametrize(
    ("number", "handler", "raised"),
    [
        (signal.SIGINT, signal.default_int_handler, KeyboardInterrupt),
        (signal.SIGTERM, _raise_stopped, _Stopped),
    ],
)
def test_a_stop_during_a_compilation_is_handled_outside_llvm_and_numba_stays_whole(
    number: int, handler: Any, raised: type[BaseException]
) -> None:
    @njit
    def twice(x: float) -> float:
        return 2.0 * x

    inside = _InsideLLVM()
    depths: list[int] = []

    def handle(signal_number: int, frame: Any) -> None:
        depths.append(inside.depth)
        handler(signal_number, frame)

    # the handler a terminal's Ctrl-C or the command line's SIGTERM finds (the suite itself
    # may run with SIGINT ignored); the signal arrives as numba enters LLVM
    previous = signal.signal(number, handle)
    try:
        with (
            event.install_listener("numba:llvm_lock", inside),
            event.install_listener("numba:llvm_lock", _SignalsOnce(number)),
            pytest.raises(raised),
        ):
            twice(1.5)
        assert signal.getsignal(number) is handle
    finally:
        signal.signal(number, previous)
    assert depths == [0]
    # numba was left whole: the kernel compiles on the next call and runs
    assert twice(1.5) == 3.0


def test_an_ignored_signal_during_a_compilation_stays_ignored() -> None:
    @njit
    def half(x: float) -> float:
        return 0.5 * x

    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with event.install_listener("numba:compile", _SignalsOnce(signal.SIGINT)):
            assert half(1.0) == 0.5
    finally:
        signal.signal(signal.SIGINT, previous)


def test_two_stops_in_one_compilation_each_reach_their_handler_once() -> None:
    @njit
    def third(x: float) -> float:
        return x / 3.0

    @njit
    def quarter(x: float) -> float:
        return x / 4.0

    stopped: list[int] = []

    def note(number: int, frame: Any) -> None:
        stopped.append(number)

    previous = (
        signal.signal(signal.SIGTERM, note),
        signal.signal(signal.SIGINT, signal.default_int_handler),
    )
    try:
        with (
            event.install_listener("numba:llvm_lock", _SignalsOnce(signal.SIGTERM, signal.SIGINT)),
            pytest.raises(KeyboardInterrupt),
        ):
            third(3.0)
        assert stopped == [signal.SIGTERM]
        assert signal.getsignal(signal.SIGTERM) is note
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
        # nothing is left over for the next compilation
        assert quarter(4.0) == 1.0
        assert stopped == [signal.SIGTERM]
    finally:
        signal.signal(signal.SIGTERM, previous[0])
        signal.signal(signal.SIGINT, previous[1])
