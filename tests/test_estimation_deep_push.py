"""Pushes that bend the link by a fifth to a third of x_c, on the simulator's geometrically exact
link: the sensing curves are the straight link's, so an answer is right within 2 cm or says why
not. At 0.6 m pushed 0.3 rad the two-frequency method's measured pair lies 37 to 40 % off the
curve, whose nearest point is 7 cm from the contact.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from sensing_antenna import paper_antenna
from sensing_antenna.antenna import NOMINAL_SENSOR_COUPLING, load_antenna
from sensing_antenna.detection.push import PushCriterion
from sensing_antenna.estimation import METHODS, estimate, gather
from sensing_antenna.simulator import DeviceImperfections, Scenario, simulate
from sensing_antenna.simulator.device import device_profile

DEVICE = paper_antenna()
DEVICE = dataclasses.replace(DEVICE, link=dataclasses.replace(DEVICE.link, youngs_modulus=132.65e9))
MODEL = dataclasses.replace(DEVICE, name="model").self_calibrated()

#: The product's promise: an `ok` answer is right within this (m).
OK_TOLERANCE = 0.02

DATA = Path(__file__).parent / "data"


@pytest.mark.parametrize(
    "case, x_c, push",
    [
        ("azimuthal", 0.6, 0.3),
        ("vertical", 0.6, 0.3),
        ("azimuthal", 0.5, 0.3),
        ("vertical", 0.35, 0.2),
        ("azimuthal", 0.7, 0.2),
        ("vertical", 0.9, 0.2),
    ],
)
def test_a_deep_push_is_right_or_said(case: str, x_c: float, push: float) -> None:
    scenario = Scenario(
        case=case,
        contact_point=x_c,
        seed=int(1000 * x_c + 100 * push),
        push=PushCriterion(threshold=push),
        link_model="nonlinear",
        duration=4.0,
    )
    recording = simulate(DEVICE, scenario)
    touched = float(recording.metadata["true_xc"])
    blind = recording.without_ground_truth()
    deflections = []
    for method in sorted(METHODS):
        result = estimate(blind, MODEL, method)
        deflections.append(result.diagnostics.get("deflection_ratio", 0.0))
        if result.status.value == "ok":
            assert abs(result.x_c - touched) <= OK_TOLERANCE, (method, result.x_c, touched)
    # the push did bend the link beyond the small-deflection range
    assert max(deflections) > 0.15


@pytest.mark.parametrize(
    ("case", "x_c", "push"), [("vertical", 0.9, 0.25), ("azimuthal", 0.7, 0.15)]
)
def test_the_axial_forces_cross_talk_moves_the_ratio_as_its_term_says(
    case: str, x_c: float, push: float
) -> None:
    # A sensor whose push moment leaks into its axial force (c N per N m, the model's nominal
    # cross-talk) moves the elastica's ratio x_c = (Gamma' + y_c R_x) / |R_perp| by about
    # c y_c x_c = c d x_c^2: 5 to 15 cm at these 20 to 30 % pushes, which no calibration of the
    # lateral forces measures. The ratio's cross-talk term for that leak holds it to first
    # order (the ratio's own error without the leak is under a tenth of it); second order
    # moves it by up to half (x_c / (1 - c y_c) is not x_c (1 + c y_c) at c y_c = 0.15)
    device = paper_antenna()
    model = device.self_calibrated()
    c = NOMINAL_SENSOR_COUPLING
    # the lateral forces' terms measured (a calibration's scatter), the axial one not
    model = dataclasses.replace(
        model, sensor=dataclasses.replace(model.sensor, nominal_coupling=c, ratio_scatter=0.01)
    )
    torque = 4 if case == "vertical" else 5  # the push's moment: about Y^m or Z^m
    errors = []
    for leak in (0.0, -c, c):
        coupling = [[0.0] * 6 for _ in range(6)]
        coupling[0][torque] = leak
        scenario = Scenario(
            case=case,
            contact_point=x_c,
            seed=5,
            link_model="nonlinear",
            push=PushCriterion(threshold=push),
            device=DeviceImperfections(sensor_coupling=tuple(map(tuple, coupling))),
        )
        recording = simulate(device, scenario)
        touched = float(recording.metadata["true_xc"])
        evidence = gather(recording.without_ground_truth(), model)
        term = float(evidence.axial_cross_talk_uncertainty(np.array(touched)))
        errors.append(float(evidence.ratio_mean[evidence.end_index]) - touched)
        assert term > 0.04
    clean, low, high = (abs(error) / term for error in errors)
    assert clean < 0.1
    assert 0.6 < min(low, high) and max(low, high) < 1.6


def test_a_deep_pushs_ratio_does_not_choose_the_branch_its_axial_leak_may_have_moved() -> None:
    # Run vertical-x0900mm-r1 of benchmarks/campaign-hard-push.toml: the default campaign's
    # realistic device (its sensor leaks the push moment into the axial force), its model as
    # that campaign prepared it (observer identified; T_e, tip mass and the lateral forces'
    # cross-talk calibrated at the default push), a push of 0.25 rad at 0.9 m on the exact link.
    # The free plane's omega_1 fits a contact at 0.68 m and one at 0.91 m; the ratio reads
    # 0.74 m (the axial leak through the elastica's y_c R_x, which the calibration did not
    # measure) and chose the near one: ok, 23 cm off. The branch must not rest on that ratio.
    model = load_antenna(DATA / "deep_push_model.toml")
    device = load_antenna(DATA / "deep_push_device.toml")
    seed = 3924558764
    scenario = Scenario(
        case="vertical",
        contact_point=0.9,
        seed=seed,
        damping_ratio=0.005,
        noise_scale=1.0,
        link_model="nonlinear",
        push=PushCriterion(threshold=0.25),
        device=device_profile("realistic", seed, device.link.length, 2021),
    )
    recording = simulate(device, scenario)
    touched = float(recording.metadata["true_xc"])
    result = estimate(recording.without_ground_truth(), model, "paper")
    assert result.status.value != "ok" or abs(result.x_c - touched) <= OK_TOLERANCE, (
        result.status,
        result.x_c,
        touched,
    )
    # the ratio is as far off as described: the test still reads that case
    assert touched - result.ratio_estimate > 0.1
