"""``explore``: sweeps of the simulated device in a scene, each contact estimated and mapped.

The device's job as the paper's algorithm states it (Section 4: sweep, contact, push, estimate,
retract, re-plan), on the simulator:

1. **Prepare** (once per output directory), as a lab prepares its device before it measures
   (docs/real-antenna.md): the free-motion observer (Eq. 15) and contact threshold identified
   on a free sweep of each joint (``identify_free_motion``), then five sweeps into smooth posts
   at known x_c (0.3 to 0.9 m) and ``calibrate_from_recordings`` (a realistic device: 15 posts
   swept both ways, T_e with the tip mass and the sensor's cross-talk, :func:`prepare_device`);
   the identified and calibrated antenna is written to ``calibrated.toml``. The estimators use
   it; the simulated device keeps its own link and takes the identified observer and threshold
   for its controller, as a lab's head does (``campaign.simulated.knowing_weight``). The simulated
   link is the settings' ``link``, the geometrically exact one by default, for the
   preparation and every sweep alike.
2. **Each manoeuvre**: the planner (``exploration.plan``: ``grid`` or ``next-best``) picks a
   sweep; ``scene.simulate_sweep`` finds its first touch and simulates it; the recording is
   written (its ``base_pose`` says where it was taken) and estimated by the map's own code path
   (``mapping.points_from_recordings``), giving a :class:`~sensing_antenna.mapping.ContactPoint`
   with its covariance and status; a sweep that touches nothing is stored as free space.
3. **The map**: ``mapping.build_map`` on every point, as ``antenna map`` builds it, with the
   free space every sweep's link passed through before its touch and the links that touched
   where no ``ok`` point says so (:func:`swept_links`).

The next-best strategy refits the surface before each manoeuvre and recognises the points before
every :data:`RECOGNITION_EVERY`-th, aiming where the named object's fit is least sure of its
surface, and at the two leading classes while recognition abstains (``exploration.plan``). After the
budget, either strategy may go on while recognition abstains (``ExploreSettings.until_recognised``):
it recognises the points before each further manoeuvre, stops once a class is named, and otherwise
takes next-best's choice with the two leading fits, which aims at telling them apart. With
``ExploreSettings.sizes_within`` it also goes on while the named class's sizes are not known that
well, aiming where that fit is least sure of its surface.

Manoeuvre i is simulated with the seed ``seed + i``. Everything is stored as it is made
(``exploration.store``); a second start with the same settings resumes after the last stored
manoeuvre (with a larger budget it goes on), and the next-best planner, fed the same stored
points, makes the same choices.
"""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import signal
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Literal

import numpy as np
import trimesh
from numpy.typing import NDArray

from sensing_antenna.antenna import Antenna, AntennaConfigError, antenna_to_toml, load_antenna
from sensing_antenna.campaign.runs import CALIBRATION_STREAM, FREE_MOTION_STREAM, derive_seed
from sensing_antenna.campaign.schema import DEFAULT_CALIBRATION_POINTS
from sensing_antenna.campaign.simulated import knowing_weight
from sensing_antenna.campaign.store import atomic_write_text
from sensing_antenna.errors import interruption_of, raise_if_signalled
from sensing_antenna.exploration.plan import (
    PREDICTION_STEP,
    STRATEGIES,
    Choice,
    NextBestPlanner,
    candidate_sweeps,
    grid_sweeps,
)
from sensing_antenna.exploration.store import (
    CALIBRATED_FILE,
    MANOEUVRES_DIR,
    RECORDINGS_DIR,
    ExplorationStoreError,
    Manoeuvre,
    exploration_lock,
    load_manoeuvres,
    write_manoeuvre,
    write_manoeuvre_table,
    write_settings,
)
from sensing_antenna.mapping.contact_map import (
    ContactMap,
    build_map,
    fit_surface,
    recognise_points,
)
from sensing_antenna.mapping.free_space import (
    FreeSpace,
    Piece,
    Touches,
    free_space,
    onset_turn,
    recording_links,
    touches,
)
from sensing_antenna.mapping.points import ContactPoint
from sensing_antenna.mapping.primitives import PRIMITIVES
from sensing_antenna.mapping.recognition import ClassFit, Recognition
from sensing_antenna.recording import write_recording
from sensing_antenna.scene.file import Scene
from sensing_antenna.scene.simulate import simulate_sweep
from sensing_antenna.scene.sweep import LinkShape, Sweep
from sensing_antenna.simulator.device import DEVICE_PROFILES, DeviceImperfections, device_profile
from sensing_antenna.simulator.scenario import LINK_MODELS

FloatArray = NDArray[np.float64]

