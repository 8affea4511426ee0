"""Checks of the PyElastica rod against the project's beam model and the closed-form elastica.

Writes ``checks.json`` beside this script (the sections run replace theirs, the others are
kept). Needs PyElastica (``requirements.txt``)::

    PYTHONPATH=src python3 benchmarks/reference/rod/checks.py [--sections NAME ...]

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
3. Sag at rest (``sag``). The rod held by the head at the sweeps' start poses (azimuthal: theta1
   = -0.108 rad, theta2 = 0; vertical: theta2 = -0.108 rad, tilted down) and at theta2 = +0.3
   rad, settled under gravity (1 s damped at 32 /s, as generate.py settles the rod before a
   recording): the noiseless wrench on the head
   against the recording format's sign check, F = -m_b g (sin theta2, 0, cos theta2) and
   ty = +0.5 m_b g l cos theta2 (the straight link's figure; the sag shortens the weight's arm),
   and the tip's sag along Z^m against the linear cantilever's -q l^4 / (8 E I) cos theta2.
4. Recordings (``recordings``; reads the files, runs no rod). In each recording that ends in
   a sticking contact, the link rings against the obstacle after the stop: the frequency of
   the bending moment (tz azimuthal, ty vertical; FFT from true_t_stop + 0.05 s to the end,
   linear trend removed, Hann window, the highest peak within 0.6 to 1.4 times the expected
   value, interpolated) against ``natural_frequencies`` at the recording's ``true_xc``, with
   the peak's height over the spectrum's median from 10 to 400 rad/s, to say whether the
   ringing stands out of the noise. The strongest peak overall is reported too (at some x_c
   the second contact mode rings louder).
"""

from __future__ import annotations

import argparse
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
    motor_axes,
    scale_fast_modes,
    straight_rod,
)

from sensing_antenna import paper_antenna  # noqa: E402
from sensing_antenna.beam.modes import natural_frequencies  # noqa: E402
from sensing_antenna.recording import read_recording  # noqa: E402

N_ELEMENTS = 40
FAST_MODE_SCALE = 100.0
TIME_STEP = 1.25e-5
RECORDINGS = HERE / "recordings"
SECTIONS = ("frequencies", "tip", "sag", "recordings")
#: Settling of the sag check: generate.py's (1 s at 32 /s, critical for the first free mode).
SETTLE_TIME = 1.0
SETTLE_DAMPING = 32.0
#: Head poses (theta1, theta2) of the sag check (rad): the sweeps' start poses and one tilted up.
SAG_POSES = {
    "azimuthal start": (-0.1081022, 0.0),
    "vertical start": (0.0, -0.1081022),
    "tilted up": (0.0, 0.3),
}
#: Band (rad/s) of the spectrum's median and strongest peak in the recordings.
RING_BAND = (10.0, 400.0)
#: Where the first contact mode is looked for, as fractions of the beam's omega_1.
RING_SEARCH = (0.6, 1.4)


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


def settled(link: RodLink, theta1: float, theta2: float) -> tuple[np.ndarray, float]:
    """Noiseless wrench on the head (fx, fy, fz, tx, ty, tz; N, N m, motor axes) and tip sag
    along Z^m (m) of the rod at rest under gravity, the head still at (theta1, theta2)."""

    def still(_t: float) -> tuple[float, float, float, float]:
        return (theta1, theta2, 0.0, 0.0)

    sim = RodSystem()
    rod = straight_rod(link, N_ELEMENTS, theta1, theta2)
    scale_fast_modes(rod, FAST_MODE_SCALE)
    sim.append(rod)
    sim.constrain(rod).using(KinematicBase, angles=still)
    sim.add_forcing_to(rod).using(ea.GravityForces, acc_gravity=np.array([0.0, 0.0, -GRAVITY]))
    sim.dampen(rod).using(
        ea.AnalyticalLinearDamper, uniform_damping_constant=SETTLE_DAMPING, time_step=TIME_STEP
    )
    sim.finalize()
    stepper = ea.PositionVerlet()
    t = 0.0
    for _ in range(round(SETTLE_TIME / TIME_STEP)):
        t = stepper.step(sim, t, TIME_STEP)
    axes = motor_axes(theta1, theta2)
    force, moment = base_wrench(rod)
    sag = float(axes[:, 2] @ rod.position_collection[:, -1])
    return np.concatenate([axes.T @ force, axes.T @ moment]), sag


