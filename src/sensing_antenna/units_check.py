"""The sign and scale check of a recording from its own physics (docs/recording-format.md).

A recording carries its own calibration: while the head rests and nothing touches the link, the
sensor reads the link's weight, F = F_g^m(theta2) (``(0, 0, -m_b g)`` at theta2 = 0) and
Gamma = Gamma_g^m(theta2) (``(0, +0.5 m_b g l, 0)``), which the antenna file predicts. A file in
mN or N mm, with a sign flipped, or with forces or torques doubled or halved does not read that.
The angles have limits of their own: an elevation lies within +-pi/2, and between two samples the
head cannot turn by half a revolution or more (the angle would be aliased); angles in degrees or a
glitch of 1e300 break them.

:func:`rest_reading` compares the mean loads over a window at rest with the weight;
:func:`is_payload` says when the moment at rest exceeds the weight by more than a tare leaves;
:func:`initial_rest` finds the samples at rest at the start of a recording; :func:`angle_problem`
checks the angles; :func:`recording_problem` is the angles and the rest at the start together.
The estimation front end (at t_c, on the window its tare averages), ``antenna identify`` and
``antenna calibrate`` all use these, so every command judges a recording's units the same way.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.antenna import STANDARD_GRAVITY, Antenna

__all__ = [
    "MAX_ANGLE_STEP",
    "MAX_ELEVATION",
    "PAYLOAD_SIGMAS",
    "REST_FORCE_FRACTION",
    "REST_TORQUE_FRACTION",
    "TARE_NOISES",
    "TIME_UNITS",
    "RestReading",
    "angle_problem",
    "initial_rest",
    "is_payload",
    "recording_problem",
    "rest_moment_std",
    "rest_reading",
    "stamps_unit",
]

FloatArray = NDArray[np.float64]

#: Units a logger may write time stamps in, each with how many of it make a second.
TIME_UNITS = (("ms", 1e3), ("us", 1e6), ("ns", 1e9))


def stamps_unit(fits: Callable[[float], bool]) -> str | None:
    """The first of :data:`TIME_UNITS` whose count per second, taken as the factor by which
    stamps read as seconds stretch time, makes ``fits`` true: the unit such stamps were likely
    written in; None when none does."""
    return next((name for name, per_second in TIME_UNITS if fits(per_second)), None)


#: Largest accepted distance |Gamma_rest - Gamma_g^m| as a fraction of the weight's moment
#: m_b g l / 2 + m_t g l. A scale or unit error of the torques is a factor 2 or more (50 % of
#: it for halved torques, 100 % doubled, 200 % a sign flipped, 10^3 in N mm), while a correct
#: file departs from it by the sensor's offset after taring (a few counts: 2 counts of the
#: simulated sensor, 6e-5 N m, are 0.3 % of the paper link's 0.0221 N m, 1.1 % at four times
#: the noise) and by the error of the link's mass in the antenna file (a few %). A quarter is
#: 20 times the first and half the smallest unit error.
REST_TORQUE_FRACTION = 0.25

#: Largest accepted distance |F_rest - F_g^m| as a multiple of the weight (m_b + m_t) g. A light
#: link weighs little against a force sensor's offset after taring: the paper's link 45 mN, the
#: simulated sensor's offset 12.5 mN per axis (2 counts), and at four times the nominal noise
#: (the campaign's noise sweep) 50 mN per axis, whose norm over three axes stays below 4.5
#: of them (225 mN, 5 weights) with probability 0.9997. So the force at rest tells only gross
#: unit errors (mN: 10^3); the plausibility layer of the estimators tells a force scaled by 2
#: from the torque/force ratio against the vibration, and identification and calibration do not
#: use the forces.
REST_FORCE_FRACTION = 5.0

#: Largest elevation |theta2| (rad): the link pointing straight up or down.
MAX_ELEVATION = 0.5 * math.pi

#: Largest turn of either angle between two consecutive samples (rad): half a revolution, beyond
#: which a turn cannot be told from one the other way round (the angle is aliased).
MAX_ANGLE_STEP = math.pi

#: Standard deviations (:func:`rest_moment_std`) by which the moment at rest must exceed the
#: model's weight to be read as weight the model does not carry (a payload at the tip).
PAYLOAD_SIGMAS = 3.0

#: The offset a tare leaves on a channel, in standard deviations of its noise per sample (about
#: one resolution count each): two counts, the order an F/T sensor's tare leaves.
TARE_NOISES = 2.0

_FORCE_COLUMNS = "'fx', 'fy', 'fz'"
_TORQUE_COLUMNS = "'tx', 'ty', 'tz'"


@dataclass(frozen=True)
class RestReading:
    """The loads at rest against the link's weight.

    Attributes
    ----------
    samples : int
        Samples averaged.
    force, torque : array, shape (3,)
        Mean measured force (N) and torque (N m), motor frame.
    expected_force, expected_torque : array, shape (3,)
        Mean weight of the link F_g^m and its moment Gamma_g^m over the same samples (N, N m).
    force_tolerance, torque_tolerance : float
        Largest accepted distances |force - expected_force| (N) and
        |torque - expected_torque| (N m).
    problem : str or None
        What is wrong, naming the columns and both readings; None when the recording reads the
        weight.
    """

    samples: int
    force: FloatArray
    torque: FloatArray
    expected_force: FloatArray
    expected_torque: FloatArray
    force_tolerance: float
    torque_tolerance: float
    problem: str | None

    @property
    def force_scale(self) -> float:
        """The measured force along the weight over the weight (1 for a correct file,
        1000 for one in mN, -1 with the sign flipped)."""
        return _scale(self.force, self.expected_force)

    @property
    def torque_scale(self) -> float:
        """The same for the torque and the weight's moment."""
        return _scale(self.torque, self.expected_torque)

    def as_dict(self) -> dict[str, object]:
        """The numbers, for diagnostics (SI units)."""
        return {
            "samples": self.samples,
            "force": self.force,
            "torque": self.torque,
            "expected_force": self.expected_force,
            "expected_torque": self.expected_torque,
            "force_tolerance": self.force_tolerance,
            "torque_tolerance": self.torque_tolerance,
        }


