"""Antenna parameters as data: the flexible link, the two motors and the free-motion observer.

The built-in set ``paper-2021`` is the antenna of the paper (Table 2 for the link, Table 1 for the
motors, Eq. 15 for the free-motion observer). Any other antenna is a TOML file that either defines
every field or names a ``base`` set and overrides some fields::

    base = "paper-2021"
    name = "short-link"
    [link]
    length = 0.5

All values are SI. Derived quantities (E I, m_b, T) are computed, never stored.

Every physical parameter must lie in a documented range (:data:`PARAMETER_RANGES`, each with its
reason), and the link as a whole must be one the linear beam theory of every model here can
describe: slender (l / r >= :data:`MIN_SLENDERNESS`) and stiff enough not to sag, in that theory,
by more than its own length under its weight (:meth:`Link.static_sag`). Values outside give one
line naming the file and the field, before any model computes with them (a length of 1e300 m
would overflow, one of 1e-300 m divide by zero). The observer's parameters are fitted, not
measured: they must be finite and positive (the damping may be zero), and its frequency below the
Nyquist frequency of the recording it is used on, which the estimators check.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from dataclasses import MISSING, dataclass, field, fields, replace
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.errors import FieldError, format_value
from sensing_antenna.toml_files import parse_toml_file, parse_toml_text

__all__ = [
    "BUILTIN_ANTENNAS",
    "CALIBRATED_T_UNCERTAINTY",
    "MAX_SENSOR_COUPLING",
    "MAX_SENSOR_GAIN_ERROR",
    "MIN_SLENDERNESS",
    "MODEL_FREQUENCY_FLOOR",
    "NOMINAL_T_UNCERTAINTY",
    "PARAMETER_RANGES",
    "RANGE_SHARE",
    "SENSOR_SWEEPS",
    "Antenna",
    "AntennaConfigError",
    "FreeMotionObserver",
    "Link",
    "Motor",
    "ParameterRange",
    "SensorCorrection",
    "SensorRange",
    "antenna_to_toml",
    "load_antenna",
    "metres_hint",
    "paper_antenna",
    "save_antenna",
]

#: Standard gravity (m/s^2), used for the gravity terms of Section 4.2.
STANDARD_GRAVITY = 9.80665


class AntennaConfigError(FieldError):
    """An antenna parameter is missing, unknown or out of range.

    The message always names the field (``link.length``) and, when known, the file.
    """


def _require_positive(owner: str, name: str, value: float) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise AntennaConfigError(
            f"{owner}.{name}", f"must be a finite number > 0, got {format_value(value)}"
        )


def _require_non_negative(owner: str, name: str, value: float) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
        raise AntennaConfigError(
            f"{owner}.{name}", f"must be a finite number >= 0, got {format_value(value)}"
        )


@dataclass(frozen=True)
class ParameterRange:
    """The values a physical parameter may take, and why.

    Parameters
    ----------
    low, high : float
        Smallest and largest value accepted, both included (in ``unit``).
    unit : str
        SI unit of the parameter, for messages.
    reason : str
        Why the range ends where it does.
    """

    low: float
    high: float
    unit: str
    reason: str

    def check(self, field_name: str, value: float) -> None:
        """Raise AntennaConfigError naming ``field_name`` unless low <= value <= high."""
        if not self.low <= value <= self.high:
            unit = f" {self.unit}" if self.unit else ""
            hint = _unit_hint(value, self.low, self.high, _OTHER_UNITS.get(self.unit, ()))
            raise AntennaConfigError(
                field_name,
                f"{format_value(value)}{unit} is outside {self.low:g} to {self.high:g}{unit}"
                f" ({self.reason}){hint}",
            )


def metres_hint(value: float, low: float, high: float) -> str:
    """ " (in mm?)", " (in cm or mm?)": the units in which a length ``value`` read as metres
    would lie in [low, high] m; "" when none does."""
    return _unit_hint(value, low, high, _OTHER_UNITS["m"])


#: Units a number meant in them is most often written in instead of the SI one, each with how
#: many of it make the SI unit: a length in cm or mm, a modulus in GPa or MPa.
_OTHER_UNITS: Mapping[str, tuple[tuple[str, float], ...]] = MappingProxyType(
    {"m": (("cm", 1e2), ("mm", 1e3)), "Pa": (("GPa", 1e-9), ("MPa", 1e-6))}
)


def _unit_hint(value: float, low: float, high: float, units: tuple[tuple[str, float], ...]) -> str:
    """ " (in cm or mm?)" and the like: those of ``units`` (name, how many make the SI unit) in
    which ``value`` would lie in [low, high] SI; "" when none does."""
    fits = [name for name, per_si in units if low <= value / per_si <= high]
    return f" (in {' or '.join(fits)}?)" if fits else ""


#: Accepted range of each physical parameter, by ``section.field`` (``motor`` for both motors).
#: The linear density is bounded through the bulk density it implies over the full circular
#: section, rho / (pi r^2), so that a hollow tube passes; the link as a whole must also be
#: slender and stiff enough (:data:`MIN_SLENDERNESS`, :meth:`Link.static_sag`).
PARAMETER_RANGES: Mapping[str, ParameterRange] = MappingProxyType(
    {
        "link.length": ParameterRange(
            1e-3, 100.0, "m", "from a millimetre whisker to a 100 m pole"
        ),
        "link.radius": ParameterRange(
            1e-6, 1.0, "m", "from a single fibre (carbon filaments are 3 to 4 um) to a 1 m shaft"
        ),
        "link.youngs_modulus": ParameterRange(
            1e5, 2e12, "Pa", "from soft rubber to beyond diamond, the stiffest solid (1.1e12 Pa)"
        ),
        "link.bulk_density": ParameterRange(
            1.0,
            25e3,
            "kg/m^3",
            "rho / (pi r^2): lighter than air even as a hollow tube, or denser than osmium,"
            " the densest element (22,590 kg/m^3)",
        ),
        "link.tip_mass": ParameterRange(
            0.0, 100.0, "kg", "more than any sensing head carries on a cantilever"
        ),
        "link.second_moment": ParameterRange(
            1e-30,
            math.pi / 4.0,
            "m^4",
            "from far below a solid 1 um fibre's (7.9e-25 m^4) to a solid section of the"
            " largest radius, 1 m",
        ),
        "link.calibrated_t": ParameterRange(
            1e-12,
            1e5,
            "s/m^2",
            "the span of T = sqrt(rho / (E I)) over the links the other ranges admit",
        ),
        "link.calibration_scatter": ParameterRange(
            0.0, 1.0, "", "a relative scatter: above 1 (100 %) the calibration says nothing"
        ),
        "link.mode2_scatter": ParameterRange(
            0.0, 1.0, "", "a relative scatter: above 1 (100 %) the calibration says nothing"
        ),
        "motor.torque_constant": ParameterRange(
            1e-6, 10.0, "N m/V", "from a micromotor to a large servomotor, before its gear"
        ),
        "motor.inertia": ParameterRange(
            1e-9, 1e3, "kg m^2", "at the joint, from a miniature head to a large robot joint"
        ),
        "motor.viscous_friction": ParameterRange(
            0.0, 1e3, "N m s/rad", "at the joint; the paper's head has 0.03 (Table 1)"
        ),
        "motor.coulomb_voltage": ParameterRange(
            0.0, 1e3, "V", "an input voltage: no servo amplifier of such a head gives more"
        ),
        "motor.gear_ratio": ParameterRange(
            1.0, 1e4, "", "n of a 1:n reduction, from direct drive to several stages"
        ),
        "motor.held_compliance": ParameterRange(
            0.0, 1e3, "rad/(N m)", "a joint a link's torque turns by radians holds nothing"
        ),
    }
)

#: Smallest length-to-radius ratio l / r of a link (10): Euler-Bernoulli theory, which every
#: model here uses (Assumption 3 of the paper), needs a slender beam; below, shear and rotary
#: inertia, which it neglects, are no longer small.
MIN_SLENDERNESS = 10.0


#: Relative standard uncertainty of T (and so of omega_1) for a link known only from its material
#: data: 5 %. T = sqrt(rho / (E I)) with I = pi r^4 / 4: a Young's modulus known to +-5 to 10 %
#: (a pultruded carbon-fibre rod's datasheet tolerance) and a radius to +-1 % (four times that in
#: I) leave about 5 % in T at one standard deviation; the paper's real link was 7 % off its
#: datasheet T (Section 5.1).
NOMINAL_T_UNCERTAINTY = 0.05

#: The same for a calibrated link whose calibration did not measure its scatter (fewer than three
#: points): 1 %, a fifth of the largest residual of the paper's own calibration (Section 5.1).
CALIBRATED_T_UNCERTAINTY = 0.01

#: The least relative uncertainty of omega_1 a calibration may claim: 0.1 %, how far the sensing
#: curve of a pinned contact and a finite-element link with a compliant contact differ (a few
#: calibration points can scatter less than that by chance, or not at all).
MODEL_FREQUENCY_FLOOR = 0.001


@dataclass(frozen=True)
class Link:
    """Uniform flexible link (Table 2 of the paper), Euler-Bernoulli beam.

    Parameters
    ----------
    length : float
        Equivalent length l (m).
    radius : float
        Radius r of the circular cross-section (m).
    youngs_modulus : float
        Young's modulus E (Pa).
    linear_density : float
        Mass per unit length rho (kg/m).
    tip_mass : float
        Payload m_t at the tip (kg); 0 for the paper's antenna.
    second_moment : float or None
        Second moment of area I (m^4); computed as pi r^4 / 4 when None.
    calibrated_t : float or None
        Calibrated T_e (s / m^2) of Section 5.1; replaces the theoretical T where given.
    calibration_scatter : float or None
        Relative error of omega_1(x_c) with that T_e, from the calibration's residuals
        (dimensionless, e.g. 0.001 for 0.1 %); the fast method's model floor on omega_1 is at
        least this. None: not measured.
    mode2_scatter : float or None
        Relative error of the second contact mode omega_2(x_c) with that T_e, from the
        calibration's measured omega_2 (dimensionless; its bias along the link included): the
        fast method lets omega_2 narrow an answer at its cap. Only with ``calibrated_t``.
        None: not measured.
    weight_tip_mass : float or None
        The tip mass the link's weight shows at rest (kg), where it differs from the
        ``tip_mass`` the vibration shows: a calibration that fits the tip mass to the contact
        frequencies (it also takes up a taper or a joint, so it is an effective mass) keeps the
        weight the sensor read here. The weight, its moment and the sag use it; None:
        ``tip_mass``.
    bow_std : float or None
        Standard deviation (m) of the unloaded link's tip offset from its root's line in each
        direction across it: a link not quite straight, bowed by an amount not measured. The
        model's link is straight; a bow d at the tip moves the touched point by about
        d (x_c / l)^2 across the link, which the map's points then carry in their covariance
        (docs/mapping.md). None: straight.
    """

    length: float
    radius: float
    youngs_modulus: float
    linear_density: float
    tip_mass: float = 0.0
    second_moment: float | None = None
    calibrated_t: float | None = None
    calibration_scatter: float | None = None
    mode2_scatter: float | None = None
    weight_tip_mass: float | None = None
    bow_std: float | None = None

    def __post_init__(self) -> None:
        for name in ("length", "radius", "youngs_modulus", "linear_density"):
            _require_positive("link", name, getattr(self, name))
        _require_non_negative("link", "tip_mass", self.tip_mass)
        if self.weight_tip_mass is not None:
            _require_non_negative("link", "weight_tip_mass", self.weight_tip_mass)
            PARAMETER_RANGES["link.tip_mass"].check("link.weight_tip_mass", self.weight_tip_mass)
        if self.second_moment is not None:
            _require_positive("link", "second_moment", self.second_moment)
        if self.calibrated_t is not None:
            _require_positive("link", "calibrated_t", self.calibrated_t)
        for name in ("calibration_scatter", "mode2_scatter", "bow_std"):
            if getattr(self, name) is not None:
                _require_non_negative("link", name, getattr(self, name))
        if self.bow_std is not None and not self.bow_std <= 0.1 * self.length:
            raise AntennaConfigError(
                "link.bow_std",
                f"must be at most a tenth of the link's length ({0.1 * self.length:g} m: a"
                f" small bow, in m), got {format_value(self.bow_std)}",
            )
        for name in ("length", "radius", "youngs_modulus", "tip_mass", "second_moment"):
            value = getattr(self, name)
            if value is not None:
                PARAMETER_RANGES[f"link.{name}"].check(f"link.{name}", value)
        bulk_range = PARAMETER_RANGES["link.bulk_density"]
        if self.length < MIN_SLENDERNESS * self.radius:
            # before the bulk density, which a radius in mm read as m also throws out; the
            # hint names the units in which the radius is slender and the bulk density in range
            hint = metres_hint(
                self.radius,
                math.sqrt(self.linear_density / (math.pi * bulk_range.high)),
                min(
                    self.length / MIN_SLENDERNESS,
                    math.sqrt(self.linear_density / (math.pi * bulk_range.low)),
                ),
            )
            raise AntennaConfigError(
                "link.radius",
                f"{format_value(self.radius)} m is more than 1/{MIN_SLENDERNESS:g} of the"
                f" length {format_value(self.length)} m: Euler-Bernoulli theory, which every"
                f" model here uses, needs a slender link{hint}",
            )
        bulk = self.linear_density / (math.pi * self.radius**2)
        if not bulk_range.low <= bulk <= bulk_range.high:
            raise AntennaConfigError(
                "link.linear_density",
                f"{format_value(self.linear_density)} kg/m over a section of radius"
                f" {format_value(self.radius)} m is a bulk density of {bulk:.4g} kg/m^3, outside"
                f" {bulk_range.low:g} to {bulk_range.high:g} kg/m^3 ({bulk_range.reason})",
            )
        for name in ("calibrated_t", "calibration_scatter", "mode2_scatter"):
            value = getattr(self, name)
            if value is not None:
                PARAMETER_RANGES[f"link.{name}"].check(f"link.{name}", value)
        if self.mode2_scatter is not None and self.calibrated_t is None:
            raise AntennaConfigError(
                "link.mode2_scatter",
                "is the scatter of a calibration's omega_2 about the model with its T_e: it "
                "needs link.calibrated_t (antenna calibrate writes both)",
            )
        sag = self.static_sag
        if not sag <= self.length:
            raise AntennaConfigError(
                "link",
                f"its tip would sag {sag:.3g} m under its own weight in linear beam theory,"
                f" more than its length {format_value(self.length)} m: too long, heavy or soft for"
                " the models here (length, linear_density, tip_mass, youngs_modulus, radius,"
                " second_moment)",
            )

    @property
    def area_moment(self) -> float:
        """Second moment of area I (m^4)."""
        if self.second_moment is not None:
            return self.second_moment
        return math.pi * self.radius**4 / 4.0

    @property
    def static_sag(self) -> float:
        """Tip deflection (m) of the link held horizontal under its weight and the tip mass,
        in linear beam theory: g (rho l^4 / 8 + m_t l^3 / 3) / (E I), from the material data
        (a calibrated T_e does not enter). Paper link: 5.9 cm."""
        rho, m_t, length = self.linear_density, self.weighed_tip_mass, self.length
        load = rho * length**4 / 8.0 + m_t * length**3 / 3.0
        return STANDARD_GRAVITY * load / self.flexural_rigidity

    @property
    def flexural_rigidity(self) -> float:
        """Bending stiffness E I (N m^2)."""
        return self.youngs_modulus * self.area_moment

    @property
    def mass(self) -> float:
        """Link mass m_b = rho l (kg)."""
        return self.linear_density * self.length

    @property
    def weighed_tip_mass(self) -> float:
        """The tip mass the weight shows (kg): ``weight_tip_mass``, else ``tip_mass``."""
        return self.tip_mass if self.weight_tip_mass is None else self.weight_tip_mass

    @functools.cached_property
    def weight(self) -> float:
        """Weight of the link and its tip mass, (m_b + m_t) g (N)."""
        return (self.mass + self.weighed_tip_mass) * STANDARD_GRAVITY

    @functools.cached_property
    def weight_moment(self) -> float:
        """Moment of that weight about the joint, straight link held horizontal,
        (m_b l / 2 + m_t l) g (N m)."""
        return (0.5 * self.mass + self.weighed_tip_mass) * self.length * STANDARD_GRAVITY

    @property
    def bending_compliance(self) -> float:
        """1 / (E I) (1 / (N m^2)) of the gravity sag: rho / T^2 with the frequency model's T
        (:attr:`t_param`), since a calibrated T_e measures the ratio of stiffness to mass the
        sag depends on."""
        return self.t_param**2 / self.linear_density

    def unit_sag(self, x: ArrayLike) -> NDArray[np.float64]:
        """u(x): the free cantilever's deflection under 1 m/s^2 across it (m per m/s^2).

        rho x^2 (6 l^2 - 4 l x + x^2) / (24 E I) from the link, m_t x^2 (3 l - x) / (6 E I) from
        the tip mass; ``x`` in m, 0 <= x <= l, any shape.
        """
        x = np.asarray(x, dtype=float)
        length = self.length
        link = self.linear_density * x**2 * (6 * length**2 - 4 * length * x + x**2) / 24.0
        tip = self.weighed_tip_mass * x**2 * (3 * length - x) / 6.0
        return np.asarray((link + tip) * self.bending_compliance)

    @functools.cached_property
    def sag_moment(self) -> float:
        """kappa (N m): the free link's own sag adds kappa sin(theta2) cos(theta2) to the moment
        of its weight about the elevation axis.

        The weight's part across the link, g cos(theta2) per kg, bends the cantilever by
        g cos(theta2) :meth:`unit_sag`. The part along the link, g sin(theta2) per kg, acts on
        those displaced masses: kappa = g^2 int u dm = g^2 (rho^2 l^5 / 20 + rho m_t l^4 / 4 +
        m_t^2 l^3 / 3) / (E I). Paper link: 1.06e-3 N m (a 5.9 cm tip sag), so 1.1e-4 N m
        between theta2 = -0.10 and +0.03 rad.
        """
        rho, m_t, length = self.linear_density, self.weighed_tip_mass, self.length
        integral = (
            rho**2 * length**5 / 20.0 + rho * m_t * length**4 / 4.0 + m_t**2 * length**3 / 3.0
        ) * self.bending_compliance
        return STANDARD_GRAVITY**2 * integral

    def gravity_moment(self, theta2: ArrayLike) -> NDArray[np.float64]:
        """Moment of the free link's weight about the elevation axis, on Y^m (N m).

        Section 4.2's m_b g l cos(theta2) / 2 with the tip mass and the static sag
        (:attr:`sag_moment`) added; same shape as ``theta2`` (rad).
        """
        cos2 = np.cos(theta2)
        return np.asarray(cos2 * (self.weight_moment + self.sag_moment * np.sin(theta2)))

    def tip_mass_for_moment(self, moment: float, theta2: ArrayLike) -> float:
        """The tip mass (kg) whose weight has the moment ``moment`` (N m) about the elevation
        axis, the straight link held at ``theta2`` (rad; the samples' mean lever):
        moment / (g l cos theta2); nan when that lever is not positive (past the vertical)."""
        lever = float(np.mean(self.length * STANDARD_GRAVITY * np.cos(theta2)))
        return moment / lever if lever > 0.0 else math.nan

    @property
    def tip_mass_ratio(self) -> float:
        """R_m = m_t / m_b of Eq. 4 (dimensionless)."""
        return self.tip_mass / self.mass

    @property
    def theoretical_t(self) -> float:
        """T = sqrt(rho / (E I)) from the material data (s / m^2)."""
        return math.sqrt(self.linear_density / self.flexural_rigidity)

    @property
    def frequency_uncertainty(self) -> float:
        """Relative standard uncertainty of the model's omega_1(x_c) (dimensionless).

        A calibrated link: the scatter its calibration measured (``calibration_scatter``), at
        least :data:`MODEL_FREQUENCY_FLOOR`, or :data:`CALIBRATED_T_UNCERTAINTY` when that was
        not measured. A link known only from its
        material data: :data:`NOMINAL_T_UNCERTAINTY`, the spread of T = sqrt(rho / (E I)) that
        datasheet tolerances leave (omega_1 scales as 1 / T).
        """
        if self.calibrated_t is None:
            return NOMINAL_T_UNCERTAINTY
        if self.calibration_scatter is None:
            return CALIBRATED_T_UNCERTAINTY
        return max(self.calibration_scatter, MODEL_FREQUENCY_FLOOR)

    @property
    def t_param(self) -> float:
        """T used by the frequency model: T_e if calibrated, else the theoretical T (s / m^2).

        The natural frequencies are omega_i = (beta_i l)^2 / (T l^2) rad/s.
        """
        return self.calibrated_t if self.calibrated_t is not None else self.theoretical_t

    def check_contact_point(self, x_c: float) -> None:
        """Raise AntennaConfigError unless 0 < x_c <= l (m)."""
        if not (math.isfinite(x_c) and 0.0 < x_c <= self.length):
            # a unit slip, where it puts the contact at least a tenth of the link out
            hint = metres_hint(x_c, 0.1 * self.length, self.length) if x_c > self.length else ""
            raise AntennaConfigError(
                "x_c",
                f"contact point must lie in (0, {self.length:g}] m, got {format_value(x_c)}{hint}",
            )


@dataclass(frozen=True)
class Motor:
    """DC servomotor with harmonic drive (Table 1 and Eq. 1 of the paper).

    Parameters
    ----------
    torque_constant : float
        K_m, motor torque per input volt before the gear (N m / V).
    inertia : float
        J, rotational inertia seen at the joint (kg m^2).
    viscous_friction : float
        v, viscous friction coefficient at the joint (N m s / rad).
    coulomb_voltage : float
        V^nlc, Coulomb friction expressed as an input voltage (V).
    gear_ratio : float
        n, reduction ratio 1:n.
    held_compliance : float or None
        The held joint's angle per link torque about it at the contacts' fundamental
        (rad/(N m)): the largest the calibration's posts on this joint measured
        (:mod:`sensing_antenna.estimation.held_joint`; written by ``antenna calibrate``). None:
        not measured, and a base moving near omega_1 is not looked for.
    """

    torque_constant: float
    inertia: float
    viscous_friction: float
    coulomb_voltage: float
    gear_ratio: float
    held_compliance: float | None = None

    def __post_init__(self) -> None:
        for name in ("torque_constant", "inertia", "gear_ratio"):
            _require_positive("motor", name, getattr(self, name))
        _require_non_negative("motor", "viscous_friction", self.viscous_friction)
        _require_non_negative("motor", "coulomb_voltage", self.coulomb_voltage)
        if self.held_compliance is not None:
            _require_non_negative("motor", "held_compliance", self.held_compliance)
        for f in fields(self):
            value = getattr(self, f.name)
            if value is not None:
                PARAMETER_RANGES[f"motor.{f.name}"].check(f"motor.{f.name}", value)

    @property
    def coulomb_torque(self) -> float:
        """Coulomb friction torque at the joint, n K_m V^nlc (N m)."""
        return self.gear_ratio * self.torque_constant * self.coulomb_voltage

    def joint_torque(self, voltage: float) -> float:
        """Eq. 1: joint torque n K_m u (N m) for an input voltage u (V)."""
        return self.gear_ratio * self.torque_constant * voltage


@dataclass(frozen=True)
class FreeMotionObserver:
    """Observer of the first free-motion mode, Eq. 15: gain s^2 / (s^2 + damping s + omega^2).

    Maps a motor angle (rad) to the coupling torque it causes in free motion (N m).

    Parameters
    ----------
    gain : float
        Numerator gain K (N m / rad; K / omega^2 is the effective inertia, kg m^2).
    natural_frequency : float
        omega, the free-motion first-mode frequency (rad/s).
    damping : float
        Coefficient of s in the denominator, 2 zeta omega (1/s).
    contact_threshold : float
        Threshold on the filtered residual of Eq. 16 (N m).
    """

    gain: float
    natural_frequency: float
    damping: float
    contact_threshold: float

    def __post_init__(self) -> None:
        _require_positive("observer", "gain", self.gain)
        _require_positive("observer", "natural_frequency", self.natural_frequency)
        _require_non_negative("observer", "damping", self.damping)
        _require_positive("observer", "contact_threshold", self.contact_threshold)

    @property
    def damping_ratio(self) -> float:
        """zeta = damping / (2 omega) (dimensionless)."""
        return self.damping / (2.0 * self.natural_frequency)


#: Largest accepted departure of a sensor correction's gains from 1: beyond it (a factor of 2
#: in the push force) it is no sensor's calibration but a wrong file.
MAX_SENSOR_GAIN_ERROR = 1.0

#: Largest accepted force-per-moment term of a sensor correction (1/m): 100 % of a force
#: channel's full scale per full-scale moment on a sensor whose force range is 100 times its
#: torque range in N and N m (an ATI Nano17's 25 N and 0.25 N m); cross-talk is a few per cent.
MAX_SENSOR_COUPLING = 100.0

#: Standard uncertainty of the lateral force read per unit moment (N per N m = 1/m) of a sensor
#: whose cross-talk no calibration measured: an accuracy of 1 % of full scale per axis (the
#: figure docs/simulator.md's realistic profile draws its coupling from) read as cross-talk of
#: the moments into the lateral forces, spread uniformly over +-1 %: 1 % / sqrt(3) of 25 N per
#: 0.25 N m on an ATI Nano17 SI-25-0.25, the paper's sensor, 0.58 N per N m.
NOMINAL_SENSOR_COUPLING = 0.01 / math.sqrt(3.0) * 25.0 / 0.25

#: The sweep directions a sensor calibration tells apart, and the motor-frame axis each pushes
#: along: an azimuthal sweep along Y^m (1), a vertical one along Z^m (2).
SENSOR_SWEEPS = MappingProxyType({"azimuthal": 1, "vertical": 2})


@dataclass(frozen=True)
class SensorCorrection:
    """Linear correction of the lateral contact forces the F/T sensor reads (its cross-talk).

    An F/T sensor's channels leak into each other; on an antenna the moments are large and the
    lateral forces small (a 1 % of full-scale coupling of a 0.25 N m torque channel into a
    25 N force channel adds 1 N per N m, as much as the push itself), so what matters is the
    lateral forces read from the moments. With R and Gamma the contact's reaction (N) and its
    moment about O (N m) in the motor frame, the corrected lateral forces are

        R_y' = fy_gain R_y + fy_per_ty Gamma_y + fy_per_tz Gamma_z
        R_z' = fz_gain R_z + fz_per_ty Gamma_y + fz_per_tz Gamma_z

    ``antenna calibrate`` fits them to contacts at known points (``calibration.sensor``); the
    default is no correction.

    Parameters
    ----------
    fy_gain, fz_gain : float
        Gains of the lateral force channels relative to the moments' (dimensionless).
    fy_per_ty, fy_per_tz, fz_per_ty, fz_per_tz : float
        Force read per unit moment (N per N m = 1/m).
    ratio_scatter : float
        Relative scatter of the torque/force ratio about the known points with the correction,
        as its calibration measured it (dimensionless): the ratio's model uncertainty is at
        least this fraction of x_c. 0: not measured.
    nominal_coupling : float
        Standard uncertainty of the force read per unit moment (1/m) while no calibration has
        measured the ratio's scatter (:meth:`coupling_uncertainty`): the sensor's accuracy
        read as cross-talk; by default :data:`NOMINAL_SENSOR_COUPLING`, the paper's Nano17.
    unmeasured_sweeps : tuple of str
        Sweep directions (:data:`SENSOR_SWEEPS`) of which the calibration that measured
        ``ratio_scatter`` saw no contact: its terms for pushes that way are not measured, so
        those pushes keep ``nominal_coupling``. Empty: every direction measured (or none, with
        ``ratio_scatter`` 0).
    """

    fy_gain: float = 1.0
    fz_gain: float = 1.0
    fy_per_ty: float = 0.0
    fy_per_tz: float = 0.0
    fz_per_ty: float = 0.0
    fz_per_tz: float = 0.0
    ratio_scatter: float = 0.0
    nominal_coupling: float = NOMINAL_SENSOR_COUPLING
    unmeasured_sweeps: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        sweeps = self.unmeasured_sweeps
        if isinstance(sweeps, str) or not isinstance(sweeps, (list, tuple)):
            raise AntennaConfigError(
                "sensor.unmeasured_sweeps", f"must be a list of sweep directions, got {sweeps!r}"
            )
        for sweep in sweeps:
            if not isinstance(sweep, str) or sweep not in SENSOR_SWEEPS:
                raise AntennaConfigError(
                    "sensor.unmeasured_sweeps",
                    f"{sweep!r} is no sweep direction (one of {', '.join(SENSOR_SWEEPS)})",
                )
        # a list from TOML becomes the tuple the frozen dataclass compares and hashes, in order
        ordered = tuple(s for s in SENSOR_SWEEPS if s in sweeps)
        object.__setattr__(self, "unmeasured_sweeps", ordered)
        for f in fields(self):
            if f.name == "unmeasured_sweeps":
                continue
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise AntennaConfigError(f"sensor.{f.name}", f"must be a number, got {value!r}")
            if not math.isfinite(value):
                raise AntennaConfigError(f"sensor.{f.name}", f"must be finite, got {value!r}")
        for name in ("fy_gain", "fz_gain"):
            if not abs(getattr(self, name) - 1.0) < MAX_SENSOR_GAIN_ERROR:
                raise AntennaConfigError(
                    f"sensor.{name}",
                    f"must lie within {MAX_SENSOR_GAIN_ERROR:g} of 1, got {getattr(self, name)!r}",
                )
        for name in ("fy_per_ty", "fy_per_tz", "fz_per_ty", "fz_per_tz"):
            if not abs(getattr(self, name)) <= MAX_SENSOR_COUPLING:
                raise AntennaConfigError(
                    f"sensor.{name}",
                    f"must lie within +-{MAX_SENSOR_COUPLING:g} 1/m (N per N m), got "
                    f"{getattr(self, name)!r}",
                )
        if not 0.0 <= self.ratio_scatter <= 1.0:
            raise AntennaConfigError(
                "sensor.ratio_scatter", f"must lie in [0, 1], got {self.ratio_scatter!r}"
            )
        if not 0.0 <= self.nominal_coupling <= MAX_SENSOR_COUPLING:
            raise AntennaConfigError(
                "sensor.nominal_coupling",
                f"must lie in [0, {MAX_SENSOR_COUPLING:g}] 1/m (N per N m), got "
                f"{self.nominal_coupling!r}",
            )

    def coupling_uncertainty(self, reaction: ArrayLike) -> float:
        """Standard uncertainty of the cross-talk of the moments into the lateral force of a
        push whose reaction is ``reaction`` (N, motor frame, shape (3,)), left after the
        correction (N per N m = 1/m).

        Each sweep direction's terms are uncertain by ``nominal_coupling`` until a calibration
        has measured the ratio's scatter on contacts of that direction, and 0 after
        (``ratio_scatter`` then bounds what is left). A push with lateral direction (u_y, u_z)
        reads the moments' leak through both directions' terms, so c^2 = u_y^2 c_az^2 +
        u_z^2 c_vert^2 (a push with no lateral force: the larger). A force read c Gamma too
        high, Gamma = x_c R_perp, moves the torque/force ratio from x_c to x_c / (1 + c x_c):
        by about c x_c^2.
        """
        measured = self.ratio_scatter > 0.0
        per_sweep = {
            sweep: 0.0
            if measured and sweep not in self.unmeasured_sweeps
            else self.nominal_coupling
            for sweep in SENSOR_SWEEPS
        }
        lateral = np.asarray(reaction, dtype=float)[[SENSOR_SWEEPS[s] for s in per_sweep]]
        size = math.hypot(*lateral)
        if not size > 0.0 or not math.isfinite(size):
            return max(per_sweep.values())
        return math.hypot(*(u / size * c for u, c in zip(lateral, per_sweep.values(), strict=True)))

    @property
    def is_identity(self) -> bool:
        """True when the correction changes no force (its scatter aside)."""
        gains = (self.fy_gain, self.fz_gain)
        couplings = (self.fy_per_ty, self.fy_per_tz, self.fz_per_ty, self.fz_per_tz)
        return gains == (1.0, 1.0) and couplings == (0.0, 0.0, 0.0, 0.0)

    def correct(
        self, reaction: NDArray[np.float64], moment: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """The corrected reaction (N), shape (..., 3), from ``reaction`` (N) and ``moment``
        (N m) of the same shape (contact loads, motor frame)."""
        if self.is_identity:
            return reaction
        out = np.array(reaction, dtype=float)
        r_y, r_z = reaction[..., 1], reaction[..., 2]
        g_y, g_z = moment[..., 1], moment[..., 2]
        out[..., 1] = self.fy_gain * r_y + self.fy_per_ty * g_y + self.fy_per_tz * g_z
        out[..., 2] = self.fz_gain * r_z + self.fz_per_ty * g_y + self.fz_per_tz * g_z
        return out


@dataclass(frozen=True)
class SensorRange:
    """The F/T sensor's measuring range on each recording column: readings at
    :data:`RANGE_SHARE` of it or beyond may be clipped. For a sensor mounted with its axes
    along the motor axes (up to signs), its datasheet's per-axis ranges.

    Parameters
    ----------
    force : tuple of 3 float
        fx, fy, fz ranges (N), > 0.
    torque : tuple of 3 float
        tx, ty, tz ranges (N m), > 0.
    """

    force: tuple[float, float, float]
    torque: tuple[float, float, float]

    def __post_init__(self) -> None:
        for name, unit in (("force", "N"), ("torque", "N m")):
            values = getattr(self, name)
            if isinstance(values, str) or not isinstance(values, (list, tuple)) or len(values) != 3:
                raise AntennaConfigError(
                    f"sensor_range.{name}", f"must be a list of 3 numbers ({unit}), got {values!r}"
                )
            for value in values:
                if isinstance(value, bool) or not isinstance(value, (int, float)):
                    raise AntennaConfigError(
                        f"sensor_range.{name}", f"must hold numbers, got {value!r}"
                    )
                if not (math.isfinite(value) and value > 0.0):
                    raise AntennaConfigError(
                        f"sensor_range.{name}", f"must be finite and > 0 {unit}, got {value!r}"
                    )
            object.__setattr__(self, name, tuple(float(v) for v in values))

    @property
    def limits(self) -> NDArray[np.float64]:
        """fx, fy, fz, tx, ty, tz ranges (N, N m), shape (6,)."""
        return np.array([*self.force, *self.torque])


#: Share of a channel's range at which its readings may be clipped: a strain-gauge sensor's
#: gauges saturate at about their rated load, and combined loads reach it on one gauge before
#: any axis reads its full range.
RANGE_SHARE = 0.95


@dataclass(frozen=True)
class Antenna:
    """A complete sensing antenna: link, azimuth motor (1), elevation motor (2), observer, and
    the F/T sensor's correction (none by default)."""

    name: str
    link: Link
    azimuth_motor: Motor
    elevation_motor: Motor
    observer: FreeMotionObserver
    description: str = ""
    extra: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)
    sensor: SensorCorrection = field(default_factory=SensorCorrection)
    sensor_range: SensorRange | None = None

    def __post_init__(self) -> None:
        name = self.name
        if not (isinstance(name, str) and name and name == name.strip() and name.isprintable()):
            raise AntennaConfigError(
                "name",
                f"must be one line of printable text without edge spaces, got {format_value(name)}"
                " (it is written into every recording's metadata)",
            )
        if not isinstance(self.description, str):
            raise AntennaConfigError(
                "description", f"must be a string, got {format_value(self.description)}"
            )

    @property
    def motors(self) -> tuple[Motor, Motor]:
        """(azimuth, elevation) motors, indexed like theta1, theta2."""
        return (self.azimuth_motor, self.elevation_motor)

    def gravity_force(self, theta2: ArrayLike) -> NDArray[np.float64]:
        """F_g^m of Section 4.2: weight of link and tip mass in the motor frame (N).

        Shape ``theta2.shape + (3,)`` (theta2 in rad).
        """
        theta2 = np.asarray(theta2, dtype=float)
        weight = self.link.weight
        out = np.zeros((*theta2.shape, 3))
        # Section 4.2: F_g^m = (-m g sin theta2, 0, -m g cos theta2)
        out[..., 0] = -weight * np.sin(theta2)
        out[..., 2] = -weight * np.cos(theta2)
        return out

    def gravity_torque(self, theta2: ArrayLike) -> NDArray[np.float64]:
        """Gamma_g^m of Section 4.2: torque of that weight about O, motor frame (N m).

        Shape ``theta2.shape + (3,)``; the static sag of the free link included
        (:meth:`Link.gravity_moment`).
        """
        theta2 = np.asarray(theta2, dtype=float)
        out = np.zeros((*theta2.shape, 3))
        out[..., 1] = self.link.gravity_moment(theta2)
        return out

    def with_calibrated_t(
        self, t_e: float, scatter: float | None = None, mode2_scatter: float | None = None
    ) -> Antenna:
        """A copy whose frequency model uses the calibrated T_e and its relative scatters (of
        omega_1 and of omega_2).

        A new T_e replaces the whole calibration: without a scatter the copy has none (the old
        one described the old T_e).
        """
        link = replace(
            self.link, calibrated_t=t_e, calibration_scatter=scatter, mode2_scatter=mode2_scatter
        )
        return replace(self, link=link)

    def with_held_compliance(self, azimuth: float | None, elevation: float | None) -> Antenna:
        """A copy whose motors carry these held compliances (rad/(N m); None keeps a motor's
        own, :attr:`Motor.held_compliance`)."""
        antenna = self
        if azimuth is not None:
            motor = replace(antenna.azimuth_motor, held_compliance=azimuth)
            antenna = replace(antenna, azimuth_motor=motor)
        if elevation is not None:
            motor = replace(antenna.elevation_motor, held_compliance=elevation)
            antenna = replace(antenna, elevation_motor=motor)
        return antenna

    def self_calibrated(self, scatter: float = MODEL_FREQUENCY_FLOOR) -> Antenna:
        """This antenna with its own T as a calibrated T_e and a relative ``scatter``: the model a
        calibration of a device identical to it gives, for simulation studies that give the
        estimators the simulated device's own antenna (its T exactly, so a simulated run is
        unchanged). The default scatter is :data:`MODEL_FREQUENCY_FLOOR`, 0.1 %, the order
        calibrations of the simulated device measure (0.01 to 0.12 %). Its sensor is the
        model's own (:meth:`with_sensor_known`)."""
        return self.with_calibrated_t(self.link.t_param, scatter).with_sensor_known()

    def with_sensor_known(self) -> Antenna:
        """This antenna as the model of a simulated device whose sensor is exactly its own: no
        cross-talk beyond its correction is feared (``sensor.nominal_coupling`` 0)."""
        return replace(self, sensor=replace(self.sensor, nominal_coupling=0.0))


