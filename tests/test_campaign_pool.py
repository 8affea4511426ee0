"""The campaign's worker processes: a dead worker, a killed or interrupted main process.

The runs here are the toy runs of test_campaign_runner (a seeded noisy "estimator"), some of
which kill their own worker process with SIGKILL, as the out-of-memory killer does. The
signal tests run the real ``antenna campaign run`` in a child process and signal it from here.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import pytest

from sensing_antenna.campaign.pool import MAX_ATTEMPTS
from sensing_antenna.campaign.records import RUN_FAILED, RUN_OK, RunResult
from sensing_antenna.campaign.runner import run_campaign
from sensing_antenna.campaign.runs import RunSpec, run_ids
from sensing_antenna.campaign.store import load_run_results
from test_campaign_runner import noisy_run, read_rows, run_inline, same_antenna, small_spec

#: Environment variable naming the directory where the toy runs below log and leave markers
#: (the worker processes inherit the environment).
LOG_DIR = "SENSING_ANTENNA_TEST_POOL_LOG"

linux_only = pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="reads /proc")


def _log(run: RunSpec) -> None:
    """Append the run's id to the log, one line per finished execution."""
    with open(Path(os.environ[LOG_DIR]) / "executions.log", "a", encoding="utf-8") as handle:
        handle.write(run.run_id + "\n")


def _first_time(name: str) -> bool:
    """True exactly once per ``name`` across processes (an O_EXCL marker file)."""
    try:
        os.close(os.open(Path(os.environ[LOG_DIR]) / name, os.O_CREAT | os.O_EXCL))
    except FileExistsError:
        return False
    return True


def killed_once_at_06(run: RunSpec) -> RunResult:
    """The first attempt of azimuthal x_c = 0.6 m, repeat 1, dies as if OOM-killed."""
    if run.run_id == "azimuthal-x0600mm-r1" and _first_time("killed"):
        os.kill(os.getpid(), signal.SIGKILL)
    _log(run)
    return noisy_run(run)


def always_killed_at_06(run: RunSpec) -> RunResult:
    """Every attempt of azimuthal x_c = 0.6 m, repeat 1, kills its worker."""
    if run.run_id == "azimuthal-x0600mm-r1":
        os.kill(os.getpid(), signal.SIGKILL)
    _log(run)
    return noisy_run(run)


def executions(log_dir: Path) -> Counter[str]:
    path = log_dir / "executions.log"
    return Counter(path.read_text("utf-8").split()) if path.is_file() else Counter()


def test_a_killed_worker_costs_one_retry_and_every_run_finishes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(LOG_DIR, str(tmp_path))
    spec = small_spec()
    reference = run_inline(spec, tmp_path / "ref")
    outcome = run_campaign(
        spec,
        tmp_path / "pool",
        run_one=killed_once_at_06,
        prepare_antenna=same_antenna,
        workers=2,
        progress=False,
    )
    assert (tmp_path / "killed").is_file(), "the worker was not killed: the test tests nothing"
    assert (outcome.n_executed, outcome.n_failed) == (12, 0)
    # every run finished exactly once (the killed attempt never finished), none was lost
    assert executions(tmp_path) == Counter(run_ids(spec))
    assert read_rows(outcome.csv_path) == read_rows(reference.csv_path)
    again = run_campaign(
        spec,
        tmp_path / "pool",
        run_one=killed_once_at_06,
        prepare_antenna=same_antenna,
        workers=2,
        progress=False,
    )
    assert again.n_executed == 0


def test_a_run_that_always_kills_its_worker_fails_alone_after_its_attempts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(LOG_DIR, str(tmp_path))
    spec = small_spec()
    outcome = run_campaign(
        spec,
        tmp_path / "pool",
        run_one=always_killed_at_06,
        prepare_antenna=same_antenna,
        workers=2,
        progress=False,
    )
    assert (outcome.n_executed, outcome.n_failed) == (12, 1)
    results = load_run_results(tmp_path / "pool", spec.methods)
    failed = [r for r in results.values() if r.status == RUN_FAILED]
    assert [r.run_id for r in failed] == ["azimuthal-x0600mm-r1"]
    assert f"died on each of {MAX_ATTEMPTS} attempts (last: killed by SIGKILL" in failed[0].error
    # the eleven others ran once each and are ok
    assert sum(r.status == RUN_OK for r in results.values()) == 11
    assert set(executions(tmp_path).values()) == {1} and len(executions(tmp_path)) == 11


# --- the command in a child process, signalled from here ---------------------------------------

#: A real campaign of 40 cheap runs (one case, the ratio method, no preparation steps): long
#: enough for a second command to start while it runs, short enough to finish.
SPEC = """
name = "signals"
antenna = "paper-2021"
cases = ["azimuthal"]
contact_points = [0.30, 0.35, 0.40, 0.45, 0.50, 0.55, 0.60, 0.65]
repeats = 5
base_seed = 4
methods = ["ratio"]
"""
#: The same with 16 runs (about 1.5 s of work on two idle cores after the first two are stored):
#: enough to be caught in the middle by a signal sent as soon as two are stored.
SHORT_SPEC = SPEC.replace("repeats = 5", "repeats = 2")
N_SHORT = 16


