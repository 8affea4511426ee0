"""Motors (Eq. 1) and their 2-DOF PID servo with coupling-torque feedback (Section 4.1, Eq. 14).

Eq. 1 at joint i: ``n K_m u = J theta_dd + v theta_d + Gamma_nlc + Gamma_coup``. The controller
adds the measured coupling torque to its command, ``n K_m u = R1 theta* - R2 theta + Gamma_coup``,
so the servo sees the plant ``1 / (s (J s + v))`` whatever the link does. With
``R(s) = (a2 s^2 + a1 s + a0) / (s (s + b))`` the closed loop is
``theta / theta* = N1 / (s^2 (s + b) (J s + v) + N2)``. Placing the four poles at p:

    J s^4 + (J b + v) s^3 + (v b + a2) s^2 + a1 s + a0 = J (s - p)^4
    => b = -4 p - v / J,  a2 = 6 J p^2 - v b,  a1 = -4 J p^3,  a0 = J p^4.

The zeros of R1 at p, ``N1 = J p^2 (s - p)^2``, cancel two poles and give Eq. 14,
``theta / theta* = p^2 / (s - p)^2 = 1 / (1 + eps s)^2`` with ``eps = -1/p``; ``N1(0) = N2(0) =
J p^4`` gives unit DC gain.

The controller runs at 1 kHz. Each R is discretised with the bilinear (Tustin) map
``s = (2 / T_s) (z - 1) / (z + 1)``; the command is held over the sample (zero-order hold).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Motor

__all__ = ["ServoDesign", "design_servo", "tustin_biquad"]


@dataclass(frozen=True)
class ServoDesign:
    """Continuous 2-DOF PID design of one joint and its 1 kHz discretisation.

    Attributes
    ----------
    pole : float
        Closed-loop pole p (rad/s, < 0).
    b : float
        Controller pole location (R denominator s (s + b)) (rad/s).
    feedback : tuple of 3 float
        (a2, a1, a0) of R2 (N m/rad, N m/(rad s), N m/(rad s^2)).
    feedforward : tuple of 3 float
        (a2, a1, a0) of R1 = J p^2 (s - p)^2 / (s (s + b)).
    sample_period : float
        Controller period T_s (s).
    """

    pole: float
    b: float
    feedback: tuple[float, float, float]
    feedforward: tuple[float, float, float]
    sample_period: float

    @property
    def time_constant(self) -> float:
        """eps = -1/p of Eq. 14 (s)."""
        return -1.0 / self.pole

    def discrete(self) -> NDArray[np.float64]:
        """Tustin biquads, shape (2, 2, 3): [R1, R2] x [numerator, denominator] in z^-1."""
        den = (1.0, self.b, 0.0)
        out = np.empty((2, 2, 3))
        for i, num in enumerate((self.feedforward, self.feedback)):
            bz, az = tustin_biquad(num, den, self.sample_period)
            out[i, 0] = bz
            out[i, 1] = az
        return out


def design_servo(motor: Motor, pole: float, sample_period: float = 1e-3) -> ServoDesign:
    """Place the four closed-loop poles and R1's zeros at ``pole`` (Section 4.1, Eq. 14).

    Parameters
    ----------
    motor : Motor
        J and v are used (link-side values of Table 1).
    pole : float
        p (rad/s), negative.
    sample_period : float
        Controller period (s).
    """
    if not pole < 0:
        raise ValueError(f"pole must be negative, got {pole}")
    j = motor.inertia
    v = motor.viscous_friction
    p = pole
    # Sec. 4.1: characteristic polynomial s^2 (s+b)(J s+v) + a2 s^2 + a1 s + a0 = J (s-p)^4
    b = -4.0 * p - v / j
    a2 = 6.0 * j * p * p - v * b
    a1 = -4.0 * j * p**3
    a0 = j * p**4
    # Eq. 14: R1 = J p^2 (s - p)^2 / (s (s + b)) cancels two closed-loop poles
    feedforward = (j * p * p, -2.0 * j * p**3, j * p**4)
    return ServoDesign(
        pole=p, b=b, feedback=(a2, a1, a0), feedforward=feedforward, sample_period=sample_period
    )


def tustin_biquad(
    num: tuple[float, float, float], den: tuple[float, float, float], sample_period: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Bilinear map of ``(n2 s^2 + n1 s + n0) / (d2 s^2 + d1 s + d0)`` to a biquad in z^-1.

    Returns
    -------
    (bz, az) : ndarrays, shape (3,)
        ``y_k = (bz . [x_k, x_k-1, x_k-2] - az[1:] . [y_k-1, y_k-2]) / 1`` with az[0] = 1.
    """
    c = 2.0 / sample_period
    n2, n1, n0 = num
    d2, d1, d0 = den
    bz = np.array([n2 * c * c + n1 * c + n0, 2.0 * n0 - 2.0 * n2 * c * c, n2 * c * c - n1 * c + n0])
    az = np.array([d2 * c * c + d1 * c + d0, 2.0 * d0 - 2.0 * d2 * c * c, d2 * c * c - d1 * c + d0])
    return bz / az[0], az / az[0]