#: A recognition that names an object (else None), and the fits the planner aims with: the
#: named object's, or the two it abstains between.
RecognitionState = tuple[Recognition | None, tuple[ClassFit, ...]]

#: A stored recording's links (``mapping.free_space.recording_links``) and its first motor
#: angles (rad, shape (2,)).
RecordedLinks = tuple[tuple[Piece, Piece | None], FloatArray]

__all__ = [
    "CALIBRATION_FRICTION",
    "CALIBRATION_POINTS",
    "DEFAULT_BUILD",
    "Exploration",
    "ExplorationInterrupted",
    "ExploreSettings",
    "calibration_points",
    "explore",
    "prepare_device",
    "realistic_calibration_points",
    "swept_links",
]

#: The name of the antenna the estimators use (``calibrated.toml``), which the recordings
#: name as theirs, followed by ``-`` and the simulated device's name (so that ``antenna map``
#: tells one antenna's recordings from another's); alone in a directory prepared before.
CALIBRATED_NAME = "explore-calibrated"

#: Where the calibration's posts are touched on the paper's 0.98 m link (m): the README's five
#: points; a shorter link's are these scaled to its length (:func:`calibration_points`).
CALIBRATION_POINTS = (0.3, 0.45, 0.6, 0.75, 0.9)

#: The link length the calibration's points are stated for (m): the paper's.
POINTS_LENGTH = 0.98

#: The calibration manoeuvres' seeds start here (the README's).
CALIBRATION_SEED = 10

#: Coulomb coefficient between the link and the calibration's posts: smooth posts, so that T_e
#: is the link's own stiffness and not a contact's (docs/real-antenna.md, step 4).
CALIBRATION_FRICTION = 0.0

#: What the preparation does (stored with the settings: a directory prepared otherwise is not
#: resumed).
PREPARATION = "observer identified on free sweeps, then T_e calibrated on smooth posts"

#: The free sweeps the observer is identified on (one of each joint), their length (s) and
#: their first seed.
FREE_MOTION_CASES = ("free", "free-vertical")
FREE_MOTION_DURATION = 4.0
FREE_MOTION_SEED = 20

#: The next-best strategy recognises the points so far before every this many manoeuvres, to
#: aim at the two leading classes when recognition abstains (a recognition takes seconds).
RECOGNITION_EVERY = 4

#: Methods the exploration offers (those that give an interval or a default sigma_x).
EXPLORE_METHODS = ("paper", "fast")

#: The sweeps of the calibration's posts.
AZIMUTHAL: Literal["azimuthal"] = "azimuthal"
VERTICAL: Literal["vertical"] = "vertical"

#: The realistic device explored by default: the default campaign's build (its base seed: the
#: same draw of imperfections, on the device file's link).
DEFAULT_BUILD = 2021


#: What the preparation of a realistic device does (stored with the settings).
REALISTIC_PREPARATION = (
    "observer identified on free sweeps, then T_e with the tip mass and the sensor's cross-talk"
    " calibrated on smooth posts swept both ways"
)


