"""The estimators' model of a simulated device whose stiffness a calibration has measured.

An antenna known only from its material data carries the spread of a nominal T (5 %,
``Link.frequency_uncertainty``), and the estimators rightly answer ``uncertain`` with it. Tests
of anything else give them the device's own T as a calibration would, with the scatter such a
calibration measures on the simulated device.
"""

from __future__ import annotations

import dataclasses
import math

from sensing_antenna.antenna import PARAMETER_RANGES, Antenna, Link, paper_antenna


def calibrated(device: Antenna | None = None) -> Antenna:
    """``device`` (default the paper's antenna) with its own T as a calibrated T_e and the
    scatter calibrations of the simulated device measure (``Antenna.self_calibrated``, 0.1 %)."""
    device = device if device is not None else paper_antenna()
    return device.self_calibrated()


def weightless(link: Link | None = None, rigidity: float | None = None) -> Link:
    """``link`` (default the paper's) at the lowest bulk density a link may have (1 kg/m^3), its
    E I kept or set to ``rigidity`` (N m^2): for loads built without the link's weight, whose
    terms in the statics (``beam.weight``) are then a thousandth of the paper link's."""
    link = link if link is not None else paper_antenna().link
    lightest = math.pi * link.radius**2 * PARAMETER_RANGES["link.bulk_density"].low
    changes: dict[str, float] = {"linear_density": lightest}
    if link.calibrated_t is not None:
        # the stiffness rho / T^2 kept: T scales with the square root of the density
        changes["calibrated_t"] = link.calibrated_t * math.sqrt(lightest / link.linear_density)
    if rigidity is not None:
        modulus = PARAMETER_RANGES["link.youngs_modulus"].high
        changes.update(youngs_modulus=modulus, second_moment=rigidity / modulus)
        if link.calibrated_t is not None:
            changes["calibrated_t"] = math.sqrt(lightest / rigidity)
    return dataclasses.replace(link, **changes)
