"""Tests of sensing_antenna.plotting.recording: the figures of one recording."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sensing_antenna.plotting.recording import PLOT_LIMIT, plot_recording
from sensing_antenna.recording import Recording, RecordingError


def _recording(n: int = 400, scale: float = 1.0) -> Recording:
    rng = np.random.default_rng(3)
    t = 1e-3 * np.arange(n)
    return Recording(
        t=t,
        theta=scale * rng.uniform(-1, 1, size=(n, 2)),
        force=scale * rng.uniform(-1, 1, size=(n, 3)),
        torque=scale * rng.uniform(-1, 1, size=(n, 3)),
        extra={"theta1_ref": scale * rng.uniform(-1, 1, size=n)},
        source="rec.csv",
    )


def test_magnitudes_up_to_the_limit_are_drawn(tmp_path: Path) -> None:
    # Every plotted column spanning -1e300 to +1e300: the four figures are written.
    paths = plot_recording(_recording(scale=PLOT_LIMIT), tmp_path)
    assert [p.name for p in paths] == [
        "angles.png",
        "force.png",
        "torque.png",
        "torque_spectrum.png",
    ]
    assert all(p.stat().st_size > 0 for p in paths)


def test_a_magnitude_beyond_the_limit_is_refused_in_one_line(tmp_path: Path) -> None:
    # Drawn, 1e308 in fx makes matplotlib's tick locator raise OverflowError.
    recording = _recording()
    force = recording.force.copy()
    force[123, 0] = 1e308
    bad = Recording(
        t=recording.t, theta=recording.theta, force=force, torque=recording.torque, source="rec.csv"
    )
    with pytest.raises(RecordingError) as info:
        plot_recording(bad, tmp_path)
    assert str(info.value) == (
        "rec.csv: column 'fx': 1e+308 at sample 123 (t = 0.123 s) is beyond +-1e+300:"
        " too large to plot"
    )
    assert not any(tmp_path.iterdir())
