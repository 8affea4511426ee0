"""The fast method's statics: the elastica's, as the paper method's Estimator 2 reads them.

References: the closed form of a cantilever under a tip load (Bisshopp and Drucker, 1945, as
:func:`~sensing_antenna.beam.elastica.tip_load_cantilever` gives it) and the PyElastica
Cosserat-rod recordings of ``benchmarks/reference/rod`` (an independent rod engine, where the
rod touched in ``true_xc``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from _models import weightless
from sensing_antenna import paper_antenna
from sensing_antenna.beam.elastica import tip_load_cantilever
from sensing_antenna.estimation import FastMethod, OnlineEstimator, estimate
from sensing_antenna.estimation.methods.fast.model_order import select_model_order
from sensing_antenna.estimation.methods.fast.static_fit import static_ratio
from sensing_antenna.estimation.result import ContactEstimate
from sensing_antenna.recording import Recording, read_recording

TS = 1e-3
ROD = Path(__file__).resolve().parents[1] / "benchmarks" / "reference" / "rod" / "recordings"


def test_a_large_deflection_reads_the_arc_length_not_the_lever() -> None:
    # A cantilever of length 0.5 m under a dead load P across its axis with P L^2 / (E I) = 2:
    # its tip lies at x / L = 0.83936, y / L = 0.49346 (Bisshopp and Drucker's table, reproduced
    # by tip_load_cantilever). The sensor then reads R_perp = P, R_x = 0 and M_0 = P x_tip; the
    # contact's arc length is L = 0.5 m, where M_0 / R_perp (the straight link's ratio) gives
    # 0.420 m. The loads are fitted as the fast method fits them (a ringing mode on each
    # channel, little noise); the elastica's table interpolates within 1e-3 of the arc length
    # (docs/estimation.md), so 2 mm.
    length, rigidity = 0.5, paper_antenna().link.flexural_rigidity
    tip = tip_load_cantilever(2.0)
    push = 2.0 * rigidity / length**2
    x_tip = tip.x * length
    rng = np.random.default_rng(5)
    t = np.arange(400) * TS
    ring = np.exp(-2.0 * t) * np.cos(60.0 * t + 0.3)
    r_y = -push * (1.0 + 0.05 * ring)
    loads = np.column_stack(
        [r_y, np.zeros_like(t), np.zeros_like(t), np.zeros_like(t), x_tip * r_y]
    )
    loads += np.array([1e-4, 1e-4, 1e-7, 1e-7, 1e-7]) * rng.standard_normal(loads.shape)
    fit = select_model_order(loads, TS, 1, min_omega=20.0, degree=1)
    assert fit is not None
    statics = static_ratio(fit, None, 0.0, weightless(rigidity=rigidity), 0.0)
    assert statics.ratio == pytest.approx(length, abs=2e-3)
    assert x_tip == pytest.approx(0.41968, abs=1e-4)
    assert 0.0 < statics.standard_error < 1e-3


@pytest.fixture(scope="module")
def hard_push() -> Recording:
    """The rod pushed at 0.9 m until the contact is deflected by 28 % of x_c."""
    return read_recording(ROD / "xc090-push028.csv")


def test_the_rod_pushed_hard_is_read_where_it_touched(hard_push: Recording) -> None:
    # Where the PyElastica rod touched (true_xc) against the fast method's statics on its
    # final window: the straight link's ratio reads 4.9 to 6.7 cm short at 0.9 m and 26 to
    # 33 % deflection (the shortening of the bent link, about 0.6 (y_c / x_c)^2 of x_c); the
    # elastica's within 1 cm, as the front end's own ratio at its t_e lies within 0.02 to
    # 0.78 cm on these pushes (docs/estimation.md).
    truth = float(hard_push.metadata["true_xc"])
    result = estimate(hard_push.without_ground_truth(), paper_antenna().self_calibrated(), "fast")
    assert abs(result.ratio_estimate - truth) < 0.01


def _online(recording: Recording, block: int) -> ContactEstimate:
    """The online form's estimate, fed ``block`` samples at a time (1: ``update``)."""
    online = OnlineEstimator(
        paper_antenna().self_calibrated(), recording.sample_period, FastMethod()
    )
    t, theta, force, torque = recording.t, recording.theta, recording.force, recording.torque
    for k in range(0, t.shape[0], block):
        s = slice(k, k + block)
        if block == 1:
            out = online.update(t[k], theta[k], force[k], torque[k])
        else:
            out = online.update_block(t[s], theta[s], force[s], torque[s])
        if out is not None:
            return out
    raise AssertionError("the online form returned no estimate")


@pytest.mark.parametrize("whole", [False, True], ids=["sample by sample", "one block"])
def test_the_elastica_statics_online_are_the_offline_ones_to_the_bit(
    hard_push: Recording, whole: bool
) -> None:
    # The statics read the hold's axial reaction and the model term on the posterior's grid
    # besides each window's fit: fixed once the hold built the contact frame, so the online
    # form gives the same bits as the batch one where the elastica's corrections are largest
    recording = hard_push.without_ground_truth()
    offline = estimate(recording, paper_antenna().self_calibrated(), "fast").to_dict()
    online = _online(recording, recording.n_samples if whole else 1).to_dict()
    for key, value in offline.items():
        if key != "diagnostics":
            assert online[key] == value, key
