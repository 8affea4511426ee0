"""The fast method's information bound (estimation/methods/fast/bound.py): the first window whose
interval would be narrow enough with omega_1 at its Cramer-Rao bound and no floors.

Reference: the method's own declaration on the same recording, and its history of windows.
"""

from __future__ import annotations

import math
from typing import Any

import pytest

from _models import calibrated
from sensing_antenna.estimation import Evidence, conclude, gather
from sensing_antenna.estimation.methods.fast import (
    FastConfig,
    FastMethod,
    bound_delay,
    bound_width,
)
from sensing_antenna.recording import Recording
from sensing_antenna.simulator import Scenario, simulate


@pytest.fixture(scope="module")
def evidence() -> Evidence:
    """Paper antenna, azimuthal sweep onto a post at 0.6 m (seed 5), as the estimators see it."""
    recording: Recording = simulate(
        calibrated(), Scenario(case="azimuthal", contact_point=0.6, seed=5)
    )
    gathered = gather(recording.without_ground_truth(), calibrated())
    assert isinstance(gathered, Evidence)
    return gathered


def test_the_bound_is_the_first_window_narrow_enough_and_not_later_than_the_declaration(
    evidence: Evidence,
) -> None:
    config = FastConfig()
    declared = conclude(evidence, FastMethod(config))
    assert declared.status.value == "ok"
    bound = bound_delay(evidence, config)
    assert config.first_window <= bound <= declared.t_e - declared.t_1
    # The same instant read off the method's history from t_1: the first window whose width
    # at the bound is within the tolerance
    history = FastMethod(config).history(evidence, from_t1=True)
    assert bound_delay(evidence, config, windows=history) == bound
    t_1 = evidence.t[evidence.rest_index]
    first = next(w for w in history if bound_width(w, evidence.antenna.link, config) <= 0.005)
    assert evidence.t[first.end_index] - t_1 == bound
    # Earlier windows are wider at the bound (or have no bound), and the window that qualifies
    # is no wider at the bound than in the method's own posterior
    earlier = [w for w in history if w.end_index < first.end_index]
    assert earlier and all(
        not bound_width(w, evidence.antenna.link, config) <= config.tolerance for w in earlier
    )
    assert bound_width(first, evidence.antenna.link, config) <= first.posterior.width


def test_fits_shared_with_the_method_change_neither_the_bound_nor_the_estimate(
    evidence: Evidence,
) -> None:
    caches: tuple[dict[Any, Any], dict[Any, Any]] = ({}, {})
    method = FastMethod()
    shared = method.conclude(evidence, caches)
    assert caches[0]  # the method's fits, which the bound reads
    assert bound_delay(evidence, caches=caches) == bound_delay(evidence)
    alone = method.conclude(evidence)
    assert (alone.x_c, alone.t_e, alone.interval) == (shared.x_c, shared.t_e, shared.interval)


def test_no_window_narrow_enough_before_the_cap_is_nan(evidence: Evidence) -> None:
    # Windows of at most 0.1 s hold too few periods of omega_1 for a 5 mm interval here; a
    # tolerance no interval reaches is never met
    assert math.isnan(bound_delay(evidence, FastConfig(cap=0.1)))
    assert math.isnan(bound_delay(evidence, FastConfig(tolerance=1e-6, cap=0.3)))
