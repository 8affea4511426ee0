"""The 2-DOF sensing-antenna simulator: it models the device and writes recordings.

``simulate(antenna, scenario) -> Recording`` runs the manoeuvre of Section 4 (steps 1 to 4) on a
model of the device of Section 3: two servo-controlled motors (Eq. 1, Eq. 14), a flexible link
bending in two planes (finite elements), rigid obstacles with friction, and a noisy F/T sensor.
See ``docs/simulator.md``.
"""

from sensing_antenna.simulator.device import (
    DEVICE_PROFILES,
    DeviceError,
    DeviceImperfections,
    device_from_mapping,
    device_profile,
    realistic_device,
)
from sensing_antenna.simulator.run import SimulationDetail, simulate, simulate_detailed
from sensing_antenna.simulator.scenario import Scenario, ScenarioError, SensorNoise

__all__ = [
    "DEVICE_PROFILES",
    "DeviceError",
    "DeviceImperfections",
    "Scenario",
    "ScenarioError",
    "SensorNoise",
    "SimulationDetail",
    "device_from_mapping",
    "device_profile",
    "realistic_device",
    "simulate",
    "simulate_detailed",
]
