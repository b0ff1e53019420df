"""Timing a scan as a new process would run it, in a benchmark that runs several in one.

The first scan of a process pays 0.4-0.7 s of one-time set-up (xarray for the assembly, the
netCDF writer and its backends); a second scan would also find the first one's reference
Hessian in the driver's cache (:mod:`flatcontact.ispes.precondition`, 0.4-1.0 s of force
calls). A benchmark that times scans one after the other, e.g. 1 worker then 2, would credit
both to the later scan: +0.1-0.15 in a speed-up of 1.8 (measured on the 12 × 12 quartz grid).
:func:`warm_up` pays the set-up once, untimed; :func:`forget_hessian` goes before each timed
scan.
"""

from __future__ import annotations

import tempfile
from pathlib import Path


def warm_up(reference, factory) -> None:
    """An untimed 2 × 2 scan at the reference's thickness, in this process (serial)."""
    from flatcontact.ispes.executors import SerialExecutor
    from flatcontact.ispes.geometry import thickness
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan

    grid = GridSpec(2, 2, thickness_angstrom=(thickness(reference),))
    with tempfile.TemporaryDirectory() as warm:
        run_scan(
            reference, factory, grid, Path(warm) / "warm-up", RelaxSettings(0.01),
            executor=SerialExecutor(),
        )  # fmt: skip


def forget_hessian() -> None:
    """Drop the driver's cached reference Hessians: the next scan computes its own."""
    from flatcontact.ispes import precondition

    precondition._CACHE.clear()
