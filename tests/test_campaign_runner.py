"""Campaign runner: parallel execution, resume after interruption, failure recording, Dask.

These tests use a small real run function of their own (a seeded noisy "estimator" of the true
contact point), so the runner is tested without the simulator; the simulate+estimate run function
is exercised in test_campaign_simulated.py.
"""

from __future__ import annotations

import csv
import json
import math
import os
from pathlib import Path

import numpy as np
import pytest
from distributed import Client, LocalCluster
from threadpoolctl import threadpool_limits

from sensing_antenna.antenna import Antenna, paper_antenna
from sensing_antenna.campaign.dask_plugin import OneBlasThreadPerDaskWorker
from sensing_antenna.campaign.records import RUN_FAILED, RUN_OK, CampaignRow, RunResult
from sensing_antenna.campaign.report import build_report
from sensing_antenna.campaign.runner import CampaignOutcome, execute_safely, run_campaign
from sensing_antenna.campaign.runs import RunSpec, expand_runs
from sensing_antenna.campaign.schema import CampaignSpec, SecondDevice
from sensing_antenna.campaign.store import (
    CampaignStoreError,
    campaign_lock,
    load_run_results,
    read_manifest,
    write_manifest,
)
from sensing_antenna.estimation import ContactEstimate

#: Columns that depend on wall-clock time and may differ between identical campaigns.
TIMING_COLUMNS = ("simulate_s", "estimate_s", "front_end_s")


def small_spec(**changes: object) -> CampaignSpec:
    values: dict[str, object] = {
        "name": "small",
        "antenna": "paper-2021",
        "cases": ("azimuthal", "vertical"),
        "contact_points": (0.3, 0.6, 0.9),
        "repeats": 2,
        "base_seed": 11,
        "methods": ("paper", "ratio"),
    }
    values.update(changes)
    return CampaignSpec(**values)  # type: ignore[arg-type]


def noisy_run(run: RunSpec) -> RunResult:
    """Deterministic toy run: each method estimates x_c with seeded Gaussian noise (1 cm)."""
    rng = np.random.default_rng(run.seed)
    rows = tuple(
        CampaignRow.of_estimate(
            run,
            ContactEstimate(
                status="ok",
                reason=None,
                method=m,
                x_c=run.contact_point + float(rng.normal(0.0, 0.01)),
            ),
            simulate_s=0.0,
            estimate_s=0.0,
        )
        for m in run.methods
    )
    return RunResult(rows=rows)


def failing_at_06(run: RunSpec) -> RunResult:
    """Like :func:`noisy_run`, but every run at x_c = 0.6 m raises."""
    if math.isclose(run.contact_point, 0.6):
        raise RuntimeError(f"simulator diverged at {run.contact_point} m")
    return noisy_run(run)


class Interrupted(BaseException):
    """Stands in for Ctrl-C / SIGTERM: not an Exception, so the runner does not record it."""


def same_antenna(spec: CampaignSpec) -> Antenna:
    return paper_antenna()


