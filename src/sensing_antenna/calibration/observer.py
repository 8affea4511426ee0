"""Identification of the free-motion observer of Eq. 15 and of the contact threshold (Section 5.2).

From a recording of free motion (nothing touching the link) the gain K, natural frequency omega and
damping d of Gamma_e,i = K s^2 / (s^2 + d s + omega^2) theta_i are fitted by least squares between
the measured coupling torques, with the link weight removed, and the output of the discrete
observer used online (``detection/filters.py``), so that the fitted model is exactly the model
the detector runs. The measured torque of joint 1 is the Z^m component and that of joint 2 the
Y^m component, with the signs of ``detection/contact.py`` (torque by the link on the head:
Z^m = -Gamma_e,1, Y^m = +Gamma_e,2). Only the joints that moved are used.

Start: a physics-based guess (K / omega^2 = rigid-link inertia m_b l^2 / 3 + m_t l^2 about O;
omega = 1.8751^2 / (T l^2), the first clamped-free mode), refined by a grid search over omega and
the damping ratio with K solved linearly at each point (the model is linear in K), then
``scipy.optimize.least_squares`` over (K, omega, d).

Units (the recording's own check, ``units_check``): before the fit, the angles' limits and the
loads at rest at the start against the link's weight (a wrench in mN and N mm, or scaled by
1e-300, reads no weight); after it, the fitted effective inertia K / omega^2 against the rigid
link's (angles in degrees give 1/57 of it).

Payload: the head rests before it moves, and the moment about Y^m at rest is the link's weight
m_b g (l / 2) cos(theta_2) plus m_t g l cos(theta_2) for whatever the link carries at its tip
(glue, a marker) that the antenna file does not. Its excess over the model's weight, when more
than three standard deviations of the rest's mean and the tare's offset, is read as such a tip
mass (a payload; the
estimators' plausibility check reads the same moment, docs/estimation.md): the identified
antenna carries it in ``link.tip_mass``, so the frequency model and the calibration of T_e know
the weight that lowers omega_1. The observer is fitted, and its threshold read, with that payload's
weight removed, as the detector of the identified antenna removes it.

Threshold (Section 5.2): the maximum of the filtered residual norm of Eq. 16 over the free-motion
recordings, computed with the fitted observer and the detector's residual filter, times a safety
margin of 1.5 ("the maximum residual obtained during free movements plus a security margin of
50 %"). The free movements should be those the head makes when it sweeps, both joints: a
threshold read from azimuthal motion alone does not cover what a vertical sweep's residual
holds (the weight's moment changing with theta_2, joint 2's own dynamics).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from sensing_antenna.antenna import STANDARD_GRAVITY, Antenna, FreeMotionObserver
from sensing_antenna.detection.contact import (
    DEFAULT_RESIDUAL_CUTOFF,
    OBSERVER_TORQUE_SIGNS,
    detect_contact,
)
from sensing_antenna.detection.filters import observe_free_motion
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.recording import Recording, resample_uniform
from sensing_antenna.torque_point import MOVED_KEY, metadata_line, torque_point_problem
from sensing_antenna.units_check import (
    angle_problem,
    initial_rest,
    is_payload,
    recording_problem,
    rest_moment_std,
    rest_reading,
    stamps_unit,
)

__all__ = [
    "CLAMPED_FREE_BETA_L",
    "DEFAULT_MARGIN",
    "LAG_GAIN",
    "LAG_SEARCH",
    "LAG_STRIDE",
    "LEVER_GAIN",
    "MAX_INERTIA_FACTOR",
    "SENSOR_OFFSET_NOTICED",
    "SENSOR_OFFSET_SHARE",
    "IdentificationError",
    "ObserverFit",
    "Payload",
    "identify_free_motion",
    "initial_guess",
    "rest_payload",
    "units_problem",
]

#: beta_1 l of the first clamped-free bending mode (root of 1 + cos x cosh x = 0).
CLAMPED_FREE_BETA_L = 1.8751040687119611

#: Safety margin on the free-motion residual (Section 5.2: "plus a security margin of 50 %").
DEFAULT_MARGIN = 1.5

#: A joint counts as moved when its angle spans more than this (rad).
MIN_MOTION = 1e-3

#: Damping ratios of the initial grid search (dimensionless).
_ZETA_GRID = (0.002, 0.01, 0.03, 0.1, 0.3)


class IdentificationError(SensingAntennaError, ValueError):
    """The recording cannot identify the observer (e.g. no joint moved)."""


@dataclass(frozen=True)
class Payload:
    """Weight at the tip that the model does not carry, read from the moment at rest.

    Parameters
    ----------
    mass : float
        The tip mass the moment's excess over the model's weight gives (kg); negative when the
        link reads lighter than its model.
    std : float
        Its standard deviation (kg): the rest's mean and the tare's offset, both from the
        torque's scatter over the rest (:func:`~sensing_antenna.units_check.rest_moment_std`);
        NaN without a rest.
    samples : int
        Samples at rest at the start (0: the recording starts moving, nothing is read).
    """

    mass: float
    std: float
    samples: int

    @property
    def significant(self) -> bool:
        """True when the mass lies far enough from zero, in its standard deviations, to be a
        payload (:func:`~sensing_antenna.units_check.is_payload`)."""
        return self.samples > 1 and is_payload(self.mass, self.std)

    def apply(self, antenna: Antenna) -> Antenna:
        """``antenna`` with the payload in ``link.tip_mass`` when significant (never below 0);
        in ``link.weight_tip_mass`` alone when the link has one (its ``tip_mass`` is what a
        calibration fitted to the frequencies)."""
        if not self.significant:
            return antenna
        link = antenna.link
        tip = max(0.0, link.weighed_tip_mass + self.mass)
        if link.weight_tip_mass is not None:
            return replace(antenna, link=replace(link, weight_tip_mass=tip))
        return replace(antenna, link=replace(link, tip_mass=tip))


@dataclass(frozen=True)
class ObserverFit:
    """Fitted free-motion observer (Eq. 15) and contact threshold (Section 5.2).

    Parameters
    ----------
    gain : float
        K (N m / rad).
    natural_frequency : float
        omega (rad/s).
    damping : float
        d, coefficient of s (1/s).
    contact_threshold : float
        ``margin`` times ``max_filtered_residual`` (N m).
    max_filtered_residual : float
        Largest filtered residual norm of Eq. 16 over the recordings with the fitted observer
        (N m).
    residual_rms : float
        RMS of measured minus fitted dynamic torque over the joints used (N m).
    joints : tuple of int
        Joints used (1 azimuth, 2 elevation).
    margin : float
        Safety factor on the threshold.
    residual_cutoff : float
        Residual filter cut-off used for the threshold (rad/s).
    initial_gain, initial_natural_frequency, initial_damping : float
        The physics-based starting point (same units).
    source : str or None
        The recordings' files, comma-separated.
    payload : Payload or None
        Weight at the tip beyond the model's, read at rest (None: not read).
    torque_point : (float, float, float) or None
        The point (S - O on the motor axes, m) the torques read as taken about, when Eq. 15
        with it explains the free motion much better (:data:`LEVER_GAIN`) though Eq. 15 alone
        passed: the recordings' ``torque_point`` should say so, and the fit be made again.
    angle_lag : float or None
        How late (s) the angles read against the torques, when Eq. 15 with them moved that much
        earlier leaves a largest free-motion residual :data:`LAG_GAIN` times smaller (clocks
        that do not agree; the threshold here holds the lag's residual); None when it does not.
    """

    gain: float
    natural_frequency: float
    damping: float
    contact_threshold: float
    max_filtered_residual: float
    residual_rms: float
    joints: tuple[int, ...]
    margin: float
    residual_cutoff: float
    initial_gain: float
    initial_natural_frequency: float
    initial_damping: float
    source: str | None = None
    payload: Payload | None = None
    torque_point: tuple[float, float, float] | None = None
    angle_lag: float | None = None

    @property
    def observer(self) -> FreeMotionObserver:
        """The fitted values as a :class:`FreeMotionObserver`."""
        return FreeMotionObserver(
            gain=self.gain,
            natural_frequency=self.natural_frequency,
            damping=self.damping,
            contact_threshold=self.contact_threshold,
        )

    @property
    def damping_ratio(self) -> float:
        """zeta = d / (2 omega) (dimensionless)."""
        return self.damping / (2.0 * self.natural_frequency)

    def apply(self, antenna: Antenna) -> Antenna:
        """``antenna`` with this observer and threshold, and the payload the rests read when
        it is significant (:meth:`Payload.apply`)."""
        identified = replace(antenna, observer=self.observer)
        return self.payload.apply(identified) if self.payload is not None else identified


#: Largest factor between the fitted effective inertia K / omega^2 and the rigid link's
#: m_b l^2 / 3 + m_t l^2 (Eq. 15 tends to K / omega^2 theta'' at low frequency, the rigid link's
#: inertial torque). A simulated free sweep of the paper's link fits 0.99 of it; angles in
#: degrees give 1/57, a wrench in mN and N mm 1000. 5 sits well between and leaves room for a
#: head whose link is not quite the antenna file's.
MAX_INERTIA_FACTOR = 5.0

#: Farthest from the clamp, as a share of the link's length, that a sensor's origin is named
#: as the point the torques are about (a Nano17's mount: 2.5 cm of the paper's 0.98 m link);
#: beyond, Eq. 15 with a lever is a contact's moment, the touched point's lever on its force.
SENSOR_OFFSET_SHARE = 0.1

#: Nearest to the clamp (m) that a torque point is suspected in a fit that passes, and the
#: share of Eq. 15's residual that Eq. 15 with the point must leave: on simulated free sweeps
#: of the paper's link, torques about O left 0.8 to 1.4 of it with the point within 1 cm, and
#: torques 2.5 cm behind the clamp, which pass, 0.13 to 0.35.
SENSOR_OFFSET_NOTICED = 0.01
LEVER_GAIN = 0.5

#: Farthest (s) either way the angles are tried against the torques for a lag between their
#: clocks, and how many times smaller the largest free-motion residual must be with the best
#: shift for the lag to be named: on simulated free sweeps of the paper's link, angles 3 ms late
#: left a residual 1.95 times the shifted fit's, 5 ms 2.8 times; on time, 1.06 at most.
LAG_SEARCH = 0.02
LAG_GAIN = 1.5

#: The search's first stride (s), two samples at least: whole milliseconds keep the number of
#: fits a search makes about the same at any sample rate.
LAG_STRIDE = 0.002

#: Lower bound of the fitted gain K (N m / rad), 1e-11 of the paper's 0.37: keeps it positive.
_MIN_GAIN = 1e-12

#: Largest accepted ratio of the fit's residual rms to the coupling torque's rms. A simulated free
#: sweep of the paper antenna fits to about 1 %; a recording with a contact, whose static torque
#: the high-pass observer cannot follow, leaves about 100 %. Half sits safely between the two.
MAX_RELATIVE_RESIDUAL = 0.5


def initial_guess(antenna: Antenna) -> tuple[float, float, float]:
    """Physics-based (K, omega, d): rigid-link inertia and the first clamped-free mode.

    Returns
    -------
    gain : float
        K = J omega^2 with J = m_b l^2 / 3 + m_t l^2 (N m / rad).
    natural_frequency : float
        omega = (beta_1 l)^2 / (T l^2), beta_1 l = 1.8751 (rad/s); ignores the tip mass.
    damping : float
        d = 2 zeta omega with zeta = 0.01 (1/s).
    """
    link = antenna.link
    inertia = link.mass * link.length**2 / 3.0 + link.tip_mass * link.length**2
    omega = CLAMPED_FREE_BETA_L**2 / (link.t_param * link.length**2)
    return inertia * omega**2, omega, 2.0 * 0.01 * omega


def _targets(recording: Recording, antenna: Antenna) -> NDArray[np.float64]:
    """Measured Gamma_e,1 and Gamma_e,2 (N m), shape (n, 2): the torques with the link weight
    removed, mapped back through the signs of Section 4.2 (``OBSERVER_TORQUE_SIGNS``)."""
    sign_y, sign_z = OBSERVER_TORQUE_SIGNS
    # Section 4.2: Gamma^m - Gamma_g^m on Y^m and Z^m
    dynamic_y = recording.torque[:, 1] - antenna.link.gravity_moment(recording.theta[:, 1])
    dynamic_z = recording.torque[:, 2]
    return np.column_stack([sign_z * dynamic_z, sign_y * dynamic_y])


def _static_terms(recording: Recording, length: float) -> NDArray[np.float64]:
    """How the targets of :func:`_targets` change, shape (n, 2, 2): [..., 0] per metre the
    torques' point S lies along the link from O (N; Gamma_O = Gamma_S + (S - O) x F gives
    tz + s Fy and ty - s Fz), [..., 1] per kilogram of tip mass the weight leaves out (N m / kg,
    g l cos theta2 on the elevation's target), for a link of ``length`` (m)."""
    sign_y, sign_z = OBSERVER_TORQUE_SIGNS
    force = recording.force
    lever = np.column_stack([sign_z * force[:, 1], -sign_y * force[:, 2]])
    weight = np.zeros_like(lever)
    weight[:, 1] = sign_y * STANDARD_GRAVITY * length * np.cos(recording.theta[:, 1])
    return np.stack([lever, weight], axis=-1)


def _fit(
    data: Sequence[tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]],
    period: float,
    guess: tuple[float, float, float],
    where: str,
    reach: float = 0.0,
    stated: NDArray[np.float64] | None = None,
) -> tuple[float, float, float, float, NDArray[np.float64] | None]:
    """(K, omega, d) of Eq. 15 fitted to the measured coupling torques, the residual rms
    (N m), and the point (S - O, m) the torques read as taken about when Eq. 15 with it
    (:func:`_lever_fit`) leaves at most :data:`LEVER_GAIN` of that residual and it lies
    from :data:`SENSOR_OFFSET_NOTICED` to ``reach`` (m) from O (else None): a grid over omega
    and zeta with K solved linearly, then least squares. ``data``
    holds, per recording, the moved joints' angles (rad) and measured torques (N m), each of
    shape (n, joints), and their :func:`_static_terms`, shape (n, joints, 2). Raises
    IdentificationError when Eq. 15 explains the torque poorly (not free motion, or torques
    about another point than O: named when within ``reach`` (m) of O,
    :func:`_torque_point_hint`, ``stated`` the point the recordings state)."""
    nyquist = math.pi / period
    k0, w0, d0 = guess
    measured = np.concatenate([torques.ravel() for _, torques, _ in data])

    def unit_response(omega: float, damping: float) -> NDArray[np.float64]:
        observer = FreeMotionObserver(1.0, omega, damping, 1.0)
        # Eq. 15 with K = 1, discretised as online, each recording from its own rest
        return np.concatenate(
            [observe_free_motion(angles, observer, period).ravel() for angles, _, _ in data]
        )

    best = (math.inf, k0, min(w0, 0.5 * nyquist), d0)
    for omega in w0 * np.geomspace(0.4, 2.5, 49):
        if omega >= 0.5 * nyquist:
            continue
        for zeta in _ZETA_GRID:
            u = unit_response(float(omega), 2.0 * zeta * float(omega))
            gain = float(np.sum(u * measured) / np.sum(u * u))
            cost = float(np.sum((measured - gain * u) ** 2))
            if gain > 0 and cost < best[0]:
                best = (cost, gain, float(omega), 2.0 * zeta * float(omega))

    def residuals(params: NDArray[np.float64]) -> NDArray[np.float64]:
        gain, omega, damping = params
        return measured - gain * unit_response(omega, damping)

    rigid = k0 / w0**2
    if best[1] < _MIN_GAIN:
        # torques (or angles) on a scale no fit starts from: the inertia says which
        _check_inertia(best[1] / best[2] ** 2, rigid, where)
    start = np.array(best[1:])
    fit = least_squares(
        residuals,
        start,
        bounds=([_MIN_GAIN, 1e-6, 0.0], [np.inf, 0.9 * nyquist, np.inf]),
        x_scale=np.maximum(np.abs(start), 1e-6),
    )
    gain, omega, damping = (float(v) for v in fit.x)
    rms = float(np.sqrt(np.mean(fit.fun**2)))
    signal_rms = float(np.sqrt(np.mean(measured**2)))
    fitted = _lever_fit(data, unit_response, omega, damping)
    if rms > MAX_RELATIVE_RESIDUAL * signal_rms:
        hint = _torque_point_hint(fitted, reach, stated)
        raise IdentificationError(
            f"{where}: columns 'tx', 'ty', 'tz': Eq. 15 explains the coupling torque poorly "
            f"(residual rms {rms:.3g} N m against a signal rms of {signal_rms:.3g} N m); is this "
            "really free motion? A contact leaves a static torque that no free-motion observer "
            f"can follow{hint}; angles stamped tens of milliseconds off the torques' clock"
            " leave such a residual too (docs/real-antenna.md)"
        )
    point, lever_rms, _ = fitted
    whole = _whole_point(point, stated)
    noticed = lever_rms <= LEVER_GAIN * rms and abs(point) >= SENSOR_OFFSET_NOTICED
    return gain, omega, damping, rms, whole if noticed and abs(whole[0]) <= reach else None


