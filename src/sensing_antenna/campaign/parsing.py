"""Campaign spec files: TOML text to a validated :class:`~.schema.CampaignSpec`.

A spec file looks like::

    name = "small"
    antenna = "paper-2021"          # built-in name, or a TOML file relative to this spec
    cases = ["azimuthal", "vertical"]
    contact_points = [0.3, 0.6, 0.9] # m
    repeats = 2
    base_seed = 7
    methods = ["paper", "ratio", "two-frequency"]
    fast_bound = true               # the fast method's information bound on its rows (default)

    [scenario]                      # keyword arguments of simulator.Scenario, SI units
    noise_scale = 1.0
    damping_ratio = 0.005

    [free_motion]                   # optional: identify the Eq. 15 observer first (Section 5.2)
    identify = true
    duration = 4.0                  # s

    [device]                        # optional: the simulated hardware, when it is not the model
    antenna = "paper-2021"          # default: the top-level antenna
    link.youngs_modulus = 132.65e9  # field overrides, SI
    profile = "realistic"           # one device built, its set-up drawn per run ("nominal": none)
    build = 7                       # which realistic device (default: the base seed)
    imperfections.tip_mass = 1e-4   # simulator.DeviceImperfections fields, set on every run

    [calibration]                   # optional: fit T_e on the device first (Section 5.1)
    enabled = true
    case = "azimuthal"
    contact_points = [0.30, 0.35, 0.40]  # m
    repeats = 1
    loss = "soft_l1"
    sensor = true                   # also the sensor's cross-talk, from both sweep directions
    tip_mass = true                 # fit the tip mass with T_e

    [noise_sweep]                   # optional: extra runs at other sensor noise levels
    noise_scales = [0.5, 2.0]       # multiples of the simulator's nominal noise; [] for none
    contact_points = [0.3, 0.6]     # default: the main contact points
    repeats = 1                     # default: the main repeats
    cases = ["azimuthal"]           # default: the main cases

    [second_device]                 # optional: the main runs again on a second device
    profile = "nominal"             # the [device] hardware with these imperfections instead
    imperfections.tip_mass = 1e-4   # (default: none); enabled = false drops a base's section

Or a file starts from another campaign and changes some fields, as antenna files do::

    base = "default"                # the built-in campaign (also "paper-2021"), or a spec file
    repeats = 2                     # relative to this one
    [device]
    link.length = 0.9               # merged into the base's [device] table

Tables merge key by key into the base's (at any depth); any other value, a list included,
replaces the base's. Without its own ``name`` the campaign is named after its file; the base's
``description`` is not inherited. Every error names the file and the field.
"""

from __future__ import annotations

from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any

from sensing_antenna.antenna import BUILTIN_ANTENNAS
from sensing_antenna.campaign.schema import (
    DEFAULT_CALIBRATION_POINTS,
    DEVICE_SECTIONS,
    METHODS,
    CalibrationStep,
    CampaignSpec,
    CampaignSpecError,
    DeviceSpec,
    FreeMotionStep,
    NoiseSweep,
    SecondDevice,
)
from sensing_antenna.toml_files import parse_toml_file, parse_toml_text

__all__ = [
    "BUILTIN_CAMPAIGNS",
    "DEFAULT_SPEC_NAME",
    "default_campaign_spec",
    "load_campaign_spec",
    "parse_campaign_spec",
]

#: Name of the built-in spec that reproduces Section 5.6.
DEFAULT_SPEC_NAME = "paper-2021"

#: Names a ``base`` (or the command line) may give for a built-in campaign: its own name and
#: ``"default"``.
BUILTIN_CAMPAIGNS = (DEFAULT_SPEC_NAME, "default")

_TOP_LEVEL_KEYS = (
    "base",
    "name",
    "description",
    "antenna",
    "cases",
    "contact_points",
    "repeats",
    "base_seed",
    "methods",
    "scenario",
    "free_motion",
    "device",
    "calibration",
    "noise_sweep",
    "second_device",
    "fast_bound",
)

