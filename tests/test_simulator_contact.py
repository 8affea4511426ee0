"""Contact physics: contact-mode frequency vs the beam model (Eq. 4), torque/force ratio (Eq. 18),
penalty convergence, unilateral contact."""

from __future__ import annotations

import math

import numpy as np
import pytest

from _simulator_helpers import RotationAfterForceStop, dominant_frequency
from sensing_antenna.antenna import STANDARD_GRAVITY, paper_antenna
from sensing_antenna.beam import natural_frequencies
from sensing_antenna.simulator import Scenario, simulate_detailed

CONTACT_POINTS = [0.3, 0.55, 0.8, 0.98]


def _shallow_stop() -> RotationAfterForceStop:
    # Stop 0.02 rad after the gravity-free force passes 12 mN (above the 5 mN inertial force of
    # the sweep's acceleration ramp): y_c / x_c of 3 % to 6 %, inside Assumption 1.
    return RotationAfterForceStop(paper_antenna(), force_threshold=0.012, rotation=0.02)


@pytest.mark.parametrize("case", ["azimuthal", "vertical"])
@pytest.mark.parametrize("x_c", CONTACT_POINTS)
def test_contact_frequency_matches_beam_model(case: str, x_c: float) -> None:
    antenna = paper_antenna()
    scenario = Scenario(case=case, contact_point=x_c, noise_scale=0.0, duration=3.5)
    detail = simulate_detailed(antenna, scenario, stop_rule=_shallow_stop())
    rec = detail.recording
    assert detail.stop_index is not None
    assert rec.metadata["true_in_contact_at_end"] == "true"
    true_xc = float(rec.metadata["true_xc"])
    # the contact stays where the sagged link touched: within 1 cm (rolling on the 1 cm radius)
    assert true_xc == pytest.approx(x_c, abs=0.01)
    expected = float(natural_frequencies(antenna.link, true_xc, 1)[0])
    # the dominant torque vibration after the stop (the channel with the largest swing)
    tail = rec.torque[detail.stop_index + 300 :]
    channel = int(np.argmax(np.ptp(tail, axis=0)))
    omega = dominant_frequency(tail[:, channel], 1e-3, 0.6 * expected)
    # 1 %: the brief's requirement; penalty (1e4 N/m vs 3EI/x_c^3 <= 10 N/m) and 16 elements
    # contribute < 0.1 %.
    assert omega == pytest.approx(expected, rel=0.01), (case, x_c, channel)


@pytest.mark.parametrize(
    ("case", "x_c"), [("azimuthal", 0.3), ("azimuthal", 0.8), ("vertical", 0.55)]
)
def test_static_torque_force_ratio_equals_contact_point(case: str, x_c: float) -> None:
    """Eq. 18 with gravity removed (Eq. 19) once the vibration has died out (heavy damping here
    only to shorten the wait; the static state does not depend on it)."""
    antenna = paper_antenna()
    scenario = Scenario(
        case=case, contact_point=x_c, noise_scale=0.0, duration=3.0, damping_ratio=0.1
    )
    detail = simulate_detailed(antenna, scenario, stop_rule=_shallow_stop())
    rec = detail.recording
    force = rec.force[-300:].mean(axis=0)
    torque = rec.torque[-300:].mean(axis=0)
    theta2 = rec.theta[-1, 1]
    weight = antenna.link.mass * STANDARD_GRAVITY
    force_g = weight * np.array([-math.sin(theta2), 0.0, -math.cos(theta2)])
    torque_g = np.array([0.0, 0.5 * weight * antenna.link.length * math.cos(theta2), 0.0])
    ratio = np.linalg.norm(torque - torque_g) / np.linalg.norm(force - force_g)
    true_xc = float(rec.metadata["true_xc"])
    # Azimuthal: 0.5 % (the brief's requirement); the second-order geometry of the bent link
    # (slope y' = 1.5 y_c / x_c at the contact) adds about 0.4 (y_c / x_c)^2, ~0.1 % here.
    # Vertical: the 2 cm gravity sag at the contact tilts the contact normal and adds a moment
    # arm (x_c + w w') / sqrt(1 + w'^2): ~0.6 % at x_c = 0.55 m, so 1 % (docs/simulator.md).
    tolerance = 5e-3 if case == "azimuthal" else 1e-2
    assert ratio == pytest.approx(true_xc, rel=tolerance)


def test_contact_frequency_converges_with_penalty_stiffness() -> None:
    antenna = paper_antenna()
    x_c = 0.55
    expected = float(natural_frequencies(antenna.link, x_c, 1)[0])
    errors = []
    for stiffness in (30.0, 300.0, 3000.0):
        scenario = Scenario(
            case="azimuthal",
            contact_point=x_c,
            noise_scale=0.0,
            duration=3.0,
            contact_stiffness=stiffness,
        )
        detail = simulate_detailed(antenna, scenario, stop_rule=_shallow_stop())
        tail = detail.recording.torque[detail.stop_index + 300 :, 2]
        true_xc = float(detail.recording.metadata["true_xc"])
        reference = float(natural_frequencies(antenna.link, true_xc, 1)[0])
        errors.append(abs(dominant_frequency(tail, 1e-3, 20.0) / reference - 1))
    # a soft support lowers the frequency; the error falls roughly as 1/k
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 0.01
    assert expected > 0


def test_contact_is_unilateral_without_push() -> None:
    """A stop rule that never fires keeps the sweep going; with a frictionless post the link
    slides past... here we check only that the normal force is never negative (no adhesion)."""
    antenna = paper_antenna()
    scenario = Scenario(case="azimuthal", contact_point=0.8, noise_scale=0.0, duration=1.5)
    detail = simulate_detailed(antenna, scenario, stop_rule=_shallow_stop())
    assert np.all(detail.normal_force >= 0.0)
    assert detail.in_contact.any()
    first = int(np.argmax(detail.in_contact))
    # the first touch happens inside the 1 ms before the first sample that shows it
    t_contact = float(detail.recording.metadata["true_t_contact"])
    assert (first - 1) * 1e-3 < t_contact <= first * 1e-3 + 1e-12


def test_obstacle_tilt_turns_the_contact_normal() -> None:
    """A post leaning by ``tilt`` along the sweep gives the contact force a vertical component
    of sin(tilt) of its horizontal one: the imperfection that excites the Z^c bending."""
    antenna = paper_antenna()
    ratios = []
    for tilt in (0.0, 0.05):
        scenario = Scenario(
            case="azimuthal", contact_point=0.55, noise_scale=0.0, duration=2.0, obstacle_tilt=tilt
        )
        detail = simulate_detailed(antenna, scenario, stop_rule=_shallow_stop())
        assert detail.obstacle is not None
        axis = np.array(detail.obstacle.direction)
        ratios.append(float(axis[1] / axis[2]))
    assert ratios[0] == pytest.approx(0.0, abs=1e-12)
    assert ratios[1] == pytest.approx(math.tan(0.05), rel=1e-9)
