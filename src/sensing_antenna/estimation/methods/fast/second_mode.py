"""The second contact mode chooses between the two branches of omega_1(x_c).

Where omega_1 is reached at two contact points and the torque/force ratio cannot tell them
apart, the paper's second-mode test (:func:`~.fusion.second_mode_choice`) on the spectrum of the
window's own samples may choose one: at every window whose posterior holds both branches
(``FastConfig.branch_by_second_mode``), and at the cap, where a window too short for the test
has it read the samples from t_1. Before an answer is given on one branch, the same spectrum
may object to it with less than a choice needs (:func:`~.fusion.second_mode_against`, the
paper method's rule).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.front.evidence import Evidence
from sensing_antenna.estimation.methods.fast.config import FastConfig
from sensing_antenna.estimation.methods.fast.curves import curve_table
from sensing_antenna.estimation.methods.fast.likelihood import ContactPosterior
from sensing_antenna.estimation.methods.paper.frequency import evidence_frequency, second_mode_peak
from sensing_antenna.estimation.methods.paper.fusion import (
    predicted_omega2,
    second_mode_against,
    second_mode_choice,
)

if TYPE_CHECKING:
    from sensing_antenna.estimation.methods.fast.window import WindowEstimate

__all__ = [
    "BranchChooser",
    "branch_at_cap",
    "narrowed_by_second_mode",
    "on_chosen_branch",
    "second_mode_chooser",
    "second_mode_objection",
]

FloatArray = NDArray[np.float64]

#: Which of two candidate contact points (m) the window [start, end] (sample indices) with
#: fundamental omega_1 (rad/s) supports: 0, 1 or None when it does not say, and the test's
#: report (see :func:`second_mode_chooser`).
BranchChooser = Callable[[int, int, float, tuple[float, ...]], "tuple[int | None, dict[str, Any]]"]


def second_mode_chooser(evidence: Evidence) -> BranchChooser:
    """The second contact mode's answer on a window of the evidence (a :data:`BranchChooser`).

    The paper's test (:func:`~.fusion.second_mode_choice`: a clear spectral peak within
    ``omega2_window`` of one candidate's omega_2, ten times stronger than near the other's) on
    the spectrum of the window's own samples [start, end], online and offline alike. It is not
    asked (no answer) when the window's Hann main lobe, +-4 pi / T_w, is as wide as the gap
    between the candidates' omega_2 (the other candidate's search window would lie on the
    lobe's slope and hold no peak whatever the truth). An answer whose peak lies nearer 2 or 3
    omega_1 than the chosen candidate's omega_2 is dropped: a clipping contact's harmonic may be
    what it saw (at 0.70 m on the paper link 3 omega_1 is 2.9 % from the other candidate's
    omega_2). The notes' ``"against"`` says, per candidate, whether the spectrum speaks against
    it by the paper method's rule (:func:`~.fusion.second_mode_against`), a peak that is not
    nearer such a harmonic.
    """

    def choose(
        start: int, end: int, omega1: float, candidates: tuple[float, ...]
    ) -> tuple[int | None, dict[str, Any]]:
        omega2 = predicted_omega2(evidence, candidates)
        lobe = 4.0 * math.pi / ((end - start) * evidence.sample_period)
        if lobe >= abs(omega2[0] - omega2[1]):
            return None, {"not_asked": f"main lobe +-{lobe:.0f} rad/s spans the candidates"}
        window = dataclasses.replace(evidence, rest_index=start, end_index=end)
        component = evidence_frequency(window).component
        choice, notes = second_mode_choice(window, component, candidates)

        def harmonic_near(k: int) -> float | None:
            # the harmonic of omega_1 nearer candidate k's peak than its omega_2, if any
            peak = notes["peak_omega"][k]
            for harmonic in (2.0 * omega1, 3.0 * omega1):
                if abs(peak - harmonic) < abs(peak - omega2[k]):
                    return harmonic
            return None

        against = [
            second_mode_against(notes, k, evidence.config) is not None
            and harmonic_near(1 - k) is None
            for k in (0, 1)
        ]
        notes = {**notes, "against": against}
        if choice is None:
            return choice, notes
        # The peak the answer rests on, nearer a harmonic than the candidate's omega_2?
        harmonic = harmonic_near(choice)
        if harmonic is not None:
            dropped = (
                f"the peak at {notes['peak_omega'][choice]:.1f} rad/s is nearer "
                f"{harmonic:.1f} rad/s, a harmonic of omega_1"
            )
            return None, {**notes, "dropped": dropped}
        return choice, notes

    return choose


def on_chosen_branch(
    posterior: ContactPosterior, candidates: tuple[float, ...], choice: int | None
) -> ContactPosterior | None:
    """``posterior`` conditioned on the branch of ``candidates[choice]``; None when there is no
    choice or that branch holds no mass."""
    if choice is None:
        return None
    branch = posterior.branch_of(candidates[choice])
    if posterior.branch_probability[branch] <= 0.0:
        return None
    return posterior.given_branch(branch)


def second_mode_objection(
    posterior: ContactPosterior,
    candidates: tuple[float, ...],
    omega1: float,
    start: int,
    end: int,
    choose_branch: BranchChooser,
) -> tuple[str, dict[str, Any]]:
    """Why the second contact mode says the posterior's branch is wrong ("" if it does not),
    and the chooser's notes ({} when not asked).

    With two candidates of omega_1 (rad/s) on different branches, the chooser is asked on the
    window [start, end]; an answer on the other branch than the posterior's maximum objects, and
    so does a spectrum that speaks against the candidate on the posterior's branch (the notes'
    ``"against"``): an answer about to be given needs less evidence against it to wait than a
    branch needs to be chosen.
    """
    if len(candidates) != 2:
        return "", {}
    choice, answer = choose_branch(start, end, omega1, candidates)
    return _objection(posterior, candidates, choice, answer), answer


def _objection(
    posterior: ContactPosterior,
    candidates: tuple[float, ...],
    choice: int | None,
    notes: dict[str, Any],
) -> str:
    """Why the chooser's ``choice``, or its notes' ``"against"``, contradicts the branch of
    ``posterior``'s maximum; ""."""
    own = posterior.branch_of(posterior.x_c)
    mine = [k for k in (0, 1) if posterior.branch_of(candidates[k]) == own]
    if choice is not None:
        if choice in mine:
            return ""
        return (
            f"the second contact mode points to x_c = {candidates[choice]:.3f} m, on the other "
            f"branch of omega_1 than the posterior's x_c = {posterior.x_c:.3f} m"
        )
    against = notes.get("against", (False, False))
    if len(mine) != 1 or not against[mine[0]]:
        return ""
    return (
        f"the spectrum speaks against the posterior's x_c = {posterior.x_c:.3f} m: a peak near "
        f"the second contact mode of x_c = {candidates[1 - mine[0]]:.3f} m, on the other branch "
        "of omega_1, ten times stronger than near its own"
    )


