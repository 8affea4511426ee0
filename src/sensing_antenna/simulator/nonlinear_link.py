"""The link's geometrically exact bending: an inextensible rod described by its deflections.

The finite-element coordinates of :mod:`~sensing_antenna.simulator.link` (Hermite deflections
``v``, ``w`` and slopes at the nodes) are read as functions of the arc length s, not of the
abscissa along X^m: the material point s of an inextensible, unshearable link sits at

    r(s) = (s - u(s)) X^m + v(s) Y^m + w(s) Z^m,   u(s) = int_0^s (1 - c) ds,
    c = sqrt(1 - v'^2 - w'^2)

(|r'| = 1 exactly: c is the cosine of the tangent's angle to X^m, u the axial shortening). Its
bending energy is the exact one of a Kirchhoff rod of circular section,

    U = int E I |r''|^2 / 2 ds = int E I (v''^2 + w''^2 + beta^2 / c^2) / 2 ds,
    beta = v' v'' + w' w''

whose first two terms are the linear model's ``q^T K q / 2``; the third, of relative size
v'^2 / c^2, is what the linear model drops. A planar cantilever under a tip load then follows
the elastica exactly up to the discretisation (the tangent angle phi has v' = sin phi, c = cos
phi, curvature v'' / cos phi). Twist is not a coordinate: a rod of circular section under no
twisting moment does not twist. Valid while the tangent stays within 90 degrees of X^m (c > 0).

Axial motion. The shortening u moves the link's mass along X^m: with the mass lumped at the nodes
(m_i, tip mass included), its inertia and the axial component g_x of gravity add the generalised
force ``sum_i m_i (u_i'' + g_x) G_i``, ``G_i = d u(x_i) / d q = int_0^{x_i} v' N' / c ds``
(Lagrange's equations for the point masses at s_i - u_i).

The functions here are compiled (numba) for the time loop of
:mod:`~sensing_antenna.simulator.integrator`; :func:`static_equilibrium` and
:func:`link_position` are their Python face, for the initial sag and for tests.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.compiler import njit
from sensing_antenna.simulator.link import LinkModel

__all__ = [
    "MIN_AXIAL_COSINE",
    "add_shortening_gradient",
    "link_forces",
    "link_position",
    "node_masses",
    "shortening_at",
    "static_equilibrium",
]

#: The tangent's cosine to X^m is floored here (the angle is then 89.9 degrees): beyond it the
#: description by deflections fails, and the floor only keeps a diverging step finite.
MIN_AXIAL_COSINE = 1e-3

# 5-point Gauss-Legendre on [0, 1]
_GAUSS_X = np.array(
    [
        0.5 - 0.5 * 0.9061798459386640,
        0.5 - 0.5 * 0.5384693101056831,
        0.5,
        0.5 + 0.5 * 0.5384693101056831,
        0.5 + 0.5 * 0.9061798459386640,
    ]
)
_GAUSS_W = 0.5 * np.array(
    [
        0.2369268850561891,
        0.4786286704993665,
        0.5688888888888889,
        0.4786286704993665,
        0.2369268850561891,
    ]
)

# 3-point Gauss-Legendre on [0, 1], for the shortening within an element (the contact search
# evaluates it a hundred times per step): 1 - c with v' quadratic is integrated to 1e-12 m
_GAUSS3_X = np.array([0.5 - 0.5 * math.sqrt(0.6), 0.5, 0.5 + 0.5 * math.sqrt(0.6)])
_GAUSS3_W = np.array([5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0])


@njit(cache=True)
def _hermite_derivatives(
    xi: float, h: float, d1: NDArray[np.float64], d2: NDArray[np.float64]
) -> None:
    """First and second derivatives d/ds of the Hermite shape functions at xi in [0, 1]."""
    xi2 = xi * xi
    d1[0] = (-6.0 * xi + 6.0 * xi2) / h
    d1[1] = 1.0 - 4.0 * xi + 3.0 * xi2
    d1[2] = (6.0 * xi - 6.0 * xi2) / h
    d1[3] = 3.0 * xi2 - 2.0 * xi
    d2[0] = (-6.0 + 12.0 * xi) / (h * h)
    d2[1] = (-4.0 + 6.0 * xi) / h
    d2[2] = (6.0 - 12.0 * xi) / (h * h)
    d2[3] = (6.0 * xi - 2.0) / h


@njit(cache=True)
def _dof(e: int, j: int, drop: int) -> int:
    """Index in a plane's coordinates of local dof j of element e (-1: removed by the clamp)."""
    return 2 * e + j - drop