def sag_checks(link: RodLink) -> list[dict[str, object]]:
    weight = link.linear_density * link.length * GRAVITY
    linear_tip = link.linear_density * GRAVITY * link.length**4 / (8.0 * link.flexural_rigidity)
    out: list[dict[str, object]] = []
    for pose, (theta1, theta2) in SAG_POSES.items():
        wrench, sag = settled(link, theta1, theta2)
        c2, s2 = math.cos(theta2), math.sin(theta2)
        expected_ty = 0.5 * weight * link.length * c2
        out.append(
            {
                "pose": pose,
                "theta1": theta1,
                "theta2": theta2,
                "wrench_rod": [float(v) for v in wrench],
                "fx_sign_check": -weight * s2,
                "fz_sign_check": -weight * c2,
                "ty_sign_check": expected_ty,
                "ty_relative_difference": float(wrench[4]) / expected_ty - 1.0,
                "tip_sag_rod": sag,
                "tip_sag_linear": -linear_tip * c2,
                "tip_sag_relative_difference": sag / (-linear_tip * c2) - 1.0,
            }
        )
        print(out[-1], flush=True)
    return out


def ringing_frequency(path: Path) -> dict[str, object]:
    """The recording's ringing after the stop against the beam's omega_1 at its true_xc."""
    recording = read_recording(path)
    meta = recording.metadata
    vertical = json.loads(meta["true_obstacle"])["kind"] == "bar"
    truth = float(meta["true_xc"])
    row: dict[str, object] = {
        "recording": path.stem,
        "true_xc": truth,
        "true_deflection_ratio": float(meta["true_deflection_ratio"]),
        "component": "ty" if vertical else "tz",
    }
    if (
        meta["true_in_contact_at_end"] != "true"
        or meta.get("true_slipping_at_end", "false") != "false"
    ):
        row["omega1_recording"] = None
        row["note"] = "not in a sticking contact at the end"
        return row
    t = recording.t
    window = t >= float(meta["true_t_stop"]) + 0.05
    signal = recording.torque[window, 1 if vertical else 2]
    trend = np.polyval(np.polyfit(t[window], signal, 1), t[window])
    signal = (signal - trend) * np.hanning(signal.size)
    n_fft = 1 << 18
    spectrum = np.abs(np.fft.rfft(signal, n_fft))
    omega = 2.0 * math.pi * np.fft.rfftfreq(n_fft, float(t[1] - t[0]))
    beam = float(natural_frequencies(paper_antenna().link, truth)[0])

    def peak(low: float, high: float) -> tuple[float, float]:
        inside = np.flatnonzero((omega >= low) & (omega <= high))
        k = int(inside[np.argmax(spectrum[inside])])
        a, b, c = np.log(spectrum[k - 1 : k + 2])
        shift = 0.5 * (a - c) / (a - 2.0 * b + c)
        return float(omega[k] + shift * (omega[1] - omega[0])), float(spectrum[k])

    found, height = peak(RING_SEARCH[0] * beam, RING_SEARCH[1] * beam)
    strongest, _ = peak(*RING_BAND)
    band = (omega >= RING_BAND[0]) & (omega <= RING_BAND[1])
    row.update(
        {
            "omega1_recording": found,
            "omega1_beam": beam,
            "relative_error": found / beam - 1.0,
            "peak_over_median": height / float(np.median(spectrum[band])),
            "strongest_peak": strongest,
            "window_s": float(t[window][-1] - t[window][0]),
        }
    )
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sections", nargs="*", choices=SECTIONS, default=list(SECTIONS))
    args = parser.parse_args()
    path = HERE / "checks.json"
    result = json.loads(path.read_text()) if path.exists() else {}
    result.update(
        {
            "engine": f"pyelastica {VERSION}",
            "n_elements": N_ELEMENTS,
            "time_step": TIME_STEP,
            "fast_mode_scale": FAST_MODE_SCALE,
        }
    )
    link = RodLink()
    if "frequencies" in args.sections:
        result["contact_frequencies"] = frequency_checks(link)
    if "tip" in args.sections:
        result["cantilever_tip_load"] = tip_checks(link)
    if "sag" in args.sections:
        result["sag_at_rest"] = sag_checks(link)
    if "recordings" in args.sections:
        rows = [ringing_frequency(p) for p in sorted(RECORDINGS.glob("*.csv"))]
        for row in rows:
            print(row, flush=True)
        result["recordings_ringing"] = rows
    path.write_text(json.dumps(result, indent=2) + "\n")


def frequency_checks(link: RodLink) -> list[dict[str, float]]:
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
    return frequencies


def tip_checks(link: RodLink) -> list[dict[str, float]]:
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
    return tips


if __name__ == "__main__":
    main()
