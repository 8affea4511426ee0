"""Campaign specs: the built-in paper campaign, validation messages, run expansion and seeds."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from sensing_antenna.antenna import paper_antenna
from sensing_antenna.campaign.limits import MAX_CONTACT_POINTS, MAX_RUNS
from sensing_antenna.campaign.parsing import default_campaign_spec, load_campaign_spec
from sensing_antenna.campaign.runs import (
    NOISE_SWEEP_STREAM,
    contact_point_label,
    derive_seed,
    expand_runs,
)
from sensing_antenna.campaign.schema import CalibrationStep, CampaignSpecError, NoiseSweep
from sensing_antenna.errors import SensingAntennaError

GOOD = """
name = "small"
antenna = "paper-2021"
cases = ["azimuthal"]
contact_points = [0.3, 0.5]
repeats = 2
base_seed = 3
methods = ["paper", "ratio"]
[scenario]
noise_scale = 0.5
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "spec.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_default_campaign_is_the_paper_section_5_6() -> None:
    # Section 5.6: x_c = 0.30 to 0.95 m every 5 cm plus 0.98 m, 5 experiments per point, 2 cases
    spec = default_campaign_spec()
    assert spec.n_main_runs == 150
    # plus the noise sweep: 4 levels x 8 points x 2 cases x 1 repeat, and the main runs again
    # on the second device
    assert spec.n_sweep_runs == 64 and spec.n_second_device_runs == 150
    assert spec.n_runs == 364
    assert spec.cases == ("azimuthal", "vertical")
    expected = [*np.round(np.arange(0.30, 0.951, 0.05), 2), 0.98]
    np.testing.assert_allclose(spec.contact_points, expected, atol=1e-12)
    assert spec.repeats == 5
    assert spec.methods == ("paper", "ratio", "two-frequency", "fast")
    assert load_campaign_spec(None) == spec


def test_runs_are_ordered_named_and_seeded_deterministically() -> None:
    spec = default_campaign_spec()
    every = expand_runs(spec, paper_antenna())
    runs = every[:150]  # the main runs come first
    assert [r.index for r in runs] == list(range(150))
    assert runs[0].run_id == "azimuthal-x0300mm-r1"
    assert runs[-1].run_id == "vertical-x0980mm-r5"
    assert len({r.run_id for r in runs}) == 150
    assert len({r.seed for r in runs}) == 150
    again = expand_runs(spec, paper_antenna())
    assert [r.seed for r in again] == [r.seed for r in every]
    # the second device's runs repeat the main runs' seeds; no other seed repeats
    assert len(every) == 364 and len({r.seed for r in every}) == 214
    assert [r.seed for r in every[214:]] == [r.seed for r in runs]
    assert runs[7].seed == derive_seed(spec.base_seed, 7)
    # the free-motion step draws from another stream of the same base seed
    assert derive_seed(spec.base_seed, 0, stream=1) not in {r.seed for r in runs}


def test_points_the_check_tells_apart_get_their_own_run_ids(tmp_path: Path) -> None:
    # 0.5 and 0.5004 m are 0.4 mm apart: two points for the spec, so two runs with two files
    spec = load_campaign_spec(write(tmp_path, GOOD.replace("0.5]", "0.5, 0.5004, 0.500401]")))
    ids = [r.run_id for r in expand_runs(spec, paper_antenna())]
    assert len(set(ids)) == len(ids) == 8
    # whole millimetres keep the ids every earlier campaign directory has
    assert ids[2:8:2] == [
        "azimuthal-x0500mm-r1",
        "azimuthal-x0500.4mm-r1",
        "azimuthal-x0500.401mm-r1",
    ]
    assert contact_point_label(0.3) == "x0300mm" and contact_point_label(0.98) == "x0980mm"


def test_points_one_id_would_name_are_refused_up_front(tmp_path: Path) -> None:
    # 0.4 um apart: below the 1 um the ids resolve, so the spec must say they are one point
    path = write(tmp_path, GOOD.replace("0.5]", "0.5, 0.5000004]"))
    with pytest.raises(CampaignSpecError, match=r"contact_points: must be distinct to 1 um"):
        load_campaign_spec(path)


def test_a_good_file_loads_with_its_scenario(tmp_path: Path) -> None:
    spec = load_campaign_spec(write(tmp_path, GOOD))
    assert spec.n_runs == 4
    assert spec.scenario == {"noise_scale": 0.5}
    assert spec.free_motion.identify is False


def test_fingerprint_ignores_name_but_not_seeds(tmp_path: Path) -> None:
    a = load_campaign_spec(write(tmp_path, GOOD))
    b = load_campaign_spec(write(tmp_path, GOOD.replace('"small"', '"renamed"')))
    c = load_campaign_spec(write(tmp_path, GOOD.replace("base_seed = 3", "base_seed = 4")))
    assert a.fingerprint() == b.fingerprint() != c.fingerprint()


