"""Declarative campaign specifications (TOML) and their expansion into individual runs.

A campaign is the experiment plan of Section 5.6 of the paper: for each case (azimuthal or vertical
movement), each contact point and each repeat, one simulated contact manoeuvre, estimated by every
method. The built-in spec ``paper-2021`` reproduces the paper: 15 contact points x 5 repeats x 2
cases = 150 runs. A spec file looks like::

    name = "small"
    antenna = "paper-2021"          # built-in name, or a TOML file relative to this spec
    cases = ["azimuthal", "vertical"]
    contact_points = [0.3, 0.6, 0.9] # m
    repeats = 2
    base_seed = 7
    methods = ["paper", "ratio", "two-frequency"]

    [scenario]                      # keyword arguments of simulator.Scenario, SI units
    noise_scale = 1.0
    damping_ratio = 0.005

    [free_motion]                   # optional: identify the Eq. 15 observer first (Section 5.2)
    identify = true
    duration = 4.0                  # s

    [device]                        # optional: the simulated hardware, when it is not the model
    antenna = "paper-2021"          # default: the top-level antenna
    link.youngs_modulus = 132.65e9  # field overrides, SI

    [calibration]                   # optional: fit T_e on the device first (Section 5.1)
    enabled = true
    case = "azimuthal"
    contact_points = [0.30, 0.35, 0.40]  # m
    repeats = 1
    loss = "soft_l1"

    [noise_sweep]                   # optional: extra runs at other sensor noise levels
    noise_scales = [0.5, 2.0]       # multiples of the simulator's nominal noise
    contact_points = [0.3, 0.6]     # default: the main contact points
    repeats = 1                     # default: the main repeats
    cases = ["azimuthal"]           # default: the main cases

The top-level ``antenna`` is the nominal model the estimators start from; ``[device]`` is what the
simulator uses as the hardware. Without ``[device]`` both are the same.

Seeds are derived from ``base_seed`` and the run index with :class:`numpy.random.SeedSequence`, so
every run's seed is fixed by the spec alone and independent of the order runs execute in.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from sensing_antenna.antenna import Antenna, AntennaConfigError, load_antenna
from sensing_antenna.errors import FieldError
from sensing_antenna.toml_files import parse_toml_file, parse_toml_text

__all__ = [
    "CALIBRATION_STREAM",
    "CASES",
    "DEFAULT_CALIBRATION_POINTS",
    "DEFAULT_SPEC_NAME",
    "DEVICE_SECTIONS",
    "FREE_MOTION_STREAM",
    "METHODS",
    "NOISE_SWEEP_STREAM",
    "RUN_STREAM",
    "SCENARIO_NOISE_SCALE",
    "CalibrationStep",
    "CampaignSpec",
    "CampaignSpecError",
    "DeviceSpec",
    "FreeMotionStep",
    "NoiseSweep",
    "RunSpec",
    "default_campaign_spec",
    "derive_seed",
    "expand_runs",
    "known_methods",
    "load_campaign_spec",
    "parse_campaign_spec",
]

#: Manoeuvres of Section 5.6: Case 1 azimuthal movement, Case 2 vertical movement.
CASES = ("azimuthal", "vertical")

#: Default estimation methods: the paper's fused estimator and the two baselines. Any key of
#: ``sensing_antenna.estimation.METHODS`` is accepted (see :func:`known_methods`).
METHODS = ("paper", "ratio", "two-frequency")

#: Seed streams of :func:`derive_seed`: contact runs, the free-motion step, the calibration step,
#: the runs of the noise sweep.
RUN_STREAM = 0
FREE_MOTION_STREAM = 1
CALIBRATION_STREAM = 2
NOISE_SWEEP_STREAM = 3

#: ``simulator.Scenario.noise_scale`` when the spec's ``[scenario]`` does not set it: the
#: simulator's nominal sensor noise.
SCENARIO_NOISE_SCALE = 1.0

#: Antenna sections a ``[device]`` section may override, with the fields allowed in each. The
#: link's ``calibrated_t`` and ``calibration_scatter`` are model parameters, not hardware, so a
#: device cannot set them.
DEVICE_SECTIONS: dict[str, tuple[str, ...]] = {
    "link": ("length", "radius", "youngs_modulus", "linear_density", "tip_mass", "second_moment"),
    "azimuth_motor": (
        "torque_constant",
        "inertia",
        "viscous_friction",
        "coulomb_voltage",
        "gear_ratio",
    ),
    "elevation_motor": (
        "torque_constant",
        "inertia",
        "viscous_friction",
        "coulomb_voltage",
        "gear_ratio",
    ),
    "observer": ("gain", "natural_frequency", "damping", "contact_threshold"),
}

#: Calibration contact points of Section 5.1: 0.30 m to the tip in 5 cm steps, and the tip.
DEFAULT_CALIBRATION_POINTS = (
    0.30,
    0.35,
    0.40,
    0.45,
    0.50,
    0.55,
    0.60,
    0.65,
    0.70,
    0.75,
    0.80,
    0.85,
    0.90,
    0.95,
    0.98,
)

#: Losses of the T_e fit (those of scipy.optimize.least_squares; see calibration.frequency).
_CALIBRATION_LOSSES = ("linear", "soft_l1", "huber", "cauchy", "arctan")

#: Name of the built-in spec that reproduces Section 5.6.
DEFAULT_SPEC_NAME = "paper-2021"

#: Scenario keys the campaign sets itself for every run.
_RESERVED_SCENARIO_KEYS = ("case", "contact_point", "seed")

_TOP_LEVEL_KEYS = (
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
)

_NOISE_SWEEP_KEYS = ("noise_scales", "contact_points", "repeats", "cases")


class CampaignSpecError(FieldError):
    """A campaign spec field is missing, unknown or invalid; the message names file and field."""


@dataclass(frozen=True)
class FreeMotionStep:
    """Optional first step: simulate a free motion and identify the Eq. 15 observer from it.

    Parameters
    ----------
    identify : bool
        Whether to run the step.
    duration : float
        Length of the simulated free motion (s).
    case : str
        Manoeuvre of the free motion (``"free"``).
    """

    identify: bool = False
    duration: float = 4.0
    case: str = "free"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.duration) and self.duration > 0):
            raise CampaignSpecError("free_motion.duration", f"must be > 0 s, got {self.duration!r}")


@dataclass(frozen=True)
class DeviceSpec:
    """The simulated hardware, when it differs from the nominal model the estimators know.

    Parameters
    ----------
    antenna : str or None
        Built-in antenna name or antenna TOML file of the device; None: the campaign's antenna.
    overrides : mapping of str to mapping of str to float
        Field values replacing the base antenna's, by section (:data:`DEVICE_SECTIONS`), SI.
    """

    antenna: str | None = None
    overrides: Mapping[str, Mapping[str, float]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for section, values in self.overrides.items():
            allowed = DEVICE_SECTIONS.get(section)
            if allowed is None:
                raise CampaignSpecError(
                    f"device.{section}",
                    f"unknown section; known: {', '.join(DEVICE_SECTIONS)}",
                )
            for key, value in values.items():
                if key not in allowed:
                    hint = (
                        " (a model value found by the calibration step, not set on the device)"
                        if key in ("calibrated_t", "calibration_scatter")
                        else f"; known: {', '.join(allowed)}"
                    )
                    raise CampaignSpecError(f"device.{section}.{key}", f"unknown field{hint}")
                if (
                    isinstance(value, bool)
                    or not isinstance(value, (int, float))
                    or not math.isfinite(value)
                ):
                    raise CampaignSpecError(
                        f"device.{section}.{key}", f"must be a finite number (SI), got {value!r}"
                    )

    @property
    def is_model(self) -> bool:
        """True when the device is the campaign's antenna unchanged."""
        return self.antenna is None and not any(self.overrides.values())

    def to_dict(self) -> dict[str, Any]:
        """Plain data in the layout of the TOML section."""
        data: dict[str, Any] = {}
        if self.antenna is not None:
            data["antenna"] = self.antenna
        for section, values in self.overrides.items():
            if values:
                data[section] = {k: float(v) for k, v in values.items()}
        return data


