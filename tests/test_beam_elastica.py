"""Tests of sensing_antenna.beam.elastica: the large-deflection statics of the pushed link.

References: the tabulated tip-load elastica of Bisshopp and Drucker (Quart. Appl. Math. 3, 1945,
Table 1: P L^2 / (E I) = 1, 2, 3, 5), the closed form of the same problem with elliptic integrals,
and, for loads with an axial part, an independent boundary-value solution computed here (scipy
solve_ivp on the cantilever of given length, its base moment found by brentq).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate, optimize

from sensing_antenna.beam.elastica import (
    contact_arc,
    contact_from_wrench,
    loaded_end,
    shoot_contact,
    tip_load_cantilever,
)

#: E I of the paper's link (N m^2); the problem scales with it.
RIGIDITY = 0.0903


def cantilever_end(length: float, axial: float, perpendicular: float) -> tuple[float, float, float]:
    """End (x, y) and base moment M_0 of a cantilever of ``length`` under the end load
    (axial, perpendicular): the base moment for which the bending moment vanishes at the end
    (a boundary-value problem, solved by shooting with brentq)."""

    def end_state(moment: float) -> np.ndarray:
        def rhs(_s: float, y: np.ndarray) -> list[float]:
            bending = moment - (y[0] * perpendicular - y[1] * axial)
            return [math.cos(y[2]), math.sin(y[2]), bending / RIGIDITY]

        sol = integrate.solve_ivp(rhs, (0.0, length), [0.0, 0.0, 0.0], rtol=1e-12, atol=1e-14)
        return np.asarray(sol.y[:, -1])

    def residual(moment: float) -> float:
        x, y, _ = end_state(moment)
        return moment - (x * perpendicular - y * axial)

    moment = optimize.brentq(residual, 1e-9, 3.0 * length * perpendicular, xtol=1e-15)
    x, y, _ = end_state(moment)
    return float(x), float(y), float(moment)


@pytest.mark.parametrize(
    ("load", "x", "y", "slope_deg"),
    [
        # Bisshopp and Drucker (1945), Table 1: horizontal (1 - Delta_h / L) and vertical
        # (Delta_v / L) tip displacement and tip slope; tabulated to 4 to 5 digits
        (1.0, 0.94357, 0.30172, 26.4),
        (2.0, 0.83936, 0.49346, 44.8),
        (3.0, 0.74558, 0.60325, 56.5),
        (5.0, 0.61237, 0.71379, 69.6),
    ],
)
def test_tip_load_closed_form_is_the_tabulated_elastica(
    load: float, x: float, y: float, slope_deg: float
) -> None:
    solution = tip_load_cantilever(load)
    assert solution.x == pytest.approx(x, abs=1e-5)
    assert solution.y == pytest.approx(y, abs=1e-5)
    assert math.degrees(solution.slope) == pytest.approx(slope_deg, abs=0.1)


def test_tip_load_closed_form_has_the_small_deflection_limit() -> None:
    # Linear beam: y / L = alpha / 3; the first correction is O(alpha^3)
    solution = tip_load_cantilever(1e-3)
    assert solution.y == pytest.approx(1e-3 / 3.0, rel=1e-5)


@pytest.mark.parametrize("load", [0.05, 0.5, 1.0, 2.0, 3.0])
def test_shooting_from_the_base_wrench_finds_the_loaded_end(load: float) -> None:
    # A cantilever of length L under a tip load P across it: the base moment is P x_tip; the
    # shooting must put the contact at s = L and at the closed form's position
    length = 0.6
    force = load * RIGIDITY / length**2
    solution = tip_load_cantilever(load)
    contact = shoot_contact(force * solution.x * length, 0.0, force, RIGIDITY)
    assert contact.arc == pytest.approx(length, rel=1e-9)
    assert contact.x == pytest.approx(solution.x * length, rel=1e-9)
    assert contact.y == pytest.approx(solution.y * length, rel=1e-8)
    assert contact.slope == pytest.approx(solution.slope, rel=1e-8)


#: Loads of pushes up to about 45 % deflection: alpha = R_perp s_c^2 / (E I) to 1.5, the
#: reaction's axial part from the contact normal's tilt with the link's slope (down to
#: -tan 40 deg) and friction (mu 0.6 either way).
CASES = [
    (length, alpha, beta)
    for length in (0.3, 0.98)
    for alpha in (0.01, 0.3, 0.9, 1.5)
    for beta in (-1.2, -0.5, 0.0, 0.6)
]


@pytest.mark.parametrize(("length", "alpha", "beta"), CASES)
def test_the_table_inverts_the_base_wrench_of_an_independent_solution(
    length: float, alpha: float, beta: float
) -> None:
    perpendicular = alpha * RIGIDITY / length**2
    axial = beta * perpendicular
    x, y, moment = cantilever_end(length, axial, perpendicular)
    exact = shoot_contact(moment, axial, perpendicular, RIGIDITY)
    assert exact.arc == pytest.approx(length, rel=1e-8)
    assert exact.x == pytest.approx(x, rel=1e-8)
    # The bilinear table: within 1e-3 of the arc length (0.3 mm at 0.3 m, 1 mm at the tip)
    arc, tx, ty, slope = contact_from_wrench(moment, axial, perpendicular, RIGIDITY)
    assert float(arc) == pytest.approx(length, rel=1e-3)
    assert float(tx) == pytest.approx(x, abs=1e-3 * length)
    assert float(ty) == pytest.approx(y, abs=1e-3 * length)
    assert float(slope) == pytest.approx(exact.slope, abs=1e-3)
    one = contact_arc(np.array([moment]), np.array([axial]), np.array([perpendicular]), RIGIDITY)
    assert float(one[0]) == pytest.approx(float(arc), rel=1e-12)
    end = loaded_end(length, axial, perpendicular, RIGIDITY)
    assert end.x == pytest.approx(x, abs=1e-3 * length)
    assert end.y == pytest.approx(y, abs=1e-3 * length)


def test_small_deflection_limit_is_the_linear_statics() -> None:
    # x_c = (M_0 + y_c R_x) / R_perp, y_c = R_perp x_c^3 / (3 E I) (Eq. 13): the elastica's
    # arc length agrees to O(q^2) with q = R_perp m^2 / (E I), m = M_0 / R_perp
    m = 0.5
    for q in (1e-3, 1e-2):
        for beta in (-0.8, 0.0, 0.5):
            perpendicular = q * RIGIDITY / m**2
            axial = beta * perpendicular
            arc = shoot_contact(m * perpendicular, axial, perpendicular, RIGIDITY).arc
            linear = m
            for _ in range(20):
                linear = m + beta * perpendicular * linear**3 / (3.0 * RIGIDITY)
            assert abs(arc - linear) <= 0.2 * q**2 * m
            assert abs(arc - m) >= 0.3 * abs(beta) * q * m  # the first-order term is there


def test_a_stream_and_a_block_give_the_same_bits() -> None:
    rng = np.random.default_rng(5)
    n = 300
    moment = rng.uniform(-0.01, 0.1, n)
    axial = rng.uniform(-0.1, 0.05, n)
    perpendicular = rng.uniform(0.0, 0.3, n)
    perpendicular[:4] = 0.0
    block = contact_arc(moment, axial, perpendicular, RIGIDITY)
    stream = np.concatenate(
        [
            contact_arc(moment[k : k + 1], axial[k : k + 1], perpendicular[k : k + 1], RIGIDITY)
            for k in range(n)
        ]
    )
    np.testing.assert_array_equal(block, stream)
    assert np.isnan(block[:4]).all()