_NOISE_SWEEP_KEYS = ("noise_scales", "contact_points", "repeats", "cases")
_SECOND_DEVICE_KEYS = ("enabled", "profile", "imperfections")


def load_campaign_spec(path: str | Path | None = None) -> CampaignSpec:
    """Load a campaign spec from a TOML file, or the built-in ``paper-2021`` spec.

    Parameters
    ----------
    path : str or Path, optional
        A spec file; None, ``"paper-2021"`` or ``"default"``: the built-in spec.

    Raises
    ------
    CampaignSpecError
        Naming the file and the field for any missing, unknown or invalid value.
    """
    if path is None or str(path) in BUILTIN_CAMPAIGNS:
        return default_campaign_spec()
    return _load_file(Path(path), ())


def default_campaign_spec() -> CampaignSpec:
    """The built-in campaign of Section 5.6: 15 points x 5 repeats x 2 cases, all methods."""
    text = (
        resources.files("sensing_antenna")
        .joinpath(f"data/campaign-{DEFAULT_SPEC_NAME}.toml")
        .read_text("utf-8")
    )
    data = parse_toml_text(
        text, lambda field, problem: CampaignSpecError(field, problem, DEFAULT_SPEC_NAME)
    )
    return parse_campaign_spec(data, DEFAULT_SPEC_NAME)


def parse_campaign_spec(
    data: Mapping[str, Any], source: str, base_dir: Path | None = None
) -> CampaignSpec:
    """Validate plain data (from TOML) into a :class:`CampaignSpec`.

    Parameters
    ----------
    data : mapping
        Parsed TOML; may name a ``base`` campaign.
    source : str
        File name or built-in name, used in error messages.
    base_dir : Path or None
        Directory relative antenna and base paths are resolved against.
    """
    return _parse(data, source, base_dir, ())


def _load_file(file: Path, chain: tuple[Path, ...]) -> CampaignSpec:
    """Parse one spec file; ``chain`` holds the files that named it as their base."""
    if not file.is_file():
        raise CampaignSpecError("spec", "no such file", str(file))
    source = str(file)
    data = parse_toml_file(file, lambda field, problem: CampaignSpecError(field, problem, source))
    return _parse(data, source, file.parent, (*chain, file.resolve()))


def _parse(
    data: Mapping[str, Any], source: str, base_dir: Path | None, chain: tuple[Path, ...]
) -> CampaignSpec:
    if "base" in data:
        data = _on_base(data, source, base_dir, chain)
        base_dir = None  # every path in the merged data is resolved already
    return _build(data, source, base_dir)


def _on_base(
    data: Mapping[str, Any], source: str, base_dir: Path | None, chain: tuple[Path, ...]
) -> dict[str, Any]:
    """The base campaign's data with this file's values merged in (paths resolved)."""
    value = data["base"]
    names = ", ".join(f'"{n}"' for n in BUILTIN_CAMPAIGNS)
    if not isinstance(value, str) or not value:
        raise CampaignSpecError(
            "base", f"must name a built-in campaign ({names}) or a file", source
        )
    if value in BUILTIN_CAMPAIGNS:
        base = default_campaign_spec()
    else:
        file = base_dir / value if base_dir is not None else Path(value)
        if not file.is_file():
            raise CampaignSpecError(
                "base",
                f"unknown {value!r}: not a built-in campaign ({names}) and no such file "
                f"({str(file)!r})",
                source,
            )
        if file.resolve() in chain:
            raise CampaignSpecError("base", f"{value!r} is based on this file (a cycle)", source)
        base = _load_file(file, chain)
    own = _resolve_paths({k: v for k, v in data.items() if k != "base"}, base_dir)
    merged = _merge(base.to_dict(), own)
    merged["name"] = own.get("name", Path(source).stem)
    merged["description"] = own.get("description", "")
    return merged


def _merge(base: Mapping[str, Any], override: Mapping[str, Any]) -> dict[str, Any]:
    """``base`` with ``override``'s values; tables merge key by key, at any depth."""
    merged = dict(base)
    for key, value in override.items():
        if isinstance(value, Mapping) and isinstance(merged.get(key), Mapping):
            merged[key] = _merge(merged[key], value)
        else:
            merged[key] = value
    return merged


