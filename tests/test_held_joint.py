"""The held joint's angle at omega_1: the calibration measures what the link's torque turns it
by, and an answer whose angle rings there beyond that (a base moving near omega_1) is not
``ok``."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from _models import calibrated
from sensing_antenna.antenna import Antenna, load_antenna, paper_antenna, save_antenna
from sensing_antenna.calibration.frequency import (
    FrequencyCalibration,
    calibrate_from_recordings,
    held_compliance_from_recordings,
)
from sensing_antenna.estimation import OnlineEstimator, Status, estimate
from sensing_antenna.estimation.held_joint import held_line
from sensing_antenna.recording import Recording
from sensing_antenna.simulator import Scenario, simulate

#: The posts of the calibration: three on each joint.
POSTS = tuple((case, x_c) for case in ("azimuthal", "vertical") for x_c in (0.4, 0.6, 0.8))


@pytest.fixture(scope="module")
def posts() -> list[Recording]:
    device = paper_antenna()
    return [
        simulate(device, Scenario(case=case, contact_point=x_c, seed=k))
        for k, (case, x_c) in enumerate(POSTS)
    ]


@pytest.fixture(scope="module")
def calibration(posts: list[Recording]) -> FrequencyCalibration:
    points = [float(r.metadata["true_xc"]) for r in posts]
    return calibrate_from_recordings(
        [r.without_ground_truth() for r in posts], calibrated(), points
    )


@pytest.fixture(scope="module")
def model(calibration: FrequencyCalibration) -> Antenna:
    return calibration.apply(calibrated())


@pytest.fixture(scope="module")
def manoeuvre() -> Recording:
    scenario = Scenario(case="azimuthal", contact_point=0.6, seed=11)
    return simulate(paper_antenna(), scenario).without_ground_truth()


def test_a_sinusoid_s_amplitude_is_read_at_its_frequency() -> None:
    # an angle 2e-3 rad/(N m) times a torque of 1 mN m at 70 rad/s, and a line of 50 urad at
    # 66.5 rad/s beside it: the amplitudes at 70 rad/s within the window's scalloping (1 %),
    # and the excess over three times the compliance within 5 % of the line (its side lobe
    # and the torque's share at its peak)
    t = np.arange(1000) * 1e-3
    torque = np.zeros((t.size, 3))
    torque[:, 2] = 1e-3 * np.sin(70.0 * t)
    theta = np.zeros((t.size, 2))
    theta[:, 0] = 2e-3 * torque[:, 2]
    line = held_line(t, theta, torque, 0, 70.0)
    assert line is not None
    assert line.torque == pytest.approx(1e-3, rel=0.01)
    assert line.compliance == pytest.approx(2e-3, rel=1e-6)
    theta[:, 0] += 5e-5 * np.sin(66.5 * t + 0.3)
    rocked = held_line(t, theta, torque, 0, 70.0, compliance=2e-3 / 3.0)
    assert rocked is not None
    assert rocked.excess == pytest.approx(5e-5, rel=0.05)


def test_the_calibration_measures_each_joint_s_held_compliance(
    calibration: FrequencyCalibration, model: Antenna, tmp_path: pytest.TempPathFactory
) -> None:
    azimuth, elevation = calibration.held_compliance
    assert calibration.held_joint is not None
    assert calibration.held_compliance_measured is not None
    motors = paper_antenna().motors
    for joint, value in ((0, azimuth), (1, elevation)):
        on_joint = calibration.held_joint == joint
        assert np.count_nonzero(on_joint) == 3
        assert value == np.max(calibration.held_compliance_measured[on_joint])
        # a held servo is stiffer than its joint's bare inertia, whose angle answers a torque
        # by 1 / (J omega^2) (0.016 rad/(N m) for the azimuth, 0.056 for the elevation at the
        # posts' highest omega_1, 99 rad/s): the posts read a fifteenth and a hundredth of it
        omega = np.max(calibration.omega1_measured[on_joint])
        assert value is not None and 0.0 < value < 1.0 / (motors[joint].inertia * omega**2)
    assert model.azimuth_motor.held_compliance == azimuth
    assert model.elevation_motor.held_compliance == elevation
    path = tmp_path / "model.toml"  # type: ignore[operator]
    save_antenna(model, path)
    assert load_antenna(path) == model
    again = FrequencyCalibration.from_dict(calibration.to_dict())
    assert again.held_compliance == calibration.held_compliance
    # two posts on a joint say too little of its servo: not stored
    fewer = dataclasses.replace(calibration, used=calibration.used & (np.arange(6) != 5))
    assert fewer.held_compliance == (azimuth, None)


def test_posts_at_unknown_points_measure_the_held_compliance_too(
    posts: list[Recording], calibration: FrequencyCalibration
) -> None:
    # the sweeps a T_e fit does not take (a campaign fits one case) measure the same servo
    blind = [r.without_ground_truth() for r in posts]
    assert held_compliance_from_recordings(blind, calibrated()) == calibration.held_compliance
    assert held_compliance_from_recordings(blind[:3], calibrated())[1] is None


def _rocked(recording: Recording, omega: float, amplitude: float, t_from: float) -> Recording:
    """``recording`` with the azimuth's encoder ringing at ``omega`` (rad/s) by ``amplitude``
    (rad) from ``t_from`` (s) on, read to the paper encoder's count: a held servo's error
    against a base that rocks."""
    count = 2.0 * math.pi / 200_000
    theta = recording.theta.copy()
    after = recording.t >= t_from
    ringing = amplitude * np.sin(omega * (recording.t[after] - t_from))
    theta[after, 0] = np.round((theta[after, 0] + ringing) / count) * count
    return dataclasses.replace(recording, theta=theta)


def test_an_angle_ringing_beside_omega1_makes_the_answer_uncertain(
    model: Antenna, manoeuvre: Recording
) -> None:
    # the held angle ringing 5 % below omega_1 by five encoder counts from t_1 on: uncertain,
    # the reason naming the base; untouched, the same manoeuvre is ok well within the bound
    plain = estimate(manoeuvre, model, "paper")
    assert plain.status is Status.OK, plain.reason
    assert plain.diagnostics["held_angle_excess"] < 0.5
    count = 2.0 * math.pi / 200_000
    rocked = _rocked(manoeuvre, 0.95 * plain.omega1, 5.0 * count, plain.t_1)
    for method in ("paper", "fast"):
        result = estimate(rocked, model, method)
        reasons = " ".join([result.reason or "", *result.diagnostics.get("other_reasons", [])])
        assert result.status is not Status.OK, (method, result.x_c)
        assert "the base moving near omega_1" in reasons, (method, reasons)
    # an antenna whose calibration did not measure the joint does not look for it
    unmeasured = estimate(rocked, calibrated(), "paper")
    assert "held_angle_excess" not in unmeasured.diagnostics


def test_the_streaming_form_judges_the_held_angle_as_the_batch_form(
    model: Antenna, manoeuvre: Recording
) -> None:
    # fast answers from a window shorter than the paper's second: the angle is judged over the
    # samples the answer read, the same whether they came at once or one by one
    plain = estimate(manoeuvre, model, "paper")
    count = 2.0 * math.pi / 200_000
    for amplitude in (0.0, 3.0):
        rocked = _rocked(manoeuvre, 0.95 * plain.omega1, amplitude * count, plain.t_1)
        offline = estimate(rocked, model, "fast")
        online = OnlineEstimator(model, rocked.sample_period, "fast")
        for k in range(rocked.n_samples):
            found = online.update(rocked.t[k], rocked.theta[k], rocked.force[k], rocked.torque[k])
            if found is not None:
                break
        assert found is not None
        assert (found.status, found.x_c) == (offline.status, offline.x_c)
        assert found.diagnostics["held_angle_excess"] == offline.diagnostics["held_angle_excess"]
    assert offline.status is not Status.OK
