"""Where the link swept without touching: space no object occupies.

A sweeping head moves its link through free space until the touch: at every angle before it,
the link crossed no object. That is evidence about the object's shape beside the touched points
themselves: a shape that reaches into space a link swept through untouched is refuted, whatever
its fit to the points (a cylinder's flat end where a sweep passed beyond a capsule's round cap).

The link at motor angles theta is the straight line x X^m bent by its weight, the same model
the contact points use (``mapping.points``): p(x) = x X^m + g |A| u(x) A, A the part of -Z^a
across the link and u the cantilever's unit sag (``Link.unit_sag``), in the world through the
base pose. Each sample of the link is known to within its standard deviation across the link,
sigma(x)^2 = (x tau)^2 + (rho s(x))^2: tau = :data:`FREE_POINTING`, rho the deflection model's
relative uncertainty (``PointUncertainty``) and s(x) the sag. The head's zero offset, part of
the points' pointing (``points.TANGENT_FLOOR``), moves a base's points and its free space alike
and does not separate them; what does is the link's swing while the head speeds up: its angular
acceleration alpha loads the link with rho_l alpha x per length, a quasi-static tip deflection
of 11 rho_l alpha l^5 / (120 E I), 3.5 mm for the paper's link at 0.8 rad/s^2 (the peak of a
smooth ramp to 0.3 rad/s in 0.6 s), which the first mode overshoots by about half.

When a contact is detected at t_c the link is pressing the object: the contact detector
(``detection.contact``, Section 4.2 of the paper) waits for the external torque to cross its
threshold tau_th, which a contact at x reaches once the head has turned on by tau_th x / (3 E I)
(a cantilever loaded at x: its base torque F x = 3 E I delta / x^2 for the deflection
delta = x dtheta), some centimetres of link at the paper's threshold (0.02 N m), well under a
millimetre at one identified on free sweeps (about 1e-4 N m), where the residual filter's lag
sets t_c. The contact's onset is found looking
back from t_c: the last sample where the detector's filtered residual was at most
:data:`ONSET_FRACTION` of the threshold, a level a contact reaches after a twentieth of that
turn plus the residual filter's lag (:func:`contact_onset`). The free part of a sweep ends
before the onset by :data:`ONSET_FACTOR` times that twentieth (:func:`onset_turn`; x an ``ok``
estimate's abscissa, else the link's length: the most compliant contact turns the head
furthest) and by the filter's lag at the head's speed there. Turns are the angle the link's
direction X^m turns through, not a difference of motor angles (an azimuth step turns the link by
cos(theta2) of it). The onset can come well before the touch, where the free motion's residual
stays near its level for a while (it only shortens the free part); the link that touched is
taken at t_c, when it is pressing the object. A recording without a detected contact adds no
free space: a contact too light to detect, sliding over an edge, bends the link as far as one
just below the threshold, so its angles do not say where the link was.

For recognition (``mapping.recognition``) a :class:`FreeSpace` gives one residual per sweep:
how far its link reaches into a shape, beyond the link's own radius, over its standard
deviation, at the deepest of its samples: r_j = min(0, min_k (d(q_k) - a) / sigma_k), d the
shape's signed distance (negative inside) and a the link's radius.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import STANDARD_GRAVITY, Antenna
from sensing_antenna.detection.contact import ContactDetection, detect_contact
from sensing_antenna.estimation.front.contact_frame import motor_axes
from sensing_antenna.estimation.result import Status
from sensing_antenna.mapping.points import ContactPoint, PointUncertainty
from sensing_antenna.mapping.pose import BasePose, base_pose_from_metadata
from sensing_antenna.recording import Recording

__all__ = [
    "FREE_POINTING",
    "FREE_STEP",
    "ONSET_FACTOR",
    "ONSET_FRACTION",
    "FreeSpace",
    "Piece",
    "Touches",
    "contact_onset",
    "free_before",
    "free_space",
    "onset_turn",
    "recording_links",
    "touches",
]

FloatArray = NDArray[np.float64]

#: A :class:`FreeSpace` or a subclass (:class:`Touches`), for methods that keep the kind.
_Space = TypeVar("_Space", bound="FreeSpace")

#: A contact's onset is the last sample before t_c where the detector's filtered residual was
#: at most this fraction of its threshold: twenty times the free motion's residual at the
#: paper's threshold, so that noise does not end the look back early.
ONSET_FRACTION = 0.05

#: How many times the static turn to the onset level (module docstring) a sweep's free part
#: ends before the onset, beside the residual filter's lag: the contact's build-up (its impact,
#: the link's own response) adds to the static turn.
ONSET_FACTOR = 5.0

#: Standard deviation (rad) of the free link's direction, from the base, beside the sag model:
#: its swing while the head speeds up, one and a half times the quasi-static tip deflection of
#: the module docstring over the paper link's length (5.2 mm at 0.98 m); the encoders' counts
#: (3e-5 rad at the joint) are negligible beside it.
FREE_POINTING = 0.0053

#: Largest distance (m) between neighbouring samples of the swept link, along it and from one
#: angle to the next: about the standard deviation of the samples 0.5 m out.
FREE_STEP = 0.005


@dataclass(frozen=True, eq=False)
class FreeSpace:
    """Samples of links that swept through free space, grouped by sweep.

    Attributes
    ----------
    samples : array, shape (k, 3)
        Points of the links' axes (m, world).
    std : array, shape (k,)
        Their standard deviations across the link (m, > 0).
    sweep : array of int, shape (k,)
        Which sweep each sample belongs to (0 .. n_sweeps - 1).
    n_sweeps : int
        Sweeps, including any whose samples were all left out by :meth:`near`.
    radius : float
        The link's radius (m): a shape's surface may come this close to a sample's axis point.
    """

    samples: FloatArray
    std: FloatArray
    sweep: NDArray[np.int64]
    n_sweeps: int
    radius: float

    def __post_init__(self) -> None:
        samples = np.asarray(self.samples, dtype=float).reshape(-1, 3)
        n = len(samples)
        std = np.asarray(self.std, dtype=float).reshape(-1)
        sweep = np.asarray(self.sweep, dtype=np.int64).reshape(-1)
        if len(std) != n or len(sweep) != n:
            raise ValueError(f"FreeSpace: {n} samples, {len(std)} std, {len(sweep)} sweep indices")
        if not np.all(std > 0.0) or not np.all(np.isfinite(std)):
            raise ValueError("FreeSpace.std: every standard deviation must be finite and > 0")
        if self.n_sweeps < 0 or not self.radius >= 0.0:
            raise ValueError("FreeSpace: n_sweeps and radius must be >= 0")
        if n and (sweep.min() < 0 or sweep.max() >= self.n_sweeps):
            raise ValueError(f"FreeSpace.sweep: indices outside 0 .. {self.n_sweeps - 1}")
        for name, value in (("samples", samples), ("std", std), ("sweep", sweep)):
            value = value.copy()
            value.flags.writeable = False
            object.__setattr__(self, name, value)

    def near(self: _Space, points: ArrayLike, margin: float) -> _Space:
        """The samples inside the points' bounding box grown by ``margin`` (m) each way: the
        part of free space a shape fitted to the points can reach."""
        p = np.asarray(points, dtype=float).reshape(-1, 3)
        low = p.min(axis=0) - margin
        high = p.max(axis=0) + margin
        keep = np.all((self.samples >= low) & (self.samples <= high), axis=1)
        return self._subset(keep)

    def within(self: _Space, signed_distance: FloatArray, distance: float) -> _Space:
        """The samples whose signed distance to a shape (m, shape (k,)) is below ``distance``
        (m) beyond the link's radius: those a shape moving a little may reach."""
        keep = np.asarray(signed_distance) - self.radius < distance
        return self._subset(keep)

    def _subset(self: _Space, keep: NDArray[np.bool_]) -> _Space:
        return dataclasses.replace(
            self, samples=self.samples[keep], std=self.std[keep], sweep=self.sweep[keep]
        )

    def residuals(self, signed_distance: FloatArray) -> FloatArray:
        """r_j (module docstring), shape (n_sweeps,), from a shape's signed distance (m) at
        every sample, shape (k,); 0 for a sweep no shape reaches (a NaN distance is none). For
        a batch of shapes' distances, shape (B, k): shape (B, n_sweeps)."""
        return self._least_depth(signed_distance, 0.0)

    def _least_depth(self, signed_distance: FloatArray, empty: float) -> FloatArray:
        """Each sweep's least (d - a) / sigma over its samples, ``empty`` for one without
        samples, shape (..., n_sweeps) for distances of shape (..., k)."""
        depth = (np.asarray(signed_distance, dtype=float) - self.radius) / self.std
        depth = np.where(np.isnan(depth), np.inf, depth)
        batch = depth.shape[:-1]
        rows = int(np.prod(batch, dtype=int))
        r = np.full(rows * self.n_sweeps, empty)
        groups = (np.arange(rows)[:, None] * self.n_sweeps + self.sweep).reshape(-1)
        np.minimum.at(r, groups, depth.reshape(-1))
        return r.reshape(*batch, self.n_sweeps)