@dataclass(frozen=True)
class ExploreSettings:
    """What an exploration does; a resume must have the same.

    Attributes
    ----------
    method : {"paper", "fast"}
    strategy : {"grid", "next-best"}
    budget : int or None
        Most manoeuvres (None: the scene's grid size).
    seed : int
        Seed of the first manoeuvre.
    include_uncertain : bool
        Let ``uncertain`` points into the map and the planner's surface.
    link : {"nonlinear", "linear"}
        The simulated link (``Scenario.link_model``), of the calibration and of every sweep:
        the geometrically exact link (the default: a physical link shortens as it bends), or
        the small-deflection one.
    device_profile : {"nominal", "realistic"}
        The simulated device's imperfections, which the estimators are not told of: none (the
        device file's own antenna), or one device of the realistic profile
        (``simulator.realistic_device``: its build, tip mass, clamp, taper, joint, sensor gains
        and coupling, drawn from ``device_build``; its set-up, the sensor's drift and the
        encoders' zero, drawn anew for every simulated manoeuvre, the preparation's included).
        A realistic device is prepared as the campaigns prepare theirs (:func:`prepare_device`).
    device_build : int or None
        The realistic device's build seed (which device of the profile); None:
        :data:`DEFAULT_BUILD`. Only with the realistic profile.
    until_recognised : int
        After the budget (or the grid's last sweep, if sooner), while recognition abstains (or
        has too few points to answer), up to this many more manoeuvres, recognising before
        each: next-best's choice with the two leading classes (``NextBestPlanner.choose``,
        which aims at telling them apart; its usual choice when there are no two leading
        primitives); 0 stops at the budget.
    sizes_within : float or None
        With ``until_recognised`` (and within its count): the manoeuvres after the budget go on
        also while the named class's sizes are not each known to within this share of
        themselves (``ClassFit.sizes_known``: twice the standard deviation, widened by the
        overdispersion, at most this share; 0.05: 5 %), aimed where the named fit is least sure
        of its surface (``NextBestPlanner.choose`` with that fit; a named user mesh ends them);
        None: naming the object ends them.
    """

    method: str = "paper"
    strategy: str = "grid"
    budget: int | None = None
    seed: int = 0
    include_uncertain: bool = False
    link: str = "nonlinear"
    until_recognised: int = 0
    device_profile: str = "nominal"
    device_build: int | None = None
    sizes_within: float | None = None

    def __post_init__(self) -> None:
        if self.method not in EXPLORE_METHODS:
            raise ValueError(f"method must be one of {', '.join(EXPLORE_METHODS)}")
        if self.strategy not in STRATEGIES:
            raise ValueError(f"strategy must be one of {', '.join(STRATEGIES)}")
        if self.budget is not None and self.budget < 1:
            raise ValueError("budget must be at least 1")
        if self.until_recognised < 0:
            raise ValueError("until_recognised must be at least 0")
        within = self.sizes_within
        if within is not None:
            number = isinstance(within, float | int) and not isinstance(within, bool)
            if not number or not 0.0 < within <= 1.0:
                raise ValueError(f"sizes_within must be a share in (0, 1], got {within!r}")
            if self.until_recognised == 0:
                raise ValueError(
                    "sizes_within is for the sweeps after the budget: give until_recognised too"
                )
        if self.link not in LINK_MODELS:
            raise ValueError(f"link must be one of {', '.join(LINK_MODELS)}")
        if self.device_profile not in DEVICE_PROFILES:
            raise ValueError(f"device_profile must be one of {', '.join(DEVICE_PROFILES)}")
        build = self.device_build
        if build is None:
            return
        if isinstance(build, bool) or not isinstance(build, int) or build < 0:
            raise ValueError(f"device_build must be an integer >= 0 (a seed), got {build!r}")
        if self.device_profile == "nominal":
            raise ValueError("device_build is a realistic device's: not used with the nominal one")

    @property
    def build(self) -> int:
        """The realistic device's build seed (``device_build``, or :data:`DEFAULT_BUILD`)."""
        return DEFAULT_BUILD if self.device_build is None else self.device_build

    def imperfections(self, seed: int, length: float) -> DeviceImperfections:
        """The simulated device's imperfections in the manoeuvre of seed ``seed`` (none on the
        nominal device); ``length`` (m) is the link's, to place its joint."""
        return device_profile(self.device_profile, seed, length, self.build)


def _scaled(points: tuple[float, ...], length: float) -> tuple[float, ...]:
    """``points`` (m, stated for the paper's link) on a link of ``length`` (m): the same share of
    a shorter link, the same points on a longer one."""
    scale = min(1.0, length / POINTS_LENGTH)
    return tuple(round(x * scale, 4) for x in points)


def calibration_points(length: float) -> tuple[float, ...]:
    """A nominal device's calibration posts (m) on a link of ``length`` (m):
    :data:`CALIBRATION_POINTS`, scaled to a link shorter than the paper's."""
    return _scaled(CALIBRATION_POINTS, length)


def realistic_calibration_points(length: float) -> tuple[float, ...]:
    """A realistic device's calibration posts (m) on a link of ``length`` (m), each swept both
    ways (azimuthal and vertical) for T_e with the tip mass and the sensor's cross-talk: the
    campaigns' points (``campaign.schema.DEFAULT_CALIBRATION_POINTS``, scaled to a link shorter
    than the paper's) short of the tip, then the tip."""
    points = _scaled(DEFAULT_CALIBRATION_POINTS, length)
    return (*(x for x in points if x < length - 1e-9), length)


class ExplorationInterrupted(KeyboardInterrupt):
    """Stopped by Ctrl-C or a stop signal; every finished manoeuvre is stored."""

    def __init__(self, signal_number: int, n_stored: int, out: Path) -> None:
        self.signal_number = signal_number
        self.n_stored = n_stored
        self.out = out
        super().__init__(self.message)

    @property
    def message(self) -> str:
        """One line for the command line."""
        if self.n_stored == 0:
            return f"interrupted before a manoeuvre was stored in {self.out}"
        return (
            f"interrupted: {self.n_stored} manoeuvres are stored in {self.out}; the same command"
            " resumes from them"
        )


