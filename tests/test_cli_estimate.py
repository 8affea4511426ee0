"""The ``antenna estimate`` and ``antenna plot estimate`` commands on recording files."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from _models import calibrated
from sensing_antenna.antenna import save_antenna
from sensing_antenna.cli import main
from sensing_antenna.estimation import METHODS, estimate
from sensing_antenna.recording import read_recording, write_recording
from test_estimation_pipeline import Synthetic, synthetic_recording


@pytest.fixture(scope="module")
def recording_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("rec") / "rec.csv"
    write_recording(synthetic_recording(Synthetic(x_c=0.62, seed=21)), path)
    return path


def test_json_output_matches_library(
    recording_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    model = tmp_path / "model.toml"
    save_antenna(calibrated(), model)
    assert main(["estimate", str(recording_file), "--json", "--antenna", str(model)]) == 0
    data = json.loads(capsys.readouterr().out)
    library = estimate(read_recording(recording_file), calibrated()).to_dict()
    for key in ("x_c", "candidates", "omega1", "ratio_estimate", "t_c", "t_1", "t_e", "status"):
        assert data[key] == library[key]
    assert data["reason"] is None and data["status"] == "ok"
    assert data["x_c"] == pytest.approx(0.62, abs=5e-3)  # built into the recording
    assert len(data["contact_point"]) == 3


def test_the_built_in_nominal_antenna_answers_uncertain_until_calibrated(
    recording_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # paper-2021 is Table 2's material data: T known to 5 %, which moves the frequency's
    # contact point at 0.62 m by centimetres; the same number, flagged, with the remedy
    assert main(["estimate", str(recording_file), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["status"] == "uncertain" and "calibrate the antenna" in data["reason"]
    assert data["x_c"] == pytest.approx(0.62, abs=5e-3)


@pytest.mark.parametrize("method", sorted(METHODS))
def test_every_method_and_summary(
    recording_file: Path, method: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["estimate", str(recording_file), "--method", method]) == 0
    out = capsys.readouterr().out
    assert f"method {method}" in out and "status" in out and "x_c" in out


def test_a_ratio_no_link_has_prints_to_four_digits(
    recording_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the torque about Z^m in N cm: the ratio reads 10^19 m, printed to four digits (to the
    # millimetre it would fill a line with digits of noise)
    recording = read_recording(recording_file)
    scaled = tmp_path / "scaled.csv"
    torque = recording.torque * [1.0, 1.0, 100.0]
    write_recording(dataclasses.replace(recording, torque=torque), scaled)
    assert main(["estimate", str(scaled)]) == 0
    (line,) = [text for text in capsys.readouterr().out.splitlines() if "ratio estimate" in text]
    assert "e+" in line and len(line.split()[-2]) <= 10, line


def test_malformed_file_is_one_line_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("t,theta1,theta2,fx,fy,fz,tx,ty,tz\n0,0,0,0,0,0,0,0,0\n0.001,0,x,0,0,0,0,0,0\n")
    assert main(["estimate", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "bad.csv" in err and "theta2" in err


def test_unknown_method_is_rejected(recording_file: Path) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["estimate", str(recording_file), "--method", "magic"])
    assert exc.value.code == 2


def test_a_tolerance_no_contact_point_needs_is_rejected(
    recording_file: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # 5 meant as mm, or 1000: any interval would do, and every answer came back ok
    for value in ("5", "1000"):
        with pytest.raises(SystemExit) as exc:
            main(["estimate", str(recording_file), "--method", "fast", "--tolerance", value])
        assert exc.value.code == 2
        assert "--tolerance: must be a finite number in (0, 0.1] m" in capsys.readouterr().err


def test_plot_estimate_writes_four_figures(recording_file: Path, tmp_path: Path) -> None:
    out = tmp_path / "figs"
    assert main(["plot", "estimate", str(recording_file), "--out", str(out)]) == 0
    names = sorted(p.name for p in out.glob("*.png"))
    assert names == [
        "figure11-contact.png",
        "figure12-push.png",
        "figure13-frequency.png",
        "figure14-ratio.png",
    ]
    assert all((out / n).stat().st_size > 10_000 for n in names)


def test_plot_estimate_says_why_figures_13_and_14_are_missing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    free = tmp_path / "free.csv"
    write_recording(
        synthetic_recording(Synthetic(contact_time=50.0, stops=False, duration=2.0)), free
    )
    out = tmp_path / "figs"
    assert main(["plot", "estimate", str(free), "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert sorted(p.name for p in out.glob("*.png")) == [
        "figure11-contact.png",
        "figure12-push.png",
    ]
    err = captured.err.strip()
    assert "\n" not in err and "figures 13 and 14 not drawn" in err and "no_contact" in err
    assert "figure13" not in captured.out


def test_a_sample_period_the_time_stamps_contradict_is_warned_of(
    recording_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the stamps 1 ms apart, the metadata says 2 ms: the estimate goes by the stamps and says so
    off = tmp_path / "off.csv"
    write_recording(read_recording(recording_file).with_metadata(sample_period="0.002"), off)
    model = tmp_path / "model.toml"  # the recording's own link, calibrated
    save_antenna(calibrated(), model)
    assert main(["estimate", str(off), "--antenna", str(model), "--json"]) == 0
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and str(off) in captured.err
    assert "'sample_period'" in captured.err and "0.001 s" in captured.err
    assert json.loads(captured.out)["status"] == "ok"
    assert main(["estimate", str(recording_file), "--antenna", str(model)]) == 0
    assert capsys.readouterr().err == ""


def test_a_recording_of_another_antenna_estimated_with_the_default_is_warned_of(
    recording_file: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    other = tmp_path / "other.csv"
    write_recording(read_recording(recording_file).with_metadata(antenna="lab-head"), other)
    assert main(["estimate", str(other)]) == 0
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0
    assert "recorded with antenna 'lab-head'" in err and "--antenna" in err
    model = tmp_path / "lab-head.toml"
    save_antenna(calibrated(), model)
    assert main(["estimate", str(other), "--antenna", str(model)]) == 0
    assert capsys.readouterr().err == ""  # the user chose the model
    # the default named on the command line is chosen too
    assert main(["estimate", str(other), "--antenna", "paper-2021"]) == 0
    assert capsys.readouterr().err == ""
    # the figures of a recording fall back on the default antenna alike, and say so
    for kind, use in (("recording", "checked"), ("estimate", "estimated")):
        figures = tmp_path / kind
        assert main(["plot", kind, str(other), "--out", str(figures)]) == 0
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and "recorded with antenna 'lab-head'" in err
        assert f"{use} with the default 'paper-2021'" in err
        assert main(["plot", kind, str(other), "--out", str(figures), "--antenna", str(model)]) == 0
        assert capsys.readouterr().err == ""
