"""Tests of sensing_antenna.antenna: built-in sets, derived values, TOML overrides and errors."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sensing_antenna.antenna import (
    BUILTIN_ANTENNAS,
    PARAMETER_RANGES,
    AntennaConfigError,
    SensorRange,
    antenna_to_toml,
    load_antenna,
    paper_antenna,
    save_antenna,
)
from sensing_antenna.errors import SensingAntennaError


@pytest.mark.parametrize("name", BUILTIN_ANTENNAS)
def test_builtins_load(name: str) -> None:
    antenna = load_antenna(name)
    assert antenna.name == name
    assert antenna.link.length == 0.98
    assert antenna.link.tip_mass == 0.0


def test_default_is_paper_2021() -> None:
    assert load_antenna() == paper_antenna()
    assert load_antenna(None).name == "paper-2021"


def test_derived_link_values_match_table_2() -> None:
    """Table 2 / paper README: E I = 0.0903 N m^2, m_b = 4.606 g, T = 0.2282 s/m^2.

    E I: tolerance 5e-4 (four printed digits). m_b = rho l exactly. T: the paper computes it
    from I rounded to 0.785 mm^4 (0.2282); from pi r^4 / 4 = 0.7854 mm^4 it is 0.22811, so the
    tolerance is 5e-4 relative (the rounding of I), not the printed digits.
    """
    link = paper_antenna().link
    assert link.area_moment == pytest.approx(0.785e-12, rel=1e-3)  # Table 2, 0.785 mm^4
    assert link.flexural_rigidity == pytest.approx(0.0903, rel=5e-4)
    assert link.mass == pytest.approx(4.606e-3, rel=1e-12)
    assert link.theoretical_t == pytest.approx(0.2282, rel=5e-4)
    assert link.t_param == link.theoretical_t
    assert link.tip_mass_ratio == 0.0


def test_calibrated_set_uses_t_e() -> None:
    """Section 5.1: T_e = 0.2124, 7 % below the theoretical T."""
    link = load_antenna("paper-2021-calibrated").link
    assert link.t_param == 0.2124
    assert 1 - link.t_param / link.theoretical_t == pytest.approx(0.07, abs=0.005)
    assert paper_antenna().with_calibrated_t(0.2124).link == link


def test_motor_and_observer_values() -> None:
    """Table 1 and Eq. 15."""
    antenna = paper_antenna()
    assert antenna.azimuth_motor.inertia == 6.2e-3
    assert antenna.elevation_motor.inertia == 1.8e-3
    assert antenna.azimuth_motor.coulomb_torque == pytest.approx(100 * 0.003 * 0.48)
    assert antenna.observer.natural_frequency == 16.4
    assert antenna.observer.damping_ratio == pytest.approx(0.3 / (2 * 16.4))


def test_toml_override_with_base(tmp_path: Path) -> None:
    path = tmp_path / "short.toml"
    path.write_text(
        'base = "paper-2021"\nname = "short-link"\n[link]\nlength = 0.5\ntip_mass = 0.001\n',
        encoding="utf-8",
    )
    antenna = load_antenna(path)
    assert antenna.name == "short-link"
    assert antenna.link.length == 0.5
    assert antenna.link.tip_mass == 0.001
    assert antenna.link.radius == paper_antenna().link.radius  # inherited
    assert antenna.azimuth_motor == paper_antenna().azimuth_motor
    assert antenna.link.tip_mass_ratio == pytest.approx(0.001 / (4.7e-3 * 0.5))


@pytest.mark.parametrize(
    ("body", "field"),
    [
        ("[link]\nlength = -1.0\n", "link.length"),
        ("[link]\nlength = 0\n", "link.length"),
        ('[link]\nradius = "thin"\n', "link.radius"),
        ("[link]\nyoungs_modulus = true\n", "link.youngs_modulus"),
        ("[link]\ntip_mass = -0.1\n", "link.tip_mass"),
        ("[link]\ncalibrated_t = nan\n", "link.calibrated_t"),
        ("[link]\ncalibration_scatter = -0.001\n", "link.calibration_scatter"),
        ("[link]\ncalibration_scatter = nan\n", "link.calibration_scatter"),
        ("[link]\nmode2_scatter = -0.001\n", "link.mode2_scatter"),
        ('[link]\nmode2_scatter = "x"\n', "link.mode2_scatter"),
        ("[link]\nmode2_scatter = 2.0\n", "link.mode2_scatter"),
        ("[link]\nbow_std = -0.001\n", "link.bow_std"),
        ("[link]\nbow_std = 2.0\n", "link.bow_std"),
        ("[link]\ncolour = 3.0\n", "link.colour"),
        ("[motor]\ninertia = 1.0\n", "motor"),
        ("[azimuth_motor]\ninertia = -1.0\n", "azimuth_motor.inertia"),
        ("[observer]\nnatural_frequency = 0.0\n", "observer.natural_frequency"),
        ("[sensor_range]\nforce = [25.0, 25.0, 35.0]\n", "sensor_range.torque"),
        ("[sensor_range]\nforce = [25, 25]\ntorque = [1, 1, 1]\n", "sensor_range.force"),
        ("[sensor_range]\nforce = [25, 25, 0]\ntorque = [1, 1, 1]\n", "sensor_range.force"),
        ('[sensor_range]\nforce = [25, 25, 25]\ntorque = [1, "a", 1]\n', "sensor_range.torque"),
        ("[sensor_range]\nforce = [1, 1, 1]\ntorque = [1, 1, 1]\nfz = 3\n", "sensor_range.fz"),
    ],
)
def test_invalid_values_name_field_and_file(tmp_path: Path, body: str, field: str) -> None:
    path = tmp_path / "bad.toml"
    path.write_text('base = "paper-2021"\n' + body, encoding="utf-8")
    with pytest.raises(AntennaConfigError) as info:
        load_antenna(path)
    message = str(info.value)
    assert str(path) in message
    assert field in message
    assert info.value.field_name == field


def test_errors_are_sensing_antenna_errors() -> None:
    assert issubclass(AntennaConfigError, SensingAntennaError)


def test_missing_section_without_base(tmp_path: Path) -> None:
    path = tmp_path / "partial.toml"
    path.write_text('name = "x"\n[link]\nlength = 1.0\n', encoding="utf-8")
    with pytest.raises(AntennaConfigError, match="missing"):
        load_antenna(path)


def test_missing_field_without_base(tmp_path: Path) -> None:
    text = antenna_to_toml(paper_antenna()).replace("radius = 0.001\n", "")
    path = tmp_path / "no-radius.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(AntennaConfigError, match=r"link\.radius: missing") as info:
        load_antenna(path)
    assert str(path) in str(info.value)
    assert "__init__" not in str(info.value)  # the field, not Python's internals


def test_bad_base_not_a_file_and_bad_toml(tmp_path: Path) -> None:
    with pytest.raises(AntennaConfigError, match="no such file"):
        load_antenna(tmp_path / "absent.toml")
    path = tmp_path / "base.toml"
    path.write_text('base = "paper-1999"\n', encoding="utf-8")
    with pytest.raises(AntennaConfigError, match="base"):
        load_antenna(path)
    path.write_text("this is = = not toml\n", encoding="utf-8")
    with pytest.raises(AntennaConfigError, match="not valid TOML"):
        load_antenna(path)


def test_save_load_round_trip(tmp_path: Path) -> None:
    original = paper_antenna()
    variant = dataclasses.replace(
        original,
        name='odd "name"',
        description="tip payload",
        link=dataclasses.replace(original.link, tip_mass=0.0012, calibrated_t=0.21),
        sensor_range=SensorRange(force=(25.0, 25.0, 35.0), torque=(0.25, 0.25, 0.25)),
    )
    for antenna in (original, load_antenna("paper-2021-calibrated"), variant):
        path = tmp_path / "round.toml"
        save_antenna(antenna, path)
        assert load_antenna(path) == antenna


def test_check_contact_point() -> None:
    link = paper_antenna().link
    link.check_contact_point(0.98)
    link.check_contact_point(1e-6)
    for bad in (0.0, -0.1, 0.99, math.inf, math.nan):
        with pytest.raises(AntennaConfigError, match="x_c"):
            link.check_contact_point(bad)


def test_gravity_terms_section_4_2() -> None:
    """Section 4.2: F_g = (-m g sin t2, 0, -m g cos t2), Gamma_g = (0, m g l cos t2 / 2, 0)."""
    antenna = paper_antenna()
    w = antenna.link.mass * 9.80665
    fx, fy, fz = antenna.gravity_force(0.0)
    assert (fx, fy, fz) == pytest.approx((0.0, 0.0, -w))
    assert antenna.gravity_torque(0.0)[1] == pytest.approx(0.5 * w * 0.98)


def test_the_tip_mass_a_moment_reads_is_its_weight_on_the_lever() -> None:
    """A 2 g point mass at the tip of the straight link at theta2 has moment m g l cos(theta2):
    the mean over two elevations; none from a link turned past the vertical."""
    link = paper_antenna().link
    theta2 = np.array([0.2, 0.4])
    moment = 0.002 * 9.80665 * 0.98 * float(np.mean(np.cos(theta2)))
    assert link.tip_mass_for_moment(moment, theta2) == pytest.approx(0.002, rel=1e-12)
    assert math.isnan(link.tip_mass_for_moment(moment, [math.pi / 2 + 0.1]))


@pytest.mark.parametrize("tip_mass", [0.0, 0.002])
def test_sag_moment_matches_the_finite_element_link(tip_mass: float) -> None:
    """kappa = g^2 int u dm (closed form) against the simulator's finite elements, g^2 t K^-1 t.

    t is the consistent load of a unit transverse acceleration (tip mass included), K the
    stiffness of the clamped link. Cubic Hermite elements converge as h^4: 2.8e-6 relative
    error with 10 elements, 1.7e-7 with 20, so 20 elements and 1e-6.
    """
    from sensing_antenna.simulator.link import build_link_model

    link = dataclasses.replace(paper_antenna().link, tip_mass=tip_mass)
    model = build_link_model(link, 20)
    load = model.translation_load
    fem = 9.80665**2 * float(load @ np.linalg.solve(model.stiffness, load))
    assert link.sag_moment == pytest.approx(fem, rel=1e-6)
    if tip_mass == 0.0:
        # rho^2 g^2 l^5 / (20 E I) for the paper link: a 5.9 cm tip sag, kappa 1.06e-3 N m
        assert link.sag_moment == pytest.approx(1.063e-3, rel=1e-3)


@pytest.mark.parametrize("tip_mass", [0.0, 0.002])
def test_gravity_torque_is_what_the_simulated_sensor_reads_at_rest(tip_mass: float) -> None:
    """Noiseless simulator, head at rest before the sweep (theta2 about -0.1 rad in the vertical
    case): the sensor reads exactly the weight's moment with tip mass and sag.

    Without the sag term the model is 1.1e-4 N m off, without the tip mass 1.8e-2 N m (close to
    the 0.02 N m contact threshold); the tolerance 1e-6 N m is 100 times the reading's own error
    (5e-8 N m, the static solve of the simulator's initial state).
    """
    from sensing_antenna.simulator import Scenario, simulate

    base = paper_antenna()
    antenna = dataclasses.replace(base, link=dataclasses.replace(base.link, tip_mass=tip_mass))
    scenario = Scenario(case="vertical", contact_point=0.6, seed=0, noise_scale=0.0, duration=0.1)
    recording = simulate(antenna, scenario)
    theta2 = float(recording.theta[0, 1])
    assert theta2 < -0.05  # the sag term is sin(theta2) cos(theta2): zero when level
    np.testing.assert_allclose(recording.torque[0], antenna.gravity_torque(theta2), atol=1e-6)
    np.testing.assert_allclose(recording.force[0], antenna.gravity_force(theta2), atol=1e-5)
    rigid = 0.5 * base.link.mass * 9.80665 * base.link.length * math.cos(theta2)
    assert abs(recording.torque[0, 1] - rigid) > 1e-4  # the test would see either term missing


_FIELDS = {
    "link": (
        "length",
        "radius",
        "youngs_modulus",
        "linear_density",
        "tip_mass",
        "second_moment",
        "calibrated_t",
        "calibration_scatter",
        "mode2_scatter",
    ),
    "azimuth_motor": (
        "torque_constant",
        "inertia",
        "viscous_friction",
        "coulomb_voltage",
        "gear_ratio",
    ),
    "observer": ("gain", "natural_frequency", "damping", "contact_threshold"),
}


@pytest.mark.parametrize(
    ("section", "name"), [(section, name) for section, names in _FIELDS.items() for name in names]
)
@pytest.mark.parametrize("value", [1e300, 1e-300, 1e30, 1e-30])
def test_absurd_values_are_refused_in_one_line_or_usable(
    tmp_path: Path, section: str, name: str, value: float
) -> None:
    # Valid floats, absurd values: either one line naming the file and the field (or the link
    # as a whole), or an antenna the beam model computes with.
    from sensing_antenna.beam import SensingCurve, natural_frequencies

    path = tmp_path / "absurd.toml"
    path.write_text(f'base = "paper-2021"\n[{section}]\n{name} = {value!r}\n', encoding="utf-8")
    try:
        antenna = load_antenna(path)
    except AntennaConfigError as exc:
        message = str(exc)
        assert "\n" not in message
        assert message.startswith(f"{path}: {section}")
        assert "np." not in message
        return
    link = antenna.link
    assert np.all(np.isfinite(natural_frequencies(link, 0.5 * link.length, 3)))
    SensingCurve.from_link(link).contact_points(50.0)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("length", 1e30),
        ("radius", 1e-30),
        ("youngs_modulus", 1e-30),
        ("linear_density", 1e30),
        ("tip_mass", 1e30),
        ("second_moment", 1e-30),
        ("calibrated_t", 1e30),
        ("calibration_scatter", 1e300),
    ],
)
def test_values_that_overflowed_the_estimators_are_refused_at_load(
    tmp_path: Path, field: str, value: float
) -> None:
    # Each of these, were it loaded, makes an estimator raise OverflowError or an overflow
    # warning (estimate with every method on a simulated recording).
    path = tmp_path / "overflow.toml"
    path.write_text(f'base = "paper-2021"\n[link]\n{field} = {value!r}\n', encoding="utf-8")
    with pytest.raises(AntennaConfigError) as info:
        load_antenna(path)
    assert info.value.field_name in (f"link.{field}", "link")


def test_link_length_limits_name_the_file_and_field(tmp_path: Path) -> None:
    path = tmp_path / "long.toml"
    for value, shown in ((1e300, "1e+300 m"), (1e-300, "1e-300 m")):
        path.write_text(f'base = "paper-2021"\n[link]\nlength = {value!r}\n', encoding="utf-8")
        with pytest.raises(AntennaConfigError) as info:
            load_antenna(path)
        assert str(info.value).startswith(f"{path}: link.length: {shown} is outside 0.001 to 100 m")
        assert "(in " not in str(info.value)  # no unit makes these lengths
    # a length written in mm (750 for 0.75 m), or cm: the units it would fit are named
    path.write_text('base = "paper-2021"\n[link]\nlength = 750.0\n', encoding="utf-8")
    with pytest.raises(AntennaConfigError, match=r"750\.0 m is outside .*\(in cm or mm\?\)$"):
        load_antenna(path)


def test_a_modulus_in_gigapascals_names_the_unit(tmp_path: Path) -> None:
    path = tmp_path / "soft.toml"
    # 210 meant as GPa (steel): read as Pa it is far below soft rubber
    path.write_text('base = "paper-2021"\n[link]\nyoungs_modulus = 210.0\n', encoding="utf-8")
    with pytest.raises(AntennaConfigError, match=r"210\.0 Pa is outside .*\(in GPa or MPa\?\)$"):
        load_antenna(path)
    # 5e3 in GPa would be stiffer than diamond, in MPa (5 GPa) it fits: only that unit is named
    path.write_text('base = "paper-2021"\n[link]\nyoungs_modulus = 5e3\n', encoding="utf-8")
    with pytest.raises(AntennaConfigError, match=r"\(in MPa\?\)$"):
        load_antenna(path)


@pytest.mark.parametrize("key", sorted(PARAMETER_RANGES))
def test_every_range_has_a_reason_and_refuses_just_outside(key: str) -> None:
    limits = PARAMETER_RANGES[key]
    assert limits.reason and limits.low < limits.high
    section, name = key.split(".")
    base = paper_antenna()
    field = "linear_density" if name == "bulk_density" else name
    for bad in (limits.low * (1 - 1e-9) if limits.low > 0 else -1.0, limits.high * (1 + 1e-9)):
        if name == "bulk_density":
            bad = bad * math.pi * base.link.radius**2
        part = base.link if section == "link" else base.azimuth_motor
        with pytest.raises(AntennaConfigError) as info:
            dataclasses.replace(part, **{field: bad})
        assert info.value.field_name == f"{section}.{field}"


def test_static_sag_and_the_links_that_would_sag_more_than_their_length() -> None:
    # Handbook cantilever (Roark, Table 8.1, cases 1a and 2a): w l^4 / (8 E I) + P l^3 / (3 E I).
    # Paper link (Table 2): w = 4.7e-3 * g, E I = 115e9 * pi (1e-3)^4 / 4, l = 0.98: 5.9 cm.
    link = paper_antenna().link
    ei = 115e9 * math.pi * 1e-12 / 4
    expected = 4.7e-3 * 9.80665 * 0.98**4 / (8 * ei)
    assert link.static_sag == pytest.approx(expected, rel=1e-12)
    assert link.static_sag == pytest.approx(0.059, abs=5e-4)
    with_tip = dataclasses.replace(link, tip_mass=0.002)
    assert with_tip.static_sag == pytest.approx(expected + 0.002 * 9.80665 * 0.98**3 / (3 * ei))
    # Three metres of it would sag 0.0589 (3 / 0.98)^4 = 5.17 m in linear theory: refused.
    with pytest.raises(AntennaConfigError, match=r"^link: its tip would sag 5\.17 m"):
        dataclasses.replace(link, length=3.0)
    with pytest.raises(AntennaConfigError, match=r"^link\.radius: .* slender"):
        dataclasses.replace(link, radius=0.15, linear_density=100.0)
    # the paper's 1 mm radius typed as 1 (m): the radius is named, not the linear density
    # whose bulk density (1.5e-3 kg/m^3) it throws out, with the units in which both fit (1 cm
    # would be a hollow tube of 15 kg/m^3)
    with pytest.raises(AntennaConfigError, match=r"^link\.radius: .* \(in cm or mm\?\)$"):
        dataclasses.replace(link, radius=1.0)


@pytest.mark.parametrize("name", ["two\nlines", "tab\there", " padded", "", "sep\u2028arator"])
def test_names_that_cannot_be_one_metadata_line_are_refused(tmp_path: Path, name: str) -> None:
    # The name goes into every recording's "# antenna:" line; TOML can carry it escaped, but a
    # recording cannot.
    path = tmp_path / "named.toml"
    path.write_text(f'base = "paper-2021"\nname = {json.dumps(name)}\n', encoding="utf-8")
    with pytest.raises(AntennaConfigError) as info:
        load_antenna(path)
    assert str(info.value).startswith(f"{path}: name:")
    with pytest.raises(AntennaConfigError, match=r"^name:"):
        dataclasses.replace(paper_antenna(), name=name)


@settings(max_examples=80, deadline=None)
@given(
    name=st.text(st.characters(blacklist_categories=("Cs",)), min_size=1, max_size=20).filter(
        lambda s: s.isprintable() and s == s.strip() and s != ""
    ),
    description=st.text(st.characters(blacklist_categories=("Cs",)), max_size=30),
)
def test_any_valid_name_and_description_round_trip(
    tmp_path_factory: pytest.TempPathFactory, name: str, description: str
) -> None:
    # read(write(a)) == a: quotes, backslashes, control characters in the description and any
    # Unicode are escaped as TOML basic strings.
    antenna = dataclasses.replace(paper_antenna(), name=name, description=description)
    path = tmp_path_factory.mktemp("rt") / "a.toml"
    save_antenna(antenna, path)
    back = load_antenna(path)
    assert back == antenna
    assert (back.name, back.description) == (name, description)


def test_contact_point_message_shows_plain_numbers() -> None:
    with pytest.raises(AntennaConfigError) as info:
        paper_antenna().link.check_contact_point(np.float64("nan"))
    assert str(info.value) == "x_c: contact point must lie in (0, 0.98] m, got nan"


def test_the_frequency_model_is_as_uncertain_as_what_is_known_of_t() -> None:
    from sensing_antenna.antenna import CALIBRATED_T_UNCERTAINTY, NOMINAL_T_UNCERTAINTY

    nominal = paper_antenna()
    assert nominal.link.frequency_uncertainty == NOMINAL_T_UNCERTAINTY == 0.05
    unmeasured = nominal.with_calibrated_t(0.2124)
    assert unmeasured.link.frequency_uncertainty == CALIBRATED_T_UNCERTAINTY == 0.01
    assert nominal.with_calibrated_t(0.2124, 0.0012).link.frequency_uncertainty == 0.0012
    # a calibration that happened to scatter less than the model can be trusted to: the floor
    assert nominal.with_calibrated_t(0.2124, 0.0).link.frequency_uncertainty == 0.001
    # its own T as the calibrated one: the same frequency model, now with a measured scatter
    own = nominal.self_calibrated(0.001)
    assert own.link.t_param == nominal.link.t_param
    assert own.link.frequency_uncertainty == 0.001
    assert nominal.self_calibrated() == own  # by default the floor a calibration may claim


def test_a_sensor_no_calibration_measured_carries_its_nominal_cross_talk(tmp_path: Path) -> None:
    # 1 % of a Nano17's 25 N per 0.25 N m full scale, spread uniformly: 1 / sqrt(3) N per N m
    nominal = paper_antenna().sensor
    along_y, along_z, oblique = [0.0, 0.3, 0.0], [0.1, 0.0, -0.3], [0.0, 0.3, 0.4]
    for push in (along_y, along_z, oblique, [0.0, 0.0, 0.0]):
        assert nominal.coupling_uncertainty(push) == pytest.approx(1.0 / math.sqrt(3.0), rel=1e-12)
    # a calibration that measured the ratio's scatter bounds the cross-talk left by it
    measured = dataclasses.replace(nominal, fy_per_tz=0.8, ratio_scatter=0.03)
    assert measured.coupling_uncertainty(oblique) == 0.0
    # one that saw azimuthal sweeps only measured the terms a push along Y^m reads, not Z^m's:
    # c^2 = u_y^2 c_az^2 + u_z^2 c_vert^2, the lateral direction u = (0.6, 0.8) here
    one_way = dataclasses.replace(measured, unmeasured_sweeps=("vertical",))
    assert one_way.coupling_uncertainty(along_y) == 0.0
    assert one_way.coupling_uncertainty(along_z) == nominal.nominal_coupling
    assert one_way.coupling_uncertainty(oblique) == pytest.approx(0.8 * nominal.nominal_coupling)
    assert one_way.coupling_uncertainty([0.0, 0.0, 0.0]) == nominal.nominal_coupling
    # a simulation study's device identical to its model has none to fear
    assert paper_antenna().self_calibrated().sensor.coupling_uncertainty(along_z) == 0.0
    # the sensor's own figure, read from the antenna file, and kept by a round trip
    path = tmp_path / "a.toml"
    text = antenna_to_toml(paper_antenna()) + "\n[sensor]\nnominal_coupling = 0.2\n"
    path.write_text(text)
    stated = load_antenna(path)
    assert stated.sensor.coupling_uncertainty(oblique) == 0.2
    save_antenna(stated, tmp_path / "b.toml")
    assert load_antenna(tmp_path / "b.toml").sensor == stated.sensor
    path.write_text(text.replace("nominal_coupling = 0.2", "nominal_coupling = -1.0"))
    with pytest.raises(SensingAntennaError, match=r"sensor\.nominal_coupling"):
        load_antenna(path)