@contextlib.contextmanager
def stopped_as_stored(out: Path, n_stored: Callable[[], int]) -> Iterator[None]:
    """Within: Ctrl-C or a stop signal (also as the ``SystemError`` a compiled function raises
    from one) ends as :class:`ExplorationInterrupted`, saying that ``n_stored()`` manoeuvres are
    stored in ``out``."""
    try:
        yield
    except (KeyboardInterrupt, SystemError) as exc:
        interrupt = interruption_of(exc)
        if interrupt is None or isinstance(exc, ExplorationInterrupted):
            raise
        number = int(getattr(interrupt, "signal_number", signal.SIGINT))
        raise ExplorationInterrupted(number, n_stored(), out) from None


@dataclass(frozen=True)
class Exploration:
    """An exploration's result.

    Attributes
    ----------
    scene : Scene
    settings : ExploreSettings
    manoeuvres : tuple of Manoeuvre
    contact_map : ContactMap
        The map of every estimated point.
    antenna : Antenna
        The calibrated antenna the estimators used.
    """

    scene: Scene
    settings: ExploreSettings
    manoeuvres: tuple[Manoeuvre, ...]
    contact_map: ContactMap
    antenna: Antenna

    @property
    def points(self) -> list[ContactPoint]:
        """Every estimated point (any status)."""
        return [m.point for m in self.manoeuvres if m.point is not None]

    def summary(self) -> dict[str, Any]:
        """Counts by outcome and by aim (``Manoeuvre.aim``), the contacts used, the simulated
        sweeping time (s), and the map's own summary."""
        outcomes: dict[str, int] = {}
        aims: dict[str, int] = {}
        for m in self.manoeuvres:
            outcomes[m.outcome] = outcomes.get(m.outcome, 0) + 1
            aims[m.aim] = aims.get(m.aim, 0) + 1
        return {
            "scene": self.scene.name,
            "method": self.settings.method,
            "strategy": self.settings.strategy,
            "manoeuvres": len(self.manoeuvres),
            "outcomes": outcomes,
            "aims": aims,
            "sweep_time_s": float(sum(m.sweep_time for m in self.manoeuvres)),
            "map": self.contact_map.summary(),
        }


