"""The plausibility layer every method's estimate passes through (estimation/plausibility.py).

Recordings in the wrong units or scale, or a wrench that is no contact, must never give ``ok``,
whatever the method, offline or online; a best guess off the link is never reported; absurd
inputs give a status, not a traceback. The recordings are one simulated manoeuvre of the paper's
antenna with columns scaled as a user's file might be (forces in mN, torques in N mm, a factor 2,
angles in degrees), so the reference is the unscaled recording, which every method estimates
``ok`` within 2 mm of the simulator's contact point.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

from _models import calibrated
from _recordings import knocked, samples_kept
from sensing_antenna.antenna import Antenna, load_antenna, paper_antenna
from sensing_antenna.detection.push import PushCriterion
from sensing_antenna.estimation import (
    METHODS,
    EstimatorConfig,
    Evidence,
    OnlineEstimator,
    Status,
    conclude,
    estimate,
    gather,
)
from sensing_antenna.estimation.front.steps import (
    free_motion_gain,
    settled_loads,
    still_angles_turn,
)
from sensing_antenna.recording import Recording, read_recording, write_recording
from sensing_antenna.simulator import DeviceImperfections, Scenario, simulate

#: Degrees per radian: the factor of a file whose angles are in degrees.
DEGREES = 180.0 / math.pi


@pytest.fixture(scope="module")
def antenna() -> Antenna:
    return calibrated()


@pytest.fixture(scope="module")
def azimuthal(antenna: Antenna) -> Recording:
    recording = simulate(antenna, Scenario(case="azimuthal", contact_point=0.55, seed=1))
    return recording.without_ground_truth()


@pytest.fixture(scope="module")
def vertical(antenna: Antenna) -> Recording:
    recording = simulate(antenna, Scenario(case="vertical", contact_point=0.55, seed=1))
    return recording.without_ground_truth()


def scaled(
    recording: Recording, force: float = 1.0, torque: float = 1.0, angle: float = 1.0
) -> Recording:
    return dataclasses.replace(
        recording,
        force=recording.force * force,
        torque=recording.torque * torque,
        theta=recording.theta * angle,
    )


def all_methods(recording: Recording, antenna: Antenna) -> dict[str, object]:
    gathered = gather(recording, antenna)
    return {name: conclude(gathered, name) for name in METHODS}


def assert_on_link_or_none(result, antenna: Antenna) -> None:  # type: ignore[no-untyped-def]
    """x_c, the touched point and the interval are either absent or on the link (the point
    within the link's reach, l plus the 10 % deflection of Assumption 1)."""
    length = antenna.link.length
    if math.isnan(result.x_c):
        assert np.all(np.isnan(result.contact_point))
    else:
        assert 0.0 < result.x_c <= length, result
    if not np.all(np.isnan(result.contact_point)):
        assert np.linalg.norm(result.contact_point) <= 1.1 * length, result.contact_point
    if result.interval is not None:
        assert 0.0 <= result.interval[0] <= result.interval[1] <= length
    assert all(0.0 < c <= length for c in result.candidates)


def test_the_unscaled_recording_is_ok_for_every_method(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # The reference the scaled files are judged against: every method ok near where the
    # simulated link touched (0.5496 m); docs/estimation.md: mean errors below 0.1 cm, the ratio
    # alone 0.8 cm, with maxima of 0.2 cm and 3 cm
    for name, result in all_methods(azimuthal, antenna).items():
        # the ratio alone is honest about its uncertainty at the default gentle push (a few cm)
        expected = Status.UNCERTAIN if name == "ratio" else Status.OK
        assert result.status is expected, (name, result.reason)
        assert result.x_c == pytest.approx(0.5496, abs=3e-2 if name == "ratio" else 2e-3), name


@pytest.mark.parametrize(
    ("force", "evidence"),
    [
        # Forces doubled: the ratio halves (0.273 m for 0.548), the vibration stays
        (2.0, "torque/force ratio"),
        # Halved: the ratio doubles, 1.09 m, past the link's end
        (0.5, "torque/force ratio"),
        # mN: the force at rest reads 1000 times the link's weight
        (1000.0, "columns 'fx', 'fy', 'fz'"),
    ],
    ids=["doubled", "halved", "mN"],
)
def test_scaled_forces_are_never_ok(
    azimuthal: Recording, antenna: Antenna, force: float, evidence: str
) -> None:
    for name, result in all_methods(scaled(azimuthal, force=force), antenna).items():
        assert result.status is not Status.OK, (name, result.x_c)
        assert_on_link_or_none(result, antenna)
    ratio = all_methods(scaled(azimuthal, force=force), antenna)["ratio"]
    text = " ".join([ratio.reason or "", *ratio.diagnostics["other_reasons"]])
    assert evidence in text


@pytest.mark.parametrize(("turn", "said"), [(1, "turned 90 degrees about X^m"), (2, "180")])
def test_a_sensor_turned_on_the_link_is_named_as_such(
    azimuthal: Recording, antenna: Antenna, turn: int, said: str
) -> None:
    # A sensor mounted a quarter turn about the link's axis, read without turning it back: the
    # moment of the link's weight at rest reads in full on tz instead of ty; the reason names the
    # turn. Half a turn is two signs flipped, which the reason already names.
    quarter = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # about X^m
    rotation = np.linalg.matrix_power(quarter, turn)
    turned = dataclasses.replace(
        azimuthal, force=azimuthal.force @ rotation.T, torque=azimuthal.torque @ rotation.T
    )
    result = estimate(turned, antenna, "paper")
    assert result.status is Status.IMPLAUSIBLE_INPUT
    reason = result.reason or ""
    if turn == 1:
        assert "the sensor's axes turned on the link" in reason and said in reason, reason
    else:
        assert "axes turned" not in reason and "a sign flipped" in reason, reason
    assert "touching" not in reason, reason


@pytest.mark.parametrize(("case", "x_c"), [("azimuthal", 0.55), ("vertical", 0.8)])
def test_a_recording_begun_with_the_link_pushing_says_where(
    antenna: Antenna, case: str, x_c: float
) -> None:
    # Recorded from 0.1 s after the head stopped against the post (a logger started late, a
    # stream joined mid-contact): the loads at the start are the weight and the push, which the
    # rest check refuses; the reason names a push across the link and where its lever puts it.
    # (A vertical push near the weight's own lever reads as the weight scaled: not named so.)
    recording = simulate(antenna, Scenario(case=case, contact_point=x_c, seed=1))
    recording = recording.without_ground_truth()
    t_1 = estimate(recording, antenna, "paper").t_1
    late = samples_kept(recording, recording.t >= t_1 + 0.1)
    result = estimate(late, antenna, "paper")
    assert result.status is Status.IMPLAUSIBLE_INPUT
    reason = result.reason or ""
    found = re.search(
        r"the link touching something as the recording began: .*, (\S+) to (\S+) m", reason
    )
    assert found is not None, reason
    assert float(found.group(1)) <= x_c <= float(found.group(2)), reason
    # read from its start, the recording's rest says nothing of a push
    for whole in (recording, scaled(recording, torque=1e3), scaled(recording, torque=-1.0)):
        assert "touching" not in (estimate(whole, antenna, "paper").reason or "")


@pytest.mark.parametrize("force", [1.0 / 9.81, 1.0 / 4.448], ids=["kgf", "lbf"])
def test_forces_in_kgf_or_lbf_are_no_record_too_short(
    azimuthal: Recording, antenna: Antenna, force: float
) -> None:
    # the ratio reads 4.4 to 10 times the contact, off the link, and its mean wanders there
    # beyond the convergence tolerance: the vibration methods name the ratio, not a record
    # to take longer or a slip
    for name, result in all_methods(scaled(azimuthal, force=force), antenna).items():
        assert result.status is not Status.OK, (name, result.x_c)
        if name != "ratio":
            assert result.status is Status.MODEL_MISMATCH, (name, result.reason)
            assert "torque/force ratio" in (result.reason or ""), (name, result.reason)


def test_a_record_cut_before_the_ratio_s_first_mean_is_too_short(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # 0.1 s after t_1 the ratio's moving mean (0.2 s) has no value yet: a record too short,
    # not a ratio off the link
    t_1 = estimate(azimuthal, antenna).t_1
    cut = samples_kept(azimuthal, azimuthal.t < t_1 + 0.1)
    for name, result in all_methods(cut, antenna).items():
        if name != "fast":
            assert result.status is Status.RECORDING_TOO_SHORT, (name, result.reason)
        reasons = " ".join([result.reason or "", *result.diagnostics.get("other_reasons", [])])
        assert "off the" not in reasons, (name, reasons)


def test_torques_in_newton_millimetres_give_a_status_not_a_traceback(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # The torque at rest reads 1000 times the weight's moment 0.0221 N m (recording format)
    for name, result in all_methods(scaled(azimuthal, torque=1000.0), antenna).items():
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert "columns 'tx', 'ty', 'tz'" in (result.reason or "")
        assert_on_link_or_none(result, antenna)


def test_a_whole_wrench_in_mn_and_n_mm_gives_no_absurd_best_guess(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # The torque/force ratio of this file reads 8.6e4 m: no method may report it as x_c
    for name, result in all_methods(scaled(azimuthal, 1000.0, 1000.0), antenna).items():
        assert_on_link_or_none(result, antenna)
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)


def test_a_whole_wrench_in_kn_and_kn_m_is_implausible_not_no_contact(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # Loads a thousand times too small never reach the contact detector's threshold: the
    # units check of the whole record names the torques, the missing contact comes second
    for name, result in all_methods(scaled(azimuthal, 1e-3, 1e-3), antenna).items():
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert "columns 'tx', 'ty', 'tz'" in (result.reason or "")
        assert any("filtered residual" in r for r in result.diagnostics["other_reasons"])
        assert math.isnan(result.x_c)


@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
def test_angles_in_degrees_are_implausible_input(
    request: pytest.FixtureRequest, antenna: Antenna, case: str
) -> None:
    # Azimuthal (theta2 = 0 throughout): the observer predicts 57 times the torque the link
    # exerts while the head turns; vertical: the elevation also reaches -6.2 "rad"
    recording = scaled(request.getfixturevalue(case), angle=DEGREES)
    for name, result in all_methods(recording, antenna).items():
        assert not result.ok, name
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert "'theta1', 'theta2'" in (result.reason or "")


@pytest.mark.parametrize(
    ("axes", "status"),
    [
        # every channel: the sine's mean over the rest before t_c already moves the torque
        ((1.0, 1.0, 1.0), "implausible_input"),
        # none along the link: the rest reads the weight; the ratio, a thousandth of where the
        # vibration puts the contact, is no contact's in any unit
        ((0.0, 1.0, 1.0), "implausible_input"),
    ],
    ids=["every-channel", "across-the-link"],
)
def test_a_synthetic_sine_as_the_wrench_is_no_contact(
    azimuthal: Recording, antenna: Antenna, axes: tuple[float, ...], status: str
) -> None:
    # The link's weight plus a 10 mN (N m) sine at 8.6 Hz: the contact detector fires, the
    # spectrum has a clear peak at 54 rad/s (a contact at 0.548 m), but the torque/force ratio
    # of the sine reads 1.0 m (past the link's end) and the second "mode" is no mode of a contact
    # (with a faint white noise, a hundredth of a sensor count: 1/16000 N, 1/3.2e6 N m, seeded)
    sine = 0.01 * np.sin(2.0 * math.pi * 8.6 * azimuthal.t)[:, None] * np.array(axes)
    theta2 = azimuthal.theta[:, 1]
    noise = np.random.default_rng(7).standard_normal((azimuthal.t.size, 6))
    recording = dataclasses.replace(
        azimuthal,
        force=antenna.gravity_force(theta2) + sine + noise[:, :3] / 16000.0,
        torque=antenna.gravity_torque(theta2) + sine + noise[:, 3:] / 3200000.0,
    )
    results = all_methods(recording, antenna)
    assert {name: r.status for name, r in results.items() if r.ok} == {}
    for name, result in results.items():
        assert result.status.value == status, (name, result.x_c, result.reason)
        assert_on_link_or_none(result, antenna)


@pytest.mark.parametrize(
    ("case", "theta", "force"),
    [
        ("azimuthal", (-1.0, 1.0), (1.0, 1.0, 1.0)),  # theta1's sign flipped
        ("vertical", (1.0, -1.0), (1.0, 1.0, 1.0)),  # theta2's
        ("azimuthal", (1.0, 1.0), (1.0, -1.0, -1.0)),  # the forces across the link
    ],
    ids=["theta1", "theta2", "forces"],
)
def test_a_sign_flipped_in_the_angles_or_forces_is_implausible_input(
    request: pytest.FixtureRequest,
    antenna: Antenna,
    case: str,
    theta: tuple[float, ...],
    force: tuple[float, ...],
) -> None:
    # The obstacle can only push back: the mean reaction over the hold opposes the head's turn
    # from where the push began to t_1 (Y^c = -Y^m for an azimuthal push, Section 5.4 note
    # (a)); a flipped sign turns one against the other, while the ratio (|R|) and the frequency
    # do not see it
    original: Recording = request.getfixturevalue(case)
    recording = dataclasses.replace(
        original, theta=original.theta * np.array(theta), force=original.force * np.array(force)
    )
    results = all_methods(recording, antenna)
    for name, result in results.items():
        assert not result.ok, name
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert "does not oppose the head's turn" in (result.reason or "")
        assert "touched nothing" not in (result.reason or "")  # a push far above the noise
        # no 95 % interval is claimed from samples the status says are wrong
        assert result.interval is None, name
    assert results["fast"].diagnostics["interval_dropped"] is not None


def test_a_detector_firing_on_the_free_motion_is_named_beside_the_signs(
    antenna: Antenna,
) -> None:
    # A device whose threshold lies below its residual (1e-4 N m, the sensor's noise 4 times
    # the datasheet's) stops on a false contact during the sweep and touches nothing: the
    # link's swing leaves a force over the hold of a few standard errors, in any direction.
    # Where it does not oppose the turn, the reason names that reading beside the signs
    observer = dataclasses.replace(antenna.observer, contact_threshold=1e-4)
    device = dataclasses.replace(antenna, observer=observer)
    named = 0
    for seed in (2, 3, 4):
        scenario = Scenario(case="vertical", contact_point=0.6, seed=seed, noise_scale=4.0)
        recording = simulate(device, scenario)
        assert math.isnan(float(recording.metadata["true_xc"]))  # the premise: no touch
        result = estimate(recording.without_ground_truth(), device, "paper")
        assert not result.ok, (seed, result.reason)
        if "does not oppose the head's turn" in (result.reason or ""):
            assert "or the link touched nothing" in (result.reason or ""), result.reason
            named += 1
    assert named


def test_a_detector_that_fires_after_the_head_stopped_still_judges_the_push_direction(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # An observer threshold above what the push reached while the head turned fires only after
    # the head stopped, from the ringing: from t_c on the head is still, or settles back. The
    # turn into the contact is counted from where the push began, so a force and torque across
    # the link mirrored (a sensor's Y axis reversed, which the ratio and the frequency cannot
    # see, and which puts the touched point on the wrong side of the bent link) are caught,
    # and the right signs pass.
    observer = dataclasses.replace(
        antenna.observer, contact_threshold=2.0 * antenna.observer.contact_threshold
    )
    late = dataclasses.replace(antenna, observer=observer)
    on_time = estimate(azimuthal, antenna)
    right = estimate(azimuthal, late)
    assert right.t_c >= on_time.t_1  # the premise: detected once the head had stopped
    evidence = gather(azimuthal, late)
    assert isinstance(evidence, Evidence)
    # the push began while the head still turned, after the touch: the on-time detector fires
    # 50 to 200 ms after it on this simulator (docs/design-notes.md, "A detector that fires
    # after the head stopped")
    assert on_time.t_c - 0.2 < evidence.t[evidence.push_onset_index] < on_time.t_1
    assert right.ok, right.reason
    # the same hold, its spectrum window started later: well within the 1 cm an ok claims
    assert abs(right.x_c - on_time.x_c) < 1e-3
    mirror = np.array([1.0, -1.0, 1.0]), np.array([1.0, 1.0, -1.0])
    mirrored = dataclasses.replace(
        azimuthal, force=azimuthal.force * mirror[0], torque=azimuthal.torque * mirror[1]
    )
    for name, result in all_methods(mirrored, late).items():
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert "does not oppose the head's turn" in (result.reason or ""), name


@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
def test_angles_that_turn_the_head_less_than_the_link_is_bent_are_a_model_mismatch(
    request: pytest.FixtureRequest, antenna: Antenna, case: str
) -> None:
    # A contact that sticks bends the link as far as the head turned into the object since the
    # touch, one that slides over a flat surface less. Halved angles keep every direction, and
    # the sign check passes, but halve the turn.
    original: Recording = request.getfixturevalue(case)
    theta = 0.5 * original.theta
    recording = dataclasses.replace(original, theta=np.ascontiguousarray(theta))
    # a sticking contact reads 1; the independent rod engine's right answers read 0.85 to 1.06
    # (docs/estimation.md), and 0.7 to 1.3 leaves room for this fixture's late detector
    for name, result in all_methods(original, antenna).items():
        assert 0.7 < result.diagnostics["bend_per_turn"] < 1.3, name
    for name, result in all_methods(recording, antenna).items():
        reasons = [result.reason or "", *result.diagnostics.get("other_reasons", [])]
        assert not result.ok, name
        assert any("do not describe the head's turn" in text for text in reasons), name
        assert result.diagnostics["bend_per_turn"] > 1.6, name


def test_swapped_angle_columns_that_pass_the_sign_check_are_named(
    vertical: Recording, antenna: Antenna
) -> None:
    # The elevation read as the azimuth: the head seems to swing across the push that bent the
    # link, which the sign check (the push against the turn) lets pass on this sweep. Such a
    # turn does no work against the push's moment, and the bend is not what it makes.
    swapped = dataclasses.replace(vertical, theta=np.ascontiguousarray(vertical.theta[:, ::-1]))
    for name, result in all_methods(swapped, antenna).items():
        reasons = [result.reason or "", *result.diagnostics.get("other_reasons", [])]
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert "the two angles swapped" in (result.reason or ""), name
        assert abs(result.diagnostics["work_share"]) < 0.05, name
        assert any("turn the head across the push that bent it" in r for r in reasons), name


@pytest.mark.parametrize(("case", "turning"), [("azimuthal", 0), ("vertical", 1)])
def test_an_angle_column_copied_from_the_turning_joints_is_named(
    request: pytest.FixtureRequest, antenna: Antenna, case: str, turning: int
) -> None:
    # A logger that writes the turning joint's angle into both columns makes the head seem to
    # sweep diagonally. Into a post that passes the push, work and bend checks (the extra turn
    # runs along the post), and the touched point was placed 3 to 8 cm above or beside the
    # object. The link's inertia tells them apart: before the touch the sensor shows no torque
    # for the copied joint's turn. Bounds: on the campaign's recordings the turning joint reads
    # about 1 (docs/design-notes.md, "An angle column copied from the other"); copied, 0.05 to
    # 0.12, below the 1/5 allowed.
    original: Recording = request.getfixturevalue(case)
    still = 1 - turning  # the angle columns' indices, as the gains': theta1, theta2
    copied = dataclasses.replace(
        original, theta=np.ascontiguousarray(original.theta[:, [turning, turning]])
    )
    for name, result in all_methods(original, antenna).items():
        gains = result.diagnostics["joint_free_motion_gains"]
        assert 0.7 < gains[turning] < 1.5, name
        assert math.isnan(gains[still]), name
        assert result.status is not Status.IMPLAUSIBLE_INPUT, (name, result.reason)
    angle = ("theta1", "theta2")[still]
    for name, result in all_methods(copied, antenna).items():
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert f"'{angle}' a copy of" in (result.reason or ""), name
        assert result.diagnostics["joint_free_motion_gains"][still] < 0.2, name


@pytest.mark.parametrize(("case", "turning"), [("azimuthal", 0), ("vertical", 1)])
def test_a_still_joints_angle_written_over_the_turning_ones_is_named(
    antenna: Antenna, case: str, turning: int
) -> None:
    # The still joint's angle in both columns: the head seems to rest, and the touched point
    # is placed where the sweep began, one swept angle (several cm) from the object; the
    # frequency and the ratio still find x_c, and the answer was ok. Before the touch the
    # sensor shows the turning link's inertia come and go, 20 to 23 times its noise on these
    # devices (docs/design-notes.md, "A still joint's angle over the turning one"); a head at
    # rest shows its noise, about 1, and 8 is allowed.
    recording = simulate(antenna, Scenario(case=case, contact_point=0.8, seed=3))
    original = recording.without_ground_truth()
    still = 1 - turning
    frozen = dataclasses.replace(
        original, theta=np.ascontiguousarray(original.theta[:, [still, still]])
    )
    for name, result in all_methods(original, antenna).items():
        assert math.isnan(result.diagnostics["still_angles_turn"]), name
    column = ("tz", "ty")[turning]
    for name, result in all_methods(frozen, antenna).items():
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert f"'{column}': before the contact neither angle turns" in (result.reason or ""), name
        assert result.diagnostics["still_angles_turn"] > 15.0, name


def test_a_head_at_rest_shows_its_sensors_noise_not_a_turn(antenna: Antenna) -> None:
    # White noise about the link's weight, angles still: the root mean square over the noise
    # the second differences measure is about 1, far from the 8 of a turn. The larger of two
    # axes over a robust noise estimate: 0.97 +- 0.03 over 200 seeds (0.88 to 1.06), and 0.1
    # is three of those deviations.
    rng = np.random.default_rng(5)
    n = 1000
    theta = np.tile([0.1, 0.2], (n, 1))
    torque = antenna.gravity_torque(theta[:, 1]) + rng.normal(0.0, 3.0e-5, size=(n, 3))
    ratio, problem = still_angles_turn(
        theta, torque, antenna, EstimatorConfig(), stop=n, tolerance=1.0e-4, window=50
    )
    assert problem is None
    assert ratio == pytest.approx(1.0, abs=0.1)


def test_a_still_head_whose_link_rings_is_no_turn(antenna: Antenna) -> None:
    # Angles still, the link left ringing at its free mode (16.4 rad/s, damping ratio 0.005)
    # with 1e-3 N m about Z^m, 30 times the noise: it swings both ways, a turn's start loads
    # one way; at no phase is it called a frozen angle column
    n = 1000
    t = np.arange(n) * 1e-3
    theta = np.tile([0.0, 0.1], (n, 1))
    torque = antenna.gravity_torque(theta[:, 1])
    torque = torque + np.random.default_rng(7).normal(0.0, 3e-5, (n, 3))
    for phase in np.linspace(0.0, 2.0 * math.pi, 12, endpoint=False):
        ringing = torque.copy()
        ringing[:, 2] += 1e-3 * np.exp(-0.005 * 16.4 * t) * np.sin(16.4 * t + phase)
        ratio, problem = still_angles_turn(
            theta, ringing, antenna, EstimatorConfig(), stop=n, tolerance=1e-4, window=50
        )
        assert problem is None, (phase, ratio)


def test_an_encoders_flicker_on_the_still_joint_is_no_turn(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # 12-bit encoders (4,096 counts a turn) whose every sample flickers by a count: the
    # observer predicts from the still joint's flicker a torque as large as the sweep's, which
    # the sensor does not show; a joint whose angle stays within the rest tolerance (three
    # steps) did not turn, and is not judged. The turning joint reads 0.67 to 1.05 under such
    # a flicker (docs/design-notes.md, "An angle column copied from the other"): 0.5 is below
    # that and above the 1/5 of a copy.
    step = 2.0 * math.pi / 4096
    flicker = np.random.default_rng(0).integers(-1, 2, size=azimuthal.theta.shape)
    theta = (np.round(azimuthal.theta / step) + flicker) * step
    recording = dataclasses.replace(azimuthal, theta=np.ascontiguousarray(theta))
    for name, result in all_methods(recording, antenna).items():
        assert result.status is not Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        theta1, theta2 = result.diagnostics["joint_free_motion_gains"]
        assert theta1 > 0.5 and math.isnan(theta2), name


def test_a_coarse_encoders_flicker_does_not_take_the_sweeps_start_for_rest(
    antenna: Antenna,
) -> None:
    # 12-bit encoders flickering a count widen the rest tolerance to about 0.015 rad, which
    # the sweep's slow start takes 0.4 s to leave: the tare then averaged the link's inertia
    # (3.8e-4 N m about Y^m) and read it as 0.04 g of payload, model_mismatch. The loads
    # show where the rest ends: the sweep starts at 0.1 s (the scenario's start_time), and
    # the tare of the torque about Y^m ends within a rest window (50 ms) of it, as on the
    # exact angles; the forces, where the start stays under the noise, keep the angles' rest.
    recording = simulate(antenna, Scenario(case="vertical", contact_point=0.8, seed=3))
    plain = recording.without_ground_truth()
    step = 2.0 * math.pi / 4096
    flicker = np.random.default_rng(0).integers(-1, 2, size=plain.theta.shape)
    theta = (np.round(plain.theta / step) + flicker) * step
    coarse = dataclasses.replace(plain, theta=np.ascontiguousarray(theta))
    exact, read = gather(plain, antenna), gather(coarse, antenna)
    start = round(0.1 / plain.sample_period)
    for evidence in (exact, read):
        assert evidence.diagnostics["tare"] == "rest"
        counts = evidence.diagnostics["tare_samples"]
        assert start <= counts[4] <= start + 50
        assert min(counts[:3]) > start + 50
    # the offsets differ by the weight's moment at a count of elevation (2.2e-2 N m x 1.5e-3)
    assert abs(read.load_offset[4] - exact.load_offset[4]) < 3.5e-5
    assert read.payload_mass() == 0.0
    assert conclude(read, "paper").status is Status.OK


@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
def test_a_slow_sweep_read_by_a_flickering_coarse_encoder_rests_where_the_head_stops(
    antenna: Antenna, case: str
) -> None:
    # A short ramp (0.2 s) into a slow cruise (0.1 rad/s) read by a 12-bit encoder flickering
    # a count: over a 50 ms window the pushing head moves 5e-3 rad, within the 0.015 rad the
    # flicker asks of a rest, and t_1 was read at t_c: the push in the hold lowered omega_1 by
    # 1.5 %, and paper answered ok 1 to 1.5 cm off (or blamed a payload the ramp's pulse put
    # in the tare). The head's drift across the hold tells the push from the rest.
    scenario = Scenario(
        case=case, contact_point=0.8, seed=3, sweep_speed=0.1, accel_time=0.2, duration=5.0
    )
    recording = simulate(antenna, scenario)
    truth = float(recording.metadata["true_xc"])
    plain = recording.without_ground_truth()
    step = 2.0 * math.pi / 4096
    flicker = np.random.default_rng(0).integers(-1, 2, size=plain.theta.shape)
    theta = (np.round(plain.theta / step) + flicker) * step
    coarse = dataclasses.replace(plain, theta=np.ascontiguousarray(theta))
    exact, read = (estimate(r, antenna, "paper") for r in (plain, coarse))
    assert read.t_1 - read.t_c > 0.2  # the push lasts 0.27 to 0.3 s
    # the hold's first half may still hold the turn's last 51 samples (test_estimation_units)
    assert abs(read.t_1 - exact.t_1) < 0.06
    assert read.status is Status.OK, read.reason
    # the exact encoder's answer is within 0.2 mm; 2 mm is a fifth of what t_1 at t_c cost
    assert abs(read.x_c - truth) < 0.002


def _resting_loads(antenna: Antenna, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A head at rest for n samples: still angles, the link's weight and white noise (1 mN,
    10 uN m), shapes (n, 2), (n, 3), (n, 3)."""
    rng = np.random.default_rng(7)
    theta = np.tile([0.0, 0.1], (n, 1))
    force = antenna.gravity_force(theta[:, 1]) + rng.normal(0.0, 1e-3, (n, 3))
    torque = antenna.gravity_torque(theta[:, 1]) + rng.normal(0.0, 1e-5, (n, 3))
    return theta, force, torque


def test_the_rest_ends_where_a_load_starts_to_build(antenna: Antenna) -> None:
    # A load about Z^m ramping from sample 300 (a sweep's start, 2e-7 N m per sample) leaves
    # the level of a 50-sample mean (5 standard errors: 7e-6 N m) within 40 samples; that
    # channel's rest ends where the first window of that run begins, a window before it at
    # most, and the other channels keep all their samples
    theta, force, torque = _resting_loads(antenna, 600)
    torque[300:, 2] += 2e-7 * np.arange(300)
    settled = settled_loads(theta, force, torque, antenna, 50)
    assert 300 - 50 <= settled[5] <= 300 + 40
    assert list(settled[:5]) == [600] * 5


def test_a_load_that_came_and_went_one_way_ends_the_rest_where_it_began(antenna: Antenna) -> None:
    # A short speed ramp into a slow cruise loads the sensor about Z^m and lets go before a
    # coarse encoder sees the turn: a half sine of 5e-4 N m from sample 300 to 550, back at
    # its level by the end. Against the level before it, it went one way only, and that
    # channel's rest ends where its first departing window begins (within a window of 300)
    theta, force, torque = _resting_loads(antenna, 700)
    torque[300:550, 2] += 5e-4 * np.sin(np.pi * np.arange(250) / 250)
    settled = settled_loads(theta, force, torque, antenna, 50)
    assert 300 - 50 <= settled[5] <= 300
    assert list(settled[:5]) == [700] * 5


def test_a_link_ringing_at_rest_keeps_its_whole_rest(antenna: Antenna) -> None:
    # Left ringing by the last manoeuvre: 16.4 rad/s (the paper link's free mode) of 1e-4 N m
    # about Z^m, 14 times the limit of a 50-sample mean (7e-6 N m), decaying over the rest.
    # Those means leave the level and come back; the rest is cut, if at all, at the last
    # crossing, within half a period (192 samples) of the end, and the ringing averages out
    # over what is kept (its mean within the limit of the weight)
    theta, force, torque = _resting_loads(antenna, 1500)
    t = np.arange(1500) * 1e-3
    torque[:, 2] += 1e-4 * np.exp(-t / 0.5) * np.sin(16.4 * t)
    settled = settled_loads(theta, force, torque, antenna, 50)[5]
    assert 1500 - 192 <= settled <= 1500
    kept = torque[:settled, 2] - antenna.gravity_torque(theta[:settled, 1])[:, 2]
    assert abs(kept.mean()) < 7e-6


def test_a_sensor_quieter_than_its_counts_keeps_its_rest(antenna: Antenna) -> None:
    # Torque counts of 1e-4 N m with noise of a fifth of a count: the second differences read
    # no noise at all, and the limit is then half a count's
    theta, force, torque = _resting_loads(antenna, 600)
    torque = np.round((torque + np.random.default_rng(3).normal(0.0, 2e-5, torque.shape)) / 1e-4)
    assert list(settled_loads(theta, force, torque * 1e-4, antenna, 50)) == [600] * 6


@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
def test_the_head_puts_into_the_link_the_energy_its_push_holds(case: str) -> None:
    # Passivity: the work of the head's turn against the contact's moment is the energy the
    # push stores in the link, Gamma^2 x_c / (6 E I) for a contact that sticks, less the link's
    # kinetic energy at the sweep's speed (I omega^2 / 2, 4 to 6 % of it here) and more what the
    # contact dissipates. Far out on the link a swapped pair of angle columns passes the bend
    # check (the head's reach across the push is what a slide over a 10 mm post may take) and
    # was answered ok with the touched point 5 to 15 cm beside the object; its turn does no work.
    # Bounds: 0.85 leaves room for the kinetic energy and the push built before counting starts,
    # 1.1 for a little friction; swapped, the sensor's noise and cross-axis terms leave |W / E|
    # within 0.02 on the 24 recordings of docs/design-notes.md, "The head's work against the
    # push", and 0.05 is twice that and a tenth of the bar.
    model = load_antenna("paper-2021").self_calibrated()
    recording = simulate(model, Scenario(case=case, contact_point=0.8, seed=3))
    plain = recording.without_ground_truth()
    for name, result in all_methods(plain, model).items():
        assert 0.85 < result.diagnostics["work_share"] < 1.1, name
        assert result.status is not Status.IMPLAUSIBLE_INPUT, (name, result.reason)
    swapped = dataclasses.replace(plain, theta=np.ascontiguousarray(plain.theta[:, ::-1]))
    for name, result in all_methods(swapped, model).items():
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert "the two angles swapped" in (result.reason or ""), name
        assert abs(result.diagnostics["work_share"]) < 0.05, name


def test_a_slow_sweep_far_out_puts_in_what_the_push_holds_before_the_detector_fires() -> None:
    # At 0.02 rad/s and 0.95 m the detector fires more than a second after the touch: the
    # energy the push already held where the work's count starts must be taken off what it
    # holds at the end, or a right answer would be taken for swapped angles. Bounds as in the
    # passivity test above.
    model = load_antenna("paper-2021").self_calibrated()
    scenario = Scenario(
        case="azimuthal",
        contact_point=0.95,
        seed=3,
        sweep_speed=0.02,
        push=PushCriterion(threshold=0.015),
        duration=12.0,
    )
    recording = simulate(model, scenario)
    truth = float(recording.metadata["true_xc"])
    plain = recording.without_ground_truth()
    results = all_methods(plain, model)
    assert any(result.status is Status.OK for result in results.values())
    for name, result in results.items():
        assert result.status is not Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        if "work_share" in result.diagnostics:
            assert 0.85 < result.diagnostics["work_share"] < 1.1, name
        if result.status is Status.OK:
            assert abs(result.x_c - truth) < 0.01, name
    swapped = dataclasses.replace(plain, theta=np.ascontiguousarray(plain.theta[:, ::-1]))
    for name, result in all_methods(swapped, model).items():
        if "work_share" in result.diagnostics:
            assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
            assert abs(result.diagnostics["work_share"]) < 0.05, name


def test_a_drifting_sensor_over_a_long_approach_does_not_count_against_the_work() -> None:
    # ty drifting by 2 counts/s over a 20 s approach: the tare at the start is 40 counts
    # (1.25 mN m) off by the touch. Counted from the start, that offset against the whole
    # sweep's turn (1 rad) takes the share to 0.18 on a right answer; counted from 0.3 s before
    # t_c it weighs on the push's turn alone.
    model = load_antenna("paper-2021").self_calibrated()
    drift = (0.0, 0.0, 0.0, 0.0, -2.0 / 32000.0, 0.0)  # N m/s: 2 counts/s of 1/32000 N m
    scenario = Scenario(
        case="vertical",
        contact_point=0.5,
        seed=3,
        sweep_speed=0.05,
        push=PushCriterion(threshold=0.015),
        approach_time=20.0,
        duration=23.6,
        device=DeviceImperfections(sensor_drift_rate=drift),
    )
    recording = simulate(load_antenna("paper-2021"), scenario)
    for name, result in all_methods(recording.without_ground_truth(), model).items():
        if "work_share" in result.diagnostics:
            assert 0.85 < result.diagnostics["work_share"] < 1.3, name
        assert result.status is not Status.IMPLAUSIBLE_INPUT, (name, result.reason)


def test_a_link_stiffer_than_the_model_is_a_mismatch_not_swapped_angles() -> None:
    # A link 2.5 times stiffer stores 1 / 2.5 of the energy the model expects for the same
    # push (E = Gamma^2 x_c / (6 E I)), so the head's work is 0.4 of it, less the kinetic
    # energy term of the passivity test: the model is wrong, not the samples' columns or units.
    nominal = load_antenna("paper-2021")
    stiff_link = dataclasses.replace(nominal.link, youngs_modulus=2.5 * nominal.link.youngs_modulus)
    device = dataclasses.replace(nominal, link=stiff_link)
    recording = simulate(device, Scenario(case="azimuthal", contact_point=0.55, seed=3))
    results = all_methods(recording.without_ground_truth(), nominal.self_calibrated())
    shares = [
        r.diagnostics["work_share"] for r in results.values() if "work_share" in r.diagnostics
    ]
    assert shares
    for share in shares:
        assert 0.3 < share < 0.5
    for name, result in results.items():
        reasons = [result.reason or "", *result.diagnostics.get("other_reasons", [])]
        assert result.status not in (Status.OK, Status.IMPLAUSIBLE_INPUT), (name, result.reason)
        if "work_share" in result.diagnostics:
            assert any("a link stiffer than the model" in r for r in reasons), name


def test_samples_dropped_inside_the_push_do_not_hide_swapped_angles(
    vertical: Recording, antenna: Antenna
) -> None:
    # Three samples dropped 0.1 s into the push (a gap the estimators fill in): swapped columns
    # still do no work against the push's moment.
    k = gather(vertical, antenna).contact_index + 100
    kept = np.r_[0:k, k + 3 : vertical.t.size]
    gapped = dataclasses.replace(
        vertical,
        t=vertical.t[kept],
        theta=vertical.theta[kept, ::-1],
        force=vertical.force[kept],
        torque=vertical.torque[kept],
        extra={},
    )
    for name, result in all_methods(gapped, antenna).items():
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert abs(result.diagnostics["work_share"]) < 0.05, name


def test_torques_about_an_unstated_sensor_origin_are_named_where_the_estimators_disagree(
    antenna: Antenna, tmp_path: Path
) -> None:
    # A sensor whose origin S lies 25 mm behind the clamp, S - O = (-0.025, 0, 0), reads
    # Gamma_S = Gamma_O - (S - O) x F: the ratio reads x_c + 0.025 m near the base, where it is
    # sharp, and disagrees with the vibration. The reason names the metadata line that mends it;
    # stated, the answer is right and ok.
    recording = simulate(antenna, Scenario(case="azimuthal", contact_point=0.3, seed=3))
    truth = float(recording.metadata["true_xc"])
    origin = np.array([-0.025, 0.0, 0.0])
    about_s = dataclasses.replace(
        recording.without_ground_truth(),
        torque=recording.torque - np.cross(origin, recording.force),
        extra={},
    )
    result = estimate(about_s, antenna, "paper")
    assert result.status is Status.ESTIMATORS_DISAGREE, result.reason
    reason = result.reason or ""
    assert "'# torque_point' does not state" in reason
    stated = float(reason.split("along X^m: ")[1].split(" m more")[0])
    assert -0.04 < stated < -0.01  # the ratio's shift, x_c - ratio, near the base
    path = tmp_path / "about_s.csv"
    write_recording(about_s, path)
    lines = path.read_text().splitlines(keepends=True)
    lines.insert(2, "# torque_point: [-0.025, 0, 0]\n")
    path.write_text("".join(lines))
    mended = estimate(read_recording(path), antenna, "paper")
    assert mended.status is Status.OK, mended.reason
    assert abs(mended.x_c - truth) < 0.005


def test_a_disagreement_on_an_uncalibrated_model_names_calibration_first() -> None:
    # A lab that skipped calibration, its datasheet E 20 % high: the frequency puts the contact
    # at 0.3 m some 4 cm short, the ratio does not follow. A torque point would shift every
    # contact alike, an uncalibrated T by an amount that varies along the link: the reason
    # says to calibrate first when no calibration measured T, and not once one did
    device = paper_antenna()
    stiff = dataclasses.replace(device.link, youngs_modulus=1.2 * device.link.youngs_modulus)
    model = dataclasses.replace(device, link=stiff)
    assert model.link.calibrated_t is None
    recording = simulate(device, Scenario(case="azimuthal", contact_point=0.3, seed=3))
    result = estimate(recording.without_ground_truth(), model, "paper")
    assert result.status is Status.ESTIMATORS_DISAGREE, result.reason
    assert "calibrate first (antenna calibrate)" in (result.reason or "")
    calibrated_t = dataclasses.replace(stiff, calibrated_t=stiff.t_param)
    claimed = estimate(
        recording.without_ground_truth(), dataclasses.replace(model, link=calibrated_t), "paper"
    )
    assert "calibrate first" not in (claimed.reason or "")


def test_a_link_that_slides_aside_on_a_steep_surface_is_not_a_flipped_sign() -> None:
    # An exploration's vertical sweep up onto a lying cylinder's side, steep to the sweep: the
    # link slid aside and pushes nearly across the head's turn (its component along the turn,
    # 0.5 mN, within one standard error of the hold's reaction), while the turn moved the
    # touched point 5.9 mm along the push. Neither is a sign flipped or a joint swapped.
    recording = read_recording(Path(__file__).parent / "data" / "steep_side_vertical_0.75.csv")
    truth = float(recording.metadata["true_xc"])
    model = load_antenna(Path(__file__).parent / "data" / "explore-calibrated.toml")
    results = all_methods(recording.without_ground_truth(), model)
    for name, result in results.items():
        assert result.status is not Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert result.status is not Status.MODEL_MISMATCH, (name, result.reason)
        if result.ok:  # right: within 1 cm (the wrong-ok threshold of the explorations' map)
            assert abs(result.x_c - truth) < 0.01, name
    fast = results["fast"]
    assert fast.ok and fast.interval is not None
    assert fast.interval[0] <= truth <= fast.interval[1]


def test_angles_in_degrees_are_named_even_when_the_recording_ends_before_the_push(
    vertical: Recording, antenna: Antenna
) -> None:
    # The elevation in degrees starts the sweep at -6.2 "rad"; with an observer of low
    # threshold and gain (as an identification on another device may give) the detector fires
    # within 50 ms of the turn's start (0.1 s) and the free motion's torque does not look 57
    # times too small. The recording ends 0.1 s later, before any push: the answer blames the
    # degrees, not the missing push.
    observer = dataclasses.replace(
        antenna.observer, contact_threshold=1e-4, gain=0.4 * antenna.observer.gain
    )
    model = dataclasses.replace(antenna, observer=observer)
    degrees = scaled(vertical, angle=DEGREES)
    t_c = estimate(degrees, model).t_c
    assert t_c is not None and t_c < 0.15
    cut = samples_kept(degrees, degrees.t <= t_c + 0.1)
    for name, result in all_methods(cut, model).items():
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert "angles in degrees?" in (result.reason or ""), name


def test_a_recording_joined_too_close_to_the_contact_to_tare_is_not_ok(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # Joined mid-sweep, 0.25 s before the touch: no rest and too little approach to read the
    # sensor's offset on, which then stays in the push, the ratio and the touched point
    t_c = all_methods(azimuthal, antenna)["paper"].t_c
    assert t_c is not None
    joined = samples_kept(azimuthal, azimuthal.t >= t_c - 0.25)
    for name, result in all_methods(joined, antenna).items():
        reasons = [result.reason or "", *result.diagnostics.get("other_reasons", [])]
        assert result.diagnostics["tare"] == "none", name
        assert not result.ok, name
        assert any("too little to tare the sensor on" in text for text in reasons), name


def test_a_link_that_slid_past_a_ball_is_slip_not_a_flipped_sign(antenna: Antenna) -> None:
    # A sweep down onto a small ball hit 0.49 rad off its top: the exact link pushes it until
    # t_1, then slides over it and springs back against its underside, so the hold's reaction
    # points along the turn. The signs are right (the push at t_1 opposed the turn), and the
    # answer says the link slid off rather than that a column is flipped.
    scenario = Scenario(
        case="vertical",
        sweep_direction=-1,
        contact_point=0.54,
        obstacle="ball",
        obstacle_radius=0.0121,
        obstacle_tilt=-0.49,
        link_model="nonlinear",
        seed=2,
        duration=4.0,
    )
    recording = simulate(antenna, scenario)
    assert recording.metadata["true_in_contact_at_end"] == "false"
    for name, result in all_methods(recording.without_ground_truth(), antenna).items():
        reasons = [result.reason or "", *result.diagnostics.get("other_reasons", [])]
        assert result.status is Status.SLIP_SUSPECTED, (name, result.reason)
        assert any("the link slid off the object or past it" in text for text in reasons), name


def test_a_torque_column_of_1e300_gives_a_status_not_a_traceback(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # tx scaled by 1e300: the tare's torque noise is 1e297 N m, whose square overflows a float
    # (an OverflowError in the ratio's uncertainty); the rest reading names the columns instead
    recording = dataclasses.replace(
        azimuthal, torque=azimuthal.torque * np.array([1e300, 1.0, 1.0])
    )
    for name, result in all_methods(recording, antenna).items():
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert_on_link_or_none(result, antenna)


def test_a_best_guess_past_the_tip_is_dropped_with_the_reason(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # Forces halved: Eq. 21 reads 1.09 m on a 0.98 m link
    result = estimate(scaled(azimuthal, force=0.5), antenna, method="ratio")
    assert math.isnan(result.x_c)
    assert result.status is Status.MODEL_MISMATCH
    assert np.all(np.isnan(result.contact_point))
    assert "outside the link" in (result.reason or "")
    assert result.ratio_estimate > antenna.link.length  # the raw reading stays a diagnostic


@pytest.fixture(scope="module")
def gentle_tip(antenna: Antenna) -> Recording:
    # A contact at the very tip pushed gently (0.015 rad past the contact): the ratio's reading
    # is noisy there and lands a few centimetres past the tip
    push = PushCriterion("rotation", 0.015)
    scenario = Scenario(case="azimuthal", contact_point=0.98, seed=5, push=push)
    return simulate(antenna, scenario).without_ground_truth()


def test_a_reading_just_past_the_tip_is_a_contact_at_the_tip(
    gentle_tip: Recording, antenna: Antenna
) -> None:
    length = antenna.link.length
    gathered = gather(gentle_tip, antenna)
    result = conclude(gathered, "ratio")
    past = result.diagnostics["x_c_past_tip"]
    # within three statistical uncertainties of the ratio past the tip: the contact cannot lie
    # beyond l, so the estimate constrained to the link is l
    assert isinstance(gathered, Evidence)
    assert length < past <= length + 3.0 * gathered.ratio_uncertainty(length, model=False)
    # no plausibility problem; the ratio alone is uncertain by centimetres at the tip
    assert result.status is Status.UNCERTAIN and "torque/force ratio is uncertain" in (
        result.reason or ""
    )
    assert result.x_c == length
    assert abs(np.linalg.norm(result.contact_point) - length) < 0.1 * length


def test_a_reading_well_past_the_tip_is_a_model_mismatch(
    gentle_tip: Recording, antenna: Antenna
) -> None:
    # torques 20 % high (within the rest check's tolerance): the ratio reads 1.2 m
    result = estimate(scaled(gentle_tip, torque=1.2), antenna, method="ratio")
    assert result.status is Status.MODEL_MISMATCH
    assert math.isnan(result.x_c)
    assert "outside the link" in (result.reason or "")


@pytest.mark.parametrize("method", sorted(METHODS))
def test_the_layer_judges_online_as_offline(
    azimuthal: Recording, antenna: Antenna, method: str
) -> None:
    recording = scaled(azimuthal, force=0.5)
    offline = estimate(recording, antenna, method=method)
    online = OnlineEstimator(antenna, recording.sample_period, method=method)
    online.update_block(recording.t, recording.theta, recording.force, recording.torque)
    result = online.finalize()
    assert result.status is offline.status is not Status.OK
    assert result.reason == offline.reason
    assert result.x_c == offline.x_c or (math.isnan(result.x_c) and math.isnan(offline.x_c))


def test_an_unmodelled_tip_mass_is_named_by_the_vibration_methods() -> None:
    # 0.2 g of glue at the tip (4 % of the link's mass), not in the antenna file: it lowers
    # omega_1 and the vibration's contact point at 0.35 m moves about 5 cm out (docs/simulator.md,
    # eval_device). At rest the link's moment ty exceeds the model's weight by m_t g l = 1.9e-3
    # N m, some 30 times the tare's two-count offset: read as a payload it would move the
    # frequency's point by centimetres, so the paper and two-frequency methods say
    # model_mismatch. The fast method carries the payload's shift of omega_1 in its posterior:
    # the ratio then holds its answer near the contact, within an interval too wide to be sure
    # of, and the reason names the payload. The ratio, whose statics do not weigh the link, is
    # not judged by it
    from sensing_antenna.simulator.device import DeviceImperfections

    device = calibrated()
    simulated = simulate(
        paper_antenna(),
        Scenario(
            case="azimuthal",
            contact_point=0.35,
            seed=3,
            device=DeviceImperfections(tip_mass=0.2e-3),
        ),
    )
    truth = float(simulated.metadata["true_xc"])
    recording = simulated.without_ground_truth()
    for method in ("paper", "two-frequency"):
        result = estimate(recording, device, method)
        assert result.status is Status.MODEL_MISMATCH, (method, result.reason)
        assert "link.tip_mass" in (result.reason or "")
        # about 4 to 5 cm, by where each method's answer sits (0.30 to 0.31 m)
        assert 0.035 < result.diagnostics["payload_spread"] < 0.06
    fast = estimate(recording, device, "fast")
    assert fast.status is Status.UNCERTAIN, fast.reason
    assert "link.tip_mass" in (fast.reason or "")
    assert fast.interval is not None and fast.interval[0] <= truth <= fast.interval[1]
    assert "payload_spread" not in estimate(recording, device, "ratio").diagnostics
    # without the payload: the tare's offset alone moves it by a millimetre or two at most
    nominal = simulate(
        paper_antenna(), Scenario(case="azimuthal", contact_point=0.35, seed=3)
    ).without_ground_truth()
    for method in ("paper", "fast"):
        result = estimate(nominal, device, method)
        assert result.status is Status.OK, result.reason
        assert result.diagnostics.get("payload_spread", 0.0) < 0.003  # absent: read lighter


def test_torques_about_a_point_behind_the_clamp_read_as_a_payload_name_that_point() -> None:
    # The sensor's origin 2.5 cm behind the clamp, not stated: at rest the weight W reads
    # 0.025 W more moment, as 0.12 g at the tip would; with a third of the simulated sensor's
    # noise (whose force noise the offset also moves into the moment) that is a payload. The
    # reason gives both readings, the point within the millimetre the line prints plus what the
    # tare's offset moves
    scenario = Scenario(case="azimuthal", contact_point=0.35, seed=3, noise_scale=0.3)
    simulated = simulate(paper_antenna(), scenario)
    point = np.array([-0.025, 0.0, 0.0])
    behind = dataclasses.replace(
        simulated, torque=simulated.torque - np.cross(point, simulated.force)
    ).without_ground_truth()
    result = estimate(behind, calibrated(), "paper")
    assert result.status is Status.MODEL_MISMATCH, result.reason
    named = float((result.reason or "").split("'# torque_point: [")[1].split(",")[0])
    assert named == pytest.approx(-0.025, abs=0.002)


@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
def test_a_payload_too_light_for_a_mismatch_widens_the_fast_interval(case: str) -> None:
    # 0.05 g of glue at 0.55 m: the weight at rest reads it (3.8e-4 N m against a tare's
    # 2-count offset of 6e-5), and it moves the vibration's contact point about 1.1 cm, under
    # the 1 cm the payload check would call a mismatch at the answer. Without its shift in
    # the posterior the fast method answered ok, 1.1 cm short, its 95 % interval (6 to 8 mm
    # wide) missing the contact; with it the interval holds the contact
    model = load_antenna("paper-2021").self_calibrated()
    seed = 550 if case == "azimuthal" else 557
    simulated = simulate(
        load_antenna("paper-2021"),
        Scenario(
            case=case, contact_point=0.55, seed=seed, device=DeviceImperfections(tip_mass=5e-5)
        ),
    )
    truth = float(simulated.metadata["true_xc"])
    result = estimate(simulated.without_ground_truth(), model, "fast")
    assert result.interval is not None and result.interval[0] <= truth <= result.interval[1]
    if not result.ok:
        assert "link.tip_mass" in (result.reason or ""), result.reason


def test_a_payload_is_named_when_the_second_mode_could_narrow_at_the_cap() -> None:
    # With omega_2 calibrated (mode2_scatter), the cap's narrowing by the second mode and its
    # check of the frequency read the model's curves without the payload: 0.05 g at 0.6 m came
    # back estimators_disagree, omega_1 6.7 standard deviations off, and the reason asked about
    # torque_point. The payload lowers omega_2 as well: no narrowing with one
    base = paper_antenna().self_calibrated()
    model = dataclasses.replace(base, link=dataclasses.replace(base.link, mode2_scatter=0.005))
    device = DeviceImperfections(tip_mass=5e-5)
    simulated = simulate(
        model, Scenario(case="azimuthal", contact_point=0.6, seed=2, device=device)
    )
    truth = float(simulated.metadata["true_xc"])
    result = estimate(simulated.without_ground_truth(), model, "fast")
    assert result.interval is not None and result.interval[0] <= truth <= result.interval[1]
    assert result.status is Status.UNCERTAIN, result.reason
    assert "link.tip_mass" in (result.reason or "")


def test_angles_in_degrees_are_caught_with_an_identified_observer() -> None:
    # An identified observer's contact threshold is low (about 0.2 mN m against the paper's
    # 20): with the angles in degrees it predicts 57 times the torque, and the detector fires
    # within the first tens of milliseconds of motion; over that short free motion the measured
    # torque is about 1/8 of the prediction, not 1/57, and still below 1/5 of it
    from sensing_antenna.calibration.observer import identify_free_motion

    device = paper_antenna()
    free = simulate(device, Scenario(case="free", duration=3.0, seed=1)).without_ground_truth()
    fit = identify_free_motion(free, device)
    model = dataclasses.replace(calibrated(), observer=fit.observer)
    recording = simulate(
        device, Scenario(case="azimuthal", contact_point=0.55, seed=2)
    ).without_ground_truth()
    assert estimate(recording, model).status is Status.OK
    degrees = dataclasses.replace(recording, theta=DEGREES * recording.theta)
    for method in ("paper", "fast"):
        result = estimate(degrees, model, method)
        assert result.status is Status.IMPLAUSIBLE_INPUT, (method, result.reason)
        assert "angles not in radians" in (result.reason or "")
    # the same when the recording is right and the antenna file's observer is another
    # device's (its gain a hundred times too large): the reason names both causes
    other = dataclasses.replace(
        model, observer=dataclasses.replace(model.observer, gain=100.0 * model.observer.gain)
    )
    result = estimate(recording, other, "paper")
    assert result.status is Status.IMPLAUSIBLE_INPUT, result.reason
    assert "observer is not this device's" in (result.reason or "")


def test_degrees_prediction_is_told_from_noise_over_a_short_free_motion() -> None:
    # Half a second at rest, then 25 ms of a turn's start (torque growing as t^3) before a tight
    # threshold fires: the prediction p reaches 0.5 mN m, the sensor's noise is 30 uN m. With
    # the angles in degrees the measured torque is p / 57 plus noise, whose root mean square
    # over the 525 samples is about a fifth of p's: the ratio of root mean squares cannot tell
    # it from a free motion, the projection (noise 0.03 of it here) can
    antenna = paper_antenna()
    rng = np.random.default_rng(3)
    n, turn = 525, 25
    p = np.zeros(n)
    p[-turn:] = 5e-4 * (np.arange(1, turn + 1) / turn) ** 3
    theta = np.zeros((n, 2))
    gravity = antenna.gravity_torque(theta[:, 1])
    predicted = gravity.copy()
    predicted[:, 2] += p

    def gain(measured: np.ndarray) -> tuple[float, str | None]:
        torque = gravity + 0.0
        torque[:, 1:] += 3e-5 * rng.standard_normal((n, 2))
        torque[:, 2] += measured
        return free_motion_gain(theta, torque, predicted, antenna, EstimatorConfig())

    value, problem = gain(p / DEGREES)
    assert problem is not None and "degrees give 1/57" in problem
    assert value == pytest.approx(1.0 / DEGREES, abs=3 * 0.03)
    assert gain(p)[1] is None
    # a prediction buried in the noise cannot be judged either way
    p[-turn:] *= 0.05
    predicted[:, 2] = gravity[:, 2] + p
    assert gain(p / DEGREES)[1] is None


@pytest.mark.parametrize("x_c", [0.35, 0.6])
def test_a_head_turned_back_before_t_e_is_not_read_as_wrong_columns(x_c: float) -> None:
    # The head turns back 0.2 s after the stop, within the paper method's window: the link
    # releases the push's energy into the head, which the work count up to t_e read as the
    # angles or torques not describing the turn (implausible_input). Counted up to the turn,
    # the answer stands: within a centimetre of where the held link touched
    scenario = Scenario(case="azimuthal", contact_point=x_c, seed=1)
    truth = float(simulate(paper_antenna(), scenario).metadata["true_xc"])
    back = simulate(paper_antenna(), dataclasses.replace(scenario, retract_after=0.2))
    for method in ("paper", "fast"):
        result = estimate(back.without_ground_truth(), calibrated(), method)
        reasons = [result.reason or "", *result.diagnostics.get("other_reasons", [])]
        assert not any("the head's turn did" in text for text in reasons), (method, reasons)
        if result.status is Status.OK:
            assert result.x_c == pytest.approx(truth, abs=0.01)


def test_torques_a_hundred_times_too_large_are_implausible_not_a_payload(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # Torques in N cm read as a moment at rest of some 2 N m beyond the link's weight: as a
    # payload that would be hundreds of grams, which the link could not carry. The units check
    # says what it is; no method reads it as weight
    scaled_torques = dataclasses.replace(azimuthal, torque=100.0 * azimuthal.torque)
    for name, result in all_methods(scaled_torques, antenna).items():
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert "payload_spread" not in result.diagnostics


def test_a_stiffer_calibration_bends_the_touched_point_less(azimuthal: Recording) -> None:
    # The push deflection of the touched point uses the stiffness the calibration measured (the
    # one its sag uses): T_e = 0.9 T makes the link 1 / 0.81 times stiffer, so the same push
    # deflects it 0.81 times as much, to first order in the deflection (the elastica's second
    # order terms move that by 3e-4 at this gentle push)
    own = calibrated()
    stiffer = own.with_calibrated_t(0.9 * own.link.t_param, 0.001)
    gathered = gather(azimuthal, own)
    a, b = conclude(gathered, "paper"), conclude(gather(azimuthal, stiffer), "paper")
    assert b.diagnostics["deflection"] / a.diagnostics["deflection"] == pytest.approx(
        0.81 * (b.x_c / a.x_c) ** 3, rel=1e-3
    )


def test_a_recording_that_starts_in_motion_is_told_to_start_at_rest() -> None:
    # A vertical sweep logged from 0.2 s on, the head already lifting the link: the moment
    # before the contact is read over the approach, where the motion adds to the weight. Read
    # as a payload it would move the answer; the reason says to start the recording at rest
    # rather than to give a payload the link does not carry
    antenna = paper_antenna().self_calibrated()
    recording = simulate(antenna, Scenario(case="vertical", contact_point=0.7, seed=3))
    late = samples_kept(recording.without_ground_truth(), slice(200, None))
    late = dataclasses.replace(late, t=late.t - late.t[0])
    result = estimate(late, antenna)
    assert result.diagnostics["tare"] == "approach"
    assert result.status is not Status.OK
    assert "start the recording with half a second at rest" in (result.reason or "")
    assert "link.tip_mass" not in (result.reason or "")


def test_forces_in_kilonewtons_are_implausible_input_first(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # Forces a thousand times too small pass the rest check (a few mN off the link's weight,
    # within what a tare leaves); the torque/force ratio then reads a thousand times the contact
    # point the vibration gives, which is the reason given, before any other (the ratio's
    # convergence, which more recording would not mend)
    for name, result in all_methods(scaled(azimuthal, 1e-3, 1.0), antenna).items():
        if name == "ratio":
            assert not result.ok, (name, result.reason)
            continue
        assert result.status is Status.IMPLAUSIBLE_INPUT, (name, result.reason)
        assert "times the contact point" in (result.reason or ""), name


def test_loads_beyond_any_device_warn_no_more_online_than_offline(
    azimuthal: Recording, antenna: Antenna
) -> None:
    # Torques of 1e150 N m overflow the fast method's arithmetic; offline its conclusion keeps
    # NumPy quiet and the status judges the result. The online form's early evaluations do too
    # (the test suite turns any RuntimeWarning into an error)
    recording = scaled(azimuthal, 1.0, 1e150)
    offline = estimate(recording, antenna, "fast")
    online = OnlineEstimator(antenna, recording.sample_period, "fast")
    given = online.update_block(
        recording.t, recording.theta, recording.force, recording.torque, every_instant=True
    )
    result = given if given is not None else online.finalize()
    assert not result.ok and result.status is offline.status


@pytest.mark.parametrize("method", ["paper", "fast"])
def test_an_omega_1_the_model_misplaces_is_told_by_omega_2_and_the_statics(method: str) -> None:
    # An antenna file whose E is 10 % high and claims a tight calibration: its omega_1 at every
    # x_c is sqrt(1.1) times the device's. At 0.8 m, near the sensing curve's top, that moves
    # the answer 3.8 cm with the ratio still within its uncertainty. omega_2 / omega_1, which T
    # does not enter, and the statics agree where the link touched, and the measured omega_1
    # is the model's there over sqrt(1.1): the status says so. With the right file the answer
    # is right and not said to be off
    device = paper_antenna().self_calibrated()
    stiff = dataclasses.replace(
        paper_antenna().link, youngs_modulus=1.1 * paper_antenna().link.youngs_modulus
    )
    wrong_file = dataclasses.replace(paper_antenna(), link=stiff).self_calibrated()
    recording = simulate(device, Scenario(case="vertical", contact_point=0.8, seed=1))
    truth = float(recording.metadata["true_xc"])
    right = estimate(recording, device, method=method)  # fast: unsure at the curve's top
    assert right.status in (Status.OK, Status.UNCERTAIN) and abs(right.x_c - truth) < 0.01
    wrong = estimate(recording, wrong_file, method=method)
    assert wrong.status is Status.MODEL_MISMATCH
    assert "which T does not enter" in (wrong.reason or "")
    # the two readings' point within the 1 cm the estimators aim at, the scale within the
    # frequency floor of the fast method (0.3 %) of the modulus's
    assert abs(wrong.diagnostics["mode_ratio_point"] - truth) < 0.01
    assert wrong.diagnostics["mode_ratio_scale"] == pytest.approx(1.1**-0.5, abs=0.003)


def test_a_soft_object_whose_second_mode_is_gone_is_not_ok() -> None:
    # An object of contact stiffness 50 N/m (foam) at 0.6 m: the support's give lowers omega_1
    # (c_1 = 6.5 N/m, beam.modes.support_compliance_coefficients) and the answer falls 2.8 cm
    # short, within the statics' uncertainty; the second mode (c_2 = 17 N/m) moves 20 % and
    # the contact's damping takes it out of the spectrum. The rigid post at the same point
    # rings it in place and stays ok.
    device = paper_antenna()
    model = calibrated(device)
    rigid = simulate(device, Scenario(case="azimuthal", contact_point=0.6, seed=3))
    soft = simulate(
        device, Scenario(case="azimuthal", contact_point=0.6, seed=3, contact_stiffness=50.0)
    )
    held = estimate(rigid.without_ground_truth(), model, "paper")
    assert held.status is Status.OK
    assert held.diagnostics["second_mode_quality"] >= 20.0  # min_peak_quality
    given = estimate(soft.without_ground_truth(), model, "paper")
    assert given.status is Status.UNCERTAIN
    assert given.reason is not None and given.reason.startswith("no second contact mode")
    assert given.x_c == pytest.approx(0.572, abs=0.003)  # 2.8 cm short, as before
    # the fast method answers on fewer samples: on the post its spectrum cannot part the second
    # mode from 3 omega_1 (not judged there, nor told by the post's low damping); at the soft
    # answer (0.42 s from t_1) the second mode's place lies clear of the harmonics, and is empty
    held = estimate(rigid.without_ground_truth(), model, "fast")
    assert held.status is Status.OK
    given = estimate(soft.without_ground_truth(), model, "fast")
    assert given.status is Status.UNCERTAIN
    assert given.reason is not None and given.reason.startswith("no second contact mode")
    assert given.x_c == pytest.approx(0.572, abs=0.003)
    # the fast method's interval widened to the statics' (it held 0.568 to 0.573 m before)
    assert given.interval is not None and given.interval[0] < 0.6 < given.interval[1]
    assert given.diagnostics["interval_before_support"][1] < 0.6


def test_a_soft_object_on_a_node_of_the_second_mode_is_told_by_its_damping() -> None:
    # At 0.5 m the contact sits where the second contact mode's shear is continuous (the free
    # link's third mode has its node at 0.49 l): a give does not move that mode (c_2 = 0), and
    # the second mode says nothing. An object of 100 N/m lowers omega_1 by 2.1 cm's worth and
    # damps the fundamental to about 3 times the link's own (0.005 in the simulator, what an
    # identified observer reads, 0.0054 on the default campaign's device); a rigid post does
    # not.
    device = paper_antenna()
    base = calibrated(device)
    own = 0.0054
    observer = dataclasses.replace(
        base.observer, damping=2.0 * own * base.observer.natural_frequency
    )
    model = dataclasses.replace(base, observer=observer)
    rigid = simulate(device, Scenario(case="azimuthal", contact_point=0.5, seed=3))
    soft = simulate(
        device, Scenario(case="azimuthal", contact_point=0.5, seed=3, contact_stiffness=100.0)
    )
    held = estimate(rigid.without_ground_truth(), model, "paper")
    assert held.status is Status.OK
    given = estimate(soft.without_ground_truth(), model, "paper")
    assert given.x_c == pytest.approx(0.479, abs=0.003)
    assert given.status is Status.UNCERTAIN
    assert given.reason is not None and "decays with a damping ratio" in given.reason
    zeta, sigma = given.diagnostics["fundamental_damping"]
    assert zeta - 3.0 * sigma > 2.0 * own


@pytest.mark.parametrize("method", ["paper", "fast"])
def test_a_detection_on_a_knock_before_the_touch_is_said_and_the_hold_still_read(
    method: str,
) -> None:
    # A knock during the sweep (a 50 Hz burst of 0.3 N and 0.03 N m on every channel, from
    # 0.3 to 0.8 s) fires the contact detector at about 0.31 s, 0.6 s before the link touches
    # the post; the recording's head, stopped by its own detector, sweeps on. The residual,
    # averaged over a free period, falls once the burst ends, before the head comes to rest at
    # t_1: the answer reads the real touch's hold, and is said to be uncertain for its t_c,
    # not a bend the head's turn did not make.
    recording = simulate(
        paper_antenna(), Scenario(case="azimuthal", contact_point=0.6, seed=1)
    ).without_ground_truth()
    knock = knocked(recording)
    result = estimate(knock, calibrated(), method)
    assert result.t_c < 0.4
    assert result.status is Status.UNCERTAIN
    assert re.search(
        r"the contact found at t_c = 0\.3\d\d s faded before the head came to rest",
        result.reason or "",
    )
    assert abs(result.x_c - 0.6) < 0.01


def test_readings_at_the_sensors_range_are_bad_input_when_the_range_is_stated() -> None:
    # A sensor sized close to the loads: its torque channels clip at 90 % of what the push
    # reached, with one count of noise on the clipped samples (a saturated gauge read through
    # the calibration matrix with live ones). Stated in the antenna (sensor_range), the range
    # makes the answer bad_input naming the column; twice the loads, nothing changes.
    from sensing_antenna.antenna import SensorRange

    recording = simulate(
        paper_antenna(), Scenario(case="azimuthal", contact_point=0.6, seed=3)
    ).without_ground_truth()
    peak = float(np.max(np.abs(recording.torque)))
    limit = 0.9 * peak
    clipped = np.clip(recording.torque, -limit, limit)
    hit = np.abs(recording.torque) > limit
    clipped[hit] += np.random.default_rng(0).normal(0.0, 3.1e-5, int(hit.sum()))
    sized = SensorRange(force=(25.0, 25.0, 35.0), torque=(limit, limit, limit))
    model = dataclasses.replace(calibrated(), sensor_range=sized)
    result = estimate(dataclasses.replace(recording, torque=clipped), model, "paper")
    assert result.status is Status.BAD_INPUT
    assert re.search(r"column 't[xyz]': .* % of the sensor's range of", result.reason or "")
    roomy = SensorRange(force=(25.0, 25.0, 35.0), torque=(2 * peak, 2 * peak, 2 * peak))
    plain = estimate(recording, calibrated(), "paper")
    within = estimate(recording, dataclasses.replace(calibrated(), sensor_range=roomy), "paper")
    assert (within.status, within.x_c) == (plain.status, plain.x_c)


def test_a_detector_firing_on_a_damped_links_swing_says_the_link_may_have_touched_nothing() -> None:
    # A link damped to 6 % (a foam coat) under a detector whose threshold its swing crosses
    # (the one identified on the default campaign's device at 0.5 % damping, tests/data: 0.14
    # mN m): the head stops before the bar and the hold's force, a few mN, does not oppose the
    # turn. More than ten of its standard errors, but less than a contact that sticks at the
    # tip would push back with for that turn: the reason says the link may have touched nothing
    # besides the wiring's causes
    identified = load_antenna(Path(__file__).parent / "data" / "realistic-2021-device.toml")
    device = paper_antenna()
    device = dataclasses.replace(
        device,
        observer=dataclasses.replace(
            device.observer, contact_threshold=identified.observer.contact_threshold
        ),
    )
    recording = simulate(
        device, Scenario(case="vertical", contact_point=0.5, seed=1, damping_ratio=0.06)
    )
    assert math.isnan(float(recording.metadata["true_t_contact"]))  # nothing was touched
    result = estimate(recording.without_ground_truth(), device.self_calibrated())
    assert result.status is Status.IMPLAUSIBLE_INPUT
    assert re.search(
        r"or the link touched nothing: \S+ mN is less than a contact that sticks",
        result.reason or "",
    )
    # the swing the detector fired on fades after the head rests, dated before it: t_c was no
    # touch, though known only after t_1 (one rule: by when the fade began)
    faded = [r for r in result.diagnostics["other_reasons"] if "faded before the head" in r]
    assert faded and result.diagnostics["contact_lost_before_rest"] > result.t_1
