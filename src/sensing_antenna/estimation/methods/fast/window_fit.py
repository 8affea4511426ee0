"""One window's fit: the contact-load channels fitted, and the fundamental measured in it.

A window [t_s, t_j] of the five contact-load channels (:mod:`.static_fit`) is fitted with
damped sinusoids with shared poles plus a polynomial per channel
(:func:`.model_order.select_model`, order and degree by BIC), with one BLAS thread whatever the
process allows. With the push phase (``FastConfig.push_phase``) the window reaches back to t_c,
with the head's angle along the push as a regressor and every mode restarted at t_1. Fits are
cached by the window's own samples (:data:`FitCache`), so a cache never serves a fit of other
data. :func:`measure_fundamental` finds the fundamental in the fit and widens its standard
error by the drift check (:func:`.checks.drift_check`) against the grid window of 2/3 the
length; a fit that leaves the window's clear spectral peak in the band unread
(:func:`misses_band_peak`) is not declared on.
"""

from __future__ import annotations

import functools
import hashlib
import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray
from threadpoolctl import ThreadpoolController

from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.methods.fast.checks import drift_check, periods_check
from sensing_antenna.estimation.methods.fast.config import FastConfig
from sensing_antenna.estimation.methods.fast.design import ModelDesign
from sensing_antenna.estimation.methods.fast.evaluation_grid import reference_index
from sensing_antenna.estimation.methods.fast.model_order import select_model_solutions
from sensing_antenna.estimation.methods.fast.parametric import DampedSinusoidFit
from sensing_antenna.estimation.methods.fast.pencil import difference_scale, first_poles
from sensing_antenna.estimation.methods.fast.planes import free_plane_share
from sensing_antenna.estimation.methods.fast.warm_start import (
    Solutions,
    fewest_modes,
    warm_reference,
)
from sensing_antenna.estimation.methods.paper.frequency import find_peak, power_spectrum

__all__ = [
    "FitCache",
    "Fundamental",
    "PushPhase",
    "WindowSpan",
    "find_fundamental",
    "fit_window",
    "measure_fundamental",
    "misses_band_peak",
    "push_phase",
    "window_key",
]

FloatArray = NDArray[np.float64]

#: Cache of window fits, each with its candidates' solutions (what longer windows start from,
#: :mod:`.warm_start`), keyed by :func:`window_key` (the window's samples themselves and the fit
#: settings, so a cache can never serve a fit of other data or other settings).
FitCache = dict[tuple[int, int, bytes], "tuple[DampedSinusoidFit | None, Solutions]"]


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


def window_key(
    channels: FloatArray,
    rest_index: int,
    end_index: int,
    sample_period: float,
    band: tuple[float, float],
    config: FastConfig,
    push: PushPhase | None = None,
) -> tuple[int, int, bytes]:
    """Cache key of the window [rest_index, end_index]: its indices and a digest of its samples,
    of T_s, of the band and of the settings of the fit (with ``push``, of the samples from its
    start and its angle)."""
    start = rest_index if push is None else push.start
    digest = hashlib.blake2b(channels[start : end_index + 1].tobytes(), digest_size=16)
    digest.update(np.array([sample_period, *band]).tobytes())
    settings = (
        config.max_modes,
        config.polynomial_degree,
        config.min_mode_fraction,
        config.push_max_modes,
        config.push_polynomial_degree,
        config.warm_start_after,
        config.long_window_min_modes,
        config.min_detection,
    )
    digest.update(np.array(settings, dtype=float).tobytes())
    if push is not None:
        digest.update(np.array([start, rest_index]).tobytes())
        digest.update(push.angle[start : end_index + 1].tobytes())
    return rest_index, end_index, digest.digest()


