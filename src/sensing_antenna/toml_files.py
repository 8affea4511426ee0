"""Reading TOML configuration files (antennae, campaign specs) with errors that name the file."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = ["parse_toml_file", "parse_toml_text"]

#: Builds the caller's exception from (field, problem); the caller adds the file name.
ErrorFactory = Callable[[str, str], Exception]


def parse_toml_text(text: str, error: ErrorFactory) -> dict[str, Any]:
    """Parse TOML text; a syntax error becomes ``error("file", "not valid TOML (...)")``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error("file", f"not valid TOML ({exc})") from exc


def parse_toml_file(path: Path, error: ErrorFactory) -> dict[str, Any]:
    """Read and parse a UTF-8 TOML file; unreadable, non-UTF-8 or invalid files raise ``error``."""
    try:
        text = path.read_text("utf-8")
    except UnicodeDecodeError as exc:
        raise error("file", f"not UTF-8 text ({exc.reason})") from exc
    except OSError as exc:
        raise error("file", f"cannot be read ({exc.strerror or exc})") from exc
    return parse_toml_text(text, error)
