"""A campaign spec expanded into its runs: seeds, run ids and the picklable :class:`RunSpec`.

Seeds are derived from the spec's ``base_seed`` with :class:`numpy.random.SeedSequence`, one
stream per kind of recording (:func:`derive_seed`), so every run's seed is fixed by the spec
alone, independent of the order runs execute in, and no two kinds share a seed.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sensing_antenna.antenna import Antenna
from sensing_antenna.campaign.schema import (
    SCENARIO_NOISE_SCALE,
    SECOND_DEVICE_SUFFIX,
    CampaignSpec,
    CampaignSpecError,
    contact_point_key,
    noise_level_key,
)

__all__ = [
    "CALIBRATION_STREAM",
    "FREE_MOTION_STREAM",
    "NOISE_SWEEP_STREAM",
    "RUN_STREAM",
    "PlannedRun",
    "RunSpec",
    "calibration_runs",
    "contact_point_label",
    "derive_seed",
    "expand_runs",
    "plan_runs",
    "run_ids",
    "second_device_run_ids",
    "with_device",
]

#: Seed streams of :func:`derive_seed`: the main runs, the free-motion step, the calibration
#: recordings, the runs of the noise sweep.
RUN_STREAM = 0
FREE_MOTION_STREAM = 1
CALIBRATION_STREAM = 2
NOISE_SWEEP_STREAM = 3


@dataclass(frozen=True)
class RunSpec:
    """Everything one run needs: picklable, so it can travel to a worker process or a Dask worker.

    Parameters
    ----------
    index : int
        Position of the run in the campaign (0-based).
    run_id : str
        Stable, file-name-safe identifier, e.g. ``azimuthal-x0300mm-r1`` (``x0500.4mm`` for a
        point off the millimetre, :func:`contact_point_label`); a run of the noise sweep ends
        in its level, e.g. ``azimuthal-x0300mm-r1-n2.00``.
    case : str
        Manoeuvre (:data:`~sensing_antenna.campaign.schema.CASES`).
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
    fast_bound : bool
        Whether the ``fast`` row also gets the information bound of its delay
        (``CampaignSpec.fast_bound``).
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
    fast_bound: bool = True

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


def contact_point_label(contact_point: float) -> str:
    """A contact point as run ids name it: ``x0300mm``, or ``x0500.4mm`` off the millimetre.

    Whole millimetres keep four digits; a point between them carries its micrometres, so two
    points get one label exactly when the distinctness check of the spec
    (:func:`~sensing_antenna.campaign.schema.contact_point_key`) calls them one point.
    """
    micrometres = contact_point_key(contact_point)
    millimetres, rest = divmod(micrometres, 1000)
    fraction = f".{rest:03d}".rstrip("0") if rest else ""
    return f"x{millimetres:04d}{fraction}mm"


@dataclass(frozen=True)
class PlannedRun:
    """One run of a spec before any antenna is known: where it sits, its id and its settings.

    Attributes
    ----------
    index : int
        Position in the campaign (0-based).
    run_id : str
    case : str
    contact_point : float
        Nominal x_c (m).
    repeat : int
        1-based.
    stream : int
        Seed stream (:data:`RUN_STREAM` or :data:`NOISE_SWEEP_STREAM`).
    position : int
        Position within that stream.
    scenario : mapping
        The run's extra ``simulator.Scenario`` fields.
    second_device : bool
        Whether the run is on the spec's second device.
    """

    index: int
    run_id: str
    case: str
    contact_point: float
    repeat: int
    stream: int
    position: int
    scenario: Mapping[str, Any]
    second_device: bool = False


def plan_runs(spec: CampaignSpec) -> Iterator[PlannedRun]:
    """Every run of ``spec`` in the campaign's order (see :func:`expand_runs`), without seeds."""
    index = 0
    for case in spec.cases:
        for x_c in spec.contact_points:
            for repeat in range(1, spec.repeats + 1):
                run_id = f"{case}-{contact_point_label(x_c)}-r{repeat}"
                yield PlannedRun(
                    index, run_id, case, float(x_c), repeat, RUN_STREAM, index, spec.scenario
                )
                index += 1
    position = 0
    for level in spec.noise_sweep.noise_scales:
        scenario = {**spec.scenario, "noise_scale": float(level)}
        suffix = f"-n{noise_level_key(level) / 100:.2f}"
        for case in spec.sweep_cases:
            for x_c in spec.sweep_contact_points:
                for repeat in range(1, spec.sweep_repeats + 1):
                    run_id = f"{case}-{contact_point_label(x_c)}-r{repeat}{suffix}"
                    yield PlannedRun(
                        index,
                        run_id,
                        case,
                        float(x_c),
                        repeat,
                        NOISE_SWEEP_STREAM,
                        position,
                        scenario,
                    )
                    index += 1
                    position += 1
    if spec.second_device.enabled:
        for main in plan_runs(spec.second_device_spec()):
            yield PlannedRun(
                index + main.index,
                main.run_id + SECOND_DEVICE_SUFFIX,
                main.case,
                main.contact_point,
                main.repeat,
                main.stream,
                main.position,
                main.scenario,
                second_device=True,
            )


