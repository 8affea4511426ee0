"""The recording's own units and signs check (units_check.py).

Reference: the sign check of docs/recording-format.md. With theta2 = 0, at rest, nothing touching
the paper's link (m_b = 4.6 g, l = 0.98 m), a correct file reads F = (0, 0, -m_b g) =
(0, 0, -0.0451) N and Gamma = (0, +0.5 m_b g l, 0) = (0, 0.0221, 0) N m.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensing_antenna.antenna import STANDARD_GRAVITY, paper_antenna
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.front.steps import free_motion_gain
from sensing_antenna.units_check import (
    REST_FORCE_FRACTION,
    REST_TORQUE_FRACTION,
    angle_problem,
    initial_rest,
    recording_problem,
    rest_reading,
)

ANTENNA = paper_antenna()
N = 200


def at_rest(theta2: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The format's reading at rest, written from the closed form (not from the antenna's
    gravity model), with one sensor count of seeded noise (1/160 N, 1/32000 N m)."""
    link = ANTENNA.link
    weight = link.mass * STANDARD_GRAVITY
    rng = np.random.default_rng(3)
    theta = np.tile([0.2, theta2], (N, 1))
    force = np.tile([-weight * math.sin(theta2), 0.0, -weight * math.cos(theta2)], (N, 1))
    moment = 0.5 * weight * link.length * math.cos(theta2)
    torque = np.tile([0.0, moment, 0.0], (N, 1))
    return theta, force + rng.normal(0, 1 / 160, (N, 3)), torque + rng.normal(0, 1 / 32000, (N, 3))


def test_the_specification_example_reads_the_weight() -> None:
    # The example file of docs/recording-format.md, to its four digits
    theta = np.zeros((2, 2))
    force = np.tile([0.0, 0.0, -0.0451], (2, 1))
    torque = np.tile([0.0, 0.0221, 0.0], (2, 1))
    reading = rest_reading(theta, force, torque, ANTENNA)
    assert reading.problem is None
    # 4 digits of the example against the antenna's 4.6 g and 0.98 m: 0.2 % and 0.1 %
    assert reading.force_scale == pytest.approx(1.0, rel=3e-3)
    assert reading.torque_scale == pytest.approx(1.0, rel=3e-3)


@pytest.mark.parametrize("theta2", [-0.4, 0.0, 0.3])
def test_a_correct_file_at_any_elevation_passes(theta2: float) -> None:
    assert rest_reading(*at_rest(theta2), ANTENNA).problem is None


@pytest.mark.parametrize(
    ("force", "torque", "columns"),
    [
        (1.0, 1000.0, "'tx', 'ty', 'tz'"),  # N mm
        (1.0, 2.0, "'tx', 'ty', 'tz'"),  # doubled
        (1.0, 0.5, "'tx', 'ty', 'tz'"),  # halved
        (1.0, -1.0, "'tx', 'ty', 'tz'"),  # sign flipped
        (1000.0, 1.0, "'fx', 'fy', 'fz'"),  # mN
        (1e-300, 1e-300, "'tx', 'ty', 'tz'"),
    ],
)
def test_scales_and_signs_that_are_not_the_weight(
    force: float, torque: float, columns: str
) -> None:
    theta, f, t = at_rest()
    reading = rest_reading(theta, force * f, torque * t, ANTENNA, "at rest")
    assert reading.problem is not None
    assert f"columns {columns}: over the {N} samples at rest" in reading.problem


def test_a_sensor_tared_with_the_link_on_is_named_as_such() -> None:
    # Tared with the link mounted, the sensor reads no weight: the reason says so, where a
    # torque in N mm or with a sign flipped gets the reason of a wrong scale
    theta, force, torque = at_rest()
    tared = rest_reading(theta, force - force.mean(axis=0), torque - torque.mean(axis=0), ANTENNA)
    assert "a sensor tared with the link on it" in (tared.problem or "")
    flipped = rest_reading(theta, force, -torque, ANTENNA)
    assert "a sign flipped?" in (flipped.problem or "")
    assert "tared" not in (flipped.problem or "")


def test_the_one_column_in_a_wrong_unit_is_named() -> None:
    # tz alone written in N mm, with a sensor offset of 22 uN m there after taring (two
    # counts of the simulated sensor are 60 uN m): it reads 0.022 "N m" where 0 is expected,
    # and the reason says which column is off
    theta, force, torque = at_rest()
    torque[:, 2] = 1000 * (torque[:, 2] + 22e-6)
    reading = rest_reading(theta, force, torque, ANTENNA)
    assert "most of it in 'tz'" in (reading.problem or "")


def test_tolerances_are_fractions_of_the_weight() -> None:
    reading = rest_reading(*at_rest(), ANTENNA)
    assert reading.torque_tolerance == pytest.approx(
        REST_TORQUE_FRACTION * 0.5 * ANTENNA.link.mass * STANDARD_GRAVITY * ANTENNA.link.length
    )
    assert reading.force_tolerance == pytest.approx(
        REST_FORCE_FRACTION * ANTENNA.link.mass * STANDARD_GRAVITY
    )


def test_angles_beyond_a_head_are_named() -> None:
    theta = np.zeros((10, 2))
    assert angle_problem(theta) is None
    # an elevation of 10 degrees written in degrees
    assert "column 'theta2': the elevation reaches 10 rad" in (
        angle_problem(theta + np.array([0.0, 10.0])) or ""
    )
    glitch = theta.copy()
    glitch[4, 0] = 1e300
    assert "column 'theta1': the angle jumps by 1e+300 rad between samples 4 and 5" in (
        angle_problem(glitch) or ""
    )


def test_initial_rest_and_the_whole_recording() -> None:
    theta, force, torque = at_rest()
    theta[120:, 0] += np.linspace(0.0, 0.5, N - 120)
    assert initial_rest(theta, 1e-4) == 121  # the first step of the ramp is 0 rad
    assert recording_problem(theta, force, torque, ANTENNA, 1e-4, 51) is None
    assert recording_problem(theta, force, 2 * torque, ANTENNA, 1e-4, 51) is not None
    # too short a rest to judge: not judged
    assert recording_problem(theta, force, 2 * torque, ANTENNA, 1e-4, 200) is None


def test_a_free_motion_misread_names_a_start_in_motion_only_when_there_was_one() -> None:
    # The observer predicts a swinging torque the sensor does not read (a gain near 0, below
    # the 1/5 allowed): degrees or a wrong observer, and, where the record has no rest at its
    # start, the observer's own start, which assumed one
    theta = np.zeros((200, 2))
    gravity = ANTENNA.gravity_torque(theta[:, 1])
    swing = np.zeros((200, 3))
    swing[:, 2] = 0.01 * np.sin(np.linspace(0.0, 6.0, 200))
    at_rest_first = free_motion_gain(theta, gravity, gravity + swing, ANTENNA, EstimatorConfig())
    in_motion = free_motion_gain(
        theta, gravity, gravity + swing, ANTENNA, EstimatorConfig(), starts_at_rest=False
    )
    assert at_rest_first[0] == in_motion[0] == 0.0
    assert "angles not in radians" in (at_rest_first[1] or "")
    assert "does not start at rest" not in (at_rest_first[1] or "")
    assert "a recording that does not start at rest" in (in_motion[1] or "")
