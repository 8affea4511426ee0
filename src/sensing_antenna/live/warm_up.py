"""Getting a listener's process ready before the first sample arrives: :func:`warm_up` and
:func:`freeze_heap`.

The first estimate of a method in a process loads its compiled kernels (numba's, from its disk
cache; compiled first when the cache is empty) and builds what the antenna's model gives once
(the sensing curves on the posterior's grid, the contact detector's filters). Left to the
first recording, that work would land on its events. :func:`warm_up` does it beforehand: it
simulates one manoeuvre of the antenna (:mod:`sensing_antenna.simulator`: the azimuthal sweep
into a post at :data:`WARM_UP_CONTACT` of the link's length) and receives it as a listener does
(:class:`~.listener.Listener`, the same method and settings), its events discarded; then it
freezes the heap.

:func:`freeze_heap`: Python's cyclic garbage collector, in its full passes, scans every object
the process holds (some 150 000 once numpy, scipy and numba are loaded) while holding the
interpreter, which stops the reader and the worker alike for tens to hundreds of
milliseconds at moments nobody chooses. The objects alive once the process is ready (the
libraries, the kernels, the antenna's model) live as long as it does; moved to the collector's
permanent generation (:func:`gc.freeze`), they are no longer scanned, and a full pass looks at
what the listeners created since.
"""

from __future__ import annotations

import gc
import time

from sensing_antenna.antenna import Antenna
from sensing_antenna.estimation.config import EstimatorConfig
from sensing_antenna.estimation.methods import EstimationMethod
from sensing_antenna.live.listener import Listener
from sensing_antenna.live.replay import stream_of

__all__ = ["WARM_UP_CONTACT", "freeze_heap", "warm_up"]

#: Where the warm-up's simulated link touches, as a fraction of the link's length: 0.6, a point
#: every method declares on (the fast method before its cap), so that every step of every
#: method runs once.
WARM_UP_CONTACT = 0.6


def warm_up(
    antenna: Antenna,
    method: str | EstimationMethod = "paper",
    config: EstimatorConfig | None = None,
    sample_period: float | None = None,
) -> float:
    """Run one simulated manoeuvre of ``antenna`` through a listener, then
    :func:`freeze_heap` (module docstring).

    Parameters
    ----------
    antenna : Antenna
        The model the listeners will use (its caches are filled for it).
    method : str or EstimationMethod
    config : EstimatorConfig, optional
        As the listeners will be given them.
    sample_period : float, optional
        The period (s) of the samples to come, the simulated manoeuvre's (the nearest the
        simulator runs at, ``simulator.scenario.SAMPLE_PERIOD_RANGE``); the paper's 1 ms when
        None.

    Returns
    -------
    float
        The wall time it took (s).
    """
    from sensing_antenna.simulator import Scenario, simulate
    from sensing_antenna.simulator.scenario import DEFAULT_SAMPLE_PERIOD, SAMPLE_PERIOD_RANGE

    start = time.perf_counter()
    scenario = Scenario(
        case="azimuthal",
        contact_point=WARM_UP_CONTACT * antenna.link.length,
        # the nearest the simulator runs at: the compiled kernels are the same at any period
        sample_period=DEFAULT_SAMPLE_PERIOD
        if sample_period is None
        else min(max(sample_period, SAMPLE_PERIOD_RANGE[0]), SAMPLE_PERIOD_RANGE[1]),
    )
    header, rows = stream_of(simulate(antenna, scenario).without_ground_truth(), "<warm-up>")
    listener = Listener(header, antenna, lambda event: None, method, config)
    listener.put(rows)
    listener.close()
    freeze_heap()
    return time.perf_counter() - start


def freeze_heap() -> None:
    """Collect what is garbage now, then leave every object alive out of the garbage
    collector's later passes (:func:`gc.freeze`; module docstring). Changes no result."""
    gc.collect()
    gc.freeze()
