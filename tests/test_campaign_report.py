"""Campaign tables and report: statistics against hand computations, the paper's tables beside ours.

Reference values: the per-point statistics are recomputed here by hand from known estimates; the
paper's numbers are Tables 3 and 4 of Feliu-Talegon et al., Sensors 2021 (the package data copies).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest

from sensing_antenna.antenna import Antenna, paper_antenna
from sensing_antenna.campaign.records import MethodOutcome, RunResult
from sensing_antenna.campaign.report import build_report
from sensing_antenna.campaign.runner import run_campaign
from sensing_antenna.campaign.spec import CampaignSpec, RunSpec
from sensing_antenna.campaign.tables import (
    campaign_rows,
    interval_summaries,
    method_summaries,
    paper_row_at,
    paper_table,
    point_table,
)

#: Offsets (m) of the "paper" toy estimates for repeats 1, 2, 3: errors of +1, -2 and +4 mm.
PAPER_OFFSETS = (0.001, -0.002, 0.004)
#: The toy "ratio" baseline is off by 3 cm on every run.
RATIO_OFFSET = 0.03
#: Float round-off of sums of a few lengths (m).
ROUND_OFF = 1e-12


def toy_run(run: RunSpec) -> RunResult:
    """Known estimates: paper = x_c + PAPER_OFFSETS[repeat - 1]; ratio = x_c + 3 cm; x_c = 0.5 m
    gives the ratio method no estimate (status no_contact)."""
    paper = MethodOutcome(
        method="paper",
        status="ok",
        x_c=run.contact_point + PAPER_OFFSETS[run.repeat - 1],
        omega1=50.0,
    )
    if math.isclose(run.contact_point, 0.5):
        ratio = MethodOutcome(method="ratio", status="no_contact", reason="no contact found")
    else:
        ratio = MethodOutcome(method="ratio", status="ok", x_c=run.contact_point + RATIO_OFFSET)
    return RunResult.for_run(run, [paper, ratio], simulate_s=0.0)


def spec() -> CampaignSpec:
    return CampaignSpec(
        name="toy",
        antenna="paper-2021",
        cases=("azimuthal", "vertical"),
        contact_points=(0.3, 0.5),
        repeats=3,
        base_seed=1,
        methods=("paper", "ratio"),
    )


def plain(spec: CampaignSpec) -> Antenna:
    return paper_antenna()


@pytest.fixture
def campaign_dir(tmp_path: Path) -> Path:
    run_campaign(
        spec(), tmp_path, run_one=toy_run, prepare_antenna=plain, workers=1, progress=False
    )
    return tmp_path


def test_point_table_matches_hand_computation(campaign_dir: Path) -> None:
    from sensing_antenna.campaign.store import load_run_results

    rows = campaign_rows(load_run_results(campaign_dir).values(), ("paper", "ratio"))
    table = point_table(rows, "azimuthal", "paper")
    assert [p.x_c for p in table] == [0.3, 0.5]
    errors = np.array(PAPER_OFFSETS)
    first = table[0]
    assert (first.n_runs, first.n_estimates) == (3, 3)
    assert first.mean_estimate == pytest.approx(0.3 + errors.mean(), abs=ROUND_OFF)
    assert first.mean_abs_error == pytest.approx(np.abs(errors).mean(), abs=ROUND_OFF)
    assert first.max_error == pytest.approx(0.004, abs=ROUND_OFF)
    assert first.std_error == pytest.approx(np.std(errors, ddof=1), abs=ROUND_OFF)
    ratio_at_05 = point_table(rows, "vertical", "ratio")[1]
    assert (ratio_at_05.n_runs, ratio_at_05.n_estimates) == (3, 0)
    assert math.isnan(ratio_at_05.mean_abs_error)


def test_method_summary_counts_statuses_and_errors(campaign_dir: Path) -> None:
    from sensing_antenna.campaign.store import load_run_results

    rows = campaign_rows(load_run_results(campaign_dir).values(), ("paper", "ratio"))
    summaries = method_summaries(rows, ("azimuthal",), ("paper", "ratio"))
    paper, ratio = summaries
    assert paper.status_counts == {"ok": 6}
    assert paper.max_abs_error == pytest.approx(0.004, abs=ROUND_OFF)
    assert ratio.status_counts == {"ok": 3, "no_contact": 3}
    assert ratio.n_estimates == 3
    assert ratio.mean_abs_error == pytest.approx(RATIO_OFFSET, abs=ROUND_OFF)


def test_paper_tables_are_tables_3_and_4() -> None:
    # Table 3, x_c = 75 cm: 76.2, 1.5, 3.9, 1.5 cm; Table 4, x_c = 80 cm: max error 6.6 cm
    row = paper_row_at("azimuthal", 0.75)
    assert row is not None
    assert (row.mean_estimate, row.mean_abs_error, row.max_error, row.std_error) == pytest.approx(
        (0.762, 0.015, 0.039, 0.015), abs=ROUND_OFF
    )
    vertical = paper_row_at("vertical", 0.80)
    assert vertical is not None and vertical.max_error == pytest.approx(0.066, abs=ROUND_OFF)
    assert len(paper_table("azimuthal")) == len(paper_table("vertical")) == 15
    assert paper_table("free") == []


def test_report_puts_the_paper_numbers_beside_ours(campaign_dir: Path) -> None:
    report = build_report(campaign_dir, figures=False)
    text = report.read_text("utf-8")
    assert report.name == "report.md"
    assert "## Methods compared on the same recordings" in text
    assert "Case 1: azimuthal movement (Table 3 of the paper)" in text
    # x_c = 30 cm, azimuthal: ours 30.10, 0.23, 0.40, 0.30 cm; paper 30.5, 0.5, 0.7, 0.20 cm;
    # the ratio baseline's mean abs error 3.00 cm
    assert "| 30 | 30.10 | 0.23 | 0.40 | 0.30 | 30.5 | 0.5 | 0.7 | 0.20 | 3.00 | 3/3 |" in text
    assert "| 50 | 50.10 | 0.23 | 0.40 | 0.30 | 50.1 | 0.3 | 0.6 | 0.20 | - | 3/3 |" in text
    assert "no_contact" in text
    assert "Runs stored: 12 of 12; failed: 0" in text


def test_report_figures_are_written_and_linked(campaign_dir: Path) -> None:
    report = build_report(campaign_dir)
    text = report.read_text("utf-8")
    figures = sorted((campaign_dir / "figures").glob("*.png"))
    names = {p.name for p in figures}
    assert {
        "errors-by-method.png",
        "figure16-azimuthal-paper.png",
        "figure17-vertical-paper.png",
        "figure18-frequencies.png",
    } <= names
    for name in names:
        assert f"](figures/{name})" in text
        assert (campaign_dir / "figures" / name).stat().st_size > 1000


class _FakeEstimate:
    """Stands in for a ContactEstimate of a method with extra diagnostics (like ``fast``)."""

    status = "ok"
    reason = None
    x_c = 0.52
    candidates = (0.52,)
    omega1 = 60.0
    t_1 = 1.0
    t_e = 1.2
    interval: tuple[float, float] | None = None
    diagnostics: ClassVar[dict[str, object]] = {
        "interval": (0.51, 0.53),
        "interval_width": 0.02,
        "model_order": 3,
    }


def test_an_interval_in_the_diagnostics_is_kept_and_summarised() -> None:
    outcome = MethodOutcome.from_estimate("fast", _FakeEstimate(), 0.01)
    assert (outcome.interval_low, outcome.interval_high) == (0.51, 0.53)
    # the result's own ``interval`` attribute wins over the diagnostics
    direct = _FakeEstimate()
    direct.interval = (0.50, 0.54)
    assert MethodOutcome.from_estimate("fast", direct, 0.0).interval_low == 0.50
    assert MethodOutcome.from_dict(outcome.to_dict()) == outcome
    # a method without an interval keeps NaN and round-trips too
    plain_outcome = MethodOutcome(method="paper", status="ok", x_c=0.5)
    again = MethodOutcome.from_dict(plain_outcome.to_dict())
    assert math.isnan(again.interval_low) and math.isnan(again.interval_high)
    runs = [
        RunSpec(i, f"azimuthal-x0{x * 1000:.0f}mm-r1", "azimuthal", x, 1, i, paper_antenna(), ())
        for i, x in enumerate((0.5, 0.52, 0.6))
    ]
    results = [RunResult.for_run(run, [outcome], 0.0) for run in runs]
    rows = campaign_rows(results, ["fast"])
    assert {"interval_low_m", "interval_high_m"} <= set(rows[0])
    (summary,) = interval_summaries(rows, ["azimuthal"], ["fast"])
    # the interval [0.51, 0.53] m contains 0.52 only, of 0.5, 0.52 and 0.6
    assert (summary.n_intervals, summary.n_covering) == (3, 1)
    assert summary.median_width == pytest.approx(0.02, abs=ROUND_OFF)
    assert summary.median_time_to_estimate == pytest.approx(0.2, abs=ROUND_OFF)


def test_report_renders_a_method_with_intervals(tmp_path: Path) -> None:
    # the toy "ratio" method here reports the fake estimate's interval and times, as ``fast``
    # does (its name does not matter to the report, which only reads the stored fields)
    def with_interval(run: RunSpec) -> RunResult:
        paper = toy_run(run).methods[0]
        extra = MethodOutcome.from_estimate("ratio", _FakeEstimate(), 0.01)
        return RunResult.for_run(run, [paper, extra], simulate_s=0.0)

    run_campaign(
        spec(), tmp_path, run_one=with_interval, prepare_antenna=plain, workers=1, progress=False
    )
    text = build_report(tmp_path).read_text("utf-8")
    assert "## Time to estimate and uncertainty" in text
    # [0.51, 0.53] m contains none of the true points 0.3 and 0.5 m; 6 runs per case
    assert "| azimuthal | ratio | 0.200 | 0/6 (0 %) | 2.00 |" in text
    assert "| azimuthal | paper | - | - | - |" in text
    header = (tmp_path / "runs.csv").read_text("utf-8").splitlines()[0].split(",")
    assert "interval_low_m" in header and "interval_high_m" in header


def test_report_with_fast_has_the_error_and_delay_figure(
    tmp_path: Path, campaign_dir: Path
) -> None:
    # Issue 6: with ``fast`` among the methods the report gets x_c error and t_e - t_1 against
    # x_c for all methods; without it (the paper/ratio toy campaign) the figure is not drawn.
    def with_fast(run: RunSpec) -> RunResult:
        paper = toy_run(run).methods[0]
        fast = MethodOutcome.from_estimate("fast", _FakeEstimate(), 0.01)
        return RunResult.for_run(run, [paper, fast], simulate_s=0.0)

    fast_spec = CampaignSpec(
        name="toy-fast",
        antenna="paper-2021",
        cases=("azimuthal", "vertical"),
        contact_points=(0.3, 0.5),
        repeats=1,
        base_seed=1,
        methods=("paper", "fast"),
    )
    out = tmp_path / "with-fast"
    run_campaign(
        fast_spec, out, run_one=with_fast, prepare_antenna=plain, workers=1, progress=False
    )
    text = build_report(out).read_text("utf-8")
    figure = out / "figures" / "error-and-delay-by-method.png"
    assert figure.stat().st_size > 1000
    assert "](figures/error-and-delay-by-method.png)" in text
    build_report(campaign_dir)
    assert not (campaign_dir / "figures" / "error-and-delay-by-method.png").exists()