def read_rows(path: Path) -> list[dict[str, str]]:
    with open(path, encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    for row in rows:
        for column in TIMING_COLUMNS:
            row.pop(column)
    return rows


def run_inline(spec: CampaignSpec, out: Path) -> CampaignOutcome:
    """The toy campaign (noisy_run, the spec's antenna unchanged) in-process, without progress."""
    return run_campaign(
        spec, out, run_one=noisy_run, prepare_antenna=same_antenna, workers=1, progress=False
    )


def test_inline_campaign_writes_one_file_per_run_and_a_row_per_method(tmp_path: Path) -> None:
    spec = small_spec()
    outcome = run_inline(spec, tmp_path)
    assert (outcome.n_runs, outcome.n_executed, outcome.n_failed) == (12, 12, 0)
    assert len(list((tmp_path / "runs").glob("*.json"))) == 12
    rows = read_rows(outcome.csv_path)
    assert len(rows) == 12 * 2
    first = rows[0]
    assert first["run_id"] == "azimuthal-x0300mm-r1"
    assert first["method"] == "paper"
    # error is estimate minus truth, in metres
    estimate = float(first["x_c_estimate_m"])
    assert float(first["error_m"]) == pytest.approx(estimate - 0.3, abs=1e-12)


def test_points_half_a_millimetre_apart_are_two_runs_with_two_files(tmp_path: Path) -> None:
    spec = small_spec(cases=("azimuthal",), contact_points=(0.5, 0.5004), repeats=1)
    outcome = run_inline(spec, tmp_path)
    assert (outcome.n_runs, outcome.n_executed) == (2, 2)
    assert len(list((tmp_path / "runs").glob("*.json"))) == 2
    truths = sorted({float(row["x_c_true_m"]) for row in read_rows(outcome.csv_path)})
    assert truths == [0.5, 0.5004]


def test_process_pool_gives_the_same_results_as_inline(tmp_path: Path) -> None:
    spec = small_spec()
    inline = run_inline(spec, tmp_path / "inline")
    pooled = run_campaign(
        spec,
        tmp_path / "pool",
        run_one=noisy_run,
        prepare_antenna=same_antenna,
        workers=2,
        progress=False,
    )
    assert read_rows(inline.csv_path) == read_rows(pooled.csv_path)


def test_interrupted_campaign_resumes_without_redoing_or_losing_runs(tmp_path: Path) -> None:
    spec = small_spec()
    reference = run_inline(spec, tmp_path / "ref")
    calls: list[str] = []

    def stop_after_five(run: RunSpec) -> RunResult:
        if len(calls) == 5:
            raise Interrupted
        calls.append(run.run_id)
        return noisy_run(run)

    out = tmp_path / "resumed"
    with pytest.raises(Interrupted):
        run_campaign(
            spec,
            out,
            run_one=stop_after_five,
            prepare_antenna=same_antenna,
            workers=1,
            progress=False,
        )
    stored_first = {p.name: p.stat().st_mtime_ns for p in (out / "runs").glob("*.json")}
    assert len(stored_first) == 5

    second: list[str] = []

    def counting(run: RunSpec) -> RunResult:
        second.append(run.run_id)
        return noisy_run(run)

    outcome = run_campaign(
        spec, out, run_one=counting, prepare_antenna=same_antenna, workers=1, progress=False
    )
    assert (outcome.n_previously_done, outcome.n_executed) == (5, 7)
    assert set(second).isdisjoint(calls), "finished runs must not be redone"
    for name, mtime in stored_first.items():
        assert (out / "runs" / name).stat().st_mtime_ns == mtime, f"{name} was rewritten"
    assert read_rows(outcome.csv_path) == read_rows(reference.csv_path)


def test_a_failing_run_is_recorded_and_the_others_finish(tmp_path: Path) -> None:
    spec = small_spec()
    outcome = run_campaign(
        spec,
        tmp_path,
        run_one=failing_at_06,
        prepare_antenna=same_antenna,
        workers=2,
        progress=False,
    )
    # 2 cases x 2 repeats at 0.6 m fail; the other 8 runs succeed
    assert (outcome.n_executed, outcome.n_failed) == (12, 4)
    results = load_run_results(tmp_path, spec.methods)
    failed = [r for r in results.values() if r.status == RUN_FAILED]
    assert {r.rows[0].x_c_true_m for r in failed} == {0.6}
    assert all("RuntimeError: simulator diverged" in r.error for r in failed)
    assert all("Traceback" in r.detail for r in failed)
    assert sum(r.status == RUN_OK for r in results.values()) == 8
    rows = read_rows(outcome.csv_path)
    failed_rows = [row for row in rows if row["run_status"] == RUN_FAILED]
    assert len(failed_rows) == 4 * 2
    assert all(row["status"] == "run-failed" and row["x_c_estimate_m"] == "" for row in failed_rows)


def test_failed_runs_are_kept_on_resume_and_redone_when_asked(tmp_path: Path) -> None:
    spec = small_spec()
    run_campaign(
        spec,
        tmp_path,
        run_one=failing_at_06,
        prepare_antenna=same_antenna,
        workers=1,
        progress=False,
    )
    again = run_inline(spec, tmp_path)
    assert (again.n_executed, again.n_failed) == (0, 4)
    retried = run_campaign(
        spec,
        tmp_path,
        run_one=noisy_run,
        prepare_antenna=same_antenna,
        workers=1,
        retry_failed=True,
        progress=False,
    )
    assert (retried.n_executed, retried.n_failed) == (4, 0)


def test_execute_safely_turns_an_exception_into_a_failed_result() -> None:
    spec_run = expand_runs(small_spec(), paper_antenna())[2]
    result = execute_safely(failing_at_06, spec_run)
    assert result.status == RUN_FAILED
    assert result.run_id == spec_run.run_id
    assert result.methods == spec_run.methods


def test_ctrl_c_inside_compiled_code_is_an_interruption_not_a_failed_run() -> None:
    # numba raises a SystemError from the KeyboardInterrupt that stopped it: the campaign
    # stops as on any Ctrl-C, the run not recorded as failed
    spec_run = expand_runs(small_spec(), paper_antenna())[0]

    def interrupted(run: RunSpec) -> RunResult:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as exc:
            raise SystemError("CPUDispatcher returned a result with an exception set") from exc

    with pytest.raises(KeyboardInterrupt):
        execute_safely(interrupted, spec_run)


def test_a_result_without_a_row_per_method_is_a_failed_run() -> None:
    spec_run = expand_runs(small_spec(), paper_antenna())[0]

    def paper_only(run: RunSpec) -> RunResult:
        return RunResult(rows=noisy_run(run).rows[:1])

    result = execute_safely(paper_only, spec_run)
    assert result.status == RUN_FAILED
    assert "('paper',) for methods ('paper', 'ratio')" in result.error


def test_a_directory_of_another_spec_is_refused(tmp_path: Path) -> None:
    run_inline(small_spec(), tmp_path)
    with pytest.raises(
        CampaignStoreError, match=r"campaign\.json: fingerprint.*differs in repeats"
    ):
        run_inline(small_spec(repeats=3), tmp_path)


def test_a_manifest_left_alone_by_a_stopped_campaign_is_replaced(tmp_path: Path) -> None:
    # a campaign stopped after writing its manifest (before its preparation): nothing of it is
    # kept, so the next spec may use the directory
    write_manifest(tmp_path, small_spec(repeats=3))
    run_inline(small_spec(), tmp_path)
    assert read_manifest(tmp_path).fingerprint() == small_spec().fingerprint()


def test_a_damaged_run_file_is_reported_with_its_path(tmp_path: Path) -> None:
    run_inline(small_spec(), tmp_path)
    damaged = tmp_path / "runs" / "vertical-x0900mm-r2.json"
    damaged.write_text(json.dumps({"run_id": "vertical-x0900mm-r2"}), encoding="utf-8")
    with pytest.raises(CampaignStoreError, match=r"vertical-x0900mm-r2\.json: damaged run file"):
        load_run_results(tmp_path, small_spec().methods)


def test_a_run_file_not_in_the_spec_is_left_out_and_named(tmp_path: Path) -> None:
    other = run_inline(small_spec(contact_points=(0.45,)), tmp_path / "other")
    assert other.n_executed == 4
    out = tmp_path / "out"
    run_inline(small_spec(), out)
    stray = out / "runs" / "azimuthal-x0450mm-r1.json"
    stray.write_bytes((tmp_path / "other" / "runs" / stray.name).read_bytes())
    outcome = run_inline(small_spec(), out)
    assert outcome.foreign_run_files == ("azimuthal-x0450mm-r1",)
    assert outcome.n_executed == 0
    rows = read_rows(outcome.csv_path)
    assert len(rows) == 12 * 2 and all(row["x_c_true_m"] != "0.45" for row in rows)
    report = build_report(out, figures=False).read_text("utf-8")
    assert "- Left out: 1 run file(s) in `runs/` that are not runs of this spec" in report
    assert "`azimuthal-x0450mm-r1`" in report


def test_temp_files_of_writers_that_are_gone_are_removed_at_start(tmp_path: Path) -> None:
    run_inline(small_spec(), tmp_path)
    # a pid above Linux's pid_max (2^22) belongs to no process; the parent of this test is alive
    gone = tmp_path / "runs" / ".azimuthal-x0300mm-r1.json.99999999.tmp"
    gone_csv = tmp_path / ".runs.csv.99999999.tmp"
    alive = tmp_path / f".report.md.{os.getppid()}.tmp"
    for path in (gone, gone_csv, alive):
        path.write_text("half written", encoding="utf-8")
    run_inline(small_spec(), tmp_path)
    assert not gone.exists() and not gone_csv.exists()
    assert alive.exists()


def test_a_directory_in_use_by_another_campaign_is_refused(tmp_path: Path) -> None:
    run_inline(small_spec(repeats=1), tmp_path)
    with campaign_lock(tmp_path):  # as the other campaign holds it
        with pytest.raises(
            CampaignStoreError, match=rf"in use by another campaign \(process {os.getpid()} on "
        ):
            run_inline(small_spec(), tmp_path)
    # the lock ends with its holder; the file it leaves behind is no lock
    assert (tmp_path / ".lock").is_file()
    assert run_inline(small_spec(repeats=1), tmp_path).n_executed == 0


def test_dask_local_cluster_gives_the_same_results(tmp_path: Path) -> None:
    spec = small_spec()
    inline = run_inline(spec, tmp_path / "inline")
    # These workers run in this process (processes=False) and take its BLAS down to one thread:
    # threadpool_limits(limits=None) changes nothing on entry and gives the other tests their
    # thread count back on exit.
    with (
        threadpool_limits(limits=None),
        LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=False,
            host="127.0.0.1",
            protocol="tcp://",
            dashboard_address=None,
        ) as cluster,
    ):
        on_dask = run_campaign(
            spec,
            tmp_path / "dask",
            run_one=failing_at_06,
            prepare_antenna=same_antenna,
            scheduler=cluster.scheduler_address,
            progress=False,
        )
        with Client(cluster.scheduler_address, set_as_default=False) as client:
            plugins = client.run(lambda dask_worker: list(dask_worker.plugins))
    # Every worker got the local pool's one-BLAS-thread limit.
    assert len(plugins) == 2
    assert all(OneBlasThreadPerDaskWorker.name in names for names in plugins.values())
    assert on_dask.n_failed == 4
    ok_rows = [row for row in read_rows(on_dask.csv_path) if row["run_status"] == RUN_OK]
    expected = [row for row in read_rows(inline.csv_path) if float(row["x_c_true_m"]) != 0.6]
    assert ok_rows == expected