def _scale(measured: FloatArray, expected: FloatArray) -> float:
    norm = float(expected @ expected)
    if norm == 0.0:
        return math.nan
    with np.errstate(over="ignore", invalid="ignore"):
        return float(measured @ expected) / norm


def initial_rest(theta: FloatArray, tolerance: float) -> int:
    """Number of samples at the start during which neither angle leaves theta[0] by more than
    ``tolerance`` (rad); ``theta`` of shape (n, 2) in rad."""
    theta = np.asarray(theta, dtype=float)
    if theta.shape[0] == 0:
        return 0
    with np.errstate(invalid="ignore", over="ignore"):
        moved = np.flatnonzero(np.any(~(np.abs(theta - theta[0]) <= tolerance), axis=1))
    return int(moved[0]) if moved.size else int(theta.shape[0])


def rest_reading(
    theta: FloatArray,
    force: FloatArray,
    torque: FloatArray,
    antenna: Antenna,
    window: str = "at rest",
) -> RestReading:
    """Compare the mean loads over samples at rest, free of contact, with the link's weight.

    Parameters
    ----------
    theta : array, shape (n, 2)
        Motor angles (rad) of the samples at rest.
    force, torque : array, shape (n, 3)
        Measured force (N) and torque (N m) there, motor frame.
    antenna : Antenna
        Supplies the weight (Section 4.2: F_g^m and Gamma_g^m).
    window : str
        Which samples these are, for the message (``"at rest before the contact"``).

    Returns
    -------
    RestReading
        ``problem`` set when the mean force or torque lies farther from the weight than the
        tolerances (:data:`REST_TORQUE_FRACTION`, :data:`REST_FORCE_FRACTION`), or is not
        finite.
    """
    theta = np.asarray(theta, dtype=float)
    force = np.asarray(force, dtype=float)
    torque = np.asarray(torque, dtype=float)
    link = antenna.link
    expected_force = antenna.gravity_force(theta[:, 1]).mean(axis=0)
    expected_torque = antenna.gravity_torque(theta[:, 1]).mean(axis=0)
    with np.errstate(over="ignore", invalid="ignore"):
        mean_force, mean_torque = force.mean(axis=0), torque.mean(axis=0)
        force_off = float(np.linalg.norm(mean_force - expected_force))
        torque_off = float(np.linalg.norm(mean_torque - expected_torque))
    force_tolerance = REST_FORCE_FRACTION * link.weight
    torque_tolerance = REST_TORQUE_FRACTION * link.weight_moment
    reading = RestReading(
        samples=int(theta.shape[0]),
        force=mean_force,
        torque=mean_torque,
        expected_force=expected_force,
        expected_torque=expected_torque,
        force_tolerance=force_tolerance,
        torque_tolerance=torque_tolerance,
        problem=None,
    )
    duration = f"the {reading.samples} samples {window}"
    problems = []
    # The torque first: its offset is small against the weight's moment, so it is the sharper
    if not math.isfinite(torque_off):
        problems.append(
            f"columns {_TORQUE_COLUMNS}: the mean torque over {duration} overflows (values "
            "beyond 1e300?)"
        )
    elif torque_off > torque_tolerance:
        # a moment near zero at rest: the weight taken out by a tare with the link mounted
        tared = float(np.linalg.norm(mean_torque)) <= torque_tolerance
        causes = (
            "a sensor tared with the link on it (tare it without the link: the format's "
            "loads hold its weight; docs/real-antenna.md gives recordings made so their weight "
            "back), or torques scaled far down?"
            if tared
            else "torques in N mm, scaled, or a sign flipped?"
            + (
                _turned_hint(mean_torque, expected_torque, torque_tolerance)
                or _pushed_hint(mean_torque, expected_torque, force, expected_force, link.length)
            )
            + _payload_hint(
                mean_torque,
                expected_torque,
                antenna,
                torque_tolerance,
                force,
                expected_force,
                theta[:, 1],
            )
        )
        problems.append(
            f"columns {_TORQUE_COLUMNS}: over {duration} the torque reads "
            f"{_vector(mean_torque)} N m, {_times(reading.torque_scale)} the moment of the "
            f"link's weight {_vector(expected_torque)} N m that the antenna predicts (more "
            f"than {torque_tolerance:.3g} N m away{_worst(mean_torque, expected_torque, 'txyz')})"
            f": {causes}"
        )
    if not math.isfinite(force_off):
        problems.append(
            f"columns {_FORCE_COLUMNS}: the mean force over {duration} overflows (values "
            "beyond 1e300?)"
        )
    elif force_off > force_tolerance:
        problems.append(
            f"columns {_FORCE_COLUMNS}: over {duration} the force reads {_vector(mean_force)} N, "
            f"{_times(reading.force_scale)} the link's weight {_vector(expected_force)} N that "
            f"the antenna predicts (more than {force_tolerance:.3g} N away"
            f"{_worst(mean_force, expected_force, 'fxyz')}): forces in mN, scaled, or a sign "
            "flipped?"
        )
    if not problems:
        return reading
    return RestReading(**{**reading.__dict__, "problem": "; ".join(problems)})


