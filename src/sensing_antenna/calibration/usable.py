"""Whether a contact manoeuvre can calibrate the antenna: the checks the estimators make of their
input, asked before a recording's frequency or loads enter a fit."""

from __future__ import annotations

from typing import TYPE_CHECKING

from sensing_antenna.estimation.result import Status

if TYPE_CHECKING:
    from sensing_antenna.antenna import Antenna
    from sensing_antenna.estimation.front.evidence import Evidence
    from sensing_antenna.recording import Recording

__all__ = ["INPUT_FAULTS", "contact_evidence"]

#: Statuses that blame a recording's samples, not the model a calibration corrects: a
#: recording an estimate would refuse for one of them calibrates nothing. The model's own
#: statuses (a frequency off the curve, estimators that disagree, an uncertain answer) are
#: what calibration is for, and slip is judged on the known point (``points_on_link``).
INPUT_FAULTS = frozenset(
    {
        Status.BAD_INPUT,
        Status.IMPLAUSIBLE_INPUT,
        Status.NO_CONTACT,
        Status.PUSH_NOT_REACHED,
        Status.RECORDING_TOO_SHORT,
    }
)


def contact_evidence(recording: Recording, antenna: Antenna) -> Evidence | str:
    """The front end's evidence of a contact manoeuvre, or why it cannot calibrate: not in the
    format's units (:func:`~.observer.units_problem`), or an estimate by the paper method that
    ends on one of :data:`INPUT_FAULTS` (samples missing in the hold, loads on another scale
    than the vibration, a record too short for the spectrum, no contact or push), named with
    its reason. A record too short for an estimate still calibrates when it holds half the
    spectrum window after t_1."""
    from sensing_antenna.calibration.observer import units_problem
    from sensing_antenna.estimation import conclude, gather
    from sensing_antenna.estimation.front.evidence import Evidence

    problem = units_problem(recording, antenna)
    if problem is not None:
        return problem
    gathered = gather(recording, antenna)
    estimate = conclude(gathered, "paper")
    refused = estimate.status in INPUT_FAULTS
    if estimate.status is Status.RECORDING_TOO_SHORT and isinstance(gathered, Evidence):
        refused = not _holds_half_the_spectrum(gathered)
    if refused or not isinstance(gathered, Evidence):
        return f"an estimate would be {estimate.status.value} ({estimate.reason})"
    return gathered


def _holds_half_the_spectrum(evidence: Evidence) -> bool:
    """Whether the samples after t_1 span half the spectrum window: omega_1 read over them is at
    most twice as coarse (a set recorded a few ms short of the window calibrates as well)."""
    have = float(evidence.t[evidence.end_index] - evidence.t[evidence.rest_index])
    return have >= 0.5 * evidence.spectrum_window
