"""The held joint's angle at the contact's fundamental, against what the link's torque explains.

While the head holds after t_1, the swept joint's servo answers the link's ringing torque with a
small angle: its compliance at that frequency, a property of the device's motor and controller,
which a calibration's posts measure (:attr:`~sensing_antenna.antenna.Motor.held_compliance`). A
base that moves near omega_1 (a robot's body, a table rocking) drives the head besides: the
encoder then shows the servo's error against that motion, a line beside the contact's
fundamental that one spectrum window cannot part from it, and that moves the frequency read.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.front.contact_frame import motor_axes
from sensing_antenna.estimation.front.spectrum import amplitude_spectrum

FloatArray = NDArray[np.float64]

__all__ = [
    "COMPLIANCE_MARGIN",
    "MIN_POSTS",
    "HeldLine",
    "held_line",
    "swept_joint",
]

#: The posts' largest compliance is taken this many times over: the servo's compliance varies
#: with the frequency across the posts' omega_1, and each post reads it from an angle of a
#: fraction of an encoder count.
COMPLIANCE_MARGIN = 3.0

#: Fewest calibration posts on a joint for its compliance to be stored: from one or two, one
#: reading of a fraction of a count says little of the servo.
MIN_POSTS = 3

#: The angle's spectrum is read within this share of omega_1 at most (or within the window's
#: main lobe, 4 pi / duration, when narrower): where a second line merges with the contact's
#: fundamental.
_NEAR_SHARE = 0.1

#: Zero padding of the spectra (to the power of two at or above this many times the window):
#: the peaks read between the bins.
_PAD = 8


@dataclass(frozen=True)
class HeldLine:
    """The swept joint's angle and the link's torque about it near omega_1.

    Attributes
    ----------
    joint : int
        0 (azimuth) or 1 (elevation).
    angle, torque : float
        Amplitudes at the spectrum's point nearest omega_1 (rad, N m).
    excess : float
        The largest amplitude of the angle near omega_1 beyond ``compliance`` times the
        torque's there (rad); NaN without a compliance.
    count : float
        The encoder's count: the angle column's smallest step over the window (rad).
    noise : float
        The angle's median amplitude from half to twice omega_1 outside the window's main lobe
        about omega_1 and the band searched (rad); NaN where nothing is left outside.
    """

    joint: int
    angle: float
    torque: float
    excess: float
    count: float
    noise: float

    @property
    def compliance(self) -> float:
        """The angle per torque at omega_1 (rad/(N m)); NaN when the torque is none."""
        return self.angle / self.torque if self.torque > 0.0 else math.nan


def swept_joint(turn: FloatArray) -> int:
    """The joint that turned the head into the contact (``turn``: rad, shape (2,))."""
    return int(np.argmax(np.abs(np.asarray(turn, dtype=float))))


def held_line(
    t: FloatArray,
    theta: FloatArray,
    torque: FloatArray,
    joint: int,
    omega1: float,
    compliance: float | None = None,
) -> HeldLine | None:
    """The swept joint's angle against the link's torque about it near ``omega1`` (rad/s).

    ``t`` (s), ``theta`` (rad, shape (n, 2)) and ``torque`` (N m, motor frame, shape (n, 3))
    over the window the fundamental was read from; the amplitude spectra of the angle and the
    torque about the joint (a line off each, Hann window). With ``compliance`` (rad/(N m)) the
    angle's excess over :data:`COMPLIANCE_MARGIN` times it. None when the window is too short
    or holds no finite spectrum."""
    with np.errstate(all="ignore"):  # loads beyond float range read as no line (None)
        line = _held_line(t, theta, torque, joint, omega1, compliance)
    if line is None or not all(math.isfinite(v) for v in (line.angle, line.torque, line.count)):
        return None
    return line


def _held_line(
    t: FloatArray,
    theta: FloatArray,
    torque: FloatArray,
    joint: int,
    omega1: float,
    compliance: float | None,
) -> HeldLine | None:
    """:func:`held_line`, its arithmetic."""
    n = t.shape[0]
    if n < 16 or not (math.isfinite(omega1) and omega1 > 0.0):
        return None
    duration = float(t[-1] - t[0])
    if not duration > 0.0:
        return None
    angle = np.asarray(theta[:, joint], dtype=float)
    signals = np.column_stack([angle, _torque_about(theta, torque, joint)])
    if not np.all(np.isfinite(signals)):
        return None
    frequencies, amplitudes = amplitude_spectrum(signals, duration / (n - 1), _PAD)
    spectra = (amplitudes[:, 0], amplitudes[:, 1])
    lobe = 4.0 * math.pi / duration
    near = np.abs(frequencies - omega1) <= min(lobe, _NEAR_SHARE * omega1)
    # the noise beside the band: a line within it spreads over the main lobe about it
    wide = (frequencies > 0.5 * omega1) & (frequencies < 2.0 * omega1)
    wide &= np.abs(frequencies - omega1) > min(lobe, _NEAR_SHARE * omega1) + lobe
    if not np.any(near):
        return None
    at = int(np.argmin(np.abs(frequencies - omega1)))
    steps = np.abs(np.diff(angle))
    steps = steps[steps > 0.0]
    excess = math.nan
    if compliance is not None:
        beyond = spectra[0][near] - COMPLIANCE_MARGIN * compliance * spectra[1][near]
        excess = float(np.max(beyond))
    return HeldLine(
        joint=joint,
        angle=float(spectra[0][at]),
        torque=float(spectra[1][at]),
        excess=excess,
        count=float(np.min(steps)) if steps.size else 0.0,
        noise=float(np.median(spectra[0][wide])) if np.any(wide) else math.nan,
    )


def _torque_about(theta: FloatArray, torque: FloatArray, joint: int) -> FloatArray:
    """The link's moment about the joint's axis (N m), from the motor frame's torques: the
    elevation's axis is Y^m, the azimuth's the absolute Z^a, whose motor-frame components are
    the last column of :func:`~.front.contact_frame.motor_axes`."""
    if joint == 1:
        return np.asarray(torque[:, 1], dtype=float)
    vertical = motor_axes(np.asarray(theta, dtype=float))[:, :, 2]
    return np.asarray(np.einsum("ij,ij->i", torque, vertical), dtype=float)