def test_the_fast_bound_is_on_unless_the_spec_turns_it_off(tmp_path: Path) -> None:
    # On by default (the built-in spec too), with the fingerprint of a spec that never mentions
    # it; off, another fingerprint (its fast rows differ), carried to every run
    default = load_campaign_spec(write(tmp_path, GOOD))
    on = load_campaign_spec(
        write(tmp_path, GOOD.replace("base_seed = 3", "base_seed = 3\nfast_bound = true"))
    )
    assert default.fast_bound and default_campaign_spec().fast_bound
    assert on == replace(default, source=on.source)
    assert on.fingerprint() == default.fingerprint()
    text = GOOD.replace("base_seed = 3", "base_seed = 3\nfast_bound = false")
    off = load_campaign_spec(write(tmp_path, text))
    assert not off.fast_bound and off.fingerprint() != default.fingerprint()
    assert not any(run.fast_bound for run in expand_runs(off, paper_antenna()))
    assert all(run.fast_bound for run in expand_runs(default, paper_antenna()))


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ('cases = ["azimuthal"]', 'cases = ["sideways"]', "cases[0]"),
        ("contact_points = [0.3, 0.5]", "contact_points = [0.3, -0.5]", "contact_points[1]"),
        ("contact_points = [0.3, 0.5]", 'contact_points = [0.3, "a"]', "contact_points[1]"),
        ("contact_points = [0.3, 0.5]", "contact_points = [0.3, 0.3]", "contact_points"),
        ("repeats = 2", "repeats = 0", "repeats"),
        ("repeats = 2", "repeats = 2.5", "repeats"),
        ("repeats = 2", "", "repeats"),
        ("base_seed = 3", "base_seed = -1", "base_seed"),
        ('methods = ["paper", "ratio"]', 'methods = ["magic"]', "methods[0]"),
        ("noise_scale = 0.5", "seed = 4", "scenario.seed"),
        ('name = "small"', 'name = "small"\ncolour = "red"', "colour"),
        ("base_seed = 3", 'base_seed = 3\nfast_bound = "yes"', "fast_bound"),
        ('name = "small"', 'name = "ti\\nny"', "name"),
    ],
)
def test_bad_fields_are_named_with_the_file(tmp_path: Path, old: str, new: str, field: str) -> None:
    path = write(tmp_path, GOOD.replace(old, new))
    with pytest.raises(CampaignSpecError, match=re.escape(f"{path}: {field}:")) as info:
        load_campaign_spec(path)
    assert isinstance(info.value, SensingAntennaError)


def test_a_contact_point_beyond_the_link_is_refused(tmp_path: Path) -> None:
    # Table 2: l = 0.98 m
    spec = load_campaign_spec(write(tmp_path, GOOD.replace("0.5]", "1.2]")))
    with pytest.raises(CampaignSpecError, match=r"contact_points\[1\]: 1.2 m is beyond"):
        spec.load_antenna()
    # 500 read as metres lies on the link in mm: said so
    spec = load_campaign_spec(write(tmp_path, GOOD.replace("0.5]", "500]")))
    with pytest.raises(CampaignSpecError, match=r"link length 0.98 m \(in mm\?\)$"):
        spec.load_antenna()


def test_an_antenna_file_that_does_not_exist_is_named_with_the_spec(tmp_path: Path) -> None:
    path = write(tmp_path, GOOD.replace('antenna = "paper-2021"', 'antenna = "mine.toml"'))
    spec = load_campaign_spec(path)
    with pytest.raises(CampaignSpecError) as raised:
        spec.load_antenna()
    assert str(raised.value).startswith(f"{path}: antenna: ") and "mine.toml: no such file" in (
        str(raised.value)
    )


def test_missing_file_and_bad_toml_are_reported(tmp_path: Path) -> None:
    with pytest.raises(CampaignSpecError, match="no such file"):
        load_campaign_spec(tmp_path / "nope.toml")
    with pytest.raises(CampaignSpecError, match="not valid TOML"):
        load_campaign_spec(write(tmp_path, "name = "))


def test_antenna_file_is_resolved_next_to_the_spec(tmp_path: Path) -> None:
    (tmp_path / "short.toml").write_text(
        'base = "paper-2021"\nname = "short"\n[link]\nlength = 0.6\n', encoding="utf-8"
    )
    spec = load_campaign_spec(
        write(tmp_path, GOOD.replace('antenna = "paper-2021"', 'antenna = "short.toml"'))
    )
    assert spec.load_antenna().link.length == 0.6


DEVICE_AND_CALIBRATION = """
[device]
antenna = "paper-2021"
link.youngs_modulus = 130e9
azimuth_motor.inertia = 7e-3
[calibration]
enabled = true
case = "azimuthal"
contact_points = [0.3, 0.5, 0.9]
repeats = 2
loss = "linear"
"""


