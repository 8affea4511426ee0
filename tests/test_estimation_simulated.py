"""The paper method on the project's simulator recordings (a handful of contact points).

Reference: the simulator's ground truth ``true_xc`` (the abscissa it actually touched), read by the
test only; the estimator gets the recording without ground-truth metadata. Tolerance 1 cm: the
paper's typical error (Tables 3 and 4); the full sweep with the baselines is
``benchmarks/eval_accuracy.py``.
"""

from __future__ import annotations

import pytest

from sensing_antenna.antenna import paper_antenna
from sensing_antenna.estimation import Status, estimate
from sensing_antenna.simulator import Scenario, simulate


@pytest.mark.parametrize(
    ("case", "x_c"),
    [("azimuthal", 0.4), ("azimuthal", 0.8), ("vertical", 0.55), ("vertical", 0.75)],
)
def test_paper_method_on_simulated_push(case: str, x_c: float) -> None:
    antenna = paper_antenna()
    recording = simulate(antenna, Scenario(case=case, contact_point=x_c, seed=7))
    truth = float(recording.metadata["true_xc"])
    result = estimate(recording.without_ground_truth(), antenna)
    assert result.status is Status.OK, result.reason
    assert result.x_c == pytest.approx(truth, abs=0.01)
    # Estimator 2 alone within the disagreement tolerance (it only has to pick a candidate).
    assert result.ratio_estimate == pytest.approx(truth, abs=0.12)


def test_free_sweep_has_no_contact() -> None:
    antenna = paper_antenna()
    recording = simulate(antenna, Scenario(case="free", seed=3, duration=2.0))
    assert estimate(recording, antenna).status is Status.NO_CONTACT
