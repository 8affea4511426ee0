"""Estimates beyond small deflection, on recordings of an independent rod engine.

The recordings are PyElastica Cosserat-rod simulations of the paper antenna pushed into a post
(``benchmarks/reference/rod``, docs/simulator.md, "An independent reference"): a geometrically
exact rod with stick-slip Coulomb friction (mu = 0.6) that did not slip (``true_slipping_at_end:
false``), with where it touched (``true_xc``, arc length) and the touched point
(``true_contact_point``) in their metadata.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from sensing_antenna import paper_antenna
from sensing_antenna.estimation import Status, estimate
from sensing_antenna.recording import Recording, read_recording

ROD = Path(__file__).resolve().parents[1] / "benchmarks" / "reference" / "rod" / "recordings"


def rod(name: str) -> tuple[Recording, float, np.ndarray]:
    recording = read_recording(ROD / f"{name}.csv")
    truth = float(recording.metadata["true_xc"])
    point = np.asarray(json.loads(recording.metadata["true_contact_point"]), dtype=float)
    return recording.without_ground_truth(), truth, point


@pytest.mark.parametrize("name", ["xc050-push028", "xc090-push028"])
def test_a_push_of_a_third_of_x_c_is_ok_and_right(name: str) -> None:
    # 31 % and 33 % deflection (true_deflection_ratio): the elastica's statics put the ratio
    # within 1 cm of where the rod touched, the answer comes back ok within 1 cm and the
    # touched point within 1 cm of the rod's in 3D (the small-deflection statics put the
    # contact 5 % of x_c too far out along X^m at this deflection)
    recording, truth, point = rod(name)
    result = estimate(recording, paper_antenna().self_calibrated())
    assert result.status is Status.OK, result.reason
    assert abs(result.x_c - truth) < 0.01
    assert abs(result.ratio_estimate - truth) < 0.01
    assert np.linalg.norm(result.contact_point - point) < 0.01
    assert result.diagnostics["deflection_ratio"] > 0.25


def test_a_reaction_outside_the_friction_cone_is_slip_suspected() -> None:
    # The same push with a force of 1.5 times the push added outwards along the link after the
    # touch: no contact at rest on the link's side holds that (friction cone of mu = 1)
    recording, _, _ = rod("xc050-push028")
    t_contact = 0.75
    after = recording.t >= t_contact
    force = recording.force.copy()
    push = np.linalg.norm(force[-200:, 1:], axis=1).mean()
    force[after, 0] += 1.5 * push
    pushed = dataclasses.replace(recording, force=force)
    result = estimate(pushed, paper_antenna().self_calibrated())
    reasons = [result.reason or "", *result.diagnostics.get("other_reasons", [])]
    assert result.status is not Status.OK
    assert any("friction cone" in text for text in reasons), reasons
