"""Reference recordings of the paper antenna from an independent rod engine (PyElastica).

Each recording is one manoeuvre of the paper's link: an azimuthal sweep into a vertical post
(files ``xc*``), or a vertical sweep up, against gravity, into a horizontal bar (files
``vertical-xc*``: gravity then acts in the bending plane). The head's angles are those of the
project's own simulator for the same scenario (a kinematic base: the motors are not simulated
again), the link is a PyElastica Cosserat rod (geometrically exact: large deflection, shear,
extension) under gravity, touching the obstacle (the scenario's post or bar, ``true_obstacle``)
by penalty with stick-slip Coulomb friction. The sensor is the section force
and moment of the rod at O, resolved on the motor axes, sampled at 1 kHz, with the simulator's
sensor noise (``SensorNoise`` at scale 1, fixed seed) and encoder resolution. The files follow
docs/recording-format.md and carry the ground truth the project's simulator writes (``true_xc``
is where the rod touched, as arc length).

Needs PyElastica (``requirements.txt`` beside this script; not a dependency of the package)::

    PYTHONPATH=src python3 benchmarks/reference/rod/generate.py [--only NAME ...] [--case CASE]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from dataclasses import asdict
from pathlib import Path

import elastica as ea
import numpy as np
from elastica.version import VERSION
from scipy.interpolate import CubicSpline

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from engine import (  # noqa: E402
    GRAVITY,
    KinematicBase,
    PostContact,
    RodLink,
    RodSystem,
    arc_length,
    base_wrench,
    motor_axes,
    scale_fast_modes,
    straight_rod,
)

from sensing_antenna import paper_antenna  # noqa: E402
from sensing_antenna.detection.push import PushCriterion  # noqa: E402
from sensing_antenna.recording import Recording, write_recording  # noqa: E402
from sensing_antenna.simulator import Scenario, SensorNoise, simulate_detailed  # noqa: E402

N_ELEMENTS = 40
FAST_MODE_SCALE = 100.0
TIME_STEP = 1.25e-5  # s: 80 steps per 1 ms sample
SAMPLE_PERIOD = 1e-3
#: Settling before t = 0 (s) under a damping (1/s) critical for the first free mode
#: (2 x 16.05 rad/s): the rod starts at rest in its sag, to 2e-6 of it.
SETTLE_TIME = 1.0
SETTLE_DAMPING = 32.0
#: Velocity damping of the rod during the manoeuvre (1/s): mass-proportional, a damping ratio of
#: nu / (2 omega) = 0.005 at omega = 100 rad/s, the simulator's damping ratio there.
DAMPING = 1.0
SEED = 2021
ENCODER_GEAR = 100.0  # the paper head's gear ratio (Table 1)

#: (name, case, nominal x_c (m), push threshold (rad of head rotation past the first touch),
#: duration (s)); azimuthal names carry no case prefix
CASES = [
    (f"xc{round(x * 100):03d}-push003", "azimuthal", x, 0.03, 3.5)
    for x in (0.30, 0.40, 0.50, 0.60, 0.70, 0.80, 0.90, 0.98)
] + [
    (f"xc{round(x * 100):03d}-push020", "azimuthal", x, 0.20, 4.0) for x in (0.30, 0.50, 0.70, 0.90)
]
# appended after the others, so that every case keeps its seed (SEED + its index)
CASES += [(f"xc{round(x * 100):03d}-push028", "azimuthal", x, 0.28, 4.3) for x in (0.50, 0.90)]
CASES += [
    (f"vertical-xc{round(x * 100):03d}-push003", "vertical", x, 0.03, 3.5)
    for x in (0.30, 0.50, 0.70, 0.90, 0.98)
]
CASES += [
    (f"vertical-xc{round(x * 100):03d}-push{round(push * 100):03d}", "vertical", x, push, d)
    for push, d in ((0.20, 4.0), (0.28, 4.3))
    for x in (0.50, 0.90)
]
#: What each case sweeps into (the recording's description).
SWEEPS = {"azimuthal": "azimuthal sweep into a post", "vertical": "vertical sweep into a bar"}


class _Damper(ea.DamperBase):
    """Velocity damping, heavy before t = 0 (settling) and ``DAMPING`` after."""

    def __init__(self, time_step: float, **kwargs: object) -> None:
        super().__init__(**kwargs)
        self.settle = math.exp(-SETTLE_DAMPING * time_step)
        self.run = math.exp(-DAMPING * time_step)

    def dampen_rates(self, system, time) -> None:
        factor = self.settle if time < 0.0 else self.run
        system.velocity_collection *= factor
        system.omega_collection *= factor


def _angles(recording: Recording):
    """The head's angle history as a function of time (rad, rad/s), from the 1 kHz recording."""
    t = recording.t
    splines = [CubicSpline(t, recording.theta[:, j]) for j in range(2)]
    t0 = float(t[0])
    half = 0.5 * TIME_STEP
    n = round((float(t[-1]) - t0 + SETTLE_TIME + 2 * TIME_STEP) / half) + 2
    grid = t0 - SETTLE_TIME + half * np.arange(n)
    inside = np.clip(grid, t0, float(t[-1]))
    still = grid < t0
    values = [s(inside) for s in splines]
    rates = [np.where(still, 0.0, s(inside, 1)) for s in splines]
    table = np.stack([values[0], values[1], rates[0], rates[1]], axis=1)

    def angles(time: float) -> tuple[float, float, float, float]:
        k = round((time - grid[0]) / half)
        row = table[min(max(k, 0), n - 1)]
        return (float(row[0]), float(row[1]), float(row[2]), float(row[3]))

    return angles


