"""``antenna import FORMAT ...``: recordings from the logs a lab keeps. Each format is registered
by a small function here (``rosbag``: ROS 1 and ROS 2 bags)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from sensing_antenna.cli.arguments import add_actions, number


def register(subparsers: Any) -> None:
    """Add ``antenna import`` and its formats."""
    parser = subparsers.add_parser(
        "import",
        help="make a recording (CSV) from a lab's log: a ROS bag",
        description=(
            "Makes a recording in the sensing-antenna format (docs/recording-format.md) from a "
            "log kept in another format, putting its streams onto one uniform clock and "
            "reporting their rates and gaps on stderr. Formats: rosbag (ROS 1 and ROS 2 bags). "
            "A log in any other format (CSV files, a database export) goes through the same clock "
            "from Python: docs/import.md, 'Another log, from Python'."
        ),
    )
    formats = add_actions(parser, "format", "FORMAT")
    _add_rosbag(formats)


def _add_rosbag(formats: Any) -> None:
    parser = formats.add_parser(
        "rosbag",
        help="a ROS 1 or ROS 2 bag: WrenchStamped and JointState topics",
        description=(
            "Reads a ROS 1 bag (a .bag file) or a ROS 2 bag (its directory) with the rosbags "
            "library: the force/torque sensor from a geometry_msgs/WrenchStamped topic, the head's "
            "two joints from a sensor_msgs/JointState topic, both on one clock of the wrench "
            "topic's rate (or --rate): each sample the sensor's own message nearest to it, the "
            "joints interpolated linearly, samples inside a gap of either topic left out. Prints "
            "each topic's rates and gaps and the joint mapping on stderr, then the recording's "
            "path. Needs the optional dependency: pip install 'sensing-antenna[ros]'. See "
            "docs/import.md."
        ),
    )
    parser.add_argument("bag", type=Path, help="a ROS 1 .bag file or a ROS 2 bag directory")
    parser.add_argument(
        "--wrench", required=True, metavar="TOPIC", help="geometry_msgs/WrenchStamped topic"
    )
    parser.add_argument(
        "--joints", required=True, metavar="TOPIC", help="sensor_msgs/JointState topic"
    )
    parser.add_argument(
        "--joint1",
        metavar="NAME",
        help="joint read as theta1, the azimuth (default: the first name in the topic's first "
        "message)",
    )
    parser.add_argument(
        "--joint2",
        metavar="NAME",
        help="joint read as theta2, the elevation (default: the second name in the topic's first "
        "message)",
    )
    parser.add_argument(
        "--frame",
        default="x,y,z",
        metavar="AXES",
        help="the sensor's axes along the motor axes X^m, Y^m, Z^m, each with its sign, a "
        "right-handed set such as --frame=-x,-y,z (turned half a turn about Z^m; the equals "
        "sign when it begins with a minus) or z,x,y",
    )
    parser.add_argument(
        "--reaction",
        action="store_true",
        help="the sensor reports the wrench the head applies to the link: change both signs",
    )
    parser.add_argument(
        "--torque-point",
        type=_point,
        default=None,
        metavar="X,Y,Z",
        help="the point the sensor takes its torques about (its origin), from the base point O "
        "on the motor axes, in m: --torque-point=-0.025,0,0 for an origin 2.5 cm behind the "
        "link's clamp (the equals sign when it begins with a minus); the torques are moved to O "
        "(default: O itself)",
    )
    parser.add_argument(
        "--rate",
        type=number(low=0.0, low_open=True, unit="Hz"),
        metavar="HZ",
        help="the recording's sample rate (Hz; default: the wrench topic's, its sample periods "
        "over its span, dropped messages counted)",
    )
    parser.add_argument(
        "--max-gap",
        type=number(low=0.0),
        default=None,
        metavar="SAMPLES",
        help="a topic missing more than this many samples' worth of the recording's clock in a "
        "row is a gap, whose samples are left out (default: the estimators' own limit, 20 "
        "ms: 20 samples at 1 kHz)",
    )
    parser.add_argument(
        "--stamps",
        choices=("header", "bag"),
        default="header",
        help="a message's time: its header stamp, or when the bag recorded it",
    )
    parser.add_argument(
        "--antenna",
        metavar="NAME",
        help="antenna metadata of the recording (informative; default: none written)",
    )
    parser.add_argument(
        "--description",
        metavar="TEXT",
        help="description metadata (default: the bag and its topics)",
    )
    parser.add_argument("--out", type=Path, required=True, help="the recording to write (CSV)")
    parser.set_defaults(
        func=_run_rosbag, flags={"frame": "--frame", "torque_point": "--torque-point"}
    )


def _point(text: str) -> tuple[float, float, float]:
    """An argparse ``type``: three numbers separated by commas (m)."""
    parse = number(unit="m")
    cells = text.split(",")
    if len(cells) != 3:
        raise argparse.ArgumentTypeError(f"must be three numbers X,Y,Z (m), got {text!r}")
    x, y, z = (parse(cell) for cell in cells)
    return x, y, z


def _run_rosbag(args: argparse.Namespace) -> int:
    from sensing_antenna.importers.axes import SensorAxes
    from sensing_antenna.importers.rosbag import read_rosbag
    from sensing_antenna.recording import write_recording

    point = (0.0, 0.0, 0.0) if args.torque_point is None else args.torque_point
    axes = SensorAxes(args.frame, reaction=args.reaction, torque_point=point)
    metadata = {
        "description": args.description
        or f"imported from ROS bag {args.bag.name} ({args.wrench}, {args.joints})"
    }
    if args.antenna:
        metadata["antenna"] = args.antenna
    result = read_rosbag(
        args.bag,
        args.wrench,
        args.joints,
        joint1=args.joint1,
        joint2=args.joint2,
        axes=axes,
        sample_period=None if args.rate is None else 1.0 / args.rate,
        max_gap=args.max_gap,
        stamps=args.stamps,
        metadata=metadata,
    )
    for line in result.report.lines():
        print(line, file=sys.stderr)
    write_recording(result.recording, args.out)
    print(args.out)
    return 0
