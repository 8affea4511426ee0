"""ROS bags to recordings: bags written by the rosbags library's own writers (ROS 1 and ROS 2)
from a simulated manoeuvre, imported, and estimated.

The reference is the simulated recording itself: a bag written at the recording's own instants,
with its angles and loads, must come back as the same recording, to the bit, and so give the same
estimate. Stamps with jitter and dropped messages must be reported as they were made.
"""

from __future__ import annotations

import dataclasses
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_typestore

from _models import calibrated
from sensing_antenna.cli import main
from sensing_antenna.estimation import estimate
from sensing_antenna.importers import AxesError, ImporterError, SensorAxes
from sensing_antenna.importers.rosbag import read_rosbag
from sensing_antenna.recording import Recording, read_recording
from sensing_antenna.simulator import Scenario, simulate

#: An arbitrary epoch for the bags' stamps (ns): 2023-11-14, as a real log's would be.
EPOCH_NS = 1_700_000_000_000_000_000
WRENCH, JOINTS = "/ft_sensor/wrench", "/head/joint_states"


@pytest.fixture(scope="module")
def recording() -> Recording:
    """A simulated azimuthal manoeuvre into a post (the project's simulator), without the
    ground truth a device would not have."""
    scenario = Scenario(case="azimuthal", contact_point=0.45, seed=7)
    return simulate(calibrated(), scenario).without_ground_truth()


