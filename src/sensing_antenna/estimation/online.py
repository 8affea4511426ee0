"""The streaming form of the pipeline: :class:`OnlineEstimator`, one update per sample (or per
block of samples that arrived together).

It is the front end (:class:`~.front.frontend.FrontEnd`, the same object the offline form feeds
the whole recording) and a method: the method concludes from the evidence at t_e, or, if it can
stop early (:class:`~.methods.EarlyStopping`), from the evidence of an earlier instant it is
ready at. Both forms therefore give the same estimate on the same samples.
"""

from __future__ import annotations

import dataclasses

from numpy.typing import ArrayLike

from sensing_antenna.antenna import Antenna
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.front.evidence import Evidence
from sensing_antenna.estimation.front.frontend import FrontEnd, one_sample
from sensing_antenna.estimation.front.steps import samples
from sensing_antenna.estimation.methods import (
    EarlyStopping,
    EstimationMethod,
    Preparing,
    Sessioned,
    resolve_method,
)
from sensing_antenna.estimation.pipeline import conclude, method_arithmetic
from sensing_antenna.estimation.result import ContactEstimate

__all__ = ["OnlineEstimator"]


class OnlineEstimator:
    """Streaming form of :func:`~sensing_antenna.estimation.pipeline.estimate`.

    Parameters
    ----------
    antenna : Antenna
    sample_period : float
        T_s (s) of the samples that will be fed (those their time stamps skip are put back).
        Samples whose first time stamps step by another period are ``bad_input``
        (:func:`~.front.steps.declared_period_problem`).
    method : str or EstimationMethod
        As for ``estimate``.
    config : EstimatorConfig, optional

    Attributes
    ----------
    result : ContactEstimate or None
        The estimate once given, else None.

    Notes
    -----
    :meth:`update` returns the estimate exactly once, at the sample it is given (t_e, or the
    earlier instant a method that stops early is ready at; up to 21 samples later at 1 kHz when
    a suspected corrupted sample near it waits for the samples that decide it, more when it
    lies inside another channel's run, :mod:`.front.spikes`), and None
    otherwise (also after the estimate). :meth:`finalize` closes a run that ended first (no
    contact, no push, too short) and returns the estimate ``estimate`` gives on the same
    samples. Samples the time stamps skip are put back by linear interpolation as they become
    known (:meth:`~.front.frontend.FrontEnd.update_block`), and more than
    ``config.gap_limit(T_s)`` in a row are remembered as gaps; the indices below count them.
    """

    def __init__(
        self,
        antenna: Antenna,
        sample_period: float,
        method: str | EstimationMethod = "paper",
        config: EstimatorConfig | None = None,
    ) -> None:
        self.antenna = antenna
        self.sample_period = float(sample_period)
        self.method = resolve_method(method)
        self.config = config if config is not None else EstimatorConfig()
        self._front = FrontEnd(antenna, self.sample_period, self.config, declared=True)
        self.reset()

    def reset(self) -> None:
        """Forget every sample: ready for a new manoeuvre."""
        self._front.reset()
        self.result: ContactEstimate | None = None
        # A method that keeps state over one manoeuvre (``fast``: its window fits) runs as a
        # session of its own; the others are used as they are
        self._run = self.method.session() if isinstance(self.method, Sessioned) else self.method
        self._early = self._run if isinstance(self._run, EarlyStopping) else None
        self._preparing = self._run if isinstance(self._run, Preparing) else None

    @property
    def n_samples(self) -> int:
        """Samples held since :meth:`reset`: those fed and those put back where the time stamps
        skipped some, less those held back until a suspected corruption among them is decided
        (:func:`.front.spikes.spike_longest` + 1, 21 at 1 kHz, or more from the start of
        another channel's run)."""
        return self._front.n_samples

    @property
    def contact_index(self) -> int | None:
        """Sample of t_c (counted from the first after :meth:`reset`, the samples put back
        included), once found."""
        return self._front.contact_index

    @property
    def rest_index(self) -> int | None:
        """Sample of t_1 (counted as :attr:`contact_index`), once found."""
        return self._front.rest_index

    @property
    def input_problem(self) -> str | None:
        """Why the samples up to t_c are not in the format's units and signs, known at t_c
        (the estimate's status will be ``implausible_input``), else None."""
        return self._front.input_problem

    @property
    def tare(self) -> str | None:
        """How the sensor was tared at t_c: ``rest``, ``approach``, or ``none`` when the samples
        began too soon before it (a stream joined in the sweep: the contact may be the contact
        detector's start, not a touch, and the estimate will not be ``ok``); None before t_c."""
        return self._front.tare

    def update(
        self, t: float, theta: ArrayLike, force: ArrayLike, torque: ArrayLike
    ) -> ContactEstimate | None:
        """Feed one sample (a block of one: t in s, theta (2,) in rad, force and torque (3,) in
        N and N m, motor frame); returns the estimate (once), else None."""
        return self.update_block(*one_sample(t, theta, force, torque))

    def update_block(
        self,
        t: ArrayLike,
        theta: ArrayLike,
        force: ArrayLike,
        torque: ArrayLike,
        *,
        every_instant: bool = False,
    ) -> ContactEstimate | None:
        """Feed the samples that arrived together; returns the estimate (once), else None.

        The front end takes every sample, but a method that stops early (``fast``) is asked
        only at the last of its evaluation instants in the block. A real-time loop that feeds
        whatever arrived since its previous call therefore falls behind by about one
        evaluation, however long an evaluation takes on its machine; the estimate is that of the
        grid instant asked (``t_e``), which may be later than the first sure instant
        sample-by-sample feeding would give. A block that reaches the pipeline's own end before
        any instant was asked concludes as the offline method does.

        With ``every_instant`` the method is asked at every evaluation instant of the block in
        turn, up to the first it is ready at (and before the pipeline's own end when the block
        reaches it), as feeding the block sample by sample would: the estimate of
        :func:`~sensing_antenna.estimation.pipeline.estimate` on the same samples however they
        are cut into blocks, at the cost of evaluating every instant.

        The samples are as for :meth:`FrontEnd.update_block
        <sensing_antenna.estimation.front.frontend.FrontEnd.update_block>`: t (n,) in s, theta
        (n, 2) in rad, force and torque (n, 3) in N and N m, motor frame; a
        :class:`~sensing_antenna.errors.FieldError` names a misshapen one.
        """
        front = self._front
        first = front.n_samples
        if self.result is not None:
            return None
        outcome = front.update_block(t, theta, force, torque)
        ask_first = every_instant and isinstance(outcome, Evidence)
        if outcome is not None and not ask_first:
            return self._emit(conclude(outcome, self._run))
        if self._early is None or front.first_evaluation_index is None:
            return None if outcome is None else self._emit(conclude(outcome, self._run))
        rest = front.rest_index
        assert rest is not None
        start = max(first, front.first_evaluation_index)
        if every_instant:
            # every instant in turn, before the pipeline's end when the block reaches it
            stop = outcome.end_index if isinstance(outcome, Evidence) else front.n_samples
            indices = range(start, stop)
        else:
            # the last evaluation instant of the block, causally: the evidence up to it only
            indices = range(front.n_samples - 1, start - 1, -1)
        for index in indices:
            if self._early.due(index - rest, self.sample_period):
                evidence = front.evidence_at(index)
                with method_arithmetic():
                    is_ready = isinstance(evidence, Evidence) and self._early.ready(evidence)
                if is_ready:
                    assert isinstance(evidence, Evidence)
                    traced = dataclasses.replace(evidence, trace=front.trace(evidence))
                    return self._emit(conclude(traced, self._run))
                if not every_instant:
                    break
        return None if outcome is None else self._emit(conclude(outcome, self._run))

    def prepare(self, step_time: float = 0.0) -> bool:
        """Use a moment the caller has nothing to feed: let a method that can
        (:class:`~.methods.Preparing`, ``fast``) do one step of the work its coming evaluations
        will need from the samples already fed (from t_1 on). Returns whether there was such a
        step (call again while idle), False when there is nothing to do (cheap). Changes no
        estimate.

        ``step_time`` (s): how long a step is expected to take (the caller's last one, say).
        Work that only a later evaluation than the next needs waits while the next one's
        sample, the samples arriving at their own pace, is due sooner than that.
        """
        front, preparing = self._front, self._preparing
        rest = front.rest_index
        if self.result is not None or preparing is None or rest is None:
            return False
        hold_end = front.first_evaluation_index
        if hold_end is None:
            # the end of the hold after t_1 the configuration gives, until the front end judges it
            config, ts = self.config, self.sample_period
            hold_end = rest + max(samples(config.frame_window, ts), samples(config.rest_window, ts))
        last, ts = front.n_samples - 1, self.sample_period
        if not preparing.wants_to_prepare(last, rest, hold_end, ts, step_time):
            return False
        with method_arithmetic():
            return preparing.prepare(front.trace(), self.antenna, hold_end, step_time)

    def _emit(self, result: ContactEstimate) -> ContactEstimate:
        self.result = result
        return result

    def finalize(self) -> ContactEstimate:
        """Close the run at the end of the samples; returns the estimate (given or final)."""
        if self.result is not None:
            return self.result
        return self._emit(conclude(self._front.finish(), self._run))
