"""Closed-form elastica of a cantilever under a transverse dead load at its tip.

An inextensible, unshearable link of length l and flexural rigidity E I, clamped horizontally at
s = 0, carries at its free end a load P of fixed direction, perpendicular to the undeformed
axis. With phi(s) the angle of the tangent to the undeformed axis, ``E I phi'' = -P cos(phi)``,
``phi(0) = 0``, ``phi'(l) = 0``; the first integral ``E I phi'^2 / 2 = P (sin phi_l - sin phi)``
and the substitution ``1 + sin(phi) = 2 p^2 sin^2(theta)`` (``1 + sin(phi_l) = 2 p^2``) give,
with ``alpha = P l^2 / (E I)``, the incomplete elliptic integrals F and E of modulus p
(parameter m = p^2) and ``theta_0 = arcsin(1 / (p sqrt 2))``:

    sqrt(alpha) = K(p) - F(theta_0, p)
    delta / l = 1 - 2 (E(p) - E(theta_0, p)) / sqrt(alpha)          (tip deflection along P)
    x_l / l = sqrt(2 sin(phi_l) / alpha)                              (tip abscissa)

(Bisshopp and Drucker, Q. Appl. Math. 3, 1945, whose table gives delta / l = 0.3017 at
alpha = 1). Linear theory is ``delta / l = alpha / 3``, ``x_l = l``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import brentq
from scipy.special import ellipe, ellipeinc, ellipk, ellipkinc

__all__ = ["TipLoadElastica", "tip_load_elastica", "tip_load_for_deflection"]


@dataclass(frozen=True)
class TipLoadElastica:
    """Equilibrium of the tip-loaded cantilever, non-dimensional.

    Attributes
    ----------
    load : float
        alpha = P l^2 / (E I) (dimensionless).
    tip_deflection : float
        delta / l, the tip's displacement along the load (dimensionless).
    tip_abscissa : float
        x_l / l, the tip's coordinate along the undeformed axis (dimensionless).
    tip_angle : float
        phi_l, the tangent's angle at the tip (rad).
    """

    load: float
    tip_deflection: float
    tip_abscissa: float
    tip_angle: float


def _load_of_modulus(p: float) -> float:
    m = p * p
    theta0 = math.asin(min(1.0, 1.0 / (p * math.sqrt(2.0))))
    return float(ellipk(m) - ellipkinc(theta0, m)) ** 2


def tip_load_elastica(load: float) -> TipLoadElastica:
    """The elastica of the cantilever under the non-dimensional tip load ``load`` = P l^2 / EI.

    Parameters
    ----------
    load : float
        alpha >= 0 (dimensionless); 0 gives the straight link.

    Returns
    -------
    TipLoadElastica
    """
    if not (math.isfinite(load) and load >= 0.0):
        raise ValueError(f"load must be finite and >= 0, got {load!r}")
    if load == 0.0:
        return TipLoadElastica(0.0, 0.0, 1.0, 0.0)
    low = 1.0 / math.sqrt(2.0)
    # alpha grows from 0 (p^2 = 1/2) to infinity (p -> 1); bracket and solve for p
    high = 1.0 - 1e-15
    p = brentq(lambda q: _load_of_modulus(q) - load, low, high, xtol=1e-15, rtol=1e-15)
    m = p * p
    theta0 = math.asin(min(1.0, 1.0 / (p * math.sqrt(2.0))))
    root = math.sqrt(load)
    deflection = 1.0 - 2.0 * float(ellipe(m) - ellipeinc(theta0, m)) / root
    sin_tip = 2.0 * m - 1.0
    abscissa = math.sqrt(2.0 * sin_tip / load)
    return TipLoadElastica(load, deflection, abscissa, math.asin(min(1.0, sin_tip)))


def tip_load_for_deflection(deflection: float) -> TipLoadElastica:
    """The elastica whose tip deflection delta / l is ``deflection`` (0 <= deflection <= 0.9).

    The displacement-controlled push: ``load`` is then the alpha it takes, against the linear
    theory's ``3 deflection``.
    """
    if not (math.isfinite(deflection) and 0.0 <= deflection <= 0.9):
        raise ValueError(f"deflection must be in [0, 0.9], got {deflection!r}")
    if deflection == 0.0:
        return tip_load_elastica(0.0)
    alpha = brentq(
        lambda a: tip_load_elastica(a).tip_deflection - deflection, 0.0, 100.0, xtol=1e-14
    )
    return tip_load_elastica(alpha)