def _resolve_paths(data: dict[str, Any], base_dir: Path | None) -> dict[str, Any]:
    """``data`` with its antenna files (top level and ``[device]``) resolved against base_dir."""
    if isinstance(data.get("antenna"), str):
        data["antenna"] = _resolve_antenna(data["antenna"], base_dir)
    device = data.get("device")
    if isinstance(device, Mapping) and isinstance(device.get("antenna"), str):
        data["device"] = {**device, "antenna": _resolve_antenna(device["antenna"], base_dir)}
    return data


def _build(data: Mapping[str, Any], source: str, base_dir: Path | None) -> CampaignSpec:
    for key in data:
        if key not in _TOP_LEVEL_KEYS:
            raise CampaignSpecError(
                key, f"unknown key; known: {', '.join(_TOP_LEVEL_KEYS)}", source
            )
    name = _get(data, "name", str, source)
    antenna = data.get("antenna", "paper-2021")
    if not isinstance(antenna, str) or not antenna:
        raise CampaignSpecError("antenna", "must be a built-in name or a file path", source)
    antenna = _resolve_antenna(antenna, base_dir)
    points = _numbers(_get(data, "contact_points", list, source), "contact_points", "m", source)
    repeats = _get(data, "repeats", int, source)
    base_seed = _get(data, "base_seed", int, source)
    methods = _str_list(data, "methods", source) if "methods" in data else METHODS
    scenario = data.get("scenario", {})
    if not isinstance(scenario, Mapping):
        raise CampaignSpecError("scenario", "must be a table of Scenario fields", source)
    free = data.get("free_motion", {})
    if not isinstance(free, Mapping):
        raise CampaignSpecError("free_motion", "must be a table", source)
    for key in free:
        if key not in ("identify", "duration", "case"):
            raise CampaignSpecError(f"free_motion.{key}", "unknown key", source)
    identify = free.get("identify", False)
    if not isinstance(identify, bool):
        raise CampaignSpecError("free_motion.identify", "must be true or false", source)
    duration = free.get("duration", 4.0)
    if isinstance(duration, bool) or not isinstance(duration, (int, float)):
        raise CampaignSpecError("free_motion.duration", "must be a number (s)", source)
    device = _parse_device(data.get("device", {}), source, base_dir)
    calibration = _parse_calibration(data.get("calibration", {}), source)
    noise_sweep = _parse_noise_sweep(data.get("noise_sweep", {}), source)
    second_device = _parse_second_device(data.get("second_device"), source)
    fast_bound = data.get("fast_bound", True)
    if not isinstance(fast_bound, bool):
        raise CampaignSpecError("fast_bound", "must be true or false", source)
    try:
        free_step = FreeMotionStep(
            identify=identify,
            duration=float(duration),
            case=None if free.get("case") is None else str(free["case"]),
        )
        return CampaignSpec(
            name=name,
            description=str(data.get("description", "")),
            antenna=antenna,
            cases=_str_list(data, "cases", source),
            contact_points=points,
            repeats=repeats,
            base_seed=base_seed,
            methods=methods,
            scenario=dict(scenario),
            free_motion=free_step,
            device=device,
            calibration=calibration,
            noise_sweep=noise_sweep,
            second_device=second_device,
            fast_bound=fast_bound,
            source=source,
        )
    except CampaignSpecError as exc:
        if exc.source is None:
            raise CampaignSpecError(exc.field_name, exc.problem, source) from exc
        raise


def _resolve_antenna(value: str, base_dir: Path | None) -> str:
    """A built-in antenna name as it is; a file name relative to ``base_dir`` when it is there."""
    if base_dir is not None and value not in BUILTIN_ANTENNAS:
        candidate = base_dir / value
        if candidate.is_file():
            return str(candidate)
    return value