@dataclass(frozen=True)
class CalibrationStep:
    """Optional step before the runs: fit T_e of the frequency model on the device (Section 5.1).

    Parameters
    ----------
    enabled : bool
        Whether to run the step.
    case : str
        Manoeuvre of the calibration recordings (Section 5.1: azimuthal, a vertical surface).
    contact_points : tuple of float
        Known contact points (m); default 0.30 m to 0.95 m every 5 cm and the tip 0.98 m.
    repeats : int
        Recordings per contact point.
    loss : str
        Loss of the T_e fit (``calibration.frequency.fit_inverse_t``).
    """

    enabled: bool = False
    case: str = "azimuthal"
    contact_points: tuple[float, ...] = DEFAULT_CALIBRATION_POINTS
    repeats: int = 1
    loss: str = "soft_l1"

    def __post_init__(self) -> None:
        if self.case not in CASES:
            raise CampaignSpecError(
                "calibration.case", f"unknown {self.case!r}; known: {', '.join(CASES)}"
            )
        if len(self.contact_points) < 2:
            raise CampaignSpecError(
                "calibration.contact_points", "needs at least 2 points (m) to fit T_e"
            )
        for i, x in enumerate(self.contact_points):
            if not (math.isfinite(x) and x > 0):
                raise CampaignSpecError(
                    f"calibration.contact_points[{i}]", f"must be a finite length > 0 m, got {x!r}"
                )
        if self.repeats < 1:
            raise CampaignSpecError("calibration.repeats", f"must be >= 1, got {self.repeats!r}")
        if self.loss not in _CALIBRATION_LOSSES:
            raise CampaignSpecError(
                "calibration.loss",
                f"unknown {self.loss!r}; known: {', '.join(_CALIBRATION_LOSSES)}",
            )

    @property
    def n_recordings(self) -> int:
        """Calibration recordings (contact points x repeats)."""
        return len(self.contact_points) * self.repeats

    def to_dict(self) -> dict[str, Any]:
        """Plain data in the layout of the TOML section."""
        return {
            "enabled": self.enabled,
            "case": self.case,
            "contact_points": list(self.contact_points),
            "repeats": self.repeats,
            "loss": self.loss,
        }


