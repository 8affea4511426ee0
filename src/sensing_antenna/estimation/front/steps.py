"""The causal steps of the front end, each a function of the samples up to the instant it needs.

1. Sampling and sensor checks (:func:`sampling_problem`, :func:`dead_channel`).
2. Sensor offset (tare) and rest tolerance from the samples up to t_c (:func:`at_contact`), and
   the recording's own units check there: the loads the tare averages against the link's weight
   (:func:`sensing_antenna.units_check.rest_reading`), the free motion before t_c against the
   observer (:func:`free_motion_gain`, and joint by joint :func:`joint_free_motion_gains`;
   a turn the still angles miss, :func:`still_angles_turn`), and the angles up to t_c
   (:func:`sensing_antenna.units_check.angle_problem`), so that an outcome found before t_e
   (no push, say) on angles in degrees names the degrees.
3. The static push over the hold window [t_1, t_1 + frame_window] (:func:`hold_push`): the mean
   contact force, not the force at one instant, because near the tip the link bounces on the
   obstacle for a few tenths of a second after the stop while the static preload is small
   against the impact. The push counts when its mean is ``min_push_significance`` standard
   errors above zero; the frame of Section 5.3 is built from that mean.
4. Estimator 2's convergence tolerance (:func:`ratio_tolerance`) and t_e (:func:`planned_end`).
5. Gaps of missing samples: filled in as they arrive (:func:`fill_missing`), remembered when long
   (:func:`time_gaps`), judged over the estimation window (:func:`gap_problem`).

:class:`~.frontend.FrontEnd` calls them in this order as the samples arrive.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, NamedTuple

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Antenna
from sensing_antenna.compiler import njit
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.front.contact_frame import (
    ContactFrame,
    contact_frame,
    rest_drift_tolerance,
    rest_tolerance,
    signal_noise,
)
from sensing_antenna.estimation.front.ratio import contact_loads, load_offset, ratio_noise
from sensing_antenna.recording import CLOCK_TOLERANCE, PERIOD_CHECK_STEPS, PERIOD_CONSISTENCY
from sensing_antenna.units_check import angle_problem, initial_rest, rest_reading, stamps_unit

__all__ = [
    "MAX_FILLED",
    "MIN_STEPS_FOR_DROPS",
    "OUTLIER_PERIODS",
    "SETTLED_ERRORS",
    "STEP_JITTER",
    "ContactStart",
    "DeclaredPeriodCheck",
    "FilledSamples",
    "HoldPush",
    "TareKind",
    "at_contact",
    "dead_channel",
    "declared_period_problem",
    "declared_period_refused",
    "fill_missing",
    "free_motion_gain",
    "gap_problem",
    "hold_push",
    "hold_samples",
    "hold_window",
    "joint_free_motion_gains",
    "planned_end",
    "ratio_tolerance",
    "samples",
    "samples_missing",
    "sampling_problem",
    "settled_loads",
    "slowest_sample_rate",
    "still_angles_turn",
    "stream_period_problem",
    "time_gaps",
]

FloatArray = NDArray[np.float64]

#: Standard errors of a rest window's mean load (the channel's white noise over its square
#: root) by which the loads leave their level where the rest ends (:func:`settled_loads`): the
#: mean before the window has its own error, so noise alone reaches 5 of these about as often
#: as 3.5 standard deviations of the difference, and the run must last to the end besides.
SETTLED_ERRORS = 5.0


def samples(duration: float, sample_period: float) -> int:
    """Number of sample intervals in ``duration`` (at least one)."""
    return max(1, round(duration / sample_period))


def hold_samples(cfg: EstimatorConfig, sample_period: float) -> int:
    """Sample intervals of the hold after t_1 the front end judges (``frame_window``, at least
    ``rest_window``), over which the head must not drift either."""
    return max(samples(cfg.frame_window, sample_period), samples(cfg.rest_window, sample_period))


def hold_window(rest_index: int, n: int, cfg: EstimatorConfig, ts: float) -> slice:
    """The samples whose mean reaction is the push: [t_1, t_1 + frame_window] within the ``n``
    samples (``ts`` the sample period, s)."""
    return slice(rest_index, min(rest_index + samples(cfg.frame_window, ts) + 1, n))


def slowest_sample_rate(band_top: float, cfg: EstimatorConfig) -> float:
    """The slowest sampling (Hz) whose Nyquist frequency is ``cfg.min_nyquist_factor`` times
    the top of the omega_1 band ``band_top`` (rad/s): what :func:`sampling_problem` asks."""
    return cfg.min_nyquist_factor * band_top / math.pi


def sampling_problem(sample_period: float, band_top: float, cfg: EstimatorConfig) -> str | None:
    """Why samples at this period cannot show the vibration (bad input), or None.

    The Nyquist frequency pi / T_s must exceed ``cfg.min_nyquist_factor`` times the top of the
    omega_1 band ``band_top`` (rad/s): the sampling at least :func:`slowest_sample_rate`.
    """
    nyquist = math.pi / sample_period
    if nyquist < cfg.min_nyquist_factor * band_top:
        # stamps in ms, us or ns read as s: 1e3, 1e6 or 1e9 times a period that in s would do
        unit = stamps_unit(
            lambda factor: (
                factor * nyquist >= cfg.min_nyquist_factor * band_top
                and sample_period >= 0.5 * factor / 1e3
            )
        )
        rate = slowest_sample_rate(band_top, cfg)
        return (
            f"sample period {sample_period:g} s: the Nyquist frequency {nyquist:.0f} rad/s is "
            f"below {cfg.min_nyquist_factor:g} times the top of the omega_1 band "
            f"({band_top:.0f} rad/s)"
            + (
                f" (time stamps in {unit}? the format's are in s)"
                if unit
                else f": this link needs samples at {math.ceil(rate)} Hz or faster"
            )
        )
    return None


def dead_channel(force: FloatArray, torque: FloatArray) -> str | None:
    """Why the sensor samples cannot be used (every component of force or torque constant over
    them, a sensor not working), or None. ``force``, ``torque``: shape (n, 3)."""
    for name, values in (("force", force), ("torque", torque)):
        if values.shape[0] < 2 or np.any(np.ptp(values[:_FIRST_LOOK], axis=0) > 0.0):
            continue  # a component that moves within the first samples: not all constant
        if np.all(np.ptp(values, axis=0) == 0.0):
            return f"{name}: every component is constant over the recording (sensor not working)"
    return None


#: Samples :func:`dead_channel` looks at first: a working sensor's noise moves them.
_FIRST_LOOK = 64


#: Most samples :func:`fill_missing` puts back in one step of the time stamps: 100,000 (100 s at
#: 1 kHz, far longer than a manoeuvre). A longer step is an outlier time stamp, whose filling
#: would take memory without bound.
MAX_FILLED = 100_000


#: Jitter allowed to a step that lost samples (periods): a step of at least k - 0.25 periods
#: counts as k (k - 1 samples missing). A sample lost with the stamps' jitter steps by 2 +- 0.25
#: periods, while a stamp taken late after one taken early (a stream whose stamps jitter by a
#: third of a period) steps by up to 1.67: filled, it would add a sample that never was and put
#: every later instant a period late. Long steps are counted the same way. A stream placed on
#: its grid as it arrives (:func:`fill_missing`) counts its steps from the grid instead.
STEP_JITTER = 0.25

#: Share of each time stamp's offset from the stream's grid by which the grid moves towards it
#: once it has placed as many samples (:class:`StreamGrid`): it averages the stamps' jitter over
#: about 1 / GRID_GAIN samples.
GRID_GAIN = 1.0 / 8.0

#: Share of each time stamp's offset from the grid by which the grid's period moves towards the
#: stamps' (:func:`fill_missing`), so that the grid follows a clock whose period is off the
#: declared one without lagging behind it: on simulated streams (5 % of samples lost, uniform
#: jitter of up to 0.3 periods) every sample kept its place with a clock up to 2 % off; with
#: the period held, a grid following by a 32nd slipped from 0.5 % off.
GRID_PERIOD_GAIN = 1.0 / 512.0


#: A step of the time stamps longer than this many sample periods is an outlier stamp: it would
#: miss more than :data:`MAX_FILLED` samples (:func:`samples_missing`).
OUTLIER_PERIODS = MAX_FILLED + 1 - STEP_JITTER


def samples_missing(steps: FloatArray, sample_period: float) -> FloatArray:
    """Samples missing in each time step (s, any shape) of a stream sampled at
    ``sample_period`` (s): k - 1 for a step of at least k - :data:`STEP_JITTER` periods
    (k >= 2), else 0 (also for a step that is not finite)."""
    with np.errstate(invalid="ignore", over="ignore"):
        missing = np.floor(np.asarray(steps, dtype=np.float64) / sample_period + STEP_JITTER)
    return np.where(np.isfinite(missing) & (missing > 1.0), missing - 1.0, 0.0)


@dataclass(frozen=True)
class FilledSamples:
    """A block of samples with the missing ones put back (:func:`fill_missing`).

    Attributes
    ----------
    t : array, shape (N,)
        Time stamps (s): the block's own, and between two that step by k sample periods
        (:func:`samples_missing`), k - 1 more at equal steps.
    values : array, shape (N, m)
        The block's values, and the filled samples' by linear interpolation between the
        samples on either side (the previous block's last for the first step).
    origin : array of int, shape (N,)
        For each sample, the block's sample it came with: its own index, or for a filled one
        the index of the sample after its gap (which revealed it).
    filled : array of bool, shape (N,)
        True for the samples put back.
    gaps : tuple of (float, float)
        The steps (s, s) that missed more than ``max_gap`` samples: filled, but too long to be
        read as the signal (:func:`gap_problem`).
    gap_starts : array of int, shape (len(gaps),)
        Where each of ``gaps`` begins among the N samples: its first sample put back.
    taken : int
        The block's samples these hold: all of them, or those before a ``jump``; ``late``
        of them left out.
    jump : str or None
        Why the samples from ``taken`` on cannot be put on the grid: a step missing more than
        :data:`MAX_FILLED` samples, or one beyond any number (an outlier time stamp).
    grid : StreamGrid or None
        The grid after the block's last sample placed (None for an empty block at a stream's
        start).
    late_at : array of int, shape (k,)
        For each of the block's samples left out for a place already taken (a repeated or
        late stamp), how many of the N samples come before it.
    """

    t: FloatArray
    values: FloatArray
    origin: NDArray[np.intp]
    filled: NDArray[np.bool_]
    gaps: tuple[tuple[float, float], ...] = ()
    gap_starts: NDArray[np.intp] = field(default_factory=lambda: np.zeros(0, dtype=np.intp))
    taken: int = 0
    jump: str | None = None
    grid: StreamGrid | None = None
    late_at: NDArray[np.intp] = field(default_factory=lambda: np.zeros(0, dtype=np.intp))


class StreamGrid(NamedTuple):
    """The grid a stream's samples are placed on as they arrive (:func:`fill_missing`).

    Attributes
    ----------
    point : float
        The grid point (s) of the last sample placed.
    period : float
        The grid's period (s): the declared one at first, then following the stamps'.
    placed : int
        Samples placed so far: the first ones move the grid by the mean of their offsets
        (1 / (placed + 1)), the later by :data:`GRID_GAIN`.
    """

    point: float
    period: float
    placed: int = 0

    def next(self, stamp: float) -> StreamGrid | None:
        """The grid once a sample stamped ``stamp`` (s) took the next place, or None when it
        lands elsewhere (after a gap, late, an outlier: :func:`fill_missing` places it)."""
        step = (stamp - self.point) / self.period
        if not 0.5 < step < 1.5:  # round(step) != 1, and False for NaN
            return None
        error = stamp - (self.point + self.period)
        gain = max(GRID_GAIN, 1.0 / (self.placed + 1))
        return StreamGrid(
            self.point + (self.period + gain * error),
            self.period + GRID_PERIOD_GAIN * error,
            self.placed + 1,
        )


@njit(cache=True)
def _grid_places(
    t: FloatArray, point: float, period: float, placed: int, gain: float, period_gain: float
) -> tuple[FloatArray, NDArray[np.int64], float, float, int]:
    """Each stamp's step from the grid point before it (grid periods), the grid steps it is
    placed at (round of that; 0 or less: a stamp at or before a place taken, a late sample),
    and the grid's last point (s), period (s) and count of samples placed
    (:class:`StreamGrid`, :func:`fill_missing`)."""
    n = t.shape[0]
    periods = np.empty(n)
    places = np.empty(n, dtype=np.int64)
    for i in range(n):
        step = (t[i] - point) / period
        periods[i] = step
        if not (np.isfinite(step) and step <= OUTLIER_PERIODS):
            places[i] = 1  # judged by the caller (an outlier ends the block)
            point += period
            continue
        k = round(step)
        places[i] = k
        if k >= 1:
            error = t[i] - (point + k * period)
            point += k * period + max(gain, 1.0 / (placed + 1)) * error
            period += period_gain * error / k
            placed += 1
    return periods, places, point, period, placed


def _placed(t: FloatArray, grid: StreamGrid) -> tuple[FloatArray, NDArray[np.int64], StreamGrid]:
    """:func:`_grid_places` on ``grid``: the steps, the places and the grid after them."""
    periods, places, point, period, placed = _grid_places(
        t, grid.point, grid.period, grid.placed, GRID_GAIN, GRID_PERIOD_GAIN
    )
    return periods, places, StreamGrid(point, period, placed)


def grid_steps(t: FloatArray, sample_period: float) -> FloatArray:
    """The grid periods between consecutive time stamps ``t`` (s, shape (n,), n >= 1) as
    :func:`fill_missing` places them on a new grid of ``sample_period`` (s): shape (n - 1,),
    at least 1 each (a late stamp counted as the next place)."""
    t = np.asarray(t, dtype=np.float64)
    _, places, _ = _placed(t, StreamGrid(float(t[0]) - sample_period, sample_period))
    return np.maximum(places[1:], 1).astype(np.float64)


#: The stream's period may differ from its declared one by this many standard errors of the
#: line through its first stamps (between ``CLOCK_TOLERANCE`` and ``PERIOD_CONSISTENCY``).
_PERIOD_SIGMAS = 8.0

#: Fewest steps whose median number of periods must be one (more are dropped samples or a
#: period declared too short); fewer cannot tell.
MIN_STEPS_FOR_DROPS = 5


def _period_of_line(stamps: FloatArray, countings: list[FloatArray]) -> tuple[float, float]:
    """The slope (s) of the least-squares line through ``stamps`` (shape (n,), n >= 2) against
    their sample numbers, those numbered by the one of ``countings`` (periods of each step,
    shape (n - 1,)) the line fits best, and its standard error (s; 0 for two stamps)."""
    best = (math.inf, math.nan, 0.0)
    relative = stamps - stamps[0]
    for periods in countings:
        number = np.concatenate([[0.0], np.cumsum(periods)])
        number -= number.mean()
        spread = float(number @ number)
        slope = float(number @ relative / spread)
        misfit = relative - relative.mean() - slope * number
        residual = float(misfit @ misfit)
        error = math.sqrt(residual / (stamps.shape[0] - 2) / spread) if stamps.shape[0] > 2 else 0.0
        best = min(best, (residual, slope, error))
    return best[1], best[2]


def declared_period_refused(sample_period: float, problem: str) -> str:
    """The ``bad_input`` reason of a stream whose time stamps do not step by the
    ``sample_period`` (s) it declared, ``problem`` saying how
    (:func:`declared_period_problem`, :func:`stream_period_problem`)."""
    return (
        f"sample_period: declared {sample_period!r} s, but {problem}: the estimates need the"
        " period the samples have"
    )


def stream_period_problem(
    stamps: FloatArray, places: NDArray[np.int64], sample_period: float
) -> str | None:
    """Why the time stamps a stream has sent so far (s, shape (n,), n >= 3) do not step by the
    ``sample_period`` (s) declared before they came, or None, their grid places (``places``,
    shape (n,), increasing: dropped samples skipped) numbering them.

    The period is the slope of the least-squares line through the stamps against their places,
    the stamps' jitter averaging out over the line; it must lie within ``CLOCK_TOLERANCE`` of
    the declared one, or as many more of the line's standard errors as the first stamps are
    given (``_PERIOD_SIGMAS``), up to ``PERIOD_CONSISTENCY``. Read at the estimate, on a
    second or more of samples, it sees a clock a few per mille off that the first stamps' line,
    their jitter comparable with the offset, cannot: a frequency read on samples taken as one
    period apart is off by as much as the two clocks disagree. The places are those the samples
    were given (:func:`fill_missing`), so places miscounted where the stamps jitter by nearly
    half a period show as well.
    """
    stamps = np.asarray(stamps, dtype=np.float64)
    ts = sample_period
    period, error = _period_of_line(stamps, [np.diff(places).astype(np.float64)])
    tolerance = min(PERIOD_CONSISTENCY, max(CLOCK_TOLERANCE, _PERIOD_SIGMAS * error / ts))
    if abs(period - ts) <= tolerance * ts * (1.0 + 1e-9):
        return None
    return (
        f"a line through its {stamps.shape[0]} time stamps up to {float(stamps[-1]):.3f} s steps"
        f" by {period:.6g} s ({100 * (period / ts - 1):+.2f} %), more than"
        f" {100 * tolerance:.2g} % off: a frequency read on them would be as far off"
    )


def declared_period_problem(stamps: FloatArray, sample_period: float) -> str | None:
    """Why a stream's first time stamps (s, shape (n,), 2 <= n <= :data:`PERIOD_CHECK_STEPS`
    + 1) do not step by the ``sample_period`` (s) declared before they came, or None.

    A dropped sample is a step of whole periods (:func:`samples_missing`), but most steps are
    one period: from :data:`MIN_STEPS_FOR_DROPS` steps on, a median of more means the period
    was declared too short, judged within ``PERIOD_CONSISTENCY``. Otherwise the period is the
    slope of the stamps against their sample numbers, each stamp's jitter averaging out over
    the line (it stays in a median of steps), the drops counted as the line fits the stamps
    best. It must lie within ``CLOCK_TOLERANCE`` of the declared one (a file's stamps are
    trusted over its period beyond it), or as much more as the stamps' jitter leaves the line
    uncertain, up to ``PERIOD_CONSISTENCY``; fewer stamps than the full count cannot tell
    their jitter and are judged within ``PERIOD_CONSISTENCY``.
    """
    stamps = np.asarray(stamps, dtype=np.float64)
    steps = stamps.shape[0] - 1
    ts = sample_period
    step = np.diff(stamps)
    periods = 1.0 + samples_missing(step, ts)
    tolerance = PERIOD_CONSISTENCY
    if steps >= MIN_STEPS_FOR_DROPS and float(np.median(periods)) != 1.0:
        period, how = float(np.median(step)), f"the median of its first {steps} steps"
    else:
        # a step of 1.6 periods is a late stamp after an early one, or a lost sample with
        # jitter, and only the others tell which (the estimator's grid tells from them all)
        countings = [periods, np.maximum(np.rint(step / ts), 1.0), grid_steps(stamps, ts)]
        period, error = _period_of_line(stamps, countings)
        how = f"a line through its first {steps + 1} time stamps"
        if steps == PERIOD_CHECK_STEPS:
            tolerance = min(tolerance, max(CLOCK_TOLERANCE, _PERIOD_SIGMAS * error / ts))
        if abs(period - ts) <= tolerance * ts * (1.0 + 1e-9):  # a stamp's last bit aside
            return None
    # stamps in ms (us, ns) read as seconds: 1000 (1e6, 1e9) times the period
    unit = stamps_unit(lambda factor: abs(period / ts - factor) <= 0.01 * factor)
    jitter = ""
    spread = float(np.max(step) - np.min(step)) if steps else 0.0
    if not unit and spread >= 0.6 * ts:
        # single steps that far apart are stamps jittering by a large part of a period
        jitter = (
            f" (its steps spread from {float(np.min(step)):.3g} to {float(np.max(step)):.3g} s:"
            " stamps that jitter by a large part of a period?)"
        )
    return (
        f"its time stamps step by {period:.6g} s ({how}), more than {100 * tolerance:.2g} %"
        " apart" + (f" (time stamps in {unit}? the format's are in s)" if unit else jitter)
    )


class DeclaredPeriodCheck:
    """A stream's first time stamps, kept until :func:`declared_period_problem` can judge them
    against the ``sample_period`` (s) declared before they came: judged once, on the first
    :data:`~sensing_antenna.recording.PERIOD_CHECK_STEPS` steps, or at the stream's end on
    those a shorter one has."""

    def __init__(self, sample_period: float) -> None:
        self.sample_period = sample_period
        self._stamps: list[float] = []
        self.judged = False

    def feed(self, times: FloatArray, final: bool = False) -> str | None:
        """Keep the time stamps ``times`` (s, shape (n,)) the check needs and, once it has
        them (``final``: the stream ended, two stamps at least), judge them: the problem, else
        None; None too before and after that one judgement."""
        if self.judged:
            return None
        self._stamps.extend(times[: PERIOD_CHECK_STEPS + 1 - len(self._stamps)].tolist())
        if len(self._stamps) < (2 if final else PERIOD_CHECK_STEPS + 1):
            return None
        self.judged = True
        return declared_period_problem(np.asarray(self._stamps), self.sample_period)


def fill_missing(
    t: FloatArray,
    values: FloatArray,
    sample_period: float,
    max_gap: int,
    previous: tuple[float, FloatArray] | None = None,
    grid: StreamGrid | None = None,
) -> FilledSamples:
    """The samples of a stream with those it missed put back on its grid, as they arrive.

    Each sample is placed on the stream's grid, of ``sample_period`` at first: the nearest grid
    point after the previous sample's, k periods on (its step from that point, rounded). The
    grid follows the stamps by :data:`GRID_GAIN` of each one's offset (by their mean over the
    first few) and its period by :data:`GRID_PERIOD_GAIN`, so that the stamps' jitter does not
    move it, nor a sample lost between a stamp taken late and one taken early hide, and a clock
    off the declared period is followed (:class:`StreamGrid`).
    Where a sample lands k >= 2 periods on, the k - 1 samples between are filled in by linear
    interpolation, at equal steps, as reading a whole recording resamples it onto its grid
    (:func:`~sensing_antenna.recording.resample_uniform`): every step of the front end reads
    the samples as uniform, so a missing one left out would shift every instant after it by a
    period (a stream missing one sample in 20 reads its vibration 5 % fast). A sample whose
    place is taken (a stamp repeated, or late after the next one) is left out and counted
    (``late``). A filled sample depends on the sample after its gap: it is known when that one
    arrives.

    Parameters
    ----------
    t : array, shape (n,)
        Time stamps (s), increasing.
    values : array, shape (n, m)
        The samples' values (any units).
    sample_period : float
        Nominal T_s (s).
    max_gap : int
        Steps missing more than this many samples are also reported as gaps.
    previous : (float, array of shape (m,)), optional
        The sample before the block (its time stamp and values); None at a stream's start.
    grid : StreamGrid, optional
        The grid after the sample before the block (the last block's ``grid``); None: a new
        one, of ``sample_period``, whose first place is the block's first stamp (or
        ``previous``'s).

    Returns
    -------
    FilledSamples
        The block itself (the same arrays) when no sample is missing or late; up to the first
        outlier step (``jump``) when there is one; ``grid``, the last sample's grid point.
    """
    t = np.asarray(t, dtype=np.float64)
    values = np.asarray(values, dtype=np.float64)
    n = t.shape[0]
    if grid is None and n:
        start = t[0] - sample_period if previous is None else previous[0]
        grid = StreamGrid(float(start), sample_period, 0 if previous is None else 1)
    if grid is None or n == 0:
        return FilledSamples(
            t, values, np.zeros(0, dtype=np.intp), np.zeros(0, dtype=bool), grid=grid
        )
    periods, places, last = _placed(t, grid)
    point = grid.point
    # beyond any filling, or beyond any number (finite stamps whose step overflows)
    with np.errstate(invalid="ignore"):
        outlier = (periods > OUTLIER_PERIODS) & np.isfinite(t) & np.isfinite(point)
    jump = None
    taken = n
    if np.any(outlier):
        taken = int(np.argmax(outlier))
        before = point if previous is None else float(previous[0])
        if taken:
            before = float(t[taken - 1])
        jump = (
            f"time jumps from {before!r} to {float(t[taken])!r} s, "
            f"{periods[taken]:.4g} sample periods of {sample_period!r} s in one "
            f"step: an outlier time stamp (at most {MAX_FILLED} missing samples are filled)"
        )
        _, _, last = _placed(t[:taken], grid)
    kept = np.flatnonzero(places[:taken] >= 1).astype(np.intp)
    late = np.flatnonzero(places[:taken] < 1).astype(np.intp)
    missing = places[kept].astype(np.float64) - 1.0
    if late.size == 0 and not np.any(missing > 0.0):
        own = np.arange(taken, dtype=np.intp)
        if taken < n:
            t, values = t[:taken], values[:taken]
        return FilledSamples(
            t,
            values,
            own,
            np.zeros(taken, dtype=bool),
            taken=taken,
            jump=jump,
            grid=last,
        )
    t, values, own = t[kept], values[kept], kept
    if previous is None:
        left_t, left_values = np.concatenate([t[:1], t[:-1]]), np.vstack([values[:1], values[:-1]])
    else:
        left_t = np.concatenate([[previous[0]], t[:-1]])
        left_values = np.vstack([np.asarray(previous[1], dtype=np.float64), values[:-1]])
    if not np.any(missing > 0.0):
        return FilledSamples(
            t,
            values,
            own,
            np.zeros(t.shape[0], dtype=bool),
            taken=taken,
            jump=jump,
            grid=last,
            late_at=np.searchsorted(own, late).astype(np.intp),
        )
    counts = missing.astype(np.intp) + 1
    origin = np.repeat(own, counts)
    step_of = np.repeat(np.arange(own.shape[0]), counts)  # each output's step among the kept
    ends = np.cumsum(counts)  # one past each own sample's place among the output
    # position of each output sample within its step: 1 .. counts, the block's own at counts
    within = np.arange(origin.shape[0]) - np.repeat(ends - counts, counts) + 1
    fraction = within / np.repeat(counts, counts)
    is_own = within == np.repeat(counts, counts)
    start_t, start_values = left_t[step_of], left_values[step_of]
    filled_t = np.where(is_own, t[step_of], start_t + fraction * (t[step_of] - start_t))
    filled_values = np.where(
        is_own[:, None],
        values[step_of],
        start_values + fraction[:, None] * (values[step_of] - start_values),
    )
    long_steps = np.flatnonzero(missing > max_gap)
    return FilledSamples(
        filled_t,
        filled_values,
        origin,
        ~is_own,
        tuple((float(left_t[k]), float(t[k])) for k in long_steps),
        (ends[long_steps] - counts[long_steps]).astype(np.intp),
        taken,
        jump,
        last,
        np.searchsorted(origin, late).astype(np.intp),
    )


def time_gaps(t: FloatArray, sample_period: float, max_gap: int) -> tuple[tuple[float, float], ...]:
    """Intervals (s) between consecutive time stamps that miss more than ``max_gap`` samples.

    Parameters
    ----------
    t : array, shape (n,)
        Original (not resampled) time stamps (s).
    sample_period : float
        Nominal T_s (s).
    max_gap : int
        Largest number of missing samples in a row that linear interpolation may fill.
    """
    missing = samples_missing(np.diff(np.asarray(t, dtype=float)), sample_period)
    where = np.flatnonzero(missing > max_gap)
    return tuple((float(t[k]), float(t[k + 1])) for k in where)


def gap_problem(
    gaps: Sequence[tuple[float, float]], t_c: float, t_e: float, sample_period: float, max_gap: int
) -> str | None:
    """The first of ``gaps`` (each longer than ``max_gap`` samples) overlapping [t_c, t_e],
    described, or None.

    From t_c the estimators read the push (its direction, the head's stop that fixes t_1, the
    hold's static loads) and after t_1 the vibration (tens to hundreds of rad/s); a straight
    line across a long gap replaces a large part of a period or more, or looks like the head at
    rest where it was still moving, and the steps after it read a signal that was never there.
    """
    overlapping = [(start, end) for start, end in gaps if end > t_c and start < t_e]
    if not overlapping:
        return None
    start, end = overlapping[0]
    missing = round((end - start) / sample_period) - 1
    within = (
        "; the contact was found inside the gap, on the straight line that fills it: "
        "it may be the gap's jump, not a touch"
        if start <= t_c <= end
        else ""
    )
    # one step of 1000 (1e6, 1e9) periods: a stamp in ms (us, ns) read as seconds
    steps = (end - start) / sample_period
    unit = stamps_unit(lambda factor: abs(steps - factor) <= 0.01 * factor)
    return (
        f"t: {missing} samples missing between {start:.4f} s and {end:.4f} s, inside "
        f"the estimation window [{t_c:.3f}, {t_e:.3f}] s from the contact (at most "
        f"{max_gap} in a row are filled in){within}"
        + (f" (time stamps in {unit}? the format's are in s)" if unit else "")
    )


#: Where the sensor offset was read: "rest" (the head still before the contact), "approach"
#: (the approach's loads, the recording starting in motion) or "none" (too few samples to read
#: it: the loads are taken as they are).
TareKind = Literal["rest", "approach", "none"]


@dataclass(frozen=True)
class ContactStart:
    """What is fixed at the contact sample: rest tolerance (rad, peak-to-peak; ``rest_drift``,
    across the hold, inf when not judged: :func:`.contact_frame.first_rest_index`), sensor
    offset (N, N m), the kind of tare and the number of samples it averaged on each channel
    (fx, fy, fz, tx, ty, tz), and the units check of the samples up to t_c: ``input_problem``
    (why the recording's loads or angles are not in the format's units and signs, None when
    they are) and ``checks`` (its numbers, for the diagnostics)."""

    rest_tolerance: float
    offset: FloatArray
    tare: TareKind
    counts: tuple[int, ...]
    input_problem: str | None = None
    checks: dict[str, Any] = field(default_factory=dict)
    rest_drift: float = math.inf


def at_contact(
    theta: FloatArray,
    force: FloatArray,
    torque: FloatArray,
    antenna: Antenna,
    contact_index: int,
    cfg: EstimatorConfig,
    ts: float,
    predicted_torque: FloatArray | None = None,
) -> ContactStart:
    """Rest tolerance, sensor offset and units check from the samples up to t_c (both forms call
    this). ``predicted_torque`` (n, 3) is the contact detector's free-motion torque
    Gamma_e^m + Gamma_g^m (N m) up to t_c, for :func:`free_motion_gain`."""
    before = slice(0, contact_index + 1)
    tolerance = rest_tolerance(theta[before], cfg)
    w_rest = samples(cfg.rest_window, ts)
    drift = rest_drift_tolerance(theta[before], cfg, tolerance, w_rest, hold_samples(cfg, ts), ts)
    quiet = initial_rest(theta[before], tolerance)
    problems: list[str] = []
    checks: dict[str, Any] = {}
    if predicted_torque is not None:
        gain, problem = free_motion_gain(
            theta[before],
            torque[before],
            predicted_torque[before],
            antenna,
            cfg,
            starts_at_rest=quiet >= w_rest + 1,
        )
        checks["free_motion_gain"] = gain
        if problem is None and quiet >= w_rest + 1:
            # the observer starts from rest: a record that starts in motion misleads it, and
            # one joint's share can then read low for right columns; both checks judge the
            # samples where the link is free of the contact, up to the tare's margin before t_c
            free = contact_index + 1 - samples(cfg.tare_margin, ts)
            gains, problem = joint_free_motion_gains(
                theta[before],
                torque[before],
                predicted_torque[before],
                antenna,
                cfg,
                stop=free,
                tolerance=tolerance,
            )
            checks["joint_free_motion_gains"] = gains
            if problem is None:
                ratio, problem = still_angles_turn(
                    theta[before],
                    torque[before],
                    antenna,
                    cfg,
                    stop=free,
                    tolerance=tolerance,
                    window=w_rest,
                )
                checks["still_angles_turn"] = ratio
        if problem is not None:
            problems.append(problem)
    angles = angle_problem(theta[before])
    if angles is not None:
        # first: a push judged on angles that are no head's is no push (degrees, a glitch)
        problems.insert(0, angles)
    if quiet >= w_rest + 1:
        # The head rests at the start: the link hangs still, the mean load is the offset; a
        # coarse encoder sees the sweep start late, the loads see it at once
        seen = min(quiet + w_rest, contact_index + 1)  # a load that left by quiet shows by then
        settled = settled_loads(theta[:seen], force[:seen], torque[:seen], antenna, w_rest)
        counts = tuple(int(c) for c in np.minimum(quiet, np.maximum(settled, w_rest + 1)))
        tare: TareKind = "rest"
        where = "at rest before the contact"
    else:
        end = contact_index - samples(cfg.tare_margin, ts)
        counts, tare = (max(end, 0),) * 6, "approach"
        where = "of the approach before the contact"
        if end < w_rest + 1:
            return ContactStart(
                tolerance, np.zeros(6), "none", (0,) * 6, _joined(problems), checks, drift
            )
    # the rest's reading judges the samples every channel counts as rest
    common, longest = slice(0, min(counts)), slice(0, max(counts))
    reading = rest_reading(theta[common], force[common], torque[common], antenna, where)
    checks["rest_reading"] = reading.as_dict()
    if reading.problem is not None:
        problems.insert(0, reading.problem)
    offset = load_offset(theta[longest], force[longest], torque[longest], antenna, counts)
    return ContactStart(tolerance, offset, tare, counts, _joined(problems), checks, drift)


def settled_loads(
    theta: FloatArray, force: FloatArray, torque: FloatArray, antenna: Antenna, window: int
) -> NDArray[np.int64]:
    """Number of samples at the start over which each contact-load channel holds its level.

    The head's angles say when it rests only to within the rest tolerance, which a coarse or
    flickering encoder makes several counts wide: the sweep's start then counts as rest while
    the link's inertia already loads the sensor, and a tare over it holds that load. Here the
    loads R = F - F_g^m and Gamma - Gamma_g^m, averaged over each ``window`` samples, are
    compared with their mean over all the samples before that window: a channel's rest ends
    where a run of windows begins that each lie more than :data:`SETTLED_ERRORS` standard
    errors of such a mean from it (the channel's white noise over sqrt(window)) and that lasts
    to the last sample, when the load went one way only against the mean before that run's
    first window; or where the first departing window begins when the load went one way only
    from there (a sweep's short start that loaded the sensor and let go before the angles
    moved). Each channel keeps its own: the turn's start shows at once in the torque about the
    turning axis, while its share in the forces stays under their noise, and a channel's tare is
    the longer for it. A link that rings at rest swings both ways about its level, and keeps
    its rest. Shapes (n, 2), (n, 3), (n, 3); returns shape (6,) for (fx, fy, fz, tx, ty, tz), n
    for a channel that ends at its level, or whose level was not held over one and a half
    windows (a link ringing from the start).
    """
    n = theta.shape[0]
    ends = np.full(6, n, dtype=np.int64)
    if window < 1 or n < 2 * window:
        return ends
    reaction, moment = contact_loads(theta, force, torque, antenna)
    loads = np.hstack([reaction, moment])
    # the noise of the loads compared (an angle's flicker reaches them through the weight); a
    # sensor quieter than its resolution reads a zero noise: half a count then, the spread of a
    # reading that flickers between two counts; a channel that never changes has no limit
    noises = [
        max(signal_noise(part)[0], signal_noise(raw)[1] / 2.0)
        for part, raw in ((reaction, force), (moment, torque))
    ]
    per_channel = np.repeat(noises, 3)
    limits = np.where(per_channel > 0.0, per_channel * SETTLED_ERRORS / math.sqrt(window), np.inf)
    total = np.vstack([np.zeros((1, 6)), np.cumsum(loads, axis=0)])
    starts = np.arange(window, n - window + 1)  # each window [s, s + window), s samples before
    windows = (total[starts + window] - total[starts]) / window
    before = total[starts] / starts[:, np.newaxis]
    with np.errstate(invalid="ignore"):
        left = np.abs(windows - before) > limits
    # a level is trusted once it held over one and a half rest windows: the first comparisons,
    # against a mean of fewer samples, are those the record's first samples bias most (the last
    # manoeuvre's ringing, which a sweep's start never precedes by less than a rest window)
    trusted = 2 * starts >= 3 * window
    for channel in map(int, np.flatnonzero((left & trusted[:, np.newaxis]).any(axis=0))):
        runs = left[:, channel]
        first = int(np.argmax(runs))
        if trusted[first] and _one_way(total, windows, starts, first, channel, limits[channel]):
            # a sweep's start, or a pulse that came and went before the angles moved
            ends[channel] = starts[first]
        elif runs[-1] and not runs.all():
            # away at the end after swinging both ways: the last run of departures, if the
            # load went one way from where it began (a sweep that started while the link rang)
            last = int(np.flatnonzero(~runs)[-1]) + 1
            if trusted[last] and _one_way(total, windows, starts, last, channel, limits[channel]):
                ends[channel] = starts[last]
    return ends


def _one_way(
    total: FloatArray,
    windows: FloatArray,
    starts: NDArray[np.int64],
    first: int,
    channel: int,
    limit: float,
) -> bool:
    """Whether the window means of a load (``windows``, rest windows starting at ``starts``)
    from the ``first`` on left the mean of the samples before it (``total``: cumulative sums)
    on one side only, by more than ``limit``; a link ringing about its level swings both
    ways."""
    start = int(starts[first])
    away = windows[first:, channel] - total[start, channel] / start
    return not (away.max() > limit and away.min() < -limit)


def _joined(problems: list[str]) -> str | None:
    return "; ".join(problems) if problems else None


def free_motion_gain(
    theta: FloatArray,
    torque: FloatArray,
    predicted_torque: FloatArray,
    antenna: Antenna,
    cfg: EstimatorConfig,
    starts_at_rest: bool = True,
) -> tuple[float, str | None]:
    """How large the measured coupling torque before t_c is against the observer's prediction.

    The observer of Eq. 15 predicts, from the angles, the torque the link exerts on the head
    while the head turns in free motion; a recording in the format's units reads at least that
    torque. The gain is the ratio of root-mean-square values over the samples up to t_c of the
    measured dynamic torque m = Gamma - Gamma_g^m and the predicted one p = Gamma_e^m (Y^m and
    Z^m, each less its mean): about 1 in free motion, more when the touch builds up torque
    before t_c, 1/57 with angles in degrees (the observer then predicts 57 times the torque).
    Only a gain below 1 / ``free_motion_gain_factor`` is a problem: the contact's torque before
    t_c can only raise it, and torques too large are the rest reading's to find. The sensor's
    noise raises it too, where the predicted torque is not far above it (a contact detected
    early in the turn: a tight threshold crossed by degrees' prediction itself). So a gain
    below 1 is also judged by the measured torque projected on the predicted one, sum(m p) /
    sum(p^2), which the noise does not bias: three of its standard errors (the noise over the
    predicted torque's norm) above it must still lie below 1 / ``free_motion_gain_factor``.

    Parameters
    ----------
    theta : array, shape (n, 2)
        Angles up to t_c (rad).
    torque, predicted_torque : array, shape (n, 3)
        Measured torque and the detector's Gamma_e^m + Gamma_g^m up to t_c (N m).
    antenna : Antenna
    cfg : EstimatorConfig
    starts_at_rest : bool
        Whether the samples begin with the head at rest. The observer starts from rest: a
        record that starts in motion gives it a start it never had, which the first free motion
        then misreads, and the problem names that cause too.

    Returns
    -------
    (gain, problem) : tuple of float and str or None
        The ratio of root-mean-square values, or the projection when it finds the problem the
        ratio misses; NaN when the observer predicts no motion (nothing to compare).
        ``problem`` names the columns and the gain.
    """
    predicted_axes, measured_axes = _dynamic_rms(theta, torque, predicted_torque, antenna)
    with np.errstate(over="ignore", invalid="ignore"):
        predicted_rms = float(np.sqrt(np.mean(predicted_axes**2)))
        measured_rms = float(np.sqrt(np.mean(measured_axes**2)))
    if not (math.isfinite(predicted_rms) and predicted_rms > 0.0):
        return math.nan, None
    gain = measured_rms / predicted_rms
    factor = cfg.free_motion_gain_factor
    if math.isfinite(gain) and 1.0 / factor <= gain < 1.0:
        projected, error = _projected_gain(theta, torque, predicted_torque, antenna)
        if projected + 3.0 * error < 1.0 / factor:
            gain = projected
    if not math.isfinite(gain) or gain >= 1.0 / factor:
        return gain, None
    return gain, (
        f"columns 'theta1', 'theta2', 'ty', 'tz': the torque of the free motion before the "
        f"contact is {gain:.3g} times what the observer predicts from the angles (at least "
        f"1/{factor:g}): angles not in radians (degrees give 1/57), or an antenna file whose "
        "observer is not this device's (antenna identify)"
        + (
            "?"
            if starts_at_rest
            else ", or a recording that does not start at rest (start it with the head still "
            "for half a second)?"
        )
    )


def _projected_gain(
    theta: FloatArray, torque: FloatArray, predicted_torque: FloatArray, antenna: Antenna
) -> tuple[float, float]:
    """The measured dynamic torque about Y^m and Z^m projected on the predicted one, each less
    its mean, and its standard error from the measured torque's white noise
    (:func:`~.contact_frame.signal_noise`); NaN without a prediction."""
    predicted = _weightless_moment(theta, predicted_torque, antenna)
    measured = _weightless_moment(theta, torque, antenna)
    with np.errstate(over="ignore", invalid="ignore"):
        p = predicted - predicted.mean(axis=0)
        m = measured - measured.mean(axis=0)
        norm = float(np.sum(p * p))
        if not (math.isfinite(norm) and norm > 0.0):
            return math.nan, math.nan
        return float(np.sum(m * p)) / norm, signal_noise(measured)[0] / math.sqrt(norm)


def _dynamic_rms(
    theta: FloatArray, torque: FloatArray, predicted_torque: FloatArray, antenna: Antenna
) -> tuple[FloatArray, FloatArray]:
    """Root-mean-square (N m) about Y^m and Z^m of the observer's predicted and of the measured
    torque, weight off, each less its mean (:func:`_rms_about_mean`); shapes (2,), (2,)."""
    return (
        _rms_about_mean(_weightless_moment(theta, predicted_torque, antenna)),
        _rms_about_mean(_weightless_moment(theta, torque, antenna)),
    )


def _came_and_went(moment: FloatArray, window: int) -> bool:
    """Whether a moment (N m, shape (n,)), averaged over ``window`` samples, made one excursion
    and came back: one peak or trough whose prominence is at least half the moment's range, and
    an end nearer its start than half its largest excursion from it. A turn's start loads the
    sensor one way and lets go; a touch builds its load up to t_c (no peak); a link left
    ringing swings to and fro (peaks and troughs)."""
    from scipy.ndimage import uniform_filter1d
    from scipy.signal import find_peaks

    if window < 1 or moment.shape[0] < 2 * window:
        return False
    smooth = uniform_filter1d(moment, window, mode="nearest")
    deviation = smooth - smooth[:window].mean()
    half = 0.5 * float(np.ptp(deviation))
    extrema = sum(find_peaks(sign * deviation, prominence=half)[0].size for sign in (1.0, -1.0))
    return bool(extrema == 1 and abs(deviation[-1]) <= 0.5 * float(np.max(np.abs(deviation))))


def _rms_about_mean(moment: FloatArray) -> FloatArray:
    """Root-mean-square (N m) of each column of ``moment`` (n, k) less its mean (the sensor's
    offset is not the link's inertia); shape (k,)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return np.sqrt(np.mean((moment - moment.mean(axis=0)) ** 2, axis=0))


def _weightless_moment(theta: FloatArray, torque: FloatArray, antenna: Antenna) -> FloatArray:
    """A torque about Y^m and Z^m less the link's weight moment (N m), shape (n, 2)."""
    gravity = antenna.gravity_torque(np.asarray(theta, dtype=float)[:, 1])
    with np.errstate(over="ignore", invalid="ignore"):
        return (np.asarray(torque, dtype=float) - gravity)[:, 1:]


#: Each joint's angle column and the torque column its turn acts on, and that torque's index in
#: (Y^m, Z^m): the azimuth theta1 turns the head about Z^m, the elevation theta2 about Y^m.
_JOINTS = (("theta1", "tz", 1), ("theta2", "ty", 0))


def joint_free_motion_gains(
    theta: FloatArray,
    torque: FloatArray,
    predicted_torque: FloatArray,
    antenna: Antenna,
    cfg: EstimatorConfig,
    stop: int,
    tolerance: float,
) -> tuple[tuple[float, float], str | None]:
    """How large the measured free-motion torque is against the observer's, joint by joint.

    :func:`free_motion_gain` judges the torques about Y^m and Z^m together; an angle column
    copied from the other joint's (the head seems to turn both joints when it turned one) or
    the two columns swapped keep that sum and move it to the other axis. Here each joint's
    torque is judged on its own over the samples before ``stop``, where the link is free of the
    contact (t_c less ``tare_margin``, the tare's own margin). A joint that turned (by more
    than the rest tolerance) and whose turn the observer predicts a torque for, at least
    1 / ``free_motion_gain_factor`` of the other joint's, and
    that shows less than 1 / ``free_motion_gain_factor`` of it, is named when the other joint's
    torque does show (a copy), or when the other axis shows the torque of this turn (a swap); a
    turn whose torque shows on neither axis is :func:`free_motion_gain`'s to name.

    Parameters
    ----------
    theta, torque, predicted_torque, antenna, cfg
        As :func:`free_motion_gain`.
    stop : int
        One past the last sample judged.
    tolerance : float
        The rest tolerance (rad, peak to peak): a joint whose angle stays within it did not
        turn, whatever torque the observer predicts from its encoder's flicker.

    Returns
    -------
    (gains, problem) : tuple of (float, float) and str or None
        Measured over predicted root-mean-square torque of theta1's turn and of theta2's (NaN
        for a joint not judged); ``problem`` names the joint's columns and its gain.
    """
    factor = cfg.free_motion_gain_factor
    if stop < 2:
        return (math.nan, math.nan), None
    axes = [axis for _, _, axis in _JOINTS]
    predicted_yz, measured_yz = _dynamic_rms(
        theta[:stop], torque[:stop], predicted_torque[:stop], antenna
    )
    predicted_rms, measured_rms = predicted_yz[axes], measured_yz[axes]
    largest = float(np.max(predicted_rms))
    if not (math.isfinite(largest) and largest > 0.0 and np.all(np.isfinite(measured_rms))):
        return (math.nan, math.nan), None
    turned = np.ptp(np.asarray(theta, dtype=float)[:stop], axis=0) > tolerance
    judged = turned & (predicted_rms >= largest / factor)
    with np.errstate(divide="ignore"):
        gains = np.where(judged, measured_rms / predicted_rms, math.nan)
    pair = (float(gains[0]), float(gains[1]))
    low = [k for k in range(2) if judged[k] and gains[k] < 1.0 / factor]
    if len(low) != 1:
        return pair, None  # both low is the sum's to name (angles in degrees)
    k = low[0]
    angle, column, _ = _JOINTS[k]
    other_angle, other_column, _ = _JOINTS[1 - k]
    if judged[1 - k]:
        # both joints turn, the other's torque is there and this one's is not
        cause = f"'{angle}' a copy of '{other_angle}', or read from another joint?"
    elif measured_rms[1 - k] >= predicted_rms[k] / factor:
        cause = f"the two angles swapped ('{other_column}' shows the turn '{angle}' describes)?"
    else:
        # one joint turns and no torque shows anywhere: the sum's to name (degrees, observer)
        return pair, None
    return pair, (
        f"columns '{angle}', '{column}': before the contact '{angle}' turns the head, but "
        f"'{column}' shows {gains[k]:.3g} times the torque the observer predicts for that turn "
        f"(at least 1/{factor:g}, from the link's inertia): {cause}"
    )


def still_angles_turn(
    theta: FloatArray,
    torque: FloatArray,
    antenna: Antenna,
    cfg: EstimatorConfig,
    stop: int,
    tolerance: float,
    window: int,
) -> tuple[float, str | None]:
    """Whether the torque before the contact shows a turn the angles do not.

    A head that turns loads the sensor with its link's inertia (about Z^m for theta1, Y^m for
    theta2) well above the sensor's noise, while a head that rests, or one an object is moved
    into, shows only noise before the touch. When neither angle leaves the rest tolerance over
    the samples before ``stop`` (the link free of the contact, as for
    :func:`joint_free_motion_gains`) and the torque about Y^m or Z^m, the link's weight and its
    mean taken off, varies by more than ``still_turn_factor`` times the sensor's white noise
    (root mean square against :func:`signal_noise`), and that load came and went (its mean over
    ``window`` samples makes one peak or trough and ends near its start), the angle columns are
    not this head's motion: the still joint's angle written over the turning one's, or a frozen
    column. A load still building at ``stop`` is not judged (an object moved slowly into a
    still link builds it so, from its touch to t_c), nor one that swings to and fro (a link
    left ringing).

    Parameters
    ----------
    theta : array, shape (n, 2)
        Angles up to t_c (rad).
    torque : array, shape (n, 3)
        Measured torque up to t_c (N m).
    antenna : Antenna
    cfg : EstimatorConfig
    stop : int
        One past the last sample judged.
    tolerance : float
        The rest tolerance (rad, peak to peak).
    window : int
        Samples the load is averaged over to judge whether it came and went (the rest window).

    Returns
    -------
    (ratio, problem) : tuple of float and str or None
        The larger axis's root-mean-square torque over the noise, NaN when not judged (a joint
        turned, fewer than 3 samples before ``stop``, or a load that did not come and go);
        ``problem`` names the columns.
    """
    theta = np.asarray(theta, dtype=float)[:stop]
    if theta.shape[0] < 3 or np.any(np.ptp(theta, axis=0) > tolerance):
        return math.nan, None
    torque = np.asarray(torque, dtype=float)[:stop]
    moment = _weightless_moment(theta, torque, antenna)
    rms = _rms_about_mean(moment)
    noise = signal_noise(torque)[0]
    if not (noise > 0.0 and np.all(np.isfinite(rms))):
        return math.nan, None
    ratios = rms / noise
    k = int(np.argmax(ratios))
    ratio = float(ratios[k])
    factor = cfg.still_turn_factor
    if ratio <= factor:
        return ratio, None
    if not _came_and_went(moment[:, k], window):
        return math.nan, None
    column = ("ty", "tz")[k]
    return ratio, (
        f"columns 'theta1', 'theta2', '{column}': before the contact neither angle turns by "
        f"more than the rest tolerance ({tolerance:.3g} rad), yet '{column}' varies "
        f"{ratio:.3g} times the sensor's noise (at most {factor:g} at rest), as a turning "
        "head's inertia loads it: the still joint's angle written over the turning one's, or "
        "a column that stopped updating?"
    )


@dataclass(frozen=True)
class HoldPush:
    """The static push over the hold window after t_1.

    Attributes
    ----------
    frame : ContactFrame or None
        Frame of Section 5.3 from the mean reaction; None when no push is measurable.
    problem : str or None
        Why there is no push (for ``push_not_reached``).
    stop : int
        Index one past the last sample of the hold window used.
    force_noise : float
        White noise of one force channel measured up to the end of the hold (N).
    standard_error : float
        Standard error of the mean perpendicular force over the hold (N).
    rebounds : dict
        Contact losses seen in the hold (count, last instant), see :func:`_contact_losses`.
    """

    frame: ContactFrame | None
    problem: str | None
    stop: int
    force_noise: float
    standard_error: float
    rebounds: dict[str, Any]


def hold_push(
    theta: FloatArray,
    force: FloatArray,
    torque: FloatArray,
    antenna: Antenna,
    offset: FloatArray,
    rest_index: int,
    cfg: EstimatorConfig,
    ts: float,
) -> HoldPush:
    """Judge the push and build the contact frame from the mean reaction over the hold window.

    The static (mean) reaction R = F - F_g^m - offset over [t_1, t_1 + frame_window] is the push:
    the vibration and the rebounds of the impact average out, the preload does not. The push
    counts when |mean R_perp| exceeds ``min_push_significance`` standard errors of that mean,
    sigma_F / sqrt(N) with sigma_F the white force noise measured in the recording (the
    magnitude of a two-component Gaussian mean exceeds k standard errors with probability
    exp(-k^2 / 2): 4e-6 for k = 5). The samples used end at
    t_1 + max(rest_window, frame_window), the instant the streaming form knows them.
    """
    n = theta.shape[0]
    stop = min(rest_index + max(samples(cfg.frame_window, ts), samples(cfg.rest_window, ts)), n - 1)
    stop += 1
    hold = hold_window(rest_index, stop, cfg, ts)
    reaction, _ = contact_loads(theta[hold], force[hold], torque[hold], antenna)
    reaction = reaction - np.asarray(offset, dtype=float)[:3]
    noise = signal_noise(force[:stop])[0]
    count = reaction.shape[0]
    standard_error = noise / math.sqrt(count)
    losses = _contact_losses(reaction, noise, cfg, ts)
    frame = contact_frame(theta[hold], reaction, antenna.link.length)
    if frame is None:
        problem = "the mean contact force over the hold is zero or along the link: no lateral push"
        return HoldPush(None, problem, stop, noise, standard_error, losses)
    perpendicular = frame.lateral_force
    limit = cfg.min_push_significance * standard_error
    if perpendicular <= limit:
        problem = (
            f"the mean contact force over the {count * ts:.3f} s after t_1 is "
            f"{1000 * perpendicular:.2f} mN, not above {cfg.min_push_significance:g} standard "
            f"errors ({1000 * limit:.2f} mN, force noise {1000 * noise:.2f} mN) of a push "
            "(gravity and sensor offset removed): no touch pushed the link at t_c, or too "
            "lightly. A detector that fires on the free motion (its threshold below this "
            "device's residual: antenna identify on its free sweeps), or torques about a point "
            "that '# torque_point' does not state?"
        )
        return HoldPush(None, problem, stop, noise, standard_error, losses)
    return HoldPush(frame, None, stop, noise, standard_error, losses)


def _contact_losses(
    reaction: FloatArray, noise: float, cfg: EstimatorConfig, ts: float
) -> dict[str, Any]:
    """Short windows of the hold where the push along its mean direction is not measurable.

    The obstacle can only push: while the link is off it, the reaction along the mean push
    direction has no static part. Means over ``loss_window`` below ``loss_significance``
    standard errors of such a mean (sigma_F / sqrt(n)) are counted as losses (rebounds); the
    count and the last one are reported, not used as a status (the link's own vibration also
    moves short means).
    """
    mean = reaction.mean(axis=0)
    norm = float(np.linalg.norm(mean))
    width = samples(cfg.loss_window, ts)
    if norm == 0.0 or reaction.shape[0] < width:
        return {"count": 0, "last": None}
    along = reaction @ (mean / norm)
    windows = np.lib.stride_tricks.sliding_window_view(along, width).mean(axis=-1)
    low = windows < cfg.loss_significance * noise / math.sqrt(width)
    starts = np.flatnonzero(low & ~np.concatenate([[False], low[:-1]]))
    last = np.flatnonzero(low)
    return {
        "count": int(starts.size),
        "last": None if not last.size else float((last[-1] + width) * ts),
    }


def ratio_tolerance(
    hold: HoldPush, antenna: Antenna, cfg: EstimatorConfig, ts: float
) -> tuple[float, float]:
    """Ratio noise (m) and the convergence tolerance it implies (m), from the hold."""
    assert hold.frame is not None
    noise = ratio_noise(
        hold.force_noise,
        hold.frame.lateral_force,
        antenna.link.length,
        cfg.lowpass_cutoff,
        ts,
    )
    # The moving average's spread over a window stays within three noise deviations.
    return noise, max(cfg.convergence_tolerance, 3.0 * noise)


def planned_end(
    rest_index: int,
    converged: int | None,
    cfg: EstimatorConfig,
    sample_period: float,
    spectrum_window: float,
) -> int:
    """Index of t_e planned from t_1 and the ratio's convergence, with Delta t_e1
    ``spectrum_window`` (s, :func:`~.evidence.spectrum_window`)."""
    # Section 4, step 6: t_e = t_1 + max(Delta t_e1, Delta t_e2)
    spectrum_end = rest_index + samples(spectrum_window, sample_period)
    ratio_end = (
        converged
        if converged is not None
        else rest_index + samples(cfg.max_ratio_wait, sample_period)
    )
    return max(spectrum_end, ratio_end)
