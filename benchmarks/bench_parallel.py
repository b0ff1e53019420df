"""Parallel efficiency of a scan on the paper preset's grid (issue 14).

``python -m benchmarks parallel`` (1 and 2 workers) or
``python -m benchmarks.bench_parallel 1 2 4`` (any worker counts).

The paper preset's interface is built once and its thicknesses probed once (serial, in this
process); then the same grid (12 × 12 lateral points × the probed thicknesses) is scanned
from scratch with 1 worker (the serial executor: every point in this process, no worker
start) and with W local worker processes (``ProcessExecutor``: spawn, imports and LAMMPS
setup included in the wall time). Printed per run: wall time, the driver's CPU time, points
per second, force calls, and the efficiency T1 / (W · T_W) against the 1-worker run. The
probe, which every run does once before the grid (serially in the driver, overlapping the
workers' start), is printed beside them; the efficiency with it counted is
(T_probe + T1) / (W · (T_probe + T_W)).

Wall times mean something only on an otherwise idle machine: the load average before and
after each run is printed, and the run is flagged when it exceeds 0.5 per core.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def load() -> float:
    return os.getloadavg()[0]


def main(argv: list[str] | None = None) -> None:
    from flatcontact.config import load_config
    from flatcontact.ispes.executors import make_executor
    from flatcontact.ispes.scan import run_scan
    from flatcontact.stages import _calculator
    from flatcontact.stages.build import BuildInputs, run_build

    workers = [int(w) for w in argv] if argv else [1, 2]
    if 1 not in workers:
        workers.insert(0, 1)  # the baseline
    cores = os.cpu_count() or 1
    settings = load_config(preset_name="paper")
    s = settings.scan
    reference = run_build(settings, BuildInputs(), None).atoms
    factory = _calculator.factory(settings)
    relax = s.relax_settings()
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        t0 = time.perf_counter()
        probed = run_scan(
            reference,
            factory,
            s.grid_spec(),
            tmp / "probe",
            relax,
            order=s.order,
            executor=make_executor("serial"),
            max_new_points=0,
        )
        t_probe = time.perf_counter() - t0
        z = tuple(float(v) for v in probed.dataset.thickness.values)
        grid = dataclasses.replace(s.grid_spec(), thickness_angstrom=z, p_range_gpa=None)
        n_points = grid.n_a * grid.n_b * len(z)
        print(
            f"== parallel efficiency, paper preset grid {grid.n_a}x{grid.n_b}x{len(z)} = "
            f"{n_points} points, {len(reference)} atoms, {cores} cores; probe {t_probe:.1f} s "
            f"(serial, once per scan), load {load():.2f} ==",
            flush=True,
        )
        rows = []
        for w in workers:
            before = load()
            executor = make_executor("processes", workers=w)
            try:
                t0, c0 = time.perf_counter(), time.process_time()
                r = run_scan(
                    reference, factory, grid, tmp / f"w{w}", relax, order=s.order, executor=executor
                )
                wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            finally:
                executor.close()
            after = load()
            calls = int(np.sum(r.force_calls_computed))
            rows.append((w, wall, cpu, calls, before, after))
            print(
                f"  {w} worker(s): {wall:.1f} s wall, driver CPU {cpu:.1f} s, "
                f"{n_points / wall:.1f} points/s, {calls} force calls, load {before:.2f} -> {after:.2f}"
                + (
                    "  (machine busy: not a clean measurement)"
                    if max(before, after) > 0.5 * cores + w
                    else ""
                ),
                flush=True,
            )
        t1 = rows[0][1]
        print("| workers | wall s | speed-up | efficiency | with the probe |")
        print("|---|---|---|---|---|")
        for w, wall, *_ in rows:
            print(
                f"| {w} | {wall:.1f} | {t1 / wall:.2f} | {t1 / (w * wall):.0%} | "
                f"{(t_probe + t1) / (w * (t_probe + wall)):.0%} |",
                flush=True,
            )


if __name__ == "__main__":
    main(sys.argv[1:])