@dataclass(frozen=True)
class NoiseSweep:
    """Optional extra runs at other sensor noise levels (issue 6: accuracy against noise).

    Each level repeats the sweep's cases x contact points x repeats with the scenario's
    ``noise_scale`` replaced by that level; every method estimates the same recordings. The main
    runs count as the level of ``[scenario]`` and are not repeated here.

    Parameters
    ----------
    noise_scales : tuple of float
        Levels, multiples of the simulator's nominal sensor noise (``Scenario.noise_scale``),
        each finite and >= 0, distinct. Empty: no sweep.
    contact_points : tuple of float or None
        Contact points x_c (m) of the sweep; None: the main contact points.
    repeats : int or None
        Runs per (level, case, contact point); None: the main repeats.
    cases : tuple of str or None
        Manoeuvres; None: the main cases.
    """

    noise_scales: tuple[float, ...] = ()
    contact_points: tuple[float, ...] | None = None
    repeats: int | None = None
    cases: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        for i, s in enumerate(self.noise_scales):
            if not (math.isfinite(s) and s >= 0):
                raise CampaignSpecError(
                    f"noise_sweep.noise_scales[{i}]", f"must be a finite number >= 0, got {s!r}"
                )
        if len({_level_key(s) for s in self.noise_scales}) != len(self.noise_scales):
            raise CampaignSpecError(
                "noise_sweep.noise_scales", "must be distinct (to 0.01, as in the run ids)"
            )
        if self.contact_points is not None:
            _check_contact_points("noise_sweep.contact_points", self.contact_points, None)
        if self.repeats is not None and self.repeats < 1:
            raise CampaignSpecError("noise_sweep.repeats", f"must be >= 1, got {self.repeats!r}")
        if self.cases is not None:
            _check_choices("noise_sweep.cases", self.cases, CASES, None)

    @property
    def enabled(self) -> bool:
        """True when the sweep has at least one noise level."""
        return bool(self.noise_scales)

    def to_dict(self) -> dict[str, Any]:
        """Plain data in the layout of the TOML section (only the fields that are set)."""
        data: dict[str, Any] = {"noise_scales": [float(s) for s in self.noise_scales]}
        if self.contact_points is not None:
            data["contact_points"] = list(self.contact_points)
        if self.repeats is not None:
            data["repeats"] = self.repeats
        if self.cases is not None:
            data["cases"] = list(self.cases)
        return data


