"""Dask worker plugin giving every Dask worker the local pool's one-BLAS-thread limit.

A Dask nanny already starts its worker with ``OMP_NUM_THREADS=1`` and the like (the default
``distributed.nanny.pre-spawn-environ``); the plugin also covers workers started without a nanny
(``dask worker --no-nanny``, in-process clusters) or under a configuration that drops that setting.
Kept apart from :mod:`~sensing_antenna.campaign.runner` so that ``distributed`` is imported only
for a run on a Dask cluster.
"""

from __future__ import annotations

from typing import Any

from distributed.diagnostics.plugin import WorkerPlugin

from sensing_antenna.campaign.worker_threads import limit_to_one_blas_thread

__all__ = ["OneBlasThreadPerDaskWorker"]


class OneBlasThreadPerDaskWorker(WorkerPlugin):
    """Runs :func:`~sensing_antenna.campaign.worker_threads.limit_to_one_blas_thread` in each
    Dask worker's process, in the workers present at registration and in those that join later.

    A worker started inside the submitting process (``LocalCluster(processes=False)``) shares
    that process, which is then limited too.
    """

    #: Plugin name on the cluster: registering again (a second campaign) replaces it.
    name = "sensing-antenna-one-blas-thread"

    def setup(self, worker: Any) -> None:
        """Called by Dask in the worker's process when the worker gets the plugin."""
        limit_to_one_blas_thread()
