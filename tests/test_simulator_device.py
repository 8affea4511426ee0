"""The simulated device's imperfections: off is the nominal device bit for bit, on has its physics.

References: the spring-clamped cantilever's characteristic equation (derived below from the
Euler-Bernoulli mode and its four boundary conditions), the beam module's contact frequencies
with a tip mass (Eq. 4 with the tip-mass condition), the clamped-free root 1.87510407 (Blevins,
Formulas for Natural Frequency and Mode Shape, Table 8-1) and the tip deflection of a cantilever
of varying E I by the unit-load method, ``delta = P int_0^l (l - x)^2 / EI(x) dx``.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from sensing_antenna.antenna import Antenna, paper_antenna
from sensing_antenna.beam import natural_frequencies
from sensing_antenna.campaign import CampaignSpec, parse_campaign_spec, run_campaign
from sensing_antenna.campaign.runs import expand_runs
from sensing_antenna.campaign.schema import CampaignSpecError
from sensing_antenna.cli import main
from sensing_antenna.estimation import measure_omega1
from sensing_antenna.simulator import (
    DeviceError,
    DeviceImperfections,
    Scenario,
    ScenarioError,
    realistic_device,
    simulate,
    simulate_detailed,
)
from sensing_antenna.simulator.contact import motor_frame
from sensing_antenna.simulator.device import NANO17_FULL_SCALE
from sensing_antenna.simulator.link import build_link_model

CLAMPED_FREE_ROOT = 1.87510407


def _arrays(detail):  # type: ignore[no-untyped-def]
    rec = detail.recording
    return [
        rec.t,
        rec.theta,
        rec.force,
        rec.torque,
        rec.extra["theta1_ref"],
        rec.extra["theta2_ref"],
        detail.true_theta,
        detail.contact_abscissa,
        detail.contact_point,
        detail.normal_force,
        detail.final_deflection,
    ]


@pytest.mark.parametrize("case, x_c", [("azimuthal", 0.55), ("vertical", 0.8)])
def test_default_imperfections_are_bit_identical(case: str, x_c: float) -> None:
    antenna = paper_antenna()
    scenario = Scenario(case=case, contact_point=x_c, seed=7, duration=2.0)
    plain = simulate_detailed(antenna, scenario)
    explicit = simulate_detailed(
        antenna, dataclasses.replace(scenario, device=DeviceImperfections())
    )
    for a, b in zip(_arrays(plain), _arrays(explicit), strict=True):
        np.testing.assert_array_equal(a, b)
    assert DeviceImperfections().is_nominal


def test_neutral_values_of_each_imperfection_are_bit_identical() -> None:
    """Each field set to its neutral value explicitly (a joint of factor 1, a taper of 1):
    the nominal device again, bit for bit."""
    antenna = paper_antenna()
    scenario = Scenario(case="azimuthal", contact_point=0.45, seed=3, duration=2.0)
    neutral = DeviceImperfections(
        tip_mass=0.0,
        stiffness_taper=1.0,
        density_taper=1.0,
        joint_start=0.3,
        joint_length=0.05,
        joint_stiffness_factor=1.0,
        joint_density_factor=1.0,
        sensor_gain=(1.0,) * 6,  # type: ignore[arg-type]
        encoder_offset=(0.0, 0.0),
        bow=(0.0, 0.0),
    )
    plain = simulate_detailed(antenna, scenario)
    other = simulate_detailed(antenna, dataclasses.replace(scenario, device=neutral))
    for a, b in zip(_arrays(plain), _arrays(other), strict=True):
        np.testing.assert_array_equal(a, b)


def test_uniform_taper_and_joint_of_factor_one_equal_the_uniform_link() -> None:
    link = paper_antenna().link
    uniform = build_link_model(link, 16)
    # a taper of 1 with a tip mass of 0 still goes through the per-element assembly when the
    # clamp is compliant; compare that path with and without a taper of exactly 1
    sprung = build_link_model(link, 16, DeviceImperfections(clamp_stiffness=30.0))
    sprung_taper = build_link_model(
        link,
        16,
        DeviceImperfections(
            clamp_stiffness=30.0, stiffness_taper=1.0, joint_length=0.1, joint_start=0.2
        ),
    )
    np.testing.assert_array_equal(sprung.stiffness, sprung_taper.stiffness)
    np.testing.assert_array_equal(sprung.mass, sprung_taper.mass)
    # the compliant clamp keeps the root slope: one more coordinate; without the spring's
    # term its stiffness block beyond the root slope is the uniform link's
    assert sprung.n_dof == uniform.n_dof + 1
    np.testing.assert_array_equal(sprung.stiffness[1:, 1:], uniform.stiffness)


def test_tip_mass_lowers_contact_frequency_as_the_beam_model_predicts() -> None:
    """The device carries a tip mass the model does not: its omega_1 at x_c is the beam model's
    for a link with that tip mass (Eq. 4 with the tip-mass boundary condition)."""
    link = paper_antenna().link
    tip = 0.5e-3  # kg, 11 % of the link's 4.6 g
    heavy = dataclasses.replace(link, tip_mass=tip)
    model = build_link_model(link, 32, DeviceImperfections(tip_mass=tip))
    for x_c in (0.3, 0.55, 0.8):
        expected = float(natural_frequencies(heavy, x_c, 1)[0])
        nominal = float(natural_frequencies(link, x_c, 1)[0])
        fe = float(model.pinned_frequencies(x_c, 1)[0])
        assert expected < nominal  # the mass lowers it, by more than the FE error below
        # 32 Hermite elements: the FE error is below 1e-6 relative (test_simulator_link)
        assert fe == pytest.approx(expected, rel=1e-5)


def test_tip_mass_in_a_recording_shifts_measured_omega1() -> None:
    """Through the whole simulator: the omega_1 measured in a recording of the device with the
    tip mass is the beam model's for that tip mass, not the nominal one (within 1 %, the
    frequency measurement's resolution on a 3 s noiseless recording, well below the 5 % shift)."""
    antenna = paper_antenna()
    tip = 0.5e-3
    x_c = 0.55
    scenario = Scenario(
        case="azimuthal",
        contact_point=x_c,
        seed=1,
        noise_scale=0.0,
        device=DeviceImperfections(tip_mass=tip),
    )
    recording = simulate(antenna, scenario)
    true_xc = float(recording.metadata["true_xc"])
    measured = measure_omega1(recording.without_ground_truth(), antenna, band=(10.0, 150.0))
    heavy = dataclasses.replace(antenna.link, tip_mass=tip)
    expected = float(natural_frequencies(heavy, true_xc, 1)[0])
    nominal = float(natural_frequencies(antenna.link, true_xc, 1)[0])
    assert nominal / expected - 1 > 0.04
    assert measured.omega1 == pytest.approx(expected, rel=0.01)


