"""The streaming form of the pipeline: :class:`OnlineEstimator`, one update per sample (or per
block of samples that arrived together).

It keeps only cheap per-sample state (contact detector, Eq. 20 filters, the rest test, the
moving mean of the ratio and its spread) and, at t_1 + hold and at t_e, calls the very functions
of :mod:`.evidence` the offline form calls on the same samples, so both give identical results.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Antenna
from sensing_antenna.detection.contact import ContactDetector
from sensing_antenna.detection.filters import FirstOrderLowPass
from sensing_antenna.detection.push import PushCriterion, PushMonitor
from sensing_antenna.errors import FieldError
from sensing_antenna.estimation.config import EstimatorConfig, no_t1_reason
from sensing_antenna.estimation.front.evidence import (
    ContactStart,
    Evidence,
    at_contact,
    bad_input,
    build_evidence,
    hold_push,
    planned_end,
    ratio_tolerance,
    samples,
    search_band,
)
from sensing_antenna.estimation.front.ratio import (
    filtered_contact_loads,
    perpendicular_ratio,
    perpendicular_ratio_sample,
)
from sensing_antenna.estimation.methods import EstimationMethod, resolve_method
from sensing_antenna.estimation.result import ContactEstimate, Status

__all__ = ["OnlineEstimator", "early_result"]

FloatArray = NDArray[np.float64]


class _Instant(NamedTuple):
    """An evaluation instant and the streaming state the evidence then needs."""

    end: int  # index of its last sample
    converged: int | None  # index where the ratio had converged, if it had
    n_gaps: int  # gaps found up to it


def early_result(
    status: Status,
    reason: str,
    method: str,
    diagnostics: dict[str, Any],
    t_c: float = math.nan,
    t_1: float = math.nan,
) -> ContactEstimate:
    """A result given before t_e (no contact, no push, bad input): no estimate of x_c."""
    return ContactEstimate(
        status=status,
        reason=reason,
        method=method,
        t_c=t_c,
        t_1=t_1,
        diagnostics=dict(diagnostics),
    )


class OnlineEstimator:
    """Streaming form of :func:`~sensing_antenna.estimation.pipeline.estimate`.

    Parameters
    ----------
    antenna : Antenna
    sample_period : float
        T_s (s) of the uniform samples that will be fed.
    method : str or EstimationMethod
        As for ``estimate``.
    config : EstimatorConfig, optional

    Attributes
    ----------
    result : ContactEstimate or None
        The estimate once given (at t_e), else None.

    Notes
    -----
    :meth:`update` returns the estimate exactly once, at the sample t_e, and None otherwise
    (also after the estimate). :meth:`finalize` closes a run that ended before t_e (no contact,
    no push, too short) and returns the estimate ``estimate`` gives on the same samples. Time
    stamps that skip more than ``config.max_gap`` samples are remembered as gaps.
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
        cfg = self.config
        self._band = search_band(antenna.link, cfg)
        self._w_rest = samples(cfg.rest_window, self.sample_period)
        self._w_hold = max(samples(cfg.frame_window, self.sample_period), self._w_rest)
        self._w_conv = samples(cfg.convergence_window, self.sample_period)
        self._n_wait = samples(cfg.max_ratio_wait, self.sample_period)
        self._link = antenna.link
        self._weight = antenna.link.weight
        self._rigidity = antenna.link.flexural_rigidity
        self._detector = ContactDetector(antenna, self.sample_period)
        # t1_source = "push": the push criterion's decision, with the same contact detector inside
        self._push = (
            PushMonitor(
                cfg.push_criterion or PushCriterion(),
                antenna,
                self.sample_period,
                contact_detector=self._detector,
            )
            if cfg.t1_source == "push"
            else None
        )
        self._filters = [
            FirstOrderLowPass(cfg.lowpass_cutoff, self.sample_period) for _ in range(6)
        ]
        self.reset()

    def reset(self) -> None:
        """Forget every sample: ready for a new manoeuvre."""
        self._detector.reset()  # the push monitor, if any, shares it
        if self._push is not None:
            self._push.reset()
        for low_pass in self._filters:
            low_pass.reset()
        capacity = 4096
        self._t = np.empty(capacity)
        self._theta = np.empty((capacity, 2))
        self._force = np.empty((capacity, 3))
        self._torque = np.empty((capacity, 3))
        self._ratio = np.empty(capacity)
        self._mean = np.empty(capacity)
        self._n = 0
        self._gaps: list[tuple[float, float]] = []
        self._contact: int | None = None
        self._tolerance = math.nan
        self._rest: int | None = None
        self._held = False
        self._converged: int | None = None
        self._ratio_tolerance = math.nan
        self._start: ContactStart | None = None
        self._offset: tuple[float, ...] = (0.0,) * 6
        self._planned: int | None = None
        self._done = False
        self._pending: _Instant | None = None
        self.result: ContactEstimate | None = None
        # A method that keeps state over one manoeuvre (``fast``: its window fits) runs as a
        # session of its own; the others are used as they are
        session = getattr(self.method, "session", None)
        self._run: EstimationMethod = session() if session is not None else self.method

    def _grow(self) -> None:
        size = 2 * self._t.shape[0]
        for name in ("_t", "_theta", "_force", "_torque", "_ratio", "_mean"):
            old = getattr(self, name)
            new = np.empty((size, *old.shape[1:]))
            new[: self._n] = old[: self._n]
            setattr(self, name, new)

    @property
    def n_samples(self) -> int:
        """Samples fed since :meth:`reset`."""
        return self._n

    def update(
        self,
        t: float,
        theta: Sequence[float] | FloatArray,
        force: Sequence[float] | FloatArray,
        torque: Sequence[float] | FloatArray,
    ) -> ContactEstimate | None:
        """Feed one sample; returns the estimate at t_e (once), else None.

        Parameters
        ----------
        t : float
            Sample time (s).
        theta : array_like, shape (2,)
            Motor angles (rad).
        force, torque : array_like, shape (3,)
            F/T sensor sample, motor frame (N, N m).
        """
        if self._done:
            return None
        out = self._take(t, theta, force, torque)
        if out is None and self._pending is not None:
            return self._ask_pending()
        return out

    def update_block(
        self, t: FloatArray, theta: FloatArray, force: FloatArray, torque: FloatArray
    ) -> ContactEstimate | None:
        """Feed the samples that arrived together; returns the estimate at t_e (once), else None.

        Every sample goes through the per-sample steps of :meth:`update`, but a method that
        stops early (``fast``) is asked only at the last of its evaluation instants in the
        block. A real-time loop that feeds whatever arrived since its previous call therefore
        falls behind by about one evaluation, however long an evaluation takes on its machine;
        the estimate is that of the grid instant asked (``t_e``), which may be later than the
        first sure instant sample-by-sample feeding would give. A block that reaches the
        pipeline's own end before any instant was asked concludes as the offline method does.

        Parameters
        ----------
        t : array, shape (n,)
            Sample times (s).
        theta : array, shape (n, 2)
            Motor angles (rad).
        force, torque : array, shape (n, 3)
            F/T sensor samples, motor frame (N, N m).
        """
        t, theta = np.atleast_1d(np.asarray(t, dtype=float)), np.asarray(theta, dtype=float)
        force, torque = np.asarray(force, dtype=float), np.asarray(torque, dtype=float)
        n = t.shape[0]
        for name, value, width in (("theta", theta, 2), ("force", force, 3), ("torque", torque, 3)):
            if value.shape != (n, width):
                raise FieldError(
                    name,
                    f"shape {value.shape}, expected ({n}, {width}) for {n} sample times",
                    "OnlineEstimator.update_block",
                )
        for k in range(n):
            if self._done:
                return None
            out = self._take(float(t[k]), theta[k], force[k], torque[k])
            if out is not None:
                return out
        if self._pending is not None and not self._done:
            return self._ask_pending()
        return None

    def _ask_pending(self) -> ContactEstimate | None:
        """Ask the method at the evaluation instant remembered by :meth:`_take`."""
        assert self._pending is not None
        evidence = self._evidence_now(True, self._pending)
        self._pending = None
        ready = getattr(self._run, "ready", None)
        if not isinstance(evidence, str) and ready is not None and ready(evidence):
            return self._emit(self._run.conclude(evidence))
        return None

    def _take(
        self,
        t: float,
        theta: Sequence[float] | FloatArray,
        force: Sequence[float] | FloatArray,
        torque: Sequence[float] | FloatArray,
    ) -> ContactEstimate | None:
        """The per-sample steps of :meth:`update`; an evaluation instant of a method that stops
        early is remembered in ``_pending`` (with the state the evidence then needs), not asked.
        """
        j = self._n
        if j == self._t.shape[0]:
            self._grow()
        if j > 0 and round((t - self._t[j - 1]) / self.sample_period) - 1 > self.config.max_gap:
            self._gaps.append((float(self._t[j - 1]), float(t)))
        theta1, theta2 = float(theta[0]), float(theta[1])
        fx, fy, fz = float(force[0]), float(force[1]), float(force[2])
        tx, ty, tz = float(torque[0]), float(torque[1]), float(torque[2])
        self._t[j] = t
        self._theta[j, 0] = theta1
        self._theta[j, 1] = theta2
        self._force[j] = (fx, fy, fz)
        self._torque[j] = (tx, ty, tz)
        self._n = j + 1
        # Section 4.2: contact loads R = F - F_g^m, Gamma - Gamma_g^m, then Eq. 20
        sin2, cos2 = math.sin(theta2), math.cos(theta2)
        filters = self._filters
        r_x = filters[0].update(fx + self._weight * sin2)
        r_y = filters[1].update(fy)
        r_z = filters[2].update(fz + self._weight * cos2)
        filters[3].update(tx)
        g_y = filters[4].update(ty - float(self._link.gravity_moment(theta2)))
        g_z = filters[5].update(tz)
        pushed = False
        if self._push is not None and self._rest is None:
            pushed = self._push.update(t, (theta1, theta2), force, torque)
        if self._contact is None:
            if self._push is not None:
                detected = self._detector.detected
            else:
                detected = self._detector.update(t, (theta1, theta2), force, torque)
            if not detected:
                return None
            index = self._detector.contact_index
            self._contact = j if index is None else index
            self._start = at_contact(
                self._theta,
                self._force,
                self._torque,
                self.antenna,
                self._contact,
                self.config,
                self.sample_period,
            )
            self._tolerance = self._start.rest_tolerance
            self._offset = tuple(float(v) for v in self._start.offset)
        if self._rest is None:
            if self._push is not None:
                if not pushed:
                    return None
                self._begin_hold(j, j)
            elif not self._rest_found(j):
                return None
        else:
            offset = self._offset
            self._ratio[j] = perpendicular_ratio_sample(
                r_x - offset[0],
                r_y - offset[1],
                r_z - offset[2],
                g_y - offset[4],
                g_z - offset[5],
                self._rigidity,
            )
        rest = self._rest
        assert rest is not None
        if not self._held:
            if j < rest + self._w_hold:
                return None
            problem = self._judge_hold(j)
            if problem is not None:
                return self._emit(problem)
        w = self._w_conv
        if self._converged is None and self._planned is None and j >= rest + w:
            # Moving average of the ratio over the last window, then its spread (ratio.py)
            self._mean[j] = self._ratio[j - w : j + 1].mean()
            if j >= rest + 2 * w:
                means = self._mean[j - w : j + 1]
                if means.max() - means.min() <= self._ratio_tolerance:
                    self._converged = j
                    self._planned = planned_end(rest, j, self.config, self.sample_period)
            if self._planned is None and j >= rest + self._n_wait:
                self._planned = planned_end(rest, None, self.config, self.sample_period)
        if self._planned is not None and j >= self._planned:
            return self._emit(self._conclude(complete=True))
        # A method that can stop early (``fast``) is asked on its own cadence, causally: the
        # instant is remembered here and asked by the caller (update: at once; update_block: the
        # block's last one)
        due = getattr(self._run, "due", None)
        if due is not None and due(j - rest, self.sample_period):
            self._pending = _Instant(j, self._converged, len(self._gaps))
        return None

    def _rest_found(self, j: int) -> bool:
        """The rest test at sample j; on success t_1 is set and the ratio filled from it."""
        assert self._contact is not None
        start = j - self._w_rest
        if start < self._contact:
            return False
        window = self._theta[start : j + 1]
        spread = window.max(axis=0) - window.min(axis=0)
        if not (spread[0] <= self._tolerance and spread[1] <= self._tolerance):
            return False
        self._begin_hold(start, j)
        return True

    def _begin_hold(self, start: int, j: int) -> None:
        """t_1 is sample ``start`` (known at sample j): fill the ratio from there."""
        self._rest = start
        reaction_f, torque_f = filtered_contact_loads(
            self._theta[: j + 1],
            self._force[: j + 1],
            self._torque[: j + 1],
            self.antenna,
            self.config.lowpass_cutoff,
            self.sample_period,
            None if self._start is None else self._start.offset,
        )
        self._ratio[start : j + 1] = perpendicular_ratio(
            reaction_f[start : j + 1], torque_f[start : j + 1], self._rigidity
        )

    def _judge_hold(self, j: int) -> ContactEstimate | None:
        """The push over the hold (same function as offline); a result when there is none."""
        assert self._contact is not None and self._rest is not None and self._start is not None
        hold = hold_push(
            self._theta[: j + 1],
            self._force[: j + 1],
            self._torque[: j + 1],
            self.antenna,
            self._start.offset,
            self._rest,
            self.config,
            self.sample_period,
        )
        if hold.frame is None:
            return early_result(
                Status.PUSH_NOT_REACHED,
                hold.problem or "",
                self.method.name,
                self._diagnostics(),
                float(self._t[self._contact]),
                float(self._t[self._rest]),
            )
        self._held = True
        _, self._ratio_tolerance = ratio_tolerance(
            hold, self.antenna, self.config, self.sample_period
        )
        return None

    def _diagnostics(self) -> dict[str, Any]:
        diag: dict[str, Any] = {"resampled": False}
        if self._start is not None:
            diag.update(
                {
                    "rest_tolerance": self._tolerance,
                    "tare": self._start.tare,
                    "load_offset": self._start.offset,
                }
            )
        return diag

    def _emit(self, result: ContactEstimate) -> ContactEstimate:
        self.result = result
        self._done = True
        return result

    def _evidence_now(self, complete: bool, at: _Instant | None = None) -> Evidence | str:
        """Evidence from the samples up to the instant ``at`` with the state it remembers
        (None: the last sample fed, and the state now)."""
        assert self._contact is not None and self._rest is not None
        if at is None:
            at = _Instant(self._n - 1, self._converged, len(self._gaps))
        return build_evidence(
            self._t,
            self._theta,
            self._force,
            self._torque,
            self.sample_period,
            self.antenna,
            self.config,
            self._band,
            self._contact,
            self._rest,
            at.converged,
            at.end,
            complete,
            self._gaps[: at.n_gaps],
            self._diagnostics(),
        )

    def _conclude(self, complete: bool) -> ContactEstimate:
        assert self._contact is not None and self._rest is not None
        evidence = self._evidence_now(complete)
        if isinstance(evidence, str):
            return early_result(
                Status.PUSH_NOT_REACHED,
                evidence,
                self.method.name,
                self._diagnostics(),
                float(self._t[self._contact]),
                float(self._t[self._rest]),
            )
        return self._run.conclude(evidence)

    def finalize(self) -> ContactEstimate:
        """Close the run at the end of the samples; returns the estimate (given or final)."""
        if self.result is not None:
            return self.result
        name = self.method.name
        n = self._n
        if n == 0:
            return self._emit(early_result(Status.BAD_INPUT, "no samples", name, {}))
        problem = bad_input(
            self._force[:n], self._torque[:n], self.sample_period, self._band[1], self.config
        )
        if problem is not None:
            return self._emit(early_result(Status.BAD_INPUT, problem, name, self._diagnostics()))
        if self._contact is None:
            limit = self._detector.threshold
            return self._emit(
                early_result(
                    Status.NO_CONTACT,
                    f"filtered residual stays at or below {limit:g} N m",
                    name,
                    self._diagnostics(),
                )
            )
        t_c = float(self._t[self._contact])
        if self._rest is None:
            return self._emit(
                early_result(
                    Status.PUSH_NOT_REACHED,
                    no_t1_reason(self.config, self._tolerance),
                    name,
                    self._diagnostics(),
                    t_c=t_c,
                )
            )
        return self._emit(self._conclude(complete=False))
