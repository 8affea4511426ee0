"""What a campaign tells the person waiting: a line per step and a bar for repeated work, on stderr.

From its first moment a campaign says what it is doing: the spec it runs, each preparation step
(the free-motion identification, the calibration recordings with their own bar), then the runs
with theirs. Lines go through ``tqdm.write`` so that they never break a bar. A disabled
:class:`Progress` says nothing.
"""

from __future__ import annotations

import sys
from types import TracebackType
from typing import TextIO

from tqdm import tqdm

__all__ = ["Progress"]


class _Bar(tqdm):
    """A tqdm bar without tqdm's monitor thread: the campaign forks worker processes while its
    bars are shown, and forking a process that runs other threads can deadlock the child."""

    monitor_interval = 0


class Progress:
    """Lines and progress bars for one campaign.

    Parameters
    ----------
    enabled : bool
        False: every call is silent (bars are created disabled).
    stream : text stream, optional
        Where to write; default ``sys.stderr`` at the time of each call.
    """

    def __init__(self, enabled: bool = True, stream: TextIO | None = None) -> None:
        self.enabled = enabled
        self._stream = stream

    @property
    def stream(self) -> TextIO:
        """The stream lines and bars go to."""
        return self._stream if self._stream is not None else sys.stderr

    def line(self, text: str) -> None:
        """One line of text, between the bars."""
        if self.enabled:
            tqdm.write(text, file=self.stream)

    def bar(self, total: int, description: str, unit: str = "run", initial: int = 0) -> tqdm:
        """A progress bar of ``total`` items (use as a context manager, ``update(1)`` per item)."""
        return _Bar(
            total=total,
            initial=initial,
            desc=description,
            unit=unit,
            file=self.stream,
            disable=not self.enabled,
        )

    def bar_from_first(self, total: int, description: str, unit: str) -> OpenedOnFirst:
        """:meth:`bar`, opened when its first item is done (work that may not happen shows
        none): call the result with each item, use it as a context manager."""
        return OpenedOnFirst(self, total, description, unit)


class OpenedOnFirst:
    """A :meth:`Progress.bar` opened at its first item (see :meth:`Progress.bar_from_first`)."""

    def __init__(self, progress: Progress, total: int, description: str, unit: str) -> None:
        self._opening = (progress, total, description, unit)
        self._bar: tqdm | None = None

    def __call__(self, _item: object = None) -> None:
        if self._bar is None:
            progress, total, description, unit = self._opening
            self._bar = progress.bar(total, description, unit)
        self._bar.update(1)

    def __enter__(self) -> OpenedOnFirst:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        if self._bar is not None:
            self._bar.close()