def test_default_campaign_simulates_a_device_with_the_paper_t_e() -> None:
    spec = default_campaign_spec()
    model = spec.load_antenna()
    device = spec.load_device()
    # Table 2 gives T = 0.2282 (Section 5.1; 0.22812 from the rounded Table 2 values)
    assert model.link.theoretical_t == pytest.approx(0.2281, abs=1e-4)
    # the device's E = rho / (T_e^2 I) makes its T the paper's calibrated T_e = 0.2124 (Section
    # 5.1); 132.65 GPa is E rounded to 4 digits, so T agrees to 1e-5
    assert device.link.theoretical_t == pytest.approx(0.2124, abs=1e-5)
    assert device.link.youngs_modulus == pytest.approx(132.6e9, rel=1e-3)
    # everything but E is the paper's antenna
    assert device.link.linear_density == model.link.linear_density
    assert device.motors == model.motors
    assert spec.calibration.enabled and spec.calibration.case == "azimuthal"
    # Section 5.1: x_c from 0.3 m to 0.98 m in 5 cm steps, one experiment each
    np.testing.assert_allclose(spec.calibration.contact_points, spec.contact_points)
    assert spec.calibration.repeats == 1
    assert spec.free_motion.identify
    # the main runs on the realistic profile, the nominal device (the same hardware) as the
    # second device
    assert spec.device.profile == "realistic" and not spec.device.imperfections
    nominal = spec.second_device_spec()
    assert nominal.device.profile == "nominal" and not nominal.device.has_imperfections
    assert nominal.load_device() == device


def test_device_and_calibration_sections_load(tmp_path: Path) -> None:
    spec = load_campaign_spec(write(tmp_path, GOOD + DEVICE_AND_CALIBRATION))
    assert spec.device.overrides == {
        "link": {"youngs_modulus": 130e9},
        "azimuth_motor": {"inertia": 7e-3},
    }
    device = spec.load_device()
    assert device.link.youngs_modulus == 130e9
    assert device.azimuth_motor.inertia == 7e-3
    assert device.elevation_motor == paper_antenna().elevation_motor
    assert spec.calibration.contact_points == (0.3, 0.5, 0.9)
    assert spec.calibration.n_recordings == 6
    assert spec.calibration.loss == "linear"
    # without the sections: the device is the model and there is no calibration
    plain = load_campaign_spec(write(tmp_path, GOOD))
    assert plain.device.is_model and not plain.calibration.enabled
    assert plain.load_device() == plain.load_antenna()


def test_the_calibration_may_push_otherwise_than_the_runs(tmp_path: Path) -> None:
    from sensing_antenna.campaign.simulated import calibration_scenario, check_scenario

    # a lab calibrates T_e with gentle pushes and then pushes its runs hard
    hard = GOOD + "push = 0.25\n" + DEVICE_AND_CALIBRATION
    gentle = hard + "[calibration.scenario]\npush = 0.03\n"
    spec = load_campaign_spec(write(tmp_path, gentle))
    assert spec.scenario == {"noise_scale": 0.5, "push": 0.25}
    assert calibration_scenario(spec) == {"noise_scale": 0.5, "push": 0.03}
    check_scenario(spec)
    plain = load_campaign_spec(write(tmp_path, hard))
    assert calibration_scenario(plain) == plain.scenario
    assert spec.preparation_fingerprint() != plain.preparation_fingerprint()
    # its fields are checked as the runs' are, and named as its own
    bad = load_campaign_spec(write(tmp_path, hard + "[calibration.scenario]\npush = -1.0\n"))
    with pytest.raises(CampaignSpecError, match=r"calibration\.scenario\.push: .*> 0"):
        check_scenario(bad)
    bad = load_campaign_spec(write(tmp_path, hard + "[calibration.scenario]\ncolour = 1\n"))
    with pytest.raises(CampaignSpecError, match=r"calibration\.scenario\.colour: not a Scenario"):
        check_scenario(bad)
    with pytest.raises(CampaignSpecError, match=r"calibration\.scenario: must be a table"):
        load_campaign_spec(write(tmp_path, hard.replace("loss", "scenario = 3\nloss")))
    # what the calibration sets for each recording is not the spec's to set
    for key in ("seed = 7", 'case = "vertical"', "contact_point = 0.2"):
        with pytest.raises(CampaignSpecError, match=r"calibration\.scenario\.\w+: is set by"):
            load_campaign_spec(write(tmp_path, hard + f"[calibration.scenario]\n{key}\n"))


