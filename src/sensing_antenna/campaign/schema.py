"""The campaign spec as data: frozen, validated dataclasses (what to simulate, how to estimate).

A :class:`CampaignSpec` is the experiment plan of Section 5.6 of the paper: for each case
(azimuthal or vertical movement), each contact point and each repeat, one simulated contact
manoeuvre, estimated by every method, with optional steps before the runs (free-motion
identification, calibration of T_e), a simulated device that may differ from the nominal model,
an optional noise sweep and an optional second device that runs the same manoeuvres. Every
dataclass checks its own fields; a bad value raises :class:`CampaignSpecError` naming the field
(and the file, when the spec came from one). TOML files become specs in
:mod:`~sensing_antenna.campaign.parsing`; specs become runs in
:mod:`~sensing_antenna.campaign.runs`.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from sensing_antenna.antenna import Antenna, AntennaConfigError, load_antenna, metres_hint
from sensing_antenna.campaign import limits
from sensing_antenna.errors import FieldError
from sensing_antenna.simulator.device import (
    DEVICE_PROFILES,
    DeviceError,
    DeviceImperfections,
    device_from_mapping,
    device_profile,
)
from sensing_antenna.simulator.scenario import FREE_CASE_OF, FREE_CASES, duration_problem

__all__ = [
    "CASES",
    "CONTACT_POINT_RESOLUTION",
    "DEFAULT_CALIBRATION_POINTS",
    "DEVICE_SECTIONS",
    "METHODS",
    "SCENARIO_NOISE_SCALE",
    "SECOND_DEVICE_SUFFIX",
    "CalibrationStep",
    "CampaignSpec",
    "CampaignSpecError",
    "DeviceSpec",
    "FreeMotionStep",
    "NoiseSweep",
    "SecondDevice",
    "contact_point_key",
    "known_methods",
    "noise_level_key",
    "same_noise_level",
]

#: Manoeuvres of Section 5.6: Case 1 azimuthal movement, Case 2 vertical movement.
CASES = ("azimuthal", "vertical")

#: Default estimation methods: the paper's fused estimator and the two baselines. Any key of
#: ``sensing_antenna.estimation.METHODS`` is accepted (see :func:`known_methods`).
METHODS = ("paper", "ratio", "two-frequency")

#: ``simulator.Scenario.noise_scale`` when the spec's ``[scenario]`` does not set it: the
#: simulator's nominal sensor noise.
SCENARIO_NOISE_SCALE = 1.0

#: Run ids of the second device's runs end in this (after the main run's id).
SECOND_DEVICE_SUFFIX = "-d2"

#: Contact points are told apart to this resolution (m), in the distinctness checks and in the
#: run ids alike (:func:`contact_point_key`): 1 micrometre, far below anything the estimators
#: resolve, so two points a spec means as different are never one run.
CONTACT_POINT_RESOLUTION = 1e-6

#: Antenna sections a ``[device]`` section may override, with the fields allowed in each. The
#: link's ``calibrated_t`` and its scatters are model parameters, not hardware, so a
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

#: Scenario keys the campaign sets itself for every run.
_RESERVED_SCENARIO_KEYS = ("case", "contact_point", "seed", "device")


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
    case : str or None
        Manoeuvre of the one free motion (``"free"``, ``"free-vertical"``); None: a free sweep
        of each joint the campaign's cases sweep (Section 5.2's "free movements").
    """

    identify: bool = False
    duration: float = 4.0
    case: str | None = None

    def free_cases(self, cases: Sequence[str]) -> tuple[str, ...]:
        """The simulator cases of the free motions for a campaign sweeping ``cases``."""
        if self.case is not None:
            return (self.case,)
        swept = [free for case, free in FREE_CASE_OF.items() if case in cases]
        return tuple(swept) or ("free",)

    def __post_init__(self) -> None:
        if problem := duration_problem(self.duration):
            raise CampaignSpecError("free_motion.duration", problem)
        if self.case is not None and self.case not in FREE_CASES:
            raise CampaignSpecError(
                "free_motion.case",
                f"must be one of {', '.join(FREE_CASES)} (a sweep with nothing to touch), "
                f"got {self.case!r}",
            )


