"""Recordings from the simulator: format sign check, metadata, determinism, validation."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from sensing_antenna.antenna import STANDARD_GRAVITY, paper_antenna
from sensing_antenna.recording import read_recording, write_recording
from sensing_antenna.simulator import Scenario, ScenarioError, simulate


def test_sign_check_of_the_recording_format_at_rest() -> None:
    """Recording format: theta2 = 0, link at rest, nothing touching: F ~ (0, 0, -m_b g) and
    torque ~ (0, +0.5 m_b g l, 0)."""
    antenna = paper_antenna()
    rec = simulate(antenna, Scenario(case="free", noise_scale=1.0, duration=0.05, start_time=1.0))
    weight = antenna.link.mass * STANDARD_GRAVITY
    force = rec.force.mean(axis=0)
    torque = rec.torque.mean(axis=0)
    assert np.all(rec.theta[:, 1] == 0.0)
    # tolerance: 4 sensor resolution counts (bias 2 counts + noise averaged over 50 samples)
    np.testing.assert_allclose(force, [0.0, 0.0, -weight], atol=4 / 160)
    np.testing.assert_allclose(
        torque, [0.0, 0.5 * weight * antenna.link.length, 0.0], atol=4 / 32000
    )
    exact = simulate(antenna, Scenario(case="free", noise_scale=0.0, duration=0.02, start_time=1.0))
    np.testing.assert_allclose(exact.force[0], [0.0, 0.0, -weight], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(
        exact.torque[0], [0.0, 0.5 * weight * antenna.link.length, 0.0], rtol=1e-12, atol=1e-15
    )


def test_same_seed_same_bytes_different_seed_differs(tmp_path: Path) -> None:
    antenna = paper_antenna()
    paths = []
    for i, seed in enumerate((7, 7, 8)):
        rec = simulate(
            antenna, Scenario(case="azimuthal", contact_point=0.7, seed=seed, duration=1.2)
        )
        paths.append(tmp_path / f"r{i}.csv")
        write_recording(rec, paths[-1])
    assert paths[0].read_bytes() == paths[1].read_bytes()
    assert paths[0].read_bytes() != paths[2].read_bytes()


def test_metadata_and_ground_truth(tmp_path: Path) -> None:
    antenna = paper_antenna()
    scenario = Scenario(case="vertical", contact_point=0.6, duration=2.0, seed=4)
    rec = simulate(antenna, scenario)
    meta = rec.metadata
    assert meta["format"] == "sensing-antenna-recording/1"
    assert float(meta["sample_period"]) == 1e-3
    assert meta["antenna"] == "paper-2021"
    assert meta["seed"] == "4"
    assert float(meta["true_xc"]) == pytest.approx(0.6, abs=0.01)
    point = json.loads(meta["true_contact_point"])
    assert len(point) == 3 and math.hypot(point[0], point[1]) == pytest.approx(0.6, abs=0.02)
    assert json.loads(meta["true_obstacle"])["kind"] == "bar"
    assert 0.3 < float(meta["true_t_contact"]) < float(meta["true_t_stop"]) < 2.0
    sim = json.loads(meta["simulation"])
    assert sim["scenario"]["contact_point"] == 0.6
    blind = rec.without_ground_truth()
    assert not any(k.startswith("true_") for k in blind.metadata)
    write_recording(rec, tmp_path / "v.csv")
    assert read_recording(tmp_path / "v.csv").metadata["true_xc"] == meta["true_xc"]


_BOX: dict[str, object] = {
    "case": "azimuthal",
    "contact_point": 0.5,
    "obstacle": "box",
    "obstacle_placement": (0.5, 0.05, 0, 0, 0, 1, 1, 1, 0),
    "obstacle_sizes": (0.05, 0.05, 0.1),
}


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        ({"case": "azimuthal"}, "contact_point"),
        ({"case": "free", "contact_point": 0.5}, "contact_point"),
        ({"case": "sideways", "contact_point": 0.5}, "case"),
        ({"case": "azimuthal", "contact_point": 0.5, "duration": -1.0}, "duration"),
        ({"case": "azimuthal", "contact_point": 0.5, "servo_pole": 5.0}, "servo_pole"),
        ({"case": "azimuthal", "contact_point": 0.5, "damping_ratio": 1.5}, "damping_ratio"),
        (
            {"case": "azimuthal", "contact_point": 0.5, "obstacle_placement": (0, 0, 0)},
            "obstacle_placement",
        ),
        ({"case": "azimuthal", "contact_point": 0.5, "obstacle": "capsule"}, "obstacle_placement"),
        (
            {
                "case": "azimuthal",
                "contact_point": 0.5,
                "obstacle": "cylinder",
                "obstacle_placement": (0.5, 0, 0, 0, 0, 1),
            },
            "obstacle_length",
        ),
        ({"case": "azimuthal", "contact_point": 0.5, "obstacle_length": 0.1}, "obstacle_length"),
        (
            {"case": "azimuthal", "contact_point": 0.5, "obstacle_placement": (0.5, 0, 0, 0, 0, 0)},
            "obstacle_placement",
        ),
        (
            {"case": "vertical", "contact_point": 0.5, "obstacle_placement": (math.nan,) * 6},
            "obstacle_placement",
        ),
        # a box needs its X axis too, not along its Z; a cone two sizes; a torus's tube no
        # wider than its ring; sizes only for the solids
        (_BOX | {"obstacle_placement": (0.5, 0, 0, 0, 0, 1)}, "obstacle_placement"),
        (_BOX | {"obstacle_placement": (0.5, 0, 0, 0, 0, 1, 0, 0, 2)}, "obstacle_placement"),
        (_BOX | {"obstacle_sizes": (0.1, 0.1)}, "obstacle_sizes"),
        (_BOX | {"obstacle_sizes": (0.1, -0.1, 0.1)}, "obstacle_sizes"),
        (_BOX | {"obstacle_length": 0.1}, "obstacle_length"),
        (
            _BOX
            | {
                "obstacle": "torus",
                "obstacle_placement": _BOX["obstacle_placement"][:6],
                "obstacle_sizes": (0.02, 0.03),
            },
            "obstacle_sizes",
        ),
        ({"case": "azimuthal", "contact_point": 0.5, "obstacle_sizes": (0.1,)}, "obstacle_sizes"),
        (
            {
                "case": "azimuthal",
                "contact_point": 0.5,
                "obstacle": "capsule",
                "obstacle_placement": (0.5, 0, 0, 0, 0, 1),
                "obstacle_length": 1e3,
            },
            "obstacle_length",
        ),
    ],
)
def test_scenario_validation_names_the_field(changes: dict[str, object], field: str) -> None:
    with pytest.raises(ScenarioError, match=f"scenario.{field}"):
        Scenario(**changes)  # type: ignore[arg-type]
