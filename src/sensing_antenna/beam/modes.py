"""Natural frequencies (rad/s) and mode shapes of the link in contact mode (Section 3.3).

The frequency conversion follows from the Euler-Bernoulli equation (Eq. 3):
``beta^4 = rho omega^2 / (E I)`` gives ``omega = beta^2 sqrt(E I / rho) = (beta l)^2 / (T l^2)``
with ``T = sqrt(rho / (E I))`` in s/m^2, and ``f = omega / (2 pi)`` in Hz. The printed Eq. 17,
``f = 2 pi sqrt(E I / rho) beta^2``, multiplies by 2 pi instead of dividing: it is (2 pi)^2 = 39.5
times too high (174 Hz instead of 4.4 Hz at x_c = 0.3 m, theoretical T); it is not used.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import Link
from sensing_antenna.beam._validate import BeamInputError, as_finite_array, check_mode_count
from sensing_antenna.beam.characteristic import eigenvalues

__all__ = [
    "contact_ratio",
    "contact_to_base_shear",
    "frequency_scale",
    "held_contact_coupling",
    "mode_shapes",
    "natural_frequencies",
    "support_compliance_coefficients",
]

FloatArray = NDArray[np.float64]

#: Spans with mu = beta l_span below this use the power-series (Krylov) basis, which stays well
#: conditioned as the span shrinks; longer spans use cos, sin and decaying exponentials.
_KRYLOV_SWITCH = 2.0
#: Terms of the Krylov power series: at mu = 2 the first omitted term is 2^48 / 48! < 1e-46.
_KRYLOV_TERMS = 12
#: Gauss-Legendre nodes per span for the modal-mass integral; exact for polynomials of degree
#: 2 * 48 - 1 and far more than the few half-waves of the modes this module is used for.
_QUADRATURE_NODES = 48
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(_QUADRATURE_NODES)


def frequency_scale(link: Link) -> float:
    """1 / (T l^2) in rad/s: multiply (beta l)^2 by this to get omega (T = ``link.t_param``)."""
    return 1.0 / (link.t_param * link.length**2)


def contact_ratio(link: Link, x_c: ArrayLike) -> FloatArray:
    """xi = x_c / l after checking 0 < x_c <= l (m).

    Raises
    ------
    BeamInputError
        Naming ``x_c`` if any value is outside (0, l] or not finite.
    """
    x_c_a = as_finite_array("x_c", x_c, low=0.0, high=link.length, low_open=True)
    return np.minimum(x_c_a / link.length, 1.0)


def natural_frequencies(link: Link, x_c: ArrayLike, n_modes: int = 3) -> FloatArray:
    """First ``n_modes`` natural frequencies omega_i (rad/s) with contact at ``x_c`` (m).

    Parameters
    ----------
    link : Link
        The link; its tip-mass ratio R_m and ``t_param`` (T, or the calibrated T_e) are used.
    x_c : array_like
        Contact point(s) in (0, l] (m), any shape.
    n_modes : int
        Number of modes, >= 1.

    Returns
    -------
    ndarray
        omega_i (rad/s), shape ``x_c.shape + (n_modes,)``, increasing along the last axis.
    """
    xi = contact_ratio(link, x_c)
    # omega_i = (beta_i l)^2 / (T l^2), from beta^4 = rho omega^2 / (E I) (replaces Eq. 17)
    return eigenvalues(xi, n_modes, link.tip_mass_ratio) ** 2 * frequency_scale(link)


def _krylov(order: int, mu: float, r: FloatArray, j: int) -> FloatArray:
    """L^k d^k/du^k of the scaled Krylov function K_j(beta u) / mu^(j-1), r = u / L.

    Term n of the series is mu^(4n) r^(4n+j-1-k) / (4n+j-1-k)!, dropped when the power is < 0.
    """
    total = np.zeros_like(r)
    for n in range(_KRYLOV_TERMS):
        power = 4 * n + j - 1 - order
        if power < 0:
            continue
        total = total + mu ** (4 * n) * r**power / math.factorial(power)
    return total


def _basis(order: int, lam: float, length: float, u: FloatArray) -> FloatArray:
    """Four basis functions of one span (columns), k-th derivative in 1/l^k units.

    ``u`` is the distance from the span start (fraction of l), ``length`` the span length.
    """
    mu = lam * length
    if mu < _KRYLOV_SWITCH:
        r = u / length
        cols = [_krylov(order, mu, r, j) / length**order for j in (1, 2, 3, 4)]
    else:
        phase = order * np.pi / 2.0
        cols = [
            lam**order * np.cos(lam * u + phase),
            lam**order * np.sin(lam * u + phase),
            (-lam) ** order * np.exp(-lam * u),
            lam**order * np.exp(-lam * (length - u)),
        ]
    return np.stack(cols, axis=-1)


def _mode_coefficients(lam: float, xi: float, ratio: float) -> list[tuple[float, FloatArray]]:
    """Null vector of the boundary conditions of Eq. 4: [(span length, 4 coefficients), ...]."""
    zero = np.zeros(1)
    if xi >= 1.0:
        rows = [
            _basis(0, lam, 1.0, zero)[0],  # Eq. 4: y(0) = 0
            _basis(1, lam, 1.0, zero)[0],  # Eq. 4: y'(0) = 0
            _basis(0, lam, 1.0, np.ones(1))[0],  # Eq. 4: y(x_c) = 0 at x_c = l
            _basis(2, lam, 1.0, np.ones(1))[0],  # Eq. 4: y''(l) = 0
        ]
        spans = [1.0]
    else:
        a, b = xi, 1.0 - xi
        end_a, end_b = np.array([a]), np.array([b])

        def pad(left: FloatArray | None, right: FloatArray | None) -> FloatArray:
            return np.concatenate(
                [
                    left if left is not None else np.zeros(4),
                    right if right is not None else np.zeros(4),
                ]
            )

        tip_shear = _basis(3, lam, b, end_b)[0] + ratio * lam**4 * _basis(0, lam, b, end_b)[0]
        rows = [
            pad(_basis(0, lam, a, zero)[0], None),  # Eq. 4: y(0) = 0
            pad(_basis(1, lam, a, zero)[0], None),  # Eq. 4: y'(0) = 0
            pad(_basis(0, lam, a, end_a)[0], None),  # Eq. 4: y(x_c-) = 0
            pad(None, _basis(0, lam, b, zero)[0]),  # Eq. 4: y(x_c+) = 0
            pad(_basis(1, lam, a, end_a)[0], -_basis(1, lam, b, zero)[0]),  # Eq. 4: slope
            pad(_basis(2, lam, a, end_a)[0], -_basis(2, lam, b, zero)[0]),  # Eq. 4: moment
            pad(None, _basis(2, lam, b, end_b)[0]),  # Eq. 4: y''(l) = 0
            pad(None, tip_shear),  # Eq. 4: E I y'''(l) = m_t y_tt(l)
        ]
        spans = [a, b]
    matrix = np.array(rows)
    matrix /= np.max(np.abs(matrix), axis=1, keepdims=True)
    null = np.linalg.svd(matrix)[2][-1]
    return [(length, null[4 * i : 4 * i + 4]) for i, length in enumerate(spans)]


def _evaluate(lam: float, pieces: list[tuple[float, FloatArray]], s: FloatArray) -> FloatArray:
    out = np.zeros_like(s)
    start = 0.0
    for i, (length, coef) in enumerate(pieces):
        last = i == len(pieces) - 1
        inside = (s >= start) & ((s <= start + length) if last else (s < start + length))
        out[inside] = _basis(0, lam, length, s[inside] - start) @ coef
        start += length
    return out


def _normalise(lam: float, pieces: list[tuple[float, FloatArray]], ratio: float) -> float:
    """Factor giving int_0^1 phi^2 ds + R_m phi(1)^2 = 1, signed so the largest value is > 0."""
    nodes, weights = _NODES, _WEIGHTS
    mass = 0.0
    samples = []
    start = 0.0
    for length, coef in pieces:
        u = 0.5 * length * (nodes + 1.0)
        values = _basis(0, lam, length, u) @ coef
        mass += 0.5 * length * float(weights @ values**2)
        samples.append(values)
        start += length
    tip = float(_evaluate(lam, pieces, np.ones(1))[0])
    mass += ratio * tip**2
    values = np.concatenate([*samples, [tip]])
    sign = 1.0 if values[np.argmax(np.abs(values))] > 0 else -1.0
    return sign / np.sqrt(mass)


def mode_shapes(link: Link, x_c: float, x: ArrayLike, n_modes: int = 3) -> FloatArray:
    """Mode shapes phi_i(x) of the link touching at ``x_c`` (m), sampled at ``x`` (m).

    Parameters
    ----------
    link : Link
        The link (length and tip-mass ratio are used).
    x_c : float
        Contact point in (0, l] (m).
    x : array_like
        Positions along the link in [0, l] (m), 1-D.
    n_modes : int
        Number of modes, >= 1.

    Returns
    -------
    ndarray
        Shape ``(len(x), n_modes)``, dimensionless. Normalised to unit modal mass relative to the
        link, ``(int_0^l rho phi^2 dx + m_t phi(l)^2) / m_b = 1``, and signed so that the value of
        largest magnitude along the link is positive. ``phi(x_c) = 0``.
    """
    xi_arr = contact_ratio(link, x_c)
    if xi_arr.ndim != 0:
        raise BeamInputError("x_c", f"must be a single contact point, got shape {xi_arr.shape}")
    xi = float(xi_arr)
    s = as_finite_array("x", x, low=0.0, high=link.length) / link.length
    if s.ndim != 1:
        raise BeamInputError("x", f"must be 1-D, got shape {s.shape}")
    n = check_mode_count(n_modes)
    ratio = link.tip_mass_ratio
    lams = eigenvalues(xi, n, ratio)
    out = np.empty((s.size, n))
    for i, lam in enumerate(lams):
        pieces = _mode_coefficients(float(lam), xi, ratio)
        out[:, i] = _evaluate(float(lam), pieces, s) * _normalise(float(lam), pieces, ratio)
    return out


def contact_to_base_shear(link: Link, x_c: ArrayLike) -> FloatArray:
    """Amplitude of the contact force over that of the base shear force in the first contact mode.

    Both are shear forces of the mode shape phi (Eq. 3 with the boundary conditions of Eq. 4):
    the contact force is the jump E I (phi'''(x_c+) - phi'''(x_c-)) at the pin (phi'''(x_c+) = 0
    when the contact is at the tip) and the base shear is E I phi'''(0); E I cancels. Negative:
    they are in antiphase. The F/T sensor sees the base shear, so this ratio turns a measured
    vibration amplitude into the vibration of the contact force.

    Parameters
    ----------
    link : Link
    x_c : array_like
        Contact points in (0, l] (m).

    Returns
    -------
    ndarray
        Dimensionless, shape ``x_c.shape``.
    """
    xi = contact_ratio(link, x_c)
    ratio = link.tip_mass_ratio
    lams = eigenvalues(xi, 1, ratio)[..., 0]
    out = np.empty(xi.shape)
    zero = np.zeros(1)
    for index in np.ndindex(xi.shape):
        lam = float(lams[index])
        pieces = _mode_coefficients(lam, float(xi[index]), ratio)
        first_length, first = pieces[0]
        base = float(_basis(3, lam, first_length, zero)[0] @ first)
        left = float(_basis(3, lam, first_length, np.array([first_length]))[0] @ first)
        right = 0.0
        if len(pieces) > 1:
            right = float(_basis(3, lam, pieces[1][0], zero)[0] @ pieces[1][1])
        out[index] = (right - left) / base
    return out


def held_contact_coupling(link: Link, x_c: ArrayLike) -> FloatArray:
    """kappa(x_c) (m): how much a contact held along the obstacle stiffens the first contact mode
    of a link the push has bent, per unit of the axial force it makes the base feel over the
    base's bending moment in that mode.

    A push deflecting the contact by d x_c bends the link to w_0(s) = d (3 x_c s^2 - s^3) /
    (2 x_c^2) (Eq. 7) in its bending plane. Vibrating there as q phi(s), the arc from O to the
    contact changes its projection along the link by -d q G at first order,

        G = integral_0^x_c (w_0' / d) phi' ds = -(3 / x_c^2) integral_0^x_c (x_c - s) phi ds,

    which a sliding contact lets go and one friction holds resists with an axial force k d G q
    (k the hold's stiffness). The base then feels the bending moment E I phi''(0) q and the
    axial force k d G q; the hold stores k (d G q)^2 / 2, so by Rayleigh's quotient the push
    plane's omega_1 rises by

        Delta omega / omega = r kappa d / 2,   kappa = E I phi''(0) G / (m_b omega_1^2),

    r the base's axial force over its bending moment at omega_1 (1/m, in phase). The straight
    link's model (Eq. 4) lets the contact slide. In the link's own units kappa = l phi''(0) G /
    (beta_1 l)^4, phi'' in units of 1 / l^2.

    Parameters
    ----------
    link : Link
    x_c : array_like
        Contact points in (0, l] (m).

    Returns
    -------
    ndarray
        Shape ``x_c.shape`` (m).
    """
    xi = contact_ratio(link, x_c)
    ratio = link.tip_mass_ratio
    lams = eigenvalues(xi, 1, ratio)[..., 0]
    nodes, weights = _NODES, _WEIGHTS
    zero = np.zeros(1)
    out = np.empty(xi.shape)
    for index in np.ndindex(xi.shape):
        lam = float(lams[index])
        pieces = _mode_coefficients(lam, float(xi[index]), ratio)
        scale = _normalise(lam, pieces, ratio)
        span, first = pieces[0]
        bending = scale * float(_basis(2, lam, span, zero)[0] @ first)
        u = 0.5 * span * (nodes + 1.0)
        phi = scale * (_basis(0, lam, span, u) @ first)
        # G = -(3 / xi^2) integral_0^xi (xi - u) phi du, Gauss-Legendre over the first span
        chord = -1.5 / span * float(weights @ ((span - u) * phi))
        out[index] = link.length * bending * chord / lam**4
    return out


def support_compliance_coefficients(link: Link, x_c: ArrayLike, n_modes: int = 2) -> FloatArray:
    """c_i (N/m): a support of finite stiffness k (N/m) at ``x_c`` in place of the pin lowers
    omega_i by the fraction c_i / k, to first order in 1 / k.

    Relaxing the pin into a spring, omega_i^2 falls by R_i^2 / k (Rayleigh), R_i the pin's
    reaction in mode i normalised to unit modal mass: the jump of E I times the third
    derivative of the mode at x_c. In the link's own units (u = s / l, phi of unit modal mass
    relative to the link) that is

        c_i = (E I / l^3) J_i^2 / (2 (beta_i l)^4),   J_i = phi_i'''(xi+) - phi_i'''(xi-),

    E I = rho / T^2 with the frequency model's T (a calibrated T_e measures that ratio). A soft
    object (foam, rubber, a stem) is such a support; a mode whose shear is continuous at x_c
    (there a node of the free link's next mode) does not feel it.

    Parameters
    ----------
    link : Link
    x_c : array_like
        Contact points in (0, l] (m).
    n_modes : int
        Number of modes, >= 1.

    Returns
    -------
    ndarray
        Shape ``x_c.shape + (n_modes,)`` (N/m).
    """
    xi = contact_ratio(link, x_c)
    n = check_mode_count(n_modes)
    ratio = link.tip_mass_ratio
    lams = eigenvalues(xi, n, ratio)
    stiffness = 1.0 / (link.bending_compliance * link.length**3)
    out = np.empty((*xi.shape, n))
    for index in np.ndindex(out.shape):
        lam = float(lams[index])
        pieces = _mode_coefficients(lam, float(xi[index[:-1]]), ratio)
        scale = _normalise(lam, pieces, ratio)
        first_length, first = pieces[0]
        left = float(_basis(3, lam, first_length, np.array([first_length]))[0] @ first)
        right = 0.0
        if len(pieces) > 1:
            right = float(_basis(3, lam, pieces[1][0], np.zeros(1))[0] @ pieces[1][1])
        jump = scale * (right - left)
        out[index] = stiffness * jump**2 / (2.0 * lam**4)
    return out