def _write_bag(
    path: Path,
    recording: Recording,
    ros: int,
    *,
    wrench_ns: NDArray[np.int64] | None = None,
    joints_ns: NDArray[np.int64] | None = None,
    joints_header_ns: NDArray[np.int64] | None = None,
    wrench_kept: Sequence[int] | None = None,
    names: Sequence[str] = ("pan", "tilt"),
    sensor: NDArray[np.float64] | None = None,
    wrench_type: str = "geometry_msgs/msg/WrenchStamped",
    headers_unset: bool = False,
    other_publisher_every: int = 0,
    nan_at: Sequence[int] = (),
) -> Path:
    """Write the recording as a bag: one WrenchStamped and one JointState message per sample.

    ``wrench_ns``/``joints_ns`` are the header stamps and the bag's record times (default:
    EPOCH_NS + t in ns); ``joints_header_ns``, when given, the joints' header stamps instead;
    ``wrench_kept`` the samples whose wrench message is written (default all); ``names`` the
    joints of each JointState message, where ``pan`` carries theta1 and ``tilt`` theta2 and any
    other name 0; ``sensor`` R with v_sensor = R @ v_motor (default the identity);
    ``headers_unset`` writes every header stamp as 0, the stamps only as the bag's record times;
    ``other_publisher_every`` > 0 adds, every so many samples, a JointState message of another
    publisher on the same topic, 1 ns before the head's, naming only a ``gripper`` joint;
    ``nan_at`` the samples whose wrench message reads NaN.
    """
    store = get_typestore(Stores.ROS2_HUMBLE if ros == 2 else Stores.ROS1_NOETIC)
    types = store.types
    serialize = store.serialize_cdr if ros == 2 else store.serialize_ros1
    stamps_ns = EPOCH_NS + np.rint(recording.t * 1e9).astype(np.int64)
    wrench_ns = stamps_ns if wrench_ns is None else wrench_ns
    joints_ns = stamps_ns if joints_ns is None else joints_ns
    joints_header = joints_ns if joints_header_ns is None else joints_header_ns
    kept = range(recording.n_samples) if wrench_kept is None else wrench_kept
    matrix = np.eye(3) if sensor is None else sensor
    force, torque = recording.force @ matrix.T, recording.torque @ matrix.T
    force[list(nan_at)] = np.nan
    vector = types["geometry_msgs/msg/Vector3"]

    def header(k: int, stamp: int) -> object:
        stamp = 0 if headers_unset else stamp
        time = types["builtin_interfaces/msg/Time"](sec=stamp // 10**9, nanosec=stamp % 10**9)
        fields = {"stamp": time, "frame_id": "sensor"}
        return types["std_msgs/msg/Header"](**fields, **({"seq": k} if ros == 1 else {}))

    writer = Writer2(path, version=9) if ros == 2 else Writer1(path)
    with writer:
        wrench_connection = writer.add_connection(WRENCH, wrench_type, typestore=store)
        joints_connection = writer.add_connection(
            JOINTS, "sensor_msgs/msg/JointState", typestore=store
        )
        for k in kept:
            if wrench_type.endswith("WrenchStamped"):
                message = types[wrench_type](
                    header=header(k, int(wrench_ns[k])),
                    wrench=types["geometry_msgs/msg/Wrench"](
                        force=vector(*force[k]), torque=vector(*torque[k])
                    ),
                )
            else:
                message = vector(*force[k])
            data = serialize(message, wrench_type)
            writer.write(wrench_connection, int(wrench_ns[k]), data)
        angle = {"pan": recording.theta[:, 0], "tilt": recording.theta[:, 1]}
        for k in range(recording.n_samples):
            message = types["sensor_msgs/msg/JointState"](
                header=header(k, int(joints_header[k])),
                name=list(names),
                position=np.array([angle[n][k] if n in angle else 0.0 for n in names]),
                velocity=np.zeros(0),
                effort=np.zeros(0),
            )
            data = serialize(message, "sensor_msgs/msg/JointState")
            writer.write(joints_connection, int(joints_ns[k]), data)
            if other_publisher_every and k % other_publisher_every == 0:
                other = types["sensor_msgs/msg/JointState"](
                    header=header(k, int(joints_ns[k]) - 1),
                    name=["gripper"],
                    position=np.array([0.5]),
                    velocity=np.zeros(0),
                    effort=np.zeros(0),
                )
                data = serialize(other, "sensor_msgs/msg/JointState")
                writer.write(joints_connection, int(joints_ns[k]) - 1, data)
    return path


def _bag_path(tmp_path: Path, ros: int) -> Path:
    return tmp_path / ("rec.bag" if ros == 1 else "rec_ros2")


def _assert_same_samples(imported: Recording, original: Recording) -> None:
    for name in ("t", "theta", "force", "torque"):
        np.testing.assert_array_equal(getattr(imported, name), getattr(original, name), name)


@pytest.mark.parametrize("ros", [1, 2])
def test_a_bag_at_the_recording_s_instants_gives_the_same_recording_and_estimate(
    ros: int, recording: Recording, tmp_path: Path
) -> None:
    bag = _write_bag(_bag_path(tmp_path, ros), recording, ros)
    result = read_rosbag(bag, WRENCH, JOINTS)
    _assert_same_samples(result.recording, recording)
    assert result.recording.sample_period == recording.sample_period == 0.001
    report = result.report
    assert report.ros_version == ros and report.joint_names == ("pan", "tilt")
    assert report.clock.wrench.n_messages == recording.n_samples
    assert report.clock.wrench.rate == pytest.approx(1000.0, rel=1e-12)
    assert report.clock.n_interpolated == report.clock.n_left_out == 0
    antenna = calibrated()
    expected = estimate(recording, antenna, method="paper").to_dict()
    assert expected["status"] == "ok"
    assert estimate(result.recording, antenna, method="paper").to_dict() == expected


def test_the_command_writes_the_recording_and_reports_on_stderr(
    recording: Recording, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bag = _write_bag(_bag_path(tmp_path, 1), recording, 1, names=("gripper", "tilt", "pan"))
    out = tmp_path / "rec.csv"
    argv = ["import", "rosbag", str(bag), "--wrench", WRENCH, "--joints", JOINTS]
    argv += ["--joint1", "pan", "--joint2", "tilt", "--antenna", "lab-1", "--out", str(out)]
    assert main(argv) == 0
    captured = capsys.readouterr()
    assert captured.out == f"{out}\n"
    assert "theta1 <- joint 'pan', theta2 <- joint 'tilt'" in captured.err
    assert f"{WRENCH} (geometry_msgs/msg/WrenchStamped): {recording.n_samples} messages" in (
        captured.err
    )
    written = read_recording(out)
    _assert_same_samples(written, recording)
    assert written.metadata["antenna"] == "lab-1"
    assert written.metadata["ros_joints"] == "theta1=pan, theta2=tilt"


def test_joints_default_to_the_two_names_of_the_first_message_and_more_must_be_named(
    recording: Recording, tmp_path: Path
) -> None:
    bag = _write_bag(_bag_path(tmp_path, 2), recording, 2, names=("tilt", "pan"))
    result = read_rosbag(bag, WRENCH, JOINTS)
    assert result.report.joint_names == ("tilt", "pan")
    np.testing.assert_array_equal(result.recording.theta, recording.theta[:, ::-1])
    # of three (ROS lists them in any order: a gripper's first, say), which two are the head's
    # is not guessed
    three = _write_bag(
        _bag_path(tmp_path / "three", 2), recording, 2, names=("gripper", "tilt", "pan")
    )
    with pytest.raises(
        ImporterError, match=r"names 3 joint\(s\) \('gripper', 'tilt', 'pan'\); name"
    ):
        read_rosbag(three, WRENCH, JOINTS)


def test_messages_of_another_publisher_on_the_joint_topic_are_left_aside(
    recording: Recording, tmp_path: Path
) -> None:
    bag = _write_bag(_bag_path(tmp_path, 1), recording, 1, other_publisher_every=10)
    # the topic's first message is the other publisher's: the joints must be named
    with pytest.raises(ImporterError, match=r"the first message names 1 joint\(s\) \('gripper'\)"):
        read_rosbag(bag, WRENCH, JOINTS)
    result = read_rosbag(bag, WRENCH, JOINTS, joint1="pan", joint2="tilt")
    _assert_same_samples(result.recording, recording)
    assert result.report.n_skipped_joint_messages == recording.n_samples // 10
    assert "; 350 without both joints left aside" in "\n".join(result.report.lines())


def test_messages_with_a_nan_or_a_repeated_stamp_are_left_out_and_counted(
    recording: Recording, tmp_path: Path
) -> None:
    # a message the sensor could not read (NaN) and a driver's repeat of the message before:
    # each left out, its sample bridged as a dropped one, the rest as they were
    short = _first(recording, 40)
    stamps = EPOCH_NS + np.arange(40, dtype=np.int64) * 1_000_000
    stamps[17] = stamps[16]
    bag = _write_bag(_bag_path(tmp_path, 2), short, 2, wrench_ns=stamps, nan_at=[5])
    result = read_rosbag(bag, WRENCH, JOINTS)
    assert (
        "; messages left out: 1 with a NaN or infinite value and 1 at the stamp of the one"
        in (result.report.lines()[1])
    )
    assert result.report.clock.n_interpolated == 2 and result.report.clock.wrench.n_missing == 2
    own = np.setdiff1d(np.arange(40), [5, 17])
    np.testing.assert_array_equal(result.recording.force[own], short.force[own])
    np.testing.assert_array_equal(result.recording.t, short.t)
    unreadable = np.full((3, 3), np.nan)  # the sensor reads NaN on every axis
    bag = _write_bag(tmp_path / "nan_ros2", _first(recording, 20), 2, sensor=unreadable)
    with pytest.raises(
        ImporterError, match=f"{WRENCH!r}: 0 message.s. kept of 20, at least 2 needed; messages"
    ):
        read_rosbag(bag, WRENCH, JOINTS)


@pytest.mark.parametrize(
    ("axes", "reaction"), [("-x,-y,z", False), ("z,x,y", False), ("x,y,z", True)]
)
def test_the_sensor_s_axes_and_the_reaction_are_turned_back_onto_the_motor_frame(
    axes: str, reaction: bool, recording: Recording, tmp_path: Path
) -> None:
    """A sensor turned on the head (or reporting the reaction) is written with its own axes;
    stating them gives back the motor frame's loads exactly (signed permutations are exact)."""
    stated = SensorAxes(axes, reaction=reaction)
    # v_motor = R @ v_sensor, so the bag holds v_sensor = R^T @ v_motor (R is orthogonal)
    bag = _write_bag(_bag_path(tmp_path, 2), recording, 2, sensor=stated.matrix.T)
    unstated = read_rosbag(bag, WRENCH, JOINTS).recording
    assert not np.array_equal(unstated.force, recording.force)
    _assert_same_samples(read_rosbag(bag, WRENCH, JOINTS, axes=stated).recording, recording)


def test_a_sensor_taking_its_torques_about_its_origin_is_moved_to_o(
    recording: Recording, tmp_path: Path
) -> None:
    """A sensor turned half a turn about Z^m, its origin 25 mm along the link and 4 mm above
    it: stating both gives back the torques about O (Gamma_O = Gamma_S + (S - O) x F)."""
    point = (0.025, 0.0, 0.004)
    stated = SensorAxes("-x,-y,z", torque_point=point)
    about_s = dataclasses.replace(
        recording, torque=recording.torque - np.cross(point, recording.force)
    )
    bag = _write_bag(_bag_path(tmp_path, 2), about_s, 2, sensor=stated.matrix.T)
    imported = read_rosbag(bag, WRENCH, JOINTS, axes=stated).recording
    np.testing.assert_array_equal(imported.force, recording.force)
    np.testing.assert_allclose(imported.torque, recording.torque, rtol=0, atol=1e-15)
    assert "torques about (0.025, 0, 0.004) m" in imported.metadata["ros_sensor_axes"]
    assert imported.metadata["torques_moved_from"] == "[0.025, 0.0, 0.004]"  # as a reader keeps it
    with pytest.raises(AxesError, match="more than 1 m: in metres"):
        SensorAxes(torque_point=(25.0, 0.0, 4.0))


def test_jittered_stamps_and_dropped_messages_are_reported(
    recording: Recording, tmp_path: Path
) -> None:
    """Stamps jittered by up to 0.2 ms (a logger's, not the sensor's): the clock keeps the
    sensor's period and every wrench message its own slot and value. One dropped message is
    bridged; thirty in a row are a gap whose samples are left out, so the recording shows them
    as dropped."""
    rng = np.random.default_rng(11)
    n = recording.n_samples
    exact = EPOCH_NS + np.arange(n, dtype=np.int64) * 1_000_000
    wrench_ns = exact + rng.integers(-200_000, 200_001, size=n)
    joints_ns = exact + rng.integers(-200_000, 200_001, size=n)
    dropped = [500, *range(960, 990)]
    kept = [k for k in range(n) if k not in dropped]
    bag = _write_bag(
        _bag_path(tmp_path, 2),
        recording,
        2,
        wrench_ns=wrench_ns,
        joints_ns=joints_ns,
        wrench_kept=kept,
    )
    result = read_rosbag(bag, WRENCH, JOINTS)
    clock = result.report.clock
    # the clock's period: the line through 3489 stamps against their sample numbers; each
    # stamp's error (uniform, +-0.2 ms: 0.115 ms standard) enters it times sqrt(12 / n^3):
    # 2e-9 s one standard deviation
    assert abs(clock.period - 0.001) <= 1e-7
    assert clock.wrench.n_messages == n - len(dropped)
    assert clock.wrench.n_missing == 31 and clock.wrench.n_gaps == 1
    assert 0.0306 <= clock.wrench.largest_step <= 0.0314  # 31 steps of 1 ms, +-0.4 ms
    assert clock.n_interpolated == 1 and clock.n_left_out == 30
    # each message at its sample's instant: the stamps lie within their jitter of the line
    # (and its own small error), the messages on the grid
    assert 0.00015 < clock.wrench.jitter <= 0.00021
    assert clock.largest_offset < 1e-9
    # slot 0 is the first wrench message both topics cover; as the stamps' jitter relative to
    # it stays under half a period, slot s holds sample first + s
    first = int(np.argmax(wrench_ns >= max(wrench_ns[0], joints_ns[0])))
    slots = np.rint(result.recording.t / clock.period).astype(int) + first
    assert set(range(first, slots[-1] + 1)) - set(slots) == set(range(960, 990))
    own = np.isin(slots, kept)
    np.testing.assert_array_equal(result.recording.force[own], recording.force[slots[own]])
    assert result.recording.sampling.n_dropped == 30
    # the angles, interpolated at their own samples' instants, the line through their stamps
    # jittered by up to 0.2 ms (0.115 ms standard): off the wrench's line by about 4 us, one
    # standard deviation of each line's place over 3,500 stamps; within 30 us of the sample's
    # true instant, they move by at most their largest speed times that (at their stamps they
    # would be up to 0.4 ms off)
    speed = np.max(np.abs(np.diff(recording.theta, axis=0)), axis=0) / 0.001
    error = np.abs(result.recording.theta - recording.theta[slots])
    assert np.all(error <= speed * 3e-5 + 1e-12)
    assert np.any(error > 0)
    text = "\n".join(result.report.lines())
    assert "1 sample(s) without their own wrench message, interpolated; 30 left out" in text
    # The gap lies in the push (t_c = 0.925 s, t_1 = 1.034 s on the original), which the
    # estimators read from t_c on: more than 20 ms missing there is bad_input, the gap named.
    # The best guess is still made from the sensor's own values after it, and only the windows'
    # edges move, by the clock's origin (0.2 ms at most, under 1 % of their 1 s): as for the
    # shifted windows of test_estimation_pipeline.py, x_c by under 0.1 mm.
    antenna = calibrated()
    original = estimate(recording, antenna)
    imported = estimate(result.recording, antenna)
    assert original.t_c < 0.96 < 0.99 < original.t_1  # the gap, where the test says it is
    assert imported.status.value == "bad_input"
    assert "30 samples missing" in (imported.reason or "")
    assert abs(imported.x_c - original.x_c) < 1e-4


def test_unset_header_stamps_are_refused_unless_the_bag_s_times_are_asked_for(
    recording: Recording, tmp_path: Path
) -> None:
    bag = _write_bag(_bag_path(tmp_path, 1), recording, 1, headers_unset=True)
    with pytest.raises(ImporterError, match=r"message 0 has no header stamp \(0\); use the bag's"):
        read_rosbag(bag, WRENCH, JOINTS)
    _assert_same_samples(read_rosbag(bag, WRENCH, JOINTS, stamps="bag").recording, recording)


@pytest.mark.parametrize("ros", [1, 2])
@pytest.mark.parametrize("back_ms", [6, 20])
def test_a_joint_clock_set_back_while_recording_is_refused_and_the_bag_s_times_hold(
    back_ms: int, ros: int, recording: Recording, tmp_path: Path
) -> None:
    # the joints' publisher's clock set back half-way (an NTP step) while the recorder's holds:
    # sorted by header stamp, the angles after the step would sit back_ms early (the step times
    # the head's speed); the first stamp after the step lies a period less than back_ms below
    # the one recorded before it, and the latency after it is back_ms longer
    recorded = EPOCH_NS + np.rint(recording.t * 1e9).astype(np.int64)
    stamped = recorded.copy()
    half = recording.n_samples // 2
    stamped[half:] -= back_ms * 1_000_000
    bag = _write_bag(
        _bag_path(tmp_path, ros), recording, ros, joints_ns=recorded, joints_header_ns=stamped
    )
    with pytest.raises(
        ImporterError,
        match=rf"topic '{JOINTS}': message {half}'s header stamp is {(back_ms - 1) / 1000:g} s"
        r" before one recorded before it \(.* s after the topic's first\), and the latency after"
        rf" it {back_ms / 1000:g} s longer: its publisher's clock was set back while recording;"
        r" the bag's record times may hold \(--stamps bag\)$",
    ):
        read_rosbag(bag, WRENCH, JOINTS)
    _assert_same_samples(read_rosbag(bag, WRENCH, JOINTS, stamps="bag").recording, recording)


@pytest.mark.parametrize("ros", [1, 2])
def test_a_recorder_clock_set_back_leaves_good_header_stamps_alone(
    ros: int, recording: Recording, tmp_path: Path
) -> None:
    # the recorder's clock steps back 20 ms half-way while the driver's stamps hold: the bag
    # gives the joints in the order of its stepped record times, so a header stamp comes after
    # a later one, but the latency falls instead of rising, and the header stamps are right
    stamped = EPOCH_NS + np.rint(recording.t * 1e9).astype(np.int64)
    recorded = stamped.copy()
    recorded[recording.n_samples // 2 :] -= 20_000_000
    bag = _write_bag(
        _bag_path(tmp_path, ros), recording, ros, joints_ns=recorded, joints_header_ns=stamped
    )
    _assert_same_samples(read_rosbag(bag, WRENCH, JOINTS).recording, recording)


def test_header_stamps_jittered_out_of_the_order_received_are_no_clock_set_back(
    recording: Recording, tmp_path: Path
) -> None:
    # a driver stamping each message within +-2 ms of its instant, recorded in order: stamps
    # up to 4 ms out of the order recorded are jitter, not a clock set back
    received = EPOCH_NS + np.rint(recording.t * 1e9).astype(np.int64)
    rng = np.random.default_rng(5)
    stamped = received + rng.integers(-2_000_000, 2_000_001, size=received.shape[0])
    bag = _write_bag(
        _bag_path(tmp_path, 2), recording, 2, joints_ns=received, joints_header_ns=stamped
    )
    report = read_rosbag(bag, WRENCH, JOINTS).report.clock
    assert report.joints.n_messages == recording.n_samples and report.n_left_out == 0


def test_a_ros2_bag_may_be_named_by_its_metadata_file_and_a_ros1_bag_needs_its_suffix(
    bag: Path, recording: Recording, tmp_path: Path
) -> None:
    by_metadata = read_rosbag(bag / "metadata.yaml", WRENCH, JOINTS).recording
    _assert_same_samples(by_metadata, _first(recording, 50))
    ros1 = _write_bag(tmp_path / "short.bag", _first(recording, 50), 1)
    renamed = ros1.rename(tmp_path / "short.log")
    with pytest.raises(ImporterError, match=r"a ROS 1 bag .* does not end in \.bag"):
        read_rosbag(renamed, WRENCH, JOINTS)


def _run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    return err.strip()


def _first(recording: Recording, n: int) -> Recording:
    """The first n samples of a recording."""
    return Recording(
        t=recording.t[:n],
        theta=recording.theta[:n],
        force=recording.force[:n],
        torque=recording.torque[:n],
    )


@pytest.fixture
def bag(recording: Recording, tmp_path: Path) -> Path:
    return _write_bag(_bag_path(tmp_path, 2), _first(recording, 50), 2)


def _import(bag: Path, *flags: str) -> list[str]:
    return ["import", "rosbag", str(bag), *flags, "--out", str(bag.parent / "out.csv")]


def test_a_missing_topic_is_one_line_naming_the_bag_and_the_topic(
    bag: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    err = _run(_import(bag, "--wrench", "/wrench", "--joints", JOINTS), capsys)
    assert err.startswith(f"antenna import rosbag: error: {bag}: no topic '/wrench'")
    assert WRENCH in err and JOINTS in err  # the topics the bag has


def test_a_topic_of_another_type_is_one_line(bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    err = _run(_import(bag, "--wrench", JOINTS, "--joints", WRENCH), capsys)
    assert err == (
        f"antenna import rosbag: error: {bag}: topic {JOINTS!r}: message type"
        " sensor_msgs/msg/JointState, expected geometry_msgs/msg/WrenchStamped"
    )


def test_a_wrench_topic_of_vectors_without_stamps_is_refused(
    recording: Recording, tmp_path: Path
) -> None:
    short = _first(recording, 20)
    bag = _write_bag(_bag_path(tmp_path, 1), short, 1, wrench_type="geometry_msgs/msg/Vector3")
    with pytest.raises(ImporterError, match="message type geometry_msgs/msg/Vector3, expected"):
        read_rosbag(bag, WRENCH, JOINTS)


def test_streams_that_do_not_overlap_are_refused(
    recording: Recording, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    short = _first(recording, 20)
    stamps = EPOCH_NS + np.arange(20, dtype=np.int64) * 1_000_000
    bag = _write_bag(_bag_path(tmp_path, 2), short, 2, wrench_ns=stamps, joints_ns=stamps + 10**9)
    err = _run(_import(bag, "--wrench", WRENCH, "--joints", JOINTS), capsys)
    assert err.startswith(f"antenna import rosbag: error: {bag}: {WRENCH!r} (")
    assert err.endswith("do not overlap in time")


def test_a_missing_joint_and_a_missing_bag_are_one_line(
    bag: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    err = _run(_import(bag, "--wrench", WRENCH, "--joints", JOINTS, "--joint2", "elbow"), capsys)
    assert err == (
        f"antenna import rosbag: error: {bag}: topic {JOINTS!r}: 0 message(s) name both joints"
        " 'pan' and 'elbow', at least 2 needed (the topic's joints: 'pan', 'tilt')"
    )
    missing = bag.parent / "nothing"
    err = _run(_import(missing, "--wrench", WRENCH, "--joints", JOINTS), capsys)
    assert err == f"antenna import rosbag: error: {missing}: no such file or directory"
    text = bag.parent / "notes.bag"
    text.write_text("not a bag\n")
    err = _run(_import(text, "--wrench", WRENCH, "--joints", JOINTS), capsys)
    assert err.startswith(f"antenna import rosbag: error: {text}: not a readable ROS 1 .bag file")


def test_without_rosbags_the_command_says_what_to_install(
    bag: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    for name in [*(n for n in sys.modules if n.startswith("rosbags.")), "rosbags"]:
        monkeypatch.setitem(sys.modules, name, None)  # an import of it now fails
    err = _run(_import(bag, "--wrench", WRENCH, "--joints", JOINTS), capsys)
    assert err == (
        "antenna import rosbag: error: reading ROS bags needs the rosbags library:"
        " pip install 'sensing-antenna[ros]'"
    )


@pytest.mark.parametrize(
    ("axes", "problem"),
    [
        ("x,y", "name each of x, y, z once"),
        ("x,x,z", "name each of x, y, z once"),
        ("x,y,w", "each axis is x, y or z"),
        ("x,y,-z", "left-handed"),
        ("y,x,z", "left-handed"),
    ],
)
def test_sensor_axes_must_be_a_rotation(
    axes: str, problem: str, capsys: pytest.CaptureFixture[str], bag: Path
) -> None:
    with pytest.raises(AxesError, match=problem):
        SensorAxes(axes)
    err = _run(_import(bag, "--wrench", WRENCH, "--joints", JOINTS, "--frame", axes), capsys)
    assert err.startswith(f"antenna import rosbag: error: --frame: {axes!r}: ")


def test_the_command_s_help_names_the_estimators_gap(capsys: pytest.CaptureFixture[str]) -> None:
    # the help writes the default out (parsing arguments imports no NumPy): it must be the
    # library's
    from sensing_antenna.estimation.config import MAX_GAP_DURATION

    with pytest.raises(SystemExit):
        main(["import", "rosbag", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert f"the estimators' own limit, {1000 * MAX_GAP_DURATION:g} ms" in text