@dataclass(frozen=True)
class DeviceSpec:
    """The simulated hardware, when it differs from the nominal model the estimators know.

    Parameters
    ----------
    antenna : str or None
        Built-in antenna name or antenna TOML file of the device; None: the campaign's antenna.
    overrides : mapping of str to mapping of str to float
        Field values replacing the base antenna's, by section (:data:`DEVICE_SECTIONS`), SI.
    profile : {"nominal", "realistic"}
        Imperfections of the device the model does not know: "nominal" none (besides
        ``imperfections``), "realistic" one device built from the manufacturing spread, whose
        set-up (drift, encoder zero) is drawn anew for every simulated manoeuvre from its seed
        (``simulator.realistic_device``).
    imperfections : mapping of str to value
        Fields of ``simulator.DeviceImperfections`` set on every manoeuvre (over the profile's
        draw), e.g. ``tip_mass = 1e-4``.
    build : int or None
        Which realistic device is built (the seed of its manufacturing draw); None: the
        campaign's ``base_seed``.
    """

    antenna: str | None = None
    overrides: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    profile: str = "nominal"
    imperfections: Mapping[str, Any] = field(default_factory=dict)
    build: int | None = None

    def __post_init__(self) -> None:
        if self.profile not in DEVICE_PROFILES:
            raise CampaignSpecError(
                "device.profile",
                f"must be one of {', '.join(DEVICE_PROFILES)}, got {self.profile!r}",
            )
        try:
            device_from_mapping(self.imperfections, "device.imperfections")
        except DeviceError as exc:
            raise CampaignSpecError(
                f"device.imperfections.{exc.field_name}", str(exc).split(": ", 1)[-1]
            ) from exc
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
                        if key in ("calibrated_t", "calibration_scatter", "mode2_scatter")
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

    @property
    def has_imperfections(self) -> bool:
        """True when some manoeuvre's device departs from the nominal one (profile or table)."""
        return self.profile != "nominal" or bool(self.imperfections)

    def build_of(self, base_seed: int) -> int:
        """The realistic device's build: ``build`` when set, else the campaign's ``base_seed``."""
        return base_seed if self.build is None else self.build

    def imperfections_for(self, seed: int, length: float, base_seed: int) -> DeviceImperfections:
        """The imperfections of the manoeuvre of seed ``seed`` on a link of ``length`` (m) in a
        campaign of ``base_seed``: the profile's draw for the device of :meth:`build_of` with
        the ``imperfections`` table set over it."""
        drawn = device_profile(self.profile, seed, length, self.build_of(base_seed))
        if not self.imperfections:
            return drawn
        fixed = device_from_mapping(self.imperfections, "device.imperfections")
        given = {key: getattr(fixed, key) for key in self.imperfections}
        return replace(drawn, **given)

    def as_built(self, length: float, base_seed: int) -> DeviceImperfections:
        """The imperfections every manoeuvre of the device shares, its build's (tip mass,
        clamp, taper, joint, sensor), with the set-up of the campaign's first seed."""
        return self.imperfections_for(base_seed, length, base_seed)

    def to_dict(self) -> dict[str, Any]:
        """Plain data in the layout of the TOML section (the profile and imperfections only
        when set, so a spec without them keeps its fingerprint)."""
        data: dict[str, Any] = {}
        if self.antenna is not None:
            data["antenna"] = self.antenna
        for section, values in self.overrides.items():
            if values:
                data[section] = {k: float(v) for k, v in values.items()}
        if self.profile != "nominal":
            data["profile"] = self.profile
        if self.build is not None:
            data["build"] = self.build
        if self.imperfections:
            data["imperfections"] = dict(self.imperfections)
        return data


