"""The asperity's loads as jobs: two loads in sequence against the same two on two local
worker processes (the scan's :class:`~flatcontact.ispes.executors.ProcessExecutor`).

A Cu(111) cylinder of R = 20 nm (EAM inside, LJ across; 1,804 atoms), Hertz p0 = 0.5 and
1.0 GPa, a press and ``ASPERITY_JOBS_STEPS`` (default 4) lateral steps of 0.05 Å each. Prints
the wall time of each and the speed-up (at most 2 on two free cores; the jobs also rebuild the
atoms and start LAMMPS in fresh processes), and checks that the states are the same bit for
bit. Under 2 minutes on a quiet 2-core machine.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np


def main() -> None:
    from benchmarks.bench_asperity import cu_model, cu_recipe
    from flatcontact.asperity.driver import load_state
    from flatcontact.asperity.experiment import ExperimentSpec, run_experiment
    from flatcontact.ispes.executors import ProcessExecutor

    recipe = cu_recipe(layers=4)
    model = cu_model()
    steps = int(os.environ.get("ASPERITY_JOBS_STEPS", "4"))
    spec = ExperimentSpec(
        "cylinder",
        200.0,
        (0.5, 1.0),
        72.98,
        0.05,
        steps,
        1e-3,
        20000,
        3.0,
        4.0,
        2,
        6.0,
        None,
        None,
        None,
        2.0,
        0.005,
        0.1,
    )
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        run_experiment(spec, recipe, model, None, Path(tmp) / "seq")
        seq = time.perf_counter() - t0
        executor = ProcessExecutor(2)
        try:
            t0 = time.perf_counter()
            run_experiment(spec, recipe, model, None, Path(tmp) / "par", executor=executor)
            par = time.perf_counter() - t0
        finally:
            executor.close()
        same = all(
            np.array_equal(
                load_state(Path(tmp) / "seq" / f"load_{i}" / f"step_{k:04d}.npz").positions,
                load_state(Path(tmp) / "par" / f"load_{i}" / f"step_{k:04d}.npz").positions,
            )
            for i in range(2)
            for k in range(steps + 1)
        )
    print(f"2 loads x {steps + 1} relaxations, 1,804 atoms")
    print(f"sequential {seq:.1f} s, 2 worker processes {par:.1f} s, speed-up {seq / par:.2f}")
    print(f"states bit-identical: {same}")
