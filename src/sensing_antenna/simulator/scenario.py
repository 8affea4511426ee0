"""What to simulate: the manoeuvre case, the obstacle, the sensor noise and the numerical settings.

Every parameter is SI. The defaults and their sources are discussed in ``docs/simulator.md``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from typing import Any, Literal

import numpy as np

from sensing_antenna.control.servo import DEFAULT_SERVO_POLE, MAX_POLE_STEP
from sensing_antenna.errors import SensingAntennaError, format_value
from sensing_antenna.simulator.device import DeviceImperfections

__all__ = [
    "ATI_NANO17_RESOLUTION",
    "CASES",
    "CONTACT_STIFFNESS_RATIO",
    "DEFAULT_CONTACT_STIFFNESS",
    "DEFAULT_SAMPLE_PERIOD",
    "FREE_CASES",
    "FREE_CASE_OF",
    "LINK_MODELS",
    "MAX_DURATION",
    "MAX_ELEMENTS",
    "MAX_NOISE_SCALE",
    "MAX_SIMULATED_SAMPLES",
    "MAX_STEP_PHASE",
    "MAX_SUBSTEPS",
    "MIN_SUBSTEPS",
    "N_ELEMENTS",
    "OBSTACLE_KINDS",
    "PLACED_KINDS",
    "SAMPLE_PERIOD_RANGE",
    "Scenario",
    "ScenarioError",
    "SensorNoise",
    "duration_problem",
]

CASES = ("azimuthal", "vertical", "free", "free-vertical")
#: The case with nothing to touch that sweeps the joint of each contact case: the azimuthal sweep
#: and the vertical one, each run past its nominal touch and brought to rest.
FREE_CASE_OF = {"azimuthal": "free", "vertical": "free-vertical"}
FREE_CASES = tuple(FREE_CASE_OF.values())
OBSTACLE_KINDS = ("post", "bar", "ball", "plane", "capsule", "cylinder", "box", "cone", "torus")
#: The kinds placed only explicitly (``Scenario.obstacle_placement``).
PLACED_KINDS = ("capsule", "cylinder", "box", "cone", "torus")
#: The placed kinds given by their own sizes (``Scenario.obstacle_sizes``), and how many.
SIZED_KINDS = {"box": 3, "cone": 2, "torus": 2}
#: The link's mechanics: "linear" (Euler-Bernoulli about the undeformed line, Assumption 1) or
#: "nonlinear" (geometrically exact inextensible rod, ``simulator.nonlinear_link``).
LINK_MODELS = ("linear", "nonlinear")

#: Cruise at constant speed between the end of the speed ramp and the nominal first touch (s):
#: lets the servo settle on its ramp lag (2 eps omega*, Eq. 14; 5 eps = 0.08 s) before the contact.
CRUISE_BEFORE_TOUCH = 0.1

#: Resolution of an ATI Nano17 SI-25-0.25 transducer with a 16-bit DAQ as recalled from ATI's
#: catalogue, NOT verified against the data sheet (docs/simulator.md): forces 1/160 N (x, y, z),
#: torques 1/32 N mm (x, y, z). (N, N, N, N m, N m, N m). A resolution, not a noise RMS.
ATI_NANO17_RESOLUTION = (
    1.0 / 160.0,
    1.0 / 160.0,
    1.0 / 160.0,
    1.0 / 32000.0,
    1.0 / 32000.0,
    1.0 / 32000.0,
)

#: Sampling and control period T_s of the paper's device (s), 1 kHz: the default
#: ``Scenario.sample_period``.
DEFAULT_SAMPLE_PERIOD = 1e-3

#: Range of ``Scenario.sample_period`` (s): 10 kHz to 200 Hz. Faster than 10 kHz an F/T
#: sensor's output is past its own filters; slower than 200 Hz the servo's default pole
#: (|p| T_s over ``control.servo.MAX_POLE_STEP``) no longer follows its design.
SAMPLE_PERIOD_RANGE = (1e-4, 5e-3)

#: Largest number of samples one simulated manoeuvre may record: 600,000, ten minutes at the
#: paper device's 1 kHz, where a manoeuvre lasts seconds (3.5 s by default). Memory grows with the
#: samples (references, measurements, ground truth, the recording and its text), so this keeps
#: ``antenna simulate`` under a gigabyte (docs/simulator.md, "Scenario limits"), and the recording
#: it writes, at most 425 bytes per sample (seventeen columns of at most 24 characters: the
#: commands and the contact's track included), within the reader's
#: ``recording.MAX_FILE_BYTES``.
MAX_SIMULATED_SAMPLES = 600_000

#: Longest ``duration`` (s): :data:`MAX_SIMULATED_SAMPLES` at the default 1 kHz
#: (:data:`DEFAULT_SAMPLE_PERIOD`), 600 s; a faster sampling shortens it in proportion.
MAX_DURATION = MAX_SIMULATED_SAMPLES * DEFAULT_SAMPLE_PERIOD

#: Most finite elements of the link: 128. The first free frequency converges as h^4 and 16
#: elements already give 1e-6 (docs/simulator.md), so 128 give about 2e-10; each time step costs
#: the square of the element count, 64 times the default's at 128.
MAX_ELEMENTS = 128

#: Largest ``noise_scale``: 1000 times the sensor's noise buries any contact (the campaign's
#: noise sweep stops at 4); beyond it a typing error, and the samples could overflow.
MAX_NOISE_SCALE = 1000.0

#: Most internal Newmark steps per sample: 100 (a 10 us step at 1 kHz). The integrator is
#: unconditionally stable, so more steps only refine the step error; the cost grows with them.
MAX_SUBSTEPS = 100

#: The default penalty contact's stiffness (N/m), the least :meth:`Scenario.resolved` gives:
#: 1000 times the paper link's local stiffness 3 E I / x_c^3 at x_c = 0.3 m (10 N/m), 215 times
#: its mass times its highest first contact frequency squared (46 N/m).
DEFAULT_CONTACT_STIFFNESS = 1.0e4

#: The default penalty contact's stiffness over the link's mass times the square of its highest
#: first contact frequency over [0.3 l, l], the stiffness scale of the modes the contact holds:
#: a softer support lowers omega_1 (by 1.6 % at 37 times, a 0.35 m carbon rod touched at
#: 0.12 m with 1e4 N/m), 150 times keeps it within about 0.1 %.
CONTACT_STIFFNESS_RATIO = 150.0

#: Fewest Newmark steps per sample by default.
MIN_SUBSTEPS = 2

#: Largest omega h (rad) of the default step at the link's highest first contact frequency:
#: Newmark average acceleration lengthens a period by (omega h)^2 / 12, 0.1 % at 0.11.
MAX_STEP_PHASE = 0.11


#: Largest value of the scenario's unbounded physical fields, with the reason. Past them the
#: simulator overflows (a sweep of 1e300 rad/s, a post of 1e300 m) long before the values mean
#: anything; within them it has been run (docs/simulator.md, "Scenario limits").
_UPPER_LIMITS: dict[str, tuple[float, str, str]] = {
    "obstacle_radius": (10.0, "m", "a post or bar thicker than that is a wall: the plane"),
    "obstacle_length": (100.0, "m", "a cylinder longer than that is endless: a post or a bar"),
    "contact_stiffness": (
        1e10,
        "N/m",
        "over 1e9 times the paper link's own stiffness 3 E I / x_c^3 at mid-length: rigid",
    ),
    "sweep_speed": (100.0, "rad/s", "950 rpm: no sensing head sweeps faster"),
    "accel_time": (MAX_DURATION, "s", "no phase of a manoeuvre outlasts the longest one"),
    "start_time": (MAX_DURATION, "s", "no phase of a manoeuvre outlasts the longest one"),
    "approach_time": (MAX_DURATION, "s", "no phase of a manoeuvre outlasts the longest one"),
    "retract_after": (MAX_DURATION, "s", "no phase of a manoeuvre outlasts the longest one"),
    "retract_angle": (math.pi, "rad", "half a turn back along the sweep"),
}


def duration_problem(duration: object, sample_period: float = DEFAULT_SAMPLE_PERIOD) -> str | None:
    """Why ``duration`` (s) cannot be the recorded time of a simulated manoeuvre sampled every
    ``sample_period`` (s), or None.

    It must be a finite number above 0.01 s and hold at most :data:`MAX_SIMULATED_SAMPLES`
    samples (:data:`MAX_DURATION` at 1 kHz). A campaign checks its spec's durations with it
    before running anything, naming its own field.
    """
    if (
        isinstance(duration, bool)
        or not isinstance(duration, (int, float))
        or not math.isfinite(duration)
    ):
        return f"must be a finite number, got {format_value(duration)}"
    if not duration > 0.01:
        return f"must be > 0.01 s, got {format_value(duration)}"
    longest = MAX_SIMULATED_SAMPLES * sample_period
    if duration > longest:
        return (
            f"{format_value(duration)} s is more than {longest:g} s:"
            f" {MAX_SIMULATED_SAMPLES} samples at {1.0 / sample_period:g} Hz, the limit that"
            " keeps a simulation's memory and its recording bounded"
        )
    return None


class ScenarioError(SensingAntennaError, ValueError):
    """A scenario parameter is out of range; the message names the field."""

    def __init__(self, field_name: str, problem: str) -> None:
        self.field_name = field_name
        super().__init__(f"scenario.{field_name}: {problem}")


def _finite(name: str, value: float, low: float | None = None, strict: bool = False) -> None:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ScenarioError(name, f"must be a finite number, got {format_value(value)}")
    if low is not None and (value <= low if strict else value < low):
        relation = ">" if strict else ">="
        raise ScenarioError(name, f"must be {relation} {low:g}, got {format_value(value)}")


@dataclass(frozen=True)
class SensorNoise:
    """Force/torque sensor and encoder imperfections.

    Parameters
    ----------
    wrench_std : tuple of 6 float
        Standard deviation of the additive white noise on (fx, fy, fz, tx, ty, tz) per sample
        (N, N m). Default: one resolution count of an ATI Nano17 SI-25-0.25 taken as the 1-sigma
        noise, a modelling assumption (unverified figures; docs/simulator.md).
    bias_std : tuple of 6 float
        Standard deviation of the constant per-run offset (residual after taring), same units.
        Default: two resolution counts.
    encoder_counts : int
        Encoder counts per motor-shaft revolution (after quadrature); 2000 = 500 lines x 4.
    """

    wrench_std: tuple[float, float, float, float, float, float] = ATI_NANO17_RESOLUTION
    bias_std: tuple[float, float, float, float, float, float] = tuple(  # type: ignore[assignment]
        2.0 * r for r in ATI_NANO17_RESOLUTION
    )
    encoder_counts: int = 2000

    def __post_init__(self) -> None:
        for name in ("wrench_std", "bias_std"):
            values = getattr(self, name)
            if len(values) != 6:
                raise ScenarioError(f"sensor.{name}", f"needs 6 values, got {len(values)}")
            for value in values:
                _finite(f"sensor.{name}", value, 0.0)
        if not isinstance(self.encoder_counts, int) or self.encoder_counts < 0:
            raise ScenarioError("sensor.encoder_counts", "must be an integer >= 0 (0 = exact)")


#: Finite elements of a simulated link unless a scenario says otherwise.
N_ELEMENTS = 16


@dataclass(frozen=True)
class Scenario:
    """One simulated manoeuvre (Section 4 of the paper, steps 1 to 4).

    Parameters
    ----------
    case : {"azimuthal", "vertical", "free", "free-vertical"}
        Azimuthal: theta1 sweeps (theta2 = 0) into a vertical post. Vertical: theta2 sweeps up,
        against gravity, into a horizontal bar. Free: the azimuthal sweep with no obstacle;
        free-vertical: the vertical one.
    contact_point : float or None
        x_c (m) at which the gravity-sagged, otherwise undeflected link would touch the obstacle.
        Required unless the case is free (:data:`FREE_CASES`).
    seed : int
        Seed of the one ``numpy.random.Generator`` that draws every random quantity.
    duration : float
        Total recorded time (s).
    noise_scale : float
        Multiplies the sensor noise and bias (0: noiseless, exact encoders); at most
        :data:`MAX_NOISE_SCALE`.
    damping_ratio : float
        Structural damping ratio of the link at its first free mode and at the highest first
        contact-mode frequency (Rayleigh damping, dimensionless).
    friction_coefficient : float
        Coulomb friction coefficient mu between link and obstacle.
    push : object or None
        The push criterion (``detection.push.PushCriterion``); None uses its default.
    obstacle : {"post", "bar", "ball", "plane", "capsule", "cylinder", "box", "cone", \
"torus"} or None
        Obstacle kind; None: post for the azimuthal case, bar for the vertical case. A post or
        a bar is an endless cylinder; a capsule and a capped cylinder need
        ``obstacle_placement`` and ``obstacle_length``, a box, a cone and a torus
        ``obstacle_placement`` and ``obstacle_sizes``.
    obstacle_radius : float
        Radius of the post, bar, ball, capsule or cylinder (m).
    obstacle_length : float
        The capsule's axis segment or the capped cylinder's height (m); 0 for the other kinds.
        Like ``obstacle_radius`` it is the obstacle the link's axis meets: an object grown by
        the link's radius, so a capped cylinder's rim is rounded by the link's radius.
    obstacle_sizes : tuple of float
        A box's three edge lengths (along its own X, Y, Z), a cone's base radius and height,
        a torus's major and minor radii (minor at most major): the object's own sizes (m),
        which the simulator grows by the link's radius (edges, rim and apex rounded by it),
        as the link's axis meets it. Empty for the other kinds.
    obstacle_tilt : float
        Misalignment of the obstacle (rad): the post leans along the sweep, the bar rolls about
        the link, the plane turns its normal out of the sweep plane, the ball's normal at the
        touch turns as the post's (azimuthal) or the bar's (vertical). Gives the contact normal
        a component out of the sweep plane.
    obstacle_placement : tuple of 6 (a box: 9) float or None
        The obstacle placed explicitly in the absolute frame instead of from ``contact_point``
        and ``obstacle_tilt``: a point (m; a point of the cylinder's axis, the ball's centre, a
        point of the plane) and a direction (the cylinder's axis, the plane's outward normal,
        the ball's outward normal at the touch; normalised; a capsule's, a capped cylinder's
        or a torus's centre and axis, a cone's base centre and axis towards its apex). A box
        takes nine: its centre, its own Z axis, and its own X axis (made perpendicular to Z).
        The sweep must then meet it near ``contact_point``, which still names
        the touch (a scene's sweeps place the touched object itself: ``scene.simulate``), and
        ``obstacle_tilt`` is not used. None: placed from ``contact_point``.
    contact_stiffness : float or None
        Normal penalty stiffness (N/m); also the tangential stick stiffness. None:
        :data:`CONTACT_STIFFNESS_RATIO` times the link's mass times the square of its highest
        first contact frequency, at least :data:`DEFAULT_CONTACT_STIFFNESS` (1e4 N/m for the
        paper's link, 1.6e5 N/m for a 0.35 m carbon rod), so that a short or stiff link's
        contact is as firm a support.
    contact_damping : float
        Normal and tangential contact damping (N s/m).
    sweep_speed : float
        Cruise speed of the swept joint (rad/s).
    sweep_direction : {1, -1}
        1: the swept joint turns up, the link moving towards +Y^m (azimuthal) or +Z^m (vertical:
        lifted against its weight); -1: down, towards -Y^m or -Z^m (vertical: lowered with its
        weight onto a bar below it). The obstacle lies ahead of the sweep either way.
    accel_time : float or None
        Duration of the raised-cosine speed ramp from rest to cruise (s). None: the vibration-free
        ramp, 1.5 periods of the link's first free mode (3 pi / omega_1,free; 0.59 s for the paper
        antenna). Its half-sine acceleration has no spectral content at omega_1,free, so the
        sweep leaves the link (almost) still, as the paper's free-motion control does (Section 1,
        ref. [17]); a short ramp leaves the link ringing and the contact is then hit while
        vibrating.
    start_time : float
        Rest before the sweep starts (s).
    approach_time : float or None
        Time from the start of the sweep to the nominal first touch (s), at least accel_time.
        None: accel_time + ``CRUISE_BEFORE_TOUCH``.
    servo_pole : float
        Closed-loop pole p of both servos (rad/s, < 0); Eq. 14 with eps = -1/p (the
        controller's ``DEFAULT_SERVO_POLE``, -60).
    compensate_servo_lag : bool
        At the stop (t_1) freeze the reference at r(t_1) - 2 eps omega*(t_1) instead of r(t_1),
        so that the joint comes to rest where it was at t_1 instead of 2 eps omega* further
        (the ramp lag of Eq. 14); see ``docs/simulator.md``, "The push criterion".
    retract_after : float or None
        Time after the stop (s) at which the swept joint turns back along the sweep by
        ``retract_angle``, on the sweep's raised-cosine ramp at its speed, and holds there: the
        link leaves the obstacle and rings free. None: the head holds to the end. Only for a
        manoeuvre that stops at a contact (not the free cases).
    retract_angle : float
        How far the retraction turns the swept joint back (rad, > 0); it must exceed the push
        past the touch for the link to leave the obstacle.
    sample_period : float
        Period T_s of the recorded samples and of the head's controller (s), within
        :data:`SAMPLE_PERIOD_RANGE`; default 1 ms, the paper device's 1 kHz. The sensor's noise
        (``sensor.wrench_std``) is per sample at any period.
    n_elements : int
        Finite elements of the link (default :data:`N_ELEMENTS`).
    link_model : {"linear", "nonlinear"}
        "linear": small-deflection bending about the undeformed line (Assumption 1 of the
        paper). "nonlinear": the geometrically exact inextensible rod (exact curvature, axial
        shortening, friction along the link; ``simulator.nonlinear_link``), for pushes beyond
        about 10 % of x_c; 3 to 6 times slower (docs/simulator.md, "Large deflection").
    substeps : int or None
        Internal Newmark steps per sample. None: enough that omega h stays within
        :data:`MAX_STEP_PHASE` at the link's highest first contact frequency over [0.3 l, l]
        (a period 0.1 % long at most), at least :data:`MIN_SUBSTEPS` (2 for the paper's link, 8
        for a 0.35 m carbon rod ringing at up to 776 rad/s).
    sensor : SensorNoise
        Sensor noise model at noise_scale = 1.
    device : DeviceImperfections
        What the simulated device does that the antenna (the estimators' model) does not know:
        tip mass, clamp compliance, non-uniform link, sensor gain, coupling and drift, encoder
        offsets. Default: none (the exact nominal device).
    description : str
        Free text copied into the recording.
    """

    case: Literal["azimuthal", "vertical", "free", "free-vertical"] = "azimuthal"
    contact_point: float | None = None
    seed: int = 0
    duration: float = 3.5
    noise_scale: float = 1.0
    damping_ratio: float = 0.005
    friction_coefficient: float = 0.6
    push: Any = None
    obstacle: (
        Literal["post", "bar", "ball", "plane", "capsule", "cylinder", "box", "cone", "torus"]
        | None
    ) = None
    obstacle_radius: float = 0.01
    obstacle_length: float = 0.0
    obstacle_sizes: tuple[float, ...] = ()
    obstacle_tilt: float = 0.02
    obstacle_placement: tuple[float, ...] | None = None
    contact_stiffness: float | None = None
    contact_damping: float = 0.5
    sweep_speed: float = 0.3
    sweep_direction: int = 1
    accel_time: float | None = None
    start_time: float = 0.1
    approach_time: float | None = None
    servo_pole: float = DEFAULT_SERVO_POLE
    compensate_servo_lag: bool = True
    retract_after: float | None = None
    retract_angle: float = 0.1
    sample_period: float = DEFAULT_SAMPLE_PERIOD
    n_elements: int = N_ELEMENTS
    substeps: int | None = None
    link_model: Literal["linear", "nonlinear"] = "linear"
    sensor: SensorNoise = field(default_factory=SensorNoise)
    device: DeviceImperfections = field(default_factory=DeviceImperfections)
    description: str = ""

    def __post_init__(self) -> None:
        if self.case not in CASES:
            raise ScenarioError(
                "case", f"must be one of {', '.join(CASES)}, got {format_value(self.case)}"
            )
        if self.case in FREE_CASES:
            if self.contact_point is not None:
                raise ScenarioError("contact_point", f"must be None for the {self.case} case")
        else:
            if self.contact_point is None:
                raise ScenarioError("contact_point", f"is required for the {self.case} case")
            _finite("contact_point", self.contact_point, 0.0, strict=True)
        if self.push is not None:
            from sensing_antenna.detection.push import PushCriterion

            if not isinstance(self.push, PushCriterion):
                raise ScenarioError(
                    "push",
                    "must be a push criterion (detection.push.PushCriterion) or None, "
                    f"got {format_value(self.push)}",
                )
        if self.link_model not in LINK_MODELS:
            raise ScenarioError(
                "link_model",
                f"must be one of {', '.join(LINK_MODELS)}, got {format_value(self.link_model)}",
            )
        if self.obstacle is not None and self.obstacle not in OBSTACLE_KINDS:
            raise ScenarioError(
                "obstacle",
                f"must be one of {', '.join(OBSTACLE_KINDS)}, got {format_value(self.obstacle)}",
            )
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise ScenarioError("seed", f"must be an integer >= 0, got {format_value(self.seed)}")
        _finite("sample_period", self.sample_period)
        low, high = SAMPLE_PERIOD_RANGE
        if not low <= self.sample_period <= high:
            raise ScenarioError(
                "sample_period",
                f"must be between {low:g} and {high:g} s ({1 / high:g} Hz to {1 / low:g} Hz),"
                f" got {format_value(self.sample_period)}",
            )
        problem = duration_problem(self.duration, self.sample_period)
        if problem is not None:
            raise ScenarioError("duration", problem)
        for name in ("noise_scale", "damping_ratio", "friction_coefficient", "contact_damping"):
            _finite(name, getattr(self, name), 0.0)
        if self.damping_ratio >= 1.0:
            raise ScenarioError("damping_ratio", "must be < 1 (light structural damping)")
        if self.noise_scale > MAX_NOISE_SCALE:
            raise ScenarioError(
                "noise_scale",
                f"must be at most {MAX_NOISE_SCALE:g} (times the sensor's noise), got "
                f"{format_value(self.noise_scale)}",
            )
        for name in ("obstacle_radius", "sweep_speed"):
            _finite(name, getattr(self, name), 0.0, strict=True)
        if self.contact_stiffness is not None:
            _finite("contact_stiffness", self.contact_stiffness, 0.0, strict=True)
        if isinstance(self.sweep_direction, bool) or self.sweep_direction not in (1, -1):
            raise ScenarioError(
                "sweep_direction",
                f"must be 1 (up) or -1 (down), got {format_value(self.sweep_direction)}",
            )
        if self.accel_time is not None:
            _finite("accel_time", self.accel_time, 0.0, strict=True)
        _finite("start_time", self.start_time, 0.0)
        _finite("obstacle_tilt", self.obstacle_tilt)
        if abs(self.obstacle_tilt) >= 0.5:
            raise ScenarioError("obstacle_tilt", "must be below 0.5 rad in magnitude")
        if self.obstacle_placement is not None:
            self._check_placement(self.obstacle_placement)
        self._check_sizes()
        _finite("obstacle_length", self.obstacle_length, 0.0)
        if self.obstacle in PLACED_KINDS:
            if self.obstacle_placement is None:
                raise ScenarioError(
                    "obstacle_placement", f"a {self.obstacle} is placed only explicitly: needed"
                )
            if self.obstacle == "cylinder" and not self.obstacle_length > 0.0:
                raise ScenarioError("obstacle_length", "a capped cylinder's height must be > 0")
        if self.obstacle not in ("capsule", "cylinder") and self.obstacle_length != 0.0:
            raise ScenarioError(
                "obstacle_length",
                f"only a capsule or a capped cylinder has a length, not a"
                f" {self.obstacle or 'default obstacle'}",
            )
        if self.approach_time is not None:
            _finite("approach_time", self.approach_time, self.accel_time or 0.0)
        if self.retract_after is not None:
            _finite("retract_after", self.retract_after, 0.0)
            if self.case in FREE_CASES:
                raise ScenarioError(
                    "retract_after", f"the {self.case} case never stops at a contact to retract"
                )
        _finite("retract_angle", self.retract_angle, 0.0, strict=True)
        for name, (high, unit, reason) in _UPPER_LIMITS.items():
            value = getattr(self, name)
            if value is not None and value > high:
                raise ScenarioError(
                    name, f"{format_value(value)} {unit} is more than {high:g} {unit} ({reason})"
                )
        _finite("servo_pole", self.servo_pole)
        if not self.servo_pole < 0:
            raise ScenarioError(
                "servo_pole", f"must be < 0 (stable), got {format_value(self.servo_pole)}"
            )
        if -self.servo_pole * self.sample_period > MAX_POLE_STEP:
            raise ScenarioError(
                "servo_pole",
                f"too fast for the {1 / self.sample_period:g} Hz controller"
                f" (|p| T_s > {MAX_POLE_STEP:g})",
            )
        if not isinstance(self.compensate_servo_lag, bool):
            raise ScenarioError(
                "compensate_servo_lag",
                f"must be true or false, got {format_value(self.compensate_servo_lag)}",
            )
        if (
            isinstance(self.n_elements, bool)
            or not isinstance(self.n_elements, int)
            or not 4 <= self.n_elements <= MAX_ELEMENTS
        ):
            raise ScenarioError(
                "n_elements",
                f"must be an integer from 4 to {MAX_ELEMENTS}, got {format_value(self.n_elements)}",
            )
        if self.substeps is not None and (
            isinstance(self.substeps, bool)
            or not isinstance(self.substeps, int)
            or not 1 <= self.substeps <= MAX_SUBSTEPS
        ):
            raise ScenarioError(
                "substeps",
                f"must be an integer from 1 to {MAX_SUBSTEPS}, got {format_value(self.substeps)}",
            )
        if not isinstance(self.device, DeviceImperfections):
            raise ScenarioError(
                "device", f"must be a DeviceImperfections, got {format_value(self.device)}"
            )
        if any(self.device.bow) and self.link_model == "nonlinear":
            raise ScenarioError("device.bow", "a bowed link is simulated on the linear link only")
        description = self.description
        if not isinstance(description, str) or (
            description
            and (
                description != description.strip()
                or description.splitlines() != [description]
                or "\0" in description
            )
        ):
            raise ScenarioError(
                "description",
                "must be one line of text without edge spaces (it is written into the"
                f" recording's metadata), got {format_value(description)}",
            )

    def _check_placement(self, placement: object) -> None:
        count = 9 if self.obstacle == "box" else 6
        what = "a centre, its Z and its X axes" if count == 9 else "a point, m, and a direction"
        if not isinstance(placement, (tuple, list)) or len(placement) != count:
            raise ScenarioError(
                "obstacle_placement",
                f"must be {count} numbers ({what}), got {format_value(placement)}",
            )
        for value in placement:
            _finite("obstacle_placement", value)
        values = np.asarray(placement, dtype=float)
        if not np.linalg.norm(values[3:6]) > 0.0:
            raise ScenarioError("obstacle_placement", "the direction must not be zero")
        if count == 9 and not np.linalg.norm(np.cross(values[3:6], values[6:9])) > 1e-6 * (
            np.linalg.norm(values[3:6]) * np.linalg.norm(values[6:9])
        ):
            raise ScenarioError(
                "obstacle_placement", "the box's X axis must not be zero or along its Z axis"
            )
        object.__setattr__(self, "obstacle_placement", tuple(float(v) for v in placement))

    def _check_sizes(self) -> None:
        sizes = self.obstacle_sizes
        count = SIZED_KINDS.get(self.obstacle or "", 0)
        if not isinstance(sizes, (tuple, list)) or len(sizes) != count:
            needed = f"{count} numbers" if count else "empty"
            raise ScenarioError(
                "obstacle_sizes",
                f"must be {needed} for a {self.obstacle or 'default obstacle'},"
                f" got {format_value(sizes)}",
            )
        high = _UPPER_LIMITS["obstacle_radius"][0]
        for value in sizes:
            _finite("obstacle_sizes", value, 0.0, strict=True)
            if value > high:
                raise ScenarioError(
                    "obstacle_sizes", f"{format_value(value)} m is more than {high:g} m (a wall)"
                )
        if self.obstacle == "torus" and sizes[1] > sizes[0]:
            raise ScenarioError(
                "obstacle_sizes", "a torus's minor radius must not exceed its major radius"
            )
        object.__setattr__(self, "obstacle_sizes", tuple(float(v) for v in sizes))

    def resolved(
        self,
        omega_free: float,
        omega_contact: float,
        link_mass: float,
        sample_period: float,
    ) -> Scenario:
        """This scenario with the default ramp times, contact stiffness and substeps made
        explicit.

        Parameters
        ----------
        omega_free : float
            First free-mode frequency of the link (rad/s).
        omega_contact : float
            The link's highest first contact frequency over [0.3 l, l] (rad/s).
        link_mass : float
            The link's mass (kg).
        sample_period : float
            Period of the recorded samples (s).
        """
        stiffness = self.contact_stiffness
        if stiffness is None:
            modal = link_mass * omega_contact**2
            stiffness = max(DEFAULT_CONTACT_STIFFNESS, CONTACT_STIFFNESS_RATIO * modal)
        substeps = self.substeps
        if substeps is None:
            needed = math.ceil(omega_contact * sample_period / MAX_STEP_PHASE)
            substeps = min(max(MIN_SUBSTEPS, needed), MAX_SUBSTEPS)
        accel = self.accel_time if self.accel_time is not None else 3.0 * math.pi / omega_free
        approach = (
            self.approach_time if self.approach_time is not None else accel + CRUISE_BEFORE_TOUCH
        )
        if approach < accel:
            raise ScenarioError(
                "approach_time",
                f"must be >= accel_time ({accel:.3g} s), got {format_value(approach)}",
            )
        return replace(
            self,
            accel_time=accel,
            approach_time=approach,
            contact_stiffness=stiffness,
            substeps=substeps,
        )

    @property
    def swept_joint(self) -> int:
        """Index of the joint the manoeuvre sweeps: 0 (theta1) or 1 (theta2)."""
        return 1 if self.case in ("vertical", FREE_CASE_OF["vertical"]) else 0

    @property
    def obstacle_kind(self) -> str | None:
        """The obstacle actually used: None for the free cases."""
        if self.case in FREE_CASES:
            return None
        if self.obstacle is not None:
            return self.obstacle
        return "post" if self.case == "azimuthal" else "bar"

    def to_json_dict(self) -> dict[str, Any]:
        """Every parameter as JSON-compatible values (the push criterion by its repr)."""
        data = asdict(self)
        data["push"] = None if self.push is None else repr(self.push)
        data["sensor"] = {
            k: list(v) if isinstance(v, tuple) else v for k, v in data["sensor"].items()
        }
        data["device"] = self.device.to_json_dict()
        return data
