"""What the commands say: bad arguments named by the flag typed, and what a result means.

An argument error names the flag as the user typed it (``--xc``, not the library's
``scenario.contact_point`` or ``x_c``) and the range allowed, the same for every bad value and
every command taking that flag; values appear as Python writes them (``nan``), never as the
array library's ``np.float64(nan)``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sensing_antenna import errors
from sensing_antenna.antenna import paper_antenna
from sensing_antenna.cli import main

#: The paper's link is 0.98 m long (Table 2): --xc must lie in (0, 0.98] m.
XC_RANGE = "(0, 0.98] m"


def _error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run ``antenna *argv``, check the exit code is 2 and stderr one line; that line."""
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse errors exit from inside parse_args
        code = int(exc.code) if exc.code is not None else 0
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert err.count("\n") == 0 and "Traceback" not in err
    return err


def _simulate(tmp_path: Path, *flags: str) -> list[str]:
    return ["simulate", *flags, "--duration", "2", "--out", str(tmp_path / "rec.csv")]


@pytest.mark.parametrize("value", ["-0.3", "0", "1.5", "nan", "inf"])
def test_a_contact_point_out_of_range_names_xc_and_the_range(
    value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for argv in (
        ["beam", "--xc", value],
        ["beam", "--xc", "0.5", value],
        _simulate(tmp_path, "--case", "azimuthal", "--xc", value),
        _simulate(tmp_path, "--case", "vertical", "--xc", value),
    ):
        err = _error(argv, capsys)
        assert err.startswith(f"antenna {argv[0]}: error: --xc: ")
        assert XC_RANGE in err and err.endswith(f"got {float(value)!r}")
    assert not (tmp_path / "rec.csv").exists()


def test_a_missing_or_unused_contact_point_names_xc(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    err = _error(_simulate(tmp_path, "--case", "azimuthal"), capsys)
    assert err.startswith("antenna simulate: error: --xc: required with --case azimuthal")
    assert XC_RANGE in err
    err = _error(_simulate(tmp_path, "--case", "free", "--xc", "0.5"), capsys)
    assert err.startswith("antenna simulate: error: --xc: not used with --case free")
    assert _error(["beam", "--xc", "near"], capsys).endswith(
        "--xc: must be a number (m), got 'near'"
    )


@pytest.mark.parametrize(
    ("flags", "named"),
    [
        # the simulator's own limit: 0.001 m is too near the base for the contact stiffness
        (["--case", "vertical", "--xc", "0.001"], "--xc: 0.001 m is below"),
        (["--case", "azimuthal", "--xc", "0.5", "--noise", "-1"], "--noise: must be >= 0"),
        (["--case", "azimuthal", "--xc", "0.5", "--seed", "-1"], "--seed: must be an integer"),
        (["--case", "azimuthal", "--xc", "0.5", "--duration", "0.001"], "--duration: must be >"),
    ],
)
def test_the_simulator_s_limits_are_named_by_the_flag(
    flags: list[str], named: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["simulate", *flags, "--out", str(tmp_path / "rec.csv")]
    err = _error(argv, capsys)
    assert err.startswith(f"antenna simulate: error: {named}")
    assert "scenario." not in err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["beam", "--xc", "0.5", "--modes", "0"],
            "--modes: must be an integer from 1 to 50, got 0",
        ),
        (["beam", "--omega1", "-3"], "--omega1: must be a finite frequency > 0 rad/s, got -3.0"),
        (["identify", "r.csv", "--out", "a.toml", "--margin", "0.5"], "--margin: must be a"),
        (["estimate", "r.csv", "--method", "fast", "--tolerance", "nan"], "--tolerance: must be"),
        (["estimate", "r.csv", "--method", "fast", "--tolerance", "0"], "--tolerance: must be"),
        (["campaign", "run", "--out", "c", "--workers", "0"], "--workers: must be an integer >= 1"),
        # one file given twice would count twice, whatever its spelling
        (["map", "r.csv", "./r.csv", "--out", "m"], "recordings: r.csv given twice"),
        (["calibrate", "r.csv", "r.csv", "--out", "a.toml"], "recordings: r.csv given twice"),
        (["identify", "r.csv", "r.csv", "--out", "a.toml"], "recordings: r.csv given twice"),
        # a flipped axis first reads as an option
        (
            ["import", "rosbag", "x.bag", "--wrench", "/w", "--joints", "/j", "--frame", "-x,y,z"],
            "--frame: expected one argument (none followed it, or it began with '-', which "
            "reads as an option: write --frame=VALUE)",
        ),
    ],
)
def test_other_bad_arguments_name_their_flag(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert f": error: {message}" in _error(argv, capsys)


@pytest.mark.parametrize(
    ("value", "shown"),
    [
        (np.float64("nan"), "nan"),
        (np.float64(-0.3), "-0.3"),
        (np.int64(3), "3"),
        (np.bool_(True), "True"),
        (np.array(2.5), "2.5"),
        (float("inf"), "inf"),
        ("fx", "'fx'"),
    ],
)
def test_values_in_messages_are_shown_as_python_writes_them(value: object, shown: str) -> None:
    assert errors.format_value(value) == shown


def test_simulate_says_where_the_link_touched_and_what_was_asked(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(_simulate(tmp_path, "--case", "azimuthal", "--xc", "0.55")) == 0
    line = capsys.readouterr().out.strip()
    # the link bends as it pushes: it touches a little off the nominal 0.55 m
    # (docs/recording-format.md, true_xc: 0.3 to 2 mm nearer the base on this device)
    assert "the link touched at x_c = 0.54" in line
    assert "--xc 0.55 m is where the undeflected link meets the obstacle" in line


def test_simulate_says_when_the_link_touched_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the sweep reaches the obstacle after the vibration-free ramp, 0.1 s + 0.69 s
    # (docs/simulator.md): 0.5 s of simulated time ends before it
    argv = ["simulate", "--case", "azimuthal", "--xc", "0.55", "--duration", "0.5"]
    assert main([*argv, "--out", str(tmp_path / "rec.csv")]) == 0
    line = capsys.readouterr().out.strip()
    assert "no contact" in line and "0.5 s simulated" in line and "--duration" in line
    assert "nan" not in line


def test_the_range_is_the_antenna_s(capsys: pytest.CaptureFixture[str]) -> None:
    # the range comes from the link in use: the paper's is 0.98 m long
    assert paper_antenna().link.length == 0.98
    err = _error(["beam", "--xc", "0.99"], capsys)
    assert err == f"antenna beam: error: --xc: contact point must lie in {XC_RANGE}, got 0.99"


def test_an_output_directory_that_is_a_file_is_named_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recording = tmp_path / "r.csv"
    assert main(["simulate", "--case", "free", "--duration", "0.5", "--out", str(recording)]) == 0
    taken = tmp_path / "taken"
    taken.write_text("")
    capsys.readouterr()
    for out in (taken, taken / "sub"):
        assert main(["map", str(recording), "--out", str(out), "--no-progress"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and f"{out}: " in err
        assert "(a file where a directory is to be made?)" in err
    # and a UDP destination of port 0, which the system refuses as an invalid argument
    assert main(["replay", str(recording), "--udp", "127.0.0.1:0"]) == 2
    assert "--udp: port 0 is no destination" in capsys.readouterr().err


def test_one_file_by_two_names_is_given_twice(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a hard link and a symbolic one lead to the same file, which would count twice
    first = tmp_path / "a.csv"
    first.write_text("")
    (tmp_path / "hard.csv").hardlink_to(first)
    (tmp_path / "soft.csv").symlink_to(first)
    for other in ("hard.csv", "soft.csv"):
        assert main(["map", str(first), str(tmp_path / other), "--out", str(tmp_path / "m")]) == 2
        err = capsys.readouterr().err
        assert f"recordings: {tmp_path / other} given twice (as {first})" in err


def test_calibrating_a_real_devices_recordings_without_a_points_table_asks_for_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a real device writes no true_xc: what is missing is --points, said first
    from sensing_antenna.recording import write_recording
    from sensing_antenna.simulator import Scenario, simulate

    files = []
    for x_c in (0.4, 0.7):
        recording = simulate(paper_antenna(), Scenario(case="azimuthal", contact_point=x_c, seed=1))
        files.append(str(tmp_path / f"post-{x_c}.csv"))
        write_recording(recording.without_ground_truth(), files[-1])
    err = _error(["calibrate", *files, "--out", str(tmp_path / "a.toml")], capsys)
    assert ": error: --points: none given, and no recording states its contact point" in err
