"""Large deflection of the pushed link: the planar elastica.

The link is an inextensible, unshearable Euler-Bernoulli rod clamped at the base O along X^m and
loaded only at the contact, at arc length s_c, by the reaction R of the object (weight is handled
apart, as a free link's, by the callers). In the bending plane (x along X^m, y along R_perp, the
part of R across the link) let r(s) = (x(s), y(s)) and theta(s) the tangent's angle. The moment
that the part of the link beyond s exerts on the part before it, about r(s), is

    M(s) = M_0 - (r(s) x R) = M_0 - (x(s) R_perp - y(s) R_x)        (0 <= s <= s_c),

with M_0 = Gamma' . v the moment of R about O that the sensor measures (v = X^m x u, u the unit
vector of R_perp). The rod's law is E I theta'(s) = M(s), with x' = cos theta, y' = sin theta and
r(0) = 0, theta(0) = 0. Beyond the contact nothing loads the link and a point contact carries no
moment, so the contact is the first s where M(s) = 0. Integrating from the base is therefore an
initial-value problem whose terminal event is M = 0 (:func:`shoot_contact`): it gives s_c and the
contact's position for any deflection. With m = M_0 / R_perp (Eq. 21 with |R_perp|),
q = R_perp m^2 / (E I) and beta = R_x / R_perp the problem scaled by m depends on (q, beta)
only: s_c = m Sigma(q, beta). As q -> 0, Sigma = 1 + beta q / 3 + O(q^2), the small-deflection
statics of :func:`sensing_antenna.estimation.front.ratio.perpendicular_ratio`'s fixed point
(x_c = (M_0 + y_c R_x) / R_perp, y_c = R_perp x_c^3 / (3 E I), Eq. 13); the next term,
q^2 / 15 at beta = 0, is the shortening of the bent link along X^m.

:class:`ElasticaTable` tabulates Sigma and the contact's position over (q, beta) once, from the
same initial-value problem integrated on the whole grid at once (classical Runge-Kutta), so that a
stream of samples is inverted by a bilinear look-up (:func:`contact_from_wrench`) and the end of a
cantilever of given length under a given end load is found by a one-dimensional search on it
(:func:`loaded_end`). :func:`tip_load_cantilever` is the classical closed form of a cantilever
under a tip load across it (elliptic integrals), the independent check of both.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "ElasticaContact",
    "ElasticaTable",
    "TipLoadSolution",
    "contact_arc",
    "contact_from_wrench",
    "elastica_table",
    "loaded_end",
    "shoot_contact",
    "tip_load_cantilever",
    "tip_load_for_deflection",
]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class TipLoadSolution:
    """Cantilever of length L under a dead load P across its undeformed axis at its free end.

    Attributes
    ----------
    load : float
        alpha = P L^2 / (E I) (dimensionless).
    x, y : float
        The loaded end's position along and across the undeformed axis over L.
    slope : float
        The end's slope angle theta_0 (rad).
    """

    load: float
    x: float
    y: float
    slope: float


def tip_load_cantilever(load: float) -> TipLoadSolution:
    """The closed-form elastica of a cantilever under a tip load across it (Bisshopp and
    Drucker, Quart. Appl. Math. 3, 1945).

    With E I theta'' = -P cos theta, theta(0) = 0 and theta'(L) = 0 (end slope theta_0), the first
    integral is theta'^2 = 2 (P / E I)(sin theta_0 - sin theta). The substitution
    1 + sin theta = 2 k^2 sin^2 phi, k^2 = (1 + sin theta_0) / 2, maps theta = 0 to
    sin phi_1 = 1 / (k sqrt 2) and theta_0 to phi = pi / 2, and gives

        sqrt(alpha) = K(k) - F(phi_1, k),
        x / L = 2 k cos(phi_1) / sqrt(alpha),
        y / L = 1 - 2 (E(k) - E(phi_1, k)) / sqrt(alpha),

    F, E the incomplete elliptic integrals of the first and second kind (scipy.special
    ``ellipkinc``, ``ellipeinc``, parameter m = k^2); theta_0 is found from the first line.

    Parameters
    ----------
    load : float
        alpha = P L^2 / (E I) >= 0.
    """
    from scipy import optimize, special  # only here: the estimators never need it

    if not (math.isfinite(load) and load >= 0.0):
        raise ValueError(f"load must be finite and >= 0, got {load!r}")
    if load == 0.0:
        return TipLoadSolution(0.0, 1.0, 0.0, 0.0)

    def residual(theta0: float) -> float:
        m = 0.5 * (1.0 + math.sin(theta0))
        phi1 = math.asin(min(1.0, 1.0 / math.sqrt(2.0 * m)))
        return float(special.ellipk(m) - special.ellipkinc(phi1, m)) - math.sqrt(load)

    theta0 = optimize.brentq(residual, 1e-12, 0.5 * math.pi - 1e-9, xtol=1e-15, rtol=1e-15)
    m = 0.5 * (1.0 + math.sin(theta0))
    phi1 = math.asin(min(1.0, 1.0 / math.sqrt(2.0 * m)))
    root = math.sqrt(load)
    x = 2.0 * math.sqrt(m) * math.cos(phi1) / root
    y = 1.0 - 2.0 * float(special.ellipe(m) - special.ellipeinc(phi1, m)) / root
    return TipLoadSolution(load=load, x=x, y=y, slope=theta0)


def tip_load_for_deflection(deflection: float) -> TipLoadSolution:
    """The tip-loaded cantilever whose end moves ``deflection`` = y / L across the axis.

    The displacement-controlled push (0, or 1e-6 to 0.9: below, the elliptic integrals' difference
    loses its digits): ``load`` is then the alpha it takes, against linear theory's
    ``3 deflection``.
    """
    from scipy import optimize  # only here: the estimators never need it

    if not (deflection == 0.0 or 1e-6 <= deflection <= 0.9):
        raise ValueError(f"deflection must be 0 or in [1e-6, 0.9], got {deflection!r}")
    if deflection == 0.0:
        return tip_load_cantilever(0.0)
    # the elastica needs more load than linear theory for the same deflection: 3 deflection
    # brackets the root from below
    alpha = optimize.brentq(
        lambda a: tip_load_cantilever(a).y - deflection, 3.0 * deflection, 100.0, xtol=1e-14
    )
    return tip_load_cantilever(alpha)


@dataclass(frozen=True)
class ElasticaContact:
    """The contact the base wrench puts on the elastica.

    Attributes
    ----------
    arc : float
        s_c, the contact's arc length from the base (m); NaN when M never vanishes.
    x, y : float
        The contact's position along X^m and along R_perp (m).
    slope : float
        The link's tangent angle at the contact from X^m, towards R_perp (rad).
    """

    arc: float
    x: float
    y: float
    slope: float


def shoot_contact(
    moment: float,
    axial: float,
    perpendicular: float,
    flexural_rigidity: float,
    max_arc: float | None = None,
) -> ElasticaContact:
    """The contact from the base wrench by shooting the elastica from the base (module notes).

    scipy.integrate.solve_ivp (DOP853, tolerances 1e-12) integrates E I theta' = M(s) with the
    terminal event M(s) = 0.

    Parameters
    ----------
    moment : float
        M_0 = Gamma' . v, the reaction's moment about O in the bending plane (N m), > 0.
    axial, perpendicular : float
        R_x along X^m and |R_perp| > 0 across it (N).
    flexural_rigidity : float
        E I (N m^2).
    max_arc : float, optional
        How far to integrate (m); 3 M_0 / R_perp when None.
    """
    from scipy import integrate  # only here: the estimators use the table

    if not (perpendicular > 0.0 and moment > 0.0 and flexural_rigidity > 0.0):
        return ElasticaContact(math.nan, math.nan, math.nan, math.nan)
    end = 3.0 * moment / perpendicular if max_arc is None else max_arc

    def bending(y: FloatArray) -> float:
        return moment - (y[0] * perpendicular - y[1] * axial)

    def rhs(_s: float, y: FloatArray) -> list[float]:
        return [math.cos(y[2]), math.sin(y[2]), bending(y) / flexural_rigidity]

    def event(_s: float, y: FloatArray) -> float:
        return bending(y)

    event.terminal = True  # type: ignore[attr-defined]
    event.direction = -1.0  # type: ignore[attr-defined]
    sol = integrate.solve_ivp(
        rhs, (0.0, end), [0.0, 0.0, 0.0], method="DOP853", events=event, rtol=1e-12, atol=1e-14
    )
    if not sol.t_events[0].size:
        return ElasticaContact(math.nan, math.nan, math.nan, math.nan)
    state = sol.y_events[0][0]
    return ElasticaContact(
        float(sol.t_events[0][0]), float(state[0]), float(state[1]), float(state[2])
    )


#: Range of q = R_perp m^2 / (E I) the table covers: up to 4, enough for a contact deflected by
#: 45 % of its abscissa (alpha = R_perp s_c^2 / (E I) = 1.5) under a reaction tilted back by
#: 50 deg (q = alpha (x - beta y)^2 / s_c^2 = 2.9 at beta = -1.2).
Q_MAX = 4.0
#: Range of beta = R_x / R_perp: the reaction's axial part, from the contact normal's tilt with
#: the link's slope (-tan 32 deg = -0.6 at a 45 % deflection) and friction (mu up to 1) either way.
BETA_RANGE = (-2.0, 1.0)
#: Grid steps of q and beta; bilinear interpolation on them is exact in the first-order term
#: beta q / 3 and within 1e-5 relative elsewhere (tested against :func:`shoot_contact`).
Q_STEP = 0.02
BETA_STEP = 0.05
#: Arc-length step of the Runge-Kutta integration, in units of m (global error ~1e-9, far
#: below the interpolation's).
_DS = 0.016
#: Largest scaled arc length integrated: beyond it M has not vanished (the link curls), NaN.
_MAX_ARC = 2.0


@dataclass(frozen=True, eq=False)
class ElasticaTable:
    """Sigma(q, beta) = s_c / m and the contact's position (x_c / m, y_c / m) and slope, on a
    regular grid (NaN where M never vanishes before s = 2 m, scaled).

    Attributes
    ----------
    q, beta : array, shape (nq,), (nb,)
        Grid axes.
    arc, x, y, slope : array, shape (nq, nb)
        s_c / m, x_c / m, y_c / m and the slope at the contact (rad).
    """

    q: FloatArray
    beta: FloatArray
    arc: FloatArray
    x: FloatArray
    y: FloatArray
    slope: FloatArray

    @functools.cached_property
    def arc_flat(self) -> FloatArray:
        """``arc`` flattened (row-major), for :func:`contact_arc`."""
        return np.ascontiguousarray(self.arc).ravel()

    @functools.cached_property
    def last_valid(self) -> list[int]:
        """For each beta column, the last q index before the first NaN of ``arc``."""
        valid = np.isfinite(self.arc)
        first_bad = np.where(valid.all(axis=0), valid.shape[0], np.argmin(valid, axis=0))
        return [int(v) - 1 for v in first_bad]

    @functools.cached_property
    def arc_list(self) -> list[float]:
        """``arc_flat`` as Python floats, for the scalar path of :func:`contact_arc`."""
        return [float(v) for v in self.arc_flat]

    def lookup(self, q: FloatArray, beta: FloatArray) -> tuple[FloatArray, ...]:
        """Bilinear values of (arc, x, y, slope) at (q, beta), NaN outside the grid."""
        fq = q / Q_STEP
        fb = (beta - BETA_RANGE[0]) / BETA_STEP
        nq, nb = self.arc.shape
        inside = (fq >= 0.0) & (fq <= nq - 1) & (fb >= 0.0) & (fb <= nb - 1)
        fq = np.where(inside, fq, 0.0)
        fb = np.where(inside, fb, 0.0)
        i = np.minimum(fq.astype(np.intp), nq - 2)
        j = np.minimum(fb.astype(np.intp), nb - 2)
        a = fq - i
        b = fb - j
        out = []
        for table in (self.arc, self.x, self.y, self.slope):
            value = (1.0 - a) * ((1.0 - b) * table[i, j] + b * table[i, j + 1]) + a * (
                (1.0 - b) * table[i + 1, j] + b * table[i + 1, j + 1]
            )
            out.append(np.where(inside, value, np.nan))
        return tuple(out)


@functools.lru_cache(maxsize=1)
def elastica_table() -> ElasticaTable:
    """The :class:`ElasticaTable`, built once per process (about 0.3 s on one core).

    Scaled by m and E I = 1: x' = cos theta, y' = sin theta, theta' = q (1 - x + beta y), from
    zero, integrated on every grid point at once by classical Runge-Kutta with step 0.016; the
    crossing of M = 1 - x + beta y through zero is placed by the cubic through M and
    M' = -(cos theta - beta sin theta) at the ends of its step, the state there by the same
    cubic (Hermite) on x, y and theta.
    """
    q = np.arange(0.0, Q_MAX + 0.5 * Q_STEP, Q_STEP)
    beta = np.arange(BETA_RANGE[0], BETA_RANGE[1] + 0.5 * BETA_STEP, BETA_STEP)
    qq, bb = (grid.ravel() for grid in np.meshgrid(q, beta, indexing="ij"))
    result = np.full((4, qq.size), np.nan)
    result[:, qq == 0.0] = np.array([[1.0], [1.0], [0.0], [0.0]])
    # Only the grid points still integrating (not crossed yet) are carried from step to step
    active = np.flatnonzero(qq > 0.0)
    state = np.zeros((3, active.size))
    h = _DS
    arc = 0.0
    qa, ba = qq[active], bb[active]
    d_prev = _rates(state, qa, ba)
    m_prev = 1.0 - state[0] + ba * state[1]
    while arc < _MAX_ARC and active.size:
        k1 = d_prev
        k2 = _rates(state + 0.5 * h * k1, qa, ba)
        k3 = _rates(state + 0.5 * h * k2, qa, ba)
        k4 = _rates(state + h * k3, qa, ba)
        new = state + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        d_new = _rates(new, qa, ba)
        m_new = 1.0 - new[0] + ba * new[1]
        cross = m_new <= 0.0
        if cross.any():
            c = cross
            # Hermite cubic of M over the step, its root by Newton steps from the secant
            dm0 = -(d_prev[0, c] - ba[c] * d_prev[1, c]) * h
            dm1 = -(d_new[0, c] - ba[c] * d_new[1, c]) * h
            t = m_prev[c] / (m_prev[c] - m_new[c])
            for _ in range(8):
                value, slope = _hermite(m_prev[c], m_new[c], dm0, dm1, t)
                t = np.clip(t - value / np.where(slope != 0.0, slope, 1.0), 0.0, 1.0)
            where = active[c]
            result[0, where] = arc + t * h
            for row in range(3):
                value, _ = _hermite(
                    state[row, c], new[row, c], d_prev[row, c] * h, d_new[row, c] * h, t
                )
                result[row + 1, where] = value
            keep = ~cross
            active, qa, ba = active[keep], qa[keep], ba[keep]
            new, d_new, m_new = new[:, keep], d_new[:, keep], m_new[keep]
        state, d_prev, m_prev = new, d_new, m_new
        arc += h
    shape = (q.size, beta.size)
    arcs, xs, ys, slopes = (row.reshape(shape) for row in result)
    return ElasticaTable(q=q, beta=beta, arc=arcs, x=xs, y=ys, slope=slopes)


def _rates(state: FloatArray, q: FloatArray, beta: FloatArray) -> FloatArray:
    """(x', y', theta') of the scaled elastica."""
    x, y, theta = state
    return np.stack([np.cos(theta), np.sin(theta), q * (1.0 - x + beta * y)])


def _hermite(
    p0: FloatArray, p1: FloatArray, d0: FloatArray, d1: FloatArray, t: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Cubic Hermite value and derivative (per unit t) at t in [0, 1]."""
    t2, t3 = t * t, t * t * t
    value = (
        (2 * t3 - 3 * t2 + 1) * p0
        + (t3 - 2 * t2 + t) * d0
        + (-2 * t3 + 3 * t2) * p1
        + (t3 - t2) * d1
    )
    slope = (
        (6 * t2 - 6 * t) * p0
        + (3 * t2 - 4 * t + 1) * d0
        + (-6 * t2 + 6 * t) * p1
        + (3 * t2 - 2 * t) * d1
    )
    return value, slope


def contact_from_wrench(
    moment: ArrayLike, axial: ArrayLike, perpendicular: ArrayLike, flexural_rigidity: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """The contact from the base wrench, by the :class:`ElasticaTable` (vectorised).

    Parameters
    ----------
    moment, axial, perpendicular : array_like, broadcast together
        M_0 = Gamma' . v (N m), R_x (N) and |R_perp| (N), as in :func:`shoot_contact`.
    flexural_rigidity : float
        E I (N m^2).

    Returns
    -------
    arc, x, y, slope : arrays
        s_c (m), the contact's position along X^m and R_perp (m) and the slope there (rad); NaN
        where the loads leave the table (q > Q_MAX, beta outside BETA_RANGE, M_0 <= 0 or
        R_perp <= 0).
    """
    moment_a, axial_a, perp_a = np.broadcast_arrays(
        np.asarray(moment, dtype=float),
        np.asarray(axial, dtype=float),
        np.asarray(perpendicular, dtype=float),
    )
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        m = moment_a / perp_a
        q = perp_a * m * m / flexural_rigidity
        beta = axial_a / perp_a
    usable = (perp_a > 0.0) & (m > 0.0) & np.isfinite(q) & np.isfinite(beta)
    arc, x, y, slope = elastica_table().lookup(
        np.where(usable, q, -1.0), np.where(usable, beta, 0.0)
    )
    return arc * m, x * m, y * m, slope


def loaded_end(
    arc: float, axial: float, perpendicular: float, flexural_rigidity: float
) -> ElasticaContact:
    """The end of a cantilever of length ``arc`` (m) under a dead end load (R_x, R_perp) (N).

    The end load's problem scaled by the end's own m: alpha = R_perp s_c^2 / (E I) =
    q Sigma(q, beta)^2, increasing in q; q is found on the table by bisection and the end's
    position is m (x, y) of the table. NaN where the table does not reach.
    """
    nan = ElasticaContact(math.nan, math.nan, math.nan, math.nan)
    if not (arc > 0.0 and perpendicular >= 0.0 and flexural_rigidity > 0.0):
        return nan
    if perpendicular == 0.0:
        return ElasticaContact(arc, arc, 0.0, 0.0)
    alpha = perpendicular * arc * arc / flexural_rigidity
    beta = axial / perpendicular
    table = elastica_table()
    nb = table.arc.shape[1]
    fb = (beta - BETA_RANGE[0]) / BETA_STEP
    if not 0.0 <= fb <= nb - 1:
        return nan
    j = min(int(fb), nb - 2)
    # alpha = q Sigma^2 rises with q up to where the table ends for this beta
    # (less one: the bilinear weights reach the next row, NaN past it)
    top = min(table.last_valid[j], table.last_valid[j + 1]) - 1
    if top < 1:
        return nan
    flat = table.arc_list

    def alpha_of(fq: float) -> float:
        sigma = _bilinear(flat, nb, fq, fb)
        return fq * Q_STEP * sigma * sigma

    low, high = 0.0, float(top)
    if not alpha_of(high) >= alpha:
        return nan
    for _ in range(40):
        mid = 0.5 * (low + high)
        if alpha_of(mid) < alpha:
            low = mid
        else:
            high = mid
    q = 0.5 * (low + high) * Q_STEP
    sigma, x, y, slope = (float(v[0]) for v in table.lookup(np.array([q]), np.array([beta])))
    m = arc / sigma
    return ElasticaContact(arc, x * m, y * m, slope)


def _bilinear(flat: list[float], nb: int, fq: float, fb: float) -> float:
    """Bilinear value of a row-major table (columns nb) at fractional indices (fq, fb)."""
    i = int(fq)
    j = int(fb)
    if i >= (len(flat) // nb) - 1:
        i -= 1
    if j >= nb - 1:
        j -= 1
    a = fq - i
    b = fb - j
    k = i * nb + j
    low = flat[k] + b * (flat[k + 1] - flat[k])
    high = flat[k + nb] + b * (flat[k + nb + 1] - flat[k + nb])
    return low + a * (high - low)


def contact_arc(
    moment: FloatArray, axial: FloatArray, perpendicular: FloatArray, flexural_rigidity: float
) -> FloatArray:
    """s_c (m) alone from the base wrench, as :func:`contact_from_wrench` gives it, with the
    fewest operations: a stream calls it one sample at a time, so a few samples go through
    plain floats (the same operations in the same order, hence the same bits) and more through
    arrays. Arrays of one shape (n,); NaN where the loads leave the table."""
    table = elastica_table()
    if moment.shape[0] <= _SCALAR_SAMPLES:
        return np.array(
            [
                _arc_of(g, r_x, r_p, flexural_rigidity, table)
                for g, r_x, r_p in zip(
                    moment.tolist(), axial.tolist(), perpendicular.tolist(), strict=True
                )
            ],
            dtype=float,
        )
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        m = moment / perpendicular
        fq = perpendicular * m * m / flexural_rigidity / Q_STEP
        fb = (axial / perpendicular - BETA_RANGE[0]) / BETA_STEP
    nq, nb = table.arc.shape
    inside = (fq >= 0.0) & (fq <= nq - 1) & (fb >= 0.0) & (fb <= nb - 1) & (m > 0.0)
    fq = np.where(inside, fq, 0.0)
    fb = np.where(inside, fb, 0.0)
    i = np.minimum(fq.astype(np.intp), nq - 2)
    j = np.minimum(fb.astype(np.intp), nb - 2)
    a = fq - i
    b = fb - j
    k = i * nb + j
    flat = table.arc_flat
    low = flat[k] + b * (flat[k + 1] - flat[k])
    high = flat[k + nb] + b * (flat[k + nb + 1] - flat[k + nb])
    return np.where(inside, (low + a * (high - low)) * m, np.nan)


#: Up to this many samples :func:`contact_arc` works on plain floats.
_SCALAR_SAMPLES = 8


def _arc_of(
    moment: float, axial: float, perpendicular: float, rigidity: float, table: ElasticaTable
) -> float:
    """One sample of :func:`contact_arc`, in plain floats."""
    if not perpendicular > 0.0:
        return math.nan
    m = moment / perpendicular
    fq = perpendicular * m * m / rigidity / Q_STEP
    fb = (axial / perpendicular - BETA_RANGE[0]) / BETA_STEP
    nq, nb = table.arc.shape
    if not (0.0 <= fq <= nq - 1 and 0.0 <= fb <= nb - 1 and m > 0.0):
        return math.nan
    i = min(int(fq), nq - 2)
    j = min(int(fb), nb - 2)
    a = fq - i
    b = fb - j
    k = i * nb + j
    flat = table.arc_list
    low = flat[k] + b * (flat[k + 1] - flat[k])
    high = flat[k + nb] + b * (flat[k + nb + 1] - flat[k + nb])
    return (low + a * (high - low)) * m