def test_device_and_calibration_change_the_fingerprints(tmp_path: Path) -> None:
    a = load_campaign_spec(write(tmp_path, GOOD + DEVICE_AND_CALIBRATION))
    b = load_campaign_spec(write(tmp_path, GOOD + DEVICE_AND_CALIBRATION.replace("130e9", "131e9")))
    c = load_campaign_spec(
        write(tmp_path, GOOD.replace("repeats = 2", "repeats = 3") + DEVICE_AND_CALIBRATION)
    )
    assert a.fingerprint() != b.fingerprint()
    assert a.preparation_fingerprint() != b.preparation_fingerprint()
    # the runs' repeats do not change what the calibration depends on
    assert a.fingerprint() != c.fingerprint()
    assert a.preparation_fingerprint() == c.preparation_fingerprint()


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("link.youngs_modulus = 130e9", "link.colour = 1.0", "device.link.colour"),
        ("link.youngs_modulus = 130e9", "link.calibrated_t = 0.2", "device.link.calibrated_t"),
        (
            "link.youngs_modulus = 130e9",
            "link.calibration_scatter = 0.001",
            "device.link.calibration_scatter",
        ),
        ("link.youngs_modulus = 130e9", 'link.youngs_modulus = "stiff"', "device.link"),
        ("link.youngs_modulus = 130e9", "link.youngs_modulus = nan", "device.link"),
        ("link.youngs_modulus = 130e9", "wheels.count = 4.0", "device.wheels"),
        ("link.youngs_modulus = 130e9", "link = 3", "device.link"),
        ('antenna = "paper-2021"\nlink', "antenna = 3\nlink", "device.antenna"),
        ("enabled = true", 'enabled = "yes"', "calibration.enabled"),
        ('case = "azimuthal"', 'case = "sideways"', "calibration.case"),
        ("[0.3, 0.5, 0.9]", "[0.3, -0.5, 0.9]", "calibration.contact_points[1]"),
        ("[0.3, 0.5, 0.9]", '[0.3, "a", 0.9]', "calibration.contact_points[1]"),
        ("[0.3, 0.5, 0.9]", "[0.3]", "calibration.contact_points"),
        ("repeats = 2\nloss", "repeats = 0\nloss", "calibration.repeats"),
        ('loss = "linear"', 'loss = "magic"', "calibration.loss"),
        ('loss = "linear"', 'loss = "linear"\ncolour = 1', "calibration.colour"),
    ],
)
def test_bad_device_and_calibration_fields_are_named(
    tmp_path: Path, old: str, new: str, field: str
) -> None:
    text = GOOD + DEVICE_AND_CALIBRATION.replace(old, new, 1)
    assert text != GOOD + DEVICE_AND_CALIBRATION
    path = write(tmp_path, text)
    with pytest.raises(CampaignSpecError, match=re.escape(f"{path}: {field}")) as info:
        load_campaign_spec(path)
    assert isinstance(info.value, SensingAntennaError)


def test_device_values_out_of_range_are_named_when_loaded(tmp_path: Path) -> None:
    path = write(tmp_path, GOOD + DEVICE_AND_CALIBRATION.replace("130e9", "-1.0"))
    spec = load_campaign_spec(path)
    with pytest.raises(CampaignSpecError, match=re.escape(f"{path}: device.link.youngs_modulus:")):
        spec.load_device()
    # a device link shorter than a calibration point (0.9 m) is refused, naming the point
    short = write(
        tmp_path, GOOD + DEVICE_AND_CALIBRATION.replace("130e9", "130e9\nlink.length = 0.8")
    )
    with pytest.raises(CampaignSpecError, match=r"calibration\.contact_points\[2\]: device: 0.9 m"):
        load_campaign_spec(short).load_device()


def test_device_antenna_file_is_resolved_next_to_the_spec(tmp_path: Path) -> None:
    (tmp_path / "stiff.toml").write_text(
        'base = "paper-2021"\nname = "stiff"\n[link]\nyoungs_modulus = 140e9\n', encoding="utf-8"
    )
    text = GOOD + '[device]\nantenna = "stiff.toml"\n'
    spec = load_campaign_spec(write(tmp_path, text))
    assert spec.load_device().link.youngs_modulus == 140e9
    assert spec.load_antenna().link.youngs_modulus == paper_antenna().link.youngs_modulus


SWEEP = (
    GOOD
    + """
[noise_sweep]
noise_scales = [0.25, 2.0]
contact_points = [0.4]
cases = ["azimuthal", "vertical"]
"""
)


