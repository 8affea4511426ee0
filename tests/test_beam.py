"""Tests of sensing_antenna.beam: frequency equation, roots, sensing curve, inverse, statics.

Reference values and their sources are named next to each tolerance. The independent
finite-element comparison lives in test_beam_fem.py.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sensing_antenna.antenna import Link, load_antenna
from sensing_antenna.beam import (
    BeamInputError,
    Candidate,
    SensingCurve,
    base_force,
    base_torque,
    characteristic_function,
    contact_deflection_from_force,
    eigenvalue_slopes,
    eigenvalues,
    mode_count,
    mode_shapes,
    natural_frequencies,
    static_deflection,
    torque_force_ratio,
)

PAPER = load_antenna("paper-2021").link
CALIBRATED = load_antenna("paper-2021-calibrated").link
#: Peak of omega_1(x_c) for R_m = 0, found by this package; used only to exclude the
#: ill-conditioned neighbourhood of the extremum from the x_c accuracy check.
PEAK_XI = 0.78344


@pytest.fixture(scope="module")
def curve() -> SensingCurve:
    return SensingCurve.from_link(CALIBRATED)


# ---------------------------------------------------------------- literature limits


def test_clamped_free_limit() -> None:
    """x_c -> 0 is a cantilever: beta l = 1.87510, 4.69409 (Blevins, Formulas for Natural
    Frequency and Mode Shape, Table 8-1, clamped-free). Tolerance 1e-5: table precision."""
    for xi in (0.0, 1e-12, 1e-9):
        np.testing.assert_allclose(eigenvalues(xi, 2), [1.87510, 4.69409], atol=1e-5)


def test_clamped_free_limit_is_approached_continuously() -> None:
    """beta_1 l(xi) tends to the cantilever value linearly (a stiff rotational root spring)."""
    small = eigenvalues(np.array([1e-6, 1e-5, 1e-4]), 1)[:, 0] - 1.8751040687
    assert np.all(small > 0)
    np.testing.assert_allclose(small[1:] / small[:-1], 10.0, rtol=1e-2)


def test_clamped_pinned_limit() -> None:
    """x_c = l is a clamped-pinned beam: beta l = 3.92660, 7.06858 (Blevins, Table 8-1,
    clamped-pinned). Tolerance 1e-5: table precision."""
    np.testing.assert_allclose(eigenvalues(1.0, 2), [3.92660, 7.06858], atol=1e-5)
    np.testing.assert_allclose(eigenvalues(1.0 - 1e-12, 2), [3.92660, 7.06858], atol=1e-5)


def test_tip_mass_does_not_act_when_contact_is_at_the_tip() -> None:
    """At x_c = l the tip mass sits on the pin: the clamped-pinned values (Blevins Table 8-1)."""
    np.testing.assert_allclose(eigenvalues(1.0, 2, 5.0), [3.92660, 7.06858], atol=1e-5)


def test_cantilever_with_tip_mass() -> None:
    """x_c -> 0, m_t / m_b = 1: (beta_i l)^2 = 1.557298, 16.25009, 50.89584 (Math. Probl. Eng.
    2017, 1568019, Table 1, column of zero rotary inertia, from the frequency equation
    1 + cos cosh + R lam (cos sinh - sin cosh) = 0). Tolerance 1e-6: six printed digits."""
    lam2 = eigenvalues(0.0, 3, 1.0) ** 2
    np.testing.assert_allclose(lam2, [1.557298, 16.25009, 50.89584], rtol=1e-6)


def test_heavy_tip_mass_limit() -> None:
    """x_c -> 0 and m_t >> m_b: the tip is effectively pinned, first root -> 3.92660 for mode 2
    and the fundamental -> (3 / R_m)^(1/4) (massless cantilever with a point mass, k = 3 E I/l^3).
    Tolerance 1e-3: O(1 / R_m) corrections at R_m = 1e4."""
    lam = eigenvalues(0.0, 2, 1e4)
    np.testing.assert_allclose(lam[0], (3.0 / 1e4) ** 0.25, rtol=1e-3)
    np.testing.assert_allclose(lam[1], 3.92660, rtol=1e-3)


def test_printed_eq6_fails_the_clamped_pinned_limit() -> None:
    """Why Eq. 6 is not used: at x_c = l it does not vanish at the clamped-pinned root."""
    b = 3.9266023120  # Blevins Table 8-1, clamped-pinned
    xc, length = 1.0, 1.0
    printed = (
        math.cosh(b * (length - xc))
        * (math.sin(b * xc) * math.cosh(b * xc) - math.sin(b * (length - xc)))
        + math.cos(b * (length - xc))
        * (math.sinh(b * (length - xc)) - math.sinh(b * xc) * math.cos(b * xc))
        + math.cos(b * xc) * (math.sin(b * xc) - math.cos(b * xc) * math.sinh(b * xc))
    )
    assert abs(printed) > 1.0
    assert abs(float(characteristic_function(b, 1.0))) < 1e-9


# ---------------------------------------------------------------- root counting


XI_CHECK = np.concatenate([[0.0, 1e-9, 1e-4], np.linspace(0.01, 0.99, 40), [1 - 1e-9, 1.0]])


@pytest.mark.parametrize("ratio", (0.0, 0.5))
def test_no_missed_or_duplicated_roots(ratio: float) -> None:
    """Strictly increasing roots, and the Wittrick-Williams count steps by one across each."""
    lam = eigenvalues(XI_CHECK, 6, ratio)
    assert np.all(np.diff(lam, axis=1) > 0)
    k = np.arange(1, 7)
    below = mode_count(lam * (1 - 1e-9), XI_CHECK[:, None], ratio)
    above = mode_count(lam * (1 + 1e-9), XI_CHECK[:, None], ratio)
    np.testing.assert_array_equal(below, np.broadcast_to(k - 1, lam.shape))
    np.testing.assert_array_equal(above, np.broadcast_to(k, lam.shape))


@pytest.mark.parametrize("ratio", (0.0, 2.0))
def test_count_matches_sign_changes_of_characteristic_function(ratio: float) -> None:
    """Independent check of the count: sign changes of the pole-free D on a fine grid.

    Grid step 2e-3 in beta l is far below the smallest gap between roots (>8 % of beta l).
    """
    grid = np.linspace(1e-3, 20.0, 10000)
    for xi in XI_CHECK:
        d = characteristic_function(grid, xi, ratio)
        changes = np.concatenate([[0], np.cumsum(np.sign(d[1:]) != np.sign(d[:-1]))])
        np.testing.assert_array_equal(mode_count(grid, xi, ratio), changes, err_msg=f"xi={xi}")


def test_roots_continuous_along_the_link() -> None:
    """On a fine grid each root moves by no more than its slope allows: no mode swaps."""
    xi = np.linspace(0.0, 1.0, 4001)
    lam = eigenvalues(xi, 3)
    slope = np.abs(eigenvalue_slopes(xi, lam))
    bound = 1.1 * np.maximum(slope[1:], slope[:-1]) * (xi[1] - xi[0]) + 1e-9
    assert np.all(np.abs(np.diff(lam, axis=0)) <= bound)


def test_slopes_match_finite_differences() -> None:
    """Implicit-differentiation slopes vs central differences of the roots (h = 1e-6).

    Tolerance 1e-6 relative to the largest slope: O(h^2) truncation plus root noise / h.
    """
    xi = np.array([0.05, 0.3, 0.6, 0.9, 0.999])
    h = 1e-6
    fd = (eigenvalues(xi + h, 3) - eigenvalues(xi - h, 3)) / (2 * h)
    slopes = eigenvalue_slopes(xi, eigenvalues(xi, 3))
    np.testing.assert_allclose(slopes, fd, atol=1e-6 * np.abs(fd).max())


def test_mode_shapes_satisfy_the_boundary_conditions() -> None:
    """phi(0) = 0 and phi(x_c) = 0 (Eq. 4); tolerance 1e-10 on shapes of size ~2."""
    shapes = mode_shapes(PAPER, 0.5, np.array([0.0, 0.5, 0.98]), 3)
    np.testing.assert_allclose(shapes[:2], 0.0, atol=1e-10)


# ---------------------------------------------------------------- scaling and units


@settings(max_examples=25, deadline=None)
@given(
    e_factor=st.floats(0.5, 5.0),
    rho_factor=st.floats(0.2, 2.0),
    l_factor=st.floats(0.2, 1.5),
    xi=st.floats(0.01, 1.0),
)
def test_frequencies_scale_with_sqrt_ei_over_rho_over_length_squared(
    e_factor: float, rho_factor: float, l_factor: float, xi: float
) -> None:
    """omega scales as sqrt(E I / rho) / l^2 at fixed x_c / l (tolerance 1e-12: same roots).

    The factors keep the link a physical one: its static sag, 6 % of its length for the paper's
    link, grows as rho l^3 / E, at most 13.5 times here, within the length (Link.static_sag).
    """
    other = dataclasses.replace(
        PAPER,
        youngs_modulus=PAPER.youngs_modulus * e_factor,
        linear_density=PAPER.linear_density * rho_factor,
        length=PAPER.length * l_factor,
    )
    base = natural_frequencies(PAPER, xi * PAPER.length, 3)
    scaled = natural_frequencies(other, min(xi * other.length, other.length), 3)
    factor = math.sqrt(e_factor / rho_factor) / l_factor**2
    np.testing.assert_allclose(scaled, base * factor, rtol=1e-12)


def test_natural_frequencies_shape_and_units() -> None:
    """Shape x_c.shape + (n_modes,); omega = (beta l)^2 / (T l^2)."""
    x_c = np.array([[0.3, 0.5], [0.7, 0.98]])
    omega = natural_frequencies(PAPER, x_c, 4)
    assert omega.shape == (2, 2, 4)
    lam = eigenvalues(x_c / PAPER.length, 4)
    np.testing.assert_allclose(omega, lam**2 / (PAPER.t_param * PAPER.length**2), rtol=1e-15)


def test_calibrated_t_replaces_theoretical_t() -> None:
    ratio = natural_frequencies(CALIBRATED, 0.5) / natural_frequencies(PAPER, 0.5)
    np.testing.assert_allclose(ratio, PAPER.theoretical_t / 0.2124, rtol=1e-12)


# ---------------------------------------------------------------- the paper's observations


def test_fundamental_range_matches_section_5_1(curve: SensingCurve) -> None:
    """Section 5.1 / Figure 10: with T_e = 0.2124 omega_1 spans [31.4, 106.8] rad/s for x_c in
    [0.3, 0.98] m. The model gives [29.77, 108.02]; tolerance 10 % (measured data, gravity,
    equivalent length)."""
    low, high = curve.omega1_range(0.3, 0.98)
    assert low == pytest.approx(31.4, rel=0.10)
    assert high == pytest.approx(106.8, rel=0.10)
    assert low == pytest.approx(float(curve.omega1(0.3)), rel=1e-12)  # lowest near the base


def test_fundamental_peaks_where_the_paper_sees_the_worst_errors(curve: SensingCurve) -> None:
    """Section 5 / Tables 3-4: worst errors near x_c = 0.75 to 0.80 m, where f1(x_c) peaks."""
    assert len(curve.extrema) == 1
    assert 0.75 <= curve.extrema[0] <= 0.80


def test_figure9_curve_passes_close_to_itself() -> None:
    """Section 4.3: the (f1, f2 - f1) curve's end x_c = 0.98 m is very close to x_c ~ 0.615 m.

    The nearest approach (excluding x_c > 0.9 m, the end's own neighbourhood) must be at
    0.615 +- 0.02 m and closer than 3 % of the curve's extent (computed: 0.46 Hz, 1.6 %).
    """
    x = np.linspace(0.98 / 4000, 0.98, 4000)
    hz = natural_frequencies(CALIBRATED, x, 2) / (2 * np.pi)
    points = np.stack([hz[:, 0], hz[:, 1] - hz[:, 0]], axis=1)
    distance = np.hypot(*(points - points[-1]).T)
    distance[x > 0.9] = np.inf
    nearest = int(np.argmin(distance))
    extent = float(np.hypot(*(points.max(axis=0) - points.min(axis=0))))
    assert x[nearest] == pytest.approx(0.615, abs=0.02)
    assert distance[nearest] < 0.03 * extent


# ---------------------------------------------------------------- sensing curve and inverse


def test_interpolated_curve_matches_exact_solver(curve: SensingCurve) -> None:
    """Hermite table vs the root solver at 500 random points: 1e-9 relative (measured 4e-12)."""
    x = np.random.default_rng(11).uniform(1e-3, CALIBRATED.length, 500)
    exact = natural_frequencies(CALIBRATED, x, 1)[:, 0]
    np.testing.assert_allclose(curve.omega1(x), exact, rtol=1e-9)


def test_slope_of_curve_matches_exact_solver(curve: SensingCurve) -> None:
    """omega1_slope vs central differences of the exact solver (h = 1e-6 m): 1e-5 relative."""
    x = np.array([0.1, 0.3, 0.6, 0.9, 0.97])
    h = 1e-6
    fd = natural_frequencies(CALIBRATED, x + h, 1) - natural_frequencies(CALIBRATED, x - h, 1)
    np.testing.assert_allclose(curve.omega1_slope(x), fd[:, 0] / (2 * h), rtol=1e-5)


@settings(max_examples=60, deadline=None)
@given(x_c=st.floats(0.005, 0.98))
def test_inverse_returns_the_true_contact_point(x_c: float) -> None:
    """The true x_c is among the candidates: 1e-6 l away from the peak; near the peak the
    inverse is ill-conditioned (x error ~ sqrt(omega error)) and 1e-4 l is allowed."""
    curve = _CURVE_FOR_HYPOTHESIS
    omega = float(natural_frequencies(CALIBRATED, x_c, 1)[0])
    candidates = curve.contact_points(omega)
    assert 1 <= len(candidates) <= 2
    error = min(abs(c.x_c - x_c) for c in candidates)
    near_peak = abs(x_c / CALIBRATED.length - PEAK_XI) < 1e-3
    assert error < (1e-4 if near_peak else 1e-6) * CALIBRATED.length


_CURVE_FOR_HYPOTHESIS = SensingCurve.from_link(CALIBRATED)


def test_two_candidates_below_the_peak_one_rising_one_falling(curve: SensingCurve) -> None:
    """Figure 8: a frequency between the tip value and the peak has two contact points."""
    candidates = curve.contact_points(80.0)
    assert len(candidates) == 2
    assert all(isinstance(c, Candidate) for c in candidates)
    assert candidates[0].x_c < curve.extrema[0] < candidates[1].x_c
    assert candidates[0].slope > 0 > candidates[1].slope
    for c in candidates:
        omega = float(natural_frequencies(CALIBRATED, c.x_c, 1)[0])
        assert omega == pytest.approx(80.0, rel=1e-9)


def test_single_candidate_and_out_of_range(curve: SensingCurve) -> None:
    """Below the tip value only the rising branch answers; outside the range nothing does."""
    tip = float(curve.omega1(CALIBRATED.length))
    assert len(curve.contact_points(0.5 * (tip + curve.omega1_range()[0]))) == 1
    low, high = curve.omega1_range()
    assert curve.contact_points(high * 1.001) == ()
    assert curve.contact_points(low) == ()  # x_c -> 0 is a limit, not a contact point
    assert curve.contact_points(-5.0) == ()
    peak = curve.contact_points(high)
    assert len(peak) == 1
    assert peak[0].x_c == pytest.approx(curve.extrema[0], abs=1e-12)


def test_tip_is_a_candidate_within_the_tolerance_below_its_frequency(
    curve: SensingCurve,
) -> None:
    """Pinned at the tip, a tip mass does not move: beta_1 l is the clamped-pinned 3.92660
    (Blevins, Table 8-1), omega_1(l) = 3.92660^2 / (T l^2). Just below it no point of the link
    has that frequency (the falling branch would need x_c > l); the tip is the candidate of
    that branch within the tolerance, and not beyond it."""
    link = CALIBRATED
    tip = 3.92660**2 / (link.t_param * link.length**2)
    assert float(curve.omega1(link.length)) == pytest.approx(tip, rel=1e-5)
    below = tip - 0.05
    assert len(curve.contact_points(below)) == 1
    found = curve.contact_points(below, tolerance=0.1)
    assert len(found) == 2 and found[1].x_c == link.length
    assert found[1].slope == pytest.approx(float(curve.omega1_slope(link.length)), rel=1e-12)
    assert len(curve.contact_points(below, tolerance=0.04)) == 1
    # above the tip's frequency the falling branch answers by itself, the tolerance adds nothing
    assert curve.contact_points(tip + 0.05, 0.1) == curve.contact_points(tip + 0.05)
    with pytest.raises(BeamInputError, match="tolerance"):
        curve.contact_points(below, tolerance=-1.0)


def test_vectorised_inverse_agrees_with_scalar(curve: SensingCurve) -> None:
    omega = np.random.default_rng(5).uniform(10.0, 115.0, (4, 25))
    inv = curve.invert(omega)
    assert inv.x_c.shape == (4, 25, 2)
    for idx in np.ndindex(omega.shape):
        expected = curve.contact_points(float(omega[idx]))
        found = inv.x_c[idx][~np.isnan(inv.x_c[idx])]
        slopes = inv.slope[idx][~np.isnan(inv.slope[idx])]
        assert inv.count[idx] == len(expected)
        np.testing.assert_allclose(np.sort(found), [c.x_c for c in expected], rtol=1e-13)
        np.testing.assert_allclose(
            slopes[np.argsort(found)], [c.slope for c in expected], rtol=1e-10
        )


def test_range_contains_sampled_frequencies(curve: SensingCurve) -> None:
    low, high = curve.omega1_range(0.2, 0.9)
    omega = curve.omega1(np.linspace(0.2, 0.9, 3001))
    assert low == pytest.approx(omega.min(), rel=1e-12)
    assert high == pytest.approx(omega.max(), rel=1e-6)  # the grid misses the exact peak


def test_tip_mass_link_inverse() -> None:
    """With a tip payload (R_m = 0.2) the inverse still returns the true contact point."""
    link = dataclasses.replace(PAPER, tip_mass=0.2 * PAPER.mass)
    curve = SensingCurve.from_link(link, n_points=801)
    for x_c in (0.1, 0.4, 0.7, 0.95):
        omega = float(natural_frequencies(link, x_c, 1)[0])
        error = min(abs(c.x_c - x_c) for c in curve.contact_points(omega))
        assert error < 1e-6 * link.length


# ---------------------------------------------------------------- statics (Eqs. 7-13)


def test_static_deflection_boundary_conditions() -> None:
    """Eq. 8: y(0) = y'(0) = 0, y(x_c) = y_c, y'' = 0 on [x_c, l] (checked by differences)."""
    x_c, y_c, h = 0.4, 0.01, 1e-4
    y = lambda x: static_deflection(x, x_c, y_c)  # noqa: E731
    assert float(y(0.0)) == 0.0
    assert float(y(h)) == pytest.approx(1.5 * y_c * (h / x_c) ** 2, rel=1e-3)  # y'(0) = 0
    assert float(y(x_c)) == pytest.approx(y_c, rel=1e-15)
    left = (float(y(x_c)) - float(y(x_c - h))) / h
    right = (float(y(x_c + h)) - float(y(x_c))) / h
    assert left == pytest.approx(right, rel=1e-3)  # continuous slope
    second = float(y(0.8)) - 2 * float(y(0.7)) + float(y(0.6))
    assert abs(second) < 1e-15  # straight beyond the contact


def test_base_force_is_the_cantilever_point_load_formula() -> None:
    """A cantilever loaded at x_c deflects y_c = F x_c^3 / (3 E I) there (Gere and Timoshenko,
    Mechanics of Materials, cantilever with end load) and the root moment is F x_c."""
    force = base_force(PAPER, 0.3, 0.005)
    assert float(force) == pytest.approx(3 * PAPER.flexural_rigidity * 0.005 / 0.3**3, rel=1e-14)
    torque = base_torque(PAPER, 0.3, 0.005)
    assert float(torque) == pytest.approx(float(force) * 0.3, rel=1e-14)
    # The README's numbers: 0.8 N bends the link about 8 cm at x_c = 0.3 m.
    assert float(contact_deflection_from_force(PAPER, 0.3, 0.8)) == pytest.approx(0.08, rel=0.01)


@settings(max_examples=50, deadline=None)
@given(x_c=st.floats(0.01, 0.98), y_c=st.floats(-0.05, 0.05).filter(lambda v: abs(v) > 1e-9))
def test_torque_force_ratio_is_contact_point(x_c: float, y_c: float) -> None:
    """Eq. 18: |Gamma| / |F| = x_c (exact algebra; tolerance 1e-13 for rounding)."""
    assert float(torque_force_ratio(PAPER, x_c, y_c)) == pytest.approx(x_c, rel=1e-13)
    force = base_force(PAPER, x_c, y_c)
    back = contact_deflection_from_force(PAPER, x_c, force)
    assert float(back) == pytest.approx(abs(y_c), rel=1e-13)


def test_statics_vectorised() -> None:
    x_c = np.array([0.3, 0.6, 0.9])
    y_c = np.array([[0.01], [0.02]])
    assert base_force(PAPER, x_c, y_c).shape == (2, 3)
    assert static_deflection(np.linspace(0, 0.98, 7)[:, None], x_c, 0.01).shape == (7, 3)


# ---------------------------------------------------------------- bad input


@pytest.mark.parametrize("x_c", [0.0, -0.1, 0.99, float("nan")])
def test_contact_point_outside_link_is_rejected(x_c: float) -> None:
    with pytest.raises(BeamInputError, match="x_c"):
        natural_frequencies(PAPER, x_c)


def test_bad_mode_count_and_ratio_are_rejected() -> None:
    with pytest.raises(BeamInputError, match="n_modes"):
        eigenvalues(0.5, 0)
    with pytest.raises(BeamInputError, match="tip_mass_ratio"):
        eigenvalues(0.5, 2, -1.0)
    with pytest.raises(BeamInputError, match="xi"):
        eigenvalues(1.5)
    with pytest.raises(BeamInputError, match="omega1"):
        SensingCurve.from_link(PAPER, n_points=11).contact_points(float("nan"))
    with pytest.raises(BeamInputError, match="force"):
        contact_deflection_from_force(PAPER, 0.5, -1.0)


def test_error_is_a_sensing_antenna_error() -> None:
    from sensing_antenna.errors import SensingAntennaError

    assert issubclass(BeamInputError, SensingAntennaError)


def test_link_is_not_mutated() -> None:
    before = dataclasses.asdict(PAPER)
    SensingCurve.from_link(PAPER, n_points=101)
    assert dataclasses.asdict(PAPER) == before
    assert isinstance(PAPER, Link)


@pytest.mark.parametrize(
    ("x_c", "expected"),
    [(0.30, -1.411), (0.55, -1.923), (0.75, -0.213), (0.90, 0.637), (0.95, 0.681), (0.98, 0.687)],
)
def test_contact_to_base_shear_matches_an_independent_solution(x_c: float, expected: float) -> None:
    # Reference: the exact two-span Euler-Bernoulli solution (6 x 6 determinant of clamped,
    # pin and free-end conditions, solved separately from this package) for the paper link
    # (l = 0.98 m, no tip mass), printed to 3 decimals, hence the 1e-3 tolerance. The same
    # quantity is checked against finite-element constraint forces over the whole link in
    # tests/test_beam_fem.py (test_contact_to_base_shear_matches_finite_element_reactions).
    # At x_c = l the link is clamped-pinned and the whole shear at the pin is the contact force.
    from sensing_antenna.antenna import paper_antenna
    from sensing_antenna.beam.modes import contact_to_base_shear

    assert contact_to_base_shear(paper_antenna().link, x_c) == pytest.approx(expected, abs=1e-3)


def test_the_tip_is_no_candidate_above_the_top_of_a_curve_that_falls_little() -> None:
    """A heavy tip (half the link's mass) flattens the falling branch: its top lies a few
    rad/s above the tip's frequency. A frequency above the top is off the curve, not at the
    tip, however wide the tolerance: the tip answers only on the side the branch cannot reach."""
    link = dataclasses.replace(PAPER, tip_mass=0.5 * PAPER.mass)
    heavy = SensingCurve.from_link(link)
    top = heavy.omega1_range()[1]
    tip = float(heavy.omega1(link.length))
    assert 0.0 < top - tip < 10.0
    assert heavy.contact_points(1.04 * top, tolerance=20.0) == ()
    assert heavy.contact_points(tip - 0.5, tolerance=1.0)[-1].x_c == link.length