def branch_at_cap(
    evidence: Evidence,
    window: WindowEstimate,
    candidates: tuple[float, ...],
    answers: bool = False,
) -> tuple[ContactPosterior, dict[str, Any]]:
    """At the cap, let the second contact mode choose between two branches the ratio cannot.

    Asked (:func:`second_mode_chooser`, on the final window, or from t_1 to the cap when that
    window is too short to resolve the candidates' omega_2) when the posterior still holds
    both branches, when the window's higher mode contradicted the branch it holds, or when the
    window ``answers`` at the cap on one branch (its interval within ``cap_tolerance``, which
    no window before it reached at ``tolerance``, where the windows ask); with
    ``branch_by_second_mode`` on, the first case has been asked at the window already. When
    decisive the posterior is conditioned on that branch. When it does not condition (no choice,
    or a branch the posterior gives no probability) and the window answers, an objection to the
    answer's branch (:func:`second_mode_objection`'s rule) is in the notes
    (``second_mode_objection``, a disagreement for the conclusion); otherwise the posterior is
    unchanged.
    """
    posterior = window.posterior
    split = max(posterior.branch_probability) < posterior.level
    if len(candidates) != 2 or not (split or window.branch_contradicted or answers):
        return posterior, {}
    asked = bool(window.second_mode) and "not_asked" not in window.second_mode
    if window.branch_chosen_by_second_mode or (split and asked):
        return posterior, {}
    choose = second_mode_chooser(evidence)
    choice, notes = choose(window.start_index, window.end_index, window.omega1, candidates)
    if "not_asked" in notes and window.start_index > evidence.rest_index:
        # a window restarted late is too short to resolve the two omega_2: the samples from
        # t_1 to the cap, the span the paper's own test reads
        choice, notes = choose(evidence.rest_index, window.end_index, window.omega1, candidates)
        notes = {**notes, "span": "from t_1"}
    conditioned = on_chosen_branch(posterior, candidates, choice)
    if conditioned is None:
        # no choice, or a branch the posterior gives no probability: no conditioning, but an
        # answer would rest on a branch the second mode may speak against
        objection = _objection(posterior, candidates, choice, notes) if answers else ""
        if objection:
            return posterior, {"second_mode": notes, "second_mode_objection": objection}
        return posterior, {"second_mode": notes}
    return conditioned, {"second_mode": notes, "branch_chosen_by": "omega2"}


