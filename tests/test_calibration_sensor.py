"""The F/T sensor's cross-talk correction: its algebra, its file section, and its calibration
from contacts at known points on a simulated device whose sensor leaks its torques into its
forces."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from sensing_antenna.antenna import (
    AntennaConfigError,
    SensorCorrection,
    load_antenna,
    paper_antenna,
    save_antenna,
)
from sensing_antenna.calibration.sensor import SensorCalibrationError, calibrate_sensor
from sensing_antenna.cli import main
from sensing_antenna.estimation import estimate
from sensing_antenna.recording import write_recording
from sensing_antenna.simulator import DeviceImperfections, Scenario, simulate

ANTENNA = paper_antenna().self_calibrated()

#: A sensor whose torque channels leak into its lateral forces: 0.6 N per N m from tz into fy
#: and -0.8 from ty into fz (0.6 % and 0.6 % of full scale on an ATI Nano17, whose force
#: ranges are 100 and 140 times its torque range), and 0.5 across the planes.
_COUPLING = np.zeros((6, 6))
_COUPLING[1, 5], _COUPLING[2, 4] = 0.6, -0.8
_COUPLING[1, 4], _COUPLING[2, 5] = 0.5, -0.5
LEAKY = DeviceImperfections(
    sensor_coupling=tuple(tuple(float(c) for c in row) for row in _COUPLING)
)

POINTS = (0.3, 0.45, 0.6, 0.75, 0.9, 0.98)


def _recordings(
    points: tuple[float, ...], seed: int, device: DeviceImperfections = LEAKY
) -> tuple[list, list[float]]:  # type: ignore[type-arg]
    recordings, truth = [], []
    for k, case in enumerate(("azimuthal", "vertical")):
        for i, x in enumerate(points):
            scenario = Scenario(case=case, contact_point=x, seed=seed + 10 * k + i, device=device)
            recording = simulate(ANTENNA, scenario)
            truth.append(float(recording.metadata["true_xc"]))
            recordings.append(recording.without_ground_truth())
    return recordings, truth


@pytest.fixture(scope="module")
def calibration_set() -> tuple[list, list[float]]:  # type: ignore[type-arg]
    return _recordings(POINTS, 100)


def test_correction_is_the_documented_linear_map() -> None:
    correction = SensorCorrection(
        fy_gain=1.1, fz_gain=0.9, fy_per_ty=0.2, fy_per_tz=-0.3, fz_per_ty=0.4, fz_per_tz=0.5
    )
    reaction = np.array([[0.01, -0.05, 0.02]])
    moment = np.array([[0.001, 0.02, -0.03]])
    out = correction.correct(reaction, moment)
    assert out[0, 0] == reaction[0, 0]  # the axial force is not touched
    assert out[0, 1] == pytest.approx(1.1 * -0.05 + 0.2 * 0.02 - 0.3 * -0.03)
    assert out[0, 2] == pytest.approx(0.9 * 0.02 + 0.4 * 0.02 + 0.5 * -0.03)
    assert SensorCorrection().correct(reaction, moment) is reaction


def test_sensor_section_round_trips_and_bad_values_name_the_field(tmp_path: Path) -> None:
    antenna = dataclasses.replace(
        ANTENNA, sensor=SensorCorrection(fy_per_tz=-0.6, ratio_scatter=0.03)
    )
    path = tmp_path / "a.toml"
    save_antenna(antenna, path)
    assert "[sensor]" in path.read_text()
    assert load_antenna(path).sensor == antenna.sensor
    save_antenna(paper_antenna(), path)
    assert "[sensor]" not in path.read_text()  # no correction, no section
    # a device identical to its model fears no cross-talk, and says so in its file
    save_antenna(ANTENNA, path)
    assert load_antenna(path).sensor.coupling_uncertainty([0.0, 0.1, 0.1]) == 0.0
    # the sweep directions no calibration saw, kept in order and read back
    one_way = dataclasses.replace(
        antenna, sensor=dataclasses.replace(antenna.sensor, unmeasured_sweeps=["vertical"])
    )  # type: ignore[arg-type]
    assert one_way.sensor.unmeasured_sweeps == ("vertical",)
    save_antenna(one_way, path)
    assert load_antenna(path).sensor == one_way.sensor
    for text, field in (
        ("[sensor]\nfy_gain = 3.0\n", "sensor.fy_gain"),
        ("[sensor]\nfz_per_ty = 1e4\n", "sensor.fz_per_ty"),
        ("[sensor]\nfx_gain = 1.0\n", "sensor.fx_gain"),
        ("[sensor]\nratio_scatter = -0.1\n", "sensor.ratio_scatter"),
        ('[sensor]\nunmeasured_sweeps = ["sideways"]\n', "sensor.unmeasured_sweeps"),
        ('[sensor]\nunmeasured_sweeps = "vertical"\n', "sensor.unmeasured_sweeps"),
        ('[sensor]\nunmeasured_sweeps = [["vertical"]]\n', "sensor.unmeasured_sweeps"),
    ):
        path.write_text('base = "paper-2021"\n' + text)
        with pytest.raises(AntennaConfigError, match=field):
            load_antenna(path)


def test_calibration_undoes_the_cross_talk_on_new_contacts(
    calibration_set: tuple[list, list[float]],  # type: ignore[type-arg]
) -> None:
    recordings, truth = calibration_set
    fit = calibrate_sensor(recordings, ANTENNA, truth)
    assert fit.sweeps == ("azimuthal", "vertical")
    # the coupling shrinks the ratio by tens of per cent; corrected, what is left is the
    # ratio's own noise at the default gentle push (a few per cent)
    assert fit.ratio_rms_before > 0.15
    assert fit.ratio_rms_after < 0.05
    # and it predicts each contact left out of the fit: adopted
    assert fit.adopted == ("azimuthal", "vertical") and fit.ratio_rms_held_out < 0.05
    # the scatter left is kept as the ratio's model floor: its rms over the degrees of freedom
    n = len(truth)
    expected = fit.ratio_rms_after * (n / (n - 4)) ** 0.5
    assert fit.correction.ratio_scatter == pytest.approx(expected, rel=1e-6)
    # the cross-plane terms are read directly from the push's direction: within 20 % of the
    # leak they undo
    assert fit.correction.fz_per_tz == pytest.approx(0.5, rel=0.2)
    assert fit.correction.fy_per_ty == pytest.approx(-0.5, rel=0.2)
    corrected = fit.apply(ANTENNA)
    new, new_truth = _recordings((0.4, 0.7), 500)
    for recording, x_c in zip(new, new_truth, strict=True):
        before = estimate(recording, ANTENNA, "ratio").ratio_estimate
        after = estimate(recording, corrected, "ratio").ratio_estimate
        assert abs(before / x_c - 1) > 0.1
        # 8 %: three times the ratio's scatter left on the calibration set
        assert abs(after / x_c - 1) < 0.08
        assert estimate(recording, corrected, "paper").status.value == "ok"


@pytest.mark.parametrize("unit", ["tz in N dm", "forces in lbf"])
def test_one_recording_with_its_loads_in_another_unit_is_left_out(
    unit: str,
    calibration_set: tuple[list, list[float]],  # type: ignore[type-arg]
) -> None:
    # tz in N dm among N m (ten times), or the forces in lbf (4.45 times too small): no leak
    # explains one contact's ratio several times off while the others' fit within per cents,
    # and torques ten times high take a tenth of the head's work the push needs; left out,
    # named, the correction is the others'
    recordings, truth = calibration_set
    names = [f"c{i}.csv" for i in range(len(recordings))]
    bad = list(recordings)
    if unit == "tz in N dm":
        bad[2] = dataclasses.replace(recordings[2], torque=recordings[2].torque * [1, 1, 10])
    else:
        bad[2] = dataclasses.replace(recordings[2], force=recordings[2].force / 4.448)
    fit = calibrate_sensor(bad, ANTENNA, truth, sources=names)
    assert "c2.csv" not in fit.sources and len(fit.sources) == len(names) - 1
    (note,) = [n for n in fit.notes if n.startswith("c2.csv: ")]
    if unit == "tz in N dm":
        # the push's moment ten times its work: refused as an estimate would be
        assert "would be implausible_input" in note and "a unit smaller than N m" in note
    else:
        assert "times its known point with the correction fitted to the others" in note
    assert fit.adopted == ("azimuthal", "vertical") and fit.ratio_rms_after < 0.05
    others = [k for k in range(len(names)) if k != 2]
    alone = calibrate_sensor([recordings[k] for k in others], ANTENNA, [truth[k] for k in others])
    assert fit.correction == alone.correction


def test_a_sensor_without_cross_talk_gets_no_correction() -> None:
    # Six contacts of one sweep direction on a sensor that does not leak, each with its own
    # noise: the ratio is 2 % off them (its noise at the default gentle push), and terms fitted
    # to that take a little of it off those contacts but add to it on each left out of the fit
    # (by a third to a half on three such sets): nothing is written, and the ratio's scatter is
    # the uncorrected one.
    recordings, truth = [], []
    for i, x in enumerate(POINTS):
        recording = simulate(ANTENNA, Scenario(case="azimuthal", contact_point=x, seed=300 + i))
        truth.append(float(recording.metadata["true_xc"]))
        recordings.append(recording.without_ground_truth())
    fit = calibrate_sensor(recordings, ANTENNA, truth)
    assert fit.ratio_rms_before < fit.ratio_rms_held_out
    assert fit.adopted == ()
    assert fit.ratio_rms_after == fit.ratio_rms_before  # nothing written
    assert fit.correction.is_identity  # no term, the scatter alone
    assert fit.correction.ratio_scatter == pytest.approx(fit.ratio_rms_before, rel=1e-6)
    assert "not adopted" in fit.ratio_summary


def test_a_leak_in_one_plane_is_corrected_there_and_nowhere_else() -> None:
    # tz leaks into fy only (0.6 N per N m): the azimuthal sweeps' terms undo it and predict
    # their contacts left out of the fit; on this set the vertical sweeps' terms, fitted to
    # their noise alone, do not, and are left at no correction (the fit stays within the
    # limits a correction may take, where an unbounded one stepped to a negative gain)
    coupling = np.zeros((6, 6))
    coupling[1, 5] = 0.6
    device = DeviceImperfections(
        sensor_coupling=tuple(tuple(float(c) for c in row) for row in coupling)
    )
    recordings, truth = _recordings(POINTS, 100, device)
    fit = calibrate_sensor(recordings, ANTENNA, truth)
    assert fit.sweeps == ("azimuthal", "vertical") and fit.adopted == ("azimuthal",)
    # within 15 %: the ratio's 2 % noise at the default push is fitted too (-0.63 on this set)
    assert fit.correction.fy_per_tz == pytest.approx(-0.6, rel=0.15)
    untouched = (fit.correction.fz_gain, fit.correction.fz_per_ty, fit.correction.fy_per_ty)
    assert untouched == (1.0, 0.0, 0.0)
    # what is written leaves the ratio within its noise, with the two terms fitted
    n = len(truth)
    assert fit.ratio_rms_after < 0.05
    expected = fit.ratio_rms_after * (n / (n - 2)) ** 0.5
    assert fit.correction.ratio_scatter == pytest.approx(expected, rel=1e-6)
    assert "not adopted for the vertical sweeps" in fit.ratio_summary


def test_one_sweep_direction_fits_its_own_terms_only(
    calibration_set: tuple[list, list[float]],  # type: ignore[type-arg]
) -> None:
    recordings, truth = calibration_set
    half = len(POINTS)
    stated = dataclasses.replace(ANTENNA, sensor=SensorCorrection())  # a Nano17's cross-talk
    fit = calibrate_sensor(recordings[:half], stated, truth[:half])
    assert fit.sweeps == ("azimuthal",)
    assert (fit.correction.fz_gain, fit.correction.fz_per_ty, fit.correction.fy_per_ty) == (
        1.0,
        0.0,
        0.0,
    )
    # the vertical terms are not measured: a push along Z^m keeps the sensor's stated cross-talk
    assert fit.correction.unmeasured_sweeps == ("vertical",)
    assert fit.correction.coupling_uncertainty([0.0, 0.2, 0.0]) == 0.0
    assert fit.correction.coupling_uncertainty([0.0, 0.0, 0.2]) == stated.sensor.nominal_coupling
    both = calibrate_sensor(recordings, stated, truth)
    assert both.correction.unmeasured_sweeps == ()
    assert both.correction.coupling_uncertainty([0.0, 0.0, 0.2]) == 0.0
    with pytest.raises(SensorCalibrationError, match="needs 4"):
        calibrate_sensor(recordings[:3], ANTENNA, truth[:3])


def test_cli_calibrate_writes_the_sensor_and_no_sensor_keeps_it(
    tmp_path: Path,
    calibration_set: tuple[list, list[float]],  # type: ignore[type-arg]
    capsys: pytest.CaptureFixture[str],
) -> None:
    recordings, truth = calibration_set
    paths = []
    for i, recording in enumerate(recordings):
        path = tmp_path / f"cal{i}.csv"
        write_recording(recording, path)
        paths.append(path)
    table = tmp_path / "points.csv"
    table.write_text(
        "file,x_c\n" + "".join(f"{p.name},{x}\n" for p, x in zip(paths, truth, strict=True))
    )
    start = tmp_path / "start.toml"
    save_antenna(ANTENNA, start)
    out = tmp_path / "cal.toml"
    args = ["calibrate", *map(str, paths), "--antenna", str(start), "--points", str(table)]
    assert main([*args, "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "sensor: lateral-force correction" in printed and "fitted on 12 recordings" in printed
    assert not load_antenna(out).sensor.is_identity
    assert main([*args, "--out", str(out), "--no-sensor"]) == 0
    assert load_antenna(out).sensor.is_identity
    # azimuthal sweeps alone: the file and the output say the vertical terms were not measured
    azimuthal = [*args[:1], *map(str, paths[: len(POINTS)]), *args[1 + len(paths) :]]
    assert main([*azimuthal, "--out", str(out)]) == 0
    assert "no vertical sweep calibrated it" in capsys.readouterr().out
    assert load_antenna(out).sensor.unmeasured_sweeps == ("vertical",)


def test_a_leak_that_nearly_cancels_the_push_near_the_tip_is_undone() -> None:
    # The realistic profile's build 0 (rounded): tz into fy at -0.96 N per N m and ty into fz
    # at +1.31, about 1 % of a Nano17's full scale, the profile's bound, and -0.90 and -0.28
    # across the planes. The lateral force reads (1 - 0.96 x_c) of an azimuthal push, 6 % of
    # it at the tip, so the ratio reads up to 16 times x_c there, and a vertical push's force
    # changes sign past 0.76 m. From no correction alone a fit can lower its loss by shrinking
    # every ratio instead, which some of the held-out fits (all but one contact) do; from the
    # linear statics' solution every fit undoes the leak.
    coupling = np.zeros((6, 6))
    coupling[1, 5], coupling[2, 4] = -0.96, 1.31
    coupling[1, 4], coupling[2, 5] = -0.90, -0.28
    device = DeviceImperfections(
        sensor_coupling=tuple(tuple(float(c) for c in row) for row in coupling)
    )
    recordings, truth = _recordings(POINTS, 100, device)
    fit = calibrate_sensor(recordings, ANTENNA, truth)
    assert fit.ratio_rms_before > 0.5
    assert fit.adopted == ("azimuthal", "vertical")
    # what is left is the ratio's noise at the default push, as for the gentler leak above
    assert fit.ratio_rms_after < 0.05 and fit.ratio_rms_held_out < 0.05
    # within 15 %, as above
    assert fit.correction.fy_per_tz == pytest.approx(0.96, rel=0.15)
    assert fit.correction.fz_per_ty == pytest.approx(-1.31, rel=0.15)
    # and the cross-plane terms, from the pushes' directions
    assert fit.correction.fy_per_ty == pytest.approx(0.90, rel=0.15)
    assert fit.correction.fz_per_tz == pytest.approx(0.28, rel=0.15)
