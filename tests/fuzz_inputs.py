"""The fuzz suite's inputs and judges, shared by ``tests/test_fuzz.py`` (a few examples per area
in every test run) and ``benchmarks/fuzz.py`` (the long run, thousands of inputs).

Each area has a hypothesis strategy that draws one input and a ``run_*`` function that feeds it
to the package through its public API and returns the :class:`Outcome` of each thing judged
(one per method for the estimators). What may come out of anything:

- a result: ``ok`` (a recording read, an antenna loaded, an estimate with status ``ok`` ...), or
  for an estimate the status that says why it is not to be trusted;
- ``error``: a :class:`~sensing_antenna.errors.SensingAntennaError` with a one-line message (the
  command line prints it and exits 2).

Anything else is a finding (:data:`BAD_KINDS`): another exception (``traceback``), an error of
several lines, an ``ok`` estimate outside (0, l] or from an input that fails the plausibility
layer's units check (a lone glitched sample aside: the front end puts it back), a best guess that is
neither on the link nor NaN, a command that ends other than with exit code 0 or 2 and one line.

Estimator, identification and calibration inputs are simulated recordings perturbed the way
users and machines get them wrong (forces in mN, a sign flipped, angles in degrees, noise,
truncation, a glitch, a synthetic sine as the wrench): :func:`simulate_bases` makes the few
recordings once, the strategies draw the perturbations.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import io
import json
import math
import os
import string
import tempfile
import traceback
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import strategies as st
from scipy.ndimage import median_filter

from sensing_antenna.antenna import Antenna, antenna_to_toml, load_antenna, paper_antenna
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.recording import Recording, read_recording, write_recording

# --------------------------------------------------------------------------------------------
# Outcomes

OK = "ok"
ERROR = "error"
TRACEBACK = "traceback"
MULTI_LINE_ERROR = "multi-line error"
OK_OUTSIDE_LINK = "ok outside (0, l]"
OK_IMPLAUSIBLE = "ok failing plausibility"
BAD_GUESS = "guess off the link"
BAD_ENDING = "bad exit or stderr"
WARNING = "warning"

#: The kinds of outcome that are findings: each one is a bug of the package.
BAD_KINDS = frozenset(
    {TRACEBACK, MULTI_LINE_ERROR, OK_OUTSIDE_LINK, OK_IMPLAUSIBLE, BAD_GUESS, BAD_ENDING, WARNING}
)


@dataclass(frozen=True)
class Outcome:
    """What one input gave: ``kind`` (``ok``, a status name, ``error`` or a finding of
    :data:`BAD_KINDS`), ``label`` (the method, or ``""``) and ``detail`` (the message)."""

    kind: str
    detail: str = ""
    label: str = ""

    @property
    def bad(self) -> bool:
        return self.kind in BAD_KINDS


def guarded(action: Callable[[], list[Outcome]]) -> list[Outcome]:
    """``action()``, with a project error as ``error`` (one line), any other exception as
    ``traceback`` and a warning (lines on a user's stderr, an error in the tests) as
    ``warning``."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            outcomes = action()
        except SensingAntennaError as exc:
            text = str(exc)
            kind = ERROR if text and "\n" not in text else MULTI_LINE_ERROR
            outcomes = [Outcome(kind, text)]
        except Exception as exc:  # any other exception is what the suite hunts
            outcomes = [Outcome(TRACEBACK, _exception_text(exc))]
    if caught:
        first = caught[0]
        where = f"{Path(first.filename).name}:{first.lineno}"
        return [Outcome(WARNING, f"{first.category.__name__}: {first.message} ({where})")]
    return outcomes


def _exception_text(exc: BaseException) -> str:
    """The exception and where it was raised (the innermost frame of the package)."""
    frames = traceback.extract_tb(exc.__traceback__)
    own = [f for f in frames if "sensing_antenna" in f.filename] or frames
    where = f" ({Path(own[-1].filename).name}:{own[-1].lineno})" if own else ""
    return f"{type(exc).__name__}: {exc}"[:400] + where


# --------------------------------------------------------------------------------------------
# Numbers users and machines write

#: Values that break arithmetic: zero, signs, the edges of float64, non-finite.
SPECIAL_FLOATS = (
    0.0,
    -0.0,
    1.0,
    -1.0,
    1e-300,
    -1e-300,
    5e-324,
    1e300,
    -1e300,
    1.7976931348623157e308,
    math.inf,
    -math.inf,
    math.nan,
)

special_floats = st.sampled_from(SPECIAL_FLOATS)
any_float = st.one_of(st.floats(allow_nan=True, allow_infinity=True), special_floats)
moderate_float = st.floats(min_value=-1e3, max_value=1e3, allow_nan=False)


def number_text(value: float) -> str:
    """A float as a CSV cell or an argument: Python's ``repr``, or an integer form."""
    return repr(value) if not float(value).is_integer() or abs(value) > 1e15 else str(int(value))


# --------------------------------------------------------------------------------------------
# Area 1: the recording reader (arbitrary bytes and text)

_REQUIRED = ("t", "theta1", "theta2", "fx", "fy", "fz", "tx", "ty", "tz")
_METADATA_KEYS = ("format", "sample_period", "antenna", "true_xc", "seed", "note", "")
_METADATA_VALUES = st.one_of(
    st.sampled_from(
        [
            "sensing-antenna-recording/1",
            "sensing-antenna-recording/2",
            "0.001",
            "0",
            "-1",
            "nan",
            "inf",
            "1e308",
            "1e-320",
            "",
        ]
    ),
    st.text(max_size=12),
)
_CELL_WORDS = ("", " ", "nan", "NaN", "inf", "-inf", "1e999", "-1e999", "0x10", "1_0", "abc", '"1"')


@st.composite
def csv_cells(draw: st.DrawFn) -> str:
    """One cell: a number (often special), or text that is not one."""
    return draw(
        st.one_of(
            moderate_float.map(number_text),
            any_float.map(number_text),
            st.sampled_from(_CELL_WORDS),
            st.text(alphabet=string.printable, max_size=6),
        )
    )


@st.composite
def recording_texts(draw: st.DrawFn) -> bytes:
    """A recording file: metadata lines, a header (columns missing, repeated, extra, reordered)
    and rows of numbers with a few bad cells, rows or time stamps (repeated, decreasing, an
    outlier), or bytes. Often a valid file: the reader's ``ok`` is judged too."""
    if draw(st.integers(0, 19)) == 0:
        return draw(st.binary(max_size=200))
    lines: list[str] = []
    for _ in range(draw(st.integers(0, 3))):
        if draw(st.booleans()):
            lines.append(
                draw(st.sampled_from(["# format: sensing-antenna-recording/1", "# note: x"]))
            )
            continue
        key = draw(st.one_of(st.sampled_from(_METADATA_KEYS), st.text(min_size=1, max_size=6)))
        value = draw(_METADATA_VALUES)
        forms = [f"# {key}: {value}"] * 6 + [f"#{key}", "#", f"# {key}:"]
        lines.append(draw(st.sampled_from(forms)))
    columns = list(_REQUIRED)
    header = draw(st.integers(0, 9))
    if header == 0:
        columns = draw(st.lists(st.sampled_from([*_REQUIRED, "true_xc", "x", ""]), max_size=11))
    elif header <= 2:
        columns = draw(st.permutations(columns))
    elif header == 3:
        columns.append(draw(st.sampled_from(["true_xc", "contact", "theta1_ref", " t "])))
    lines.append(",".join(columns))
    n_rows = draw(st.integers(0, 12))
    period = draw(st.sampled_from([1e-3, 1e-3, 1.0, 1e-9, 1e6, 0.1]))
    time_kind = draw(st.sampled_from(["regular"] * 4 + ["jitter", "outlier", "repeat"]))
    rows = []
    for i in range(n_rows):
        t = i * period
        if time_kind == "jitter":
            t += draw(st.floats(-0.5, 0.5)) * period
        if time_kind == "outlier" and i == n_rows - 1:
            t = draw(st.sampled_from([1e6, 1e300, 1e12, 10.0]))
        if time_kind == "repeat" and i == n_rows // 2:
            t = (i - 1) * period
        values = draw(st.lists(moderate_float, min_size=len(columns), max_size=len(columns)))
        rows.append([number_text(t), *(number_text(v) for v in values[1:])])
    for _ in range(draw(st.integers(0, 3)) if rows else 0):
        row = draw(st.integers(0, len(rows) - 1))
        if draw(st.integers(0, 5)) == 0:
            rows[row] = rows[row][: draw(st.integers(0, len(rows[row])))]
        elif rows[row]:
            rows[row][draw(st.integers(0, len(rows[row]) - 1))] = draw(csv_cells())
    lines.extend(",".join(row) for row in rows)
    newline = draw(st.sampled_from(["\n", "\r\n", "\r"]))
    text = newline.join(lines) + draw(st.sampled_from(["", newline, newline * 3]))
    data = text.encode("utf-8")
    if draw(st.integers(0, 9)) == 0 and data:
        k = draw(st.integers(0, len(data) - 1))
        data = (
            data[:k] + draw(st.sampled_from([b"\0", b"\xff", b"\xc3", b"\xef\xbb\xbf"])) + data[k:]
        )
    return data


def run_reader(data: bytes) -> list[Outcome]:
    """Write ``data`` to a file and read it as a recording; a recording read must be one."""

    def action() -> list[Outcome]:
        with tempfile.TemporaryDirectory(prefix="fuzz-") as folder:
            path = Path(folder) / "rec.csv"
            path.write_bytes(data)
            recording = read_recording(path)
            for name in ("t", "theta", "force", "torque"):
                if not np.all(np.isfinite(getattr(recording, name))):
                    return [Outcome(TRACEBACK, f"{name}: a value read is not finite")]
            if not np.all(np.diff(recording.t) > 0):
                return [Outcome(TRACEBACK, "t: read but not increasing")]
            back = Path(folder) / "back.csv"
            write_recording(recording, back)
            again = read_recording(back)
            same = all(
                np.array_equal(getattr(again, name), getattr(recording, name))
                for name in ("t", "theta", "force", "torque")
            ) and all(np.array_equal(again.extra[k], v) for k, v in recording.extra.items())
            if not same or list(again.extra) != list(recording.extra):
                return [Outcome(TRACEBACK, "written and read again, the samples differ")]
            _ = recording.sampling
        return [Outcome(OK)]

    return guarded(action)


# --------------------------------------------------------------------------------------------
# The simulated recordings every perturbation starts from


@dataclass(frozen=True)
class Bases:
    """Simulated recordings of the paper's antenna: contact manoeuvres and a free motion."""

    antenna: Antenna
    contacts: tuple[Recording, ...]
    contact_points: tuple[float, ...]
    free: Recording


def simulate_bases() -> Bases:
    """Two contact manoeuvres (azimuthal at 0.4 m, vertical at 0.8 m) and a 2 s free motion
    (seconds of simulation: make them once)."""
    from sensing_antenna.simulator import Scenario, simulate

    antenna = paper_antenna()
    contacts = tuple(
        simulate(antenna, Scenario(case=case, contact_point=x_c, seed=seed))
        for case, x_c, seed in (("azimuthal", 0.4, 1), ("vertical", 0.8, 2))
    )
    free = simulate(antenna, Scenario(case="free", duration=2.0, seed=3))
    return Bases(
        # the estimators' model: the device's own T as a calibration gives it (0.1 %), so the
        # untouched manoeuvres are ok and a perturbation is what moves them
        antenna=antenna.self_calibrated(),
        contacts=tuple(r.without_ground_truth() for r in contacts),
        contact_points=tuple(float(r.metadata["true_xc"]) for r in contacts),
        free=free.without_ground_truth(),
    )


_SCALES = (1.0, -1.0, 2.0, 0.5, 1e-3, 1e3, 0.0, 1e-300, 1e300)


def scale_factors() -> st.SearchStrategy[float]:
    """A factor for loads or angles: mostly 1, often a unit error, sometimes anything finite."""
    return st.one_of(
        st.just(1.0),
        st.sampled_from(_SCALES),
        st.sampled_from([180.0 / math.pi, math.pi / 180.0]),
        st.floats(min_value=-1e6, max_value=1e6, allow_nan=False),
    )


@dataclass(frozen=True)
class Perturbation:
    """How a simulated recording is spoilt (every field's neutral value leaves it as it is).

    ``base`` picks the recording; the loads and angles are multiplied by their scales and the
    columns ``theta1, theta2, fx, fy, fz, tx, ty, tz`` marked in ``flips`` change sign; Gaussian
    ``noise`` (times each column's spread) is added; only the fraction ``keep_from`` to
    ``keep_to`` of the samples is kept; ``glitch`` = (where, column, value) sets one sample;
    ``sine_hz`` replaces the wrench after its first third by a sine about its mean; the time
    stamps are multiplied by ``time_scale`` (the sample period goes with them).
    """

    base: int = 0
    force_scale: float = 1.0
    torque_scale: float = 1.0
    angle_scale: float = 1.0
    flips: tuple[bool, ...] = (False,) * 8
    noise: float = 0.0
    noise_seed: int = 0
    keep_from: float = 0.0
    keep_to: float = 1.0
    glitch: tuple[float, int, float] | None = None
    sine_hz: float | None = None
    time_scale: float = 1.0

    def apply(self, recording: Recording) -> Recording:
        """The spoilt recording (raises ``RecordingError`` when it is no recording at all)."""
        n = recording.n_samples
        start = min(int(self.keep_from * n), n - 2)
        stop = max(start + 2, math.ceil(self.keep_to * n))
        window = slice(start, stop)
        t = recording.t[window] * self.time_scale
        columns = np.column_stack(
            [recording.theta[window], recording.force[window], recording.torque[window]]
        )
        with np.errstate(all="ignore"):
            columns[:, :2] *= self.angle_scale
            columns[:, 2:5] *= self.force_scale
            columns[:, 5:] *= self.torque_scale
            columns[:, list(self.flips)] *= -1.0
            if self.sine_hz is not None:
                # the wrench after the first third: its mean plus a synthetic sine
                k = columns.shape[0] // 3
                sine = np.sin(2.0 * math.pi * self.sine_hz * (t[k:] - t[k]))
                loads = columns[k:, 2:]
                columns[k:, 2:] = loads.mean(axis=0) + loads.std(axis=0) * 3.0 * sine[:, None]
            if self.noise > 0.0:
                rng = np.random.default_rng(self.noise_seed)
                spread = np.std(columns, axis=0) + 1e-12
                columns += self.noise * spread * rng.standard_normal(columns.shape)
            if self.glitch is not None:
                where, column, value = self.glitch
                columns[min(int(where * columns.shape[0]), columns.shape[0] - 1), column] = value
        return Recording(
            t=t,
            theta=columns[:, :2],
            force=columns[:, 2:5],
            torque=columns[:, 5:],
            metadata={k: v for k, v in recording.metadata.items() if k != "sample_period"},
            source="<fuzzed>",
        )


#: Each spoiler's strategy; :func:`perturbations` draws a few of them, the rest stay neutral.
SPOILERS: dict[str, st.SearchStrategy[Any]] = {
    "force_scale": scale_factors(),
    "torque_scale": scale_factors(),
    "angle_scale": scale_factors(),
    "flips": st.lists(st.booleans(), min_size=8, max_size=8).map(tuple),
    "noise": st.sampled_from([0.01, 0.1, 1.0, 10.0]),
    "keep_from": st.floats(0.0, 0.95),
    "keep_to": st.floats(0.05, 1.0),
    "glitch": st.tuples(st.floats(0.0, 1.0), st.integers(0, 7), any_float),
    "sine_hz": st.floats(0.5, 60.0),
    "time_scale": st.sampled_from([1e-3, 1e3, 0.5, 2.0, 1e-6]),
}


@st.composite
def perturbations(draw: st.DrawFn, n_bases: int = 2) -> Perturbation:
    """A :class:`Perturbation` of one of ``n_bases`` recordings: none to three spoilers, each
    drawn separately, so shrinking finds the one that matters."""
    names = draw(st.lists(st.sampled_from(sorted(SPOILERS)), max_size=3, unique=True))
    values = {name: draw(SPOILERS[name]) for name in names}
    return Perturbation(
        base=draw(st.integers(0, n_bases - 1)),
        noise_seed=draw(st.integers(0, 2**16)),
        **values,
    )


# --------------------------------------------------------------------------------------------
# Area 2: the estimators, every method of the registry


def _up_to(recording: Recording, t_end: float) -> Recording:
    """The samples up to ``t_end`` (s), at least two."""
    if not math.isfinite(t_end):
        return recording
    stop = max(int(np.searchsorted(recording.t, t_end, side="right")), 2)
    return Recording(
        t=recording.t[:stop],
        theta=recording.theta[:stop],
        force=recording.force[:stop],
        torque=recording.torque[:stop],
        metadata=recording.metadata,
    )


def _without_lone_samples(recording: Recording) -> Recording:
    """The recording with each wrench channel through a running median of three samples, so a
    single sample off both its neighbours (a glitch of the bus) takes a neighbour's value."""
    with np.errstate(all="ignore"):
        loads = median_filter(
            np.column_stack([recording.force, recording.torque]), size=(3, 1), mode="nearest"
        )
    return dataclasses.replace(recording, force=loads[:, :3], torque=loads[:, 3:])


def _finite_or_nan(value: float) -> bool:
    return math.isfinite(value) or math.isnan(value)


def judge_estimate(estimate: Any, recording: Recording, antenna: Antenna) -> Outcome:
    """The outcome of one estimate (see the module docstring)."""
    from sensing_antenna.calibration.observer import units_problem
    from sensing_antenna.estimation import Status
    from sensing_antenna.units_check import angle_problem

    length = antenna.link.length
    x_c = float(estimate.x_c)
    label = estimate.method
    on_link = math.isfinite(x_c) and 0.0 < x_c <= length
    try:
        json.dumps(estimate.to_dict(), allow_nan=False)
    except (TypeError, ValueError) as exc:
        return Outcome(TRACEBACK, f"to_dict is not JSON: {exc}", label)
    if estimate.status is Status.OK:
        if not on_link:
            return Outcome(OK_OUTSIDE_LINK, f"x_c = {x_c!r} m, l = {length} m", label)
        # check 1 of the layer: the loads at rest before t_c, the angles up to t_e; a lone
        # sensor sample off its neighbours is a glitch the front end puts back, not units
        problem = units_problem(
            _without_lone_samples(_up_to(recording, estimate.t_c)), antenna
        ) or angle_problem(_up_to(recording, estimate.t_e).theta)
        if problem is not None:
            return Outcome(OK_IMPLAUSIBLE, problem, label)
        if "vibration_contact_point" not in estimate.diagnostics:
            return Outcome(OK_IMPLAUSIBLE, "no vibration check recorded", label)
        if estimate.reason is not None:
            return Outcome(OK_IMPLAUSIBLE, "an ok estimate with a reason", label)
    elif not (on_link or math.isnan(x_c)):
        return Outcome(BAD_GUESS, f"{estimate.status.value}: x_c = {x_c!r} m", label)
    if not all(0.0 < c <= length for c in estimate.candidates):
        return Outcome(BAD_GUESS, f"candidates {estimate.candidates}", label)
    if estimate.interval is not None:
        low, high = estimate.interval
        if not (0.0 <= low <= high <= length):
            return Outcome(BAD_GUESS, f"interval {estimate.interval}", label)
    point = np.asarray(estimate.contact_point)
    if not (np.all(np.isnan(point)) or float(np.linalg.norm(point)) <= 1.1 * length):
        return Outcome(BAD_GUESS, f"contact point {point} m", label)
    for name in ("omega1", "peak_quality", "ratio_estimate", "t_c", "t_1", "t_e"):
        if not _finite_or_nan(float(getattr(estimate, name))):
            return Outcome(BAD_GUESS, f"{name} = {getattr(estimate, name)!r}", label)
    if not estimate.ok and not estimate.reason:
        return Outcome(TRACEBACK, "a status without a reason", label)
    return Outcome(estimate.status.value, estimate.reason or "", label)


def run_estimators(bases: Bases, perturbation: Perturbation) -> list[Outcome]:
    """Every registered method on one spoilt contact recording (the front end once)."""
    from sensing_antenna.estimation import METHODS, conclude, gather

    outcomes: list[Outcome] = []

    def action() -> list[Outcome]:
        recording = perturbation.apply(bases.contacts[perturbation.base])
        gathered = gather(recording, bases.antenna)
        for name in METHODS:
            judged = guarded(
                lambda name=name: [
                    judge_estimate(conclude(gathered, name), recording, bases.antenna)
                ]
            )
            outcomes.extend(dataclasses.replace(o, label=name) for o in judged)
        return outcomes

    result = guarded(action)
    if result is outcomes:
        return outcomes
    # the recording could not be built or the front end failed: the same for every method
    return [dataclasses.replace(result[0], label=name) for name in _method_names()]


def _method_names() -> tuple[str, ...]:
    from sensing_antenna.estimation import METHODS

    return tuple(METHODS)


# --------------------------------------------------------------------------------------------
# Area 3: identification of the free-motion observer


@st.composite
def identify_inputs(draw: st.DrawFn) -> tuple[Perturbation, float]:
    """A spoilt free-motion recording and a margin."""
    margin = draw(st.one_of(st.just(1.5), any_float, st.floats(0.5, 10.0)))
    return draw(perturbations(n_bases=1)), margin


def run_identify(bases: Bases, case: tuple[Perturbation, float]) -> list[Outcome]:
    """``identify_free_motion`` on a spoilt free motion; a fit must be a usable observer
    from a recording that passes the units check."""
    from sensing_antenna.antenna import FreeMotionObserver
    from sensing_antenna.calibration.observer import identify_free_motion, units_problem

    perturbation, margin = case

    def action() -> list[Outcome]:
        recording = perturbation.apply(bases.free)
        fit = identify_free_motion(recording, bases.antenna, margin=margin)
        values = (fit.gain, fit.natural_frequency, fit.damping, fit.contact_threshold)
        if not all(math.isfinite(v) and v > 0.0 for v in values):
            return [Outcome(OK_IMPLAUSIBLE, f"fit {values}")]
        problem = units_problem(recording, bases.antenna)
        if problem is not None:
            return [Outcome(OK_IMPLAUSIBLE, problem)]
        FreeMotionObserver(*values)
        return [Outcome(OK)]

    return guarded(action)


# --------------------------------------------------------------------------------------------
# Area 4: calibration of T_e


@st.composite
def calibrate_inputs(draw: st.DrawFn) -> tuple[str, Any]:
    """Either spoilt contact recordings with contact points (``recordings``) or measured
    frequencies at contact points (``table``), each possibly absurd."""
    if draw(st.booleans()):
        n = draw(st.integers(0, 3))
        spoilt = draw(st.lists(perturbations(), min_size=n, max_size=n))
        points = draw(
            st.lists(
                st.one_of(st.sampled_from([0.4, 0.8]), any_float, st.floats(0.0, 1.2)),
                min_size=n,
                max_size=n + draw(st.integers(0, 1)),
            )
        )
        loss = draw(st.sampled_from(["soft_l1", "linear", "huber", "cauchy", "arctan"]))
        return "recordings", (spoilt, points, loss)
    n = draw(st.integers(0, 6))
    points = draw(st.lists(st.one_of(st.floats(0.01, 0.98), any_float), min_size=n, max_size=n))
    omega = draw(
        st.lists(
            st.one_of(st.floats(1.0, 1e4), any_float),
            min_size=n,
            max_size=n + draw(st.integers(0, 1)),
        )
    )
    loss = draw(st.one_of(st.sampled_from(["soft_l1", "linear"]), st.text(max_size=5)))
    return "table", (points, omega, loss)


def run_calibrate(bases: Bases, case: tuple[str, Any]) -> list[Outcome]:
    """Calibration of T_e; a fitted T_e must be finite and positive, and no recording that fails
    the units check may enter the fit (the calibration leaves such a file out, with a note)."""
    from sensing_antenna.calibration.frequency import calibrate_from_recordings, calibrate_t_e
    from sensing_antenna.calibration.observer import units_problem

    kind, data = case

    def action() -> list[Outcome]:
        if kind == "recordings":
            spoilt, points, loss = data
            recordings = [p.apply(bases.contacts[p.base]) for p in spoilt]
            fit = calibrate_from_recordings(recordings, bases.antenna, points, loss=loss)
            for recording, used in zip(recordings, fit.used, strict=True):
                problem = units_problem(recording, bases.antenna)
                if problem is not None and used:
                    return [Outcome(OK_IMPLAUSIBLE, problem)]
        else:
            points, omega, loss = data
            fit = calibrate_t_e(points, omega, bases.antenna.link, loss=loss)
        if not (math.isfinite(fit.t_e) and fit.t_e > 0.0):
            return [Outcome(OK_IMPLAUSIBLE, f"T_e = {fit.t_e!r}")]
        fit.apply(bases.antenna)
        return [Outcome(OK)]

    return guarded(action)


# --------------------------------------------------------------------------------------------
# TOML text of arbitrary values


def toml_value(value: Any) -> str:
    """``value`` as a TOML value (inline tables and arrays; strings with JSON's escapes)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{toml_key(k)} = {toml_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(type(value))


def toml_key(key: str) -> str:
    """A TOML key: bare when it can be, quoted otherwise."""
    bare = key and all(c.isascii() and (c.isalnum() or c in "-_") for c in key)
    return key if bare else json.dumps(key, ensure_ascii=False)


def toml_document(tables: Mapping[str, Mapping[str, Any]], top: Mapping[str, Any]) -> str:
    """A TOML document: the ``top`` keys, then one ``[table]`` per entry of ``tables``."""
    lines = [f"{toml_key(k)} = {toml_value(v)}" for k, v in top.items()]
    for name, table in tables.items():
        lines.append(f"[{toml_key(name)}]")
        lines.extend(f"{toml_key(k)} = {toml_value(v)}" for k, v in table.items())
    return "\n".join(lines) + "\n"


scalar_values = st.one_of(
    any_float,
    st.floats(min_value=1e-4, max_value=1e3),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.sampled_from([0, 1, -1, 2, 10**9]),
    st.booleans(),
    st.text(max_size=8),
    st.sampled_from(["paper-2021", "default", "azimuthal", "vertical", "free", "paper"]),
)
toml_values = st.recursive(
    scalar_values,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=5), inner, max_size=3)
    ),
    max_leaves=6,
)


@st.composite
def edited_tables(
    draw: st.DrawFn, tables: Mapping[str, Mapping[str, Any]], top: Mapping[str, Any]
) -> tuple[dict[str, dict[str, Any]], dict[str, Any]]:
    """``tables`` and ``top`` with some known fields set to arbitrary values, some dropped and an
    unknown one added now and then."""
    new_top = dict(top)
    new_tables = {name: dict(table) for name, table in tables.items()}
    for _ in range(draw(st.integers(0, 3))):
        where = draw(st.sampled_from(["", *new_tables]))
        target = new_top if where == "" else new_tables[where]
        if not target:
            continue
        key = draw(st.sampled_from(sorted(target)))
        action = draw(st.integers(0, 9))
        if action == 0:
            del target[key]
        elif action == 1:
            target[draw(st.text(min_size=1, max_size=6))] = draw(scalar_values)
        else:
            target[key] = draw(toml_values)
    return new_tables, new_top


# --------------------------------------------------------------------------------------------
# Area 5: antenna TOML files

_ANTENNA_TOP = {"name": "fuzzed", "description": "an antenna from the fuzz suite"}
_ANTENNA_TABLES = {
    "link": {
        "length": 0.98,
        "radius": 1.0e-3,
        "youngs_modulus": 115e9,
        "linear_density": 4.7e-3,
        "tip_mass": 0.0,
    },
    "azimuth_motor": {
        "torque_constant": 0.003,
        "inertia": 6.2e-3,
        "viscous_friction": 30.4e-3,
        "coulomb_voltage": 0.48,
        "gear_ratio": 100.0,
    },
    "elevation_motor": {
        "torque_constant": 0.003,
        "inertia": 1.8e-3,
        "viscous_friction": 28.5e-3,
        "coulomb_voltage": 0.42,
        "gear_ratio": 100.0,
    },
    "observer": {
        "gain": 0.37,
        "natural_frequency": 16.4,
        "damping": 0.3,
        "contact_threshold": 0.02,
    },
}


@st.composite
def antenna_files(draw: st.DrawFn) -> bytes:
    """An antenna TOML file: the paper's with fields changed, a ``base`` variant, or junk."""
    choice = draw(st.integers(0, 9))
    if choice == 0:
        return draw(st.binary(max_size=100))
    if choice == 1:
        return draw(st.text(max_size=100)).encode("utf-8")
    if choice <= 3:
        top = {"base": draw(st.one_of(st.just("paper-2021"), scalar_values))}
        tables = {"link": {"length": draw(toml_values)}}
        new_tables, new_top = draw(edited_tables(tables, top))
        return toml_document(new_tables, new_top).encode("utf-8")
    tables, top = draw(edited_tables(_ANTENNA_TABLES, _ANTENNA_TOP))
    return toml_document(tables, top).encode("utf-8")


def run_antenna_file(data: bytes) -> list[Outcome]:
    """Load an antenna file; an antenna loaded must have finite positive parameters, be written
    back to TOML that loads as the same antenna, and give the sensing curve's physics."""
    from sensing_antenna.beam import natural_frequencies

    def action() -> list[Outcome]:
        with tempfile.TemporaryDirectory(prefix="fuzz-") as folder:
            path = Path(folder) / "antenna.toml"
            path.write_bytes(data)
            antenna = load_antenna(path)
            again = Path(folder) / "again.toml"
            again.write_text(antenna_to_toml(antenna), encoding="utf-8")
            if load_antenna(again) != antenna:
                return [Outcome(TRACEBACK, "written and loaded again, the antenna differs")]
        link = antenna.link
        if not (math.isfinite(link.theoretical_t) and link.theoretical_t > 0):
            return [Outcome(TRACEBACK, f"T = {link.theoretical_t!r}")]
        omega = natural_frequencies(link, 0.5 * link.length, 1)
        if not np.all(np.isfinite(omega)):
            return [Outcome(TRACEBACK, f"omega_1 at l / 2 = {omega!r}")]
        return [Outcome(OK)]

    return guarded(action)


# --------------------------------------------------------------------------------------------
# Area 6: campaign specs

_CAMPAIGN_TOP = {
    "name": "fuzzed",
    "antenna": "paper-2021",
    "cases": ["azimuthal"],
    "contact_points": [0.3, 0.6],
    "repeats": 1,
    "base_seed": 1,
    "methods": ["paper"],
}
_CAMPAIGN_TABLES = {
    "scenario": {"noise_scale": 1.0, "damping_ratio": 0.005, "duration": 3.5},
    "free_motion": {"identify": True, "duration": 4.0},
    "device": {"antenna": "paper-2021", "link": {"youngs_modulus": 132.65e9}},
    "calibration": {
        "enabled": True,
        "case": "azimuthal",
        "contact_points": [0.3, 0.6],
        "repeats": 1,
        "loss": "soft_l1",
    },
    "noise_sweep": {"noise_scales": [0.5], "contact_points": [0.3], "repeats": 1},
}


@st.composite
def campaign_files(draw: st.DrawFn) -> bytes:
    """A campaign spec file: a small spec with fields changed, a ``base`` variant, or junk."""
    choice = draw(st.integers(0, 9))
    if choice == 0:
        return draw(st.binary(max_size=100))
    if choice <= 2:
        top = {"base": draw(st.one_of(st.just("default"), scalar_values)), "repeats": 1}
        new_tables, new_top = draw(edited_tables({"scenario": {"noise_scale": 1.0}}, top))
        return toml_document(new_tables, new_top).encode("utf-8")
    tables = {k: v for k, v in _CAMPAIGN_TABLES.items() if draw(st.booleans())}
    new_tables, new_top = draw(edited_tables(tables, _CAMPAIGN_TOP))
    return toml_document(new_tables, new_top).encode("utf-8")


def run_campaign_file(data: bytes) -> list[Outcome]:
    """Load a campaign spec and list its runs; a spec loaded must list them within the limits."""
    from sensing_antenna.campaign.limits import MAX_RUNS
    from sensing_antenna.campaign.parsing import load_campaign_spec
    from sensing_antenna.campaign.runs import run_ids

    def action() -> list[Outcome]:
        with tempfile.TemporaryDirectory(prefix="fuzz-") as folder:
            path = Path(folder) / "spec.toml"
            path.write_bytes(data)
            spec = load_campaign_spec(path)
        ids = run_ids(spec)
        if not 0 < len(ids) <= MAX_RUNS:
            return [Outcome(TRACEBACK, f"{len(ids)} runs")]
        return [Outcome(OK)]

    return guarded(action)


# --------------------------------------------------------------------------------------------
# Area 7: the command line on small files


@dataclass(frozen=True)
class CliFiles:
    """Files the command-line inputs name, in one directory."""

    folder: Path
    paths: Mapping[str, str]


def make_cli_files(bases: Bases, folder: Path) -> CliFiles:
    """A contact recording, a free motion, a short and a garbage recording, antenna files good
    and bad, a points table, and places to write."""
    folder.mkdir(parents=True, exist_ok=True)
    paths: dict[str, str] = {}

    def put(name: str, data: bytes | str) -> None:
        path = folder / name
        if isinstance(data, str):
            data = data.encode("utf-8")
        path.write_bytes(data)
        paths[name] = str(path)

    write_recording(bases.contacts[0], folder / "contact.csv")
    paths["contact.csv"] = str(folder / "contact.csv")
    write_recording(bases.free, folder / "free.csv")
    paths["free.csv"] = str(folder / "free.csv")
    mn = Perturbation(force_scale=1e3, torque_scale=1e3).apply(bases.contacts[0])
    write_recording(mn, folder / "milli.csv")
    paths["milli.csv"] = str(folder / "milli.csv")
    short = Perturbation(keep_to=0.1).apply(bases.contacts[1])
    write_recording(short, folder / "short.csv")
    paths["short.csv"] = str(folder / "short.csv")
    put("garbage.csv", b"t,theta1\n1,2\n\xff\n")
    put("antenna.toml", toml_document(_ANTENNA_TABLES, _ANTENNA_TOP))
    put("bad-antenna.toml", 'base = "paper-2021"\n[link]\nlength = 1e300\n')
    put("points.csv", f"file,x_c\ncontact.csv,{bases.contact_points[0]}\nshort.csv,0.8\n")
    put("bad-points.csv", b"file,x_c\n\xff,1\n")
    paths["missing.csv"] = str(folder / "missing.csv")
    paths["out.toml"] = str(folder / "new.toml")
    paths["sim.csv"] = str(folder / "sim.csv")
    paths["out-dir"] = str(folder / "figures")
    paths["no-dir/out.toml"] = str(folder / "no" / "such" / "dir" / "x.toml")
    paths["folder"] = str(folder)
    return CliFiles(folder=folder, paths=paths)


_ARG_WORDS = ("0", "-1", "0.5", "1e300", "nan", "inf", "-0.3", "abc", "", "2", "1.5", "1e-300")
_RECORDINGS = ("contact.csv", "free.csv", "milli.csv", "short.csv", "garbage.csv", "missing.csv")
_ANTENNAS = ("paper-2021", "paper-2021-calibrated", "antenna.toml", "bad-antenna.toml", "out.toml")


@st.composite
def cli_arguments(draw: st.DrawFn, files: Mapping[str, str]) -> list[str]:
    """``antenna`` arguments: a valid command line on the files of :func:`make_cli_files`
    (recordings good and bad, antennae good and bad), then none to three changes: a flag left
    out, a value replaced by a word or another file, an unknown flag, the order shuffled."""
    recording = st.sampled_from(_RECORDINGS).map(lambda name: files.get(name, name))
    antenna = st.sampled_from(_ANTENNAS).map(lambda name: files.get(name, name))
    word = st.one_of(st.sampled_from(_ARG_WORDS), moderate_float.map(number_text))
    number = st.one_of(st.floats(0.01, 1.2).map(number_text), word)
    command = draw(
        st.sampled_from(
            ["estimate"] * 4
            + ["identify"] * 2
            + ["calibrate"] * 2
            + ["beam"] * 2
            + ["plot estimate", "simulate", "campaign report"]
        )
    )
    options: list[list[str]] = []
    if command == "estimate":
        argv = ["estimate", draw(recording)]
        method = ["paper", "ratio", "two-frequency", "fast"]
        options = [
            ["--method", draw(st.sampled_from(method))],
            ["--json"],
            ["--antenna", draw(antenna)],
            ["--tolerance", draw(number)],
            ["--t1", draw(st.sampled_from(["rest", "push"]))],
        ]
    elif command == "identify":
        argv = ["identify", draw(recording), "--out", files["out.toml"]]
        options = [["--antenna", draw(antenna)], ["--margin", draw(number)], ["--name", "n"]]
    elif command == "calibrate":
        n = draw(st.integers(1, 3))
        argv = ["calibrate", *(draw(recording) for _ in range(n)), "--out", files["out.toml"]]
        points = st.sampled_from(["points.csv", "bad-points.csv"]).map(lambda k: files[k])
        loss = st.sampled_from(["linear", "soft_l1", "huber"])
        options = [["--points", draw(points)], ["--loss", draw(loss)], ["--antenna", draw(antenna)]]
    elif command == "beam":
        argv = ["beam", *draw(st.sampled_from([["--xc", draw(number)], ["--omega1", draw(word)]]))]
        options = [["--modes", draw(st.sampled_from(["1", "3", "0", "-2", "x"]))], ["--json"]]
        options.append(["--antenna", draw(antenna)])
    elif command == "plot estimate":
        argv = ["plot", "estimate", draw(recording), "--out", files["out-dir"]]
    elif command == "simulate":
        argv = ["simulate", "--case", draw(st.sampled_from(["azimuthal", "vertical", "free"]))]
        argv += ["--out", files["sim.csv"]]
        options = [
            ["--xc", draw(number)],
            ["--duration", draw(st.sampled_from(["0.3", "0.5", "-1", "1e9", "nan", "0"]))],
            ["--noise", draw(number)],
            ["--seed", draw(st.sampled_from(["0", "-1", "1e3", "x", "99999999999999999999"]))],
            ["--antenna", draw(antenna)],
        ]
    else:
        argv = [
            "campaign",
            "report",
            draw(st.sampled_from([files["folder"], files["missing.csv"]])),
        ]
    for option in options:
        if draw(st.booleans()):
            argv.extend(option)
    pool = st.one_of(word, recording, antenna, st.sampled_from(list(files.values())))
    for _ in range(draw(st.integers(0, 3))):
        change = draw(st.integers(0, 3))
        if change == 0 and len(argv) > 1:
            del argv[draw(st.integers(1, len(argv) - 1))]
        elif change == 1 and len(argv) > 1:
            argv[draw(st.integers(1, len(argv) - 1))] = draw(pool)
        elif change == 2:
            argv.insert(draw(st.integers(0, len(argv))), draw(st.sampled_from(["--bogus", "-x"])))
        else:
            argv = draw(st.permutations(argv))
    return argv


@contextlib.contextmanager
def _working_directory(folder: Path) -> Iterator[None]:
    """Within: ``folder`` is the working directory (an output named by a word lands there)."""
    previous = Path.cwd()
    os.chdir(folder)
    try:
        yield
    finally:
        os.chdir(previous)


def run_cli(argv: Sequence[str], folder: Path) -> list[Outcome]:
    """``antenna *argv`` in this process, in ``folder``: exit code 0 or 2 (``beam``: 1 for a
    frequency out of range), and after 2 one line on stderr; no traceback."""
    from sensing_antenna.cli import main

    out, err = io.StringIO(), io.StringIO()
    with (
        _working_directory(folder),
        contextlib.redirect_stdout(out),
        contextlib.redirect_stderr(err),
        warnings.catch_warnings(record=True) as caught,
    ):
        warnings.simplefilter("always")
        try:
            code = main(list(argv))
        except SystemExit as exc:  # argparse's errors and --help end here
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
        except Exception as exc:  # what the suite hunts
            return [Outcome(TRACEBACK, _exception_text(exc))]
    if caught:
        first = caught[0]
        where = f"{Path(first.filename).name}:{first.lineno}"
        return [Outcome(WARNING, f"{first.category.__name__}: {first.message} ({where})")]
    text = err.getvalue()
    lines = [line for line in text.splitlines() if line.strip()]
    allowed = (0, 2, 1) if argv[:1] == ["beam"] else (0, 2)
    if code not in allowed or "Traceback" in text:
        return [Outcome(BAD_ENDING, f"exit {code}: {text[-300:]}")]
    if code == 2:
        if len(lines) != 1:
            return [Outcome(BAD_ENDING, f"exit 2 with {len(lines)} lines: {text[-300:]}")]
        return [Outcome(ERROR, lines[0])]
    return [Outcome(OK, f"exit {code}")]


# --------------------------------------------------------------------------------------------
# Area 8: scene files

#: One object of each kind as a scene file writes it: the sizes a primitive needs, a mesh file.
_SCENE_OBJECTS = (
    {"shape": "sphere", "radius": 0.06, "position": [0.6, 0.1, 0.0]},
    {"shape": "cylinder", "radius": 0.04, "height": 0.15, "position": [0.5, 0.0, 0.0]},
    {"shape": "capsule", "radius": 0.03, "length": 0.1, "position": [0.5, 0.0, 0.0]},
    {"shape": "cone", "radius": 0.05, "height": 0.12, "position": [0.6, 0.0, -0.05]},
    {"shape": "torus", "major_radius": 0.07, "minor_radius": 0.02, "position": [0.6, 0.0, 0.0]},
    {"shape": "box", "extents": [0.12, 0.08, 0.16], "position": [0.55, 0.05, 0.0]},
    {"shape": "mesh", "file": "part.stl", "scale": 0.001, "position": [0.5, -0.2, 0.0]},
)
_SCENE_BASES = (
    {"position": [0.0, 0.0, 0.0]},
    {"position": [0.87, -0.4, 0.0], "yaw": 2.09},
    {"position": [0.8, 0.5, 0.1], "quaternion": [0.9, 0.0, 0.0, 0.43]},
    {"position": [0.0, 0.0, 0.0], "azimuth": [-0.3, 0.3], "elevation": [-0.8, -0.4]},
)
_SCENE_EXPLORE = {
    "azimuth": [-0.6, 0.6],
    "elevation": [-0.35, 0.35],
    "azimuthal_sweeps": 3,
    "vertical_sweeps": 4,
}
#: Mesh files beside a scene, by name: a closed box in millimetres, an open surface (one
#: triangle), text that is no mesh, and an empty file.
_SCENE_MESH_FILES = ("part.stl", "sheet.obj", "junk.ply", "empty.stl")


@functools.cache
def _scene_mesh_bytes() -> dict[str, bytes]:
    """The contents of :data:`_SCENE_MESH_FILES`, by name (made once)."""
    import trimesh

    box = trimesh.creation.box(extents=(80.0, 60.0, 40.0)).export(file_type="stl")
    return {
        "part.stl": bytes(box),
        "sheet.obj": b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        "junk.ply": b"ply\nformat ascii 1.0\nnonsense\n",
        "empty.stl": b"",
    }


def write_scene_meshes(folder: Path) -> None:
    """The files of :data:`_SCENE_MESH_FILES` in ``folder``."""
    for name in _SCENE_MESH_FILES:
        (folder / name).write_bytes(_scene_mesh_bytes()[name])


#: Values a scene's fields get wrong or put at their limits, by the kind of field: sizes zero,
#: tiny or huge; positions far or not finite; angles at and past one turn; quaternions off unit
#: length; ranges reversed, empty or past their limits (a half-turn, 1.2 rad); sweep counts at
#: and past their bounds.
_SIZE_EDGES = (0, -0.0, 5e-324, 1e-30, 1e-6, 9.99e-4, 1e-3, 10.0, 10.000001, 1e300, math.nan, -1)
_SCENE_EDGES: dict[str, tuple[Any, ...]] = {
    "size": _SIZE_EDGES,
    # a mesh's scale is within (0, 1]; part.stl's 80 mm read at 0.125 is 10 m, the limit
    "scale": (0, 1e-300, 1e-6, 0.0125, 0.125, 0.1250001, 1.0, 1.0000001, math.nan),
    "extents": (*([0.1, 0.1, v] for v in _SIZE_EDGES), [0.1, 0.1], [0.1, 0.1, 0.1, 0.1]),
    "position": ([0.0, 0.0, 0.0], [99.0, 0.0, 0.0], [1e300, 0.0, 0.0], [math.nan, 0.0, 0.0]),
    "rotation": (
        [math.pi, 0.0, 0.0],
        [2.0 * math.pi, 0.0, 0.0],
        [2.0 * math.pi + 1e-9, 0.0, 0.0],
        [0.0, 0.0, -90.0],
        [1e300, 0.0, 0.0],
    ),
    "yaw": (math.pi, -2.0 * math.pi, 2.0 * math.pi + 1e-9, 90.0, math.inf),
    "quaternion": (
        [1.0, 0.0, 0.0, 0.0],
        [0.7071, 0.0, 0.0, 0.7071],
        [0.98, 0.0, 0.0, 0.0],
        [1.02, 0.0, 0.0, 0.1],
        [0.0, 0.0, 0.0, 0.0],
        [1e300, 0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
    ),
    "range": (
        [-math.pi, math.pi],
        [-1.2, 1.2],
        [-1.2000001, 0.0],
        [-3.2, 0.0],
        [0.5, 0.5],
        [1.0, 0.0],
        [0.0],
    ),
    "count": (0, 1, 100, 101, -1, True, 1.5),
    "name": ("", "a\nb", "x" * 200),
    "file": (*_SCENE_MESH_FILES, "missing.stl", ".", ""),
}
#: The kind of each field a scene's tables hold or may be given.
_SCENE_FIELDS = {
    "radius": "size",
    "height": "size",
    "length": "size",
    "major_radius": "size",
    "minor_radius": "size",
    "scale": "scale",
    "extents": "extents",
    "position": "position",
    "rotation": "rotation",
    "yaw": "yaw",
    "quaternion": "quaternion",
    "azimuth": "range",
    "elevation": "range",
    "azimuthal_sweeps": "count",
    "vertical_sweeps": "count",
    "name": "name",
    "file": "file",
}


@st.composite
def scene_files(draw: st.DrawFn) -> bytes:
    """A scene file: one to three objects of every kind, bases and the explored region, valid
    but for one field (now and then two) of a table (mostly one it holds) set to an edge value
    of its kind (:data:`_SCENE_EDGES`), a TOML value of any kind or dropped; the top level
    changed now and then; or junk."""
    choice = draw(st.integers(0, 9))
    if choice == 0:
        return draw(st.binary(max_size=100))
    if choice == 1:
        return draw(st.text(max_size=100)).encode("utf-8")
    objects = []
    for _ in range(draw(st.integers(1, 3))):
        template = dict(draw(st.sampled_from(_SCENE_OBJECTS)))
        if template["shape"] == "mesh" and draw(st.booleans()):
            template["file"] = draw(st.sampled_from([*_SCENE_MESH_FILES, "missing.stl", "."]))
        objects.append(template)
    bases = [dict(draw(st.sampled_from(_SCENE_BASES))) for _ in range(draw(st.integers(0, 3)))]
    explore = dict(_SCENE_EXPLORE) if draw(st.booleans()) else None
    editable = [*objects, *bases, *([explore] if explore is not None else [])]
    # one field edited, now and then a second (two sizes of one shape at their edges together)
    for _ in range(draw(st.sampled_from([0, 1, 1, 1, 1, 1, 1, 2, 2, 2])) if choice >= 3 else 0):
        table = draw(st.sampled_from(editable))
        # a first edit may have dropped the table's last field of its own
        own = sorted(k for k in table if k != "shape") or sorted(_SCENE_FIELDS)
        key = draw(st.sampled_from(own if draw(st.integers(0, 3)) else sorted(_SCENE_FIELDS)))
        how = draw(st.integers(0, 9))
        if how == 0:
            table.pop(key, None)
        elif how == 1:
            table[key] = draw(toml_values)
        else:
            table[key] = draw(st.sampled_from(_SCENE_EDGES[_SCENE_FIELDS[key]]))
    top: dict[str, Any] = {"name": "fuzzed", "objects": objects}
    if bases:
        top["bases"] = bases
    tables = {"explore": explore} if explore is not None else {}
    if choice == 2:
        tables, top = draw(edited_tables(tables, top))
    return toml_document(tables, top).encode("utf-8")


def run_scene_file(data: bytes) -> list[Outcome]:
    """Load a scene file beside the mesh files of :func:`write_scene_meshes`; a scene loaded
    must have finite, non-empty meshes whose signed distance is finite, finite base poses and,
    for every base, explored angles in order within their limits (``scene.sweep.MAX_AZIMUTH``
    and ``MAX_ELEVATION``) and at least one sweep."""

    def action() -> list[Outcome]:
        from sensing_antenna.scene import load_scene
        from sensing_antenna.scene.sweep import MAX_AZIMUTH, MAX_ELEVATION

        with tempfile.TemporaryDirectory(prefix="fuzz-") as folder:
            write_scene_meshes(Path(folder))
            path = Path(folder) / "scene.toml"
            path.write_bytes(data)
            scene = load_scene(path)
        for obj in scene.objects:
            vertices = np.asarray(obj.mesh.vertices)
            if len(obj.mesh.faces) == 0 or not np.all(np.isfinite(vertices)):
                return [Outcome(TRACEBACK, f"object {obj.name}: an empty or non-finite mesh")]
        probe = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]])
        if not np.all(np.isfinite(scene.signed_distance(probe))):
            return [Outcome(TRACEBACK, "the scene's signed distance is not finite")]
        for pose in scene.bases:
            if not (np.all(np.isfinite(pose.rotation)) and np.all(np.isfinite(pose.position))):
                return [Outcome(TRACEBACK, "a base pose is not finite")]
        for index in range(len(scene.bases)):
            region = scene.region_of(index)
            for name, (low, high), limit in (
                ("azimuth", region.azimuth, MAX_AZIMUTH),
                ("elevation", region.elevation, MAX_ELEVATION),
            ):
                if not -limit <= low < high <= limit:
                    return [Outcome(TRACEBACK, f"base {index}: {name} {(low, high)}")]
            counts = (region.azimuthal_sweeps, region.vertical_sweeps)
            if min(counts) < 0 or max(counts) == 0:
                return [Outcome(TRACEBACK, f"base {index}: sweep counts {counts}")]
        return [Outcome(OK)]

    return guarded(action)
