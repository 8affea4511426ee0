"""Checks of the PyElastica rod against the project's beam model and the closed-form elastica.

Writes ``checks.json`` beside this script. Needs PyElastica (``requirements.txt``)::

    PYTHONPATH=src python3 benchmarks/reference/rod/checks.py

1. Contact frequencies. The paper's link clamped at the base and pinned at x_c (its lateral
   displacement held at the node there), released straight under gravity, rings in its first
   contact mode; the frequency of the base moment (FFT, Hann window, peak interpolated) is set
   against ``sensing_antenna.beam.natural_frequencies`` (what ``antenna beam`` prints), for three
   x_c on nodes of the mesh. Target: within 1 %.
2. Large deflection. The link as a cantilever, no gravity, under a vertical dead load P at the tip
   with alpha = P l^2 / (E I) = 1, 2 and 5, damped to rest; the tip's deflection and abscissa
   are set against the elastica, solved here by shooting on EI theta'' = -P cos(theta),
   theta(0) = 0, theta'(l) = 0 (Bisshopp and Drucker 1945 tabulate the same curve: at alpha = 1
   the tip drops 0.302 l).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import elastica as ea
import numpy as np
from elastica.version import VERSION
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from engine import (  # noqa: E402
    GRAVITY,
    KinematicBase,
    PinnedNode,
    RodLink,
    RodSystem,
    arc_length,
    base_wrench,
    scale_fast_modes,
    straight_rod,
)

from sensing_antenna import paper_antenna  # noqa: E402
from sensing_antenna.beam.modes import natural_frequencies  # noqa: E402

N_ELEMENTS = 40
FAST_MODE_SCALE = 100.0
TIME_STEP = 1.25e-5


def _still(_t: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, 0.0, 0.0)


def contact_frequency(link: RodLink, node: int, duration: float = 1.0) -> float:
    """omega_1 (rad/s) of the rod clamped at O and pinned at ``node``, from the base moment."""
    sim = RodSystem()
    rod = straight_rod(link, N_ELEMENTS)
    scale_fast_modes(rod, FAST_MODE_SCALE)
    sim.append(rod)
    sim.constrain(rod).using(KinematicBase, angles=_still)
    sim.constrain(rod).using(PinnedNode, node=node)
    sim.add_forcing_to(rod).using(ea.GravityForces, acc_gravity=np.array([0.0, 0.0, -GRAVITY]))
    sim.finalize()
    stepper = ea.PositionVerlet()
    every = 8
    n_steps = round(duration / TIME_STEP)
    moment = []
    t = 0.0
    for k in range(n_steps):
        t = stepper.step(sim, t, TIME_STEP)
        if k % every == 0:
            moment.append(base_wrench(rod)[1][1])
    signal = np.asarray(moment) - np.mean(moment)
    signal *= np.hanning(signal.size)
    n_fft = 1 << 20
    spectrum = np.abs(np.fft.rfft(signal, n_fft))
    omega = 2.0 * math.pi * np.fft.rfftfreq(n_fft, every * TIME_STEP)
    k = int(np.argmax(spectrum[1:])) + 1
    a, b, c = np.log(spectrum[k - 1 : k + 2])
    shift = 0.5 * (a - c) / (a - 2.0 * b + c)
    return float(omega[k] + shift * (omega[1] - omega[0]))


def elastica_tip(alpha: float) -> tuple[float, float]:
    """Tip deflection and abscissa (fractions of l) of the elastica under alpha = P l^2 / EI."""

    def rhs(_s: float, y: np.ndarray) -> list[float]:
        theta, dtheta, _x, _z = y
        return [dtheta, -alpha * math.cos(theta), math.cos(theta), math.sin(theta)]

    def end_slope(k0: float) -> float:
        sol = solve_ivp(rhs, (0.0, 1.0), [0.0, k0, 0.0, 0.0], rtol=1e-11, atol=1e-12)
        return float(sol.y[1, -1])

    k0 = brentq(end_slope, 1e-9, alpha, xtol=1e-13)
    sol = solve_ivp(rhs, (0.0, 1.0), [0.0, k0, 0.0, 0.0], rtol=1e-11, atol=1e-12)
    return float(sol.y[3, -1]), float(sol.y[2, -1])


def rod_tip(link: RodLink, alpha: float, duration: float = 2.0) -> tuple[float, float]:
    """Tip deflection and abscissa (fractions of l) of the PyElastica cantilever at rest."""
    load = alpha * link.flexural_rigidity / link.length**2
    sim = RodSystem()
    rod = straight_rod(link, N_ELEMENTS)
    scale_fast_modes(rod, FAST_MODE_SCALE)
    sim.append(rod)
    sim.constrain(rod).using(KinematicBase, angles=_still)
    sim.add_forcing_to(rod).using(
        ea.EndpointForces,
        start_force=np.zeros(3),
        end_force=np.array([0.0, 0.0, -load]),
        ramp_up_time=0.3,
    )
    sim.dampen(rod).using(
        ea.AnalyticalLinearDamper, uniform_damping_constant=20.0, time_step=TIME_STEP
    )
    sim.finalize()
    stepper = ea.PositionVerlet()
    t = 0.0
    for _ in range(round(duration / TIME_STEP)):
        t = stepper.step(sim, t, TIME_STEP)
    tip = rod.position_collection[:, -1]
    return float(-tip[2] / link.length), float(tip[0] / link.length)


def main() -> None:
    link = RodLink()
    model = paper_antenna().link
    frequencies = []
    for node in (12, 20, 32):
        x_c = arc_length(link, N_ELEMENTS, node)
        rod_omega = contact_frequency(link, node)
        beam_omega = float(natural_frequencies(model, x_c)[0])
        frequencies.append(
            {
                "x_c": x_c,
                "omega1_rod": rod_omega,
                "omega1_beam": beam_omega,
                "relative_error": rod_omega / beam_omega - 1.0,
            }
        )
        print(frequencies[-1], flush=True)
    tips = []
    for alpha in (1.0, 2.0, 5.0):
        rod_dz, rod_x = rod_tip(link, alpha)
        ref_dz, ref_x = elastica_tip(alpha)
        tips.append(
            {
                "alpha": alpha,
                "tip_deflection_rod": rod_dz,
                "tip_deflection_elastica": ref_dz,
                "tip_abscissa_rod": rod_x,
                "tip_abscissa_elastica": ref_x,
                "deflection_error": rod_dz - ref_dz,
                "linear_theory_deflection": alpha / 3.0,
            }
        )
        print(tips[-1], flush=True)
    result = {
        "engine": f"pyelastica {VERSION}",
        "n_elements": N_ELEMENTS,
        "time_step": TIME_STEP,
        "fast_mode_scale": FAST_MODE_SCALE,
        "contact_frequencies": frequencies,
        "cantilever_tip_load": tips,
    }
    (HERE / "checks.json").write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()
