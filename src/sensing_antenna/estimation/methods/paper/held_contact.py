"""A contact friction holds along the link, read from the force along it.

The straight link's model lets the contact slide along the link. On a link the push has bent,
a contact that friction holds on the obstacle resists the in-plane vibration's change of the
chord from O to the contact, and the push plane's modes rise (docs/estimation.md, "The two
bending planes"; the free plane's do not). The force that resists rings at omega_1 along the
link and reaches the base: with r its amplitude over that of the base's bending moment in the
push plane (the torque omega_1 is read from), Rayleigh's quotient puts the rise at r kappa d / 2
(:func:`~sensing_antenna.beam.modes.held_contact_coupling`, d the push's deflection over x_c).
So the ringing of the force along the link, over the spectrum's own window, tells how far a
push plane's omega_1 may sit above the straight link's curve.

Only the part of r in phase with the vibration stores energy, and the product's sign says
which way it moves the frequency: a hold stiffens (Re(r) kappa > 0); the exact link pushed
sideways into a post, where friction rings along the link in phase the other way, rings lower,
by about what the product says. The rise taken still reads the whole amplitude: on the rod
engine's vertical push at 0.7 m the force along the link rang mostly in quadrature and the push
plane rose 4.5 % (docs/design-notes.md, "The hold's ringing in phase"). The part in phase is
evidence that a hold stiffens the push plane: where the free plane's peak agrees with the push
plane's and may be its leak, only that evidence voids the agreement.

What else rings along the link at omega_1 is taken off r first:

- a sliding contact's own axial share: its reaction keeps its direction, R_x / |R_perp| of the
  contact force, which rings at -:func:`~sensing_antenna.beam.modes.contact_to_base_shear`
  times the base's lateral reading (the ratio of the mode's support forces; the reading is the
  base support's opposite); subtracted as a complex amplitude;
- the sensor's cross-talk of the moments into F_x: up to sqrt(3) ``nominal_coupling`` (the edge
  of the uniform spread that standard uncertainty describes) per N m of the three torques'
  ringing, which no calibration here measures;
- the channels' noise: 2.1 medians of the force channel's amplitude spectrum over the band (a
  white noise's amplitude exceeds 2.08 medians with probability 5 %), and the lateral channel's
  through the sliding share.

The rise taken is three times Rayleigh's estimate from what is left. Against a finite-element
link whose chord a spring holds, the estimate from the r of the reshaped mode is at least the
rise while the rise stays in the band (tests/test_beam_fem.py); on the simulator's exact link
pushed up into a bar it fell short of the rise, by less than three times (docs/design-notes.md,
"A push plane that friction holds, read from the force along the link"). A link's own axial
inertia rings along it too; that only adds to the rise taken.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.beam.modes import contact_to_base_shear, held_contact_coupling
from sensing_antenna.estimation.front.evidence import Evidence, first_mode_value

__all__ = ["HeldContact", "held_contact"]

FloatArray = NDArray[np.float64]

#: Multiple of Rayleigh's estimate taken as the rise.
BOUND_FACTOR = 3.0

#: Medians of a white noise's Hann amplitude spectrum its amplitude exceeds with probability 5 %
#: (Rayleigh-distributed: sqrt(2 ln 20) / sqrt(2 ln 2) = 2.08).
NOISE_MEDIANS = 2.1

#: The largest cross-talk over its standard uncertainty for a uniform spread.
COUPLING_EDGE = math.sqrt(3.0)


@dataclass(frozen=True)
class HeldContact:
    """The force along the link ringing with the push plane's omega_1.

    Attributes
    ----------
    ringing : float
        Amplitude of the axial force at omega_1 beyond a sliding contact's own axial share, over
        the push plane's bending moment at the base (1/m, N per N m).
    in_phase : float
        Its part in phase with that moment (1/m), signed so that a hold's is positive (a
        negative one lowers omega_1).
    leak : float
        The part of it the sensor's cross-talk and the channels' noise may make (1/m).
    shift : float
        The rise of the push plane's omega_1 taken for a hold: three times Rayleigh's estimate
        from the ringing beyond the leak, relative (dimensionless); inf when the loads are not
        finite.
    """

    ringing: float
    in_phase: float
    leak: float
    shift: float

    @property
    def stiffens(self) -> bool:
        """Whether the part in phase is a hold's beyond what the leak may make, or the loads
        give no bound (``shift`` infinite)."""
        return bool(self.in_phase > self.leak or math.isinf(self.shift))


def _noise_amplitudes(
    signal: FloatArray, t: FloatArray, band: tuple[float, float], omega: float
) -> FloatArray | None:
    """Median Hann amplitude of each column of ``signal`` (n, k), mean removed, over the band
    (rad/s) outside the main lobe around ``omega`` (rad/s), shape (k,); None where no frequency
    is left there."""
    window = np.hanning(signal.shape[0])
    centred = (signal - signal.mean(axis=0)) * window[:, None]
    amplitudes = np.abs(np.fft.rfft(centred, axis=0)) * 2.0 / window.sum()
    frequencies = 2.0 * math.pi * np.fft.rfftfreq(signal.shape[0], float(t[1] - t[0]))
    lobe = 4.0 * math.pi / float(t[-1] - t[0])
    away = (frequencies >= band[0]) & (frequencies <= band[1])
    away &= np.abs(frequencies - omega) > lobe
    if np.count_nonzero(away) < 3:
        return None
    return np.asarray(np.median(amplitudes[away], axis=0), dtype=float)


def _amplitude(signal: FloatArray, t: FloatArray, omega: float) -> FloatArray:
    """Complex Hann amplitude at ``omega`` (rad/s) of each column of ``signal`` (n, k), mean
    removed; shape (k,)."""
    window = np.hanning(t.size)
    centred = signal - signal.mean(axis=0)
    phase = np.exp(-1j * omega * (t - t[0]))
    return np.asarray(2.0 * (window * phase) @ centred / window.sum())


def held_contact(evidence: Evidence, omega: float, x_c: float) -> HeldContact | None:
    """How far a hold may have raised the push plane's omega_1 (``omega``, rad/s) at the contact
    point ``x_c`` (m), from the loads over the spectrum's window; None where the window, the band
    or the push gives nothing to read."""
    window = evidence.spectrum_slice
    t = evidence.t[window]
    reaction = evidence.frame.reaction_m
    lateral = np.array([0.0, float(reaction[1]), float(reaction[2])])
    push = float(np.linalg.norm(lateral))
    if t.size < 16 or not (push > 0.0 and math.isfinite(omega) and omega > 0.0):
        return None
    across = lateral / push
    normal = np.cross([1.0, 0.0, 0.0], across)
    force, moment = (loads[window] for loads in evidence.contact_loads_unfiltered)
    # one amplitude per channel; the projections follow by linearity
    amplitudes = _amplitude(np.hstack([force, moment]), t, omega)
    axial, shear, bending = amplitudes[0], amplitudes[:3] @ across, amplitudes[3:] @ normal
    if not np.all(np.isfinite(amplitudes)):
        return HeldContact(ringing=math.nan, in_phase=math.nan, leak=math.nan, shift=math.inf)
    lines = np.column_stack([force[:, 0], force @ across])
    noise = _noise_amplitudes(lines, t, evidence.band, omega)
    if noise is None or not abs(bending) > 0.0:
        return None
    link = evidence.antenna.link
    share = -float(reaction[0]) / push * first_mode_value(link, contact_to_base_shear, x_c)
    coupling = first_mode_value(link, held_contact_coupling, x_c)
    ratio = (axial - share * shear) / bending
    sign = math.copysign(1.0, coupling) if math.isfinite(coupling) else math.nan
    ringing, in_phase = float(abs(ratio)), float(ratio.real * sign)
    # what the cross-talk of the three torques and the channels' noise may put there
    torques = float(np.abs(amplitudes[3:]).sum())
    cross_talk = COUPLING_EDGE * evidence.antenna.sensor.nominal_coupling
    noisy = NOISE_MEDIANS * (float(noise[0]) + abs(share) * float(noise[1]))
    leak = float((cross_talk * torques + noisy) / abs(bending))
    kappa = abs(coupling)
    deflection = float(evidence.push_deflection_ratio(x_c))
    shift = float(BOUND_FACTOR * 0.5 * max(ringing - leak, 0.0) * kappa * deflection)
    if not (math.isfinite(ringing) and math.isfinite(leak) and math.isfinite(shift)):
        shift = math.inf
    return HeldContact(ringing=ringing, in_phase=in_phase, leak=leak, shift=shift)
