"""``antenna simulate`` end to end: files, summary line, one-line errors."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from sensing_antenna.antenna import load_antenna
from sensing_antenna.cli import main
from sensing_antenna.estimation import estimate
from sensing_antenna.recording import read_recording, write_recording


def test_simulate_writes_a_readable_recording(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "rec.csv"
    code = main(
        [
            "simulate",
            "--case",
            "azimuthal",
            "--xc",
            "0.55",
            "--duration",
            "2.5",
            "--seed",
            "3",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    captured = capsys.readouterr()
    line = captured.out.strip()
    assert line.count("\n") == 0 and "x_c = 0.5" in line and "y_c / x_c = " in line
    assert captured.err == ""
    rec = read_recording(out)
    assert 0.0 < float(rec.metadata["true_deflection_ratio"]) < 0.1
    assert rec.n_samples == 2500
    assert rec.metadata["seed"] == "3"
    assert "theta1_ref" in rec.extra


def test_simulate_bad_input_is_one_line_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code = main(["simulate", "--case", "azimuthal", "--out", str(tmp_path / "r.csv")])
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert "--xc" in err and err.count("\n") == 0
    code = main(["simulate", "--case", "vertical", "--xc", "1.5", "--out", str(tmp_path / "r.csv")])
    assert code == 2
    assert "--xc" in capsys.readouterr().err


def test_simulate_warns_when_the_push_exceeds_the_small_deflection_limit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A detector with twice the paper's threshold (0.04 N m) notices the contact near the tip
    late: a quasi-static contact needs thr x_c / (3 E I) = 0.15 rad of head rotation before it
    fires (docs/simulator.md), so the push ends beyond the 10 % of Assumption 1."""
    antenna = tmp_path / "late.toml"
    antenna.write_text(
        'base = "paper-2021"\nname = "late"\n[observer]\ncontact_threshold = 0.04\n',
        encoding="utf-8",
    )
    out = tmp_path / "rec.csv"
    args = ["simulate", "--case", "azimuthal", "--xc", "0.98", "--duration", "2.5"]
    assert main([*args, "--antenna", str(antenna), "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert float(read_recording(out).metadata["true_deflection_ratio"]) > 0.1
    err = captured.err.strip()
    assert err.startswith("warning:") and err.count("\n") == 0
    assert "Assumption 1" in err and "antenna identify" in err and "--controller" in err
    # the same link, its controller given an identified file's threshold: detected on time
    identified = tmp_path / "identified.toml"
    identified.write_text(
        'base = "paper-2021"\nname = "identified"\n[observer]\ncontact_threshold = 0.002\n',
        encoding="utf-8",
    )
    controlled = [*args, "--antenna", str(antenna), "--controller", str(identified)]
    assert main([*controlled, "--out", str(out)]) == 0
    assert capsys.readouterr().err == ""
    assert float(read_recording(out).metadata["true_deflection_ratio"]) < 0.1


def test_simulate_warns_when_the_stop_leaves_no_spectrum_window(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The estimators need EstimatorConfig.spectrum_window (1 s) after t_1: a stop at about 1 s
    (the default push at x_c = 0.5 m) in 1.5 s of recording leaves half of it; the duration
    suggested gives antenna estimate its window."""
    short, long = tmp_path / "short.csv", tmp_path / "long.csv"
    common = ["simulate", "--case", "azimuthal", "--xc", "0.5"]
    assert main([*common, "--duration", "1.5", "--out", str(short)]) == 0
    err = capsys.readouterr().err.strip()
    assert err.startswith("warning: the motors stop at ") and err.count("\n") == 0
    assert "spectrum window" in err
    suggested = err.rsplit("--duration ", 1)[1].split()[0]
    assert main(["estimate", str(short)]) != 0 or "recording_too_short" in capsys.readouterr().out
    capsys.readouterr()
    assert main([*common, "--duration", suggested, "--out", str(long)]) == 0
    assert capsys.readouterr().err == ""
    main(["estimate", str(long)])
    assert "recording_too_short" not in capsys.readouterr().out
    # a retraction within the window is said the same way
    assert main([*common, "--retract-after", "0.3", "--out", str(long)]) == 0
    err = capsys.readouterr().err.strip()
    assert err.startswith("warning: --retract-after 0.3 s turns the head back before")
    assert err.endswith("--retract-after 1.1 leaves the whole window held")


def test_a_link_too_stiff_for_the_samples_is_said_and_not_explored(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a 0.2 m steel rod of 3 mm: its omega_1 band reaches 2,400 rad/s, and the estimators ask a
    # Nyquist frequency twice that, samples at 1.5 kHz. At the default 1 kHz the recording is
    # written, with one line saying so; an exploration, which would estimate nothing, stops
    # before it starts. Sampled at 2 kHz the link is read.
    steel = tmp_path / "steel.toml"
    steel.write_text(
        'name = "steel-20"\nbase = "paper-2021"\n[link]\nlength = 0.2\nradius = 1.5e-3\n'
        "youngs_modulus = 200e9\nlinear_density = 0.0555\n"
    )
    argv = ["simulate", "--case", "azimuthal", "--xc", "0.15", "--antenna", str(steel)]
    assert main([*argv, "--duration", "1.5", "--out", str(tmp_path / "s.csv")]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    warning = [line for line in err if line.startswith("warning: samples at 1000 Hz are too slow")]
    assert len(warning) == 1
    assert "needs samples at 1527 Hz or faster" in warning[0]
    assert warning[0].endswith("(--sample-rate)")
    assert main(["explore", "sphere", "--antenna", str(steel), "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1  # no banner for an exploration that cannot start
    assert err[0].startswith(
        "antenna explore: error: --antenna: steel-20: link: samples at 1000 Hz are too slow"
    )
    assert err[0].endswith("antenna explore simulates a device sampled at 1 kHz")
    fast = tmp_path / "fast.csv"
    assert main([*argv, "--duration", "2.5", "--sample-rate", "2000", "--out", str(fast)]) == 0
    assert "too slow" not in capsys.readouterr().err
    recording = read_recording(fast)
    assert float(recording.metadata["sample_period"]) == 5e-4
    result = estimate(recording, load_antenna(str(steel)), method="paper")
    # the answer is honest about the uncalibrated stiffness, but it reads the link: its best
    # guess within the 1 cm the estimators aim at
    assert abs(result.x_c - float(recording.metadata["true_xc"])) < 0.01
    assert (
        main(["simulate", "--case", "azimuthal", "--xc", "0.5", "--out", str(tmp_path / "p.csv")])
        == 0
    )
    assert "too slow" not in capsys.readouterr().err


def test_simulate_says_when_the_push_is_not_reached(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "far.csv"
    argv = ["simulate", "--case", "azimuthal", "--xc", "0.5", "--push", "3", "--duration", "1.5"]
    assert main([*argv, "--out", str(out)]) == 0
    line = capsys.readouterr().out
    assert "the push was not reached within --duration 1.5 s" in line
    assert "nan" not in line


def test_plot_recording_writes_pngs(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "rec.csv"
    assert (
        main(
            ["simulate", "--case", "vertical", "--xc", "0.8", "--duration", "2", "--out", str(out)]
        )
        == 0
    )
    capsys.readouterr()
    assert main(["plot", "recording", str(out), "--out", str(tmp_path / "fig")]) == 0
    names = sorted(p.name for p in (tmp_path / "fig").iterdir())
    assert names == ["angles.png", "force.png", "torque.png", "torque_spectrum.png"]
    assert all((tmp_path / "fig" / n).stat().st_size > 5000 for n in names)
    assert capsys.readouterr().err == ""
    # torques logged in N mm are drawn as recorded, and said to be off the format's units
    recording = read_recording(out)
    write_recording(dataclasses.replace(recording, torque=1000 * recording.torque), out)
    assert main(["plot", "recording", str(out), "--out", str(tmp_path / "fig")]) == 0
    err = capsys.readouterr().err
    assert err.startswith(f"antenna plot recording: warning: {out}: columns 'tx', 'ty', 'tz'")
    assert "torques in N mm" in err and err.count("\n") == 1


def test_plot_recording_says_the_torques_were_moved_to_o(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A file whose torques were taken about the sensor's origin and moved to O on reading or
    # import: drawn as the estimators read them, and said so
    out = tmp_path / "rec.csv"
    argv = ["simulate", "--case", "azimuthal", "--xc", "0.6", "--duration", "1.5"]
    assert main([*argv, "--out", str(out)]) == 0
    recording = read_recording(out)
    moved = {**recording.metadata, "torques_moved_from": "[-0.025, 0.0, 0.0]"}
    write_recording(dataclasses.replace(recording, metadata=moved), out)
    capsys.readouterr()
    assert main(["plot", "recording", str(out), "--out", str(tmp_path / "fig")]) == 0
    err = capsys.readouterr().err
    assert err == (
        f"antenna plot recording: {out}: torques drawn about O, moved from the sensor's point "
        "[-0.025, 0.0, 0.0] m (torques_moved_from), as the estimators read them\n"
    )


def _device_of(path: Path) -> dict[str, object]:
    import json

    simulation = json.loads(read_recording(path).metadata["simulation"])
    device: dict[str, object] = simulation["scenario"]["device"]
    return device


def test_simulate_device_profile_and_file(tmp_path: Path) -> None:
    """--device realistic draws from --seed (same seed, same device); a TOML file sets fields
    over the profile it names; both are written in the recording's simulation metadata."""
    base = ["simulate", "--case", "free", "--duration", "0.5"]
    first, again, other = tmp_path / "a.csv", tmp_path / "b.csv", tmp_path / "c.csv"
    assert main([*base, "--device", "realistic", "--seed", "4", "--out", str(first)]) == 0
    assert main([*base, "--device", "realistic", "--seed", "4", "--out", str(again)]) == 0
    assert main([*base, "--device", "realistic", "--seed", "5", "--out", str(other)]) == 0
    assert _device_of(first) == _device_of(again) != _device_of(other)
    assert _device_of(first)["clamp_stiffness"] is not None
    spec = tmp_path / "device.toml"
    spec.write_text('[device]\nprofile = "realistic"\ntip_mass = 2e-4\n', encoding="utf-8")
    out = tmp_path / "d.csv"
    assert main([*base, "--device", str(spec), "--seed", "4", "--out", str(out)]) == 0
    device = _device_of(out)
    assert device["tip_mass"] == 2e-4
    assert device["clamp_stiffness"] == _device_of(first)["clamp_stiffness"]
    nominal = tmp_path / "n.csv"
    assert main([*base, "--out", str(nominal)]) == 0
    assert _device_of(nominal)["clamp_stiffness"] is None
    # one build, two seeds: the same device, set up anew (the encoders' zero)
    built = tmp_path / "built.toml"
    built.write_text('profile = "realistic"\nbuild = 11\n', encoding="utf-8")
    one, two = tmp_path / "b1.csv", tmp_path / "b2.csv"
    assert main([*base, "--device", str(built), "--seed", "4", "--out", str(one)]) == 0
    assert main([*base, "--device", str(built), "--seed", "5", "--out", str(two)]) == 0
    assert _device_of(one)["clamp_stiffness"] == _device_of(two)["clamp_stiffness"]
    assert _device_of(one)["encoder_offset"] != _device_of(two)["encoder_offset"]


@pytest.mark.parametrize(
    "content, expected",
    [
        ("tip_mas = 1e-4\n", "device.tip_mas"),
        ("tip_mass = -1.0\n", "device.tip_mass"),
        ('profile = "perfect"\n', "profile"),
        ("tip_mass = [\n", "not a TOML file"),
        ('profile = "realistic"\nbuild = -2\n', "build must be an integer >= 0"),
    ],
)
def test_simulate_bad_device_file_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], content: str, expected: str
) -> None:
    spec = tmp_path / "device.toml"
    spec.write_text(content, encoding="utf-8")
    code = main(
        ["simulate", "--case", "free", "--device", str(spec), "--out", str(tmp_path / "r.csv")]
    )
    assert code != 0
    err = capsys.readouterr().err.strip()
    assert expected in err and err.count("\n") == 0


def test_a_deeper_push_bends_the_link_more_and_names_the_nonlinear_link(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    common = ["simulate", "--case", "azimuthal", "--xc", "0.5", "--duration", "3.5"]
    gentle, deep = tmp_path / "gentle.csv", tmp_path / "deep.csv"
    assert main([*common, "--out", str(gentle)]) == 0
    capsys.readouterr()
    assert main([*common, "--push", "0.15", "--commands", "--out", str(deep)]) == 0
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--link nonlinear" in err
    gentle_ratio = float(read_recording(gentle).metadata["true_deflection_ratio"])
    recording = read_recording(deep)
    # the head turns 0.15 rad past the first touch instead of 0.03: the tip of the link at
    # x_c is pushed about 0.15 x_c across, several times the default's bend
    assert float(recording.metadata["true_deflection_ratio"]) > 2.5 * gentle_ratio
    assert {"u1", "u2"} <= set(recording.extra)


def test_the_nonlinear_link_is_chosen_by_flag_without_the_linear_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "deep.csv"
    argv = ["simulate", "--case", "vertical", "--xc", "0.5", "--push", "0.15", "--link"]
    assert main([*argv, "nonlinear", "--duration", "3.5", "--out", str(out)]) == 0
    assert capsys.readouterr().err == ""
    assert '"link_model": "nonlinear"' in read_recording(out).metadata["simulation"]
    with pytest.raises(SystemExit) as exc:
        main([*argv, "curved", "--out", str(out)])
    assert exc.value.code == 2