@njit(cache=True)
def _plane_derivatives(
    q: NDArray[np.float64], e: int, drop: int, d1: NDArray[np.float64], d2: NDArray[np.float64]
) -> tuple[float, float]:
    first = 0.0
    second = 0.0
    for j in range(4):
        idx = _dof(e, j, drop)
        if idx >= 0:
            first += d1[j] * q[idx]
            second += d2[j] * q[idx]
    return first, second


@njit(cache=True)
def link_forces(
    X: NDArray[np.float64],
    V: NDArray[np.float64],
    A: NDArray[np.float64],
    n: int,
    n_el: int,
    h_el: float,
    rigidity: NDArray[np.float64],
    node_mass: NDArray[np.float64],
    axial_gravity: float,
    dynamic: bool,
    out: NDArray[np.float64],
    axial: NDArray[np.float64],
) -> None:
    """Generalised forces the linear model lacks, for the plane coordinates X[0:2n].

    ``out`` (2 n) receives ``dU/dq - K q`` (the bending energy's nonlinear part) plus
    ``sum_i m_i (u_i'' + g_x) G_i`` (axial inertia, only when ``dynamic``, and axial gravity
    ``axial_gravity`` = g_x, m/s^2). ``axial`` (n_el + 1, 2) receives u_i and u_i'' at the nodes
    (m, m/s^2). X, V, A: coordinates, rates and accelerations (only X when not ``dynamic``).
    """
    drop = 2 * n_el + 2 - n
    d1 = np.empty(4)
    d2 = np.empty(4)
    gvec = np.zeros((n_el, 8))
    du = np.zeros(n_el)
    dacc = np.zeros(n_el)
    for i in range(2 * n):
        out[i] = 0.0
    for e in range(n_el):
        ei = rigidity[e]
        for k in range(5):
            _hermite_derivatives(_GAUSS_X[k], h_el, d1, d2)
            wt = _GAUSS_W[k] * h_el
            v1, v2 = _plane_derivatives(X[0:n], e, drop, d1, d2)
            w1, w2 = _plane_derivatives(X[n : 2 * n], e, drop, d1, d2)
            cc = 1.0 - v1 * v1 - w1 * w1
            if cc < MIN_AXIAL_COSINE * MIN_AXIAL_COSINE:
                cc = MIN_AXIAL_COSINE * MIN_AXIAL_COSINE
            c = math.sqrt(cc)
            beta = v1 * v2 + w1 * w2
            # d/dv' and d/dv'' of E I beta^2 / (2 c^2), c^2 = 1 - v'^2 - w'^2
            fv1 = ei * (beta * v2 / cc + beta * beta * v1 / (cc * cc))
            fv2 = ei * beta * v1 / cc
            fw1 = ei * (beta * w2 / cc + beta * beta * w1 / (cc * cc))
            fw2 = ei * beta * w1 / cc
            for j in range(4):
                idx = _dof(e, j, drop)
                if idx >= 0:
                    out[idx] += wt * (fv1 * d1[j] + fv2 * d2[j])
                    out[n + idx] += wt * (fw1 * d1[j] + fw2 * d2[j])
                gvec[e, j] += wt * v1 * d1[j] / c
                gvec[e, 4 + j] += wt * w1 * d1[j] / c
            du[e] += wt * (1.0 - c)
            if dynamic:
                vd1, _ = _plane_derivatives(V[0:n], e, drop, d1, d2)
                wd1, _ = _plane_derivatives(V[n : 2 * n], e, drop, d1, d2)
                va1, _ = _plane_derivatives(A[0:n], e, drop, d1, d2)
                wa1, _ = _plane_derivatives(A[n : 2 * n], e, drop, d1, d2)
                # u' = 1 - c: (u')^.. = Pdot / c + P^2 / c^3, P = v' v'^. + w' w'^.
                p = v1 * vd1 + w1 * wd1
                pdot = vd1 * vd1 + v1 * va1 + wd1 * wd1 + w1 * wa1
                dacc[e] += wt * (pdot / c + p * p / (cc * c))
    axial[0, 0] = 0.0
    axial[0, 1] = 0.0
    for e in range(n_el):
        axial[e + 1, 0] = axial[e, 0] + du[e]
        axial[e + 1, 1] = axial[e, 1] + dacc[e]
    # sum over the nodes beyond element e of m_i (u_i'' + g_x), times the element's G increment
    load = 0.0
    for e in range(n_el - 1, -1, -1):
        acc = axial[e + 1, 1] if dynamic else 0.0
        load += node_mass[e + 1] * (acc + axial_gravity)
        for j in range(4):
            idx = _dof(e, j, drop)
            if idx >= 0:
                out[idx] += load * gvec[e, j]
                out[n + idx] += load * gvec[e, 4 + j]


