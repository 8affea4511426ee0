"""The commanded trajectory of Section 4 steps 1 to 4: rest, sweep, (contact, push), stop, hold.

The swept joint follows a raised-cosine speed ramp from rest to the cruise speed,
``omega*(t) = omega_s (1 - cos(pi t / T_a)) / 2`` for ``0 <= t < T_a``, then ``omega_s``: speed
and acceleration are continuous, so the sweep itself excites little vibration. The position is the
integral, ``omega_s (t - T_a sin(pi t / T_a) / pi) / 2`` during the ramp and
``omega_s (t - T_a / 2)`` after it. Stopping (step 4) freezes the reference at its current value;
the servo (Eq. 14) then brings the joint to rest without overshoot. The free case decelerates with
the mirrored ramp after ``approach_time`` and holds.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ["ramp_displacement", "sweep_reference"]


def ramp_displacement(
    t: NDArray[np.float64], speed: float, accel_time: float
) -> NDArray[np.float64]:
    """Angle covered (rad) after time t (s) >= 0 by the raised-cosine ramp to ``speed`` (rad/s)."""
    t = np.asarray(t, dtype=float)
    tc = np.clip(t, 0.0, None)
    during = 0.5 * speed * (tc - accel_time / math.pi * np.sin(math.pi * tc / accel_time))
    after = speed * (tc - 0.5 * accel_time)
    return np.where(tc < accel_time, during, after)


def sweep_reference(
    t: NDArray[np.float64],
    start_angle: float,
    speed: float,
    accel_time: float,
    start_time: float,
    stop_after: float | None = None,
) -> NDArray[np.float64]:
    """Reference angle (rad) of the swept joint at times ``t`` (s), shape like t.

    Parameters
    ----------
    start_angle : float
        Angle at rest before ``start_time`` (rad).
    speed, accel_time : float
        Cruise speed (rad/s) and ramp duration (s).
    start_time : float
        Start of the sweep (s).
    stop_after : float or None
        If given, decelerate with the mirrored ramp starting ``stop_after`` s after the start.
    """
    tau = np.asarray(t, dtype=float) - start_time
    angle = start_angle + ramp_displacement(tau, speed, accel_time)
    if stop_after is not None:
        angle = angle - ramp_displacement(tau - stop_after, speed, accel_time)
    return np.asarray(angle)
