"""Parallel efficiency of a scan on the paper preset's grid (issue 14).

``python -m benchmarks parallel`` (1 and 2 workers) or
``python -m benchmarks.bench_parallel 1 2 4`` (any worker counts).

The paper preset's interface is built once; then the whole scan of the paper preset (the
probe of the thicknesses: its single points in the driver, its columns' chains and the work
of separation on the workers; then 12 × 12 lateral points × the probed thicknesses) runs
from scratch with 1 worker (the serial executor: every point in this
process, no worker start) and with W local worker processes (``ProcessExecutor``: spawn,
imports and LAMMPS setup overlapping the probe), as ``flatcontact run --preset paper`` does.
Printed per run: wall time, the driver's CPU time, points per second, force calls, and the
efficiency T1 / (W · T_W). More workers than the machine has cores: the schedule model,
``python -m benchmarks.schedule_model``.

The machine's own ceiling is measured too: W independent processes each running LAMMPS's
force loop on the same cell (no Python, no communication) against one alone. On a VM whose
vCPUs share physical cores, or with a shared memory bus and turbo clocks, W of them together
do less than W times the work of one; the scan's efficiency divided by that ceiling is the
part the tool's scheduling can still lose.

Wall times mean something only on an otherwise idle machine: the load average before and
after each run is printed, and the run is flagged when it exceeds 0.5 per core.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.scan_fairness import forget_hessian, warm_up


def load() -> float:
    return os.getloadavg()[0]


def main(argv: list[str] | None = None) -> None:
    from flatcontact.config import load_config
    from flatcontact.ispes.executors import make_executor
    from flatcontact.ispes.scan import run_scan
    from flatcontact.stages import _calculator
    from flatcontact.stages.build import BuildInputs, build_stage
    from flatcontact.stages.scan import grid_spec, relax_settings

    workers = [int(w) for w in argv] if argv else [1, 2]
    if 1 not in workers:
        workers.insert(0, 1)  # the baseline
    cores = os.cpu_count() or 1
    settings = load_config(preset_name="paper")
    s = settings.scan
    reference = build_stage(settings, BuildInputs(), None).atoms
    factory = _calculator.factory(settings)
    relax = relax_settings(s)
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        grid = grid_spec(s)
        print(
            f"== parallel efficiency, paper preset ({grid.n_a}x{grid.n_b} lateral, thicknesses "
            f"from the probe), {len(reference)} atoms, {cores} cores, load {load():.2f} ==",
            flush=True,
        )
        ceiling = {w: hardware_ceiling(w) for w in workers}
        warm_up(reference, factory)  # untimed: each timed scan as a new process runs it
        rows = []
        for w in workers:
            before = load()
            forget_hessian()
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
            n_points = r.points_total
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
            print(
                "    driver phases (s; a/b is part of a): "
                + ", ".join(f"{k} {v:.2f}" for k, v in r.phase_seconds.items()),
                flush=True,
            )
        t1 = rows[0][1]
        print(
            "| workers | wall s | speed-up | efficiency | machine ceiling | efficiency / ceiling |"
        )
        print("|---|---|---|---|---|---|")
        for w, wall, *_ in rows:
            eff = t1 / (w * wall)
            print(
                f"| {w} | {wall:.1f} | {t1 / wall:.2f} | {eff:.0%} | {ceiling[w]:.0%} | "
                f"{eff / ceiling[w]:.0%} |",
                flush=True,
            )


def _force_loop(seconds_out, ready, start, steps: int) -> None:
    """One process: LAMMPS's own force loop on the quartz interface (no Python per call)."""
    from flatcontact.potentials import InteractionModel
    from flatcontact.potentials.calculator import LammpsInterfaceCalculator
    from flatcontact.structures.build import build_quartz_interface

    spec = InteractionModel(intra="snap:sio2-snap")
    reference, _ = build_quartz_interface(spec, layers=6, source="shipped")
    calc = LammpsInterfaceCalculator(spec, reference)
    calc.engine.compute(reference.positions)
    ready.put(True)
    start.wait()
    t0 = time.perf_counter()
    calc.engine.lmp.command(f"run {steps} pre no post no")
    seconds_out.put(time.perf_counter() - t0)
    calc.close()


def hardware_ceiling(workers: int, steps: int = 3000) -> float:
    """Throughput of ``workers`` concurrent LAMMPS force loops over ``workers`` × one alone.

    Each process runs ``steps`` force evaluations of the quartz interface after a common
    start signal; the ceiling is t_alone / (mean of the concurrent times). 1.0 = the cores
    scale perfectly.
    """
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")

    def run(n: int) -> float:
        out, ready, start = ctx.Queue(), ctx.Queue(), ctx.Event()
        procs = [ctx.Process(target=_force_loop, args=(out, ready, start, steps)) for _ in range(n)]
        for p in procs:
            p.start()
        for _ in procs:  # every process has built its interface and LAMMPS
            ready.get()
        start.set()
        times = [out.get() for _ in procs]
        for p in procs:
            p.join()
        return float(np.mean(times))

    alone = run(1)
    return 1.0 if workers == 1 else alone / run(workers)


if __name__ == "__main__":
    main(sys.argv[1:])
