"""A campaign's local worker processes: a dead worker costs one run, none outlives the campaign.

Each worker process takes one run at a time over its own pipe, so the pool always knows which
run each worker holds. A worker that dies (the out-of-memory killer, a crash in compiled code,
``kill -9``) loses only that run: it goes back to the front of the queue and a fresh worker takes
it, up to :data:`MAX_ATTEMPTS` times in all; after that it is recorded as failed, with the cause.
No other run is touched, and a run is never recorded as failed without having been tried.

Workers ignore SIGINT: Ctrl-C in a terminal reaches the whole process group, and the main
process decides (it stops the workers and keeps every finished run). A worker exits on its own
as soon as the process that started it is gone (a watchdog thread polls the parent's pid), so a
campaign killed with SIGKILL leaves no worker behind; one busy in a run exits when it next holds
the interpreter, at the latest when the run's current compiled call returns.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections import Counter, deque
from collections.abc import Callable, Generator, Iterable
from dataclasses import dataclass
from multiprocessing import get_context
from multiprocessing.connection import Connection, wait
from multiprocessing.process import BaseProcess

from sensing_antenna.campaign.records import RunResult
from sensing_antenna.campaign.runs import RunSpec
from sensing_antenna.errors import SensingAntennaError

__all__ = ["MAX_ATTEMPTS", "WorkerPoolError", "run_on_workers"]

#: Attempts of one run whose worker process dies each time, before it is recorded as failed: a
#: worker killed once (by the out-of-memory killer for a neighbour's sake, by hand) is retried;
#: a run that kills its worker every time would otherwise be retried for ever.
MAX_ATTEMPTS = 3

#: How often an idle or busy worker checks that its parent is alive (s).
_PARENT_POLL_S = 0.5
#: How long a stopped worker is given to exit before it is killed (s).
_STOP_TIMEOUT_S = 5.0
#: Longest wait for a result before the pool looks at its workers again (s).
_WAIT_S = 1.0


class WorkerPoolError(SensingAntennaError, RuntimeError):
    """The worker processes cannot run at all (each one dies before taking a run)."""


@dataclass
class _Worker:
    """One worker process, the main process's end of its pipe and the run it holds."""

    process: BaseProcess
    conn: Connection
    run: RunSpec | None = None


def run_on_workers(
    task: Callable[[RunSpec], RunResult],
    runs: Iterable[RunSpec],
    workers: int,
    *,
    initializer: Callable[[], None] | None = None,
    max_attempts: int = MAX_ATTEMPTS,
    on_event: Callable[[str], None] | None = None,
) -> Generator[RunResult, None, None]:
    """Run ``task`` on every run in ``workers`` local processes; yield each result when it comes.

    Parameters
    ----------
    task : callable
        Picklable (module level) ``RunSpec -> RunResult``; it must not raise (the runner's
        ``execute_safely`` turns exceptions into failed results).
    runs : iterable of RunSpec
    workers : int
        Processes at most (fewer when there are fewer runs); >= 1.
    initializer : callable, optional
        Called once in each worker before its first run.
    max_attempts : int
        Tries of a run whose worker dies while running it; then a failed result.
    on_event : callable, optional
        Told, in one line, when a worker dies and what happens to its run.

    Yields
    ------
    RunResult
        In the order they finish. Closing the generator (or an exception while it waits, such as
        KeyboardInterrupt) stops every worker: runs in progress are abandoned, not recorded.

    Raises
    ------
    WorkerPoolError
        When ``max_attempts`` fresh workers in a row die before taking a run.
    """
    if workers < 1 or max_attempts < 1:
        raise ValueError(f"workers and max_attempts must be >= 1, got {workers}, {max_attempts}")
    context = get_context()
    queue = deque(runs)
    deaths: Counter[str] = Counter()
    pool: list[_Worker] = []
    stillborn = 0
    tell = on_event or (lambda _message: None)

    def start() -> _Worker:
        mine, theirs = context.Pipe(duplex=True)
        process = context.Process(
            target=_serve,
            args=(theirs, task, initializer, os.getpid()),
            name="campaign-worker",
            daemon=True,
        )
        process.start()
        theirs.close()
        return _Worker(process, mine)

    try:
        while queue or any(w.run is not None for w in pool):
            idle = [w for w in pool if w.run is None]
            while queue and len(pool) < workers:
                worker = start()
                pool.append(worker)
                idle.append(worker)
            for worker in idle:
                if not queue:
                    break
                run = queue.popleft()
                try:
                    worker.conn.send(run)
                except OSError:  # died before it could take the run: the run was never started
                    queue.appendleft(run)
                    _discard(worker, pool)
                    stillborn += 1
                    if stillborn >= max_attempts:
                        raise WorkerPoolError(
                            f"{stillborn} worker processes in a row died before taking a run "
                            f"({_exit_cause(worker.process)})"
                        ) from None
                    continue
                worker.run = run
            busy = [w for w in pool if w.run is not None]
            ready = set(wait([w.conn for w in busy] + [w.process.sentinel for w in busy], _WAIT_S))
            for worker in busy:
                if worker.conn not in ready and worker.process.sentinel not in ready:
                    continue
                held = worker.run
                assert held is not None
                result = _receive(worker.conn, held)
                if result is not None:
                    worker.run = None
                    stillborn = 0
                    yield result
                    continue
                _discard(worker, pool)
                deaths[held.run_id] += 1
                cause = _exit_cause(worker.process)
                attempt = deaths[held.run_id]
                if attempt < max_attempts:
                    queue.appendleft(held)
                    tell(
                        f"worker process {worker.process.pid} died ({cause}) running "
                        f"{held.run_id}; trying it again (attempt {attempt + 1} of {max_attempts})"
                    )
                    continue
                tell(f"worker process {worker.process.pid} died ({cause}) running {held.run_id}")
                yield RunResult.failed(
                    held,
                    f"WorkerDied: the worker process running it died on each of {attempt} "
                    f"attempts (last: {cause}; a kill by the out-of-memory killer is SIGKILL)",
                )
    finally:
        _stop(pool)


