"""The two bending planes as independent evidence of omega_1.

The straight link's model (Eq. 3 and 4) has the contact pin the link in both planes through its
axis, so the torque about Y^c (vibration out of the push plane, the "free" plane) and about Z^c
(vibration in the push plane) ring at the same omega_1. A push that bends the link breaks this
in the push plane only: on a bent link, a contact that friction holds along the obstacle's
surface adds a constraint the straight link's pin does not have (the contact may not slide
along the chord while the link vibrates in the bent plane, which stiffens the mode), and the
reaction's share along the bent axis adds a tension; both raise the push plane's frequency.
Out of the push plane the same contact is the model's pin, held by friction: where friction
cannot hold it the free plane's frequency falls instead. So two clear peaks that differ by more
than ``component_agreement`` say that the model does not hold in one of the planes, and only
other evidence can say which (docs/estimation.md, "The two bending planes"):

- the torque/force ratio, when it is precise enough to tell the two planes' candidates apart
  (``ratio_resolution_sigmas`` of its uncertainty), chooses the plane;
- otherwise the answer is ``uncertain``.

A frequency read in the push plane alone (the free plane silent) carries the bent link's
uncertainty (:meth:`~sensing_antenna.estimation.front.evidence.Evidence.bent_link_uncertainty`)
into the status at two standard deviations, and the rise a contact friction holds along the
link may make (:mod:`~sensing_antenna.estimation.methods.paper.held_contact`); one
corroborated by a peak at the same frequency in the free plane, clear or at least half as clear
as a peak must be on its own, carries the first as the bound of a shift (the plausibility
layer): on a bent link the push plane's mode leaks into the free plane's component (the sag
tilts the planes), so the two can agree on the push plane's frequency. Where the free plane's
peak may be such a leak (no free plane's own mode, below), a force along the link that rings
in phase as a hold's voids the agreement, and the hold's rise is carried as when read alone.

The free plane's own mode is known when its clear peak cannot be such a leak
(:func:`free_plane_mode`): no peak of the push plane lies within the Hann window's main lobe of
it, or the one there has less power (a leak is weaker than its source). Where a push plane's
peak lies within the lobe, the two may be merged in the free plane's component, and their
distance counts in the frequency's uncertainty. A frequency of that mode is held by the free
plane's own bound (:func:`~sensing_antenna.beam.free_plane.free_plane_shift`), not by the bent
link's.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.methods.paper.frequency import FrequencyMeasurement, SpectralPeak
from sensing_antenna.estimation.result import Status

__all__ = ["PLANES", "bending_planes", "free_plane_mode", "planes_agree", "reading_plane"]

#: Torque component of each bending plane: about Y^c the vibration out of the push plane
#: ("free"), about Z^c the vibration in it ("push").
PLANES = {"free": "y_c", "push": "z_c"}


def _nearest(candidates: tuple[float, ...], ratio_estimate: float) -> float:
    """The candidate nearest to the ratio estimate (m); NaN without candidates or ratio."""
    if not candidates or not math.isfinite(ratio_estimate):
        return math.nan
    return min(candidates, key=lambda x: abs(x - ratio_estimate))


def bending_planes(
    measurement: FrequencyMeasurement,
    locate: Callable[[float], tuple[float, ...]],
    ratio_estimate: float,
    sigma_ratio: float,
    config: EstimatorConfig,
    diagnostics: dict[str, Any],
) -> tuple[FrequencyMeasurement, tuple[Status, str] | None]:
    """The measurement to invert, judged on both bending planes, and a problem if any.

    Parameters
    ----------
    measurement : FrequencyMeasurement
        Estimator 1's clearest peak, with the peak of each plane in ``peaks``.
    locate : callable
        omega_1 (rad/s) to the contact points of the sensing curve (m).
    ratio_estimate, sigma_ratio : float
        The torque/force ratio's estimate and standard uncertainty (m).
    config : EstimatorConfig
    diagnostics : dict
        Receives ``frequency_plane`` ("free", "push" or "both"), ``free_plane_mode``
        (:func:`free_plane_mode`) and, when the planes disagree, ``plane_candidates`` and
        ``plane_chosen_by``.

    Returns
    -------
    measurement : FrequencyMeasurement
        The given one, or the same with the plane the ratio chose.
    problem : (Status, str) or None
        ``uncertain`` when the planes disagree and the ratio cannot tell which holds.
    """
    peaks: dict[str, SpectralPeak | None] = {
        plane: measurement.peaks.get(component) for plane, component in PLANES.items()
    }
    clear = {
        plane: peak is not None and peak.quality >= config.min_peak_quality
        for plane, peak in peaks.items()
    }
    agree = measurement.components_agree(config.component_agreement)
    if not measurement.clear:
        return measurement, None
    diagnostics["free_plane_mode"] = free_plane_mode(measurement, config)
    if clear["free"] and clear["push"] and not agree:
        return _disagreeing(
            measurement, peaks, locate, ratio_estimate, sigma_ratio, config, diagnostics
        )
    diagnostics["frequency_plane"] = reading_plane(measurement, config)
    return measurement, None


def reading_plane(measurement: FrequencyMeasurement, config: EstimatorConfig) -> str:
    """The plane omega_1 was read in: "both" where the planes agree (:func:`planes_agree`),
    "free" from the torque about Y^c, or from the summed spectra with a clear free-plane peak,
    else "push" (the push plane alone, the free plane silent)."""
    if planes_agree(measurement, config):
        return "both"
    free = measurement.peaks.get(PLANES["free"])
    free_clear = free is not None and free.quality >= config.min_peak_quality
    if measurement.component == PLANES["free"] or (measurement.component == "sum" and free_clear):
        return "free"
    return "push"


def free_plane_mode(
    measurement: FrequencyMeasurement, config: EstimatorConfig
) -> dict[str, float] | None:
    """The free plane's own mode, or None: ``omega`` (rad/s), its clear peak in the torque about
    Y^c, and ``separation``, the relative distance to the push plane's peak when that lies within
    the Hann window's main lobe (4 pi / T_w rad/s) and may be merged with it (0 beyond, or when
    that peak is not even half as clear as a peak must be: noise). None without a clear
    free-plane peak, or with a push-plane peak within the lobe of more power (both components
    are torques, N m; the two bands' median powers differ, so their qualities do not compare):
    the free plane's peak may then be the push plane's mode leaking into its component."""
    free = measurement.peaks.get(PLANES["free"])
    push = measurement.peaks.get(PLANES["push"])
    if free is None or not free.quality >= config.min_peak_quality:
        return None
    window = measurement.t_end - measurement.t_start
    lobe = 4.0 * math.pi / window if window > 0 else math.inf
    separation = 0.0
    if push is not None and abs(push.omega - free.omega) < lobe:
        if not push.power <= free.power:
            return None
        if push.quality >= 0.5 * config.min_peak_quality:
            separation = abs(push.omega - free.omega) / free.omega
    return {"omega": free.omega, "separation": separation}


def planes_agree(measurement: FrequencyMeasurement, config: EstimatorConfig) -> bool:
    """True when both bending planes ring at the same omega_1: within ``component_agreement``,
    each peak at least half as clear as a peak must be on its own (a noise bin reaches 10 times
    the median with probability 1e-3, and must also fall within the agreement)."""
    weakest = min(
        (peak.quality if peak is not None else 0.0)
        for peak in (measurement.peaks.get(component) for component in PLANES.values())
    )
    return bool(
        measurement.components_agree(config.component_agreement)
        and weakest >= 0.5 * config.min_peak_quality
    )


def _disagreeing(
    measurement: FrequencyMeasurement,
    peaks: dict[str, SpectralPeak | None],
    locate: Callable[[float], tuple[float, ...]],
    ratio_estimate: float,
    sigma_ratio: float,
    config: EstimatorConfig,
    diagnostics: dict[str, Any],
) -> tuple[FrequencyMeasurement, tuple[Status, str] | None]:
    """Both planes ring clearly and apart: the plane the ratio tells, or ``uncertain``."""
    free, push = peaks["free"], peaks["push"]
    assert free is not None and push is not None
    nearest = {
        "free": _nearest(locate(free.omega), ratio_estimate),
        "push": _nearest(locate(push.omega), ratio_estimate),
    }
    diagnostics["plane_candidates"] = nearest
    distance = {plane: abs(x - ratio_estimate) for plane, x in nearest.items()}
    margin = abs(distance["free"] - distance["push"])
    if math.isfinite(margin) and margin >= config.ratio_resolution_sigmas * sigma_ratio:
        plane = min(distance, key=distance.__getitem__)
        peak = free if plane == "free" else push
        diagnostics["frequency_plane"] = plane
        diagnostics["plane_chosen_by"] = "ratio"
        chosen = dataclasses.replace(
            measurement, omega1=peak.omega, quality=peak.quality, component=PLANES[plane]
        )
        return chosen, None
    diagnostics["frequency_plane"] = "free" if measurement.component == PLANES["free"] else "push"
    diagnostics["plane_chosen_by"] = None
    return measurement, (
        Status.UNCERTAIN,
        f"the two bending planes ring apart ({free.omega:.1f} rad/s out of the push plane, "
        f"{push.omega:.1f} rad/s in it: contact at {nearest['free']:.3f} or "
        f"{nearest['push']:.3f} m), where the straight link's model has one omega_1; the "
        f"bent link's preload raises the push plane's, a contact friction does not hold "
        f"lowers the other's, and the torque/force ratio ({ratio_estimate:.3f} m, "
        f"+-{sigma_ratio:.3f} m) cannot tell which",
    )
