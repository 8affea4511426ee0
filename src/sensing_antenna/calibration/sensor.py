"""Calibration of the F/T sensor's cross-talk into the lateral forces, from known contacts.

The torque/force ratio reads the contact point from the push's moment over its force. On an
antenna the moments are large and the lateral forces small, so a sensor's cross-talk from its
torque channels into its force channels (a per cent of full scale, as much as the push) scales
the ratio as r = g x / (1 + k x), g and k fixed for the sensor. Contacts at known points x_i
(the recordings of the frequency calibration) pin that down: the lateral force corrected by
:class:`~sensing_antenna.antenna.SensorCorrection`,

    R_y' = fy_gain R_y + fy_per_ty Gamma_y + fy_per_tz Gamma_z   (and R_z' alike),

is fitted so that (1) the elastica statics of the corrected push give x_i
(:func:`~sensing_antenna.estimation.front.ratio.perpendicular_ratio`, relative residual), and
(2) the push lies in the plane the head swept in (an azimuthal sweep pushes along Y^m: the
corrected R_z' / R_y' is zero; a vertical sweep the other way round), by
``scipy.optimize.least_squares`` with a soft-L1 loss (a recording whose push was disturbed does
not pull the fit), started from no correction and from the small-deflection statics' solution
in closed form, the lower loss kept: a cross-talk that nearly cancels the push's force near
the tip puts the ratio there many times off, and from no correction alone the loss can fall
more by shrinking every ratio than by undoing the leak. The loads are
the hold's mean (the window the contact frame uses, tared by the contact-free offset). A sweep
about the azimuth fixes fy_gain, fy_per_tz and fz_per_tz; one about the elevation fz_gain,
fz_per_ty and fy_per_ty; terms no recording fixes stay at no correction. The antenna's
frequency model (T_e) should be calibrated first: the statics use its stiffness.

A sweep direction's terms are adopted only when they predict contacts they were not fitted to:
each recording is left out in turn, the terms fitted to the others, and the left-out ratio's
error with that fit compared with its error uncorrected, over the direction's recordings. Five
contacts of one sweep direction on a sensor without cross-talk leave the ratio several per cent
off for other reasons (the sensor's noise at a gentle push, the statics' model); two terms
fitted to that fit it on those contacts and lengthen the ratio elsewhere. A direction whose
held-out error with the terms is not below its error without them keeps no correction (the
others are fitted again without its terms). With :data:`MIN_SENSOR_RECORDINGS` recordings of a
direction, each held-out fit has one fewer than a fit needs, which leans towards refusing. The
ratio's relative scatter about the known points left with the terms adopted is kept as
``ratio_scatter``, a floor of the ratio's model uncertainty; a sweep direction without
recordings enough is kept in ``unmeasured_sweeps``, so that pushes that way keep the sensor's
nominal cross-talk uncertainty.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from sensing_antenna.antenna import (
    MAX_SENSOR_COUPLING,
    MAX_SENSOR_GAIN_ERROR,
    SENSOR_SWEEPS,
    Antenna,
    SensorCorrection,
)
from sensing_antenna.calibration.frequency import points_on_link
from sensing_antenna.errors import SensingAntennaError

__all__ = [
    "MIN_SENSOR_RECORDINGS",
    "SensorCalibration",
    "SensorCalibrationError",
    "calibrate_sensor",
]

FloatArray = NDArray[np.float64]

#: Recordings of one sweep direction needed to fit its three terms.
MIN_SENSOR_RECORDINGS = 4

#: The fitted terms of each sweep: azimuthal sweeps push along Y^m, vertical along Z^m.
_PLANE_TERMS = {
    "azimuthal": ("fy_gain", "fy_per_tz", "fz_per_tz"),
    "vertical": ("fz_gain", "fz_per_ty", "fy_per_ty"),
}

#: Scale of the soft-L1 loss on the residuals (relative ratio error and the push's out-of-plane
#: slope, both dimensionless): beyond 10 % a residual counts linearly.
_LOSS_SCALE = 0.1


class SensorCalibrationError(SensingAntennaError, ValueError):
    """The recordings cannot calibrate the sensor (too few usable ones)."""


@dataclass(frozen=True)
class SensorCalibration:
    """The fitted sensor correction and what it did.

    Attributes
    ----------
    correction : SensorCorrection
    sweeps : tuple of str
        The sweep directions fitted ("azimuthal", "vertical").
    sources : tuple of str
        The recordings used.
    notes : tuple of str
        Recordings left out and why.
    ratio_rms_before, ratio_rms_after : float
        RMS relative error of the hold's torque/force ratio against the known points, without
        and with the correction written (dimensionless).
    ratio_rms_held_out : float
        The same with each recording corrected by every direction's terms fitted to the others
        (the test that adopts them).
    adopted : tuple of str
        The sweep directions whose terms are kept: those whose recordings' held-out error is
        below their error without correction. The others' terms are no correction; with none
        adopted, ``correction`` is no correction, its ``ratio_scatter`` the uncorrected ratio's.
    """

    correction: SensorCorrection
    sweeps: tuple[str, ...]
    sources: tuple[str, ...]
    notes: tuple[str, ...]
    ratio_rms_before: float
    ratio_rms_after: float
    ratio_rms_held_out: float
    adopted: tuple[str, ...]

    def apply(self, antenna: Antenna) -> Antenna:
        """``antenna`` with this correction."""
        return replace(antenna, sensor=self.correction)

    @property
    def ratio_summary(self) -> str:
        """The ratio's error against the known points without and with the correction, and
        whether it was adopted."""
        summary = (
            f"torque/force ratio against the known points {100 * self.ratio_rms_before:.1f} % "
            f"rms before, {100 * self.ratio_rms_after:.1f} % after, "
            f"{100 * self.ratio_rms_held_out:.1f} % on each left out of the fit"
        )
        if self.adopted == self.sweeps:
            return summary
        refused = ", ".join(s for s in self.sweeps if s not in self.adopted)
        kept = f"adopted for the {', '.join(self.adopted)} sweeps; " if self.adopted else ""
        return (
            f"{summary}: {kept}not adopted for the {refused} sweeps, whose contacts left out of "
            "the fit it does not predict better than no correction (no cross-talk they can "
            "tell)"
        )


@dataclass(frozen=True)
class _Hold:
    sweep: str
    x_c: float
    reaction: FloatArray  # (3,) N, uncorrected
    moment: FloatArray  # (3,) N m
    theta2: float  # rad, the link's elevation


def calibrate_sensor(
    recordings: Sequence[Any],
    antenna: Antenna,
    contact_points: Sequence[float],
    *,
    sources: Sequence[str] = (),
) -> SensorCalibration:
    """Fit the sensor's cross-talk correction to contacts at known points (module docstring).

    Parameters
    ----------
    recordings : sequence of Recording
        Contact manoeuvres (azimuthal or vertical sweeps), ground truth not read.
    antenna : Antenna
        The model, its frequency model calibrated; its own ``sensor`` is replaced.
    contact_points : sequence of float
        Known x_c (m) of each recording.

    Raises
    ------
    SensorCalibrationError
        When no sweep direction has :data:`MIN_SENSOR_RECORDINGS` usable recordings.
    """

    if len(recordings) != len(contact_points):
        raise SensorCalibrationError(
            f"contact points: {len(contact_points)} given for {len(recordings)} recordings"
        )
    plain = replace(antenna, sensor=SensorCorrection())
    names = list(sources) or [f"recording {i}" for i in range(len(recordings))]
    points_in, on_link, notes = points_on_link(
        np.asarray(contact_points, dtype=float), antenna.link.length, names
    )
    holds: list[_Hold] = []
    used: list[str] = []
    for name, recording, x_c, on in zip(names, recordings, points_in, on_link, strict=True):
        if not on:
            continue  # named in the notes
        hold = _hold(recording, plain, float(x_c))
        if isinstance(hold, str):
            notes.append(f"{name}: {hold}")
        else:
            holds.append(hold)
            used.append(name)
    return _fit(holds, used, notes, antenna)


def _fit(
    holds: list[_Hold], used: list[str], notes: list[str], antenna: Antenna
) -> SensorCalibration:
    """:func:`calibrate_sensor` on the holds read (``used``: their recordings' names; ``notes``:
    why the others were left out)."""
    from sensing_antenna.estimation.front.ratio import perpendicular_ratio

    sweeps = tuple(
        s for s in _PLANE_TERMS if sum(h.sweep == s for h in holds) >= MIN_SENSOR_RECORDINGS
    )
    if not sweeps:
        raise SensorCalibrationError(
            f"{len(holds)} usable recording(s): each sweep direction needs "
            f"{MIN_SENSOR_RECORDINGS} to fit the sensor"
            + (f" ({'; '.join(notes)})" if notes else "")
        )
    kept = [(h, n) for h, n in zip(holds, used, strict=True) if h.sweep in sweeps]
    holds = [h for h, _ in kept]
    terms = _terms(sweeps)
    reaction = np.array([h.reaction for h in holds])
    elevation = np.array([h.theta2 for h in holds])
    moment = np.array([h.moment for h in holds])
    points = np.array([h.x_c for h in holds])
    lateral = np.array([SENSOR_SWEEPS[h.sweep] for h in holds])
    rows = np.arange(len(holds))

    def correction(params: FloatArray, names: Sequence[str]) -> SensorCorrection:
        terms: dict[str, Any] = dict(zip(names, (float(p) for p in params), strict=True))
        return SensorCorrection(**terms)

    def residuals(
        params: FloatArray, names: Sequence[str], keep: NDArray[np.bool_] | None = None
    ) -> FloatArray:
        """The ratio's relative errors, then the pushes' out-of-plane slopes, of the holds in
        ``keep`` (all when None), with the terms ``names`` at ``params``."""
        chosen = rows if keep is None else rows[keep]
        corrected = correction(params, names).correct(reaction[chosen], moment[chosen])
        ratio = perpendicular_ratio(corrected, moment[chosen], antenna.link, elevation[chosen])
        along = corrected[np.arange(chosen.size), lateral[chosen]]
        across = corrected[np.arange(chosen.size), 3 - lateral[chosen]]
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = np.where(np.abs(along) > 0, across / np.abs(along), 1.0)
        return np.concatenate([ratio / points[chosen] - 1.0, slope])

    def identity(names: Sequence[str]) -> FloatArray:
        """The terms ``names`` at no correction."""
        return np.array([getattr(SensorCorrection(), t) for t in names], dtype=float)

    def fitted(names: Sequence[str], keep: NDArray[np.bool_] | None = None) -> FloatArray:
        # within the limits a SensorCorrection accepts (gains in (0, 2), couplings to +-100)
        gain = [t.endswith("_gain") for t in names]
        low = np.where(gain, 1.0 - 0.99 * MAX_SENSOR_GAIN_ERROR, -MAX_SENSOR_COUPLING)
        high = np.where(gain, 1.0 + 0.99 * MAX_SENSOR_GAIN_ERROR, MAX_SENSOR_COUPLING)
        chosen = rows if keep is None else rows[keep]
        linear = _linear_start(
            names, reaction[chosen], moment[chosen], points[chosen], lateral[chosen]
        )
        # from no correction and from the linear statics' solution: a cross-talk that nearly
        # cancels the force near the tip puts the ratio several times off there, and from no
        # correction the loss can fall more by shrinking every ratio than by undoing it
        best: Any = None
        for start in (identity(names), np.clip(linear, low, high)):
            found = least_squares(
                lambda params: residuals(params, names, keep),
                start,
                bounds=(low, high),
                loss="soft_l1",
                f_scale=_LOSS_SCALE,
            )
            if best is None or found.cost < best.cost:
                best = found
        return np.asarray(best.x, dtype=float)

    held_out = np.array(
        [residuals(fitted(terms, rows != i), terms, rows == i)[0] for i in range(len(holds))],
        dtype=float,
    )
    worst = _gross_outlier(held_out)
    if worst is not None:
        # one recording no correction of the others' predicts: its loads, not the sensor's leak
        name = kept[worst][1]
        note = (
            f"{name}: its torque/force ratio is {1.0 + held_out[worst]:.3g} times its known point"
            " with the correction fitted to the others, which put theirs within"
            f" {100 * float(np.nanmedian(np.abs(np.delete(held_out, worst)))):.2g} % (median):"
            " loads on another scale than the others'?"
        )
        others = [k for k in range(len(kept)) if k != worst]
        return _fit(
            [kept[k][0] for k in others], [kept[k][1] for k in others], [*notes, note], antenna
        )
    before = residuals(identity(terms), terms)[: len(holds)]
    params = fitted(terms)
    # each sweep direction's terms are kept when they predict its holds left out of the fit
    # better than no correction
    direction = np.array([h.sweep for h in holds])
    adopted = tuple(
        s for s in sweeps if _rms(held_out[direction == s]) < _rms(before[direction == s])
    )
    names = _terms(adopted)
    if adopted != sweeps:  # none adopted: no terms, no correction
        params = fitted(names) if names else identity(names)
    left = residuals(params, names)[: len(holds)]
    # the ratio's scatter left, over the degrees of freedom the fitted in-plane terms leave
    # (two per sweep direction adopted)
    finite = left[np.isfinite(left)]
    dof = max(finite.size - 2 * len(adopted), 1)
    scatter = min(math.sqrt(float(np.sum(finite**2)) / dof), 1.0)
    return SensorCalibration(
        correction=replace(
            correction(params, names),
            ratio_scatter=scatter,
            nominal_coupling=antenna.sensor.nominal_coupling,  # the sensor's stated figure
            # pushes the other way read terms these contacts did not measure
            unmeasured_sweeps=tuple(s for s in SENSOR_SWEEPS if s not in sweeps),
        ),
        sweeps=sweeps,
        sources=tuple(n for _, n in kept),
        notes=tuple(notes),
        ratio_rms_before=_rms(before),
        ratio_rms_after=_rms(left),
        ratio_rms_held_out=_rms(held_out),
        adopted=adopted,
    )


#: A recording whose held-out ratio error is beyond this (relative: its ratio twice its known
#: point, or on the wrong side of the base) and :data:`OUTLIER_FACTOR` times the others' median
#: is one no leak explains (:func:`_gross_outlier`).
GROSS_RATIO_ERROR = 1.0
#: How many times the others' median held-out error such a recording's is: the others' own
#: held-out predictions carry its pull on their fits (a member with its forces in lbf, 3.3 against
#: a median of 0.37 in a set of five).
OUTLIER_FACTOR = 3.0


def _gross_outlier(held_out: FloatArray) -> int | None:
    """The hold whose held-out relative ratio error is beyond :data:`GROSS_RATIO_ERROR` and
    :data:`OUTLIER_FACTOR` times the others' median, or None: a file whose loads are on another
    scale (a torque in N dm among N m), which would otherwise pull the correction and its
    scatter."""
    errors = np.abs(held_out)
    if errors.size < 3 or not np.any(np.isfinite(errors)):
        return None
    worst = int(np.nanargmax(np.where(np.isfinite(errors), errors, -np.inf)))
    others = float(np.nanmedian(np.delete(errors, worst)))
    return worst if errors[worst] > max(GROSS_RATIO_ERROR, OUTLIER_FACTOR * others) else None


def _linear_start(
    names: Sequence[str],
    reaction: FloatArray,
    moment: FloatArray,
    points: FloatArray,
    lateral: NDArray[np.int_],
) -> FloatArray:
    """The terms ``names`` that the small-deflection statics give in closed form, shape
    (len(names),): each push's corrected force along its sweep equal to its moment over its
    known x_c (R_y' = Gamma_z / x_i for an azimuthal sweep, R_z' = -Gamma_y / x_i for a vertical
    one, the signs of ``perpendicular_ratio``'s moment in the bending plane) and its force
    across the sweep zero, each a linear least-squares fit of its own terms, twice round (the
    planes share small cross terms). Each push's along-sweep equation is weighted by x_i over
    its moment, so that it counts by its relative ratio error, as the fit does."""
    current = dict(zip(names, (getattr(SensorCorrection(), t) for t in names), strict=True))

    def term(force: str, torque: str | None = None) -> float:
        """The current value of f{force}_gain, or of f{force}_per_t{torque}."""
        name = f"f{force}_gain" if torque is None else f"f{force}_per_t{torque}"
        return current.get(name, getattr(SensorCorrection(), name))

    axis = {"y": 1, "z": 2}
    for _ in range(2):
        for sweep, (gain, along, across) in _PLANE_TERMS.items():
            if gain not in current:
                continue
            # the force along the sweep, and the axis of its moment, which is also the force
            # across it: an azimuthal sweep pushes along Y^m about Z^m, a vertical one the
            # other way round
            f, m = ("y", "z") if sweep == "azimuthal" else ("z", "y")
            rows = lateral == axis[f]
            r, g = reaction[rows], moment[rows]
            r_f, r_m, g_f, g_m = r[:, axis[f]], r[:, axis[m]], g[:, axis[f]], g[:, axis[m]]
            # along: gain R_f + along Gamma_m + f_per_t{f} Gamma_f = +-Gamma_m / x_i
            sign = 1.0 if f == "y" else -1.0
            target = sign * g_m / points[rows] - term(f, f) * g_f
            with np.errstate(divide="ignore"):
                weight = np.where(g_m != 0.0, points[rows] / np.abs(g_m), 0.0)
            design = np.column_stack([r_f, g_m]) * weight[:, None]
            solution, *_ = np.linalg.lstsq(design, target * weight, rcond=None)
            current[gain], current[along] = (float(v) for v in solution)
            # across: m_gain R_m + m_per_t{f} Gamma_f + across Gamma_m = 0
            rest = term(m) * r_m + term(m, f) * g_f
            denominator = float(g_m @ g_m)
            if denominator > 0.0:
                current[across] = -float(rest @ g_m) / denominator
    return np.array([current[t] for t in names], dtype=float)


def _terms(sweeps: Sequence[str]) -> list[str]:
    """The correction's terms the sweep directions ``sweeps`` fix, in order."""
    return [t for s in sweeps for t in _PLANE_TERMS[s]]


def _rms(values: FloatArray) -> float:
    finite = values[np.isfinite(values)]
    return float(np.sqrt(np.mean(finite**2))) if finite.size else math.nan


def _hold(recording: Any, antenna: Antenna, x_c: float) -> _Hold | str:
    """The hold's mean tared loads of one contact manoeuvre, or why it cannot be used."""
    from sensing_antenna.calibration.usable import contact_evidence
    from sensing_antenna.estimation.front.ratio import contact_loads
    from sensing_antenna.estimation.front.steps import hold_window

    evidence = contact_evidence(recording, antenna)
    if isinstance(evidence, str):
        return evidence
    hold = hold_window(
        evidence.rest_index, evidence.theta.shape[0], evidence.config, evidence.sample_period
    )
    reaction, moment = contact_loads(
        evidence.theta[hold], evidence.force[hold], evidence.torque[hold], antenna
    )
    offset = evidence.load_offset
    before = evidence.theta[: evidence.contact_index + 1]
    span = np.ptp(before, axis=0) if before.shape[0] else np.zeros(2)
    sweep = "azimuthal" if span[0] >= span[1] else "vertical"
    return _Hold(
        sweep=sweep,
        x_c=x_c,
        reaction=(reaction - offset[:3]).mean(axis=0),
        moment=(moment - offset[3:]).mean(axis=0),
        theta2=float(evidence.theta[hold, 1].mean()),
    )