_SECTIONS: dict[str, type] = {
    "link": Link,
    "azimuth_motor": Motor,
    "elevation_motor": Motor,
    "observer": FreeMotionObserver,
}
_TOP_LEVEL_KEYS = {"name", "base", "description", "sensor", "sensor_range", *_SECTIONS}

#: Names of the antenna sets shipped with the package.
BUILTIN_ANTENNAS = ("paper-2021", "paper-2021-calibrated")


def _builtin_text(name: str) -> str:
    if name not in BUILTIN_ANTENNAS:
        raise AntennaConfigError(
            "antenna", f"unknown built-in set {name!r}; known: {', '.join(BUILTIN_ANTENNAS)}"
        )
    return resources.files("sensing_antenna").joinpath(f"data/{name}.toml").read_text("utf-8")


def _parse_toml(text: str, source: str) -> dict[str, Any]:
    return parse_toml_text(text, lambda field, problem: AntennaConfigError(field, problem, source))


def _merge(base: dict[str, Any], override: Mapping[str, Any]) -> dict[str, Any]:
    merged = {k: (dict(v) if isinstance(v, dict) else v) for k, v in base.items()}
    for key, value in override.items():
        if isinstance(value, Mapping) and isinstance(merged.get(key), dict):
            merged[key] = {**merged[key], **value}
        else:
            merged[key] = value
    return merged


