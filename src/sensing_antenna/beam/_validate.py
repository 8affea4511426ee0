"""Input checks shared by the beam modules; every failure is a :class:`BeamInputError`."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from sensing_antenna.errors import SensingAntennaError, format_value

__all__ = ["MAX_MODES", "BeamInputError", "as_finite_array", "check_mode_count"]

#: Most modes computed at once: 1000. Euler-Bernoulli theory describes mode i only while its
#: half wavelength, about l / i, stays well above the link's diameter (l / (2 r) = 490 for the
#: paper's link), so no link is described that far; the roots are found one by one, so the
#: bound also keeps the cost and the arrays small.
MAX_MODES = 1000


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
        raise BeamInputError(name, f"must be numeric, got {format_value(value)}") from exc
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
        raise BeamInputError(
            name, f"must be finite and lie in {interval}, got {format_value(first)}"
        )
    return array


def check_mode_count(n_modes: int) -> int:
    """Return ``n_modes`` if it is an integer from 1 to :data:`MAX_MODES`, else raise
    BeamInputError."""
    if (
        isinstance(n_modes, bool)
        or not isinstance(n_modes, (int, np.integer))
        or not 1 <= n_modes <= MAX_MODES
    ):
        raise BeamInputError(
            "n_modes", f"must be an integer from 1 to {MAX_MODES}, got {format_value(n_modes)}"
        )
    return int(n_modes)
