"""The real run function: simulate one contact manoeuvre, then estimate it with every method.

Also the optional first step of a campaign (Section 5.2 of the paper): simulate a free motion and
identify the free-motion observer of Eq. 15 and its contact threshold from it, so that the contact
detector is tuned to the simulated device rather than to the paper's real one.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

from sensing_antenna.antenna import Antenna
from sensing_antenna.campaign.records import METHOD_ERROR, MethodOutcome, RunResult
from sensing_antenna.campaign.spec import CampaignSpec, CampaignSpecError, RunSpec, derive_seed

__all__ = [
    "check_scenario",
    "identify_observer",
    "make_scenario",
    "prepare_antenna",
    "simulate_and_estimate",
]


def make_scenario(case: str, contact_point: float | None, seed: int, extra: dict[str, Any]) -> Any:
    """A ``simulator.Scenario`` for one run; unknown extra fields raise CampaignSpecError."""
    from sensing_antenna.simulator import Scenario

    known = {f.name for f in dataclasses.fields(Scenario)}
    for key in extra:
        if key not in known:
            raise CampaignSpecError(
                f"scenario.{key}", f"not a Scenario field; known: {', '.join(sorted(known))}"
            )
    kwargs: dict[str, Any] = {"case": case, "seed": seed, **extra}
    if contact_point is not None:
        kwargs["contact_point"] = contact_point
    return Scenario(**kwargs)


def simulate_and_estimate(run: RunSpec) -> RunResult:
    """Simulate the run's manoeuvre and estimate the recording with each of ``run.methods``.

    An estimator that raises is recorded for that method (status ``"error"``) and the other
    methods still run; an exception from the simulator propagates (the runner records the run as
    failed).
    """
    from sensing_antenna.estimation import estimate
    from sensing_antenna.simulator import simulate

    start = time.perf_counter()
    scenario = make_scenario(run.case, run.contact_point, run.seed, dict(run.scenario))
    recording = simulate(run.antenna, scenario)
    simulate_s = time.perf_counter() - start
    # The estimators get the recording without ground truth (recording format: they must never
    # read it); the run result keeps the true contact point from the run spec.
    blind = recording.without_ground_truth()
    outcomes = []
    for method in run.methods:
        begin = time.perf_counter()
        try:
            result = estimate(blind, run.antenna, method=method)
        except Exception as exc:  # recorded per method: one broken estimator must not hide others
            outcomes.append(
                MethodOutcome(
                    method=method,
                    status=METHOD_ERROR,
                    reason=f"{type(exc).__name__}: {exc}",
                    elapsed_s=time.perf_counter() - begin,
                )
            )
            continue
        outcomes.append(MethodOutcome.from_estimate(method, result, time.perf_counter() - begin))
    return RunResult.for_run(run, outcomes, simulate_s)


def identify_observer(antenna: Antenna, spec: CampaignSpec) -> Antenna:
    """Simulate a free motion and return ``antenna`` with the observer identified from it (Eq. 15).

    The free motion uses the spec's scenario settings and its own seed (stream 1 of the base seed).
    """
    from sensing_antenna.calibration.observer import identify_free_motion
    from sensing_antenna.simulator import simulate

    extra = dict(spec.scenario)
    extra["duration"] = spec.free_motion.duration
    scenario = make_scenario(
        spec.free_motion.case, None, derive_seed(spec.base_seed, 0, stream=1), extra
    )
    recording = simulate(antenna, scenario)
    fit = identify_free_motion(recording, antenna)
    return dataclasses.replace(antenna, observer=fit.observer)


def check_scenario(spec: CampaignSpec) -> None:
    """Raise CampaignSpecError (naming the spec file) if the scenario section is not valid."""
    from sensing_antenna.simulator.scenario import ScenarioError

    try:
        make_scenario(spec.cases[0], spec.contact_points[0], 0, dict(spec.scenario))
    except ScenarioError as exc:
        raise CampaignSpecError(
            f"scenario.{exc.field_name}", str(exc).split(": ", 1)[-1], spec.source or None
        ) from exc
    except TypeError as exc:
        raise CampaignSpecError("scenario", str(exc), spec.source or None) from exc


def prepare_antenna(spec: CampaignSpec) -> Antenna:
    """The antenna of every run: the spec's antenna, with the identified observer if asked.

    Checks the spec's scenario section first, so a bad value stops the campaign with one clear
    error instead of failing every run.
    """
    check_scenario(spec)
    antenna = spec.load_antenna()
    if spec.free_motion.identify:
        antenna = identify_observer(antenna, spec)
    return antenna
