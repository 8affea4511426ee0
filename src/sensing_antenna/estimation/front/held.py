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
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.front.spikes import Spike

__all__ = [
    "HELD_CHANCE",
    "LEAST_NEIGHBOURS",
    "NEIGHBOURS",
    "ONE_CHANNEL_STEPS",
    "describe_held",
    "find_held",
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
