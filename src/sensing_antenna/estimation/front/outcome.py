"""What the front end hands on besides the :class:`~.evidence.Evidence`: an early outcome when it
stops before t_e, and the trace of what it saw (for figures).

- :class:`EarlyOutcome`: no estimate is possible (bad input, no contact, no push); the status,
  the reason, t_c and t_1 when known, the diagnostics.
- :class:`FrontTrace`: the front end's signals over every sample it was fed (the contact detector's
  residual, the filtered loads, Estimator 2's ratio), its instants and the contact frame. It rides
  on the evidence, the early outcome and the final
  :class:`~sensing_antenna.estimation.result.ContactEstimate`, is never compared and never written
  out: figures draw from it instead of computing anything again.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from sensing_antenna.estimation.front.contact_frame import ContactFrame
from sensing_antenna.estimation.result import ContactEstimate, Status

__all__ = ["EarlyOutcome", "FrontTrace"]

FloatArray = NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class FrontTrace:
    """The front end's signals over the n samples it was fed (all of a recording in batch).

    Attributes
    ----------
    t : array, shape (n,)
        Sample times (s).
    sample_period : float
        T_s (s).
    theta, force, torque : array, shape (n, 2), (n, 3), (n, 3)
        Samples (rad, N, N m; motor frame).
    estimated_torque : array, shape (n, 3)
        Gamma_e^m + Gamma_g^m of the contact detector (Eq. 15 and the weight) (N m).
    filtered_residual_norm : array, shape (n,)
        |low-pass(r^m)| of Eq. 16, zero while taring (N m).
    contact_threshold : float
        The detector's threshold on it (N m).
    contact_index, rest_index, end_index : int or None
        Samples of t_c, t_1 and t_e, None when not reached.
    load_offset : array, shape (6,)
        Sensor offset removed from the loads (N, N m); zero before t_c fixes it.
    reaction_f, torque_f : array, shape (n, 3)
        Eq. 20 filtered contact loads R = F - F_g^m and Gamma - Gamma_g^m, offset removed
        (N, N m).
    ratio : array, shape (n,)
        Estimator 2, x_c(t) (m); NaN everywhere before t_c (no offset yet).
    frame : ContactFrame or None
        Contact frame from the hold after t_1, None when the push was not judged or not found.
    spectrum : slice or None
        Samples of the Delta t_e1 window analysed by Estimator 1, None before t_e.
    band : tuple of float
        omega_1 search band (rad/s).
    """

    t: FloatArray
    sample_period: float
    theta: FloatArray
    force: FloatArray
    torque: FloatArray
    estimated_torque: FloatArray
    filtered_residual_norm: FloatArray
    contact_threshold: float
    contact_index: int | None
    rest_index: int | None
    end_index: int | None
    load_offset: FloatArray
    reaction_f: FloatArray
    torque_f: FloatArray
    ratio: FloatArray
    frame: ContactFrame | None
    spectrum: slice | None
    band: tuple[float, float]


@dataclass(frozen=True, eq=False)
class EarlyOutcome:
    """The front end stopped before t_e: there is no evidence to conclude from.

    Attributes
    ----------
    status : Status
        ``bad_input``, ``implausible_input``, ``no_contact``, ``recording_too_short`` (too few
        samples to hold a contact at all) or ``push_not_reached``.
    reason : str
        Why, in one sentence.
    t_c, t_1 : float
        Contact and push instants (s); NaN when not reached.
    diagnostics : Mapping
        What the front end knew (sampling report, rest tolerance, tare, load offset).
    trace : FrontTrace or None
        What the front end saw (not compared).
    """

    status: Status
    reason: str
    t_c: float = math.nan
    t_1: float = math.nan
    diagnostics: Mapping[str, Any] = field(default_factory=dict)
    trace: FrontTrace | None = field(default=None, repr=False)

    def estimate(self, method: str) -> ContactEstimate:
        """This outcome as the estimate of ``method`` (no contact point), the trace kept."""
        return ContactEstimate(
            status=self.status,
            reason=self.reason,
            method=method,
            t_c=self.t_c,
            t_1=self.t_1,
            diagnostics=dict(self.diagnostics),
            trace=self.trace,
        )