def _stated_point(
    recordings: Sequence[Recording], antenna: Antenna
) -> tuple[float, NDArray[np.float64] | None]:
    """How far from O (m) a torque point is named (:data:`SENSOR_OFFSET_SHARE` of the link; 0
    when the recordings state different points) and the point they state (S - O, m; None
    when none does)."""
    stated = {recording.metadata.get(MOVED_KEY) for recording in recordings}
    if len(stated) > 1:
        return 0.0, None
    text = stated.pop()
    point = None if text is None else torque_point_problem(text)[0]  # checked by the reader
    return SENSOR_OFFSET_SHARE * antenna.link.length, point


def _lever_fit(
    data: Sequence[tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]],
    unit_response: Callable[[float, float], NDArray[np.float64]],
    omega: float,
    damping: float,
) -> tuple[float, float, float]:
    """Eq. 15 with the torques' point and a tip mass, ``K u - s w + m v`` (:func:`_static_terms`:
    the weight the rest read as payload is the lever's too; K, s, m by linear least squares
    over a grid about ``omega`` and ``damping``): the point s (m along the link from O), the
    residual rms and the rms of the torques moved to that point (N m); (0, inf, inf) when no
    gain is positive."""
    measured = np.concatenate([torques.ravel() for _, torques, _ in data])
    terms = np.concatenate([static.reshape(-1, 2) for _, _, static in data])
    best = (math.inf, 0.0, math.inf)
    for scale in np.geomspace(0.5, 2.0, 15):
        for zeta in _ZETA_GRID:
            w = float(omega * scale)
            u = unit_response(w, 2.0 * zeta * w if damping > 0 else 0.0)
            basis = np.column_stack([u, terms])
            (gain, shift, mass), *_ = np.linalg.lstsq(basis, measured, rcond=None)
            cost = float(np.mean((measured - basis @ (gain, shift, mass)) ** 2))
            if gain > 0 and cost < best[0]:
                # the torques read shift w short of O's; moved, they keep the dynamic part
                moved = measured - shift * terms[:, 0] - mass * terms[:, 1]
                best = (cost, -float(shift), float(np.sqrt(np.mean(moved**2))))
    return best[1], math.sqrt(best[0]), best[2]