@dataclass(frozen=True, eq=False)
class Touches(FreeSpace):
    """The link of each contact when it was detected, touching the object somewhere along its
    length (the attributes of :class:`FreeSpace`, one group per contact): a shape that comes
    nowhere near such a link is refuted, r_j = max(0, min_k (d(q_k) - a) / sigma_k)."""

    def residuals(self, signed_distance: FloatArray) -> FloatArray:
        """r_j, shape (n_sweeps,), from a shape's signed distance (m) at every sample, shape
        (k,); 0 for a contact whose link the shape reaches, and for one with no samples (a NaN
        distance is none). For a batch of shapes' distances, shape (B, k): shape (B, n_sweeps)."""
        r = self._least_depth(signed_distance, np.inf)
        return np.where(np.isfinite(r), np.maximum(r, 0.0), 0.0)

    def near(self: _Space, points: ArrayLike, margin: float) -> _Space:
        """All the samples: a link that touched beyond the points still says the object
        reaches it (a few hundred samples per contact)."""
        return self

    def within(self: _Space, signed_distance: FloatArray, distance: float) -> _Space:
        """All the samples: the one nearest a shape decides, however far it is."""
        return self


def onset_turn(antenna: Antenna, x_c: float) -> float:
    """How far before the contact's onset (rad) a sweep's free part ends, for a contact at
    ``x_c`` (m; the link's length when not finite): :data:`ONSET_FACTOR` times
    :data:`ONSET_FRACTION` tau_th x / (3 E I), E I from the antenna's (calibrated) frequency
    model."""
    link = antenna.link
    x = x_c if math.isfinite(x_c) and 0.0 < x_c <= link.length else link.length
    rigidity = 1.0 / link.bending_compliance
    static = antenna.observer.contact_threshold * x / (3.0 * rigidity)
    return ONSET_FACTOR * ONSET_FRACTION * static


