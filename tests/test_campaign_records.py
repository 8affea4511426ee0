"""The campaign row: from an estimate to the run file to runs.csv and back, as the same rows.

Reference values: the runs.csv columns are those users' scripts read (docs/campaigns.md); the
format-1 run file below is one written by the campaign code of the first layout (run
``vertical-x0500mm-r2`` of the default campaign with four methods, shortened to two).
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from sensing_antenna.antenna import paper_antenna
from sensing_antenna.campaign import (
    CSV_COLUMNS,
    CampaignRow,
    RunResult,
    RunSpec,
    load_run_results,
    read_runs_csv,
)
from sensing_antenna.campaign.records import float_or_nan
from sensing_antenna.campaign.store import CampaignStoreError, write_run_result, write_runs_csv
from sensing_antenna.estimation import ContactEstimate

#: The columns of runs.csv, in order (docs/campaigns.md), then the front end's time.
DOCUMENTED_COLUMNS = (
    "run_id, index, case, x_c_true_m, repeat, seed, run_status, method, status, reason, "
    "x_c_estimate_m, error_m, abs_error_m, omega1_rad_s, peak_quality, ratio_estimate_m, "
    "candidates_m, t_c_s, t_1_s, t_e_s, interval_low_m, interval_high_m, simulate_s, "
    "estimate_s, noise_scale, x_c_contact_m, error_contact_m, abs_error_contact_m, "
    "omega1_se_rad_s, omega1_crb_rad_s, front_end_s, point_error_m, bound_delay_s"
).split(", ")

RUN = RunSpec(3, "vertical-x0500mm-r2", "vertical", 0.5, 2, 1327166134, paper_antenna(), ())
METHODS = ("paper", "fast")


def estimates() -> list[ContactEstimate]:
    """A paper estimate with candidates at full precision; a fast one with an interval and the
    frequency's standard error and bound; both times in s, lengths in m."""
    paper = ContactEstimate(
        status="ok",
        reason=None,
        method="paper",
        x_c=0.49903272478425376,
        candidates=(0.49903272478425376, 0.8812345678901234),
        omega1=49.688356762803956,
        peak_quality=94290.36215441866,
        ratio_estimate=0.4954127973003703,
        t_c=0.744,
        t_1=0.846,
        t_e=1.846,
    )
    fast = ContactEstimate(
        status="uncertain",
        reason="the interval stayed wide",
        method="fast",
        x_c=0.5,
        omega1=49.84747938644254,
        t_1=0.846,
        t_e=1.162,
        interval=(0.498375, 0.5018750000000001),
        diagnostics={"omega1_se": 0.12101681329110635, "omega1_crb": 0.11},
    )
    return [paper, fast]


def result() -> RunResult:
    timing = {"simulate_s": 0.089, "front_end_s": 0.01}
    bounds = {"paper": math.nan, "fast": 0.28700000000000003}
    rows = tuple(
        CampaignRow.of_estimate(
            RUN,
            e,
            contact_abscissa=0.49905517596364546,
            estimate_s=0.02,
            bound_delay_s=bounds[e.method],
            **timing,
        )
        for e in estimates()
    )
    return RunResult(rows=rows)


def test_the_csv_columns_are_the_row_fields_in_the_documented_order() -> None:
    assert list(CSV_COLUMNS) == DOCUMENTED_COLUMNS


def test_a_row_scores_the_touched_point_where_the_contact_was_at_its_instant() -> None:
    """The truth is the contact's track at the estimate's t_point, not where it ended."""
    from sensing_antenna.campaign.simulated import point_error
    from sensing_antenna.recording import CONTACT_POINT_COLUMNS, IN_CONTACT_COLUMN, Recording

    t = np.arange(0.0, 1.0, 0.001)
    track = np.zeros((t.size, 3))
    touching = t >= 0.1
    # the contact slides 1 cm along y from t = 0.1 s to the end
    track[touching] = [0.3, 0.4, 0.1]
    track[touching, 1] += 0.01 * (t[touching] - 0.1) / 0.9
    zeros = np.zeros((t.size, 3))
    extra = {name: track[:, k] for k, name in enumerate(CONTACT_POINT_COLUMNS)}
    recording = Recording(
        t, zeros[:, :2], zeros, zeros, {}, {**extra, IN_CONTACT_COLUMN: touching * 1.0}
    )
    # without the contact frame the point is the axis point itself; the track at 0.55 s is at
    # (0.3, 0.405, 0.1): 3 mm along y and 4 mm along z from the estimate, 5 mm
    paper = dataclasses.replace(
        estimates()[0],
        contact_point=np.array([0.3, 0.408, 0.104]),
        diagnostics={"t_point": 0.55},
    )
    assert point_error(paper, recording, paper_antenna()) == pytest.approx(0.005, abs=2e-5)
    # an instant before the touch reads the first sample in contact, at (0.3, 0.4, 0.1)
    early = dataclasses.replace(paper, diagnostics={"t_point": 0.0})
    expected = math.hypot(0.008, 0.004)
    assert point_error(early, recording, paper_antenna()) == pytest.approx(expected, rel=1e-9)
    # unknown without an instant or a track
    assert math.isnan(point_error(estimates()[0], recording, paper_antenna()))
    assert math.isnan(point_error(paper, dataclasses.replace(recording, extra={}), paper_antenna()))
    row = CampaignRow.of_estimate(RUN, paper, point_error_m=0.005)
    assert CampaignRow.from_csv(row.to_csv()).point_error_m == 0.005
    assert math.isnan(CampaignRow.of_estimate(RUN, paper).point_error_m)  # truth unknown