def start_campaign(spec: Path, out: Path) -> subprocess.Popen[str]:
    """``antenna campaign run SPEC --out OUT --workers 2 --no-progress`` in a child process."""
    code = "import sys; from sensing_antenna.cli import main; sys.exit(main())"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    args = ["campaign", "run", str(spec), "--out", str(out), "--workers", "2", "--no-progress"]
    return subprocess.Popen(
        [sys.executable, "-c", code, *args],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def stored_runs(out: Path) -> list[Path]:
    return sorted((out / "runs").glob("*.json"))


def wait_for_runs(out: Path, process: subprocess.Popen[str], n: int = 1) -> None:
    """Wait until ``n`` runs are stored (the workers are busy); fail if the command ends first."""
    deadline = time.monotonic() + 180.0  # a cold numba cache compiles the kernels first
    while len(stored_runs(out)) < n:
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "no run stored in 180 s"
        time.sleep(0.05)


def running(pid: int) -> bool:
    """Whether process ``pid`` exists and is not a zombie."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (FileNotFoundError, ProcessLookupError):
        return False
    return fields[0] != "Z"


def children(pid: int) -> list[int]:
    """Running processes whose parent is ``pid``."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (FileNotFoundError, ProcessLookupError):
            continue
        if int(fields[1]) == pid and fields[0] != "Z":
            found.append(int(stat.parent.name))
    return found


def all_gone(pids: list[int], within: float) -> bool:
    deadline = time.monotonic() + within
    while any(running(p) for p in pids):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.1)
    return True


@linux_only
# Ctrl-C ends the process by SIGINT itself (the shell reports 130), SIGTERM with exit code 143
@pytest.mark.parametrize(
    ("stop", "exit_code"), [(signal.SIGINT, -signal.SIGINT), (signal.SIGTERM, 143)]
)
def test_a_signal_to_the_main_process_alone_stops_it_and_keeps_every_finished_run(
    tmp_path: Path, stop: signal.Signals, exit_code: int
) -> None:
    spec = tmp_path / "signals.toml"
    spec.write_text(SHORT_SPEC, encoding="utf-8")
    out = tmp_path / "out"
    process = start_campaign(spec, out)
    wait_for_runs(out, process, 2)
    workers = children(process.pid)
    assert len(workers) == 2
    # only the main process: as `timeout`, a batch scheduler or a supervisor sends it
    process.send_signal(stop)
    _, err = process.communicate(timeout=30)
    assert process.returncode == exit_code
    n_stored = len(stored_runs(out))
    assert err.splitlines() == [
        f"antenna campaign run: interrupted by {stop.name}: {n_stored} of {N_SHORT} runs are "
        f"stored in {out}; the same command again runs the others"
    ]
    assert all_gone(workers, within=5.0), "a worker outlived its campaign"
    before = {p.name: p.stat().st_mtime_ns for p in stored_runs(out)}
    resumed = start_campaign(spec, out)
    printed, err = resumed.communicate(timeout=300)
    assert resumed.returncode == 0, err
    assert (
        printed.splitlines()[0]
        == f"{N_SHORT} runs: {n_stored} already done, {N_SHORT - n_stored} run now, 0 failed"
    )
    assert all((out / "runs" / name).stat().st_mtime_ns == t for name, t in before.items())


@linux_only
def test_workers_exit_with_a_killed_main_process_and_a_plain_resume_finishes(
    tmp_path: Path,
) -> None:
    spec = tmp_path / "signals.toml"
    spec.write_text(SHORT_SPEC, encoding="utf-8")
    out = tmp_path / "out"
    process = start_campaign(spec, out)
    wait_for_runs(out, process, 2)
    workers = children(process.pid)
    assert len(workers) == 2
    process.kill()  # SIGKILL: nothing in the main process runs any more
    process.communicate(timeout=30)
    assert all_gone(workers, within=10.0), "workers outlived a killed campaign"
    resumed = start_campaign(spec, out)
    printed, err = resumed.communicate(timeout=300)
    assert resumed.returncode == 0, err
    assert "0 failed" in printed.splitlines()[0]
    assert len(stored_runs(out)) == N_SHORT


def test_a_second_campaign_on_the_same_directory_is_refused_and_runs_nothing(
    tmp_path: Path,
) -> None:
    spec = tmp_path / "signals.toml"
    spec.write_text(SPEC, encoding="utf-8")
    out = tmp_path / "out"
    first = start_campaign(spec, out)
    wait_for_runs(out, first, 2)
    # the first paused while the second starts, so that it cannot finish its runs (and free the
    # directory) before the second has looked: it still holds the directory, as a busy one does
    os.kill(first.pid, signal.SIGSTOP)
    try:
        second = start_campaign(spec, out)
        printed, err = second.communicate(timeout=120)
    finally:
        os.kill(first.pid, signal.SIGCONT)
    assert second.returncode == 2
    assert printed == ""
    assert err.startswith(
        f"antenna campaign run: error: {out}: in use by another campaign (process {first.pid} on "
    )
    printed, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    # every run done once, by the first: it ran them all and found none already done
    assert printed.splitlines()[0] == "40 runs: 0 already done, 40 run now, 0 failed"
    assert len(stored_runs(out)) == 40


def test_a_bar_opened_on_its_first_item_shows_nothing_for_work_not_done() -> None:
    import io

    from sensing_antenna.campaign.progress import Progress

    for items in (0, 2):
        stream = io.StringIO()
        with Progress(enabled=True, stream=stream).bar_from_first(7, "recognising", "shape") as bar:
            for _ in range(items):
                bar()
        if items:
            assert "recognising" in stream.getvalue() and "2/7" in stream.getvalue()
        else:
            assert stream.getvalue() == ""


def test_progress_bars_start_no_thread_in_the_process_that_forks_the_workers() -> None:
    import io
    import threading

    from sensing_antenna.campaign.progress import Progress

    before = threading.active_count()
    with Progress(enabled=True, stream=io.StringIO()).bar(3, "runs") as bar:
        bar.update(1)
        # tqdm's own bars start a monitor thread; forking beside a thread can deadlock a worker
        assert threading.active_count() == before
