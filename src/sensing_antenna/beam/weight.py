"""The weight of a pushed, sagging link: what it adds to the contact's moment at the base.

The elastica statics (:mod:`sensing_antenna.beam.elastica`) load a link that is straight before
the push at the contact alone. A real link carries its own weight: free, it sags under it
(:meth:`~sensing_antenna.antenna.Link.unit_sag`), and the gravity model
(:meth:`~sensing_antenna.antenna.Antenna.gravity_torque`) removes the moment of that free, sagged
link's weight. Pushing it moves its masses and its contact away from where those two models put
them, and the base feels the difference.

Notation. X along the link at the base, z up, u the direction of the reaction's part across the
link (|R_perp| = P, along the link R_x), v = X x u the axis the ratio reads the moment about;
zeta_X = X . z and zeta_u = u . z. Small deflections superpose: the link's shape is its sag
w_g(s) = -g u_s(s) (z - zeta_X X) (u_s the unit sag) plus the push's P G(s) u, G the cantilever
loaded at x_c (Eq. 13's shape: G = c s^2 (3 x_c - s) / 6 up to x_c, c x_c^2 (3 s - x_c) / 6
beyond, c = 1 / (E I)). A point moved by dr changes the moment about v of a weight -g dm z by
g dm (dr_u zeta_X - dr_X zeta_u), and the contact moved by dr_c changes R's by
-(dr_c . u) R_x + (dr_c . X) P. The projection of the link on X shortens by
a(s) = 1/2 integral of |theta|^2 up to s, and its slope theta is the sag's plus the push's, so
the cross product of the two slopes shortens it in proportion to the push. Six terms, each a
moment about v (N m), kept to first order in the sag:

1. the sag's lever on the reaction along the link: ``g zeta_u u_s(x_c) R_x``;
2. the masses swept across by the push: ``g zeta_X P integral of G dm``;
3. the masses drawn in by the push's own shortening: ``g zeta_u P^2 / 2 integral of G'^2 m(s)
   ds``, m(s) the mass beyond s;
4. the masses drawn in (or let out) by the sag's slope times the push's:
   ``-g^2 zeta_u^2 P integral of u_s' G' m(s) ds``;
5. the contact drawn in the same way: ``g zeta_u P^2 integral of u_s' G' ds`` up to x_c;
6. the contact drawn in by the sag's own shortening: ``-g^2 (1 - zeta_X^2) P / 2 integral of
   u_s'^2 ds`` up to x_c.

The elastica holds the push's own geometry (the contact's lateral lever on R_x and its
shortening); these terms are what the weight adds to it. Each integrand is a polynomial of
degree 6 or less on [0, x_c] and on [x_c, l], so Gauss-Legendre quadrature with four nodes on
each is exact, and each integral a polynomial of degree 8 or less in x_c, interpolated once
per link. Not among them: what the reaction along the link does to the sagging link (R_x
bends it further, a lever for R_x itself, of order g zeta_u R_x^2 / (E I)) and the weight's
share along the link bending the pushed link (of order g zeta_X P R_x). Against a shooting
solution of the planar elastica carrying its weight and the push
(``tests/test_beam_weight.py``) what the sum leaves grows with the deflection;
:data:`WEIGHT_RESIDUAL` bounds it.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import STANDARD_GRAVITY, Link

__all__ = [
    "WEIGHT_RESIDUAL",
    "WEIGHT_TERMS",
    "pushed_weight_moment",
    "weight_moment",
    "weight_residual",
]

FloatArray = NDArray[np.float64]

#: Names of the terms of :func:`pushed_weight_moment`, in order.
WEIGHT_TERMS = (
    "sag lever",
    "sweep",
    "push shortening",
    "cross shortening",
    "contact cross shortening",
    "contact sag shortening",
)

#: (a, b): the first-order terms' error is at most (a + b d) times the sum of their magnitudes, d
#: the push's deflection over x_c; set against the shooting elastica with its weight
#: (``tests/test_beam_weight.py``).
WEIGHT_RESIDUAL = (0.05, 1.5)

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(4)

#: The integrals' highest degree in x_c.
_DEGREE = 8

#: Up to this many samples :func:`weight_moment` works on plain floats.
_SCALAR_SAMPLES = 8


def pushed_weight_moment(
    link: Link,
    x_c: ArrayLike,
    push: ArrayLike,
    axial: ArrayLike,
    link_vertical: ArrayLike,
    push_vertical: ArrayLike,
) -> FloatArray:
    """The moment (N m) the pushed link's weight adds about v = X x u to the contact's, beyond
    the elastica loaded at the contact alone and the free link's weight (module docstring),
    term by term.

    Parameters
    ----------
    link : Link
        Its stiffness is ``1 / bending_compliance``, the one its sag has.
    x_c : array_like
        Contact points (m), on the link.
    push : array_like
        |R_perp| (N).
    axial : array_like
        R_x, the reaction along the link (N).
    link_vertical, push_vertical : array_like
        X . z and u . z, signed.

    Returns
    -------
    array, shape ``broadcast shape + (6,)``
        The terms of :data:`WEIGHT_TERMS`.
    """
    x_c, push, axial, zeta_x, zeta_u = np.broadcast_arrays(
        *(np.asarray(a, dtype=float) for a in (x_c, push, axial, link_vertical, push_vertical))
    )
    integrals = np.polynomial.polynomial.polyval(x_c / link.length, _polynomials(link).T)
    factors = _factors(push, axial, zeta_x, zeta_u)
    return np.stack([f * i for f, i in zip(factors, integrals, strict=True)], axis=-1)


def weight_moment(
    link: Link,
    x_c: FloatArray,
    push: FloatArray,
    axial: FloatArray,
    link_vertical: FloatArray,
    push_vertical: FloatArray,
) -> FloatArray:
    """The sum of :func:`pushed_weight_moment`'s terms (N m), for arrays of one shape (n,); a
    stream calls it a sample at a time, so a few samples go through plain floats."""
    if x_c.shape[0] > _SCALAR_SAMPLES:
        return np.asarray(
            pushed_weight_moment(link, x_c, push, axial, link_vertical, push_vertical).sum(-1)
        )
    rows = _polynomial_rows(link)
    length = link.length
    out = []
    for x, p, r_x, zx, zu in zip(
        x_c.tolist(),
        push.tolist(),
        axial.tolist(),
        link_vertical.tolist(),
        push_vertical.tolist(),
        strict=True,
    ):
        t = x / length
        integrals = []
        for row in rows:
            value = 0.0
            for c in row:
                value = value * t + c
            integrals.append(value)
        factors = _factors(p, r_x, zx, zu)
        out.append(sum(f * i for f, i in zip(factors, integrals, strict=True)))
    return np.array(out, dtype=float)


def _factors(push: Any, axial: Any, zeta_x: Any, zeta_u: Any) -> list[Any]:
    """What multiplies each of the six integrals of :func:`_integrals` (floats or arrays)."""
    g = STANDARD_GRAVITY
    # products, not powers: a float's power raises where a product of loads beyond any sensor
    # overflows to inf
    return [
        g * zeta_u * axial,
        g * zeta_x * push,
        0.5 * g * zeta_u * push * push,
        -g * g * zeta_u * zeta_u * push,
        g * zeta_u * push * push,
        -0.5 * g * g * (1.0 - zeta_x * zeta_x) * push,
    ]


def weight_residual(deflection: ArrayLike) -> FloatArray:
    """(a + b d) of :data:`WEIGHT_RESIDUAL` at the push's deflection over x_c ``deflection``
    (d = |R_perp| x_c^2 / (3 E I), Eq. 13; dimensionless, any shape)."""
    return np.asarray(
        WEIGHT_RESIDUAL[0] + WEIGHT_RESIDUAL[1] * np.asarray(deflection, dtype=float), dtype=float
    )


def _slope(link: Link, x_c: FloatArray, s: FloatArray) -> FloatArray:
    """G'(s): the slope of the link loaded by 1 N at x_c (rad per N)."""
    compliance = link.bending_compliance
    return np.where(s <= x_c, s * (2.0 * x_c - s), x_c**2) * (0.5 * compliance)