def prepare_device(
    device: Antenna,
    folder: Path | None = None,
    link: str = "nonlinear",
    *,
    device_profile: str = "nominal",
    device_build: int | None = None,
) -> Antenna:
    """The preparation of the simulated ``device`` (module docstring), with the simulator's
    ``link`` model: the observer and contact threshold identified on :data:`FREE_MOTION_CASES`
    (seeds from :data:`FREE_MOTION_SEED`), then T_e calibrated on smooth posts
    (:data:`CALIBRATION_FRICTION`) at :func:`calibration_points` (seeds from
    :data:`CALIBRATION_SEED`) touched by the device with that observer; every recording is
    written into ``folder`` when given.

    A nominal device's sensor is its model's: the estimators fear no cross-talk beyond its
    correction (``sensor.nominal_coupling`` 0). A realistic device is prepared as a campaign
    prepares its own: each recording with a seed of
    its own (the campaigns' free-motion and calibration streams of the build, so that no sweep
    shares its set-up or noise), the posts at :func:`realistic_calibration_points` touched by an
    azimuthal and by a vertical sweep, their planned x_c the known points, T_e fitted with the
    tip mass on the azimuthal ones (``soft_l1`` loss) and the sensor's cross-talk on all
    (``calibration.sensor``; kept only when it predicts posts left out of its fit), what the
    sensor's fit found written to ``folder/sensor.txt``.

    Parameters
    ----------
    device : Antenna
        The simulated device (its link and motors; the estimators' starting model).
    folder : Path, optional
        Where the preparation's recordings (and a realistic device's ``sensor.txt``) go.
    link : {"nonlinear", "linear"}
        The simulated link, as :attr:`ExploreSettings.link`.
    device_profile : {"nominal", "realistic"}
    device_build : int or None
        As in :class:`ExploreSettings`.

    Returns
    -------
    Antenna
        ``device`` as the estimators know it: identified observer and payload, calibrated T_e
        (and tip mass and sensor correction, for a realistic device).
    """
    from sensing_antenna.calibration.frequency import calibrate_from_recordings
    from sensing_antenna.calibration.observer import identify_free_motion
    from sensing_antenna.calibration.sensor import SensorCalibrationError, calibrate_sensor
    from sensing_antenna.simulator import Scenario, simulate

    profile = ExploreSettings(link=link, device_profile=device_profile, device_build=device_build)
    realistic = device_profile != "nominal"
    length = device.link.length

    def seed_of(index: int, stream: int, first: int) -> int:
        return derive_seed(profile.build, index, stream) if realistic else first + index

    free = []
    for k, case in enumerate(FREE_MOTION_CASES):
        seed = seed_of(k, FREE_MOTION_STREAM, FREE_MOTION_SEED)
        scenario = Scenario(
            case=case,  # type: ignore[arg-type]
            seed=seed,
            duration=FREE_MOTION_DURATION,
            link_model=link,  # type: ignore[arg-type]
            device=profile.imperfections(seed, length),
        )
        free.append(simulate(device, scenario))
    free_runs = [run.without_ground_truth() for run in free]
    model = identify_free_motion(free_runs, device, find_lag=False).apply(device)
    controlled = knowing_weight(device, model)
    at = realistic_calibration_points(length) if realistic else calibration_points(length)
    posts: list[tuple[Literal["azimuthal", "vertical"], float]] = [(AZIMUTHAL, x) for x in at]
    if realistic:
        posts += [(VERTICAL, x) for x in at]
    runs = []
    for k, (case, x) in enumerate(posts):
        seed = seed_of(k, CALIBRATION_STREAM, CALIBRATION_SEED)
        scenario = Scenario(
            case=case,
            contact_point=x,
            seed=seed,
            link_model=link,  # type: ignore[arg-type]
            friction_coefficient=CALIBRATION_FRICTION,
            device=profile.imperfections(seed, length),
        )
        runs.append(simulate(controlled, scenario))
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
        for case, run in zip(FREE_MOTION_CASES, free, strict=True):
            write_recording(run, folder / f"{case}.csv")
        for (case, x), run in zip(posts, runs, strict=True):
            name = f"post-{x:.2f}.csv" if case == AZIMUTHAL else f"post-{x:.2f}-{case}.csv"
            write_recording(run, folder / name)
    if not realistic:
        points = [float(run.metadata["true_xc"]) for run in runs]
        calibrated = calibrate_from_recordings(runs, model, points).apply(model)
        return calibrated.with_sensor_known()  # the nominal device's sensor is its model's
    blind = [run.without_ground_truth() for run in runs]
    planned = [x for _, x in posts]
    own = [i for i, (case, _) in enumerate(posts) if case == AZIMUTHAL]
    calibrated = calibrate_from_recordings(
        [blind[i] for i in own], model, [planned[i] for i in own], loss="soft_l1", fit_tip_mass=True
    ).apply(model)
    try:
        sensor = calibrate_sensor(blind, calibrated, planned)
    except SensorCalibrationError as exc:
        summary, prepared = f"the sensor is not calibrated: {exc}", calibrated
    else:
        summary, prepared = sensor.ratio_summary, sensor.apply(calibrated)
    if folder is not None:
        atomic_write_text(folder / "sensor.txt", summary + "\n")
    return prepared


def _device_settings(settings: ExploreSettings) -> dict[str, Any]:
    """The stored settings of the device and what step 1 makes of it (the profile and build
    for a realistic device only, so that a directory without them resumes as nominal)."""
    if settings.device_profile == "nominal":
        # an older directory's antenna was calibrated only, its sweeps detected with the
        # nominal observer: another preparation, not resumed
        return {"preparation": PREPARATION}
    return {
        "device_profile": settings.device_profile,
        "device_build": settings.build,
        "preparation": REALISTIC_PREPARATION,
    }


def _prepared(device: Antenna, out: Path, settings: ExploreSettings) -> Antenna:
    path = out / CALIBRATED_FILE
    if path.is_file():
        stored = load_antenna(path)
        if stored.name.startswith(f"{CALIBRATED_NAME}-"):
            return stored
        # a directory prepared before the model had its device's name in its own, or any name
        # of its own: its recordings name it so
        return replace(stored, name=CALIBRATED_NAME)
    prepared = prepare_device(
        device,
        out / "calibration",
        settings.link,
        device_profile=settings.device_profile,
        device_build=settings.device_build,
    )
    prepared = replace(
        prepared,
        name=f"{CALIBRATED_NAME}-{device.name}",
        description=(
            f"{device.name} as the exploration's preparation identified and calibrated it on"
            " the simulated device (its recordings in calibration/ beside this file)"
        ),
    )
    atomic_write_text(path, antenna_to_toml(prepared))
    return load_antenna(path)


