"""The ``antenna campaign`` and ``antenna calibrate`` commands: reports and one-line errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sensing_antenna.antenna import Antenna, paper_antenna
from sensing_antenna.campaign.records import CampaignRow, RunResult
from sensing_antenna.campaign.runner import run_campaign
from sensing_antenna.campaign.runs import RunSpec
from sensing_antenna.campaign.schema import CampaignSpec
from sensing_antenna.cli import main
from sensing_antenna.estimation import ContactEstimate
from sensing_antenna.recording import Recording, write_recording


def toy_run(run: RunSpec) -> RunResult:
    rng = np.random.default_rng(run.seed)
    rows = tuple(
        CampaignRow.of_estimate(
            run,
            ContactEstimate(
                status="ok",
                reason=None,
                method=m,
                x_c=run.contact_point + float(rng.normal(0, 0.02)),
            ),
        )
        for m in run.methods
    )
    return RunResult(rows=rows)


def plain(spec: CampaignSpec) -> Antenna:
    return paper_antenna()


def test_campaign_report_rebuilds_from_stored_runs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = CampaignSpec(
        name="baselines-only",
        antenna="paper-2021",
        cases=("azimuthal",),
        contact_points=(0.4, 0.7),
        repeats=2,
        base_seed=5,
        methods=("ratio", "two-frequency"),
    )
    run_campaign(spec, tmp_path, run_one=toy_run, prepare_antenna=plain, workers=1, progress=False)
    assert main(["campaign", "report", str(tmp_path)]) == 0
    printed = capsys.readouterr().out.strip().splitlines()
    assert printed[-1] == str(tmp_path / "report.md")
    text = (tmp_path / "report.md").read_text("utf-8")
    assert "](figures/errors-by-method.png)" in text
    assert (tmp_path / "figures" / "errors-by-method.png").is_file()
    assert (tmp_path / "runs.csv").is_file()


def test_campaign_run_reports_a_bad_spec_on_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec = tmp_path / "bad.toml"
    spec.write_text(
        'name = "x"\ncases = ["azimuthal"]\ncontact_points = [0.5]\nrepeats = 0\nbase_seed = 1\n',
        encoding="utf-8",
    )
    assert main(["campaign", "run", str(spec), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"antenna campaign run: error: {spec}: repeats: must be >= 1, got 0"


def test_campaign_report_on_a_non_campaign_directory_fails_cleanly(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["campaign", "report", str(tmp_path)]) == 2
    assert "campaign.json: no such file" in capsys.readouterr().err


def test_calibrate_without_known_contact_points_fails_cleanly(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    n = 50
    recording = Recording(
        t=np.arange(n) * 1e-3,
        theta=np.zeros((n, 2)),
        force=np.zeros((n, 3)),
        torque=np.zeros((n, 3)),
    )
    path = tmp_path / "r1.csv"
    write_recording(recording, path)
    code = main(["calibrate", str(path), "--out", str(tmp_path / "cal.toml")])
    assert code == 2
    err = capsys.readouterr().err
    # no --points and no true_xc: the table is what is missing, said first
    assert "--points: none given, and no recording states its contact point" in err
    assert not (tmp_path / "cal.toml").exists()


def test_methods_option_replaces_the_spec_methods_and_names_bad_ones(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:

    assert main(["campaign", "run", "--methods", "paper,bogus", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    # the flag is named, not the spec file the value did not come from
    assert err.startswith("antenna campaign run: error: --methods: unknown 'bogus'"), err


def test_campaign_run_exits_non_zero_while_runs_are_left_failed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    spec_file = tmp_path / "one.toml"
    spec_file.write_text(
        'name = "one"\nantenna = "paper-2021"\ncases = ["azimuthal"]\ncontact_points = [0.4, 0.7]\n'
        'repeats = 1\nbase_seed = 5\nmethods = ["ratio"]\n',
        encoding="utf-8",
    )
    from sensing_antenna.campaign.parsing import load_campaign_spec

    def fails_at_04(run: RunSpec) -> RunResult:
        if run.contact_point == 0.4:
            raise RuntimeError("diverged")
        return toy_run(run)

    out = tmp_path / "out"
    run_campaign(
        load_campaign_spec(spec_file),
        out,
        run_one=fails_at_04,
        prepare_antenna=plain,
        workers=1,
        progress=False,
    )
    # a plain resume leaves the failed run as it is: the command must not say all is well
    assert main(["campaign", "run", str(spec_file), "--out", str(out), "--no-progress"]) == 1
    captured = capsys.readouterr()
    assert captured.out.splitlines()[0] == "2 runs: 2 already done, 0 run now, 1 failed"
    assert captured.err.splitlines() == [
        "antenna campaign run: 1 run(s) failed (listed in the report); "
        "--retry-failed runs them again"
    ]