def _spring_clamped_root(kappa: float) -> float:
    """First root lambda = beta l of a cantilever whose root turns against a rotational spring
    k, with kappa = k l / (E I).

    Mode w = a cosh(bx) + b sinh(bx) + c cos(bx) + d sin(bx); boundary conditions, in
    lambda = b l and s = x / l: w(0) = 0; E I w''(0) = k w'(0), i.e. lambda (a - c) =
    kappa (b + d); w''(l) = 0 and w'''(l) = 0 (free end). A non-trivial mode needs the
    determinant of these four rows to vanish.
    """

    def det(lam: float) -> float:
        ch, sh, c, s = math.cosh(lam), math.sinh(lam), math.cos(lam), math.sin(lam)
        rows = np.array(
            [
                [1.0, 0.0, 1.0, 0.0],
                [lam, -kappa, -lam, -kappa],
                [ch, sh, -c, -s],
                [sh, ch, s, -c],
            ]
        )
        return float(np.linalg.det(rows))

    grid = np.linspace(0.05, CLAMPED_FREE_ROOT + 1e-6, 400)
    values = [det(x) for x in grid]
    for i in range(len(grid) - 1):
        if values[i] == 0.0 or values[i] * values[i + 1] < 0:
            return float(brentq(det, grid[i], grid[i + 1], xtol=1e-14))
    raise AssertionError("no root below the clamped-free one")


