"""The estimators' model of a simulated device whose stiffness a calibration has measured.

An antenna known only from its material data carries the spread of a nominal T (5 %,
``Link.frequency_uncertainty``), and the estimators rightly answer ``uncertain`` with it. Tests
of anything else give them the device's own T as a calibration would, with the scatter such a
calibration measures on the simulated device.
"""

from __future__ import annotations

from sensing_antenna.antenna import Antenna, paper_antenna


def calibrated(device: Antenna | None = None) -> Antenna:
    """``device`` (default the paper's antenna) with its own T as a calibrated T_e and the
    scatter calibrations of the simulated device measure (``Antenna.self_calibrated``, 0.1 %)."""
    device = device if device is not None else paper_antenna()
    return device.self_calibrated()
