"""After t_c: the contact lost, and the link touching again (:class:`ContactWatch`).

A recording holds one contact: its estimate is the first's. The contact detector's residual of
Eq. 16 (unfiltered), averaged over one period of the link's free mode (the observer's natural
frequency), shows the push for as long as the link touches, bouncing or not; the link's own
free ringing after a release averages out over that period. The same watch runs on a stream as
its samples arrive (``antenna listen``) and on a whole recording (:func:`contact_changes`, for
``antenna estimate``), so both say the same.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Antenna
from sensing_antenna.detection.contact import detect_contact
from sensing_antenna.history import GrowingArray
from sensing_antenna.recording import Recording

__all__ = [
    "CONTACT_AGAIN_SHARE",
    "CONTACT_LOST_SHARE",
    "ContactChange",
    "ContactWatch",
    "contact_changes",
    "free_period_samples",
    "lost_before_rest",
]

FloatArray = NDArray[np.float64]

#: Contact counts as lost once the contact detector's residual, averaged over one period of the
#: link's free mode (the observer's natural frequency), has fallen to this share of the largest
#: such average since t_c (the push), and to the detector's threshold. Averaged over a free
#: period, the link's free ringing after a release (and the observer's own, which a lightly
#: damped observer predicts for tens of seconds after the head stops) comes to nearly nothing,
#: while a contact's static push stays, bouncing or not: the filtered residual itself swung
#: through the threshold while the link bounced on a post, and stayed above it for tens of
#: seconds after a release.
CONTACT_LOST_SHARE = 0.2

#: After the contact was lost, a touch again: the same average rising above the detector's
#: threshold and this share of the first push's. The estimate is the first contact's; the
#: second is said, not estimated.
CONTACT_AGAIN_SHARE = 0.5


@dataclass(frozen=True)
class ContactChange:
    """The contact lost, or the link touching again.

    Parameters
    ----------
    kind : {"lost", "again"}
    row : int
        Samples from t_c (its sample 0) to the one at which the change is known.
    t : float
        When (s): for ``lost`` where the push began to vanish (one free period back from
        ``row``, plus the share of it still held, not before t_c); for ``again``, ``known``.
    known : float
        The time stamp (s) of the sample at ``row``: by then the change had happened.
    """

    kind: Literal["lost", "again"]
    row: int
    t: float
    known: float


def free_period_samples(antenna: Antenna, sample_period: float) -> int:
    """One period of the link's free mode (the observer's natural frequency) in samples of
    ``sample_period`` (s), at least one."""
    return max(1, round(2.0 * math.pi / (antenna.observer.natural_frequency * sample_period)))


class ContactWatch:
    """Watches the residual from t_c on, block by block, for the contact lost and a touch
    again (each said once; after a touch again, nothing more).

    Parameters
    ----------
    free_period : int
        One period of the link's free mode, in samples (:func:`free_period_samples`).
    threshold : float
        The contact detector's threshold (N m).
    sample_period : float
        T_s (s).
    """

    def __init__(self, free_period: int, threshold: float, sample_period: float) -> None:
        self.free_period = free_period
        self.threshold = threshold
        self.sample_period = sample_period
        self._sums = GrowingArray(3)  # cumulative residual from t_c (row 0: none yet)
        self._sums.extend(np.zeros((1, 3)))
        self._levels = GrowingArray()  # the averages' norms, from t_c
        self._push_level = 0.0
        self.lost: ContactChange | None = None
        self.again: ContactChange | None = None
        self._t_c = math.nan  # the first sample's time

    @classmethod
    def for_antenna(cls, antenna: Antenna, threshold: float, sample_period: float) -> ContactWatch:
        """A watch over ``antenna``'s free period (:func:`free_period_samples`) at
        ``sample_period`` (s), with the contact detector's ``threshold`` (N m)."""
        return cls(free_period_samples(antenna, sample_period), threshold, sample_period)

    @property
    def rows(self) -> int:
        """Samples fed so far (from t_c)."""
        return self._sums.size - 1

    def feed(self, residual: FloatArray, t: FloatArray) -> list[ContactChange]:
        """The next samples from t_c on: the residual r^m (N m), shape (k, 3), and their time
        stamps (s), shape (k,). Returns the changes they make known."""
        if self.again is not None or residual.shape[0] == 0:
            return []
        done = self.rows
        if done == 0:
            self._t_c = float(t[0])
        self._sums.extend(self._sums.values[self._sums.size - 1] + np.cumsum(residual, axis=0))
        sums = self._sums.values
        period = self.free_period
        ends = np.arange(done + 1, self._sums.size)  # rows: samples since t_c
        starts = np.maximum(ends - period, 0)
        means = (sums[ends] - sums[starts]) / (ends - starts)[:, None]
        levels = np.linalg.norm(means, axis=1)
        self._levels.extend(levels)
        if self.lost is not None:
            return self._watch_again(ends, levels, t)
        peaks = np.maximum.accumulate(np.maximum(levels, self._push_level))
        self._push_level = float(peaks[-1])
        limit = np.minimum(self.threshold, CONTACT_LOST_SHARE * peaks)
        lost = np.flatnonzero((ends >= period) & (levels <= limit))
        if lost.size == 0:
            return []
        k = int(lost[0])
        row = int(ends[k])  # the mean over the free period ending at this row's sample
        before = float(self._levels.values[row - period - 1]) if row > period else 0.0
        held = min(1.0, float(levels[k]) / before) if before > 0.0 else 0.0
        when = max(float(t[k]) - (1.0 - held) * period * self.sample_period, self._t_c)
        self.lost = ContactChange("lost", row - 1, when, float(t[k]))
        changes = [self.lost]
        if k + 1 < ends.shape[0]:
            changes += self._watch_again(ends[k + 1 :], levels[k + 1 :], t[k + 1 :])
        return changes

    def _watch_again(
        self, ends: NDArray[np.int_], levels: FloatArray, t: FloatArray
    ) -> list[ContactChange]:
        again = np.flatnonzero(levels > max(self.threshold, CONTACT_AGAIN_SHARE * self._push_level))
        if again.size == 0:
            return []
        first = int(again[0])
        self.again = ContactChange("again", int(ends[first]) - 1, float(t[first]), float(t[first]))
        return [self.again]


def lost_before_rest(changes: list[ContactChange], t_1: float) -> ContactChange | None:
    """The loss among ``changes`` when the push began to vanish before the head came to rest
    at ``t_1`` (s), else None: the contact found at t_c was no touch the hold reads (a
    detection on something else), and the touch a watch would call a second is the one
    estimated. Judged by the loss's time, not by when it became known (up to a free period
    later), so the front end, the live listener and ``antenna estimate`` say the same."""
    lost = next((change for change in changes if change.kind == "lost"), None)
    return lost if lost is not None and lost.t < t_1 else None


def contact_changes(recording: Recording, antenna: Antenna, t_c: float) -> list[ContactChange]:
    """The contact lost and a touch again in a whole ``recording`` after its contact at
    ``t_c`` (s, an estimate's), as :class:`ContactWatch` says them live: the residual of the
    contact detector (:func:`~.contact.detect_contact`) on the recording's grid. None before
    a finite ``t_c`` inside the recording."""
    detection = detect_contact(recording, antenna)
    t = detection.t
    if t.shape[0] < 2 or not t[0] <= t_c <= t[-1]:
        return []
    period = float(t[1] - t[0])
    start = int(np.searchsorted(t, t_c - 0.5 * period))
    watch = ContactWatch.for_antenna(antenna, detection.threshold, period)
    return watch.feed(detection.residual[start:], t[start:])
