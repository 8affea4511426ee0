"""Shared helpers of the tests on recordings."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from sensing_antenna.recording import Recording


def samples_kept(recording: Recording, keep: Any) -> Recording:
    """``recording`` with only the samples ``keep`` selects (a boolean mask, a slice or indices),
    in every column, the extra ones too; metadata unchanged."""
    return dataclasses.replace(
        recording,
        t=recording.t[keep],
        theta=recording.theta[keep],
        force=recording.force[keep],
        torque=recording.torque[keep],
        extra={name: values[keep] for name, values in recording.extra.items()},
    )


def knocked(recording: Recording) -> Recording:
    """``recording`` with a knock during its sweep: a 50 Hz burst of 0.3 N and 0.03 N m on every
    channel from 0.3 to 0.8 s (a detector that fires on it, before the touch, is no contact)."""
    t = recording.t
    burst = np.sin(2.0 * np.pi * 50.0 * t) * ((t > 0.3) & (t < 0.8))
    return dataclasses.replace(
        recording,
        force=recording.force + 0.3 * burst[:, None],
        torque=recording.torque + 0.03 * burst[:, None],
    )