def _whole_point(point: float, stated: NDArray[np.float64] | None) -> NDArray[np.float64]:
    """S - O (m, shape (3,)): ``point`` (m along the link) beyond the ``stated`` one."""
    return np.array([point, 0.0, 0.0]) + (0.0 if stated is None else stated)


def _torque_point_hint(
    fitted: tuple[float, float, float], reach: float, stated: NDArray[np.float64] | None
) -> str:
    """ "; or ..." naming the point along the link the torques read as taken about, when Eq. 15
    with it (:func:`_lever_fit`, ``fitted``) explains the torques moved there as Eq. 15 alone
    must explain free motion (:data:`MAX_RELATIVE_RESIDUAL`) and the whole point lies within
    ``reach`` (m) of O; "" otherwise. ``stated``: the point the recordings already state
    (S - O, m), which the named one adds to."""
    point, rms, moved_rms = fitted
    if not (math.isfinite(rms) and rms <= MAX_RELATIVE_RESIDUAL * moved_rms):
        return ""
    whole = _whole_point(point, stated)
    if not abs(whole[0]) <= reach:
        return ""
    beyond = "" if stated is None else " beyond the '# torque_point' the recordings state"
    return (
        f"; or torques about the sensor's own origin: they read as about a point {point:+.3f} m"
        f" along the link from its clamp{beyond} (residual rms {rms:.3g} N m), which"
        f" '{metadata_line(whole)}' would state (docs/recording-format.md)"
    )


