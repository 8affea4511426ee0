"""Statics without lag: the torque/force ratio from the fitted static part of the loads.

Estimator 2 of the paper (Eq. 20, 21) low-pass filters force and torque at omega_c = 5 rad/s and
waits for the filter to settle. Here the static part of each contact-load channel is instead
estimated together with the decaying vibration modes over the same short window
(:mod:`.parametric`): the offsets c_k at the window centre are the static loads, with their
covariance, and there is no filter lag.

Channels (motor frame, gravity removed sample by sample as in Eq. 21, see :mod:`.ratio`):
R_y, R_z (the reaction perpendicular to the link) and the three components of Gamma - Gamma_g^m.
The statics are those of the paper method's Estimator 2, called, not repeated: the planar
elastica loaded at the contact
(:func:`~sensing_antenna.estimation.front.ratio.perpendicular_ratio`,
:mod:`sensing_antenna.beam.elastica`) inverted from M_0 = Gamma' . v (v = X^m x R_perp /
|R_perp|), the axial R_x and |R_perp|, with the one stiffness of every statics,
1 / :attr:`~sensing_antenna.antenna.Link.bending_compliance`, the link's weight taken off at
the window's elevation. The axial force is not fitted (the five channels hold the vibration's
information; R_x enters the statics through the deflection and the link's sag, the levers the
contact's offset from X^m gives it): it is the front end's filtered reaction along the link at
the window's last sample. Without deflection or weight this is x_c = |M_0| / |R_perp| (Eq. 21
with the perpendicular force). Its standard error propagates the offsets' covariance through
the gradient of that inversion, by differences of the same function (first-order delta method).

Sensor bias. An F/T sensor keeps a small offset after taring (the simulator draws two resolution
counts, 12.5 mN and 6e-5 N m, per run). Against pushes of 20 to 200 mN a force offset of 10 mN
moves the ratio by 5 to 50 %, far more than any other error, for the paper method as well. Before
the sweep the head rests and there is no contact, so the gravity-compensated loads are the bias
alone: :func:`sensor_bias` averages them over that initial rest and the ratio uses the loads minus
the bias, the bias's covariance added to the offsets' (they are independent: disjoint samples).
Without an initial rest the bias is taken as zero and the diagnostics say so.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import Antenna, Link
from sensing_antenna.estimation.front.ratio import contact_loads, perpendicular_ratio
from sensing_antenna.estimation.methods.fast.parametric import DampedSinusoidFit

__all__ = [
    "FORCE_CHANNELS",
    "TORQUE_CHANNELS",
    "SensorBias",
    "StaticRatio",
    "StaticsModel",
    "contact_channels",
    "sensor_bias",
    "static_ratio",
]

FloatArray = NDArray[np.float64]

#: Columns of :func:`contact_channels` holding R_y and R_z (N).
FORCE_CHANNELS = (0, 1)
#: Columns holding the contact torque Gamma - Gamma_g^m, x, y, z (N m).
TORQUE_CHANNELS = (2, 3, 4)


@dataclass(frozen=True)
class StaticRatio:
    """x_c from the static loads of a short window.

    Attributes
    ----------
    ratio : float
        The contact's arc length x_c by the elastica's statics of the loads at the window
        centre (m); NaN when R_perp is zero.
    standard_error : float
        Its standard error from the offsets' covariance (m).
    reaction_perp : array, shape (2,)
        Static perpendicular reaction (R_y, R_z) of the object on the link (N). The axial R_x
        is not fitted (it does not enter the ratio).
    torque_m : array, shape (3,)
        Static contact torque (N m).
    force_cov : array, shape (2, 2)
        Covariance of the static (R_y, R_z) (N^2), the bias's included.
    """

    ratio: float
    standard_error: float
    reaction_perp: FloatArray
    torque_m: FloatArray
    force_cov: FloatArray = field(default_factory=lambda: np.zeros((2, 2)))

    @property
    def perpendicular_force(self) -> float:
        """|R_perp| (N)."""
        return float(math.hypot(self.reaction_perp[0], self.reaction_perp[1]))


def contact_channels(
    theta: FloatArray, force_m: FloatArray, torque_m: FloatArray, antenna: Antenna
) -> FloatArray:
    """The five contact-load channels R_y, R_z, Gamma_x, Gamma_y, Gamma_z, shape (n, 5).

    Parameters
    ----------
    theta : array, shape (n, 2)
        Motor angles (rad).
    force_m, torque_m : array, shape (n, 3)
        Measured force (N) and torque (N m), motor frame.
    antenna : Antenna

    Returns
    -------
    array, shape (n, 5)
        Gravity removed (Section 4.2, as in Eq. 21); N for the first two columns, N m after.
    """
    reaction, moment = contact_loads(theta, force_m, torque_m, antenna)
    return np.column_stack([reaction[:, 1:], moment])


def static_ratio(
    fit: DampedSinusoidFit,
    bias: SensorBias | None,
    axial: float,
    link: Link,
    theta2: float,
) -> StaticRatio:
    """The contact's arc length from the fitted offsets, with its standard error.

    Parameters
    ----------
    fit : DampedSinusoidFit
        A fit of the five :func:`contact_channels`.
    bias : SensorBias or None
        Subtracted from the offsets, its covariance added.
    axial : float
        R_x, the reaction along the link (N).
    link : Link
        Its stiffness (``1 / bending_compliance``, that of every statics) and its weight.
    theta2 : float
        The link's elevation (rad) over the window.

    Returns
    -------
    StaticRatio
    """
    c = fit.offsets
    cov = fit.offset_cov
    if bias is not None:
        c = c - bias.bias
        cov = cov + bias.cov
    force = c[list(FORCE_CHANNELS)]
    torque = c[list(TORQUE_CHANNELS)]
    f_norm = float(np.linalg.norm(force))
    reaction = np.array(force, dtype=float)
    force_cov = cov[np.ix_(FORCE_CHANNELS, FORCE_CHANNELS)]
    if f_norm == 0.0:
        return StaticRatio(math.nan, math.nan, reaction, torque, force_cov)
    # The offsets and, for the delta method, each channel moved by a small step: one call of the
    # front end's statics on the six rows (a few rows go through its scalar path)
    steps = _STEP * np.array([f_norm, f_norm, *(3 * [max(float(np.linalg.norm(torque)), 1e-300)])])
    rows = np.vstack([c, c + np.diag(steps)])
    loads = np.zeros((rows.shape[0], 3))
    loads[:, 0] = axial
    loads[:, 1:] = rows[:, list(FORCE_CHANNELS)]
    arcs = perpendicular_ratio(loads, rows[:, list(TORQUE_CHANNELS)], link, theta2)
    ratio = float(arcs[0])
    gradient = (arcs[1:] - ratio) / steps
    variance = float(gradient @ cov @ gradient)
    se = math.sqrt(variance) if variance >= 0.0 and math.isfinite(variance) else math.nan
    return StaticRatio(ratio, se, reaction, torque, force_cov)


#: Relative step of the differences that give the statics' gradient: far below the loads'
#: statistical errors (1e-3 to 1e-2 relative), far above rounding.
_STEP = 1e-6


@dataclass(frozen=True, eq=False)
class StaticsModel:
    """What the hold's push tells every window of a manoeuvre beside its own fit: the axial
    reaction the statics read, and what the model leaves out at that push.

    Attributes
    ----------
    axial : array, shape (n,)
        R_x, the reaction along the link (N), at every sample: the front end's filtered contact
        load (Eq. 20, causal), read at each window's last sample.
    grid : array, shape (G,), optional
        Contact points (m) at which ``model_sd`` is given: the posterior's grid.
    model_sd : array, shape (G,), optional
        Standard uncertainty (m) of the statics' answer from what the elastica does not hold,
        at each grid point: the front end's own
        (:meth:`~sensing_antenna.estimation.front.evidence.Evidence.ratio_model_uncertainty`).
        None: no model term (the statistical error alone).
    omega1_sd : array, shape (G,), optional
        Standard uncertainty (rad/s) of omega_1(x_c) from the push's deflection at each grid
        point: the sensing curves are the straight link's, and the bent link's preload shifts
        its frequencies; the front end's uncertainty of a contact point read from the vibration
        (:meth:`~sensing_antenna.estimation.front.evidence.Evidence.bent_link_uncertainty`),
        times the curve's slope there, and in quadrature the shift of a payload the weight at
        rest reads and the model does not carry
        (:meth:`~sensing_antenna.estimation.front.evidence.Evidence.payload_shifts`). It
        enters the posterior's likelihood of omega_1 and
        the frequency's consistency with the answer (:func:`.checks.frequency_check`), as
        the paper method's candidate carries it. None: none.
    push_direction : array, shape (2,), optional
        The hold's reaction across the link, (R_y, R_z) in the motor frame (N): which plane is
        the push's, so that the fundamental is read in the free plane when it rings
        (:mod:`.planes`). None: the strongest mode, whatever its plane.
    elevation : array, shape (n,), optional
        theta2 (rad) at every sample, which puts the link's weight in the statics; None: a
        level link.
    free_omega1_sd : array, shape (G,), optional
        ``omega1_sd`` where omega_1 is the free plane's own mode (a fitted mode that vibrates mostly
        out of the push plane): half the free plane's bound of its shift
        (:func:`~sensing_antenna.beam.free_plane.free_plane_shifts`, a bound taken as two
        standard uncertainties) at each grid point's deflection, times omega_1 there, the
        payload's shift in quadrature; ``omega1_sd`` where that bound is not known. None: the
        free plane's mode carries ``omega1_sd``.
    """

    axial: FloatArray | None = None
    grid: FloatArray | None = None
    model_sd: FloatArray | None = None
    omega1_sd: FloatArray | None = None
    push_direction: FloatArray | None = None
    elevation: FloatArray | None = None
    free_omega1_sd: FloatArray | None = None

    def axial_at(self, index: int) -> float:
        """R_x (N) at sample ``index``; 0 without it."""
        if self.axial is None or not 0 <= index < self.axial.shape[0]:
            return 0.0
        return float(self.axial[index])

    def elevation_at(self, index: int) -> float:
        """theta2 (rad) at sample ``index``; 0 (a level link) without it."""
        if self.elevation is None or not 0 <= index < self.elevation.shape[0]:
            return 0.0
        return float(self.elevation[index])

    def sd_at(self, x_c: float) -> float:
        """``model_sd`` at ``x_c`` (m), linearly between grid points; 0 without a model term."""
        if self.grid is None or self.model_sd is None:
            return 0.0
        return float(np.interp(x_c, self.grid, self.model_sd))

    def frequency_sd(self, free_plane: bool) -> FloatArray | None:
        """The omega_1 term on the grid for a fundamental in the free plane (``free_omega1_sd``
        where given) or not (``omega1_sd``)."""
        if free_plane and self.free_omega1_sd is not None:
            return self.free_omega1_sd
        return self.omega1_sd

    def omega1_sd_at(self, x_c: float, free_plane: bool = False) -> float:
        """:meth:`frequency_sd` at ``x_c`` (m), linearly between grid points; 0 without it."""
        term = self.frequency_sd(free_plane)
        if self.grid is None or term is None:
            return 0.0
        return float(np.interp(x_c, self.grid, term))


@dataclass(frozen=True)
class SensorBias:
    """Contact-load channels measured while nothing touches the link and the head rests.

    Attributes
    ----------
    bias : array, shape (5,)
        Mean of the :func:`contact_channels` over the initial rest (N, N m).
    cov : array, shape (5, 5)
        Its covariance (diagonal, white noise: variance / n).
    n_samples : int
        Samples averaged (0 when there was no initial rest: bias and cov are zero).
    """

    bias: FloatArray
    cov: FloatArray
    n_samples: int


def sensor_bias(
    channels: FloatArray,
    theta: FloatArray,
    contact_index: int,
    tolerance: float,
    min_samples: int = 20,
    guard: int = 0,
    settled: Sequence[int] | None = None,
) -> SensorBias:
    """Bias of the contact-load channels from the initial rest before the sweep.

    Parameters
    ----------
    channels : array, shape (n, 5)
        :func:`contact_channels` of the recording.
    theta : array, shape (n, 2)
        Motor angles (rad).
    contact_index : int
        Index of t_c; only samples before it are used.
    tolerance : float
        The head rests while both angles stay within this distance of their first value (rad).
    min_samples : int
        Fewer rest samples than this give no bias (zero, ``n_samples = 0``).
    guard : int
        Samples left out before the first one where the head has moved, or before t_c (the
        motion, or the touch, loads the sensor before it is detected).
    settled : sequence of int, shape (5,), optional
        Samples at the start over which each channel's load holds its level (the front end's
        tare at rest, :func:`~sensing_antenna.estimation.front.steps.settled_loads`): the
        channel's rest ends there at the latest, since a coarse encoder sees the sweep start
        late.

    Returns
    -------
    SensorBias
    """
    theta = np.asarray(theta, dtype=float)
    moved = np.flatnonzero(np.any(np.abs(theta[:contact_index] - theta[0]) > tolerance, axis=1))
    stop = (int(moved[0]) if moved.size else contact_index) - guard
    k = channels.shape[1]
    stops = np.full(k, stop) if settled is None else np.minimum(stop, np.asarray(settled))
    if stops.min() < min_samples:
        return SensorBias(np.zeros(k), np.zeros((k, k)), 0)
    rest = [np.asarray(channels[:count, j], dtype=float) for j, count in enumerate(stops)]
    mean = np.array([part.mean() for part in rest])
    variance = np.array([part.var(ddof=1) / part.size for part in rest])
    return SensorBias(mean, np.diag(variance), int(stops.min()))
