"""The free-motion observer of Eq. 15 for both joints, stepped per sample.

``Gamma_e,i = K s^2 / (s^2 + d s + omega^2) theta_i`` (Section 4.2): the coupling torque the
motion of joint i causes at the base while nothing touches the link, from the measured angle
alone ("its inputs are the measured motor angles"); the motor command does not enter it. K, omega
and d are the antenna's :class:`~sensing_antenna.antenna.FreeMotionObserver`, the values
``antenna identify`` fits and writes into the antenna file.

One implementation: the observer is the Tustin biquad (prewarped at omega) of
:func:`~sensing_antenna.detection.filters.observer_coefficients`, run by the compiled recursion
:func:`~sensing_antenna.detection.filters.df2t_step` through
:class:`~sensing_antenna.detection.filters.FreeMotionObserverFilter`. The contact detector, the
identification of ``antenna identify`` (:func:`~sensing_antenna.detection.filters.
observe_free_motion`, a fresh filter fed one block) and :class:`CouplingTorqueObserver` all run
it, so the per-sample form here and the batch form agree to the bit. It starts at rest on the
angles relative to the first ones stepped after a reset.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import FreeMotionObserver
from sensing_antenna.detection.filters import FreeMotionObserverFilter
from sensing_antenna.errors import refuse_non_finite

__all__ = ["CouplingTorqueObserver", "observe_coupling_torques"]


class CouplingTorqueObserver:
    """Eq. 15 for joints 1 and 2: measured angles (rad) in, Gamma_e,1 and Gamma_e,2 (N m) out.

    Parameters
    ----------
    observer : FreeMotionObserver
        K (N m / rad), omega (rad/s), d (1/s), e.g. ``antenna.observer``.
    sample_period : float
        T_s (s), the loop's period (1e-3 for the paper's 1 kHz); omega T_s must be below pi.

    Notes
    -----
    In the recording's convention (torque by the link on the head, motor frame) the observed
    torque is (0, +Gamma_e,2, -Gamma_e,1) plus the link's weight
    (:data:`~sensing_antenna.detection.contact.OBSERVER_TORQUE_SIGNS`).
    """

    def __init__(self, observer: FreeMotionObserver, sample_period: float) -> None:
        self.observer = observer
        self.sample_period = float(sample_period)
        self._filter = FreeMotionObserverFilter(observer, self.sample_period)

    def reset(self) -> None:
        """Start again at rest: the next angles stepped are the new origin."""
        self._filter.reset()

    def step(self, measured: ArrayLike) -> NDArray[np.float64]:
        """Observed coupling torques for one sample.

        Parameters
        ----------
        measured : array_like, shape (2,)
            Measured angles theta_1, theta_2 (rad).

        Returns
        -------
        ndarray, shape (2,)
            Gamma_e,1 and Gamma_e,2 (N m).

        Raises
        ------
        ValueError
            For angles that are NaN or infinite (an encoder glitch): the observer's state is
            untouched; a NaN stepped in would hold every later output at NaN.
        """
        angles = np.asarray(measured, dtype=np.float64)
        if angles.shape != (2,):
            raise ValueError(
                f"measured: expected two angles (joints 1 and 2), got shape {angles.shape}"
            )
        _finite(angles[None, :])
        return self._filter.update_block(angles[None, :])[0]

    def step_block(self, measured: ArrayLike) -> NDArray[np.float64]:
        """Observed coupling torques for consecutive samples: :meth:`step` row by row.

        Parameters
        ----------
        measured : array_like, shape (n, 2)
            Measured angles (rad), time on axis 0.

        Returns
        -------
        ndarray, shape (n, 2)
            Gamma_e,1 and Gamma_e,2 (N m).

        Raises
        ------
        ValueError
            For misshapen angles or a NaN or infinite one (naming its row), the state untouched.
        """
        angles = np.asarray(measured, dtype=np.float64)
        if angles.ndim != 2 or angles.shape[1] != 2:
            raise ValueError(
                f"measured: expected shape (n, 2) (joints 1 and 2), got shape {angles.shape}"
            )
        _finite(angles)
        return self._filter.update_block(angles)


def _finite(angles: NDArray[np.float64]) -> None:
    """Refuse NaN or infinite angles (shape (n, 2))."""
    if angles.shape[0] == 1 and math.isfinite(angles[0, 0]) and math.isfinite(angles[0, 1]):
        return  # one sample, the loop's case: cheaper in Python than NumPy calls
    refuse_non_finite([("measured", angles)], "coupling torque")


def observe_coupling_torques(
    measured: ArrayLike, observer: FreeMotionObserver, sample_period: float
) -> NDArray[np.float64]:
    """Batch Eq. 15 for both joints: a fresh :class:`CouplingTorqueObserver` fed one block.

    Parameters
    ----------
    measured : array_like, shape (n, 2)
        Measured angles (rad).
    observer : FreeMotionObserver
    sample_period : float
        T_s (s).

    Returns
    -------
    ndarray, shape (n, 2)
        Gamma_e,1 and Gamma_e,2 (N m), from rest relative to the first angles.
    """
    return CouplingTorqueObserver(observer, sample_period).step_block(measured)
