"""Shared helpers of the simulator tests: an independent frequency finder and a test stop rule."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from sensing_antenna.antenna import STANDARD_GRAVITY, Antenna


def dominant_frequency(signal: ArrayLike, sample_period: float, omega_min: float) -> float:
    """Peak of a Hann-windowed, zero-padded FFT with log-parabolic interpolation (rad/s).

    Independent of the project's estimators (they are never imported here).
    """
    x = np.asarray(signal, dtype=float)
    x = x - x.mean()
    n_fft = 1 << 20
    spectrum = np.abs(np.fft.rfft(x * np.hanning(x.size), n_fft))
    omega = 2.0 * math.pi * np.fft.rfftfreq(n_fft, sample_period)
    spectrum[omega < omega_min] = 0.0
    i = int(np.argmax(spectrum))
    y0, y1, y2 = np.log(spectrum[i - 1 : i + 2])
    shift = 0.5 * (y0 - y2) / (y0 - 2.0 * y1 + y2)
    return float((i + shift) * (omega[1] - omega[0]))


class RotationAfterForceStop:
    """Test stop rule: contact when the gravity-free force exceeds ``force_threshold`` (N), stop
    once the swept joint has turned ``rotation`` (rad) further. Implements the PushMonitor
    interface (reset, update) so the manoeuvre can be tested without the estimation package."""

    def __init__(self, antenna: Antenna, force_threshold: float, rotation: float) -> None:
        self.weight = antenna.link.mass * STANDARD_GRAVITY
        self.force_threshold = force_threshold
        self.rotation = rotation
        self.reset()

    def reset(self) -> None:
        self.theta_c: np.ndarray | None = None

    def update(self, t: float, theta: ArrayLike, force: ArrayLike, torque: ArrayLike) -> bool:
        th = np.asarray(theta, dtype=float)
        f = np.asarray(force, dtype=float)
        fg = np.array([-math.sin(th[1]), 0.0, -math.cos(th[1])]) * self.weight
        if self.theta_c is None and np.linalg.norm(f - fg) > self.force_threshold:
            self.theta_c = th.copy()
        return self.theta_c is not None and float(np.abs(th - self.theta_c).max()) >= self.rotation
