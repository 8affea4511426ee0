"""The compiled time loop: hub-and-link dynamics, contact, sensor and 1 kHz servo.

Unknowns ``X = [q_v, q_w, theta1, theta2]``: the finite-element coordinates of the deflection
along Y^m (v) and Z^m (w) and the two joint angles. Linearised about the moving motor frame
(small deflection, Assumption 1), the equations of motion are

    M q_v'' + C q_v' + K q_v + cos(theta2) s theta1''          = N(x_c) F_y
    M q_w'' + C q_w' + K q_w + s theta2''                      = -g cos(theta2) m + N(x_c) F_z
    (J1 + S2 cos^2 theta2) theta1'' + cos(theta2) s.q_v'' + v1 theta1' + F_c1 = tau1 + Q1
    (J2 + S2) theta2'' + s.q_w'' + v2 theta2' + F_c2 = tau2 + Q2_gravity + Q2

with ``m = int rho N``, ``s = int rho x N`` and S2 the rigid link's inertia about O (link.py):
x cos(theta2) theta1'' and x theta2'' are the transverse accelerations of the moving base line.
The joint rows are Eq. 1 with the coupling torque written out as the link's reaction (hub-beam
model), so the link loads the motors exactly as the real link loads the real joints. Contact
forces enter as generalised forces of the force F applied at the continuous abscissa x_c.

Time integration: Newmark average acceleration (beta = 1/4, gamma = 1/2; Newmark 1959),
unconditionally stable and free of numerical dissipation, with internal step h = T_s / substeps.
The effective matrix of the link, ``A = 4 M / h^2 + 2 C / h + K``, is inverted once; the joint
rows border it (Schur complement) and the contact adds a rank-2 term (normal and tangential
penalty), solved with the Woodbury identity. The Coulomb friction of the motors is regularised,
``Gamma_nlc tanh(omega / omega_s)``, and linearised at the start of each step.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.compiler import njit
from sensing_antenna.control.servo import joint_coupling_torques, joint_servo_step
from sensing_antenna.simulator.contact import distance_and_normal
from sensing_antenna.simulator.nonlinear_link import (
    add_shortening_gradient,
    link_forces,
    shortening_at,
)

__all__ = ["TRUTH_COLUMNS", "P", "run_samples", "sensor_wrench"]


class P:
    """Indices into the packed parameter vector of the compiled loop."""

    STEP = 0
    SUBSTEPS = 1
    GRAVITY = 2
    J1 = 3
    J2 = 4
    V1 = 5
    V2 = 6
    COULOMB1 = 7
    COULOMB2 = 8
    OMEGA_S = 9
    S1 = 10
    S2 = 11
    MASS = 12
    K_N = 13
    C_N = 14
    K_T = 15
    C_T = 16
    MU = 17
    LENGTH = 18
    X_MIN = 19
    ENCODER = 20
    FEEDBACK = 21
    CONTROL = 22
    TORQUE_GAIN1 = 23
    TORQUE_GAIN2 = 24
    NONLINEAR = 25
    SIZE = 26


# The same indices as module constants, for the compiled code.
_P_STEP = 0
_P_SUBSTEPS = 1
_P_GRAVITY = 2
_P_J1 = 3
_P_J2 = 4
_P_V1 = 5
_P_V2 = 6
_P_COULOMB1 = 7
_P_COULOMB2 = 8
_P_OMEGA_S = 9
_P_S1 = 10
_P_S2 = 11
_P_MASS = 12
_P_K_N = 13
_P_C_N = 14
_P_K_T = 15
_P_C_T = 16
_P_MU = 17
_P_LENGTH = 18
_P_X_MIN = 19
_P_ENCODER = 20
_P_FEEDBACK = 21
_P_CONTROL = 22
_P_TORQUE_GAIN1 = 23
_P_TORQUE_GAIN2 = 24
_P_NONLINEAR = 25
_P_SIZE = 26

#: The nonlinear link's step is iterated until no coordinate changes by more than this (m, rad)
#: between two iterates, or ``MAX_ITERATIONS`` times.
ITERATION_TOLERANCE = 1e-11
MAX_ITERATIONS = 60

# Contact state vector layout.
_ACTIVE = 0
_STICK = 1
_ANCHOR = 2  # 3 values, absolute frame
_XC = 5
_FORCE_M = 6  # 3 values, force on the link, motor frame
_POINT_M = 9  # 3 values, contact point, motor frame
_FIRST_TOUCH = 12
_NORMAL_FORCE = 13
_ANCHOR_ARC = 14  # nonlinear link: the abscissa of the material point stuck at the contact
CONTACT_STATE_SIZE = 15

#: Half-bandwidth of the link's mass matrix: a Hermite element couples the 4 consecutive
#: coordinates of its two nodes (``link.build_link_model``).
_MASS_BAND = 3

#: Columns of the ground-truth array written by :func:`run_samples`: true angles (2), contact
#: flag, x_c, contact point in the absolute frame (3), normal force, motor voltages (2), contact
#: force on the link in the motor frame (3), stick flag.
TRUTH_COLUMNS = 14


@njit(cache=True)
def _frame(theta1: float, theta2: float) -> NDArray[np.float64]:
    c1 = math.cos(theta1)
    s1 = math.sin(theta1)
    c2 = math.cos(theta2)
    s2 = math.sin(theta2)
    f = np.empty((3, 3))
    f[0, 0] = c2 * c1
    f[0, 1] = c2 * s1
    f[0, 2] = s2
    f[1, 0] = -s1
    f[1, 1] = c1
    f[1, 2] = 0.0
    f[2, 0] = -s2 * c1
    f[2, 1] = -s2 * s1
    f[2, 2] = c2
    return f


@njit(cache=True)
def _shape(
    x: float, n_el: int, h_el: float, out_n: NDArray[np.float64], out_d: NDArray[np.float64]
) -> int:
    """Hermite weights (value and slope) at x into out_n/out_d (4,); returns the element index."""
    e = int(x / h_el)
    if e < 0:
        e = 0
    if e > n_el - 1:
        e = n_el - 1
    xi = (x - e * h_el) / h_el
    if xi < 0.0:
        xi = 0.0
    if xi > 1.0:
        xi = 1.0
    xi2 = xi * xi
    xi3 = xi2 * xi
    out_n[0] = 1.0 - 3.0 * xi2 + 2.0 * xi3
    out_n[1] = h_el * (xi - 2.0 * xi2 + xi3)
    out_n[2] = 3.0 * xi2 - 2.0 * xi3
    out_n[3] = h_el * (xi3 - xi2)
    out_d[0] = (-6.0 * xi + 6.0 * xi2) / h_el
    out_d[1] = 1.0 - 4.0 * xi + 3.0 * xi2
    out_d[2] = (6.0 * xi - 6.0 * xi2) / h_el
    out_d[3] = 3.0 * xi2 - 2.0 * xi
    return e


@njit(cache=True)
def _interp(
    q: NDArray[np.float64], e: int, wn: NDArray[np.float64], wd: NDArray[np.float64], drop: int
) -> tuple[float, float]:
    """Deflection and slope from plane dofs q in element e; the clamp removed the first ``drop``
    dofs of node 0 (2 rigid, 1 compliant: the root slope stays)."""
    val = 0.0
    slope = 0.0
    for j in range(4):
        idx = 2 * e + j - drop
        if idx >= 0:
            val += wn[j] * q[idx]
            slope += wd[j] * q[idx]
    return val, slope


@njit(cache=True)
def _gap(
    x: float,
    X: NDArray[np.float64],
    n: int,
    n_el: int,
    h_el: float,
    frame: NDArray[np.float64],
    obst: NDArray[np.float64],
    wn: NDArray[np.float64],
    wd: NDArray[np.float64],
    axial: NDArray[np.float64],
    nonlinear: bool,
) -> float:
    """Signed distance (m) of the link's axis point at abscissa ``x`` from the obstacle
    (``contact.distance_and_normal``, inlined, so that the normal it does not use is not
    computed on this hot path; compiled into this file's kernels: numba's cache does not see
    a change there, so a change to the obstacles changes this file too)."""
    e = _shape(x, n_el, h_el, wn, wd)
    drop = 2 * n_el + 2 - n
    v, _ = _interp(X[0:n], e, wn, wd, drop)
    w, _ = _interp(X[n : 2 * n], e, wn, wd, drop)
    if nonlinear:
        # the material point x sits at x - u(x) along X^m
        x = x - shortening_at(x, X, n, n_el, h_el, axial)
    px = x * frame[0, 0] + v * frame[1, 0] + w * frame[2, 0] - obst[1]
    py = x * frame[0, 1] + v * frame[1, 1] + w * frame[2, 1] - obst[2]
    pz = x * frame[0, 2] + v * frame[1, 2] + w * frame[2, 2] - obst[3]
    return distance_and_normal(px, py, pz, obst)[0]


@njit(cache=True)
def _closest(
    X: NDArray[np.float64],
    n: int,
    n_el: int,
    h_el: float,
    frame: NDArray[np.float64],
    obst: NDArray[np.float64],
    x_min: float,
    length: float,
    wn: NDArray[np.float64],
    wd: NDArray[np.float64],
    axial: NDArray[np.float64],
    nonlinear: bool,
) -> tuple[float, float]:
    """Abscissa in [x_min, l] of the smallest gap, and that gap (m); ``axial``: the nonlinear
    link's nodal shortening (``nonlinear_link.link_forces``)."""
    n_s = 4 * n_el + 1
    best = 1e300
    ibest = 0
    dx = (length - x_min) / (n_s - 1)
    for i in range(n_s):
        g = _gap(x_min + i * dx, X, n, n_el, h_el, frame, obst, wn, wd, axial, nonlinear)
        if g < best:
            best = g
            ibest = i
    if best > 0.05:
        return x_min + ibest * dx, best
    lo = x_min + max(ibest - 1, 0) * dx
    hi = x_min + min(ibest + 1, n_s - 1) * dx
    ratio = 0.6180339887498949
    a = hi - ratio * (hi - lo)
    b = lo + ratio * (hi - lo)
    ga = _gap(a, X, n, n_el, h_el, frame, obst, wn, wd, axial, nonlinear)
    gb = _gap(b, X, n, n_el, h_el, frame, obst, wn, wd, axial, nonlinear)
    for _ in range(40):
        if ga < gb:
            hi = b
            b = a
            gb = ga
            a = hi - ratio * (hi - lo)
            ga = _gap(a, X, n, n_el, h_el, frame, obst, wn, wd, axial, nonlinear)
        else:
            lo = a
            a = b
            ga = gb
            b = lo + ratio * (hi - lo)
            gb = _gap(b, X, n, n_el, h_el, frame, obst, wn, wd, axial, nonlinear)
    xc = 0.5 * (lo + hi)
    g = _gap(xc, X, n, n_el, h_el, frame, obst, wn, wd, axial, nonlinear)
    if best < g:
        return x_min + ibest * dx, best
    return xc, g


