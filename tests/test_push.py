"""Tests of the push criterion and the instant t_1 (Section 4 steps 3-4, Section 5.3, Eq. 20).

The synthetic manoeuvre: the azimuth accelerates smoothly from rest to a constant speed, touches an
object at ``CONTACT`` and keeps turning, so the contact force and torque grow in proportion to the
rotation past the contact. The free-motion part of the torque comes from the library's observer
(tested independently in test_contact.py); what is tested here is the criterion itself.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensing_antenna.antenna import paper_antenna
from sensing_antenna.detection.contact import (
    ContactDetector,
    SamplePeriodError,
    free_motion_torque,
)
from sensing_antenna.detection.push import (
    DEFAULT_ROTATION,
    PushConfigError,
    PushCriterion,
    PushMonitor,
    detect_push,
    link_axis_angle,
)
from sensing_antenna.recording import Recording

TS = 1e-3  # s
ANTENNA = paper_antenna()
SPEED = 0.9  # rad/s, head speed after the ease-in (no sample lands exactly on 0.03 rad)
CONTACT = 1500  # sample of first touch
X_C = 0.5  # m, contact point
# Contact stiffness seen at the joint: F = 3 E I delta / x_c^2 (static cantilever with the tip
# displaced by x_c delta), torque = F x_c.
FORCE_PER_RAD = 3 * ANTENNA.link.flexural_rigidity / X_C**2  # N / rad


def _manoeuvre(n: int = 2600, theta2: float = 0.0, stop: int | None = None) -> Recording:
    t = TS * np.arange(n)
    ramp = np.minimum(t / 1.0, 1.0)
    speed = SPEED * ramp**3 * (10 - 15 * ramp + 6 * ramp**2)
    if stop is not None:
        speed[stop:] = 0.0  # motors stopped abruptly (rotation past contact stays small)
    theta1 = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * TS)])
    theta = np.column_stack([theta1, np.full(n, theta2)])
    past = np.maximum(theta1 - theta1[CONTACT], 0.0)
    past[:CONTACT] = 0.0
    contact_force = FORCE_PER_RAD * past  # N, on Y^m (by the link on the head: pushed back)
    weight = ANTENNA.link.mass * 9.80665
    force = np.column_stack(
        [-weight * np.sin(theta[:, 1]), -contact_force, -weight * np.cos(theta[:, 1])]
    )
    torque = free_motion_torque(theta, ANTENNA, TS)
    torque[:, 2] -= X_C * contact_force  # contact force at x_c on -Y^m: torque on -Z^m
    return Recording(t=t, theta=theta, force=force, torque=torque)


def _ramp_filter_lag(slope: float, threshold: float, cutoff: float) -> float:
    """Time after the start of a ramp at which the ramp through 1 / (1 + s / cutoff) reaches the
    threshold: slope (u - tau (1 - exp(-u / tau))) = threshold, solved by bisection (s)."""
    tau = 1.0 / cutoff
    lo, hi = 0.0, 10.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if slope * (mid - tau * (1 - math.exp(-mid / tau))) > threshold:
            hi = mid
        else:
            lo = mid
    return lo


def test_default_criterion_is_rotation_of_a_few_percent() -> None:
    crit = PushCriterion()
    assert crit.kind == "rotation"
    # 0.03 rad: the push.py docstring adds the detection delay to reach about 3 %
    # (checked on the simulator in test_simulator_contact.py).
    assert crit.threshold == DEFAULT_ROTATION == 0.03
    assert crit.unit == "rad"


def test_rotation_criterion_triggers_after_the_right_rotation() -> None:
    rec = _manoeuvre()
    result = detect_push(rec, ANTENNA)
    assert result.status == "pushed"
    contact = result.contact
    assert contact.index is not None
    # Quasi-static contact (no impact transient in this synthetic signal): the residual is the
    # torque ramp X_C * FORCE_PER_RAD * SPEED = 0.49 N m/s, which reaches 0.02 N m after 41 ms,
    # plus about 10 ms of residual-filter lag.
    assert CONTACT + 41 <= contact.index <= CONTACT + 41 + 15
    # theta2 = 0: the link-axis angle is |delta theta1| exactly (independent of link_axis_angle).
    turned = rec.theta[:, 0] - rec.theta[contact.index, 0]
    expected = contact.index + int(np.argmax(turned[contact.index :] > DEFAULT_ROTATION))
    assert result.index == expected
    assert result.t_1 == pytest.approx(rec.t[expected])
    assert turned[expected] == pytest.approx(DEFAULT_ROTATION, abs=SPEED * TS)


def test_force_criterion_matches_filtered_ramp() -> None:
    # |F - F_g| = FORCE_PER_RAD * SPEED * (t - t_contact) after contact: a ramp through Eq. 20.
    rec = _manoeuvre()
    threshold = 0.05  # N
    result = detect_push(rec, ANTENNA, PushCriterion("force", threshold))
    assert result.status == "pushed"
    lag = _ramp_filter_lag(FORCE_PER_RAD * SPEED, threshold, 5.0)
    assert result.index is not None
    # Tolerance 2 samples: Tustin vs continuous filter, trapezoidal angle integration.
    assert abs((result.index - CONTACT) - lag / TS) <= 2


def test_torque_criterion_matches_filtered_ramp() -> None:
    rec = _manoeuvre()
    threshold = 0.02  # N m
    result = detect_push(rec, ANTENNA, PushCriterion("torque", threshold))
    lag = _ramp_filter_lag(X_C * FORCE_PER_RAD * SPEED, threshold, 5.0)
    assert result.index is not None
    # Tolerance 5 samples: the free-motion dynamic torque (about 1e-3 N m after the ease-in) is
    # also in |Gamma - Gamma_g| and shifts the crossing by a few ms at this slope.
    assert abs((result.index - CONTACT) - lag / TS) <= 5


def test_no_push_when_motors_stop_early_and_no_contact_without_touch() -> None:
    # Detection happens about 51 samples after the touch (see the rotation test); stopping 65
    # samples after the touch leaves at most 14 samples (0.013 rad < DEFAULT_ROTATION = 0.03 rad)
    # past t_c.
    rec = _manoeuvre(stop=CONTACT + 65)
    result = detect_push(rec, ANTENNA)
    assert result.contact.status == "contact"
    assert result.status == "no_push"
    assert result.t_1 is None
    free = _manoeuvre(n=CONTACT + 1)
    result = detect_push(free, ANTENNA)
    assert result.status == "no_contact"
    assert result.t_c is None


@pytest.mark.parametrize(
    ("kind", "threshold"), [("rotation", 0.03), ("force", 0.05), ("torque", 0.02)]
)
def test_streaming_equals_batch(kind: str, threshold: float) -> None:
    rec = _manoeuvre(theta2=0.3)
    crit = PushCriterion(kind, threshold)  # type: ignore[arg-type]
    batch = detect_push(rec, ANTENNA, crit)
    assert batch.status == "pushed"
    period = rec.sample_period  # the batch form reads it from the time stamps
    monitor = PushMonitor(crit, ANTENNA, period, ContactDetector(ANTENNA, period))
    for _ in range(2):  # the second pass checks reset()
        monitor.reset()
        flags, measures = [], []
        for k in range(rec.n_samples):
            flags.append(monitor.update(rec.t[k], rec.theta[k], rec.force[k], rec.torque[k]))
            measures.append(monitor.measure)
        assert monitor.contact_time == batch.t_c
        assert monitor.push_time == batch.t_1
        assert monitor.push_index == batch.index
        assert flags.index(True) == batch.index
        assert all(flags[batch.index :])
        assert batch.index is not None
        # One compiled kernel in both forms: equal to the bit.
        np.testing.assert_array_equal(measures, batch.measure)
    rng = np.random.default_rng(6)
    cuts = np.sort(rng.choice(np.arange(1, rec.n_samples), size=30, replace=False))
    monitor.reset()
    for part in np.split(np.arange(rec.n_samples), cuts):
        monitor.update_block(rec.t[part], rec.theta[part], rec.force[part], rec.torque[part])
    blocks = monitor.detection()
    assert (blocks.index, blocks.t_1, blocks.t_c) == (batch.index, batch.t_1, batch.t_c)
    np.testing.assert_array_equal(blocks.measure, batch.measure)


@pytest.mark.parametrize(("row", "channel"), [(1200, "theta"), (1600, "force"), (1700, "torque")])
def test_a_sample_that_is_not_finite_is_refused_and_the_monitor_goes_on(
    row: int, channel: str
) -> None:
    # a control loop's glitch: a NaN in one sample. Fed, it would hold the observer's and the
    # filters' states at NaN, and neither t_c nor t_1 would ever come while the head swept on.
    # Refused with the monitor's state unchanged, the loop skips the sample and the decisions
    # come where the clean samples put them
    rec = _manoeuvre()
    clean = detect_push(rec, ANTENNA)
    monitor = PushMonitor(PushCriterion(), ANTENNA, TS)
    values = {"theta": rec.theta, "force": rec.force, "torque": rec.torque}
    for k in range(rec.n_samples):
        sample = {name: v[k].copy() for name, v in values.items()}
        if k == row:
            sample[channel][1] = math.nan
            with pytest.raises(ValueError, match=rf"^{channel}: \[.*nan.*\] is not finite"):
                monitor.update(rec.t[k], sample["theta"], sample["force"], sample["torque"])
            continue
        monitor.update(rec.t[k], sample["theta"], sample["force"], sample["torque"])
    # one sample fewer before the push: the decisions move by one sample at most (1 % for the
    # sums of stamps that are not exact in binary)
    assert clean.t_c is not None and monitor.contact_time is not None
    assert abs(monitor.contact_time - clean.t_c) <= 1.01 * TS
    assert monitor.push_time is not None and abs(monitor.push_time - clean.t_1) <= 1.01 * TS


def test_samples_at_another_period_than_the_monitors_are_refused() -> None:
    # a monitor built for a 1 kHz loop fed a 500 Hz loop's samples: its observer and filters
    # would run at half speed and find a contact in free motion. The time stamps say so once
    # the first twenty steps are in, and go on saying it: a loop that catches the error does not
    # get the wrong period taken. It is no ValueError, which a loop skipping glitches catches
    rec = _manoeuvre()
    half = Recording(
        t=rec.t[::2], theta=rec.theta[::2], force=rec.force[::2], torque=rec.torque[::2]
    )
    monitor = PushMonitor(PushCriterion(), ANTENNA, TS)
    for k in range(20):
        monitor.update(half.t[k], half.theta[k], half.force[k], half.torque[k])
    for k in (20, 21, 500):
        with pytest.raises(SamplePeriodError) as info:
            monitor.update(half.t[k], half.theta[k], half.force[k], half.torque[k])
        assert not isinstance(info.value, ValueError)
        assert str(info.value) == (
            "t: the detector was built for a sample_period of 0.001 s, but its time stamps step"
            " by 0.002 s (the median of its first 20 steps), more than 2 % apart: build it with"
            " the samples' period"
        )
    monitor.reset()  # a new manoeuvre is judged again
    monitor.update_block(half.t[:20], half.theta[:20], half.force[:20], half.torque[:20])
    built = PushMonitor(PushCriterion(), ANTENNA, 2 * TS)  # built for them: it decides
    built.update_block(half.t, half.theta, half.force, half.torque)
    assert built.contact_time is not None and built.push_time is not None


def test_a_jittery_stream_at_the_monitors_period_is_taken() -> None:
    # stamps with a tenth of a period of jitter and three samples dropped among the first
    # twenty: the period is read from a line through them, as a live stream's is (a median of
    # the steps refused such streams 38 % of the time), and the push is found in every draw
    rec = _manoeuvre()
    keep = np.ones(rec.n_samples, dtype=bool)
    keep[[4, 9, 15]] = False
    for seed in range(20):
        jitter = np.random.default_rng(seed).normal(scale=0.1 * TS, size=rec.n_samples)
        monitor = PushMonitor(PushCriterion(), ANTENNA, TS)
        stamps = (rec.t + jitter)[keep]
        monitor.update_block(stamps, rec.theta[keep], rec.force[keep], rec.torque[keep])
        assert monitor.push_time is not None


def test_link_axis_angle_against_dot_product() -> None:
    # Reference: arccos of the dot product of the X^m unit vectors, accurate for angles that are
    # not tiny (here >= 0.05 rad; error of arccos ~ 1e-16 / angle).
    rng = np.random.default_rng(4)
    a = rng.uniform(-1.5, 1.5, size=(50, 2))
    b = a + rng.uniform(0.05, 0.5, size=(50, 2)) * rng.choice([-1, 1], size=(50, 2))

    def axis(th: np.ndarray) -> np.ndarray:
        return np.column_stack(
            [
                np.cos(th[:, 1]) * np.cos(th[:, 0]),
                np.cos(th[:, 1]) * np.sin(th[:, 0]),
                np.sin(th[:, 1]),
            ]
        )

    reference = np.arccos(np.clip(np.sum(axis(a) * axis(b), axis=1), -1, 1))
    np.testing.assert_allclose(link_axis_angle(a, b), reference, rtol=1e-9)
    # Elevated link: an azimuth turn moves the axis by less (cos theta2), the circle of latitude.
    angle = link_axis_angle(np.array([0.02, 1.0]), np.array([0.0, 1.0]))
    assert angle == pytest.approx(2 * math.asin(math.cos(1.0) * math.sin(0.01)), rel=1e-12)


def test_criterion_validation() -> None:
    with pytest.raises(PushConfigError, match=r"push\.kind"):
        PushCriterion("pressure", 1.0)  # type: ignore[arg-type]
    with pytest.raises(PushConfigError, match=r"push\.threshold"):
        PushCriterion("force", 0.0)
    with pytest.raises(PushConfigError, match=r"push\.cutoff"):
        PushCriterion("force", 0.8, cutoff=float("nan"))
