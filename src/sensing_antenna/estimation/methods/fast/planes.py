"""Which bending plane each fitted mode vibrates in: the push plane or the free plane.

The sensing curves are the straight link's, pinned at the contact in both planes. A link the
push has bent keeps that model out of its bending plane (the free plane: within a few per cent
of omega_1 up to 30 % deflection, friction along the link included, docs/estimation.md, "The two
bending planes"), while in the push plane a contact that friction holds along the obstacle
raises the frequency by an amount no function of the deflection bounds (up to +173 % at
x_c = 0.9 m held outright). When both planes ring in the
omega_1 band as separate modes, the free plane's is the one to read.

The five contact-load channels (:func:`.static_fit.contact_channels`) are R_y, R_z, Gamma_x,
Gamma_y, Gamma_z in the motor frame. With u the push's unit direction in the Y^m-Z^m plane and
v = X^m x u, a mode vibrating in the push plane moves the reaction along u and the moment along
X^m x u = v; one in the free plane the reaction along v and the moment along X^m x v = -u. A
mode's complex amplitudes in the channels (one phase for a standing vibration) projected on
those directions, each pair over its noise, give its energy in each plane.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.methods.fast.parametric import DampedSinusoidFit

__all__ = ["free_plane_share"]

FloatArray = NDArray[np.float64]


def free_plane_share(fit: DampedSinusoidFit, push_direction: FloatArray) -> FloatArray:
    """Fraction of each mode's signal-to-noise energy in the free plane, shape (M,), in [0, 1].

    Parameters
    ----------
    fit : DampedSinusoidFit
        A fit of the five contact-load channels, with its ``phasors``.
    push_direction : array, shape (2,)
        The hold's reaction across the link, (R_y, R_z) in the motor frame (N); only its
        direction is used.

    Returns
    -------
    array, shape (M,)
        0: the mode is wholly in the push plane; 1: wholly in the free plane; NaN for every
        mode when the fit has no phasors or the push has no direction.
    """
    m = fit.n_modes
    u = np.asarray(push_direction, dtype=float)
    norm = float(np.hypot(u[0], u[1]))
    if fit.phasors is None or fit.phasors.shape[0] != 5 or not norm > 0.0:
        return np.full(m, np.nan)
    u = u / norm
    v = np.array([-u[1], u[0]])
    force = fit.phasors[0:2] / np.mean(fit.noise_std[0:2])
    moment = fit.phasors[3:5] / np.mean(fit.noise_std[3:5])
    push = np.abs(u @ force) ** 2 + np.abs(v @ moment) ** 2
    free = np.abs(v @ force) ** 2 + np.abs(u @ moment) ** 2
    total = push + free
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.asarray(np.where(total > 0.0, free / total, np.nan), dtype=float)
