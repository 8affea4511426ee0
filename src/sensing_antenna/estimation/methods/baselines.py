"""Baselines with the paper method's interface, for side-by-side comparison.

- ``ratio``: the torque/force ratio alone, Eq. 21 exactly as printed (filter F and Gamma, then
  subtract the gravity terms; divide by the full |F_f - F_g|), the estimator of the paper's
  reference [17], read at the same t_e as the paper method.
- ``two-frequency``: reference [22]: omega_1 and omega_2 from the spectrum, located on the
  (omega_1, omega_2) sensing curve by the nearest point in relative distance; a pair too far
  from the curve (``EstimatorConfig.max_curve_distance``, or three times what the frequency
  model's own uncertainty allows) is a ``model_mismatch``, and an answer that the model's
  uncertainty (at least the pair's distance from the curve; and, read in the push plane alone,
  the bent link's, ``Evidence.bent_link_uncertainty``, and a held contact's rise,
  :mod:`~sensing_antenna.estimation.methods.paper.held_contact`; read in both planes where the
  free plane's peak may be the push plane's leak, that rise when the force along the link rings
  in phase as a hold's) may move by more than ``max_model_spread`` at two standard deviations
  is ``uncertain``, as the paper method's candidate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.front.evidence import Evidence
from sensing_antenna.estimation.front.ratio import paper_ratio
from sensing_antenna.estimation.methods.paper.frequency import (
    evidence_frequency,
)
from sensing_antenna.estimation.methods.paper.fusion import (
    conclude,
    curve_allowance,
    held_contact_spread,
    pair_distance,
    second_mode_band,
    second_peak,
)
from sensing_antenna.estimation.methods.paper.planes import free_plane_mode, reading_plane
from sensing_antenna.estimation.result import ContactEstimate, Status

__all__ = ["RatioMethod", "TwoFrequencyMethod"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class RatioMethod:
    """Reference [17]: x_c from Eq. 21 alone at t_e."""

    name: str = "ratio"

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        """Eq. 21 as printed, read at t_e."""
        ratio = paper_ratio(
            evidence.theta,
            evidence.force,
            evidence.torque,
            evidence.antenna,
            evidence.config.lowpass_cutoff,
            evidence.sample_period,
            evidence.load_offset,
        )
        x_c = float(ratio[evidence.end_index])
        problems: list[tuple[Status, str]] = []
        spread = (
            2.0 * evidence.ratio_uncertainty(x_c, statics="small-deflection", coupling=True)
            if math.isfinite(x_c)
            else math.nan
        )
        if spread > evidence.config.max_model_spread:
            # the same bar as the paper method's candidate: 1 cm at two standard deviations
            problems.append((Status.UNCERTAIN, _uncertain_ratio(evidence, x_c, spread)))
        return conclude(
            evidence,
            self.name,
            x_c,
            ratio_estimate=x_c,
            problems=problems,
            diagnostics={"ratio_spread": spread},
        )


def _uncertain_ratio(evidence: Evidence, x_c: float, spread: float) -> str:
    """Why the ratio ``x_c`` (m) with ``spread`` (m, two standard deviations) is uncertain, and
    what would help: a push held longer, or a calibration of the sensor's cross-talk for the
    push's direction, which alone brings the spread within the bar when it is most of it; not
    when the scatter the sensor's calibration measured is beyond the bar on its own, which
    neither a push nor a rest narrows."""
    bar = evidence.config.max_model_spread
    leak = float(evidence.cross_talk_uncertainty(np.array(x_c))) > 0.0
    sensor = evidence.antenna.sensor
    scatter = 2.0 * sensor.ratio_scatter * min(max(x_c, 0.0), evidence.antenna.link.length)
    terms = "noise, tare, small-deflection model" + (", the sensor's cross-talk" if leak else "")
    if sensor.ratio_scatter > 0.0:
        terms += (
            f", the scatter of {100 * sensor.ratio_scatter:.2g} % of x_c the sensor's"
            f" calibration left ({100 * scatter:.1f} cm alone)"
        )
    calibrate = (
        f"calibrate the sensor's cross-talk on {' and '.join(sensor.unmeasured_sweeps)} sweeps "
        "too (antenna calibrate)"
        if sensor.ratio_scatter > 0.0
        else "calibrate the sensor's cross-talk (antenna calibrate)"
    )
    plain = 2.0 * evidence.ratio_uncertainty(x_c, statics="small-deflection")
    if scatter > bar:
        advice = (
            "no push or rest narrows that scatter; a method that reads the vibration (paper,"
            " fast) places the contact" + (f"; {calibrate}" if leak else "")
        )
    elif not leak:
        advice = "push harder or rest longer"
    elif plain <= bar:
        advice = f"{calibrate}, which leaves {100 * plain:.1f} cm"
    else:
        advice = f"push harder or rest longer, and {calibrate}"
    return (
        f"the torque/force ratio is uncertain by {100 * spread:.1f} cm at two standard "
        f"deviations ({terms}), more than {100 * bar:g} cm: {advice}"
    )


@dataclass(frozen=True)
class TwoFrequencyMethod:
    """Reference [22]: nearest point of the (omega_1, omega_2) curve to the two measured peaks."""

    name: str = "two-frequency"

    def conclude(self, evidence: Evidence) -> ContactEstimate:
        """Measure omega_1 and omega_2 and locate them on the curve."""
        cfg = evidence.config
        measurement = evidence_frequency(evidence)
        problems: list[tuple[Status, str]] = []
        diag: dict[str, Any] = {"torque_component": measurement.component}
        grid, omegas = evidence.contact_modes
        omega2 = math.nan
        x_c = math.nan
        if measurement.clear and measurement.component in ("y_c", "z_c", "sum"):
            peak2 = second_peak(evidence, measurement.component, measurement.omega1)
            if peak2 is not None:
                omega2 = peak2.omega
                diag["omega2_quality"] = peak2.quality
                # Nearest point of the (omega_1, omega_2) curve, relative distance
                k, distance = pair_distance(evidence, measurement.omega1, omega2)
                x_c = float(grid[k])
                diag["curve_distance"] = distance
                # read in the push plane alone: the free plane does not ring with it; or with a
                # free-plane peak that may be the push plane's leak, which a hold's stiffening
                # voids as corroboration (the planes as the paper method reads them)
                plane = reading_plane(measurement, cfg)
                diag["frequency_plane"] = plane
                push_plane = plane == "push"
                hold = 0.0
                if push_plane or (plane == "both" and free_plane_mode(measurement, cfg) is None):
                    hold = held_contact_spread(
                        evidence, measurement.omega1, x_c, diag, alone=push_plane
                    )[1]
                problems.extend(
                    _curve_problems(evidence, grid, omegas, k, distance, push_plane, hold)
                )
            else:
                low, high = second_mode_band(evidence, measurement.omega1)
                problems.append(
                    (
                        Status.NO_CLEAR_PEAK,
                        f"no clear second-mode peak in {low:.0f} to {high:.0f} rad/s",
                    )
                )
        else:
            problems.append((Status.NO_CLEAR_PEAK, "no clear fundamental peak"))
        diag["omega2"] = omega2
        return conclude(
            evidence,
            self.name,
            x_c,
            candidates=(x_c,) if math.isfinite(x_c) else (),
            omega1=measurement.omega1,
            peak_quality=measurement.quality,
            problems=problems,
            diagnostics=diag,
        )


def _curve_problems(
    evidence: Evidence,
    grid: NDArray[np.float64],
    omegas: NDArray[np.float64],
    k: int,
    distance: float,
    push_plane: bool,
    hold: float = 0.0,
) -> list[tuple[Status, str]]:
    """Why the two-frequency answer ``grid[k]`` (m), whose measured pair lies ``distance``
    (relative) from the curve ``omegas`` (rad/s, (n, 2)), is not to be trusted: off the curve
    by more than the model allows, or moved by the model's own uncertainty, by the bent link
    for frequencies read in the push plane alone (``push_plane``), and by a contact held along
    it (``hold``: how far (m) its rise of omega_1 may move the answer), as the paper method's
    candidate."""
    cfg = evidence.config
    x_c = float(grid[k])
    u = evidence.antenna.link.frequency_uncertainty
    problems: list[tuple[Status, str]] = []
    # the model's own error may put the pair off the curve by u in each frequency
    allowed = curve_allowance(evidence.antenna.link, cfg)
    if distance > allowed:
        problems.append(
            (
                Status.MODEL_MISMATCH,
                f"the measured omega_1 and omega_2 lie {100 * distance:.0f} % from the nearest "
                f"point of the sensing curves (at x_c = {x_c:.3f} m), more than "
                f"{100 * allowed:.2g} %: no contact point of the straight link rings so (a "
                "push that bent the link, or a device the model does not describe)",
            )
        )
    # every point of the curve whose two frequencies lie within 2 u of the answer's could be
    # the contact, for a model known to u (that of another branch too); a pair that lies
    # further from the curve shows the model off by at least that much on this manoeuvre, and
    # an error that large moves the answer as far
    off = distance > 2.0 * u
    near = np.all(np.abs(omegas / omegas[k] - 1.0) <= max(2.0 * u, distance), axis=1)
    spread = float(np.max(np.abs(grid[near] - x_c))) if np.any(near) else 0.0
    bent = 2.0 * evidence.bent_link_uncertainty(x_c) if push_plane else 0.0
    total = math.hypot(spread, bent, hold)
    if total > cfg.max_model_spread:
        model = (
            f"the pair's distance from the curves ({100 * distance:.2g} %, more than twice "
            f"the model's own uncertainty, {100 * u:.2g} % in each frequency, allows)"
            if off
            else f"the frequency model's own uncertainty ({100 * u:.2g} % of each frequency)"
        )
        problems.append(
            (
                Status.UNCERTAIN,
                f"{model} and the bent link (the curves are the straight link's"
                + (", and friction may hold the contact along it" if hold > 0.0 else "")
                + f") may move this answer by {100 * total:.1f} cm at two standard deviations, "
                f"more than {100 * cfg.max_model_spread:g} cm",
            )
        )
    return problems