@pytest.mark.parametrize("stiffness", [2.0, 20.0, 100.0])
def test_clamp_spring_lowers_free_frequency_as_the_closed_form_predicts(stiffness: float) -> None:
    link = paper_antenna().link
    ei, rho, length = link.flexural_rigidity, link.linear_density, link.length
    lam = _spring_clamped_root(stiffness * length / ei)
    expected = lam**2 * math.sqrt(ei / (rho * length**4))
    rigid = CLAMPED_FREE_ROOT**2 * math.sqrt(ei / (rho * length**4))
    fe = float(build_link_model(link, 32, DeviceImperfections(clamp_stiffness=stiffness))
               .free_frequencies(1)[0])  # fmt: skip
    assert expected < rigid
    # 32 Hermite elements: discretisation below 1e-6 relative
    assert fe == pytest.approx(expected, rel=1e-5)


def test_a_very_stiff_clamp_is_the_rigid_clamp() -> None:
    link = paper_antenna().link
    rigid = float(build_link_model(link, 16).free_frequencies(1)[0])
    stiff = float(
        build_link_model(link, 16, DeviceImperfections(clamp_stiffness=1e6)).free_frequencies(1)[0]
    )
    # delta omega / omega ~ 2 E I / (k l) = 2e-7 at k = 1e6 N m/rad (a stiffer spring only
    # worsens the conditioning of K)
    assert stiff == pytest.approx(rigid, rel=1e-6)
    assert stiff < rigid


def test_joint_over_the_whole_link_scales_the_frequency() -> None:
    """A joint covering [0, l] with E I and rho factors f_k, f_rho is a uniform link of
    E I f_k and rho f_rho: omega_1 scales by sqrt(f_k / f_rho)."""
    link = paper_antenna().link
    nominal = float(build_link_model(link, 16).free_frequencies(1)[0])
    device = DeviceImperfections(
        joint_start=0.0,
        joint_length=link.length,
        joint_stiffness_factor=2.0,
        joint_density_factor=1.5,
    )
    scaled = float(build_link_model(link, 16, device).free_frequencies(1)[0])
    # exact but for the eigensolver's rounding (about 1e-10 relative)
    assert scaled == pytest.approx(nominal * math.sqrt(2.0 / 1.5), rel=1e-9)


@pytest.mark.parametrize("taper", [0.7, 1.3])
def test_taper_tip_deflection_matches_unit_load_integral(taper: float) -> None:
    """Static tip deflection under a tip load P on the tapered link against
    P int_0^l (l - x)^2 / EI(x) dx with EI(x) linear, ratio ``taper`` tip/root, mean E I."""
    link = paper_antenna().link
    ei, length = link.flexural_rigidity, link.length
    root = 2.0 / (taper + 1.0)
    tip = 2.0 * taper / (taper + 1.0)

    def profile(x: float) -> float:
        return ei * (root + (tip - root) * x / length)

    expected, _ = quad(lambda x: (length - x) ** 2 / profile(x), 0.0, length)
    model = build_link_model(link, 64, DeviceImperfections(stiffness_taper=taper))
    load = model.shape_at(length)  # generalised force of a unit tip load
    deflection = float(model.shape_at(length) @ np.linalg.solve(model.stiffness, load))
    # midpoint E I per element: O(h^2) error, about 1e-5 relative at 64 elements
    assert deflection == pytest.approx(expected, rel=2e-4)
    uniform = length**3 / (3 * ei)
    assert abs(deflection / uniform - 1) > 0.01  # the taper matters at this size


def test_sensor_gain_coupling_and_drift_appear_exactly_in_the_recording() -> None:
    """The free case (no stop rule, so the motion is the same): the recorded wrench is
    diag(g) (I + C) w + rate t for the nominal recording's w."""
    antenna = paper_antenna()
    rng = np.random.default_rng(0)
    full = np.asarray(NANO17_FULL_SCALE)
    eps = rng.uniform(-0.01, 0.01, size=(6, 6))
    np.fill_diagonal(eps, 0.0)
    coupling = eps * full[:, None] / full[None, :]
    gain = (1.01, 0.99, 1.005, 0.995, 1.02, 0.98)
    rate = (1e-3, -2e-3, 0.5e-3, 1e-6, -1e-6, 2e-6)
    device = DeviceImperfections(
        sensor_gain=gain,
        sensor_coupling=tuple(tuple(row) for row in coupling),  # type: ignore[arg-type]
        sensor_drift_rate=rate,
    )
    scenario = Scenario(case="free", seed=5, duration=1.5)
    nominal = simulate(antenna, scenario)
    imperfect = simulate(antenna, dataclasses.replace(scenario, device=device))
    wrench = np.hstack([nominal.force, nominal.torque])
    expected = wrench @ (np.asarray(gain)[:, None] * (np.eye(6) + coupling)).T
    expected += nominal.t[:, None] * np.asarray(rate)[None, :]
    got = np.hstack([imperfect.force, imperfect.torque])
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(imperfect.theta, nominal.theta)


