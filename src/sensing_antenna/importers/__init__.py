"""Importers: recordings made from the logs a lab keeps in other formats (docs/import.md).

Each format has its own module that reads the log into timed streams; :mod:`.clock` puts the
streams onto the recording's one uniform clock and reports their rates and gaps, and
:mod:`.axes` turns a sensor's axes onto the motor frame. Formats:

``rosbag``
    ROS 1 and ROS 2 bags (``geometry_msgs/WrenchStamped``, ``sensor_msgs/JointState``) through
    the optional ``rosbags`` library: :func:`sensing_antenna.importers.rosbag.read_rosbag`.
"""

from sensing_antenna.importers.axes import AxesError, SensorAxes
from sensing_antenna.importers.clock import ImporterError

__all__ = ["AxesError", "ImporterError", "SensorAxes"]