def test_a_stop_signal_whose_exception_was_lost_stops_the_campaign_at_the_next_run(
    tmp_path: Path,
) -> None:
    # A signal handler's exception is raised wherever the main thread is; compiled code calling
    # back into Python (numba unpickling a constant in the fast method's solver) drops it, and a
    # SIGTERM 3.5 s into the default campaign was lost that way: the campaign ran to its end.
    # The handlers record the signal, and the campaign checks after each run
    import signal

    from sensing_antenna.campaign.runner import CampaignInterrupted
    from sensing_antenna.errors import note_signal

    calls: list[str] = []

    def signalled_at_third(run: RunSpec) -> RunResult:
        calls.append(run.run_id)
        if len(calls) == 3:
            note_signal(signal.SIGTERM)  # as the handler does, its exception then lost
        return noisy_run(run)

    out = tmp_path / "stopped"
    with pytest.raises(CampaignInterrupted) as stopped:
        run_campaign(
            small_spec(),
            out,
            run_one=signalled_at_third,
            prepare_antenna=same_antenna,
            workers=1,
            progress=False,
        )
    assert stopped.value.signal_number == signal.SIGTERM
    assert len(calls) == 3 and len(list((out / "runs").glob("*.json"))) == 3
    # the next campaign starts afresh: the signal was the last one's
    outcome = run_campaign(
        small_spec(),
        out,
        run_one=noisy_run,
        prepare_antenna=same_antenna,
        workers=1,
        progress=False,
    )
    assert outcome.n_previously_done == 3


