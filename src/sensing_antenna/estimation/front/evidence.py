"""What the front end hands every method at t_e, :class:`Evidence`, and the sensing curves and
mode ratios the methods read (built once per link).

The front end (:class:`~.frontend.FrontEnd`) builds the evidence from the samples up to t_e only,
identically in batch and streaming; a method turns it into a
:class:`~sensing_antenna.estimation.result.ContactEstimate`.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.interpolate import CubicSpline

from sensing_antenna.antenna import Antenna, Link
from sensing_antenna.beam.weight import pushed_weight_moment, weight_residual
from sensing_antenna.estimation.config import PAPER_SPECTRUM_WINDOW, EstimatorConfig
from sensing_antenna.estimation.front.contact_frame import ContactFrame
from sensing_antenna.estimation.front.held import describe_held, find_held
from sensing_antenna.estimation.front.ratio import (
    contact_loads,
    lowpass_noise_gain,
    vertical_shares,
)
from sensing_antenna.estimation.front.spectrum import power_spectrum
from sensing_antenna.estimation.front.spikes import (
    LEVEL_SAMPLES,
    describe_run,
    find_long_runs,
    long_run_longest,
    spike_floor,
    spike_longest,
)
from sensing_antenna.estimation.front.steps import TareKind, gap_problem

if TYPE_CHECKING:
    from sensing_antenna.estimation.front.outcome import FrontTrace

__all__ = [
    "SUPPORT_KNOTS",
    "TWO_FREQUENCY_GRID_STEP",
    "Evidence",
    "first_mode_value",
    "search_band",
    "sensing_curve",
    "support_coefficients",
    "two_frequency_curve",
]

FloatArray = NDArray[np.float64]


#: Share of the hold's push below which the contact force has not yet begun to push
#: (:attr:`Evidence.push_onset_index`): above the link's own loads of a sweep, well below the
#: push the detector fires on.
ONSET_SHARE = 0.1


def sensing_curve(link: Link) -> Any:
    """The omega_1(x_c) sensing curve of a link, built once per link."""
    return _sensing_curve(link)


@functools.lru_cache(maxsize=16)
def _sensing_curve(link: Link) -> Any:
    from sensing_antenna.beam import SensingCurve

    return SensingCurve.from_link(link)


#: Knots of the splines :func:`first_mode_value` reads from, evenly spaced over (0, l]: on the
#: paper link 48 knots (2 cm apart) give the contact-to-base shear ratio and the held contact's
#: coupling within 1e-4 of the direct computation (each direct value solves the modes,
#: milliseconds) for the cost of 48 direct ones per link.
MODE_KNOTS = 48


@functools.lru_cache(maxsize=32)
def _mode_spline(link: Link, quantity: Callable[[Link, ArrayLike], FloatArray]) -> CubicSpline:
    x = np.linspace(link.length / MODE_KNOTS, link.length, MODE_KNOTS)
    return CubicSpline(x, quantity(link, x))


def first_mode_value(
    link: Link, quantity: Callable[[Link, ArrayLike], FloatArray], x_c: float
) -> float:
    """A quantity of the first contact mode at ``x_c`` (m), ``quantity(link, x_c)`` one of
    :mod:`sensing_antenna.beam.modes` (``contact_to_base_shear``, ``held_contact_coupling``),
    from a spline of the link's (built once per link and quantity); computed directly before
    the first knot."""
    spline = _mode_spline(link, quantity)
    if x_c < spline.x[0]:
        return float(quantity(link, x_c))
    return float(spline(min(x_c, link.length)))


#: Knots of the spline :func:`support_coefficients` reads from over [x_min, l], closer
#: together towards the tip (u -> 1 - (1 - u)^1.5 of the span), where a tip mass sharpens the
#: second mode's reaction: 48 hold c_1 and c_2 within 2e-3 of their largest value on the paper
#: link with tip masses up to its own over the default contact range (from 0.2 l), within 5e-3
#: from 0.1 l (each direct value solves the modes, milliseconds).
SUPPORT_KNOTS = 48


@functools.lru_cache(maxsize=16)
def _support_spline(link: Link, x_min: float) -> CubicSpline:
    from sensing_antenna.beam.modes import support_compliance_coefficients

    u = 1.0 - (1.0 - np.linspace(0.0, 1.0, SUPPORT_KNOTS)) ** 1.5
    x = x_min + (link.length - x_min) * u
    return CubicSpline(x, support_compliance_coefficients(link, x, 2))


def support_coefficients(link: Link, x_min: float, x_c: float) -> tuple[float, float]:
    """(c_1, c_2) (N/m) of :func:`~sensing_antenna.beam.modes.support_compliance_coefficients`
    at ``x_c`` in [``x_min``, l] (m), from a spline built once per link and ``x_min``."""
    c_1, c_2 = np.maximum(_support_spline(link, x_min)(min(x_c, link.length)), 0.0)
    return float(c_1), float(c_2)


#: Spacing of the x_c grid on which the (omega_1, omega_2) curve is tabulated (m); 0.5 mm is
#: twenty times finer than the paper's typical error.
TWO_FREQUENCY_GRID_STEP = 5e-4


@functools.lru_cache(maxsize=16)
def two_frequency_curve(link: Link, x_min: float, x_max: float) -> tuple[FloatArray, FloatArray]:
    """Tabulated sensing curve (omega_1, omega_2)(x_c) of Figure 9.

    Returns
    -------
    x : array, shape (m,)
        Contact points (m).
    omegas : array, shape (m, 2)
        First two natural frequencies in contact (rad/s).
    """
    from sensing_antenna.beam import natural_frequencies

    x = np.arange(x_min, x_max + 0.5 * TWO_FREQUENCY_GRID_STEP, TWO_FREQUENCY_GRID_STEP)
    x = x[(x > 0.0) & (x <= link.length)]
    omegas = np.asarray(natural_frequencies(link, x, 2), dtype=float)
    return x, omegas


#: Smallest cos(theta_2) at which the weight at rest is read as a payload: beyond 60 deg of
#: elevation the moment's lever shrinks, and a few counts of offset would read as grams.
_PAYLOAD_COSINE = 0.5


@functools.lru_cache(maxsize=8)
def _payload_shifts(link: Link, mass: float, points: bytes, shape: tuple[int, ...]) -> FloatArray:
    """:meth:`Evidence.payload_shifts` of ``mass`` (kg) at the contact points held in
    ``points`` (float64 bytes, of ``shape``); read-only."""
    from sensing_antenna.beam import natural_frequencies
    from sensing_antenna.errors import SensingAntennaError

    x_c = np.frombuffer(points, dtype=float).reshape(shape)
    try:
        heavier = replace(link, tip_mass=link.tip_mass + mass)
    except SensingAntennaError:
        return np.zeros(shape)
    x_c = np.clip(x_c, 1e-6 * link.length, link.length)
    model = np.asarray(natural_frequencies(link, x_c, 1), dtype=float)[..., 0]
    loaded = np.asarray(natural_frequencies(heavier, x_c, 1), dtype=float)[..., 0]
    shifts = np.maximum(model - loaded, 0.0)
    shifts.setflags(write=False)
    return shifts


def search_band(link: Link, config: EstimatorConfig) -> tuple[float, float]:
    """omega_1 band allowed by the sensing curve over the contact range, with the margin (rad/s).

    Section 4.3: the fundamental is searched only where the sensing curve can put it; the margin
    ``config.band_margin`` allows for calibration error of T.
    """
    low, high = sensing_curve(link).omega1_range(
        config.contact_range[0] * link.length, config.contact_range[1] * link.length
    )
    return float(low) / (1.0 + config.band_margin), float(high) * (1.0 + config.band_margin)


def spectrum_window(link: Link, config: EstimatorConfig) -> float:
    """Delta t_e1 (s) for ``link``: ``config.spectrum_window`` when set, else the paper's 1 s
    (:data:`~sensing_antenna.estimation.config.PAPER_SPECTRUM_WINDOW`) times how many times
    lower than the lowest omega_1 the paper link's band searches (:func:`search_band`, its
    margin for calibration error included) this link's lowest over the contact range lies, when
    it does: the window then holds as many of the link's periods as the paper's holds of its
    own. A link within the paper's band, calibrated or not, keeps 1 s."""
    if config.spectrum_window is not None:
        return config.spectrum_window
    low, high = config.contact_range  # a list or an array too: the cache needs a tuple
    return _scaled_window(link, (float(low), float(high)), config.band_margin)