def _check_scale_alone(
    recording: Recording,
    data: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]],
    period: float,
    guess: tuple[float, float, float],
) -> None:
    """IdentificationError naming ``recording`` when Eq. 15 fitted to it alone (``data`` as
    one entry of :func:`_fit`'s) gives an effective inertia on another scale than the rigid
    link's (:func:`_check_inertia`: angles in degrees, time stamps in ms); nothing when its own
    fit fails otherwise or passes."""
    where = recording.source or "<recording>"
    try:
        gain, omega, *_ = _fit([data], period, guess, where)
    except _WrongScale:
        raise
    except IdentificationError:
        return
    _check_inertia(gain / omega**2, guess[0] / guess[1] ** 2, where)


class _WrongScale(IdentificationError):
    """An effective inertia on another scale than the rigid link's (:func:`_check_inertia`)."""


def _check_inertia(inertia: float, rigid: float, where: str) -> None:
    """_WrongScale (an IdentificationError) unless the effective inertia K / omega^2 (kg m^2)
    lies within ``MAX_INERTIA_FACTOR`` of the rigid link's ``rigid`` (kg m^2)."""
    if 1.0 / MAX_INERTIA_FACTOR <= inertia / rigid <= MAX_INERTIA_FACTOR:
        return
    # time in ms reads the motion a thousand times slower: the inertia a million times larger
    ratio = inertia / rigid
    unit = stamps_unit(lambda factor: 0.1 <= ratio / factor**2 <= 10.0)
    raise _WrongScale(
        f"{where}: columns 'theta1', 'theta2', 'ty', 'tz': the observer's inertia "
        f"K / omega^2 = {inertia:.3g} kg m^2 is {ratio:.3g} times the rigid link's "
        f"{rigid:.3g} kg m^2 (more than a factor {MAX_INERTIA_FACTOR:g}): "
        + (
            f"time stamps in {unit}? the format's are in s"
            if unit
            else "angles in degrees, or torques scaled?"
        )
    )


