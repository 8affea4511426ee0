"""ROS bags (ROS 1 ``.bag`` files and ROS 2 bag directories) to recordings (docs/import.md).

A bag with a ``geometry_msgs/WrenchStamped`` topic (the force/torque sensor) and a
``sensor_msgs/JointState`` topic (the head's joints) becomes a recording: two joints, named or
the two of the first message when it names two, give theta1 (azimuth) and theta2 (elevation);
the wrench, turned onto the motor axes by :class:`~sensing_antenna.importers.axes.SensorAxes`,
gives the force and torque; both are put on one uniform clock by
:func:`~sensing_antenna.importers.clock.put_on_clock`, which reports their rates and gaps.

Reading uses the ``rosbags`` library, an optional dependency (``pip install
'sensing-antenna[ros]'``), imported only when a bag is read.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from sensing_antenna.importers.axes import SensorAxes
from sensing_antenna.importers.clock import (
    ClockReport,
    ImporterError,
    Stream,
    put_on_clock,
)
from sensing_antenna.recording import Recording
from sensing_antenna.torque_point import MOVED_KEY

__all__ = [
    "INSTALL_HINT",
    "JOINTS_TYPE",
    "STEP_BACK_NS",
    "WRENCH_TYPE",
    "ImportReport",
    "RosbagImport",
    "read_rosbag",
]

#: Message type of the force/torque topic.
WRENCH_TYPE = "geometry_msgs/msg/WrenchStamped"
#: Message type of the joint topic.
JOINTS_TYPE = "sensor_msgs/msg/JointState"
#: What to install when ``rosbags`` is missing.
INSTALL_HINT = "pip install 'sensing-antenna[ros]'"

_NS = 10**9
#: A header stamp this far (ns) below one recorded before it is a clock stepped back.
STEP_BACK_NS = 5_000_000
#: Messages either side of such a stamp whose median latencies say which clock stepped.
_LATENCY_WINDOW = 31
_ROS1_MAGIC = b"#ROSBAG V2.0"


@dataclass(frozen=True)
class LeftOut:
    """Messages of a topic left out: with a NaN or infinite value, and at the stamp of the
    message before them."""

    non_finite: int = 0
    repeated: int = 0

    def describe(self) -> str:
        """What was left out, for a person; empty when nothing was."""
        parts = []
        if self.non_finite:
            parts.append(f"{self.non_finite} with a NaN or infinite value")
        if self.repeated:
            parts.append(f"{self.repeated} at the stamp of the one before")
        return f"; messages left out: {' and '.join(parts)}" if parts else ""


@dataclass(frozen=True)
class ImportReport:
    """What the import found and did: the two topics' rates and gaps, the clock, the mapping.

    Parameters
    ----------
    source : str
        The bag.
    ros_version : int
        1 or 2.
    joint_names : tuple of str
        The joints read as theta1 and theta2.
    n_skipped_joint_messages : int
        Joint messages that did not name both joints (another publisher's), left aside.
    clock : ClockReport
        Both topics' rates and gaps, the clock's period and origin, the samples interpolated and
        left out.
    axes : SensorAxes
        The sensor's axes on the motor frame.
    left_out : (LeftOut, LeftOut)
        The wrench's and the joints' messages left out (a NaN, a repeated stamp).
    """

    source: str
    ros_version: int
    joint_names: tuple[str, str]
    n_skipped_joint_messages: int
    clock: ClockReport
    axes: SensorAxes
    left_out: tuple[LeftOut, LeftOut] = (LeftOut(), LeftOut())

    def lines(self) -> list[str]:
        """A few lines for a person: each topic, the joints, the frame, the clock, the gaps."""
        skipped = self.n_skipped_joint_messages
        wrench, joints, *clock = self.clock.lines()
        return [
            f"{self.source}: ROS {self.ros_version} bag",
            f"  {wrench}{self.left_out[0].describe()}",
            f"  {joints}{self.left_out[1].describe()}"
            + (f"; {skipped} without both joints left aside" if skipped else ""),
            f"  theta1 <- joint {self.joint_names[0]!r}, theta2 <- joint"
            f" {self.joint_names[1]!r}; sensor axes on X^m, Y^m, Z^m: {self.axes.describe()}",
            *(f"  {line}" for line in clock),
        ]


@dataclass(frozen=True)
class RosbagImport:
    """A bag made into a recording: the recording and the report of how."""

    recording: Recording
    report: ImportReport


def _load_rosbags() -> Any:
    try:
        from rosbags import highlevel
    except ImportError:
        raise ImporterError(f"reading ROS bags needs the rosbags library: {INSTALL_HINT}") from None
    return highlevel


def _message_type(name: str | None) -> str:
    """``pkg/Type`` (ROS 1 spelling) as ``pkg/msg/Type``."""
    if name is None:
        return "(several types)"
    parts = name.split("/")
    return f"{parts[0]}/msg/{parts[1]}" if len(parts) == 2 else name


def _stamp(message: Any, bag_time: int, stamps: str) -> int:
    if stamps == "bag":
        return int(bag_time)
    stamp = message.header.stamp
    return int(stamp.sec) * _NS + int(stamp.nanosec)


def _check_topic(topics: Mapping[str, Any], topic: str, expected: str, source: str) -> Any:
    if topic not in topics:
        names = ", ".join(sorted(topics)) or "none"
        raise ImporterError(f"{source}: no topic {topic!r} (the bag has: {names})")
    info = topics[topic]
    kind = _message_type(info.msgtype)
    if kind != expected:
        raise ImporterError(f"{source}: topic {topic!r}: message type {kind}, expected {expected}")
    if info.msgcount < 2:
        raise ImporterError(
            f"{source}: topic {topic!r}: {info.msgcount} message(s), at least 2 needed"
        )
    return info


def _sorted(
    source: str,
    topic: str,
    kind: str,
    stamps: list[int],
    values: list[Any],
    stamp_kind: str,
    received: list[int],
) -> tuple[Stream, LeftOut]:
    stamp_array = np.array(stamps, dtype=np.int64)
    if stamp_kind == "header" and np.any(stamp_array == 0):
        k = int(np.argmax(stamp_array == 0))
        raise ImporterError(
            f"{source}: topic {topic!r}: message {k} has no header stamp (0); use the bag's"
            " record times (--stamps bag)"
        )
    _check_publisher_clock(
        source, topic, stamp_array, np.array(received, dtype=np.int64), stamp_kind
    )
    value_array = np.array(values, dtype=np.float64).reshape(len(values), -1)
    order = np.argsort(stamp_array, kind="stable")
    stamp_array, value_array = stamp_array[order], value_array[order]
    # a message with a NaN or infinite value, or at the stamp of the one before it (a driver's
    # repeat), is left out: the clock then sees that sample as dropped, and bridges it
    finite = np.all(np.isfinite(value_array), axis=1)
    stamp_array, value_array = stamp_array[finite], value_array[finite]
    new = np.ones(stamp_array.shape[0], dtype=bool)
    new[1:] = np.diff(stamp_array) > 0
    stream = Stream(name=topic, kind=kind, stamps=stamp_array[new], values=value_array[new])
    left_out = LeftOut(int(np.sum(~finite)), int(np.sum(~new)))
    if stream.stamps.shape[0] < 2:
        raise ImporterError(
            f"{source}: topic {topic!r}: {stream.stamps.shape[0]} message(s) kept of"
            f" {len(values)}, at least 2 needed{left_out.describe()}"
        )
    return stream, left_out


def _check_publisher_clock(
    source: str, topic: str, stamps: np.ndarray, received: np.ndarray, stamp_kind: str
) -> None:
    """Refuse a topic whose publisher's clock was set back while recording.

    The reader gives a topic's messages in the order of the bag's record times. A header stamp
    :data:`STEP_BACK_NS` or more below an earlier message's is a clock stepped back, the
    publisher's or the recorder's; the latency, record time less header stamp, tells which: it
    rises for good by the step when the publisher's clock went back (its stamps, sorted, would
    interleave two stretches, each sample up to the step off its instant), and falls when the
    recorder's did (the header stamps hold, only the order was the recorder's)."""
    if stamp_kind != "header" or stamps.shape[0] < 2:
        return
    behind = np.maximum.accumulate(stamps)[:-1] - stamps[1:]
    k = int(np.argmax(behind >= STEP_BACK_NS))
    if not behind[k] >= STEP_BACK_NS:
        return
    latency = received - stamps
    step = k + 1
    width = _LATENCY_WINDOW
    before = float(np.median(latency[max(0, step - width) : step]))
    after = float(np.median(latency[step : step + width]))
    if after - before >= 0.5 * float(behind[k]):
        since = int(stamps[step] - stamps[0]) / _NS
        raise ImporterError(
            f"{source}: topic {topic!r}: message {step}'s header stamp is"
            f" {behind[k] / _NS:.3g} s before one recorded before it ({since:.4g} s after the"
            f" topic's first), and the latency after it {(after - before) / _NS:.3g} s longer:"
            " its publisher's clock was set back while recording; the bag's record times may"
            " hold (--stamps bag)"
        )


def _read_streams(
    reader: Any,
    source: str,
    wrench_topic: str,
    joints_topic: str,
    joint_names: tuple[str | None, str | None],
    stamps: str,
) -> tuple[tuple[Stream, LeftOut], tuple[Stream, LeftOut], tuple[str, str], int]:
    topics = reader.topics
    wrench_info = _check_topic(topics, wrench_topic, WRENCH_TYPE, source)
    joints_info = _check_topic(topics, joints_topic, JOINTS_TYPE, source)
    wrench_stamps: list[int] = []
    wrench_received: list[int] = []
    wrench_values: list[tuple[float, ...]] = []
    for connection, bag_time, raw in reader.messages(connections=wrench_info.connections):
        message = reader.deserialize(raw, connection.msgtype)
        force, torque = message.wrench.force, message.wrench.torque
        wrench_stamps.append(_stamp(message, bag_time, stamps))
        wrench_received.append(int(bag_time))
        wrench_values.append((force.x, force.y, force.z, torque.x, torque.y, torque.z))
    names: tuple[str, str] | None = None
    indices: dict[tuple[str, ...], tuple[int, int] | None] = {}
    joint_stamps: list[int] = []
    joint_received: list[int] = []
    joint_values: list[tuple[float, float]] = []
    for number, (connection, bag_time, raw) in enumerate(
        reader.messages(connections=joints_info.connections)
    ):
        message = reader.deserialize(raw, connection.msgtype)
        message_names = tuple(str(name) for name in message.name)
        if names is None:
            names = _choose_joints(message_names, joint_names, source, joints_topic)
        if message_names not in indices:
            indices[message_names] = (
                (message_names.index(names[0]), message_names.index(names[1]))
                if names[0] in message_names and names[1] in message_names
                else None
            )
        pair = indices[message_names]
        if pair is None:
            continue
        position = message.position
        if len(position) != len(message_names):
            raise ImporterError(
                f"{source}: topic {joints_topic!r}: message {number} has {len(message_names)}"
                f" names and {len(position)} positions"
            )
        joint_stamps.append(_stamp(message, bag_time, stamps))
        joint_received.append(int(bag_time))
        joint_values.append((float(position[pair[0]]), float(position[pair[1]])))
    assert names is not None  # the topic has at least two messages
    if len(joint_stamps) < 2:
        seen = sorted({name for message_names in indices for name in message_names})
        listed = ", ".join(repr(name) for name in seen) or "none"
        raise ImporterError(
            f"{source}: topic {joints_topic!r}: {len(joint_stamps)} message(s) name both joints"
            f" {names[0]!r} and {names[1]!r}, at least 2 needed (the topic's joints: {listed})"
        )
    skipped = joints_info.msgcount - len(joint_stamps)
    wrench = _sorted(
        source, wrench_topic, WRENCH_TYPE, wrench_stamps, wrench_values, stamps, wrench_received
    )
    joints = _sorted(
        source, joints_topic, JOINTS_TYPE, joint_stamps, joint_values, stamps, joint_received
    )
    return wrench, joints, names, skipped


def _choose_joints(
    message_names: tuple[str, ...],
    wanted: tuple[str | None, str | None],
    source: str,
    topic: str,
) -> tuple[str, str]:
    """The joints read as theta1, theta2: those named, else the first and the second name of
    the topic's first message when it names two (of more, which are the head's is not known)."""
    chosen = []
    for position, name in enumerate(wanted):
        if name is None:
            if len(message_names) != 2:
                listed = ", ".join(repr(n) for n in message_names) or "none"
                raise ImporterError(
                    f"{source}: topic {topic!r}: the first message names {len(message_names)}"
                    f" joint(s) ({listed}); name the two to read (theta1, theta2) with --joint1"
                    " and --joint2"
                )
            name = message_names[position]
        chosen.append(name)
    if chosen[0] == chosen[1]:
        raise ImporterError(f"{source}: topic {topic!r}: joint {chosen[0]!r} read for both angles")
    return chosen[0], chosen[1]


def _bag_path(path: Path, source: str) -> Path:
    """The path rosbags opens: a ROS 2 bag's directory when given its ``metadata.yaml``; a ROS 1
    bag only under a name ending in ``.bag`` (rosbags tells the two apart by that suffix)."""
    if not path.exists():
        raise ImporterError(f"{source}: no such file or directory")
    if path.name == "metadata.yaml":
        return path.parent
    if path.is_file() and path.suffix != ".bag":
        with path.open("rb") as file:
            if file.read(len(_ROS1_MAGIC)) == _ROS1_MAGIC:
                raise ImporterError(
                    f"{source}: a ROS 1 bag (its first line says so) under a name that does not"
                    " end in .bag, which rosbags needs to read it as one: rename or link it"
                )
    return path


def read_rosbag(
    path: str | Path,
    wrench_topic: str,
    joints_topic: str,
    *,
    joint1: str | None = None,
    joint2: str | None = None,
    axes: SensorAxes | None = None,
    sample_period: float | None = None,
    max_gap: float | None = None,
    stamps: Literal["header", "bag"] = "header",
    metadata: Mapping[str, str] | None = None,
) -> RosbagImport:
    """Read a ROS 1 or ROS 2 bag into a recording.

    Parameters
    ----------
    path : str or Path
        A ROS 1 bag (a ``.bag`` file) or a ROS 2 bag (its directory or its ``metadata.yaml``).
    wrench_topic : str
        Topic of ``geometry_msgs/WrenchStamped`` messages: force (N), torque (N m).
    joints_topic : str
        Topic of ``sensor_msgs/JointState`` messages: positions (rad).
    joint1, joint2 : str, optional
        Joints read as theta1 (azimuth) and theta2 (elevation); when None, the first and the
        second name of the topic's first message. Messages that do not name both (another
        publisher's on the same topic) are left aside.
    axes : SensorAxes, optional
        The sensor's axes on the motor frame; the identity when None.
    sample_period : float, optional
        The recording's T_s (s); the wrench topic's own period when None
        (:func:`.clock.sample_clock`).
    max_gap : float, optional
        A topic missing more than this many periods' worth of the recording's clock in a row is
        a gap, whose samples are left out (>= 0); None: the estimators' own limit (20 ms).
    stamps : {"header", "bag"}
        Time of a message: its header stamp, or the time the bag recorded it.
    metadata : Mapping[str, str], optional
        Metadata for the recording (``antenna``, ``description``), after the import's own
        (``sample_period``, ``ros_*`` keys).

    Returns
    -------
    RosbagImport
        The recording (t = 0 at the first wrench message both topics cover) and the report.

    Raises
    ------
    ImporterError
        rosbags missing; the bag unreadable; a topic missing, of another type or with fewer
        than two messages; fewer than two messages naming both joints (or with finite values
        at stamps of their own); a header stamp of zero; topics that do not overlap in time.
    """
    source = str(path)
    highlevel = _load_rosbags()
    axes = SensorAxes() if axes is None else axes
    bag = _bag_path(Path(path), source)
    try:
        reader = highlevel.AnyReader([bag])
        with reader:
            read, joint_read, names, skipped = _read_streams(
                reader, source, wrench_topic, joints_topic, (joint1, joint2), stamps
            )
            ros_version = 2 if reader.is2 else 1
    except (ImporterError, MemoryError):
        raise
    except Exception as exc:  # rosbags' own errors on a damaged or foreign file
        raise ImporterError(
            f"{source}: not a readable ROS 1 .bag file or ROS 2 bag directory"
            f" ({type(exc).__name__}: {exc})".replace("\n", " ")
        ) from None
    (wrench, wrench_left_out), (joints, joints_left_out) = read, joint_read
    clocked = put_on_clock(wrench, joints, source=source, period=sample_period, max_gap=max_gap)
    clock = clocked.report
    force, torque = axes.to_motor(clocked.wrench[:, :3], clocked.wrench[:, 3:])
    own = {
        "sample_period": repr(clock.period),
        "ros_bag": bag.name,
        "ros_wrench_topic": wrench_topic,
        "ros_joints_topic": joints_topic,
        "ros_joints": f"theta1={names[0]}, theta2={names[1]}",
        "ros_sensor_axes": axes.describe(),
        **({MOVED_KEY: json.dumps(list(axes.torque_point))} if any(axes.torque_point) else {}),
        "ros_time_origin": f"{clock.origin_ns // _NS}.{clock.origin_ns % _NS:09d}",
    }
    recording = Recording(
        t=clocked.t,
        theta=clocked.joints,
        force=force,
        torque=torque,
        metadata={**own, **(metadata or {})},
        source=source,
    )
    report = ImportReport(
        source=source,
        ros_version=ros_version,
        joint_names=names,
        n_skipped_joint_messages=skipped,
        clock=clock,
        axes=axes,
        left_out=(wrench_left_out, joints_left_out),
    )
    return RosbagImport(recording=recording, report=report)
