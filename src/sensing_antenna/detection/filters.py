"""Discrete filters shared by the detectors and the estimators: one streaming object each.

Both filters are discretised with the bilinear (Tustin) transform, prewarped at their
characteristic frequency omega_p: s -> c (1 - z^-1) / (1 + z^-1), c = omega_p / tan(omega_p T_s/2).
The bilinear map sends the stable left half-plane inside the unit circle, so a stable continuous
filter gives a stable discrete one for any T_s, and prewarping makes the discrete response match the
continuous one exactly at omega_p (the cut-off of Eq. 20, the natural frequency of Eq. 15). The
frequency axis is otherwise compressed as omega_d = (2 / T_s) arctan(omega T_s / 2), an error below
0.1 % for omega < 0.1 pi / T_s (157 rad/s at 1 kHz).

One recursion, :func:`df2t_step`, compiled with numba: the direct form II transposed that
``scipy.signal.lfilter`` uses, with the same coefficients and the same order of operations, so its
output equals ``lfilter``'s to the bit. The streaming objects feed it a block of samples at a time
with the state carried, and a block of one sample is the per-sample form; the batch functions
(:func:`low_pass`, :func:`observe_free_motion`) feed a fresh object one block, so the forms agree to
the bit on the same samples however they are cut into blocks. The detectors' compiled kernels call
:func:`df2t_step` too. Initial conditions: the low-pass filter starts in steady state at its first
input (``scipy.signal.lfilter_zi``); the free-motion observer starts at rest and is fed the angle
relative to the first sample (its s^2 numerator gives zero output for a constant angle, so the
first angle is not a start-up step).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.signal import lfilter_zi

from sensing_antenna.antenna import FreeMotionObserver
from sensing_antenna.compiler import njit
from sensing_antenna.errors import SensingAntennaError

__all__ = [
    "FilterConfigError",
    "FirstOrderLowPass",
    "FreeMotionObserverFilter",
    "df2t_step",
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


@njit(cache=True)
def df2t_step(
    b: NDArray[np.float64], a: NDArray[np.float64], state: NDArray[np.float64], x: float
) -> float:
    """One sample x through the direct form II transposed recursion of ``lfilter``.

    ``b``, ``a``: coefficients, shape (order + 1,), a[0] = 1; ``state``: shape (order,), updated
    in place. Returns the output sample.
    """
    order = b.shape[0] - 1
    # y[k] = b0 x[k] + z0[k-1]
    y = state[0] + b[0] * x
    # z_m[k] = z_{m+1}[k-1] + b_{m+1} x[k] - a_{m+1} y[k], the last without z_{m+1}
    for m in range(order - 1):
        state[m] = state[m + 1] + x * b[m + 1] - y * a[m + 1]
    state[order - 1] = x * b[order] - y * a[order]
    return y


@njit(cache=True)
def _filter_block(
    b: NDArray[np.float64],
    a: NDArray[np.float64],
    state: NDArray[np.float64],
    x: NDArray[np.float64],
    y: NDArray[np.float64],
) -> None:
    """y[i, c] = df2t_step over the rows of x, shape (n, k), with state (k, order) carried."""
    for i in range(x.shape[0]):
        for c in range(x.shape[1]):
            y[i, c] = df2t_step(b, a, state[c], x[i, c])


class _Recursion:
    """A discrete filter applied channel by channel along axis 0, its state carried between
    blocks. Subclasses set the start (:meth:`_begin`) at the first sample after a reset."""

    def __init__(self, b: NDArray[np.float64], a: NDArray[np.float64]) -> None:
        self._b = np.ascontiguousarray(b, dtype=np.float64)
        self._a = np.ascontiguousarray(a, dtype=np.float64)
        self.reset()

    def reset(self) -> None:
        """Forget the past: the next sample starts the filter again."""
        self._state: NDArray[np.float64] | None = None
        self._origin: NDArray[np.float64] | None = None
        self.output = 0.0

    def _begin(self, first: NDArray[np.float64]) -> None:
        raise NotImplementedError

    def update_block(self, values: ArrayLike) -> NDArray[np.float64]:
        """Filter the samples that follow the ones fed so far.

        Parameters
        ----------
        values : array_like, shape (n,) or (n, k)
            Time on axis 0; the channel count k stays that of the first block after a reset.

        Returns
        -------
        ndarray, same shape as ``values``
        """
        x = np.asarray(values, dtype=np.float64)
        if x.shape[0] == 0:
            return x.copy()
        rows = np.ascontiguousarray(x.reshape(x.shape[0], -1))
        if self._state is None:
            self._begin(rows[0])
        assert self._state is not None
        if rows.shape[1] != self._state.shape[0]:
            raise ValueError(
                f"{rows.shape[1]} channels, but this filter was started on {self._state.shape[0]}"
            )
        if self._origin is not None:
            rows = rows - self._origin
        out = np.empty_like(rows)
        _filter_block(self._b, self._a, self._state, rows, out)
        self.output = float(out[-1, 0]) if out.shape[1] == 1 else out[-1].copy()
        return out.reshape(x.shape)

    def update(self, value: float) -> float:
        """Filter one sample of a one-channel signal (a block of one); returns and stores
        (``output``) the filtered value."""
        return float(self.update_block(np.array([float(value)]))[0])


class FirstOrderLowPass(_Recursion):
    """Streaming low-pass filter of Eq. 20, channel by channel.

    Parameters
    ----------
    cutoff : float
        omega_c (rad/s).
    sample_period : float
        T_s (s).

    Notes
    -----
    The first sample after :meth:`reset` puts the filter in steady state at that input
    (``lfilter_zi``) and comes out unchanged, as in :func:`low_pass`.
    """

    def __init__(self, cutoff: float = PAPER_LOW_PASS_CUTOFF, sample_period: float = 1e-3) -> None:
        b, a = low_pass_coefficients(cutoff, sample_period)
        self.cutoff = float(cutoff)
        self.sample_period = float(sample_period)
        self._steady = lfilter_zi(b, a)
        super().__init__(b, a)

    def _begin(self, first: NDArray[np.float64]) -> None:
        # steady state at the first input: z = lfilter_zi(b, a) x[0]
        self._state = np.ascontiguousarray(first[:, None] * self._steady[None, :])


def low_pass(
    signal: ArrayLike, cutoff: float = PAPER_LOW_PASS_CUTOFF, sample_period: float = 1e-3
) -> NDArray[np.float64]:
    """Batch low-pass filter of Eq. 20 along axis 0, starting in steady state at the first sample:
    :class:`FirstOrderLowPass` fed one block.

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
        Equal to ``lfilter`` started at ``lfilter_zi`` times the first sample.
    """
    return FirstOrderLowPass(cutoff, sample_period).update_block(signal)


class FreeMotionObserverFilter(_Recursion):
    """Streaming free-motion observer of Eq. 15, joint by joint: angle (rad) in, torque (N m) out.

    Parameters
    ----------
    observer : FreeMotionObserver
    sample_period : float
        T_s (s).

    Notes
    -----
    The observer starts at rest; it is fed theta - theta[0] where theta[0] is the first angle
    after :meth:`reset`, as in :func:`observe_free_motion`.
    """

    def __init__(self, observer: FreeMotionObserver, sample_period: float) -> None:
        b, a = observer_coefficients(observer, sample_period)
        self.observer = observer
        self.sample_period = float(sample_period)
        super().__init__(b, a)

    def _begin(self, first: NDArray[np.float64]) -> None:
        # at rest, relative to the first angle
        self._origin = first.copy()
        self._state = np.zeros((first.shape[0], self._b.shape[0] - 1))


def observe_free_motion(
    angles: ArrayLike, observer: FreeMotionObserver, sample_period: float
) -> NDArray[np.float64]:
    """Batch free-motion observer of Eq. 15 along axis 0 (from rest, relative to the first angle):
    :class:`FreeMotionObserverFilter` fed one block.

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
        Torque K s^2 / (s^2 + d s + omega^2) theta (N m).
    """
    return FreeMotionObserverFilter(observer, sample_period).update_block(angles)
