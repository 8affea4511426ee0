"""A campaign spec expanded into its runs: seeds, run ids and the picklable :class:`RunSpec`.

Seeds are derived from the spec's ``base_seed`` with :class:`numpy.random.SeedSequence`, one
stream per kind of recording (:func:`derive_seed`), so every run's seed is fixed by the spec
alone, independent of the order runs execute in, and no two kinds share a seed.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from sensing_antenna.antenna import Antenna
from sensing_antenna.campaign.schema import SCENARIO_NOISE_SCALE, CampaignSpec, noise_level_key

__all__ = [
    "CALIBRATION_STREAM",
    "FREE_MOTION_STREAM",
    "NOISE_SWEEP_STREAM",
    "RUN_STREAM",
    "RunSpec",
    "calibration_runs",
    "derive_seed",
    "expand_runs",
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
        Stable, file-name-safe identifier, e.g. ``azimuthal-x0300mm-r1``; a run of the noise
        sweep ends in its level, e.g. ``azimuthal-x0300mm-r1-n2.00``.
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

    The main runs come first; then, if the spec has a noise sweep, its runs ordered by level,
    case, contact point and repeat, with ids ending in ``-n<level>`` and seeds from
    :data:`NOISE_SWEEP_STREAM` (position within the sweep). Adding a sweep leaves the main runs'
    indices, ids and seeds as they are.

    Parameters
    ----------
    spec : CampaignSpec
    antenna : Antenna
        The model the estimators use (the spec's, possibly with an identified observer and a
        calibrated T_e).
    device : Antenna, optional
        The simulated hardware; None simulates with ``antenna``.
    """

    def run(
        index: int,
        suffix: str,
        case: str,
        x_c: float,
        repeat: int,
        seed: int,
        scenario: Mapping[str, Any],
    ) -> RunSpec:
        return RunSpec(
            index=index,
            run_id=f"{case}-x{round(x_c * 1000):04d}mm-r{repeat}{suffix}",
            case=case,
            contact_point=float(x_c),
            repeat=repeat,
            seed=seed,
            antenna=antenna,
            methods=spec.methods,
            scenario=dict(scenario),
            device=device,
        )

    runs: list[RunSpec] = []
    for case in spec.cases:
        for x_c in spec.contact_points:
            for repeat in range(1, spec.repeats + 1):
                index = len(runs)
                seed = derive_seed(spec.base_seed, index, RUN_STREAM)
                runs.append(run(index, "", case, x_c, repeat, seed, spec.scenario))
    position = 0
    for level in spec.noise_sweep.noise_scales:
        scenario = {**spec.scenario, "noise_scale": float(level)}
        suffix = f"-n{noise_level_key(level) / 100:.2f}"
        for case in spec.sweep_cases:
            for x_c in spec.sweep_contact_points:
                for repeat in range(1, spec.sweep_repeats + 1):
                    seed = derive_seed(spec.base_seed, position, NOISE_SWEEP_STREAM)
                    runs.append(run(len(runs), suffix, case, x_c, repeat, seed, scenario))
                    position += 1
    return runs


def calibration_runs(spec: CampaignSpec) -> list[tuple[str, float, int]]:
    """(name, contact point in m, seed) of each calibration recording, in a fixed order.

    Seeds come from :data:`CALIBRATION_STREAM` of the base seed, so they never coincide with the
    runs' or the free motion's.
    """
    step = spec.calibration
    runs: list[tuple[str, float, int]] = []
    for x_c in step.contact_points:
        for repeat in range(1, step.repeats + 1):
            name = f"calibration-{step.case}-x{round(x_c * 1000):04d}mm-r{repeat}"
            seed = derive_seed(spec.base_seed, len(runs), CALIBRATION_STREAM)
            runs.append((name, float(x_c), seed))
    return runs