def test_a_noise_sweep_adds_runs_after_the_main_ones_with_their_own_seeds(
    tmp_path: Path,
) -> None:
    spec = load_campaign_spec(write(tmp_path, SWEEP))
    # main: 1 case x 2 points x 2 repeats; sweep: 2 levels x 2 cases x 1 point x 2 repeats
    assert (spec.n_main_runs, spec.n_sweep_runs, spec.n_runs) == (4, 8, 12)
    assert spec.noise_scale == 0.5
    runs = expand_runs(spec, paper_antenna())
    main, sweep = runs[:4], runs[4:]
    # the main runs are what they were without a sweep
    plain = expand_runs(load_campaign_spec(write(tmp_path, GOOD)), paper_antenna())
    assert [(r.run_id, r.seed, r.noise_scale) for r in main] == [
        (r.run_id, r.seed, r.noise_scale) for r in plain
    ]
    assert [r.index for r in runs] == list(range(12))
    assert sweep[0].run_id == "azimuthal-x0400mm-r1-n0.25"
    assert sweep[-1].run_id == "vertical-x0400mm-r2-n2.00"
    assert [r.noise_scale for r in sweep] == [0.25] * 4 + [2.0] * 4
    assert all(r.scenario["noise_scale"] == r.noise_scale for r in sweep)
    assert all(r.methods == ("paper", "ratio") for r in sweep)  # every method, same recordings
    assert len({r.run_id for r in runs}) == 12
    assert len({r.seed for r in runs}) == 12
    assert sweep[3].seed == derive_seed(spec.base_seed, 3, NOISE_SWEEP_STREAM)
    others = {derive_seed(spec.base_seed, i, stream) for i in range(20) for stream in (0, 1, 2)}
    assert not others & {r.seed for r in sweep}


def test_the_sweep_defaults_to_the_main_points_repeats_and_cases(tmp_path: Path) -> None:
    text = GOOD + "[noise_sweep]\nnoise_scales = [2]\n"
    spec = load_campaign_spec(write(tmp_path, text))
    assert spec.sweep_cases == ("azimuthal",)
    assert spec.sweep_contact_points == (0.3, 0.5)
    assert spec.sweep_repeats == 2 and spec.n_sweep_runs == 4


def test_the_sweep_is_in_the_fingerprint_only_when_present(tmp_path: Path) -> None:
    plain = load_campaign_spec(write(tmp_path, GOOD))
    swept = load_campaign_spec(write(tmp_path, SWEEP))
    assert "noise_sweep" not in plain.to_dict()  # stored campaigns without a sweep still resume
    assert plain.fingerprint() != swept.fingerprint()
    assert plain.preparation_fingerprint() == swept.preparation_fingerprint()
    again = load_campaign_spec(write(tmp_path, SWEEP.replace("2.0]", "4.0]")))
    assert again.fingerprint() != swept.fingerprint()
    from sensing_antenna.campaign.parsing import parse_campaign_spec

    assert parse_campaign_spec(swept.to_dict(), "copy") == replace(swept, source="copy")


@pytest.mark.parametrize(
    ("section", "field"),
    [
        ("noise_scales = [0.5, -1.0]", "noise_sweep.noise_scales[1]"),
        ('noise_scales = ["loud"]', "noise_sweep.noise_scales[0]"),
        ("noise_scales = 2.0", "noise_sweep.noise_scales"),
        ("noise_scales = [2.0, 2.0]", "noise_sweep.noise_scales"),
        ("noise_scales = [2.0, 0.5]", "noise_sweep.noise_scales[1]"),  # the main level
        ("repeats = 2", "noise_sweep.noise_scales"),  # missing
        ("noise_scales = [2.0]\nrepeats = 0", "noise_sweep.repeats"),
        ("noise_scales = [2.0]\nrepeats = 1.5", "noise_sweep.repeats"),
        ("noise_scales = [2.0]\ncontact_points = [0.3, 0.0]", "noise_sweep.contact_points[1]"),
        ("noise_scales = [2.0]\ncontact_points = []", "noise_sweep.contact_points"),
        ('noise_scales = [2.0]\ncases = ["sideways"]', "noise_sweep.cases[0]"),
        ("noise_scales = [2.0]\nseeds = 3", "noise_sweep.seeds"),
    ],
)
def test_bad_noise_sweep_fields_are_named_with_the_file(
    tmp_path: Path, section: str, field: str
) -> None:
    path = write(tmp_path, GOOD + "[noise_sweep]\n" + section + "\n")
    with pytest.raises(CampaignSpecError, match=re.escape(f"{path}: {field}:")):
        load_campaign_spec(path)


def test_a_sweep_point_beyond_the_link_is_named(tmp_path: Path) -> None:
    text = GOOD + "[noise_sweep]\nnoise_scales = [2.0]\ncontact_points = [0.4, 1.3]\n"
    spec = load_campaign_spec(write(tmp_path, text))
    with pytest.raises(CampaignSpecError, match=r"noise_sweep\.contact_points\[1\]: 1.3 m"):
        spec.load_antenna()


def test_an_empty_noise_sweep_means_none(tmp_path: Path) -> None:
    text = GOOD + "[noise_sweep]\nnoise_scales = []\ncontact_points = [0.4]\n"
    spec = load_campaign_spec(write(tmp_path, text))
    assert not spec.noise_sweep.enabled and spec.n_sweep_runs == 0
    assert spec.fingerprint() == load_campaign_spec(write(tmp_path, GOOD)).fingerprint()


