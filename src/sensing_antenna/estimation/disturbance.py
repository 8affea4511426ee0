"""A line at the answer's omega_1 in the torques before the contact: a steady disturbance.

The contact modes ring only once the link touches; at rest before the sweep the sensor reads the
link's weight and noise. A sinusoid at the contact's fundamental already there (a drive's PWM or
a switching supply aliased into the band by a sampler without an anti-alias filter, a machine
nearby) goes on through the hold, where a fit of the ringing can take it for the contact's mode:
it does not decay, and a method that weighs the late window reads it more than the decaying
ringing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.front.spikes import WRENCH_CHANNELS

FloatArray = NDArray[np.float64]

__all__ = ["RestLine", "line_at", "rest_line"]


@dataclass(frozen=True)
class RestLine:
    """The line at a frequency in one channel over its rest.

    Attributes
    ----------
    channel : str
        The channel's column name.
    amplitude : float
        The line's amplitude (the channel's unit).
    standard_error : float
        The amplitude's standard error from the residual.
    samples : int
        The rest's length (samples).
    """

    channel: str
    amplitude: float
    standard_error: float
    samples: int

    @property
    def significance(self) -> float:
        """The amplitude in standard errors (0 when there is no error to weigh it by)."""
        return self.amplitude / self.standard_error if self.standard_error > 0.0 else 0.0


def line_at(t: FloatArray, y: FloatArray, omega: float) -> tuple[float, float]:
    """Amplitude of a sinusoid at ``omega`` (rad/s) in ``y`` over ``t`` (s) by least squares,
    with a parabola fitted beside it (an offset, a drift, the bow of a slow swing), and its
    standard error from the residual (the parameters' covariance, so a window of about a
    period, where the sinusoid and the parabola trade, says so): (amplitude, standard error),
    in ``y``'s unit."""
    with np.errstate(all="ignore"):  # loads beyond float range read as no line (NaN)
        return _line_at(t, y, omega)


def _line_at(t: FloatArray, y: FloatArray, omega: float) -> tuple[float, float]:
    """:func:`line_at`, its arithmetic."""
    if not np.all(np.isfinite(y)):
        return math.nan, math.nan
    u = (t - t.mean()) / max(float(np.ptp(t)), 1e-12)
    design = np.column_stack(
        [np.cos(omega * t), np.sin(omega * t), np.ones_like(t), u, u**2 - 1.0 / 12.0]
    )
    columns = design.shape[1]
    try:
        coefficients, _, rank, _ = np.linalg.lstsq(design, y, rcond=None)
    except np.linalg.LinAlgError:
        return math.nan, math.nan
    if rank < columns or t.size <= columns:
        return math.nan, math.nan
    residual = y - design @ coefficients
    variance = float(residual @ residual) / (t.size - columns)
    # noise that is not white (a sensor's own low-pass filter) has more power near omega than
    # its variance says: the least-squares error scaled by the residual's spectral density at
    # omega over its mean (never below 1)
    variance *= _colour(residual, omega * float(np.median(np.diff(t))))
    covariance = variance * np.linalg.inv(design.T @ design)[:2, :2]
    amplitude = math.hypot(float(coefficients[0]), float(coefficients[1]))
    if amplitude > 0.0:
        unit = coefficients[:2] / amplitude
        error = math.sqrt(max(float(unit @ covariance @ unit), 0.0))
    else:
        error = math.sqrt(max(float(np.trace(covariance)) / 2.0, 0.0))
    return amplitude, error


def _colour(residual: FloatArray, phase: float) -> float:
    """The residual's spectral density at ``phase`` (rad per sample) over its variance, at
    least 1: that of an autoregressive model of order 2 fitted to it (Yule-Walker), which
    takes a sensor's low-pass filter of second order."""
    n = residual.size
    centred = residual - residual.mean()
    gamma = [float(centred[k:] @ centred[: n - k]) / n for k in range(3)]
    if not gamma[0] > 0.0:
        return 1.0
    matrix = np.array([[gamma[0], gamma[1]], [gamma[1], gamma[0]]])
    try:
        a = np.linalg.solve(matrix, np.array([gamma[1], gamma[2]]))
    except np.linalg.LinAlgError:
        return 1.0
    innovation = gamma[0] - float(a @ np.array([gamma[1], gamma[2]]))
    response = 1.0 - a[0] * np.exp(-1j * phase) - a[1] * np.exp(-2j * phase)
    density = innovation / max(float(abs(response) ** 2), 1e-12)
    return max(1.0, density / gamma[0]) if math.isfinite(density) else 1.0


def rest_line(
    t: FloatArray, torque: FloatArray, rests: tuple[int, ...], omega: float
) -> RestLine | None:
    """The most significant line at ``omega`` (rad/s) among the torque channels (``torque``,
    N m, shape (n, 3)), each over its own rest at the start (``rests``: samples, one per
    channel); None when no channel rests for half a period of ``omega``."""
    if not (math.isfinite(omega) and omega > 0.0):
        return None
    best: RestLine | None = None
    for k, name in enumerate(WRENCH_CHANNELS[3:]):
        n = min(int(rests[k]), t.shape[0])
        if n < 16 or float(t[n - 1] - t[0]) < math.pi / omega:
            continue
        amplitude, error = line_at(t[:n], np.asarray(torque[:n, k], dtype=float), omega)
        if not (math.isfinite(amplitude) and math.isfinite(error)):
            continue
        found = RestLine(name, amplitude, error, n)
        if best is None or found.significance > best.significance:
            best = found
    return best