def _parse_device(data: Any, source: str, base_dir: Path | None) -> DeviceSpec:
    if not isinstance(data, Mapping):
        raise CampaignSpecError("device", "must be a table", source)
    antenna = data.get("antenna")
    if antenna is not None:
        if not isinstance(antenna, str) or not antenna:
            raise CampaignSpecError(
                "device.antenna", "must be a built-in name or a file path", source
            )
        antenna = _resolve_antenna(antenna, base_dir)
    overrides: dict[str, dict[str, float]] = {}
    profile = data.get("profile", "nominal")
    if not isinstance(profile, str):
        raise CampaignSpecError("device.profile", "must be a string", source)
    imperfections = data.get("imperfections", {})
    if not isinstance(imperfections, Mapping):
        raise CampaignSpecError(
            "device.imperfections",
            "must be a table of fields (e.g. imperfections.tip_mass = 1e-4)",
            source,
        )
    build = data.get("build")
    if build is not None and (isinstance(build, bool) or not isinstance(build, int) or build < 0):
        raise CampaignSpecError(
            "device.build", f"must be an integer >= 0 (a seed), got {build!r}", source
        )
    for key, values in data.items():
        if key in ("antenna", "profile", "imperfections", "build"):
            continue
        if key not in DEVICE_SECTIONS:
            raise CampaignSpecError(
                f"device.{key}",
                "unknown key; known: antenna, profile, imperfections, build,"
                f" {', '.join(DEVICE_SECTIONS)}",
                source,
            )
        if not isinstance(values, Mapping):
            raise CampaignSpecError(
                f"device.{key}",
                "must be a table of fields (e.g. link.youngs_modulus = 1e11)",
                source,
            )
        overrides[key] = dict(values)
    try:
        return DeviceSpec(
            antenna=antenna,
            overrides=overrides,
            profile=profile,
            imperfections=dict(imperfections),
            build=build,
        )
    except CampaignSpecError as exc:
        raise CampaignSpecError(exc.field_name, exc.problem, source) from exc


def _parse_calibration(data: Any, source: str) -> CalibrationStep:
    if not isinstance(data, Mapping):
        raise CampaignSpecError("calibration", "must be a table", source)
    known = (
        "enabled",
        "case",
        "contact_points",
        "repeats",
        "loss",
        "sensor",
        "tip_mass",
        "scenario",
    )
    for key in data:
        if key not in known:
            raise CampaignSpecError(
                f"calibration.{key}", f"unknown key; known: {', '.join(known)}", source
            )
    enabled = data.get("enabled", False)
    sensor = data.get("sensor", False)
    tip_mass = data.get("tip_mass", False)
    for key, flag in (("enabled", enabled), ("sensor", sensor), ("tip_mass", tip_mass)):
        if not isinstance(flag, bool):
            raise CampaignSpecError(f"calibration.{key}", "must be true or false", source)
    case = data.get("case", "azimuthal")
    loss = data.get("loss", "soft_l1")
    for key, value in (("case", case), ("loss", loss)):
        if not isinstance(value, str):
            raise CampaignSpecError(
                f"calibration.{key}", f"must be a string, got {value!r}", source
            )
    repeats = data.get("repeats", 1)
    if isinstance(repeats, bool) or not isinstance(repeats, int):
        raise CampaignSpecError(
            "calibration.repeats", f"must be an integer, got {repeats!r}", source
        )
    raw = data.get("contact_points", list(DEFAULT_CALIBRATION_POINTS))
    points = _numbers(raw, "calibration.contact_points", "m", source)
    scenario = data.get("scenario", {})
    if not isinstance(scenario, Mapping):
        raise CampaignSpecError(
            "calibration.scenario", "must be a table of Scenario fields", source
        )
    try:
        return CalibrationStep(
            enabled=enabled,
            case=case,
            contact_points=points,
            repeats=repeats,
            loss=loss,
            sensor=sensor,
            tip_mass=tip_mass,
            scenario=dict(scenario),
        )
    except CampaignSpecError as exc:
        raise CampaignSpecError(exc.field_name, exc.problem, source) from exc