def test_sensor_random_walk_has_its_stated_intensity() -> None:
    antenna = paper_antenna()
    walk = (2e-3, 1e-3, 1e-3, 1e-5, 1e-5, 2e-5)
    scenario = Scenario(case="free", seed=9, duration=3.0)
    nominal = simulate(antenna, scenario)
    imperfect = simulate(
        antenna, dataclasses.replace(scenario, device=DeviceImperfections(sensor_drift_walk=walk))
    )
    offset = np.hstack([imperfect.force - nominal.force, imperfect.torque - nominal.torque])
    steps = np.diff(offset, axis=0)
    # increments of std walk sqrt(T_s); 2999 of them: the sample std is within 5 % (4 sigma)
    np.testing.assert_allclose(steps.std(axis=0), np.asarray(walk) * math.sqrt(1e-3), rtol=0.05)
    assert np.all(offset[0] == 0.0)


def test_encoder_offsets_shift_the_recorded_angles_exactly() -> None:
    antenna = paper_antenna()
    offsets = (0.01, -0.004)
    scenario = Scenario(case="free", seed=2, duration=1.5)
    nominal = simulate(antenna, scenario)
    shifted = simulate(
        antenna, dataclasses.replace(scenario, device=DeviceImperfections(encoder_offset=offsets))
    )
    np.testing.assert_array_equal(shifted.theta, nominal.theta + np.asarray(offsets))
    np.testing.assert_array_equal(shifted.force, nominal.force)


def test_realistic_profile_is_reproducible_and_differs_between_seeds() -> None:
    first = realistic_device(11)
    assert realistic_device(11) == first
    assert realistic_device(12) != first
    for seed in range(20):
        device = realistic_device(seed)
        assert 0.0 <= device.tip_mass <= 0.1e-3
        assert device.clamp_stiffness is not None and 15.0 <= device.clamp_stiffness <= 100.0
        assert 0.92 <= device.stiffness_taper <= 1.08
        assert all(abs(g - 1) <= 0.01 for g in device.sensor_gain)
        assert all(abs(v) <= 0.005 for v in device.encoder_offset)
        assert not device.is_nominal


def _realistic_spec(device: dict[str, object]) -> object:
    return parse_campaign_spec(
        {
            "name": "t",
            "antenna": "paper-2021",
            "cases": ["azimuthal"],
            "contact_points": [0.5],
            "repeats": 3,
            "base_seed": 1,
            "device": device,
        },
        "test",
    )


def test_campaign_realistic_profile_is_one_device_whose_set_up_differs_per_run() -> None:
    spec = _realistic_spec({"profile": "realistic", "imperfections": {"tip_mass": 1e-4}})
    runs = expand_runs(spec, spec.load_antenna())
    devices = [run.scenario["device"] for run in runs]
    # built once: the link, the clamp and the sensor's calibration are the same in every run
    assert len({(d.clamp_stiffness, d.joint_start, d.sensor_coupling) for d in devices}) == 1
    # set up anew: the encoders' zero and the sensor's drift differ between runs
    assert len({d.encoder_offset for d in devices}) == 3
    assert len({d.sensor_drift_rate for d in devices}) == 3
    assert all(d.tip_mass == 1e-4 for d in devices)
    assert expand_runs(spec, spec.load_antenna())[0].scenario["device"] == devices[0]
    other = _realistic_spec({"profile": "realistic", "build": 7})
    built = expand_runs(other, other.load_antenna())[0].scenario["device"]
    assert built.clamp_stiffness != devices[0].clamp_stiffness


def test_realistic_device_of_one_build_differs_only_in_set_up() -> None:
    first, second = realistic_device(1, build=5), realistic_device(2, build=5)
    assert first.tip_mass == second.tip_mass and first.sensor_gain == second.sensor_gain
    assert first.encoder_offset != second.encoder_offset
    assert realistic_device(3).tip_mass != realistic_device(4).tip_mass