def _optional_table(
    data: Mapping[str, Any], name: str, cls: type, source: str, required: str = "required"
) -> Any:
    """The optional table ``name`` of ``data`` built as ``cls`` (a dataclass whose checks raise
    :class:`AntennaConfigError`), or None when absent; its unknown keys and missing fields
    (``required`` says what each needs) named with ``source``."""
    values = data.get(name)
    if values is None:
        return None
    if not isinstance(values, Mapping):
        raise AntennaConfigError(name, "must be a table", source)
    for f in fields(cls):
        if f.default is MISSING and f.default_factory is MISSING and f.name not in values:
            raise AntennaConfigError(f"{name}.{f.name}", f"missing ({required})", source)
    allowed = {f.name for f in fields(cls)}
    for key in values:
        if key not in allowed:
            raise AntennaConfigError(f"{name}.{key}", "unknown key", source)
    try:
        return cls(**values)
    except AntennaConfigError as exc:
        raise AntennaConfigError(exc.field_name, exc.problem, source) from exc


def _build(data: Mapping[str, Any], source: str) -> Antenna:
    unknown = set(data) - _TOP_LEVEL_KEYS
    if unknown:
        raise AntennaConfigError(sorted(unknown)[0], "unknown key", source)
    parts: dict[str, Any] = {}
    for section, cls in _SECTIONS.items():
        values = data.get(section)
        if not isinstance(values, Mapping):
            raise AntennaConfigError(section, "missing section", source)
        allowed = {f.name for f in fields(cls)}
        required = [
            f.name
            for f in fields(cls)
            if f.default is MISSING and f.default_factory is MISSING and f.init
        ]
        missing = [name for name in required if name not in values]
        if missing:
            raise AntennaConfigError(
                f"{section}.{missing[0]}", "missing (a number is required here)", source
            )
        for key, value in values.items():
            if key not in allowed:
                raise AntennaConfigError(f"{section}.{key}", "unknown key", source)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise AntennaConfigError(
                    f"{section}.{key}", f"must be a number, got {value!r}", source
                )
        try:
            parts[section] = cls(**{k: float(v) for k, v in values.items()})
        except AntennaConfigError as exc:
            # "motor.inertia" is "azimuth_motor.inertia" here; "link" (the whole) stays itself
            _, dot, name = exc.field_name.partition(".")
            field_name = f"{section}.{name}" if dot else section
            raise AntennaConfigError(field_name, exc.problem, source) from exc
    parts["sensor"] = _optional_table(data, "sensor", SensorCorrection, source)
    parts["sensor_range"] = _optional_table(
        data, "sensor_range", SensorRange, source, "a list of 3 numbers is required"
    )
    name = data.get("name", "unnamed")
    if not isinstance(name, str) or not name:
        raise AntennaConfigError("name", "must be a non-empty string", source)
    try:
        return Antenna(
            name=name,
            description=str(data.get("description", "")),
            link=parts["link"],
            azimuth_motor=parts["azimuth_motor"],
            elevation_motor=parts["elevation_motor"],
            observer=parts["observer"],
            sensor=parts["sensor"] or SensorCorrection(),
            sensor_range=parts["sensor_range"],
        )
    except AntennaConfigError as exc:
        raise AntennaConfigError(exc.field_name, exc.problem, source) from exc


