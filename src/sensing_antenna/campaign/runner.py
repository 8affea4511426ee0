"""Running a campaign: every pending run, in parallel, resumable, with failures recorded.

The runner is independent of what a run does: it takes a pure function ``run_one(RunSpec) ->
RunResult`` (by default :func:`sensing_antenna.campaign.simulated.simulate_and_estimate`). Runs
execute inline (one worker), on local worker processes (default: all cores;
:mod:`~sensing_antenna.campaign.pool`) or on a Dask cluster (``scheduler="tcp://host:port"``).
Each finished run is stored at once (see :mod:`~sensing_antenna.campaign.store`), so a campaign
started again skips what is done. A run whose function raises is stored as failed with its
error, and the others continue; a run whose worker process dies is tried again on a fresh one.

Ctrl-C (SIGINT), SIGTERM and SIGHUP stop the campaign cleanly: the workers are stopped, every
finished run stays stored, and :class:`CampaignInterrupted` says how many.
"""

from __future__ import annotations

import contextlib
import functools
import os
import signal
import threading
import traceback
from collections.abc import Callable, Generator, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import FrameType

from sensing_antenna.antenna import Antenna
from sensing_antenna.campaign.pool import run_on_workers
from sensing_antenna.campaign.progress import Progress
from sensing_antenna.campaign.records import RUN_FAILED, RunResult
from sensing_antenna.campaign.runs import RunSpec, expand_runs
from sensing_antenna.campaign.schema import CampaignSpec
from sensing_antenna.campaign.store import (
    CSV_FILE,
    SECOND_DEVICE_DIR,
    Preparation,
    campaign_lock,
    load_campaign_results,
    read_preparation,
    remove_stale_temp_files,
    write_manifest,
    write_preparation,
    write_run_result,
    write_runs_csv,
)
from sensing_antenna.campaign.worker_threads import limit_to_one_blas_thread
from sensing_antenna.errors import (
    SensingAntennaError,
    forget_signals,
    interruption_of,
    note_signal,
    raise_if_signalled,
)

__all__ = [
    "CampaignInterrupted",
    "CampaignOutcome",
    "PrepareAntenna",
    "RunFunction",
    "execute_safely",
    "run_campaign",
]

#: A run function: pure, picklable (module level), one run in, its result out.
RunFunction = Callable[[RunSpec], RunResult]
#: The steps before the runs: from the spec, the model and device antennas and the calibration
#: (:class:`~sensing_antenna.campaign.store.Preparation`); an Antenna means device = model.
PrepareAntenna = Callable[[CampaignSpec], Antenna | Preparation]


@dataclass(frozen=True)
class CampaignOutcome:
    """Summary of one call of :func:`run_campaign`.

    Attributes
    ----------
    out_dir : Path
        Campaign directory.
    csv_path : Path
        The run x method table rebuilt from every stored run.
    n_runs : int
        Runs in the campaign.
    n_previously_done : int
        Runs found finished when this call started (not redone).
    n_executed : int
        Runs executed by this call.
    n_failed : int
        Stored runs whose status is failed (all of them, not only this call's).
    foreign_run_files : tuple of str
        Ids of valid run files in ``out_dir/runs`` that are not runs of the spec: left out of
        ``runs.csv`` and the report.
    """

    out_dir: Path
    csv_path: Path
    n_runs: int
    n_previously_done: int
    n_executed: int
    n_failed: int
    foreign_run_files: tuple[str, ...] = ()