def _check_contact_points(key: str, points: Sequence[float], source: str | None) -> None:
    """At least one contact point, each a finite length > 0 m, all distinct (to 1 um)."""
    if not points:
        raise CampaignSpecError(key, "must list at least one point (m)", source)
    for i, x in enumerate(points):
        if not (math.isfinite(x) and x > 0):
            raise CampaignSpecError(
                f"{key}[{i}]", f"must be a finite length > 0 m, got {x!r}", source
            )
    if len({round(x * 1e6) for x in points}) != len(points):
        raise CampaignSpecError(key, "must be distinct", source)


def _level_key(noise_scale: float) -> int:
    """A noise level as it appears in run ids (hundredths)."""
    return round(noise_scale * 100)


@dataclass(frozen=True)
class CampaignSpec:
    """A validated campaign: what to simulate and which methods estimate each recording.

    Parameters
    ----------
    name : str
        Campaign name, used in the report title.
    antenna : str
        The nominal model the estimators start from: built-in antenna name or path of an antenna
        TOML file (absolute or relative to the current directory once loaded).
    cases : tuple of str
        Manoeuvres among :data:`CASES`.
    contact_points : tuple of float
        True contact points x_c (m), distinct, each in (0, l].
    repeats : int
        Runs per (case, contact point), each with its own seed.
    base_seed : int
        Seed from which each run's seed is derived (>= 0).
    methods : tuple of str
        Estimation methods among :func:`known_methods`; each run is estimated by all of them.
    scenario : mapping
        Extra keyword arguments of ``simulator.Scenario`` (SI units), same for every run.
    free_motion : FreeMotionStep
        Optional observer identification step.
    device : DeviceSpec
        The simulated hardware; by default the model itself.
    calibration : CalibrationStep
        Optional T_e calibration step on the device.
    noise_sweep : NoiseSweep
        Optional extra runs at other sensor noise levels; by default none.
    description : str
        Free text for the report.
    source : str
        Where the spec came from (file path or built-in name), for messages.
    """

    name: str
    antenna: str
    cases: tuple[str, ...]
    contact_points: tuple[float, ...]
    repeats: int
    base_seed: int
    methods: tuple[str, ...] = METHODS
    scenario: Mapping[str, Any] = field(default_factory=dict)
    free_motion: FreeMotionStep = field(default_factory=FreeMotionStep)
    device: DeviceSpec = field(default_factory=DeviceSpec)
    calibration: CalibrationStep = field(default_factory=CalibrationStep)
    noise_sweep: NoiseSweep = field(default_factory=NoiseSweep)
    description: str = ""
    source: str = ""

    def __post_init__(self) -> None:
        src = self.source or None
        if not self.name:
            raise CampaignSpecError("name", "must be a non-empty string", src)
        _check_choices("cases", self.cases, CASES, src)
        _check_choices("methods", self.methods, known_methods(), src)
        _check_contact_points("contact_points", self.contact_points, src)
        if self.repeats < 1:
            raise CampaignSpecError("repeats", f"must be >= 1, got {self.repeats!r}", src)
        if self.base_seed < 0:
            raise CampaignSpecError("base_seed", f"must be >= 0, got {self.base_seed!r}", src)
        for key in self.scenario:
            if key in _RESERVED_SCENARIO_KEYS:
                raise CampaignSpecError(
                    f"scenario.{key}", "is set by the campaign for each run; remove it", src
                )
        main = self.noise_scale
        for i, s in enumerate(self.noise_sweep.noise_scales):
            if math.isfinite(main) and _level_key(s) == _level_key(main):
                raise CampaignSpecError(
                    f"noise_sweep.noise_scales[{i}]",
                    f"{s!r} is the main runs' level (scenario.noise_scale = {main!r}), which "
                    "already counts in the sweep; remove it",
                    src,
                )

    @property
    def noise_scale(self) -> float:
        """Sensor noise level of the main runs (``scenario.noise_scale``, default 1)."""
        value = self.scenario.get("noise_scale", SCENARIO_NOISE_SCALE)
        try:
            return float(value)
        except (TypeError, ValueError):
            return math.nan  # reported by the scenario check before any run

    @property
    def sweep_cases(self) -> tuple[str, ...]:
        """Cases of the noise sweep (its own or the main ones)."""
        return self.noise_sweep.cases if self.noise_sweep.cases is not None else self.cases

    @property
    def sweep_contact_points(self) -> tuple[float, ...]:
        """Contact points of the noise sweep (its own or the main ones), m."""
        points = self.noise_sweep.contact_points
        return points if points is not None else self.contact_points

    @property
    def sweep_repeats(self) -> int:
        """Repeats of the noise sweep (its own or the main ones)."""
        repeats = self.noise_sweep.repeats
        return repeats if repeats is not None else self.repeats

    @property
    def n_main_runs(self) -> int:
        """Runs at the main noise level (cases x contact points x repeats)."""
        return len(self.cases) * len(self.contact_points) * self.repeats

    @property
    def n_sweep_runs(self) -> int:
        """Extra runs of the noise sweep (levels x its cases x points x repeats)."""
        return (
            len(self.noise_sweep.noise_scales)
            * len(self.sweep_cases)
            * len(self.sweep_contact_points)
            * self.sweep_repeats
        )

    @property
    def n_runs(self) -> int:
        """Number of simulated runs: the main runs and those of the noise sweep."""
        return self.n_main_runs + self.n_sweep_runs

    @property
    def all_cases(self) -> tuple[str, ...]:
        """Every case of the campaign, main runs first, then any only the sweep has."""
        return self.cases + tuple(c for c in self.sweep_cases if c not in self.cases)

    def load_antenna(self) -> Antenna:
        """The campaign's nominal model; checks every contact point lies on its link."""
        antenna = load_antenna(self.antenna)
        self._check_points(antenna, "")
        return antenna

    def load_device(self) -> Antenna:
        """The simulated hardware: the device's antenna with its overrides applied.

        Raises
        ------
        CampaignSpecError
            Naming ``device.<section>.<field>`` when an override is out of range, or a contact
            point beyond the device's link.
        """
        antenna = load_antenna(self.device.antenna or self.antenna)
        for section, values in self.device.overrides.items():
            if not values:
                continue
            part = getattr(antenna, section)
            try:
                part = replace(part, **{k: float(v) for k, v in values.items()})
            except AntennaConfigError as exc:
                name = exc.field_name.split(".", 1)[-1]
                raise CampaignSpecError(
                    f"device.{section}.{name}", exc.problem, self.source or None
                ) from exc
            antenna = replace(antenna, **{section: part})
        if not self.device.is_model:
            antenna = replace(antenna, name=f"{antenna.name} (device)")
        self._check_points(antenna, "device: ")
        return antenna

    def _check_points(self, antenna: Antenna, what: str) -> None:
        checks = [("contact_points", self.contact_points)]
        if self.noise_sweep.enabled and self.noise_sweep.contact_points is not None:
            checks.append(("noise_sweep.contact_points", self.noise_sweep.contact_points))
        if self.calibration.enabled:
            checks.append(("calibration.contact_points", self.calibration.contact_points))
        for key, points in checks:
            for i, x in enumerate(points):
                if x > antenna.link.length:
                    raise CampaignSpecError(
                        f"{key}[{i}]",
                        f"{what}{x!r} m is beyond the link length {antenna.link.length:g} m",
                        self.source or None,
                    )

    def to_dict(self) -> dict[str, Any]:
        """Plain data (JSON/TOML-ready) that :func:`parse_campaign_spec` reads back.

        ``noise_sweep`` appears only when the sweep is enabled, so the fingerprint of a spec
        without one is what it was before sweeps existed (stored campaigns still resume).
        """
        data = {
            "name": self.name,
            "description": self.description,
            "antenna": self.antenna,
            "cases": list(self.cases),
            "contact_points": list(self.contact_points),
            "repeats": self.repeats,
            "base_seed": self.base_seed,
            "methods": list(self.methods),
            "scenario": dict(self.scenario),
            "free_motion": {
                "identify": self.free_motion.identify,
                "duration": self.free_motion.duration,
                "case": self.free_motion.case,
            },
            "device": self.device.to_dict(),
            "calibration": self.calibration.to_dict(),
        }
        if self.noise_sweep.enabled:
            data["noise_sweep"] = self.noise_sweep.to_dict()
        return data

    def preparation_fingerprint(self) -> str:
        """Short hash of what the preparation steps (identification, calibration) depend on.

        The antennas, the scenario, the base seed and the two steps' sections; not the runs'
        contact points, repeats or methods.
        """
        data = self.to_dict()
        keys = ("antenna", "scenario", "base_seed", "free_motion", "device", "calibration")
        text = json.dumps({k: data[k] for k in keys}, sort_keys=True)
        return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]

    def fingerprint(self) -> str:
        """Short hash of everything that determines the results (not name or description)."""
        data = self.to_dict()
        data.pop("name")
        data.pop("description")
        text = json.dumps(data, sort_keys=True)
        return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


