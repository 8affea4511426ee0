"""Shared helpers of the tests on recordings."""

from __future__ import annotations

import dataclasses
from typing import Any

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