def units_problem(recording: Recording, antenna: Antenna) -> str | None:
    """Why a recording is not in the format's units, or None: its angles and its loads at rest at
    the start (:func:`~sensing_antenna.units_check.recording_problem`), at rest as the
    estimators judge it (the rest tolerance and window of ``EstimatorConfig``)."""
    problem = angle_problem(recording.theta)
    if problem is not None:
        # before the rest tolerance, whose angle differences a glitch of 1e308 rad overflows
        return problem
    return recording_problem(
        recording.theta, recording.force, recording.torque, antenna, *_rest_rule(recording)
    )


def _rest_rule(recording: Recording) -> tuple[float, int]:
    """The estimators' rest: the angle tolerance (rad) and the fewest samples a rest has."""
    from sensing_antenna.estimation.config import EstimatorConfig
    from sensing_antenna.estimation.front.contact_frame import rest_tolerance

    config = EstimatorConfig()
    return (
        rest_tolerance(recording.theta, config),
        round(config.rest_window / recording.sample_period) + 1,
    )


def rest_payload(recording: Recording, antenna: Antenna) -> Payload:
    """The tip mass (kg) the moment about Y^m at rest at the start reads beyond ``antenna``'s
    weight (module docstring), with its standard deviation; zero samples without a rest of at
    least the estimators' rest window."""
    tolerance, fewest = _rest_rule(recording)
    rest = initial_rest(recording.theta, tolerance)
    if rest < max(2, fewest):
        return Payload(0.0, math.nan, 0)
    window = slice(0, rest)
    theta = recording.theta[window]
    reading = rest_reading(theta, recording.force[window], recording.torque[window], antenna)
    excess = float(reading.torque[1] - reading.expected_torque[1])
    mass = antenna.link.tip_mass_for_moment(excess, theta[:, 1])
    if not math.isfinite(mass):
        return Payload(0.0, math.nan, 0)
    noise = float(np.std(recording.torque[window, 1], ddof=1))
    error = rest_moment_std(noise, noise / math.sqrt(rest))
    return Payload(mass, antenna.link.tip_mass_for_moment(error, theta[:, 1]), rest)


