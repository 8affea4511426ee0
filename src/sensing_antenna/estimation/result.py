"""The result of a contact-point estimation: the number, how sure it is, and why.

A :class:`ContactEstimate` always carries an explicit :class:`Status`. Estimators never raise on
doubtful data: a doubtful case gets a status other than ``ok`` and a one-sentence ``reason``; the
best guess of ``x_c`` may still be given, but the status says why it is not to be trusted.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from sensing_antenna.estimation.front.outcome import FrontTrace

__all__ = ["STATUS_PRECEDENCE", "ContactEstimate", "Status"]


class Status(str, enum.Enum):  # noqa: UP042 (a StrEnum's str() would read "ok", not "Status.OK")
    """Outcome of an estimation (a ``str`` enum: ``Status.OK == "ok"``)."""

    #: Both estimators agree; the contact point is trustworthy.
    OK = "ok"
    #: No contact was detected in the samples.
    NO_CONTACT = "no_contact"
    #: Contact was detected but the head never came to rest pushing the object (no t_1).
    PUSH_NOT_REACHED = "push_not_reached"
    #: Estimator 1 found no spectral peak clearly above the noise in the allowed band.
    NO_CLEAR_PEAK = "no_clear_peak"
    #: The frequency candidates and the torque/force ratio disagree beyond tolerance.
    ESTIMATORS_DISAGREE = "estimators_disagree"
    #: Too few samples after t_1 for the spectrum or for the ratio to converge.
    RECORDING_TOO_SHORT = "recording_too_short"
    #: The contact force or the ratio drifts during the hold, or the deflection is too large.
    SLIP_SUSPECTED = "slip_suspected"
    #: The samples cannot be used at all (sampling too coarse, dead sensor channels, ...).
    BAD_INPUT = "bad_input"
    #: The recording is not in the format's units and signs by its own physics: the loads at
    #: rest are not the link's weight (mN, N mm, scaled, a sign flipped), the angles are not
    #: those of a head in radians, the free motion's torque is not what the angles predict, or
    #: the torque/force ratio is more than 30 times from where the vibration puts the contact.
    IMPLAUSIBLE_INPUT = "implausible_input"
    #: The evidence does not fit the physics of a contact: the answer lies outside the link
    #: (0, l], or the torque/force ratio or the answer is a factor (1.5 to 30) away from where
    #: the measured vibration puts the contact.
    MODEL_MISMATCH = "model_mismatch"
    #: The method's interval never became narrower than the requested tolerance before its cap
    #: (``fast`` method); x_c is the best estimate at the cap.
    UNCERTAIN = "uncertain"

    def __str__(self) -> str:
        return self.value


#: When several problems are found, the first one in this order is the status.
STATUS_PRECEDENCE: tuple[Status, ...] = (
    Status.BAD_INPUT,
    Status.IMPLAUSIBLE_INPUT,
    Status.NO_CONTACT,
    Status.PUSH_NOT_REACHED,
    Status.RECORDING_TOO_SHORT,
    Status.SLIP_SUSPECTED,
    Status.NO_CLEAR_PEAK,
    Status.MODEL_MISMATCH,
    Status.ESTIMATORS_DISAGREE,
    Status.UNCERTAIN,
    Status.OK,
)


def _json_value(value: Any) -> Any:
    """Convert numpy scalars/arrays, enums and non-finite floats to JSON-able values."""
    if isinstance(value, enum.Enum):
        return value.value
    if isinstance(value, Mapping):
        return {str(k): _json_value(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_value(v) for v in value]
    if isinstance(value, np.ndarray):
        return [_json_value(v) for v in value.tolist()]
    if isinstance(value, (np.floating, float)):
        number = float(value)
        return number if math.isfinite(number) else None
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (np.bool_,)):
        return bool(value)
    return value


@dataclass(frozen=True)
class ContactEstimate:
    """Estimated contact point with its status and diagnostics.

    Attributes
    ----------
    status : Status
        Outcome; anything other than ``Status.OK`` means "do not trust x_c blindly".
    reason : str or None
        One sentence explaining a status other than ``ok`` (None when ok).
    method : str
        Name of the method that produced the estimate (``"paper"``, ``"ratio"``, ...).
    x_c : float
        Estimated contact point along the link (m), within (0, l] whatever the status (the
        pipeline drops a best guess outside the link and says so in the reason); NaN when
        there is no guess.
    candidates : tuple of float
        Contact points compatible with the measured fundamental frequency (m), ascending.
    omega1 : float
        Measured fundamental frequency in contact (rad/s); NaN if not measured.
    peak_quality : float
        Peak-to-median power ratio of the spectral peak (dimensionless); NaN if not measured.
    ratio_estimate : float
        Torque/force ratio estimate of Estimator 2 at t_e (m); NaN if not available.
    t_c : float
        Contact instant (s); NaN if no contact.
    t_1 : float
        Instant the head came to rest pushing the object (s); NaN if not reached.
    t_e : float
        Instant the estimate became available (s); NaN if never.
    contact_point : numpy.ndarray
        Touched point in the absolute frame, shape (3,) (m); NaN if unknown.
    interval : tuple of float or None
        95 % interval (low, high) of x_c (m) from methods that give one (``fast``), else None.
    branch_probability : tuple of float or None
        Posterior probability of each candidate's branch of the sensing curve, aligned with
        ``candidates``, from methods that give one (``fast``), else None.
    diagnostics : Mapping
        Everything else worth knowing (sampling report, torque component used, frame axes, ...).
    trace : FrontTrace or None
        What the front end saw (signals, instants, frame), for figures; not compared by ``==``
        and not in :meth:`to_dict`.
    """

    status: Status
    reason: str | None
    method: str
    x_c: float = math.nan
    candidates: tuple[float, ...] = ()
    omega1: float = math.nan
    peak_quality: float = math.nan
    ratio_estimate: float = math.nan
    t_c: float = math.nan
    t_1: float = math.nan
    t_e: float = math.nan
    contact_point: np.ndarray = field(default_factory=lambda: np.full(3, np.nan))
    diagnostics: Mapping[str, Any] = field(default_factory=dict)
    interval: tuple[float, float] | None = None
    branch_probability: tuple[float, ...] | None = None
    trace: FrontTrace | None = field(default=None, compare=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "status", Status(self.status))
        point = np.array(self.contact_point, dtype=float).reshape(3)
        point.setflags(write=False)
        object.__setattr__(self, "contact_point", point)
        object.__setattr__(self, "candidates", tuple(float(c) for c in self.candidates))
        if self.status is Status.OK and self.reason is not None:
            raise ValueError("an ok estimate has no reason")
        if self.status is not Status.OK and not self.reason:
            raise ValueError(f"status {self.status.value} needs a reason")

    @property
    def ok(self) -> bool:
        """True when the status is ``ok``."""
        return self.status is Status.OK

    @property
    def held_back_by_width(self) -> bool:
        """True when an ``uncertain`` estimate's one fault is its 95 % interval's width: every
        check passed, and the interval (wider than the method's tolerance, one spread: not x_c
        near one of two points) is what is known of x_c; a map may take its point with that
        spread (``fast`` method)."""
        return bool(
            self.status is Status.UNCERTAIN
            and self.interval is not None
            and self.diagnostics.get("held_back_by_width", False)
            and not self.diagnostics.get("other_reasons")
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-able dictionary (SI units; NaN becomes None)."""
        return {
            "method": self.method,
            "status": self.status.value,
            "reason": self.reason,
            "x_c": _json_value(self.x_c),
            "candidates": _json_value(self.candidates),
            "omega1": _json_value(self.omega1),
            "peak_quality": _json_value(self.peak_quality),
            "ratio_estimate": _json_value(self.ratio_estimate),
            "t_c": _json_value(self.t_c),
            "t_1": _json_value(self.t_1),
            "t_e": _json_value(self.t_e),
            "contact_point": _json_value(self.contact_point),
            "interval": _json_value(self.interval),
            "branch_probability": _json_value(self.branch_probability),
            "diagnostics": _json_value(self.diagnostics),
        }
