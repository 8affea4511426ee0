"""The antenna files ``antenna identify`` and ``antenna calibrate`` write: a new antenna of its own.

The file written is not the starting antenna: it is named after ``--out`` (or ``--name``) and
its description says which command made it from which recordings. A name that is not one line
of printable text (it would not survive as a one-line TOML string) is refused before anything
is computed or written.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from sensing_antenna.antenna import load_antenna, paper_antenna
from sensing_antenna.cli import main
from sensing_antenna.recording import write_recording
from sensing_antenna.simulator import Scenario, simulate


@pytest.fixture(scope="module")
def free_motion(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A simulated free motion, what ``antenna identify`` fits (as docs/simulator.md suggests)."""
    path = tmp_path_factory.mktemp("free") / "free-sweep.csv"
    recording = simulate(paper_antenna(), Scenario(case="free", duration=3.0, seed=1))
    write_recording(recording.without_ground_truth(), path)
    return path


@pytest.fixture(scope="module")
def contacts(tmp_path_factory: pytest.TempPathFactory) -> list[Path]:
    """Three simulated contacts with their true_xc, what ``antenna calibrate`` fits."""
    folder = tmp_path_factory.mktemp("contacts")
    paths = []
    for i, x_c in enumerate((0.4, 0.6, 0.8)):
        scenario = Scenario(case="azimuthal", contact_point=x_c, duration=2.0, seed=10 + i)
        paths.append(folder / f"contact-{i}.csv")
        write_recording(simulate(paper_antenna(), scenario), paths[-1])
    return paths


