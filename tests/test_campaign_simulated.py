"""The real run function (simulate, then estimate with every method) and the free-motion step."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from sensing_antenna.antenna import paper_antenna
from sensing_antenna.campaign.records import RUN_OK, CampaignRow
from sensing_antenna.campaign.runs import RunSpec, expand_runs
from sensing_antenna.campaign.schema import CampaignSpec, CampaignSpecError, FreeMotionStep


def one_point_spec(**changes: object) -> CampaignSpec:
    values: dict[str, object] = {
        "name": "one",
        "antenna": "paper-2021",
        "cases": ("azimuthal",),
        "contact_points": (0.55,),
        "repeats": 1,
        "base_seed": 99,
        "methods": ("paper", "ratio", "two-frequency"),
    }
    values.update(changes)
    return CampaignSpec(**values)  # type: ignore[arg-type]


def test_run_function_copies_each_method_estimate_of_the_seeded_recording() -> None:
    from sensing_antenna.campaign.simulated import (
        make_scenario,
        point_error,
        simulate_and_estimate,
    )
    from sensing_antenna.estimation import Evidence, estimate, gather
    from sensing_antenna.estimation.methods.fast import bound_delay
    from sensing_antenna.simulator import simulate

    antenna = paper_antenna()
    run = expand_runs(one_point_spec(methods=("paper", "ratio", "two-frequency", "fast")), antenna)[
        0
    ]
    result = simulate_and_estimate(run)
    assert result.status == RUN_OK
    assert result.methods == ("paper", "ratio", "two-frequency", "fast")
    # the same seed gives the same recording; the estimators see it without ground truth
    scenario = make_scenario(run.case, run.contact_point, run.seed, {})
    recording = simulate(antenna, scenario)
    # the contact abscissa is the recording's ground truth, kept beside the nominal x_c
    contact = result.rows[0].x_c_contact_m
    assert contact == float(recording.metadata["true_xc"])
    # Pushed on until y_c = d x_c, the base has turned by about d: the fixed obstacle, x_c from
    # the base, sits x_c cos d ~ x_c (1 - d^2 / 2) along the turned link, and the bent link
    # (slope d - 3 d / 2 at x_c, cantilever under an end load) touches the cylinder R d / 2
    # nearer the base. With d = 0.072 here that is 1.44 + 0.36 = 1.80 mm; the arc length of the
    # bend and the sag, left out, moved it by under 4 % from 0.3 to 0.9 m: 10 %.
    turn = float(recording.metadata["true_deflection_ratio"])
    slide = run.contact_point * turn**2 / 2 + scenario.obstacle_radius * turn / 2
    assert run.contact_point - contact == pytest.approx(slide, rel=0.1)
    # the front end ran once for all methods; each method's estimate is what ``estimate`` gives
    blind = recording.without_ground_truth()
    for row in result.rows:
        assert row.noise_scale == 1.0 and row.x_c_contact_m == contact
        assert 0 < row.front_end_s <= row.estimate_s
        estimated = estimate(blind, antenna, method=row.method)
        assert row == CampaignRow.of_estimate(
            run,
            estimated,
            contact_abscissa=contact,
            simulate_s=row.simulate_s,
            front_end_s=row.front_end_s,
            estimate_s=row.estimate_s,
            point_error_m=point_error(estimated, recording, antenna),
            bound_delay_s=row.bound_delay_s,
        )
        # the touched point in 3D: within a few mm of where the link touched (the 3D point of
        # an estimate within 1 cm along the link, bent and sagged by the model's statics)
        assert 0.0 <= row.point_error_m < 0.01
    # the fast row also holds the information bound of its delay, as the package computes it on
    # the same evidence, and no later than the method's own declaration; the others hold none
    fast, evidence = result.rows[-1], gather(blind, antenna)
    assert isinstance(evidence, Evidence)
    assert fast.bound_delay_s == bound_delay(evidence)
    assert 0.0 < fast.bound_delay_s <= fast.delay_s
    assert all(math.isnan(row.bound_delay_s) for row in result.rows[:-1])
    # a spec without the bound leaves it out
    off = expand_runs(one_point_spec(methods=("fast",), fast_bound=False), antenna)[0]
    assert math.isnan(simulate_and_estimate(off).rows[0].bound_delay_s)


def test_a_run_the_front_end_stops_early_and_a_method_that_raises_are_recorded() -> None:
    from sensing_antenna.campaign.simulated import simulate_and_estimate

    # 0.5 s of recording ends before the contact (about 0.75 s into the default manoeuvre): the
    # front end stops at no contact and every method reports it; an unknown method raises
    run = RunSpec(
        0,
        "short",
        "azimuthal",
        0.5,
        1,
        3,
        paper_antenna(),
        ("paper", "bogus", "fast"),
        {"duration": 0.5},
    )
    paper, bogus, fast = simulate_and_estimate(run).rows
    assert [(r.method, r.status) for r in (paper, fast)] == [
        ("paper", "no_contact"),
        ("fast", "no_contact"),
    ]
    assert paper.reason == fast.reason != ""
    assert bogus.status == "error"
    assert bogus.reason.startswith("UnknownMethodError: method: unknown 'bogus'")
    assert math.isnan(bogus.x_c_estimate_m) and bogus.run_status == RUN_OK


def test_a_bad_scenario_field_stops_the_campaign_with_one_error(tmp_path: Path) -> None:
    from sensing_antenna.campaign.runner import run_campaign

    spec = one_point_spec(scenario={"noise_scale": -1.0}, source="bad.toml")
    with pytest.raises(CampaignSpecError, match=r"bad\.toml: scenario\.noise_scale"):
        run_campaign(spec, tmp_path, workers=1, progress=False)
    spec = one_point_spec(scenario={"colour": "red"}, source="bad.toml")
    with pytest.raises(CampaignSpecError, match=r"scenario\.colour: not a Scenario field"):
        run_campaign(spec, tmp_path / "b", workers=1, progress=False)


def test_a_spec_push_is_the_head_rotation_or_the_criterion_fields(tmp_path: Path) -> None:
    from sensing_antenna.campaign.runner import run_campaign
    from sensing_antenna.campaign.simulated import make_scenario
    from sensing_antenna.detection.push import PushCriterion

    # a number: the head's rotation past the first touch (rad), as antenna simulate --push
    scenario = make_scenario("azimuthal", 0.5, 0, {"push": 0.1})
    assert scenario.push == PushCriterion(kind="rotation", threshold=0.1)
    table = {"kind": "force", "threshold": 0.5}
    assert make_scenario("azimuthal", 0.5, 0, {"push": table}).push == PushCriterion(**table)
    for bad, problem in [
        ("deep", r"push: must be the head's rotation past the first touch"),
        (-1.0, r"push: must be a finite number > 0"),
        ({"kind": "speed"}, r"push\.kind: must be one of"),
        ({"cutoff": 0.0}, r"push\.cutoff: must be a finite number > 0"),
        ({"treshold": 0.1}, r"push\.treshold: not a push criterion field; known: cutoff, kind"),
    ]:
        spec = one_point_spec(scenario={"push": bad}, source="bad.toml")
        with pytest.raises(CampaignSpecError, match=rf"bad\.toml: scenario\.{problem}"):
            run_campaign(spec, tmp_path / str(bad), workers=1, progress=False)


def test_every_run_scenario_is_checked_before_anything_is_written(tmp_path: Path) -> None:
    from sensing_antenna.campaign.runner import run_campaign

    # The preparation is the caller's (it checks nothing); the runs use the simulator, whose
    # Scenario refuses a damping ratio of 1.5: one error, no directory, no run stored as failed.
    spec = one_point_spec(scenario={"damping_ratio": 1.5}, source="bad.toml")
    out = tmp_path / "out"
    with pytest.raises(CampaignSpecError, match=r"bad\.toml: scenario\.damping_ratio: must be < 1"):
        run_campaign(
            spec, out, prepare_antenna=lambda _: paper_antenna(), workers=1, progress=False
        )
    assert not out.exists()
    # and a contact point beyond the link, which only the antenna's file can tell
    spec = one_point_spec(contact_points=(1.2,), source="bad.toml")
    with pytest.raises(CampaignSpecError, match=r"contact_points\[0\]: 1\.2 m is beyond the link"):
        run_campaign(spec, out, workers=1, progress=False)
    assert not out.exists()


def test_the_free_motion_duration_is_checked_when_the_spec_is_made() -> None:
    # a free motion of 0.005 s is below the simulator's shortest recording (0.01 s): refused
    # with the spec, before any campaign could write anything
    with pytest.raises(CampaignSpecError, match=r"free_motion\.duration: must be > 0\.01 s"):
        FreeMotionStep(identify=True, duration=0.005)


def test_free_motion_step_identifies_the_observer_once_and_stores_it(tmp_path: Path) -> None:
    from sensing_antenna.campaign.simulated import prepare_antenna
    from sensing_antenna.campaign.store import read_stored_antenna

    spec = one_point_spec(free_motion=FreeMotionStep(identify=True, duration=3.0))
    antenna = prepare_antenna(spec)
    # identified on the simulator, so not the paper's Eq. 15 values copied over
    assert antenna.observer != paper_antenna().observer
    assert antenna.link == paper_antenna().link
    again = prepare_antenna(spec)
    assert again.observer == antenna.observer  # deterministic: seeded from the base seed
    from sensing_antenna.campaign.runner import run_campaign

    run_campaign(spec, tmp_path, workers=1, progress=False)
    stored = read_stored_antenna(tmp_path)
    assert stored is not None and stored.observer == antenna.observer


def test_a_campaign_says_what_it_does_from_its_first_moment(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from sensing_antenna.campaign.runner import run_campaign
    from sensing_antenna.campaign.schema import CalibrationStep

    spec = one_point_spec(
        free_motion=FreeMotionStep(identify=True, duration=2.0),
        calibration=CalibrationStep(enabled=True, contact_points=(0.4, 0.7)),
        methods=("ratio",),
    )
    run_campaign(spec, tmp_path, workers=1, progress=True)
    err = capsys.readouterr().err
    lines = [line for chunk in err.split("\n") for line in chunk.split("\r") if line.strip()]
    # a line before any work, one per preparation step, the calibration's bar, then the runs'
    expected = [
        f"campaign one: 1 runs (1 main) x 1 method(s) (ratio), in {tmp_path}",
        "preparation: identifying the free-motion observer (Eq. 15) on 1 free sweep of 2 s",
        "preparation: calibrating T_e on 2 contact recordings of the device (Section 5.1)",
        "calibration: 100%",
        "runs: 0 of 1 stored already, 1 to run in this process",
        "campaign one: 100%",
    ]
    positions = [next(i for i, line in enumerate(lines) if line.startswith(e)) for e in expected]
    assert positions == sorted(positions) and positions[0] == 0
    run_campaign(spec, tmp_path, workers=1, progress=True)
    again = capsys.readouterr().err
    assert f"preparation: the one stored in {tmp_path}" in again
    assert "runs: 1 of 1 stored already, 0 to run (nothing to do)" in again
