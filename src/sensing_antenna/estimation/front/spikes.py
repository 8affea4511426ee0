"""Corrupted samples of the force/torque sensor (a glitch of the bus or the DAQ): runs of up to
:func:`spike_longest` samples found against a robust local noise scale and put back by
interpolation between their neighbours.

A sensor read over EtherCAT or a serial line now and then delivers a sample, or a few in a row,
whose wrench is not the link's: a channel (or all six) with a huge value, a sign flipped, all
zeros. One such sample moves the tare, the hold's mean push, the Eq. 20 filter's ratio for a
second and the spectrum's floor, and the statuses that follow name causes it is not (slip,
units, a sign flipped, a tip mass). Here, per channel, sample j is a *suspect* when its step
from j - 1 departs from the local trend (the median of the ``SPIKE_WINDOW`` first differences
before it) by more than ``SPIKE_FACTOR`` robust deviations (1.4826 times their median absolute
deviation) and by more than a floor (:func:`spike_floor`); it starts a *spike* of m samples
when those m samples lie off the trend by that bound and the signal comes back to the trend at
j + m (m at most ``longest``) and goes on calmly, and then the m samples are replaced by
the straight line between their neighbours. A step that stays (a contact) is left alone; an
impact's pulse as brief and above the floor cannot be told from a glitch and is put back too.
Every decision reads the raw samples j - SPIKE_WINDOW - 1 .. j + longest + 1 only, so a
stream decides as a whole recording does, holding a suspect back until the samples after it
that decide it have come.

A longer run (:func:`find_long_runs`, up to ``LONG_RUN_DURATION``) is not put back: a straight
line across it would make up a large part of a period of the link's vibration. It starts as a
spike does, lies off the level of the quiet samples before it and comes back to that level to
stay; found over the samples up to an estimate's t_e, it makes the estimate ``bad_input``
(``Evidence.sample_problem``).

The median absolute deviation of 31 steps is itself noisy, so white noise alone passes ten of
them now and then; the floor, far above any sensor's noise, is what keeps its samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.ndimage import maximum_filter1d

from sensing_antenna.antenna import Antenna
from sensing_antenna.estimation.config import periods_in

__all__ = [
    "LEVEL_SAMPLES",
    "LONG_RUN_DURATION",
    "SPIKE_DURATION",
    "SPIKE_FACTOR",
    "SPIKE_LEAST",
    "SPIKE_WINDOW",
    "WRENCH_CHANNELS",
    "Spike",
    "describe_run",
    "find_long_runs",
    "find_spikes",
    "judged_from",
    "long_run_longest",
    "repair",
    "spike_floor",
    "spike_longest",
]

FloatArray = NDArray[np.float64]

#: First differences before a sample that give the local trend and noise scale (odd: the
#: median is one of them, the same bits however it is computed).
SPIKE_WINDOW = 31
#: Robust deviations from the local trend beyond which a step is a suspect.
SPIKE_FACTOR = 10.0
#: Longest run of corrupted samples put back (s) at rates above 1 kHz: half the shortest rebound
#: (a contact lost and found again, 40 ms) the simulator shows, so none is taken for one.
SPIKE_DURATION = 0.02
#: Fewest samples of that longest run, below 1 kHz: there a corrupted run left in place does more
#: harm than a brief rebound put back (docs/design-notes.md, "Samples lost inside the window").
SPIKE_LEAST = 20
#: Longest corrupted run looked for (s) beyond those put back: longer ones are not told from a
#: step that stays (a contact, a push) by the same test.
LONG_RUN_DURATION = 0.5
#: Samples on either side of a long run that give the level it leaves and comes back to: quiet
#: about their median within a quarter of the run's least height.
LEVEL_SAMPLES = 5
#: Least spike, in the link's weight (forces) and its weight's moment, the link horizontal
#: (torques): above the single-sample pulses the simulated link's impacts ring between calm
#: neighbours at its default contact (docs/design-notes.md, "Corrupted samples").
SPIKE_FLOOR_WEIGHTS = (2.0, 0.5)
#: Largest float: the height of a run of infinite samples.
_LARGEST = float(np.finfo(np.float64).max)
#: MAD to standard deviation for Gaussian noise.
_MAD_TO_SIGMA = 1.4826

WRENCH_CHANNELS = ("fx", "fy", "fz", "tx", "ty", "tz")


@dataclass(frozen=True)
class Spike:
    """Corrupted samples found: ``index`` (of the first, in the array searched), ``length``
    (1 to the longest looked for) and the channels (0..5, fx..tz)."""

    index: int
    length: int
    channels: tuple[int, ...]

    def describe(self, t: FloatArray) -> str:
        """Its channels, length and start at sample times ``t`` (s), to begin a reason."""
        channels = ", ".join(WRENCH_CHANNELS[c] for c in self.channels)
        return f"{channels}: {self.length} samples in a row from t = {t[self.index]:.4f} s"


def spike_longest(sample_period: float) -> int:
    """Most corrupted samples in a row put back at ``sample_period`` (s): as many as span
    :data:`SPIKE_DURATION`, and at least :data:`SPIKE_LEAST`."""
    return max(SPIKE_LEAST, periods_in(SPIKE_DURATION, sample_period))


def long_run_longest(sample_period: float) -> int:
    """Most corrupted samples in a row looked for at ``sample_period`` (s): as many as span
    :data:`LONG_RUN_DURATION`, and at least :func:`spike_longest`."""
    return max(spike_longest(sample_period), periods_in(LONG_RUN_DURATION, sample_period))


def find_spikes(
    raw: FloatArray,
    start: int,
    floor: FloatArray,
    final: bool = False,
    *,
    longest: int,
    to_level: bool = False,
) -> tuple[list[Spike], int]:
    """The spikes among ``raw[start:]`` and how many leading samples are decided.

    Parameters
    ----------
    raw : array, shape (n, 6)
        Raw wrench samples (N, N m); those before ``start`` are history (already decided).
    start : int
        First sample to judge.
    floor : array, shape (6,)
        Least departure from the trend a spike has, per channel (N, N m): below it a sample is
        not judged, however calm its neighbours (:func:`spike_floor`).
    final : bool
        No samples will follow: a suspect too near the end to decide is left as it is.
    longest : int
        Most samples in a run (:func:`spike_longest` for the spikes put back); a suspect waits
        for ``longest + 1`` samples after it.
    to_level : bool
        Judge a run against the level of the quiet samples before it (:func:`find_long_runs`)
        rather than the trend line.

    Returns
    -------
    (spikes, decided) : list of Spike, int
        Samples ``raw[:decided]`` are final (repaired with ``spikes`` where listed); the rest
        wait for the samples that decide a suspect among them.
    """
    n = raw.shape[0]
    w = SPIKE_WINDOW
    first = max(start, w + 2)
    if n - first <= 0:
        return [], n  # too few samples before them for a window: not judged
    with np.errstate(over="ignore", invalid="ignore"):
        d = np.diff(raw[first - w - 1 :], axis=0)  # d[k]: the step into sample first - w + k
        size = d.shape[0]
        absd = np.abs(d)
        # the w steps before the step into j (j = first .. n - 1) are d[j - first : j - first + w]
        # and the step into j is d[j - first + w]. A suspect departs from the trend (the median
        # of those w steps, at most their largest in size) by more than the floor: only samples
        # whose step and largest window step together exceed it are judged (the same decisions,
        # without a median for every calm sample).
        if size - w == 1:  # one sample to judge (the stream's case): no sliding window
            largest = absd[:w].max(axis=0)[None, :]
        else:  # the running maximum of w steps, each row's window starting at that row
            largest = maximum_filter1d(absd[: size - 1], w, axis=0, origin=-(w // 2))[: size - w]
        step = d[w:]
        candidate = absd[w:] + largest >= judged_from(floor)
        rows = np.flatnonzero(candidate.any(axis=1))
        flagged = np.zeros(step.shape, dtype=bool)
        trend = np.zeros(step.shape)
        limit = np.zeros(step.shape)
        if rows.size:
            windows = d[rows[:, None] + np.arange(w)]  # (rows, w, 6)
            centre = np.median(windows, axis=1)
            scale = _MAD_TO_SIGMA * np.median(np.abs(windows - centre[:, None, :]), axis=1)
            trend[rows] = centre
            limit[rows] = np.maximum(SPIKE_FACTOR * scale, floor)
            flagged[rows] = np.abs(step[rows] - centre) > limit[rows]
    spikes: list[Spike] = []
    skip_to = np.full(6, first)  # per channel: the first sample after a spike's landing
    for k in np.flatnonzero(flagged.any(axis=1)):
        j = first + int(k)
        channels = np.flatnonzero(flagged[k] & (skip_to <= j))
        if not channels.size:
            continue  # the return of a spike just found
        if j + longest + 1 > n - 1:
            if not final:
                return _decided_before(spikes, j)  # wait for the samples that decide it
            if j + 2 > n - 1:
                break  # too near the end for a single sample's landing and the step after it
        by_length: dict[int, list[int]] = {}
        for c in channels:
            if to_level:
                x = raw[j - LEVEL_SAMPLES : j + longest + LEVEL_SAMPLES, c]
                length = _run_to_level(x, float(limit[k, c]), longest)
            else:
                x = raw[j - 2 : j + longest + 2, c]
                length = _spike_length(x, float(trend[k, c]), float(limit[k, c]), longest)
            if length:
                by_length.setdefault(length, []).append(int(c))
                skip_to[c] = j + 1 + length
        for length in sorted(by_length):
            spikes.append(Spike(j, length, tuple(by_length[length])))
    return spikes, n


def find_long_runs(
    wrench: FloatArray, floor: FloatArray, *, longest: int, most: int
) -> list[Spike]:
    """The runs of ``longest + 1`` to ``most`` samples in ``wrench`` that leave their level and
    come back to it, too long to put back.

    A run starts as a spike does, with a step off the local trend. The ``LEVEL_SAMPLES`` before
    it give the level (their median) and lie within a quarter of the run's least height of it;
    each of its samples lies off that level by more than the spike's bound; and the
    ``LEVEL_SAMPLES`` from its landing on lie within a quarter of its least height of the level
    (a level, not the trend line: over tens of samples the link's slow motion moves it by more
    than the noise). An impact's ringing is not quiet on both sides.

    Parameters
    ----------
    wrench : array, shape (n, 6)
        Wrench samples (N, N m), spikes of up to ``longest`` samples already put back; all of
        them are judged, as at the end of a recording.
    floor : array, shape (6,)
        Least departure from the trend per channel (N, N m, :func:`spike_floor`).
    longest, most : int
        Most samples a spike put back has (:func:`spike_longest`), and most samples of a run
        looked for (:func:`long_run_longest`).
    """
    runs, _ = find_spikes(wrench, 0, floor, final=True, longest=most, to_level=True)
    return [run for run in runs if run.length > longest]


def describe_run(run: Spike, t: FloatArray, longest: int) -> str:
    """One line on a corrupted run too long to put back, at sample times ``t`` (s)."""
    return (
        f"{run.describe(t)} leave the level of their neighbours and come back to it, like a "
        f"corrupted run, longer than the {longest} in a row put back on a line"
    )


def _decided_before(spikes: list[Spike], j: int) -> tuple[list[Spike], int]:
    """The spikes found before a suspect ``j`` that waits, and the samples decided: up to ``j``,
    or up to the first sample of a spike whose samples or landing reach ``j`` (found again, with
    its channels, when the samples after ``j`` have come, so a stream decides as a whole
    recording does)."""
    decided = j
    moved = True
    while moved:
        moved = False
        for spike in spikes:
            if spike.index < decided <= spike.index + spike.length:
                decided, moved = spike.index, True
    return [s for s in spikes if s.index + s.length < decided], decided


def judged_from(floor: FloatArray) -> FloatArray:
    """The least sum of a sample's step and the largest step of its window (N, N m, per
    channel) that :func:`find_spikes` judges: below it the step cannot leave the trend (the
    window's median, at most its largest step) by the ``floor``; a relative 1e-9 less, for
    rounding."""
    return np.asarray(floor * (1.0 - 1e-9))


def spike_floor(antenna: Antenna) -> FloatArray:
    """The least departure (N, N m) a spike has on each channel fx..tz
    (:data:`SPIKE_FLOOR_WEIGHTS` of the link's weight and its moment)."""
    level = np.array([0.0])
    weight = float(np.linalg.norm(antenna.gravity_force(level)))
    moment = float(np.linalg.norm(antenna.gravity_torque(level)))
    force, torque = SPIKE_FLOOR_WEIGHTS
    return np.array([force * weight] * 3 + [torque * moment] * 3)


def _run_to_level(x: FloatArray, limit: float, most: int) -> int:
    """The number of samples from x[LEVEL_SAMPLES] on (1 to ``most``) that leave the level of
    the quiet samples before them and come back to it to stay (:func:`find_long_runs`), else 0.

    ``x``: the samples j - LEVEL_SAMPLES .. j + most + LEVEL_SAMPLES - 1 of one channel (fewer
    at the end of a recording); ``limit`` the bound on a departure.
    """
    k = LEVEL_SAMPLES
    with np.errstate(over="ignore", invalid="ignore"):
        level = float(np.median(x[:k]))
        quiet = float(np.max(np.abs(x[:k] - level)))
        off = np.abs(x[k:] - level)
        longest = min(most, off.shape[0] - k)
        height = math.inf  # the least departure of the run's samples so far
        for m in range(1, longest + 1):
            if not off[m - 1] > limit:
                return 0  # a sample back within the bound before a landing: no run
            height = min(height, float(off[m - 1]))
            bound = 0.25 * min(height, _LARGEST)  # a run of inf lands on finite samples only
            if quiet <= bound and bool(np.all(off[m : m + k] <= bound)):
                return m
    return 0


def _spike_length(x: FloatArray, slope: float, limit: float, most: int) -> int:
    """The number of samples from x[2] on (1 to ``most``) that leave the trend and come back,
    else 0.

    ``x``: the samples j - 2 .. j + most + 1 of one channel (fewer at the end of a
    recording); ``slope`` the local trend per sample and ``limit`` the bound on a departure
    from it. A spike leaves a calm signal (the step into j - 1 within the bound), each of its
    samples lies beyond the bound off the trend line from j - 1, the next sample lands on that
    line within the bound and within a quarter of the spike's least height, and the signal goes
    on calmly (the step after the landing within the bound). A step that stays (a contact) does
    not come back; the ringing of an impact is not calm on either side.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        if not abs(x[1] - x[0] - slope) <= limit:
            return 0
        longest = min(most, x.shape[0] - 4)  # fewer at a recording's end
        # departures from the trend line through x[1], of x[2] .. x[longest + 2]
        off = x[2 : longest + 3] - x[1] - slope * np.arange(1.0, longest + 2.0)
        size = np.abs(off)
        height = math.inf  # the least departure of the spike's samples so far
        for m in range(1, longest + 1):
            if not size[m - 1] > limit:
                return 0  # a sample back within the bound before a landing: no spike
            height = min(height, float(size[m - 1]))
            after = x[m + 3] - x[m + 2] - slope
            if abs(off[m]) <= min(limit, 0.25 * height) and abs(after) <= limit:
                return m
    return 0


def repair(raw: FloatArray, spikes: list[Spike]) -> FloatArray:
    """``raw`` with the spikes' samples on the straight line between their neighbours (a copy
    when there is any, else ``raw`` itself)."""
    if not spikes:
        return raw
    out = np.array(raw, dtype=np.float64, copy=True)
    for spike in spikes:
        j, m, c = spike.index, spike.length, list(spike.channels)
        before, after = raw[j - 1, c], raw[j + m, c]
        for i in range(m):
            out[j + i, c] = before + (i + 1) / (m + 1) * (after - before)
    return out