def load_antenna(spec: str | Path | None = None) -> Antenna:
    """Load an antenna by built-in name or from a TOML file (None: ``paper-2021``).

    Raises
    ------
    AntennaConfigError
        Naming the file and the field for any missing, unknown or invalid value.
    """
    if spec is None:
        spec = "paper-2021"
    if isinstance(spec, str) and spec in BUILTIN_ANTENNAS:
        return _build(_parse_toml(_builtin_text(spec), spec), spec)
    path = Path(spec)
    source = str(path)
    if not path.is_file():
        raise AntennaConfigError(
            "antenna",
            f"no such file, and not a built-in set ({', '.join(BUILTIN_ANTENNAS)})",
            source,
        )
    data = parse_toml_file(path, lambda field, problem: AntennaConfigError(field, problem, source))
    base_name = data.get("base")
    if base_name is not None:
        if not isinstance(base_name, str) or base_name not in BUILTIN_ANTENNAS:
            raise AntennaConfigError(
                "base", f"must name a built-in set ({', '.join(BUILTIN_ANTENNAS)})", source
            )
        base = _parse_toml(_builtin_text(base_name), base_name)
        # A variant without its own name is named after its file, never after its base.
        base["name"] = path.stem
        base.pop("description", None)
        data = _merge(base, {k: v for k, v in data.items() if k != "base"})
    return _build(data, source)


