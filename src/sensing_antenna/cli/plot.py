"""``antenna plot KIND ...``: every figure. Each kind is registered by a small function here."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


def register(subparsers: Any) -> None:
    """Add ``antenna plot`` and its kinds."""
    parser = subparsers.add_parser("plot", help="draw figures as PNG files")
    kinds = parser.add_subparsers(dest="kind", metavar="KIND", parser_class=type(parser))
    kinds.required = True
    for add_kind in (_add_sensing_curves, _add_recording, _add_estimate):
        add_kind(kinds)


def _add_out(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=Path, required=True, help="output directory")


def _add_sensing_curves(kinds: Any) -> None:
    parser = kinds.add_parser("sensing-curves", help="Figures 8 and 9: omega_i(x_c), f2 vs f1")
    parser.add_argument("--antenna", default=None, help="built-in name or TOML file")
    _add_out(parser)
    parser.set_defaults(func=_run_sensing_curves)


def _run_sensing_curves(args: argparse.Namespace) -> int:
    from sensing_antenna.antenna import load_antenna
    from sensing_antenna.plotting.sensing_curves import plot_sensing_curves

    for path in plot_sensing_curves(load_antenna(args.antenna), args.out):
        print(path)
    return 0


def _add_recording(kinds: Any) -> None:
    parser = kinds.add_parser("recording", help="angles, forces and torques of a recording")
    parser.add_argument("recording", type=Path)
    _add_out(parser)
    parser.set_defaults(func=_run_recording)


def _run_recording(args: argparse.Namespace) -> int:
    from sensing_antenna.plotting.recording import plot_recording
    from sensing_antenna.recording import read_recording

    for path in plot_recording(read_recording(args.recording), args.out):
        print(path)
    return 0


def _add_estimate(kinds: Any) -> None:
    parser = kinds.add_parser("estimate", help="Figures 11 to 14 for one recording")
    parser.add_argument("recording", type=Path)
    parser.add_argument("--antenna", default=None, help="built-in name or TOML file")
    _add_out(parser)
    parser.set_defaults(func=_run_estimate)


def _run_estimate(args: argparse.Namespace) -> int:
    from sensing_antenna.antenna import load_antenna
    from sensing_antenna.plotting.estimate import plot_estimate
    from sensing_antenna.recording import read_recording

    recording = read_recording(args.recording)
    for path in plot_estimate(recording, load_antenna(args.antenna), args.out):
        print(path)
    return 0