@dataclass(frozen=True)
class RunSpec:
    """Everything one run needs: picklable, so it can travel to a worker process or a Dask worker.

    Parameters
    ----------
    index : int
        Position of the run in the campaign (0-based).
    run_id : str
        Stable, file-name-safe identifier, e.g. ``azimuthal-x0300mm-r1``; a run of the noise
        sweep ends in its level, e.g. ``azimuthal-x0300mm-r1-n2.00``.
    case : str
        Manoeuvre (:data:`CASES`).
    contact_point : float
        True contact point x_c (m).
    repeat : int
        Repeat number, 1-based.
    seed : int
        Seed of this run's simulation (derived from the base seed and the run's position: stream
        :data:`RUN_STREAM` for the main runs, :data:`NOISE_SWEEP_STREAM` for the sweep's).
    antenna : Antenna
        The model the estimators use (nominal antenna, identified observer, calibrated T_e).
    methods : tuple of str
        Methods that estimate the recording.
    scenario : mapping
        Extra keyword arguments of ``simulator.Scenario`` (a sweep run's holds its
        ``noise_scale``).
    device : Antenna or None
        The simulated hardware (with the observer its controller uses); None: ``antenna``.
    """

    index: int
    run_id: str
    case: str
    contact_point: float
    repeat: int
    seed: int
    antenna: Antenna
    methods: tuple[str, ...]
    scenario: Mapping[str, Any] = field(default_factory=dict)
    device: Antenna | None = None

    @property
    def noise_scale(self) -> float:
        """Sensor noise level of this run (``scenario["noise_scale"]``, default 1)."""
        return float(self.scenario.get("noise_scale", SCENARIO_NOISE_SCALE))

    @property
    def simulated_antenna(self) -> Antenna:
        """The antenna the simulator uses: ``device`` if given, else ``antenna``."""
        return self.device if self.device is not None else self.antenna