def _deflection(link: Link, x_c: FloatArray, s: FloatArray | float) -> FloatArray:
    """G(s): the deflection of the link loaded by 1 N at x_c (m per N)."""
    shape = np.where(s <= x_c, s**2 * (3.0 * x_c - s), x_c**2 * (3.0 * s - x_c))
    return np.asarray(shape * (link.bending_compliance / 6.0), dtype=float)


def _sag_slope(link: Link, s: FloatArray) -> FloatArray:
    """u_s'(s): the slope of the unit sag (rad per m/s^2)."""
    length, rho, tip = link.length, link.linear_density, link.weighed_tip_mass
    spread = rho * s * (3.0 * length**2 - 3.0 * length * s + s**2) / 6.0
    return np.asarray((spread + tip * s * (2.0 * length - s) / 2.0) * link.bending_compliance)


def _integrals(link: Link, x_c: FloatArray) -> FloatArray:
    """The six integrals the terms multiply, shape ``x_c.shape + (6,)``, by quadrature: the
    unit sag u_s(x_c), integral of G dm, of G'^2 m(s) ds, of u_s' G' m(s) ds (over the link),
    of u_s' G' ds and of u_s'^2 ds (up to x_c)."""
    inner = _quadrature(link, x_c, np.zeros(x_c.shape), x_c)
    outer = _quadrature(link, x_c, x_c, np.full(x_c.shape, link.length))
    whole = {k: inner[k] + outer[k] for k in inner}
    sweep = whole["deflection_mass"] + link.weighed_tip_mass * _deflection(link, x_c, link.length)
    return np.stack(
        [
            np.asarray(link.unit_sag(x_c)),
            sweep,
            whole["slope_squared_mass"],
            whole["cross_mass"],
            inner["cross"],
            inner["sag_slope_squared"],
        ],
        axis=-1,
    )


