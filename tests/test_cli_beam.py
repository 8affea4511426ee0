"""Tests of ``antenna beam`` and ``antenna plot sensing-curves`` (cli/beam.py, plotting)."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from sensing_antenna.antenna import load_antenna
from sensing_antenna.beam import natural_frequencies
from sensing_antenna.cli import main


def test_frequencies_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["beam", "--xc", "0.3", "0.5", "0.98", "--modes", "3", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["x_c"] for r in rows] == [0.3, 0.5, 0.98]
    expected = natural_frequencies(load_antenna().link, [0.3, 0.5, 0.98], 3)
    for row, omega in zip(rows, expected, strict=True):
        assert set(row) == {"x_c", "omega", "hz"}
        np.testing.assert_allclose(row["omega"], omega, rtol=1e-12)
        np.testing.assert_allclose(row["hz"], omega / (2 * np.pi), rtol=1e-12)


def test_frequencies_table(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["beam", "--xc", "0.5", "--modes", "2"]) == 0
    out = capsys.readouterr().out
    assert "rad/s" in out and "Hz" in out
    assert len([line for line in out.splitlines() if line.strip().startswith("0.5000")]) == 2


def test_contact_points_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["beam", "--omega1", "80", "--antenna", "paper-2021-calibrated", "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["omega1"] == 80.0
    assert len(payload["candidates"]) == 2
    link = load_antenna("paper-2021-calibrated").link
    for candidate in payload["candidates"]:
        assert set(candidate) == {"x_c", "slope"}
        omega = natural_frequencies(link, candidate["x_c"], 1)[0]
        assert omega == pytest.approx(80.0, rel=1e-9)


def test_the_tip_frequency_as_printed_finds_the_tip(capsys: pytest.CaptureFixture[str]) -> None:
    # omega_1 of a contact at the tip, 70.37633 rad/s, given to three decimals: a hair below it,
    # where only a contact past the end would ring; within the default tolerance it is the tip
    assert main(["beam", "--omega1", "70.376", "--json"]) == 0
    payload = json.loads(capsys.readouterr().out)
    assert [round(c["x_c"], 3) for c in payload["candidates"]] == [0.624, 0.98]
    assert payload["tolerance"] == pytest.approx(0.070376)
    assert main(["beam", "--omega1", "70.376", "--tolerance", "0", "--json"]) == 0
    assert len(json.loads(capsys.readouterr().out)["candidates"]) == 1


def test_a_frequency_just_above_the_top_finds_the_top_within_its_tolerance(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # the paper link's curve tops at 100.5763 rad/s (x_c = 0.768 m): 100.58 measured a little
    # high there is the top within 0.1 rad/s, and off the curve within 0.001, the range printed
    # to enough digits to show it. The top found independently, by a bounded search of
    # omega_1(x_c); 0.1 mm covers the flat top (omega_1 within 2e-5 rad/s of it over +-0.1 mm)
    from scipy.optimize import minimize_scalar

    link = load_antenna("paper-2021").link
    top = minimize_scalar(
        lambda x: -float(natural_frequencies(link, x, 1)[0]),
        bounds=(0.6, 0.9),
        method="bounded",
        options={"xatol": 1e-8},
    )
    assert -top.fun == pytest.approx(100.5763, abs=1e-4)
    assert main(["beam", "--omega1", "100.58", "--tolerance", "0.1", "--json"]) == 0
    (found,) = json.loads(capsys.readouterr().out)["candidates"]
    # the answer is the curve's extremum itself, where its slope is zero
    assert found["x_c"] == pytest.approx(top.x, abs=1e-4) and found["slope"] == 0.0
    assert main(["beam", "--omega1", "100.58", "--tolerance", "0.001"]) == 1
    printed = re.search(r"\(([0-9.]+), ([0-9.]+)\] rad/s", capsys.readouterr().err)
    assert printed is not None
    low, high = float(printed.group(1)), float(printed.group(2))
    # the range's low end is the limit x_c -> 0, the clamped-free cantilever's fundamental
    # (beta_1 l = 1.87510407, Euler-Bernoulli), and both ends are printed to 7 digits: enough
    # to show the top below 100.58 by more than the tolerance
    cantilever = 1.875104068711961**2 / (link.theoretical_t * link.length**2)
    assert low == pytest.approx(cantilever, rel=1e-6)
    assert high == pytest.approx(-top.fun, abs=1e-4) and high < 100.58 - 0.001
    # the tolerance is --omega1's: with --xc it is refused, not ignored
    assert main(["beam", "--xc", "0.5", "--tolerance", "1"]) == 2
    assert "--tolerance: the uncertainty of --omega1" in capsys.readouterr().err


def test_out_of_range_frequency_exits_1_with_empty_list(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["beam", "--omega1", "500", "--json"]) == 1
    captured = capsys.readouterr()
    assert json.loads(captured.out)["candidates"] == []
    assert "outside the model's range" in captured.err


@pytest.mark.parametrize(
    "argv",
    [
        ["beam", "--xc", "1.5"],
        ["beam", "--xc", "0"],
        ["beam", "--xc", "0.3", "--modes", "0"],
        ["beam", "--omega1", "abc"],
        ["beam", "--omega1", "nan"],
        ["beam", "--xc", "0.3", "--omega1", "80"],
        ["beam"],
        ["beam", "--xc", "0.3", "--antenna", "no-such-antenna.toml"],
    ],
)
def test_bad_arguments_exit_2_with_one_line(
    argv: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse errors exit from inside parse_args
        code = int(exc.code) if exc.code is not None else 0
    captured = capsys.readouterr()
    assert code == 2
    assert len(captured.err.strip().splitlines()) == 1
    assert "Traceback" not in captured.err


def test_plot_sensing_curves(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "figs"
    assert main(["plot", "sensing-curves", "--out", str(out)]) == 0
    printed = capsys.readouterr().out.split()
    paths = [Path(p) for p in printed]
    assert [p.name for p in paths] == ["figure8.png", "figure9.png"]
    for path in paths:
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_figure8_shows_the_papers_measurements_on_the_papers_link_only() -> None:
    import dataclasses

    import matplotlib.pyplot as plt

    from sensing_antenna.antenna import paper_antenna
    from sensing_antenna.plotting.sensing_curves import figure8

    def labels(antenna: Any) -> list[str]:
        fig = figure8(antenna)
        found = [text.get_text() for text in fig.axes[0].get_legend().get_texts()]
        plt.close(fig)
        return found

    paper = paper_antenna()
    assert labels(paper) == [
        "f1 (T = 0.2281 s/m$^2$)",
        "f2 (T = 0.2281 s/m$^2$)",
        "f3 (T = 0.2281 s/m$^2$)",
        "f1 with the paper's T_e = 0.2124",
        "the paper's measured f1 band",
    ]
    # the paper's link calibrated: its own T_e, named so, beside the paper's
    assert labels(paper.with_calibrated_t(0.23))[0] == "f1 (T_e = 0.2300 s/m$^2$)"
    assert labels(paper.with_calibrated_t(0.2124))[3:] == ["the paper's measured f1 band"]
    # another link: its own curves only
    other = dataclasses.replace(paper, link=dataclasses.replace(paper.link, length=0.75))
    assert [label[:3] for label in labels(other)] == ["f1 ", "f2 ", "f3 "]