@njit(cache=True)
def shortening_at(
    x: float,
    X: NDArray[np.float64],
    n: int,
    n_el: int,
    h_el: float,
    axial: NDArray[np.float64],
) -> float:
    """u(x) (m): the nodal value of ``axial`` (from :func:`link_forces` at the same X) plus the
    integral of 1 - c from the element's first node to x (3-point Gauss)."""
    drop = 2 * n_el + 2 - n
    e = int(x / h_el)
    if e < 0:
        e = 0
    if e > n_el - 1:
        e = n_el - 1
    xi_end = (x - e * h_el) / h_el
    if xi_end < 0.0:
        xi_end = 0.0
    if xi_end > 1.0:
        xi_end = 1.0
    d1 = np.empty(4)
    d2 = np.empty(4)
    total = axial[e, 0]
    for k in range(3):
        xi = _GAUSS3_X[k] * xi_end
        _hermite_derivatives(xi, h_el, d1, d2)
        v1, _ = _plane_derivatives(X[0:n], e, drop, d1, d2)
        w1, _ = _plane_derivatives(X[n : 2 * n], e, drop, d1, d2)
        cc = 1.0 - v1 * v1 - w1 * w1
        if cc < MIN_AXIAL_COSINE * MIN_AXIAL_COSINE:
            cc = MIN_AXIAL_COSINE * MIN_AXIAL_COSINE
        total += _GAUSS3_W[k] * xi_end * h_el * (1.0 - math.sqrt(cc))
    return total


@njit(cache=True)
def add_shortening_gradient(
    x: float,
    X: NDArray[np.float64],
    n: int,
    n_el: int,
    h_el: float,
    scale: float,
    out: NDArray[np.float64],
) -> None:
    """out[0:2n] += scale * d u(x) / d q, with d u / d q = int_0^x (v' N', w' N') / c ds."""
    drop = 2 * n_el + 2 - n
    e_end = int(x / h_el)
    if e_end > n_el - 1:
        e_end = n_el - 1
    if e_end < 0:
        e_end = 0
    d1 = np.empty(4)
    d2 = np.empty(4)
    for e in range(e_end + 1):
        span = 1.0
        if e == e_end:
            span = (x - e * h_el) / h_el
            if span < 0.0:
                span = 0.0
            if span > 1.0:
                span = 1.0
        for k in range(5):
            _hermite_derivatives(_GAUSS_X[k] * span, h_el, d1, d2)
            wt = _GAUSS_W[k] * span * h_el
            v1, _ = _plane_derivatives(X[0:n], e, drop, d1, d2)
            w1, _ = _plane_derivatives(X[n : 2 * n], e, drop, d1, d2)
            cc = 1.0 - v1 * v1 - w1 * w1
            if cc < MIN_AXIAL_COSINE * MIN_AXIAL_COSINE:
                cc = MIN_AXIAL_COSINE * MIN_AXIAL_COSINE
            c = math.sqrt(cc)
            for j in range(4):
                idx = _dof(e, j, drop)
                if idx >= 0:
                    out[idx] += scale * wt * v1 * d1[j] / c
                    out[n + idx] += scale * wt * w1 * d1[j] / c


def node_masses(model: LinkModel) -> NDArray[np.float64]:
    """Masses lumped at the nodes for the axial motion (kg), shape (n_elements + 1,): half of
    each element's mass at each of its nodes, the tip mass at the last."""
    element = model.element_density * np.diff(model.nodes)
    masses = np.zeros(model.n_elements + 1)
    masses[:-1] += 0.5 * element
    masses[1:] += 0.5 * element
    masses[-1] += model.total_mass - float(element.sum())
    return masses


