"""Identification of the free-motion observer of Eq. 15 and of the contact threshold (Section 5.2).

From a recording of free motion (nothing touching the link) the gain K, natural frequency omega and
damping d of Gamma_e,i = K s^2 / (s^2 + d s + omega^2) theta_i are fitted by least squares between
the measured coupling torques, with the link weight removed, and the output of the discrete
observer used online (``detection/filters.py``), so that the fitted model is exactly the model
the detector runs. The measured torque of joint 1 is the Z^m component and that of joint 2 the
Y^m component, with the signs of ``detection/contact.py`` (torque by the link on the head:
Z^m = -Gamma_e,1, Y^m = +Gamma_e,2). Only the joints that moved are used.

Start: a physics-based guess (K / omega^2 = rigid-link inertia m_b l^2 / 3 + m_t l^2 about O;
omega = 1.8751^2 / (T l^2), the first clamped-free mode), refined by a grid search over omega and
the damping ratio with K solved linearly at each point (the model is linear in K), then
``scipy.optimize.least_squares`` over (K, omega, d).

Threshold (Section 5.2): the maximum of the filtered residual norm of Eq. 16 over the free-motion
recording, computed with the fitted observer and the detector's residual filter, times a safety
margin of 1.5 ("the maximum residual obtained during free movements plus a security margin of
50 %").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from sensing_antenna.antenna import Antenna, FreeMotionObserver
from sensing_antenna.detection.contact import (
    DEFAULT_RESIDUAL_CUTOFF,
    OBSERVER_TORQUE_SIGNS,
    detect_contact,
)
from sensing_antenna.detection.filters import observe_free_motion
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.recording import Recording, resample_uniform

__all__ = [
    "CLAMPED_FREE_BETA_L",
    "DEFAULT_MARGIN",
    "IdentificationError",
    "ObserverFit",
    "identify_free_motion",
    "initial_guess",
]

#: beta_1 l of the first clamped-free bending mode (root of 1 + cos x cosh x = 0).
CLAMPED_FREE_BETA_L = 1.8751040687119611

#: Safety margin on the free-motion residual (Section 5.2: "plus a security margin of 50 %").
DEFAULT_MARGIN = 1.5

#: A joint counts as moved when its angle spans more than this (rad).
MIN_MOTION = 1e-3

#: Damping ratios of the initial grid search (dimensionless).
_ZETA_GRID = (0.002, 0.01, 0.03, 0.1, 0.3)


class IdentificationError(SensingAntennaError, ValueError):
    """The recording cannot identify the observer (e.g. no joint moved)."""


@dataclass(frozen=True)
class ObserverFit:
    """Fitted free-motion observer (Eq. 15) and contact threshold (Section 5.2).

    Parameters
    ----------
    gain : float
        K (N m / rad).
    natural_frequency : float
        omega (rad/s).
    damping : float
        d, coefficient of s (1/s).
    contact_threshold : float
        ``margin`` times ``max_filtered_residual`` (N m).
    max_filtered_residual : float
        Largest filtered residual norm of Eq. 16 over the recording with the fitted observer (N m).
    residual_rms : float
        RMS of measured minus fitted dynamic torque over the joints used (N m).
    joints : tuple of int
        Joints used (1 azimuth, 2 elevation).
    margin : float
        Safety factor on the threshold.
    residual_cutoff : float
        Residual filter cut-off used for the threshold (rad/s).
    initial_gain, initial_natural_frequency, initial_damping : float
        The physics-based starting point (same units).
    source : str or None
        Recording file.
    """

    gain: float
    natural_frequency: float
    damping: float
    contact_threshold: float
    max_filtered_residual: float
    residual_rms: float
    joints: tuple[int, ...]
    margin: float
    residual_cutoff: float
    initial_gain: float
    initial_natural_frequency: float
    initial_damping: float
    source: str | None = None

    @property
    def observer(self) -> FreeMotionObserver:
        """The fitted values as a :class:`FreeMotionObserver`."""
        return FreeMotionObserver(
            gain=self.gain,
            natural_frequency=self.natural_frequency,
            damping=self.damping,
            contact_threshold=self.contact_threshold,
        )

    @property
    def damping_ratio(self) -> float:
        """zeta = d / (2 omega) (dimensionless)."""
        return self.damping / (2.0 * self.natural_frequency)


#: Largest accepted ratio of the fit's residual rms to the coupling torque's rms. A simulated free
#: sweep of the paper antenna fits to about 1 %; a recording with a contact, whose static torque
#: the high-pass observer cannot follow, leaves about 100 %. Half sits safely between the two.
MAX_RELATIVE_RESIDUAL = 0.5


def initial_guess(antenna: Antenna) -> tuple[float, float, float]:
    """Physics-based (K, omega, d): rigid-link inertia and the first clamped-free mode.

    Returns
    -------
    gain : float
        K = J omega^2 with J = m_b l^2 / 3 + m_t l^2 (N m / rad).
    natural_frequency : float
        omega = (beta_1 l)^2 / (T l^2), beta_1 l = 1.8751 (rad/s); ignores the tip mass.
    damping : float
        d = 2 zeta omega with zeta = 0.01 (1/s).
    """
    link = antenna.link
    inertia = link.mass * link.length**2 / 3.0 + link.tip_mass * link.length**2
    omega = CLAMPED_FREE_BETA_L**2 / (link.t_param * link.length**2)
    return inertia * omega**2, omega, 2.0 * 0.01 * omega


def _targets(recording: Recording, antenna: Antenna) -> NDArray[np.float64]:
    """Measured Gamma_e,1 and Gamma_e,2 (N m), shape (n, 2): the torques with the link weight
    removed, mapped back through the signs of Section 4.2 (``OBSERVER_TORQUE_SIGNS``)."""
    sign_y, sign_z = OBSERVER_TORQUE_SIGNS
    # Section 4.2: Gamma^m - Gamma_g^m on Y^m and Z^m
    dynamic_y = recording.torque[:, 1] - antenna.link.gravity_moment(recording.theta[:, 1])
    dynamic_z = recording.torque[:, 2]
    return np.column_stack([sign_z * dynamic_z, sign_y * dynamic_y])


def identify_free_motion(
    recording: Recording,
    antenna: Antenna,
    margin: float = DEFAULT_MARGIN,
    residual_cutoff: float = DEFAULT_RESIDUAL_CUTOFF,
) -> ObserverFit:
    """Fit the Eq. 15 observer and the contact threshold to a free-motion recording.

    Parameters
    ----------
    recording : Recording
        Free motion, no contact; irregular sampling is resampled linearly first.
    antenna : Antenna
        Link (weight, physics-based start); its current observer is not used.
    margin : float
        Safety factor on the maximum free-motion residual (Section 5.2: 1.5).
    residual_cutoff : float
        Cut-off of the residual filter (rad/s); must match the detector's.

    Returns
    -------
    ObserverFit

    Raises
    ------
    IdentificationError
        When no joint moved by more than ``MIN_MOTION``, ``margin`` is not a number >= 1, or the
        fitted observer leaves more than ``MAX_RELATIVE_RESIDUAL`` of the torque unexplained
        (not a free motion).
    """
    where = recording.source or "<recording>"
    if not (math.isfinite(margin) and margin >= 1.0):
        raise IdentificationError(f"margin: must be a number >= 1, got {margin!r}")
    uniform = resample_uniform(recording) if recording.sampling.irregular else recording
    period = uniform.sample_period
    span = np.ptp(uniform.theta, axis=0)
    joints = tuple(j for j in (0, 1) if span[j] > MIN_MOTION)
    if not joints:
        raise IdentificationError(
            f"{where}: columns 'theta1', 'theta2': no joint moved by more than {MIN_MOTION:g} rad;"
            " a free-motion recording is needed"
        )
    angles = uniform.theta[:, joints]
    measured = _targets(uniform, antenna)[:, joints]
    nyquist = math.pi / period

    def unit_response(omega: float, damping: float) -> NDArray[np.float64]:
        observer = FreeMotionObserver(1.0, omega, damping, 1.0)
        # Eq. 15 with K = 1, discretised as online
        return observe_free_motion(angles, observer, period)

    k0, w0, d0 = initial_guess(antenna)
    best = (math.inf, k0, min(w0, 0.5 * nyquist), d0)
    for omega in w0 * np.geomspace(0.4, 2.5, 49):
        if omega >= 0.5 * nyquist:
            continue
        for zeta in _ZETA_GRID:
            u = unit_response(float(omega), 2.0 * zeta * float(omega))
            gain = float(np.sum(u * measured) / np.sum(u * u))
            cost = float(np.sum((measured - gain * u) ** 2))
            if gain > 0 and cost < best[0]:
                best = (cost, gain, float(omega), 2.0 * zeta * float(omega))

    def residuals(params: NDArray[np.float64]) -> NDArray[np.float64]:
        gain, omega, damping = params
        return (measured - gain * unit_response(omega, damping)).ravel()

    start = np.array(best[1:])
    fit = least_squares(
        residuals,
        start,
        bounds=([1e-12, 1e-6, 0.0], [np.inf, 0.9 * nyquist, np.inf]),
        x_scale=np.maximum(np.abs(start), 1e-6),
    )
    gain, omega, damping = (float(v) for v in fit.x)
    rms = float(np.sqrt(np.mean(fit.fun**2)))
    signal_rms = float(np.sqrt(np.mean(measured**2)))
    if rms > MAX_RELATIVE_RESIDUAL * signal_rms:
        raise IdentificationError(
            f"{where}: columns 'tx', 'ty', 'tz': Eq. 15 explains the coupling torque poorly "
            f"(residual rms {rms:.3g} N m against a signal rms of {signal_rms:.3g} N m); is this "
            "really free motion? A contact leaves a static torque that no free-motion observer "
            "can follow"
        )
    provisional = FreeMotionObserver(gain, omega, damping, contact_threshold=1.0)
    provisional_antenna = replace(antenna, observer=provisional)
    detection = detect_contact(uniform, provisional_antenna, residual_cutoff=residual_cutoff)
    peak = float(np.max(detection.filtered_residual_norm))
    return ObserverFit(
        gain=gain,
        natural_frequency=omega,
        damping=damping,
        contact_threshold=margin * peak,
        max_filtered_residual=peak,
        residual_rms=rms,
        joints=tuple(j + 1 for j in joints),
        margin=float(margin),
        residual_cutoff=float(residual_cutoff),
        initial_gain=k0,
        initial_natural_frequency=w0,
        initial_damping=d0,
        source=recording.source,
    )
