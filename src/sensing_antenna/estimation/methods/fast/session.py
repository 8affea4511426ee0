"""The fast method online: one manoeuvre's session, keeping its window fits between evaluations."""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

from sensing_antenna.antenna import Antenna
from sensing_antenna.estimation.front.evidence import Evidence
from sensing_antenna.estimation.front.outcome import FrontTrace
from sensing_antenna.estimation.methods.fast.conclude import conclude_fast
from sensing_antenna.estimation.methods.fast.evaluation_grid import (
    evaluation_offsets,
    reference_index,
)
from sensing_antenna.estimation.methods.fast.search import ScanResult, scan_inputs
from sensing_antenna.estimation.methods.fast.second_mode import second_mode_chooser
from sensing_antenna.estimation.methods.fast.static_fit import contact_channels
from sensing_antenna.estimation.methods.fast.window import (
    ScanInputs,
    WindowEstimate,
    bounced_from_t1,
    evaluate_from_t1_or_hold,
    with_early_statics_of,
)
from sensing_antenna.estimation.methods.fast.window_fit import FitCache, fit_window, window_key
from sensing_antenna.estimation.result import ContactEstimate

if TYPE_CHECKING:
    from sensing_antenna.estimation.methods.fast.method import FastMethod

__all__ = ["FastSession"]