def narrowed_by_second_mode(
    evidence: Evidence, window: WindowEstimate, posterior: ContactPosterior, config: FastConfig
) -> tuple[ContactPosterior | None, dict[str, Any]]:
    """At the cap: ``posterior`` times the likelihood of the window's second contact mode.

    Near the top of omega_1(x_c) the fundamental hardly moves with x_c while omega_2 changes by
    several rad/s per cm, so omega_2 places the contact there. It is used only on a link whose
    calibration measured omega_2 (``Link.mode2_scatter``): the measured peak
    (:func:`~.paper.frequency.second_mode_peak` on the window's own samples, near the model's
    omega_2 at the posterior's x_c) enters as N(omega_2; omega_2(x_c), sigma^2): sigma is the
    calibration's scatter or ``higher_mode_floor``, the larger, times omega_2 (as omega_1's
    floor is the larger of its calibration's scatter and ``frequency_floor``), and the peak's
    statistical error, sqrt(6 / Q) / T_w for a peak of quality Q over a window of T_w seconds,
    in quadrature. Not used without a calibrated T_e, or when ``higher_modes`` has put a
    fitted higher mode in the posterior already.

    Returns the narrowed posterior (None when not used) and notes: why not, or the peak, its
    sigma and how far it lies from the model over the posterior's interval. A peak farther
    than ``max_disagreement`` sigmas from omega_2 at every x_c of the interval is not used and
    is said (``"disagrees"``): the device departs from the model more than its calibration.
    Nor is it used when the posterior holds another branch whose own omega_2 has a clear peak
    of its own (:func:`_rival_peak`): a spectrum ringing near both branches' omega_2 does not
    tell them apart, and the likelihood would choose the branch the posterior's maximum
    happened to lie on.
    """
    link = evidence.antenna.link
    if link.mode2_scatter is None or link.calibrated_t is None:
        return None, {"not_used": "no calibration measured omega_2 (link.mode2_scatter)"}
    if config.higher_modes:
        return None, {"not_used": "a fitted higher mode is already in the posterior"}
    table = curve_table(
        link, posterior.branch_edges[0], posterior.branch_edges[-1], config.grid_step
    )
    omega2_of_x = np.interp(posterior.grid, table.grid, table.higher[:, 0])
    expected = float(np.interp(posterior.x_c, posterior.grid, omega2_of_x))
    samples = dataclasses.replace(
        evidence, rest_index=window.start_index, end_index=window.end_index
    )
    component = evidence_frequency(samples).component
    peak = second_mode_peak(samples, component, expected, window.omega1)
    if peak is None:
        return None, {"not_used": f"no clear peak of omega_2 near {expected:.1f} rad/s"}
    rival = _rival_peak(samples, component, posterior, omega2_of_x, window.omega1, peak.omega)
    if rival is not None:
        return None, {
            "not_used": (
                f"clear peaks near the second contact modes of both branches of omega_1 "
                f"({peak.omega:.1f} rad/s near {expected:.1f}, {rival[1]:.1f} rad/s near "
                f"{rival[0]:.1f}, x_c = {rival[2]:.3f} m)"
            )
        }
    # the model's error, and the peak's own: the Cramer-Rao bound of a sinusoid's frequency in
    # white noise over T_w, 3 / (Q T_w^2) with Q the spectrum's signal to noise, doubled for
    # the windowed peak's estimator and the median the quality is taken over
    span = samples.spectrum_slice
    duration = (span.stop - span.start) * evidence.sample_period
    statistical = math.sqrt(6.0 / peak.quality) / duration
    sigma = math.hypot(max(link.mode2_scatter, config.higher_mode_floor) * peak.omega, statistical)
    z = (peak.omega - omega2_of_x) / sigma
    low, high = posterior.interval
    inside = (posterior.grid >= low) & (posterior.grid <= high)
    nearest = float(np.min(np.abs(z[inside]))) if np.any(inside) else math.inf
    notes: dict[str, Any] = {
        "omega2": peak.omega,
        "omega2_sigma": sigma,
        "omega2_statistical": statistical,
        "omega2_quality": peak.quality,
        "omega2_z_in_interval": nearest,
    }
    if nearest > config.max_disagreement:
        notes["disagrees"] = (
            f"the second contact mode at {peak.omega:.1f} rad/s lies {nearest:.1f} standard "
            f"deviations or more from the model's omega_2 at every x_c of the interval: the "
            "device departs from the model more than its calibration measured"
        )
        return None, notes
    return posterior.times(np.exp(-0.5 * z**2)), notes


def _rival_peak(
    samples: Evidence,
    component: str,
    posterior: ContactPosterior,
    omega2_of_x: FloatArray,
    omega1: float,
    found: float,
) -> tuple[float, float, float] | None:
    """A clear peak of omega_2 for another branch than the posterior's maximum's, apart from the
    peak ``found`` (rad/s) there: (that branch's omega_2 at its own maximum, the peak, that
    maximum x_c), all rad/s but x_c (m); None when no branch holding at least 1 - ``level`` of
    the posterior mass has one. Peaks within ``omega2_window`` of ``found`` are the same peak
    (near the top of omega_1(x_c) both branches' omega_2 meet)."""
    window = samples.config.omega2_window
    own = posterior.branch_of(posterior.x_c)
    for branch, mass in enumerate(posterior.branch_probability):
        if branch == own or not mass >= 1.0 - posterior.level:
            continue
        on_branch = posterior.given_branch(branch)
        expected = float(np.interp(on_branch.x_c, posterior.grid, omega2_of_x))
        peak = second_mode_peak(samples, component, expected, omega1)
        if peak is not None and abs(peak.omega - found) > window * found:
            return expected, peak.omega, on_branch.x_c
    return None
