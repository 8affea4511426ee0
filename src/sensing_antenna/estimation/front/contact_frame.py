"""The instant t_1 found in the recording, and the contact frame X^c Y^c Z^c (Section 5.3).

Offline, t_1 is the instant the head comes to rest after the contact: from t_1 on, for
``rest_window`` seconds, neither motor angle moves by more than a tolerance that is the larger of a
fixed floor, a multiple of the angle noise and a few encoder steps, both measured on the samples
before the contact. This uses no knowledge of the device's push criterion, so it works on recordings
from devices that stop their motors on other criteria. The test is causal (it needs the samples up
to t_1 + rest_window), so the streaming estimator applies exactly the same rule.

The frame (Section 5.3) is built from averages over [t_1, t_1 + frame_window]:

- Y^c along the reaction of the object on the antenna, R = F - F_g^m. With the recording
  convention (F is exerted by the link on the head) the link's equilibrium is
  -F + R + W = 0, and F_g^m is W in the motor frame, so R = F - F_g^m. Gravity matters: the link
  weight m_b g = 0.045 N is comparable to gentle pushes.
- Z^c along OP_r x Y^c, with P_r = l X^m the tip of the rigid link from the motor angles.
- X^c = Y^c x Z^c (equal to X^m when the reaction is perpendicular to the link).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.config import EstimatorConfig

__all__ = [
    "REST_DRIFT_SIGMAS",
    "REST_SPEED_SHARE",
    "ContactFrame",
    "contact_frame",
    "first_rest_index",
    "motor_axes",
    "rest_drift_tolerance",
    "rest_tolerance",
    "signal_noise",
    "to_absolute",
]

FloatArray = NDArray[np.float64]

#: Candidate instants of t_1 tested per step of :func:`first_rest_index`.
_REST_CHUNK = 256

#: Standard deviations of the angle noise by which a resting head's drift over its hold may
#: read (:func:`rest_drift_tolerance`): white noise passes 5 with probability 6e-7 per span.
REST_DRIFT_SIGMAS = 5.0

#: Share of the head's speed before the touch that a resting head may still turn at over its
#: hold (:func:`rest_drift_tolerance`): a push still going on turns at about the sweep's speed,
#: while the link's vibration and the servo's settling move a stopped head by a fraction of a
#: milliradian either way.
REST_SPEED_SHARE = 0.1


def motor_axes(theta: FloatArray) -> FloatArray:
    """Rows X^m, Y^m, Z^m of the motor frame in absolute coordinates.

    Parameters
    ----------
    theta : array, shape (2,) or (k, 2)
        Motor angles theta1 (azimuth), theta2 (elevation) (rad).

    Returns
    -------
    array, shape (3, 3) or (k, 3, 3)
    """
    theta = np.asarray(theta, dtype=float)
    c1, s1 = np.cos(theta[..., 0]), np.sin(theta[..., 0])
    c2, s2 = np.cos(theta[..., 1]), np.sin(theta[..., 1])
    rows = (
        (c2 * c1, c2 * s1, s2),
        (-s1, c1, np.zeros_like(c1)),
        (-s2 * c1, -s2 * s1, c2),
    )
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def to_absolute(vector_m: FloatArray, theta: FloatArray) -> FloatArray:
    """Vectors given in the motor frame, in absolute coordinates: shape (3,) or (n, 3), with
    one pair of angles ``theta`` (2,) for all or a pair per vector (n, 2)."""
    return np.einsum("...j,...ji->...i", np.asarray(vector_m, dtype=float), motor_axes(theta))


def signal_noise(theta: FloatArray) -> tuple[float, float]:
    """White-noise level and quantisation step of sampled signals, the larger over the channels.

    Used for the motor angles (rad) and for the F/T channels (N or N m).

    The noise is the robust standard deviation of the second differences divided by sqrt(6)
    (the second difference of white noise of variance s^2 has variance 6 s^2; a smooth trajectory
    sampled at 1 kHz contributes only acceleration * T_s^2). The encoder step is the smallest
    non-zero first difference (0 when there are fewer than 3 samples).

    Parameters
    ----------
    theta : array, shape (n, k)
        Samples, time on axis 0.

    Returns
    -------
    (noise, step) : tuple of float
    """
    theta = np.asarray(theta, dtype=float)
    if theta.shape[0] < 3:
        return 0.0, 0.0
    second = np.diff(theta, n=2, axis=0)
    mad = np.median(np.abs(second - np.median(second, axis=0)), axis=0)
    noise = float(np.max(mad / 0.6745 / np.sqrt(6.0)))
    first = np.abs(np.diff(theta, axis=0))
    nonzero = first[first > 0.0]
    step = float(nonzero.min()) if nonzero.size else 0.0
    return noise, step


def rest_tolerance(theta_before_contact: FloatArray, config: EstimatorConfig) -> float:
    """Peak-to-peak angle tolerance (rad) below which the head counts as at rest.

    The largest of the floor ``config.rest_angle_tolerance``, ``rest_noise_factor`` times the
    angle noise, and three encoder steps (a quantised angle at rest flickers by one or two steps).
    """
    noise, step = signal_noise(theta_before_contact)
    return max(config.rest_angle_tolerance, config.rest_noise_factor * noise, 3.0 * step)


def rest_drift_tolerance(
    theta_before_contact: FloatArray,
    config: EstimatorConfig,
    tolerance: float,
    rest_samples: int,
    drift_samples: int,
    sample_period: float,
) -> float:
    """Largest drift (rad) of a resting head's angle across ``drift_samples`` intervals (the
    hold after t_1): the mean of the span's second half less that of its first (h samples
    each), or inf when the peak-to-peak test (``tolerance``, :func:`rest_tolerance` of the
    same samples, over ``rest_samples`` intervals) already tells a push from rest.

    A coarse or flickering encoder widens the peak-to-peak tolerance to several counts, which a
    slow push stays within for a whole rest window: the test alone then bounds a resting head's
    speed by more than ``REST_SPEED_SHARE`` of the head's speed over the ``tare_margin`` before
    the touch. The push's drift still shows in the halves' means, while a stopped head only
    sways. The tolerance is then the largest of ``REST_DRIFT_SIGMAS`` times what white angle
    noise s gives the difference (s sqrt(2 / h)), the turn at that share of the speed across
    the halves' distance, and the floor ``config.rest_angle_tolerance``. A head that did not
    turn before the touch (an object moved into it) is not judged."""
    theta = np.asarray(theta_before_contact, dtype=float)
    window = max(rest_samples, 1)
    back = min(round(config.tare_margin / sample_period), theta.shape[0])
    if back < 2 * window:
        return math.inf
    noise, _ = signal_noise(theta)
    # the head's turn between the means of a rest window at each end of the margin, which an
    # encoder's flicker does not blur
    turn = float(np.max(np.abs(theta[-window:].mean(axis=0) - theta[-back:][:window].mean(axis=0))))
    unseen = max(config.rest_angle_tolerance, REST_DRIFT_SIGMAS * noise * math.sqrt(2.0 / window))
    speed = turn / ((back - window) * sample_period)
    limit = REST_SPEED_SHARE * speed * rest_samples * sample_period
    if turn <= unseen or tolerance <= limit:
        return math.inf
    half = max((drift_samples + 1) // 2, 1)
    distance = (drift_samples + 1 - half) * sample_period
    return max(
        config.rest_angle_tolerance,
        REST_DRIFT_SIGMAS * noise * math.sqrt(2.0 / half),
        REST_SPEED_SHARE * speed * distance,
    )


def first_rest_index(
    theta: FloatArray,
    start: int,
    window_samples: int,
    tolerance: float,
    drift_tolerance: float = math.inf,
    drift_samples: int = 0,
) -> int | None:
    """First index i >= start with both angles within ``tolerance`` peak-to-peak on [i, i + w]
    and drifting by at most ``drift_tolerance`` across [i, i + d] (:func:`rest_drift_tolerance`).

    Parameters
    ----------
    theta : array, shape (n, 2)
        Motor angles (rad).
    start : int
        First candidate index (the contact index).
    window_samples : int
        w, the number of sample intervals in the rest window.
    tolerance : float
        Peak-to-peak tolerance (rad).
    drift_tolerance : float
        Largest difference (rad) between the means of the last and the first halves of
        [i, i + d].
    drift_samples : int
        d, the span the drift is judged over (sample intervals, at least w; w without a finite
        ``drift_tolerance``): the head must hold for it, and a span longer than the rest window
        tells a slow turn from noise.

    Returns
    -------
    int or None
        The index of t_1, or None when the head never rests in the samples.
    """
    from scipy.ndimage import maximum_filter1d, minimum_filter1d

    theta = np.asarray(theta, dtype=float)
    w = window_samples
    d = max(drift_samples, w) if math.isfinite(drift_tolerance) else w
    half = max((d + 1) // 2, 1)
    # The largest and smallest angle over every [i, i + w] by running filters, O(n) whatever w
    # (the window starts at i: origin -(w + 1) // 2); max and min are exact, so the spread is
    # the same number as over each window's own samples
    size, origin = w + 1, -((w + 1) // 2)
    # candidates i in [start, n - d), looked at a few hundred at a time: the head usually rests
    # soon after t_c
    for first in range(start, theta.shape[0] - d, _REST_CHUNK):
        stop = min(first + _REST_CHUNK, theta.shape[0] - d)
        segment = theta[first : stop + d]
        highest = maximum_filter1d(segment, size, axis=0, origin=origin)[: stop - first]
        lowest = minimum_filter1d(segment, size, axis=0, origin=origin)[: stop - first]
        still = np.all(highest - lowest <= tolerance, axis=1)
        if math.isfinite(drift_tolerance):
            # the halves [i, i + h) and [i + d + 1 - h, i + d + 1) of each span, by sums
            total = np.vstack([np.zeros((1, theta.shape[1])), np.cumsum(segment, axis=0)])
            first_half = total[half : half + stop - first] - total[: stop - first]
            ends = np.arange(stop - first) + d + 1
            second_half = total[ends] - total[ends - half]
            drift = np.abs(second_half - first_half) / half
            still &= np.all(drift <= drift_tolerance, axis=1)
        hits = np.flatnonzero(still)
        if hits.size:
            return first + int(hits[0])
    return None


@dataclass(frozen=True)
class ContactFrame:
    """The frame attached to the contact at t_1 (Section 5.3); turned (:meth:`turned_to`), the
    frame of a later instant, with Y^c along its reaction and the head at its motor angles,
    where a point of that instant is placed.

    Attributes
    ----------
    axes_m : array, shape (3, 3)
        Rows X^c, Y^c, Z^c in motor coordinates.
    motor_axes_a : array, shape (3, 3)
        Rows X^m, Y^m, Z^m in absolute coordinates at :attr:`theta`.
    theta : array, shape (2,)
        Motor angles averaged over the frame window (rad), or at the instant of a frame
        :meth:`turned_to` another.
    reaction_m : array, shape (3,)
        Reaction of the object on the antenna R = F - F_g^m, motor frame (N).
    """

    axes_m: FloatArray
    motor_axes_a: FloatArray
    theta: FloatArray
    reaction_m: FloatArray

    @property
    def axes_a(self) -> FloatArray:
        """Rows X^c, Y^c, Z^c in absolute coordinates, shape (3, 3)."""
        return self.axes_m @ self.motor_axes_a

    @property
    def push_force(self) -> float:
        """|R| (N)."""
        return float(np.linalg.norm(self.reaction_m))

    @property
    def lateral_force(self) -> float:
        """|R_perp| (N): the reaction across the undeflected link, the push."""
        return math.hypot(float(self.reaction_m[1]), float(self.reaction_m[2]))

    @property
    def axial_fraction(self) -> float:
        """|R . X^m| / |R|: share of the reaction along the undeflected link (dimensionless)."""
        norm = self.push_force
        return float(abs(self.reaction_m[0]) / norm) if norm > 0 else float("nan")

    def turned_to(
        self, reaction_m: FloatArray, theta: FloatArray | None = None
    ) -> ContactFrame | None:
        """The frame of another instant: Y^c along its reaction (motor frame, N, shape (3,)),
        as a contact that slides along the surface turns it, and the head at its motor angles
        ``theta`` (rad, shape (2,); default this frame's), as a servo that yields under the
        push turns it. None where Y^c or Z^c is undefined."""
        axes = _contact_axes(np.asarray(reaction_m, dtype=float), 1.0)
        if axes is None:
            return None
        angles = self.theta if theta is None else np.asarray(theta, dtype=float).reshape(2)
        return ContactFrame(
            axes_m=axes,
            motor_axes_a=self.motor_axes_a if theta is None else motor_axes(angles),
            theta=angles,
            reaction_m=np.asarray(reaction_m, dtype=float),
        )


def contact_frame(
    theta: FloatArray, reaction_m: FloatArray, link_length: float
) -> ContactFrame | None:
    """Build the contact frame from samples around t_1.

    Parameters
    ----------
    theta : array, shape (k, 2)
        Motor angles over the frame window (rad).
    reaction_m : array, shape (k, 3)
        Reaction of the object on the antenna R = F - F_g^m over the frame window, motor frame
        (N); see :func:`sensing_antenna.estimation.front.ratio.contact_loads`.
    link_length : float
        l (m), for the rigid tip P_r = l X^m.

    Returns
    -------
    ContactFrame or None
        None when the reaction is zero or along the link, where Y^c or Z^c is undefined.
    """
    theta_mean = np.mean(np.asarray(theta, dtype=float), axis=0)
    # Section 5.3: Y^c along the reaction of the object on the antenna, averaged over the window
    reaction = np.mean(np.asarray(reaction_m, dtype=float), axis=0)
    axes = _contact_axes(reaction, link_length)
    if axes is None:
        return None
    return ContactFrame(
        axes_m=axes,
        motor_axes_a=motor_axes(theta_mean),
        theta=theta_mean,
        reaction_m=reaction,
    )


def _contact_axes(reaction: FloatArray, length: float) -> FloatArray | None:
    """Rows X^c, Y^c, Z^c in motor coordinates for a reaction (motor frame) and a link of
    ``length`` (m; it scales OP_r only), or None."""
    norm = float(np.linalg.norm(reaction))
    if norm == 0.0:
        return None
    y_c = reaction / norm
    # Section 5.3: Z^c along OP_r x Y^c, OP_r = l X^m = (l, 0, 0) in motor coordinates
    z_raw = np.cross(np.array([length, 0.0, 0.0]), y_c)
    z_norm = float(np.linalg.norm(z_raw))
    if z_norm < 1e-6 * length:
        return None
    z_c = z_raw / z_norm
    # Section 5.3: X^c = Y^c x Z^c
    x_c = np.cross(y_c, z_c)
    return np.vstack([x_c, y_c, z_c])