def _turned_hint(measured: FloatArray, expected: FloatArray, tolerance: float) -> str:
    """ " Or ..." naming the turn about a motor axis that takes the ``expected`` moment at rest
    (N m) to the ``measured`` one, when the two have one size within ``tolerance`` (N m) and lie
    20 to 160 degrees apart about an axis within 25 degrees of X^m, Y^m or Z^m: a sensor's
    axes turned on the link, not a unit; "" otherwise."""
    size = float(np.linalg.norm(expected))
    if not (size > 2.0 * tolerance and abs(float(np.linalg.norm(measured)) - size) <= tolerance):
        return ""
    normal = np.cross(expected, measured)
    sine = float(np.linalg.norm(normal))
    angle = math.degrees(math.atan2(sine, float(expected @ measured)))
    if not (20.0 <= angle <= 160.0 and sine > 0.0):
        return ""
    axis = normal / sine
    k = int(np.argmax(np.abs(axis)))
    if abs(float(axis[k])) < math.cos(math.radians(25.0)):
        return ""
    sign = "" if axis[k] > 0 else "-"
    # a quarter turn is one of the axes' permutations the importers name; another is not
    quarter = abs(angle - 90.0) <= 15.0
    how = (
        "docs/import.md, 'Frames and signs'"
        if quarter
        else "the loads turned back by that angle before they are written"
    )
    return (
        f" Or the sensor's axes turned on the link: the moment has the weight's size, turned "
        f"{angle:.0f} degrees about {sign}{'XYZ'[k]}^m from it ({how})"
    )


