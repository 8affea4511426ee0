"""Scenario validation: every field checked up front, limits that bound a simulation's size."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sensing_antenna.antenna import paper_antenna
from sensing_antenna.recording import MAX_FILE_BYTES, MAX_SAMPLES
from sensing_antenna.simulator import Scenario, ScenarioError
from sensing_antenna.simulator.run import simulate_detailed
from sensing_antenna.simulator.scenario import (
    DEFAULT_SAMPLE_PERIOD,
    MAX_DURATION,
    MAX_ELEMENTS,
    MAX_SIMULATED_SAMPLES,
    MAX_SUBSTEPS,
    duration_problem,
)


@pytest.mark.parametrize("case", ["azimuthal", "free"])
def test_a_duration_past_the_budget_is_refused_up_front(case: str) -> None:
    # A duration of 1e9 s would ask the simulator for arrays of 1e12 samples: every run of a
    # campaign would fail. It is refused before anything is simulated.
    contact = None if case == "free" else 0.5
    with pytest.raises(ScenarioError) as info:
        Scenario(case=case, contact_point=contact, duration=1e9)  # type: ignore[arg-type]
    assert str(info.value) == (
        "scenario.duration: 1000000000.0 s is more than 600 s: 600000 samples at 1000 Hz, the"
        " limit that keeps a simulation's memory and its recording bounded"
    )
    assert Scenario(case=case, contact_point=contact, duration=MAX_DURATION).duration == 600.0  # type: ignore[arg-type]


def test_duration_problem_is_the_check_a_campaign_runs_on_its_own_fields() -> None:
    assert duration_problem(3.5) is None
    assert duration_problem(MAX_DURATION) is None
    assert "more than 600 s" in str(duration_problem(math.nextafter(MAX_DURATION, math.inf)))
    assert duration_problem(0.01) == "must be > 0.01 s, got 0.01"
    assert duration_problem(np.float64("nan")) == "must be a finite number, got nan"
    assert duration_problem("long") == "must be a finite number, got 'long'"
    assert duration_problem(True) == "must be a finite number, got True"
    # the budget is in samples: at 10 kHz a tenth of the duration
    assert duration_problem(60.0, 1e-4) is None
    assert duration_problem(61.0, 1e-4) == (
        "61.0 s is more than 60 s: 600000 samples at 10000 Hz, the limit that keeps a"
        " simulation's memory and its recording bounded"
    )


def test_the_budget_fits_the_simulator_and_the_recording_reader() -> None:
    # The longest simulation records MAX_SIMULATED_SAMPLES at the simulator's period, a recording
    # the reader accepts both by sample count and by file size (with 64 KiB for the metadata).
    # Its longest row: every column the simulator writes (its motor commands and the contact's
    # track included) at 24 characters per number (repr of a double, e.g.
    # -2.2250738585072014e-308), a comma between two and a line feed.
    scenario = Scenario(case="azimuthal", contact_point=0.5, duration=1.0)
    recording = simulate_detailed(paper_antenna(), scenario, record_commands=True).recording
    columns = 9 + len(recording.extra)
    assert columns == 17
    longest_row = columns * 24 + columns
    assert round(MAX_DURATION / DEFAULT_SAMPLE_PERIOD) == MAX_SIMULATED_SAMPLES
    assert MAX_SIMULATED_SAMPLES <= MAX_SAMPLES
    assert MAX_SIMULATED_SAMPLES * longest_row + 2**16 <= MAX_FILE_BYTES


@pytest.mark.parametrize(
    ("field", "value", "words"),
    [
        ("n_elements", MAX_ELEMENTS + 1, f"from 4 to {MAX_ELEMENTS}"),
        ("n_elements", 3, f"from 4 to {MAX_ELEMENTS}"),
        ("substeps", MAX_SUBSTEPS + 1, f"from 1 to {MAX_SUBSTEPS}"),
        ("substeps", True, f"from 1 to {MAX_SUBSTEPS}"),
        ("sweep_speed", 1e300, "1e+300 rad/s is more than 100 rad/s"),
        ("obstacle_radius", 1e300, "1e+300 m is more than 10 m"),
        ("contact_stiffness", 1e300, "1e+300 N/m is more than 1e+10 N/m"),
        ("accel_time", 1e300, "1e+300 s is more than 600 s"),
        ("approach_time", 1e300, "1e+300 s is more than 600 s"),
        ("start_time", 1e300, "1e+300 s is more than 600 s"),
        ("description", "two\nlines", "one line"),
        ("description", " padded", "one line"),
        ("noise_scale", np.float64("nan"), "must be a finite number, got nan"),
        ("noise_scale", 1e300, "must be at most 1000 (times the sensor's noise), got 1e+300"),
        ("sample_period", 1.0, "must be between 0.0001 and 0.005 s (200 Hz to 10000 Hz)"),
        ("sample_period", 0.0, "must be between 0.0001 and 0.005 s (200 Hz to 10000 Hz)"),
        ("sample_period", np.float64("inf"), "must be a finite number, got inf"),
    ],
)
def test_each_limit_names_its_field_in_one_line(field: str, value: object, words: str) -> None:
    # At 1e300, sweep speed, obstacle radius, contact stiffness and the ramp times make the
    # simulator overflow (a traceback, or a recording of NaN refused as "<recording>: NaN").
    with pytest.raises(ScenarioError) as info:
        Scenario(case="azimuthal", contact_point=0.5, **{field: value})  # type: ignore[arg-type]
    message = str(info.value)
    assert message.startswith(f"scenario.{field}: ")
    assert words in message
    assert "\n" not in message and "np." not in message


def test_the_free_vertical_sweep_moves_theta2_alone_and_touches_nothing() -> None:
    # The vertical sweep with no bar: theta2 ramps up to the sweep speed and is brought to
    # rest after the approach time, theta1 stays put, and nothing touches the link.
    from sensing_antenna.simulator import simulate

    scenario = Scenario(case="free-vertical", duration=2.0, noise_scale=0.0)
    assert scenario.obstacle_kind is None
    recording = simulate(paper_antenna(), scenario)
    theta1, theta2 = recording.theta.T
    assert np.ptp(theta1) < 1e-9
    assert np.ptp(theta2) > 0.1
    # brought to rest: over the last 0.1 s it moves at under 3 % of the 0.3 rad/s sweep speed
    # (the servo's last creep under the weight's moment)
    assert abs(theta2[-1] - theta2[-100]) < 0.03 * 0.3 * 0.1
    assert "true_xc" not in recording.metadata  # no obstacle to touch
    with pytest.raises(ScenarioError, match="contact_point: must be None"):
        Scenario(case="free-vertical", contact_point=0.5)


def test_a_push_that_is_not_a_criterion_is_refused() -> None:
    # a bare angle would reach the push monitor and fail there; the scenario names the field
    with pytest.raises(ScenarioError, match=r"push: must be a push criterion"):
        Scenario(case="azimuthal", contact_point=0.5, push=0.1)