def _check_stored_sweeps(
    out: Path, manoeuvres: list[Manoeuvre], scene: Scene, grid: list[Sweep], strategy: str
) -> None:
    """Refuse stored manoeuvres that this strategy would not have swept: an exploration made
    by another version of the planner (a grid that swept one way only, say) would go on with
    sweeps that repeat or skip its own. The grid's planned sweeps must come in its order;
    next-best's, and any sweep aimed at recognition, must be sweeps of the grid or of the
    next-best candidates (where the budget ended is not stored: an aimed sweep may stand
    anywhere)."""
    allowed = {*grid, *candidate_sweeps(scene)}
    for index, manoeuvre in enumerate(manoeuvres):
        sweep = manoeuvre.sweep
        if strategy == "grid" and manoeuvre.aim == "plan":
            fits = sweep == _next_grid_sweep(grid, [m.sweep for m in manoeuvres[:index]])
        else:
            fits = sweep in allowed
        if not fits:
            path = out / MANOEUVRES_DIR / f"{index:03d}.json"
            raise ExplorationStoreError(
                f"{path}: sweep: base {sweep.base}, {sweep.case} at {sweep.fixed:+.4f} rad, "
                f"direction {sweep.direction:+d} is not one this version's {strategy} strategy "
                "sweeps there (an exploration made by another version); explore into another "
                "output directory"
            )


def _next_grid_sweep(grid: Sequence[Sweep], done: Sequence[Sweep]) -> Sweep | None:
    """The grid's first sweep not among ``done`` (None once every one is)."""
    swept = set(done)
    return next((sweep for sweep in grid if sweep not in swept), None)


def _grid_end(done: Sequence[Sweep], grid: Sequence[Sweep], budget: int) -> int:
    """How many manoeuvres the grid's own plan takes: the budget, or, once every grid sweep
    is among ``done``, the manoeuvres up to the one that completed it, if fewer."""
    left = set(grid)
    for index, sweep in enumerate(done):
        left.discard(sweep)
        if not left:
            return min(budget, index + 1)
    return budget


def _scene_fingerprint(scene: Scene) -> str:
    digest = hashlib.sha256()
    for obj in scene.objects:
        digest.update(obj.name.encode())
        digest.update(obj.shape.encode())
        digest.update(np.round(np.asarray(obj.mesh.vertices), 9).tobytes())
    for base in scene.bases:
        digest.update(np.round(base.matrix, 12).tobytes())
    digest.update(repr(scene.region).encode())
    digest.update(repr(scene.base_regions).encode())
    return digest.hexdigest()[:16]