def test_a_row_copies_the_estimate_and_computes_the_errors() -> None:
    paper, fast = result().rows
    assert (paper.method, paper.status, paper.reason) == ("paper", "ok", "")
    assert paper.candidates_m == (0.49903272478425376, 0.8812345678901234)
    assert paper.error_m == 0.49903272478425376 - 0.5
    assert paper.abs_error_m == abs(paper.error_m)
    assert paper.error_contact_m == 0.49903272478425376 - 0.49905517596364546
    assert paper.delay_s == pytest.approx(1.0, abs=1e-12)
    assert (fast.status, fast.reason) == ("uncertain", "the interval stayed wide")
    assert (fast.interval_low_m, fast.interval_high_m) == (0.498375, 0.5018750000000001)
    assert (fast.omega1_se_rad_s, fast.omega1_crb_rad_s) == (0.12101681329110635, 0.11)
    assert math.isnan(fast.peak_quality) and math.isnan(paper.interval_low_m)
    assert paper.noise_scale == 1.0  # the run's level (no noise_scale in its scenario)
    # the information bound of the fast method's delay; a run file without it reads NaN
    assert fast.bound_delay_s == 0.28700000000000003 and math.isnan(paper.bound_delay_s)
    older = {k: v for k, v in fast.to_dict().items() if k != "bound_delay_s"}
    assert math.isnan(CampaignRow.from_dict(older).bound_delay_s)


def test_rows_read_back_from_the_run_file_are_the_same_rows(tmp_path: Path) -> None:
    stored = result()
    write_run_result(tmp_path, stored)
    assert load_run_results(tmp_path, METHODS) == {RUN.run_id: stored}


def test_rows_read_back_from_runs_csv_are_the_same_rows(tmp_path: Path) -> None:
    stored = result()
    path = write_runs_csv(tmp_path / "runs.csv", [stored])
    assert path.read_text("utf-8").splitlines()[0] == ",".join(DOCUMENTED_COLUMNS)
    paper, fast = read_runs_csv(path)
    assert fast == stored.rows[1]
    # runs.csv holds the candidates to 6 significant digits; everything else exactly
    assert paper.candidates_m == (0.499033, 0.881235)
    assert paper == dataclasses.replace(stored.rows[0], candidates_m=(0.499033, 0.881235))


def test_a_failed_run_has_one_row_per_method_with_its_error() -> None:
    failed = RunResult.failed(
        RunSpec(0, "r", "azimuthal", 0.3, 1, 5, paper_antenna(), METHODS),
        "RuntimeError: diverged",
        "Traceback ...",
    )
    assert failed.methods == METHODS
    assert failed.status == "failed" and failed.error == "RuntimeError: diverged"
    assert {(r.status, r.reason) for r in failed.rows} == {("run-failed", "RuntimeError: diverged")}
    assert all(math.isnan(r.x_c_estimate_m) for r in failed.rows)


def test_rows_of_different_runs_are_not_one_run() -> None:
    paper, fast = result().rows
    other = CampaignRow.of_estimate(RUN, estimates()[1], simulate_s=1.0)
    with pytest.raises(ValueError, match="simulate_s"):
        RunResult(rows=(paper, other))
    with pytest.raises(ValueError, match="at least one row"):
        RunResult(rows=())
    assert RunResult(rows=(paper, fast)).methods == METHODS


#: Run ``vertical-x0500mm-r2`` as the first layout stored it (two of its four methods).
FORMAT_1 = {
    "run_id": "vertical-x0500mm-r2",
    "index": 96,
    "case": "vertical",
    "contact_point": 0.5,
    "repeat": 2,
    "seed": 1327166134,
    "status": "ok",
    "error": "",
    "detail": "",
    "simulate_s": 0.08895051999999737,
    "methods": [
        {
            "method": "paper",
            "status": "ok",
            "reason": "",
            "x_c": 0.49903272478425376,
            "omega1": 49.688356762803956,
            "peak_quality": 94290.36215441866,
            "ratio_estimate": 0.4954127973003703,
            "t_c": 0.744,
            "t_1": 0.846,
            "t_e": 1.846,
            "candidates": [0.49903272478425376],
            "elapsed_s": 0.010805778000005262,
            "interval": [None, None],
            "omega1_se": None,
            "omega1_crb": None,
        },
        {
            "method": "fast",
            "status": "ok",
            "reason": "",
            "x_c": 0.5,
            "omega1": 49.84747938644254,
            "peak_quality": None,
            "ratio_estimate": 0.5063508329701853,
            "t_c": 0.744,
            "t_1": 0.846,
            "t_e": 1.162,
            "candidates": [0.5000864946735706],
            "elapsed_s": 0.2469240639999981,
            "interval": [0.498375, 0.5018750000000001],
            "omega1_se": 0.12101681329110635,
            "omega1_crb": 0.12101681329110635,
        },
    ],
    "contact_abscissa": 0.49905517596364546,
    "noise_scale": 1.0,
}


