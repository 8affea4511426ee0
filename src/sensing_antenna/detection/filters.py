"""Discrete filters shared by the estimators, each as a streaming object and a batch function.

Both filters are discretised with the bilinear (Tustin) transform, prewarped at their
characteristic frequency omega_p: s -> c (1 - z^-1) / (1 + z^-1), c = omega_p / tan(omega_p T_s/2).
The bilinear map sends the stable left half-plane inside the unit circle, so a stable continuous
filter gives a stable discrete one for any T_s, and prewarping makes the discrete response match the
continuous one exactly at omega_p (the cut-off of Eq. 20, the natural frequency of Eq. 15). The
frequency axis is otherwise compressed as omega_d = (2 / T_s) arctan(omega T_s / 2), an error below
0.1 % for omega < 0.1 pi / T_s (157 rad/s at 1 kHz).

Streaming objects implement exactly the direct form II transposed recursion that
``scipy.signal.lfilter`` uses, with the same coefficients, so streaming and batch outputs agree to
rounding. Initial conditions: the low-pass filter starts in steady state at its first input; the
free-motion observer starts at rest and is fed the angle relative to the first sample (its s^2
numerator gives zero output for a constant angle, so the first angle is not a start-up step).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import lfilter, lfilter_zi

from sensing_antenna.antenna import FreeMotionObserver
from sensing_antenna.errors import SensingAntennaError

__all__ = [
    "FilterConfigError",
    "FirstOrderLowPass",
    "FreeMotionObserverFilter",
    "low_pass",
    "low_pass_coefficients",
    "observe_free_motion",
    "observer_coefficients",
]

#: Cut-off omega_c of the low-pass filter of Eq. 20 used by the paper (rad/s, Sections 5.1, 5.3).
PAPER_LOW_PASS_CUTOFF = 5.0


class FilterConfigError(SensingAntennaError, ValueError):
    """A filter cannot be discretised at the requested sample period."""


def _tustin_constant(omega: float, sample_period: float, what: str) -> float:
    if not (math.isfinite(sample_period) and sample_period > 0):
        raise FilterConfigError(f"sample_period: must be finite and > 0, got {sample_period!r}")
    if not (math.isfinite(omega) and omega > 0):
        raise FilterConfigError(f"{what}: must be finite and > 0, got {omega!r}")
    if omega * sample_period >= math.pi:
        raise FilterConfigError(
            f"{what}: {omega:g} rad/s is at or above the Nyquist frequency "
            f"{math.pi / sample_period:g} rad/s of the sample period {sample_period:g} s"
        )
    return omega / math.tan(0.5 * omega * sample_period)


def low_pass_coefficients(
    cutoff: float, sample_period: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Coefficients (b, a) of Eq. 20, G(s) = 1 / (1 + s / omega_c), discretised (Tustin, prewarped).

    Parameters
    ----------
    cutoff : float
        omega_c (rad/s), below pi / sample_period.
    sample_period : float
        T_s (s).

    Returns
    -------
    b, a : ndarray, shape (2,)
        ``lfilter`` numerator and denominator, a[0] = 1. Unit gain at DC.
    """
    c = _tustin_constant(cutoff, sample_period, "cutoff")
    # Eq. 20 with s = c (1 - z^-1) / (1 + z^-1):
    # G(z) = omega_c (1 + z^-1) / ((omega_c + c) + (omega_c - c) z^-1)
    norm = cutoff + c
    b = np.array([cutoff / norm, cutoff / norm])
    a = np.array([1.0, (cutoff - c) / norm])
    return b, a