def _pushed_hint(
    torque: FloatArray,
    expected: FloatArray,
    force: FloatArray,
    expected_force: FloatArray,
    length: float,
) -> str:
    """ " Or ..." naming a push on the link, when the mean moment at rest (``torque``, N m)
    beyond the weight's (``expected``) is that of the mean force beyond the weight's (``force``,
    N, shape (n, 3), less ``expected_force``) across the link at a point on it: the two at right
    angles to each other and to the link (X^m) within 25 degrees, the lever within ``length``
    (m) and 5 % more, and the force beyond two standard deviations of what a tare leaves (a
    tare's offset that large lies in that direction once in tens: the geometry is the sharper
    test); the lever's range is the force's two standard deviations. Not along the weight at
    its own lever (within 15 %): that is the weight read scaled or half turned. The recording
    began with the link touching (a sensor turned on the link reads the same of its weight's
    lever: asked first); "" otherwise (loads too large to square: not a push)."""
    if len(force) < 2:
        return ""
    with np.errstate(over="ignore", invalid="ignore"):
        return _push_named(torque - expected, force, expected_force, expected, length)


def _push_named(
    excess: FloatArray,
    force: FloatArray,
    expected_force: FloatArray,
    expected: FloatArray,
    length: float,
) -> str:
    """:func:`_pushed_hint`'s test and sentence (``excess``: the mean moment beyond the
    weight's, N m)."""
    push = force.mean(axis=0) - expected_force
    push[0] = 0.0  # across the link
    size = float(np.linalg.norm(push))
    noise = float(np.max(np.std(force[:, 1:], axis=0, ddof=1)))
    spread = 2.0 * rest_moment_std(noise, noise / math.sqrt(len(force)))  # N
    if not size > spread:
        return ""
    lever = np.cross([1.0, 0.0, 0.0], push)  # the moment of the push at 1 m along the link
    distance = float(excess @ lever) / size**2  # m
    cosine = float(excess @ lever) / (float(np.linalg.norm(excess)) * size)
    if not (0.0 < distance <= 1.05 * length and cosine >= math.cos(math.radians(25.0))):
        return ""
    # along the weight at the weight's own lever: the weight misread (scaled, or a sensor
    # turned half round), not a push
    across = expected_force.copy()
    across[0] = 0.0
    weight = float(np.linalg.norm(across))
    if weight > 0.0:
        weight_lever = float(np.linalg.norm(expected)) / weight
        along = abs(float(push @ across)) / (size * weight)
        if (
            along >= math.cos(math.radians(25.0))
            and abs(distance - weight_lever) <= 0.15 * weight_lever
        ):
            return ""
    near = distance * size / (size + spread)
    far = min(distance * size / (size - spread), length)
    return (
        f" Or the link touching something as the recording began: the loads beyond the weight "
        f"are those of a push of {size:.2g} N across the link, {near:.2g} to {far:.2g} m along "
        "it (a recording starts with the head at rest and the link free)."
    )


def _payload_hint(
    torque: FloatArray,
    expected: FloatArray,
    antenna: Antenna,
    tolerance: float,
    force: FloatArray,
    expected_force: FloatArray,
    theta2: FloatArray,
) -> str:
    """ " Or ..." naming the tip mass (g) whose weight the mean torque at rest (N m) reads beyond
    the model's ``expected`` moment, when the excess lies along that moment (the rest across it
    within ``tolerance``, N m), adds to it, and the forces at rest (N, shape (n, 3)) carry that
    weight too beyond ``expected_force`` (N), as far as the offset a tare leaves tells
    (:func:`is_payload` of the difference): a torque scaled up three times or more reads no
    heavier force; "" otherwise."""
    size = float(np.linalg.norm(expected))
    weight = float(np.linalg.norm(expected_force))
    if not (size > 0.0 and weight > 0.0 and len(force) > 1):
        return ""
    along = expected / size
    excess = torque - expected
    extra = float(excess @ along)
    across = float(np.linalg.norm(excess - extra * along))
    if not (extra > 0.0 and across <= tolerance):
        return ""
    mass = antenna.link.tip_mass_for_moment(extra, theta2)
    if not mass > 0.0:
        return ""
    down = force @ (expected_force / weight)  # N, each sample's force along the weight
    noise = float(np.std(down, ddof=1))
    # the force's excess over the model's weight, less the tip mass's, judged as the moment's
    # payload is: beyond the tare's offset and the mean's error, the force reads another weight
    missing = float(np.mean(down)) - weight - mass * STANDARD_GRAVITY
    if is_payload(missing, rest_moment_std(noise, noise / math.sqrt(len(down)))):
        return ""
    return (
        f" Or, as weight, {1e3 * mass:.2g} g at the tip that the antenna file does not carry"
        " (its [link] tip_mass)"
    )


