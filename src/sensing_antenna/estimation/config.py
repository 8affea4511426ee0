"""Every tunable of the contact-point pipeline, with its unit and the reason for its default.

Variants are made with :func:`dataclasses.replace`; a config is validated when built.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Literal

from sensing_antenna.detection.push import PushCriterion
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.recording import CLOCK_TOLERANCE

__all__ = [
    "MAX_GAP_DURATION",
    "PAPER_SPECTRUM_WINDOW",
    "EstimatorConfig",
    "EstimatorConfigError",
    "no_t1_reason",
    "periods_in",
]

#: Longest run of missing samples (s) filled in on a straight line inside [t_c, t_e] by default:
#: 20 samples at 1 kHz, as many as the corrupted samples in a row the front end puts back
#: (:data:`.front.spikes.SPIKE_DURATION`). A fiftieth of the spectrum window and a tenth of the
#: 0.2 s hold, the shortest record ``fast`` answers from; measured by
#: ``benchmarks/eval_glitches.py --kinds drop``. Held in time, not samples: at 250 Hz twenty
#: samples span 80 ms, three periods of the band's top.
MAX_GAP_DURATION = 0.02

#: Delta t_e1 of Section 5.4 (s): the record after t_1 the paper's Estimator 1 reads.
PAPER_SPECTRUM_WINDOW = 1.0


class EstimatorConfigError(SensingAntennaError, ValueError):
    """An estimator setting is out of range; the message names the field."""


@dataclass(frozen=True)
class EstimatorConfig:
    """Settings of the estimation pipeline (SI units).

    Parameters
    ----------
    t1_source : {"rest", "push"}
        How t_1 is found. ``"rest"`` (default): the instant the head comes to rest after the
        contact, read from the angles, which works on any recording whatever push criterion
        stopped its motors. ``"push"``: the push criterion's own decision (``push_criterion``,
        Section 4 step 4), as the controller that stops the motors takes it; use it when the
        recording comes from a device whose stop rule is that criterion. Both forms (batch and
        streaming) use the same rule, so they stay identical.
    push_criterion : PushCriterion or None
        The criterion for ``t1_source = "push"``; None: ``PushCriterion()``.
    rest_window : float
        Offline t_1 (s): the head is at rest at t_1 when, for this long after t_1, neither motor
        angle moves by more than the rest tolerance. 50 ms is 2.5 % of the slowest contact
        vibration period and 10 time constants of the paper's servo (poles of Eq. 14 are fast),
        long enough not to mistake a slow crossing of a turning point for rest.
    rest_angle_tolerance : float
        Floor of the rest tolerance (rad, peak-to-peak over ``rest_window``). 1e-4 rad is 0.1 mm
        at the tip of a 1 m link, while a head still pushing at 0.01 rad/s moves 5e-4 rad in
        50 ms.
    rest_noise_factor : float
        The rest tolerance is at least this many times the angle noise estimated from the
        recording (robust standard deviation of second differences), so encoder noise alone never
        prevents rest. 8 sigma peak-to-peak over 50 samples is exceeded by Gaussian noise with
        probability below 1e-6.
    tare_margin : float
        When the recording does not start at rest, the sensor offset is the mean contact load over
        the approach up to this long before t_c (s). 0.3 s: at gentle pushes the torque takes
        over 0.1 s from the touch to the contact threshold, and the link's free vibration
        (16.4 rad/s) averages out over the approach.
    frame_window : float
        Hold window (s) after t_1 over which the static push is judged and the contact frame
        built from the mean reaction and angles. 0.2 s: near the tip the link rebounds on the
        obstacle for 0.1 to 0.45 s after the stop (a preload of 8 mN against the impact), so the
        force at one instant can be near zero while the static push is not; 0.2 s holds one
        period of the slowest contact vibration (31 rad/s), which then averages out, and ends
        before the first convergence test of the ratio (t_1 + 2 convergence_window) needs it.
    min_push_significance : float
        A push counts when the mean perpendicular reaction over the hold exceeds this many
        standard errors of that mean (sigma_F / sqrt(N), sigma_F measured in the recording).
        The magnitude of a two-component Gaussian mean with no push exceeds k standard errors
        with probability exp(-k^2 / 2): 4e-6 for 5.
    loss_window : float
        Length (s) of the short means in which contact losses (rebounds) are looked for in the
        hold; 10 ms is a quarter of the fastest rebound seen on the simulator (40 ms).
    loss_significance : float
        A short mean of the reaction along the push below this many of its standard errors is a
        contact loss (reported in the diagnostics); 3 standard errors.
    max_gap : int or None
        Largest number of consecutive missing samples inside [t_c, t_e] that linear
        interpolation may fill; longer gaps give ``bad_input``. None (the default): as many as
        span :data:`MAX_GAP_DURATION` at the recording's sample period (:meth:`gap_limit`).
    spectrum_window : float or None
        Delta t_e1 (s), the record after t_1 analysed by Estimator 1. The paper's 1 s
        (:data:`PAPER_SPECTRUM_WINDOW`) holds 5 periods of the lowest fundamental of its tested
        range (31 rad/s at 0.3 m, period 0.2 s) and gives a DFT bin of 6.3 rad/s that zero
        padding and interpolation refine far below the bin. None (the default): 1 s, or, for a
        link whose lowest fundamental over the contact range lies below the lowest the paper
        link's band searches (with ``band_margin``), as much longer as it holds fewer of its
        periods (:func:`~sensing_antenna.estimation.front.evidence.spectrum_window`): the
        touch's transients and the head's settling last periods of the link, not seconds.
    zero_padding : int
        The spectrum is computed on ``zero_padding`` times the window length (power of two above),
        so that the parabolic peak interpolation has a negligible bias (< 1e-3 bin at 16).
    contact_range : tuple of float
        Fractions of the link length (min, max) where a contact is searched for; (0.2, 1.0)
        covers the paper's tested range 0.3 to 0.98 m with room below.
    band_margin : float
        Relative margin added on both sides of the omega_1 band the sensing curve allows, for
        calibration error; 0.15 covers the 7 % T vs T_e difference of Section 5.1 twice.
    min_peak_quality : float
        A spectral peak is clear when its power exceeds this many times the median power of the
        band (13 dB). A white-noise bin exceeds 20 times the median power with probability
        exp(-20 ln 2) ~ 1e-6, so about 1e-3 over the ~250 independent bins of the band and the
        three spectra examined; real contact peaks reach 1e3 and more.
    component_agreement : float
        Relative tolerance between the peaks found in the two perpendicular torque components
        (when both are clear); beyond it the diagnostics flag the disagreement. 0.05 is several
        times the interpolation error of a clear peak.
    lowpass_cutoff : float
        omega_c of the Eq. 20 low-pass filter (rad/s); 5 rad/s as in Section 5.1, six times below
        the lowest fundamental.
    convergence_window : float
        Estimator 2 has converged at t when the ratio stayed within ``convergence_tolerance`` over
        [t - window, t] (s). 0.2 s is one filter time constant 1 / omega_c and one period of the
        slowest vibration.
    convergence_tolerance : float
        Peak-to-peak band of the converged ratio (m); 1 cm is the paper's typical accuracy.
    max_ratio_wait : float
        If the ratio has not converged this long after t_1 (s), the estimate is given with
        ``slip_suspected``; 3 s is 15 filter time constants.
    disagreement_sigmas : float
        The chosen frequency candidate and the ratio estimate disagree when they are more than
        this many standard uncertainties apart (``Evidence.ratio_uncertainty``: force noise
        through Eq. 20, residual sensor offset, statics model; with the candidate's
        ``Evidence.bent_link_uncertainty``). 3: a
        Gaussian exceeds 3 sigma with probability 0.27 %, and the model term is an upper bound
        (noise-free simulator: 0.7 of it at x_c = 0.9 m, vertical). With 4, a 7 % error of T
        (x_c = 0.266 m for 0.299 m, ratio 0.299 m +- 0.95 cm) passed as ok.
    ratio_resolution_sigmas : float
        The ratio chooses between two frequency candidates only when it is this many of its
        standard uncertainties closer to one than to the other; otherwise the second mode
        decides if it is clear. 2 (a wrong choice with probability about 2 % on a Gaussian).
    ratio_model_factor : float
        Coefficient of the model term factor (y_c / x_c) x_c of the ratio uncertainty
        (``Evidence.ratio_uncertainty``). For Eq. 21 as printed (the ``ratio`` baseline) the
        neglected moments are the axial force times the link's slope (1.5 y_c / x_c, Eq. 9,
        times R_x / R_perp up to the friction coefficient 0.6) and the weight of the bent link;
        1.0 bounds 1.5 x 0.6 = 0.9. For the elastica's statics (the front end's ratio), which
        take the link's weight off to first order, what those terms leave
        (:func:`~sensing_antenna.beam.weight.weight_residual`, set against an exact solution):
        1.0 takes it whole.
    ratio_model_floor : float
        Relative floor of the elastica statics' model term of the ratio uncertainty
        (``Evidence.ratio_uncertainty``): what no statics here holds, the contact's own size
        and compliance, dynamic loads left in the ratio's mean. 1 % of x_c, the paper's typical
        accuracy: the ratio read on the rod recordings lies within 0.02 to 0.9 cm of the
        contact at pushes of 22 to 33 % deflection, and 1.5 mm from it at 0.3 m on the default
        campaign at a quarter of its noise.
    bent_link_factor : float
        Coefficient of the uncertainty a push's deflection adds to a contact point read from
        the vibration, factor (y_c / x_c)^2 x_c (``Evidence.bent_link_uncertainty``): the
        sensing curves are the straight link's, and the preload of the bent link shifts the
        frequencies at second order (and, where friction holds the contact along the bent
        link, at first order in the push). 0.6 bounds what the rod recordings show at a hard
        push (0.8 cm at 22 % deflection, x_c = 0.3 m, against 1.0 cm); at their default push
        (8 to 10 %) the rod's contacts at 0.6 to 0.9 m lie 1.3 of it away (rms). The fast
        method's posterior carries it as the frequency's standard uncertainty at every x_c. The
        paper method charges it, at two standard deviations, to the status of a frequency read
        in the push plane alone (``max_model_spread``); beyond ``max_model_spread`` itself it
        makes every answer read from the vibration ``uncertain``, in whichever plane, but for
        the paper method's reading of the free plane's own mode, judged on that plane's own
        bound (``beam.free_plane_shift``; the plausibility layer); a push plane that rings
        apart from the free one is judged by the ratio
        (:mod:`~sensing_antenna.estimation.methods.paper.planes`). 0: a link whose
        frequencies do not move with the push (the simulator's linear link).
    omega2_window : float
        Relative half-width of the search window around each candidate's predicted omega_2;
        0.05 is a quarter of the 20 % gap between the candidates' omega_2 at the curve's top.
    max_friction_ratio : float
        Plausibility (``slip_suspected``): the largest ratio of the reaction's part along the
        link's tangent at the contact to its part along the contact normal that friction can
        hold still (mu). The tangent is the elastica's at the answer
        (:mod:`sensing_antenna.beam.elastica`); a point contact on the link's side has its
        normal across the tangent. Dry friction of metals, plastics, wood and stone on each
        other lies below 1 (rubber excepted): 1.0, a cone of 45 deg. A reaction outside the
        cone by more than 3 of its standard errors cannot be a contact at rest: it slides, or
        it is not a point contact on the link's side.
    max_direction_drift : float or None
        Largest angle (rad) about the link's axis between the hold's push direction and the
        filtered contact force across the link over the last ``convergence_window`` before t_e,
        before a slip over the obstacle is suspected; None (the default): not judged. A contact
        that slides across the link, round the object, turns the force but moves neither x_c
        nor the point placed at its instant (docs/design-notes.md, "The direction check
        switched off").
    max_ratio_drift : float
        Largest change (m) of the filtered ratio over the last ``convergence_window`` before t_e
        tolerated as a steady hold; beyond it the contact is drifting (slip). 2 cm.
    min_nyquist_factor : float
        The Nyquist frequency pi / T_s must exceed this factor times the top of the omega_1 band;
        below it the recording cannot show the vibration (bad_input). 2 keeps the peak away from
        the anti-aliasing roll-off.
    max_scale_mismatch : float
        Plausibility (``model_mismatch``): the torque/force ratio and the answer must lie within
        this factor of the contact point the vibration gives (the nearest point of the sensing
        curve with the measured omega_1), unless ``disagreement_sigmas`` of the ratio's
        uncertainty cover the difference. A unit or scale error of the forces or torques is a
        factor 2 or more (doubled, halved, 10^3), while on the default campaign, noise sweep
        included (four times the nominal noise), the ratio lies within 0.87 to 1.16 times that
        point. 1.5 sits between.
    max_model_spread : float
        The paper method's answer is ``uncertain`` when the frequency model's own uncertainty
        (``Link.frequency_uncertainty``: 5 % for a link known from its material data, the
        calibration's scatter once calibrated) moves the chosen candidate by more than this at
        two standard deviations (m), and the ratio method's when the ratio's uncertainty
        (``Evidence.ratio_uncertainty``) exceeds it at two standard deviations; the plausibility
        layer's payload check uses the same bar. 1 cm, the paper's typical accuracy (Tables 3
        and 4).
    free_motion_gain_factor : float
        Plausibility (``implausible_input``): the torque of the free motion before t_c must be
        at least 1 / this factor of what the observer predicts from the angles (root-mean-square
        ratio, :func:`~.front.steps.free_motion_gain`). Angles in degrees give 1/57, or about
        1/8 when the 57-fold prediction fires the contact detector within the first tens of
        milliseconds of motion (an identified observer's low threshold); the simulated device
        gives 0.8 to 3 with the paper's observer (the touch adds torque before t_c) and 1.0 with
        an identified one. 5 sits between. The same factor judges each joint's share on its
        own (:func:`~.front.steps.joint_free_motion_gains`: an angle column copied from the
        other joint's).
    still_turn_factor : float
        Plausibility (``implausible_input``): before t_c, with neither angle leaving the rest
        tolerance, the torque about Y^m and Z^m (weight and mean taken off) may vary by at most
        this many times the sensor's white noise (root mean square,
        :func:`~.front.steps.still_angles_turn`): a head at rest reads about 1 (its noise), a
        sensor's cross-talk from a turning axis a little more, a sweep's start on the turning
        axis an order of magnitude more (docs/design-notes.md, "A still joint's angle over the
        turning one"). 8 sits between.
    max_curve_distance : float
        The ``two-frequency`` method's answer is a ``model_mismatch`` when the measured
        (omega_1, omega_2) lie farther than this from the nearest point of the straight link's
        (omega_1, omega_2) curve (relative distance, dimensionless): no contact point of the
        model rings so. 5 %: the pair lies within 2 % of the curve on gentle pushes of the
        calibrated realistic simulated device (median 0.2 %), and 37 to 40 % off it when a
        push bends the link by a third of x_c.
    mode_ratio_uncertainty : float
        Plausibility (``model_mismatch``): the relative standard uncertainty with which the
        model's omega_2 / omega_1 at a contact point is taken to hold on a device. T does not
        enter that ratio (a calibration of T_e leaves it as it is), so where it and the statics
        agree on a point the answer's omega_1 puts far from both, the model's omega_1 is off
        there: a wrong T, or time stamps on another clock. 2 %: the ratio lies within 2 % of
        the model's on the independent rod engine's recordings, on a tapered, jointed or
        compliantly clamped simulated device, and on the calibrated realistic one's gentle
        pushes; an unknown payload moves it more, which its own check names.
    max_deflection_ratio : float
        An answer at which the measured push would bend the link by more than this fraction of
        x_c (y_c / x_c) is ``uncertain``: the statics and the frequencies of a link bent so far
        were checked against no independent reference (the rod engine's recordings reach 33 %),
        and a wrong answer far out on the link reads a push as such a bend. 0.4.
    max_bend_per_turn : float
        Plausibility (``model_mismatch``): how far the link's bend along the push from t_c to
        t_e (the elastica's y_c at the answer from the measured reaction and the model's
        stiffness) may lie outside what the head's turn into the object makes. A contact that
        sticks bends the link exactly as far as the rigid link's point x_c moved against the
        push; one sliding over a flat surface with friction up to ``max_friction_ratio``, at an
        angle phi between the push and that motion, between 1 - mu tan(phi) times as far and
        as far (a convex surface allows a little more, docs/estimation.md). The bend
        may lie up to this factor above the band or below it: 1.6 covers a calibrated
        sensor's residual cross-talk and a stiffness known to a few percent. Beyond it: forces
        that read high or low (an uncalibrated sensor), a link stiffer than the model, angles
        that do not describe the head's turn, or an answer off the contact (the ratio moves
        as the square of x_c over the contact's).
    min_work_share, input_work_share : float
        Plausibility: the work the head's turn did against the contact's moment, counted from
        ``tare_margin`` before t_c to t_e, against the energy the push stored in the link
        meanwhile (what it holds at t_e less what it held where the count starts), bent at the
        lesser of the answer and the torque/force ratio (linear statics, the model's E I). The
        obstacle and the link only store or dissipate what the head puts in: a contact that
        sticks takes the share 1, less the link's kinetic energy at the sweep's speed (a few
        %); one that slides, a compliant clamp or obstacle, more; a link stiffer than the
        model by a factor f, or torques read f times high, 1 / f. Below ``min_work_share``
        (0.5) the estimate is ``model_mismatch``. Angles or torque axes swapped put the push's
        moment across the turn, a share near 0, and torques in N dm or a smaller unit take a
        tenth or less: below ``input_work_share`` (0.2) it is ``implausible_input``.
    """

    t1_source: Literal["rest", "push"] = "rest"
    push_criterion: PushCriterion | None = None
    rest_window: float = 0.05
    rest_angle_tolerance: float = 1.0e-4
    rest_noise_factor: float = 8.0
    tare_margin: float = 0.3
    frame_window: float = 0.2
    min_push_significance: float = 5.0
    loss_window: float = 0.01
    loss_significance: float = 3.0
    max_gap: int | None = None
    spectrum_window: float | None = None
    zero_padding: int = 16
    contact_range: tuple[float, float] = (0.2, 1.0)
    band_margin: float = 0.15
    min_peak_quality: float = 20.0
    component_agreement: float = 0.05
    lowpass_cutoff: float = 5.0
    convergence_window: float = 0.2
    convergence_tolerance: float = 0.01
    max_ratio_wait: float = 3.0
    disagreement_sigmas: float = 3.0
    ratio_resolution_sigmas: float = 2.0
    ratio_model_factor: float = 1.0
    omega2_window: float = 0.05
    max_friction_ratio: float = 1.0
    bent_link_factor: float = 0.6
    ratio_model_floor: float = 0.01
    max_direction_drift: float | None = None
    max_ratio_drift: float = 0.02
    min_nyquist_factor: float = 2.0
    max_scale_mismatch: float = 1.5
    max_model_spread: float = 0.01
    free_motion_gain_factor: float = 5.0
    still_turn_factor: float = 8.0
    max_curve_distance: float = 0.05
    mode_ratio_uncertainty: float = 0.02
    max_deflection_ratio: float = 0.4
    max_bend_per_turn: float = 1.6
    min_work_share: float = 0.5
    input_work_share: float = 0.2

    def __post_init__(self) -> None:
        if self.t1_source not in ("rest", "push"):
            raise EstimatorConfigError(
                f"t1_source: must be 'rest' or 'push', got {self.t1_source!r}"
            )
        if self.push_criterion is not None and not isinstance(self.push_criterion, PushCriterion):
            raise EstimatorConfigError(
                f"push_criterion: must be a PushCriterion or None, got {self.push_criterion!r}"
            )
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name in ("t1_source", "push_criterion"):
                continue
            if f.name == "contact_range":
                low, high = value
                if not (0.0 <= low < high <= 1.0):
                    raise EstimatorConfigError(
                        f"contact_range: must satisfy 0 <= min < max <= 1, got {value!r}"
                    )
                continue
            if f.name == "bent_link_factor":
                if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                    raise EstimatorConfigError(
                        f"{f.name}: must be a finite number >= 0, got {value!r}"
                    )
                continue
            if f.name in ("max_gap", "max_direction_drift", "spectrum_window") and value is None:
                continue
            if f.name in ("zero_padding", "max_gap"):
                if not (isinstance(value, int) and not isinstance(value, bool) and value >= 1):
                    raise EstimatorConfigError(f"{f.name}: must be an integer >= 1, got {value!r}")
                continue
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise EstimatorConfigError(f"{f.name}: must be a finite number > 0, got {value!r}")
        for name in ("max_scale_mismatch", "free_motion_gain_factor", "still_turn_factor"):
            if getattr(self, name) <= 1.0:
                raise EstimatorConfigError(
                    f"{name}: must be a factor > 1, got {getattr(self, name)!r}"
                )
        if self.rest_window > self.convergence_window:
            raise EstimatorConfigError(
                "rest_window: must not exceed convergence_window (t_1 is known rest_window "
                "after it, before the first ratio window closes)"
            )
        if self.frame_window > self.convergence_window:
            raise EstimatorConfigError(
                "frame_window: must not exceed convergence_window (the ratio's tolerance needs "
                "the hold's push before the first convergence test)"
            )
        if self.max_ratio_wait < self.convergence_window:
            raise EstimatorConfigError("max_ratio_wait: must be >= convergence_window")
        if self.input_work_share > self.min_work_share:
            raise EstimatorConfigError(
                "input_work_share: must not exceed min_work_share (a share too low for a "
                "mismatched model is too low for the samples' units)"
            )

    def gap_limit(self, sample_period: float) -> int:
        """Most missing samples in a row filled in at ``sample_period`` (s): ``max_gap``, or
        as many as span :data:`MAX_GAP_DURATION` (at least one) on a clock that may run
        :data:`~sensing_antenna.recording.CLOCK_TOLERANCE` slow (a 1 kHz sensor whose stamps
        say 999.995 Hz fills 20)."""
        if self.max_gap is not None:
            return self.max_gap
        return max(1, periods_in(MAX_GAP_DURATION * (1.0 + CLOCK_TOLERANCE), sample_period))


def periods_in(duration: float, sample_period: float) -> int:
    """Whole sample periods in ``duration`` (s) at ``sample_period`` (s); a duration set as a
    whole number of periods counts them all despite the division's rounding."""
    return math.floor(duration / sample_period + 1e-9)


def no_t1_reason(config: EstimatorConfig, rest_tolerance: float) -> str:
    """Why t_1 was not found after t_c, in words, for either ``t1_source``."""
    if config.t1_source == "push":
        rule = config.push_criterion or PushCriterion()
        return (
            f"the push criterion ({rule.kind} above {rule.threshold:g} {rule.unit}) is never "
            "met after t_c"
        )
    return (
        f"the head never came to rest after t_c (angles within {rest_tolerance:.2g} rad for "
        f"{config.rest_window:g} s)"
    )
