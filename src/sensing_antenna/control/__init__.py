"""The head's controller and observer as discrete-time objects, for a real device's loop.

- :mod:`.servo`: the 2-DOF PID with coupling-torque feedback of each joint (Section 4.1,
  Eq. 14): its design, its compiled step (:func:`~.servo.joint_servo_step`) and
  :class:`~.servo.HeadController`;
- :mod:`.observer`: the free-motion observer of Eq. 15 for both joints, stepped per sample
  (:class:`~.observer.CouplingTorqueObserver`).

This floor sits below the device simulator, whose compiled time loop calls the same step as
:class:`~.servo.HeadController`, so a simulated head and a real one run one controller. See
``docs/control.md``.
"""

from sensing_antenna.control.observer import CouplingTorqueObserver, observe_coupling_torques
from sensing_antenna.control.servo import (
    DEFAULT_SERVO_POLE,
    FRICTION_SPEED,
    HeadController,
    ServoDesign,
    coupling_torques,
    design_servo,
)

__all__ = [
    "DEFAULT_SERVO_POLE",
    "FRICTION_SPEED",
    "CouplingTorqueObserver",
    "HeadController",
    "ServoDesign",
    "coupling_torques",
    "design_servo",
    "observe_coupling_torques",
]
