"""Benchmarks: timings and force-call counts, printed as ratios. Run ``make bench``."""

import os

# as the ``flatcontact`` command does (flatcontact/cli/__init__.py): one BLAS thread per
# process, set before numpy is imported, so the benchmarks time what the CLI runs
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
