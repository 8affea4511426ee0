"""How big a campaign may be: limits on its size, checked when its spec is made, before any work.

Each limit has a reason, and docs/campaigns.md ("Limits") gives the measured figures behind it.
The length of a simulated recording is the simulator's own limit
(:func:`sensing_antenna.simulator.scenario.duration_problem`), checked under the spec's field.
The functions return the problem in words, or None within the limit; the spec's dataclasses
(:mod:`~sensing_antenna.campaign.schema`) raise it as an error naming the file and the field.
"""

from __future__ import annotations

__all__ = [
    "MAX_CALIBRATION_RECORDINGS",
    "MAX_CONTACT_POINTS",
    "MAX_NOISE_LEVELS",
    "MAX_RUNS",
    "calibration_problem",
    "contact_points_problem",
    "noise_levels_problem",
    "runs_problem",
]

#: Runs in a campaign, main and noise sweep: every stored run is read into memory to resume and
#: to build the report, and the run list itself is built in memory.
MAX_RUNS = 100_000
#: Contact points in one list (main, noise sweep, calibration): the tables in the layout of
#: Tables 3 and 4 have one row per point; this many is a 1 mm grid on a 1 m link.
MAX_CONTACT_POINTS = 1_000
#: Noise levels of the sweep: its tables have one row per level and method.
MAX_NOISE_LEVELS = 100
#: Calibration recordings (points x repeats): simulated one after another in the main process
#: before any run.
MAX_CALIBRATION_RECORDINGS = 1_000
_SEE = "see docs/campaigns.md, Limits"


def runs_problem(n_main: int, n_sweep: int, n_second: int = 0) -> str | None:
    """Too many runs (:data:`MAX_RUNS`)? ``n_second``: runs on a second device."""
    n = n_main + n_sweep + n_second
    if n <= MAX_RUNS:
        return None
    second = f", {n_second} on the second device" if n_second else ""
    return (
        f"the campaign would have {n} runs ({n_main} main, {n_sweep} in the noise "
        f"sweep{second}), more than the {MAX_RUNS} a campaign may have (every run is held in "
        f"memory to resume and to report; {_SEE}); split it into several campaigns"
    )


def contact_points_problem(n_points: int) -> str | None:
    """Too many contact points in one list (:data:`MAX_CONTACT_POINTS`)?"""
    if n_points <= MAX_CONTACT_POINTS:
        return None
    return (
        f"{n_points} points, more than the {MAX_CONTACT_POINTS} a list may have (one table row "
        f"per point; {_SEE})"
    )


def noise_levels_problem(n_levels: int) -> str | None:
    """Too many noise levels in the sweep (:data:`MAX_NOISE_LEVELS`)?"""
    if n_levels <= MAX_NOISE_LEVELS:
        return None
    return (
        f"{n_levels} levels, more than the {MAX_NOISE_LEVELS} a sweep may have (its tables have a "
        f"row per level and method; {_SEE})"
    )


def calibration_problem(n_points: int, repeats: int) -> str | None:
    """Too many calibration recordings (:data:`MAX_CALIBRATION_RECORDINGS`)?"""
    n = n_points * repeats
    if n <= MAX_CALIBRATION_RECORDINGS:
        return None
    return (
        f"{n_points} points x {repeats} repeats = {n} recordings, more than the "
        f"{MAX_CALIBRATION_RECORDINGS} a calibration may simulate (they run one after another "
        f"before any run; {_SEE})"
    )