def test_campaign_device_build_must_be_a_seed() -> None:
    with pytest.raises(CampaignSpecError, match=r"device\.build"):
        _realistic_spec({"profile": "realistic", "build": -1})


def test_campaign_without_device_profile_has_nominal_runs() -> None:
    spec = parse_campaign_spec(
        {
            "name": "t",
            "antenna": "paper-2021",
            "cases": ["azimuthal"],
            "contact_points": [0.5],
            "repeats": 1,
            "base_seed": 1,
        },
        "test",
    )
    assert "device" not in expand_runs(spec, spec.load_antenna())[0].scenario


@pytest.mark.parametrize(
    "device, field",
    [
        ({"profile": "perfect"}, "device.profile"),
        ({"imperfections": {"tip_mas": 1.0}}, "device.imperfections.tip_mas"),
        ({"imperfections": {"tip_mass": -1.0}}, "device.imperfections.tip_mass"),
    ],
)
def test_campaign_device_errors_name_the_field(device: dict[str, object], field: str) -> None:
    with pytest.raises(CampaignSpecError) as info:
        parse_campaign_spec(
            {
                "name": "t",
                "antenna": "paper-2021",
                "cases": ["azimuthal"],
                "contact_points": [0.5],
                "repeats": 1,
                "base_seed": 1,
                "device": device,
            },
            "test",
        )
    assert field in str(info.value)


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"tip_mass": -1e-3}, "tip_mass"),
        ({"clamp_stiffness": 0.0}, "clamp_stiffness"),
        ({"stiffness_taper": 0.0}, "stiffness_taper"),
        ({"sensor_gain": (1.0, 1.0)}, "sensor_gain"),
        ({"sensor_coupling": tuple((1.0,) * 6 for _ in range(6))}, "sensor_coupling"),
        ({"encoder_offset": (math.nan, 0.0)}, "encoder_offset"),
        ({"bow": (0.2, 0.0)}, "bow"),
    ],
)
def test_bad_imperfection_names_its_field(kwargs: dict[str, object], field: str) -> None:
    with pytest.raises(DeviceError, match=f"device.{field}"):
        DeviceImperfections(**kwargs)  # type: ignore[arg-type]


def test_campaign_on_the_realistic_profile_runs_and_says_so(tmp_path: Path) -> None:
    """A campaign with ``[device] profile = "realistic"`` simulates each run on its own draw and
    its report says the device carries imperfections the model does not know."""
    spec = parse_campaign_spec(
        {
            "name": "realistic",
            "antenna": "paper-2021",
            "cases": ["azimuthal"],
            "contact_points": [0.55],
            "repeats": 2,
            "base_seed": 3,
            "methods": ["paper"],
            "device": {"profile": "realistic"},
        },
        "test",
    )

    def plain(_: CampaignSpec) -> Antenna:
        return paper_antenna()

    run_campaign(spec, tmp_path, prepare_antenna=plain, workers=1, progress=False)
    assert main(["campaign", "report", str(tmp_path)]) == 0
    text = (tmp_path / "report.md").read_text("utf-8")
    assert "- Device imperfections: profile realistic" in text
    assert "has exactly the parameters of the model" not in text
    rows = (tmp_path / "runs.csv").read_text("utf-8").splitlines()
    assert len(rows) == 3  # header and two runs


def test_a_joint_off_the_link_is_refused() -> None:
    antenna = paper_antenna()
    device = DeviceImperfections(joint_start=1.2, joint_length=0.02, joint_stiffness_factor=2.0)
    scenario = Scenario(case="azimuthal", contact_point=0.5, device=device)
    with pytest.raises(DeviceError, match=r"device\.joint_start"):
        simulate(antenna, scenario)