def test_identify_names_the_antenna_after_its_file(
    free_motion: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "lab-head.toml"
    assert main(["identify", str(free_motion), "--out", str(out)]) == 0
    capsys.readouterr()
    identified = load_antenna(out)
    assert identified.name == "lab-head"
    assert str(free_motion) in identified.description
    assert "identify" in identified.description and "paper-2021" in identified.description
    start = paper_antenna()
    assert identified.description != start.description
    assert identified.link == start.link and identified.observer != start.observer


def test_identify_takes_a_name(
    free_motion: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "a.toml"
    assert main(["identify", str(free_motion), "--out", str(out), "--name", "lab head 2"]) == 0
    capsys.readouterr()
    assert load_antenna(out).name == "lab head 2"


@pytest.mark.parametrize(
    ("flags", "flag"),
    [
        (["--name", "lab\nhead"], "--name"),
        (["--name", "lab\thead"], "--name"),
        (["--name", "  "], "--name"),
        ([], "--out"),  # the stem of --out, "lab\nhead", would be the name
    ],
)
def test_a_name_that_is_not_one_printable_line_is_refused(
    flags: list[str],
    flag: str,
    free_motion: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    out = tmp_path / "lab\nhead.toml" if flag == "--out" else tmp_path / "a.toml"
    for command in (["identify", str(free_motion)], ["calibrate", str(free_motion)]):
        assert main([*command, "--out", str(out), *flags]) == 2
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0
        assert err.startswith(f"antenna {command[0]}: error: {flag}: ")
        assert "one line of printable text" in err
        assert not out.exists()


def test_identify_refuses_a_starting_antenna_named_over_two_lines(
    free_motion: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a TOML name holding a newline (an escape in a TOML string) could not be the one-line
    # "# antenna:" metadata of a recording: the antenna file is refused, naming it and the field
    start = tmp_path / "start.toml"
    start.write_text('base = "paper-2021"\nname = "old\\nhead"\n', encoding="utf-8")
    out = tmp_path / "new.toml"
    assert main(["identify", str(free_motion), "--antenna", str(start), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    assert err.startswith(f"antenna identify: error: {start}: name: must be one line")
    assert not out.exists()


def test_calibrate_names_the_antenna_after_its_file(
    contacts: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "lab-calibrated.toml"
    assert main(["calibrate", *map(str, contacts), "--out", str(out)]) == 0
    capsys.readouterr()
    calibrated = load_antenna(out)
    assert calibrated.name == "lab-calibrated"
    assert calibrated.link.calibrated_t is not None
    assert "calibrate" in calibrated.description and "3 recording(s)" in calibrated.description
    assert all(str(path) in calibrated.description for path in contacts)
    assert calibrated.description != paper_antenna().description


def test_calibrate_goes_on_without_a_file_it_cannot_use(
    contacts: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A contact at the tip written as the sum of an abscissa and a rounding, a file that is not a
    # recording, and one without a known contact point: the set is calibrated from the rest
    tip = tmp_path / "tip.csv"
    text = contacts[2].read_text(encoding="utf-8")
    start = text.index("# true_xc:")
    end = text.index("\n", start)
    tip.write_text(f"{text[:start]}# true_xc: 0.9800000000000002{text[end:]}", encoding="utf-8")
    broken = tmp_path / "broken.csv"
    broken.write_text("not, a recording\n", encoding="utf-8")
    unknown = tmp_path / "unknown.csv"
    unknown.write_text(text[:start] + text[end + 1 :], encoding="utf-8")
    out = tmp_path / "set.toml"
    files = [*contacts[:2], tip, broken, unknown]
    assert main(["calibrate", *map(str, files), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"{tip}: x_c = 0.9800 m" in printed
    left_out = [line for line in printed.splitlines() if "left out:" in line]
    assert len(left_out) == 2
    assert str(broken) in left_out[0] and f"{unknown}: no known contact point" in left_out[1]
    assert "np.float64" not in printed
    assert "3 recording(s)" in load_antenna(out).description


def _calibrate_args(files: list[Path], known: tuple[float, ...], folder: Path) -> list[str]:
    """``antenna calibrate`` of ``files`` with a points table (``folder/points.csv``) giving
    each its ``known`` x_c (m), writing ``folder/set.toml``."""
    points = folder / "points.csv"
    rows = [f"{path.name},{x}" for path, x in zip(files, known, strict=True)]
    points.write_text("file,x_c\n" + "\n".join(rows) + "\n", encoding="utf-8")
    return [
        "calibrate",
        *map(str, files),
        "--points",
        str(points),
        "--out",
        str(folder / "set.toml"),
    ]


def test_calibrate_points_out_a_point_too_few_others_can_judge(
    contacts: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Three known points, the middle one written 5 cm short: below five points the fit cannot
    # leave it out as a wrong point, but the line says it lies far off the others
    assert main(_calibrate_args(contacts, (0.4, 0.55, 0.8), tmp_path)) == 0
    lines = capsys.readouterr().out.splitlines()
    flagged = [line for line in lines if "check it" in line]
    assert len(flagged) == 1 and f"{contacts[1]}: x_c = 0.5500 m" in flagged[0]


def test_calibrate_names_the_points_table_when_its_points_fit_no_curve(
    contacts: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The first and last known points swapped: no T_e puts the measured omega_1 near the
    # curve, and the refusal names the table the points came from, not the library's field
    assert main(_calibrate_args(contacts, (0.8, 0.55, 0.4), tmp_path)) != 0
    error = capsys.readouterr().err
    assert f"--points {tmp_path / 'points.csv'}: no calibration:" in error
    assert "contact_points" not in error
    assert not (tmp_path / "set.toml").exists()


def test_calibrate_keeps_a_point_it_left_out_out_of_the_sensor_fit(
    contacts: list[Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Five known points, one written 5 cm short: the T_e fit leaves it out as a wrong point,
    # and the sensor's fit leaves it out by name, not as a point without a known contact
    more = []
    for i, x_c in enumerate((0.5, 0.7)):
        scenario = Scenario(case="azimuthal", contact_point=x_c, duration=2.0, seed=20 + i)
        more.append(tmp_path / f"more-{i}.csv")
        write_recording(simulate(paper_antenna(), scenario), more[-1])
    assert main(_calibrate_args([*contacts, *more], (0.4, 0.55, 0.8, 0.5, 0.7), tmp_path)) == 0
    printed = capsys.readouterr().out
    assert f"{contacts[1]}: x_c = 0.5500 m" in printed and "left out of the fit" in printed
    assert f"sensor, left out: {contacts[1]}: a wrong spectral peak or known point" in printed
    assert "no known contact point" not in printed