def identify_free_motion(
    recordings: Recording | Sequence[Recording],
    antenna: Antenna,
    margin: float = DEFAULT_MARGIN,
    residual_cutoff: float = DEFAULT_RESIDUAL_CUTOFF,
    *,
    find_lag: bool = True,
) -> ObserverFit:
    """Fit the Eq. 15 observer and the contact threshold to free-motion recordings.

    Parameters
    ----------
    recordings : Recording or sequence of Recording
        Free motion, no contact: one recording, or several (the head's free movements, e.g. an
        azimuthal and a vertical sweep) fitted together, each joint from the recordings in which
        it moved; irregular sampling is resampled linearly first.
    antenna : Antenna
        Link (weight, physics-based start); its current observer is not used.
    margin : float
        Safety factor on the maximum free-motion residual (Section 5.2: 1.5).
    residual_cutoff : float
        Cut-off of the residual filter (rad/s); must match the detector's.
    find_lag : bool
        Look for angles read on a clock that lags the sensor's (:attr:`ObserverFit.angle_lag`;
        a few more fits of Eq. 15); False: ``angle_lag`` is None.

    Returns
    -------
    ObserverFit
        The threshold is ``margin`` times the largest filtered residual over all recordings; the
        payload is the rests' inverse-variance mean, with the smallest of their standard
        deviations (a shared tare does not average out). The observer's torques and the
        threshold's residuals are those of the link with that payload: the
        weight the sensor read, which a detector using the identified antenna removes.

    Raises
    ------
    IdentificationError
        When no joint moved by more than ``MIN_MOTION``, ``margin`` is not a number >= 1, a
        recording is not in the format's units (its angles, or its loads at rest against the
        link's weight, :func:`~sensing_antenna.units_check.recording_problem`), the fitted
        observer leaves more than ``MAX_RELATIVE_RESIDUAL`` of the torque unexplained (not a
        free motion), or its effective inertia is more than ``MAX_INERTIA_FACTOR`` from the
        rigid link's.
    """
    given = [recordings] if isinstance(recordings, Recording) else list(recordings)
    if not given:
        raise IdentificationError("recordings: none given; a free-motion recording is needed")
    if not (math.isfinite(margin) and margin >= 1.0):
        raise IdentificationError(f"margin: must be a number >= 1, got {margin!r}")
    named = any(r.source for r in given)
    where = ", ".join(r.source or f"<recording {k + 1}>" for k, r in enumerate(given))
    if len(given) == 1:
        where = given[0].source or "<recording>"
    moves = [_free_motion(recording, antenna) for recording in given]
    payload = _combined_payload([move.payload for move in moves])
    weighed = payload.apply(antenna)
    first = next((move for move in moves if move.joints), None)
    if first is None:
        raise IdentificationError(
            f"{where}: columns 'theta1', 'theta2': no joint moved by more than {MIN_MOTION:g} rad;"
            " a free-motion recording is needed"
        )
    # the observer runs at one period: every recording on the first moving one's grid
    period = first.recording.sample_period
    moves = [
        move
        if move.recording.sample_period == period
        else replace(move, recording=resample_uniform(move.recording, period))
        for move in moves
    ]
    gain, omega, damping, rms, suspect, peak = _observed(
        moves, antenna, weighed, where, residual_cutoff
    )
    if not math.isfinite(margin * peak):
        raise IdentificationError(
            f"contact threshold: {margin!r} x the largest filtered residual ({peak!r} N m) is not "
            "finite: a load sample of the free motion is far out of range"
        )
    lag = _angle_lag(moves, antenna, weighed, where, residual_cutoff, peak) if find_lag else None
    k0, w0, d0 = initial_guess(antenna)
    joints = sorted({j + 1 for move in moves for j in move.joints})
    return ObserverFit(
        gain=gain,
        natural_frequency=omega,
        damping=damping,
        contact_threshold=margin * peak,
        max_filtered_residual=peak,
        residual_rms=rms,
        joints=tuple(joints),
        margin=float(margin),
        residual_cutoff=float(residual_cutoff),
        initial_gain=k0,
        initial_natural_frequency=w0,
        initial_damping=d0,
        source=where if named else None,
        payload=payload,
        torque_point=None
        if suspect is None
        else (float(suspect[0]), float(suspect[1]), float(suspect[2])),
        angle_lag=lag,
    )