def run_case(
    name: str, case: str, x_c: float, push: float, duration: float, seed: int
) -> tuple[Recording, np.ndarray, float, np.ndarray]:
    """One recording, the rod's noiseless wrench on the head at rest at t = 0 (fx, fy, fz, tx,
    ty, tz: N, N m, motor axes), theta2 there (rad), and the contact's state at each sample,
    shape (n, 6): normal force (N), arc coordinate (elements), point (m, x3), 1 when sliding."""
    antenna = paper_antenna()
    scenario = Scenario(
        case=case,
        contact_point=x_c,
        seed=seed,
        duration=duration,
        noise_scale=0.0,
        push=PushCriterion(kind="rotation", threshold=push),
    )
    detail = simulate_detailed(antenna, scenario)
    kinematics, scenario = detail.recording, detail.scenario  # its defaults as simulated
    obstacle = json.loads(kinematics.metadata["true_obstacle"])
    angles = _angles(kinematics)
    link = RodLink(
        length=antenna.link.length,
        radius=antenna.link.radius,
        youngs_modulus=antenna.link.youngs_modulus,
        linear_density=antenna.link.linear_density,
    )
    theta0 = kinematics.theta[0]
    contact_state = np.zeros(6)
    sim = RodSystem()
    rod = straight_rod(link, N_ELEMENTS, float(theta0[0]), float(theta0[1]))
    scale_fast_modes(rod, FAST_MODE_SCALE)
    sim.append(rod)
    sim.constrain(rod).using(KinematicBase, angles=angles)
    sim.add_forcing_to(rod).using(ea.GravityForces, acc_gravity=np.array([0.0, 0.0, -GRAVITY]))
    sim.add_forcing_to(rod).using(
        PostContact,
        axis_point=np.array(obstacle["point"]),
        axis_dir=np.array(obstacle["direction"]),
        radius=float(obstacle["radius"]),
        rod_radius=link.radius,
        stiffness=scenario.contact_stiffness,
        damping=scenario.contact_damping,
        mu=scenario.friction_coefficient,
        out=contact_state,
    )
    sim.dampen(rod).using(_Damper, time_step=TIME_STEP)
    sim.finalize()
    stepper = ea.PositionVerlet()
    per_sample = round(SAMPLE_PERIOD / TIME_STEP)
    t = -SETTLE_TIME
    while t < -0.5 * TIME_STEP:
        t = stepper.step(sim, t, TIME_STEP)
    t = 0.0
    sag = _settled_sag(rod, link, theta0)
    n = kinematics.t.size
    wrench = np.zeros((n, 6))
    state = np.zeros((n, 6))
    for k in range(n):
        if k:
            for _ in range(per_sample):
                t = stepper.step(sim, t, TIME_STEP)
        th1, th2 = kinematics.theta[k]
        axes = motor_axes(float(th1), float(th2))
        force, moment = base_wrench(rod)
        wrench[k, :3] = axes.T @ force
        wrench[k, 3:] = axes.T @ moment
        state[k] = contact_state
    # ground truth
    touching = state[:, 0] > 0.0
    dx_arc = np.array([arc_length(link, N_ELEMENTS, c) for c in state[:, 1]])
    rng = np.random.default_rng(seed)
    noise = SensorNoise()
    bias = rng.normal(0.0, 1.0, 6) * np.asarray(noise.bias_std)
    measured = wrench + bias + rng.normal(0.0, 1.0, (n, 6)) * np.asarray(noise.wrench_std)
    step = 2.0 * math.pi / (noise.encoder_counts * ENCODER_GEAR)
    theta = np.round(kinematics.theta / step) * step
    metadata = {
        "format": "sensing-antenna-recording/1",
        "sample_period": "0.001",
        "antenna": "paper-2021",
        "description": (
            f"PyElastica rod: {SWEEPS[case]} at x_c = {x_c} m,"
            f" pushed {push} rad past the first touch"
        ),
    }
    metadata.update(_truth(kinematics, state, touching, dx_arc, obstacle, sag))
    metadata["seed"] = str(seed)
    metadata["simulation"] = json.dumps(
        {
            "simulator": f"pyelastica {VERSION} via benchmarks/reference/rod",
            "case": name,
            "kinematics": "theta1, theta2 of sensing_antenna.simulator for the scenario",
            "scenario": {k: v for k, v in asdict(scenario).items() if k != "sensor"},
            "push": {"kind": "rotation", "threshold": push},
            "n_elements": N_ELEMENTS,
            "time_step": TIME_STEP,
            "fast_mode_scale": FAST_MODE_SCALE,
            "damping": DAMPING,
            "contact": "penalty, stick-slip Coulomb, rod radius included",
        },
        default=str,
    )
    # rounded far below the sensor's resolution and the encoder's step, to keep the files small
    recording = Recording(
        t=np.round(kinematics.t, 6),
        theta=np.round(theta, 9),
        force=np.round(measured[:, :3], 6),
        torque=np.round(measured[:, 3:], 8),
        metadata=metadata,
    )
    return recording, sag[3], float(theta0[1]), state