def observer_coefficients(
    observer: FreeMotionObserver, sample_period: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Coefficients (b, a) of Eq. 15, K s^2 / (s^2 + d s + omega^2), discretised (Tustin,
    prewarped at omega).

    Parameters
    ----------
    observer : FreeMotionObserver
        Gain K (N m / rad), natural frequency omega (rad/s), damping d (1/s).
    sample_period : float
        T_s (s); omega T_s must be below pi.

    Returns
    -------
    b, a : ndarray, shape (3,)
        ``lfilter`` coefficients mapping an angle (rad) to a torque (N m), a[0] = 1.
    """
    w = observer.natural_frequency
    c = _tustin_constant(w, sample_period, "observer.natural_frequency")
    k, d = observer.gain, observer.damping
    # Eq. 15 with s = c (1 - z^-1) / (1 + z^-1), multiplied through by (1 + z^-1)^2:
    # numerator K c^2 (1 - z^-1)^2, denominator c^2 (1 - z^-1)^2 + d c (1 - z^-2) + w^2 (1 + z^-1)^2
    a0 = c * c + d * c + w * w
    a1 = 2.0 * (w * w - c * c)
    a2 = c * c - d * c + w * w
    b = (k * c * c / a0) * np.array([1.0, -2.0, 1.0])
    a = np.array([1.0, a1 / a0, a2 / a0])
    return b, a


class FirstOrderLowPass:
    """Streaming low-pass filter of Eq. 20 on one scalar signal.

    Parameters
    ----------
    cutoff : float
        omega_c (rad/s).
    sample_period : float
        T_s (s).

    Notes
    -----
    The first :meth:`update` after :meth:`reset` puts the filter in steady state at its input and
    returns it unchanged, as :func:`low_pass` does.
    """

    def __init__(self, cutoff: float = PAPER_LOW_PASS_CUTOFF, sample_period: float = 1e-3) -> None:
        b, a = low_pass_coefficients(cutoff, sample_period)
        self.cutoff = float(cutoff)
        self.sample_period = float(sample_period)
        self._b0 = float(b[0])
        self._b1 = float(b[1])
        self._a1 = float(a[1])
        self._state = 0.0
        self._started = False
        self.output = 0.0

    def reset(self) -> None:
        """Forget the past: the next input restarts the filter in steady state."""
        self._state = 0.0
        self._started = False
        self.output = 0.0

    def update(self, value: float) -> float:
        """Filter one sample; returns (and stores in ``output``) the filtered value."""
        if not self._started:
            # Steady state at the first input: y = x and the DF2T state z = (b1 - a1) x.
            self._started = True
            self._state = (self._b1 - self._a1) * value
        # Direct form II transposed, as scipy.signal.lfilter.
        y = self._b0 * value + self._state
        self._state = self._b1 * value - self._a1 * y
        self.output = y
        return y


def low_pass(
    signal: ArrayLike, cutoff: float = PAPER_LOW_PASS_CUTOFF, sample_period: float = 1e-3
) -> NDArray[np.float64]:
    """Batch low-pass filter of Eq. 20 along axis 0, starting in steady state at the first sample.

    Parameters
    ----------
    signal : array_like, shape (n,) or (n, k)
    cutoff : float
        omega_c (rad/s).
    sample_period : float
        T_s (s).

    Returns
    -------
    ndarray, same shape as ``signal``
        Identical (to rounding) to :class:`FirstOrderLowPass` run sample by sample.
    """
    x = np.asarray(signal, dtype=np.float64)
    b, a = low_pass_coefficients(cutoff, sample_period)
    if x.shape[0] == 0:
        return x.copy()
    zi_shape = (1,) + (1,) * (x.ndim - 1)
    zi = lfilter_zi(b, a).reshape(zi_shape) * x[:1]
    y, _ = lfilter(b, a, x, axis=0, zi=zi)
    return np.asarray(y, dtype=np.float64)


class FreeMotionObserverFilter:
    """Streaming free-motion observer of Eq. 15 for one joint: angle (rad) in, torque (N m) out.

    Parameters
    ----------
    observer : FreeMotionObserver
    sample_period : float
        T_s (s).

    Notes
    -----
    The observer starts at rest; it is fed theta - theta[0] where theta[0] is the first angle
    after :meth:`reset`, exactly as :func:`observe_free_motion`.
    """

    def __init__(self, observer: FreeMotionObserver, sample_period: float) -> None:
        b, a = observer_coefficients(observer, sample_period)
        self.observer = observer
        self.sample_period = float(sample_period)
        self._b0, self._b1, self._b2 = (float(v) for v in b)
        self._a1, self._a2 = float(a[1]), float(a[2])
        self.reset()

    def reset(self) -> None:
        """Back to rest; the next angle becomes the reference angle."""
        self._z1 = 0.0
        self._z2 = 0.0
        self._origin: float | None = None
        self.output = 0.0

    def update(self, angle: float) -> float:
        """Observe one angle (rad); returns (and stores in ``output``) the torque (N m)."""
        if self._origin is None:
            self._origin = angle
        x = angle - self._origin
        # Direct form II transposed, as scipy.signal.lfilter.
        y = self._b0 * x + self._z1
        self._z1 = self._b1 * x - self._a1 * y + self._z2
        self._z2 = self._b2 * x - self._a2 * y
        self.output = y
        return y


def observe_free_motion(
    angles: ArrayLike, observer: FreeMotionObserver, sample_period: float
) -> NDArray[np.float64]:
    """Batch free-motion observer of Eq. 15 along axis 0 (from rest, relative to the first angle).

    Parameters
    ----------
    angles : array_like, shape (n,) or (n, k)
        Motor angles (rad).
    observer : FreeMotionObserver
    sample_period : float
        T_s (s).

    Returns
    -------
    ndarray, same shape as ``angles``
        Torque K s^2 / (s^2 + d s + omega^2) theta (N m), identical (to rounding) to
        :class:`FreeMotionObserverFilter`.
    """
    x = np.asarray(angles, dtype=np.float64)
    b, a = observer_coefficients(observer, sample_period)
    if x.shape[0] == 0:
        return x.copy()
    y = lfilter(b, a, x - x[:1], axis=0)
    return np.asarray(y, dtype=np.float64)