def _check_reserved(
    scenario: Mapping[str, Any], section: str, setter: str, source: str | None = None
) -> None:
    """Refuse a Scenario field of ``section`` that the campaign sets itself (``setter`` says
    who), naming it as ``section.<key>``."""
    for key in scenario:
        if key in _RESERVED_SCENARIO_KEYS:
            where = (
                "comes from [device] (profile, imperfections)"
                if key == "device"
                else f"is set by {setter}"
            )
            raise CampaignSpecError(f"{section}.{key}", f"{where}; remove it", source)


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
    sensor : bool
        Also calibrate the F/T sensor's cross-talk (``calibration.sensor``) on the step's
        recordings and as many of the other sweep direction at the same points; T_e is fitted
        on the step's ``case`` alone.
    tip_mass : bool
        Fit the link's tip mass with T_e (``calibration.frequency.calibrate_t_e``).
    scenario : dict
        ``simulator.Scenario`` fields that the calibration recordings take instead of the
        campaign's ``[scenario]`` ones (``[calibration.scenario]``): a lab calibrates with gentle
        pushes, ``push = 0.03``, and may then push its runs hard.
    """

    enabled: bool = False
    case: str = "azimuthal"
    contact_points: tuple[float, ...] = DEFAULT_CALIBRATION_POINTS
    repeats: int = 1
    loss: str = "soft_l1"
    sensor: bool = False
    tip_mass: bool = False
    scenario: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.case not in CASES:
            raise CampaignSpecError(
                "calibration.case", f"unknown {self.case!r}; known: {', '.join(CASES)}"
            )
        if len(self.contact_points) < 2:
            raise CampaignSpecError(
                "calibration.contact_points", "needs at least 2 points (m) to fit T_e"
            )
        if problem := limits.contact_points_problem(len(self.contact_points)):
            raise CampaignSpecError("calibration.contact_points", problem)
        for i, x in enumerate(self.contact_points):
            if not (math.isfinite(x) and x > 0):
                raise CampaignSpecError(
                    f"calibration.contact_points[{i}]", f"must be a finite length > 0 m, got {x!r}"
                )
        if self.repeats < 1:
            raise CampaignSpecError("calibration.repeats", f"must be >= 1, got {self.repeats!r}")
        if problem := limits.calibration_problem(len(self.contact_points), self.repeats):
            raise CampaignSpecError("calibration.repeats", problem)
        if self.loss not in _CALIBRATION_LOSSES:
            raise CampaignSpecError(
                "calibration.loss",
                f"unknown {self.loss!r}; known: {', '.join(_CALIBRATION_LOSSES)}",
            )
        _check_reserved(self.scenario, "calibration.scenario", "the calibration for each recording")

    @property
    def cases(self) -> tuple[str, ...]:
        """The sweep directions recorded: ``case``, and the other with ``sensor``."""
        if not self.sensor:
            return (self.case,)
        other = "vertical" if self.case == "azimuthal" else "azimuthal"
        return (self.case, other)

    @property
    def n_recordings(self) -> int:
        """Calibration recordings (cases x contact points x repeats)."""
        return len(self.cases) * len(self.contact_points) * self.repeats

    def to_dict(self) -> dict[str, Any]:
        """Plain data in the layout of the TOML section (``sensor``, ``tip_mass`` and
        ``scenario`` only when set, so a spec without them keeps its fingerprint)."""
        data: dict[str, Any] = {
            "enabled": self.enabled,
            "case": self.case,
            "contact_points": list(self.contact_points),
            "repeats": self.repeats,
            "loss": self.loss,
        }
        if self.sensor:
            data["sensor"] = True
        if self.tip_mass:
            data["tip_mass"] = True
        if self.scenario:
            data["scenario"] = dict(self.scenario)
        return data


@dataclass(frozen=True)
class NoiseSweep:
    """Optional extra runs at other sensor noise levels: accuracy against noise.

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
        if problem := limits.noise_levels_problem(len(self.noise_scales)):
            raise CampaignSpecError("noise_sweep.noise_scales", problem)
        for i, s in enumerate(self.noise_scales):
            if not (math.isfinite(s) and s >= 0):
                raise CampaignSpecError(
                    f"noise_sweep.noise_scales[{i}]", f"must be a finite number >= 0, got {s!r}"
                )
        if len({noise_level_key(s) for s in self.noise_scales}) != len(self.noise_scales):
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


