"""Settings of the fast method: :class:`FastConfig`, its validation, and the model floor."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from sensing_antenna.antenna import Link
from sensing_antenna.errors import SensingAntennaError

__all__ = ["FastConfig", "FastConfigError", "model_floor"]


class FastConfigError(SensingAntennaError, ValueError):
    """A setting of the fast method is out of range; the message names the field."""


@dataclass(frozen=True)
class FastConfig:
    """Settings of the fast method (SI units).

    The measurements behind the defaults are in docs/design-notes.md; what a user may change,
    in docs/fast.md ("Settings").

    Parameters
    ----------
    tolerance : float
        Declare when the 95 % interval of x_c is narrower than this (m). 5 mm, half the paper's
        typical 1 cm error.
    cap_tolerance : float
        At the cap, the final window's answer is ``ok`` when its 95 % interval is narrower than
        this (m) and every other check passes; wider, or any check failing, ``uncertain``. The
        tolerance above decides how early to stop; at the cap the method has the record the
        paper method answers from, and an interval that holds the truth bounds the error by its
        width. 1 cm, the paper's typical error and the fast method's largest allowed error.
        Never below ``tolerance``.
    settled_margin : float
        A window whose interval is wider than ``tolerance`` is declared all the same when every
        check passes, the interval is within ``cap_tolerance``, the window is long enough for
        the slip check's reference, and the interval is at most this fraction wider than the
        narrowest one unlimited data could leave (every statistical error gone, the model
        floors kept, the narrowest of omega_1 and two of its standard errors either side):
        the floors hold it above the tolerance, and waiting for the cap would narrow it
        little. 0.1; 0 waits for the cap.
    cadence : float
        Shortest time between evaluations of the growing window (s). 10 ms: on short windows
        the declaration comes at most this late after the first instant that would be sure.
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
        status ``uncertain``. 1 s, the record of the paper's spectrum on its link: an unsure
        case is never later than the paper method in data time and has at least its information
        there (on a link slower than the paper's the paper method reads longer,
        ``EstimatorConfig.spectrum_window``).
    drift_factor : float
        Non-stationarity of omega_1 measured on the recording itself: the fundamental of the
        window [t_1, t] is compared with that of [t_1, t_1 + 2/3 (t - t_1)]; ``drift_factor``
        times the change (its excess over what the noise alone explains, sqrt(max(0, d^2 -
        (se_short^2 - se^2)))) is added in quadrature to the standard error. The check sees
        what the white-noise standard error leaves out: the leakage of a close unmodelled
        mode, a slow transient. 2: an error that falls as 1 / T_w is at T_w twice its change
        from 2/3 T_w to T_w.
    min_periods : float
        The window must hold this many periods of the fitted fundamental before an estimate can
        be declared (a shorter record cannot tell a frequency from a drift), and so must the
        drift check's window of 2/3 the length (so at least 2.25 periods in all). 1.5.
    min_detection : float
        The fundamental is used only when its detection statistic, the amplitude at the window
        start over the noise (combined over channels) times sqrt(n / 2), reaches this value. For
        white noise the largest of ~n / 2 independent periodogram ordinates reaches about
        sqrt(2 ln n) ~ 3.7 standard deviations; 10 leaves no room for a noise peak.
    free_plane_margin : float
        A mode detected in the omega_1 band that vibrates mostly in the free plane is read as
        the fundamental instead of the strongest mode (in the push plane) only when its
        frequency is at most this fraction above the strongest's (:mod:`.planes`). The push
        plane rings above the straight link's omega_1 where friction holds the contact along
        the obstacle and at most 4 % below it where it slides, the free plane within -0.9 to
        +2.3 % of it (pushes up to 31 % deflection, docs/estimation.md, "The two bending
        planes"): 0.07. A free-plane mode further above every detected push-plane mode of the
        band is another vibration, such as the free plane's own where friction does not hold
        the contact, and is not read even when it is the strongest.
    push_plane_gap : float
        Relative distance (dimensionless) beyond which two detected modes of the omega_1 band
        that vibrate mostly in the push plane are two fundamentals: a link held at one point
        has one such mode, so the window holds a contact that bounced or moved
        (:func:`~.checks.other_fundamental`). 0.07, as ``free_plane_margin``: one held
        contact's free and push planes ring within that of each other where it slides, and a
        mode mixing them may be counted in the push plane.
    max_modes : int
        Largest number of damped modes tried (BIC chooses 1 .. max_modes). 3: the fundamental
        and the two strongest modes above it. The touch and the stop excite contact modes 2
        and 3 and modes of the link moving along the surface, often more than the fundamental;
        a mode left out of the model leaks into the fundamental of short windows, which then
        read omega_1 high and are held back by the drift check. Each further mode costs a full
        set of fits at every degree.
    min_mode_fraction : float
        Modes are fitted above this fraction of the lower end of the omega_1 band; slower
        content (the servo's slow creep, ~8 rad/s) goes to the polynomial. 0.6: below the band,
        above the creep.
    polynomial_degree : int
        Highest degree of the static polynomial per channel; the BIC chooses it from 2 up to
        this together with the number of modes. 4: the servo's slow creep (~8 rad/s) spans up
        to 0.8 rad of its cycle over the longest window, more than a quadratic follows; on
        short windows a quartic would take up part of the vibration itself, and the BIC then
        chooses a lower degree.
    frequency_floor : float
        Relative model error of omega_1 added in quadrature (dimensionless): how well T (or
        T_e) and the sensing curve predict the frequency. 0.003: how far a physical contact
        lets a gently pushed link ring off its calibrated sensing curve in the windows the
        method answers from (friction, the reaction's tilt, the post's radius, the contact
        settling after the stop), which a calibration on one kind of post does not see
        (docs/fast.md, "Posterior and floors"). A link whose own frequency uncertainty is larger
        (``Link.frequency_uncertainty``: its calibration's scatter, or the spread of a nominal
        T when not calibrated) uses that instead (:func:`model_floor`).
    grid_step : float
        Spacing of the x_c grid of the posterior (m). 0.25 mm, a twentieth of the tolerance.
    bias_min_samples : int
        Samples of initial rest needed to estimate the sensor bias; 20 (20 ms).
    bias_guard : float
        Time (s) of the initial rest left out before the head is seen to move: the sweep's start
        loads the sensor (inertia) while the angles are still within the rest tolerance, and
        those samples would bias the rest's mean. 0.05 s, longer than that lead.
    max_direction_drift : float or None
        Largest angle (rad) between the fitted static perpendicular reaction of the window's
        first half from t_1 (``WindowEstimate.early_statics``) and that of the whole window at
        t_e (both with the sensor bias removed) before a slip is suspected, or 3 standard
        errors of that angle when larger; None (the default): not judged, as the pipeline's
        ``max_direction_drift``.
    peak_margin : float
        No declaration while omega_1 is less than this many standard deviations below the
        maximum of the sensing curve: there the inverse is singular, and a short window's
        omega_1 a little high makes the interval collapse onto the curve's flat top, far from
        the truth. 3.
    max_disagreement : float
        Largest distance, in the ratio's standard deviations (model floor included), between the
        torque/force ratio and the maximum a posteriori x_c before the two estimators are said
        to disagree; no declaration while they do. The posterior weighs both, but where one
        of them is wrong (the fundamental of a chattering tip contact reads low) the product can
        still be narrow on the wrong branch. 3.
    max_opening : float
        Largest predicted vibration of the contact force over the static push at the window
        start. The obstacle can only push: when the fundamental's contact force (its base-force
        amplitude times :func:`~sensing_antenna.beam.modes.contact_to_base_shear` at the MAP
        x_c) exceeds the static push, the link bounces on the obstacle and is not pinned over
        the window, so its frequency is not omega_1(x_c) (windows over the bouncing read it
        low). The window then starts at the end of the pipeline's hold (``frame_window`` after
        t_1, sized for the rebounds near the tip), and a hold's length later again while the
        contact still opens there; it is only declared from a start where the contact stays
        closed. 1, the physical limit.
    higher_modes : bool
        Whether a fitted contact mode 2 or 3 enters the posterior. Off by default: a fitted
        higher mode may be one the pinned-contact model does not describe (a compliant contact
        lowers them; the link moving along the surface adds modes of its own), so a sure
        interval could rest on a wrong match.
    higher_mode_floor : float
        Relative model error of the higher contact modes (2 and 3) against their pinned-contact
        sensing curves (dimensionless), added in quadrature: to omega_2 when it narrows an
        answer at the cap (a calibration's larger ``Link.mode2_scatter`` replaces it) and to
        the fitted modes with ``higher_modes``. 0.005: covers the lowering of those modes by
        the finite-element simulator's compliant contact with a margin (a stiffer contact lowers
        them less; one three times softer than the calibration's, by 0.5 to 1 %).
    branch_mode_tolerance : float
        Relative distance (dimensionless) within which a fitted higher mode is taken as contact
        mode 2 or 3 of a candidate x_c. When omega_1 fits candidates on two branches, the window
        is not declared while a higher mode in its fit lies within this of a mode of another
        branch's candidate and farther than this (and than twice that distance) from both modes
        of the posterior's branch's candidate: the modes say the ratio chose the wrong branch.
        0.025: above the offset of fitted modes 2 and 3 from their pinned-contact curves with a
        compliant contact, below the gap between the two candidates' modes for most pairs (on
        the paper link mode 2 differs by 6 to 41 % between the candidates, mode 3 by 0 to 7 %,
        nothing where the two branches' curves cross). Used whether or not ``higher_modes`` is
        on.
    branch_by_second_mode : bool
        Whether, at every window whose posterior holds two branches of omega_1(x_c), the
        paper's second-mode test (:func:`~.fusion.second_mode_choice` on the spectrum of the
        window's own samples, :func:`~.second_mode.second_mode_chooser`) may choose the branch;
        the posterior is then conditioned on it before the other checks. On by default: the
        test answers only on a clear peak near one candidate's omega_2, and is not asked when
        the window's spectral resolution cannot separate the candidates. Off, the second mode
        is asked at the cap only.
    push_phase : bool
        Also fit every window from t_c, through the push: the contact modes ring from the
        touch on, so the push (about 0.1 s) adds periods to every window. The static loads
        follow the head's angle along the push (a regressor beside the polynomial) and every
        mode's amplitude and phase may change at t_1, where the head stops. That fit gives
        omega_1 only when it passes every kind of check the window from t_1 passes, is more
        precise, and agrees with it within ``max_disagreement`` standard deviations of their
        difference (the touch can leave content the model does not describe: a bouncing
        contact, more modes); otherwise the window from t_1 does. The statics always come from
        the window from t_1. Off by default: every window is fitted twice, so a real-time loop
        on a small machine may answer later with it than without it, although in data time it
        declares earlier where the push is clean.
    push_max_modes : int
        Largest number of modes tried on a window through the push (the touch excites contact
        modes the stop hardly does). 3.
    push_polynomial_degree : int
        Highest degree of the static polynomial on a window through the push (the BIC chooses
        it from 2, or from this when lower, up to it, with the number of modes). 2: the head's
        angle, the regressor, carries the static loads' growth over the push, and each degree
        costs a full set of fits.
    warm_start_after : float
        Windows at least this long (s, from their start: t_1, or the end of the hold where the
        window restarts there) start every fit, each polynomial degree and number of modes,
        from the solution of the same model on their drift check's reference window (the grid
        window of about 2/3 their length, fitted anyway), with one solve weighted by the noise
        found there, instead of two solves from the matrix pencil (:mod:`.warm_start`); from
        the pencil as well, the smaller BIC kept, when no detected mode of that fit reads the
        window's clear spectral peak in the omega_1 band (a shorter window may have fitted two
        close modes as one). A rule of the window alone, so a window has the same fit offline
        and online, whichever windows were fitted before. 0.2 s, the pipeline's hold: every
        window evaluated after the hold starts warm, from references that themselves start
        from the pencil while shorter than this. 0: every window from the pencil. Windows
        through the push (``push_phase``) always start from the pencil: their reference holds
        relatively more of the touch's ringing, and a start from it can settle in a worse
        optimum.
    long_window_min_modes : int
        Fewest damped modes tried on the windows that start warm (``warm_start_after``);
        shorter windows try from one. 2: the touch and the stop excite contact modes 2 and 3
        as well as the fundamental, so on windows that long the BIC almost never chooses a
        single mode, and each order costs a fit at every degree.
    """

    tolerance: float = 0.005
    cap_tolerance: float = 0.01
    settled_margin: float = 0.1
    cadence: float = 0.01
    growth: float = 1.1
    first_window: float = 0.05
    cap: float = 1.0
    drift_factor: float = 2.0
    min_periods: float = 1.5
    min_detection: float = 10.0
    free_plane_margin: float = 0.07
    push_plane_gap: float = 0.07
    max_modes: int = 3
    min_mode_fraction: float = 0.6
    polynomial_degree: int = 4
    frequency_floor: float = 0.003
    grid_step: float = 2.5e-4
    bias_min_samples: int = 20
    bias_guard: float = 0.05
    max_direction_drift: float | None = None
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
    warm_start_after: float = 0.2
    long_window_min_modes: int = 2

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name in ("higher_modes", "branch_by_second_mode", "push_phase"):
                if not isinstance(value, bool):
                    raise FastConfigError(f"{f.name}: must be true or false, got {value!r}")
                continue
            if f.name == "max_direction_drift" and value is None:
                continue
            counts = ("max_modes", "bias_min_samples", "push_max_modes", "long_window_min_modes")
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
                "warm_start_after",
                "free_plane_margin",
                "frequency_floor",
                "bias_guard",
                "settled_margin",
            )
            if value == 0.0 and f.name not in may_be_zero:
                raise FastConfigError(f"{f.name}: must be > 0, got {value!r}")
        if self.first_window > self.cap:
            raise FastConfigError("first_window: must not exceed cap")
        if self.cap_tolerance < self.tolerance:
            raise FastConfigError(
                f"cap_tolerance: must not be below tolerance ({self.tolerance!r}), "
                f"got {self.cap_tolerance!r}"
            )
        if self.growth <= 1.0:
            raise FastConfigError(f"growth: must be > 1, got {self.growth!r}")


def model_floor(link: Link, config: FastConfig) -> float:
    """Relative model error of omega_1 (dimensionless): the config's floor, or the link's own
    frequency uncertainty (:attr:`~sensing_antenna.antenna.Link.frequency_uncertainty`: its
    calibration's scatter, or the spread of a nominal T) when that is larger."""
    return max(config.frequency_floor, link.frequency_uncertainty)
