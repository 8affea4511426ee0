"""Tests of the motor fit of Eq. 1 (calibration/motor.py), `antenna identify --servo`, and the
simulator's optional command columns and command limit."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

from sensing_antenna.antenna import STANDARD_GRAVITY, Antenna, load_antenna, paper_antenna
from sensing_antenna.calibration.motor import identify_motors
from sensing_antenna.calibration.observer import IdentificationError
from sensing_antenna.cli import main
from sensing_antenna.control import HeadController, coupling_torques
from sensing_antenna.control.servo import design_servo
from sensing_antenna.recording import (
    COMMAND_COLUMNS,
    CONTACT_TRACK_COLUMNS,
    Recording,
    read_recording,
    write_recording,
)
from sensing_antenna.simulator import Scenario, simulate, simulate_detailed

TS = 1e-3  # s
PAPER = paper_antenna()


def _with_motors(antenna: Antenna, **changes: tuple[float, float]) -> Antenna:
    """``antenna`` whose motors' fields take the (joint 1, joint 2) values given."""
    motors = list(antenna.motors)
    for name, values in changes.items():
        motors = [dataclasses.replace(m, **{name: v}) for m, v in zip(motors, values, strict=True)]
    return dataclasses.replace(antenna, azimuth_motor=motors[0], elevation_motor=motors[1])


# A head whose motors are not the paper's (Table 1: J = 6.2e-3, 1.8e-3 kg m^2; v = 30.4e-3,
# 28.5e-3 N m s/rad; V_nlc = 0.48, 0.42 V): the fit must find these, not the starting antenna's.
TRUE = _with_motors(
    PAPER,
    inertia=(8.0e-3, 2.5e-3),
    viscous_friction=(20.0e-3, 40.0e-3),
    coulomb_voltage=(0.3, 0.6),
)


def _moves(t: np.ndarray, times: list[float], targets: list[float], duration: float) -> np.ndarray:
    """Piecewise minimum-jerk moves (rad): from rest, to each target starting at each time."""
    out = np.zeros_like(t)
    previous = 0.0
    for start, target in zip(times, targets, strict=True):
        s = np.clip((t - start) / duration, 0.0, 1.0)
        out += (target - previous) * s**3 * (10 - 15 * s + 6 * s**2)
        previous = target
    return out


def _eq1_recording(antenna: Antenna) -> Recording:
    """Both joints of Eq. 1 without Coulomb friction, integrated exactly over each held command
    (matrix exponential), under a HeadController following back-and-forth moves; the elevation
    carries the link's weight as its coupling torque, measured exactly. Independent of the
    device simulator: the fit's own bias shows here."""
    n = 4000
    t = TS * np.arange(n)
    reference = np.column_stack(
        [
            _moves(t, [0.2, 1.2, 2.2, 3.0], [0.4, -0.2, 0.3, 0.0], 0.5),
            _moves(t, [0.5, 1.5, 2.5, 3.2], [0.2, -0.1, 0.25, 0.05], 0.4),
        ]
    )
    controller = HeadController(antenna, sample_period=TS)
    controller.reset(origin=(0.0, 0.0))
    transitions = [
        expm(
            np.array([[0, 1, 0], [0, -m.viscous_friction / m.inertia, 1 / m.inertia], [0, 0, 0]])
            * TS
        )
        for m in antenna.motors
    ]
    weight = antenna.link.mass * STANDARD_GRAVITY
    moment = 0.5 * weight * antenna.link.length
    state = np.zeros((2, 2))
    theta = np.zeros((n, 2))
    voltage = np.zeros((n, 2))
    for k in range(n):
        theta[k] = state[:, 0]
        load = (0.0, moment * np.cos(theta[k, 1]))
        torque = controller.step(reference[k], theta[k], load)
        voltage[k] = controller.voltage(torque)
        for j in range(2):
            state[j] = (transitions[j] @ [*state[j], torque[j] - load[j]])[:2]
    force = np.column_stack(
        [-weight * np.sin(theta[:, 1]), np.zeros(n), -weight * np.cos(theta[:, 1])]
    )
    torque_m = np.column_stack([np.zeros(n), moment * np.cos(theta[:, 1]), np.zeros(n)])
    return Recording(
        t=t,
        theta=theta,
        force=force,
        torque=torque_m,
        metadata={"sample_period": "0.001"},
        extra={"u1": voltage[:, 0], "u2": voltage[:, 1]},
        source="eq1.csv",
    )


