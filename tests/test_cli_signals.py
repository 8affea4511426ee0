"""How a command ends: interrupted, asked to stop, its reader gone, or out of memory.

Each test runs ``antenna`` in a fresh process and does to it what a person or a machine does:
Ctrl-C (SIGINT), a supervisor's or batch scheduler's SIGTERM, ``| head`` closing the pipe, a
memory limit. The expected endings are the shell's conventions: Ctrl-C ends the process by
SIGINT (the shell reports 130), SIGTERM with 143 and a closed pipe with 141 (128 + SIGPIPE),
each with at most one line on stderr; a request too large for the memory with one line and
exit code 2.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import sensing_antenna

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals and pipes")

#: ``antenna`` as the console script runs it. SIGINT gets Python's usual handler even when the
#: test runner was started with SIGINT ignored (a background job), as a terminal's Ctrl-C finds it.
_ANTENNA = (
    "import signal, sys\n"
    "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
    "from sensing_antenna.cli import main\n"
    "sys.exit(main())\n"
)

#: A command that computes for several seconds (120 s of simulated time, 4 to 8 s on two cores)
#: and writes nothing before it is done.
_LONG_COMMAND = ["simulate", "--case", "azimuthal", "--xc", "0.5", "--duration", "120"]

#: A command that is done in about a second.
_SHORT_COMMAND = ["simulate", "--case", "azimuthal", "--xc", "0.5", "--duration", "2.5"]

#: Time given to the process to start and enter the command (s): parsing takes 50 ms on an idle
#: machine, over a second on a loaded one (the suite beside other jobs on two cores); the 120 s
#: simulation runs for several seconds more.
_STARTED = 2.5


def _environment() -> dict[str, str]:
    src = str(Path(sensing_antenna.__file__).resolve().parents[1])
    return {**os.environ, "PYTHONPATH": os.pathsep.join([src, os.environ.get("PYTHONPATH", "")])}


def _interrupt(
    signal_number: int,
    out: Path,
    command: list[str] = _LONG_COMMAND,
    started: float = _STARTED,
    program: str = _ANTENNA,
    ready: Path | None = None,
) -> subprocess.CompletedProcess[str]:
    """Start ``command`` (run by ``program``), send ``signal_number`` to its process alone
    ``started`` seconds after (once it runs), or once the file ``ready`` exists (the program
    is given its path in ``ANTENNA_TEST_READY``); its ending."""
    environment = _environment()
    if ready is not None:
        environment["ANTENNA_TEST_READY"] = str(ready)
    process = subprocess.Popen(
        [sys.executable, "-c", program, *command, "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=environment,
    )
    if ready is None:
        time.sleep(started)
    else:
        deadline = time.monotonic() + 60.0
        while not ready.exists() and process.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
    assert process.poll() is None, "the command ended before it could be interrupted"
    process.send_signal(signal_number)
    stdout, stderr = process.communicate(timeout=60)
    return subprocess.CompletedProcess(process.args, process.returncode, stdout, stderr)


def test_ctrl_c_ends_with_one_line_and_by_sigint(tmp_path: Path) -> None:
    # the process ends by SIGINT itself, as Python ends any interrupted program: the shell
    # reports 130, and a shell loop running the command stops too (test below)
    done = _interrupt(signal.SIGINT, tmp_path / "rec.csv")
    assert done.returncode == -signal.SIGINT
    assert done.stderr.strip() == "antenna simulate: interrupted"
    assert done.stdout == ""
    assert not (tmp_path / "rec.csv").exists()


@pytest.mark.skipif(shutil.which("bash") is None, reason="needs bash")
def test_ctrl_c_stops_the_shell_script_that_runs_the_command(tmp_path: Path) -> None:
    # Ctrl-C reaches the whole foreground process group: the script and the command. bash
    # stops the script only if the command died by SIGINT; after a command that exits normally
    # (even with 130) it goes on with the next line.
    command = shlex.join([sys.executable, "-c", _ANTENNA, *_LONG_COMMAND])
    script = f"{command} --out {shlex.quote(str(tmp_path / 'rec.csv'))}; echo went on"
    process = subprocess.Popen(
        ["bash", "-c", script],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_environment(),
        start_new_session=True,
    )
    time.sleep(_STARTED)
    assert process.poll() is None, "the command ended before it could be interrupted"
    os.killpg(process.pid, signal.SIGINT)
    stdout, stderr = process.communicate(timeout=60)
    assert "went on" not in stdout
    assert stderr.strip() == "antenna simulate: interrupted"


def test_sigterm_ends_with_one_line_and_143(tmp_path: Path) -> None:
    done = _interrupt(signal.SIGTERM, tmp_path / "rec.csv")
    assert done.returncode == 143
    assert done.stderr.strip() == "antenna simulate: stopped by SIGTERM"
    assert not (tmp_path / "rec.csv").exists()


#: ``antenna`` whose simulation first drops an object with a slow finalizer: Python runs the
#: finalizer in the main thread, and an exception raised there (the signal's) is printed and
#: dropped, the program going on.
_ANTENNA_SLOW_FINALIZER = (
    "import os, pathlib, signal, sys, time\n"
    "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
    "import sensing_antenna.simulator as simulator\n"
    "class Slow:\n"
    "    def __del__(self):\n"
    "        pathlib.Path(os.environ['ANTENNA_TEST_READY']).touch()\n"
    "        time.sleep(4.0)\n"
    "original = simulator.simulate\n"
    "def slowed(*args, **kwargs):\n"
    "    Slow()\n"
    "    return original(*args, **kwargs)\n"
    "simulator.simulate = slowed\n"
    "from sensing_antenna.cli import main\n"
    "sys.exit(main())\n"
)


def test_sigterm_inside_a_finalizer_still_stops_the_command(tmp_path: Path) -> None:
    # the signal lands while the finalizer sleeps (sent once the finalizer says it has begun:
    # the imports alone take 2.5 to 3.3 s here); Python drops the exception raised there, and
    # the command delivers the signal again where it can unwind: one line, 143, no recording
    out = tmp_path / "rec.csv"
    done = _interrupt(
        signal.SIGTERM, out, program=_ANTENNA_SLOW_FINALIZER, ready=tmp_path / "finalizing"
    )
    assert done.returncode == 143, done.stderr
    assert done.stderr.strip() == "antenna simulate: stopped by SIGTERM"
    assert not out.exists()


#: ``antenna`` whose simulator swallows a SIGTERM it receives (a library catching everything).
_ANTENNA_SWALLOWING = (
    "import os, signal, sys, time\n"
    "import sensing_antenna.simulator as simulator\n"
    "original = simulator.simulate\n"
    "def swallowing(*args, **kwargs):\n"
    "    try:\n"
    "        os.kill(os.getpid(), signal.SIGTERM)\n"
    "        time.sleep(2.0)\n"
    "    except BaseException:\n"
    "        pass\n"
    "    return original(*args, **kwargs)\n"
    "simulator.simulate = swallowing\n"
    "from sensing_antenna.cli import main\n"
    "sys.exit(main())\n"
)


#: ``antenna`` whose simulator stands for a compiled function (numba's) interrupted inside: the
#: KeyboardInterrupt comes back as the cause of a SystemError.
_ANTENNA_COMPILED = (
    "import signal, sys\n"
    "import sensing_antenna.simulator as simulator\n"
    "def compiled(*args, **kwargs):\n"
    "    try:\n"
    "        raise KeyboardInterrupt\n"
    "    except KeyboardInterrupt as exc:\n"
    "        raise SystemError('CPUDispatcher(<function solve>) returned a result with an'\n"
    "                          ' exception set') from exc\n"
    "simulator.simulate = compiled\n"
    "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
    "from sensing_antenna.cli import main\n"
    "sys.exit(main())\n"
)


def _short_run(program: str, out: Path) -> subprocess.CompletedProcess[str]:
    """The short command run to its end by ``program``, writing ``out``."""
    return subprocess.run(
        [sys.executable, "-c", program, *_SHORT_COMMAND, "--out", str(out)],
        capture_output=True,
        text=True,
        env=_environment(),
        timeout=120,
        check=False,
    )


def test_ctrl_c_inside_a_compiled_function_is_an_interruption(tmp_path: Path) -> None:
    done = _short_run(_ANTENNA_COMPILED, tmp_path / "r.csv")
    assert done.returncode == -signal.SIGINT, done.stderr
    assert done.stderr.strip() == "antenna simulate: interrupted"


def test_a_stop_the_command_swallowed_still_stops_it_when_it_returns(tmp_path: Path) -> None:
    # the command's own code caught the SIGTERM and went on to finish; the command line still
    # reports the stop and ends by it when the command returns
    done = _short_run(_ANTENNA_SWALLOWING, tmp_path / "r.csv")
    assert done.returncode == 143, done.stderr
    assert done.stderr.strip() == "antenna simulate: stopped by SIGTERM"


def test_an_interrupted_campaign_says_what_it_keeps(tmp_path: Path) -> None:
    # the default campaign runs for a minute or more: it is interrupted while it sets up or runs
    command = ["campaign", "run", "--workers", "1", "--no-progress"]
    for signal_number, code in ((signal.SIGINT, -signal.SIGINT), (signal.SIGTERM, 143)):
        # 1.5 s: while it sets up (identification, calibration)
        done = _interrupt(signal_number, tmp_path / "out", command, started=1.5)
        assert done.returncode == code
        name = signal.Signals(signal_number).name
        assert re.fullmatch(
            # before the campaign has begun (still importing), or while it sets up or runs
            rf"antenna campaign run: (interrupted|stopped by {name}|interrupted by {name}"
            rf"(: \d+ of \d+ runs are stored in {re.escape(str(tmp_path / 'out'))}; the same "
            r"command again runs the others| before any run))",
            done.stderr.strip(),
        ), done.stderr


def test_a_closed_pipe_ends_quietly_with_141() -> None:
    # `antenna beam --xc ... | head -2` once head has exited: the read end of stdout is closed
    # before the command writes anything, so every write fails, whatever the timing.
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        done = subprocess.run(
            [sys.executable, "-c", _ANTENNA, "beam", "--xc", "0.3", "0.5", "--modes", "50"],
            stdout=write_end,
            stderr=subprocess.PIPE,
            text=True,
            env=_environment(),
            check=False,
            timeout=60,
        )
    finally:
        os.close(write_end)
    assert done.returncode == 141
    assert done.stderr == ""


def test_a_request_too_large_for_the_memory_is_one_line(tmp_path: Path) -> None:
    # 1e7 s of simulated time is 1e10 samples, 80 GB per column: more than the 4 GiB of address
    # space the process is given here, whatever the machine has
    limited = "import resource\nresource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))\n"
    argv = [*_LONG_COMMAND[:-1], "1e7", "--out", str(tmp_path / "rec.csv")]
    done = subprocess.run(
        [sys.executable, "-c", limited + _ANTENNA, *argv],
        capture_output=True,
        text=True,
        env=_environment(),
        check=False,
        timeout=120,
    )
    assert done.returncode == 2
    err = done.stderr.strip()
    assert err.startswith("antenna simulate: error: ") and err.count("\n") == 0
    assert not (tmp_path / "rec.csv").exists()


def test_an_interruption_while_a_class_is_made_is_an_interruption(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # Ctrl-C while a module is imported can land in a dataclass field's __set_name__, which
    # Python 3.11 reports as a RuntimeError raised from the KeyboardInterrupt: it is the
    # interruption, one line and no traceback, not a failure
    import sensing_antenna.cli.beam as beam
    from sensing_antenna.cli import main

    class Field:
        def __set_name__(self, owner: type, name: str) -> None:
            raise KeyboardInterrupt

    def interrupted(args: object) -> int:
        type("Made", (), {"peaks": Field()})
        return 0

    monkeypatch.setattr(beam, "run", interrupted)
    with pytest.raises(KeyboardInterrupt):
        main(["beam", "--xc", "0.5"])
    assert capsys.readouterr().err.strip() == "antenna beam: interrupted"
