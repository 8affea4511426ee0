"""Input checks shared by the beam modules; every failure is a :class:`BeamInputError`."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.errors import SensingAntennaError

__all__ = ["BeamInputError", "as_finite_array", "check_mode_count"]


class BeamInputError(SensingAntennaError, ValueError):
    """A beam-model argument is out of range; the message names the argument and the problem."""

    def __init__(self, field_name: str, problem: str) -> None:
        self.field_name = field_name
        self.problem = problem
        super().__init__(f"{field_name}: {problem}")


def as_finite_array(
    name: str,
    value: ArrayLike,
    low: float | None = None,
    high: float | None = None,
    low_open: bool = False,
) -> NDArray[np.float64]:
    """Convert to a float array and check ``low (<|<=) value <= high`` element-wise.

    Raises
    ------
    BeamInputError
        Naming ``name`` and the first offending value.
    """
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise BeamInputError(name, f"must be numeric, got {value!r}") from exc
    bad = ~np.isfinite(array)
    if low is not None:
        bad |= (array <= low) if low_open else (array < low)
    if high is not None:
        bad |= array > high
    if np.any(bad):
        first = float(array[bad].flat[0])
        left = "(" if low_open else "["
        interval = f"{left}{low if low is not None else '-inf'}, "
        interval += f"{high if high is not None else 'inf'}]"
        raise BeamInputError(name, f"must be finite and lie in {interval}, got {first!r}")
    return array


def check_mode_count(n_modes: int) -> int:
    """Return ``n_modes`` if it is an integer >= 1, else raise BeamInputError."""
    if isinstance(n_modes, bool) or not isinstance(n_modes, (int, np.integer)) or n_modes < 1:
        raise BeamInputError("n_modes", f"must be an integer >= 1, got {n_modes!r}")
    return int(n_modes)
