"""Estimator 1 (Sections 4.3 and 5.4): the fundamental frequency of the vibration in contact.

After t_1 the head is still and the link, clamped at the base and pinned at the contact, vibrates
at the natural frequencies of Eq. 3 with the boundary conditions of Eq. 4. Both bending planes
through the link axis have the same stiffness (circular section) and the contact pins the link in
both, so the torque about Y^c (vibration along Z^c, out of the push plane, the paper's choice)
and the torque about Z^c (vibration in the push plane) oscillate at the same omega_1. Which of the
two carries the vibration depends on the device: the paper found the push plane damped, a linear
symmetric model may show the opposite. So both are examined, plus the sum of their power spectra
(invariant to a rotation of the frame about X^c), and the clearest peak wins; the choice and the
peak quality of each are reported.

Spectrum: linear detrend (removes the static torque and the servo's slow settling), Hann window,
zero padding to ``zero_padding`` times the window length, peak searched among the local maxima
inside the band the sensing curve allows, refined by a parabola through the logarithm of the three
power values around the maximum (exact for a Gaussian peak, nearly exact for the Hann main lobe on
a finely padded grid). The frequency of a decaying sinusoid is not biased by the decay: the product
of the window and the decay is a real function, so its transform has a magnitude symmetric about
the oscillation frequency.

Peak quality is the peak power divided by the median power in the band: about 1 to 10 for noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.front.spectrum import power_spectrum

if TYPE_CHECKING:
    from sensing_antenna.estimation.front.evidence import Evidence

__all__ = [
    "COMPONENTS",
    "FrequencyMeasurement",
    "SpectralPeak",
    "evidence_frequency",
    "evidence_spectrum",
    "find_peak",
    "measure_frequency",
    "power_spectrum",
    "second_mode_peak",
]

FloatArray = NDArray[np.float64]

#: Names of the spectra examined: torque about Y^c, about Z^c, and the sum of both powers.
COMPONENTS = ("y_c", "z_c", "sum")


@dataclass(frozen=True)
class SpectralPeak:
    """A peak of a power spectrum.

    Attributes
    ----------
    omega : float
        Interpolated peak frequency (rad/s).
    power : float
        Interpolated peak power (signal units squared, arbitrary scale).
    quality : float
        Peak power over the median power of the band (dimensionless).
    """

    omega: float
    power: float
    quality: float


@dataclass(frozen=True)
class FrequencyMeasurement:
    """The fundamental frequency measured over a window of samples.

    Attributes
    ----------
    omega1 : float
        Fundamental frequency (rad/s); NaN when no peak was found in the band.
    quality : float
        Peak quality of the chosen spectrum (dimensionless); NaN when no peak.
    component : str
        Which spectrum gave the peak: ``"y_c"`` (torque about Y^c), ``"z_c"`` or ``"sum"``.
    t_start, t_end : float
        The analysed window (s).
    band : tuple of float
        The searched band (rad/s).
    clear : bool
        True when ``quality`` reaches the configured threshold.
    peaks : dict
        Peak of each spectrum (None where none was found), keyed by :data:`COMPONENTS`.
    reason : str or None
        Why there is no usable measurement (no contact, no push, too short), else None.
    """

    omega1: float
    quality: float
    component: str
    t_start: float
    t_end: float
    band: tuple[float, float]
    clear: bool
    peaks: dict[str, SpectralPeak | None] = field(default_factory=dict)
    reason: str | None = None

    def components_agree(self, relative_tolerance: float) -> bool | None:
        """Whether the y_c and z_c peaks agree within a relative tolerance (None: not both)."""
        y, z = self.peaks.get("y_c"), self.peaks.get("z_c")
        if y is None or z is None:
            return None
        return abs(y.omega - z.omega) <= relative_tolerance * max(y.omega, z.omega)


def find_peak(
    omega: FloatArray,
    power: FloatArray,
    band: tuple[float, float],
    lowest_clear: tuple[float, float] | None = None,
) -> SpectralPeak | None:
    """Highest local maximum of a power spectrum inside a band, refined by interpolation.

    With ``lowest_clear = (min_quality, isolation)``, the lowest-frequency local maximum that is
    clear (quality >= min_quality) and isolated (the largest power within +-isolation rad/s, so
    not a side lobe of a stronger peak) is returned instead, when there is one: the fundamental
    is the lowest mode, and a wide band may also hold the second mode, stronger in the torque.

    Parameters
    ----------
    omega : array, shape (m,)
        Uniform frequency grid (rad/s).
    power : array, shape (m,)
        Power at each frequency.
    band : tuple of float
        (low, high) limits of the search (rad/s).

    Returns
    -------
    SpectralPeak or None
        None when the band holds no local maximum (monotonic spectrum, empty band, zero signal).
    """
    inside = np.flatnonzero((omega >= band[0]) & (omega <= band[1]))
    inside = inside[(inside > 0) & (inside < omega.size - 1)]
    if inside.size == 0:
        return None
    p = power
    local = inside[(p[inside] > p[inside - 1]) & (p[inside] >= p[inside + 1])]
    if local.size == 0:
        return None
    k = int(local[np.argmax(p[local])])
    floor = float(np.median(p[inside]))
    if lowest_clear is not None and floor > 0.0:
        min_quality, isolation = lowest_clear
        reach = max(1, round(isolation / float(omega[1] - omega[0])))
        for j in local:
            lo, hi = max(0, j - reach), min(p.size, j + reach + 1)
            if p[j] >= min_quality * floor and p[j] >= p[lo:hi].max():
                k = int(j)
                break
    if p[k] <= 0.0:
        return None
    tiny = np.finfo(float).tiny
    a, b, c = np.log(np.maximum(p[k - 1 : k + 2], tiny))
    denominator = a - 2.0 * b + c
    shift = 0.5 * (a - c) / denominator if denominator < 0 else 0.0
    shift = float(np.clip(shift, -0.5, 0.5))
    step = float(omega[1] - omega[0])
    peak_power = float(np.exp(b - 0.25 * (a - c) * shift))
    quality = peak_power / floor if floor > 0 else math.inf
    return SpectralPeak(omega=float(omega[k]) + shift * step, power=peak_power, quality=quality)


def measure_frequency(
    torque_m: FloatArray,
    axes_m: FloatArray,
    sample_period: float,
    band: tuple[float, float],
    min_quality: float,
    zero_padding: int = 16,
    t_start: float = 0.0,
) -> FrequencyMeasurement:
    """Measure omega_1 in the torque about Y^c and Z^c over a window.

    Parameters
    ----------
    torque_m : array, shape (n, 3)
        Torque by the link on the head over the window Delta t_e1, motor frame (N m).
    axes_m : array, shape (3, 3)
        Rows X^c, Y^c, Z^c in motor coordinates.
    sample_period : float
        T_s (s).
    band : tuple of float
        Search band (rad/s).
    min_quality : float
        Peak quality above which the peak is clear.
    zero_padding : int
        See :func:`power_spectrum`.
    t_start : float
        Time of the first sample (s), for the report.

    Returns
    -------
    FrequencyMeasurement
    """
    torque = np.asarray(torque_m, dtype=float)
    # Section 5.4: the torque components along Y^c and Z^c (projection on the contact frame)
    projected = torque @ np.asarray(axes_m, dtype=float)[1:].T
    omega, power = power_spectrum(projected, sample_period, zero_padding)
    return _read_peaks(omega, power, torque.shape[0], sample_period, band, min_quality, t_start)


def _read_peaks(
    omega: FloatArray,
    power: FloatArray,
    n_samples: int,
    sample_period: float,
    band: tuple[float, float],
    min_quality: float,
    t_start: float,
) -> FrequencyMeasurement:
    """Estimator 1's choice among the y_c, z_c and summed spectra (``power`` shape (m, 2)) of
    a window of ``n_samples``."""
    spectra = {"y_c": power[:, 0], "z_c": power[:, 1], "sum": power[:, 0] + power[:, 1]}
    # A side lobe of the Hann window is within 8 DFT bins of its peak (-50 dB beyond)
    isolation = 8.0 * 2.0 * math.pi / (n_samples * sample_period)
    peaks = {
        name: find_peak(omega, spectra[name], band, (min_quality, isolation)) for name in COMPONENTS
    }
    found = {name: peak for name, peak in peaks.items() if peak is not None}
    t_end = t_start + (n_samples - 1) * sample_period
    if not found:
        return FrequencyMeasurement(
            math.nan, math.nan, "none", t_start, t_end, band, False, peaks=peaks
        )
    best = max(found, key=lambda name: found[name].quality)
    peak = found[best]
    return FrequencyMeasurement(
        omega1=peak.omega,
        quality=peak.quality,
        component=best,
        t_start=t_start,
        t_end=t_end,
        band=band,
        clear=peak.quality >= min_quality,
        peaks=peaks,
    )


def evidence_frequency(
    evidence: Evidence, band: tuple[float, float] | None = None
) -> FrequencyMeasurement:
    """Estimator 1 over the Delta t_e1 window of the evidence after t_1.

    ``band`` (rad/s) defaults to the evidence's own omega_1 band.
    """
    window = evidence.spectrum_slice
    omega, power = evidence.window_spectrum
    return _read_peaks(
        omega,
        power,
        window.stop - window.start,
        evidence.sample_period,
        evidence.band if band is None else band,
        evidence.config.min_peak_quality,
        float(evidence.t[window.start]),
    )


def evidence_spectrum(evidence: Evidence, component: str) -> tuple[FloatArray, FloatArray]:
    """Power spectrum of the torque about Y^c (``"y_c"``), Z^c (``"z_c"``) or their sum.

    Over the Delta t_e1 window of the evidence, as Estimator 1 computes it.

    Returns
    -------
    omega : array, shape (m,)
        Angular frequencies (rad/s).
    power : array, shape (m,)
    """
    omega, power = evidence.window_spectrum
    spectra = {"y_c": power[:, 0], "z_c": power[:, 1]}
    return omega, spectra.get(component, power.sum(axis=1))


def second_mode_peak(
    evidence: Evidence, component: str, expected: float, omega1: float
) -> SpectralPeak | None:
    """The second contact mode's spectral peak near ``expected`` (rad/s), or None.

    Searched, in the spectrum of ``component`` over the evidence's Delta t_e1 window, within
    ``omega2_window`` of ``expected`` (the model's omega_2 where the contact is thought to be);
    its quality is over the median power within a factor 1 + 4 ``omega2_window`` of it (the
    search band itself lies on the peak's main lobe). None when that band holds no peak of at
    least ``min_peak_quality``, when the peak lies nearer 2 or 3 omega_1 than ``expected`` (a
    clipping contact's harmonic may be what it is: on the paper link 2 omega_1 comes within 4 %
    of omega_2 near 0.73 m, and 3 omega_1 meets it near 0.63 and 0.84 m), or when omega_1 is
    not known.
    """
    cfg = evidence.config
    if not (math.isfinite(expected) and expected > 0.0 and math.isfinite(omega1)):
        return None
    omega, spectrum = evidence_spectrum(evidence, component)
    band = (expected / (1.0 + cfg.omega2_window), expected * (1.0 + cfg.omega2_window))
    peak = find_peak(omega, spectrum, band)
    wide = (omega >= expected / (1.0 + 4.0 * cfg.omega2_window)) & (
        omega <= expected * (1.0 + 4.0 * cfg.omega2_window)
    )
    floor = float(np.median(spectrum[wide])) if np.any(wide) else 0.0
    if peak is None or not peak.power >= cfg.min_peak_quality * floor:
        return None
    for harmonic in (2.0 * omega1, 3.0 * omega1):
        if abs(peak.omega - harmonic) < abs(peak.omega - expected):
            return None
    return SpectralPeak(peak.omega, peak.power, peak.power / floor if floor > 0 else math.inf)
