"""Reading TOML configuration files (antennae, campaign specs) with errors that name the file.

Configuration files are small (an antenna file is about 1 kB, the built-in campaign 3.5 kB), so
the reader bounds what it parses before the parser can exhaust memory or the stack:

- at most :data:`MAX_TOML_BYTES` bytes, checked before reading a regular file and while reading
  anything else (a device such as ``/dev/zero`` or a pipe);
- keys of at most :data:`MAX_KEY_PARTS` dotted parts (``device.link.youngs_modulus`` has three):
  Python's TOML parser keeps every prefix of a dotted key, so memory grows with the square of its
  length (a key of 10,000 parts takes 400 MB, of 100,000 parts more than any machine has);
- inline tables and arrays nested so deeply that the parser runs out of stack are refused too.
"""

from __future__ import annotations

import os
import re
import stat
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["MAX_KEY_PARTS", "MAX_TOML_BYTES", "parse_toml_file", "parse_toml_text"]

#: Builds the caller's exception from (field, problem); the caller adds the file name.
ErrorFactory = Callable[[str, str], Exception]

#: Largest configuration file read (bytes): 1 MiB, some 300 times the built-in campaign.
MAX_TOML_BYTES = 2**20

#: Most parts a dotted key or table header may have: 32, ten times the deepest key the
#: configuration files use (``device.link.youngs_modulus``).
MAX_KEY_PARTS = 32

# One part of a key: bare, or a basic or literal string on one line.
_PART = r"""(?:[A-Za-z0-9_-]+|"(?:[^"\\\n]|\\.)*"|'[^'\n]*')"""
# A run of parts joined by dots: a dotted key, a table header, or a float such as 1.5 (two parts).
_DOTTED = re.compile(rf"{_PART}(?:[ \t]*\.[ \t]*{_PART})*")


def _longest_key(text: str) -> tuple[int, int]:
    """(parts, line) of the longest dotted run in ``text``; strings count as one part each,
    so the count never falls below the longest key's."""
    parts, line = 0, 0
    for number, text_line in enumerate(text.splitlines(), start=1):
        if text_line.count(".") < parts:
            continue
        for match in _DOTTED.finditer(text_line):
            found = len(re.findall(rf"{_PART}", match.group()))
            if found > parts:
                parts, line = found, number
    return parts, line


def parse_toml_text(text: str, error: ErrorFactory) -> dict[str, Any]:
    """Parse TOML text; a syntax error becomes ``error("file", "not valid TOML (...)")``.

    Keys of more than :data:`MAX_KEY_PARTS` parts and nesting deeper than the parser's stack
    are refused the same way, naming the line where known.
    """
    parts, line = _longest_key(text)
    if parts > MAX_KEY_PARTS:
        raise error(
            "file",
            f"line {line}: a key of {parts} dotted parts, more than the limit of {MAX_KEY_PARTS}",
        )
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error("file", f"not valid TOML ({exc})") from exc
    except RecursionError as exc:
        raise error("file", "tables or arrays nested too deeply to parse") from exc


def _read_limited(path: Path) -> bytes | str:
    """The file's bytes, or why it is refused: more than :data:`MAX_TOML_BYTES`."""
    limit = f"the limit of {MAX_TOML_BYTES} bytes (1 MiB) for a configuration file"
    with path.open("rb") as stream:
        status = os.fstat(stream.fileno())
        if stat.S_ISREG(status.st_mode) and status.st_size > MAX_TOML_BYTES:
            return f"{status.st_size} bytes, larger than {limit}"
        data = stream.read(MAX_TOML_BYTES + 1)
    if len(data) > MAX_TOML_BYTES:
        return f"not a regular file, and longer than {limit}"
    return data


def parse_toml_file(path: Path, error: ErrorFactory) -> dict[str, Any]:
    """Read and parse a UTF-8 TOML file; unreadable, non-UTF-8, invalid or oversized files (more
    than :data:`MAX_TOML_BYTES`) raise ``error``."""
    try:
        data = _read_limited(path)
    except OSError as exc:
        raise error("file", f"cannot be read ({exc.strerror or exc})") from exc
    if isinstance(data, str):
        raise error("file", data)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error("file", f"not UTF-8 text ({exc.reason})") from exc
    return parse_toml_text(text, error)