def test_a_run_file_of_the_first_layout_reads_as_rows(tmp_path: Path) -> None:
    runs = tmp_path / "runs"
    runs.mkdir()
    (runs / "vertical-x0500mm-r2.json").write_text(json.dumps(FORMAT_1), encoding="utf-8")
    (loaded,) = load_run_results(tmp_path, ("paper", "fast", "ratio")).values()
    paper, fast, ratio = loaded.rows
    assert (paper.index, paper.seed, paper.x_c_true_m) == (96, 1327166134, 0.5)
    assert (paper.x_c_estimate_m, paper.estimate_s) == (0.49903272478425376, 0.010805778000005262)
    assert paper.x_c_contact_m == 0.49905517596364546 and paper.noise_scale == 1.0
    assert (fast.interval_low_m, fast.interval_high_m) == (0.498375, 0.5018750000000001)
    assert fast.candidates_m == (0.5000864946735706,) and math.isnan(fast.peak_quality)
    assert math.isnan(fast.front_end_s)  # the first layout did not time the front end alone
    # a method the spec has but the run did not store
    assert (ratio.status, ratio.reason) == ("run-failed", "method not run")
    # the same rows once written in the current layout
    write_run_result(tmp_path, loaded)
    assert load_run_results(tmp_path, ("paper", "fast", "ratio"))[loaded.run_id] == loaded


def test_a_failed_run_of_the_first_layout_and_one_without_the_later_fields(
    tmp_path: Path,
) -> None:
    old = {k: v for k, v in FORMAT_1.items() if k not in ("contact_abscissa", "noise_scale")}
    failed = {**old, "status": "failed", "error": "RuntimeError: diverged", "methods": []}
    (loaded,) = RunResult.from_dict(failed, METHODS).rows[:1]
    assert (loaded.run_status, loaded.status, loaded.reason) == (
        "failed",
        "run-failed",
        "RuntimeError: diverged",
    )
    ok = RunResult.from_dict(old, METHODS)
    assert all(math.isnan(r.x_c_contact_m) and math.isnan(r.noise_scale) for r in ok.rows)


def test_a_format_2_run_file_reads_with_its_point_error_unknown(tmp_path: Path) -> None:
    # format 2 measured the 3D point against the end of the record, not the contact at the
    # estimate's instant: a campaign resumed across versions must not average the two
    stored = result()
    rows = [dataclasses.replace(row, point_error_m=0.002) for row in stored.rows]
    write_run_result(tmp_path, dataclasses.replace(stored, rows=tuple(rows)))
    path = tmp_path / "runs" / f"{RUN.run_id}.json"
    data = json.loads(path.read_text("utf-8"))
    assert load_run_results(tmp_path, METHODS)[RUN.run_id].rows[0].point_error_m == 0.002
    path.write_text(json.dumps({**data, "format": 2}), encoding="utf-8")
    (loaded,) = load_run_results(tmp_path, METHODS).values()
    assert all(math.isnan(row.point_error_m) for row in loaded.rows)
    assert [row.x_c_estimate_m for row in loaded.rows] == [row.x_c_estimate_m for row in rows]


def test_a_run_file_of_an_unknown_format_is_one_clear_error(tmp_path: Path) -> None:
    write_run_result(tmp_path, result())
    path = tmp_path / "runs" / f"{RUN.run_id}.json"
    data = json.loads(path.read_text("utf-8"))
    path.write_text(json.dumps({**data, "format": 9}), encoding="utf-8")
    with pytest.raises(CampaignStoreError, match=r"\.json: format: 9 is not one this version"):
        load_run_results(tmp_path, METHODS)


@pytest.mark.parametrize(
    ("stored", "expected"), [(0.5, 0.5), ("0.5", 0.5), ("-1e-3", -1e-3), (3, 3.0)]
)
def test_a_stored_number_reads_as_that_float(stored: object, expected: float) -> None:
    assert float_or_nan(stored) == expected


@pytest.mark.parametrize("stored", [None, "", "nan", "NaN", "inf", "n/a", [0.5], {}])
def test_a_stored_gap_or_text_reads_as_nan(stored: object) -> None:
    # JSON null, an empty CSV cell, written NaN or infinity and anything else not a number
    assert math.isnan(float_or_nan(stored))