def explore(
    scene: Scene,
    device: Antenna,
    out: Path,
    settings: ExploreSettings | None = None,
    progress: Callable[[Manoeuvre, int], None] | None = None,
    meshes: Mapping[str, trimesh.Trimesh] | None = None,
    mapping: Callable[[int], None] | None = None,
    resuming: Callable[[int], None] | None = None,
    class_fitted: Callable[[str], None] | None = None,
) -> Exploration:
    """Explore ``scene`` with the simulated ``device``, storing everything in ``out``.

    Parameters
    ----------
    scene : Scene
    device : Antenna
        The simulated device (the estimators use its calibration, step 1).
    out : Path
        Output directory (created; resumed when it holds the same exploration).
    settings : ExploreSettings, optional
    progress : callable, optional
        Called with each new manoeuvre and the most manoeuvres the exploration may make (the
        budget and ``until_recognised``).
    meshes : mapping of str to trimesh.Trimesh, optional
        User meshes recognition registers beside the shape classes (``antenna map --objects``).
    mapping : callable, optional
        Called with the number of points once the sweeps are done and their map is being made
        (the surface and recognition, which can take a minute).
    resuming : callable, optional
        Called with the number of manoeuvres ``out`` holds, when it holds some and its settings
        are these (the exploration goes on after them).
    class_fitted : callable, optional
        Called with each shape class's name as the map's recognition fits it (none when the
        recognition that ended the sweeps is kept).

    Raises
    ------
    ExplorationInterrupted
        On Ctrl-C or a stop signal, with every finished manoeuvre stored.
    ExplorationStoreError
        ``out`` holds another exploration or is in use.
    AntennaConfigError
        ``device``'s link rings faster than the simulator's samples resolve.
    """
    from sensing_antenna.simulator.run import sampling_warning

    coarse = sampling_warning(device)
    if coarse is not None:
        raise AntennaConfigError("link", coarse, device.name)
    settings = settings if settings is not None else ExploreSettings()
    recorded: dict[int, RecordedLinks] = {}  # each stored recording's links, read once
    grid = grid_sweeps(scene)
    budget = settings.budget if settings.budget is not None else len(grid)
    with exploration_lock(out):
        write_settings(
            out,
            {
                "scene": scene.name,
                "scene_fingerprint": _scene_fingerprint(scene),
                "device": antenna_to_toml(device),
                "method": settings.method,
                "strategy": settings.strategy,
                "seed": settings.seed,
                "include_uncertain": settings.include_uncertain,
                "link": settings.link,
                **_device_settings(settings),
            },
        )
        scene.mesh.export(out / "scene.ply")
        manoeuvres = load_manoeuvres(out)
        _check_stored_sweeps(out, manoeuvres, scene, grid, settings.strategy)
        if manoeuvres and resuming is not None:
            resuming(len(manoeuvres))
        with stopped_as_stored(out, lambda: len(manoeuvres)):
            try:
                antenna = _prepared(device, out, settings)
                # the planner knows the device file's link; the simulated link sags as built
                shape = LinkShape(device.link)
                build = settings.imperfections(settings.seed, device.link.length)
                built = LinkShape(device.link, device=build)
                controlled = knowing_weight(device, antenna)
                planner = (
                    NextBestPlanner(scene, shape) if settings.strategy == "next-best" else None
                )
                # the planner of the sweeps after the budget (next-best's own, or one made then)
                chooser = planner
                leaders: tuple[ClassFit, ...] = ()
                final: Recognition | None = None  # the last recognition, when it ended the sweeps

                def recognised(upto: list[Manoeuvre]) -> RecognitionState:
                    return _recognition_state(
                        [m.point for m in upto if m.point is not None],
                        settings.include_uncertain,
                        swept_links(upto, scene, antenna, out, recorded),
                        meshes,
                    )

                last = len(manoeuvres) - len(manoeuvres) % RECOGNITION_EVERY
                if planner is not None and last < len(manoeuvres) < budget:
                    # resumed between recognitions: the leaders the last one found
                    _, leaders = recognised(manoeuvres[:last])
                while True:
                    index = len(manoeuvres)
                    done = [m.sweep for m in manoeuvres]
                    free = [m.sweep for m in manoeuvres if m.outcome == "free"]
                    points = [m.point for m in manoeuvres if m.point is not None]
                    end = budget if planner is not None else _grid_end(done, grid, budget)
                    choice: Choice | None = None
                    aim = "plan"
                    if index < end and planner is None:
                        following = _next_grid_sweep(grid, done)  # one is left until the grid ends
                        assert following is not None
                        choice = Choice(following, math.nan, np.full(3, np.nan))
                    elif index < end and planner is not None:
                        surface = fit_surface(points, settings.include_uncertain)
                        if index % RECOGNITION_EVERY == 0:
                            _, leaders = recognised(manoeuvres)
                        choice = planner.choose(done, surface, free, leaders)
                    elif index < end + settings.until_recognised:
                        named, leaders = recognised(manoeuvres)
                        within = settings.sizes_within
                        # a recognition that names the object has it as its best fit
                        if named is not None and (within is None or named.best.sizes_known(within)):
                            final = named  # of every point and swept link: the map's own
                            break
                        chooser = chooser if chooser is not None else NextBestPlanner(scene, shape)
                        surface = fit_surface(points, settings.include_uncertain)
                        choice = chooser.choose(done, surface, free, leaders)
                        aim = "recognition" if named is None else "sizes"
                    if choice is None:
                        break
                    manoeuvre = _run_one(
                        scene, controlled, antenna, built, choice, index, settings, out, aim
                    )
                    write_manoeuvre(out, manoeuvre)
                    manoeuvres.append(manoeuvre)
                    if progress is not None:
                        progress(manoeuvre, end + settings.until_recognised)
                    raise_if_signalled()
            finally:
                # every manoeuvre stored so far, whatever stops the sweeps
                write_manoeuvre_table(out, manoeuvres)
    points = [m.point for m in manoeuvres if m.point is not None]
    if mapping is not None:
        mapping(len(points))
    with stopped_as_stored(out, lambda: len(manoeuvres)):
        # the swept links are recognition's evidence only: the recognition that ended the
        # sweeps has weighed them already
        swept = () if final is not None else swept_links(manoeuvres, scene, antenna, out, recorded)
        contact_map = build_map(
            points,
            settings.include_uncertain,
            meshes=meshes,
            swept=swept,
            recognition=final,
            class_fitted=class_fitted,
        )
    return Exploration(scene, settings, tuple(manoeuvres), contact_map, antenna)