def test_a_campaign_may_start_from_the_built_in_one(tmp_path: Path) -> None:
    path = tmp_path / "fewer.toml"
    path.write_text('base = "default"\nrepeats = 2\n', encoding="utf-8")
    spec = load_campaign_spec(path)
    # everything else is the built-in campaign's; named after the file, no inherited text
    expected = replace(
        default_campaign_spec(), name="fewer", description="", repeats=2, source=str(path)
    )
    assert spec == expected
    assert spec.n_main_runs == 2 * 15 * 2
    path.write_text('base = "paper-2021"\nrepeats = 2\n', encoding="utf-8")
    assert load_campaign_spec(path) == expected


def test_a_nested_table_merges_into_the_base_table(tmp_path: Path) -> None:
    path = tmp_path / "heavier.toml"
    path.write_text(
        'base = "default"\nname = "heavier"\n'
        "[scenario]\ndamping_ratio = 0.01\n"
        "[device]\nlink.linear_density = 5e-3\n",
        encoding="utf-8",
    )
    spec = load_campaign_spec(path)
    base = default_campaign_spec()
    assert spec.scenario == {**base.scenario, "damping_ratio": 0.01}
    # the base's device (paper-2021 with E = 132.65 GPa) keeps its E and gains a density
    assert spec.device.antenna == base.device.antenna
    assert spec.device.overrides == {"link": {"youngs_modulus": 132.65e9, "linear_density": 5e-3}}
    assert spec.load_device().link.linear_density == 5e-3
    assert (spec.calibration, spec.noise_sweep) == (base.calibration, base.noise_sweep)


def test_a_base_file_is_read_next_to_the_spec_with_its_own_paths(tmp_path: Path) -> None:
    shared = tmp_path / "shared"
    shared.mkdir()
    (shared / "short.toml").write_text(
        'base = "paper-2021"\nname = "short"\n[link]\nlength = 0.6\n', encoding="utf-8"
    )
    (shared / "base.toml").write_text(GOOD.replace('"paper-2021"', '"short.toml"'), "utf-8")
    own = tmp_path / "mine"
    own.mkdir()
    path = own / "variant.toml"
    path.write_text('base = "../shared/base.toml"\nbase_seed = 9\n', encoding="utf-8")
    spec = load_campaign_spec(path)
    # the base's antenna file resolves next to the base, not next to this file
    assert spec.load_antenna().link.length == 0.6
    assert (spec.base_seed, spec.repeats, spec.name) == (9, 2, "variant")
    # dropping the base's noise sweep
    (shared / "base.toml").write_text(SWEEP, encoding="utf-8")
    path.write_text(
        'base = "../shared/base.toml"\n[noise_sweep]\nnoise_scales = []\n', encoding="utf-8"
    )
    assert not load_campaign_spec(path).noise_sweep.enabled


def test_an_unknown_base_is_one_error_naming_the_file_and_field(tmp_path: Path) -> None:
    path = write(tmp_path, 'base = "paper-2019"\nrepeats = 2\n')
    with pytest.raises(CampaignSpecError) as info:
        load_campaign_spec(path)
    message = str(info.value)
    assert message.startswith(f"{path}: base: unknown 'paper-2019': not a built-in campaign")
    assert "\n" not in message
    path = write(tmp_path, "base = 3\n")
    with pytest.raises(CampaignSpecError, match=re.escape(f"{path}: base: must name")):
        load_campaign_spec(path)


def test_errors_in_a_base_name_the_base_file_and_cycles_are_refused(tmp_path: Path) -> None:
    bad = tmp_path / "bad-base.toml"
    bad.write_text(GOOD.replace("repeats = 2", "repeats = 0"), encoding="utf-8")
    path = tmp_path / "variant.toml"
    path.write_text('base = "bad-base.toml"\n', encoding="utf-8")
    with pytest.raises(CampaignSpecError, match=re.escape(f"{bad}: repeats: must be >= 1")):
        load_campaign_spec(path)
    # an override is checked like any field, naming this file
    path.write_text('base = "default"\nrepeats = 0\n', encoding="utf-8")
    with pytest.raises(CampaignSpecError, match=re.escape(f"{path}: repeats: must be >= 1")):
        load_campaign_spec(path)
    a, b = tmp_path / "a.toml", tmp_path / "b.toml"
    a.write_text('base = "b.toml"\n', encoding="utf-8")
    b.write_text('base = "a.toml"\n', encoding="utf-8")
    with pytest.raises(CampaignSpecError, match=r"b\.toml: base: 'a\.toml' is based on this file"):
        load_campaign_spec(a)


def test_a_billion_repeats_are_refused_before_any_run_list_is_built(tmp_path: Path) -> None:
    path = write(tmp_path, GOOD.replace("repeats = 2", "repeats = 1000000000"))
    with pytest.raises(
        CampaignSpecError, match=rf"{re.escape(str(path))}: repeats: .*2000000000 runs"
    ):
        load_campaign_spec(path)
    assert MAX_RUNS == 100_000


