"""Shared pytest configuration.

Hypothesis profiles (select with ``HYPOTHESIS_PROFILE``):

- ``dev`` (default): random examples, so local runs keep exploring new inputs;
- ``ci``: derandomized (the examples follow from the test's source), so CI reruns exactly
  what a developer ran with ``HYPOTHESIS_PROFILE=ci make test``; ``.ci/run`` selects it.
"""

import os

import matplotlib
from hypothesis import settings

matplotlib.use("Agg")
os.environ.setdefault("OMP_NUM_THREADS", "1")

settings.register_profile("dev", deadline=None)
settings.register_profile("ci", deadline=None, derandomize=True, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "dev"))
