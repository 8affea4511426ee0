"""One BLAS/OpenMP thread per campaign worker, the same on the local process pool and on Dask.

Both executors already run one worker per core; multi-threaded linear algebra inside each (the
fast method's least squares) made them fight for the cores: 7 to 73 s per recording on 2 cores
instead of about 1 s. :func:`limit_to_one_blas_thread` is the process pool's initializer, and
:class:`~sensing_antenna.campaign.dask_plugin.OneBlasThreadPerDaskWorker` calls it in every Dask
worker.
"""

from __future__ import annotations

from threadpoolctl import threadpool_limits

__all__ = ["limit_to_one_blas_thread"]


def limit_to_one_blas_thread() -> None:
    """Limit the BLAS and OpenMP libraries of the calling process to one thread each, for good."""
    threadpool_limits(limits=1)
