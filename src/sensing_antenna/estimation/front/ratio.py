"""Estimator 2 (Sections 4.4 and 5.5): the torque/force ratio of the low-pass filtered loads.

Statics of the link (recording convention: F and Gamma are exerted by the link on the head, torque
about O). With R the reaction of the object on the antenna, applied at the contact point r_c, and
W the link weight:

    F = R + W,            Gamma = r_c x R + Gamma_W

so the contact part of the loads is R = F - F_g^m and r_c x R = Gamma - Gamma_g^m (Section 4.2).
Where r_c lies follows from the statics of the bent link: the planar elastica loaded at the contact
(:mod:`sensing_antenna.beam.elastica`, :func:`perpendicular_ratio`), the moment its own weight
adds taken off first (:mod:`sensing_antenna.beam.weight`), which for small
deflections gives |Gamma - Gamma_g^m| = x_c |R_perp| up to the moment of the axial force through
the deflection, R_perp the part of R perpendicular to the link. Eq. 19 divides by |R| instead,
which equals |R_perp| when the reaction is normal to the link (the paper's Assumption 4) and
underestimates x_c by the factor cos(angle) otherwise. The paper method inverts the elastica; the
``ratio`` baseline keeps Eq. 21 as printed.

Filter start. Eq. 21 filters F and Gamma (Eq. 20) and subtracts the gravity terms afterwards.
Here gravity is subtracted sample by sample before the filter: the filter is linear, so the two
agree exactly while theta2 is constant (after t_1) and this one is also right while the head moves.
The filter runs continuously from the first sample, started in steady state: before the contact the
contact loads are zero (apart from the inertial loads of the free motion), and while the push
builds up R(t) = r(t) u and r_c x R(t) = x_c r(t) (X^m x u) grow in proportion, so the filtered
ratio already equals x_c at t_1; only the vibration and the decaying inertial loads remain, and
they fade with the filter. Starting the filter from zero at t_1 (and subtracting gravity after the
filter, as in Eq. 21) would instead bias the ratio for several 1/omega_c.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import Antenna, Link
from sensing_antenna.beam.elastica import contact_arc
from sensing_antenna.beam.weight import weight_moment
from sensing_antenna.detection.filters import FirstOrderLowPass, low_pass

__all__ = [
    "contact_loads",
    "converged_index",
    "filtered_contact_loads",
    "lowpass_noise_gain",
    "paper_ratio",
    "perpendicular_ratio",
    "ratio_noise",
    "vertical_shares",
    "window_mean",
]

FloatArray = NDArray[np.float64]

#: Fixed-point steps of the small-deflection statics that :func:`perpendicular_ratio` falls back
#: to beyond the elastica's table; four steps shrink the error of the first estimate by (0.1)^4.
_FIXED_POINT_STEPS = 4

#: Fixed-point steps that take the link's weight off the moment at the contact point read: the
#: weight's moment changes with x_c by at most 0.2 |R_perp| (the paper link, pushes to 40 % of
#: x_c, friction to 0.6), so two steps leave at most 4 % of the first step's error.
_WEIGHT_STEPS = 2


def contact_loads(
    theta: FloatArray, force_m: FloatArray, torque_m: FloatArray, antenna: Antenna
) -> tuple[FloatArray, FloatArray]:
    """Loads of the contact alone: R = F - F_g^m and Gamma - Gamma_g^m (Section 4.2), the
    lateral forces corrected for the sensor's cross-talk (``antenna.sensor``).

    Parameters
    ----------
    theta : array, shape (n, 2)
        Motor angles (rad).
    force_m, torque_m : array, shape (n, 3)
        Measured force (N) and torque (N m), motor frame.
    antenna : Antenna

    Returns
    -------
    reaction_m : array, shape (n, 3)
        Reaction of the object on the antenna (N).
    contact_torque_m : array, shape (n, 3)
        Its moment about O (N m).
    """
    theta2 = np.asarray(theta, dtype=float)[:, 1]
    # Section 4.2 / Eq. 19: remove the gravity force and torque of the link
    reaction = np.asarray(force_m, dtype=float) - antenna.gravity_force(theta2)
    moment = np.asarray(torque_m, dtype=float) - antenna.gravity_torque(theta2)
    # the sensor's cross-talk into the lateral forces, as calibrated (none by default)
    return antenna.sensor.correct(reaction, moment), moment


def filtered_contact_loads(
    theta: FloatArray,
    force_m: FloatArray,
    torque_m: FloatArray,
    antenna: Antenna,
    cutoff: float,
    sample_period: float,
    offset: FloatArray | None = None,
    running: FirstOrderLowPass | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Contact loads through the low-pass filter of Eq. 20, from the first sample in steady state.

    Parameters
    ----------
    offset : array, shape (6,), optional
        Sensor offset (N, N m) subtracted after the filter (see :func:`load_offset`); the filter
        has unit gain at DC and starts in steady state, so this equals filtering tared samples.
    running : FirstOrderLowPass, optional
        The filter to continue (its state carried from the samples it was fed before), for a
        stream fed block by block; a fresh one (cut-off ``cutoff``) when None.

    Returns
    -------
    reaction_f, torque_f : array, shape (n, 3)
        Filtered R (N) and filtered Gamma - Gamma_g^m (N m), motor frame.
    """
    reaction, moment = contact_loads(theta, force_m, torque_m, antenna)
    lowpass = FirstOrderLowPass(cutoff, sample_period) if running is None else running
    # Eq. 20: G(s) = 1 / (1 + s / omega_c) on all six channels
    both = lowpass.update_block(np.hstack([reaction, moment]))
    if offset is not None:
        both = both - np.asarray(offset, dtype=float)
    return both[:, :3], both[:, 3:]