def _observed(
    moves: Sequence[_FreeMotion],
    antenna: Antenna,
    weighed: Antenna,
    where: str,
    residual_cutoff: float,
) -> tuple[float, float, float, float, NDArray[np.float64] | None, float]:
    """Eq. 15 fitted to the moved joints of ``moves`` (one period) with the weight of
    ``weighed``: (K, omega, d, the residual rms, the suspected torque point or None, the largest
    filtered residual of Eq. 16 over all of ``moves``, N m)."""
    period = next(move for move in moves if move.joints).recording.sample_period
    moved = [move for move in moves if move.joints]
    data = [
        (
            move.recording.theta[:, move.joints],
            _targets(move.recording, weighed)[:, move.joints],
            _static_terms(move.recording, antenna.link.length)[:, move.joints],
        )
        for move in moved
    ]
    k0, w0, d0 = initial_guess(antenna)
    try:
        # Arithmetic that overflows means values no link gives (a wrench of 1e300 N m)
        with np.errstate(over="raise"):
            reach, stated = _stated_point([move.recording for move in moved], antenna)
            try:
                gain, omega, damping, rms, suspect = _fit(
                    data, period, (k0, w0, d0), where, reach, stated
                )
                _check_inertia(gain / omega**2, k0 / w0**2, where)
            except IdentificationError:
                # one recording on another scale spoils the joint fit: it names itself
                if len(moved) > 1:
                    for move, one in zip(moved, data, strict=True):
                        _check_scale_alone(move.recording, one, period, (k0, w0, d0))
                raise
    except FloatingPointError:
        raise IdentificationError(
            f"{where}: columns 'theta1', 'theta2', 'ty', 'tz': the fit of Eq. 15 overflows: "
            "angles or torques far beyond a head's (units?)"
        ) from None
    provisional = FreeMotionObserver(gain, omega, damping, contact_threshold=1.0)
    provisional_antenna = replace(weighed, observer=provisional)
    peak = max(
        float(
            np.max(
                detect_contact(
                    move.recording, provisional_antenna, residual_cutoff=residual_cutoff
                ).filtered_residual_norm
            )
        )
        for move in moves
    )
    return gain, omega, damping, rms, suspect, peak


