"""The front end as one streaming object, :class:`FrontEnd`.

The front end turns samples into the :class:`~.evidence.Evidence` a method concludes from, or into
an :class:`~.outcome.EarlyOutcome` when no estimate is possible. Its steps (Section 4), each
causal, so an instant depends only on the samples up to it (and, where a sensor sample is
suspected of corruption, on the few after it that decide it, which the stream waits for):

0. Sensor samples off their neighbours (a run of up to 20 ms, at least twenty samples, between
   calm ones: a glitch, or an impact's pulse as brief) put back on the line between them
   (:mod:`.spikes`).
1. t_c: the contact detector of Section 4.2
   (:class:`~sensing_antenna.detection.contact.ContactDetector`); the sensor offset and the rest
   tolerance from the samples up to t_c.
2. t_1: the head comes to rest after t_c (:func:`.contact_frame.first_rest_index`), or, with
   ``t1_source = "push"``, the push criterion's decision
   (:class:`~sensing_antenna.detection.push.PushMonitor`).
3. At t_1 + hold: the static push and the contact frame (:func:`.steps.hold_push`).
4. Estimator 2's ratio, its moving mean and convergence (:mod:`.ratio`); t_e (Section 4, step 6).

Samples come in blocks (:meth:`FrontEnd.update_block`); a block of one is the per-sample form, and
:func:`~sensing_antenna.estimation.pipeline.gather` feeds a whole recording as one block. The
detectors are compiled kernels with their state carried; the Eq. 20 filter carries its state too;
the ratio and its moving mean are elementwise and computed once per sample, when first needed or,
once t_e is planned, every :data:`_FILL_AHEAD` samples. So the evidence, its instants and every
number in it are the same to the bit however the samples are cut into blocks.
"""

from __future__ import annotations

import bisect
import dataclasses
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import Antenna
from sensing_antenna.detection.contact import OBSERVER_TORQUE_SIGNS, ContactDetector
from sensing_antenna.detection.contact_watch import ContactWatch, lost_before_rest
from sensing_antenna.detection.filters import FirstOrderLowPass
from sensing_antenna.detection.push import PushCriterion, PushMonitor
from sensing_antenna.errors import FieldError
from sensing_antenna.estimation.config import EstimatorConfig, no_t1_reason
from sensing_antenna.estimation.front.contact_frame import (
    first_rest_index,
    rest_drift_tolerance,
    signal_noise,
)
from sensing_antenna.estimation.front.evidence import Evidence, search_band, spectrum_window
from sensing_antenna.estimation.front.outcome import EarlyOutcome, FrontTrace
from sensing_antenna.estimation.front.ratio import (
    converged_index,
    filtered_contact_loads,
    perpendicular_ratio,
    window_mean,
)
from sensing_antenna.estimation.front.spikes import (
    SPIKE_WINDOW,
    WRENCH_CHANNELS,
    find_spikes,
    judged_from,
    repair,
    spike_floor,
    spike_longest,
)
from sensing_antenna.estimation.front.steps import (
    ContactStart,
    DeclaredPeriodCheck,
    HoldPush,
    StreamGrid,
    at_contact,
    dead_channel,
    declared_period_refused,
    fill_missing,
    hold_push,
    hold_samples,
    planned_end,
    ratio_tolerance,
    samples,
    sampling_problem,
    time_gaps,
)
from sensing_antenna.estimation.result import Status

__all__ = ["FrontEnd", "Gathered", "one_sample"]

FloatArray = NDArray[np.float64]

#: What the front end hands on: the evidence at t_e, or why there is none.
Gathered = Evidence | EarlyOutcome

# The buffers of FrontEnd (set in reset), grown by doubling, NaN where not written.
#: The columns of a sample, as the recording format names them.
_COLUMNS = ("t", "theta1", "theta2", "fx", "fy", "fz", "tx", "ty", "tz")

_BUFFERS = ("_t", "_theta", "_force", "_torque", "_reaction", "_moment", "_ratio", "_mean")

#: Once t_e is planned, the filtered loads and the ratio are filled as soon as this many samples
#: wait (the samples up to t_e only), so that the step at t_e has few left to fill.
_FILL_AHEAD = 128


#: The last stretch of a recording without a contact (s) whose mean residual about the turned
#: joint's axis, resisting the turn by more than :data:`HELD_UNDER_SHARE` of the threshold, says
#: a push the threshold missed: a free motion's residual dies out once the head rests and its
#: noise averages out, a push's static moment stays (the link's ringing on it averages out too),
#: and a sensor's drift since the tare takes any direction.
HELD_UNDER_TIME = 0.5
HELD_UNDER_SHARE = 0.4


