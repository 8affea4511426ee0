"""Test-suite configuration shared by every test module.

Hypothesis runs derandomized under CI (``CI`` set, as in ``.ci/run``), so a CI run is
reproducible: the same examples every time. Locally it explores new examples on each run.

The tests run with one BLAS thread, as every campaign worker does: the estimators' linear algebra
is small, and on a busy two-core machine more threads only fight for the cores, which makes the
suite several times slower.
"""

from __future__ import annotations

import os
from collections.abc import Iterator

import pytest
from hypothesis import settings
from threadpoolctl import threadpool_limits

settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")


@pytest.fixture(autouse=True, scope="session")
def one_blas_thread() -> Iterator[None]:
    """One BLAS and OpenMP thread for the whole session."""
    with threadpool_limits(limits=1):
        yield