@dataclass(frozen=True)
class SecondDevice:
    """Optional: the main runs again on a second device, for a side-by-side comparison.

    The second device is the ``[device]`` hardware (its antenna and overrides) with its own
    imperfections: by default none (``profile = "nominal"``), the device the model describes
    up to its stiffness. Its runs repeat the main runs (cases x contact points x repeats) with
    the main runs' seeds, so the two devices see the same manoeuvres and sensor noise; its
    preparation (identification, calibration) is its own, made as the main one is, with the
    same seeds.

    Parameters
    ----------
    enabled : bool
        Whether the campaign runs the second device.
    profile : {"nominal", "realistic"}
        As ``[device] profile``, for the second device.
    imperfections : mapping of str to value
        As ``[device] imperfections``, for the second device.
    """

    enabled: bool = False
    profile: str = "nominal"
    imperfections: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        try:
            DeviceSpec(profile=self.profile, imperfections=self.imperfections)
        except CampaignSpecError as exc:
            name = exc.field_name.replace("device.", "second_device.", 1)
            raise CampaignSpecError(name, exc.problem) from exc

    def device(self, hardware: DeviceSpec) -> DeviceSpec:
        """The second device's spec: ``hardware``'s antenna and overrides, these imperfections."""
        return replace(hardware, profile=self.profile, imperfections=dict(self.imperfections))

    def to_dict(self) -> dict[str, Any]:
        """Plain data in the layout of the TOML section."""
        data: dict[str, Any] = {"enabled": self.enabled, "profile": self.profile}
        if self.imperfections:
            data["imperfections"] = dict(self.imperfections)
        return data


def _check_contact_points(key: str, points: Sequence[float], source: str | None) -> None:
    """At least one contact point, each a finite length > 0 m, all distinct (to 1 um)."""
    if not points:
        raise CampaignSpecError(key, "must list at least one point (m)", source)
    if problem := limits.contact_points_problem(len(points)):
        raise CampaignSpecError(key, problem, source)
    for i, x in enumerate(points):
        if not (math.isfinite(x) and x > 0):
            raise CampaignSpecError(
                f"{key}[{i}]", f"must be a finite length > 0 m, got {x!r}", source
            )
    first: dict[int, int] = {}
    for i, x in enumerate(points):
        j = first.setdefault(contact_point_key(x), i)
        if j != i:
            raise CampaignSpecError(
                key,
                f"must be distinct to {CONTACT_POINT_RESOLUTION * 1e6:g} um (as in the run ids): "
                f"[{j}] = {points[j]!r} and [{i}] = {x!r} are one point",
                source,
            )


def contact_point_key(contact_point: float) -> int:
    """A contact point as the checks and the run ids tell it apart: whole micrometres."""
    return round(contact_point * 1e6)


def noise_level_key(noise_scale: float) -> int:
    """A noise level as it appears in run ids: hundredths of the nominal noise."""
    return round(noise_scale * 100)


