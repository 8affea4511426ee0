"""Every estimator on a sweep towards -Y^m: the mirror image of a simulated +Y^m push.

The reflection y -> -y of the head's absolute frame keeps gravity (along -Z) and the round link's
physics, so a device sweeping towards -Y^m records the +Y^m sweep's recording with theta1, fy,
tx and tz negated (``simulator.mirror``; docs/recording-format.md). The contact abscissa does not
depend on the side the link is pushed from: each method must give the same x_c and status on
both, and the reflected 3D point.
"""

from __future__ import annotations

import numpy as np
import pytest

from _models import calibrated
from sensing_antenna.estimation import ContactEstimate, estimate
from sensing_antenna.estimation.methods import METHODS
from sensing_antenna.recording import Recording
from sensing_antenna.simulator import Scenario, simulate
from sensing_antenna.simulator.mirror import mirror_recording

ANTENNA = calibrated()


@pytest.fixture(scope="module")
def pair() -> tuple[Recording, Recording]:
    # a post leaning 0.3 rad along the sweep: all six wrench components carry the contact
    recording = simulate(
        ANTENNA, Scenario(case="azimuthal", contact_point=0.7, obstacle_tilt=0.3, seed=5)
    )
    return recording, mirror_recording(recording)


def test_the_mirrored_recording_turns_the_other_way(pair: tuple[Recording, Recording]) -> None:
    ahead, back = pair
    # the head turned towards -Y^m: theta1 falls through the touch, the link held back along +Y^m
    # pushes the head that way (fy > 0 at the hold, where the +Y^m sweep's is negative)
    assert back.theta[-1, 0] < back.theta[0, 0]
    assert np.mean(back.force[-200:, 1]) > 0 > np.mean(ahead.force[-200:, 1])
    # the weight is the same either way: fz and ty unchanged
    np.testing.assert_array_equal(back.force[:, 2], ahead.force[:, 2])
    np.testing.assert_array_equal(back.torque[:, 1], ahead.torque[:, 1])
    assert mirror_recording(back) == ahead


def _pair_estimates(
    pair: tuple[Recording, Recording], method: str
) -> tuple[ContactEstimate, ContactEstimate]:
    ahead, back = pair
    return (
        estimate(ahead.without_ground_truth(), ANTENNA, method),
        estimate(back.without_ground_truth(), ANTENNA, method),
    )


@pytest.mark.parametrize("method", sorted(METHODS))
def test_every_method_estimates_the_mirrored_push_alike(
    pair: tuple[Recording, Recording], method: str
) -> None:
    ahead, back = _pair_estimates(pair, method)
    assert back.status is ahead.status, back.reason
    # the same arithmetic on negated numbers: equal to rounding (1 um is far below any
    # method's resolution)
    assert back.x_c == pytest.approx(ahead.x_c, abs=1e-6)
    np.testing.assert_allclose(back.contact_point * [1, -1, 1], ahead.contact_point, atol=1e-6)
    truth = float(pair[1].metadata["true_xc"])
    assert back.x_c == pytest.approx(truth, abs=0.02)
