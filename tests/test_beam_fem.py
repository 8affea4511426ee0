"""Independent finite-element reference for the contact-mode beam (tests beam.characteristic/modes).

The FE model shares no code with the package: Euler-Bernoulli beam elements with cubic Hermite
shape functions, consistent mass matrices, a node placed exactly at the contact point whose
deflection is constrained to zero (the pin of Eq. 4), the base node clamped, and the tip mass as a
point mass on the tip deflection. The generalised eigenproblem K v = Lambda M v is solved with
``scipy.linalg.eigh``; in non-dimensional units (E I = rho = l = 1) Lambda = (beta l)^4.

Mesh choice. Hermite elements with consistent mass converge as O((beta h)^4) in Lambda, with a
small constant (about 1/720 for a single element). The third mode has beta l <= 10.3 on the whole
link, so with element length h <= 1/100, (beta h)^4 <= 1.2e-4 and the error in beta l is about
1e-4 / 720 / 4 ~ 4e-8, far below the 1e-4 the comparison needs. ``test_fe_mesh_converged`` checks
it by halving h. The eigenproblem is solved for 1 / Lambda (K on the positive-definite side) so
that rounding does not grow with the largest mesh eigenvalue (~1e12 at this h).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eigh

from sensing_antenna.antenna import Link
from sensing_antenna.beam import eigenvalues, mode_shapes
from sensing_antenna.beam.modes import support_compliance_coefficients

ELEMENT_LENGTH = 1.0 / 100.0


def _element_matrices(h: float) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness and consistent mass of one Hermite beam element, DOFs (w1, t1, w2, t2)."""
    k = (
        np.array(
            [
                [12.0, 6 * h, -12.0, 6 * h],
                [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                [-12.0, -6 * h, 12.0, -6 * h],
                [6 * h, 2 * h * h, -6 * h, 4 * h * h],
            ]
        )
        / h**3
    )
    m = (
        np.array(
            [
                [156.0, 22 * h, 54.0, -13 * h],
                [22 * h, 4 * h * h, 13 * h, -3 * h * h],
                [54.0, 13 * h, 156.0, -22 * h],
                [-13 * h, -3 * h * h, -22 * h, 4 * h * h],
            ]
        )
        * h
        / 420.0
    )
    return k, m


def _mesh(xi: float, h_max: float) -> tuple[np.ndarray, int]:
    """Node positions with one node exactly at xi; returns (nodes, index of the contact node)."""
    n1 = max(1, math.ceil(xi / h_max))
    left = np.linspace(0.0, xi, n1 + 1)
    if xi >= 1.0:
        return left, n1
    n2 = max(1, math.ceil((1.0 - xi) / h_max))
    right = np.linspace(xi, 1.0, n2 + 1)
    return np.concatenate([left, right[1:]]), n1


def _fe_modes(
    xi: float, ratio: float, n_modes: int, h_max: float
) -> tuple[np.ndarray, np.ndarray, int, np.ndarray, np.ndarray, np.ndarray]:
    """Lambda_i, nodes, contact node, every DOF of the mass-normalised modes, K and M (global)."""
    nodes, contact = _mesh(xi, h_max)
    n_dof = 2 * nodes.size
    big_k = np.zeros((n_dof, n_dof))
    big_m = np.zeros((n_dof, n_dof))
    for e in range(nodes.size - 1):
        k, m = _element_matrices(nodes[e + 1] - nodes[e])
        dofs = slice(2 * e, 2 * e + 4)
        big_k[dofs, dofs] += k
        big_m[dofs, dofs] += m
    big_m[n_dof - 2, n_dof - 2] += ratio  # tip mass m_t / (rho l) on the tip deflection
    fixed = {0, 1, 2 * contact}  # clamp at the base, pin (zero deflection) at the contact
    free = np.array([d for d in range(n_dof) if d not in fixed])
    # Solved as M v = (1 / Lambda) K v for the largest 1 / Lambda: K is the positive-definite
    # side, so rounding is relative to the lowest modes instead of to the highest (1e12 here).
    k_free, m_free = big_k[np.ix_(free, free)], big_m[np.ix_(free, free)]
    inverse, vectors = eigh(m_free, k_free, subset_by_index=[free.size - n_modes, free.size - 1])
    order = np.argsort(inverse)[::-1]
    values = 1.0 / inverse[order]
    vectors = vectors[:, order]
    vectors /= np.sqrt(np.einsum("im,ij,jm->m", vectors, m_free, vectors))  # v^T M v = 1
    full = np.zeros((n_dof, n_modes))
    full[free] = vectors
    return values, nodes, contact, full, big_k, big_m


def fe_solve(
    xi: float, ratio: float, n_modes: int, h_max: float = ELEMENT_LENGTH
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """FE eigenvalues beta_i l, node positions and mass-normalised deflections (nodes x modes)."""
    values, nodes, _, full, _, _ = _fe_modes(xi, ratio, n_modes, h_max)
    return values**0.25, nodes, full[0::2]


def fe_contact_to_base_shear(xi: float, ratio: float, h_max: float = ELEMENT_LENGTH) -> float:
    """Pin reaction over base shear in the first mode, from the FE constraint forces.

    (K - Lambda M) v is zero at the free DOFs and, at a constrained DOF, the force the support
    applies to the beam: the base deflection DOF carries the base shear, the contact node's
    deflection DOF the contact force.
    """
    values, _, contact, full, big_k, big_m = _fe_modes(xi, ratio, 1, h_max)
    forces = (big_k - values[0] * big_m) @ full[:, 0]
    return float(forces[2 * contact] / forces[0])


def _link(ratio: float) -> Link:
    """A link with rho = l = 1, so that its tip mass is R_m, as in the FE model.

    The shapes and the shear ratio compared here are non-dimensional (functions of xi and R_m
    only), so E I is free: 10 N m^2 on a 1 cm radius keeps the link a physical one (slender, a
    bulk density of 3183 kg/m^3, a static sag of 0.45 m at R_m = 1).
    """
    radius = 0.01
    return Link(
        length=1.0,
        radius=radius,
        youngs_modulus=10.0 / (math.pi * radius**4 / 4.0),
        linear_density=1.0,
        tip_mass=ratio,
    )


XI_GRID = (0.05, 0.2, 0.3, 0.5, 0.615, 0.75, 0.7834, 0.9, 0.99, 1.0)
RATIOS = (0.0, 0.3, 1.0)


def test_fe_mesh_converged() -> None:
    """The FE error at the chosen mesh is ~4e-8 and the method converges as O(h^4).

    Halving h changes beta_i l by < 1e-7 relative. The third mode (the one with the largest
    discretisation error) shows the h^4 rate: successive differences shrink by ~16 (8 to 32
    allowed for higher-order terms); the lower modes are already near the rounding floor.
    """
    for xi in (0.05, 0.75, 1.0):
        h4, h2, h1, h0 = (fe_solve(xi, 0.3, 3, f * ELEMENT_LENGTH)[0] for f in (4, 2, 1, 0.5))
        assert np.all(np.abs(h1 - h0) / h0 < 1e-7)
        rate = (h4[2] - h2[2]) / (h2[2] - h1[2])
        assert 8.0 < rate < 32.0, rate


@pytest.mark.parametrize("ratio", RATIOS)
def test_eigenvalues_match_finite_elements(ratio: float) -> None:
    """First three beta_i l agree with the FE model to 2e-7 relative (FE error <= 4e-8, above).

    Frequencies go as (beta l)^2, so this is 4e-7 on omega, well inside the 1e-3 required.
    """
    exact = eigenvalues(np.array(XI_GRID), 3, ratio)
    for row, xi in zip(exact, XI_GRID, strict=True):
        fe = fe_solve(xi, ratio, 3)[0]
        np.testing.assert_allclose(row, fe, rtol=2e-7, err_msg=f"xi={xi}, R_m={ratio}")


@pytest.mark.parametrize("ratio", (0.0, 1.0))
@pytest.mark.parametrize("xi", (0.05, 0.3, 0.7834, 1.0))
def test_mode_shapes_match_finite_elements(xi: float, ratio: float) -> None:
    """Mass-normalised mode shapes agree with FE eigenvectors (M-normalised) at the nodes.

    Tolerance 1e-6 absolute on shapes of magnitude ~2: the FE nodal values converge like the
    eigenvalues (O(h^4), ~1e-8 here), and both use the same normalisation
    (int phi^2 + R_m phi(1)^2 = 1).
    """
    _, nodes, shapes_fe = fe_solve(xi, ratio, 3)
    shapes = mode_shapes(_link(ratio), xi, nodes, 3)
    for i in range(3):
        fe = shapes_fe[:, i]
        fe = fe * np.sign(fe[np.argmax(np.abs(fe))])  # the package's sign convention
        np.testing.assert_allclose(shapes[:, i], fe, atol=1e-6, err_msg=f"mode {i + 1}")


@pytest.mark.parametrize("ratio", RATIOS)
def test_contact_to_base_shear_matches_finite_element_reactions(ratio: float) -> None:
    """contact_to_base_shear against the FE constraint forces, to 1e-6 absolute.

    Halving h moves the FE ratio by less than 1e-7 (checked below at two points; 1.5e-8 at
    worst over the grid), so 1e-6 is ten times the FE error; the ratios are of order 1 and
    cross zero between xi = 0.75 and 0.9, hence an absolute tolerance.
    """
    from sensing_antenna.beam import contact_to_base_shear

    values = contact_to_base_shear(_link(ratio), np.array(XI_GRID))
    assert values.shape == (len(XI_GRID),)
    for xi, value in zip(XI_GRID, values, strict=True):
        fe = fe_contact_to_base_shear(xi, ratio)
        assert value == pytest.approx(fe, abs=1e-6), f"xi={xi}"
    for xi in (0.3, 1.0):
        fine = fe_contact_to_base_shear(xi, ratio, ELEMENT_LENGTH / 2)
        assert abs(fine - fe_contact_to_base_shear(xi, ratio)) < 1e-7


def _chord_vector(nodes: np.ndarray, contact: int) -> np.ndarray:
    """g over every DOF: the chord from O to the contact changes by -d g.v for a vibration v of
    the link pushed to w_0 = d (3 xi s^2 - s^3) / (2 xi^2), g = integral_0^xi (w_0' / d) w' ds,
    by 4-point Gauss-Legendre on each element's Hermite derivatives (exact: a cubic times a
    quadratic)."""
    xi = nodes[contact]
    points, weights = np.polynomial.legendre.leggauss(4)
    g = np.zeros(2 * nodes.size)
    for e in range(contact):
        h = nodes[e + 1] - nodes[e]
        u = 0.5 * (points + 1.0)  # fraction of the element
        s = nodes[e] + h * u
        slope = (6.0 * xi * s - 3.0 * s**2) / (2.0 * xi**2)
        derivative = np.stack(
            [
                (-6.0 * u + 6.0 * u**2) / h,
                1.0 - 4.0 * u + 3.0 * u**2,
                (6.0 * u - 6.0 * u**2) / h,
                -2.0 * u + 3.0 * u**2,
            ]
        )
        g[2 * e : 2 * e + 4] += 0.5 * h * derivative @ (weights * slope)
    return g


def fe_held_rise(xi: float, ratio: float, target: float) -> tuple[float, float]:
    """The first mode's rise (omega / omega_0 - 1) when an axial spring resists the chord's
    change (E I = rho = l = 1, d = 1), stiff enough for Rayleigh's quotient to put the rise at
    ``target``, and the base's axial force over its bending moment in the mode with that hold,
    r (the support's moment at the clamp's rotation DOF)."""
    values, nodes, contact, full, big_k, big_m = _fe_modes(xi, ratio, 1, ELEMENT_LENGTH)
    g = _chord_vector(nodes, contact)
    hold = 2.0 * target * values[0] / float(g @ full[:, 0]) ** 2
    n_dof = 2 * nodes.size
    free = np.array([d for d in range(n_dof) if d not in {0, 1, 2 * contact}])
    held_k = big_k + hold * np.outer(g, g)
    inverse, vector = eigh(
        big_m[np.ix_(free, free)], held_k[np.ix_(free, free)], subset_by_index=[free.size - 1] * 2
    )
    mode = np.zeros(n_dof)
    mode[free] = vector[:, 0]
    lam = 1.0 / float(inverse[0])
    moment = float(((big_k - lam * big_m) @ mode)[1])
    return math.sqrt(lam / values[0]) - 1.0, hold * float(g @ mode) / moment


def fe_held_coupling(xi: float, ratio: float) -> float:
    """kappa from the FE's own first mode, unheld (E I = rho = l = 1): the clamp's support
    moment times the chord's change g.v, over Lambda = omega_1^2 (modal mass 1)."""
    values, nodes, contact, full, big_k, big_m = _fe_modes(xi, ratio, 1, ELEMENT_LENGTH)
    moment = float(((big_k - values[0] * big_m) @ full[:, 0])[1])
    return moment * float(_chord_vector(nodes, contact) @ full[:, 0]) / float(values[0])


@pytest.mark.parametrize("ratio", (0.0, 0.3))
@pytest.mark.parametrize("xi", (0.2, 0.3, 0.5, 0.7, 0.85, 1.0))
def test_held_contact_coupling_matches_finite_elements(xi: float, ratio: float) -> None:
    """held_contact_coupling against the FE link, and Rayleigh's rise against a hold.

    kappa itself: the FE's support moment at the clamp and its chord's change, from Hermite
    derivatives without the integration by parts, agree to 1e-5 (the FE's error in shapes and
    moments at this mesh is about 1e-7 to 1e-6). A soft hold of the chord (a rise of 1e-3) rises by
    r kappa / 2 (per unit d) within 5e-2 (the estimate's own first-order error: 4e-2 at xi = 0.2,
    2e-2 or less from 0.4 on), and a soft spring of the other sign falls by as much. Stiffer, the
    mode reshapes; wherever the rise stays under 60 % (which a push plane's peak inside the paper
    link's band cannot exceed) the estimate from the r of the reshaped mode is at least the rise."""
    from sensing_antenna.beam import held_contact_coupling

    kappa = float(held_contact_coupling(_link(ratio), xi))
    # of the opposite sign: the FE's moment is the support's on the link, kappa's the link's on
    # the base, as the sensor reads it (so is r's there, and a hold's r kappa stays positive)
    assert kappa == pytest.approx(-fe_held_coupling(xi, ratio), rel=1e-5)
    rise, r = fe_held_rise(xi, ratio, 1e-3)
    assert 0.5 * abs(r * kappa) == pytest.approx(rise, rel=5e-2)
    # Rayleigh's quotient signed, in the FE's own convention: an axial force in phase the other
    # way (a softening spring, as the link's axial inertia or slipping friction make) lowers
    # omega_1 as much as a hold raises it
    fall, r_soft = fe_held_rise(xi, ratio, -1e-3)
    assert fall < 0.0
    assert 0.5 * r_soft * fe_held_coupling(xi, ratio) == pytest.approx(fall, rel=5e-2)
    assert 0.5 * r * fe_held_coupling(xi, ratio) == pytest.approx(rise, rel=5e-2)
    for target in (1e-2, 1e-1, 3e-1, 1.0, 1e3):
        stiff_rise, stiff_r = fe_held_rise(xi, ratio, target)
        if stiff_rise < 0.6:
            assert 0.5 * abs(stiff_r * kappa) >= 0.99 * stiff_rise, target


def test_held_contact_coupling_scales_with_the_link_alone() -> None:
    """kappa is a length: at the same xi and tip-mass ratio it scales with l, and E I and rho
    leave it (omega_1^2 m_b = E I (beta_1 l)^4 / l^3). The longer link: l = 2 m, E I = 700 N m^2,
    rho = 3 kg/m, a tip mass of 0.3 of the link's."""
    from sensing_antenna.beam import held_contact_coupling

    base = _link(0.3)
    longer = Link(
        length=2.0,
        radius=0.02,
        youngs_modulus=700.0 / (math.pi * 0.02**4 / 4.0),
        linear_density=3.0,
        tip_mass=0.3 * 3.0 * 2.0,
    )
    for xi in (0.3, 0.7, 1.0):
        assert float(held_contact_coupling(longer, 2.0 * xi)) == pytest.approx(
            2.0 * float(held_contact_coupling(base, xi)), rel=1e-9
        )


@pytest.mark.parametrize("ratio", RATIOS)
def test_support_compliance_coefficients_match_finite_element_reactions(ratio: float) -> None:
    # A pin relaxed into a spring of stiffness k lowers Lambda_i = (beta_i l)^4 by R_i^2 / k at
    # first order (Rayleigh), R_i the FE constraint force at the contact in the mass-normalised
    # mode i; in the link's units omega_i falls by the fraction c_i / k with
    # c_i = (E I / l^3) R_i^2 / (2 Lambda_i), here E I = 10 N m^2 and l = 1 m.
    link = _link(ratio)
    # one call over the grid (shape (points, modes)), each row against its own FE model
    every = support_compliance_coefficients(link, np.array(XI_GRID), 2)
    assert every.shape == (len(XI_GRID), 2)
    for xi, got in zip(XI_GRID, every, strict=True):
        values, _, contact, full, big_k, big_m = _fe_modes(xi, ratio, 2, ELEMENT_LENGTH)
        expected = []
        for i in range(2):
            reaction = float(((big_k - values[i] * big_m) @ full[:, i])[2 * contact])
            expected.append(10.0 * reaction**2 / (2.0 * values[i]))
        # 1e-3 of the larger coefficient: the mesh's h = 1/100 leaves 1e-4 in the shear jump
        # (its third derivatives are the least converged), and a node of mode 2's shear
        # (xi = 0.5 without a tip mass) makes c_2 vanish
        scale = max(expected)
        assert got == pytest.approx(expected, abs=1e-3 * scale), (xi, ratio)
