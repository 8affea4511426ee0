"""Test-suite configuration shared by every test module.

Hypothesis runs derandomized under CI (``CI`` set, as in ``.ci/run``), so a CI run is
reproducible: the same examples every time. Locally it explores new examples on each run.
"""

from __future__ import annotations

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")