def _worst(read: FloatArray, expected: FloatArray, names: str) -> str:
    """Which column (``names``: the letter, then x, y, z) lies farthest from its expected value,
    when it holds most of the distance: a single column in the wrong unit or sign."""
    off = np.abs(read - expected)
    k = int(np.argmax(off))
    # "most": 80 % of the squared distance. One column in the wrong unit or sign holds nearly
    # all of it (a tz in N mm: 0.0218 N m against the others' offsets of 1e-4), a scale of
    # the whole wrench spreads it as the weight's moment does (ty alone at theta2 = 0, yet
    # then that is the column to look at too)
    if not (math.isfinite(off[k]) and off[k] ** 2 > 0.8 * float(off @ off)):
        return ""
    return f", most of it in '{names[0]}{names[1 + k]}'"


def _vector(values: FloatArray) -> str:
    return "(" + ", ".join(f"{v:.3g}" for v in values) + ")"


def _times(scale: float) -> str:
    if not math.isfinite(scale):
        return "unlike"
    return f"{scale:.3g} times"


def angle_problem(theta: FloatArray) -> str | None:
    """Why the angles (rad), shape (n, 2), cannot be a head's angles in radians, or None.

    An elevation beyond +-pi/2 (:data:`MAX_ELEVATION`), a step between two samples of
    :data:`MAX_ANGLE_STEP` or more, or a value that is not finite; the message names the column
    and the value (angles in degrees reach beyond pi/2 as soon as the elevation exceeds
    1.6 degrees).
    """
    theta = np.asarray(theta, dtype=float)
    with np.errstate(invalid="ignore", over="ignore"):
        for column, name in ((1, "theta2"), (0, "theta1")):
            values = theta[:, column]
            if not np.all(np.isfinite(values)):
                return f"column '{name}': a value is not finite"
            if column == 1:
                worst = int(np.argmax(np.abs(values)))
                if abs(values[worst]) > MAX_ELEVATION:
                    return (
                        f"column '{name}': the elevation reaches {values[worst]:.4g} rad, beyond "
                        f"the vertical ({MAX_ELEVATION:.4f} rad): angles in degrees?"
                    )
            steps = np.abs(np.diff(values))
            if steps.size and not np.all(steps < MAX_ANGLE_STEP):
                k = int(np.argmax(~(steps < MAX_ANGLE_STEP)))
                return (
                    f"column '{name}': the angle jumps by {steps[k]:.4g} rad between samples "
                    f"{k + 1} and {k + 2} (at most {MAX_ANGLE_STEP:.4f} rad per sample)"
                )
    return None


def recording_problem(
    theta: FloatArray,
    force: FloatArray,
    torque: FloatArray,
    antenna: Antenna,
    rest_tolerance: float,
    min_rest_samples: int,
) -> str | None:
    """Why a whole recording is not in the format's units and signs, or None.

    The angles (:func:`angle_problem`), then the loads over the samples at rest at the start
    (:func:`initial_rest` within ``rest_tolerance`` rad) against the link's weight
    (:func:`rest_reading`), when the head rests for at least ``min_rest_samples`` samples (a
    recording that starts moving is not judged by its rest). Shapes (n, 2), (n, 3), (n, 3).
    """
    problem = angle_problem(theta)
    if problem is not None:
        return problem
    rest = initial_rest(theta, rest_tolerance)
    if rest < min_rest_samples:
        return None
    window = slice(0, rest)
    reading = rest_reading(
        theta[window], force[window], torque[window], antenna, "at rest at the start"
    )
    return reading.problem


def rest_moment_std(noise: float, mean_error: float) -> float:
    """Standard deviation (N m) of a moment at rest beyond the model's weight when the link
    carries none: the rest mean's ``mean_error`` and the offset a tare leaves,
    :data:`TARE_NOISES` times the channel's ``noise`` per sample (N m), in quadrature."""
    return math.hypot(mean_error, TARE_NOISES * noise)


def is_payload(excess: float, std: float) -> bool:
    """Whether a moment at rest ``excess`` (N m) beyond the model's weight is weight the model
    does not carry: more than :data:`PAYLOAD_SIGMAS` times its ``std`` (:func:`rest_moment_std`)
    from zero, either sign (a lighter reading is a link lighter than its model)."""
    return bool(std >= 0.0 and abs(excess) > PAYLOAD_SIGMAS * std)