def _forces(model: LinkModel, q: NDArray[np.float64], axial_gravity: float) -> NDArray[np.float64]:
    n = model.n_dof
    out = np.zeros(2 * n)
    axial = np.zeros((model.n_elements + 1, 2))
    link_forces(
        q,
        q,
        q,
        n,
        model.n_elements,
        model.length / model.n_elements,
        model.element_rigidity,
        node_masses(model),
        axial_gravity,
        False,
        out,
        axial,
    )
    return out


def static_equilibrium(
    model: LinkModel,
    load_v: NDArray[np.float64],
    load_w: NDArray[np.float64],
    axial_gravity: float = 0.0,
    tolerance: float = 1e-12,
    max_iterations: int = 100,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Static equilibrium of the nonlinear link under generalised loads of fixed direction.

    Solves ``K q + f_nl(q) = f`` (f_nl: :func:`link_forces`, static) by Newton's method with a
    finite-difference tangent, starting from the linear solution, in equal load steps that
    each add at most 0.2 to the linear solution's tip slope.

    Parameters
    ----------
    model : LinkModel
    load_v, load_w : ndarray, shape (n_dof,)
        Generalised loads of each plane (N, N m), e.g. ``P * model.shape_at(l)`` for a dead
        load P along Y^m at the tip, or ``-g * model.translation_load`` for gravity along -Z^m.
    axial_gravity : float
        Gravity's component along X^m (m/s^2).
    tolerance : float
        Newton stops when the largest coordinate change is below this (m, rad).
    max_iterations : int
        Newton iterations per load step.

    Returns
    -------
    (q_v, q_w) : ndarrays, shape (n_dof,)

    Raises
    ------
    ValueError
        When Newton's method has not converged within ``max_iterations`` in a load step.
    """
    n = model.n_dof
    stiffness = np.zeros((2 * n, 2 * n))
    stiffness[:n, :n] = stiffness[n:, n:] = model.stiffness
    load = np.concatenate([load_v, load_w])
    q = np.linalg.solve(stiffness, load)
    slope = max(
        abs(float(model.slope_at(model.length) @ q[:n])),
        abs(float(model.slope_at(model.length) @ q[n:])),
    )
    steps = max(1, math.ceil(slope / 0.2))
    q = q / steps
    for step in range(1, steps + 1):
        target = load * step / steps
        for iteration in range(max_iterations + 1):
            if iteration == max_iterations:
                raise ValueError(
                    f"static equilibrium: no convergence in {max_iterations} Newton iterations"
                    f" at load step {step} of {steps} (beyond the nonlinear link's range?)"
                )
            base = _forces(model, q, axial_gravity)
            residual = stiffness @ q + base - target
            tangent = stiffness.copy()
            for i in range(2 * n):
                delta = 1e-7 * max(1e-3, abs(q[i]))
                shifted = q.copy()
                shifted[i] += delta
                tangent[:, i] += (_forces(model, shifted, axial_gravity) - base) / delta
            change = np.linalg.solve(tangent, -residual)
            q = q + change
            if float(np.max(np.abs(change))) < tolerance:
                break
    return q[:n].copy(), q[n:].copy()


def link_position(
    model: LinkModel, q_v: NDArray[np.float64], q_w: NDArray[np.float64], s: float
) -> NDArray[np.float64]:
    """Position (m) of the material point at arc length ``s`` in the motor frame, shape (3,):
    ``(s - u(s), v(s), w(s))``."""
    n = model.n_dof
    q = np.concatenate([q_v, q_w])
    axial = np.zeros((model.n_elements + 1, 2))
    out = np.zeros(2 * n)
    h_el = model.length / model.n_elements
    link_forces(
        q,
        q,
        q,
        n,
        model.n_elements,
        h_el,
        model.element_rigidity,
        node_masses(model),
        0.0,
        False,
        out,
        axial,
    )
    u = shortening_at(s, q, n, model.n_elements, h_el, axial)
    return np.array([s - u, float(model.shape_at(s) @ q_v), float(model.shape_at(s) @ q_w)])