def contact_onset(detection: ContactDetection) -> float:
    """The contact's onset (s): the last sample at or before t_c where the detector's filtered
    residual was at most :data:`ONSET_FRACTION` of its threshold (the recording's first sample
    when it never was); NaN when no contact was detected."""
    if detection.index is None:
        return math.nan
    level = detection.filtered_residual_norm[: detection.index + 1]
    quiet = np.nonzero(level <= ONSET_FRACTION * detection.threshold)[0]
    return float(detection.t[quiet[-1] if quiet.size else 0])


def free_before(theta: ArrayLike, t: ArrayLike, onset: float, turn: float) -> FloatArray:
    """The angles (rad, shape (k, 2)) of a recording's head while its link was free: those
    before the contact's ``onset`` (s) at least ``turn`` (rad) from the angles there; none
    when the onset is not known (NaN: no contact detected, module docstring)."""
    angles = np.asarray(theta, dtype=float).reshape(-1, 2)
    times = np.asarray(t, dtype=float).reshape(-1)
    if not math.isfinite(onset):
        return angles[:0]
    at_onset = _sample_at(times, onset)
    before = angles[: at_onset + 1]
    far = _turn(before, angles[at_onset]) >= turn
    last = np.nonzero(far)[0]
    return before[: last[-1] + 1] if last.size else before[:0]


def _sample_at(times: FloatArray, instant: float) -> int:
    """The first sample at or after ``instant`` (s) of ``times`` (s, increasing), the last
    one past the end."""
    return int(np.clip(np.searchsorted(times, instant), 0, len(times) - 1))


def _turn(theta: FloatArray, to: FloatArray) -> FloatArray:
    """The angle (rad, shape (k,)) the link's direction turns through from each of ``theta``
    (rad, shape (k, 2)) to ``to`` (rad, shape (2,))."""
    a = motor_axes(theta)[:, 0]
    b = motor_axes(np.asarray(to, dtype=float).reshape(1, 2))[:, 0]
    return np.asarray(np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), a @ b[0]))


#: One stretch of a sweep: the base pose its angles are in and the head's angles (rad, shape
#: (k, 2)) while the link was free (or, for :class:`Touches`, when it touched).
Piece = tuple[BasePose, ArrayLike]