@njit(cache=True)
def _solve_s0(
    r: NDArray[np.float64],
    n: int,
    ainv: NDArray[np.float64],
    z: NDArray[np.float64],
    coef_b1: float,
    coef_b2: float,
    sz: float,
    d1: float,
    d2: float,
) -> NDArray[np.float64]:
    """Solve the bordered system [[A, b1],[b1^T, d1]] (plane v) and likewise for plane w.

    b1 = coef_b1 * s and b2 = coef_b2 * s, with z = A^-1 s and sz = s . z precomputed.
    """
    out = np.empty(2 * n + 2)
    for plane in range(2):
        off = plane * n
        coef = coef_b1 if plane == 0 else coef_b2
        d = d1 if plane == 0 else d2
        y = ainv @ r[off : off + n]
        # Schur complement of the joint row
        theta = (r[2 * n + plane] - coef * (z @ r[off : off + n])) / (d - coef * coef * sz)
        out[off : off + n] = y - coef * theta * z
        out[2 * n + plane] = theta
    return out


@njit(cache=True)
def _contact_solve(
    rhs: NDArray[np.float64],
    x_free: NDArray[np.float64],
    X: NDArray[np.float64],
    V: NDArray[np.float64],
    vcoef: NDArray[np.float64],
    g0: float,
    s0: float,
    un: NDArray[np.float64],
    ut: NDArray[np.float64],
    par: NDArray[np.float64],
    h: float,
    n: int,
    ainv: NDArray[np.float64],
    z: NDArray[np.float64],
    cb1: float,
    cb2: float,
    s_dot: float,
    d1: float,
    d2: float,
) -> tuple[NDArray[np.float64], bool, bool, float, float]:
    """The step with the penalty contact in force: stick (rank-2 Woodbury update along the
    normal and tangential directions ``un``, ``ut``) or slip (rank-1 along un + sign mu ut).

    Returns the new coordinates (``x_free`` when the contact releases), whether the contact
    holds, whether it sticks, and the normal and tangential forces (N).
    """
    nn = 2 * n + 2
    u0 = np.empty(nn)
    ub = np.empty(nn)
    x_new = x_free
    kn = par[_P_K_N]
    cn = par[_P_C_N]
    kt = par[_P_K_T]
    ct = par[_P_C_T]
    un_x = un @ X
    ut_x = ut @ X
    rn = -kn * (g0 - un_x) + cn * (un @ vcoef)
    rt = -kt * (s0 - ut_x) + ct * (ut @ vcoef)
    stick = True
    active = True
    slip_sign = 0.0
    mu = par[_P_MU]
    dn = kn + 2.0 * cn / h
    fn = 0.0
    ft = 0.0
    for _it in range(2):
        if stick:
            for i in range(nn):
                u0[i] = rhs[i] + rn * un[i] + rt * ut[i]
            y0 = _solve_s0(u0, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            yn = _solve_s0(un, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            yt = _solve_s0(ut, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            dt_ = kt + 2.0 * ct / h
            # Woodbury: (D^-1 + U^T S0^-1 U)^-1 U^T S0^-1 u0
            m00 = 1.0 / dn + un @ yn
            m01 = un @ yt
            m10 = ut @ yn
            m11 = 1.0 / dt_ + ut @ yt
            b0 = un @ y0
            b1 = ut @ y0
            det = m00 * m11 - m01 * m10
            c0 = (m11 * b0 - m01 * b1) / det
            c1 = (-m10 * b0 + m00 * b1) / det
            x_try = y0 - c0 * yn - c1 * yt
        else:
            # slip: F_t = sign mu F_n with F_n = rn - dn un.x, so the contact
            # force acts along ub = un + sign mu ut (Sherman-Morrison)
            for i in range(nn):
                ub[i] = un[i] + slip_sign * mu * ut[i]
                u0[i] = rhs[i] + rn * ub[i]
            y0 = _solve_s0(u0, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            yb = _solve_s0(ub, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            c0 = (un @ y0) / (1.0 / dn + un @ yb)
            x_try = y0 - c0 * yb
        v_try = 2.0 / h * (x_try - X) - V
        g_new = g0 + un @ (x_try - X)
        fn = -kn * g_new - cn * (un @ v_try)
        if fn <= 0.0:
            fn = 0.0
            active = False
            break
        if stick:
            s_new = s0 + ut @ (x_try - X)
            ft_trial = -kt * s_new - ct * (ut @ v_try)
            if abs(ft_trial) <= mu * fn:
                ft = ft_trial
                x_new = x_try
                break
            stick = False
            slip_sign = math.copysign(1.0, ft_trial)
        else:
            ft = slip_sign * mu * fn
            x_new = x_try
            break
    return x_new, active, stick, fn, ft


@njit(cache=True)
def _solve3(m: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Solve the 3x3 system m x = b by Cramer's rule (a diverging step gives NaN, which the
    caller reports, instead of an exception from inside the compiled loop)."""
    c00 = m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1]
    c01 = m[1, 2] * m[2, 0] - m[1, 0] * m[2, 2]
    c02 = m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0]
    det = m[0, 0] * c00 + m[0, 1] * c01 + m[0, 2] * c02
    x = np.empty(3)
    x[0] = (
        b[0] * c00
        + m[0, 1] * (m[1, 2] * b[2] - b[1] * m[2, 2])
        + m[0, 2] * (b[1] * m[2, 1] - m[1, 1] * b[2])
    ) / det
    x[1] = (
        m[0, 0] * (b[1] * m[2, 2] - m[1, 2] * b[2])
        + b[0] * c01
        + m[0, 2] * (m[1, 0] * b[2] - b[1] * m[2, 0])
    ) / det
    x[2] = (
        m[0, 0] * (m[1, 1] * b[2] - b[1] * m[2, 1])
        + m[0, 1] * (b[1] * m[2, 0] - m[1, 0] * b[2])
        + b[0] * c02
    ) / det
    return x


@njit(cache=True)
def _contact_solve_axial(
    rhs: NDArray[np.float64],
    x_free: NDArray[np.float64],
    X: NDArray[np.float64],
    V: NDArray[np.float64],
    vcoef: NDArray[np.float64],
    g0: float,
    s0: float,
    s0a: float,
    un: NDArray[np.float64],
    ut: NDArray[np.float64],
    ua: NDArray[np.float64],
    par: NDArray[np.float64],
    h: float,
    n: int,
    ainv: NDArray[np.float64],
    z: NDArray[np.float64],
    cb1: float,
    cb2: float,
    s_dot: float,
    d1: float,
    d2: float,
) -> tuple[NDArray[np.float64], bool, bool, float, float, float]:
    """:func:`_contact_solve` with friction in the whole tangent plane: a second stick spring
    along the link (direction ``ua``, stretch ``s0a`` at the start of the step), for the
    nonlinear link, which can slide along its length through the contact. Stick: rank-3
    Woodbury update; slip: rank 1 along un + mu (tangential trial force's direction).

    Returns the new coordinates, whether the contact holds, whether it sticks, and the normal,
    transverse tangential and axial tangential forces (N).
    """
    nn = 2 * n + 2
    u0 = np.empty(nn)
    ub = np.empty(nn)
    x_new = x_free
    kn = par[_P_K_N]
    cn = par[_P_C_N]
    kt = par[_P_K_T]
    ct = par[_P_C_T]
    rn = -kn * (g0 - un @ X) + cn * (un @ vcoef)
    rt = -kt * (s0 - ut @ X) + ct * (ut @ vcoef)
    ra = -kt * (s0a - ua @ X) + ct * (ua @ vcoef)
    stick = True
    active = True
    dir_t = 0.0
    dir_a = 0.0
    mu = par[_P_MU]
    dn = kn + 2.0 * cn / h
    dt_ = kt + 2.0 * ct / h
    fn = 0.0
    ft = 0.0
    fa = 0.0
    matrix = np.empty((3, 3))
    right = np.empty(3)
    for _it in range(2):
        if stick:
            for i in range(nn):
                u0[i] = rhs[i] + rn * un[i] + rt * ut[i] + ra * ua[i]
            y0 = _solve_s0(u0, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            yn = _solve_s0(un, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            yt = _solve_s0(ut, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            ya = _solve_s0(ua, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            # Woodbury: (D^-1 + U^T S0^-1 U) c = U^T S0^-1 u0, x = y0 - S0^-1 U c
            matrix[0, 0] = 1.0 / dn + un @ yn
            matrix[0, 1] = un @ yt
            matrix[0, 2] = un @ ya
            matrix[1, 0] = ut @ yn
            matrix[1, 1] = 1.0 / dt_ + ut @ yt
            matrix[1, 2] = ut @ ya
            matrix[2, 0] = ua @ yn
            matrix[2, 1] = ua @ yt
            matrix[2, 2] = 1.0 / dt_ + ua @ ya
            right[0] = un @ y0
            right[1] = ut @ y0
            right[2] = ua @ y0
            coef = _solve3(matrix, right)
            x_try = y0 - coef[0] * yn - coef[1] * yt - coef[2] * ya
        else:
            for i in range(nn):
                ub[i] = un[i] + mu * (dir_t * ut[i] + dir_a * ua[i])
                u0[i] = rhs[i] + rn * ub[i]
            y0 = _solve_s0(u0, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            yb = _solve_s0(ub, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            c0 = (un @ y0) / (1.0 / dn + un @ yb)
            x_try = y0 - c0 * yb
        v_try = 2.0 / h * (x_try - X) - V
        g_new = g0 + un @ (x_try - X)
        fn = -kn * g_new - cn * (un @ v_try)
        if fn <= 0.0:
            fn = 0.0
            active = False
            break
        if stick:
            ft_trial = -kt * (s0 + ut @ (x_try - X)) - ct * (ut @ v_try)
            fa_trial = -kt * (s0a + ua @ (x_try - X)) - ct * (ua @ v_try)
            size = math.sqrt(ft_trial * ft_trial + fa_trial * fa_trial)
            if size <= mu * fn:
                ft = ft_trial
                fa = fa_trial
                x_new = x_try
                break
            stick = False
            dir_t = ft_trial / size
            dir_a = fa_trial / size
        else:
            ft = dir_t * mu * fn
            fa = dir_a * mu * fn
            x_new = x_try
            break
    return x_new, active, stick, fn, ft, fa


@njit(cache=True)
def sensor_wrench(
    X: NDArray[np.float64],
    A: NDArray[np.float64],
    n: int,
    mass_m: NDArray[np.float64],
    mq: NDArray[np.float64],
    sq: NDArray[np.float64],
    par: NDArray[np.float64],
    cs: NDArray[np.float64],
    out: NDArray[np.float64],
    axial_sums: NDArray[np.float64],
    rest: NDArray[np.float64],
) -> None:
    """Wrench by the link on the head about O, motor frame: out = [F (3), torque (3)].

    ``rest`` = [q_v0, q_w0], a bowed link's rest shape (zeros for a straight link), from
    which the link deflects: its points lie at the rest shape plus the deflection, the arm of
    their weight and inertia.

    ``axial_sums`` = (sum m_i u_i, sum m_i u_i'') of the nonlinear link's axial motion (kg m,
    N; zeros for the linear link): the weight's arm along X^m shrinks by the first, the second
    is the axial inertia force.

    From the momentum balance of the link: the head exerts ``F_h = int rho a dx - W - F_c`` and
    ``tau_h = int rho p x a dx - int p x rho g dx - p_c x F_c``; the sensor reads -F_h, -tau_h.

    About X^m, with the deflected points p = (x, v, w) and the accelerations of the equations
    of motion, ``a_y = v'' + cos(theta2) x theta1''`` and ``a_z = w'' + x theta2''``, the link's
    inertial moment is ``int rho (v a_z - w a_y) dx = q_v.M q_w'' - q_w.M q_v''
    + theta2'' s.q_v - cos(theta2) theta1'' s.q_w``: exact with the consistent mass matrix
    ``mass_m`` (M, banded, tip mass included) and ``s = int rho x N dx`` (``sq``), since v and w
    lie in the Hermite space. Gravity's moment is ``g_z int rho v dx`` (g_y = 0 in the motor
    frame). The elastic forces of either link model have no moment about X^m (the bending
    energy and the shortening do not change when the deflection turns about X^m), so the
    balance gives what a link that does not twist transmits: no torque about X^m, bar the
    Rayleigh damping's moment. The nonlinear link's arc length s stands for x in the rigid
    accelerations, as in its equations of motion; its axial shortening moves mass along X^m
    only and leaves the moment about X^m unchanged.
    """
    g = par[_P_GRAVITY]
    s1 = par[_P_S1] - axial_sums[0]
    s2m = par[_P_S2]
    mass = par[_P_MASS]
    th2 = X[2 * n + 1]
    c2 = math.cos(th2)
    sn2 = math.sin(th2)
    gx = -g * sn2
    gz = -g * c2
    acc1 = A[2 * n]
    acc2 = A[2 * n + 1]
    mav = mq @ A[0:n]
    maw = mq @ A[n : 2 * n]
    sav = sq @ A[0:n]
    saw = sq @ A[n : 2 * n]
    mv = mq @ X[0:n] + mq @ rest[0:n]
    mw = mq @ X[n : 2 * n] + mq @ rest[n : 2 * n]
    # int rho (v a_z - w a_y) dx about X^m: q_v.M q_w'' - q_w.M q_v'' over M's band (no
    # temporaries), plus the rigid accelerations' part
    spin = 0.0
    for i in range(n):
        row_w = acc2 * sq[i]
        row_v = c2 * acc1 * sq[i]
        for j in range(max(i - _MASS_BAND, 0), min(i + _MASS_BAND + 1, n)):
            row_w += mass_m[i, j] * A[n + j]
            row_v += mass_m[i, j] * A[j]
        spin += (X[i] + rest[i]) * row_w - (X[n + i] + rest[n + i]) * row_v
    fcx = cs[_FORCE_M]
    fcy = cs[_FORCE_M + 1]
    fcz = cs[_FORCE_M + 2]
    px = cs[_POINT_M]
    py = cs[_POINT_M + 1]
    pz = cs[_POINT_M + 2]
    fhx = -mass * gx - fcx - axial_sums[1]
    fhy = c2 * acc1 * s1 + mav - fcy
    fhz = acc2 * s1 + maw - mass * gz - fcz
    thx = spin - (gz * mv) - (py * fcz - pz * fcy)
    thy = -(acc2 * s2m + saw) - (gx * mw - gz * s1) - (pz * fcx - px * fcz)
    thz = c2 * acc1 * s2m + sav - (-gx * mv) - (px * fcy - py * fcx)
    out[0] = -fhx
    out[1] = -fhy
    out[2] = -fhz
    out[3] = -thx
    out[4] = -thy
    out[5] = -thz


@njit(cache=True)
def run_samples(
    k0: int,
    k1: int,
    X: NDArray[np.float64],
    V: NDArray[np.float64],
    A: NDArray[np.float64],
    ctrl: NDArray[np.float64],
    cs: NDArray[np.float64],
    par: NDArray[np.float64],
    mass_m: NDArray[np.float64],
    damp_c: NDArray[np.float64],
    ainv: NDArray[np.float64],
    z: NDArray[np.float64],
    mq: NDArray[np.float64],
    sq: NDArray[np.float64],
    n_el: int,
    obst: NDArray[np.float64],
    servo: NDArray[np.float64],
    reference: NDArray[np.float64],
    noise: NDArray[np.float64],
    bias: NDArray[np.float64],
    meas_theta: NDArray[np.float64],
    meas_wrench: NDArray[np.float64],
    truth: NDArray[np.float64],
    rigidity: NDArray[np.float64],
    node_mass: NDArray[np.float64],
    rest: NDArray[np.float64],
) -> None:
    """Advance samples k0..k1-1: sense at t_k, command the motors, integrate to t_{k+1}.

    Writes the measured angles (n, 2) and wrench (n, 6) of each sample and the ground truth
    (n, TRUTH_COLUMNS): true angles (2), contact flag, x_c, contact point in the absolute frame
    (3), normal force, motor voltages (2), contact force on the link in the motor frame (3) and
    the stick flag (1 sticking, 0 slipping or no contact). The servo runs the controller's
    compiled step on ``ctrl`` (2, JOINT_STATE_SIZE) with the coefficients ``servo`` (2, 2, 2, 3)
    of :class:`~sensing_antenna.control.servo.ServoDesign`; each joint's command limit, if any,
    sits in its ``ctrl`` row (``initial_servo_state``).

    With ``par[P.NONLINEAR]`` set, the link is the geometrically exact one of
    :mod:`~sensing_antenna.simulator.nonlinear_link`, with E I of each element ``rigidity``
    (n_el,) and the axial masses ``node_mass`` (n_el + 1,); each step is then iterated on its
    extra forces (fixed point with the linear step's matrix) to ``ITERATION_TOLERANCE``.

    ``rest`` (2 n,) is the linear link's rest shape (a bow; zeros for a straight link): the
    elastic forces act on the coordinates, the deflection from it, while the contact, the
    weight and the inertial moments see the link where it is, at the rest shape plus them.
    """
    n = mass_m.shape[0]
    nn = 2 * n + 2
    h = par[_P_STEP]
    nsub = int(par[_P_SUBSTEPS])
    period = h * nsub
    g = par[_P_GRAVITY]
    s1m = par[_P_S1]
    s2m = par[_P_S2]
    length = par[_P_LENGTH]
    h_el = length / n_el
    drop = 2 * n_el + 2 - n
    s_dot = float(sq @ z)
    wrench = np.empty(6)
    nonlinear = par[_P_NONLINEAR] > 0.0
    max_iterations = MAX_ITERATIONS if nonlinear else 1
    nl_force = np.zeros(2 * n)
    axial0 = np.zeros((n_el + 1, 2))
    axial1 = np.zeros((n_el + 1, 2))
    axial_sums = np.zeros(2)
    axial_ready = False
    residual = np.zeros(nn)
    residual_prev = np.zeros(nn)
    g_prev = np.zeros(nn)
    v_iter = np.zeros(nn)
    a_iter = np.zeros(nn)
    rhs_iter = np.zeros(nn)
    placed = np.zeros(nn)  # the link's coordinates where it is (rest shape and deflection)
    wn = np.empty(4)
    wd = np.empty(4)
    un = np.zeros(nn)
    ut = np.zeros(nn)
    ua = np.zeros(nn)
    avec = np.zeros(3)
    acoef = np.empty(nn)
    vcoef = np.empty(nn)
    rhs = np.empty(nn)
    for k in range(k0, k1):
        # --- sensor sample at t_k -------------------------------------------------------------
        if nonlinear:
            # the axial motion of the state: from the last step's last iterate (within
            # ITERATION_TOLERANCE of it), or computed at the start of a call
            if not axial_ready:
                link_forces(
                    X, V, A, n, n_el, h_el, rigidity, node_mass, 0.0, True, nl_force, axial1
                )
                axial_ready = True
            axial_sums[0] = 0.0
            axial_sums[1] = 0.0
            for i in range(n_el + 1):
                axial_sums[0] += node_mass[i] * axial1[i, 0]
                axial_sums[1] += node_mass[i] * axial1[i, 1]
        sensor_wrench(X, A, n, mass_m, mq, sq, par, cs, wrench, axial_sums, rest)
        for i in range(6):
            meas_wrench[k, i] = wrench[i] + bias[i] + noise[k, i]
        quantum = par[_P_ENCODER]
        for j in range(2):
            th = X[2 * n + j]
            if quantum > 0.0:
                th = quantum * math.floor(th / quantum + 0.5)
            meas_theta[k, j] = th
        truth[k, 0] = X[2 * n]
        truth[k, 1] = X[2 * n + 1]
        truth[k, 2] = cs[_ACTIVE]
        truth[k, 3] = cs[_XC]
        fr = _frame(X[2 * n], X[2 * n + 1])
        for i in range(3):
            truth[k, 4 + i] = (
                cs[_POINT_M] * fr[0, i] + cs[_POINT_M + 1] * fr[1, i] + cs[_POINT_M + 2] * fr[2, i]
            )
        truth[k, 7] = cs[_NORMAL_FORCE]
        for i in range(3):
            truth[k, 10 + i] = cs[_FORCE_M + i]
        truth[k, 13] = cs[_STICK]
        # --- servo command (Sec. 4.1, Fig. 7): the library's step, control/servo.py -----------
        # coupling torque about Z^a (joint 1) and about -Y^m (joint 2), from the sensor
        coupling = joint_coupling_torques(meas_theta[k, 1], meas_wrench[k, 3:6])
        tau = np.zeros(2)
        if par[_P_CONTROL] > 0.0:
            for j in range(2):
                tau[j] = joint_servo_step(
                    servo[j],
                    ctrl[j],
                    reference[k, j],
                    meas_theta[k, j],
                    coupling[j],
                    par[_P_FEEDBACK],
                    par[_P_COULOMB1 + j],
                    par[_P_OMEGA_S],
                    period,
                )
        truth[k, 8] = tau[0] / par[_P_TORQUE_GAIN1]
        truth[k, 9] = tau[1] / par[_P_TORQUE_GAIN2]
        # --- internal Newmark steps --------------------------------------------------------------
        for sub in range(nsub):
            th1 = X[2 * n]
            th2 = X[2 * n + 1]
            c2 = math.cos(th2)
            sn2 = math.sin(th2)
            fr = _frame(th1, th2)
            # regularised Coulomb friction of Eq. 1, linearised at the current speed
            cf = np.empty(2)
            fconst = np.empty(2)
            for j in range(2):
                om = V[2 * n + j]
                gc = par[_P_COULOMB1 + j]
                ws = par[_P_OMEGA_S]
                th_ = math.tanh(om / ws)
                cf[j] = gc / ws * (1.0 - th_ * th_)
                fconst[j] = gc * th_ - cf[j] * om
            for i in range(nn):
                acoef[i] = 4.0 / (h * h) * X[i] + 4.0 / h * V[i] + A[i]
                vcoef[i] = 2.0 / h * X[i] + V[i]
            j1 = par[_P_J1] + s2m * c2 * c2
            j2 = par[_P_J2] + s2m
            # rhs = M_aug acoef + C_aug vcoef + loads
            rv = mass_m @ acoef[0:n] + damp_c @ vcoef[0:n] + c2 * sq * acoef[2 * n]
            rw = mass_m @ acoef[n : 2 * n] + damp_c @ vcoef[n : 2 * n] + sq * acoef[2 * n + 1]
            # gravity on the w plane: -g cos(theta2) int rho N dx
            rw = rw - g * c2 * mq
            rhs[0:n] = rv
            rhs[n : 2 * n] = rw
            mw = mq @ X[n : 2 * n] + mq @ rest[n : 2 * n]
            rhs[2 * n] = (
                c2 * (sq @ acoef[0:n])
                + j1 * acoef[2 * n]
                + (par[_P_V1] + cf[0]) * vcoef[2 * n]
                + tau[0]
                - fconst[0]
            )
            # gravity moment about the elevation axis: g_z S1 - g_x int rho w dx
            q2g = -g * c2 * s1m + g * sn2 * mw
            rhs[2 * n + 1] = (
                sq @ acoef[n : 2 * n]
                + j2 * acoef[2 * n + 1]
                + (par[_P_V2] + cf[1]) * vcoef[2 * n + 1]
                + tau[1]
                - fconst[1]
                + q2g
            )
            cb1 = 4.0 / (h * h) * c2
            cb2 = 4.0 / (h * h)
            d1 = 4.0 / (h * h) * j1 + 2.0 / h * (par[_P_V1] + cf[0])
            d2 = 4.0 / (h * h) * j2 + 2.0 / h * (par[_P_V2] + cf[1])
            x_new = _solve_s0(rhs, n, ainv, z, cb1, cb2, s_dot, d1, d2)
            if nonlinear:
                # shortening of the state at the start of the step, for the contact geometry
                axial0[:, :] = axial1
            fn = 0.0
            ft = 0.0
            fa = 0.0
            s0a = 0.0
            nvec = np.zeros(3)
            tvec = np.zeros(3)
            pc = np.zeros(3)
            xc = 0.0
            active = False
            stick = True
            geometry = False
            g0 = 0.0
            s0 = 0.0
            u_c = 0.0
            e = 0
            v_c = 0.0
            w_c = 0.0
            dth1 = np.zeros(3)
            dth2 = np.zeros(3)
            if obst[0] > 0.0:
                # where the link is: its rest shape plus its deflection
                for i in range(nn):
                    placed[i] = X[i]
                for i in range(2 * n):
                    placed[i] += rest[i]
                xc, g0 = _closest(
                    placed,
                    n,
                    n_el,
                    h_el,
                    fr,
                    obst,
                    par[_P_X_MIN],
                    length,
                    wn,
                    wd,
                    axial0,
                    nonlinear,
                )
                e = _shape(xc, n_el, h_el, wn, wd)
                v_c, dv_c = _interp(placed[0:n], e, wn, wd, drop)
                w_c, dw_c = _interp(placed[n : 2 * n], e, wn, wd, drop)
                x_axis = xc
                if nonlinear:
                    u_c = shortening_at(xc, X, n, n_el, h_el, axial0)
                    x_axis = xc - u_c
                for i in range(3):
                    pc[i] = x_axis * fr[0, i] + v_c * fr[1, i] + w_c * fr[2, i]
                if g0 < 0.02:
                    geometry = True
                    # outward normal at the contact point
                    _, nx, ny, nz = distance_and_normal(
                        pc[0] - obst[1], pc[1] - obst[2], pc[2] - obst[3], obst
                    )
                    nvec[0], nvec[1], nvec[2] = nx, ny, nz
                    if nonlinear:
                        axial_cos = math.sqrt(max(1.0 - dv_c * dv_c - dw_c * dw_c, 1e-6))
                        tang = axial_cos * fr[0] + dv_c * fr[1] + dw_c * fr[2]
                    else:
                        tang = fr[0] + dv_c * fr[1] + dw_c * fr[2]
                    tvec[0] = nvec[1] * tang[2] - nvec[2] * tang[1]
                    tvec[1] = nvec[2] * tang[0] - nvec[0] * tang[2]
                    tvec[2] = nvec[0] * tang[1] - nvec[1] * tang[0]
                    tvec /= math.sqrt(tvec @ tvec)
                    # generalised directions: d p_c / d X
                    dth1 = (
                        x_axis * c2 * fr[1] - v_c * (c2 * fr[0] - sn2 * fr[2]) - w_c * sn2 * fr[1]
                    )
                    dth2 = x_axis * fr[2] - w_c * fr[0]
                    ny = nvec @ fr[1]
                    nz = nvec @ fr[2]
                    ty = tvec @ fr[1]
                    tz = tvec @ fr[2]
                    un[:] = 0.0
                    ut[:] = 0.0
                    for jj in range(4):
                        idx = 2 * e + jj - drop
                        if idx >= 0:
                            un[idx] = ny * wn[jj]
                            un[n + idx] = nz * wn[jj]
                            ut[idx] = ty * wn[jj]
                            ut[n + idx] = tz * wn[jj]
                    if nonlinear:
                        # the contact point moves by -u(x_c) along X^m
                        add_shortening_gradient(xc, X, n, n_el, h_el, -(nvec @ fr[0]), un)
                        add_shortening_gradient(xc, X, n, n_el, h_el, -(tvec @ fr[0]), ut)
                    un[2 * n] = nvec @ dth1
                    un[2 * n + 1] = nvec @ dth2
                    ut[2 * n] = tvec @ dth1
                    ut[2 * n + 1] = tvec @ dth2
                    if cs[_ACTIVE] == 0.0:
                        s0 = 0.0
                    else:
                        s0 = float(tvec @ (pc - cs[_ANCHOR : _ANCHOR + 3]))
                    if nonlinear:
                        # friction along the link too: avec, the tangent in the contact plane;
                        # the stuck material point sits s0a past the contact along it
                        avec[:] = tang - (tang @ nvec) * nvec
                        avec /= math.sqrt(avec @ avec)
                        ua[:] = 0.0
                        for jj in range(4):
                            idx = 2 * e + jj - drop
                            if idx >= 0:
                                ua[idx] = (avec @ fr[1]) * wn[jj]
                                ua[n + idx] = (avec @ fr[2]) * wn[jj]
                        add_shortening_gradient(xc, X, n, n_el, h_el, -(avec @ fr[0]), ua)
                        ua[2 * n] = avec @ dth1
                        ua[2 * n + 1] = avec @ dth2
                        s0a = cs[_ANCHOR_ARC] - xc if cs[_ACTIVE] > 0.0 else 0.0
            # the step: once for the linear link; for the nonlinear one, a fixed-point iteration
            # on its extra forces, evaluated at the iterate (A: the linear step's matrix)
            # first iterate: the Taylor prediction X + h V + h^2 A / 2 (error O(h^3))
            x_iter = X + h * V + 0.5 * h * h * A
            for _iteration in range(max_iterations):
                if nonlinear:
                    for i in range(nn):
                        v_iter[i] = 2.0 / h * (x_iter[i] - X[i]) - V[i]
                        a_iter[i] = 4.0 / (h * h) * (x_iter[i] - X[i]) - 4.0 / h * V[i] - A[i]
                    link_forces(
                        x_iter,
                        v_iter,
                        a_iter,
                        n,
                        n_el,
                        h_el,
                        rigidity,
                        node_mass,
                        -g * sn2,
                        True,
                        nl_force,
                        axial1,
                    )
                    for i in range(nn):
                        rhs_iter[i] = rhs[i]
                    for i in range(2 * n):
                        rhs_iter[i] -= nl_force[i]
                    x_new = _solve_s0(rhs_iter, n, ainv, z, cb1, cb2, s_dot, d1, d2)
                else:
                    rhs_iter = rhs
                active = False
                stick = True
                fn = 0.0
                ft = 0.0
                if geometry:
                    # predicted gap with the contact-free solution
                    g_free = g0 + un @ (x_new - X)
                    if g_free < 0.0 or (cs[_ACTIVE] > 0.0 and g0 < 0.0):
                        active = True
                    if active and nonlinear:
                        x_new, active, stick, fn, ft, fa = _contact_solve_axial(
                            rhs_iter,
                            x_new,
                            X,
                            V,
                            vcoef,
                            g0,
                            s0,
                            s0a,
                            un,
                            ut,
                            ua,
                            par,
                            h,
                            n,
                            ainv,
                            z,
                            cb1,
                            cb2,
                            s_dot,
                            d1,
                            d2,
                        )
                    elif active:
                        x_new, active, stick, fn, ft = _contact_solve(
                            rhs_iter,
                            x_new,
                            X,
                            V,
                            vcoef,
                            g0,
                            s0,
                            un,
                            ut,
                            par,
                            h,
                            n,
                            ainv,
                            z,
                            cb1,
                            cb2,
                            s_dot,
                            d1,
                            d2,
                        )
                if not nonlinear:
                    break
                # residual of the fixed point x = G(x), G the step solved at the iterate
                change = 0.0
                for i in range(nn):
                    residual[i] = x_new[i] - x_iter[i]
                    change = max(change, abs(residual[i]))
                if change < ITERATION_TOLERANCE:
                    break
                # Anderson acceleration of depth 1 (secant on the residual; Walker and Ni 2011)
                gamma = 0.0
                if _iteration > 0:
                    num = 0.0
                    den = 0.0
                    for i in range(nn):
                        d = residual[i] - residual_prev[i]
                        num += residual[i] * d
                        den += d * d
                    if den > 0.0:
                        gamma = num / den
                for i in range(nn):
                    step_prev = g_prev[i]
                    g_prev[i] = x_new[i]
                    residual_prev[i] = residual[i]
                    x_iter[i] = x_new[i] - gamma * (x_new[i] - step_prev)
            if active:
                if cs[_ACTIVE] == 0.0:
                    cs[_ANCHOR : _ANCHOR + 3] = pc
                    cs[_ANCHOR_ARC] = xc
                if nonlinear and not stick:
                    # slip: the stuck material point moves so the axial spring carries fa
                    cs[_ANCHOR_ARC] += -fa / par[_P_K_T] - (s0a + ua @ (x_new - X))
                dp = np.zeros(3)
                dx = x_new - X
                for i in range(3):
                    dp[i] = dth1[i] * dx[2 * n] + dth2[i] * dx[2 * n + 1]
                v_new, _ = _interp(x_new[0:n], e, wn, wd, drop)
                w_new, _ = _interp(x_new[n : 2 * n], e, wn, wd, drop)
                v_rest, _ = _interp(rest[0:n], e, wn, wd, drop)
                w_rest, _ = _interp(rest[n : 2 * n], e, wn, wd, drop)
                v_new += v_rest
                w_new += w_rest
                for i in range(3):
                    dp[i] += (v_new - v_c) * fr[1, i] + (w_new - w_c) * fr[2, i]
                if nonlinear:
                    u_new = shortening_at(xc, x_new, n, n_el, h_el, axial1)
                    for i in range(3):
                        dp[i] -= (u_new - u_c) * fr[0, i]
                if not stick:
                    # slip: move the anchor so the spring carries the Coulomb force
                    s_new = -ft / par[_P_K_T]
                    cs[_ANCHOR : _ANCHOR + 3] = pc + dp - s_new * tvec
                cs[_STICK] = 1.0 if stick else 0.0
                for i in range(3):
                    pc[i] += dp[i]
            if not active:
                fn = 0.0
                ft = 0.0
                cs[_STICK] = 0.0
            acc_new = 4.0 / (h * h) * (x_new - X) - 4.0 / h * V - A
            V[:] = V + 0.5 * h * (A + acc_new)
            A[:] = acc_new
            X[:] = x_new
            cs[_ACTIVE] = 1.0 if active else 0.0
            cs[_NORMAL_FORCE] = fn
            if active:
                if cs[_FIRST_TOUCH] < 0.0:
                    cs[_FIRST_TOUCH] = k * h * nsub + (sub + 1) * h
                cs[_XC] = xc
                fr2 = _frame(X[2 * n], X[2 * n + 1])
                for r in range(3):
                    if nonlinear:
                        cs[_FORCE_M + r] = fr2[r] @ (fn * nvec + ft * tvec + fa * avec)
                    else:
                        cs[_FORCE_M + r] = fr2[r] @ (fn * nvec + ft * tvec)
                    cs[_POINT_M + r] = fr2[r] @ pc
            else:
                for i in range(3):
                    cs[_FORCE_M + i] = 0.0