def test_a_bowed_links_rest_moment_about_its_axis_is_its_weight_aside() -> None:
    # A link bowed sideways by d at the tip (the arc d (x / l)^2) hangs its weight beside the
    # root's line: at rest, level, the torque about X^m is -g (rho l d / 3 + m_tip d) (the
    # recorded torque's sign as in test_simulator_contact's statics); bowed up instead, none.
    antenna = paper_antenna()
    link = antenna.link
    d = 0.02
    scenario = Scenario(case="azimuthal", contact_point=0.6, seed=1, noise_scale=0.0)
    side = simulate(antenna, dataclasses.replace(scenario, device=DeviceImperfections(bow=(d, 0))))
    up = simulate(antenna, dataclasses.replace(scenario, device=DeviceImperfections(bow=(0, d))))
    rest = slice(0, 100)  # before the sweep starts (the head still, the link at rest)
    expected = -9.80665 * (link.linear_density * link.length / 3.0 + link.tip_mass) * d
    # the consistent mass matrix integrates the quadratic arc exactly; each reading is rounded
    # to the sensor's resolution (2e-5 of this moment), which the mean of 100 takes below 1e-5
    assert side.torque[rest, 0].mean() == pytest.approx(expected, rel=1e-5)
    # the upward bow's weight lies along Z^m, without a moment about X^m: the readings' rounding
    assert abs(up.torque[rest, 0].mean()) < 1e-4 * abs(expected)


@pytest.mark.parametrize("bow", [(0.02, 0.0), (0.0, -0.02)])
def test_a_bowed_link_pushed_meets_the_obstacle_at_its_rest_shape(bow: tuple[float, float]) -> None:
    # The link touches the obstacle where its rest shape puts it, deflects from that shape,
    # and its recorded wrench is the contact's and the weight's about O from where the link is
    # (rest shape and deflection), as for the straight link (test_simulator_contact).
    antenna = paper_antenna()
    x_c = 0.7
    scenario = Scenario(
        case="azimuthal",
        contact_point=x_c,
        noise_scale=0.0,
        duration=3.5,
        damping_ratio=0.1,
        device=DeviceImperfections(bow=bow),
    )
    detail = simulate_detailed(antenna, scenario)
    straight = simulate_detailed(
        antenna, dataclasses.replace(scenario, device=DeviceImperfections())
    )
    rec = detail.recording
    arc = np.array(bow) * (x_c / antenna.link.length) ** 2

    def first_touch_point(run):  # type: ignore[no-untyped-def]
        touch = int(np.flatnonzero(run.recording.extra["true_in_contact"] > 0.5)[0])
        return motor_frame(*run.true_theta[touch]) @ run.contact_point[touch]

    # at the first touch the link's point lies off the straight link's by its rest shape: the
    # contact lies on the obstacle's surface, which the bow moves by the arc, and only where on
    # it the first sample in contact falls differs (within a micrometre; measured 0.5 um)
    moved = first_touch_point(detail) - first_touch_point(straight)
    np.testing.assert_allclose(moved[1:], arc, atol=1e-6)
    window = slice(-1000, None)
    points = np.array(
        [
            motor_frame(*th) @ p
            for th, p in zip(detail.true_theta, detail.contact_point, strict=True)
        ]
    )
    moment = np.cross(points[window], detail.contact_force[window]).mean(axis=0)
    model = detail.link_model
    length = antenna.link.length
    nodes = model.nodes
    shape = np.zeros(2 * nodes.size)
    shape[0::2], shape[1::2] = (nodes / length) ** 2, 2.0 * nodes / length**2
    rest = shape[model.root_dofs :]
    v_integral, _ = model.translation_load @ (detail.final_deflection.T + np.outer(rest, bow))
    g_z = -9.80665 * math.cos(detail.true_theta[-1, 1])
    weight = antenna.link.mass * 9.80665
    # the straight, level link's weight moment is (0, m g l / 2, 0); the rest of it from v, w
    expected = moment + np.array([g_z * v_integral, 0.5 * weight * length, 0.0])
    # 1e-6 N m, 3e-5 of the moment: the held link's residual vibration and the servo's hunting
    # over the last second, which the straight link's statics leave within 0.05 % of its ratio
    # (test_simulator_contact); measured 1.4e-7 N m
    np.testing.assert_allclose(rec.torque[window].mean(axis=0), expected, atol=1e-6)


def test_a_bowed_link_is_simulated_on_the_linear_link_only() -> None:
    # refused with the scenario, before any run (a campaign's spec checks its scenarios so)
    with pytest.raises(
        ScenarioError, match=r"device\.bow: a bowed link is simulated on the linear"
    ):
        Scenario(
            case="azimuthal",
            contact_point=0.6,
            link_model="nonlinear",
            device=DeviceImperfections(bow=(0.01, 0.0)),
        )