class FastSession:
    """The fast method over one manoeuvre online (:meth:`FastMethod.session`).

    The samples of a window do not change once they have arrived, so the fits of every window
    evaluated so far are kept (by the window's own samples: never served for other data) and
    the next evaluation fits only its own window (its drift check's shorter windows are earlier
    grid windows). :meth:`conclude` evaluates one window only: the last grid instant at or
    before the end of the samples (the one :meth:`ready` has just found sure, or the cap, or
    the last before the samples ended). Asked at every grid instant, it gives the answers of
    the method without a session; asked at fewer (``OnlineEstimator.update_block``), the
    windows it skipped are never fitted, and a bounce of the link that only they would have
    shown is not carried to the later windows (``evaluate_from_t1_or_hold``'s ``bounced``).

    Between evaluations, :meth:`prepare` fits ahead of time, as soon as their samples have
    arrived, the shorter windows the coming evaluations read (their drift check's reference and,
    should one be declared, its slip check's), so that the evaluation at the instant that
    becomes sure fits little more than its own window. Every fit is a function of its window's
    samples alone, so the answers are the same whether or not it was prepared.
    """

    def __init__(self, method: FastMethod) -> None:
        self.method = method
        self._caches: tuple[FitCache, FitCache] = ({}, {})
        # Digest of each window asked, by its last index (for the evaluation count)
        self._asked: dict[int, bytes] = {}
        # What the evaluations so far saw of the link bouncing in their windows from t_1
        # (evaluate_from_t1_or_hold's ``bounced``: None for nothing; not None once one
        # restarted its window at the end of the hold)
        self._bounced: tuple[float, float] | None = None
        # Windows (start, end, which cache) prepared, and the plan of those to prepare
        self._prepared: set[tuple[int, int, int]] = set()
        self._planned: tuple[object, list[tuple[int, int, int, int]]] = (None, [])
        # The evidence :meth:`ready` was last asked on and the window it evaluated
        self._last: tuple[Evidence, ScanInputs, WindowEstimate] | None = None

    @property
    def name(self) -> str:
        """The method's name."""
        return self.method.name

    def session(self) -> FastSession:
        """A fresh session of the same method (an online estimator takes one per manoeuvre)."""
        return self.method.session()

    def due(self, samples_since_t1: int, sample_period: float) -> bool:
        """As :meth:`FastMethod.due`."""
        return self.method.due(samples_since_t1, sample_period)

    def _evaluate(
        self, inputs: ScanInputs, evidence: Evidence, end: int, final: bool
    ) -> WindowEstimate:
        """:func:`.window.evaluate_from_t1_or_hold` on the window ending at ``end``, remembered; the
        slip check's early statics only for the ``final`` window (the one concluded on)."""
        window = evaluate_from_t1_or_hold(
            inputs._replace(end_index=end),
            evidence.hold_end,
            self._caches,
            second_mode_chooser(evidence),
            with_early_statics=final,
            bounced=self._bounced,
        )
        self._bounced = bounced_from_t1(window, inputs, self._bounced, evidence.hold_end)
        self._asked[end] = window_key(
            inputs.channels,
            inputs.rest_index,
            end,
            inputs.sample_period,
            inputs.band,
            inputs.config,
            inputs.push,
        )[2]
        return window

    def ready(self, evidence: Evidence) -> bool:
        """As :meth:`FastMethod.ready`, with this manoeuvre's fits."""
        offsets = evaluation_offsets(evidence.sample_period, self.method.config)
        if evidence.end_index >= evidence.rest_index + int(offsets[-1]):
            return True
        inputs = scan_inputs(evidence, self.method.config)
        window = self._evaluate(inputs, evidence, evidence.end_index, final=False)
        self._last = (evidence, inputs, window)
        return window.sure

    def _kept(self, evidence: Evidence) -> tuple[ScanInputs, WindowEstimate] | None:
        """The inputs and the window :meth:`ready` evaluated last, when it was asked on this very
        evidence (the same objects: the samples and every other field but the trace); else
        None."""
        if self._last is None:
            return None
        asked, inputs, window = self._last
        same = all(
            getattr(asked, name.name) is getattr(evidence, name.name)
            for name in dataclasses.fields(Evidence)
            if name.name != "trace"
        )
        return (inputs, window) if same else None

    def _plan(
        self, rest_index: int, hold_end: int, sample_period: float
    ) -> list[tuple[int, int, int, int]]:
        """The shorter windows the evaluations from ``hold_end`` on read besides their own, as
        (start, end, cache: 0 from t_1, 1 from the hold's end, the first grid instant that reads
        it), by end: for every grid instant at or after ``hold_end``, the drift check's
        reference (2/3) and, with the direction check on, the slip check's (1/2) of its window
        from t_1 and, once an evaluation restarted at the hold's end or saw the link bounce, of
        its window from there."""
        from_hold = self._bounced is not None
        key = (rest_index, hold_end, sample_period, from_hold)
        if self._planned[0] == key:
            return self._planned[1]
        config = self.method.config
        instants = rest_index + evaluation_offsets(sample_period, config)
        starts = [(rest_index, 0)] + ([(hold_end, 1)] if from_hold else [])
        fractions = (2.0 / 3.0,) if config.max_direction_drift is None else (2.0 / 3.0, 0.5)
        first_reader: dict[tuple[int, int, int], int] = {}
        for j in instants[instants >= hold_end][::-1]:
            for begin, cache in starts:
                for fraction in fractions:
                    end = reference_index(begin, int(j), fraction, sample_period, config)
                    if end is not None:
                        first_reader[(begin, end, cache)] = int(j)
        plan = sorted(
            ((*item, j) for item, j in first_reader.items()), key=lambda item: (item[1], item[2])
        )
        self._planned = (key, plan)
        return plan

    def _next_to_prepare(
        self,
        last_index: int,
        rest_index: int,
        hold_end: int,
        sample_period: float,
        step_time: float,
    ) -> tuple[int, int, int, int] | None:
        """The first window of :meth:`_plan` not prepared yet whose samples (up to
        ``last_index``) have all arrived, and that the next evaluation reads or, when that
        evaluation's sample is more than ``step_time`` (s) of samples away, any later one."""
        instants = rest_index + evaluation_offsets(sample_period, self.method.config)
        coming = instants[(instants > last_index) & (instants >= hold_end)]
        following = int(coming[0]) if coming.size else None
        ahead = following is None or (following - last_index) * sample_period > step_time
        for item in self._plan(rest_index, hold_end, sample_period):
            if item[1] > last_index:
                return None
            if item[:3] not in self._prepared and (ahead or item[3] <= (following or 0)):
                return item
        return None

    def wants_to_prepare(
        self,
        last_index: int,
        rest_index: int,
        hold_end: int,
        sample_period: float,
        step_time: float = 0.0,
    ) -> bool:
        """Whether :meth:`prepare` has a window to fit once the samples up to ``last_index`` have
        arrived (t_1 at ``rest_index``, evaluations from ``hold_end`` on, T_s in s; a window
        only a later evaluation than the next reads waits while the next one's sample is less
        than ``step_time`` s away, so that a fit started now does not delay it); cheap."""
        item = self._next_to_prepare(last_index, rest_index, hold_end, sample_period, step_time)
        return item is not None

    def prepare(
        self, samples: FrontTrace, antenna: Antenna, hold_end: int, step_time: float = 0.0
    ) -> bool:
        """Fit one window a coming evaluation reads (the class docstring), from the samples the
        front end was fed so far (``samples``, of the manoeuvre ``antenna`` measured;
        evaluations from ``hold_end`` on; ``step_time`` as for :meth:`wants_to_prepare`), into
        this session's caches; False when there is none to fit.

        The fit is that of the evaluation itself (the same function of the same samples), so
        preparing changes no answer, only when its time is spent.
        """
        rest, ts = samples.rest_index, samples.sample_period
        if rest is None:
            return False
        item = self._next_to_prepare(samples.t.shape[0] - 1, rest, hold_end, ts, step_time)
        if item is None:
            return False
        begin, end, cache, _ = item
        channels = contact_channels(samples.theta, samples.force, samples.torque, antenna)
        config = self.method.config
        fit_window(channels, begin, end, ts, samples.band, config, self._caches[cache])
        self._prepared.add((begin, end, cache))
        return True

    def _asked_here(self, inputs: ScanInputs) -> set[int]:
        """Last indices of the windows asked on these very samples."""
        return {
            end
            for end, digest in self._asked.items()
            if end <= inputs.end_index
            and digest
            == window_key(
                inputs.channels,
                inputs.rest_index,
                end,
                inputs.sample_period,
                inputs.band,
                inputs.config,
                inputs.push,
            )[2]
        }

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        """The estimate at the last grid instant at or before ``evidence.end_index``.

        When :meth:`ready` was asked on these samples, one window is evaluated: that instant's
        (the one just found sure, or the cap, or the last before the samples ended), with
        status, evaluation count (windows asked) and cap as :meth:`FastMethod.conclude` gives
        them when every earlier instant was unsure, so the same estimate when asked at every
        instant. When it was not (offline, or other samples), as :meth:`FastMethod.conclude`.
        The window :meth:`ready` has just evaluated on the same evidence is taken as it is,
        with its slip reference added, rather than evaluated again.
        """
        method = self.method
        kept = self._kept(evidence)
        inputs = kept[0] if kept is not None else scan_inputs(evidence, method.config)
        asked = self._asked_here(inputs)
        offsets = evaluation_offsets(evidence.sample_period, method.config)
        instants = inputs.rest_index + offsets
        instants = instants[(instants >= evidence.hold_end) & (instants <= evidence.end_index)]
        if not asked or instants.size == 0:
            return method.conclude(evidence, self._caches)
        end = int(instants[-1])
        if kept is not None and kept[1].end_index == end:
            window = with_early_statics_of(inputs, kept[1], self._caches)
        else:
            window = self._evaluate(inputs, evidence, end, final=True)
        count = len(asked | {window.end_index})
        reached_cap = inputs.rest_index + int(offsets[-1]) <= evidence.end_index
        result = ScanResult(window, count, reached_cap and not window.sure)
        return conclude_fast(evidence, result, inputs.bias, method.config, method.name)