def load_offset(
    theta: FloatArray,
    force_m: FloatArray,
    torque_m: FloatArray,
    antenna: Antenna,
    counts: Sequence[int] | None = None,
) -> FloatArray:
    """Sensor offset: the mean contact loads over samples known to be free of contact.

    F/T sensors keep an offset after taring (a few resolution counts), which matters when the
    push is gentle: a 10 mN offset is half the push near the tip. Without contact the contact
    loads R = F - F_g^m and Gamma - Gamma_g^m are zero apart from the offset, the noise and the
    (zero-mean at rest) free vibration, so their mean is the offset.

    ``counts`` (6,): each channel's mean over its own first samples (between 1 and n); all n
    samples when None.

    Returns
    -------
    array, shape (6,)
        Offset of (fx, fy, fz, tx, ty, tz) (N, N m).
    """
    reaction, moment = contact_loads(theta, force_m, torque_m, antenna)
    loads = np.hstack([reaction, moment])
    if counts is None:
        return np.asarray(loads.mean(axis=0), dtype=float)
    return np.array([loads[:count, channel].mean() for channel, count in enumerate(counts)])


def perpendicular_ratio(
    reaction_f: FloatArray, torque_f: FloatArray, link: Link, theta2: ArrayLike
) -> FloatArray:
    """Estimator 2 of the paper method: x_c(t), the contact's arc length, from the statics of the
    pushed link (m), (n,).

    With u the direction of R_perp (the reaction perpendicular to the link) and v = X^m x u, the
    sensor measures the reaction's moment about O in the bending plane, M_0 = Gamma' . v, and
    R = (R_x, |R_perp|). The link is the planar elastica loaded at the contact
    (:mod:`sensing_antenna.beam.elastica`): E I theta' = M_0 - (r(s) x R) from the base, and the
    contact is where that moment vanishes. The inversion is tabulated
    (:func:`~sensing_antenna.beam.elastica.contact_arc`), exact for any deflection the table
    covers (deflections to about 60 % of x_c). In the small-deflection limit it is the linear
    statics x_c = (M_0 + y_c R_x) / |R_perp|, y_c = |R_perp| x_c^3 / (3 E I) (Eq. 13); loads
    beyond the table (a sensor in the wrong units, a glitch) get that linear reading, by a few
    fixed-point steps from x_c = M_0 / |R_perp|, for the plausibility layer to judge. Without
    axial force and deflection this is Eq. 21 with |R_perp|.

    The link's own weight adds to M_0 what the elastica loaded at the contact alone does not
    hold: the sag's lever on R_x and the masses and the contact the push moves
    (:func:`~sensing_antenna.beam.weight.pushed_weight_moment`). It is taken off M_0 at the
    contact point read, by :data:`_WEIGHT_STEPS` fixed-point steps.

    Parameters
    ----------
    reaction_f : array, shape (n, 3)
        Filtered reaction R (N), motor frame.
    torque_f : array, shape (n, 3)
        Filtered Gamma - Gamma_g^m (N m), motor frame.
    link : Link
        Its stiffness is ``1 / bending_compliance``, the one the frequency model implies.
    theta2 : array_like, shape (n,) or scalar
        The link's elevation (rad), which puts gravity in the motor frame.

    Returns
    -------
    array, shape (n,)
        NaN where R_perp is exactly zero.
    """
    reaction_f = np.asarray(reaction_f, dtype=float)
    torque_f = np.asarray(torque_f, dtype=float)
    r_x, r_y, r_z = reaction_f[..., 0], reaction_f[..., 1], reaction_f[..., 2]
    perpendicular = np.hypot(r_y, r_z)
    rigidity = 1.0 / link.bending_compliance
    with np.errstate(divide="ignore", invalid="ignore"):
        # M_0 = Gamma' . v with v = X^m x R_perp / |R_perp| = (0, -R_z, R_y) / |R_perp|
        moment_v = (torque_f[..., 2] * r_y - torque_f[..., 1] * r_z) / perpendicular
    link_vertical, push_vertical = vertical_shares(reaction_f, theta2)
    x_c = _elastica_arc(moment_v, r_x, perpendicular, rigidity)
    for _ in range(_WEIGHT_STEPS):
        with np.errstate(over="ignore", invalid="ignore"):
            weight = weight_moment(
                link,
                np.clip(x_c, 0.0, link.length),
                perpendicular,
                r_x,
                link_vertical,
                push_vertical,
            )
        # where nothing is read (no push, loads beyond the table) the weight is not taken off
        weight = np.where(np.isfinite(weight), weight, 0.0)
        x_c = _elastica_arc(moment_v - weight, r_x, perpendicular, rigidity)
    return np.where(perpendicular > 0.0, x_c, np.nan)