def same_noise_level(a: float, b: float) -> bool:
    """Whether two noise levels are the same to 0.01 (as in the run ids)."""
    return noise_level_key(a) == noise_level_key(b)


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
    second_device : SecondDevice
        Optional: the main runs again on a second device; by default none.
    fast_bound : bool
        Whether each run's ``fast`` row also gets the information bound of its delay
        (``estimation.methods.fast.bound_delay``, docs/fast.md): the windows from t_1 up to the
        first that qualifies, those before the pipeline's hold fitted for it alone. Default on.
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
    second_device: SecondDevice = field(default_factory=SecondDevice)
    fast_bound: bool = True
    description: str = ""
    source: str = ""

    def __post_init__(self) -> None:
        src = self.source or None
        if not (isinstance(self.name, str) and self.name and self.name.isprintable()):
            # one line: it titles the report
            raise CampaignSpecError("name", f"must be a line of text, got {self.name!r}", src)
        _check_choices("cases", self.cases, CASES, src)
        _check_choices("methods", self.methods, known_methods(), src)
        _check_contact_points("contact_points", self.contact_points, src)
        if self.repeats < 1:
            raise CampaignSpecError("repeats", f"must be >= 1, got {self.repeats!r}", src)
        if self.base_seed < 0:
            raise CampaignSpecError("base_seed", f"must be >= 0, got {self.base_seed!r}", src)
        if not isinstance(self.fast_bound, bool):
            raise CampaignSpecError("fast_bound", "must be true or false", src)
        if problem := limits.runs_problem(
            self.n_main_runs, self.n_sweep_runs, self.n_second_device_runs
        ):
            field_name = "repeats" if self.n_main_runs > limits.MAX_RUNS else "noise_sweep"
            if self.n_main_runs + self.n_sweep_runs <= limits.MAX_RUNS:
                field_name = "second_device"
            raise CampaignSpecError(field_name, problem, src)
        duration = self.scenario.get("duration")
        if duration is not None and (problem := duration_problem(duration)):
            raise CampaignSpecError("scenario.duration", problem, src)
        _check_reserved(self.scenario, "scenario", "the campaign for each run", src)
        main = self.noise_scale
        for i, s in enumerate(self.noise_sweep.noise_scales):
            if math.isfinite(main) and noise_level_key(s) == noise_level_key(main):
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
    def n_second_device_runs(self) -> int:
        """Runs on the second device (the main runs again), 0 without one."""
        return self.n_main_runs if self.second_device.enabled else 0

    @property
    def n_runs(self) -> int:
        """Number of simulated runs: the main runs, the noise sweep's, the second device's."""
        return self.n_main_runs + self.n_sweep_runs + self.n_second_device_runs

    def second_device_spec(self) -> CampaignSpec:
        """The campaign of the second device alone: this spec with its device as ``[device]``,
        without noise sweep or second device.

        Its main runs are this spec's second-device runs (same cases, points, repeats and
        seeds, ids without the suffix), and its preparation is the second device's.

        Raises
        ------
        CampaignSpecError
            When the spec has no second device.
        """
        if not self.second_device.enabled:
            raise CampaignSpecError(
                "second_device", "the spec has no second device", self.source or None
            )
        return replace(
            self,
            device=self.second_device.device(self.device),
            noise_sweep=NoiseSweep(),
            second_device=SecondDevice(),
        )

    @property
    def all_cases(self) -> tuple[str, ...]:
        """Every case of the campaign, main runs first, then any only the sweep has."""
        return self.cases + tuple(c for c in self.sweep_cases if c not in self.cases)

    def free_motion_cases(self) -> tuple[str, ...]:
        """The simulator cases of the free-motion step: ``free_motion.case``, else a free sweep
        of each joint the campaign sweeps (its runs, the noise sweep's, the calibration's)."""
        swept = self.all_cases
        if self.calibration.enabled and self.calibration.case not in swept:
            swept = (*swept, self.calibration.case)
        return self.free_motion.free_cases(swept)

    def load_antenna(self) -> Antenna:
        """The campaign's nominal model; checks every contact point lies on its link."""
        antenna = self._named_antenna("antenna", self.antenna)
        self._check_points(antenna, "")
        return antenna

    def _named_antenna(self, key: str, name: str) -> Antenna:
        """:func:`~sensing_antenna.antenna.load_antenna` of the spec's field ``key``; a file
        that does not exist is named with the spec and the field that names it."""
        try:
            return load_antenna(name)
        except AntennaConfigError as exc:
            if exc.field_name != "antenna" or Path(name).is_file():
                raise
            raise CampaignSpecError(key, f"{name}: {exc.problem}", self.source or None) from None

    def load_device(self) -> Antenna:
        """The simulated hardware: the device's antenna with its overrides applied.

        Raises
        ------
        CampaignSpecError
            Naming ``device.<section>.<field>`` when an override is out of range, or a contact
            point beyond the device's link.
        """
        antenna = (
            self._named_antenna("device.antenna", self.device.antenna)
            if self.device.antenna
            else self._named_antenna("antenna", self.antenna)
        )
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
        if self.scenario.get("obstacle") == "plane":
            self._check_tip_points(antenna.link.length)
        return antenna

    def _check_tip_points(self, length: float) -> None:
        """A plane is touched by the link's tip: every contact point must be the device's l."""
        for key, points in self._point_lists():
            for i, x in enumerate(points):
                if not math.isclose(x, length, rel_tol=1e-9):
                    raise CampaignSpecError(
                        f"{key}[{i}]",
                        f"{x!r} m: scenario.obstacle = 'plane' is touched by the link tip, so "
                        f"every contact point must be the device's link length {length:g} m",
                        self.source or None,
                    )

    def _point_lists(self) -> list[tuple[str, Sequence[float]]]:
        """Every list of contact points the spec simulates, under its field name."""
        checks: list[tuple[str, Sequence[float]]] = [("contact_points", self.contact_points)]
        if self.noise_sweep.enabled and self.noise_sweep.contact_points is not None:
            checks.append(("noise_sweep.contact_points", self.noise_sweep.contact_points))
        if self.calibration.enabled:
            checks.append(("calibration.contact_points", self.calibration.contact_points))
        return checks

    def _check_points(self, antenna: Antenna, what: str) -> None:
        for key, points in self._point_lists():
            for i, x in enumerate(points):
                if x > antenna.link.length:
                    hint = metres_hint(x, 0.0, antenna.link.length)
                    raise CampaignSpecError(
                        f"{key}[{i}]",
                        f"{what}{x!r} m is beyond the link length {antenna.link.length:g} m{hint}",
                        self.source or None,
                    )

    def to_dict(self) -> dict[str, Any]:
        """Plain data (JSON/TOML-ready) that :func:`parse_campaign_spec` reads back.

        ``noise_sweep`` and ``second_device`` appear only when enabled, and ``fast_bound`` only
        when off, so a spec without them has the fingerprint of one that never mentions them.
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
        if self.second_device.enabled:
            data["second_device"] = self.second_device.to_dict()
        if not self.fast_bound:
            data["fast_bound"] = False
        return data

    def preparation_fingerprint(self) -> str:
        """Short hash of what the preparation steps (identification, calibration) depend on.

        The antennas, the scenario, the base seed, the two steps' sections and, when the
        observer is identified, the free motions' cases; not the runs' contact points, repeats
        or methods.
        """
        data = self.to_dict()
        keys = ("antenna", "scenario", "base_seed", "free_motion", "device", "calibration")
        hashed = {k: data[k] for k in keys}
        if self.free_motion.identify:
            hashed["free_motion_cases"] = list(self.free_motion_cases())
        text = json.dumps(hashed, sort_keys=True)
        return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]

    def determining(self) -> dict[str, Any]:
        """:meth:`to_dict` less what does not determine the results (name and description)."""
        data = self.to_dict()
        data.pop("name")
        data.pop("description")
        return data

    def fingerprint(self) -> str:
        """Short hash of everything that determines the results (:meth:`determining`)."""
        text = json.dumps(self.determining(), sort_keys=True)
        return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


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