def test_recovers_eq1_of_both_joints_from_exact_data() -> None:
    truth = _with_motors(TRUE, coulomb_voltage=(0.0, 0.0))
    fit = identify_motors(_eq1_recording(truth), PAPER)
    assert [j.joint for j in fit.joints] == [1, 2]
    for joint, motor in zip(fit.joints, truth.motors, strict=True):
        # The filter's input between samples is the angle's straight line: a bias of about
        # (lambda T_s)^2 = 0.25 % at most, 0.02 % measured; 0.1 % leaves room for rounding
        assert joint.inertia == pytest.approx(motor.inertia, rel=1e-3)
        assert joint.viscous_friction == pytest.approx(motor.viscous_friction, rel=1e-3)
        # no Coulomb friction in these data: below 0.1 % of the paper motor's sliding torque
        assert abs(joint.coulomb_torque) < 1e-3 * PAPER.azimuth_motor.coulomb_torque


@pytest.mark.parametrize(
    ("scenario", "joint"),
    [
        (Scenario(case="free"), 1),
        (Scenario(case="free", sweep_speed=1.0, accel_time=0.2), 1),
        (Scenario(case="vertical", contact_point=0.5), 2),
    ],
    ids=["free-slow", "free-fast", "vertical-contact"],
)
def test_recovers_the_simulated_device_motors(scenario: Scenario, joint: int) -> None:
    """The device simulator (FE link, sensor noise, encoder steps, regularised Coulomb friction)
    running motors unlike the starting antenna's: the fit finds them within three of its own
    standard errors, which stay below 10 % of J (the motion is slow: the sweep accelerates at
    most 0.8 rad/s^2 at the default speed)."""
    recording = simulate(TRUE, scenario, record_commands=True)
    fit = identify_motors(recording, PAPER)
    assert [j.joint for j in fit.joints] == [joint]
    assert [j for j, _ in fit.skipped] == [3 - joint]
    found = fit.joints[0]
    motor = TRUE.motors[joint - 1]
    assert found.inertia_error < 0.1 * motor.inertia
    assert abs(found.inertia - motor.inertia) < 3 * found.inertia_error
    assert abs(found.viscous_friction - motor.viscous_friction) < 3 * found.viscous_error
    assert abs(found.coulomb_torque - motor.coulomb_torque) < 3 * found.coulomb_error
    # the fitted antenna: the fitted joint's motor changes, the other stays the starting one's
    fitted = fit.antenna(PAPER)
    assert fitted.motors[joint - 1].inertia == found.inertia
    assert fitted.motors[2 - joint] == PAPER.motors[2 - joint]


