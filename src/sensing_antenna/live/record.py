"""What a listener received, written as a recording while it arrives (``antenna listen
--record``).

The file is in the recording format (docs/recording-format.md): the stream's metadata with
``format`` and ``sample_period`` first, its header, then the samples in the order received,
every number at ``repr`` precision, flushed after each block of samples. A recording sent by
``antenna replay`` and received whole is read back equal to the one sent.
"""

from __future__ import annotations

import glob
from pathlib import Path
from types import TracebackType

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.live.wire import StreamHeader, format_sample

__all__ = ["RecordWriter", "numbered_path", "record_path_problem"]


def numbered_path(path: Path, number: int) -> Path:
    """Where the ``number``-th recording of a stream goes: ``path`` for the first,
    ``rec-2.csv``, ``rec-3.csv``, ... for the next ones."""
    return path if number == 1 else path.with_name(f"{path.stem}-{number}{path.suffix}")


def record_path_problem(path: Path) -> str | None:
    """Why recordings cannot be kept at ``path`` and its numbered next ones, or None: a folder
    that does not exist, or a file of that name there already (a session's recordings are not
    written over)."""
    folder = path.parent
    if not folder.is_dir():
        return f"{path}: the folder {folder} does not exist"
    taken = [path] if path.exists() else []
    for found in sorted(folder.glob(f"{glob.escape(path.stem)}-[0-9]*{glob.escape(path.suffix)}")):
        number = found.name[len(path.stem) + 1 : len(found.name) - len(path.suffix)]
        if number.isdigit() and int(number) >= 2 and found == numbered_path(path, int(number)):
            taken.append(found)
    if taken:
        return (
            f"{taken[0]} exists: recordings are not written over; give another name or move "
            "the earlier ones"
        )
    return None


class RecordWriter:
    """A recording file written as samples arrive.

    Parameters
    ----------
    path : Path
        Destination, a new file (an existing one is not written over: ``FileExistsError``).
    header : StreamHeader
        Metadata and columns of the stream.
    """

    def __init__(self, path: Path, header: StreamHeader) -> None:
        self.path = path
        self._file = open(path, "x", encoding="utf-8", newline="")
        self._file.write("\n".join(header.lines()) + "\n")
        self._file.flush()

    def write(self, rows: NDArray[np.float64]) -> None:
        """Append samples, shape (k, n_columns) in the header's order, and flush."""
        self._file.write("".join(format_sample(row) + "\n" for row in rows.tolist()))
        self._file.flush()

    def close(self) -> None:
        """Close the file."""
        self._file.close()

    def __enter__(self) -> RecordWriter:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()