def fit_window(
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
    as a regressor and the modes restarted at rest_index; from ``cache`` when it holds it.

    A window from its start (t_1, or the end of the hold) at least ``warm_start_after`` long
    starts every candidate from the solutions of its drift check's reference window
    (:mod:`.warm_start`), fitted first (and cached) when not at hand, and tries
    ``long_window_min_modes`` modes or more; from the matrix pencil as well, the smaller BIC
    kept, when that fit misses the band's clear spectral peak (:func:`misses_band_peak`).
    """
    span = WindowSpan(
        channels, rest_index, end_index, sample_period, band, config, {} if cache is None else cache
    )
    return _fit_and_solutions(span, push)[0]


def _fit_and_solutions(
    span: WindowSpan, push: PushPhase | None
) -> tuple[DampedSinusoidFit | None, Solutions]:
    """:func:`fit_window` (``span.cache`` not None) with every candidate's solution."""
    channels, rest_index, end_index, sample_period, band, config, cache = span
    assert cache is not None
    if push is not None and push.start >= rest_index:
        push = None
    key = window_key(channels, rest_index, end_index, sample_period, band, config, push)
    if key in cache:
        return cache[key]
    reference = warm_reference(rest_index, end_index, sample_period, config, push is not None)
    warm = None
    if reference is not None:
        warm = _fit_and_solutions(span._replace(end_index=reference), None)[1]
    # The fit with the smallest BIC over the polynomial degrees and model orders
    start = rest_index if push is None else push.start
    max_modes = config.max_modes if push is None else config.push_max_modes
    highest = config.polynomial_degree if push is None else config.push_polynomial_degree
    signals = channels[start : end_index + 1]
    lowest = min(2, highest)
    degrees = range(lowest, highest + 1)
    # The matrix pencil every degree starts from, computed once: where the lowest degree's
    # largest model order fits the record (otherwise each fit computes its own) and some
    # degree's largest order does not start warm
    fits_at_all = signals.shape[0] >= 3 * (lowest + 1 + 4 * max_modes)
    cold = warm is None or any((degree, max_modes) not in warm for degree in degrees)
    select = functools.partial(
        select_model_solutions,
        signals,
        sample_period,
        max_modes,
        degrees,
        start * sample_period,
        min_omega=config.min_mode_fraction * band[0],
        target_band=band,
        regressors=None if push is None else push.angle[start : end_index + 1],
        restart=None if push is None else rest_index - start,
        min_modes=fewest_modes(rest_index, end_index, sample_period, config, push is not None),
    )
    # One BLAS thread for the fit's small matrices (a few hundred rows by ten to twenty
    # columns): more threads only contend for the cores and spin, the more so when the
    # process or the machine already runs one thread per core
    with _blas_libraries().limit(limits=1, user_api="blas"):
        poles = first_poles(signals, max_modes) if fits_at_all and cold else None
        result = select(poles=poles, warm=warm)
        if (
            warm is not None
            and fits_at_all
            and misses_band_peak(signals, result[0], sample_period, band, config)
        ):
            # Started where a shorter window's fits were, the fit does not read the window's
            # clear vibration in the band (a window too short to part two close modes
            # fits them as one, and its solutions carry that on): the fits are started from
            # the pencil too, and the smaller BIC of the two kept
            from_pencil = select(
                poles=poles if poles is not None else first_poles(signals, max_modes)
            )
            if from_pencil[0] is not None and (
                result[0] is None or from_pencil[0].bic < result[0].bic
            ):
                result = from_pencil
    cache[key] = result
    return result


#: Power over the band's median a spectral peak needs before a fit is asked to read it
#: (:func:`misses_band_peak`): the paper method's clear peak, its default
#: ``min_peak_quality``. A false alarm costs one more set of fits and leaves the window
#: undeclared on (:func:`measure_fundamental`); a longer window sharpens the spectrum.
_CLEAR_PEAK = EstimatorConfig.min_peak_quality


def misses_band_peak(
    signals: FloatArray,
    fit: DampedSinusoidFit | None,
    sample_period: float,
    band: tuple[float, float],
    config: FastConfig,
    push_direction: FloatArray | None = None,
) -> bool:
    """Whether ``fit`` (of ``signals``, the five contact-load channels, shape (n, 5)) misses
    the highest clear peak (:data:`_CLEAR_PEAK`) in ``band`` (rad/s) of the channels' summed
    spectrum or, with ``push_direction`` (as in :func:`find_fundamental`), of the push plane's
    (:mod:`.planes`: the reaction along the push and the moment across it): none of its modes
    detected at ``config.min_detection`` lies within the half width of the Hann window's main
    lobe, 4 pi / T_w, of the peak (True without a fit, when the band holds a clear peak).
    The push plane's own spectrum is asked because a strong vibration of the free plane can
    hide its peak in the sum, and without the push plane's mode :func:`find_fundamental`
    cannot tell the free plane's other vibrations from the fundamental. The channels are rid
    of the fit's static part at ``config.polynomial_degree`` (:class:`.design.ModelDesign`'s
    polynomial columns); each channel of either spectrum, the push plane's projected in
    physical units first, is divided by its noise (:func:`.pencil.difference_scale`). False
    when neither spectrum holds a clear peak."""
    n, k = signals.shape
    static = _static_basis(n, sample_period, config.polynomial_degree)
    dynamic = signals - static @ (static.T @ signals)
    columns = [dynamic / difference_scale(signals)]
    if push_direction is not None and k == 5:
        length = float(np.hypot(push_direction[0], push_direction[1]))
        if math.isfinite(length) and length > 0.0:
            # projected in physical units, then each over its noise: scaling the channels
            # first would turn the projection off the push plane when their noises differ
            u = np.asarray(push_direction, dtype=float) / length
            v = np.array([-u[1], u[0]])
            plane = np.stack([dynamic[:, 0:2] @ u, dynamic[:, 3:5] @ v], axis=1)
            columns.append(plane / difference_scale(plane))
    # one transform for the channels and the push plane's two
    omega, power = power_spectrum(np.hstack(columns), sample_period, zero_padding=2)
    lobe = 4.0 * math.pi / (n * sample_period)
    for summed in (power[:, :k], power[:, k:]):
        if not summed.shape[1]:
            continue
        peak = find_peak(omega, summed.sum(axis=1), band)
        if peak is None or peak.quality < _CLEAR_PEAK:
            continue
        if fit is None:
            return True
        near = np.abs(fit.omega - peak.omega) <= lobe
        if not np.any(near & (fit.detection() >= config.min_detection)):
            return True
    return False


@functools.lru_cache(maxsize=64)
def _static_basis(n: int, sample_period: float, degree: int) -> FloatArray:
    """Orthonormal columns, shape (n, degree + 1), spanning the fit's polynomial part of a
    window of ``n`` samples (:class:`.design.ModelDesign`'s polynomial columns)."""
    basis, _ = np.linalg.qr(ModelDesign(n, sample_period, degree).fixed)
    basis = np.asarray(basis, dtype=float)
    basis.setflags(write=False)  # shared by every caller through the cache
    return basis


@functools.cache
def _blas_libraries() -> ThreadpoolController:
    """The BLAS libraries loaded in this process, found once, when a fit first needs them:
    numpy's, and scipy's, whose LAPACK the compiled solver calls."""
    import scipy.linalg  # noqa: F401  (loads scipy's BLAS, so the controller sees it)

    return ThreadpoolController()


def find_fundamental(
    fit: DampedSinusoidFit | None,
    band: tuple[float, float],
    config: FastConfig,
    push_direction: FloatArray | None = None,
) -> tuple[int | None, str]:
    """Index of the fundamental in ``fit`` and, when it cannot be used, why.

    The strongest mode in the omega_1 band; with ``push_direction`` (the hold's reaction
    across the link, (R_y, R_z) in the motor frame), when that mode vibrates mostly in the
    push plane, the strongest detected mode of the band that vibrates mostly in the free
    plane at most ``free_plane_margin`` above it (:mod:`.planes`): out of its bending plane
    the bent link keeps the straight link's omega_1, in it a held contact raises it, or lowers
    it by at most a few per cent where the contact slides. So when the strongest mode lies in
    the free plane more than the margin above every detected push-plane mode of the band, it
    is another vibration (the free plane's own where the contact does not hold it): the
    fundamental is chosen as above from the strongest of those push-plane modes.
    """
    if fit is None:
        return None, "window too short for the model"
    k = fit.strongest_in_band(band)
    if k is None:
        return None, "no vibration mode in the omega_1 band"
    detection = fit.detection()
    if push_direction is not None:
        share = free_plane_share(fit, push_direction)
        detected = fit.in_band(band) & (detection >= config.min_detection)
        ceiling = 1.0 + config.free_plane_margin
        pushed = detected & (share < 0.5)
        if share[k] > 0.5 and pushed.any() and np.all(ceiling * fit.omega[pushed] < fit.omega[k]):
            # every push-plane mode far below the free plane's: the push plane's is read (a fit
            # that cannot bound its frequency gives no fundamental, below)
            below = np.flatnonzero(pushed)
            k = int(below[np.argmax(detection[below])])
        usable = detected & np.isfinite(fit.omega_se)
        free = np.flatnonzero(usable & (share > 0.5) & (fit.omega <= ceiling * fit.omega[k]))
        if free.size and not share[k] > 0.5:
            k = int(free[np.argmax(detection[free])])
    if detection[k] < config.min_detection:
        return None, f"the fundamental's detection statistic is only {detection[k]:.1f}"
    if not (fit.converged and math.isfinite(fit.omega_se[k])):
        return None, "the fit did not converge"
    return k, ""


class Fundamental(NamedTuple):
    """The fundamental of one window and the checks on it (see :func:`measure_fundamental`).

    Attributes
    ----------
    fit : DampedSinusoidFit or None
        The window's fit.
    mode : int or None
        Index of the fundamental in ``fit``; None when there is none to use.
    omega1, omega1_se, omega1_crb : float
        Fundamental, its standard error with the drift term, and the fit's own standard error
        (the Cramer-Rao value of the fitted model) (rad/s); NaN without a fundamental.
    drift : float
        Change of omega_1 from the window of 2/3 the length beyond what the noise explains
        (rad/s); NaN without a drift reference.
    notes : tuple of str
        Why the fundamental cannot be declared on (empty when every check passed).
    failed : frozenset of str
        The checks that failed: "fundamental", "periods", "band_peak" (no detected mode at
        the window's clear spectral peak in the band, :func:`misses_band_peak`),
        "drift_reference".
    """

    fit: DampedSinusoidFit | None
    mode: int | None
    omega1: float
    omega1_se: float
    omega1_crb: float
    drift: float
    notes: tuple[str, ...]
    failed: frozenset[str] = frozenset()


class WindowSpan(NamedTuple):
    """The window [rest_index, end_index] and what its fits need: :func:`fit_window`'s leading
    arguments, in order."""

    channels: FloatArray
    rest_index: int
    end_index: int
    sample_period: float
    band: tuple[float, float]
    config: FastConfig
    cache: FitCache | None


def measure_fundamental(
    span: WindowSpan, push: PushPhase | None, push_direction: FloatArray | None = None
) -> Fundamental:
    """Fit the window (through the push when given) and measure its fundamental: its standard
    error with the drift check's term, and the period checks. ``push_direction`` as in
    :func:`find_fundamental`."""
    config, band = span.config, span.band
    fit = fit_window(*span, push)
    omega1 = omega1_se = omega1_crb = drift = math.nan
    k, note = find_fundamental(fit, band, config, push_direction)
    notes = [note] if note else []
    failed = {"fundamental"} if note else set()
    if fit is not None and k is not None:
        omega1 = float(fit.omega[k])
        omega1_crb = float(fit.omega_se[k])
        omega1_se = omega1_crb
        note = periods_check(fit, omega1, config)
        if note:
            notes.append(note)
            failed.add("periods")
        window = span.channels[span.rest_index : span.end_index + 1]
        if misses_band_peak(window, fit, span.sample_period, band, config, push_direction):
            # A clear vibration of the band that no detected mode reads: the fundamental
            # found may be another vibration (a slide's ring, the free plane's own) beside
            # the contact's
            notes.append(
                "the fit leaves the window's clear spectral peak in the omega_1 band unread"
            )
            failed.add("band_peak")
        # The same fundamental on a window of 2/3 the length: its change measures how far
        # unmodelled content still moves the estimate (drift_factor times it, in quadrature)
        ref = reference_index(
            span.rest_index, span.end_index, 2.0 / 3.0, span.sample_period, config
        )
        ref_fit = None if ref is None else fit_window(*span._replace(end_index=ref), push)
        k_ref, _ = find_fundamental(ref_fit, band, config, push_direction)
        drift, note = drift_check(ref_fit, k_ref, omega1, omega1_crb, config)
        if note:
            notes.append(note)
            failed.add("drift_reference")
        else:
            omega1_se = math.hypot(omega1_se, config.drift_factor * drift)
    return Fundamental(
        fit, k, omega1, omega1_se, omega1_crb, drift, tuple(notes), frozenset(failed)
    )