def test_a_recording_without_commands_is_one_clear_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    recording = simulate(PAPER, Scenario(case="free"))
    with pytest.raises(IdentificationError, match="'u1', 'u2' missing"):
        identify_motors(recording, PAPER)
    path = tmp_path / "free.csv"
    write_recording(recording, path)
    out = tmp_path / "x.toml"
    assert main(["identify", str(path), "--out", str(out), "--servo"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "free.csv: columns 'u1', 'u2' missing" in err
    assert "without the motor commands" in err
    assert not out.exists()
    # without --servo the same recording identifies the observer as before
    assert main(["identify", str(path), "--out", str(out)]) == 0
    assert "Eq. 1:" not in capsys.readouterr().out


def _free_motion(antenna: Antenna, folder: Path) -> Path:
    """A simulated free motion of ``antenna`` with its motor commands, written to ``folder``."""
    path = folder / "free.csv"
    write_recording(simulate(antenna, Scenario(case="free"), record_commands=True), path)
    return path


def test_cli_writes_the_fitted_motors_and_prints_their_gains(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _free_motion(TRUE, tmp_path)
    out = tmp_path / "lab.toml"
    # the form the help gives for a pole in exponent form
    assert main(["identify", str(path), "--out", str(out), "--servo", "--servo-pole=-4e1"]) == 0
    text = capsys.readouterr().out
    written = load_antenna(out)
    fit = identify_motors(read_recording(path), PAPER)
    assert written.azimuth_motor == fit.joints[0].motor(PAPER.azimuth_motor)
    assert written.elevation_motor == PAPER.elevation_motor
    assert "joint 2 (elevation), Eq. 1: not fitted" in text
    # the gains printed are the pole placement on the written motors
    design = design_servo(written.azimuth_motor, -40.0, TS)
    assert f"b = {design.b:.6g} rad/s" in text
    assert f"({', '.join(f'{c:.6g}' for c in design.feedback)})" in text
    assert "and the motors of joint 1 identified" in written.description


def test_cli_fits_each_joints_motor_from_the_recording_that_moves_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A free sweep of each joint: joint 1 from the azimuthal one, joint 2 from the vertical
    # one, each line naming its recording; the observer from both, as without --servo
    paths = []
    for case in ("free", "free-vertical"):
        paths.append(tmp_path / f"{case}.csv")
        write_recording(simulate(TRUE, Scenario(case=case), record_commands=True), paths[-1])
    out = tmp_path / "lab.toml"
    assert main(["identify", *map(str, paths), "--out", str(out), "--servo"]) == 0
    text = capsys.readouterr().out
    written = load_antenna(out)
    azimuth, elevation = (identify_motors(read_recording(p), PAPER).joints[0] for p in paths)
    assert (azimuth.joint, elevation.joint) == (1, 2)
    assert written.azimuth_motor == azimuth.motor(PAPER.azimuth_motor)
    assert written.elevation_motor == elevation.motor(PAPER.elevation_motor)
    assert f"joint 1 (azimuth), Eq. 1 (from {paths[0]}):" in text
    assert f"joint 2 (elevation), Eq. 1 (from {paths[1]}):" in text
    assert "not fitted" not in text
    assert "joints used: theta1, theta2" in text
    # each within three of its fit's standard errors of the device's own motor, as a single
    # recording's fit is (test_recovers_the_simulated_device_motors)
    for joint, true in zip((azimuth, elevation), TRUE.motors, strict=True):
        assert abs(joint.inertia - true.inertia) < 3 * joint.inertia_error


def test_cli_refuses_motors_fitted_from_recordings_of_two_loop_periods(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The servo's gains are designed at one period: a second sweep logged every other sample
    # (2 ms) is named, in one line, and nothing is written
    free = simulate(TRUE, Scenario(case="free"), record_commands=True)
    vertical = simulate(TRUE, Scenario(case="free-vertical"), record_commands=True)
    metadata = {k: v for k, v in vertical.metadata.items() if k != "sample_period"}
    halved = dataclasses.replace(
        vertical,
        t=vertical.t[::2],
        theta=vertical.theta[::2],
        force=vertical.force[::2],
        torque=vertical.torque[::2],
        extra={name: column[::2] for name, column in vertical.extra.items()},
        metadata=metadata,
    )
    paths = [tmp_path / "free.csv", tmp_path / "vertical-2ms.csv"]
    for recording, path in zip((free, halved), paths, strict=True):
        write_recording(recording, path)
    out = tmp_path / "lab.toml"
    assert main(["identify", *map(str, paths), "--out", str(out), "--servo"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert f"{paths[1]}: sampled every 0.002 s, {paths[0]} every 0.001 s" in err
    assert not out.exists()


def test_cli_fits_the_motors_on_a_sweep_into_an_object_and_keeps_the_observer(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A sweep into a bar fits the elevation's Eq. 1 (docs/control.md), while its static contact
    # torque is no free motion for the observer: the motors are written, the observer kept
    path = tmp_path / "bar.csv"
    recording = simulate(TRUE, Scenario(case="vertical", contact_point=0.5), record_commands=True)
    write_recording(recording, path)
    assert main(["identify", str(path), "--out", str(tmp_path / "observer.toml")]) == 2
    assert "is this really free motion?" in capsys.readouterr().err
    out = tmp_path / "lab.toml"
    assert main(["identify", str(path), "--out", str(out), "--servo"]) == 0
    text = capsys.readouterr().out
    written = load_antenna(out)
    assert "observer: not identified" in text and "observer and contact threshold kept" in text
    assert written.observer == PAPER.observer
    fit = identify_motors(read_recording(path), PAPER)
    assert written.elevation_motor == fit.joints[0].motor(PAPER.elevation_motor)


def test_servo_pole_needs_servo(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _free_motion(PAPER, tmp_path)
    assert (
        main(["identify", str(path), "--out", str(tmp_path / "x.toml"), "--servo-pole", "-40"]) == 2
    )
    assert "--servo-pole" in capsys.readouterr().err


@pytest.mark.parametrize("pole", ["5", "0", "-0", "nan", "-inf"])
def test_servo_pole_has_one_bound_and_one_message(
    pole: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Eq. 14's closed loop is stable for p < 0 only: every other value gets the same line."""
    out = tmp_path / "x.toml"
    argv = ["identify", "free.csv", "--out", str(out), "--servo", f"--servo-pole={pole}"]
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith("antenna identify: error: --servo-pole: must be a finite number < 0 ")
    assert "rad/s (a stable pole), got " in err[-1]
    assert not out.exists()


def test_a_servo_pole_too_fast_for_the_recordings_period_is_refused_before_any_fit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _free_motion(PAPER, tmp_path)
    out = tmp_path / "x.toml"
    argv = ["identify", str(path), "--out", str(out), "--servo", "--servo-pole=-3000"]
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == ""  # nothing fitted, nothing printed
    assert captured.err.strip() == (
        "antenna identify: error: --servo-pole: -3000 rad/s is too fast for the controller's "
        "period 0.001 s (|p| T_s = 3, more than 0.3: its discrete form no longer follows the "
        "design); at most 300 rad/s in magnitude"
    )
    assert not out.exists()


def test_a_still_recording_fits_no_joint() -> None:
    recording = simulate(PAPER, Scenario(case="free"), record_commands=True)
    still = Recording(
        t=recording.t[:80],
        theta=recording.theta[:80],
        force=recording.force[:80],
        torque=recording.torque[:80],
        metadata=recording.without_ground_truth().metadata,
        extra={name: recording.extra[name][:80] for name in COMMAND_COLUMNS},
        source="still.csv",
    )
    with pytest.raises(IdentificationError, match=r"no joint's Eq\. 1 could be fitted"):
        identify_motors(still, PAPER)


def test_a_command_of_the_wrong_sign_is_named() -> None:
    recording = simulate(PAPER, Scenario(case="free"), record_commands=True)
    flipped = dict(recording.extra)
    flipped["u1"] = -flipped["u1"]
    wrong = dataclasses.replace(recording, extra=flipped, source="flipped.csv")
    with pytest.raises(IdentificationError, match="not a positive inertia: does column 'u1'"):
        identify_motors(wrong, PAPER)


def test_commands_in_millivolts_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """u1, u2 in mV fit a J a thousand times the motor's (Eq. 1 is linear in u): far beyond the
    factor 5 around the antenna file's motor J plus the rigid link's inertia (Table 1: 6.2e-3
    kg m^2, the link's m_b l^2 / 3 + m_t l^2 about 1.5e-3), while a head whose motor J is 30 %
    off the file's (TRUE, tested above) is fitted."""
    recording = simulate(PAPER, Scenario(case="free"), record_commands=True)
    millivolts = dict(recording.extra)
    for name in COMMAND_COLUMNS:
        millivolts[name] = 1e3 * millivolts[name]
    path = tmp_path / "mv.csv"
    write_recording(dataclasses.replace(recording, extra=millivolts), path)
    out = tmp_path / "mv.toml"
    assert main(["identify", str(path), "--out", str(out), "--servo"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "mv.csv: column 'u1'" in err
    assert "in V (not mV)" in err
    assert not out.exists()


def test_simulator_writes_commands_only_when_asked() -> None:
    scenario = Scenario(case="azimuthal", contact_point=0.6)
    plain = simulate(PAPER, scenario)
    detail = simulate_detailed(PAPER, scenario, record_commands=True)
    assert list(plain.extra) == ["theta1_ref", "theta2_ref", *CONTACT_TRACK_COLUMNS]
    assert list(detail.recording.extra) == [
        "theta1_ref",
        "theta2_ref",
        *CONTACT_TRACK_COLUMNS,
        "u1",
        "u2",
    ]
    np.testing.assert_array_equal(detail.recording.extra["u1"], detail.voltage[:, 0])
    np.testing.assert_array_equal(detail.recording.extra["u2"], detail.voltage[:, 1])
    # everything else is the default recording's, to the bit
    without = dict(detail.recording.extra)
    del without["u1"], without["u2"]
    assert dataclasses.replace(detail.recording, extra=without) == plain


def test_simulator_limit_runs_the_library_controller_to_the_bit() -> None:
    # the vertical push needs up to 0.19 N m of the elevation motor: 0.16 clips it
    limits = (1.0, 0.16)
    scenario = Scenario(case="vertical", contact_point=0.5)
    detail = simulate_detailed(PAPER, scenario, torque_limit=limits)
    rec = detail.recording
    controller = HeadController(PAPER, TS, pole=scenario.servo_pole, torque_limit=limits)
    reference = np.column_stack([rec.extra["theta1_ref"], rec.extra["theta2_ref"]])
    commands = controller.step_block(reference, rec.theta, coupling_torques(rec.theta, rec.torque))
    np.testing.assert_array_equal(controller.voltage(commands), detail.voltage)
    assert np.sum(np.abs(commands[:, 1]) == limits[1]) > 10
    assert '"torque_limit": [1.0, 0.16]' in rec.metadata["simulation"]
    # without a limit the simulation metadata says nothing of one
    assert "torque_limit" not in simulate(PAPER, scenario).metadata["simulation"]