def test_too_many_contact_points_or_noise_levels_are_refused(tmp_path: Path) -> None:
    many = ", ".join(f"{0.3 + i * 1e-5:.5f}" for i in range(MAX_CONTACT_POINTS + 1))
    path = write(
        tmp_path, GOOD.replace("contact_points = [0.3, 0.5]", f"contact_points = [{many}]")
    )
    with pytest.raises(CampaignSpecError, match=r"contact_points: 1001 points, more than the 1000"):
        load_campaign_spec(path)
    levels = tuple(float(i) for i in range(10**6))
    with pytest.raises(CampaignSpecError, match=r"noise_sweep\.noise_scales: 1000000 levels"):
        NoiseSweep(noise_scales=levels)
    with pytest.raises(CampaignSpecError, match=r"calibration\.repeats: .* = 15000 recordings"):
        CalibrationStep(enabled=True, repeats=1000)


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        ("noise_scale = 0.5", "duration = 1e9", "scenario.duration"),
        (
            "noise_scale = 0.5",
            "noise_scale = 0.5\n[free_motion]\nduration = 1e9",
            "free_motion.duration",
        ),
    ],
)
def test_durations_longer_than_a_recording_may_be_are_refused(
    tmp_path: Path, old: str, new: str, field: str
) -> None:
    path = write(tmp_path, GOOD.replace(old, new))
    with pytest.raises(
        CampaignSpecError, match=rf"{re.escape(field)}: 1000000000.0 s is more than 600 s"
    ):
        load_campaign_spec(path)


SECOND = GOOD + '[device]\nprofile = "realistic"\n[second_device]\n'


def test_a_second_device_repeats_the_main_runs_with_their_seeds_after_the_others(
    tmp_path: Path,
) -> None:
    spec = load_campaign_spec(write(tmp_path, SECOND + "[noise_sweep]\nnoise_scales = [2.0]\n"))
    # main: 1 case x 2 points x 2 repeats; sweep: 4 more; second device: the 4 main again
    assert (spec.n_main_runs, spec.n_sweep_runs, spec.n_second_device_runs) == (4, 4, 4)
    assert spec.n_runs == 12
    model, hardware = paper_antenna(), replace(paper_antenna(), name="second")
    runs = expand_runs(spec, paper_antenna(), second_model=model, second_device=hardware)
    main, sweep, second = runs[:4], runs[4:8], runs[8:]
    # the main and sweep runs are what they are without a second device
    without = load_campaign_spec(
        write(
            tmp_path,
            GOOD + '[device]\nprofile = "realistic"\n[noise_sweep]\nnoise_scales = [2.0]\n',
        )
    )
    assert [(r.run_id, r.seed, dict(r.scenario)) for r in main + sweep] == [
        (r.run_id, r.seed, dict(r.scenario)) for r in expand_runs(without, paper_antenna())
    ]
    assert [r.index for r in runs] == list(range(12))
    # same manoeuvres and seeds as the main runs, ids with the suffix, the second device's
    # antennas, and no imperfections (profile nominal) where the main runs draw them
    assert [r.run_id for r in second] == [f"{r.run_id}-d2" for r in main]
    assert [(r.case, r.contact_point, r.repeat, r.seed) for r in second] == [
        (r.case, r.contact_point, r.repeat, r.seed) for r in main
    ]
    assert all(r.antenna is model and r.device is hardware for r in second)
    assert all("device" in r.scenario for r in main)
    assert all("device" not in r.scenario for r in second)


def test_a_second_device_with_its_own_imperfections_draws_them(tmp_path: Path) -> None:
    text = GOOD + '[second_device]\nprofile = "realistic"\nimperfections.tip_mass = 2e-5\n'
    spec = load_campaign_spec(write(tmp_path, text))
    runs = expand_runs(spec, paper_antenna())
    assert all("device" not in r.scenario for r in runs[:4])
    drawn = [r.scenario["device"] for r in runs[4:]]
    assert all(d.tip_mass == 2e-5 for d in drawn)
    # one device built, its set-up drawn per manoeuvre by its seed
    assert len({d.clamp_stiffness for d in drawn}) == 1
    assert len({d.encoder_offset for d in drawn}) == 4


def test_the_second_device_is_in_the_fingerprint_only_when_present(tmp_path: Path) -> None:
    base = GOOD + '[device]\nprofile = "realistic"\n'
    plain = load_campaign_spec(write(tmp_path, base))
    second = load_campaign_spec(write(tmp_path, SECOND))
    dropped = load_campaign_spec(write(tmp_path, SECOND + "enabled = false\n"))
    assert "second_device" not in plain.to_dict()  # stored campaigns without one still resume
    assert dropped == replace(plain, source=dropped.source)
    assert plain.fingerprint() == dropped.fingerprint() != second.fingerprint()
    assert plain.preparation_fingerprint() == second.preparation_fingerprint()
    from sensing_antenna.campaign.parsing import parse_campaign_spec

    assert parse_campaign_spec(second.to_dict(), "copy") == replace(second, source="copy")
    # the second device's own campaign: its preparation is that of the nominal device
    nominal = load_campaign_spec(write(tmp_path, GOOD))
    alone = second.second_device_spec()
    assert alone.preparation_fingerprint() == nominal.preparation_fingerprint()
    assert alone.fingerprint() == nominal.fingerprint()
    with pytest.raises(CampaignSpecError, match="second_device: the spec has no second device"):
        plain.second_device_spec()