def swept_links(
    manoeuvres: Sequence[Manoeuvre],
    scene: Scene,
    antenna: Antenna,
    out: Path,
    recorded: dict[int, RecordedLinks] | None = None,
) -> tuple[FreeSpace, Touches]:
    """Where the manoeuvres' links were free and where they touched (``mapping.free_space``).

    Free: the whole sweep when it touched nothing; up to the touch otherwise, the recording's
    own angles before its detected contact's onset when it has one (in its own frame,
    ``base_pose``) after the unrecorded approach as planned, else (a glancing touch, or one
    whose push would press a second object: nothing kept) the planned angles short of the
    geometric touch by the onset turn of a contact at the tip. Touched: the link at the
    detection of each contact whose point is not ``ok`` (an ``ok`` point says more), and at
    each glancing or second-object touch. ``recorded`` keeps each
    manoeuvre's recording's :func:`~sensing_antenna.mapping.free_space.recording_links` and
    first angles by its index between calls (a stored recording does not change), so that each
    is read once.
    """
    from sensing_antenna.recording import read_recording

    links = recorded if recorded is not None else {}
    free: list[list[Piece]] = []
    touched: list[list[Piece]] = []
    for m in manoeuvres:
        sweep = m.sweep
        planned = sweep.swept_angles(PREDICTION_STEP)
        base = scene.base(sweep.base)
        pieces: list[Piece] = []
        if m.outcome == "free":
            end = math.inf * sweep.direction
        elif m.outcome not in ("touch", "glancing", "second_object") or m.touch is None:
            continue
        elif m.recording is not None and (out / m.recording).exists():
            if m.index not in links:
                recording = read_recording(out / m.recording)
                links[m.index] = (
                    recording_links(recording, antenna, m.point),
                    recording.theta[0],
                )
            ((pose, free_angles), touching), first = links[m.index]
            if touching is not None:
                touched.append([touching])
            # the recording's frame is turned to the touch's angles: its swept angle plus the
            # touch's is the sweep's, and the simulated approach may begin before the sweep did
            joint = 0 if sweep.case == "azimuthal" else 1
            angle = float(m.touch["angle"]) + np.asarray(free_angles)[:, joint]
            inside = (angle >= sweep.start) & (angle <= sweep.end)
            pieces.append((pose, np.asarray(free_angles)[inside]))
            end = float(m.touch["angle"]) + float(first[joint])
        else:
            touch = float(m.touch["angle"])
            touched.append([(base, np.array([sweep.angles(touch)]))])
            end = touch - sweep.direction * onset_turn(antenna, math.nan)
        before = planned[(planned - end) * sweep.direction < 0]
        theta = np.array([sweep.angles(float(a)) for a in before]).reshape(-1, 2)
        free.append([(base, theta), *pieces])
    return free_space(free, antenna), touches(touched, antenna)


def _recognition_state(
    points: list[ContactPoint],
    include_uncertain: bool,
    swept: Sequence[FreeSpace],
    meshes: Mapping[str, trimesh.Trimesh] | None = None,
) -> RecognitionState:
    """The recognition (the map's, with the user's ``meshes``) of the points so far when it
    names an object (else None), and the fits the planner aims with: the named object's fit,
    or, when recognition abstains, the two fits it abstains between (the best and its rival,
    or the two leading scores); none when they are not all primitives."""
    recognition = recognise_points(points, include_uncertain, meshes, swept=swept)
    if recognition is None:
        return None, ()
    named = recognition.named
    if named is not None:
        return recognition, (named,) if named.name in PRIMITIVES else ()
    by_name = {f.name: f for f in recognition.fits}
    leaders = tuple(by_name[name] for name in recognition.candidates)
    return None, leaders if all(f.name in PRIMITIVES for f in leaders) else ()


def _run_one(
    scene: Scene,
    device: Antenna,
    antenna: Antenna,
    shape: LinkShape,
    choice: Choice,
    index: int,
    settings: ExploreSettings,
    out: Path,
    aim: str,
) -> Manoeuvre:
    from sensing_antenna.mapping.contact_map import points_from_recordings

    seed = settings.seed + index
    outcome = simulate_sweep(
        device,
        scene,
        choice.sweep,
        seed=seed,
        shape=shape,
        link_model=settings.link,
        imperfections=settings.imperfections(seed, device.link.length),
    )
    recording_name = None
    point = None
    if outcome.recording is not None:
        folder = out / RECORDINGS_DIR
        folder.mkdir(exist_ok=True)
        path = folder / f"{index:03d}.csv"
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        # named after the model its estimates need (calibrated.toml), as a lab's recordings
        # name their antenna's file: another model is warned of where they are read again
        write_recording(outcome.recording.with_metadata(antenna=antenna.name), tmp)
        tmp.replace(path)
        recording_name = f"{RECORDINGS_DIR}/{path.name}"
        # the map's own code path: the recording as a file, its base pose from its metadata
        point = points_from_recordings([path], antenna, settings.method)[0]
    return Manoeuvre(
        index=index,
        sweep=choice.sweep,
        outcome=outcome.outcome,
        reason=outcome.reason,
        touch=None if outcome.touch is None else outcome.touch.to_dict(),
        sweep_time=outcome.sweep_time,
        seed=seed,
        recording=recording_name,
        point=point,
        score=choice.score,
        aim=aim,
    )
