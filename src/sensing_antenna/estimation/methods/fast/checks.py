"""The checks of the fast method: what keeps a window from being declared, and the problems
reported with an estimate.

On the fundamental of a window (:mod:`.window_fit`): enough periods, and a drift reference (the
grid window of 2/3 the length) whose change widens the standard error; a fit through the push
stands only when it passes the same checks, is more precise and agrees. On the posterior
(:mod:`.window`): the torque/force ratio agrees with the maximum a posteriori x_c; the contact
stays closed (the predicted vibration of the contact force below the static push) and the push
plane rings at one fundamental (the link held at one point); omega_1 is
away from the top of the sensing curve; no higher mode of the fit points to another branch; the
measured omega_1 agrees with the sensing curve at the MAP x_c. On the estimate
(:func:`problems`): the static force does not turn between the window's first half and t_e
(slip); a window at the cap that is not sure answers ``ok`` only when every check but the
interval's width passed and the interval is within ``cap_tolerance`` (:func:`accepted_at_cap`).

Each check returns a note (empty when it passes) or a value with its note, so the window can
say why it is not sure.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Link
from sensing_antenna.beam import contact_to_base_shear
from sensing_antenna.estimation.front.evidence import first_mode_value
from sensing_antenna.estimation.methods.fast.config import FastConfig
from sensing_antenna.estimation.methods.fast.curves import CurveTable, contact_candidates
from sensing_antenna.estimation.methods.fast.likelihood import ContactPosterior
from sensing_antenna.estimation.methods.fast.parametric import DampedSinusoidFit
from sensing_antenna.estimation.methods.fast.planes import free_plane_share
from sensing_antenna.estimation.methods.fast.static_fit import StaticRatio
from sensing_antenna.estimation.result import Status

if TYPE_CHECKING:
    from sensing_antenna.estimation.methods.fast.search import ScanResult
    from sensing_antenna.estimation.methods.fast.window import WindowEstimate
    from sensing_antenna.estimation.methods.fast.window_fit import Fundamental

__all__ = [
    "accepted_at_cap",
    "branch_contradiction",
    "direction_change",
    "drift_check",
    "frequency_check",
    "frequency_sigma",
    "is_slip_reference",
    "opening_check",
    "other_fundamental",
    "peak_check",
    "periods_check",
    "periods_held",
    "problems",
    "push_agrees",
    "ratio_check",
]

#: Largest relative distance (dimensionless) between the fundamental of the slip check's half
#: window and the whole window's for the two to be the same mode. 0.1: well above the few per
#: cent by which short windows misread omega_1 (often at many of their standard errors, so the
#: test is not in standard errors), well below the distance to the nearest other contact mode
#: (above twice omega_1 on the paper link's sensing curves).
_SAME_MODE = 0.1


def periods_held(fit: DampedSinusoidFit, omega1: float) -> float:
    """How many periods of ``omega1`` (rad/s) the window of ``fit`` holds."""
    return fit.duration * omega1 / (2.0 * math.pi)


def periods_check(fit: DampedSinusoidFit, omega1: float, config: FastConfig) -> str:
    """Why the window is too short for a frequency: it holds fewer than ``min_periods`` periods
    of ``omega1`` (rad/s); "" when it holds enough."""
    periods = periods_held(fit, omega1)
    if periods < config.min_periods:
        return f"the window holds {periods:.2f} periods of omega_1"
    return ""


def drift_check(
    reference: DampedSinusoidFit | None,
    reference_mode: int | None,
    omega1: float,
    omega1_crb: float,
    config: FastConfig,
) -> tuple[float, str]:
    """The drift of omega_1 against the window of 2/3 the length, and why there is none.

    Parameters
    ----------
    reference : DampedSinusoidFit or None
        Fit of the shorter window (None: not on the grid, or too short for the model).
    reference_mode : int or None
        Index of its fundamental (None: none usable).
    omega1, omega1_crb : float
        The window's fundamental and its statistical standard error (rad/s).
    config : FastConfig

    Returns
    -------
    drift : float
        Change of omega_1 beyond what the noise explains (rad/s); NaN when there is no usable
        reference.
    note : str
        Why there is no usable reference; "" when there is one.
    """
    if reference is None or reference_mode is None:
        return math.nan, "no fundamental on the shorter window to check its drift"
    ref_periods = periods_held(reference, omega1)
    if ref_periods < config.min_periods:
        # Below min_periods the shorter window's own fundamental is too loose to see a
        # drift of the size that matters here: "no change seen" would mean nothing
        return math.nan, (
            f"the shorter window that checks the drift holds {ref_periods:.2f} periods of omega_1"
        )
    # Nested windows: the change of an efficient estimate has variance se_ref^2 - se^2
    # from noise alone; only the excess over that is drift
    change = omega1 - float(reference.omega[reference_mode])
    noise_part = max(float(reference.omega_se[reference_mode]) ** 2 - omega1_crb**2, 0.0)
    return math.sqrt(max(change**2 - noise_part, 0.0)), ""


def push_agrees(through: Fundamental, from_t1: Fundamental, config: FastConfig) -> bool:
    """Whether the window's fit through the push may stand for it.

    Its fundamental must pass every frequency check the window from t_1 passes, be more
    precise (drift term included), and agree with that of the window from t_1: the window
    from t_1 is part of the one through the push, so for efficient estimates of the same
    omega_1 their difference has variance se_t1^2 - se_push^2 (statistical parts); a
    difference beyond ``max_disagreement`` of its standard deviations means the push holds
    content the model does not describe (a bouncing contact, modes beyond
    ``push_max_modes``) that moved it (and when its statistical part is not the smaller, none
    is allowed). Without a fundamental from t_1 there is nothing to check it against, and it
    may not stand.
    """
    if through.mode is None or from_t1.mode is None:
        return False
    if not through.failed <= from_t1.failed:
        return False
    spread = math.sqrt(max(from_t1.omega1_crb**2 - through.omega1_crb**2, 0.0))
    return (
        through.omega1_se < from_t1.omega1_se
        and abs(through.omega1 - from_t1.omega1) <= config.max_disagreement * spread
    )


def is_slip_reference(
    half: DampedSinusoidFit | None, omega1: float, band: tuple[float, float], config: FastConfig
) -> bool:
    """Whether the fit of a window's first half may serve as the slip check's reference.

    It must hold ``min_periods`` periods of the whole window's fundamental ``omega1`` (rad/s)
    and a mode of ``band``, detected, within :data:`_SAME_MODE` of it: the fundamental, which
    need not be the strongest (the free plane's, :mod:`.planes`).
    """
    if half is None or periods_held(half, omega1) < config.min_periods:
        # Statics of a window too short for the model are not a reference (mode and offset
        # are confounded below a period or so)
        return False
    # A half that read another fundamental has put part of the vibration in its static part
    # (a slow, fast-decaying mode in its place): its statics are no reference either
    detected = half.detection() >= config.min_detection
    in_band = half.in_band(band)
    near = np.abs(half.omega - omega1) <= _SAME_MODE * omega1
    return bool(np.any(detected & in_band & near))


def ratio_check(
    statics: StaticRatio, x_map: float, model_sd: float, config: FastConfig
) -> tuple[float, str]:
    """Distance of the ratio from ``x_map`` (m) in its standard deviations (the statics model's
    ``model_sd`` (m) at ``x_map`` included), and the note when it exceeds ``max_disagreement``
    (else "")."""
    ratio = statics.ratio
    if not math.isfinite(ratio):
        return math.nan, ""
    # Posterior predictive check of the ratio at the MAP point (its model term included)
    sigma_r = math.hypot(statics.standard_error, model_sd)
    ratio_z = abs(ratio - x_map) / sigma_r if sigma_r > 0.0 else math.inf
    if ratio_z <= config.max_disagreement:
        return ratio_z, ""
    return ratio_z, (
        f"the torque/force ratio ({ratio:.3f} m) is {ratio_z:.1f} standard deviations "
        f"from x_c = {x_map:.3f} m"
    )


def frequency_sigma(
    omega1: float, omega1_se: float, frequency_floor: float, model_sd: float
) -> float:
    """The standard deviation of omega_1 (rad/s) its check against the sensing curve allows,
    as the posterior has it: the fit's error ``omega1_se`` (rad/s), the relative
    ``frequency_floor`` and the curve's own term ``model_sd`` (rad/s, the bent link's), in
    quadrature."""
    return math.hypot(omega1_se, frequency_floor * omega1, model_sd)


def frequency_check(
    omega1: float, sigma: float, omega_at_map: float, x_map: float, top: float, config: FastConfig
) -> tuple[float, str]:
    """Distance of the measured ``omega1`` from the sensing curve's ``omega_at_map`` at the MAP
    ``x_map`` (m), in its standard deviations ``sigma`` (rad/s, floors included), and the note
    when it exceeds ``max_disagreement`` (else "").

    The posterior predictive check of the frequency, as :func:`ratio_check` is the ratio's:
    the posterior's maximum sits where the curve gives the measured omega_1 unless the ratio
    pulls it onto a point the frequency does not allow, which the prior's edge (the tip) makes
    possible: omega_1 far below the curve's value at l has no point on the falling branch, yet
    a ratio near l puts the maximum at l. The frequency then says the contact is not there.
    Above the curve's maximum ``top`` (rad/s) no point has the frequency, on any branch:
    :func:`peak_check` speaks for that, not this.
    """
    if not (math.isfinite(omega1) and sigma > 0.0) or omega1 >= top:
        return math.nan, ""
    z = abs(omega1 - omega_at_map) / sigma
    if z <= config.max_disagreement:
        return z, ""
    return z, (
        f"omega_1 = {omega1:.2f} rad/s is {z:.1f} standard deviations from the sensing curve's "
        f"{omega_at_map:.2f} rad/s at x_c = {x_map:.3f} m, where the torque/force ratio puts it"
    )


def _opening(fit: DampedSinusoidFit, k: int, push: float, link: Link, x_c: float) -> float:
    """Fundamental's contact-force amplitude at the window start over the static push |R_perp|.

    The base-force amplitude (R_y and R_z channels) at the window start is turned into the
    contact force by the first mode's shape.
    """
    start = fit.start_amplitudes()
    base = math.hypot(float(start[0, k]), float(start[1, k]))
    return abs(first_mode_value(link, contact_to_base_shear, x_c)) * base / push


def opening_check(
    fit: DampedSinusoidFit, k: int, push: float, link: Link, x_c: float, config: FastConfig
) -> tuple[float, str]:
    """:func:`_opening` and, when it exceeds ``max_opening`` (the contact opens), the note."""
    opening = _opening(fit, k, push, link, x_c)
    if opening > config.max_opening:
        return opening, (
            f"the contact opens: the predicted vibration of the contact force is "
            f"{opening:.2f} times the static push at the window start"
        )
    return opening, ""


def other_fundamental(
    fit: DampedSinusoidFit,
    k: int,
    band: tuple[float, float],
    push_direction: NDArray[np.float64] | None,
    config: FastConfig,
) -> tuple[float, float, str]:
    """Two fundamentals of the push plane in ``fit``: the one the fundamental ``k`` is, or the
    strongest, and the nearest other (rad/s), with the note; NaN, NaN and "" when the push
    plane has one.

    Held at one point, the link has one mode in the omega_1 band in the plane it is pushed in
    (its free plane's may ring apart from it, and ``k`` may be that one, :mod:`.planes`). Two
    detected modes of the band that vibrate mostly in the push plane, the other farther than
    ``push_plane_gap`` from that one, say the window holds more than one contact state: a
    contact that bounces, or one that moved along the link. Which of them is the contact's
    cannot be told from the window.
    """
    if push_direction is None:
        return math.nan, math.nan, ""
    share = free_plane_share(fit, push_direction)
    detection = fit.detection()
    pushed = np.flatnonzero(
        fit.in_band(band)
        & (detection >= config.min_detection)
        & np.isfinite(fit.omega_se)
        & (share < 0.5)
    )
    if pushed.size < 2:
        return math.nan, math.nan, ""
    reference = k if k in pushed else int(pushed[np.argmax(detection[pushed])])
    omega = float(fit.omega[reference])
    others = pushed[np.abs(fit.omega[pushed] - omega) > config.push_plane_gap * omega]
    if others.size == 0:
        return math.nan, math.nan, ""
    second = float(fit.omega[others[np.argmin(np.abs(fit.omega[others] - omega))]])
    return (
        omega,
        second,
        (
            f"the push plane rings at {omega:.2f} and {second:.2f} rad/s, two fundamentals: the "
            f"link was not held at one point over the window"
        ),
    )


def peak_check(
    omega1: float, omega1_se: float, frequency_floor: float, top: float, config: FastConfig
) -> str:
    """Why omega_1 (rad/s) is too near ``top``, the maximum of the sensing curve; "" if not.

    Near the top of omega_1(x_c) the inverse is singular: a frequency bias e moves x_c by
    sqrt(2 e / |omega_1''|) and the Gaussian interval can collapse onto the peak; so no
    declaration while omega_1 is within ``peak_margin`` standard deviations (``omega1_se`` and
    the relative ``frequency_floor`` in quadrature) of the maximum.
    """
    sigma = math.hypot(omega1_se, frequency_floor * omega1)
    if omega1 > top:
        by = f", by {(omega1 - top) / sigma:.1f} standard deviations" if sigma > 0.0 else ""
        return (
            f"omega_1 = {omega1:.2f} rad/s is above the top of the sensing curve "
            f"({top:.2f} rad/s){by}"
        )
    if top - omega1 < config.peak_margin * sigma:
        return (
            f"omega_1 = {omega1:.2f} rad/s is within {config.peak_margin:g} standard "
            f"deviations of the top of the sensing curve ({top:.2f} rad/s)"
        )
    return ""


def branch_contradiction(
    fit: DampedSinusoidFit,
    k: int,
    posterior: ContactPosterior,
    table: CurveTable,
    link: Link,
    config: FastConfig,
) -> str:
    """Why a higher mode of ``fit`` says the posterior's branch is wrong ("" if it does not).

    Each candidate x_c whose omega_1 is the fitted fundamental ``fit.omega[k]`` predicts its
    contact modes 2 and 3. A detected mode above 1.5 omega_1 contradicts the branch the ratio
    chose when it lies within ``branch_mode_tolerance`` of a mode of a candidate on another
    branch, farther than that from both modes of the posterior's branch's candidate, and at
    least twice as far from those as from the other's. A mode within the tolerance of a
    multiple of omega_1 is skipped: a contact that bounces or clips makes harmonics, so it may
    be one. No check without a candidate on the posterior's branch and one on another.
    """
    omega1 = float(fit.omega[k])
    tolerance = config.branch_mode_tolerance
    candidates = contact_candidates(link, omega1, posterior, config)
    chosen = posterior.branch_of(posterior.x_c)
    own = [c for c in candidates if posterior.branch_of(c) == chosen]
    others = [c for c in candidates if posterior.branch_of(c) != chosen]
    if not own or not others:
        return ""
    detection = fit.detection()

    def mismatch(omega: float, x_c: float) -> tuple[float, int]:
        # Relative distance to the nearer of the candidate's modes 2 and 3, and which one
        modes = [float(np.interp(x_c, table.grid, table.higher[:, j])) for j in (0, 1)]
        distances = [abs(omega / m - 1.0) for m in modes]
        j = int(np.argmin(distances))
        return distances[j], j + 2

    for m in range(fit.n_modes):
        omega = float(fit.omega[m])
        harmonic = round(omega / omega1) * omega1
        if (
            m == k
            or omega < 1.5 * omega1
            or not detection[m] >= config.min_detection  # NaN: not detected
            or abs(omega - harmonic) <= tolerance * omega
        ):
            continue
        mine, _, candidate = min((*mismatch(omega, c), c) for c in own)
        theirs, mode, other = min((*mismatch(omega, c), c) for c in others)
        if mine > tolerance and theirs <= min(tolerance, 0.5 * mine):
            return (
                f"the contact mode at {omega:.1f} rad/s is {100 * theirs:.1f} % from mode "
                f"{mode} of x_c = {other:.3f} m and {100 * mine:.1f} % from modes 2 and 3 of "
                f"x_c = {candidate:.3f} m, the candidate on the posterior's branch"
            )
    return ""


def direction_change(early: StaticRatio, late: StaticRatio) -> tuple[float, float]:
    """Angle (rad) between two static perpendicular reactions and its standard error (rad)."""
    a, b = early.reaction_perp, late.reaction_perp
    norm_a, norm_b = float(np.linalg.norm(a)), float(np.linalg.norm(b))
    if norm_a == 0.0 or norm_b == 0.0:
        return math.nan, math.nan
    cosine = float(np.dot(a, b) / (norm_a * norm_b))
    angle = math.acos(min(1.0, max(-1.0, cosine)))
    # Variance of each direction: the force covariance across the direction over |R|^2
    variance = 0.0
    for reaction, norm, cov in ((a, norm_a, early.force_cov), (b, norm_b, late.force_cov)):
        across = np.array([-reaction[1], reaction[0]]) / norm
        variance += float(across @ cov @ across) / norm**2
    return angle, math.sqrt(max(variance, 0.0))


def accepted_at_cap(final: WindowEstimate, config: FastConfig) -> bool:
    """Whether the window at the cap, not sure at ``tolerance``, still answers ``ok``: every
    check but the interval's width passed and the interval is within ``cap_tolerance``."""
    return final.checks_passed and final.posterior.width <= config.cap_tolerance


def _too_wide(posterior: ContactPosterior, config: FastConfig) -> str:
    """Why an interval wider than ``cap_tolerance`` is not sure: its width, or, when the
    highest-density region is in parts (x_c near one of two points, one on each branch), the
    parts and their probabilities."""
    pieces = posterior.pieces()
    if len(pieces) > 1:
        places = " or ".join(f"{lo:.4f} to {hi:.4f} m ({mass:.2f})" for lo, hi, mass in pieces)
        return (
            f"the 95 % region is {len(pieces)} separate parts, {places}, which omega_1 and the"
            " torque/force ratio do not tell apart"
        )
    return (
        f"the 95 % interval is {1000 * posterior.width:.1f} mm wide, more than "
        f"the {1000 * config.cap_tolerance:g} mm allowed at the cap"
    )


def problems(result: ScanResult, config: FastConfig) -> list[tuple[Status, str]]:
    """What is wrong with the scan's final window, as (status, reason) pairs; empty when nothing.

    Not sure at the end of the search (the estimators disagree, the cap, or the samples ended);
    the static contact force turned between the window's first half and t_e (slip). The
    plausibility layer adds the checks every method shares (the friction cone among them).
    """
    found: list[tuple[Status, str]] = []
    final = result.final
    if final is None:
        return [(Status.RECORDING_TOO_SHORT, "too few samples after t_1 for a first window")]
    if not final.sure and (
        final.ratio_z > config.max_disagreement or final.frequency_z > config.max_disagreement
    ):
        found.append(
            (
                Status.ESTIMATORS_DISAGREE,
                f"the frequency and the torque/force ratio disagree at the end of the search "
                f"({final.note})",
            )
        )
    elif not final.sure and not (result.reached_cap and accepted_at_cap(final, config)):
        if result.reached_cap:
            why = final.note
            if final.checks_passed:  # only the width held it back, and the cap's is wider
                why = _too_wide(final.posterior, config)
            found.append((Status.UNCERTAIN, f"not sure within {config.cap:g} s after t_1 ({why})"))
        else:
            found.append(
                (
                    Status.RECORDING_TOO_SHORT,
                    f"the samples ended before the estimate was sure ({final.note})",
                )
            )
    limit = config.max_direction_drift
    if limit is not None and final.statics is not None and final.early_statics is not None:
        # Slip on the surface turns the static reaction: the fitted static loads of the window's
        # first half against the whole window (vibration is in the model, not in the statics)
        angle, se = direction_change(final.early_statics, final.statics)
        if math.isfinite(angle) and angle > max(limit, 3.0 * se):
            found.append(
                (
                    Status.SLIP_SUSPECTED,
                    f"the static contact force turned by {math.degrees(angle):.1f} deg "
                    f"(+- {math.degrees(se):.1f}) between the first half of the window and t_e",
                )
            )
    return found
