"""``simulate(antenna, scenario) -> Recording``: the device of Section 3 doing Section 4 steps 1-4.

The controller takes its stop decision online from the simulated sensor samples, through a
streaming stop rule with ``reset()`` and ``update(t, theta, force, torque) -> bool`` (by default the
project's :class:`~sensing_antenna.detection.push.PushMonitor`), exactly as the real controller
would: the simulator's ground truth is never used to stop.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.antenna import STANDARD_GRAVITY, Antenna, Link, antenna_to_toml
from sensing_antenna.control.servo import FRICTION_SPEED, design_servo, initial_servo_state
from sensing_antenna.recording import (
    COMMAND_COLUMNS,
    CONTACT_POINT_COLUMNS,
    FORMAT_NAME,
    IN_CONTACT_COLUMN,
    Recording,
)
from sensing_antenna.simulator.contact import Obstacle, place_obstacle, place_solid
from sensing_antenna.simulator.device import DeviceImperfections
from sensing_antenna.simulator.integrator import (
    CONTACT_STATE_SIZE,
    TRUTH_COLUMNS,
    P,
    run_samples,
)
from sensing_antenna.simulator.link import LinkModel, build_link_model, rayleigh_coefficients
from sensing_antenna.simulator.manoeuvre import ramp_displacement, sweep_reference
from sensing_antenna.simulator.nonlinear_link import node_masses, static_equilibrium
from sensing_antenna.simulator.scenario import (
    DEFAULT_CONTACT_STIFFNESS,
    DEFAULT_SAMPLE_PERIOD,
    FREE_CASES,
    SIZED_KINDS,
    Scenario,
    ScenarioError,
)

__all__ = [
    "FINAL_AVERAGE_TIME",
    "MIN_STIFFNESS_RATIO",
    "NONLINEAR_ANGLE_LIMIT_DEG",
    "SMALL_DEFLECTION_LIMIT",
    "SimulationDetail",
    "StopRule",
    "deflection_warning",
    "device_link",
    "minimum_contact_point",
    "sampling_warning",
    "simulate",
    "simulate_detailed",
]

#: Contact search starts this fraction of l away from the clamp.
CONTACT_SEARCH_START = 0.02

#: Assumption 1 of the paper: the deflection y_c / x_c stays below 10 %.
SMALL_DEFLECTION_LIMIT = 0.1

#: The final deflection is averaged over this last part of the recording (s).
FINAL_AVERAGE_TIME = 0.5

#: The nonlinear link's step (a fixed point on its extra forces) converges while the link's
#: tangent stays within about this angle of X^m (measured: the iteration fails at 49 degrees,
#: its contraction growing as tan^2 of the angle); docs/simulator.md, "Large deflection".
NONLINEAR_ANGLE_LIMIT_DEG = 45.0

#: The penalty contact must be at least this many times stiffer than the link's local stiffness
#: 3 E I / x_c^3, or it is no support at all (docs/simulator.md, "Smallest contact point").
MIN_STIFFNESS_RATIO = 10.0


def device_link(link: Link) -> Link:
    """The link the simulator builds for ``link``: a calibrated one vibrates with its T_e.

    A calibrated T_e (Section 5.1) is the device's measured ratio of mass to stiffness,
    T_e = sqrt(rho / (E I)); the simulator stands for that device, so it takes the flexural
    rigidity E I = rho / T_e^2 that gives it, keeping rho (the weight) and I (E changes), and
    drops the calibration. A link without one is built as it is (T from the material data).
    """
    if link.calibrated_t is None:
        return link
    # T_e = sqrt(rho / (E I)) solved for E with rho and I kept
    youngs = link.linear_density / (link.calibrated_t**2 * link.area_moment)
    return replace(
        link, youngs_modulus=youngs, calibrated_t=None, calibration_scatter=None, mode2_scatter=None
    )


class StopRule(Protocol):
    """Streaming stop rule of the controller (PushMonitor interface)."""

    def reset(self) -> None: ...

    def update(self, t: float, theta: Any, force: Any, torque: Any) -> bool: ...


@dataclass(frozen=True)
class SimulationDetail:
    """A recording plus the simulator's internal truth, for tests and diagnostics.

    Attributes
    ----------
    recording : Recording
    true_theta : ndarray, shape (n, 2)
        Exact joint angles (rad).
    in_contact : ndarray of bool, shape (n,)
    contact_abscissa : ndarray, shape (n,)
        x_c of the current (or last) contact (m).
    contact_point : ndarray, shape (n, 3)
        Contact point, absolute frame (m).
    normal_force : ndarray, shape (n,)
        Normal contact force (N).
    contact_force : ndarray, shape (n, 3)
        Contact force exerted by the obstacle on the link, motor frame (N); zero without contact.
    sticking : ndarray of bool, shape (n,)
        True while the contact sticks, False while it slips or there is no contact.
    contact_deflection : ndarray, shape (n,)
        Deflection of the link at the contact point, |(v - v0, w - w0 - w_g)(x_c)| with w_g the
        static gravity sag at the current theta2 and (v0, w0) a bowed link's rest shape
        (``DeviceImperfections.bow``; zero for a straight link) (m); NaN without contact.
    voltage : ndarray, shape (n, 2)
        Motor input voltages u_i (V).
    final_deflection : ndarray, shape (2, n_dof)
        Finite-element coordinates of v (row 0) and w (row 1) at the end of the run (m, rad);
        ``link_model.shape_at(x) @ final_deflection[0]`` is v(x), the deflection from the
        link's rest shape (a bowed link's lies beside it, :func:`rest_shape`).
    stop_index : int or None
        Sample at which the stop rule fired (t_1), or None.
    obstacle : Obstacle or None
    link_model : LinkModel
    rayleigh : (float, float)
        Damping coefficients alpha (1/s), beta (s).
    scenario : Scenario
        The scenario as simulated, its defaults made explicit (:meth:`Scenario.resolved`: the
        ramp times, the contact stiffness and the substeps the link was given).
    """

    recording: Recording
    true_theta: NDArray[np.float64]
    in_contact: NDArray[np.bool_]
    contact_abscissa: NDArray[np.float64]
    contact_point: NDArray[np.float64]
    normal_force: NDArray[np.float64]
    contact_force: NDArray[np.float64]
    sticking: NDArray[np.bool_]
    contact_deflection: NDArray[np.float64]
    voltage: NDArray[np.float64]
    final_deflection: NDArray[np.float64]
    stop_index: int | None
    obstacle: Obstacle | None
    link_model: LinkModel
    rayleigh: tuple[float, float]
    scenario: Scenario


@lru_cache(maxsize=16)
def _link_setup(
    link: Link, n_elements: int, device: DeviceImperfections | None = None
) -> tuple[LinkModel, float, float]:
    """FE model, first free frequency and highest first contact frequency over [0.3 l, l]."""
    model = build_link_model(link, n_elements, device)
    omega_free = float(model.free_frequencies(1)[0])
    grid = np.linspace(0.3, 1.0, 15) * link.length
    omega_contact = max(float(model.pinned_frequencies(x, 1)[0]) for x in grid)
    return model, omega_free, omega_contact


@lru_cache(maxsize=16)
def _unit_sag(
    link: Link, n_elements: int, device: DeviceImperfections | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Static sag of the link under 1 m/s^2 of transverse gravity on a grid of abscissae.

    Returns (x, w): the grid (m), shape (401,), and the FE deflection there (m per m/s^2),
    negative (the load points along -Z^m). Linear interpolation on this 2.5 mm grid is exact to
    < 1e-7 m for the paper link.
    """
    model, _, _ = _link_setup(link, n_elements, device)
    q = np.linalg.solve(model.stiffness, -model.translation_load)
    x = np.linspace(0.0, link.length, 401)
    w = np.array([float(model.shape_at(float(xi)) @ q) for xi in x])
    return x, w