def paper_antenna() -> Antenna:
    """The paper's antenna (Tables 1 and 2, Eq. 15) with the theoretical T."""
    return load_antenna("paper-2021")


def antenna_to_toml(antenna: Antenna) -> str:
    """Serialise an antenna to TOML text that :func:`load_antenna` reads back unchanged."""
    lines = [f"name = {_toml_str(antenna.name)}"]
    if antenna.description:
        lines.append(f"description = {_toml_str(antenna.description)}")
    for section in _SECTIONS:
        lines.append("")
        lines.append(f"[{section}]")
        obj = getattr(antenna, section)
        for f in fields(obj):
            value = getattr(obj, f.name)
            if value is not None:
                lines.append(f"{f.name} = {float(value)!r}")
    if antenna.sensor != SensorCorrection():
        lines += ["", "[sensor]"]
        # the sensor's stated cross-talk only where it is not the default's
        default = antenna.sensor.nominal_coupling == NOMINAL_SENSOR_COUPLING
        skipped = {"unmeasured_sweeps", *(("nominal_coupling",) if default else ())}
        lines += [
            f"{f.name} = {float(getattr(antenna.sensor, f.name))!r}"
            for f in fields(SensorCorrection)
            if f.name not in skipped
        ]
        if antenna.sensor.unmeasured_sweeps:
            sweeps = ", ".join(_toml_str(s) for s in antenna.sensor.unmeasured_sweeps)
            lines.append(f"unmeasured_sweeps = [{sweeps}]")
    if antenna.sensor_range is not None:
        lines += ["", "[sensor_range]"]
        for name in ("force", "torque"):
            values = ", ".join(repr(v) for v in getattr(antenna.sensor_range, name))
            lines.append(f"{name} = [{values}]")
    return "\n".join(lines) + "\n"


def save_antenna(antenna: Antenna, path: str | Path) -> None:
    """Write an antenna as a TOML file that every command accepts with ``--antenna``."""
    Path(path).write_text(antenna_to_toml(antenna), encoding="utf-8")


#: TOML basic-string escapes (TOML 1.0, "String"); other control characters become \uXXXX.
_TOML_ESCAPES = {
    "\\": "\\\\",
    '"': '\\"',
    "\b": "\\b",
    "\t": "\\t",
    "\n": "\\n",
    "\f": "\\f",
    "\r": "\\r",
}


def _toml_str(text: str) -> str:
    """``text`` as a TOML basic string that any TOML reader gives back unchanged."""
    out = []
    for char in text:
        if char in _TOML_ESCAPES:
            out.append(_TOML_ESCAPES[char])
        elif ord(char) < 0x20 or ord(char) == 0x7F:
            out.append(f"\\u{ord(char):04X}")
        else:
            out.append(char)
    return '"' + "".join(out) + '"'
