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
all six channels repeat, against the most chance allows. A channel repeats by chance when its
step rounds to nothing, about its finest step over its typical step, which :data:`NEIGHBOURS`
steps at a time say; all six together at most as often as the one that repeats least (whatever
their correlation). A logger that stamps such readings as new samples stretches the record's
time by their share, and the frequencies read from it fall by as much (the plausibility layer's
"time base" check).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.stats import poisson

from sensing_antenna.estimation.front.spikes import Spike

__all__ = [
    "HELD_CHANCE",
    "LEAST_NEIGHBOURS",
    "NEIGHBOURS",
    "ONE_CHANNEL_STEPS",
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
    """Steps whose six channels all repeat the sample before, more than chance allows.

    Attributes
    ----------
    count : int
        Such steps.
    steps : int
        Steps judged.
    expected : float
        Most such steps the channels' own steps allow by chance.
    """

    count: int
    steps: int
    expected: float

    @property
    def share(self) -> float:
        """count / steps: the time a logger stamping each as a new sample adds (relative)."""
        return self.count / self.steps


def repeated_rows(wrench: FloatArray, first: int = 0) -> RepeatedRows | None:
    """The steps from sample ``first`` on in ``wrench`` (n, 6; N, N m) where all six channels
    repeat the sample before, when chance cannot explain their number (a Poisson tail under
    :data:`HELD_CHANCE` about the most chance allows, the module docstring); None when it can.
    Each channel's finest step is taken over all of ``wrench``; a channel that never moves
    says nothing."""
    with np.errstate(invalid="ignore", over="ignore"):
        step = np.abs(np.diff(wrench, axis=0))
    finite = np.isfinite(step)
    moving = np.where((step > 0.0) & finite, step, np.inf)
    quantum = np.min(moving, axis=0, initial=np.inf)
    judged = step[max(first, 0) :]
    same = np.all(judged == 0.0, axis=1)
    count = int(np.count_nonzero(same))
    if count == 0:
        return None
    expected = 0.0
    for start in range(0, judged.shape[0], NEIGHBOURS):
        block = judged[start : start + NEIGHBOURS]
        with np.errstate(divide="ignore", invalid="ignore"):
            typical = np.median(block, axis=0)
            # a step rounds to nothing about once in typical / quantum; twice that, for tails
            chance = np.where(typical > 0.0, 2.0 * quantum / typical, 1.0)
        share = float(np.min(np.minimum(np.nan_to_num(chance, nan=1.0), 1.0)))
        expected += share * block.shape[0]
    if not float(poisson.sf(count - 1, expected)) < HELD_CHANCE:
        return None
    return RepeatedRows(count, int(judged.shape[0]), expected)


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
