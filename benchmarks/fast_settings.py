"""The fast method's settings on a benchmark's command line, shared by the benchmarks.

``--push-phase`` switches ``FastConfig.push_phase`` on; ``--set FIELD=VALUE`` (repeatable) sets
any other ``FastConfig`` field, its value read as JSON (``max_modes=2``, ``tolerance=0.01``,
``higher_modes=true``). The settings as given go into each benchmark's JSON output.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence
from dataclasses import fields
from typing import Any

from sensing_antenna.estimation.methods.fast import FastConfig, FastConfigError


def add_fast_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``--push-phase`` and ``--set`` to ``parser``."""
    parser.add_argument(
        "--push-phase",
        action="store_true",
        help="windows also through the push from t_c (FastConfig.push_phase)",
    )
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="FIELD=VALUE",
        help="another FastConfig setting (JSON value, e.g. max_modes=2); repeatable",
    )


def config_overrides(items: Sequence[str]) -> dict[str, Any]:
    """``FIELD=VALUE`` strings as FastConfig keyword arguments (each value read as JSON)."""
    names = {f.name for f in fields(FastConfig)}
    overrides: dict[str, Any] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or name not in names:
            raise SystemExit(f"--set {item!r}: expected FIELD=VALUE with a FastConfig field")
        try:
            overrides[name] = json.loads(value)
        except json.JSONDecodeError as error:
            raise SystemExit(f"--set {item!r}: the value is not JSON ({error})") from None
    return overrides


def fast_settings(args: argparse.Namespace) -> tuple[FastConfig, dict[str, Any]]:
    """The FastConfig the parsed ``args`` ask for, and the settings as given (for the JSON)."""
    settings = {"push_phase": bool(args.push_phase), **config_overrides(args.set)}
    try:
        return FastConfig(**settings), settings
    except FastConfigError as error:
        raise SystemExit(f"--set: {error}") from None
