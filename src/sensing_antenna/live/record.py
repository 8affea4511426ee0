"""What a listener received, written as a recording while it arrives (``antenna listen
--record``).

The file is in the recording format (docs/recording-format.md): the stream's metadata with
``format`` and ``sample_period`` first, its header, then the samples in the order received,
every number at ``repr`` precision, flushed after each block of samples. A recording sent by
``antenna replay`` and received whole is read back equal to the one sent.
"""

from __future__ import annotations

from pathlib import Path
from types import TracebackType

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.live.wire import StreamHeader, format_sample

__all__ = ["RecordWriter", "numbered_path"]


def numbered_path(path: Path, number: int) -> Path:
    """Where the ``number``-th recording of a stream goes: ``path`` for the first,
    ``rec-2.csv``, ``rec-3.csv``, ... for the next ones."""
    return path if number == 1 else path.with_name(f"{path.stem}-{number}{path.suffix}")


class RecordWriter:
    """A recording file written as samples arrive.

    Parameters
    ----------
    path : Path
        Destination, overwritten.
    header : StreamHeader
        Metadata and columns of the stream.
    """

    def __init__(self, path: Path, header: StreamHeader) -> None:
        self.path = path
        self._file = open(path, "w", encoding="utf-8", newline="")
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