@functools.lru_cache(maxsize=16)
def _scaled_window(link: Link, contact_range: tuple[float, float], margin: float) -> float:
    from sensing_antenna.antenna import paper_antenna

    def lowest(of: Link) -> float:
        low, _ = sensing_curve(of).omega1_range(
            contact_range[0] * of.length, contact_range[1] * of.length
        )
        return float(low)

    floor = lowest(paper_antenna().link) / (1.0 + margin)
    return PAPER_SPECTRUM_WINDOW * max(1.0, floor / lowest(link))


@dataclass(frozen=True)
class Evidence:
    """Everything the pipeline knows at t_e, from the samples up to t_e only.

    Built by :class:`~.frontend.FrontEnd`, identically whether the samples came as one block
    (:func:`~sensing_antenna.estimation.pipeline.gather`) or one by one (the online estimator);
    a method turns it into a :class:`~sensing_antenna.estimation.result.ContactEstimate`. The
    sample and ratio arrays are read-only views.

    Attributes
    ----------
    t : array, shape (n,)
        Sample times up to and including t_e (s).
    theta, force, torque : array, shape (n, 2), (n, 3), (n, 3)
        Samples up to t_e (rad, N, N m; motor frame).
    sample_period : float
        T_s (s).
    antenna : Antenna
    config : EstimatorConfig
    contact_index, rest_index, end_index : int
        Indices of t_c, t_1 and t_e (end_index = n - 1).
    converged_index : int or None
        Index of t_1 + Delta t_e2, None when the ratio never settled.
    complete : bool
        False when the samples ended before the planned t_e (recording too short).
    frame : ContactFrame
        Contact frame from the mean reaction over the hold after t_1.
    reaction_f, torque_f : array, shape (n, 3)
        Filtered contact loads (Eq. 20 after removing gravity), motor frame (N, N m).
    ratio : array, shape (n,)
        Estimator 2, x_c(t) (m).
    ratio_mean : array, shape (n,)
        Its causal moving average over ``convergence_window`` from t_1 on (NaN before) (m).
    load_offset : array, shape (6,)
        Sensor offset removed from the loads (N, N m), see
        :func:`~sensing_antenna.estimation.front.ratio.load_offset`.
    ratio_noise : float
        Expected standard deviation of the ratio from the force noise (m), see
        :func:`~sensing_antenna.estimation.front.ratio.ratio_noise`.
    band : tuple of float
        omega_1 search band (rad/s).
    hold_end : int
        Last index of the hold window that judged the push and built the frame; a method that
        stops early (``fast``) may not declare before it.
    offset_error, torque_offset_error : float
        Standard errors of the force (N) and torque (N m) offsets removed by the tare.
    tare : {"rest", "approach", "none"}
        Where the offset was read (:data:`~.steps.TareKind`).
    tare_samples : tuple of int, length 6
        Samples the tare averaged on each channel (fx, fy, fz, tx, ty, tz): each channel's rest
        ends where its load leaves its level (docs/estimation.md, step 2).
    gaps : tuple of (float, float)
        The steps of the time stamps (s, s) that missed more than ``config.gap_limit`` samples
        (those known by t_e in a stream); :meth:`gap_within` judges them over a method's own
        window.
    input_problem : str or None
        Why the samples up to t_c are not in the format's units and signs (the loads at rest
        against the link's weight, the free motion against the observer), None when they are;
        the plausibility layer makes it the status ``implausible_input``.
    declared_period : bool
        ``sample_period`` was declared before the samples came (a stream), not read from their
        stamps (a recording, put on the period they keep by its reader): the plausibility
        layer then holds the stamps up to t_e to it.
    diagnostics : dict
        Front-end diagnostics (sampling, rest tolerance, rebounds, ...).
    trace : FrontTrace or None
        What the front end saw (set on the evidence at t_e; not compared).
    """

    t: FloatArray
    theta: FloatArray
    force: FloatArray
    torque: FloatArray
    sample_period: float
    antenna: Antenna
    config: EstimatorConfig
    contact_index: int
    rest_index: int
    end_index: int
    converged_index: int | None
    complete: bool
    frame: ContactFrame
    reaction_f: FloatArray
    torque_f: FloatArray
    ratio: FloatArray
    ratio_mean: FloatArray
    load_offset: FloatArray
    ratio_noise: float
    band: tuple[float, float]
    hold_end: int = 0
    offset_error: float = 0.0
    torque_offset_error: float = 0.0
    tare: TareKind = "rest"
    tare_samples: tuple[int, ...] = ()
    gaps: tuple[tuple[float, float], ...] = ()
    input_problem: str | None = None
    declared_period: bool = False
    diagnostics: dict[str, Any] = field(default_factory=dict)
    trace: FrontTrace | None = field(default=None, compare=False, repr=False)

    def gap_within(self, t_end: float) -> str | None:
        """The first of :attr:`gaps` overlapping [t_c, t_end] (s), described (bad input), or
        None: a method that answers before the planned t_e is judged over its own samples."""
        t_c = float(self.t[self.contact_index])
        limit = self.config.gap_limit(self.sample_period)
        return gap_problem(self.gaps, t_c, t_end, self.sample_period, limit)

    def held_within(self, t_end: float) -> str | None:
        """The first run of one wrench value held where its neighbours change
        (:func:`.held.find_held`), longer than ``config.gap_limit`` samples, up to ``t_end`` (s)
        and reaching the contact (ending at most that many samples before t_c: a contact made
        while the sensor stood still is found when it moves again), described (bad input), or
        None."""
        stop = int(np.searchsorted(self.t, t_end, side="right"))
        limit = self.config.gap_limit(self.sample_period)
        wrench = np.hstack([self.force[:stop], self.torque[:stop]])
        runs = find_held(wrench, limit, first=max(self.contact_index - limit, 0))
        return describe_held(runs[0], self.t, limit) if runs else None

    def corrupted_within(self, t_end: float) -> str | None:
        """The first run of wrench samples up to ``t_end`` (s) that leaves its neighbours and
        comes back, too long to put back (:func:`.spikes.find_long_runs`) and not the contact
        lost and found again (:meth:`_contact_lost`), described (bad input), or None."""
        stop = int(np.searchsorted(self.t, t_end, side="right"))
        longest = spike_longest(self.sample_period)
        wrench = np.hstack([self.force[:stop], self.torque[:stop]])
        runs = find_long_runs(
            wrench,
            spike_floor(self.antenna),
            longest=longest,
            most=long_run_longest(self.sample_period),
        )
        for run in runs:
            if not self._contact_lost(run.index, run.length):
                return describe_run(run, self.t, longest)
        return None

    def _contact_lost(self, start: int, length: int) -> bool:
        """Whether the push of the contact (its reaction along the hold's, N) over samples
        ``start`` .. ``start + length - 1`` falls to within half the push just before them,
        from at least a quarter of the hold's: a contact lost and found again (a rebound) leaves
        the loads' level and comes back as a corrupted run does."""
        held = self.frame.push_force
        if not held > 0.0 or start < 1:
            return False
        direction = self.frame.reaction_m / held
        before = max(start - LEVEL_SAMPLES, 0)
        rows = slice(before, start + length)
        reaction = self.contact_loads_unfiltered[0][rows]
        with np.errstate(over="ignore", invalid="ignore"):
            push = (reaction - self.load_offset[:3]) @ direction
            push_before = float(np.mean(push[: start - before]))
            push_during = float(np.mean(push[start - before :]))
        return push_before >= 0.25 * held and abs(push_during) <= 0.5 * push_before

    def sample_problem(self, t_end: float) -> str | None:
        """Why the samples up to ``t_end`` (s) are not whole (:meth:`gap_within`,
        :meth:`held_within`, :meth:`corrupted_within`), or None: a method's answer from them is
        ``bad_input``."""
        return self.gap_within(t_end) or self.held_within(t_end) or self.corrupted_within(t_end)

    @property
    def contact_modes(self) -> tuple[FloatArray, FloatArray]:
        """The tabulated (omega_1, omega_2)(x_c) over the config's contact range
        (:func:`two_frequency_curve`, cached): contact points (m), shape (m,), and the two
        frequencies (rad/s), shape (m, 2)."""
        link = self.antenna.link
        low, high = self.config.contact_range
        return two_frequency_curve(link, low * link.length, high * link.length)

    @property
    def filtered_force_error(self) -> float:
        """Standard error (N) of a filtered, tared contact force: the force channel's noise
        through the Eq. 20 low-pass (:func:`.ratio.lowpass_noise_gain`) and the tare's offset
        error, in quadrature."""
        noise = float(self.diagnostics.get("force_noise", 0.0)) * lowpass_noise_gain(
            self.config.lowpass_cutoff, self.sample_period
        )
        return math.hypot(noise, self.offset_error)

    @functools.cached_property
    def push_onset_index(self) -> int:
        """Sample where the push began: the last, up to t_c, at which the filtered contact force
        along the hold's reaction was at most :data:`ONSET_SHARE` of the hold's push or three
        of its standard errors (the low-passed noise and the tare's), the larger; where no
        sample was, the one where it was least. A detector fires once the push has built up
        (tens of ms after the touch on the simulator) or, when its threshold lies above what
        the push reached while the head turned, only after the head stopped (from the
        ringing): the head's turn into the contact is counted from here."""
        held = self.frame.push_force
        k = self.contact_index
        if not held > 0.0:
            return k
        level = max(ONSET_SHARE * held, 3.0 * self.filtered_force_error)
        push = self.reaction_f[: k + 1] @ (self.frame.reaction_m / held)
        quiet = np.flatnonzero(push <= level)
        if quiet.size:
            return int(quiet[-1])
        finite = np.where(np.isfinite(push), push, np.inf)
        return int(np.argmin(finite)) if np.isfinite(finite).any() else k

    @property
    def push_turn(self) -> tuple[FloatArray, FloatArray]:
        """The head's turn into the contact from where the push began
        (:attr:`push_onset_index`) to t_1: dtheta (rad), shape (2,), and the move it gives the
        link in the motor frame at t_1, (0, dtheta_1 cos theta_2, dtheta_2) (rad), shape (3,):
        the azimuth about Z^a moves X^m along cos theta_2 Y^m, the elevation along Z^m."""
        turn = self.theta[self.rest_index] - self.theta[self.push_onset_index]
        theta2 = float(self.theta[self.rest_index, 1])
        return turn, np.array([0.0, float(turn[0]) * math.cos(theta2), float(turn[1])])

    @property
    def spectrum_window(self) -> float:
        """Delta t_e1 (s) for this antenna's link (:func:`spectrum_window`)."""
        return spectrum_window(self.antenna.link, self.config)

    @property
    def spectrum_slice(self) -> slice:
        """Samples of the Delta t_e1 window after t_1 (shortened if the samples end first)."""
        n_window = round(self.spectrum_window / self.sample_period)
        return slice(self.rest_index, min(self.rest_index + n_window, self.end_index + 1))

    @functools.cached_property
    def contact_loads_unfiltered(self) -> tuple[FloatArray, FloatArray]:
        """The contact's loads at every sample, unfiltered (:func:`.ratio.contact_loads`),
        computed once: reaction (N) and its moment about O (N m), shape (n, 3) each."""
        with np.errstate(over="ignore", invalid="ignore"):
            reaction, moment = contact_loads(self.theta, self.force, self.torque, self.antenna)
        reaction.flags.writeable = False
        moment.flags.writeable = False
        return reaction, moment

    @functools.cached_property
    def window_spectrum(self) -> tuple[FloatArray, FloatArray]:
        """Power spectra of the torque about Y^c and Z^c over :attr:`spectrum_slice`, as
        Estimator 1 reads them (:func:`~.spectrum.power_spectrum`), computed once: angular
        frequencies (rad/s), shape (m,), and power (N^2 m^2), shape (m, 2)."""
        projected = self.torque[self.spectrum_slice] @ self.frame.axes_m[1:].T
        omega, power = power_spectrum(projected, self.sample_period, self.config.zero_padding)
        omega.flags.writeable = False
        power.flags.writeable = False
        return omega, power

    def ratio_uncertainty(
        self, x_c: float, model: bool = True, statics: str = "elastica", coupling: bool = False
    ) -> float:
        """Standard uncertainty (m) of the ratio estimate at a contact point ``x_c``.

        Three independent terms, added in quadrature:

        - the white force noise through the Eq. 20 filter (``ratio_noise``, given at x = l, here
          scaled to x_c: the ratio's error is x e_F / R_perp);
        - the residual sensor offset after the tare: errors e_F on R_perp and e_T on Gamma'
          move x = Gamma' / R_perp by x e_F / R_perp and e_T / R_perp;
        - the statics model, left out with ``model=False`` (the statistical part alone, which
          does not grow with the loads' scale). With d = |R_perp| x_c^2 / (3 E I) (the
          small-deflection y_c / x_c, Eq. 13; 1 / (E I) the link's bending compliance):

          - ``statics="elastica"`` (the front end's ratio, :func:`.ratio.perpendicular_ratio`):
            the elastica holds the axial force's moment at any deflection; what it does not
            hold is the stiffness's own uncertainty, 2 u of E I (u the frequency model's
            relative uncertainty: E I = rho / T^2), on its corrections |R_x / R_perp| d x_c
            and 0.6 d^2 x_c (first and second order); the error of the link's weight terms
            the ratio takes off (:func:`~sensing_antenna.beam.weight.pushed_weight_moment`,
            first order in the sag): ``ratio_model_factor`` times
            :func:`~sensing_antenna.beam.weight.weight_residual` times the terms' magnitudes
            over |R_perp|; and a floor, ``ratio_model_floor`` x_c (or
            the sensor calibration's ``ratio_scatter`` x_c when larger), for
            what no statics here holds (the contact's own size and compliance, dynamic loads
            left in the mean);
          - ``statics="small-deflection"`` (Eq. 21 as printed, the ``ratio`` baseline): the
            neglected moments, the axial force times the link's slope and the weight of the
            bent link, ``ratio_model_factor`` d x_c, and the scatter the sensor's calibration
            measured about its known points, ``ratio_scatter`` x_c;

          and with either and ``coupling``, the cross-talk of a sensor no calibration has
          measured, ``coupling_uncertainty`` x_c^2 (:meth:`.SensorCorrection.coupling_uncertainty`).
          It is asked by an answer that rests on the ratio (the ``ratio`` baseline, the ``fast``
          posterior), not by the checks that judge the ratio against the vibration: there a
          cross-talk that moves the ratio shows as a disagreement, which is not ``ok`` either.

        The model holds on the link only: a reading outside it (a ratio of 10^5 m from torques
        in N mm) is judged at the nearest point of [0, l], where the terms stay finite.
        """
        if not math.isfinite(x_c):
            return math.inf
        link = self.antenna.link
        x_c = min(max(x_c, 0.0), link.length)
        push = self.frame.lateral_force
        if push <= 0.0:
            return math.inf
        offset_term = math.hypot(x_c * self.offset_error, self.torque_offset_error) / push
        deflection_ratio = float(self.push_deflection_ratio(x_c))
        model_term = 0.0
        if model and statics == "small-deflection":
            model_term = math.hypot(
                self.config.ratio_model_factor * deflection_ratio * x_c,
                self.antenna.sensor.ratio_scatter * x_c,
                float(self.cross_talk_uncertainty(np.array(x_c))) if coupling else 0.0,
            )
        elif model:
            model_term = float(self.ratio_model_uncertainty(np.array(x_c), coupling))
        noise_term = self.ratio_noise * x_c / link.length
        # in quadrature without squaring (a torque noise of 1e297 N m must not overflow)
        return math.hypot(noise_term, offset_term, model_term)

    def ratio_model_uncertainty(self, x_c: FloatArray, coupling: bool = False) -> FloatArray:
        """The elastica statics' model term of :meth:`ratio_uncertainty` (m), at contact points
        ``x_c`` (m, any shape, on the link): the stiffness's uncertainty on the statics'
        corrections, what the link's weight leaves after the ratio took its terms off
        (:data:`~sensing_antenna.beam.weight.WEIGHT_RESIDUAL`), and the floor
        ``ratio_model_floor`` x_c (the sensor calibration's ``ratio_scatter`` x_c when larger),
        and with ``coupling`` an uncalibrated sensor's cross-talk (``coupling_uncertainty``
        x_c^2, :meth:`ratio_uncertainty` says when), in quadrature, for the hold's push
        (``frame``). A method
        with statics of its own that are the elastica's (``fast``) weighs them with it. Infinite
        where there is no push to read the ratio by, or where loads beyond any sensor overflow
        the term: the ratio says nothing there."""
        link = self.antenna.link
        x_c = np.asarray(x_c, dtype=float)
        reaction = self.frame.reaction_m
        push = self.frame.lateral_force
        if push <= 0.0:
            return np.full(x_c.shape, np.inf)
        deflection_ratio = self.push_deflection_ratio(x_c)
        axial = abs(float(reaction[0])) / push
        stiffness = (
            2.0
            * link.frequency_uncertainty
            * (axial + 1.2 * deflection_ratio)
            * deflection_ratio
            * x_c
        )
        # what the first-order weight terms the ratio takes off leave (beam.weight)
        link_vertical, push_vertical = vertical_shares(reaction, self.frame.theta[1])
        with np.errstate(over="ignore", invalid="ignore"):
            terms = pushed_weight_moment(
                link, x_c, push, float(reaction[0]), link_vertical, push_vertical
            )
            weight = (
                self.config.ratio_model_factor
                * weight_residual(deflection_ratio)
                * np.abs(terms).sum(axis=-1)
                / push
            )
        # the floor, or the scatter the sensor's calibration left on the ratio if larger
        sensor = self.antenna.sensor
        floor = max(self.config.ratio_model_floor, sensor.ratio_scatter) * x_c
        leak = (
            np.hypot(self.cross_talk_uncertainty(x_c), self.axial_cross_talk_uncertainty(x_c))
            if coupling
            else np.zeros(x_c.shape)
        )
        term = np.asarray(np.hypot(np.hypot(stiffness, weight), np.hypot(floor, leak)), dtype=float)
        return np.where(np.isnan(term), np.inf, term)

    def cross_talk_uncertainty(self, x_c: FloatArray) -> FloatArray:
        """Standard uncertainty (m) of the ratio at contact points ``x_c`` (m, any shape) from the
        cross-talk of a sensor no calibration has measured for the hold's push: a force read
        c x_c R_perp too high moves the ratio by about c x_c^2
        (:meth:`.SensorCorrection.coupling_uncertainty`). The push's direction is the one the
        sensor reads, which the leak itself may tilt, or the head's turn from where the push
        began to t_1 (:attr:`push_turn`), whichever gives the larger c."""
        sensor = self.antenna.sensor
        _, move = self.push_turn
        coupling = max(
            sensor.coupling_uncertainty(self.frame.reaction_m), sensor.coupling_uncertainty(move)
        )
        return np.asarray(coupling * np.square(x_c), dtype=float)

    def axial_cross_talk_uncertainty(self, x_c: FloatArray) -> FloatArray:
        """Standard uncertainty (m) of the elastica's ratio at contact points ``x_c`` (m, any
        shape) from the cross-talk of the moments into the force along the link, which no
        calibration here measures (:mod:`~sensing_antenna.calibration.sensor` fits the lateral
        forces' terms). The statics read x_c = (Gamma' + y_c R_x) / |R_perp|, so an axial force
        read c Gamma' off moves the ratio by c y_c x_c = c d x_c^2, d the push's y_c / x_c
        (:meth:`push_deflection_ratio`), c the sensor's ``nominal_coupling``: with the default
        c, 1.5 and 4.5 cm at 0.6 and 0.9 m for the paper antenna's own pushes (8 to 10 %), a
        third of that at an identified observer's 3 %, and many cm at a third of x_c, where a
        calibration made at gentle pushes has absorbed only its own push's share into the
        lateral terms (its ``ratio_scatter`` holds that share)."""
        x_c = np.asarray(x_c, dtype=float)
        coupling = self.antenna.sensor.nominal_coupling
        return np.asarray(coupling * self.push_deflection_ratio(x_c) * np.square(x_c), dtype=float)

    def bent_link_uncertainty(self, x_c: float) -> float:
        """Standard uncertainty (m) of a contact point read from the vibration, from the push's
        deflection alone: ``bent_link_factor`` d^2 x_c, d = |R_perp| x_c^2 / (3 E I).

        The sensing curves are those of the straight link. A push that bends the link also
        loads it along its bent axis (the reaction tilts with the link's slope), which shifts
        its contact frequencies at second order in the deflection: on the rod recordings a
        push deflecting the contact by 22 % of x_c = 0.30 m put the frequency's candidate
        0.8 cm from the contact (d = 0.24: 0.6 d^2 x_c = 1.0 cm). Small at gentle pushes
        (0.5 mm at d = 0.03, x_c = 1 m); 2 mm at the default push at 0.6 m (d = 0.075).
        """
        if not math.isfinite(x_c):
            return math.inf
        return float(self.bent_link_uncertainties(np.array(x_c)))

    def bent_link_uncertainties(self, x_c: FloatArray) -> FloatArray:
        """:meth:`bent_link_uncertainty` at contact points ``x_c`` (m, any shape, finite)."""
        x_c = np.clip(np.asarray(x_c, dtype=float), 0.0, self.antenna.link.length)
        deflection_ratio = self.push_deflection_ratio(x_c)
        return np.asarray(self.config.bent_link_factor * deflection_ratio**2 * x_c, dtype=float)

    def push_deflection_ratio(self, x_c: FloatArray | float) -> FloatArray:
        """d = |R_perp| x_c^2 / (3 E I) (dimensionless, the shape of ``x_c``): the hold's push
        deflection over x_c (m) by the linear statics, as :meth:`bent_link_uncertainty` reads
        it."""
        x_c = np.asarray(x_c, dtype=float)
        return np.asarray(
            self.frame.lateral_force * x_c**2 * self.antenna.link.bending_compliance / 3.0
        )

    def payload_mass(self) -> float:
        """Tip mass (kg) the link's weight at rest reads beyond the model's, 0 when none.

        Before the contact the loads are the link's weight, which the model removes
        (``load_offset`` is what remains: the sensor's offset after taring, a few counts). A
        moment about Y^m left over beyond what such an offset can be
        (:func:`~sensing_antenna.units_check.is_payload`) is weight the model does not carry,
        most often a payload at the tip (glue, a marker): m_t = excess / (g l cos theta_2). A
        lighter reading is no payload (an offset weighs nothing); loads not in the format's
        units and an elevation beyond 60 deg (the lever's cosine below a half) say nothing of
        one; a tare read over the approach holds the head's motion too (see
        :meth:`payload_shifts`).
        """
        from sensing_antenna.units_check import is_payload, rest_moment_std

        if self.input_problem is not None:
            return 0.0
        cosine = math.cos(float(self.theta[0, 1]))
        if not cosine >= _PAYLOAD_COSINE:
            return 0.0  # near a vertical link the weight's moment says little of a mass
        excess = float(self.load_offset[4])
        noise = float(self.diagnostics.get("torque_noise", 0.0))
        std = rest_moment_std(noise, self.torque_offset_error)
        if not (excess > 0.0 and is_payload(excess, std)):
            return 0.0
        return self.antenna.link.tip_mass_for_moment(excess, self.theta[0, 1])

    def carried_payload_mass(self) -> float:
        """:meth:`payload_mass` as the fast method carries it (kg): 0 when the tare was read
        over the approach, whose loads hold the head's motion, which the reading cannot tell
        from weight (the plausibility layer's payload check words that case)."""
        return self.payload_mass() if self.tare != "approach" else 0.0

    def payload_shifts(self, x_c: FloatArray) -> FloatArray:
        """How much lower (rad/s) omega_1 rings at contact points ``x_c`` (m, shape (G,)) on a
        link carrying :meth:`payload_mass` at its tip than on the model's: what the sensing
        curve leaves out of a vibration read at ``x_c``; zeros without a payload, with one read
        over an approach's tare, or with one more than the link could carry (the plausibility
        layer names those)."""
        x_c = np.asarray(x_c, dtype=float)
        mass = self.carried_payload_mass()
        if not mass > 0.0:
            return np.zeros(x_c.shape)
        # an online session asks at every window with the same grid and mass: computed once
        shifts = _payload_shifts(self.antenna.link, mass, x_c.tobytes(), x_c.shape)
        return np.array(shifts, dtype=float)