@functools.lru_cache(maxsize=16)
def _polynomials(link: Link) -> FloatArray:
    """Coefficients (6, 9) of the six integrals as polynomials of x_c / l, lowest power first:
    each is one of degree 8 or less, so interpolating it at nine Chebyshev points is exact (to
    rounding)."""
    t = 0.5 - 0.5 * np.cos(np.pi * (np.arange(_DEGREE + 1) + 0.5) / (_DEGREE + 1))
    values = _integrals(link, t * link.length)
    return np.asarray(np.polynomial.polynomial.polyfit(t, values, _DEGREE).T, dtype=float)


@functools.lru_cache(maxsize=16)
def _polynomial_rows(link: Link) -> list[list[float]]:
    """:func:`_polynomials` as lists of floats, highest power first (Horner's order)."""
    return [row[::-1].tolist() for row in _polynomials(link)]


def _quadrature(
    link: Link, x_c: FloatArray, start: FloatArray, stop: FloatArray
) -> dict[str, FloatArray]:
    """The integrals of the module docstring over [start, stop], one polynomial piece of G."""
    half = 0.5 * (stop - start)
    s = (0.5 * (stop + start))[..., None] + half[..., None] * _NODES
    weights = half[..., None] * _WEIGHTS
    slope = _slope(link, x_c[..., None], s)
    sag_slope = _sag_slope(link, s)
    beyond = link.linear_density * (link.length - s) + link.weighed_tip_mass
    deflection = _deflection(link, x_c[..., None], s)
    return {
        "deflection_mass": np.sum(weights * deflection, axis=-1) * link.linear_density,
        "slope_squared_mass": np.sum(weights * slope**2 * beyond, axis=-1),
        "cross_mass": np.sum(weights * sag_slope * slope * beyond, axis=-1),
        "cross": np.sum(weights * sag_slope * slope, axis=-1),
        "sag_slope_squared": np.sum(weights * sag_slope**2, axis=-1),
    }
