"""Finite-element model of the flexible link: Euler-Bernoulli bending, Hermite cubic elements.

The link is clamped at the head (x = 0) and bends in two planes of the motor frame: ``v(x, t)``
along Y^m and ``w(x, t)`` along Z^m. With a circular section both planes share one set of
matrices. Each node carries a deflection and a slope; the clamped node is removed, so a model of
``n_elements`` elements has ``2 n_elements`` degrees of freedom per plane, ordered
``[v_1, v_1', v_2, v_2', ...]``.

Euler-Bernoulli (Eq. 3 of the paper, with the loads put back) reads
``rho v_tt + E I v_xxxx = q(x, t)``; the Galerkin discretisation with the cubic Hermite shape
functions gives ``M q_tt + K q = f``. Hermite cubics represent the rigid motions exactly, so the
vectors ``M r`` of the rigid translation and rotation are the exact integrals ``int rho N dx`` and
``int rho x N dx`` used for inertial loads and base reactions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import eigh

from sensing_antenna.antenna import Link
from sensing_antenna.simulator.device import DeviceError, DeviceImperfections

__all__ = [
    "LinkModel",
    "build_link_model",
    "hermite_shape",
    "hermite_shape_slope",
    "rayleigh_coefficients",
]


def hermite_shape(xi: float, h: float) -> NDArray[np.float64]:
    """Cubic Hermite shape functions of one element at local coordinate ``xi`` in [0, 1].

    Parameters
    ----------
    xi : float
        Local coordinate s / h (dimensionless).
    h : float
        Element length (m).

    Returns
    -------
    ndarray, shape (4,)
        Weights of ``[w_a, w_a', w_b, w_b']`` (dimensionless, m, dimensionless, m).
    """
    xi2 = xi * xi
    xi3 = xi2 * xi
    return np.array(
        [
            1.0 - 3.0 * xi2 + 2.0 * xi3,
            h * (xi - 2.0 * xi2 + xi3),
            3.0 * xi2 - 2.0 * xi3,
            h * (xi3 - xi2),
        ]
    )


def hermite_shape_slope(xi: float, h: float) -> NDArray[np.float64]:
    """Derivatives d/dx of :func:`hermite_shape` (1/m, dimensionless, 1/m, dimensionless)."""
    xi2 = xi * xi
    return np.array(
        [
            (-6.0 * xi + 6.0 * xi2) / h,
            1.0 - 4.0 * xi + 3.0 * xi2,
            (6.0 * xi - 6.0 * xi2) / h,
            3.0 * xi2 - 2.0 * xi,
        ]
    )


def _element_matrices(
    ei: float, rho: float, h: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Consistent stiffness and mass matrices of one Hermite beam element (N/m..., kg...)."""
    k = (ei / h**3) * np.array(
        [
            [12.0, 6.0 * h, -12.0, 6.0 * h],
            [6.0 * h, 4.0 * h * h, -6.0 * h, 2.0 * h * h],
            [-12.0, -6.0 * h, 12.0, -6.0 * h],
            [6.0 * h, 2.0 * h * h, -6.0 * h, 4.0 * h * h],
        ]
    )
    m = (rho * h / 420.0) * np.array(
        [
            [156.0, 22.0 * h, 54.0, -13.0 * h],
            [22.0 * h, 4.0 * h * h, 13.0 * h, -3.0 * h * h],
            [54.0, 13.0 * h, 156.0, -22.0 * h],
            [-13.0 * h, -3.0 * h * h, -22.0 * h, 4.0 * h * h],
        ]
    )
    return k, m


