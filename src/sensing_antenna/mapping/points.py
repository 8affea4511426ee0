"""Contact points in the world with their covariance: what a map is built from.

An estimate gives the touched point in the recording's absolute frame (``contact_point``),
p_a = x_c X^m + y_c Y^c + s A, the abscissa x_c along the link's rigid line X^m, bent by the
push deflection y_c along Y^c (the reaction's direction) and by the weight's sag s along A (the
part of -Z^a across the link; estimation/methods/touch_point.py), all at the instant the point
describes (the diagnostics' ``t_point``, with the head's motor angles and the reaction then): a
point of the link's axis. The map's
point is on the link's surface, where the object touches it (the link's thickness, below). Its
covariance is propagated to first order from independent sources (docs/mapping.md derives each
term):

along the link
    x_c has a standard deviation sigma_x: from the method's 95 % interval, (high - low) / (2 *
    1.96), or a documented default per method when it gives none (:data:`DEFAULT_ALONG_STD`).
    dp/dx_c = (1 - 5 delta / x_c) X^m + (3 y_c / x_c) Y^c + (ds/dx_c) A: at a given load y_c
    grows as x_c^3 and the bent link's shortening delta (below) as y_c^2 / x_c, i.e. x_c^5.
the encoders
    each angle is known to one count, q_i = 2 pi / (counts n_i) (n_i the gear ratio), a uniform
    rounding error of variance q_i^2 / 12. dX^m/dtheta1 = cos(theta2) Y^m and dX^m/dtheta2 = Z^m,
    so dp/dtheta1 = x_c cos(theta2) Y^m and dp/dtheta2 = x_c Z^m.
the deflection model
    y_c and s both scale with the link's compliance 1 / (E I), but they are different load
    cases of the model (a pinned contact; a uniform weight) and err differently: a relative
    uncertainty rho of the push's deflection moves the contact along the elastica the
    estimators place it on (estimation/methods/touch_point.py): by rho y_c along Y^c (across
    the link, the measured reaction's direction) and by 2 rho delta back along X^m, delta =
    x_c - p_a . X^m the bent link's shortening (second order in y_c: delta grows as the
    square of the compliance); independently, rho s along A. The deflection's direction is
    the reaction's, which the sensor measures: a round link bends along the load it carries.
    Without the contact frame (an estimate that does not report it) that direction is
    unknown: rho y_c in every direction, and y_c = (y_c / x_c) x_c from the reported ratio.

the link's thickness
    the estimate is a point of the link's axis, the object is touched by the link's surface,
    on the side the object pushes from: the link bends away from the object, along Y^c, so the
    surface point is the axis point moved by r against Y^c (its part across the link,
    :func:`surface_offset`). The normal's direction around the link is the reaction's only to
    within the friction cone, and unknown without the contact frame (no move then): the
    variance r^2 / 2 in each of the two directions across the link, as for an offset in an
    unknown direction, covers both.

the link's straightness
    the model's link is straight; a real one may be bowed (its unloaded tip off its root's line
    by d), which moves the contact by the arc d (x_c / l)^2 across the link. With the antenna's
    ``link.bow_std`` (the tip offset's standard deviation in each direction across the link),
    (bow_std (x_c / l)^2)^2 in each direction across it.

Sigma_a = sigma_x^2 J_x J_x^T + sum_i q_i^2 / 12 J_i J_i^T + rho^2 (J_d J_d^T + s^2 A A^T)
+ (r^2 / 2 + b^2) (I - X^m X^mT), J_d = y_c Y^c - 2 delta X^m, b = bow_std (x_c / l)^2, and in
the world Sigma_w = R Sigma_a R^T with the base pose's rotation R.

The link's tangent at the contact, t ~ X^m + (3 y_c / (2 x_c)) Y^c + (ds/dx_c) A (the end slope
of a cantilever of length x_c loaded at its end, y' = 3 y_c / (2 x_c), and the sag's slope),
with the standard deviation in angle sqrt((rho y')^2 + (rho ds/dx_c)^2 + tau^2), tau =
:data:`TANGENT_FLOOR` the head's pointing: a round link touching an object is tangent to it
there, which the recognition checks (mapping.recognition, "The link's line").
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from sensing_antenna.antenna import STANDARD_GRAVITY, Antenna
from sensing_antenna.estimation.front.contact_frame import motor_axes
from sensing_antenna.estimation.result import ContactEstimate, Status
from sensing_antenna.mapping.pose import BasePose

__all__ = [
    "DEFAULT_ALONG_STD",
    "TANGENT_FLOOR",
    "Z_95",
    "ContactPoint",
    "PointUncertainty",
    "contact_point_from_estimate",
    "isolated_points",
    "link_tangent",
    "select_points",
    "surface_offset",
]

FloatArray = NDArray[np.float64]

#: Two-sided 95 % quantile of the standard normal: a 95 % interval is +- 1.96 sigma.
Z_95 = 1.959963984540054

#: Standard deviation of x_c (m) for methods that give no interval, set from the mean and
#: maximum abscissa errors of each method on the default simulated campaign (docs/mapping.md):
#: ``paper`` and ``two-frequency`` stay within about 2 mm of the contact abscissa, the
#: torque/force ``ratio`` alone errs by centimetres. A method not listed gets ``unknown``.
DEFAULT_ALONG_STD: Mapping[str, float] = {
    "paper": 0.001,
    "two-frequency": 0.0015,
    "ratio": 0.03,
    "unknown": 0.01,
}


#: Standard deviation (rad) of the link's direction at a contact beside the deflection model's:
#: the head's pointing, its encoders' zero (set by hand or an index pulse, a few mrad) and a
#: clamp that lets the rod rock in its bore under the push (a few mrad at the paper's loads).
TANGENT_FLOOR = 0.01


@dataclass(frozen=True)
class PointUncertainty:
    """What the covariance of a contact point is made of, beside the estimate itself.

    Attributes
    ----------
    encoder_counts : int
        Encoder counts per motor-shaft revolution after quadrature (2000: a 500-line encoder,
        the simulator's default); the joint's resolution divides by the gear ratio.
    deflection_relative_std : float
        rho, relative standard deviation of the push deflection and of the sag (both scale with
        1 / (E I)): 0.1, the Euler-Bernoulli cantilever and a pinned contact against a
        compliant one, and E I known from a calibrated T_e to a few per cent.
    along_std : Mapping[str, float]
        sigma_x (m) per method without an interval (:data:`DEFAULT_ALONG_STD`).
    """

    encoder_counts: int = 2000
    deflection_relative_std: float = 0.1
    along_std: Mapping[str, float] = field(default_factory=lambda: dict(DEFAULT_ALONG_STD))

    def __post_init__(self) -> None:
        if self.encoder_counts < 0:
            raise ValueError("encoder_counts must be >= 0 (0: exact encoders)")
        if not self.deflection_relative_std >= 0:
            raise ValueError("deflection_relative_std must be >= 0")

    def sigma_along(self, estimate: ContactEstimate) -> float:
        """sigma_x (m): from the 95 % interval when the estimate has one, else the default."""
        if estimate.interval is not None:
            low, high = estimate.interval
            if math.isfinite(low) and math.isfinite(high) and high >= low:
                return (high - low) / (2.0 * Z_95)
        return float(self.along_std.get(estimate.method, self.along_std["unknown"]))


@dataclass(frozen=True)
class ContactPoint:
    """One touched point in the world frame.

    Attributes
    ----------
    point : array, shape (3,)
        The touched point (m), world frame, on the link's surface where the object touches it;
        NaN without an estimate.
    covariance : array, shape (3, 3)
        Its covariance (m^2), world frame; NaN without an estimate.
    status : Status
        The estimate's status (only ``ok`` points enter a map by default).
    source : str
        Where it came from (the recording's path).
    method : str
        The estimation method.
    x_c : float
        Contact abscissa along the link (m).
    base_position : array, shape (3,)
        The antenna's base point O in the world (m): the link reached the point from there, so
        it lies on the object's outer side (a surface's outward normal points towards it).
    reason : str or None
        Why the status is not ``ok``.
    true_point : array, shape (3,)
        The simulator's ground truth in the world frame when known (where the contact was at
        the estimate's ``t_point`` from the recording's contact track, else where it ended,
        ``true_contact_point``), else NaN; never used to build the map.
    tangent : array, shape (3,)
        The link's unit tangent at the contact, from the base towards the tip (world); NaN when
        not known.
    tangent_std : float
        Its standard deviation in angle (rad); NaN when not known.
    link_beyond : float
        Link length (m) between the contact and the tip; NaN when not known.
    held_back_by_width : bool
        An ``uncertain`` estimate whose one fault is its interval's width, one spread
        (:attr:`~sensing_antenna.estimation.ContactEstimate.held_back_by_width`): its
        covariance carries that width.
    """

    point: FloatArray
    covariance: FloatArray
    status: Status
    source: str
    method: str
    x_c: float
    base_position: FloatArray
    reason: str | None = None
    true_point: FloatArray = field(default_factory=lambda: np.full(3, np.nan))
    tangent: FloatArray = field(default_factory=lambda: np.full(3, np.nan))
    tangent_std: float = math.nan
    link_beyond: float = math.nan
    held_back_by_width: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "status", Status(self.status))
        for name, shape in (
            ("point", (3,)),
            ("covariance", (3, 3)),
            ("base_position", (3,)),
            ("true_point", (3,)),
            ("tangent", (3,)),
        ):
            array = np.array(getattr(self, name), dtype=float).reshape(shape)
            array.setflags(write=False)
            object.__setattr__(self, name, array)

    @property
    def usable(self) -> bool:
        """True when the point and its covariance are finite numbers."""
        return bool(np.all(np.isfinite(self.point)) and np.all(np.isfinite(self.covariance)))

    @property
    def std(self) -> float:
        """sqrt of the largest eigenvalue of the covariance (m): the worst-direction sigma."""
        if not self.usable:
            return math.nan
        return float(math.sqrt(max(np.linalg.eigvalsh(self.covariance)[-1], 0.0)))


def contact_point_from_estimate(
    estimate: ContactEstimate,
    antenna: Antenna,
    base_pose: BasePose | None = None,
    source: str = "",
    uncertainty: PointUncertainty | None = None,
    true_point_a: FloatArray | None = None,
) -> ContactPoint:
    """The world point and covariance of an estimate (see the module's docstring).

    Parameters
    ----------
    estimate : ContactEstimate
        Its ``contact_point`` (absolute frame, m), ``x_c``, ``interval``, ``status`` and the
        diagnostics ``theta_at_point`` (rad, shape (2,)), ``deflection`` (m) and
        ``axes_c_absolute`` (rows X^c, Y^c, Z^c) when present; without the angles the link's
        direction is taken from the point itself.
    antenna : Antenna
        The link (sag) and the gear ratios (encoder resolution).
    base_pose : BasePose, optional
        The absolute frame in the world (identity when None).
    source : str
        Recorded in the point.
    uncertainty : PointUncertainty, optional
        Encoders, deflection model, defaults along the link.
    true_point_a : array, shape (3,), optional
        Ground truth in the absolute frame, carried to the world for scoring.
    """
    pose = base_pose if base_pose is not None else BasePose.identity()
    spec = uncertainty if uncertainty is not None else PointUncertainty()
    truth = pose.point_to_world(true_point_a) if true_point_a is not None else np.full(3, np.nan)
    point_a = np.asarray(estimate.contact_point, dtype=float)
    x_c = float(estimate.x_c)
    usable = bool(np.all(np.isfinite(point_a)) and math.isfinite(x_c) and x_c > 0)
    if usable:
        g = _geometry(estimate, antenna)
        tangent, tangent_std = _tangent(g, x_c, spec)
        point_w = pose.point_to_world(point_a + _surface_offset(g, antenna.link.radius))
        covariance = pose.covariance_to_world(_covariance(g, estimate, antenna, spec))
    else:
        tangent, tangent_std = np.full(3, np.nan), math.nan
        point_w, covariance = np.full(3, np.nan), np.full((3, 3), np.nan)
    return ContactPoint(
        point=point_w,
        covariance=covariance,
        status=estimate.status,
        source=source,
        method=estimate.method,
        x_c=x_c,
        base_position=pose.position,
        reason=estimate.reason,
        true_point=truth,
        tangent=pose.rotation @ tangent,
        tangent_std=tangent_std,
        link_beyond=max(antenna.link.length - x_c, 0.0) if usable else math.nan,
        held_back_by_width=estimate.held_back_by_width,
    )


@dataclass(frozen=True)
class _Geometry:
    """The estimate's link at the contact, in the absolute frame (module docstring)."""

    theta: FloatArray  # motor angles the point was placed at (rad)
    x_m: FloatArray
    y_m: FloatArray
    z_m: FloatArray
    deflection: float  # y_c (m)
    y_c_axis: FloatArray | None  # the deflection's direction, when reported
    sag: float  # s (m)
    sag_axis: FloatArray  # A, unit
    sag_slope: float  # ds/dx_c


def _geometry(estimate: ContactEstimate, antenna: Antenna) -> _Geometry:
    x_c = float(estimate.x_c)
    point_a = np.asarray(estimate.contact_point, dtype=float)
    diagnostics = estimate.diagnostics
    theta = _angles(diagnostics.get("theta_at_point"), point_a)
    axes_m = motor_axes(theta)  # rows X^m, Y^m, Z^m in the absolute frame
    x_m = axes_m[0]
    deflection = _finite(
        diagnostics.get("deflection"), _finite(diagnostics.get("deflection_ratio"), 0.0) * x_c
    )
    # the sag's direction A: -Z^a without its part along X^m; s = g |A| u(x_c)
    down = np.array([0.0, 0.0, -1.0])
    across = down - (down @ x_m) * x_m
    across_norm = float(np.linalg.norm(across))
    link = antenna.link
    x_in = min(x_c, link.length)
    # ds/dx_c by a central difference of the handbook sag curve (1 mm steps inside the link)
    step = min(1e-3, 0.5 * x_in)
    slope = (
        STANDARD_GRAVITY
        * across_norm
        * float(link.unit_sag(min(x_in + step, link.length)) - link.unit_sag(x_in - step))
        / (min(x_in + step, link.length) - (x_in - step))
    )
    return _Geometry(
        theta=theta,
        x_m=x_m,
        y_m=axes_m[1],
        z_m=axes_m[2],
        deflection=deflection,
        y_c_axis=_contact_y_axis(diagnostics.get("axes_c_absolute")),
        sag=STANDARD_GRAVITY * across_norm * float(link.unit_sag(x_in)),
        sag_axis=across / across_norm if across_norm > 0 else np.zeros(3),
        sag_slope=slope,
    )


def surface_offset(estimate: ContactEstimate, antenna: Antenna) -> FloatArray:
    """From the link's axis to its surface where the object touches it (m, absolute frame,
    shape (3,)): the link's radius against the deflection's direction Y^c, across the link
    (module docstring); zero without the contact frame."""
    return _surface_offset(_geometry(estimate, antenna), antenna.link.radius)


def _surface_offset(g: _Geometry, radius: float) -> FloatArray:
    if g.y_c_axis is None:
        return np.zeros(3)
    across = g.y_c_axis - (g.y_c_axis @ g.x_m) * g.x_m
    norm = float(np.linalg.norm(across))
    if not norm > 0:
        return np.zeros(3)
    return np.asarray(-radius * across / norm)


def link_tangent(
    estimate: ContactEstimate, antenna: Antenna, uncertainty: PointUncertainty
) -> tuple[FloatArray, float]:
    """The link's unit tangent at the contact (absolute frame, shape (3,)) and its standard
    deviation in angle (rad) (module docstring); without the deflection's direction the push's
    slope is unknown and enters only the standard deviation."""
    return _tangent(_geometry(estimate, antenna), float(estimate.x_c), uncertainty)


def _tangent(g: _Geometry, x_c: float, uncertainty: PointUncertainty) -> tuple[FloatArray, float]:
    push_slope = 1.5 * g.deflection / x_c
    tangent = g.x_m + g.sag_slope * g.sag_axis
    if g.y_c_axis is not None:
        tangent = tangent + push_slope * g.y_c_axis
    rho = uncertainty.deflection_relative_std
    push_std = rho * push_slope if g.y_c_axis is not None else push_slope
    std = math.sqrt(push_std**2 + (rho * g.sag_slope) ** 2 + TANGENT_FLOOR**2)
    return np.asarray(tangent / np.linalg.norm(tangent)), std


def _covariance(
    g: _Geometry, estimate: ContactEstimate, antenna: Antenna, uncertainty: PointUncertainty
) -> FloatArray:
    """Sigma_a (m^2), shape (3, 3), in the recording's absolute frame (module docstring)."""
    x_c = float(estimate.x_c)
    point_a = np.asarray(estimate.contact_point, dtype=float)
    theta, x_m, y_m, z_m = g.theta, g.x_m, g.y_m, g.z_m
    deflection, y_c_axis = g.deflection, g.y_c_axis
    sag, sag_axis, slope = g.sag, g.sag_axis, g.sag_slope
    link = antenna.link
    # the bent link's shortening delta = x_c - p_a . X^m (the deflection and the sag lie
    # across X^m); known only with the deflection's direction
    shortening = max(x_c - float(point_a @ x_m), 0.0) if y_c_axis is not None else 0.0
    # along: dp/dx_c = (1 - 5 delta / x_c) X^m + (3 y_c / x_c) Y^c + (ds/dx_c) A
    j_along = (1.0 - 5.0 * shortening / x_c) * x_m + slope * sag_axis
    if y_c_axis is not None:
        j_along = j_along + (3.0 * deflection / x_c) * y_c_axis
    sigma_x = uncertainty.sigma_along(estimate)
    covariance = sigma_x**2 * np.outer(j_along, j_along)
    # encoders: dp/dtheta1 = x_c cos(theta2) Y^m, dp/dtheta2 = x_c Z^m; variance q^2 / 12
    if uncertainty.encoder_counts > 0:
        for motor, j_angle in zip(
            antenna.motors, (x_c * math.cos(theta[1]) * y_m, x_c * z_m), strict=True
        ):
            quantum = 2.0 * math.pi / (uncertainty.encoder_counts * motor.gear_ratio)
            covariance += quantum**2 / 12.0 * np.outer(j_angle, j_angle)
    rho2 = uncertainty.deflection_relative_std**2
    if y_c_axis is not None:
        # deflection model along the elastica: J_d = y_c Y^c - 2 delta X^m
        j_deflection = deflection * y_c_axis - 2.0 * shortening * x_m
        covariance += rho2 * np.outer(j_deflection, j_deflection)
        # and, independently, rho s along A
        covariance += rho2 * sag**2 * np.outer(sag_axis, sag_axis)
    else:
        # direction unknown: rho y_c in every direction, plus the sag's rho s
        covariance += rho2 * deflection**2 * np.eye(3)
        covariance += rho2 * sag**2 * np.outer(sag_axis, sag_axis)
    across = np.eye(3) - np.outer(x_m, x_m)
    # the link's thickness: r^2 / 2 in each direction across the link
    covariance += 0.5 * link.radius**2 * across
    # a bow the model does not hold: its arc d (x_c / l)^2 in each direction across the link
    if link.bow_std:
        covariance += (link.bow_std * (x_c / link.length) ** 2) ** 2 * across
    return np.asarray(0.5 * (covariance + covariance.T))


def select_points(
    points: list[ContactPoint] | tuple[ContactPoint, ...], include_uncertain: bool = False
) -> list[ContactPoint]:
    """The points that enter a map: usable ones with status ``ok`` or held back by their
    interval's width alone (:attr:`ContactPoint.held_back_by_width`: their covariance carries
    it), and every ``uncertain`` one if asked."""
    return [
        p
        for p in points
        if p.usable
        and (
            p.status is Status.OK
            or (p.status is Status.UNCERTAIN and (p.held_back_by_width or include_uncertain))
        )
    ]


#: A point whose nearest other lies farther than the link's length and than this many times
#: the points' median spacing is named as isolated (:func:`isolated_points`): maps of one object
#: keep their points within centimetres of a neighbour (a tenth of the link at most on the
#: explorations' maps), while a base pose in cm or mm puts its point metres away.
ISOLATED_SPACING = 10.0


def isolated_points(
    points: list[ContactPoint] | tuple[ContactPoint, ...], reach: float
) -> list[tuple[ContactPoint, float, float]]:
    """The points a map uses (:func:`select_points`) that lie alone: farther than ``reach``
    (m, the link's length) and :data:`ISOLATED_SPACING` times the median spacing from every
    other one, with that distance and the spacing (m); none with fewer than four points."""
    used = select_points(points)
    if len(used) < 4:
        return []
    at = np.array([p.point for p in used])
    nearest = cKDTree(at).query(at, k=2)[0][:, 1]  # the first neighbour found is the point
    spacing = float(np.median(nearest))
    limit = max(reach, ISOLATED_SPACING * spacing)
    return [(p, float(d), spacing) for p, d in zip(used, nearest, strict=True) if d > limit]


def _angles(value: object, point_a: FloatArray) -> FloatArray:
    try:
        theta = np.asarray(value, dtype=float).reshape(2)
        if np.all(np.isfinite(theta)):
            return theta
    except (TypeError, ValueError):
        pass
    # the link's direction from the point itself (the deflection is a few per cent of x_c)
    x, y, z = point_a
    return np.array([math.atan2(y, x), math.atan2(z, math.hypot(x, y))])


def _contact_y_axis(value: object) -> FloatArray | None:
    try:
        axes = np.asarray(value, dtype=float).reshape(3, 3)
    except (TypeError, ValueError):
        return None
    return np.asarray(axes[1]) if np.all(np.isfinite(axes)) else None


def _finite(value: object, default: float) -> float:
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return default
    return number if math.isfinite(number) else default