def _receive(conn: Connection, run: RunSpec) -> RunResult | None:
    """The worker's result for ``run``; None when it died without sending one."""
    if not conn.poll():
        return None
    try:
        result: RunResult = conn.recv()
    except (EOFError, OSError):
        return None
    except Exception as exc:  # a result that cannot be unpickled here is that run's failure
        return RunResult.failed(run, f"its result could not be read: {type(exc).__name__}: {exc}")
    return result


def _exit_cause(process: BaseProcess) -> str:
    """How a worker process ended, in words."""
    process.join(_STOP_TIMEOUT_S)
    code = process.exitcode
    if code is None:
        return "still running"
    if code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        return f"killed by {name}"
    return f"exit code {code}"


def _discard(worker: _Worker, pool: list[_Worker]) -> None:
    """Forget a dead worker: close its pipe and reap its process."""
    pool.remove(worker)
    worker.conn.close()
    worker.process.join(_STOP_TIMEOUT_S)


def _stop(pool: list[_Worker]) -> None:
    """Stop every worker: idle ones are asked to exit, busy ones terminated; killed if they stay."""
    for worker in pool:
        try:
            if worker.run is None:
                worker.conn.send(None)
            else:
                worker.process.terminate()
        except (OSError, ValueError):  # already gone
            pass
    deadline = time.monotonic() + _STOP_TIMEOUT_S
    for worker in pool:
        worker.process.join(max(0.0, deadline - time.monotonic()))
        if worker.process.is_alive():
            worker.process.kill()
            worker.process.join()
        worker.conn.close()
    pool.clear()


def _serve(
    conn: Connection,
    task: Callable[[RunSpec], RunResult],
    initializer: Callable[[], None] | None,
    campaign_pid: int,
) -> None:
    """A worker's life: take runs from ``conn`` until told to stop (None) or the pipe closes."""
    # Ctrl-C reaches the whole process group; the main process stops the workers itself. A
    # worker forked from the main process inherits its SIGTERM handler, which is the main
    # process's business: here SIGTERM ends the process at once.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _exit_with_parent(campaign_pid)
    if initializer is not None:
        initializer()
    while True:
        try:
            run = conn.recv()
        except (EOFError, OSError):
            return
        if run is None:
            return
        result = task(run)
        try:
            conn.send(result)
        except OSError:  # the main process is gone
            return
        except Exception as exc:  # the result cannot be pickled: that run's failure
            conn.send(RunResult.failed(run, f"its result could not be sent: {exc}"))


def _exit_with_parent(campaign_pid: int) -> None:
    """Start a daemon thread that ends this process when its parent or the campaign is gone."""
    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent and _alive(campaign_pid):
            time.sleep(_PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True