@dataclass(frozen=True)
class LinkModel:
    """Assembled finite-element matrices of the clamped link (one bending plane).

    Attributes
    ----------
    nodes : ndarray, shape (n_elements + 1,)
        Node abscissae x_i along the link (m), node 0 at the clamp.
    mass : ndarray, shape (n, n)
        Consistent mass matrix M (kg, kg m, kg m^2 blocks), n = 2 n_elements.
    stiffness : ndarray, shape (n, n)
        Stiffness matrix K (N/m, N, N m blocks).
    translation_load : ndarray, shape (n,)
        ``int rho N dx + m_t N(l)`` (kg): M times the rigid translation; the load of a uniform
        transverse acceleration of 1 m/s^2 and the weight of the deflection field.
    rotation_load : ndarray, shape (n,)
        ``int rho x N dx + m_t l N(l)`` (kg m): M times the rigid rotation about O.
    total_mass : float
        m_b + m_t (kg).
    first_moment : float
        ``int rho x dx + m_t l`` (kg m).
    second_moment : float
        ``int rho x^2 dx + m_t l^2``, the rigid link's inertia about O (kg m^2).
    root_dofs : int
        Degrees of freedom of node 0 removed by the clamp: 2 for a rigid clamp, 1 for a
        compliant clamp (the root slope stays free, against the clamp's spring, and is then the
        first coordinate: ``[v_0', v_1, v_1', ...]``).
    element_rigidity : ndarray, shape (n_elements,)
        E I of each element (N m^2), for the nonlinear link (``simulator.nonlinear_link``).
    element_density : ndarray, shape (n_elements,)
        rho of each element (kg/m).
    """

    nodes: NDArray[np.float64]
    mass: NDArray[np.float64]
    stiffness: NDArray[np.float64]
    translation_load: NDArray[np.float64]
    rotation_load: NDArray[np.float64]
    total_mass: float
    first_moment: float
    second_moment: float
    root_dofs: int = 2
    element_rigidity: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    element_density: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    @property
    def n_elements(self) -> int:
        """Number of elements."""
        return int(self.nodes.size - 1)

    @property
    def n_dof(self) -> int:
        """Degrees of freedom per bending plane (2 n_elements, or 2 n_elements + 1 with a
        compliant clamp)."""
        return int(self.mass.shape[0])

    @property
    def length(self) -> float:
        """Link length l (m)."""
        return float(self.nodes[-1])

    def shape_at(self, x: float) -> NDArray[np.float64]:
        """Row ``N(x)`` with ``v(x) = N(x) @ q`` for 0 <= x <= l, shape (n_dof,) (mixed units)."""
        return self._interpolation_row(x, slope=False)

    def slope_at(self, x: float) -> NDArray[np.float64]:
        """Row ``N'(x)`` with ``v'(x) = N'(x) @ q``, shape (n_dof,)."""
        return self._interpolation_row(x, slope=True)

    def _interpolation_row(self, x: float, slope: bool) -> NDArray[np.float64]:
        h = self.length / self.n_elements
        e = min(max(int(x / h), 0), self.n_elements - 1)
        xi = min(max((x - self.nodes[e]) / h, 0.0), 1.0)
        local = hermite_shape_slope(xi, h) if slope else hermite_shape(xi, h)
        row = np.zeros(self.n_dof + self.root_dofs)
        row[2 * e : 2 * e + 4] = local
        return row[self.root_dofs :]

    def free_frequencies(self, n_modes: int = 3) -> NDArray[np.float64]:
        """Natural frequencies of the clamped-free link (rad/s), ascending, shape (n_modes,)."""
        values = eigh(self.stiffness, self.mass, eigvals_only=True)
        return np.sqrt(np.clip(values[:n_modes], 0.0, None))

    def pinned_frequencies(self, x_c: float, n_modes: int = 3) -> NDArray[np.float64]:
        """Natural frequencies with the deflection pinned at x_c (rad/s), shape (n_modes,).

        The pin ``v(x_c) = 0`` is imposed exactly at the continuous abscissa x_c (not snapped to a
        node) by projecting onto the null space of the constraint row ``N(x_c)``: these are the
        contact-mode frequencies of Eq. 4 of the paper, computed independently of ``beam.py``.
        """
        row = self.shape_at(x_c)
        basis = _null_space_of_row(row)
        k = basis.T @ self.stiffness @ basis
        m = basis.T @ self.mass @ basis
        values = eigh(k, m, eigvals_only=True)
        return np.sqrt(np.clip(values[:n_modes], 0.0, None))


def _null_space_of_row(row: NDArray[np.float64]) -> NDArray[np.float64]:
    """Orthonormal basis (n, n-1) of the vectors orthogonal to ``row``."""
    _, _, vt = np.linalg.svd(row[np.newaxis, :])
    return np.asarray(vt[1:].T)