class CampaignInterrupted(KeyboardInterrupt):
    """A campaign stopped by a signal; every run finished before it is stored.

    A KeyboardInterrupt, so that code which stops on Ctrl-C stops on it too.

    Attributes
    ----------
    signal_number : int
        SIGINT (Ctrl-C), SIGTERM or SIGHUP.
    out_dir : Path or None
        The campaign directory, once known.
    n_stored : int
        Runs stored in ``out_dir`` (finished, including those of earlier starts).
    n_runs : int
        Runs in the campaign (0 when it stopped before they were counted).
    """

    def __init__(
        self,
        signal_number: int,
        out_dir: Path | None = None,
        n_stored: int = 0,
        n_runs: int = 0,
    ) -> None:
        self.signal_number = signal_number
        self.out_dir = out_dir
        self.n_stored = n_stored
        self.n_runs = n_runs
        super().__init__(self.message)

    @property
    def signal_name(self) -> str:
        """The signal's name, e.g. ``SIGINT``."""
        try:
            return signal.Signals(self.signal_number).name
        except ValueError:
            return f"signal {self.signal_number}"

    @property
    def message(self) -> str:
        """One line: what stopped the campaign and what is kept."""
        if self.out_dir is None:
            return f"interrupted by {self.signal_name} before any run"
        return (
            f"interrupted by {self.signal_name}: {self.n_stored} of {self.n_runs} runs are stored "
            f"in {self.out_dir}; the same command again runs the others"
        )


#: Signals that stop a campaign cleanly besides SIGINT: a supervisor's or batch scheduler's
#: SIGTERM, a closed terminal's SIGHUP.
_STOP_SIGNALS = tuple(
    getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name)
)