def minimum_contact_point(link: Link, contact_stiffness: float) -> float:
    """Smallest x_c (m) the simulator accepts: where ``contact_stiffness`` (N/m) is
    ``MIN_STIFFNESS_RATIO`` times the link's local stiffness 3 E I / x_c^3.

    Below it the penalty contact no longer acts as a support (the link's own stiffness is
    comparable with the penalty), and the push forces 3 E I y_c / x_c^3 grow past the range of
    a small force sensor (paper link, default 1e4 N/m: x_c >= 0.065 m, where y_c / x_c = 3 %
    takes 1.9 N; at 0.02 m it would take 20 N).
    """
    ratio = MIN_STIFFNESS_RATIO * 3.0 * link.flexural_rigidity / contact_stiffness
    return float(ratio ** (1.0 / 3.0))


def bow_arc(x: ArrayLike, length: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A bowed link's rest shape per metre of tip offset (``DeviceImperfections.bow``) at the
    abscissae ``x`` (m) of a link ``length`` long: the arc (x / l)^2 and its slope 2 x / l^2."""
    x = np.asarray(x, dtype=np.float64)
    return (x / length) ** 2, 2.0 * x / length**2


def rest_shape(model: LinkModel, bow: tuple[float, float]) -> NDArray[np.float64]:
    """The unloaded link's rest shape as the linear link's coordinates [q_v, q_w], shape
    (2 n_dof,): the arcs (:func:`bow_arc`) of tip offsets ``bow`` (m) along Y^m and Z^m, exact
    in the Hermite elements (values and slopes at the nodes)."""
    values = np.zeros(2 * model.nodes.size)
    values[0::2], values[1::2] = bow_arc(model.nodes, float(model.nodes[-1]))
    free = values[model.root_dofs :]
    return np.concatenate([bow[0] * free, bow[1] * free])


def _contact_deflection(
    link: Link,
    n_elements: int,
    truth: NDArray[np.float64],
    gravity: float,
    device: DeviceImperfections | None = None,
    bow: tuple[float, float] = (0.0, 0.0),
) -> NDArray[np.float64]:
    """|(v - v0, w - w0 - w_g)| at the contact point of each sample (m), from the link's rest
    shape (a ``bow``'s arcs v0, w0) and its sag w_g; NaN without contact."""
    theta1, theta2 = truth[:, 0], truth[:, 1]
    c1, s1, c2, s2 = np.cos(theta1), np.sin(theta1), np.cos(theta2), np.sin(theta2)
    point = truth[:, 4:7]
    # motor frame (recording format): Y^m = (-s1, c1, 0), Z^m = (-s2 c1, -s2 s1, c2)
    v = -s1 * point[:, 0] + c1 * point[:, 1]
    w = -s2 * c1 * point[:, 0] - s2 * s1 * point[:, 1] + c2 * point[:, 2]
    grid, unit = _unit_sag(link, n_elements, device)
    sag = gravity * c2 * np.interp(truth[:, 3], grid, unit)
    arc, _ = bow_arc(truth[:, 3], link.length)
    deflection = np.hypot(v - bow[0] * arc, w - bow[1] * arc - sag)
    return np.where(truth[:, 2] > 0.5, deflection, np.nan)


def sampling_warning(antenna: Antenna, sample_period: float = DEFAULT_SAMPLE_PERIOD) -> str | None:
    """A one-line warning when the estimators cannot read ``antenna``'s link from samples every
    ``sample_period`` (s): its contact frequencies reach beyond what that period resolves (a
    short, stiff link), else None. The line names the slowest sampling that does."""
    from sensing_antenna.estimation.config import EstimatorConfig
    from sensing_antenna.estimation.front.evidence import search_band
    from sensing_antenna.estimation.front.steps import slowest_sample_rate

    config = EstimatorConfig()
    band_top = search_band(antenna.link, config)[1]
    rate = slowest_sample_rate(band_top, config)
    if rate * sample_period <= 1.0:
        return None
    return (
        f"samples at {1.0 / sample_period:g} Hz are too slow for this antenna's link: its"
        f" omega_1 reaches {band_top:.0f} rad/s, which needs samples at {math.ceil(rate)} Hz or"
        " faster, so no estimator reads its recordings"
    )


def deflection_warning(recording: Recording) -> str | None:
    """A one-line warning when the recording's ``true_deflection_ratio`` exceeds
    ``SMALL_DEFLECTION_LIMIT`` (Assumption 1), else None (also when the key is absent)."""
    text = recording.metadata.get("true_deflection_ratio")
    if text is None:
        return None
    ratio = float(text)
    if not ratio > SMALL_DEFLECTION_LIMIT:
        return None
    return (
        f"warning: final contact deflection y_c / x_c = {100 * ratio:.1f} % exceeds the"
        f" {100 * SMALL_DEFLECTION_LIMIT:.0f} % small-deflection limit (Assumption 1): the"
        " contact was detected late; identify the device's observer and contact threshold"
        " (antenna identify) and give the simulated head's controller that antenna file"
        " (antenna simulate --controller)"
    )


@lru_cache(maxsize=16)
def _effective_inverse(
    link: Link,
    n_elements: int,
    step: float,
    alpha: float,
    beta: float,
    device: DeviceImperfections | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    model, _, _ = _link_setup(link, n_elements, device)
    damping = alpha * model.mass + beta * model.stiffness
    effective = 4.0 / step**2 * model.mass + 2.0 / step * damping + model.stiffness
    ainv: NDArray[np.float64] = np.linalg.inv(effective).astype(np.float64)
    z = ainv @ model.rotation_load
    return damping, ainv, z


def _default_stop_rule(antenna: Antenna, push: Any, sample_period: float) -> StopRule:
    from sensing_antenna.detection.push import PushCriterion, PushMonitor

    criterion = PushCriterion() if push is None else push
    # a nonlinear link out of its range gives samples that are not finite: said after the run
    return PushMonitor(criterion, antenna, sample_period, check_input=False)


def simulate(
    antenna: Antenna,
    scenario: Scenario,
    progress: Callable[[float], None] | None = None,
    stop_rule: StopRule | None = None,
    *,
    torque_limit: tuple[float, float] | None = None,
    record_commands: bool = False,
) -> Recording:
    """Simulate one manoeuvre and return its recording (recording format v1, with ground truth).

    Parameters
    ----------
    antenna : Antenna
        Link and motors of the device (the observer is not used by the physics). A link with a
        calibrated T_e is built with the flexural rigidity that gives it (:func:`device_link`).
    scenario : Scenario
    progress : callable, optional
        Called with the fraction done (0..1) now and then.
    stop_rule : object with reset() and update(t, theta, force, torque) -> bool, optional
        The controller's stop rule; default ``PushMonitor(scenario.push or PushCriterion())``.
    torque_limit : (float, float), optional
        A device whose amplifiers saturate: each joint's command limit |n K_m u| (N m), the
        controller's ``HeadController(torque_limit=...)`` with its anti-windup. None (the
        default): no limit.
    record_commands : bool
        Add the motor voltages as the columns ``u1, u2`` (V, ``recording.COMMAND_COLUMNS``),
        what ``antenna identify --servo`` fits Eq. 1 with. Off by default.

    Returns
    -------
    Recording
        Columns t, theta, force, torque plus ``theta1_ref, theta2_ref`` (and ``u1, u2`` when
        asked); metadata format, sample_period, antenna, description and ground truth
        (``true_*``, ``seed``, ``simulation``).
    """
    return simulate_detailed(
        antenna,
        scenario,
        progress,
        stop_rule,
        torque_limit=torque_limit,
        record_commands=record_commands,
    ).recording


def simulate_detailed(
    antenna: Antenna,
    scenario: Scenario,
    progress: Callable[[float], None] | None = None,
    stop_rule: StopRule | None = None,
    gravity: float = STANDARD_GRAVITY,
    *,
    torque_limit: tuple[float, float] | None = None,
    record_commands: bool = False,
) -> SimulationDetail:
    """Like :func:`simulate`, also returning the simulator's internal truth (tests, plots).

    ``gravity`` (m/s^2) exists for closed-form tests only.
    """
    limits = (math.inf, math.inf) if torque_limit is None else tuple(map(float, torque_limit))
    link = device_link(antenna.link)
    ts = scenario.sample_period
    n_samples = round(scenario.duration / ts)
    t: NDArray[np.float64] = np.arange(n_samples, dtype=np.float64) * ts
    imperfect = scenario.device.link_part  # the key of the cached link set-up
    model, omega_free, omega_contact = _link_setup(link, scenario.n_elements, imperfect)
    # the smallest contact point is judged on the stated stiffness: the default, resolved, is
    # always firm enough, but the push forces near the clamp are not
    stated = scenario.contact_stiffness or DEFAULT_CONTACT_STIFFNESS
    scenario = scenario.resolved(omega_free, omega_contact, link.mass, ts)
    assert scenario.accel_time is not None and scenario.approach_time is not None
    assert scenario.substeps is not None and scenario.contact_stiffness is not None
    alpha, beta = rayleigh_coefficients(scenario.damping_ratio, omega_free, omega_contact)
    step = ts / scenario.substeps
    damping, ainv, z = _effective_inverse(link, scenario.n_elements, step, alpha, beta, imperfect)
    n = model.n_dof
    bow = scenario.device.bow
    rest = rest_shape(model, bow)  # the link's position is its rest shape and its deflection

    # --- reference trajectory (Section 4 step 1) -----------------------------------------------
    sweep_joint = scenario.swept_joint
    servo = [design_servo(m, scenario.servo_pole, ts) for m in antenna.motors]
    # the swept joint's signed speed: up (+1) or down (-1)
    speed = scenario.sweep_direction * scenario.sweep_speed
    lag = 2.0 * servo[sweep_joint].time_constant * speed
    travel = float(ramp_displacement(np.array(scenario.approach_time), speed, scenario.accel_time))
    theta_touch = (0.0, 0.0)
    start = [0.0, 0.0]
    start[sweep_joint] = theta_touch[sweep_joint] - travel + lag
    reference = np.empty((n_samples, 2))
    reference[:, 1 - sweep_joint] = start[1 - sweep_joint]
    stop_after = scenario.approach_time if scenario.case in FREE_CASES else None
    reference[:, sweep_joint] = sweep_reference(
        t,
        start[sweep_joint],
        speed,
        scenario.accel_time,
        scenario.start_time,
        stop_after,
    )

    # --- initial state: static gravity equilibrium ---------------------------------------------
    nonlinear = scenario.link_model == "nonlinear"
    c2 = math.cos(start[1])
    q_w: NDArray[np.floating[Any]]
    if nonlinear:
        _, q_w = static_equilibrium(
            model,
            np.zeros(n),
            -gravity * c2 * model.translation_load,
            axial_gravity=-gravity * math.sin(start[1]),
        )
    else:
        q_w = np.linalg.solve(model.stiffness, -gravity * c2 * model.translation_load)
    x_state = np.zeros(2 * n + 2)
    x_state[n : 2 * n] = q_w
    x_state[2 * n] = start[0]
    x_state[2 * n + 1] = start[1]
    v_state = np.zeros_like(x_state)
    a_state = np.zeros_like(x_state)

    # --- obstacle (placed from x_c on the sagged link at the touch angles) ---------------------
    obstacle: Obstacle | None = None
    obst_array = np.zeros(10)
    kind = scenario.obstacle_kind
    if kind is not None:
        assert scenario.contact_point is not None
        link.check_contact_point(scenario.contact_point)
        x_min = minimum_contact_point(link, stated)
        if scenario.contact_point < x_min:
            raise ScenarioError(
                "contact_point",
                f"{scenario.contact_point:g} m is below {x_min:.3g} m, where the contact"
                f" stiffness {stated:g} N/m is {MIN_STIFFNESS_RATIO:g} times"
                " the link's local stiffness 3 E I / x_c^3 (the contact would be no support and"
                " the push force would leave the sensor's range)",
            )
        q_sag = np.linalg.solve(
            model.stiffness, -gravity * math.cos(theta_touch[1]) * model.translation_load
        )
        sag = float(model.shape_at(scenario.contact_point) @ q_sag)
        sag_slope = float(model.slope_at(scenario.contact_point) @ q_sag)
        # a bowed link touches where its rest shape puts it: its arc w0 beside the sag, v0 aside
        arc, arc_slope = (float(v) for v in bow_arc(scenario.contact_point, link.length))
        sag, sag_slope = sag + bow[1] * arc, sag_slope + bow[1] * arc_slope
        placement = (
            None if scenario.obstacle_placement is None else np.asarray(scenario.obstacle_placement)
        )
        if placement is not None and kind in SIZED_KINDS:
            # its own sizes, grown by the link's radius as the link's axis meets it
            obstacle = place_solid(kind, placement, scenario.obstacle_sizes, antenna.link.radius)
        elif placement is not None:
            direction = placement[3:] / np.linalg.norm(placement[3:])
            radius = 0.0 if kind == "plane" else scenario.obstacle_radius
            half = 0.5 * scenario.obstacle_length
            # a capped cylinder as the link's axis meets it: its rim rounded by the link's
            # radius (its radius and height given grown by it)
            rounding = min(antenna.link.radius, radius, half) if kind == "cylinder" else 0.0
            obstacle = Obstacle(
                kind, tuple(placement[:3]), tuple(direction), radius, half, rounding
            )
        else:
            obstacle = place_obstacle(
                kind,
                scenario.contact_point,
                link.length,
                theta_touch,
                sag,
                sag_slope,
                scenario.obstacle_radius,
                scenario.obstacle_tilt,
                sweep_joint,
                scenario.sweep_direction,
                lateral=(bow[0] * arc, bow[0] * arc_slope),
            )
        obst_array = obstacle.as_array()

    # --- parameters of the compiled loop -------------------------------------------------------
    par = np.zeros(P.SIZE)
    par[P.STEP] = step
    par[P.SUBSTEPS] = scenario.substeps
    par[P.GRAVITY] = gravity
    m1, m2 = antenna.motors
    par[P.J1], par[P.J2] = m1.inertia, m2.inertia
    par[P.V1], par[P.V2] = m1.viscous_friction, m2.viscous_friction
    par[P.COULOMB1], par[P.COULOMB2] = m1.coulomb_torque, m2.coulomb_torque
    par[P.OMEGA_S] = FRICTION_SPEED
    par[P.S1] = model.first_moment
    par[P.S2] = model.second_moment
    par[P.MASS] = model.total_mass
    par[P.K_N] = scenario.contact_stiffness
    par[P.C_N] = scenario.contact_damping
    par[P.K_T] = scenario.contact_stiffness
    par[P.C_T] = scenario.contact_damping
    par[P.MU] = scenario.friction_coefficient
    par[P.LENGTH] = link.length
    par[P.X_MIN] = CONTACT_SEARCH_START * link.length
    counts = scenario.sensor.encoder_counts
    par[P.ENCODER] = 0.0 if counts == 0 else 2.0 * math.pi / (counts * m1.gear_ratio)
    par[P.FEEDBACK] = 1.0
    par[P.CONTROL] = 1.0
    par[P.TORQUE_GAIN1] = m1.gear_ratio * m1.torque_constant
    par[P.TORQUE_GAIN2] = m2.gear_ratio * m2.torque_constant
    par[P.NONLINEAR] = 1.0 if nonlinear else 0.0
    lumped = node_masses(model)
    servo_array = np.stack([s.discrete() for s in servo])

    # --- randomness: one seeded generator ------------------------------------------------------
    rng = np.random.default_rng(scenario.seed)
    scale = scenario.noise_scale
    bias = rng.normal(size=6) * np.asarray(scenario.sensor.bias_std) * scale
    noise = rng.normal(size=(n_samples, 6)) * np.asarray(scenario.sensor.wrench_std) * scale

    meas_theta = np.zeros((n_samples, 2))
    meas_wrench = np.zeros((n_samples, 6))
    truth = np.zeros((n_samples, TRUTH_COLUMNS))
    ctrl = np.stack(
        [
            initial_servo_state(angle, limit, design.tracking_gain)
            for angle, limit, design in zip(start, limits, servo, strict=True)
        ]
    )
    cs = np.zeros(CONTACT_STATE_SIZE)
    cs[12] = -1.0
    record = _sensor_output(scenario.device, t, scenario.seed, meas_theta, meas_wrench)

    def advance(k0: int, k1: int) -> None:
        run_samples(
            k0,
            k1,
            x_state,
            v_state,
            a_state,
            ctrl,
            cs,
            par,
            model.mass,
            damping,
            ainv,
            z,
            model.translation_load,
            model.rotation_load,
            model.n_elements,
            obst_array,
            servo_array,
            reference,
            noise,
            bias,
            meas_theta,
            meas_wrench,
            truth,
            model.element_rigidity,
            lumped,
            rest,
        )
        if record is not None:
            record(k0, k1)

    stop_index: int | None = None
    if scenario.case not in FREE_CASES:
        rule = _default_stop_rule(antenna, scenario.push, ts) if stop_rule is None else stop_rule
        rule.reset()
        for k in range(n_samples):
            advance(k, k + 1)
            if rule.update(float(t[k]), meas_theta[k], meas_wrench[k, :3], meas_wrench[k, 3:]):
                stop_index = k
                # Section 4 step 4: stop the motors, i.e. freeze the reference from t_1 on;
                # Eq. 14 lag of a ramp, 2 eps omega*: the joint comes to rest where it is now
                hold = reference[k, sweep_joint]
                if scenario.compensate_servo_lag and k > 0:
                    slope = (reference[k, sweep_joint] - reference[k - 1, sweep_joint]) / ts
                    hold -= 2.0 * servo[sweep_joint].time_constant * slope
                reference[k + 1 :, sweep_joint] = hold
                if scenario.retract_after is not None:
                    # back along the sweep at its own signed speed and ramp
                    back = t[k + 1 :] - (t[k] + scenario.retract_after)
                    reference[k + 1 :, sweep_joint] -= sweep_reference(
                        back,
                        0.0,
                        speed,
                        scenario.accel_time,
                        0.0,
                        scenario.retract_angle / scenario.sweep_speed,
                    )
                break
            if progress is not None and k % 500 == 0:
                progress(k / n_samples)
        if stop_index is not None and stop_index + 1 < n_samples:
            advance(stop_index + 1, n_samples)
    else:
        advance(0, n_samples)
    if progress is not None:
        progress(1.0)

    if nonlinear and not np.isfinite(meas_wrench).all():
        bad = int(np.flatnonzero(~np.isfinite(meas_wrench).all(axis=1))[0])
        raise ScenarioError(
            "link_model",
            f"the nonlinear link left its range at t = {t[bad]:.3f} s: its tangent turned"
            f" about {NONLINEAR_ANGLE_LIMIT_DEG:g} degrees from the head's axis (a push of about"
            " 50 % of x_c), where its step no longer converges; push less deep",
        )
    in_contact = truth[:, 2] > 0.5
    deflection = _contact_deflection(link, scenario.n_elements, truth, gravity, imperfect, bow)
    final = max(1, round(FINAL_AVERAGE_TIME / ts))
    first_touch = float(cs[12]) if cs[12] >= 0 else None
    metadata: dict[str, str] = {
        "format": FORMAT_NAME,
        "sample_period": repr(ts),
        "antenna": antenna.name,
        "description": scenario.description or _describe(scenario, kind),
    }
    if obstacle is not None:
        last = int(np.nonzero(in_contact)[0][-1]) if in_contact.any() else None
        metadata["true_xc"] = "nan" if last is None else repr(float(truth[last, 3]))
        metadata["true_contact_point"] = json.dumps(
            None if last is None else [float(v) for v in truth[last, 4:7]]
        )
        metadata["true_obstacle"] = obstacle.to_json()
        metadata["true_t_contact"] = "nan" if first_touch is None else repr(first_touch)
        metadata["true_in_contact_at_end"] = "true" if in_contact[-1] else "false"
        metadata["true_t_stop"] = "nan" if stop_index is None else repr(float(t[stop_index]))
        metadata["true_deflection_ratio"] = repr(
            _final_deflection_ratio(deflection[-final:], truth[-final:, 3], in_contact[-final:])
        )
    metadata["seed"] = str(scenario.seed)
    metadata["simulation"] = json.dumps(
        {
            "simulator": "sensing_antenna.simulator/1",
            "scenario": scenario.to_json_dict(),
            "antenna": antenna_to_toml(antenna),
            "damping_alpha": alpha,
            "damping_beta": beta,
            **({} if torque_limit is None else {"torque_limit": list(limits)}),
        },
        sort_keys=True,
    )
    extra = {"theta1_ref": reference[:, 0].copy(), "theta2_ref": reference[:, 1].copy()}
    if obstacle is not None:
        extra.update(_contact_track(in_contact, truth[:, 4:7], obstacle, antenna.link.radius))
    if record_commands:
        extra.update({name: truth[:, 8 + j].copy() for j, name in enumerate(COMMAND_COLUMNS)})
    recording = Recording(
        t=t,
        theta=meas_theta,
        force=meas_wrench[:, :3],
        torque=meas_wrench[:, 3:],
        metadata=metadata,
        extra=extra,
    )
    return SimulationDetail(
        recording=recording,
        true_theta=truth[:, :2].copy(),
        in_contact=in_contact,
        contact_abscissa=truth[:, 3].copy(),
        contact_point=truth[:, 4:7].copy(),
        normal_force=truth[:, 7].copy(),
        contact_force=truth[:, 10:13].copy(),
        sticking=truth[:, 13] > 0.5,
        contact_deflection=deflection,
        voltage=truth[:, 8:10].copy(),
        final_deflection=x_state[: 2 * n].reshape(2, n).copy(),
        stop_index=stop_index,
        obstacle=obstacle,
        link_model=model,
        rayleigh=(alpha, beta),
        scenario=scenario,
    )


def _sensor_output(
    device: DeviceImperfections,
    t: NDArray[np.float64],
    seed: int,
    meas_theta: NDArray[np.float64],
    meas_wrench: NDArray[np.float64],
) -> Callable[[int, int], None] | None:
    """The sensor's and encoders' imperfections, applied in place to samples k0..k1-1 of the
    measured angles and wrench once the loop has written them (None: an ideal sensor).

    The loop's servo has used the ideal sample; the stop rule and the recording get this one.
    """
    matrix = device.sensor_matrix()
    offsets = device.sensor_offsets(t, seed)
    encoder = np.asarray(device.encoder_offset)
    if matrix is None and offsets is None and not encoder.any():
        return None

    def apply(k0: int, k1: int) -> None:
        if matrix is not None:
            meas_wrench[k0:k1] = meas_wrench[k0:k1] @ matrix.T
        if offsets is not None:
            meas_wrench[k0:k1] += offsets[k0:k1]
        if encoder.any():
            meas_theta[k0:k1] += encoder

    return apply


def _final_deflection_ratio(
    deflection: NDArray[np.float64],
    abscissa: NDArray[np.float64],
    in_contact: NDArray[np.bool_],
) -> float:
    """Mean y_c / x_c over the samples given (the hold's last ``FINAL_AVERAGE_TIME``), NaN
    unless the link is in contact over all of them (the mean over a few periods removes most of
    the vibration)."""
    if not in_contact.all():
        return math.nan
    return float(np.mean(deflection / abscissa))


def _describe(scenario: Scenario, kind: str | None) -> str:
    if kind is None:
        return f"simulated {scenario.case} sweep, no obstacle"
    return f"simulated {scenario.case} sweep into a {kind} at x_c = {scenario.contact_point:g} m"


def _contact_track(
    in_contact: NDArray[np.bool_],
    axis_point: NDArray[np.float64],
    obstacle: Obstacle,
    radius: float,
) -> dict[str, NDArray[np.float64]]:
    """Where the link touched at every sample, as ``recording.CONTACT_TRACK_COLUMNS``: a
    contact that slides after the touch is known where it was at the instant an estimate
    describes (its ``t_point``), not only where it ended.

    ``axis_point`` (n, 3) is the simulated contact on the link's axis (m, absolute frame),
    ``in_contact`` (n,) where it touches; the link's surface touches ``radius`` (m) from its
    axis against the obstacle's outward normal, on the obstacle's surface, where a map places
    its points. The columns hold 0 while not in contact.
    """
    touching = np.asarray(in_contact, dtype=bool)
    axis = np.nan_to_num(np.asarray(axis_point, dtype=float))
    point = np.zeros_like(axis)
    if touching.any():
        normals = obstacle.outward_normals(axis[touching])
        point[touching] = axis[touching] - radius * np.nan_to_num(normals)
    track = {name: point[:, k].copy() for k, name in enumerate(CONTACT_POINT_COLUMNS)}
    return {**track, IN_CONTACT_COLUMN: touching.astype(float)}