def _angle_lag(
    moves: Sequence[_FreeMotion],
    antenna: Antenna,
    weighed: Antenna,
    where: str,
    residual_cutoff: float,
    peak: float,
) -> float | None:
    """How late (s) the angles read against the torques, when Eq. 15 fitted with the angles
    moved earlier by that much leaves a largest filtered residual :data:`LAG_GAIN` times
    smaller than ``peak`` (N m), the lag at least two samples; else None. Whole samples: a
    stride of :data:`LAG_STRIDE` (two samples at least) from one stride either way, on in the
    direction the residual falls (up to :data:`LAG_SEARCH`) while it falls, then half strides
    about the best down to one sample."""
    period = next(move for move in moves if move.joints).recording.sample_period
    stride = max(2, round(LAG_STRIDE / period))
    most = max(stride, round(LAG_SEARCH / period))
    peaks = {0: peak}

    def peak_at(shift: int) -> float:
        if shift not in peaks:
            moved = [
                replace(move, recording=_angles_moved(move.recording, shift)) for move in moves
            ]
            try:
                peaks[shift] = _observed(moved, antenna, weighed, where, residual_cutoff)[5]
            except IdentificationError:
                peaks[shift] = math.inf
        return peaks[shift]

    direction = 1 if peak_at(stride) <= peak_at(-stride) else -1
    shift = stride * direction
    while abs(shift) + stride <= most and peak_at(shift + stride * direction) < peak_at(shift):
        shift += stride * direction
    best = min(peaks, key=peaks.__getitem__)
    while stride > 1:
        stride = max(1, stride // 2)
        for beside in (best - stride, best + stride):
            if abs(beside) <= most:
                peak_at(beside)
        best = min(peaks, key=peaks.__getitem__)
    if abs(best) < 2 or not peaks[best] * LAG_GAIN <= peak:
        return None
    return best * period


def _angles_moved(recording: Recording, shift: int) -> Recording:
    """``recording`` with each sample's angles taken ``shift`` samples later (earlier when
    negative), the ends held."""
    theta = recording.theta
    index = np.clip(np.arange(theta.shape[0]) + shift, 0, theta.shape[0] - 1)
    return replace(recording, theta=np.ascontiguousarray(theta[index]))


@dataclass(frozen=True)
class _FreeMotion:
    """One free-motion recording, checked and uniformly sampled, with its moved joints (0-based)
    and the payload its rest reads."""

    recording: Recording
    joints: list[int]
    payload: Payload


def _free_motion(recording: Recording, antenna: Antenna) -> _FreeMotion:
    where = recording.source or "<recording>"
    uniform = resample_uniform(recording) if recording.sampling.irregular else recording
    problem = units_problem(uniform, antenna)
    if problem is not None:
        raise IdentificationError(f"{where}: {problem}")
    span = np.ptp(uniform.theta, axis=0)
    joints = [j for j in (0, 1) if span[j] > MIN_MOTION]
    return _FreeMotion(uniform, joints, rest_payload(uniform, antenna))


def _combined_payload(payloads: Sequence[Payload]) -> Payload:
    """The payloads of several rests as one: their inverse-variance mean mass (kg), with the
    smallest of their standard deviations (not the mean's, which would fall as more rests are
    added: most of each is the tare's offset, which rests after one tare share), and the
    samples summed; no samples when none read a rest."""
    read = [p for p in payloads if p.samples > 1 and math.isfinite(p.std) and p.std > 0]
    if not read:
        return Payload(0.0, math.nan, 0)
    weights = np.array([1.0 / p.std**2 for p in read])
    mass = float(np.sum(weights * np.array([p.mass for p in read])) / np.sum(weights))
    return Payload(mass, min(p.std for p in read), sum(p.samples for p in read))