def _numbers(raw: Any, key: str, unit: str, source: str) -> tuple[float, ...]:
    """A TOML list of numbers (``unit`` names them in messages); field ``key[i]`` on error."""
    if not isinstance(raw, list):
        raise CampaignSpecError(key, f"must be a list of numbers ({unit})", source)
    values: list[float] = []
    for i, x in enumerate(raw):
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            raise CampaignSpecError(f"{key}[{i}]", f"must be a number ({unit}), got {x!r}", source)
        values.append(float(x))
    return tuple(values)


def _parse_noise_sweep(data: Any, source: str) -> NoiseSweep:
    if not isinstance(data, Mapping):
        raise CampaignSpecError("noise_sweep", "must be a table", source)
    if not data:
        return NoiseSweep()
    for key in data:
        if key not in _NOISE_SWEEP_KEYS:
            raise CampaignSpecError(
                f"noise_sweep.{key}", f"unknown key; known: {', '.join(_NOISE_SWEEP_KEYS)}", source
            )
    if "noise_scales" not in data:
        raise CampaignSpecError("noise_sweep.noise_scales", "missing", source)
    scales = _numbers(data["noise_scales"], "noise_sweep.noise_scales", "noise multiples", source)
    if not scales:  # no sweep: how a campaign drops its base's sweep
        return NoiseSweep()
    points = (
        _numbers(data["contact_points"], "noise_sweep.contact_points", "m", source)
        if "contact_points" in data
        else None
    )
    repeats = data.get("repeats")
    if repeats is not None and (isinstance(repeats, bool) or not isinstance(repeats, int)):
        raise CampaignSpecError(
            "noise_sweep.repeats", f"must be an integer, got {repeats!r}", source
        )
    cases = None
    if "cases" in data:
        raw = data["cases"]
        if not isinstance(raw, list) or not all(isinstance(c, str) for c in raw):
            raise CampaignSpecError("noise_sweep.cases", "must be a list of case names", source)
        cases = tuple(raw)
    try:
        return NoiseSweep(noise_scales=scales, contact_points=points, repeats=repeats, cases=cases)
    except CampaignSpecError as exc:
        raise CampaignSpecError(exc.field_name, exc.problem, source) from exc


def _parse_second_device(data: Any, source: str) -> SecondDevice:
    """``[second_device]``: present means enabled (unless ``enabled = false``)."""
    if data is None:
        return SecondDevice()
    if not isinstance(data, Mapping):
        raise CampaignSpecError("second_device", "must be a table", source)
    for key in data:
        if key not in _SECOND_DEVICE_KEYS:
            raise CampaignSpecError(
                f"second_device.{key}",
                f"unknown key; known: {', '.join(_SECOND_DEVICE_KEYS)} (the hardware is "
                "[device]'s)",
                source,
            )
    enabled = data.get("enabled", True)
    if not isinstance(enabled, bool):
        raise CampaignSpecError("second_device.enabled", "must be true or false", source)
    if not enabled:
        return SecondDevice()
    profile = data.get("profile", "nominal")
    if not isinstance(profile, str):
        raise CampaignSpecError("second_device.profile", "must be a string", source)
    imperfections = data.get("imperfections", {})
    if not isinstance(imperfections, Mapping):
        raise CampaignSpecError(
            "second_device.imperfections",
            "must be a table of fields (e.g. imperfections.tip_mass = 1e-4)",
            source,
        )
    try:
        return SecondDevice(enabled=True, profile=profile, imperfections=dict(imperfections))
    except CampaignSpecError as exc:
        raise CampaignSpecError(exc.field_name, exc.problem, source) from exc


def _get(data: Mapping[str, Any], key: str, kind: type | tuple[type, ...], src: str) -> Any:
    if key not in data:
        raise CampaignSpecError(key, "missing", src)
    value = data[key]
    if (isinstance(value, bool) and kind is not bool) or not isinstance(value, kind):
        raise CampaignSpecError(key, f"wrong type: got {value!r}", src)
    return value


def _str_list(data: Mapping[str, Any], key: str, src: str) -> tuple[str, ...]:
    value = _get(data, key, list, src)
    for i, item in enumerate(value):
        if not isinstance(item, str):
            raise CampaignSpecError(f"{key}[{i}]", f"must be a string, got {item!r}", src)
    return tuple(value)