@pytest.mark.parametrize(
    ("section", "field"),
    [
        ('profile = "sloppy"', "second_device.profile"),
        ("profile = 3", "second_device.profile"),
        ("imperfections.tip_mass = -1.0", "second_device.imperfections.tip_mass"),
        ("imperfections = 2", "second_device.imperfections"),
        ('antenna = "paper-2021"', "second_device.antenna"),
        ('enabled = "yes"', "second_device.enabled"),
    ],
)
def test_bad_second_device_fields_are_named_with_the_file(
    tmp_path: Path, section: str, field: str
) -> None:
    path = write(tmp_path, SECOND + section + "\n")
    with pytest.raises(CampaignSpecError, match=re.escape(f"{path}: {field}:")):
        load_campaign_spec(path)


def test_runs_a_second_device_adds_over_the_limit_are_refused_naming_it(tmp_path: Path) -> None:
    repeats = MAX_RUNS // 2 + 1  # the main runs fit, with the second device's they do not
    text = GOOD.replace("contact_points = [0.3, 0.5]", "contact_points = [0.3]").replace(
        "repeats = 2", f"repeats = {repeats}"
    )
    path = write(tmp_path, text + "[second_device]\n")
    message = f"{2 * repeats} runs ({repeats} main, 0 in the noise sweep, {repeats} on the second"
    with pytest.raises(
        CampaignSpecError, match=re.escape(f"{path}: second_device: ") + ".*" + re.escape(message)
    ):
        load_campaign_spec(path)


def test_a_plane_campaign_off_the_tip_is_refused_naming_the_point(tmp_path: Path) -> None:
    text = GOOD.replace("contact_points = [0.3, 0.5]", "contact_points = [0.98, 0.5]")
    spec = load_campaign_spec(write(tmp_path, text + 'obstacle = "plane"\n'))
    with pytest.raises(CampaignSpecError) as info:
        spec.load_device()
    message = str(info.value)
    assert "contact_points[1]" in message and "link length 0.98 m" in message
    at_tip = load_campaign_spec(
        write(tmp_path, text.replace("[0.98, 0.5]", "[0.98]") + 'obstacle = "plane"\n')
    )
    assert at_tip.load_device().link.length == 0.98


def test_the_free_motions_are_a_free_sweep_of_each_swept_joint(tmp_path: Path) -> None:
    # Section 5.2: the threshold comes from the free movements; by default one free sweep per
    # joint the campaign sweeps (its runs, the noise sweep's, the calibration's), or the one
    # free_motion.case names
    assert default_campaign_spec().free_motion_cases() == ("free", "free-vertical")
    spec = load_campaign_spec(write(tmp_path, GOOD + "\n[free_motion]\nidentify = true\n"))
    assert spec.free_motion_cases() == ("free",)
    calibrated = GOOD + "\n[free_motion]\nidentify = true\n[calibration]\nenabled = true\n"
    calibrated += 'case = "vertical"\ncontact_points = [0.4, 0.6]\n'
    both = load_campaign_spec(write(tmp_path, calibrated))
    assert both.free_motion_cases() == ("free", "free-vertical")
    assert both.preparation_fingerprint() != spec.preparation_fingerprint()
    one = GOOD + '\n[free_motion]\nidentify = true\ncase = "free-vertical"\n'
    assert load_campaign_spec(write(tmp_path, one)).free_motion_cases() == ("free-vertical",)
    for case in ("sideways", "azimuthal"):
        with pytest.raises(CampaignSpecError, match=r"free_motion\.case: must be one of free, "):
            load_campaign_spec(write(tmp_path, one.replace('"free-vertical"', f'"{case}"')))


def test_the_simulated_controller_knows_the_weight_identification_found() -> None:
    # The device's link carries 0.1 g at its tip that the model lacks; identification read it
    # as a payload, so the identified model weighs it. The controller's weight moment is the
    # identified model's, once (not the device's own tip mass plus the payload again), and the
    # device's physics (its tip_mass) is untouched.
    from sensing_antenna.campaign.simulated import knowing_weight

    model = paper_antenna()
    device = replace(model, link=replace(model.link, tip_mass=1e-4, youngs_modulus=132.65e9))
    identified = replace(model, link=replace(model.link, tip_mass=1e-4))
    known = knowing_weight(device, identified)
    assert known.link.weight_moment == pytest.approx(identified.link.weight_moment, rel=1e-12)
    assert known.link.tip_mass == device.link.tip_mass
    assert known.observer == identified.observer