def test_a_second_device_is_prepared_once_and_resumes_with_its_stored_preparation(
    tmp_path: Path,
) -> None:
    spec = small_spec(second_device=SecondDevice(enabled=True))
    calls: list[CampaignSpec] = []

    def prepare(given: CampaignSpec) -> Antenna:
        calls.append(given)
        return paper_antenna()

    class Stop(BaseException):
        pass

    done = 0

    def stop_after_three(run: RunSpec) -> RunResult:
        nonlocal done
        if done == 3:
            raise Stop
        done += 1
        return noisy_run(run)

    with pytest.raises(Stop):
        run_campaign(
            spec,
            tmp_path,
            run_one=stop_after_three,
            prepare_antenna=prepare,
            workers=1,
            progress=False,
        )
    assert calls == [spec, spec.second_device_spec()]
    outcome = run_campaign(
        spec, tmp_path, run_one=noisy_run, prepare_antenna=prepare, workers=1, progress=False
    )
    assert calls == [spec, spec.second_device_spec()]  # both preparations reused
    assert (outcome.n_runs, outcome.n_previously_done, outcome.n_executed) == (24, 3, 21)
    ids = [row["run_id"] for row in read_rows(outcome.csv_path)][::2]
    assert ids[12:] == [f"{run_id}-d2" for run_id in ids[:12]]
