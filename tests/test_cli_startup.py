"""The ``antenna`` command answers help and argument errors without loading the numerical stack.

A person who types ``antenna --help`` or mistypes an argument should get the answer at once. The
contract checked here, without timing anything: parsing arguments imports none of NumPy, SciPy,
Matplotlib or numba (importing them is what takes a second or more); they are imported only when
a command runs.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import sensing_antenna
from sensing_antenna.cli import main
from sensing_antenna.estimation import METHODS

#: Packages whose import costs a noticeable fraction of a second each.
HEAVY = ("numpy", "scipy", "matplotlib", "numba", "dask", "tqdm", "trimesh", "sklearn", "skimage")

#: Run ``main(argv)`` in a fresh interpreter; print its exit code and the heavy packages loaded.
_PROBE = """
import json, sys
from sensing_antenna.cli import main
argv = json.loads(sys.argv[1])
try:
    code = main(argv)
except SystemExit as exc:
    code = exc.code
heavy = json.loads(sys.argv[2])
loaded = sorted(name for name in heavy if name in sys.modules)
print(json.dumps({"code": code, "loaded": loaded}), file=sys.stderr)
"""


def _probe(argv: list[str]) -> tuple[int, list[str], str]:
    """Exit code, heavy packages imported and stdout of ``antenna *argv`` in a new process."""
    src = str(Path(sensing_antenna.__file__).resolve().parents[1])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([src, os.environ.get("PYTHONPATH", "")])}
    done = subprocess.run(
        [sys.executable, "-c", _PROBE, json.dumps(argv), json.dumps(HEAVY)],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        timeout=60,
    )
    report = json.loads(done.stderr.strip().splitlines()[-1])
    return int(report["code"]), list(report["loaded"]), done.stdout


@pytest.mark.parametrize(
    "argv",
    [
        ["--help"],
        ["beam", "--help"],
        ["simulate", "--help"],
        ["identify", "--help"],
        ["estimate", "--help"],
        ["calibrate", "--help"],
        ["campaign", "--help"],
        ["campaign", "run", "--help"],
        ["campaign", "report", "--help"],
        ["map", "--help"],
        ["plot", "--help"],
        ["plot", "sensing-curves", "--help"],
        ["plot", "recording", "--help"],
        ["plot", "estimate", "--help"],
        ["import", "--help"],
        ["import", "rosbag", "--help"],
    ],
    ids=" ".join,
)
def test_help_loads_no_numerical_package(argv: list[str]) -> None:
    code, loaded, out = _probe(argv)
    assert code == 0 and "usage: antenna" in out
    assert loaded == []


@pytest.mark.parametrize(
    "argv",
    [
        [],
        ["teleport"],
        ["beam"],
        ["beam", "--xc", "near"],
        ["simulate", "--case", "sideways", "--out", "rec.csv"],
        ["estimate"],
        ["estimate", "rec.csv", "--method", "magic"],
        ["estimate", "rec.csv", "--t1", "later"],
        ["campaign", "run"],
        ["campaign"],
        ["map", "rec.csv"],
        ["map", "rec.csv", "--out", "m", "--method", "magic"],
        ["plot"],
        ["plot", "figure-99", "--out", "figures"],
        ["beam", "--xc", "0.5", "--modes", "0"],
        ["beam", "--omega1", "-3"],
        ["simulate", "--case", "free", "--xc", "near", "--out", "rec.csv"],
        ["identify", "rec.csv", "--out", "a.toml", "--margin", "0.5"],
        ["identify", "rec.csv", "--out", "a.toml", "--name", "two\nlines"],
        ["calibrate", "rec.csv", "--out", "a.toml", "--loss", "square"],
        ["estimate", "rec.csv", "--method", "fast", "--tolerance", "-1"],
        ["campaign", "run", "--out", "c", "--workers", "0"],
        ["import"],
        ["import", "rosbag", "b.bag", "--wrench", "/w", "--joints", "/j", "--rate", "0"],
    ],
    ids=lambda argv: " ".join(argv) or "no arguments",
)
def test_argument_errors_load_no_numerical_package(argv: list[str]) -> None:
    code, loaded, _ = _probe(argv)
    assert code == 2
    assert loaded == []


def test_version_loads_no_numerical_package() -> None:
    code, loaded, out = _probe(["--version"])
    assert code == 0 and out.startswith("antenna ")
    assert loaded == []


def test_a_command_that_runs_does_load_them() -> None:
    # the probe can see an import: the same check on a command that computes finds NumPy
    code, loaded, out = _probe(["beam", "--xc", "0.5", "--json"])
    assert code == 0 and json.loads(out)[0]["x_c"] == 0.5
    assert "numpy" in loaded


def test_estimate_offers_every_registered_method(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["estimate", "--help"])
    assert exc.value.code == 0
    assert "{" + ",".join(sorted(METHODS)) + "}" in capsys.readouterr().out


def test_an_unknown_method_is_named_with_the_known_ones(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["estimate", "rec.csv", "--method", "magic"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "'magic'" in err
    assert all(repr(name) in err for name in METHODS)


@pytest.mark.parametrize(
    ("argv", "prog", "suggestion"),
    [
        (["estimate", "rec.csv", "--metod", "fast"], "antenna estimate", "--method"),
        (["--verison"], "antenna", "--version"),
        (
            ["simulate", "--case", "free", "--out", "x.csv", "--sed", "1"],
            "antenna simulate",
            "--seed",
        ),
        (["campaign", "run", "--out", "x", "--workrs", "2"], "antenna campaign run", "--workers"),
    ],
)
def test_a_mistyped_option_is_answered_with_the_close_one(
    argv: list[str], prog: str, suggestion: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    # one line, from the (sub)command that owns the options, nested ones included
    assert "\n" not in err and err.startswith(f"{prog}: error: unrecognized arguments")
    assert f"(did you mean {suggestion}?)" in err


def test_a_second_recording_to_estimate_says_it_reads_one(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["estimate", "rec.csv", "rec2.csv"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("antenna estimate: error: unrecognized arguments: rec2.csv (")
    assert "estimate reads one recording" in err and "antenna map" in err


def test_an_unexpected_option_is_named_without_a_guess(
    capsys: pytest.CaptureFixture[str],
) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["estimate", "rec.csv", "--zzz"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err == "antenna estimate: error: unrecognized arguments: --zzz"
