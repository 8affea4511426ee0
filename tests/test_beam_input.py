"""Absurd input to the beam model, through the library and ``antenna beam``: one line each."""

from __future__ import annotations

import numpy as np
import pytest

from sensing_antenna.antenna import paper_antenna
from sensing_antenna.beam import (
    MAX_MODES,
    BeamInputError,
    SensingCurve,
    eigenvalues,
    natural_frequencies,
)
from sensing_antenna.beam.sensing import MAX_POINTS
from sensing_antenna.cli import main

LINK = paper_antenna().link


def test_mode_counts_are_bounded_in_the_library() -> None:
    # 10**9 modes would allocate gigabytes before finding the first root one by one.
    assert natural_frequencies(LINK, 0.5, MAX_MODES).shape == (MAX_MODES,)
    for bad in (MAX_MODES + 1, 10**9, 0, np.int64(0)):
        with pytest.raises(BeamInputError) as info:
            natural_frequencies(LINK, 0.5, bad)  # type: ignore[arg-type]
        assert str(info.value) == f"n_modes: must be an integer from 1 to {MAX_MODES}, got {bad}"
    with pytest.raises(BeamInputError, match=r"n_modes: .* got 2\.5"):
        eigenvalues(0.5, 2.5)  # type: ignore[arg-type]


def test_sensing_curve_tables_are_bounded() -> None:
    with pytest.raises(
        BeamInputError, match=f"n_points: must be an integer from 3 to {MAX_POINTS}"
    ):
        SensingCurve.from_link(LINK, MAX_POINTS + 1)
    curve = SensingCurve.from_link(LINK)
    with pytest.raises(BeamInputError) as info:
        curve.contact_points(np.float64("inf"))
    assert str(info.value) == "omega1: must be finite, got inf"


def _run(argv: list[str]) -> int:
    """Exit code of ``antenna beam`` with ``argv``, whether argparse or the command refuses."""
    try:
        return main(["beam", *argv])
    except SystemExit as exc:
        return int(exc.code or 0)


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["--xc", "0.5", "--modes", "100000"], "--modes: must be an integer from 1 to"),
        (["--xc", "0.5", "--modes", "0"], "--modes: must be an integer from 1 to"),
        (["--xc", "1e300"], "--xc: contact point must lie in (0, 0.98] m, got 1e+300"),
        (["--xc", "0.3", "nan"], "--xc: contact point must lie in (0, 0.98] m, got nan"),
        (["--xc", "-0.3"], "--xc: contact point must lie in (0, 0.98] m, got -0.3"),
        # a contact point in mm: the unit it fits is named
        (["--xc", "300"], "--xc: contact point must lie in (0, 0.98] m, got 300.0 (in mm?)"),
        (["--omega1", "inf"], "--omega1: must be a finite frequency > 0 rad/s, got inf"),
        (["--omega1", "-5"], "--omega1: must be a finite frequency > 0 rad/s, got -5.0"),
    ],
)
def test_absurd_arguments_give_one_line_and_exit_2(
    capsys: pytest.CaptureFixture[str], argv: list[str], words: str
) -> None:
    assert _run(argv) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("antenna beam: error: ")
    assert words in lines[0]
    assert "np." not in lines[0]


@pytest.mark.parametrize("omega1", ["1e300", "1e-300"])
def test_a_frequency_outside_the_model_is_exit_1_with_the_range(
    capsys: pytest.CaptureFixture[str], omega1: str
) -> None:
    # Documented in cli/beam.py: the empty candidate list is printed, the reason on stderr.
    assert _run(["--omega1", omega1]) == 1
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "outside the model's range" in err[0]


def test_a_contact_point_at_the_base_is_the_cantilever_limit() -> None:
    # x_c -> 0 is the documented limit (beam/characteristic.py: xi = 0 is the cantilever), so a
    # tiny x_c is not refused: its frequencies are the free cantilever's, to 1e-9 relative.
    # Reference: Blevins, clamped-free beam, (beta_1 l)^2 = 3.5160.
    omega = natural_frequencies(LINK, 1e-300, 1)[0]
    assert omega * LINK.t_param * LINK.length**2 == pytest.approx(3.51601527, rel=1e-8)
