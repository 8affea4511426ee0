"""The machine a benchmark ran on, as its results file records it."""

from __future__ import annotations

import os
import platform
from typing import Any

from threadpoolctl import threadpool_info


def machine_info() -> dict[str, Any]:
    """CPUs, the Python version and the BLAS libraries loaded with their thread counts."""
    blas = [
        {"library": lib.get("internal_api"), "threads": lib.get("num_threads")}
        for lib in threadpool_info()
        if lib.get("user_api") == "blas"
    ]
    return {"cpus": os.cpu_count(), "python": platform.python_version(), "blas": blas}
