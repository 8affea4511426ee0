"""Running a campaign: every pending run, in parallel, resumable, with failures recorded.

The runner is independent of what a run does: it takes a pure function ``run_one(RunSpec) ->
RunResult`` (by default :func:`sensing_antenna.campaign.simulated.simulate_and_estimate`). Runs
execute inline (one worker), on a local process pool (default: all cores) or on a Dask cluster
(``scheduler="tcp://host:port"``). Each finished run is stored at once (see
:mod:`~sensing_antenna.campaign.store`), so a campaign started again skips what is done. A run
whose function raises is stored as failed with its error, and the others continue.
"""

from __future__ import annotations

import functools
import os
import sys
import traceback
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from sensing_antenna.antenna import Antenna
from sensing_antenna.campaign.records import RUN_FAILED, RunResult
from sensing_antenna.campaign.runs import RunSpec, expand_runs
from sensing_antenna.campaign.schema import CampaignSpec
from sensing_antenna.campaign.store import (
    CSV_FILE,
    Preparation,
    load_run_results,
    read_preparation,
    write_manifest,
    write_preparation,
    write_run_result,
    write_runs_csv,
)
from sensing_antenna.campaign.worker_threads import limit_to_one_blas_thread
from sensing_antenna.errors import SensingAntennaError

__all__ = [
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
    """

    out_dir: Path
    csv_path: Path
    n_runs: int
    n_previously_done: int
    n_executed: int
    n_failed: int


def execute_safely(run_one: RunFunction, run: RunSpec) -> RunResult:
    """Call ``run_one(run)``; an exception becomes a failed RunResult with its traceback.

    A result for another run, or without one row per method of the run in order, is recorded
    as a failed run too.
    """
    try:
        result = run_one(run)
    except Exception as exc:  # a failing run is recorded and must not stop the others
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
        spec asks.
    workers : int, optional
        Local worker processes; default all cores. 1 runs inline in this process.
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:port``); runs go to that cluster instead.
    retry_failed : bool
        Redo runs stored as failed.
    progress : bool
        Show a progress bar on stderr.

    Returns
    -------
    CampaignOutcome
    """
    if workers is not None and workers < 1:
        raise SensingAntennaError(f"--workers: must be >= 1, got {workers}")
    if run_one is None or prepare_antenna is None:
        from sensing_antenna.campaign import simulated

        # every scenario the simulation will be given, checked before anything is written
        simulated.check_scenario(spec)
        run_one = run_one or simulated.simulate_and_estimate
        prepare_antenna = prepare_antenna or simulated.prepare_campaign
    directory = Path(out_dir)
    directory.mkdir(parents=True, exist_ok=True)
    write_manifest(directory, spec)
    preparation = read_preparation(directory, spec)
    if preparation is None:
        prepared = prepare_antenna(spec)
        preparation = prepared if isinstance(prepared, Preparation) else Preparation.same(prepared)
        write_preparation(directory, spec, preparation)
    runs = expand_runs(spec, preparation.model, preparation.device)
    done = load_run_results(directory, spec.methods)
    if retry_failed:
        done = {k: v for k, v in done.items() if v.status != RUN_FAILED}
    pending = [run for run in runs if run.run_id not in done]
    task = functools.partial(execute_safely, run_one)
    executed = 0
    with tqdm(
        total=len(runs),
        initial=len(runs) - len(pending),
        desc=f"campaign {spec.name}",
        unit="run",
        file=sys.stderr,
        disable=not progress,
    ) as bar:
        for result in _execute(task, pending, workers, scheduler):
            write_run_result(directory, result)
            executed += 1
            bar.update(1)
    stored = load_run_results(directory, spec.methods)
    csv_path = write_runs_csv(directory / CSV_FILE, stored.values())
    return CampaignOutcome(
        out_dir=directory,
        csv_path=csv_path,
        n_runs=len(runs),
        n_previously_done=len(runs) - len(pending),
        n_executed=executed,
        n_failed=sum(1 for r in stored.values() if r.status == RUN_FAILED),
    )


def _execute(
    task: Callable[[RunSpec], RunResult],
    pending: Sequence[RunSpec],
    workers: int | None,
    scheduler: str | None,
) -> Iterator[RunResult]:
    if not pending:
        return
    if scheduler is not None:
        yield from _execute_dask(task, pending, scheduler)
    elif (workers or os.cpu_count() or 1) == 1 or len(pending) == 1:
        for run in pending:
            yield task(run)
    else:
        yield from _execute_pool(task, pending, workers or os.cpu_count() or 1)


def _execute_pool(
    task: Callable[[RunSpec], RunResult], pending: Sequence[RunSpec], workers: int
) -> Iterator[RunResult]:
    executor = ProcessPoolExecutor(
        max_workers=min(workers, len(pending)), initializer=limit_to_one_blas_thread
    )
    futures: dict[Future[RunResult], RunSpec] = {}
    try:
        futures = {executor.submit(task, run): run for run in pending}
        remaining = set(futures)
        while remaining:
            finished, remaining = wait(remaining, return_when=FIRST_COMPLETED)
            for future in finished:
                yield _result_of(future, futures[future])
    finally:
        executor.shutdown(wait=True, cancel_futures=True)


def _result_of(future: Future[RunResult], run: RunSpec) -> RunResult:
    try:
        return future.result()
    except Exception as exc:  # e.g. a worker process died: record it against this run
        return RunResult.failed(run, f"{type(exc).__name__}: {exc}")


def _execute_dask(
    task: Callable[[RunSpec], RunResult], pending: Sequence[RunSpec], scheduler: str
) -> Iterator[RunResult]:
    from distributed import Client, as_completed

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
                except Exception as exc:  # worker lost or task could not run remotely
                    result = RunResult.failed(runs[future.key], f"{type(exc).__name__}: {exc}")
                yield result
    finally:
        client.close()
