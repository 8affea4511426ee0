"""The simulated device's imperfections: what the hardware does that the estimators' model does not.

:class:`DeviceImperfections` names every departure of the simulated device from the nominal
antenna the estimators use: an unmodelled tip mass, a compliant clamp, a non-uniform link (a
linear taper and a local joint or sleeve), F/T sensor gain errors, cross-axis coupling and drift,
and encoder offsets. Every field defaults to the exact nominal device, with which a simulation is
bit-identical to one without imperfections. The obstacle's compliance and friction are
``Scenario`` fields (``contact_stiffness``, ``contact_damping``, ``friction_coefficient``).

:func:`realistic_device` draws one set from the manufacturing and set-up spread documented in
``docs/simulator.md`` ("A device the model does not know"), seeded so repeats differ
reproducibly. The antenna (the model) never carries these: they are what the model does not know.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.errors import SensingAntennaError, format_value

__all__ = [
    "DEVICE_PROFILES",
    "DEVICE_STREAM",
    "MAX_BOW",
    "NANO17_FULL_SCALE",
    "DeviceError",
    "DeviceImperfections",
    "device_from_mapping",
    "device_profile",
    "realistic_device",
]

#: Names of the device profiles: the exact nominal device and the realistic spread.
DEVICE_PROFILES = ("nominal", "realistic")

#: Largest tip offset of a bowed link's rest shape (m, ``DeviceImperfections.bow``): the
#: linear link's small slopes.
MAX_BOW = 0.1

#: Spawn key that separates the device's random draws (its realistic profile, the sensor's
#: random-walk drift) from the scenario's noise stream of the same seed.
DEVICE_STREAM = 0xDE71CE

#: Full-scale range of an ATI Nano17 SI-25-0.25 (N, N, N, N m, N m, N m): forces 25 N (x, y),
#: 35 N (z), torques 0.25 N m. Cross-axis coupling is expressed as a fraction of full scale,
#: so the coupling of channel j into channel i is ``epsilon_ij FS_i / FS_j``.
NANO17_FULL_SCALE = (25.0, 25.0, 35.0, 0.25, 0.25, 0.25)

_SIX = tuple[float, float, float, float, float, float]
_IDENTITY_GAIN: _SIX = (1.0, 1.0, 1.0, 1.0, 1.0, 1.0)
_ZERO6: _SIX = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
_NO_COUPLING: tuple[_SIX, ...] = tuple(_ZERO6 for _ in range(6))


class DeviceError(SensingAntennaError, ValueError):
    """A device imperfection is out of range; the message names the field."""

    def __init__(self, field_name: str, problem: str) -> None:
        self.field_name = field_name
        super().__init__(f"device.{field_name}: {problem}")


def _number(name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise DeviceError(name, f"must be a finite number, got {format_value(value)}")
    return float(value)


def _vector(name: str, values: object, size: int) -> tuple[float, ...]:
    if not isinstance(values, (tuple, list)) or len(values) != size:
        raise DeviceError(name, f"needs {size} numbers, got {format_value(values)}")
    return tuple(_number(name, v) for v in values)


@dataclass(frozen=True)
class DeviceImperfections:
    """Departures of the simulated device from the nominal antenna (all off by default).

    Parameters
    ----------
    tip_mass : float
        Mass at the free end that the model does not know (kg): glue, a marker, a cap. Added to
        the link's own ``tip_mass`` in the finite-element model. Default 0.
    clamp_stiffness : float or None
        Rotational stiffness of the clamp at the root (N m/rad): the root keeps its deflection
        at zero but may turn, against this spring. None: rigid clamp (default).
    stiffness_taper : float
        Ratio E I(l) / E I(0) of a linear variation of the flexural rigidity along the link,
        with its mean over the length kept at the nominal E I (dimensionless, > 0). Default 1.
    density_taper : float
        Ratio rho(l) / rho(0) of a linear variation of the linear density, mean kept at the
        nominal rho (dimensionless, > 0). Default 1.
    joint_start : float
        Abscissa where a joint or sleeve begins (m, >= 0).
    joint_length : float
        Length of the joint or sleeve (m, >= 0); 0: no joint (default).
    joint_stiffness_factor : float
        E I of the joint over the link's local E I there (dimensionless, > 0). Default 1.
    joint_density_factor : float
        Linear density of the joint over the link's local rho (dimensionless, > 0). Default 1.
    sensor_gain : tuple of 6 float
        Gain of each F/T channel (fx, fy, fz, tx, ty, tz), dimensionless. Default all 1.
    sensor_coupling : 6 x 6 tuple of float
        Cross-axis coupling C (diagonal 0): the recorded wrench is
        ``diag(sensor_gain) (I + C) w + offset(t)``, with w the true wrench in recording units
        (N, N m); ``C[i][j]`` is in units of channel i per unit of channel j. Default 0.
    sensor_drift_rate : tuple of 6 float
        Offset ramp of each channel (N/s, N m/s), from 0 at t = 0. Default 0.
    sensor_drift_walk : tuple of 6 float
        Random-walk intensity of each channel's offset (N/sqrt(s), N m/sqrt(s)): a standard
        deviation of ``walk sqrt(t)`` after t seconds, drawn from the scenario's seed on a stream
        of its own (:data:`DEVICE_STREAM`). Default 0.
    encoder_offset : tuple of 2 float
        Constant added to the recorded theta1 and theta2 (rad): the encoders' zero is off the
        head's geometric zero. Default 0.
    bow : tuple of 2 float
        The unloaded link's tip offset from its root's line along Y^m and Z^m (m), a circular
        arc d (x / l)^2 (a link not quite straight): its rest shape, from which it deflects.
        Linear link only. Default 0: straight.

    Notes
    -----
    The link imperfections change the finite-element model of the simulated link; the sensor
    and encoder imperfections change what is recorded (and what the stop rule sees, as a real
    controller's would) while the servo closes its loop on the ideal readings.
    """

    tip_mass: float = 0.0
    clamp_stiffness: float | None = None
    stiffness_taper: float = 1.0
    density_taper: float = 1.0
    joint_start: float = 0.0
    joint_length: float = 0.0
    joint_stiffness_factor: float = 1.0
    joint_density_factor: float = 1.0
    sensor_gain: _SIX = _IDENTITY_GAIN
    sensor_coupling: tuple[_SIX, ...] = _NO_COUPLING
    sensor_drift_rate: _SIX = _ZERO6
    sensor_drift_walk: _SIX = _ZERO6
    encoder_offset: tuple[float, float] = (0.0, 0.0)
    bow: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "tip_mass", _number("tip_mass", self.tip_mass))
        if self.tip_mass < 0:
            raise DeviceError("tip_mass", f"must be >= 0 kg, got {self.tip_mass!r}")
        if self.clamp_stiffness is not None:
            value = _number("clamp_stiffness", self.clamp_stiffness)
            if not value > 0:
                raise DeviceError(
                    "clamp_stiffness", f"must be > 0 N m/rad (None: rigid), got {value!r}"
                )
            set_(self, "clamp_stiffness", value)
        for name in (
            "stiffness_taper",
            "density_taper",
            "joint_stiffness_factor",
            "joint_density_factor",
        ):
            value = _number(name, getattr(self, name))
            if not value > 0:
                raise DeviceError(name, f"must be > 0, got {value!r}")
            set_(self, name, value)
        for name in ("joint_start", "joint_length"):
            value = _number(name, getattr(self, name))
            if value < 0:
                raise DeviceError(name, f"must be >= 0 m, got {value!r}")
            set_(self, name, value)
        for name in ("sensor_gain", "sensor_drift_rate", "sensor_drift_walk"):
            set_(self, name, _vector(name, getattr(self, name), 6))
        for value in self.sensor_drift_walk:
            if value < 0:
                raise DeviceError("sensor_drift_walk", f"must be >= 0, got {value!r}")
        rows = self.sensor_coupling
        if not isinstance(rows, (tuple, list)) or len(rows) != 6:
            raise DeviceError("sensor_coupling", f"needs 6 rows of 6, got {format_value(rows)}")
        coupling = tuple(_vector("sensor_coupling", row, 6) for row in rows)
        if any(coupling[i][i] != 0.0 for i in range(6)):
            raise DeviceError(
                "sensor_coupling", "its diagonal must be 0 (the gains are sensor_gain)"
            )
        set_(self, "sensor_coupling", coupling)
        set_(self, "encoder_offset", _vector("encoder_offset", self.encoder_offset, 2))
        set_(self, "bow", _vector("bow", self.bow, 2))
        if max(abs(v) for v in self.bow) > MAX_BOW:
            raise DeviceError("bow", f"must be within +-{MAX_BOW:g} m, got {self.bow!r}")

    @property
    def is_nominal(self) -> bool:
        """True when every field is at its default (the exact nominal device)."""
        return self == DeviceImperfections()

    @property
    def link_is_nominal(self) -> bool:
        """True when the link, clamp and tip are nominal (sensor and encoders aside)."""
        return (
            self.tip_mass == 0.0
            and self.clamp_stiffness is None
            and self.stiffness_taper == 1.0
            and self.density_taper == 1.0
            and (
                self.joint_length == 0.0
                or (self.joint_stiffness_factor == 1.0 and self.joint_density_factor == 1.0)
            )
        )

    @property
    def link_part(self) -> DeviceImperfections | None:
        """The part the link's model depends on (tip mass, clamp, taper, joint), or None when
        that is nominal: devices whose sensor and encoders alone differ share it."""
        if self.link_is_nominal:
            return None
        return DeviceImperfections(
            tip_mass=self.tip_mass,
            clamp_stiffness=self.clamp_stiffness,
            stiffness_taper=self.stiffness_taper,
            density_taper=self.density_taper,
            joint_start=self.joint_start,
            joint_length=self.joint_length,
            joint_stiffness_factor=self.joint_stiffness_factor,
            joint_density_factor=self.joint_density_factor,
        )

    def sensor_matrix(self) -> NDArray[np.float64] | None:
        """``diag(gain) (I + C)``, shape (6, 6), or None when it is the identity."""
        if self.sensor_gain == _IDENTITY_GAIN and self.sensor_coupling == _NO_COUPLING:
            return None
        coupling = np.eye(6) + np.asarray(self.sensor_coupling, dtype=np.float64)
        return np.asarray(self.sensor_gain, dtype=np.float64)[:, np.newaxis] * coupling

    def sensor_offsets(self, t: NDArray[np.float64], seed: int) -> NDArray[np.float64] | None:
        """Drift offsets of each channel at the sample times ``t`` (s), shape (n, 6), or None.

        ``rate t`` plus a random walk of intensity ``walk``, zero at the first sample, drawn from
        ``numpy.random.default_rng([seed, DEVICE_STREAM])``.
        """
        if self.sensor_drift_rate == _ZERO6 and self.sensor_drift_walk == _ZERO6:
            return None
        offsets = np.asarray(self.sensor_drift_rate)[np.newaxis, :] * t[:, np.newaxis]
        walk = np.asarray(self.sensor_drift_walk)
        if walk.any() and t.size > 1:
            rng = np.random.default_rng([seed, DEVICE_STREAM, 1])
            steps = rng.normal(size=(t.size - 1, 6)) * np.sqrt(np.diff(t))[:, np.newaxis]
            offsets[1:] += np.cumsum(steps, axis=0) * walk
        return np.asarray(offsets, dtype=np.float64)

    def element_factors(
        self, nodes: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Factors on E I and rho of each element between ``nodes`` (m), shapes (n_elements,).

        The taper is taken at each element's midpoint; a joint covering a fraction f of an
        element blends in with f: harmonically for E I (compliances in series add) and
        arithmetically for rho (masses add). Exactly 1 where nothing departs from nominal.
        """
        length = float(nodes[-1])
        left, right = nodes[:-1], nodes[1:]
        middle = 0.5 * (left + right) / length - 0.5
        stiffness = _taper(self.stiffness_taper, middle)
        density = _taper(self.density_taper, middle)
        if self.joint_length > 0.0:
            end = self.joint_start + self.joint_length
            overlap = np.clip(np.minimum(right, end) - np.maximum(left, self.joint_start), 0, None)
            fraction = overlap / (right - left)
            covered = fraction > 0.0
            k = self.joint_stiffness_factor
            rho = self.joint_density_factor
            blend_k = 1.0 / (1.0 - fraction + fraction / k)
            blend_rho = 1.0 - fraction + fraction * rho
            stiffness = np.where(covered, stiffness * blend_k, stiffness)
            density = np.where(covered, density * blend_rho, density)
        return stiffness, density

    def to_json_dict(self) -> dict[str, Any]:
        """Every field as JSON-compatible values (tuples as lists); ``bow`` only when the link
        has one (a straight link's metadata as it has always been written)."""
        data = asdict(self)
        if not any(self.bow):
            del data["bow"]
        return {
            key: [list(v) if isinstance(v, tuple) else v for v in value]
            if isinstance(value, tuple)
            else value
            for key, value in data.items()
        }


def _taper(ratio: float, middle: NDArray[np.float64]) -> NDArray[np.float64]:
    """Linear profile with value ratio at the tip over the root's and mean 1; exactly 1 at 1."""
    if ratio == 1.0:
        return np.ones_like(middle)
    return 1.0 + 2.0 * (ratio - 1.0) / (ratio + 1.0) * middle


def device_from_mapping(data: Mapping[str, Any], source: str = "device") -> DeviceImperfections:
    """A :class:`DeviceImperfections` from a mapping (a TOML ``[device]`` table).

    Unknown keys are refused with a :class:`DeviceError` naming the key and ``source``.
    """
    known = {f.name for f in fields(DeviceImperfections)}
    for key in data:
        if key not in known:
            raise DeviceError(
                str(key), f"unknown field in {source}; known: {', '.join(sorted(known))}"
            )
    kwargs: dict[str, Any] = {}
    for key, value in data.items():
        if key == "sensor_coupling" and isinstance(value, list):
            value = tuple(tuple(row) if isinstance(row, list) else row for row in value)
        elif isinstance(value, list):
            value = tuple(value)
        kwargs[key] = value
    return DeviceImperfections(**kwargs)


#: Spread of the realistic profile (the reasoning and sources of each: docs/simulator.md).
#: tip mass (kg), uniform
REALISTIC_TIP_MASS = (0.0, 0.1e-3)
#: clamp stiffness (N m/rad), log-uniform
REALISTIC_CLAMP_STIFFNESS = (15.0, 100.0)
#: E I tip/root ratio, uniform (the density ratio is its square root: d^4 against d^2)
REALISTIC_STIFFNESS_TAPER = (0.92, 1.08)
#: joint: start as a fraction of l, length (m), E I and rho factors, uniform
REALISTIC_JOINT_START = (0.1, 0.8)
REALISTIC_JOINT_LENGTH = (0.01, 0.02)
REALISTIC_JOINT_FACTOR = (1.0, 1.5)
#: sensor: gain error (fraction, uniform +-), coupling (fraction of full scale, uniform +-)
REALISTIC_GAIN_ERROR = 0.01
REALISTIC_COUPLING = 0.01
#: drift rate (resolution counts per second, uniform +-), random walk (counts per sqrt(s))
REALISTIC_DRIFT_COUNTS_PER_S = 0.2
REALISTIC_WALK_COUNTS = 0.1
#: encoder offsets (rad, uniform +-)
REALISTIC_ENCODER_OFFSET = 0.005


def realistic_device(
    seed: int, length: float = 0.98, build: int | None = None
) -> DeviceImperfections:
    """One device drawn from the realistic manufacturing and set-up spread.

    What a device is built with (tip mass, clamp, taper, joint, the sensor's gains and
    coupling) is drawn from its ``build``; what changes between manoeuvres of one device (the
    sensor's drift, the encoders' zero after homing) from the manoeuvre's ``seed``. A lab's
    manoeuvres on its one antenna share a build and differ in set-up.

    Parameters
    ----------
    seed : int
        The manoeuvre's seed: the set-up draws use
        ``numpy.random.default_rng([seed, DEVICE_STREAM, 1])``.
    length : float
        Link length l (m), to place the joint.
    build : int, optional
        The device's build: its draws use ``numpy.random.default_rng([build, DEVICE_STREAM])``.
        None: ``seed`` (every manoeuvre on a device of its own).

    Returns
    -------
    DeviceImperfections
    """
    from sensing_antenna.simulator.scenario import ATI_NANO17_RESOLUTION

    rng = np.random.default_rng([seed if build is None else build, DEVICE_STREAM])
    low, high = REALISTIC_CLAMP_STIFFNESS
    clamp = float(math.exp(rng.uniform(math.log(low), math.log(high))))
    taper = float(rng.uniform(*REALISTIC_STIFFNESS_TAPER))
    full_scale = np.asarray(NANO17_FULL_SCALE)
    eps = rng.uniform(-REALISTIC_COUPLING, REALISTIC_COUPLING, size=(6, 6))
    np.fill_diagonal(eps, 0.0)
    coupling = eps * full_scale[:, np.newaxis] / full_scale[np.newaxis, :]
    gain = 1.0 + rng.uniform(-REALISTIC_GAIN_ERROR, REALISTIC_GAIN_ERROR, size=6)
    built: dict[str, Any] = {
        "tip_mass": float(rng.uniform(*REALISTIC_TIP_MASS)),
        "clamp_stiffness": clamp,
        "stiffness_taper": taper,
        "density_taper": math.sqrt(taper),
        "joint_start": float(rng.uniform(*REALISTIC_JOINT_START)) * length,
        "joint_length": float(rng.uniform(*REALISTIC_JOINT_LENGTH)),
        "joint_stiffness_factor": float(rng.uniform(*REALISTIC_JOINT_FACTOR)),
        "joint_density_factor": float(rng.uniform(*REALISTIC_JOINT_FACTOR)),
        "sensor_gain": tuple(float(g) for g in gain),
        "sensor_coupling": tuple(tuple(float(c) for c in row) for row in coupling),
    }
    setup = np.random.default_rng([seed, DEVICE_STREAM, 1])
    resolution = np.asarray(ATI_NANO17_RESOLUTION)
    rate = setup.uniform(-1.0, 1.0, size=6) * REALISTIC_DRIFT_COUNTS_PER_S * resolution
    offsets = setup.uniform(-1.0, 1.0, size=2) * REALISTIC_ENCODER_OFFSET
    built["sensor_drift_rate"] = tuple(float(r) for r in rate)
    built["sensor_drift_walk"] = tuple(float(r) for r in REALISTIC_WALK_COUNTS * resolution)
    built["encoder_offset"] = tuple(float(v) for v in offsets)
    return DeviceImperfections(**built)


def device_profile(
    name: str, seed: int, length: float = 0.98, build: int | None = None
) -> DeviceImperfections:
    """The device of profile ``name`` (:data:`DEVICE_PROFILES`) for a run of seed ``seed`` on
    the device of ``build`` (:func:`realistic_device`)."""
    if name == "nominal":
        return DeviceImperfections()
    if name == "realistic":
        return realistic_device(seed, length, build)
    raise DeviceError(
        "profile", f"must be one of {', '.join(DEVICE_PROFILES)}, got {format_value(name)}"
    )