def run_ids(spec: CampaignSpec) -> list[str]:
    """The run ids of ``spec`` in order; two runs that would share an id are refused.

    Raises
    ------
    CampaignSpecError
        When two runs would have one id (and so one run file).
    """
    ids: dict[str, int] = {}
    for run in plan_runs(spec):
        other = ids.setdefault(run.run_id, run.index)
        if other != run.index:
            raise CampaignSpecError(
                "contact_points",
                f"runs {other} and {run.index} would share the id {run.run_id!r} (one run file)",
                spec.source or None,
            )
    return list(ids)


def second_device_run_ids(spec: CampaignSpec) -> frozenset[str]:
    """The ids of the runs on the spec's second device (empty without one)."""
    return frozenset(run.run_id for run in plan_runs(spec) if run.second_device)


def expand_runs(
    spec: CampaignSpec,
    antenna: Antenna,
    device: Antenna | None = None,
    *,
    second_model: Antenna | None = None,
    second_device: Antenna | None = None,
) -> list[RunSpec]:
    """All runs of a campaign in a fixed order: case, then contact point, then repeat.

    The main runs come first; then, if the spec has a noise sweep, its runs ordered by level,
    case, contact point and repeat, with ids ending in ``-n<level>`` and seeds from
    :data:`NOISE_SWEEP_STREAM` (position within the sweep); then, if the spec has a second
    device, the main runs again on it, with the main runs' seeds and ids ending in
    :data:`~sensing_antenna.campaign.schema.SECOND_DEVICE_SUFFIX`. Adding a sweep or a second
    device leaves the main runs' indices, ids and seeds as they are. Run ids name the contact
    point with :func:`contact_point_label`.

    Parameters
    ----------
    spec : CampaignSpec
    antenna : Antenna
        The model the estimators use (the spec's, possibly with an identified observer and a
        calibrated T_e).
    device : Antenna, optional
        The simulated hardware; None simulates with ``antenna``. Its imperfections (the spec's
        ``[device]`` profile and table) go into each run's scenario (:func:`with_device`).
    second_model, second_device : Antenna, optional
        The model and hardware of the second device's runs (its own preparation); None: those
        of the main runs. The second device's imperfections are the spec's
        ``[second_device]``'s.

    Raises
    ------
    CampaignSpecError
        When two runs would share an id (see :func:`run_ids`).
    """
    run_ids(spec)
    second_spec = spec.second_device_spec() if spec.second_device.enabled else spec
    runs = []
    for run in plan_runs(spec):
        seed = derive_seed(spec.base_seed, run.position, run.stream)
        model, hardware, own = antenna, device, spec
        if run.second_device:
            model = second_model or antenna
            hardware = second_device or device
            own = second_spec
        length = (hardware or model).link.length
        runs.append(
            RunSpec(
                index=run.index,
                run_id=run.run_id,
                case=run.case,
                contact_point=run.contact_point,
                repeat=run.repeat,
                seed=seed,
                antenna=model,
                methods=spec.methods,
                scenario=with_device(own, run.scenario, seed, length),
                device=hardware,
                fast_bound=spec.fast_bound,
            )
        )
    return runs


def with_device(
    spec: CampaignSpec, scenario: Mapping[str, Any], seed: int, length: float
) -> dict[str, Any]:
    """``scenario`` with the ``device`` imperfections of the manoeuvre of seed ``seed`` (the
    spec's ``[device]`` profile and table, ``simulator.DeviceImperfections``; every manoeuvre
    of the campaign on one realistic device, built from the base seed unless the spec names its
    ``build``), unchanged when the spec sets none; ``length`` (m) is the simulated link's, to
    place a joint."""
    extra = dict(scenario)
    if spec.device.has_imperfections:
        extra["device"] = spec.device.imperfections_for(seed, length, spec.base_seed)
    return extra


def calibration_runs(spec: CampaignSpec) -> list[tuple[str, str, float, int]]:
    """(name, case, contact point in m, seed) of each calibration recording, in a fixed order
    (the step's case first: a spec without ``sensor`` keeps its seeds).

    Seeds come from :data:`CALIBRATION_STREAM` of the base seed, so they never coincide with the
    runs' or the free motion's.
    """
    step = spec.calibration
    runs: list[tuple[str, str, float, int]] = []
    for case in step.cases:
        for x_c in step.contact_points:
            for repeat in range(1, step.repeats + 1):
                name = f"calibration-{case}-{contact_point_label(x_c)}-r{repeat}"
                seed = derive_seed(spec.base_seed, len(runs), CALIBRATION_STREAM)
                runs.append((name, case, float(x_c), seed))
    return runs
