"""Readings a stalled sensor repeats: one value held where the neighbours change.

A force/torque sensor that misses its readings for a while often has its last one sent again: an
EtherCAT slave that stalls, a serial driver that republishes, a logger that samples a value
nobody refreshed. The time stamps go on and the wrench stands still. Through the push the link
rings and the sensor's noise spans many resolution steps, so one reading repeated tens of times
is not a measurement: the spectrum and the ratio would read a flat stretch the link never made.

Samples that repeat the one before them, N in a row, are *held* when chance cannot explain them:
each channel's neighbours (up to :data:`NEIGHBOURS` steps on either side) repeat their reading from
one sample to the next in a share p of their steps, counted as (repeats + 1) / (steps + 2) on the
side where repeats are commoner, and the product of p^(N - 1) over the channels that hold is below
:data:`HELD_CHANCE`. All six channels holding together (a stall) are judged against either side.
One channel alone (stuck, zeroed, or at the end of its range) is judged only where it moves on both
sides by a median step of at least :data:`ONE_CHANNEL_STEPS` of its finest step: a slow signal read
to a coarse resolution dwells on one count, and a ringing may fade below the resolution, and
neither is a stall. A channel whose noise is under the sensor's resolution repeats often and weighs
little; a wrench that stands still throughout (a noiseless simulation at rest) has no neighbours to
judge by. A held run longer than the gaps a recording may have (``EstimatorConfig.gap_limit``) and
reaching the contact makes an estimate ``bad_input`` (``Evidence.sample_problem``).

Readings sent again one at a time, scattered, are counted by :func:`repeated_rows`: steps where
all six channels repeat the sample before. A sensor read to its resolution makes such repeats
where the loads stand nearly still, however its channels mix its gauges; a reading sent again
makes them at any pace. Where they come while the smoothest-ringing channel moves fast, more
often than that channel's own repeats there allow, they are readings sent again: in place of
lost ones (the step after each is about two), or stamped as new samples, which stretches the
record's time by their share and lowers the frequencies read from it by as much (the
plausibility layer's "time base" check). A sensor read too coarsely for any channel to ring
smoothly from one sample to the next is not judged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.stats import poisson

from sensing_antenna.estimation.front.spikes import Spike

__all__ = [
    "FAST_PACE",
    "HELD_CHANCE",
    "IN_PLACE_RATIO",
    "LEAST_NEIGHBOURS",
    "NEIGHBOURS",
    "ONE_CHANNEL_STEPS",
    "REPEAT_CHANCE",
    "SMOOTH_CORRELATION",
    "RepeatedRows",
    "describe_held",
    "find_held",
    "repeated_rows",
]

FloatArray = NDArray[np.float64]

#: Steps on each side of a run whose repeats say how often the channel repeats by chance.
NEIGHBOURS = 100

#: Least steps on a side for its share of repeats to count.
LEAST_NEIGHBOURS = 10

#: Least median step of a channel's neighbours, in its finest step, for it to be judged alone.
ONE_CHANNEL_STEPS = 3.0

#: Chance below which a run of one reading is not the sensor's noise.
HELD_CHANCE = 1e-9


def find_held(wrench: FloatArray, longer_than: int, first: int = 0) -> list[Spike]:
    """The held runs of more than ``longer_than`` samples in ``wrench`` that reach sample
    ``first`` or later, in order; channels that hold over the same samples are one run.

    Parameters
    ----------
    wrench : array, shape (n, 6)
        Wrench samples (N, N m).
    longer_than : int
        Most samples in a row a run may hold without being named.
    first : int
        Index of the first sample judged (runs ending before it are left alone).
    """
    n, width = wrench.shape
    repeat = wrench[1:] == wrench[:-1]  # step k (sample k to k + 1) repeats, per channel
    with np.errstate(invalid="ignore", over="ignore"):
        step = np.abs(np.diff(wrench, axis=0))
    repeats = np.vstack([np.zeros((1, width)), np.cumsum(repeat, axis=0)])
    moving = np.where(repeat | ~np.isfinite(step), np.inf, step)
    quantum = np.min(moving, axis=0, initial=np.inf)  # the finest step each channel takes
    found: dict[tuple[int, int], tuple[int, ...]] = {}
    for channels in [tuple(range(width)), *((c,) for c in range(width))]:
        for start, end in _runs(np.all(repeat[:, channels], axis=1)):
            length = end - start + 1  # samples start .. end hold one reading
            if length <= longer_than or end < first:
                continue
            sides = [
                (a, b)
                for a, b in (
                    (max(start - 1 - NEIGHBOURS, 0), start - 1),  # steps before the run
                    (end + 1, min(end + 1 + NEIGHBOURS, n - 1)),  # steps after it
                )
                if b - a >= LEAST_NEIGHBOURS
            ]
            if len(channels) == 1:
                # one channel: moving by steps of its resolution or more on both sides, since a
                # slow signal dwells on one count and a ringing may fade under the resolution
                c = channels[0]
                if len(sides) < 2 or not all(
                    np.median(step[a:b, c]) >= ONE_CHANNEL_STEPS * quantum[c] for a, b in sides
                ):
                    continue
            elif not sides:
                continue  # no neighbours to judge by
            # per channel, the share of repeats on the side where they are commoner
            shares = np.max(
                [
                    (repeats[b, channels] - repeats[a, channels] + 1.0) / (b - a + 2.0)
                    for a, b in sides
                ],
                axis=0,
            )
            if (length - 1) * float(np.sum(np.log(shares))) < math.log(HELD_CHANCE):
                key = (start, length)
                found[key] = tuple(sorted({*found.get(key, ()), *channels}))
    return [Spike(index, length, channels) for (index, length), channels in sorted(found.items())]


@dataclass(frozen=True)
class RepeatedRows:
    """Steps whose six channels all repeat the sample before, beyond what the sensor's
    resolution explains (:func:`repeated_rows`).

    Attributes
    ----------
    count : int
        Steps judged whose six channels all repeat the sample before, fast or slow.
    steps : int
        Steps judged.
    fast : int
        Of ``count``, those where ``channel`` moves at :data:`FAST_PACE` times its typical step
        or more either side.
    expected : float
        The mean number of such fast repeats the resolution gives: ``channel``'s own repeats at
        that pace where the other channels move on, as a rate, times its fast steps.
    channel : int
        The channel (0 to 5: fx, fy, fz, tx, ty, tz) that rings smoothest, whose pace judged them.
    in_place : bool
        Whether the step after a fast repeat is about twice the one before it: the repeats stand
        in place of readings that were lost, on the right time stamps; not so when readings
        were sent again and stamped as new samples.
    """

    count: int
    steps: int
    fast: int
    expected: float
    channel: int
    in_place: bool

    @property
    def share(self) -> float:
        """count / steps: the time a logger stamping each as a new sample adds (relative)."""
        return self.count / self.steps


#: Least correlation of a channel's successive steps for its ringing to judge repeats: a ringing
#: resolved far above the noise and the resolution steps alike from one sample to the next
#: (white noise's steps correlate at -0.5); a sensor read coarsely falls below.
SMOOTH_CORRELATION = 0.75

#: The pace, in the smooth channel's typical (median) steps, of the steps either side of a repeat
#: for it to count as one where the loads move fast.
FAST_PACE = 1.5

#: Chance under which the fast repeats are not the sensor's resolution. Such readings make an
#: answer ``uncertain`` at most, and only where they would move it (the plausibility layer).
REPEAT_CHANCE = 1e-3

#: The median ratio of the step after a fast repeat to the step before it from which the
#: repeats stand in place of lost readings (about 2) rather than readings stamped as new
#: samples (about 1).
IN_PLACE_RATIO = 1.5


def repeated_rows(wrench: FloatArray, first: int = 0) -> RepeatedRows | None:
    """The steps from sample ``first`` on in ``wrench`` (n, 6; N, N m) where all six channels
    repeat the sample before, when the sensor's resolution cannot explain those where the loads
    move fast; None when it can, or when no channel rings smoothly enough to tell
    (:data:`SMOOTH_CORRELATION`).

    A sensor read to its resolution repeats all six channels where the loads stand nearly still,
    however its channels mix its gauges; where the smoothest channel moves at
    :data:`FAST_PACE` times its typical step on both sides, such a repeat needs that channel's
    own step to round to nothing, which its other steps at that pace say how often happens. A
    reading sent again repeats at any pace. Judged by a Poisson tail under
    :data:`REPEAT_CHANCE`."""
    with np.errstate(invalid="ignore", over="ignore"):
        signed = np.diff(np.asarray(wrench, dtype=float), axis=0)
    step = np.abs(signed)
    begin = max(first, 1)  # each judged step has a step before it and one after it
    rows = np.arange(begin, step.shape[0] - 1)
    if rows.size < 3:
        return None
    here, before, after = step[rows], step[rows - 1], step[rows + 1]
    same = np.all(here == 0.0, axis=1)
    count = int(np.count_nonzero(same))
    if count == 0:
        return None
    channel, smooth = _smoothest(signed[begin:])
    if not smooth >= SMOOTH_CORRELATION:
        return None
    typical = float(np.median(step[begin:, channel]))
    with np.errstate(invalid="ignore", over="ignore"):
        fast = before[:, channel] + after[:, channel] >= 2.0 * FAST_PACE * typical
    repeats = int(np.count_nonzero(same & fast))
    others = fast & ~same
    alone = int(np.count_nonzero(others & (here[:, channel] == 0.0)))
    expected = (alone + 1.0) / (int(np.count_nonzero(others)) + 2.0) * int(np.count_nonzero(fast))
    if repeats == 0 or not float(poisson.sf(repeats - 1, expected)) < REPEAT_CHANCE:
        return None
    judged = same & fast & (before[:, channel] > 0.0)
    ratio = float(np.median(after[judged, channel] / before[judged, channel]))
    return RepeatedRows(
        count=count,
        steps=int(rows.size),
        fast=repeats,
        expected=expected,
        channel=channel,
        in_place=ratio >= IN_PLACE_RATIO,
    )


def _smoothest(signed: FloatArray) -> tuple[int, float]:
    """The channel whose successive steps (``signed``, (m, 6)) correlate most, and that
    correlation (NaN where no channel's steps vary)."""
    best, value = 0, math.nan
    for channel in range(signed.shape[1]):
        a, b = signed[:-1, channel], signed[1:, channel]
        if not (np.all(np.isfinite(a)) and a.std() > 0.0 and b.std() > 0.0):
            continue
        correlation = float(np.corrcoef(a, b)[0, 1])
        if not value >= correlation:
            best, value = channel, correlation
    return best, value


def _runs(same: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """(first, last) sample of each run where ``same[k]`` (sample k + 1 repeats sample k)."""
    edges = np.diff(np.concatenate(([0], same.astype(np.int8), [0])))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def describe_held(run: Spike, t: FloatArray, longer_than: int) -> str:
    """One line on a held run, at sample times ``t`` (s)."""
    return (
        f"{run.describe(t)} hold one value where their neighbours change (a stalled sensor or "
        f"driver, a channel stuck or at the end of its range), longer than the {longer_than} "
        f"missing in a row a recording may have"
    )
