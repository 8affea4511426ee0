"""The real run function: simulate one contact manoeuvre, then estimate it with every method.

Also the steps before the runs, in the paper's order:

1. free-motion identification (Section 5.2): simulate a free motion on the device and identify
   the free-motion observer of Eq. 15 and its contact threshold from it, so that the contact
   detector is tuned to the simulated device rather than to the paper's real one; the device's
   controller (the simulator's stop rule) and the estimators both use it;
2. calibration (Section 5.1): simulate contact manoeuvres on the device at known contact points,
   measure omega_1 in each with a wide band and fit T_e; the estimators use the nominal model
   with that T_e. The device's own T is never given to the estimators.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from sensing_antenna.antenna import STANDARD_GRAVITY, Antenna
from sensing_antenna.calibration.frequency import FrequencyCalibration
from sensing_antenna.calibration.observer import ObserverFit
from sensing_antenna.campaign.progress import Progress
from sensing_antenna.campaign.records import CampaignRow, RunResult, float_or_nan
from sensing_antenna.campaign.runs import (
    FREE_MOTION_STREAM,
    RunSpec,
    calibration_runs,
    derive_seed,
    plan_runs,
    with_device,
)
from sensing_antenna.campaign.schema import CampaignSpec, CampaignSpecError
from sensing_antenna.campaign.store import Preparation
from sensing_antenna.errors import SensingAntennaError
from sensing_antenna.recording import Recording, tracked_contact

if TYPE_CHECKING:
    from sensing_antenna.estimation import ContactEstimate, Evidence
    from sensing_antenna.estimation.methods.fast import FastMethod
    from sensing_antenna.estimation.methods.fast.window_fit import FitCache

__all__ = [
    "calibrate_on_device",
    "check_scenario",
    "identify_observer",
    "make_scenario",
    "point_error",
    "prepare_antenna",
    "prepare_campaign",
    "simulate_and_estimate",
]


def make_scenario(case: str, contact_point: float | None, seed: int, extra: dict[str, Any]) -> Any:
    """A ``simulator.Scenario`` for one run; unknown extra fields raise CampaignSpecError."""
    from sensing_antenna.simulator import Scenario

    known = {f.name for f in dataclasses.fields(Scenario)}
    for key in extra:
        if key not in known:
            raise CampaignSpecError(
                f"scenario.{key}", f"not a Scenario field; known: {', '.join(sorted(known))}"
            )
    kwargs: dict[str, Any] = {"case": case, "seed": seed, **extra}
    if "push" in kwargs:
        kwargs["push"] = push_criterion(kwargs["push"])
    if contact_point is not None:
        kwargs["contact_point"] = contact_point
    return Scenario(**kwargs)


def push_criterion(value: Any) -> Any:
    """``scenario.push`` of a spec as the simulator's push criterion: a number is the head's
    rotation past the first touch (rad), as ``antenna simulate --push``; a table gives the
    fields of ``detection.push.PushCriterion`` (kind, threshold, cutoff). Raises
    CampaignSpecError naming the field."""
    from sensing_antenna.detection.push import PushConfigError, PushCriterion

    if value is None or isinstance(value, PushCriterion):
        return value
    known = {f.name for f in dataclasses.fields(PushCriterion)}
    if isinstance(value, Mapping):
        for key in value:
            if key not in known:
                raise CampaignSpecError(
                    f"scenario.push.{key}",
                    f"not a push criterion field; known: {', '.join(sorted(known))}",
                )
    try:
        if isinstance(value, Mapping):
            return PushCriterion(**value)
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return PushCriterion(kind="rotation", threshold=float(value))
    except PushConfigError as exc:
        # "push.<field>: <problem>"; a bare number is the threshold
        field, _, problem = str(exc).partition(": ")
        name = f"scenario.{field}" if isinstance(value, Mapping) else "scenario.push"
        raise CampaignSpecError(name, problem) from exc
    raise CampaignSpecError(
        "scenario.push",
        "must be the head's rotation past the first touch (rad) or a table of the push "
        f"criterion's kind, threshold and cutoff, got {value!r}",
    )


def simulate_and_estimate(run: RunSpec) -> RunResult:
    """Simulate the run's manoeuvre and estimate the recording with each of ``run.methods``.

    The estimation front end runs once on the recording (``estimation.gather``) and every
    method concludes from its evidence, which gives each method the estimate ``estimate``
    gives. Timing (wall clock): ``front_end_s`` is the front end's, ``estimate_s`` of a method
    is that plus its own conclusion. With ``run.fast_bound`` the ``fast`` row also gets the
    information bound of its delay (``estimation.methods.fast.bound_delay``, reading the
    method's window fits), outside its ``estimate_s``. An estimator that raises is recorded for
    that method (status ``"error"``) and the other methods still run; an exception from the
    simulator or the bound propagates (the runner records the run as failed).
    """
    from sensing_antenna.estimation import METHODS, Evidence, conclude, gather
    from sensing_antenna.estimation.methods.fast import FastMethod, bound_delay
    from sensing_antenna.simulator import simulate

    start = time.perf_counter()
    scenario = make_scenario(run.case, run.contact_point, run.seed, dict(run.scenario))
    recording = simulate(run.simulated_antenna, scenario)
    simulate_s = time.perf_counter() - start
    # The estimators get the recording without ground truth (recording format: they must never
    # read it); the rows keep the nominal contact point from the run spec and the contact
    # abscissa the simulator reports (where the link touched at the last in-contact sample).
    truth = {
        "contact_abscissa": _true_contact_abscissa(recording.metadata),
        "simulate_s": simulate_s,
    }
    blind = recording.without_ground_truth()
    begin = time.perf_counter()
    try:
        evidence = gather(blind, run.antenna)
    except Exception as exc:  # every method would raise the same: recorded for each
        front_end_s = time.perf_counter() - begin
        reason = f"{type(exc).__name__}: {exc}"
        timing = {"front_end_s": front_end_s, "estimate_s": front_end_s}
        rows = [CampaignRow.of_error(run, m, reason, **truth, **timing) for m in run.methods]
        return RunResult(rows=tuple(rows))
    front_end_s = time.perf_counter() - begin
    rows = []
    for method in run.methods:
        impl = METHODS.get(method)
        bounded = (
            _KeepingFits(impl, ({}, {}))
            if run.fast_bound and isinstance(impl, FastMethod) and isinstance(evidence, Evidence)
            else None
        )
        begin = time.perf_counter()
        try:
            # an early outcome of the front end (no contact, no push, bad input) is every
            # method's result, under its own name
            estimate = conclude(evidence, bounded or method)
        except Exception as exc:  # recorded per method: one broken estimator must not hide others
            elapsed = front_end_s + time.perf_counter() - begin
            reason = f"{type(exc).__name__}: {exc}"
            rows.append(
                CampaignRow.of_error(
                    run, method, reason, **truth, front_end_s=front_end_s, estimate_s=elapsed
                )
            )
            continue
        elapsed = front_end_s + time.perf_counter() - begin
        bound = math.nan
        if bounded is not None:
            assert isinstance(evidence, Evidence)
            bound = bound_delay(evidence, bounded.method.config, caches=bounded.caches)
        rows.append(
            CampaignRow.of_estimate(
                run,
                estimate,
                **truth,
                front_end_s=front_end_s,
                estimate_s=elapsed,
                point_error_m=point_error(estimate, recording, run.antenna),
                bound_delay_s=bound,
            )
        )
    return RunResult(rows=tuple(rows))


@dataclasses.dataclass(frozen=True)
class _KeepingFits:
    """The fast method concluding with ``caches``, which it fills with its window fits, so that
    the information bound computed after it reads them instead of fitting those windows again
    (a window's fit is a function of its own samples: neither answer changes)."""

    method: FastMethod
    caches: tuple[FitCache, FitCache]

    @property
    def name(self) -> str:
        """The method's name."""
        return self.method.name

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        """The method's estimate (:meth:`FastMethod.conclude`)."""
        return self.method.conclude(evidence, self.caches)


def point_error(estimate: ContactEstimate, recording: Recording, antenna: Antenna) -> float:
    """Distance (m) from the estimate's touched point, on the link's surface
    (``contact_point`` plus ``mapping.points.surface_offset``), to where the link touched at
    the instant the point describes (its ``diagnostics["t_point"]``) by the recording's contact
    track (``recording.tracked_contact``); NaN without either."""
    from sensing_antenna.mapping.points import surface_offset

    truth = tracked_contact(recording, estimate.diagnostics.get("t_point"))
    point = np.asarray(estimate.contact_point, dtype=float)
    if truth is None or point.shape != (3,):
        return math.nan
    return float_or_nan(np.linalg.norm(point + surface_offset(estimate, antenna) - truth))


def _true_contact_abscissa(metadata: Mapping[str, str]) -> float:
    """The recording's ground-truth ``true_xc`` (m), NaN when absent or not a number."""
    return float_or_nan(metadata.get("true_xc"))


def identify_observer(
    device: Antenna, spec: CampaignSpec, model: Antenna | None = None
) -> ObserverFit:
    """Simulate free motions on ``device`` and identify the observer of Eq. 15 from them, and
    the payload their rests read.

    The free motions (``CampaignSpec.free_motion_cases``: by default a free sweep of each
    swept joint) use the spec's scenario settings and their own seeds (stream 1 of the base seed).
    The identification starts from what the engineer knows, ``model`` (default: the device
    itself), and sees only the recordings.
    """
    from sensing_antenna.calibration.observer import identify_free_motion
    from sensing_antenna.simulator import simulate

    recordings = []
    for k, case in enumerate(spec.free_motion_cases()):
        seed = derive_seed(spec.base_seed, k, FREE_MOTION_STREAM)
        extra = with_device(spec, spec.scenario, seed, device.link.length)
        extra["duration"] = spec.free_motion.duration
        scenario = make_scenario(case, None, seed, extra)
        recording = simulate(device, scenario).without_ground_truth()
        # named in the step's errors as the calibration recordings are
        recordings.append(dataclasses.replace(recording, source=f"free motion '{case}'"))
    try:
        return identify_free_motion(recordings, model or device, find_lag=False)
    except SensingAntennaError as exc:
        raise CampaignSpecError(
            "free_motion", f"the free-motion step failed: {exc}", spec.source or None
        ) from exc


def knowing_weight(device: Antenna, identified: Antenna) -> Antenna:
    """The simulated device whose controller knows what identification found: the observer and
    threshold of ``identified`` (the model after identification, its payload applied), and the
    weight's moment about the head that model gives, carried as the device's
    ``link.weight_tip_mass`` (which the detector and the push monitor remove and the
    simulator's physics does not read)."""
    link = device.link
    # (m_b / 2 + m_t) l g of the device's link equal to the identified model's moment
    tip = identified.link.weight_moment / (STANDARD_GRAVITY * link.length) - 0.5 * link.mass
    weighed = dataclasses.replace(link, weight_tip_mass=max(0.0, tip))
    return dataclasses.replace(device, observer=identified.observer, link=weighed)


def calibrate_on_device(
    spec: CampaignSpec, device: Antenna, model: Antenna, progress: Progress | None = None
) -> tuple[FrequencyCalibration, Antenna]:
    """Section 5.1 on the simulated device: T_e of the frequency model from known contact points,
    and, with ``calibration.sensor``, the sensor's cross-talk from the same points swept both
    ways.

    Each calibration manoeuvre is simulated on ``device``; omega_1 is measured in the wide band
    :func:`~sensing_antenna.calibration.frequency.calibration_band` by Estimator 1's frequency
    measurement, using
    ``model`` (the observer for t_c and t_1); T_e is fitted to the model's beta_1(x_c)^2 on the
    step's case. The contact points are known by construction (a calibration), so they come from
    the spec, and the estimators never see the device's T. ``progress`` shows a bar of the
    recordings and a line for the sensor's fit.

    Returns
    -------
    (FrequencyCalibration, Antenna)
        The T_e fit, and ``model`` with T_e (and the sensor's correction) applied.
    """
    from sensing_antenna.calibration.frequency import (
        CalibrationError,
        calibrate_from_recordings,
        held_compliance_from_recordings,
    )
    from sensing_antenna.calibration.sensor import SensorCalibrationError, calibrate_sensor
    from sensing_antenna.simulator import simulate

    step = spec.calibration
    names, cases, points, recordings = [], [], [], []
    planned = calibration_runs(spec)
    progress = progress or Progress(enabled=False)
    bar = progress.bar(len(planned), "calibration", "recording")
    with bar:
        for name, case, x_c, seed in planned:
            extra = with_device(spec, calibration_scenario(spec), seed, device.link.length)
            scenario = make_scenario(case, x_c, seed, extra)
            recordings.append(simulate(device, scenario).without_ground_truth())
            names.append(name)
            cases.append(case)
            points.append(x_c)
            bar.update(1)
    own = [i for i, case in enumerate(cases) if case == step.case]
    try:
        calibration = calibrate_from_recordings(
            [recordings[i] for i in own],
            model,
            [points[i] for i in own],
            sources=[names[i] for i in own],
            loss=step.loss,
            fit_tip_mass=step.tip_mass,
        )
    except CalibrationError as exc:
        raise CampaignSpecError(
            "calibration", f"the calibration step failed: {exc}", spec.source or None
        ) from exc
    # the held joints' servos from every post, both sweeps (the fit takes the step's case
    # only), those the fit left out excepted, as antenna calibrate leaves them out
    left_out = {i for j, i in enumerate(own) if not calibration.used[j]}
    posts = [r for i, r in enumerate(recordings) if i not in left_out]
    calibrated = calibration.apply(model).with_held_compliance(
        *held_compliance_from_recordings(posts, model)
    )
    if step.sensor:
        try:
            sensor = calibrate_sensor(recordings, calibrated, points, sources=names)
        except SensorCalibrationError as exc:
            progress.line(f"preparation: the sensor is not calibrated ({exc})")
        else:
            calibrated = sensor.apply(calibrated)
            progress.line(
                f"preparation: sensor cross-talk {'fitted' if sensor.adopted else 'tried'} "
                f"({', '.join(sensor.sweeps)} sweeps); {sensor.ratio_summary}"
            )
    return calibration, calibrated


#: How :func:`check_scenario` prefixes a problem of the free motions' and the calibration's.
FREE_MOTION, CALIBRATION = "the free motion: ", "the calibration: "


def check_scenario(spec: CampaignSpec) -> None:
    """Check every scenario the campaign will simulate, before any work.

    Each run's (case, contact point, noise level), the free motion (when identified) and each
    calibration recording (when calibrating) is made into a ``simulator.Scenario``, whose checks
    apply; seeds are left out (every derived seed is valid).

    Raises
    ------
    CampaignSpecError
        Naming the spec file and ``scenario.<field>`` (``free_motion.duration`` and
        ``free_motion.case`` for the free motions', ``calibration.scenario.<field>`` for a field
        the calibration sets), on the first scenario that is not valid.
    """
    from sensing_antenna.simulator.scenario import ScenarioError

    # the model's and the devices' files, and every contact point against their links
    spec.load_antenna()
    spec.load_device()
    if spec.second_device.enabled:
        spec.second_device_spec().load_device()
    checked: set[tuple[str, float | None, tuple[tuple[str, str], ...]]] = set()

    def section(field: str, prefix: str) -> str:
        """The spec's name of a Scenario ``field`` (``push`` or ``push.kind``): its own step's
        when the free motion or the calibration sets it, the ``[scenario]`` one's otherwise."""
        head = field.split(".")[0]
        if prefix == FREE_MOTION and head in ("duration", "case"):
            return f"free_motion.{field}"
        if prefix == CALIBRATION and head in spec.calibration.scenario:
            return f"calibration.scenario.{field}"
        return f"scenario.{field}"

    def check(case: str, x_c: float | None, extra: Mapping[str, Any], prefix: str) -> None:
        key = (case, x_c, tuple(sorted((k, repr(v)) for k, v in extra.items())))
        if key in checked:
            return
        checked.add(key)
        try:
            make_scenario(case, x_c, 0, dict(extra))
        except ScenarioError as exc:
            raise CampaignSpecError(
                section(exc.field_name, prefix),
                prefix + str(exc).split(": ", 1)[-1],
                spec.source or None,
            ) from exc
        except CampaignSpecError as exc:
            name = exc.field_name
            if name.startswith("scenario."):
                name = section(name.removeprefix("scenario."), prefix)
            raise CampaignSpecError(name, exc.problem, spec.source or None) from exc
        except TypeError as exc:
            raise CampaignSpecError("scenario", str(exc), spec.source or None) from exc

    for run in plan_runs(spec):
        check(run.case, run.contact_point, run.scenario, "")
    if spec.free_motion.identify:
        extra = {**spec.scenario, "duration": spec.free_motion.duration}
        for case in spec.free_motion_cases():
            check(case, None, extra, FREE_MOTION)
    if spec.calibration.enabled:
        for _, case, x_c, _ in calibration_runs(spec):
            check(case, x_c, calibration_scenario(spec), CALIBRATION)


def calibration_scenario(spec: CampaignSpec) -> dict[str, Any]:
    """The scenario fields of the calibration recordings: ``[scenario]`` with
    ``[calibration.scenario]`` over it."""
    return {**spec.scenario, **spec.calibration.scenario}


def prepare_campaign(spec: CampaignSpec, progress: Progress | None = None) -> Preparation:
    """The steps before the runs: load model and device, identify the observer, calibrate T_e.

    Order (the paper's): free-motion identification on the device (if asked), then calibration
    on the device (if asked). The identified observer goes to both antennas (the device's
    controller and the estimators use the same detector); the payload its rest reads (a tip mass
    the model lacks) and T_e go to the model only.
    Checks the spec's scenario section first, so a bad value stops the campaign with one clear
    error instead of failing every run. ``progress`` gets a line per step and the calibration's
    bar.
    """
    progress = progress or Progress(enabled=False)
    check_scenario(spec)
    model = spec.load_antenna()
    device = spec.load_device()
    if spec.free_motion.identify:
        cases = spec.free_motion_cases()
        progress.line(
            f"preparation: identifying the free-motion observer (Eq. 15) on {len(cases)} "
            f"free sweep{'s' if len(cases) > 1 else ''} of {spec.free_motion.duration:g} s of "
            "the device"
        )
        fit = identify_observer(device, spec, model)
        model = fit.apply(model)
        device = knowing_weight(device, model)
    calibration = None
    if spec.calibration.enabled:
        progress.line(
            f"preparation: calibrating T_e{' and the sensor' if spec.calibration.sensor else ''} "
            f"on {spec.calibration.n_recordings} contact recordings of the device (Section 5.1)"
        )
        calibration, model = calibrate_on_device(spec, device, model, progress)
    return Preparation(model=model, device=device, calibration=calibration)


def compile_methods(
    spec: CampaignSpec, preparation: Preparation, progress: Progress | None = None
) -> None:
    """Estimate one manoeuvre of the device with every method of ``spec``, in this process.

    The methods' compiled kernels (numba) then exist before the workers start: workers forked
    from this process inherit them, others load them from numba's cache, instead of every
    worker compiling them at once on its first run. The estimates are thrown away.
    """
    from sensing_antenna.estimation import conclude, gather
    from sensing_antenna.simulator import simulate

    cases = [case for case in spec.cases if case != "free"]
    if not cases:
        return
    (progress or Progress(enabled=False)).line(
        "preparation: compiling the methods on one manoeuvre of the device"
    )
    point = spec.contact_points[len(spec.contact_points) // 2]
    extra = with_device(spec, spec.scenario, spec.base_seed, preparation.device.link.length)
    scenario = make_scenario(cases[0], point, spec.base_seed, extra)
    recording = simulate(preparation.device, scenario).without_ground_truth()
    gathered = gather(recording, preparation.model)
    for method in spec.methods:
        conclude(gathered, method)


def prepare_antenna(spec: CampaignSpec) -> Antenna:
    """The antenna the estimators of every run use (:func:`prepare_campaign`'s model)."""
    return prepare_campaign(spec).model