def build_link_model(
    link: Link, n_elements: int = 20, device: DeviceImperfections | None = None
) -> LinkModel:
    """Assemble the clamped-free finite-element model of ``link``.

    Parameters
    ----------
    link : Link
        Length, E I, rho and tip mass are used; a calibrated T_e is not read here (``simulate``
        passes a calibrated link as the E I that gives its T_e, ``run.device_link``).
    n_elements : int
        Number of equal Hermite elements (>= 2).
    device : DeviceImperfections, optional
        The device's departures from ``link``: its extra tip mass (added to the tip node), its
        clamp spring (on the root slope, which then stays a coordinate) and the factors of its
        taper and joint on each element's E I and rho (``DeviceImperfections.element_factors``).
        None or the nominal device: the uniform, rigidly clamped ``link``.

    Returns
    -------
    LinkModel
    """
    if n_elements < 2:
        raise ValueError(f"n_elements must be >= 2, got {n_elements}")
    length = link.length
    ei = link.flexural_rigidity
    rho = link.linear_density
    h = length / n_elements
    n_full = 2 * (n_elements + 1)
    k_full = np.zeros((n_full, n_full))
    m_full = np.zeros((n_full, n_full))
    nodes = np.linspace(0.0, length, n_elements + 1)
    tip_mass = link.tip_mass
    root_dofs = 2
    rigidity = np.full(n_elements, ei)
    density = np.full(n_elements, rho)
    if device is None or device.link_is_nominal:
        k_e, m_e = _element_matrices(ei, rho, h)
        for e in range(n_elements):
            sl = slice(2 * e, 2 * e + 4)
            k_full[sl, sl] += k_e
            m_full[sl, sl] += m_e
    else:
        if device.joint_length > 0.0 and device.joint_start >= length:
            raise DeviceError(
                "joint_start",
                f"{device.joint_start!r} m is not on the link (length {length:g} m)",
            )
        stiffness_factor, density_factor = device.element_factors(nodes)
        rigidity = ei * np.asarray(stiffness_factor, dtype=np.float64)
        density = rho * np.asarray(density_factor, dtype=np.float64)
        for e in range(n_elements):
            k_e, m_e = _element_matrices(
                ei * float(stiffness_factor[e]), rho * float(density_factor[e]), h
            )
            sl = slice(2 * e, 2 * e + 4)
            k_full[sl, sl] += k_e
            m_full[sl, sl] += m_e
        tip_mass += device.tip_mass
        if device.clamp_stiffness is not None:
            k_full[1, 1] += device.clamp_stiffness
            root_dofs = 1
    m_full[n_full - 2, n_full - 2] += tip_mass
    translation = np.zeros(n_full)
    translation[0::2] = 1.0
    rotation = np.zeros(n_full)
    rotation[0::2] = nodes
    rotation[1::2] = 1.0
    m_t = m_full @ translation
    m_r = m_full @ rotation
    free = slice(root_dofs, None)
    return LinkModel(
        nodes=nodes,
        mass=m_full[free, free].copy(),
        stiffness=k_full[free, free].copy(),
        translation_load=m_t[free].copy(),
        rotation_load=m_r[free].copy(),
        total_mass=float(translation @ m_t),
        first_moment=float(translation @ m_r),
        second_moment=float(rotation @ m_r),
        root_dofs=root_dofs,
        element_rigidity=rigidity,
        element_density=density,
    )


def rayleigh_coefficients(
    damping_ratio: float, omega_a: float, omega_b: float
) -> tuple[float, float]:
    """Rayleigh damping ``C = alpha M + beta K`` with ratio ``damping_ratio`` at two frequencies.

    The modal damping ratio is ``zeta(omega) = alpha / (2 omega) + beta omega / 2``; solving
    ``zeta(omega_a) = zeta(omega_b) = damping_ratio`` gives
    ``alpha = 2 zeta omega_a omega_b / (omega_a + omega_b)`` and
    ``beta = 2 zeta / (omega_a + omega_b)``.

    Parameters
    ----------
    damping_ratio : float
        Target zeta (dimensionless).
    omega_a, omega_b : float
        Reference angular frequencies (rad/s), both > 0.

    Returns
    -------
    (alpha, beta) : tuple of float
        Mass coefficient (1/s) and stiffness coefficient (s).
    """
    if not (omega_a > 0 and omega_b > 0):
        raise ValueError("reference frequencies must be > 0")
    if math.isclose(omega_a, omega_b):
        return 0.0, 2.0 * damping_ratio / omega_a
    total = omega_a + omega_b
    return 2.0 * damping_ratio * omega_a * omega_b / total, 2.0 * damping_ratio / total
