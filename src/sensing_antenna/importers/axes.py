"""How a force/torque sensor's axes lie on the motor frame, and which wrench it reports.

The recording format (docs/recording-format.md) wants the force and torque that the link applies
to the head, resolved on the motor axes X^m (along the link), Y^m, Z^m. A sensor mounted another
way round reports the same wrench on its own axes; :class:`SensorAxes` names, for each motor
axis in turn, the sensor axis that lies along it with its sign (``"z,-y,x"``: X^m is the sensor's
+z, Y^m its -y, Z^m its +x). Only right-handed choices are accepted: a rotation turns force and
torque alike. A sensor that reports the wrench the head applies to the link (the reaction) is
stated apart (``reaction=True``): both vectors change sign. A sensor takes its torques about its
own origin S; where S is not the base point O, ``torque_point`` (S - O on the motor axes, m)
moves them there (:mod:`sensing_antenna.torque_point`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.errors import FieldError
from sensing_antenna.torque_point import point_problem, torques_about_base

__all__ = ["AxesError", "SensorAxes"]

_AXES = ("x", "y", "z")


class AxesError(FieldError):
    """A sensor-axes description is malformed or left-handed; ``field_name`` is ``frame``."""


@dataclass(frozen=True)
class SensorAxes:
    """The sensor axes along X^m, Y^m, Z^m, and whether the sensor reports the reaction.

    Parameters
    ----------
    axes : str
        Three signed sensor axes separated by commas, one for each motor axis X^m, Y^m, Z^m:
        ``"x,y,z"`` (the sensor's axes are the motor axes), ``"-x,-y,z"`` (turned half a turn
        about Z^m), ``"z,x,y"``... Each of x, y, z once, optional sign ``+`` or ``-``, and the
        three must form a right-handed set (a rotation).
    reaction : bool
        True when the sensor reports the wrench the head applies to the link, the opposite of
        what the recording holds.
    torque_point : tuple of 3 float
        S - O, the sensor's origin from the base point O on the motor axes (m), about which it
        takes its torques; (0, 0, 0): about O.
    """

    axes: str = "x,y,z"
    reaction: bool = False
    torque_point: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        self.matrix  # noqa: B018  (validates)
        problem = point_problem(np.array(self.torque_point, dtype=float))
        if problem is not None:
            raise AxesError("torque_point", problem)

    @property
    def matrix(self) -> NDArray[np.float64]:
        """The 3 x 3 matrix R, shape (3, 3), with v_motor = R @ v_sensor (reaction included)."""
        items = [item.strip().lower() for item in str(self.axes).split(",")]
        rows = []
        for item in items:
            sign = -1.0 if item.startswith("-") else 1.0
            name = item.lstrip("+-")
            if name not in _AXES or len(item) - len(name) > 1:
                raise AxesError(
                    "frame", f"{self.axes!r}: each axis is x, y or z with an optional sign"
                )
            row = np.zeros(3)
            row[_AXES.index(name)] = sign
            rows.append(row)
        matrix = np.array(rows)
        if len(items) != 3 or not np.array_equal(np.abs(matrix).sum(axis=0), np.ones(3)):
            raise AxesError("frame", f"{self.axes!r}: name each of x, y, z once, in three items")
        if round(float(np.linalg.det(matrix))) != 1:
            raise AxesError(
                "frame",
                f"{self.axes!r}: a left-handed set; name a rotation of the sensor's axes (flip"
                " two signs, or swap two axes and flip one), and state a sensor that reports"
                " the head's wrench on the link as the reaction",
            )
        return -matrix if self.reaction else matrix

    def to_motor(
        self, force: NDArray[np.float64], torque: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Force (N) and torque (N m) on the sensor's axes, shape (n, 3) each, to the motor
        frame, the wrench by the link on the head, its torques about O; shapes kept."""
        matrix = self.matrix
        force_m = force @ matrix.T
        return force_m, torques_about_base(
            force_m, torque @ matrix.T, np.array(self.torque_point, dtype=float)
        )

    def describe(self) -> str:
        """One line: the axes, ``reaction`` when the sensor reports the reaction, and the point
        its torques are taken about when it is not O."""
        point = ""
        if any(self.torque_point):
            point = f", torques about ({', '.join(f'{v:g}' for v in self.torque_point)}) m"
        return f"{self.axes}{', reaction' if self.reaction else ''}{point}"