def _held_under(detector: ContactDetector, theta: FloatArray, last: int) -> str:
    """What a recording without a contact owes to a push under the detector's threshold: its
    mean residual over the ``last`` samples about the axis of the joint that turned most
    (``theta``, shape (n, 2), rad), "" unless it resists that turn by more than
    :data:`HELD_UNDER_SHARE` of the threshold."""
    residual = detector.detection().residual
    if residual.shape[0] < 2 * last or last < 1 or theta.shape[0] != residual.shape[0]:
        return ""
    turn = theta[-1] - theta[0]
    joint = int(np.argmax(np.abs(turn)))
    mean = np.mean(residual[-last:], axis=0)
    # the azimuth turns about Z^m, the elevation about Y^m; a push resists the turn as the
    # bent link's spring torque does, which the observer gives those signs
    sign_y, sign_z = OBSERVER_TORQUE_SIGNS
    axis, sign = (2, sign_z) if joint == 0 else (1, sign_y)
    held = float(mean[axis] * sign * np.sign(turn[joint]))
    if not held > HELD_UNDER_SHARE * detector.threshold:
        return ""
    return (
        f"; but over its last {HELD_UNDER_TIME:g} s it holds {held:.3g} N m against the head's"
        " turn, as a push gentler than the threshold does: push deeper, or give the antenna the"
        " device's own threshold (antenna identify on a free sweep)"
    )