def derive_seed(base_seed: int, index: int, stream: int = RUN_STREAM) -> int:
    """Seed of run ``index``: SeedSequence(base_seed, spawn_key=(stream, index)), first word.

    Stream 0 (:data:`RUN_STREAM`) holds the contact runs, stream 1 the free-motion identification
    step, stream 2 the calibration recordings and stream 3 the runs of the noise sweep, so no two
    of them share a seed sequence.
    """
    state = np.random.SeedSequence(base_seed, spawn_key=(stream, index)).generate_state(1)
    return int(state[0])


def expand_runs(
    spec: CampaignSpec, antenna: Antenna, device: Antenna | None = None
) -> list[RunSpec]:
    """All runs of a campaign in a fixed order: case, then contact point, then repeat.

    The main runs come first (indices and ids as without a sweep); then, if the spec has a noise
    sweep, its runs ordered by level, case, contact point and repeat, with ids ending in
    ``-n<level>`` and seeds from :data:`NOISE_SWEEP_STREAM` (position within the sweep).

    Parameters
    ----------
    spec : CampaignSpec
    antenna : Antenna
        The model the estimators use (the spec's, possibly with an identified observer and a
        calibrated T_e).
    device : Antenna, optional
        The simulated hardware; None simulates with ``antenna``.
    """
    runs: list[RunSpec] = []
    for case in spec.cases:
        for x_c in spec.contact_points:
            for repeat in range(1, spec.repeats + 1):
                index = len(runs)
                runs.append(
                    RunSpec(
                        index=index,
                        run_id=f"{case}-x{round(x_c * 1000):04d}mm-r{repeat}",
                        case=case,
                        contact_point=float(x_c),
                        repeat=repeat,
                        seed=derive_seed(spec.base_seed, index),
                        antenna=antenna,
                        methods=spec.methods,
                        scenario=dict(spec.scenario),
                        device=device,
                    )
                )
    sweep = 0
    for level in spec.noise_sweep.noise_scales:
        scenario = {**spec.scenario, "noise_scale": float(level)}
        for case in spec.sweep_cases:
            for x_c in spec.sweep_contact_points:
                for repeat in range(1, spec.sweep_repeats + 1):
                    runs.append(
                        RunSpec(
                            index=len(runs),
                            run_id=(
                                f"{case}-x{round(x_c * 1000):04d}mm-r{repeat}"
                                f"-n{_level_key(level) / 100:.2f}"
                            ),
                            case=case,
                            contact_point=float(x_c),
                            repeat=repeat,
                            seed=derive_seed(spec.base_seed, sweep, NOISE_SWEEP_STREAM),
                            antenna=antenna,
                            methods=spec.methods,
                            scenario=dict(scenario),
                            device=device,
                        )
                    )
                    sweep += 1
    return runs