@contextlib.contextmanager
def _stop_signals_interrupt() -> Iterator[None]:
    """While inside, the stop signals raise CampaignInterrupted (main thread only; a signal the
    process ignores, e.g. SIGHUP under nohup, stays ignored)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def interrupt(signal_number: int, _frame: FrameType | None) -> None:
        note_signal(signal_number)
        raise CampaignInterrupted(signal_number)

    def keyboard(signal_number: int, _frame: FrameType | None) -> None:
        note_signal(signal_number)
        raise KeyboardInterrupt

    forget_signals()
    previous = {}
    for number in _STOP_SIGNALS:
        if signal.getsignal(number) is signal.SIG_DFL:
            previous[number] = signal.signal(number, interrupt)
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        # Ctrl-C as Python's own handler, but recorded: a KeyboardInterrupt lost on its way up
        # (raise_if_signalled) still stops the campaign at the next run
        previous[signal.SIGINT] = signal.signal(signal.SIGINT, keyboard)
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


def execute_safely(run_one: RunFunction, run: RunSpec) -> RunResult:
    """Call ``run_one(run)``; an exception becomes a failed RunResult with its traceback.

    A result for another run, or without one row per method of the run in order, is recorded
    as a failed run too.
    """
    try:
        result = run_one(run)
    except Exception as exc:  # a failing run is recorded and must not stop the others
        interrupt = interruption_of(exc)  # Ctrl-C inside compiled code: no failure of the run
        if interrupt is not None:
            raise interrupt from None
        return RunResult.failed(run, f"{type(exc).__name__}: {exc}", traceback.format_exc())
    if result.run_id != run.run_id:
        return RunResult.failed(
            run, f"run function returned run_id {result.run_id!r} for {run.run_id!r}"
        )
    if result.methods != run.methods:
        return RunResult.failed(
            run, f"run function returned rows of {result.methods} for methods {run.methods}"
        )
    return result


def run_campaign(
    spec: CampaignSpec,
    out_dir: str | Path,
    *,
    run_one: RunFunction | None = None,
    prepare_antenna: PrepareAntenna | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    retry_failed: bool = False,
    progress: bool = True,
) -> CampaignOutcome:
    """Run every pending run of ``spec`` and store the results in ``out_dir``.

    Parameters
    ----------
    spec : CampaignSpec
    out_dir : str or Path
        Campaign directory (created if missing). Started again on the same directory, the
        campaign continues where it stopped; a directory of another spec is refused.
    run_one : callable, optional
        The run function; default simulates and estimates
        (:func:`~sensing_antenna.campaign.simulated.simulate_and_estimate`).
    prepare_antenna : callable, optional
        The steps before the runs, called once when ``out_dir`` holds no complete preparation for
        this spec; returns a :class:`~sensing_antenna.campaign.store.Preparation` (or an Antenna,
        used as both device and model). Default
        :func:`~sensing_antenna.campaign.simulated.prepare_campaign`: loads the model and the
        device, identifies the free-motion observer on the device and calibrates T_e, as the
        spec asks. With a second device it is called again with
        ``spec.second_device_spec()`` (stored in ``out_dir/second_device``).
    workers : int, optional
        Local worker processes; default all cores. 1 runs inline in this process.
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:port``); runs go to that cluster instead.
    retry_failed : bool
        Redo runs stored as failed.
    progress : bool
        Say on stderr what the campaign is doing, from the start: a line for the campaign and
        for each preparation step, bars for the calibration recordings and the runs.

    Returns
    -------
    CampaignOutcome
    """
    if workers is not None and workers < 1:
        raise SensingAntennaError(f"--workers: must be >= 1, got {workers}")
    report = Progress(enabled=progress)
    directory = Path(out_dir)
    prepare: PrepareAntenna
    compile_methods: Callable[[Preparation], None] | None = None
    if run_one is None or prepare_antenna is None:
        from sensing_antenna.campaign import simulated

        # every scenario the simulation will be given, checked before anything is written
        simulated.check_scenario(spec)
        if run_one is None:
            run_one = simulated.simulate_and_estimate
            compile_methods = functools.partial(simulated.compile_methods, spec, progress=report)
        prepare = prepare_antenna or functools.partial(simulated.prepare_campaign, progress=report)
    else:
        prepare = prepare_antenna
    sweep = f", {spec.n_sweep_runs} in the noise sweep" if spec.n_sweep_runs else ""
    if spec.n_second_device_runs:
        sweep += f", {spec.n_second_device_runs} on the second device"
    report.line(
        f"campaign {spec.name}: {spec.n_runs} runs ({spec.n_main_runs} main{sweep}) x "
        f"{len(spec.methods)} method(s) ({', '.join(spec.methods)}), in {directory}"
    )
    n_stored = 0
    try:
        with _stop_signals_interrupt():
            directory.mkdir(parents=True, exist_ok=True)
            with campaign_lock(directory):
                remove_stale_temp_files(directory)
                write_manifest(directory, spec)
                preparation = _prepared(directory, spec, prepare, report)
                second = preparation
                if spec.second_device.enabled:
                    report.line("preparation of the second device:")
                    folder = directory / SECOND_DEVICE_DIR
                    folder.mkdir(exist_ok=True)
                    second = _prepared(folder, spec.second_device_spec(), prepare, report)
                runs = expand_runs(
                    spec,
                    preparation.model,
                    preparation.device,
                    second_model=second.model,
                    second_device=second.device,
                )
                done = load_campaign_results(directory, spec).results
                if retry_failed:
                    done = {k: v for k, v in done.items() if v.status != RUN_FAILED}
                pending = [run for run in runs if run.run_id not in done]
                n_stored = len(runs) - len(pending)
                report.line(
                    f"runs: {n_stored} of {len(runs)} stored already, {len(pending)} to run "
                    + _where(pending, workers, scheduler)
                )
                # worker processes start with the methods compiled (inline, the first run does it)
                if compile_methods is not None and pending and scheduler is None and workers != 1:
                    compile_methods(preparation)
                task = functools.partial(execute_safely, run_one)
                executed = 0
                with (
                    report.bar(len(runs), f"campaign {spec.name}", initial=n_stored) as bar,
                    contextlib.closing(
                        _execute(task, pending, workers, scheduler, report.line)
                    ) as results,
                ):
                    for result in results:
                        write_run_result(directory, result)
                        executed += 1
                        n_stored += 1
                        bar.update(1)
                        raise_if_signalled()
                stored = load_campaign_results(directory, spec)
                csv_path = write_runs_csv(directory / CSV_FILE, stored.results.values())
    except KeyboardInterrupt as exc:
        # Ctrl-C, or a stop signal turned into an interruption here or by the caller (the
        # command line's SIGTERM)
        number = int(getattr(exc, "signal_number", signal.SIGINT))
        where = directory if directory.is_dir() else None
        raise CampaignInterrupted(number, where, n_stored, spec.n_runs) from None
    return CampaignOutcome(
        out_dir=directory,
        csv_path=csv_path,
        n_runs=len(runs),
        n_previously_done=len(runs) - len(pending),
        n_executed=executed,
        n_failed=sum(1 for r in stored.results.values() if r.status == RUN_FAILED),
        foreign_run_files=stored.foreign,
    )


def _prepared(
    directory: Path, spec: CampaignSpec, prepare: PrepareAntenna, report: Progress
) -> Preparation:
    """The preparation stored in ``directory`` for this spec, or made now and stored."""
    preparation = read_preparation(directory, spec)
    if preparation is not None:
        report.line(f"preparation: the one stored in {directory} (model, device, calibration)")
        return preparation
    prepared = prepare(spec)
    preparation = prepared if isinstance(prepared, Preparation) else Preparation.same(prepared)
    write_preparation(directory, spec, preparation)
    return preparation


def _where(pending: Sequence[RunSpec], workers: int | None, scheduler: str | None) -> str:
    """Where the pending runs will execute, in words."""
    if not pending:
        return "(nothing to do)"
    if scheduler is not None:
        return f"on the Dask cluster at {scheduler}"
    n = min(workers or os.cpu_count() or 1, len(pending))
    return "in this process" if n == 1 else f"on {n} worker processes"


def _execute(
    task: Callable[[RunSpec], RunResult],
    pending: Sequence[RunSpec],
    workers: int | None,
    scheduler: str | None,
    note: Callable[[str], None] | None,
) -> Generator[RunResult, None, None]:
    if not pending:
        return
    if scheduler is not None:
        yield from _execute_dask(task, pending, scheduler)
    elif (workers or os.cpu_count() or 1) == 1 or len(pending) == 1:
        for run in pending:
            yield task(run)
    else:
        yield from run_on_workers(
            task,
            pending,
            workers or os.cpu_count() or 1,
            initializer=limit_to_one_blas_thread,
            on_event=note,
        )


def _execute_dask(
    task: Callable[[RunSpec], RunResult], pending: Sequence[RunSpec], scheduler: str
) -> Generator[RunResult, None, None]:
    from distributed import Client, as_completed
    from distributed.scheduler import KilledWorker

    from sensing_antenna.campaign.dask_plugin import OneBlasThreadPerDaskWorker

    try:
        client = Client(scheduler, timeout="10s", set_as_default=False)
    except OSError as exc:
        raise SensingAntennaError(
            f"--scheduler: cannot reach Dask scheduler {scheduler!r} ({exc})"
        ) from exc
    try:
        client.register_plugin(OneBlasThreadPerDaskWorker())
        with client.as_current():
            futures = client.map(task, list(pending), pure=False)
            runs = {future.key: run for future, run in zip(futures, pending, strict=True)}
            for future in as_completed(futures):
                try:
                    result = future.result()
                except KilledWorker as exc:  # Dask tried it on several workers; each died
                    result = RunResult.failed(runs[future.key], f"{type(exc).__name__}: {exc}")
                except Exception as exc:  # the cluster, not the run: store nothing, stop
                    raise SensingAntennaError(
                        f"--scheduler: the Dask cluster at {scheduler} could not run "
                        f"{runs[future.key].run_id} ({type(exc).__name__}: {exc}); the finished "
                        "runs are stored, the same command again runs the others"
                    ) from exc
                yield result
    finally:
        client.close()
