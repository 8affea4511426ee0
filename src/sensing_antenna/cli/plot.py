"""``antenna plot KIND ...``: every figure. Each kind is registered by a small function here."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from sensing_antenna.cli.arguments import add_actions
from sensing_antenna.cli.estimate import (
    DEFAULT_ANTENNA,
    warn_of_contradicted_period,
    warn_of_other_antennas,
)


def register(subparsers: Any) -> None:
    """Add ``antenna plot`` and its kinds."""
    parser = subparsers.add_parser(
        "plot",
        help="draw figures as PNG files",
        description=(
            "Draws figures as PNG files into the --out directory and prints their paths: the "
            "sensing curves of an antenna, the signals of a recording, or Figures 11 to 14 of "
            "the paper for the estimate of one recording. Campaign figures come with antenna "
            "campaign report."
        ),
    )
    kinds = add_actions(parser, "kind", "KIND")
    for add_kind in (_add_sensing_curves, _add_recording, _add_estimate):
        add_kind(kinds)


def _add_out(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, required=True, help="output directory")


def _add_sensing_curves(kinds: Any) -> None:
    parser = kinds.add_parser(
        "sensing-curves",
        help="Figures 8 and 9: f_i(x_c), f2 - f1 vs f1",
        description=(
            "The sensing curves of an antenna: Figure 8, the natural frequencies f1, f2, f3 (Hz) "
            "of the link against the contact point; Figure 9, f2 - f1 against f1."
        ),
    )
    parser.add_argument("--antenna", default=DEFAULT_ANTENNA, help="built-in name or TOML file")
    _add_out(parser)
    parser.set_defaults(func=_run_sensing_curves)


def _run_sensing_curves(args: argparse.Namespace) -> int:
    from sensing_antenna.antenna import load_antenna
    from sensing_antenna.plotting.sensing_curves import plot_sensing_curves

    for path in plot_sensing_curves(load_antenna(args.antenna), args.out):
        print(path)
    return 0


def _add_recording(kinds: Any) -> None:
    parser = kinds.add_parser(
        "recording",
        help="angles, forces and torques of a recording",
        description=(
            "The motor angles, the forces and the torques of a recording against time, and the "
            "spectrum of the torques; a line on stderr when its angles or its loads at rest "
            "are not in the format's units (judged against --antenna's link)."
        ),
    )
    parser.add_argument("recording", type=Path, help="recording in the sensing-antenna format")
    parser.add_argument(
        "--antenna",
        default=None,
        help=f"built-in name or TOML file, its link's weight (default {DEFAULT_ANTENNA})",
    )
    _add_out(parser)
    parser.set_defaults(func=_run_recording)


def _run_recording(args: argparse.Namespace) -> int:
    from sensing_antenna.calibration.observer import units_problem
    from sensing_antenna.plotting.recording import plot_recording
    from sensing_antenna.recording import read_recording
    from sensing_antenna.torque_point import MOVED_KEY

    recording = read_recording(args.recording)
    antenna = _model(args, recording, "checked")  # a bad file said before any figure
    for path in plot_recording(recording, args.out):
        print(path)
    moved = recording.metadata.get(MOVED_KEY)
    if moved is not None:
        print(
            f"antenna plot recording: {args.recording}: torques drawn about O, moved from the "
            f"sensor's point {moved} m ({MOVED_KEY}), as the estimators read them",
            file=sys.stderr,
        )
    problem = units_problem(recording, antenna)
    if problem is not None:
        print(
            f"antenna plot recording: warning: {args.recording}: {problem}; drawn as recorded",
            file=sys.stderr,
        )
    return 0


def _model(args: argparse.Namespace, recording: Any, use: str) -> Any:
    """The antenna of ``--antenna``, or the default one with a warning when the recording's
    ``antenna`` metadata names another (as ``antenna estimate`` does; ``use`` as there)."""
    from sensing_antenna.antenna import load_antenna

    warn_of_contradicted_period(args.recording, recording.period_problem)
    if args.antenna is not None:
        return load_antenna(args.antenna)
    antenna = load_antenna(DEFAULT_ANTENNA)
    warn_of_other_antennas(
        {recording.metadata.get("antenna", ""): [str(args.recording)]}, antenna.name, use
    )
    return antenna


def _add_estimate(kinds: Any) -> None:
    parser = kinds.add_parser(
        "estimate",
        help="Figures 11 to 14 for one recording",
        description=(
            "Figures 11 to 14 of the paper for the estimate of one recording (the paper's "
            "method): the contact detection, the push, the frequency spectrum and the "
            "torque/force ratio."
        ),
    )
    parser.add_argument("recording", type=Path, help="recording in the sensing-antenna format")
    parser.add_argument(
        "--antenna", default=None, help=f"built-in name or TOML file (default {DEFAULT_ANTENNA})"
    )
    _add_out(parser)
    parser.set_defaults(func=_run_estimate)


def _run_estimate(args: argparse.Namespace) -> int:
    from sensing_antenna.estimation import EstimatorConfig, estimate
    from sensing_antenna.plotting.estimate import plot_contact_estimate
    from sensing_antenna.recording import read_recording

    recording = read_recording(args.recording)
    antenna = _model(args, recording, "estimated")
    result = estimate(recording, antenna)
    paths = plot_contact_estimate(result, antenna, args.out, EstimatorConfig().zero_padding)
    for path in paths:
        print(path)
    trace = result.trace
    if trace is None or trace.frame is None or trace.spectrum is None:
        print(
            f"antenna plot estimate: figures 13 and 14 not drawn: the estimate stopped before "
            f"its spectrum and ratio windows ({result.status.value}: {result.reason})",
            file=sys.stderr,
        )
    return 0