def known_methods() -> tuple[str, ...]:
    """Names of the estimation methods (``sensing_antenna.estimation.METHODS``)."""
    try:
        from sensing_antenna.estimation import METHODS as registry
    except ImportError:  # pragma: no cover - the estimation package is part of the install
        return METHODS
    return tuple(registry)


def _check_choices(
    name: str, values: tuple[str, ...], allowed: tuple[str, ...], src: str | None
) -> None:
    if not values:
        raise CampaignSpecError(name, f"must list at least one of {', '.join(allowed)}", src)
    for i, value in enumerate(values):
        if value not in allowed:
            raise CampaignSpecError(
                f"{name}[{i}]", f"unknown {value!r}; known: {', '.join(allowed)}", src
            )
    if len(set(values)) != len(values):
        raise CampaignSpecError(name, "must not repeat a value", src)


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


def parse_campaign_spec(
    data: Mapping[str, Any], source: str, base_dir: Path | None = None
) -> CampaignSpec:
    """Validate plain data (from TOML) into a :class:`CampaignSpec`.

    Parameters
    ----------
    data : mapping
        Parsed TOML.
    source : str
        File name or built-in name, used in error messages.
    base_dir : Path or None
        Directory relative antenna paths are resolved against.
    """
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
    try:
        free_step = FreeMotionStep(
            identify=identify, duration=float(duration), case=str(free.get("case", "free"))
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
            source=source,
        )
    except CampaignSpecError as exc:
        if exc.source is None:
            raise CampaignSpecError(exc.field_name, exc.problem, source) from exc
        raise


def _resolve_antenna(value: str, base_dir: Path | None) -> str:
    if base_dir is not None and not value.startswith("paper-2021"):
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
    for key, values in data.items():
        if key == "antenna":
            continue
        if key not in DEVICE_SECTIONS:
            raise CampaignSpecError(
                f"device.{key}",
                f"unknown key; known: antenna, {', '.join(DEVICE_SECTIONS)}",
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
        return DeviceSpec(antenna=antenna, overrides=overrides)
    except CampaignSpecError as exc:
        raise CampaignSpecError(exc.field_name, exc.problem, source) from exc


def _parse_calibration(data: Any, source: str) -> CalibrationStep:
    if not isinstance(data, Mapping):
        raise CampaignSpecError("calibration", "must be a table", source)
    known = ("enabled", "case", "contact_points", "repeats", "loss")
    for key in data:
        if key not in known:
            raise CampaignSpecError(
                f"calibration.{key}", f"unknown key; known: {', '.join(known)}", source
            )
    enabled = data.get("enabled", False)
    if not isinstance(enabled, bool):
        raise CampaignSpecError("calibration.enabled", "must be true or false", source)
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
    try:
        return CalibrationStep(
            enabled=enabled, case=case, contact_points=points, repeats=repeats, loss=loss
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
    if not scales:
        raise CampaignSpecError(
            "noise_sweep.noise_scales", "must list at least one level (or drop the table)", source
        )
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


def load_campaign_spec(path: str | Path | None = None) -> CampaignSpec:
    """Load a campaign spec from a TOML file, or the built-in ``paper-2021`` spec when None.

    Raises
    ------
    CampaignSpecError
        Naming the file and the field for any missing, unknown or invalid value.
    """
    if path is None or str(path) == DEFAULT_SPEC_NAME:
        return default_campaign_spec()
    file = Path(path)
    if not file.is_file():
        raise CampaignSpecError("spec", "no such file", str(file))
    data = parse_toml_file(
        file, lambda field, problem: CampaignSpecError(field, problem, str(file))
    )
    return parse_campaign_spec(data, str(file), base_dir=file.parent)


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
