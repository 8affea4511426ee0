"""A float history that grows as samples arrive (:class:`GrowingArray`): a stream's readers
append blocks of any size and read back any part, in amortised constant time per sample."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["GrowingArray"]


class GrowingArray:
    """Values, or rows of ``width`` values, appended in blocks; capacity doubled when full.

    ``values[:size]`` holds what was appended (a view: read it before the next
    :meth:`extend`, which may move it).
    """

    def __init__(self, width: int | None = None) -> None:
        self.values: NDArray[np.float64] = np.empty(4096 if width is None else (4096, width))
        self.size = 0

    def extend(self, block: NDArray[np.float64]) -> None:
        """Append ``block``, shape (k,) or (k, width)."""
        stop = self.size + block.shape[0]
        if stop > self.values.shape[0]:
            grown = np.empty((max(stop, 2 * self.values.shape[0]), *self.values.shape[1:]))
            grown[: self.size] = self.values[: self.size]
            self.values = grown
        self.values[self.size : stop] = block
        self.size = stop