def _settled_sag(rod, link: RodLink, theta0) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """The rod at rest in its sag at t = 0, before the sweep.

    Returns the nodes' arc lengths from O (m), their deflection along Z^m (m), cos(theta2) at
    the start, and the noiseless wrench on the head (fx, fy, fz, tx, ty, tz), motor axes.
    """
    axes = motor_axes(float(theta0[0]), float(theta0[1]))
    nodes = np.arange(rod.position_collection.shape[1], dtype=float)
    arc = np.array([arc_length(link, N_ELEMENTS, c) for c in nodes])
    w = axes[:, 2] @ rod.position_collection
    force, moment = base_wrench(rod)
    wrench = np.concatenate([axes.T @ force, axes.T @ moment])
    return arc, w, math.cos(float(theta0[1])), wrench


def _truth(kinematics, state, touching, arc, obstacle, sag) -> dict[str, str]:
    t = kinematics.t
    truth: dict[str, str] = {}
    if touching.any():
        last = int(np.flatnonzero(touching)[-1])
        truth["true_xc"] = repr(float(arc[last]))
        truth["true_contact_point"] = json.dumps([float(v) for v in state[last, 2:5]])
        truth["true_t_contact"] = repr(float(t[np.flatnonzero(touching)[0]]))
    else:
        truth["true_xc"] = "nan"
        truth["true_contact_point"] = "null"
        truth["true_t_contact"] = "nan"
    truth["true_obstacle"] = json.dumps(obstacle)
    truth["true_t_stop"] = kinematics.metadata.get("true_t_stop", "nan")
    truth["true_in_contact_at_end"] = "true" if touching[-1] else "false"
    window = t >= t[-1] - 0.5
    vertical = obstacle["kind"] == "bar"
    sag_arc, sag_w, sag_cos, _ = sag
    if touching[window].all():
        ratios = []
        for k in np.flatnonzero(window):
            theta1, theta2 = (float(v) for v in kinematics.theta[k])
            axes = motor_axes(theta1, theta2)
            point = state[k, 2:5]
            if vertical:
                # the deflection from the rod's own sag at rest, scaled to the current theta2
                w_g = np.interp(arc[k], sag_arc, sag_w) * math.cos(theta2) / sag_cos
                v, w = float(axes[:, 1] @ point), float(axes[:, 2] @ point)
                ratios.append(math.hypot(v, w - w_g) / float(arc[k]))
            else:
                ratios.append(abs(float(axes[:, 1] @ point)) / float(arc[k]))
        truth["true_deflection_ratio"] = repr(float(np.mean(ratios)))
    else:
        truth["true_deflection_ratio"] = "nan"
    truth["true_slipping_at_end"] = "true" if state[-1, 5] > 0 else "false"
    return truth


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", help="case names to (re)generate")
    parser.add_argument("--case", choices=sorted(SWEEPS), help="only the recordings of this case")
    parser.add_argument("--out", default=str(HERE / "recordings"))
    parser.add_argument(
        "--contact",
        action="store_true",
        help="also write NAME-contact.csv: t, normal force, arc length, sliding (not a recording)",
    )
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for index, (name, case, x_c, push, duration) in enumerate(CASES):
        if args.only and name not in args.only:
            continue
        if args.case and case != args.case:
            continue
        start = time.time()
        recording, settled, theta2, state = run_case(name, case, x_c, push, duration, SEED + index)
        write_recording(recording, out / f"{name}.csv")
        if args.contact:
            rod_link = RodLink(length=paper_antenna().link.length)
            along = [arc_length(rod_link, N_ELEMENTS, c) for c in state[:, 1]]
            arc = np.where(state[:, 0] > 0.0, along, np.nan)
            table = np.column_stack([recording.t, state[:, 0], arc, state[:, 5]])
            np.savetxt(
                out / f"{name}-contact.csv",
                table,
                fmt="%.6g",
                delimiter=",",
                header="t,normal_force,arc_length,sliding",
                comments="",
            )
        meta = recording.metadata
        print(
            f"{name}: true_xc {meta['true_xc']}, deflection {meta['true_deflection_ratio']},"
            f" in contact at end {meta['true_in_contact_at_end']},"
            f" sliding at end {meta['true_slipping_at_end']},"
            f" at rest (theta2 {theta2:.6f}) fx {settled[0]:.6f} fz {settled[2]:.6f}"
            f" ty {settled[4]:.6f}, {time.time() - start:.0f} s",
            flush=True,
        )


if __name__ == "__main__":
    main()