def one_sample(
    t: float, theta: ArrayLike, force: ArrayLike, torque: ArrayLike
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """One sample as a block of one: t (1,), theta (1, 2), force and torque (1, 3)."""
    return (
        np.array([t], dtype=np.float64),
        np.asarray(theta, dtype=np.float64)[None, :],
        np.asarray(force, dtype=np.float64)[None, :],
        np.asarray(torque, dtype=np.float64)[None, :],
    )


def _rows(name: str, value: ArrayLike, count: int, width: int) -> FloatArray:
    """``value`` as an array of shape (count, width), or a FieldError naming it."""
    array = np.asarray(value, dtype=np.float64)
    if array.shape != (count, width):
        raise FieldError(
            name,
            f"shape {array.shape}, expected ({count}, {width}) for {count} sample times",
            "FrontEnd.update_block",
        )
    return array


def _read_only(view: FloatArray) -> FloatArray:
    view.flags.writeable = False
    return view


def _samples_arithmetic() -> np.errstate:
    """Arithmetic on the samples: a value far beyond any device's (a glitch of 1e300 N, a wrench
    in wrong units) overflows to inf or NaN in sums, norms and the ratio's fixed point; the
    steps judge those values (no push, no convergence, a status), so NumPy's warnings would
    only put lines on a user's terminal."""
    return np.errstate(over="ignore", invalid="ignore", divide="ignore")


class FrontEnd:
    """The front end of the estimation pipeline as a streaming object.

    Parameters
    ----------
    antenna : Antenna
        Link, observer and contact threshold.
    sample_period : float
        T_s (s) of the samples that will be fed (those missing are put back:
        :meth:`update_block`).
    config : EstimatorConfig, optional
        Defaults to ``EstimatorConfig()``.
    diagnostics : Mapping, optional
        What the caller knows about the samples (the sampling report of a recording), put first
        in every outcome's diagnostics; ``{"resampled": False}`` when None.
    declared : bool
        ``sample_period`` was declared before the samples came (a stream, not a recording whose
        period its reader took from its stamps): the first time stamps are judged against it
        (:class:`~.steps.DeclaredPeriodCheck`), and samples at another period are
        ``bad_input``.

    Notes
    -----
    :meth:`update_block` returns the outcome once: the :class:`~.evidence.Evidence` at t_e or an
    :class:`~.outcome.EarlyOutcome`; later samples are ignored until :meth:`reset`.
    :meth:`finish` closes a run whose samples ended first. A method that may stop before t_e
    asks :meth:`evidence_at` for the evidence of an earlier instant.
    """

    def __init__(
        self,
        antenna: Antenna,
        sample_period: float,
        config: EstimatorConfig | None = None,
        *,
        diagnostics: Mapping[str, Any] | None = None,
        declared: bool = False,
    ) -> None:
        self.antenna = antenna
        self.declared = declared
        self.sample_period = ts = float(sample_period)
        self.config = cfg = config if config is not None else EstimatorConfig()
        self.band = search_band(antenna.link, cfg)
        self._window = spectrum_window(antenna.link, cfg)  # Delta t_e1 (s)
        self._notes = dict(diagnostics) if diagnostics is not None else {"resampled": False}
        self._w_rest = samples(cfg.rest_window, ts)
        self._w_hold = hold_samples(cfg, ts)
        self._w_conv = samples(cfg.convergence_window, ts)
        self._n_wait = samples(cfg.max_ratio_wait, ts)
        # Samples too coarse for the vibration are refused before any filter is built for them
        self._refused = sampling_problem(ts, self.band[1], cfg)
        self._detector: ContactDetector | None = None
        self._monitor: PushMonitor | None = None
        self._loads_filter: FirstOrderLowPass | None = None
        self._spike_floor = spike_floor(antenna)
        self._spike_longest = spike_longest(ts)
        self._spike_gate = judged_from(self._spike_floor)
        if self._refused is None:
            # the samples fed are on the period's grid, judged here (check_input off)
            self._detector = ContactDetector(antenna, ts, check_input=False)
            if cfg.t1_source == "push":
                # Section 4 step 4: t_1 is the push criterion's decision, on the same detector
                rule = cfg.push_criterion or PushCriterion()
                self._monitor = PushMonitor(rule, antenna, ts, contact_detector=self._detector)
            self._loads_filter = FirstOrderLowPass(cfg.lowpass_cutoff, ts)
        self.reset()

    def reset(self) -> None:
        """Forget every sample: ready for a new manoeuvre."""
        if self._monitor is not None:
            self._monitor.reset()  # and its contact detector
        elif self._detector is not None:
            self._detector.reset()
        if self._loads_filter is not None:
            self._loads_filter.reset()
        # samples, the filtered contact loads (offset not removed), the ratio and its mean
        self._t: FloatArray = np.empty(0)
        self._theta: FloatArray = np.empty((0, 2))
        self._force: FloatArray = np.empty((0, 3))
        self._torque: FloatArray = np.empty((0, 3))
        self._reaction: FloatArray = np.empty((0, 3))
        self._moment: FloatArray = np.empty((0, 3))
        self._ratio: FloatArray = np.empty(0)
        self._mean: FloatArray = np.empty(0)
        self._n = 0
        self._loads_done = self._ratio_done = self._mean_done = 0
        self._filled: list[tuple[int, tuple[float, float]]] = []  # (known at sample, interval)
        self._put_back_at: list[int] = []  # samples put back where stamps skip (ascending)
        self._grid: StreamGrid | None = None  # where the samples received were placed
        self._late_at: list[int] = []  # samples left out, their place taken (ascending)
        # samples received but held back until the samples that decide a suspect among them
        # have come (spikes.find_spikes), and the raw wrench of the last ones released
        self._pending: tuple[FloatArray, FloatArray, FloatArray] | None = None
        self._history: FloatArray = np.empty((0, 6))
        # an upper bound of the largest raw step in the window of SPIKE_WINDOW steps before the
        # next sample: the largest step of the current run of up to SPIKE_WINDOW steps and of
        # the run before it (the per-sample path's gate, spikes.find_spikes)
        self._run_max = np.zeros(6)
        self._step_bound = np.full(6, np.inf)  # the larger of the two runs' largest steps
        self._run_count = 0
        # the spikes put back: (first sample, length, channels)
        self._spikes: list[tuple[int, int, tuple[int, ...]]] = []
        self._jump: str | None = None  # a step of the time stamps too long to fill
        # the declared period, judged on the first time stamps received
        self._period = DeclaredPeriodCheck(self.sample_period) if self.declared else None
        self._contact: int | None = None
        self._start: ContactStart | None = None
        self._rest: int | None = None
        self._hold: HoldPush | None = None
        self._ratio_tolerance = math.nan
        self._converged: int | None = None
        self._planned: int | None = None
        self._outcome: Gathered | None = None

    @property
    def n_samples(self) -> int:
        """Samples held since :meth:`reset`: those fed, and those put back where the time stamps
        skipped some (:meth:`update_block`); not those held back until the samples that decide
        a suspected corruption among them have come (``spike_longest`` + 1, or more from the
        start of another channel's run that reaches the suspect)."""
        return self._n

    @property
    def contact_index(self) -> int | None:
        """Sample of t_c, once found."""
        return self._contact

    @property
    def rest_index(self) -> int | None:
        """Sample of t_1, once found."""
        return self._rest

    @property
    def input_problem(self) -> str | None:
        """Why the samples up to t_c are not in the format's units and signs (found at t_c),
        None when they are or before t_c."""
        return None if self._start is None else self._start.input_problem

    @property
    def tare(self) -> str | None:
        """How the sensor was tared at t_c (``rest``, ``approach`` or ``none``: too few samples
        free of contact before it), None before t_c."""
        return None if self._start is None else self._start.tare

    @property
    def first_evaluation_index(self) -> int | None:
        """First sample at which :meth:`evidence_at` may be asked: the end of the hold after t_1,
        once the push there was judged measurable; None before."""
        if self._hold is None or self._rest is None:
            return None
        return self._rest + self._w_hold

    @property
    def outcome(self) -> Gathered | None:
        """The evidence at t_e or the early outcome, once given."""
        return self._outcome

    def update(
        self, t: float, theta: ArrayLike, force: ArrayLike, torque: ArrayLike
    ) -> Gathered | None:
        """Feed one sample (a block of one: t in s, theta (2,) in rad, force and torque (3,) in
        N and N m, motor frame); returns the outcome once, else None."""
        return self.update_block(*one_sample(t, theta, force, torque))

    def update_block(
        self,
        t: ArrayLike,
        theta: ArrayLike,
        force: ArrayLike,
        torque: ArrayLike,
        filled_gaps: Sequence[tuple[float, float]] = (),
    ) -> Gathered | None:
        """Feed the samples that follow; returns the outcome once (at t_e or earlier), else None.

        Parameters
        ----------
        t : array_like, shape (n,)
            Sample times (s). Where they step by k sample periods (k >= 2, less a quarter at
            most: :func:`.steps.samples_missing`), the k - 1 samples missing are put back by
            linear interpolation (:func:`.steps.fill_missing`, as a whole recording is
            resampled) and counted in the diagnostics
            (``filled_samples``); steps of more than ``config.gap_limit(T_s)`` missing samples
            are also gaps, and one beyond :data:`.steps.MAX_FILLED` makes the outcome ``bad_input``.
        theta : array_like, shape (n, 2)
            Motor angles (rad).
        force, torque : array_like, shape (n, 3)
            F/T sensor samples, motor frame (N, N m).
        filled_gaps : sequence of (float, float)
            Intervals (s) in which the caller filled missing samples of this block (a resampled
            recording), known from the block's first sample on.

        Raises
        ------
        FieldError
            When the shapes do not match.
        """
        times = np.atleast_1d(np.asarray(t, dtype=np.float64))
        count = times.shape[0]
        angles, forces, moments = (
            _rows(name, value, count, width)
            for name, value, width in (
                ("theta", theta, 2),
                ("force", force, 3),
                ("torque", torque, 3),
            )
        )
        if self._outcome is not None or count == 0:
            return None
        if self._refused is None:
            times, angles, forces, moments = self._before_nan(times, angles, forces, moments)
            self._judge_period(times)
        if self._refused is None:
            times, angles, forces, moments = self._put_back(times, angles, forces, moments)
            # after an outlier time stamp no sample follows: what is held back is released
            final = self._jump is not None
            times, angles, forces, moments = self._despike(times, angles, forces, moments, final)
        return self._ingest(times, angles, forces, moments, filled_gaps)

    def _judge_period(self, times: FloatArray, final: bool = False) -> None:
        """Samples at another period than the declared one are refused (``declared``)."""
        problem = None if self._period is None else self._period.feed(times, final)
        if problem is not None:
            self._refused = declared_period_refused(self.sample_period, problem)

    def _ingest(
        self,
        times: FloatArray,
        angles: FloatArray,
        forces: FloatArray,
        moments: FloatArray,
        filled_gaps: Sequence[tuple[float, float]] = (),
    ) -> Gathered | None:
        """Store the samples released (spikes repaired) and run the steps on them."""
        count = times.shape[0]
        first, stop = self._n, self._n + count
        self._reserve(stop)
        # the detectors read the samples where they now lie (writable, C-ordered: no copy)
        fed = (
            self._t[first:stop],
            self._theta[first:stop],
            self._force[first:stop],
            self._torque[first:stop],
        )
        fed[0][:], fed[1][:], fed[2][:], fed[3][:] = times, angles, forces, moments
        self._n = stop
        if filled_gaps:
            self._filled.extend((first, (float(a), float(b))) for a, b in filled_gaps)
        if self._refused is not None:
            return self._stop(self._early(Status.BAD_INPUT, self._refused))
        outcome = None
        if stop > first:
            if self._monitor is not None:
                self._monitor.update_block(*fed)
            else:
                assert self._detector is not None
                self._detector.update_block(*fed)
            with _samples_arithmetic():
                outcome = self._advance(first, stop)
        if outcome is None and self._jump is not None:
            # the samples before an outlier time stamp or a NaN said what they could; it ends
            # the run
            return self._stop(self._early(Status.BAD_INPUT, self._jump))
        return outcome

    def _despike(
        self,
        t: FloatArray,
        theta: FloatArray,
        force: FloatArray,
        torque: FloatArray,
        final: bool = False,
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """The samples decided so far, runs of corrupted wrench samples put back on the line
        between their neighbours (:mod:`.spikes`); those from a suspect whose deciding samples
        have not come yet (and from the first sample of a run that reaches it) are held back
        (all released, undecided ones as they are, when ``final``). The decisions read the raw
        samples only, so they are the same however the samples are cut into blocks."""
        wrench = np.concatenate([force, torque], axis=1)
        history = self._history
        if self._pending is None and t.shape[0] == 1 and history.shape[0] == SPIKE_WINDOW + 2:
            # one sample after calm ones: no suspect when its step and the largest step before
            # it together stay below the floor (find_spikes' own gate, with a bound of that step)
            # a step that is no number (a NaN sample, inf - inf) bounds nothing: NaN, carried
            # by np.maximum into the bound, fails "below the gate" as inf would
            with np.errstate(over="ignore", invalid="ignore"):
                step = np.abs(wrench[0] - history[-1])
                calm = (step + self._step_bound < self._spike_gate).all()
            if calm:
                self._history = np.concatenate([history[1:], wrench])
                self._note_steps(step, 1)
                return t, theta, force, torque
        if self._pending is not None:
            pt, ptheta, pwrench = self._pending
            t = np.concatenate([pt, t])
            theta = np.concatenate([ptheta, theta])
            wrench = np.concatenate([pwrench, wrench])
        h = history.shape[0]
        raw = np.concatenate([history, wrench]) if h else wrench
        spikes, decided = find_spikes(
            raw, h, self._spike_floor, final=final, longest=self._spike_longest
        )
        released = decided - h
        if spikes:
            origin = self._n - h  # sample index of raw[0]
            self._spikes.extend((origin + s.index, s.length, s.channels) for s in spikes)
            out = repair(raw, spikes)[h:decided]
            force, torque = out[:, 0:3], out[:, 3:6]
        elif released < t.shape[0] or self._pending is not None:
            force, torque = wrench[:released, 0:3], wrench[:released, 3:6]
        self._pending = (
            None if released == t.shape[0] else (t[released:], theta[released:], wrench[released:])
        )
        self._history = raw[:decided][-(SPIKE_WINDOW + 2) :]
        if released:
            with np.errstate(over="ignore", invalid="ignore"):
                steps = np.abs(np.diff(raw[max(h - 1, 0) : decided], axis=0))
                if steps.shape[0]:
                    self._note_steps(steps.max(axis=0), steps.shape[0])
        return t[:released], theta[:released], force, torque

    def _note_steps(self, largest: FloatArray, count: int) -> None:
        """Fold ``count`` raw steps into the samples released, ``largest`` their largest size
        per channel (shape (6,); NaN for a step that is no number, which np.maximum keeps),
        into the runs' largest steps (a run that reaches SPIKE_WINDOW steps or more becomes the
        last one)."""
        np.maximum(self._run_max, largest, out=self._run_max)
        np.maximum(self._step_bound, largest, out=self._step_bound)
        self._run_count += count
        if self._run_count >= SPIKE_WINDOW:
            self._rotate_runs()

    def _rotate_runs(self) -> None:
        self._step_bound = self._run_max
        self._run_max, self._run_count = np.zeros(6), 0

    def _last_received(self) -> tuple[float, FloatArray] | None:
        """The last sample received (held back or stored): its time and values (theta, force,
        torque), or None before the first."""
        if self._pending is not None:
            pt, ptheta, pwrench = self._pending
            return float(pt[-1]), np.concatenate([ptheta[-1], pwrench[-1]])
        n = self._n
        if not n:
            return None
        return float(self._t[n - 1]), np.concatenate(
            [self._theta[n - 1], self._force[n - 1], self._torque[n - 1]]
        )

    def _before_nan(
        self, t: FloatArray, theta: FloatArray, force: FloatArray, torque: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """The block cut before its first sample with a NaN (a reading the device did not give,
        which no repair can judge) or an infinite time stamp (no place in time), which ends
        the run (``bad_input``) after the samples before it, as a recording with one is
        refused."""
        if self._jump is not None:
            return t, theta, force, torque
        values = np.hstack([t[:, None], theta, force, torque])
        unusable = np.isnan(values)
        if math.isinf(t[0]) if t.shape[0] == 1 else np.isinf(t).any():  # the loop's case cheap
            unusable[:, 0] |= np.isinf(t)
        rows = np.flatnonzero(unusable.any(axis=1))
        if rows.size == 0:
            return t, theta, force, torque
        k = int(rows[0])
        column = _COLUMNS[int(np.flatnonzero(unusable[k])[0])]
        previous = self._last_received()
        before = float(t[k - 1]) if k else None if previous is None else previous[0]
        if column != "t":
            where = f"at t = {t[k]:.4f} s"
        elif before is not None:
            where = f"after t = {before:.4f} s"
        else:
            where = "at the stream's first sample"
        what = "infinite" if column == "t" and np.isinf(t[k]) else "not a number (NaN)"
        self._jump = (
            f"column '{column}': {what} {where}, a reading the device did not give; a sample's "
            "values must all be numbers, its time stamp finite"
        )
        return t[:k], theta[:k], force[:k], torque[:k]

    def _put_back(
        self, t: FloatArray, theta: FloatArray, force: FloatArray, torque: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """The block with the samples its time stamps skip put back (:func:`fill_missing`), the
        long steps remembered as gaps from their first sample put back; cut before a step
        beyond any filling, which ends the run (``bad_input``) after the samples before it."""
        ts = self.sample_period
        pending = self._pending
        n = self._n + (0 if pending is None else pending[0].shape[0])
        if n and t.shape[0] == 1 and self._grid is not None:
            following = self._grid.next(float(t[0]))
            if following is not None:
                # the loop's case: the next place on the grid, nothing skipped (as fill_missing)
                self._grid = following
                return t, theta, force, torque
        previous = self._last_received()
        filled = fill_missing(
            t,
            np.hstack([theta, force, torque]),
            ts,
            self.config.gap_limit(ts),
            previous,
            self._grid,
        )
        self._grid = filled.grid
        self._late_at.extend((n + filled.late_at).tolist())
        if filled.jump is not None:
            self._jump = f"t: {filled.jump}"
        if filled.t is t:
            return t, theta, force, torque
        self._put_back_at.extend((n + np.flatnonzero(filled.filled)).tolist())
        self._filled.extend(
            (n + int(k), gap) for k, gap in zip(filled.gap_starts, filled.gaps, strict=True)
        )
        v = filled.values
        return filled.t, v[:, 0:2], v[:, 2:5], v[:, 5:8]

    def _reserve(self, stop: int) -> None:
        size = self._t.shape[0]
        if stop <= size:
            return
        size = max(stop, 2 * size, 4096)
        for name in _BUFFERS:
            old = getattr(self, name)
            new = np.full((size, *old.shape[1:]), np.nan)
            new[: self._n] = old[: self._n]
            setattr(self, name, new)

    def _gaps_known(self, end: int) -> list[tuple[float, float]]:
        """Gaps known at sample ``end``: those the caller filled in the blocks fed by then, and
        steps of the time stamps up to ``end`` missing more than ``config.gap_limit(T_s)``
        samples."""
        filled = [gap for known, gap in self._filled if known <= end]
        limit = self.config.gap_limit(self.sample_period)
        stamps = time_gaps(self._t[: end + 1], self.sample_period, limit)
        return filled + list(stamps)

    def _advance(self, first: int, stop: int) -> Gathered | None:
        """The steps after the detectors, on samples first..stop (module docstring)."""
        cfg, ts, last = self.config, self.sample_period, stop - 1
        if self._contact is None:
            assert self._detector is not None
            if self._detector.contact_index is None:
                return None
            self._contact = self._detector.contact_index
            self._start = at_contact(
                self._theta[:stop],
                self._force[:stop],
                self._torque[:stop],
                self.antenna,
                self._contact,
                cfg,
                ts,
                self._detector.detection().estimated_torque,
            )
        assert self._start is not None
        if self._rest is None:
            if self._monitor is not None:
                self._rest = self._monitor.push_index
            else:
                # spans [i, i + d] (the hold's) from t_c on, those ending before this block
                # tested already
                start = max(self._contact, first - self._w_hold)
                self._rest = first_rest_index(
                    self._theta[:stop],
                    start,
                    self._w_rest,
                    self._start.rest_tolerance,
                    self._start.rest_drift,
                    self._w_hold,
                )
            if self._rest is None:
                return None
        rest = self._rest
        if self._hold is None:
            judged = rest + self._w_hold
            if judged > last:
                return None
            hold = self._judge_hold(judged)
            if hold.frame is None:
                return self._stop(self._early(Status.PUSH_NOT_REACHED, hold.problem or "", judged))
            self._hold = hold
            _, self._ratio_tolerance = ratio_tolerance(hold, self.antenna, cfg, ts)
        if self._planned is None:
            self._test_convergence(first, stop)
        if self._planned is None:
            return None
        if last >= self._planned:
            return self._stop(self._evidence(self._planned, complete=True))
        if stop - self._ratio_done >= _FILL_AHEAD:
            self._fill(stop)  # the samples up to t_e only: last < planned
        return None

    def _judge_hold(self, end: int) -> HoldPush:
        """The push over the hold after t_1, from the samples up to ``end``."""
        assert self._start is not None and self._rest is not None
        stop = end + 1
        return hold_push(
            self._theta[:stop],
            self._force[:stop],
            self._torque[:stop],
            self.antenna,
            self._start.offset,
            self._rest,
            self.config,
            self.sample_period,
        )

    def _test_convergence(self, first: int, stop: int) -> None:
        """Estimator 2's convergence over the windows ending in first..stop; plans t_e."""
        assert self._rest is not None
        rest, w = self._rest, self._w_conv
        # the ratio is tested up to t_1 + max_ratio_wait, its windows of means from t_1 + 2 w on
        last = min(stop - 1, rest + self._n_wait)
        first_end = max(first, rest + 2 * w)
        if last >= first_end:
            self._fill(last + 1)
            found = converged_index(self._mean[: last + 1], first_end - w, w, self._ratio_tolerance)
            if found is not None:
                self._converged = found
                self._planned = planned_end(
                    rest, found, self.config, self.sample_period, self._window
                )
                return
        if stop - 1 >= rest + self._n_wait:
            self._planned = planned_end(rest, None, self.config, self.sample_period, self._window)

    def _fill(self, stop: int) -> None:
        """Filtered loads, ratio (once t_c fixed the offset) and its moving mean (from t_1 + w)
        up to sample ``stop``, each computed once."""
        if self._loads_done < stop and self._loads_filter is not None:
            a = self._loads_done
            self._reaction[a:stop], self._moment[a:stop] = filtered_contact_loads(
                self._theta[a:stop],
                self._force[a:stop],
                self._torque[a:stop],
                self.antenna,
                self.config.lowpass_cutoff,
                self.sample_period,
                running=self._loads_filter,
            )
            self._loads_done = stop
        if self._start is None:
            return
        if self._ratio_done < stop:
            a, offset = self._ratio_done, self._start.offset
            # Estimator 2 on the tared loads
            self._ratio[a:stop] = perpendicular_ratio(
                self._reaction[a:stop] - offset[:3],
                self._moment[a:stop] - offset[3:],
                self.antenna.link,
                self._theta[a:stop, 1],
            )
            self._ratio_done = stop
        if self._rest is None:
            return
        w = self._w_conv
        a = max(self._mean_done, self._rest + w)
        if a < stop:
            # m[j] = mean(ratio[j - w : j + 1]), from the w samples before a on
            self._mean[a:stop] = window_mean(self._ratio[a - w : stop], 0, w)[w:]
            self._mean_done = stop

    def evidence_at(self, index: int) -> Gathered:
        """The evidence the samples up to ``index`` give, for a method that may stop before t_e.

        ``index`` lies in [:attr:`first_evaluation_index`, :attr:`n_samples`); the instants and
        the convergence are those known at ``index``.
        """
        first = self.first_evaluation_index
        if first is None or not first <= index < self._n:
            raise ValueError(
                f"index {index}: evidence is available from {first} to {self._n - 1} only"
            )
        with _samples_arithmetic():
            return self._evidence(index, complete=True)

    def _evidence(self, end: int, complete: bool) -> Gathered:
        """Evidence from the samples 0..end (or the early outcome they give)."""
        assert self._contact is not None and self._start is not None and self._rest is not None
        stop = end + 1
        problem = dead_channel(self._force[:stop], self._torque[:stop])
        if problem is not None:
            return self._early(Status.BAD_INPUT, problem, end)
        hold = self._hold if self._hold is not None else self._judge_hold(end)
        if hold.frame is None:
            return self._early(Status.PUSH_NOT_REACHED, hold.problem or "", end)
        self._fill(stop)
        cfg, ts, start, rest = self.config, self.sample_period, self._start, self._rest
        offset = start.offset
        noise, _ = ratio_tolerance(hold, self.antenna, cfg, ts)
        # Standard errors of the tare's means; without a tare the offset is taken as one noise
        # deviation (a sensor tared shortly before, as the simulator's two-count offset).
        torque_noise = signal_noise(self._torque[: hold.stop])[0]
        # each group's error from its shortest tare (a channel cut where the sweep's start shows)
        force_root, torque_root = (
            math.sqrt(min(part)) if min(part) else 1.0
            for part in (start.counts[:3], start.counts[3:])
        )
        converged = self._converged
        diagnostics = self._diagnostics(end)
        diagnostics.update(
            {
                "rebounds": hold.rebounds,
                "hold_push_standard_error": hold.standard_error,
                "force_noise": hold.force_noise,
                "torque_noise": torque_noise,
            }
        )
        lost = self._lost_before_rest(rest, end)
        if lost is not None:
            diagnostics["contact_lost_before_rest"] = lost
        gaps = self._gaps_known(end)
        t = self._t
        return Evidence(
            t=_read_only(t[:stop]),
            theta=_read_only(self._theta[:stop]),
            force=_read_only(self._force[:stop]),
            torque=_read_only(self._torque[:stop]),
            sample_period=ts,
            antenna=self.antenna,
            config=cfg,
            contact_index=self._contact,
            rest_index=rest,
            end_index=end,
            converged_index=converged if converged is not None and converged <= end else None,
            complete=complete,
            frame=hold.frame,
            reaction_f=self._reaction[:stop] - offset[:3],
            torque_f=self._moment[:stop] - offset[3:],
            ratio=_read_only(self._ratio[:stop]),
            ratio_mean=_read_only(self._mean[:stop]),
            load_offset=offset,
            ratio_noise=noise,
            band=self.band,
            hold_end=hold.stop - 1,
            offset_error=hold.force_noise / force_root,
            torque_offset_error=torque_noise / torque_root,
            tare=start.tare,
            tare_samples=start.counts,
            gaps=tuple(gaps),
            input_problem=start.input_problem,
            declared_period=self.declared,
            diagnostics=diagnostics,
        )

    def _lost_before_rest(self, rest: int, end: int) -> float | None:
        """By when (s) the contact found at t_c had gone, when it began to go before the head
        came to rest at t_1 (sample ``rest``), or None: the contact detector's residual from t_c
        to sample ``end``, averaged over a free period
        (:func:`~sensing_antenna.detection.contact_watch.lost_before_rest`). A detection on
        something other than the touch (angles stamped late against the loads, a knock, hum)
        that the head turned on from."""
        if self._detector is None or self._contact is None:
            return None
        detection = self._detector.detection()
        ts, k = self.sample_period, self._contact
        watch = ContactWatch.for_antenna(self.antenna, detection.threshold, ts)
        changes = watch.feed(detection.residual[k : end + 1], self._t[k : end + 1])
        lost = lost_before_rest(changes, float(self._t[rest]))
        return None if lost is None else lost.known

    def _notes_now(self, end: int | None = None) -> dict[str, Any]:
        """What the caller said of the samples, and how many missing ones were put back up to
        sample ``end`` (all held when None)."""
        notes = dict(self._notes)
        last = self._n - 1 if end is None else end
        filled = bisect.bisect_right(self._put_back_at, last)
        if filled:
            notes["filled_samples"] = filled
        late = bisect.bisect_right(self._late_at, last)  # those that came before sample `last`
        if late:
            notes["late_samples"] = late
        repaired = [
            {
                "t": float(self._t[index]),
                "samples": length,
                "channels": [WRENCH_CHANNELS[c] for c in channels],
            }
            for index, length, channels in self._spikes
            if index <= last
        ]
        if repaired:
            notes["repaired_samples"] = repaired
        return notes

    def _diagnostics(self, end: int | None = None) -> dict[str, Any]:
        diagnostics = self._notes_now(end)
        if self._start is not None:
            diagnostics.update(
                {
                    "rest_tolerance": self._start.rest_tolerance,
                    "tare": self._start.tare,
                    "tare_samples": list(self._start.counts),
                    "load_offset": self._start.offset,
                    **self._start.checks,
                }
            )
        return diagnostics

    def _early(self, status: Status, reason: str, end: int | None = None) -> EarlyOutcome:
        """An outcome without evidence; bad input keeps only what the caller said. A recording
        not in the format's units (found at t_c) says so first: the push or its absence was
        judged on loads of the wrong scale."""
        t = self._t
        diagnostics = self._notes_now(end) if status is Status.BAD_INPUT else self._diagnostics(end)
        problem = None if self._start is None else self._start.input_problem
        if problem is not None and status is not Status.BAD_INPUT:
            diagnostics["other_reasons"] = [reason]
            status, reason = Status.IMPLAUSIBLE_INPUT, problem
        return EarlyOutcome(
            status=status,
            reason=reason,
            t_c=math.nan if self._contact is None else float(t[self._contact]),
            t_1=math.nan if self._rest is None else float(t[self._rest]),
            diagnostics=diagnostics,
        )

    def _stop(self, outcome: Gathered) -> Gathered:
        """The outcome, with the trace, given once."""
        self._outcome = dataclasses.replace(outcome, trace=self.trace(outcome))
        return self._outcome

    def finish(self) -> Gathered:
        """Close the run at the end of the samples: the outcome given, or the one they give."""
        if self._outcome is not None:
            return self._outcome
        if self._refused is None:
            self._judge_period(np.empty(0), final=True)
            if self._refused is not None:
                return self._stop(self._early(Status.BAD_INPUT, self._refused))
        if self._pending is not None:
            # the samples held back: decided as far as they can be, the rest as they are
            empty = np.empty((0, 3))
            released = self._despike(np.empty(0), np.empty((0, 2)), empty, empty, final=True)
            outcome = self._ingest(*released)
            if outcome is not None:
                return outcome
        with _samples_arithmetic():
            return self._finish()

    def _finish(self) -> Gathered:
        n = self._n
        if n == 0:
            return self._stop(self._early(Status.BAD_INPUT, "no samples"))
        problem = dead_channel(self._force[:n], self._torque[:n])
        if problem is not None:
            return self._stop(self._early(Status.BAD_INPUT, problem))
        if self._contact is None:
            assert self._detector is not None
            status = Status.NO_CONTACT
            reason = f"filtered residual stays at or below {self._detector.threshold:g} N m"
            last = samples(HELD_UNDER_TIME, self.sample_period)
            reason += _held_under(self._detector, self._theta[:n], last)
            shortest = 2.0 * self.config.rest_window + self.config.frame_window
            if n - 1 < samples(shortest, self.sample_period):
                # too few samples to hold a contact the front end could use: not a free sweep
                status = Status.RECORDING_TOO_SHORT
                reason = (
                    f"{n} samples ({(n - 1) * self.sample_period:.4g} s) and no contact in "
                    f"them: too few for any manoeuvre, which needs {shortest:g} s at the least "
                    "(a rest before the sweep and one at the push, rest_window each, and the "
                    "push's hold, frame_window)"
                )
            outcome = self._early(status, reason)
            # loads in kN or torques in kN m never reach the threshold: the units check of
            # the whole record, as at a contact, says so before "no contact"
            problem = at_contact(
                self._theta[:n],
                self._force[:n],
                self._torque[:n],
                self.antenna,
                n - 1,
                self.config,
                self.sample_period,
            ).input_problem
            if problem is not None:
                diagnostics = {**outcome.diagnostics, "other_reasons": [reason]}
                outcome = dataclasses.replace(
                    outcome,
                    status=Status.IMPLAUSIBLE_INPUT,
                    reason=problem,
                    diagnostics=diagnostics,
                )
            return self._stop(outcome)
        assert self._start is not None
        if self._rest is None and self._monitor is None:
            # the samples ended within a hold of the head's rest: its drift judged over the
            # longest span left after a candidate, a rest window at the least
            self._rest = self._rest_in_what_is_left(n)
        if self._rest is None:
            reason = no_t1_reason(self.config, self._start.rest_tolerance)
            return self._stop(self._early(Status.PUSH_NOT_REACHED, reason))
        return self._stop(self._evidence(n - 1, complete=False))

    def _rest_in_what_is_left(self, n: int) -> int | None:
        """t_1 among the last samples, which hold less than a hold after it: the drift judged
        over spans shrinking from the hold's to the rest window's, the first span that finds a
        rest giving it."""
        assert self._start is not None and self._contact is not None
        theta, tolerance = self._theta[:n], self._start.rest_tolerance
        w_rest, span = self._w_rest, self._w_hold
        while span >= w_rest:
            drift = rest_drift_tolerance(
                theta[: self._contact + 1], self.config, tolerance, w_rest, span, self.sample_period
            )
            rest = first_rest_index(theta, self._contact, w_rest, tolerance, drift, span)
            if rest is not None or not math.isfinite(drift):
                return rest
            span -= w_rest
        return None

    def trace(self, outcome: Gathered | None = None) -> FrontTrace:
        """What the front end saw over every sample fed; ``outcome`` (or an evidence from
        :meth:`evidence_at`) gives t_e, the frame and the spectrum window."""
        n = self._n
        with _samples_arithmetic():
            self._fill(n)
        nan3 = np.full((n, 3), np.nan)
        estimated, norm, threshold = nan3, np.full(n, np.nan), math.nan
        if self._detector is not None:
            detection = self._detector.detection()
            estimated, norm = detection.estimated_torque, detection.filtered_residual_norm
            threshold = detection.threshold
        offset = np.zeros(6) if self._start is None else self._start.offset
        evidence = outcome if isinstance(outcome, Evidence) else None
        frame = self._hold.frame if self._hold is not None else None
        return FrontTrace(
            t=_read_only(self._t[:n]),
            sample_period=self.sample_period,
            theta=_read_only(self._theta[:n]),
            force=_read_only(self._force[:n]),
            torque=_read_only(self._torque[:n]),
            estimated_torque=estimated,
            filtered_residual_norm=norm,
            contact_threshold=threshold,
            contact_index=self._contact,
            rest_index=self._rest,
            end_index=None if evidence is None else evidence.end_index,
            load_offset=offset,
            reaction_f=self._reaction[:n] - offset[:3],
            torque_f=self._moment[:n] - offset[3:],
            ratio=_read_only(self._ratio[:n]),
            frame=frame if evidence is None else evidence.frame,
            spectrum=None if evidence is None else evidence.spectrum_slice,
            band=self.band,
        )
