"""``--method fast``: the contact point from a short record, declared as soon as it is sure.

The paper (Section 7) leaves reducing the estimation time as future work: its Estimator 1 needs a
1 s spectrum and its Estimator 2 a settled 5 rad/s low-pass filter. Here, on a window that grows
from t_1:

1. the five contact-load channels (R_y, R_z, Gamma - Gamma_g^m; gravity removed as in Eq. 21,
   sensor bias from the initial rest removed, :mod:`.static_fit`) are fitted with damped
   sinusoids with shared poles plus a polynomial of degree 2 to 4 (:mod:`.parametric`, order and
   degree by BIC): omega_1 with its standard error (widened by its drift between the window and
   its first 2/3), and the static loads with their covariance, without filter lag;
2. the torque/force ratio of the static loads gives x_c with its standard error;
3. both become a posterior over x_c on a 0.25 mm grid (:mod:`.likelihood`);
4. the estimate is declared at the first evaluation whose 95 % interval is narrower than
   ``tolerance`` and where the ratio agrees with it. Evaluations run on a geometric grid
   (:func:`evaluation_offsets`) from ``first_window`` (50 ms) after t_1, so t_e adapts to how
   easy the case is; at ``cap`` (1 s) after t_1 the best estimate is given with status
   ``uncertain``. Whenever the posterior is split between two branches of omega_1(x_c), the
   second contact mode may choose one (:func:`second_mode_chooser`).

Every evaluation uses the samples up to its own instant only, so the streaming form (the
pipeline's ``OnlineEstimator`` asking a :class:`FastSession`'s ``due`` and ``ready`` at every
sample) and the batch form (:class:`FastMethod` in ``estimate``, or :func:`scan`) declare at the
same sample with the same numbers. Fed in blocks (``OnlineEstimator.update_block``), the
streaming form asks at each block's last evaluation instant only.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, fields
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Link
from sensing_antenna.beam import contact_to_base_shear, natural_frequencies
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.estimation.front.evidence import Evidence, sensing_curve
from sensing_antenna.estimation.methods.fast.likelihood import ContactPosterior, contact_posterior
from sensing_antenna.estimation.methods.fast.parametric import (
    DampedSinusoidFit,
    first_poles,
    select_model,
)
from sensing_antenna.estimation.methods.fast.static_fit import (
    SensorBias,
    StaticRatio,
    contact_channels,
    sensor_bias,
    static_ratio,
)
from sensing_antenna.estimation.methods.paper.frequency import evidence_frequency
from sensing_antenna.estimation.methods.paper.fusion import predicted_omega2, second_mode_choice
from sensing_antenna.estimation.methods.touch_point import touched_point
from sensing_antenna.estimation.result import STATUS_PRECEDENCE, ContactEstimate, Status

__all__ = [
    "CurveTable",
    "FastConfig",
    "FastConfigError",
    "FastMethod",
    "FastSession",
    "PushPhase",
    "ScanInputs",
    "ScanResult",
    "WindowEstimate",
    "curve_table",
    "evaluate_from_t1_or_hold",
    "evaluate_window",
    "evaluations",
    "model_floor",
    "push_phase",
    "scan",
]

FloatArray = NDArray[np.float64]


class FastConfigError(SensingAntennaError, ValueError):
    """A setting of the fast method is out of range; the message names the field."""


#: Largest relative distance (dimensionless) between the fundamental of the slip check's half
#: window and the whole window's for the two to be the same mode. 0.1: short windows read
#: omega_1 up to about 2 % off (docs/fast.md, "Three modes"), and 0.2 to 1.5 % off at 3 to 7 of
#: their standard errors on the half windows of the paper antenna (so no test in standard
#: errors); the nearest other contact mode is at least 2.2 times omega_1, and the mode that
#: once took the fundamental's place was 53 % off.
_SAME_MODE = 0.1


@dataclass(frozen=True)
class FastConfig:
    """Settings of the fast method (SI units).

    Parameters
    ----------
    tolerance : float
        Declare when the 95 % interval of x_c is narrower than this (m). 5 mm, half the paper's
        typical 1 cm error.
    cadence : float
        Shortest time between evaluations of the growing window (s). 10 ms.
    growth : float
        Evaluations are spaced by the larger of ``cadence`` and (growth - 1) times the window
        length, a geometric grid: the declaration is late by at most 10 % of t_e - t_1, and
        the window at about 2/3 (and 1/2) of every window is itself on the grid, so the drift
        check below reuses it. 1.1: 17 evaluations between 0.2 s and 1 s.
    first_window : float
        First evaluation this long after t_1 (s). 50 ms, about one period of the fastest
        fundamental in the range.
    cap : float
        Last evaluation this long after t_1 (s); if still unsure, the estimate is given with
        status ``uncertain``. 1 s, the record of the paper's spectrum: an unsure case is never
        later than the paper method in data time and has at least its information.
    drift_factor : float
        Non-stationarity of omega_1 measured on the recording itself: the fundamental of the
        window [t_1, t] is compared with that of [t_1, t_1 + 2/3 (t - t_1)]; ``drift_factor``
        times the change (its excess over what the noise alone explains, sqrt(max(0, d^2 -
        (se_short^2 - se^2)))) is added in quadrature to the standard error. 2: an error that falls
        as 1 / T_w (the leakage of a close unmodelled mode, a slow transient) is at T_w twice
        its change from 2/3 T_w to T_w. Near the peak of omega_1(x_c) on the simulator a close
        mode biased 0.3 s windows by 1.6 % and 1 s windows by 0.15 %, far beyond the white-noise
        standard error (docs/fast.md). The check measures such leakage on the record itself;
        the fixed floor proportional to 2 pi / T_w that once stood for it was removed
        (docs/fast.md, "Posterior and floors").
    min_periods : float
        The window must hold this many periods of the fitted fundamental before an estimate can
        be declared (a shorter record cannot tell a frequency from a drift), and so must the
        drift check's window of 2/3 the length (so at least 2.25 periods in all). 1.5.
    min_detection : float
        The fundamental is used only when its detection statistic, the amplitude at the window
        start over the noise (combined over channels) times sqrt(n / 2), reaches this value. For
        white noise the largest of ~n / 2 independent periodogram ordinates reaches about
        sqrt(2 ln n) ~ 3.7 standard deviations; 10 leaves no room for a noise peak.
    max_modes : int
        Largest number of damped modes tried (BIC chooses 1 .. max_modes). 3: the fundamental
        and the two strongest modes above it. The touch and the stop excite contact modes 2
        and 3 and modes of the link moving along the surface (calibrated-device campaign,
        vertical 0.5 m: fitted at 50, 395 and 430 rad/s over 0.2 s after t_1, the two upper
        ones the stronger; contact mode 3 is at 437 rad/s). With room for one of them only,
        short windows read omega_1 up to 2 % high (50.9 against 49.7 rad/s at 0.215 s; 50.1
        with three modes) and the drift check held them back. Against 2 (docs/fast.md, "Three
        modes"): median t_e - t_1 0.421 to 0.383 s on the calibrated-device campaign and 0.316
        to 0.302 s on the paper antenna, MAE 0.73 to 0.65 mm and 0.37 to 0.23 mm, coverage
        149/150 on the campaign as before. It costs 1.5 to 1.8 times the CPU; with the
        compiled fit the real-time loop of a two-core machine answers 0.43 to 0.46 s after
        t_1 (docs/fast.md, "Online, in real time").
    min_mode_fraction : float
        Modes are fitted above this fraction of the lower end of the omega_1 band; slower content
        (the servo's slow creep at ~8 rad/s) goes to the polynomial. 0.6 of ~23 rad/s.
    polynomial_degree : int
        Highest degree of the static polynomial per channel; the BIC chooses it from 2 up to
        this together with the number of modes. 4: the servo's slow creep (~8 rad/s) spans up
        to 0.8 rad of its cycle over the longest window; with degree 2 the fitted omega_1 at
        x_c = 0.3 m wandered by 1.5 % between windows of 0.3 and 0.6 s (simulated recordings,
        well beyond its standard error), with degree 4 by 0.1 %. On short windows a quartic
        takes up part of the vibration itself (at 0.55 m, a 0.215 s window: standard error
        2.9 rad/s with degree 4, 0.56 with degree 2), which the BIC sees.
    frequency_floor : float
        Relative model error of omega_1 added in quadrature (dimensionless): how well T (or
        T_e) and the sensing curve predict the frequency. 0.001: the link's sensing curve and
        the frequencies of the finite-element simulator with a compliant contact differ by 0.01
        to 0.12 % over the azimuthal grid (1 s spectrum on noiseless recordings, see
        docs/fast.md). A link whose calibration measured a larger relative scatter
        (``Link.calibration_scatter``) uses that instead: on the simulated device with a
        contact three times softer the calibration residuals reached 0.46 % near the tip.
    ratio_geometry_factor : float
        kappa of the ratio's model floor kappa (y_c / x_c) x_c (dimensionless). 0.5: the
        neglected torque of the axial force on the deflection is (y_c / x_c)(R_x / R_perp) x_c,
        with R_x / R_perp up to the friction coefficient (0.6), and the shortening of the bent
        link is of the same order.
    grid_step : float
        Spacing of the x_c grid of the posterior (m). 0.25 mm, a twentieth of the tolerance.
    bias_min_samples : int
        Samples of initial rest needed to estimate the sensor bias; 20 (20 ms).
    bias_guard : float
        Time (s) of the initial rest left out before the head is seen to move: the sweep's start
        loads the sensor (inertia) while the angles are still within the rest tolerance. 0.05 s:
        on the simulated device the loads leave the rest 60 ms before the move is seen (1e-6
        N m then, 5e-5 N m 10 ms before it), which biased the rest mean by 2 to 3 standard
        errors in Gamma_z (azimuthal) without the guard.
    peak_margin : float
        No declaration while omega_1 is less than this many standard deviations below the
        maximum of the sensing curve (the interval there rests on the curve's flat top). 3: in
        the simulator a 0.12 s window at x_c = 0.80 m read omega_1 0.5 % high and the interval
        collapsed onto the peak, 27 mm from the truth.
    max_disagreement : float
        Largest distance, in the ratio's standard deviations (model floor included), between the
        torque/force ratio and the maximum a posteriori x_c before the two estimators are said
        to disagree; no declaration while they do. 3. The posterior weighs both, but where one
        of them is wrong (the fundamental of a chattering tip contact read 1.7 % low on a
        0.29 s window) the product can still be narrow on the wrong branch: 3 of 150 campaign
        runs at 0.98 m were declared at 0.62 m, 3.4 ratio deviations from the ratio.
    max_direction_drift : float
        Largest angle (rad) between the fitted static perpendicular reaction of the window's
        first half from t_1 (``WindowEstimate.early_statics``) and that of the whole window at
        t_e (both with the sensor bias removed) before a slip is suspected, or 3 standard
        errors of that angle when larger; 0.15 rad as the pipeline's ``max_direction_drift``.
    max_opening : float
        Largest predicted vibration of the contact force over the static push at the window
        start. The obstacle can only push: when the fundamental's contact force (its base-force
        amplitude times :func:`~sensing_antenna.beam.modes.contact_to_base_shear` at the MAP
        x_c) exceeds the static push, the link bounces on the obstacle and is not pinned over
        the window, so its frequency is not omega_1(x_c). The window then starts at the end of
        the pipeline's hold (``frame_window`` after t_1, sized for the rebounds near the tip)
        and is only declared if the contact stays closed there. 1, the physical limit. On the
        simulator the bouncing lasted 0.15 to 0.2 s after the stop at 0.95 to 0.98 m, and
        windows from t_1 read omega_1 2 to 3 % low at 0.2 s (one run declared at 0.62 m for a
        tip contact at noise 2); windows from 0.2 s read it within 0.4 %.
    higher_modes : bool
        Whether a fitted contact mode 2 or 3 enters the posterior (off by default). On the
        simulated paper device the fitted higher modes departed from the pinned-contact curves
        by 1.4 to 2 % (mode 3, compliant contact) and, in the vertical case, by 7 to 21 %
        (modes of the link moving along the surface), so a sure interval could rest on a mode
        the model does not describe; see docs/fast.md.
    higher_mode_floor : float
        Relative model error of the higher contact modes (2 and 3) against their pinned-contact
        sensing curves (dimensionless), added in quadrature. 0.005: the compliant contact of the
        finite-element simulator lowers them by 0.2 to 0.35 % (0.5 s fits at noise 1, seed 200
        of benchmarks/eval_fast.py, 30 runs; see docs/fast.md), a stiffer contact less; the
        floor covers that bias at about 1.5 standard deviations. On a real device use the
        scatter of a calibration of the higher modes.
    branch_mode_tolerance : float
        Relative distance (dimensionless) within which a fitted higher mode is taken as contact
        mode 2 or 3 of a candidate x_c. When omega_1 fits candidates on two branches, the window
        is not declared while a higher mode in its fit lies within this of a mode of another
        branch's candidate and farther than this (and than twice that distance) from both modes
        of the posterior's branch's candidate: the modes say the ratio chose the wrong branch.
        0.025: on the simulated device (calibrated T_e) the fitted modes 2 and 3 sat 0.1 to
        0.4 % and 0.5 to 2.3 % below their pinned-contact curves. How far apart the candidates'
        modes are depends on the pair (paper link): mode 2 by 14 to 41 % from 0.65 / 0.935 m to
        0.75 / 0.787 m and by 6 % at 0.76 / 0.776 m; mode 3 by 0 to 7 %, nothing where the two
        branches' curves cross (0.66 / 0.92 m). Used whether or not ``higher_modes`` is on.
    branch_by_second_mode : bool
        Whether, at every window whose posterior holds two branches of omega_1(x_c), the
        paper's second-mode test (:func:`~.fusion.second_mode_choice` on the spectrum of the
        window's own samples, :func:`second_mode_chooser`) may choose the branch; the
        posterior is then conditioned on it before the other checks. On by default: on
        simulated recordings at 0.65 to 0.98 m (192: the calibrated-device campaign's device at
        noise 1 and 2, the paper antenna, a contact three times softer; windows of 0.3 to 1 s)
        it never chose the wrong branch; it said nothing on 155 of the 192 windows of 0.3 s and
        on 22 of the 24 runs at 0.98 m (docs/fast.md). Off, the second mode is asked at the cap
        only.
    push_phase : bool
        Also fit every window from t_c, through the push: the contact modes ring from the
        touch on, so the push (about 0.1 s) adds periods to every window. The static loads
        follow the head's angle along the push (a regressor beside the polynomial) and every
        mode's amplitude and phase may change at t_1, where the head stops. That fit gives
        omega_1 only when it passes every kind of check the window from t_1 passes, is more
        precise, and agrees with it within ``max_disagreement`` standard deviations of their
        difference (the touch can leave content the model does not describe: a bouncing
        contact, more modes); otherwise the window from t_1 does. The statics always come from
        the window from t_1. Off by default: on the
        paper antenna it brings the median delay from 0.302 to 0.261 s (on the calibrated
        device it stays 0.383 s), but every window is fitted twice and the CPU per
        recording is about 1.4 times larger, so in a real-time loop on a two-core machine the
        answer comes later than without it (0.519 against 0.43 to 0.46 s after t_1,
        docs/fast.md).
    push_max_modes : int
        Largest number of modes tried on a window through the push (the touch excites contact
        modes the stop hardly does). 3.
    push_polynomial_degree : int
        Highest degree of the static polynomial on a window through the push (the BIC chooses
        it from 2, or from this when lower, up to it, with the number of modes). 2: the head's
        angle, the regressor, carries the static loads' growth over the push; offered degrees
        up to 4, the BIC chose 2 on 122 of 132 windows through the push (six paper-antenna
        recordings at 0.30 to 0.85 m), and each degree costs a full set of fits.
    """

    tolerance: float = 0.005
    cadence: float = 0.01
    growth: float = 1.1
    first_window: float = 0.05
    cap: float = 1.0
    drift_factor: float = 2.0
    min_periods: float = 1.5
    min_detection: float = 10.0
    max_modes: int = 3
    min_mode_fraction: float = 0.6
    polynomial_degree: int = 4
    frequency_floor: float = 0.001
    ratio_geometry_factor: float = 0.5
    grid_step: float = 2.5e-4
    bias_min_samples: int = 20
    bias_guard: float = 0.05
    max_direction_drift: float = 0.15
    peak_margin: float = 3.0
    max_disagreement: float = 3.0
    max_opening: float = 1.0
    higher_modes: bool = False
    higher_mode_floor: float = 0.005
    branch_mode_tolerance: float = 0.025
    branch_by_second_mode: bool = True
    push_phase: bool = False
    push_max_modes: int = 3
    push_polynomial_degree: int = 2

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name in ("higher_modes", "branch_by_second_mode", "push_phase"):
                if not isinstance(value, bool):
                    raise FastConfigError(f"{f.name}: must be true or false, got {value!r}")
                continue
            counts = ("max_modes", "bias_min_samples", "push_max_modes")
            degrees = ("polynomial_degree", "push_polynomial_degree")
            if f.name in counts + degrees:
                low = 0 if f.name in degrees else 1
                if isinstance(value, bool) or not isinstance(value, int) or value < low:
                    raise FastConfigError(f"{f.name}: must be an integer >= {low}, got {value!r}")
                continue
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise FastConfigError(f"{f.name}: must be a number, got {value!r}")
            if not (math.isfinite(value) and value >= 0.0):
                raise FastConfigError(f"{f.name}: must be a finite number >= 0, got {value!r}")
            may_be_zero = (
                "frequency_floor",
                "ratio_geometry_factor",
                "bias_guard",
            )
            if value == 0.0 and f.name not in may_be_zero:
                raise FastConfigError(f"{f.name}: must be > 0, got {value!r}")
        if self.first_window > self.cap:
            raise FastConfigError("first_window: must not exceed cap")
        if self.growth <= 1.0:
            raise FastConfigError(f"growth: must be > 1, got {self.growth!r}")


@dataclass(frozen=True)
class CurveTable:
    """The sensing curves on the posterior's grid.

    Attributes
    ----------
    grid : array, shape (G,)
        Contact points (m).
    omega1 : array, shape (G,)
        omega_1 at each (rad/s).
    edges : tuple of float
        Range limits and the extrema of omega_1 inside (m), ascending: the branch edges.
    higher : array, shape (G, 2)
        Contact modes 2 and 3 at each (rad/s).
    """

    grid: FloatArray
    omega1: FloatArray
    edges: tuple[float, ...]
    higher: FloatArray


@functools.lru_cache(maxsize=16)
def curve_table(link: Link, low: float, high: float, step: float) -> CurveTable:
    """:class:`CurveTable` of ``link`` on [low, high] (m) every ``step`` (m); cached."""
    curve = sensing_curve(link)
    n = max(2, round((high - low) / step) + 1)
    grid = np.linspace(low, high, n)
    inner = tuple(x for x in curve.extrema if low < x < high)
    # Contact modes 2 and 3 (Eq. 3 with the boundary conditions of Eq. 4), shape (G, 2)
    higher = np.asarray(natural_frequencies(link, grid, 3), dtype=float)[:, 1:]
    return CurveTable(
        grid, np.asarray(curve.omega1(grid), dtype=float), (low, *inner, high), higher
    )


@dataclass(frozen=True)
class WindowEstimate:
    """One evaluation of the growing window [t_s, t_j] (t_s: t_1, or the end of the hold).

    Attributes
    ----------
    start_index : int
        First sample of the window: t_1, or the end of the hold after an opening. A fit
        through the push (``FastConfig.push_phase``) reaches back to t_c; its ``restart`` is
        then t_1's place in it.
    end_index : int
        j, the last sample used.
    fit : DampedSinusoidFit or None
        The chosen fit of the contact-load channels (None: too few samples or no pole).
    omega1, omega1_se : float
        Fundamental and its standard error (rad/s): the fit's statistical error and
        ``drift_factor`` times the drift, in quadrature (the relative model floor is added by
        the posterior); NaN when not usable.
    omega1_crb : float
        Cramer-Rao bound of omega_1 for this record length and noise (rad/s): the square root
        of the inverse Fisher information of the fitted model at the fitted parameters and the
        residual noise (the statistical part of ``omega1_se``); NaN when not usable.
    statics : StaticRatio or None
        The static torque/force ratio.
    posterior : ContactPosterior
    sure : bool
        ``checks_passed`` and the interval no wider than the tolerance.
    checks_passed : bool
        True when every check but the interval's width passes (usable frequency, periods in
        the window, drift, ratio agreement, contact closed, away from the top of the curve):
        ``sure`` at any tolerance at least the interval's width.
    note : str
        Why the frequency was not used or why it is not sure (empty when sure).
    omega1_drift : float
        Change of omega_1 from the window's first 2/3 beyond what the noise explains (rad/s).
    early_statics : StaticRatio or None
        Statics of the window's first half (the slip reference); None when that half holds
        fewer than ``min_periods`` periods, has no mode near the whole window's fundamental, or
        when not added (:func:`evaluate_window` leaves them to :func:`with_early_statics_of`).
    ratio_z : float
        Distance of the ratio from the MAP x_c in its standard deviations.
    opening : float
        Predicted vibration amplitude of the contact force over the static push at the window
        start (> 1: the contact opens); NaN when not computed.
    branch_contradicted : bool
        True when a higher mode of the fit points to another branch than the posterior's.
    branch_chosen_by_second_mode : bool
        True when the posterior held two branches and the second contact mode chose one
        (``FastConfig.branch_by_second_mode``); ``posterior`` is then conditioned on it.
    second_mode : dict
        What the second contact mode's test reported when it was asked (empty otherwise).
    """

    start_index: int
    end_index: int
    fit: DampedSinusoidFit | None
    omega1: float
    omega1_se: float
    omega1_crb: float
    statics: StaticRatio | None
    posterior: ContactPosterior
    sure: bool
    checks_passed: bool
    note: str
    omega1_drift: float = math.nan
    early_statics: StaticRatio | None = None
    ratio_z: float = math.nan
    opening: float = math.nan
    branch_contradicted: bool = False
    branch_chosen_by_second_mode: bool = False
    second_mode: dict[str, Any] = field(default_factory=dict)


#: Which of two candidate contact points (m) the window [start, end] (sample indices) with
#: fundamental omega_1 (rad/s) supports: 0, 1 or None when it does not say, and the test's
#: report (see :func:`second_mode_chooser`).
BranchChooser = Callable[[int, int, float, tuple[float, ...]], "tuple[int | None, dict[str, Any]]"]

#: Cache of window fits, keyed by :func:`_window_key` (the window's samples themselves, so a
#: cache can never serve a fit of other data).
FitCache = dict[tuple[int, int, bytes], "DampedSinusoidFit | None"]


class PushPhase(NamedTuple):
    """The push before t_1, for windows that reach back to it (``FastConfig.push_phase``).

    Attributes
    ----------
    start : int
        First sample of such windows (t_c).
    angle : array, shape (n,)
        The head's angle along the push, relative to its pose at t_1 (rad): the static loads
        follow it.
    """

    start: int
    angle: FloatArray


def push_phase(theta: FloatArray, contact_index: int, rest_index: int) -> PushPhase | None:
    """The push from t_c to t_1 as :class:`PushPhase`; None when the head did not move.

    Parameters
    ----------
    theta : array, shape (n, 2)
        Motor angles (rad).
    contact_index, rest_index : int
        Indices of t_c and t_1.
    """
    theta = np.asarray(theta, dtype=float)
    direction = theta[rest_index] - theta[contact_index]
    norm = float(np.linalg.norm(direction))
    if rest_index <= contact_index or norm == 0.0:
        return None
    return PushPhase(contact_index, (theta - theta[rest_index]) @ (direction / norm))


def _window_key(
    channels: FloatArray,
    rest_index: int,
    end_index: int,
    sample_period: float,
    band: tuple[float, float],
    push: PushPhase | None = None,
) -> tuple[int, int, bytes]:
    """Cache key of the window [rest_index, end_index]: its indices and a digest of its samples,
    of T_s and of the band (with ``push``, of the samples from its start and its angle)."""
    start = rest_index if push is None else push.start
    digest = hashlib.blake2b(channels[start : end_index + 1].tobytes(), digest_size=16)
    digest.update(np.array([sample_period, *band]).tobytes())
    if push is not None:
        digest.update(np.array([start, rest_index]).tobytes())
        digest.update(push.angle[start : end_index + 1].tobytes())
    return rest_index, end_index, digest.digest()


def _fit_window(
    channels: FloatArray,
    rest_index: int,
    end_index: int,
    sample_period: float,
    band: tuple[float, float],
    config: FastConfig,
    cache: FitCache | None,
    push: PushPhase | None = None,
) -> DampedSinusoidFit | None:
    """The fit of [rest_index, end_index], or of [push.start, end_index] with the push's angle
    as a regressor and the modes restarted at rest_index; from ``cache`` when it holds it."""
    if push is not None and push.start >= rest_index:
        push = None
    key = _window_key(channels, rest_index, end_index, sample_period, band, push)
    if cache is not None and key in cache:
        return cache[key]
    # The fit with the smallest BIC over the polynomial degrees and model orders
    start = rest_index if push is None else push.start
    max_modes = config.max_modes if push is None else config.push_max_modes
    highest = config.polynomial_degree if push is None else config.push_polynomial_degree
    signals = channels[start : end_index + 1]
    lowest = min(2, highest)
    # The matrix pencil every degree starts from, once: where the lowest degree's largest
    # model order fits the record (each fit computes it itself otherwise, as it always did)
    fits_at_all = signals.shape[0] >= 3 * (lowest + 1 + 4 * max_modes)
    poles = first_poles(signals, max_modes) if fits_at_all else None
    fit = select_model(
        signals,
        sample_period,
        max_modes,
        range(lowest, highest + 1),
        start * sample_period,
        min_omega=config.min_mode_fraction * band[0],
        target_band=band,
        poles=poles,
        regressors=None if push is None else push.angle[start : end_index + 1],
        restart=None if push is None else rest_index - start,
    )
    if cache is not None:
        cache[key] = fit
    return fit


def _fundamental(
    fit: DampedSinusoidFit | None, band: tuple[float, float], config: FastConfig
) -> tuple[int | None, str]:
    """Index of the fundamental in ``fit`` and, when it cannot be used, why."""
    if fit is None:
        return None, "window too short for the model"
    k = fit.strongest_in_band(band)
    if k is None:
        return None, "no vibration mode in the omega_1 band"
    detection = fit.snr()[k] * math.sqrt(0.5 * fit.n_samples)
    if detection < config.min_detection:
        return None, f"the fundamental's detection statistic is only {detection:.1f}"
    if not (fit.converged and math.isfinite(fit.omega_se[k])):
        return None, "the fit did not converge"
    return k, ""


def reference_index(
    rest_index: int, end_index: int, fraction: float, sample_period: float, config: FastConfig
) -> int | None:
    """The evaluation-grid index whose window is nearest to ``fraction`` of [t_1, end]."""
    offsets = evaluation_offsets(sample_period, config)
    target = fraction * (end_index - rest_index)
    k = int(np.argmin(np.abs(offsets - target)))
    if offsets[k] >= end_index - rest_index:
        return None
    return rest_index + int(offsets[k])


class _Frequency(NamedTuple):
    """The fundamental of one window and the checks on it (see :func:`_frequency`); ``mode``
    is its index in ``fit``; ``failed`` names the checks that failed ("fundamental",
    "periods", "drift_reference"), ``notes`` says why."""

    fit: DampedSinusoidFit | None
    mode: int | None
    omega1: float
    omega1_se: float
    omega1_crb: float
    drift: float
    notes: tuple[str, ...]
    failed: frozenset[str] = frozenset()


class _Window(NamedTuple):
    """The window [rest_index, end_index] and what its fits need: :func:`_fit_window`'s
    leading arguments, in order (as in :func:`evaluate_window`)."""

    channels: FloatArray
    rest_index: int
    end_index: int
    sample_period: float
    band: tuple[float, float]
    config: FastConfig
    cache: FitCache | None


def _frequency(window: _Window, push: PushPhase | None) -> _Frequency:
    """Fit the window (through the push when given) and measure its fundamental: its standard
    error with the drift check's term, and the period checks."""
    config, band = window.config, window.band
    fit = _fit_window(*window, push)
    omega1 = omega1_se = omega1_crb = drift = math.nan
    k, note = _fundamental(fit, band, config)
    notes = [note] if note else []
    failed = {"fundamental"} if note else set()
    if fit is not None and k is not None:
        omega1 = float(fit.omega[k])
        omega1_crb = float(fit.omega_se[k])
        omega1_se = omega1_crb
        periods = fit.duration * omega1 / (2.0 * math.pi)
        if periods < config.min_periods:
            notes.append(f"the window holds {periods:.2f} periods of omega_1")
            failed.add("periods")
        # The same fundamental on a window of 2/3 the length: its change measures how far
        # unmodelled content still moves the estimate (drift_factor times it, in quadrature)
        ref = reference_index(
            window.rest_index, window.end_index, 2.0 / 3.0, window.sample_period, config
        )
        ref_fit = None if ref is None else _fit_window(*window._replace(end_index=ref), push)
        k_ref, _ = _fundamental(ref_fit, band, config)
        ref_periods = math.nan if ref_fit is None else ref_fit.duration * omega1 / (2.0 * math.pi)
        if ref_fit is None or k_ref is None:
            notes.append("no fundamental on the shorter window to check its drift")
            failed.add("drift_reference")
        elif ref_periods < config.min_periods:
            # Below min_periods the shorter window's own fundamental is too loose to see a
            # drift of the size that matters here: "no change seen" would mean nothing
            notes.append(
                f"the shorter window that checks the drift holds {ref_periods:.2f} periods of "
                "omega_1"
            )
            failed.add("drift_reference")
        else:
            # Nested windows: the change of an efficient estimate has variance se_ref^2 - se^2
            # from noise alone; only the excess over that is drift
            change = omega1 - float(ref_fit.omega[k_ref])
            noise_part = max(float(ref_fit.omega_se[k_ref]) ** 2 - omega1_crb**2, 0.0)
            drift = math.sqrt(max(change**2 - noise_part, 0.0))
            omega1_se = math.hypot(omega1_se, config.drift_factor * drift)
    return _Frequency(fit, k, omega1, omega1_se, omega1_crb, drift, tuple(notes), frozenset(failed))


def _early_statics(window: _Window, omega1: float, bias: SensorBias) -> StaticRatio | None:
    """Statics of the window's first half from t_1, the slip check's reference; None when that
    half holds fewer than ``min_periods`` periods of ``omega1`` (rad/s), is not on the grid, or
    has no mode within :data:`_SAME_MODE` of ``omega1`` in the band (another mode took the
    fundamental's place)."""
    config = window.config
    half = reference_index(window.rest_index, window.end_index, 0.5, window.sample_period, config)
    half_fit = None if half is None else _fit_window(*window._replace(end_index=half))
    if half_fit is None or half_fit.duration * omega1 < 2.0 * math.pi * config.min_periods:
        # Statics of a window too short for the model are not a reference (mode and offset
        # are confounded below a period or so)
        return None
    # A half that read another fundamental has put part of the vibration in its static part
    # (a slow, fast-decaying mode in its place): its statics are no reference either
    k = half_fit.strongest_in_band(window.band)
    if k is None or not abs(float(half_fit.omega[k]) - omega1) <= _SAME_MODE * omega1:
        return None
    return static_ratio(half_fit, bias)


def _push_agrees(through: _Frequency, from_t1: _Frequency, config: FastConfig) -> bool:
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


def evaluate_window(
    channels: FloatArray,
    bias: SensorBias,
    rest_index: int,
    end_index: int,
    sample_period: float,
    band: tuple[float, float],
    link: Link,
    x_range: tuple[float, float],
    config: FastConfig,
    push: PushPhase | None = None,
    cache: FitCache | None = None,
    choose_branch: BranchChooser | None = None,
) -> WindowEstimate:
    """Fit the window [rest_index, end_index] and form the posterior over x_c.

    The slip check's early statics (the fit of the window's first half) enter neither the
    posterior nor ``sure``: they are left out (None), and :func:`with_early_statics_of` adds
    them to the window that is concluded on.

    Parameters
    ----------
    channels : array, shape (n, 5)
        :func:`~.static_fit.contact_channels` of the samples (at least up to ``end_index``).
    bias : SensorBias
    rest_index, end_index : int
        Indices of t_1 and of the last sample used.
    sample_period : float
        T_s (s).
    band : tuple of float
        omega_1 band (rad/s).
    link : Link
    x_range : tuple of float
        Prior range of x_c (m).
    config : FastConfig
    push : PushPhase, optional
        With it, every window fitted here reaches back to the push's start
        (``FastConfig.push_phase``); None: windows start at ``rest_index``.
    cache : dict, optional
        Window fits keyed by the windows' own samples (:data:`FitCache`); the drift check's
        shorter windows are taken from it (and added to it). The scan and an online session
        pass one; None refits.
    choose_branch : BranchChooser, optional
        When the posterior holds two branches of omega_1(x_c), asked which candidate the
        window supports (:func:`second_mode_chooser`); the posterior is conditioned on its
        answer before the checks. None: not asked.

    Returns
    -------
    WindowEstimate
    """
    window = _Window(channels, rest_index, end_index, sample_period, band, config, cache)
    from_t1 = _frequency(window, None)
    frequency = from_t1
    if push is not None:
        through = _frequency(window, push)
        if _push_agrees(through, from_t1, config):
            frequency = through
    fit, k = frequency.fit, frequency.mode
    omega1, omega1_se, omega1_crb = frequency.omega1, frequency.omega1_se, frequency.omega1_crb
    drift = frequency.drift
    notes = list(frequency.notes)
    # The statics from the window from t_1 always: a fit through the push has its static part
    # at the centre of [t_c, t], inside the push for short windows, while the opening check
    # compares it with the vibration at t_1
    statics = static_ratio(from_t1.fit, bias) if from_t1.fit is not None else None
    table = curve_table(link, x_range[0], x_range[1], config.grid_step)
    frequency_floor = model_floor(link, config)
    omega_h = omega_h_se = math.nan
    if config.higher_modes and fit is not None and math.isfinite(omega1):
        omega_h, omega_h_se = _higher_mode(fit, omega1, table.higher, config)
    ratio = statics.ratio if statics is not None else math.nan
    ratio_se = statics.standard_error if statics is not None else math.nan
    push_force = statics.perpendicular_force if statics is not None else 0.0
    posterior = contact_posterior(
        table.omega1,
        table.grid,
        table.edges,
        omega1,
        omega1_se,
        ratio,
        ratio_se,
        push_force,
        link.flexural_rigidity,
        frequency_floor,
        config.ratio_geometry_factor,
        higher_modes_of_x=table.higher,
        omega_higher=omega_h,
        omega_higher_se=omega_h_se,
        higher_mode_floor=config.higher_mode_floor,
    )
    chosen = False
    second_mode: dict[str, Any] = {}
    if (
        choose_branch is not None
        and config.branch_by_second_mode
        and max(posterior.branch_probability) < posterior.level
    ):
        candidates = _candidates(link, omega1, posterior)
        if len(candidates) == 2:
            choice, second_mode = choose_branch(rest_index, end_index, omega1, candidates)
            conditioned = _on_chosen_branch(posterior, candidates, choice)
            chosen = conditioned is not None
            posterior = conditioned or posterior
    ratio_z = math.nan
    if statics is not None and math.isfinite(omega1):
        ratio_z, disagreement = _ratio_check(statics, posterior.x_c, link, config)
        if disagreement:
            notes.append(disagreement)
    opening = math.nan
    if fit is not None and k is not None and push_force > 0.0:
        opening = _opening(fit, k, push_force, link, posterior.x_c)
        if opening > config.max_opening:
            notes.append(
                f"the contact opens: the predicted vibration of the contact force is "
                f"{opening:.2f} times the static push at the window start"
            )
    contradiction = ""
    if fit is not None and k is not None:
        contradiction = _branch_contradiction(fit, k, posterior, table, link, config)
        if contradiction:
            notes.append(contradiction)
    if not notes and math.isfinite(omega1) and not math.isfinite(omega_h):
        # Near the top of omega_1(x_c) the inverse is singular: a frequency bias e moves x_c by
        # sqrt(2 e / |omega_1''|) and the Gaussian interval can collapse onto the peak; so no
        # declaration while omega_1 is within peak_margin standard deviations of the maximum,
        # unless a higher contact mode (whose curves do not peak there) enters the posterior.
        sigma = math.hypot(omega1_se, frequency_floor * omega1)
        top = float(table.omega1.max())
        if top - omega1 < config.peak_margin * sigma:
            notes.append(
                f"omega_1 = {omega1:.2f} rad/s is within {config.peak_margin:g} standard "
                f"deviations of the top of the sensing curve ({top:.2f} rad/s)"
            )
    checks_passed = not notes
    if not notes and posterior.width > config.tolerance:
        notes.append(
            f"the 95 % interval is {1000 * posterior.width:.1f} mm wide "
            f"(tolerance {1000 * config.tolerance:g} mm)"
        )
    return WindowEstimate(
        start_index=rest_index,
        end_index=end_index,
        fit=fit,
        omega1=omega1,
        omega1_se=omega1_se,
        omega1_crb=omega1_crb,
        statics=statics,
        posterior=posterior,
        sure=not notes,
        checks_passed=checks_passed,
        note="; ".join(notes),
        omega1_drift=drift,
        early_statics=None,
        ratio_z=ratio_z,
        opening=opening,
        branch_contradicted=bool(contradiction),
        branch_chosen_by_second_mode=chosen,
        second_mode=second_mode,
    )


def _ratio_check(
    statics: StaticRatio, x_map: float, link: Link, config: FastConfig
) -> tuple[float, str]:
    """Distance of the ratio from ``x_map`` (m) in its standard deviations (model floor
    included), and the note when it exceeds ``max_disagreement`` (else "")."""
    ratio = statics.ratio
    if not math.isfinite(ratio):
        return math.nan, ""
    # Posterior predictive check of the ratio at the MAP point (its floor included)
    deflection = statics.perpendicular_force * x_map**2 / (3.0 * link.flexural_rigidity)
    sigma_r = math.hypot(statics.standard_error, config.ratio_geometry_factor * deflection * x_map)
    ratio_z = abs(ratio - x_map) / sigma_r if sigma_r > 0.0 else math.inf
    if ratio_z <= config.max_disagreement:
        return ratio_z, ""
    return ratio_z, (
        f"the torque/force ratio ({ratio:.3f} m) is {ratio_z:.1f} standard deviations "
        f"from x_c = {x_map:.3f} m"
    )


def model_floor(link: Link, config: FastConfig) -> float:
    """Relative model error of omega_1 (dimensionless): the config's floor, or the link's
    calibration scatter when that is larger."""
    return max(config.frequency_floor, link.calibration_scatter or 0.0)


@functools.lru_cache(maxsize=4096)
def _contact_to_base_shear(link: Link, x_c: float) -> float:
    return float(contact_to_base_shear(link, x_c))


def _opening(fit: DampedSinusoidFit, k: int, push: float, link: Link, x_c: float) -> float:
    """Fundamental's contact-force amplitude at the window start over the static push |R_perp|.

    The base-force amplitude (R_y and R_z channels) at the window start is turned into the
    contact force by the first mode's shape.
    """
    start = fit.start_amplitudes()
    base = math.hypot(float(start[0, k]), float(start[1, k]))
    return abs(_contact_to_base_shear(link, x_c)) * base / push


def _branch_contradiction(
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
    candidates = _candidates(link, omega1, posterior)
    chosen = posterior.branch_of(posterior.x_c)
    own = [c for c in candidates if posterior.branch_of(c) == chosen]
    others = [c for c in candidates if posterior.branch_of(c) != chosen]
    if not own or not others:
        return ""
    detection = fit.snr() * math.sqrt(0.5 * fit.n_samples)

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


def evaluate_from_t1_or_hold(
    inputs: ScanInputs,
    hold_end: int,
    caches: tuple[FitCache, FitCache] | None = None,
    choose_branch: BranchChooser | None = None,
    with_early_statics: bool = True,
) -> WindowEstimate:
    """:func:`evaluate_window` on [t_1, ``inputs.end_index``]; from the end of the hold when the
    contact opened.

    When the window from t_1 shows the contact opening (``max_opening``), the link was bouncing
    on the obstacle early in the window; the window [hold_end, end_index] is evaluated instead
    once it is at least ``first_window`` long (before that the one from t_1 is returned, not
    sure). ``caches`` holds the fits of the two kinds of window; None refits.
    ``choose_branch`` as in :func:`evaluate_window`; ``with_early_statics``: the returned window
    gets the slip check's early statics (:func:`with_early_statics_of`).
    """
    early, late = caches if caches is not None else (None, None)
    window = evaluate_window(*inputs, cache=early, choose_branch=choose_branch)
    first = round(inputs.config.first_window / inputs.sample_period)
    if (
        window.opening > inputs.config.max_opening
        and inputs.rest_index < hold_end <= inputs.end_index - first
    ):
        window = evaluate_window(
            *inputs._replace(rest_index=hold_end, push=None),
            cache=late,
            choose_branch=choose_branch,
        )
    return with_early_statics_of(inputs, window, caches) if with_early_statics else window


def with_early_statics_of(
    inputs: ScanInputs,
    estimate: WindowEstimate,
    caches: tuple[FitCache, FitCache] | None = None,
) -> WindowEstimate:
    """``estimate`` (a window of :func:`evaluate_from_t1_or_hold` on ``inputs``' samples) with
    the slip check's early statics: those of its first half, with the fundamental of its fit
    from its own start (never through the push). Its fits come from ``caches`` (the windows
    from t_1 or, when it was restarted, those from the hold's end); None refits them."""
    restarted = estimate.start_index != inputs.rest_index
    cache = None if caches is None else caches[1 if restarted else 0]
    window = _Window(
        inputs.channels,
        estimate.start_index,
        estimate.end_index,
        inputs.sample_period,
        inputs.band,
        inputs.config,
        cache,
    )
    from_t1 = _frequency(window, None)
    early = None if from_t1.mode is None else _early_statics(window, from_t1.omega1, inputs.bias)
    return dataclasses.replace(estimate, early_statics=early)


def _higher_mode(
    fit: DampedSinusoidFit, omega1: float, higher: FloatArray, config: FastConfig
) -> tuple[float, float]:
    """The strongest detected mode above omega_1 within the range of contact modes 2 and 3.

    Returns its frequency and standard error (rad/s), the non-stationarity floor in quadrature
    as for omega_1; NaN when there is none.
    """
    low, high = float(higher.min()), float(higher.max())
    detection = fit.snr() * math.sqrt(0.5 * fit.n_samples)
    usable = [
        k
        for k in range(fit.n_modes)
        if fit.omega[k] > 1.5 * omega1
        and low * (1.0 - 5.0 * config.higher_mode_floor)
        <= fit.omega[k]
        <= high * (1.0 + 5.0 * config.higher_mode_floor)
        and detection[k] >= config.min_detection
        and math.isfinite(fit.omega_se[k])
    ]
    if not usable or not fit.converged:
        return math.nan, math.nan
    k = max(usable, key=lambda i: float(detection[i]))
    return float(fit.omega[k]), float(fit.omega_se[k])


@functools.lru_cache(maxsize=32)
def _offsets(
    sample_period: float, first: float, cadence: float, growth: float, cap: float
) -> tuple[int, ...]:
    offsets = [max(1, round(first / sample_period))]
    last = max(1, round(cap / sample_period))
    while offsets[-1] < last:
        step = max(cadence, (growth - 1.0) * offsets[-1] * sample_period)
        offsets.append(min(last, offsets[-1] + max(1, round(step / sample_period))))
    return tuple(offsets)


def evaluation_offsets(sample_period: float, config: FastConfig) -> NDArray[np.int_]:
    """Samples after t_1 at which windows are evaluated, ascending; the last is the cap."""
    return np.asarray(
        _offsets(sample_period, config.first_window, config.cadence, config.growth, config.cap),
        dtype=int,
    )


class ScanInputs(NamedTuple):
    """The samples and model a window reads: :func:`evaluate_window`'s leading arguments, in order.

    ``end_index`` is the last sample available; :func:`evaluations` replaces it by each
    window's end.
    """

    channels: FloatArray
    bias: SensorBias
    rest_index: int
    end_index: int
    sample_period: float
    band: tuple[float, float]
    link: Link
    x_range: tuple[float, float]
    config: FastConfig
    push: PushPhase | None = None


@dataclass(frozen=True)
class ScanResult:
    """Outcome of the growing-window search.

    Attributes
    ----------
    final : WindowEstimate or None
        The declared evaluation (sure), or the last one (unsure); None if none could run.
    evaluations : int
        Number of grid windows evaluated (the concluded window's early statics, added after,
        are not another evaluation).
    reached_cap : bool
        True when the search stopped at the cap without being sure.
    """

    final: WindowEstimate | None
    evaluations: int
    reached_cap: bool


def evaluations(
    inputs: ScanInputs,
    earliest: int = 0,
    hold_end: int = -1,
    choose_branch: BranchChooser | None = None,
    caches: tuple[FitCache, FitCache] | None = None,
    with_early_statics: bool = True,
) -> Iterator[WindowEstimate]:
    """Every window ending on the evaluation grid from ``earliest`` to the cap, in order.

    The grid is t_1 + :func:`evaluation_offsets`; evaluation starts at the first grid point at or
    after ``earliest`` and ends at the cap or at ``inputs.end_index``, whichever comes first. Each
    window starts at t_1, or at ``hold_end`` when the contact opened
    (:func:`evaluate_from_t1_or_hold`; -1: always t_1). The fits of one recording are cached, so
    the drift check's shorter windows are fitted once; ``caches`` (windows from t_1, windows from
    the hold's end) are used and filled when given, else new ones. ``choose_branch`` and
    ``with_early_statics`` as in :func:`evaluate_from_t1_or_hold`.
    """
    if caches is None:
        caches = ({}, {})
    for offset in evaluation_offsets(inputs.sample_period, inputs.config):
        j = inputs.rest_index + int(offset)
        if j < earliest:
            continue
        if j > inputs.end_index:
            return
        yield evaluate_from_t1_or_hold(
            inputs._replace(end_index=j), hold_end, caches, choose_branch, with_early_statics
        )


def scan(
    inputs: ScanInputs,
    earliest: int = 0,
    hold_end: int = -1,
    choose_branch: BranchChooser | None = None,
    caches: tuple[FitCache, FitCache] | None = None,
) -> ScanResult:
    """Evaluate the growing window on the evaluation grid until sure, the cap or the samples' end.

    The windows are those of :func:`evaluations` (``caches`` as there); ``earliest`` is the end
    of the pipeline's hold, before which there is no contact frame. Only the window concluded on
    gets the slip check's early statics (they do not decide ``sure``), added after from the
    cached fits (:func:`with_early_statics_of`).
    """
    if caches is None:
        caches = ({}, {})
    last = inputs.rest_index + int(evaluation_offsets(inputs.sample_period, inputs.config)[-1])
    final: WindowEstimate | None = None
    count = 0
    for final in evaluations(inputs, earliest, hold_end, choose_branch, caches, False):
        count += 1
        if final.sure:
            break
    if final is None:
        return ScanResult(None, 0, last <= inputs.end_index)
    final = with_early_statics_of(inputs, final, caches)
    return ScanResult(final, count, not final.sure and last <= inputs.end_index)


@dataclass(frozen=True)
class FastMethod:
    """The fast method as a pipeline method: ``estimate(recording, antenna, FastMethod())``.

    Offline the pipeline hands over the samples up to its own t_e; this method searches them
    from t_1 on and declares at its own, earlier instant (reported as ``t_e``), using only the
    samples up to that instant. Online the pipeline takes a :meth:`session` per manoeuvre and
    asks its ``due`` after every sample and, on the cadence grid, its ``ready``; it concludes
    at the first ready sample, the same one.
    """

    config: FastConfig = field(default_factory=FastConfig)
    name: str = "fast"

    def _prepare(self, evidence: Evidence) -> ScanInputs:
        """What :func:`evaluate_window` and :func:`scan` share, from the pipeline's evidence."""
        link = evidence.antenna.link
        channels = contact_channels(
            evidence.theta, evidence.force, evidence.torque, evidence.antenna
        )
        tolerance = float(evidence.diagnostics.get("rest_tolerance", 1e-4))
        bias = sensor_bias(
            channels,
            evidence.theta,
            evidence.contact_index,
            tolerance,
            self.config.bias_min_samples,
            guard=round(self.config.bias_guard / evidence.sample_period),
        )
        x_range = (
            evidence.config.contact_range[0] * link.length,
            evidence.config.contact_range[1] * link.length,
        )
        push = (
            push_phase(evidence.theta, evidence.contact_index, evidence.rest_index)
            if self.config.push_phase
            else None
        )
        return ScanInputs(
            channels,
            bias,
            evidence.rest_index,
            evidence.end_index,
            evidence.sample_period,
            evidence.band,
            link,
            x_range,
            self.config,
            push,
        )

    def due(self, samples_since_t1: int, sample_period: float) -> bool:
        """Whether the online form should evaluate after this sample (the evaluation grid)."""
        offsets = evaluation_offsets(sample_period, self.config)
        k = int(np.searchsorted(offsets, samples_since_t1))
        return k < offsets.size and int(offsets[k]) == samples_since_t1

    def session(self) -> FastSession:
        """A fresh online run of this method: keeps the window fits of one manoeuvre."""
        return FastSession(self)

    def ready(self, evidence: Evidence) -> bool:
        """Whether the window ending at ``evidence.end_index`` is sure or at the cap."""
        return self.session().ready(evidence)

    def history(self, evidence: Evidence, from_t1: bool = False) -> tuple[WindowEstimate, ...]:
        """Every evaluation of the growing window up to the cap, without stopping when sure.

        For studying the method (how the interval narrows, which check holds the declaration
        back): the first ``sure`` element at or after the end of the pipeline's hold is the
        one :meth:`conclude` declares. ``from_t1`` starts at ``first_window`` after t_1 instead
        of at the end of the hold.
        """
        inputs = self._prepare(evidence)
        earliest = inputs.rest_index if from_t1 else evidence.hold_end
        return tuple(
            evaluations(inputs, earliest, evidence.hold_end, second_mode_chooser(evidence))
        )

    def conclude(
        self, evidence: Evidence, caches: tuple[FitCache, FitCache] | None = None
    ) -> ContactEstimate:
        """Scan the evidence from t_1 and give the first sure estimate (or the capped one).

        ``caches`` as in :func:`evaluations`.
        """
        inputs = self._prepare(evidence)
        result = scan(
            inputs, evidence.hold_end, evidence.hold_end, second_mode_chooser(evidence), caches
        )
        return conclude_fast(evidence, result, inputs.bias, self.config, self.name)


class FastSession:
    """The fast method over one manoeuvre online (:meth:`FastMethod.session`).

    The samples of a window do not change once they have arrived, so the fits of every window
    evaluated so far are kept (by the window's own samples: never served for other data) and
    the next evaluation fits only its own window (its drift check's shorter windows are earlier
    grid windows). :meth:`conclude` evaluates one window only: the last grid instant at or
    before the end of the samples (the one :meth:`ready` has just found sure, or the cap, or
    the last before the samples ended). Asked at every grid instant, it gives the answers of
    the method without a session; asked at fewer (``OnlineEstimator.update_block``), the
    windows it skipped are never fitted.
    """

    def __init__(self, method: FastMethod) -> None:
        self.method = method
        self._caches: tuple[FitCache, FitCache] = ({}, {})
        # Digest of each window asked, by its last index (for the evaluation count)
        self._asked: dict[int, bytes] = {}

    @property
    def name(self) -> str:
        """The method's name."""
        return self.method.name

    def session(self) -> FastSession:
        """A fresh session of the same method (an online estimator takes one per manoeuvre)."""
        return self.method.session()

    def due(self, samples_since_t1: int, sample_period: float) -> bool:
        """As :meth:`FastMethod.due`."""
        return self.method.due(samples_since_t1, sample_period)

    def _evaluate(
        self, inputs: ScanInputs, evidence: Evidence, end: int, final: bool
    ) -> WindowEstimate:
        """:func:`evaluate_from_t1_or_hold` on the window ending at ``end``, remembered; the
        slip check's early statics only for the ``final`` window (the one concluded on)."""
        window = evaluate_from_t1_or_hold(
            inputs._replace(end_index=end),
            evidence.hold_end,
            self._caches,
            second_mode_chooser(evidence),
            with_early_statics=final,
        )
        self._asked[end] = _window_key(
            inputs.channels, inputs.rest_index, end, inputs.sample_period, inputs.band, inputs.push
        )[2]
        return window

    def ready(self, evidence: Evidence) -> bool:
        """As :meth:`FastMethod.ready`, with this manoeuvre's fits."""
        offsets = evaluation_offsets(evidence.sample_period, self.method.config)
        if evidence.end_index >= evidence.rest_index + int(offsets[-1]):
            return True
        inputs = self.method._prepare(evidence)
        return self._evaluate(inputs, evidence, evidence.end_index, final=False).sure

    def _asked_here(self, inputs: ScanInputs) -> set[int]:
        """Last indices of the windows asked on these very samples."""
        return {
            end
            for end, digest in self._asked.items()
            if end <= inputs.end_index
            and digest
            == _window_key(
                inputs.channels,
                inputs.rest_index,
                end,
                inputs.sample_period,
                inputs.band,
                inputs.push,
            )[2]
        }

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        """The estimate at the last grid instant at or before ``evidence.end_index``.

        When :meth:`ready` was asked on these samples, one window is evaluated: that instant's
        (the one just found sure, or the cap, or the last before the samples ended), with
        status, evaluation count (windows asked) and cap as :meth:`FastMethod.conclude` gives
        them when every earlier instant was unsure, so the same estimate when asked at every
        instant. When it was not (offline, or other samples), as :meth:`FastMethod.conclude`.
        """
        method = self.method
        inputs = method._prepare(evidence)
        asked = self._asked_here(inputs)
        offsets = evaluation_offsets(evidence.sample_period, method.config)
        instants = inputs.rest_index + offsets
        instants = instants[(instants >= evidence.hold_end) & (instants <= evidence.end_index)]
        if not asked or instants.size == 0:
            return method.conclude(evidence, self._caches)
        window = self._evaluate(inputs, evidence, int(instants[-1]), final=True)
        count = len(asked | {window.end_index})
        reached_cap = inputs.rest_index + int(offsets[-1]) <= evidence.end_index
        result = ScanResult(window, count, reached_cap and not window.sure)
        return conclude_fast(evidence, result, inputs.bias, method.config, method.name)


def _direction_change(early: StaticRatio, late: StaticRatio) -> tuple[float, float]:
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


def _problems(
    result: ScanResult,
    config: FastConfig,
    deflection_ratio: float,
    limit: float,
) -> list[tuple[Status, str]]:
    found: list[tuple[Status, str]] = []
    final = result.final
    if final is None:
        return [(Status.RECORDING_TOO_SHORT, "too few samples after t_1 for a first window")]
    if not final.sure and final.ratio_z > config.max_disagreement:
        found.append(
            (
                Status.ESTIMATORS_DISAGREE,
                f"the frequency and the torque/force ratio disagree at the end of the search "
                f"({final.note})",
            )
        )
    elif not final.sure:
        if result.reached_cap:
            found.append(
                (
                    Status.UNCERTAIN,
                    f"uncertain: not sure within {config.cap:g} s after t_1 ({final.note})",
                )
            )
        else:
            found.append(
                (
                    Status.RECORDING_TOO_SHORT,
                    f"the samples ended before the estimate was sure ({final.note})",
                )
            )
    if final.statics is not None and final.early_statics is not None:
        # Slip on the surface turns the static reaction: the fitted static loads of the window's
        # first half against the whole window (vibration is in the model, not in the statics)
        angle, se = _direction_change(final.early_statics, final.statics)
        if math.isfinite(angle) and angle > max(config.max_direction_drift, 3.0 * se):
            found.append(
                (
                    Status.SLIP_SUSPECTED,
                    f"the static contact force turned by {math.degrees(angle):.1f} deg "
                    f"(+- {math.degrees(se):.1f}) between the first half of the window and t_e",
                )
            )
    if math.isfinite(deflection_ratio) and deflection_ratio > limit:
        found.append(
            (
                Status.SLIP_SUSPECTED,
                f"the static deflection at the contact is {100 * deflection_ratio:.0f} % of "
                f"x_c, beyond the {100 * limit:.0f} % small-deflection limit of Assumption 1",
            )
        )
    return found


def _candidates(link: Link, omega1: float, posterior: ContactPosterior) -> tuple[float, ...]:
    """Contact points (m) whose omega_1 is ``omega1``, inside the posterior's range."""
    if not math.isfinite(omega1):
        return ()
    low, high = posterior.branch_edges[0], posterior.branch_edges[-1]
    return tuple(
        float(c.x_c) for c in sensing_curve(link).contact_points(omega1) if low <= c.x_c <= high
    )


def second_mode_chooser(evidence: Evidence) -> BranchChooser:
    """The second contact mode's answer on a window of the evidence (a :data:`BranchChooser`).

    The paper's test (:func:`~.fusion.second_mode_choice`: a clear spectral peak within
    ``omega2_window`` of one candidate's omega_2, ten times stronger than near the other's) on
    the spectrum of the window's own samples [start, end], online and offline alike. It is not
    asked (no answer) when the window's Hann main lobe, +-4 pi / T_w, is as wide as the gap
    between the candidates' omega_2 (the other candidate's search window would lie on the
    lobe's slope and hold no peak whatever the truth). An answer whose peak lies nearer 2 or 3
    omega_1 than the chosen candidate's omega_2 is dropped: a clipping contact's harmonic may be
    what it saw (at 0.70 m on the paper link 3 omega_1 is 2.9 % from the other candidate's
    omega_2).
    """

    def choose(
        start: int, end: int, omega1: float, candidates: tuple[float, ...]
    ) -> tuple[int | None, dict[str, Any]]:
        omega2 = predicted_omega2(evidence, candidates)
        lobe = 4.0 * math.pi / ((end - start) * evidence.sample_period)
        if lobe >= abs(omega2[0] - omega2[1]):
            return None, {"not_asked": f"main lobe +-{lobe:.0f} rad/s spans the candidates"}
        window = dataclasses.replace(evidence, rest_index=start, end_index=end)
        component = evidence_frequency(window).component
        choice, notes = second_mode_choice(window, component, candidates)
        if choice is None:
            return choice, notes
        # The peak the answer rests on, nearer a harmonic than the candidate's omega_2?
        peak = notes["peak_omega"][choice]
        for harmonic in (2.0 * omega1, 3.0 * omega1):
            if abs(peak - harmonic) < abs(peak - omega2[choice]):
                dropped = (
                    f"the peak at {peak:.1f} rad/s is nearer {harmonic:.1f} rad/s, a "
                    "harmonic of omega_1"
                )
                return None, {**notes, "dropped": dropped}
        return choice, notes

    return choose


def _on_chosen_branch(
    posterior: ContactPosterior, candidates: tuple[float, ...], choice: int | None
) -> ContactPosterior | None:
    """``posterior`` conditioned on the branch of ``candidates[choice]``; None when there is no
    choice or that branch holds no mass."""
    if choice is None:
        return None
    branch = posterior.branch_of(candidates[choice])
    if posterior.branch_probability[branch] <= 0.0:
        return None
    return posterior.given_branch(branch)


def _branch_by_second_mode(
    evidence: Evidence,
    window: WindowEstimate,
    candidates: tuple[float, ...],
) -> tuple[ContactPosterior, dict[str, Any]]:
    """At the cap, let the second contact mode choose between two branches the ratio cannot.

    Asked (:func:`second_mode_chooser`, on the final window) when the posterior still holds
    both branches, or when the window's higher mode contradicted the branch it holds; with
    ``branch_by_second_mode`` on, the first case has been asked at the window already. When
    decisive the posterior is conditioned on that branch; otherwise it is unchanged.
    """
    posterior = window.posterior
    split = max(posterior.branch_probability) < posterior.level
    if len(candidates) != 2 or not (split or window.branch_contradicted):
        return posterior, {}
    if window.branch_chosen_by_second_mode or (split and window.second_mode):
        return posterior, {}
    choose = second_mode_chooser(evidence)
    choice, notes = choose(window.start_index, window.end_index, window.omega1, candidates)
    conditioned = _on_chosen_branch(posterior, candidates, choice)
    if conditioned is None:
        return posterior, {"second_mode": notes}
    return conditioned, {"second_mode": notes, "branch_chosen_by": "omega2"}


def conclude_fast(
    evidence: Evidence, result: ScanResult, bias: SensorBias, config: FastConfig, name: str
) -> ContactEstimate:
    """The :class:`ContactEstimate` of a scan: status, interval, branch probabilities, 3D point."""
    final = result.final
    t = evidence.t
    t_c = float(t[evidence.contact_index])
    t_1 = float(t[evidence.rest_index])
    diag: dict[str, Any] = dict(evidence.diagnostics)
    diag.update({"evaluations": result.evaluations, "bias_samples": bias.n_samples})
    if bias.n_samples == 0:
        diag["bias_note"] = "no initial rest: sensor bias not removed"
    if final is None:
        return ContactEstimate(
            status=Status.RECORDING_TOO_SHORT,
            reason="too few samples after t_1 for a first window",
            method=name,
            t_c=t_c,
            t_1=t_1,
            diagnostics=diag,
        )
    post = final.posterior
    # The branch edges do not change with conditioning: the candidates serve before and after
    candidates = _candidates(evidence.antenna.link, final.omega1, post)
    if final.second_mode:
        diag["second_mode"] = final.second_mode
    if final.branch_chosen_by_second_mode:
        diag["branch_chosen_by"] = "omega2"
    if result.reached_cap and not final.sure:
        # The final window's samples only (up to the cap), online and offline alike
        post, second_mode = _branch_by_second_mode(evidence, final, candidates)
        diag.update(second_mode)
        if post is not final.posterior and final.statics is not None:
            # The ratio's agreement is judged again at the chosen branch's maximum
            ratio_z, _ = _ratio_check(final.statics, post.x_c, evidence.antenna.link, config)
            final = dataclasses.replace(final, posterior=post, ratio_z=ratio_z)
            result = dataclasses.replace(result, final=final)
    statics = final.statics
    push = statics.perpendicular_force if statics is not None else math.nan
    touch = touched_point(post.x_c, evidence.frame, push, evidence.antenna.link)
    found = _problems(
        result,
        config,
        touch.deflection_ratio,
        evidence.config.max_deflection_ratio,
    )
    if evidence.gap is not None:
        found.append((Status.BAD_INPUT, evidence.gap))
    order = {status: rank for rank, status in enumerate(STATUS_PRECEDENCE)}
    found.sort(key=lambda item: order.get(item[0], len(order)))
    status, reason = found[0] if found else (Status.OK, None)
    if reason is not None and "branch_chosen_by" in diag:
        reason += (
            f"; the second contact mode then chose the branch of x_c = {post.x_c:.3f} m, and "
            "the interval is given on that branch"
        )
    branch_of = [post.branch_of(c) for c in candidates]
    diag.update(
        {
            "interval_width": post.width,
            "branch_edges": post.branch_edges,
            "branch_probability_by_branch": post.branch_probability,
            "omega1_se": final.omega1_se,
            "omega1_crb": final.omega1_crb,
            "omega1_drift": final.omega1_drift,
            "ratio_z": final.ratio_z,
            "ratio_se": statics.standard_error if statics is not None else math.nan,
            "model_order": final.fit.n_modes if final.fit is not None else 0,
            "fit_through_push": final.fit is not None and final.fit.restart is not None,
            "modes": final.fit.omega if final.fit is not None else (),
            "push_force": push,
            "deflection_ratio": touch.deflection_ratio,
            "note": final.note,
            "other_reasons": [text for _, text in found[1:]],
        }
    )
    return ContactEstimate(
        status=status,
        reason=reason,
        method=name,
        x_c=post.x_c,
        candidates=candidates,
        omega1=final.omega1,
        ratio_estimate=statics.ratio if statics is not None else math.nan,
        t_c=t_c,
        t_1=t_1,
        t_e=float(t[final.end_index]),
        contact_point=touch.point_a,
        diagnostics=diag,
        interval=post.interval,
        branch_probability=tuple(post.branch_probability[b] for b in branch_of),
    )