def recording_links(
    recording: Recording, antenna: Antenna, point: ContactPoint | None = None
) -> tuple[Piece, Piece | None]:
    """What a recording says of its link: the free part of its sweep (:func:`free_before` the
    onset of its detected contact, by the :func:`onset_turn` of a contact at ``point``'s x_c
    when it is ``ok``, else at the tip, and by the residual filter's lag at the head's speed),
    and the link when the contact was detected (t_c) when ``point`` (the recording's estimate)
    is not ``ok``: an ``ok`` point says more (None then, and without a detected contact); both
    in the recording's ``base_pose``. The onset, looked back for, can come well before the
    touch (where the free motion's residual is large); the link at t_c is pressing the object.
    A recording whose estimate says its samples are not in the format's units and signs
    (``implausible_input``: angles in degrees, loads in other units) says neither; one whose
    samples could not be used (``bad_input``: a gap in the hold) keeps its angles' free sweep.

    Raises
    ------
    FieldError
        One line naming the recording when its base pose is malformed.
    """
    pose = base_pose_from_metadata(recording.metadata, recording.source)
    if point is not None and point.status is Status.IMPLAUSIBLE_INPUT:
        return (pose, recording.theta[:0]), None
    detection = detect_contact(recording, antenna)
    onset = contact_onset(detection)
    if not math.isfinite(onset):
        return (pose, recording.theta[:0]), None
    t = recording.t
    at = _sample_at(t, onset)
    # the head's turn rate over the filter's time constant before the onset
    lag = 1.0 / detection.residual_cutoff
    earlier = int(np.clip(np.searchsorted(t, onset - lag), 0, at))
    span = float(t[at] - t[earlier])
    rate = (
        float(_turn(recording.theta[earlier : earlier + 1], recording.theta[at])[0]) / span
        if span > 0
        else 0.0
    )
    ok = point is not None and point.status is Status.OK
    x_c = point.x_c if point is not None and ok else math.nan
    free = free_before(recording.theta, t, onset, onset_turn(antenna, x_c) + rate * lag)
    # t_c on the recording's own samples (the detector may have resampled them); a finite
    # onset means a detected contact, which has its t_c
    assert detection.t_c is not None
    detected = _sample_at(t, detection.t_c)
    return (pose, free), None if ok else (pose, recording.theta[detected : detected + 1])


def free_space(
    sweeps: Sequence[Sequence[Piece]],
    antenna: Antenna,
    uncertainty: PointUncertainty | None = None,
) -> FreeSpace:
    """The links of ``sweeps`` (each one or more :data:`Piece`), sampled every
    :data:`FREE_STEP` along the link and between angles (module docstring)."""
    return FreeSpace(*_sampled(sweeps, antenna, uncertainty))


def touches(
    contacts: Sequence[Sequence[Piece]],
    antenna: Antenna,
    uncertainty: PointUncertainty | None = None,
) -> Touches:
    """The links of ``contacts`` when each was detected (each one or more :data:`Piece`,
    usually one angle), sampled as :func:`free_space` samples them."""
    return Touches(*_sampled(contacts, antenna, uncertainty))


def _sampled(
    sweeps: Sequence[Sequence[Piece]], antenna: Antenna, uncertainty: PointUncertainty | None
) -> tuple[FloatArray, FloatArray, NDArray[np.int64], int, float]:
    uncertainty = uncertainty if uncertainty is not None else PointUncertainty()
    link = antenna.link
    x = np.linspace(0.0, link.length, max(2, math.ceil(link.length / FREE_STEP) + 1))[1:]
    unit_sag = STANDARD_GRAVITY * np.asarray(link.unit_sag(x), dtype=float)
    rho = uncertainty.deflection_relative_std
    samples, std, index = [], [], []
    for j, pieces in enumerate(sweeps):
        for pose, theta in pieces:
            angles = np.asarray(theta, dtype=float).reshape(-1, 2)
            angles = _resampled(angles, FREE_STEP / link.length)
            if not len(angles):
                continue
            x_m = motor_axes(angles)[:, 0]  # X^m per angle, shape (k, 3)
            # the sag along A, the part of -Z^a across the link: g u(x) (-Z^a - (-Z^a . X^m) X^m)
            across = -np.eye(3)[2][None, :] + x_m[:, 2:3] * x_m
            along = x[None, :, None] * x_m[:, None, :]
            local = along + unit_sag[None, :, None] * across[:, None, :]
            sag = unit_sag[None, :] * np.linalg.norm(across, axis=1)[:, None]
            sigma = np.hypot(x[None, :] * FREE_POINTING, rho * sag)
            samples.append(pose.point_to_world(local.reshape(-1, 3)))
            std.append(sigma.reshape(-1))
            index.append(np.full(sigma.size, j))
    if not samples:
        return np.zeros((0, 3)), np.zeros(0), np.zeros(0, np.int64), len(sweeps), link.radius
    return (
        np.concatenate(samples),
        np.concatenate(std),
        np.concatenate(index).astype(np.int64),
        len(sweeps),
        link.radius,
    )


def _resampled(angles: FloatArray, step: float) -> FloatArray:
    """The head's path through ``angles`` (rad, shape (k, 2)) every ``step`` (rad) of the motor
    angles' path (the link turns by as much or less), its ends kept: a recording's 1 kHz
    samples are far denser than the link needs."""
    if len(angles) < 2:
        return angles
    turn = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(angles, axis=0), axis=1))])
    if turn[-1] <= step:
        return angles[[0, -1]]
    at = np.linspace(0.0, turn[-1], math.ceil(turn[-1] / step) + 1)
    return np.column_stack([np.interp(at, turn, angles[:, i]) for i in range(2)])
