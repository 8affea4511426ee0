"""``--method fast``: the contact point from a short record, declared as soon as it is sure.

The paper (Section 7) leaves reducing the estimation time as future work: its Estimator 1 needs a
1 s spectrum and its Estimator 2 a settled 5 rad/s low-pass filter. Here, on a window that grows
from t_1:

1. the five contact-load channels (R_y, R_z, Gamma - Gamma_g^m; gravity removed as in Eq. 21,
   sensor bias from the initial rest removed, :mod:`.static_fit`) are fitted with damped
   sinusoids with shared poles plus a polynomial of degree 2 to 4 (:mod:`.window_fit`,
   :mod:`.parametric`, order and degree by BIC): omega_1 with its standard error (widened by
   its drift between the window and its first 2/3), and the static loads with their
   covariance, without filter lag;
2. the torque/force ratio of the static loads gives x_c with its standard error;
3. both become a posterior over x_c on a 0.25 mm grid (:mod:`.likelihood`, :mod:`.window`);
4. the estimate is declared at the first evaluation whose 95 % interval is narrower than
   ``tolerance`` and that passes every check (:mod:`.checks`), or whose interval the model
   floors hold above it but within ``cap_tolerance`` and within ``settled_margin`` of what
   unlimited data could leave (:mod:`.window`). Evaluations run on a geometric
   grid (:mod:`.evaluation_grid`) from ``first_window`` (50 ms) after t_1, so t_e adapts to
   how easy the case is (:mod:`.search`); at ``cap`` (1 s) after t_1 the best estimate is given
   with status ``uncertain`` (:mod:`.conclude`). Whenever the posterior is split between two
   branches of omega_1(x_c), the second contact mode may choose one (:mod:`.second_mode`).

Every evaluation uses the samples up to its own instant only, so the streaming form (the
pipeline's ``OnlineEstimator`` asking a :class:`~.session.FastSession`'s ``due`` and ``ready``
at every sample) and the batch form (:class:`FastMethod` in ``estimate``, or :func:`.search.scan`)
declare at the same sample with the same numbers. Fed in blocks
(``OnlineEstimator.update_block``), the streaming form asks at each block's last evaluation
instant only, and a bounce of the link that only an instant it skipped would have seen is not
carried to the later windows (:func:`.window.evaluate_from_t1_or_hold`): its answer may then
differ from the batch form's.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from sensing_antenna.estimation.front.evidence import Evidence
from sensing_antenna.estimation.methods.fast.conclude import conclude_fast
from sensing_antenna.estimation.methods.fast.config import FastConfig
from sensing_antenna.estimation.methods.fast.evaluation_grid import evaluation_offsets
from sensing_antenna.estimation.methods.fast.search import evaluations, scan, scan_inputs
from sensing_antenna.estimation.methods.fast.second_mode import second_mode_chooser
from sensing_antenna.estimation.methods.fast.session import FastSession
from sensing_antenna.estimation.methods.fast.window import WindowEstimate
from sensing_antenna.estimation.methods.fast.window_fit import FitCache
from sensing_antenna.estimation.result import ContactEstimate

__all__ = ["FastMethod"]


@dataclass(frozen=True)
class FastMethod:
    """The fast method as a pipeline method: ``estimate(recording, antenna, FastMethod())``.

    Offline the pipeline hands over the samples up to its own t_e; this method searches them
    from t_1 on and declares at its own, earlier instant (reported as ``t_e``), using only the
    samples up to that instant. Online the pipeline takes a :meth:`session` per manoeuvre and
    asks its ``due`` after every sample and, on the cadence grid, its ``ready``; it concludes
    at the first ready sample, the same one.
    """

    config: FastConfig = field(default_factory=FastConfig)
    name: str = "fast"

    def due(self, samples_since_t1: int, sample_period: float) -> bool:
        """Whether the online form should evaluate after this sample (the evaluation grid)."""
        offsets = evaluation_offsets(sample_period, self.config)
        k = int(np.searchsorted(offsets, samples_since_t1))
        return k < offsets.size and int(offsets[k]) == samples_since_t1

    def session(self) -> FastSession:
        """A fresh online run of this method: keeps the window fits of one manoeuvre."""
        return FastSession(self)

    def ready(self, evidence: Evidence) -> bool:
        """Whether the window ending at ``evidence.end_index`` is sure or at the cap."""
        return self.session().ready(evidence)

    def history(self, evidence: Evidence, from_t1: bool = False) -> tuple[WindowEstimate, ...]:
        """Every evaluation of the growing window up to the cap, without stopping when sure.

        For studying the method (how the interval narrows, which check holds the declaration
        back): the first ``sure`` element at or after the end of the pipeline's hold is the
        one :meth:`conclude` declares. ``from_t1`` starts at ``first_window`` after t_1 instead
        of at the end of the hold.
        """
        inputs = scan_inputs(evidence, self.config)
        earliest = inputs.rest_index if from_t1 else evidence.hold_end
        return tuple(
            evaluations(inputs, earliest, evidence.hold_end, second_mode_chooser(evidence))
        )

    def conclude(
        self, evidence: Evidence, caches: tuple[FitCache, FitCache] | None = None
    ) -> ContactEstimate:
        """Scan the evidence from t_1 and give the first sure estimate (or the capped one).

        ``caches`` as in :func:`.search.evaluations`.
        """
        inputs = scan_inputs(evidence, self.config)
        result = scan(
            inputs, evidence.hold_end, evidence.hold_end, second_mode_chooser(evidence), caches
        )
        return conclude_fast(evidence, result, inputs.bias, self.config, self.name)