def vertical_shares(reaction: ArrayLike, theta2: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """X^m . z and u . z (u = R_perp / |R_perp|), gravity along z = (sin theta2, 0, cos theta2)
    in the motor frame: the link's and the push's vertical shares that
    :func:`~sensing_antenna.beam.weight.pushed_weight_moment` reads, for reactions ``reaction``
    (N, shape (..., 3), motor frame) at elevations ``theta2`` (rad, broadcast to (...)); the
    push's share is NaN where R_perp is zero."""
    reaction = np.asarray(reaction, dtype=float)
    theta2 = np.broadcast_to(np.asarray(theta2, dtype=float), reaction.shape[:-1])
    with np.errstate(divide="ignore", invalid="ignore"):
        push = reaction[..., 2] * np.cos(theta2) / np.hypot(reaction[..., 1], reaction[..., 2])
    return np.asarray(np.sin(theta2), dtype=float), np.asarray(push, dtype=float)


def _elastica_arc(
    moment_v: FloatArray, r_x: FloatArray, perpendicular: FloatArray, rigidity: float
) -> FloatArray:
    """The elastica's contact arc (m), the linear statics beyond its table."""
    x_c = contact_arc(moment_v, r_x, perpendicular, rigidity)
    outside = np.isnan(x_c) & (perpendicular > 0.0)
    if outside.any():
        x_c[outside] = _linear_statics(
            moment_v[outside], r_x[outside], perpendicular[outside], rigidity
        )
    return x_c


def _linear_statics(
    moment_v: FloatArray, r_x: FloatArray, perpendicular: FloatArray, flexural_rigidity: float
) -> FloatArray:
    """The small-deflection statics x_c = (M_0 + y_c R_x) / R_perp, y_c = R_perp x_c^3 / (3 E I)
    (Eq. 13), by fixed-point steps from M_0 / R_perp (m)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        x_c = moment_v / perpendicular
        for _ in range(_FIXED_POINT_STEPS):
            y_c = perpendicular * x_c**3 / (3.0 * flexural_rigidity)
            x_c = (moment_v + y_c * r_x) / perpendicular
    return np.asarray(x_c, dtype=float)


def paper_ratio(
    theta: FloatArray,
    force_m: FloatArray,
    torque_m: FloatArray,
    antenna: Antenna,
    cutoff: float,
    sample_period: float,
    offset: FloatArray | None = None,
) -> FloatArray:
    """Eq. 21 exactly as printed: filter F and Gamma, then subtract the gravity terms (m), (n,).

    This is the estimator of the paper's reference [17], used by the ``ratio`` baseline; the
    sensor ``offset`` (6,), when given, is removed as for the paper method, and the forces are
    corrected for the sensor's cross-talk (``antenna.sensor``) as everywhere.
    """
    theta2 = np.asarray(theta, dtype=float)[:, 1]
    # Eq. 20: filter the measured force and torque
    filtered = low_pass(
        np.hstack([np.asarray(force_m, dtype=float), np.asarray(torque_m, dtype=float)]),
        cutoff,
        sample_period,
    )
    # Eq. 21: x_c(t) = |Gamma_f - Gamma_g| / |F_f - F_g|, the force read through the sensor's
    # calibrated cross-talk correction (none by default), then tared as the contact loads are
    moment = filtered[:, 3:] - antenna.gravity_torque(theta2)
    reaction = antenna.sensor.correct(filtered[:, :3] - antenna.gravity_force(theta2), moment)
    if offset is not None:
        reaction = reaction - np.asarray(offset, dtype=float)[:3]
        moment = moment - np.asarray(offset, dtype=float)[3:]
    numerator = np.linalg.norm(moment, axis=-1)
    denominator = np.linalg.norm(reaction, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = numerator / denominator
    return np.where(denominator > 0.0, ratio, np.nan)


def window_mean(ratio: FloatArray, start: int, window_samples: int) -> FloatArray:
    """Causal moving average m[j] = mean(ratio[j - w : j + 1]) for j >= start + w, else NaN (m).

    The ratio keeps a ripple at the contact vibration (attenuated only omega_c / omega_1 ~ 1/6
    by Eq. 20 at the lowest fundamental); a window of one period of the slowest vibration
    (0.2 s) removes most of it, so convergence tests the trend, not the ripple.

    Parameters
    ----------
    ratio : array, shape (n,)
        x_c(t) (m).
    start : int
        Index of t_1: the average never reaches before it.
    window_samples : int
        w, the window length in sample intervals.
    """
    ratio = np.asarray(ratio, dtype=float)
    out = np.full(ratio.shape, np.nan)
    segment = ratio[start:]
    if segment.shape[0] >= window_samples + 1:
        windows = np.lib.stride_tricks.sliding_window_view(segment, window_samples + 1)
        out[start + window_samples :] = windows.mean(axis=-1)
    return out


def converged_index(
    ratio: FloatArray, start: int, window_samples: int, tolerance: float
) -> int | None:
    """First index j >= start + w where ratio[j - w : j + 1] stays within ``tolerance``.

    The test is causal: it uses samples up to j only, so a streaming estimator declares
    convergence at the same sample. The pipeline applies it to the :func:`window_mean` of the
    ratio, from ``start = t_1 index + w``.

    Parameters
    ----------
    ratio : array, shape (n,)
        x_c(t) or its moving average (m).
    start : int
        First index the window may include.
    window_samples : int
        w, the window length in sample intervals.
    tolerance : float
        Largest peak-to-peak spread (m).

    Returns
    -------
    int or None
        The convergence index (t_1 + Delta t_e2), None if the ratio never converges.
    """
    segment = np.asarray(ratio, dtype=float)[start:]
    if segment.shape[0] < window_samples + 1:
        return None
    windows = np.lib.stride_tricks.sliding_window_view(segment, window_samples + 1)
    spread = windows.max(axis=-1) - windows.min(axis=-1)
    hits = np.flatnonzero(spread <= tolerance)
    return start + window_samples + int(hits[0]) if hits.size else None


def lowpass_noise_gain(cutoff: float, sample_period: float) -> float:
    """sqrt(omega_c T_s / 2) (dimensionless): the first-order low-pass filter of Eq. 20 passes
    white noise of standard deviation s with standard deviation s sqrt(omega_c T_s / 2) (its
    noise bandwidth is omega_c / 4 in Hz, of the 1 / (2 T_s) Hz of the samples); omega_c in
    rad/s, T_s in s."""
    return float(np.sqrt(0.5 * cutoff * sample_period))


def ratio_noise(
    force_noise: float, push_force: float, length: float, cutoff: float, sample_period: float
) -> float:
    """Standard deviation of the filtered ratio caused by white force noise (m).

    The filter passes white force noise s as s :func:`lowpass_noise_gain`; the ratio
    x = |Gamma| / |R| then varies by x s_f / |R|, taken at x = l as an upper bound.

    Parameters
    ----------
    force_noise : float
        White noise of one force channel (N).
    push_force : float
        |R_perp| at t_1 (N).
    length : float
        l (m).
    cutoff, sample_period : float
        omega_c (rad/s) and T_s (s).
    """
    if push_force <= 0.0:
        return float("inf")
    return length * force_noise * lowpass_noise_gain(cutoff, sample_period) / push_force
