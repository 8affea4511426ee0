"""Calibration of the frequency model: the equivalent parameter T_e of Section 5.1.

The contact-mode frequency model is omega_1(x_c) = (beta_1 l)^2 / (T l^2), where beta_1 l depends
only on x_c / l (the pinned-clamped-free problem of Eqs. 3 and 4) and T = sqrt(rho / (E I)) is in
s / m^2. Section 5.1 replaces the theoretical T by an equivalent T_e that fits the fundamental
frequencies measured at known contact points in the least-squares sense.

The model is linear in u = 1 / T: omega_1 = k(x_c) u with k = beta_1(x_c)^2 (1 / m^2), so the
ordinary least-squares solution is closed form, u = sum(k omega) / sum(k^2). A robust loss
(``soft_l1`` by default) keeps one bad frequency measurement from pulling the fit; it is solved
with :func:`scipy.optimize.least_squares` starting from the closed form.

``fit`` (this module) and ``apply`` (:meth:`~sensing_antenna.antenna.Antenna.with_calibrated_t`)
are separate steps.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares

from sensing_antenna.antenna import PARAMETER_RANGES, Antenna, Link, metres_hint
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.recording import other_separator

__all__ = [
    "CALIBRATION_BAND",
    "CALIBRATION_BAND_MARGIN",
    "LOSSES",
    "MIN_MODE2_POINTS",
    "MIN_TIP_MASS_POINTS",
    "TIP_MASS_LOSS_SCALE",
    "WRONG_PEAK",
    "CalibrationError",
    "FrequencyCalibration",
    "calibrate_from_recordings",
    "calibrate_t_e",
    "fit_inverse_t",
    "held_compliance_from_recordings",
    "model_beta1_squared",
    "points_on_link",
    "read_contact_points",
    "unmatched_point_rows",
]

#: Robust losses accepted by :func:`fit_inverse_t` (those of scipy.optimize.least_squares).
LOSSES = ("linear", "soft_l1", "huber", "cauchy", "arctan")

#: The narrowest band (rad/s) searched for the fundamental frequency during calibration (1.6 Hz
#: to 64 Hz): the paper's measured range 31.4 to 106.8 rad/s (Section 5.1) with a factor 3 of
#: margin on each side. :func:`calibration_band` widens it for another link.
CALIBRATION_BAND = (10.0, 400.0)

#: Margin (factor each side) of :func:`calibration_band` around the model's omega_1 range: a
#: link whose T is twice its datasheet's (E I a quarter) still has its fundamental inside. A
#: wider one reaches down to the head's own slow motions (peaks at 8 to 10 rad/s on the
#: simulated realistic device, which a factor 3 below the paper link's 22 rad/s takes in).
CALIBRATION_BAND_MARGIN = 2.0


def calibration_band(link: Link) -> tuple[float, float]:
    """Band (rad/s) searched for omega_1 when calibrating ``link``: the model's omega_1 over the
    estimators' contact range, :data:`CALIBRATION_BAND_MARGIN` wider each side, and at least
    :data:`CALIBRATION_BAND`. Wide, so that the measured frequencies hardly presuppose the
    T being fitted; derived from the link, so that a short or stiff link's fundamental (a
    0.35 m carbon rod rings at up to 770 rad/s) is not left out of its own calibration."""
    from sensing_antenna.estimation.config import EstimatorConfig
    from sensing_antenna.estimation.front.evidence import search_band

    # the estimators' own band, its margin a factor CALIBRATION_BAND_MARGIN
    bottom, top = search_band(link, EstimatorConfig(band_margin=CALIBRATION_BAND_MARGIN - 1.0))
    return min(CALIBRATION_BAND[0], bottom), max(CALIBRATION_BAND[1], top)


#: Floor of the robust loss scale, relative to the median measured frequency. With noise-free data
#: the MAD of the residuals is 0, which would make the robust scale zero; 1e-6 of the frequency
#: scale is far below any measurement resolution (an FFT bin of a 1 s window is 6.3 rad/s).
_RELATIVE_SCALE_FLOOR = 1e-6

#: 1.4826 MAD estimates the standard deviation of Gaussian residuals.
_MAD_TO_SIGMA = 1.4826

#: A calibration point whose relative residual is farther than this from the median is a wrong
#: spectral peak, not model error (:attr:`FrequencyCalibration.relative_scatter`). 5 %: wrong
#: peaks are another mode or a harmonic (the nearest, 2 omega_1 or mode 2, is 100 % or more away),
#: while a compliant contact or the contact's offset from the given point moved the simulated
#: device's omega_1 by at most 1 %.
WRONG_PEAK = 0.05


class CalibrationError(SensingAntennaError, ValueError):
    """Calibration input that cannot be used: too few points, bad values, missing contact points.

    ``field`` names the input at fault when the message blames one (``"contact_points"``), so a
    caller that took that input from elsewhere (a table, a file's ``true_xc``) can name it
    instead; ``problem`` is the message without it.
    """

    def __init__(self, problem: str, field: str | None = None) -> None:
        self.field = field
        self.problem = problem
        super().__init__(problem if field is None else f"{field}: {problem}")


@dataclass(frozen=True, eq=False)
class FrequencyCalibration:
    """Result of the T_e fit of Section 5.1.

    Attributes
    ----------
    t_e : float
        Fitted equivalent parameter T_e (s / m^2).
    t_e_std_error : float
        Standard error of T_e (s / m^2) from the linearised fit; NaN with fewer than 2 points.
    t_theoretical : float
        T = sqrt(rho / (E I)) of the starting link (s / m^2), for comparison.
    contact_points : ndarray, shape (n,)
        Known contact points x_c (m).
    omega1_measured : ndarray, shape (n,)
        Measured fundamental frequencies (rad/s); NaN where no frequency could be measured.
    omega1_fitted : ndarray, shape (n,)
        Model frequencies with T_e at the same contact points (rad/s).
    used : ndarray of bool, shape (n,)
        Points that entered the fit.
    loss : str
        Loss used by the fit.
    sources : tuple of str
        Where each point came from (file names), same order as ``contact_points``.
    notes : tuple of str
        Why points were left out, one note per excluded point.
    tip_mass : float or None
        The tip mass fitted with T_e (kg; :func:`calibrate_t_e` with ``fit_tip_mass``), None
        when T_e alone was fitted.
    omega2_measured : ndarray, shape (n,), or None
        The second contact mode measured at each point (rad/s; NaN where no clear peak lay
        near the calibrated model's), None when not looked for.
    omega2_fitted : ndarray, shape (n,), or None
        The calibrated model's omega_2 at each point (rad/s), None when not looked for.
    left_out_as_wrong : ndarray of bool, shape (n,), or None
        Points the fit left out as wrong spectral peaks or wrong known points (more than
        :data:`WRONG_PEAK` from the others, and few); None when not recorded (older files).
    held_joint : ndarray of int, shape (n,), or None
        The joint each point's sweep turned (0 azimuth, 1 elevation; -1 not measured), None
        when not looked for.
    held_compliance_measured : ndarray, shape (n,), or None
        The held joint's angle per link torque at each point's omega_1 (rad/(N m);
        :mod:`~sensing_antenna.estimation.held_joint`; NaN where not measured), None when not
        looked for.
    """

    t_e: float
    t_e_std_error: float
    t_theoretical: float
    contact_points: NDArray[np.float64]
    omega1_measured: NDArray[np.float64]
    omega1_fitted: NDArray[np.float64]
    used: NDArray[np.bool_]
    loss: str = "soft_l1"
    sources: tuple[str, ...] = ()
    notes: tuple[str, ...] = field(default=())
    tip_mass: float | None = None
    omega2_measured: NDArray[np.float64] | None = None
    omega2_fitted: NDArray[np.float64] | None = None
    left_out_as_wrong: NDArray[np.bool_] | None = None
    held_joint: NDArray[np.int64] | None = None
    held_compliance_measured: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        n = self.contact_points.shape
        for name in (
            "omega1_measured",
            "omega1_fitted",
            "used",
            "omega2_measured",
            "omega2_fitted",
            "left_out_as_wrong",
            "held_joint",
            "held_compliance_measured",
        ):
            value = getattr(self, name)
            if value is not None and value.shape != n:
                raise CalibrationError(f"{name}: shape {value.shape} != {n}")
        if not (math.isfinite(self.t_e) and self.t_e > 0):
            raise CalibrationError(f"t_e: must be finite and > 0, got {self.t_e!r}")

    @property
    def residuals(self) -> NDArray[np.float64]:
        """Measured minus fitted omega_1 (rad/s), shape (n,); NaN where not measured."""
        return self.omega1_measured - self.omega1_fitted

    @property
    def rms_residual(self) -> float:
        """Root-mean-square residual over the points used (rad/s)."""
        r = self.residuals[self.used]
        return float(np.sqrt(np.mean(r**2))) if r.size else math.nan

    @property
    def relative_scatter(self) -> float:
        """Relative error of the calibrated model omega_1(x_c), dimensionless; NaN if unknown.

        The root-mean-square relative residual (measured / fitted - 1) over the points used,
        with n - 1 degrees of freedom (T_e is fitted; n - 2 with the tip mass). It measures
        how far the device departs from the fitted model along the link (a compliant contact, a
        base that is not a clamp, contacts away from the given points), which the fit cannot
        absorb. A point more than :data:`WRONG_PEAK` from the median, one of few
        (:attr:`wrong_peak_points`), is a wrong spectral peak or a wrong known point, not model
        error: left out of the fit and of this (:attr:`wrong_peaks`); NaN with fewer than 3
        points left.
        """
        relative = self._relative_residuals()
        kept = relative[self.used & np.isfinite(relative) & ~self.wrong_peak_points]
        fitted = 1 if self.tip_mass is None else 2
        if kept.size < 2 + fitted:
            return math.nan
        return math.sqrt(float(np.sum(kept**2)) / (kept.size - fitted))

    @property
    def mode2_scatter(self) -> float:
        """Relative error of the calibrated model's omega_2(x_c), dimensionless; NaN if unknown.

        The root-mean-square relative residual (measured / model - 1) of the second contact
        mode over the points used where it was measured (the wrong peaks of omega_1 left out,
        as in :attr:`relative_scatter`), its mean included: nothing is fitted to omega_2, so a
        link whose second mode sits off the model's (a taper, a joint, a clamp that is not
        rigid, which T_e fitted to omega_1 does not take up) shows it here whole. NaN with
        fewer than :data:`MIN_MODE2_POINTS` such points, or when omega_2 was found at fewer
        than two thirds of them: it is searched within 5 % of the model's, so a link far off
        the model would leave only its nearest points, and a scatter that says too little.
        """
        kept, looked = self._mode2_residuals()
        if kept.size < MIN_MODE2_POINTS or 3 * kept.size < 2 * looked:
            return math.nan
        return math.sqrt(float(np.mean(kept**2)))

    @property
    def mode2_points(self) -> int:
        """Points whose second contact mode was found near the model's (those
        :attr:`mode2_scatter` is taken over); 0 when it was not looked for."""
        return int(self._mode2_residuals()[0].size)

    def _mode2_residuals(self) -> tuple[NDArray[np.float64], int]:
        """omega_2's relative residuals where it was found, and at how many points it was
        looked for (the points used, wrong peaks left out)."""
        if self.omega2_measured is None or self.omega2_fitted is None:
            return np.zeros(0), 0
        with np.errstate(divide="ignore", invalid="ignore"):
            relative = self.omega2_measured / self.omega2_fitted - 1.0
        points = self.used & np.isfinite(self.omega2_fitted) & ~self.wrong_peak_points
        return relative[points & np.isfinite(relative)], int(points.sum())

    @property
    def wrong_peaks(self) -> int:
        """Points left out of the fit and of :attr:`relative_scatter` as wrong peaks."""
        return int(self.wrong_peak_points.sum())

    @property
    def wrong_peak_points(self) -> NDArray[np.bool_]:
        """Which points, shape (n,), are wrong spectral peaks or wrong known points: those the
        fit left out as such (:attr:`left_out_as_wrong`), and any point it used that lies more
        than :data:`WRONG_PEAK` from the median relative residual when such points are few
        (one, or a tenth of the points, of :data:`MIN_WRONG_PEAK_POINTS` or more). More are the
        model's error (a payload bends the whole curve: 0.2 g puts 4 of 15 points beyond)."""
        relative = self._relative_residuals()
        found = _wrong_peaks(relative, self.used & np.isfinite(relative))
        if self.left_out_as_wrong is not None:
            found = found | self.left_out_as_wrong
        return found

    @property
    def kept_far_points(self) -> NDArray[np.bool_]:
        """Which points, shape (n,), the fit used and kept although they lie more than
        :data:`WRONG_PEAK` from the median relative residual of the points it used (three at
        least): wrong peaks or known points it could not leave out (below
        :data:`MIN_WRONG_PEAK_POINTS` points, or beyond the one or a tenth it leaves out)."""
        relative = self._relative_residuals()
        usable = self.used & np.isfinite(relative)
        if int(usable.sum()) < 3:
            return np.zeros(usable.shape, dtype=bool)
        far = usable & ~_near_median(relative, usable, WRONG_PEAK)
        return np.asarray(far & ~self.wrong_peak_points, dtype=bool)

    def _relative_residuals(self) -> NDArray[np.float64]:
        """measured / fitted - 1 at every point, shape (n,)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.asarray(self.omega1_measured / self.omega1_fitted - 1.0, dtype=float)

    @property
    def relative_difference(self) -> float:
        """(T_e - T) / T, dimensionless (the paper reports 7 %)."""
        return (self.t_e - self.t_theoretical) / self.t_theoretical

    @property
    def held_compliance(self) -> tuple[float | None, float | None]:
        """Each joint's held compliance (rad/(N m)): the largest its points used measured, None
        from fewer than :data:`~sensing_antenna.estimation.held_joint.MIN_POSTS`."""
        if self.held_joint is None or self.held_compliance_measured is None:
            return None, None
        used = self.used & np.isfinite(self.held_compliance_measured)
        return _largest_per_joint(self.held_joint[used], self.held_compliance_measured[used])

    def apply(self, antenna: Antenna) -> Antenna:
        """The antenna with this T_e as its calibrated T, :attr:`relative_scatter` and
        :attr:`mode2_scatter` as its scatters (none when unknown), the fitted tip mass, when
        fitted (the weight keeps the antenna's tip mass, ``Link.weight_tip_mass``), and each
        joint's :attr:`held_compliance` (kept where not measured)."""
        scatter, mode2 = self.relative_scatter, self.mode2_scatter
        if self.tip_mass is not None:
            # the weight the sensor reads at rest stays the antenna's (weight_tip_mass)
            link = antenna.link
            link = replace(link, tip_mass=self.tip_mass, weight_tip_mass=link.weighed_tip_mass)
            antenna = replace(antenna, link=link)
        antenna = antenna.with_held_compliance(*self.held_compliance)
        return antenna.with_calibrated_t(
            self.t_e,
            scatter if math.isfinite(scatter) else None,
            mode2 if math.isfinite(mode2) else None,
        )

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-ready summary (SI units); NaN (no measurement) is stored as None."""
        return {
            "t_e": self.t_e,
            "t_e_std_error": _json_float(self.t_e_std_error),
            "t_theoretical": self.t_theoretical,
            "relative_difference": self.relative_difference,
            "relative_scatter": _json_float(self.relative_scatter),
            "wrong_peaks": self.wrong_peaks,
            "rms_residual": _json_float(self.rms_residual),
            "loss": self.loss,
            "tip_mass": self.tip_mass,
            "mode2_scatter": _json_float(self.mode2_scatter),
            "points": [
                {
                    "source": self.sources[i] if i < len(self.sources) else "",
                    "x_c": float(self.contact_points[i]),
                    "omega1_measured": _json_float(float(self.omega1_measured[i])),
                    "omega1_fitted": _json_float(float(self.omega1_fitted[i])),
                    "used": bool(self.used[i]),
                    "wrong": bool(self.wrong_peak_points[i]),
                    **self._omega2_at(i),
                    **self._held_at(i),
                }
                for i in range(self.contact_points.size)
            ],
            "notes": list(self.notes),
        }

    def _omega2_at(self, i: int) -> dict[str, float | None]:
        """Point ``i``'s omega_2 entries of :meth:`to_dict`; none when not looked for."""
        if self.omega2_measured is None or self.omega2_fitted is None:
            return {}
        return {
            "omega2_measured": _json_float(float(self.omega2_measured[i])),
            "omega2_fitted": _json_float(float(self.omega2_fitted[i])),
        }

    def _held_at(self, i: int) -> dict[str, float | int | None]:
        """Point ``i``'s held-joint entries of :meth:`to_dict`; none when not looked for."""
        if self.held_joint is None or self.held_compliance_measured is None:
            return {}
        return {
            "held_joint": int(self.held_joint[i]),
            "held_compliance": _json_float(float(self.held_compliance_measured[i])),
        }

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> FrequencyCalibration:
        """Inverse of :meth:`to_dict` (derived values are recomputed, not read).

        Raises
        ------
        KeyError, TypeError, ValueError
            On malformed data; callers name the file.
        """
        points = list(data["points"])

        def column(name: str) -> NDArray[np.float64]:
            values = [math.nan if p[name] is None else float(p[name]) for p in points]
            return np.array(values, dtype=float)

        with_omega2 = bool(points) and all("omega2_fitted" in p for p in points)
        with_held = bool(points) and all("held_joint" in p for p in points)
        return cls(
            t_e=float(data["t_e"]),
            t_e_std_error=_float_or_nan(data.get("t_e_std_error")),
            t_theoretical=float(data["t_theoretical"]),
            contact_points=column("x_c"),
            omega1_measured=column("omega1_measured"),
            omega1_fitted=column("omega1_fitted"),
            used=np.array([bool(p["used"]) for p in points], dtype=bool),
            loss=str(data.get("loss", "soft_l1")),
            sources=tuple(str(p.get("source", "")) for p in points),
            notes=tuple(str(n) for n in data.get("notes", [])),
            tip_mass=None if data.get("tip_mass") is None else float(data["tip_mass"]),
            omega2_measured=column("omega2_measured") if with_omega2 else None,
            omega2_fitted=column("omega2_fitted") if with_omega2 else None,
            left_out_as_wrong=(
                np.array([bool(p["wrong"]) for p in points], dtype=bool)
                if points and all("wrong" in p for p in points)
                else None
            ),
            held_joint=(
                np.array([int(p["held_joint"]) for p in points], dtype=np.int64)
                if with_held
                else None
            ),
            held_compliance_measured=column("held_compliance") if with_held else None,
        )


def fit_inverse_t(
    beta1_squared: ArrayLike, omega1: ArrayLike, *, loss: str = "soft_l1"
) -> tuple[float, float]:
    """Fit u = 1 / T_e in omega_1 = beta_1^2 u; return (T_e, standard error of T_e).

    Parameters
    ----------
    beta1_squared : array_like, shape (n,)
        beta_1(x_c)^2 of the model at each contact point (1 / m^2), all > 0.
    omega1 : array_like, shape (n,)
        Measured fundamental frequencies (rad/s), finite.
    loss : str
        ``"linear"`` for ordinary least squares (closed form), or a robust loss of
        :func:`scipy.optimize.least_squares`.

    Returns
    -------
    t_e : float
        Equivalent T_e (s / m^2).
    std_error : float
        Standard error of T_e (s / m^2): residual variance s^2 = sum(r^2) / (n - 1), var(u) =
        s^2 / sum(k^2), propagated to T = 1 / u by the delta method; NaN when n < 2.
    """
    k = np.asarray(beta1_squared, dtype=float).ravel()
    w = np.asarray(omega1, dtype=float).ravel()
    if loss not in LOSSES:
        raise CalibrationError(f"loss: unknown {loss!r}; known: {', '.join(LOSSES)}")
    if k.shape != w.shape:
        raise CalibrationError(f"omega1: {w.size} frequencies for {k.size} contact points")
    if k.size == 0:
        raise CalibrationError("omega1: no measured frequency to fit")
    if not (np.all(np.isfinite(k)) and np.all(k > 0)):
        raise CalibrationError("beta1_squared: must be finite and > 0")
    if not (np.all(np.isfinite(w)) and np.all(w > 0)):
        raise CalibrationError("omega1: measured frequencies must be finite and > 0")
    # Each point alone gives T = k / omega_1; one outside the span of any link (1e240 rad/s,
    # 5e-324 rad/s) is no vibration of a link, and its arithmetic would overflow. The fit lies
    # between the points' own T, so within the span too.
    span = PARAMETER_RANGES["link.calibrated_t"]
    with np.errstate(over="ignore", divide="ignore"):
        own_t = k / w
    outside = np.flatnonzero(~((own_t >= span.low) & (own_t <= span.high)))
    if outside.size:
        i = int(outside[0])
        raise CalibrationError(
            f"omega1: {float(w[i]):.4g} rad/s gives T = beta_1^2 / omega_1 = "
            f"{float(own_t[i]):.4g} s/m^2, outside {span.low:g} to {span.high:g} s/m^2 "
            f"({span.reason}): not a link's fundamental frequency"
        )
    # Section 5.1, linear in u = 1 / T: least-squares normal equation u = sum(k w) / sum(k^2)
    u = float(np.dot(k, w) / np.dot(k, k))
    if loss != "linear" and k.size >= 3:
        r0 = k * u - w
        scale = max(
            _MAD_TO_SIGMA * float(np.median(np.abs(r0 - np.median(r0)))),
            _RELATIVE_SCALE_FLOOR * float(np.median(w)),
        )
        sol = least_squares(lambda x: k * x[0] - w, x0=[u], loss=loss, f_scale=scale)
        u = float(sol.x[0])
    residuals = k * u - w
    if k.size < 2:
        return 1.0 / u, math.nan
    variance = float(np.dot(residuals, residuals)) / (k.size - 1)
    std_u = math.sqrt(variance / float(np.dot(k, k)))
    # Delta method for T = 1 / u: sigma_T = sigma_u / u^2
    return 1.0 / u, std_u / u**2


def model_beta1_squared(link: Link, contact_points: ArrayLike) -> NDArray[np.float64]:
    """beta_1(x_c)^2 (1 / m^2) of the contact-mode model, so that omega_1 = beta_1^2 / T.

    Computed with :func:`sensing_antenna.beam.natural_frequencies` on a copy of the link whose T
    is 1 s / m^2, where omega_1 in rad/s equals beta_1^2 in 1 / m^2 numerically.

    Returns
    -------
    ndarray, shape of ``contact_points``
    """
    from sensing_antenna.beam import natural_frequencies

    unit_link = replace(link, calibrated_t=1.0)
    x_c = np.asarray(contact_points, dtype=float)
    omega = np.asarray(natural_frequencies(unit_link, x_c, 1), dtype=float)
    return np.asarray(omega[..., 0], dtype=float)


def calibrate_t_e(
    contact_points: ArrayLike,
    omega1: ArrayLike,
    link: Link,
    *,
    loss: str = "soft_l1",
    sources: Sequence[str] = (),
    notes: Sequence[str] = (),
    fit_tip_mass: bool = False,
) -> FrequencyCalibration:
    """Fit T_e of Section 5.1 to measured fundamental frequencies at known contact points.

    With ``fit_tip_mass``, the link's tip mass is fitted with it (from
    :data:`MIN_TIP_MASS_POINTS` points on): T_e scales the whole sensing curve, a tip mass
    reshapes it (it weighs on the overhang beyond x_c, so it lowers omega_1 most for contacts
    near the root and least at the tip), and the two together absorb the smooth departures of a
    real link from the uniform one (a payload, a taper, a joint, a compliant clamp) that T_e
    alone leaves as a scatter along the link. The fit is ``scipy.optimize.least_squares`` on
    the relative residuals, with ``loss`` at a scale of :data:`TIP_MASS_LOSS_SCALE`, from T_e
    alone and the link's tip mass, the mass kept within [0, the link's own mass].

    Parameters
    ----------
    contact_points : array_like, shape (n,)
        Known contact points x_c (m). A point not on (0, l] (NaN: not known) is left out of the
        fit with a note naming it; one a few ulp past l (:data:`END_ULPS`) is the tip, l.
    omega1 : array_like, shape (n,)
        Measured fundamental frequencies (rad/s); NaN marks a point without a measurement
        (left out of the fit, kept in the result).
    link : Link
        The link whose geometry (l) defines the model; its T is reported as ``t_theoretical``.
    loss : str
        See :func:`fit_inverse_t`.
    sources, notes : sequence of str
        Provenance of each point, and reasons for points left out (kept in the result).
    """
    x_c = np.asarray(contact_points, dtype=float).ravel()
    w = np.asarray(omega1, dtype=float).ravel()
    if x_c.shape != w.shape:
        raise CalibrationError(f"omega1: {w.size} frequencies for {x_c.size} contact points")
    x_c, on_link, left_out = points_on_link(x_c, link.length, sources)
    given = np.isfinite(x_c)
    hints = {_unit_hint(float(v), link.length) for v in x_c[given]}
    if given.sum() >= 2 and not on_link.any() and len(hints) == 1 and "" not in hints:
        # every known point off the link in one way: a unit, said first
        unit = hints.pop().strip(" ()")
        raise CalibrationError(
            f"x_c: none of the {int(given.sum())} known contact points lies on the link (0, "
            f"{link.length:g}] m, {unit} (they are in m): {left_out[0]}"
        )
    used = on_link & np.isfinite(w) & (w > 0)
    if int(used.sum()) < 2:
        reasons = [*left_out, *notes]
        why = ""
        if reasons:
            more = f"; and {len(reasons) - 1} more recording(s)" if len(reasons) > 1 else ""
            why = f" (left out: {reasons[0]}{more})"
        raise CalibrationError(
            f"omega1: need at least 2 measured frequencies to fit T_e, got {int(used.sum())}{why}"
        )
    k = np.full(x_c.shape, math.nan)
    k[on_link] = model_beta1_squared(link, x_c[on_link])
    t_e, std_error = fit_inverse_t(k[used], w[used], loss=loss)
    tip_mass = None
    joint = _with_tip_mass(link, x_c, on_link, w, used, k, t_e, loss) if fit_tip_mass else None
    if joint is not None:
        t_e, std_error, tip_mass, k, kept = joint
        wrong = used & ~kept
    else:
        # a wrong peak or a wrong known point: the robust loss only tempers its pull
        wrong = _wrong_peaks(w / (k / t_e) - 1.0, used)
        if np.any(wrong):
            t_e, std_error = fit_inverse_t(k[used & ~wrong], w[used & ~wrong], loss=loss)
    for i in map(int, np.flatnonzero(wrong)):
        label = sources[i] if i < len(sources) else f"point {i}"
        off = float(w[i] / (k[i] / t_e) - 1.0)
        left_out.append(
            f"{label}: omega_1 = {float(w[i]):.2f} rad/s lies {100 * off:+.1f} % from the "
            "others' fit, a wrong spectral peak or a wrong known point (left out of the fit)"
        )
    used = used & ~wrong
    calibration = FrequencyCalibration(
        t_e=t_e,
        t_e_std_error=std_error,
        t_theoretical=link.theoretical_t,
        contact_points=x_c,
        omega1_measured=w,
        # Section 5.1 model: omega_1 = (beta_1 l)^2 / (T_e l^2) = beta_1^2 / T_e
        omega1_fitted=k / t_e,
        used=used,
        loss=loss,
        sources=tuple(sources),
        notes=(*left_out, *notes),
        tip_mass=tip_mass,
        left_out_as_wrong=wrong,
    )
    scatter = calibration.relative_scatter
    if math.isfinite(scatter) and scatter >= NO_FIT_SCATTER:
        raise CalibrationError(
            f"no calibration: {scatter_problem(scatter, int(used.sum()))}", field="contact_points"
        )
    return calibration


#: The rms relative scatter (:attr:`FrequencyCalibration.relative_scatter`) from which a fit
#: says nothing of the link (the antenna's bound on ``link.calibration_scatter``).
NO_FIT_SCATTER = 1.0


def scatter_problem(scatter: float, points: int) -> str:
    """What a calibration whose frequencies scatter ``scatter`` (rms relative) about the fit
    over ``points`` points says of its inputs."""
    return (
        f"the measured omega_1 lie {100 * scatter:.0f} % rms about the best fit over {points} "
        f"points (a calibration's scatter is a fraction of a per cent, and one point "
        f"{100 * WRONG_PEAK:g} % off the others is a wrong peak or point): known points in the "
        "wrong rows or files, recordings of another link, or a link far from its model (a "
        "payload: fit the tip mass)?"
    )


#: Fewest points used whose median residual can single out a wrong peak.
MIN_WRONG_PEAK_POINTS = 5


def _wrong_peaks(relative: NDArray[np.float64], usable: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Which points of ``usable`` lie more than :data:`WRONG_PEAK` from the median of the
    ``relative`` residuals, when they are few (one, or a tenth of the points, of
    :data:`MIN_WRONG_PEAK_POINTS` or more): wrong peaks or wrong known points. More are the
    model's error (a payload bends the whole curve), and none is returned."""
    none = np.zeros(relative.shape, dtype=bool)
    if int(usable.sum()) < MIN_WRONG_PEAK_POINTS:
        return none  # a median of fewer cannot tell a wrong peak from the model's error
    median = float(np.median(relative[usable]))
    with np.errstate(invalid="ignore"):
        beyond = np.asarray(usable & (np.abs(relative - median) > WRONG_PEAK), dtype=bool)
    return beyond if int(beyond.sum()) <= max(1, int(usable.sum()) // 10) else none


#: A point whose omega_1 lies farther than this (relative) from the median of T_e alone's fit is
#: left out of the tip mass's fit before it starts: a peak of another mode, a harmonic or the
#: free motion's, not a shape a tip mass makes (0.2 g at the tip moves the points by 13 % at
#: most, 0.55 m against the tip, of which T_e takes up the mean).
GROSS_WRONG_PEAK = 0.25


def _near_median(
    relative: NDArray[np.float64], among: NDArray[np.bool_], limit: float
) -> NDArray[np.bool_]:
    """Points whose relative residual lies within ``limit`` of the median over ``among``."""
    finite = np.isfinite(relative)
    if not np.any(among & finite):
        return np.zeros(relative.shape, dtype=bool)
    median = float(np.median(relative[among & finite]))
    return np.asarray(finite & (np.abs(relative - median) <= limit), dtype=bool)


#: Points a fit of the tip mass with T_e needs (two parameters, and two degrees of freedom
#: left for the scatter).
MIN_TIP_MASS_POINTS = 4

#: Scale of the robust loss of that fit, on relative residuals: 1 %, beyond which a point counts
#: linearly (model departures left by the two parameters are tenths of a per cent, a wrong
#: spectral peak tens of per cent).
TIP_MASS_LOSS_SCALE = 0.01


def _with_tip_mass(
    link: Link,
    x_c: NDArray[np.float64],
    on_link: NDArray[np.bool_],
    omega: NDArray[np.float64],
    used: NDArray[np.bool_],
    k_alone: NDArray[np.float64],
    t_e: float,
    loss: str,
) -> tuple[float, float, float, NDArray[np.float64], NDArray[np.bool_]] | None:
    """T_e and the tip mass fitted together from T_e alone (``t_e`` with beta_1^2 ``k_alone``
    of the link's own tip mass at every point), wrong spectral peaks out
    first: gross ones against T_e alone (:data:`GROSS_WRONG_PEAK`), then those more than
    :data:`WRONG_PEAK` from the median of the two-parameter fit (as ``relative_scatter`` leaves
    them out of the scatter). Returns (T_e, its standard error, the mass, beta_1^2 of every
    point with it, the points fitted), or None with fewer than :data:`MIN_TIP_MASS_POINTS`."""

    def beta1_squared(mass: float) -> NDArray[np.float64]:
        k = np.full(x_c.shape, math.nan)
        k[on_link] = model_beta1_squared(replace(link, tip_mass=mass), x_c[on_link])
        return k

    kept = used & _near_median(k_alone / t_e / omega - 1.0, used, GROSS_WRONG_PEAK)
    if int(kept.sum()) < MIN_TIP_MASS_POINTS:
        return None
    fitted = _fit_with_tip_mass(link, x_c[kept], omega[kept], t_e, loss)
    k = beta1_squared(fitted[2])
    refined = used & _near_median(k / fitted[0] / omega - 1.0, kept, WRONG_PEAK)
    if int(refined.sum()) < MIN_TIP_MASS_POINTS:
        return None
    if not np.array_equal(refined, kept):
        fitted = _fit_with_tip_mass(link, x_c[refined], omega[refined], fitted[0], loss)
        k = beta1_squared(fitted[2])
    return (*fitted, k, refined)


def _fit_with_tip_mass(
    link: Link, x_c: NDArray[np.float64], omega: NDArray[np.float64], t_e: float, loss: str
) -> tuple[float, float, float]:
    """(T_e in s/m^2, its standard error, tip mass in kg) fitted to omega_1 at ``x_c``."""

    def residuals(params: NDArray[np.float64]) -> NDArray[np.float64]:
        inverse_t, mass = params
        k = model_beta1_squared(replace(link, tip_mass=float(mass)), x_c)
        return np.asarray(k * inverse_t / omega - 1.0, dtype=float)

    start = np.array([1.0 / t_e, min(max(link.tip_mass, 0.0), link.mass)])
    fit = least_squares(
        residuals,
        start,
        bounds=([0.0, 0.0], [np.inf, link.mass]),
        x_scale=[start[0], 0.01 * link.mass],
        loss=loss,
        f_scale=TIP_MASS_LOSS_SCALE,
    )
    inverse_t, mass = (float(v) for v in fit.x)
    dof = x_c.size - 2
    std_error = math.nan
    if dof > 0:
        variance = float(np.sum(fit.fun**2)) / dof
        try:
            covariance = np.linalg.inv(fit.jac.T @ fit.jac) * variance
            std_error = math.sqrt(max(float(covariance[0, 0]), 0.0)) / inverse_t**2
        except np.linalg.LinAlgError:
            pass
    return 1.0 / inverse_t, std_error, mass


#: Contact points this many ulp of l past the link's end are at the end: a point written as
#: ``0.9800000000000002`` (the sum of an abscissa and a rounding) is the tip of a 0.98 m link.
END_ULPS = 4


def points_on_link(
    x_c: NDArray[np.float64], length: float, sources: Sequence[str]
) -> tuple[NDArray[np.float64], NDArray[np.bool_], list[str]]:
    """Points (m) with those a few ulp past the end set to l, which lie on (0, l], and a note
    naming each one that does not."""
    at_end = (x_c > length) & (x_c <= length + END_ULPS * math.ulp(length))
    x_c = np.where(at_end, length, x_c)
    on_link = np.isfinite(x_c) & (x_c > 0.0) & (x_c <= length)
    notes = []
    for i in map(int, np.flatnonzero(~on_link)):
        label = sources[i] if i < len(sources) else f"point {i}"
        where = (
            "no known contact point (no row in the --points table or, without one, no "
            "true_xc metadata; or one that is not a number)"
            if math.isnan(x_c[i])
            else f"x_c = {float(x_c[i])!r} m is not on the link (0, {length:g}] m"
            + _unit_hint(float(x_c[i]), length)
        )
        notes.append(f"{label}: {where}")
    return x_c, np.asarray(on_link, dtype=bool), notes


def _unit_hint(x_c: float, length: float) -> str:
    """The hint " (in cm?)" or " (in mm?)" when ``x_c`` (m) read in that unit lies where
    contacts are estimated on the link (``EstimatorConfig.contact_range``), else ""."""
    from sensing_antenna.estimation.config import EstimatorConfig

    low, high = EstimatorConfig().contact_range
    return metres_hint(x_c, low * length, high * length)


def calibrate_from_recordings(
    recordings: Sequence[Any],
    antenna: Antenna,
    contact_points: Sequence[float],
    *,
    sources: Sequence[str] = (),
    band: tuple[float, float] | None = None,
    loss: str = "soft_l1",
    fit_tip_mass: bool = False,
) -> FrequencyCalibration:
    """Measure omega_1 in each recording and fit T_e (Section 5.1), and the tip mass with
    ``fit_tip_mass`` (:func:`calibrate_t_e`).

    Parameters
    ----------
    recordings : sequence of Recording
        Contact manoeuvres at known contact points.
    antenna : Antenna
        The antenna the recordings were made with (its link's T is the starting value).
    contact_points : sequence of float
        Known x_c (m) of each recording, same order.
    band : (float, float) or None
        Search band for the fundamental frequency (rad/s); None: :func:`calibration_band` of
        the antenna's link, wide so that the measured frequencies hardly presuppose the model
        being fitted.

    A recording that cannot be used is left out with a note naming it and why (the estimators'
    checks of their input, :func:`~.usable.contact_evidence`: not in the format's units,
    samples missing in the hold, loads on another scale than the vibration, a record too short;
    no clear fundamental; no known contact point), and the fit goes on with the others.

    Raises
    ------
    CalibrationError
        When fewer than two recordings are left to fit.
    """
    from sensing_antenna.calibration.usable import contact_evidence
    from sensing_antenna.estimation import omega1_of

    if len(recordings) != len(contact_points):
        raise CalibrationError(
            f"contact points: {len(contact_points)} given for {len(recordings)} recordings"
        )
    names = list(sources) or [f"recording {i}" for i in range(len(recordings))]
    if band is None:
        band = calibration_band(antenna.link)
    omega = np.full(len(recordings), math.nan)
    components = ["none"] * len(recordings)
    evidences: list[Any] = [None] * len(recordings)
    notes: list[str] = []
    _, on_link, _ = points_on_link(
        np.asarray(contact_points, dtype=float), antenna.link.length, names
    )
    for i, recording in enumerate(recordings):
        if not on_link[i]:
            continue  # left out for its point, one note (calibrate_t_e's)
        gathered = contact_evidence(recording, antenna)
        if isinstance(gathered, str):
            notes.append(f"{names[i]}: {gathered}")
            continue
        measurement = omega1_of(gathered, band)
        value = float(measurement.omega1)
        if not (math.isfinite(value) and value > 0):
            notes.append(f"{names[i]}: no fundamental frequency found ({_describe(measurement)})")
        elif getattr(measurement, "clear", True) is False:
            notes.append(
                f"{names[i]}: spectral peak at {value:.2f} rad/s not clear of the noise "
                f"({_describe(measurement)})"
            )
        else:
            omega[i] = value
            components[i] = measurement.component
            evidences[i] = gathered
    calibration = calibrate_t_e(
        contact_points,
        omega,
        antenna.link,
        loss=loss,
        sources=names,
        notes=notes,
        fit_tip_mass=fit_tip_mass,
    )
    calibration = _with_second_mode(calibration, evidences, antenna, components)
    return _with_held_joint(calibration, evidences)


#: Fewest points with a measured second contact mode for its scatter
#: (:attr:`FrequencyCalibration.mode2_scatter`): with fewer, one rms says little of the link.
MIN_MODE2_POINTS = 5


def _with_second_mode(
    calibration: FrequencyCalibration,
    evidences: Sequence[Any],
    antenna: Antenna,
    components: Sequence[str],
) -> FrequencyCalibration:
    """``calibration`` with omega_2 measured at each point used, near the calibrated model's
    (:func:`~sensing_antenna.estimation.methods.paper.frequency.second_mode_peak`, on the
    evidence and spectrum omega_1 was read from; None: no evidence)."""
    from sensing_antenna.beam import natural_frequencies
    from sensing_antenna.estimation.methods.paper.frequency import second_mode_peak

    link = calibration.apply(antenna).link
    x_c = calibration.contact_points
    fitted = np.full(x_c.shape, math.nan)
    inside = (x_c > 0.0) & (x_c <= link.length)
    if np.any(inside):
        fitted[inside] = np.asarray(natural_frequencies(link, x_c[inside], 2), dtype=float)[:, 1]
    measured = np.full(x_c.shape, math.nan)
    for i in map(int, np.flatnonzero(calibration.used & np.isfinite(fitted))):
        evidence = evidences[i]
        if evidence is None:
            continue
        omega1 = float(calibration.omega1_measured[i])
        peak = second_mode_peak(evidence, components[i], float(fitted[i]), omega1)
        if peak is not None:
            measured[i] = peak.omega
    return replace(calibration, omega2_measured=measured, omega2_fitted=fitted)


def _with_held_joint(
    calibration: FrequencyCalibration, evidences: Sequence[Any]
) -> FrequencyCalibration:
    """``calibration`` with the held joint's compliance measured at each point used, over the
    window its omega_1 was read from (:func:`_held_compliance_of`; NaN and joint -1: no
    evidence)."""
    n = calibration.contact_points.size
    joints = np.full(n, -1, dtype=np.int64)
    compliance = np.full(n, math.nan)
    for i in map(int, np.flatnonzero(calibration.used)):
        if evidences[i] is not None:
            joints[i], compliance[i] = _held_compliance_of(
                evidences[i], float(calibration.omega1_measured[i])
            )
    return replace(calibration, held_joint=joints, held_compliance_measured=compliance)


def held_compliance_from_recordings(
    recordings: Sequence[Any], antenna: Antenna, band: tuple[float, float] | None = None
) -> tuple[float | None, float | None]:
    """Each joint's held compliance (rad/(N m); :attr:`FrequencyCalibration.held_compliance`)
    from contact recordings at any points (their omega_1 read in ``band``, None:
    :func:`calibration_band`): the sweeps a T_e fit does not take (a calibration on one case,
    the sensor's posts swept the other way) measure the other joint's servo. Recordings
    without a clear fundamental are passed over."""
    from sensing_antenna.calibration.usable import contact_evidence
    from sensing_antenna.estimation import omega1_of

    band = band if band is not None else calibration_band(antenna.link)
    joints, values = [], []
    for recording in recordings:
        gathered = contact_evidence(recording, antenna)
        if isinstance(gathered, str):
            continue
        measurement = omega1_of(gathered, band)
        omega1 = float(measurement.omega1)
        if not math.isfinite(omega1) or getattr(measurement, "clear", True) is False:
            continue
        joint, value = _held_compliance_of(gathered, omega1)
        if math.isfinite(value):
            joints.append(joint)
            values.append(value)
    return _largest_per_joint(np.array(joints, dtype=np.int64), np.array(values, dtype=float))


def _held_compliance_of(evidence: Any, omega1: float) -> tuple[int, float]:
    """The swept joint and its angle per link torque at ``omega1`` (rad/s) over the window the
    fundamental was read from (:func:`~sensing_antenna.estimation.held_joint.held_line`);
    (-1, NaN) when it cannot be read."""
    from sensing_antenna.estimation.held_joint import held_line, swept_joint

    window = evidence.spectrum_slice
    joint = swept_joint(evidence.push_turn[0])
    line = held_line(
        evidence.t[window], evidence.theta[window], evidence.torque[window], joint, omega1
    )
    if line is None or not math.isfinite(line.compliance):
        return -1, math.nan
    return joint, line.compliance


def _largest_per_joint(
    joints: NDArray[np.int64], values: NDArray[np.float64]
) -> tuple[float | None, float | None]:
    """The largest of ``values`` on each joint (0, 1); None on a joint with fewer than
    :data:`~sensing_antenna.estimation.held_joint.MIN_POSTS`."""
    from sensing_antenna.estimation.held_joint import MIN_POSTS

    found: list[float | None] = []
    for joint in (0, 1):
        on_joint = values[joints == joint]
        found.append(float(np.max(on_joint)) if on_joint.size >= MIN_POSTS else None)
    return found[0], found[1]


def read_contact_points(
    paths: Sequence[Path], recordings: Sequence[Any], table: Path | None = None
) -> list[float]:
    """Known contact points (m) of calibration recordings, from a table or their metadata.

    With ``table``, a CSV file (UTF-8) with columns ``file`` and ``x_c`` (m); a row matches a
    recording by its path as given or by its file name, and a recording without a row has no
    known point (NaN: the calibration leaves it out with a note). Two rows for one ``file``, or
    a file name two rows match, are refused (naming the lines): which would win is not the
    user's intent.
    Without it, each recording's ground-truth metadata ``true_xc`` is used (NaN where it is
    absent or not a number; the calibration leaves that recording out with a note): calibration
    is the one place where ground truth is an input, since the contact points of a calibration
    are known by construction.

    Raises
    ------
    CalibrationError
        Naming the file, line or recording and what is missing or wrong; a table that names
        none of the recordings.
    """
    if table is not None:
        rows = _read_points_table(table)
        points = [_point_of(table, rows, path) for path in paths]
        if paths and all(math.isnan(x) for x in points):
            raise CalibrationError(
                f"{table}: file: no row names any of the {len(paths)} recording(s) given "
                f"(by path as given or by file name; the first is {paths[0]})"
            )
        return points
    return [_metadata_point(recording.metadata.get("true_xc")) for recording in recordings]


@dataclass(frozen=True)
class _PointRow:
    """One row of a ``--points`` table: its line, the ``file`` text and x_c (m)."""

    line: int
    file: str
    x_c: float


def _read_points_table(table: Path) -> list[_PointRow]:
    """The rows of a ``--points`` table; two rows for one ``file`` are refused."""
    if not table.is_file():
        raise CalibrationError(f"{table}: no such file")
    rows: list[_PointRow] = []
    try:
        with open(table, encoding="utf-8-sig", newline="") as handle:
            reader = csv.DictReader(handle, skipinitialspace=True)
            columns = [name.strip() for name in reader.fieldnames or []]
            reader.fieldnames = columns
            for column in ("file", "x_c"):
                if column not in columns:
                    called = other_separator(columns)
                    separated = (
                        ""
                        if called is None
                        else f" (its header {columns[0]!r} is one column separated by {called};"
                        " columns are separated by commas)"
                    )
                    raise CalibrationError(f"{table}: line 1: missing column {column!r}{separated}")
            for record in reader:
                rows.append(_point_row(table, reader.line_num, record))
    except UnicodeDecodeError as exc:
        raise CalibrationError(
            f"{table}: not UTF-8 text (byte {exc.start}: {exc.reason})"
        ) from None
    except (OSError, csv.Error) as exc:
        raise CalibrationError(f"{table}: cannot be read ({exc})") from None
    first: dict[str, _PointRow] = {}
    for row in rows:
        if row.file in first:
            earlier = first[row.file]
            raise CalibrationError(
                f"{table}: lines {earlier.line} and {row.line}: two rows for file {row.file!r} "
                f"(x_c = {earlier.x_c:g} and {row.x_c:g} m); keep one"
            )
        first[row.file] = row
    return rows


def _point_row(table: Path, line: int, row: dict[str | Any, Any]) -> _PointRow:
    text: Any = row.get("x_c")
    if text is None:
        raise CalibrationError(f"{table}: line {line}: x_c: missing (the row is short of cells)")
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise CalibrationError(f"{table}: line {line}: x_c: not a number: {text!r}") from None
    if not math.isfinite(value):
        raise CalibrationError(f"{table}: line {line}: x_c: not finite")
    name = (row.get("file") or "").strip()
    if not name:
        raise CalibrationError(f"{table}: line {line}: file: empty")
    return _PointRow(line, name, value)


def unmatched_point_rows(table: Path, paths: Sequence[Path]) -> list[str]:
    """One line per row of the ``--points`` ``table`` that matches none of the recordings
    ``paths`` (by path as given or by file name, as :func:`read_contact_points` matches them):
    a typo in a file name leaves that recording without a point, and the row unused. Raises
    as :func:`read_contact_points` on a table it cannot read."""
    return [
        f"{table}: line {row.line}: file {row.file!r} names none of the recordings given"
        for row in _read_points_table(table)
        if not any(row.file == str(path) or Path(row.file).name == path.name for path in paths)
    ]


def _point_of(table: Path, rows: Sequence[_PointRow], path: Path) -> float:
    """x_c of the row for recording ``path``: its path as given, else its file name; a name
    that two rows match is ambiguous and refused."""
    exact = [row for row in rows if row.file == str(path)]
    if exact:
        return exact[0].x_c
    named = [row for row in rows if Path(row.file).name == path.name]
    if not named:
        return math.nan  # no known point: left out with a note, as a recording without metadata
    if len(named) > 1:
        lines = " and ".join(str(row.line) for row in named)
        raise CalibrationError(
            f"{table}: lines {lines}: {len(named)} rows match recording {path} by its file name "
            f"({', '.join(repr(row.file) for row in named)}); give its path as passed"
        )
    return named[0].x_c


def _json_float(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def _float_or_nan(value: Any) -> float:
    return math.nan if value is None else float(value)


def _metadata_point(text: str | None) -> float:
    """``true_xc`` metadata as a contact point (m); NaN when absent or not a number."""
    try:
        return math.nan if text is None else float(text)
    except ValueError:
        return math.nan


def _describe(measurement: Any) -> str:
    reason = getattr(measurement, "reason", None)
    if reason:
        return str(reason)
    return f"peak quality {getattr(measurement, 'quality', math.nan):.3g}"
