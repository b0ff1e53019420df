"""Issue 14's figures in one run (printed by ``python -m benchmarks scan`` first).

1. flatcontact against the hand-written native LAMMPS script (:mod:`benchmarks.native_lammps`)
   on the same 6×6×6 quartz grid (sio2-snap + LJ, held atoms, warm starts, fmax 0.005 eV/Å
   max-norm; the 6 thicknesses from the driver's probe for -0.5 … 5 GPa, probed once and then
   given explicitly to both): wall time ratio, force calls per point, largest energy
   difference.
2. Per-call overhead: the serial scan's wall time minus its fixed costs, per force call,
   against LAMMPS's own cost of one force evaluation (``run N pre no post no`` on the same
   cell, the loop ``minimize`` runs).
3. Fixed costs per scan: imports (a fresh interpreter), storing points (per point), writing
   ``ispes.nc``, the overlap check of every grid point.
4. Parallel efficiency: 1 and 2 local worker processes measured on the same grid, and a
   schedule model for 1 … 16 workers on the paper preset's grid (12×12×20, ``columns``
   tree): per-point cost = force calls × cost per call, force calls by how the point starts
   (measured medians), the driver serial per stored point; efficiency = Σ cost / (W × makespan).
5. Large cells: one relaxed point of a Cu(111) bicrystal (cu-eam) and of the quartz interface
   repeated laterally, time, force calls and peak memory (:mod:`benchmarks.large_cells`).

CPU time is noisy on a shared machine: the load average is printed with every timing, times
are best of the repeats given, and counts (force calls) are printed beside them.
"""

from __future__ import annotations

import heapq
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

GRID = (6, 6)
P_RANGE_GPA = (-0.5, 5.0, 6)  # the 6×6×6 grid: 6 loads from adhesion to 5 GPa
FMAX = 0.005
PAPER_SHAPE = (12, 12, 20)


def load() -> str:
    return f"load {os.getloadavg()[0]:.1f}"


def import_seconds(repeats: int = 3) -> tuple[float, float]:
    """Best wall time of a fresh interpreter importing what ``flatcontact scan`` needs, and
    the best CPU time (user + system) of such an interpreter as a whole."""
    import resource

    code = (
        "import time; t = time.perf_counter(); "
        "import flatcontact.ispes.scan, flatcontact.ispes.executors, flatcontact.potentials; "
        "print(time.perf_counter() - t)"
    )
    best, best_cpu = np.inf, np.inf
    for _ in range(repeats):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        best, best_cpu = min(best, float(out.stdout.strip())), min(best_cpu, cpu)
    return best, best_cpu


def lammps_seconds_per_call(reference, model, n: int = 100, repeats: int = 5) -> float:
    """LAMMPS's own cost of one force evaluation on ``reference`` (best of ``repeats``)."""
    from flatcontact.potentials.calculator import LammpsInterfaceCalculator

    calc = LammpsInterfaceCalculator(model, reference)
    calc.engine.compute(reference.positions)
    best = np.inf
    for _ in range(repeats):
        t0 = time.process_time()  # CPU time: the machine is shared
        calc.engine.lmp.command(f"run {n} pre no post no")
        best = min(best, (time.process_time() - t0) / n)
    calc.close()
    return best


def simulate(parent: dict, cost: dict, workers: int, driver_s: float) -> float:
    """Makespan of the driver's schedule: a point is submitted once its parent is stored,
    in tree rank order, to the first free worker; the driver stores results one at a time."""
    rank = {idx: k for k, idx in enumerate(parent)}
    children: dict = {}
    for idx, par in parent.items():
        children.setdefault(par, []).append(idx)
    ready = [(rank[i], i) for i in children.get(None, [])]
    heapq.heapify(ready)
    running: list = []
    free, t_driver = workers, 0.0
    while ready or running:
        while ready and free:
            _, idx = heapq.heappop(ready)
            heapq.heappush(running, (t_driver + cost[idx], idx))
            free -= 1
        t_fin, idx = heapq.heappop(running)
        free += 1
        t_driver = max(t_driver, t_fin) + driver_s
        for child in children.get(idx, []):
            heapq.heappush(ready, (rank[child], child))
    return t_driver


def start_kind(parent: dict, idx) -> str:
    par = parent[idx]
    if par is None:
        return "cold"
    if par[:2] != idx[:2]:
        return "lateral"
    grand = parent[par]
    return "z-extrapolated" if grand is not None and grand[:2] == idx[:2] else "z"


SECTIONS = ("native", "parallel", "large")


def main(argv: list[str] | None = None) -> None:
    """All sections, or only the per-call and fixed-cost figures plus those named in ``argv``
    (``python -m benchmarks.scale_report percall [native] [parallel] [large]``)."""
    import ase.db

    wanted = set(argv) if argv else {"percall", *SECTIONS}
    unknown = wanted - {"percall", *SECTIONS}
    if unknown:
        sys.exit(
            f"error: unknown section(s) {sorted(unknown)}; available: percall, {', '.join(SECTIONS)}"
        )

    from benchmarks.bench_scan import build
    from benchmarks.large_cells import run as large_point
    from benchmarks.native_lammps import run_script, write_inputs
    from flatcontact.ispes import grid as grid_mod
    from flatcontact.ispes.executors import make_executor
    from flatcontact.ispes.geometry import thickness
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.order import search_tree
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan

    print(f"== scale report (issue 14), {os.cpu_count()} cores shared, {load()} ==", flush=True)
    t_imp, cpu_imp = import_seconds()
    spec, reference, factory = build("snap:sio2-snap")
    z_ref = thickness(reference)
    with tempfile.TemporaryDirectory() as probe_dir:
        probed = run_scan(
            reference,
            factory,
            GridSpec(*GRID, p_range_gpa=P_RANGE_GPA),
            probe_dir,
            RelaxSettings(FMAX),
            executor=make_executor("serial"),
            max_new_points=0,
        )
    zs = tuple(float(z) for z in probed.dataset.thickness.values)
    print(f"  thicknesses {np.round(zs, 3).tolist()} Å (probe {probed.seconds:.1f} s)", flush=True)
    grid = GridSpec(*GRID, thickness_angstrom=zs)
    n_points = GRID[0] * GRID[1] * len(zs)
    t_call = lammps_seconds_per_call(reference, spec)

    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        # -- 1 worker (serial, in this process) and 2 worker processes, same grid
        runs = {}
        for workers in (1, 2) if "parallel" in wanted else (1,):
            executor = make_executor("processes", workers=workers)
            try:
                t0, c0 = time.perf_counter(), time.process_time()
                r = run_scan(
                    reference,
                    factory,
                    grid,
                    tmp / f"w{workers}",
                    RelaxSettings(FMAX),
                    executor=executor,
                )
                runs[workers] = (time.perf_counter() - t0, r)
                cpu_driver = time.process_time() - c0  # all of the serial scan for 1 worker
                if workers == 1:
                    cpu1 = cpu_driver
            finally:
                executor.close()
            print(
                f"  {workers} worker(s): {n_points} points in {runs[workers][0]:.1f} s "
                f"(worker start included), {load()}",
                flush=True,
            )
        wall1, r1 = runs[1]
        calls = np.asarray(r1.force_calls_computed)
        e_tool = r1.dataset.energy.values
        # -- fixed costs
        t0 = time.perf_counter()
        grid_mod.check_thicknesses(reference, grid, zs)
        t_overlap = time.perf_counter() - t0
        from flatcontact.ispes.scan import scan_settings
        from flatcontact.ispes.store import PointStore

        with PointStore(
            tmp / "w1" / "points.db",
            scan_settings(reference, factory, grid, RelaxSettings(FMAX)),
            reference,
        ) as store:
            t0 = time.perf_counter()
            store.write_ispes(tmp / "again.nc")
            t_nc = time.perf_counter() - t0
            rows = list(ase.db.connect(str(tmp / "w1" / "points.db")).select())
        from flatcontact.ispes.relax import PointResult

        with PointStore(
            tmp / "copy" / "points.db",
            scan_settings(reference, factory, grid, RelaxSettings(FMAX)),
            reference,
        ) as copy:
            t0 = time.perf_counter()
            for row in rows:
                if row.start:  # the driver reads the parent's positions for each warm start
                    parent_index = tuple(int(x) for x in row.start.split(","))
                    if parent_index in copy:
                        copy.positions(parent_index)
                copy.write(
                    PointResult(
                        (row.i_a, row.i_b, row.i_z),
                        row.shift_a,
                        row.shift_b,
                        row.thickness,
                        row.energy,
                        row.normal_stress_gpa,
                        row.reaction_stress_gpa,
                        row.force_calls,
                        row.steps,
                        row.converged,
                        row.max_force_ev_per_a,
                        row.seconds,
                        row.positions,
                        None,
                    )
                )
            t_store = (time.perf_counter() - t0) / len(rows)
        fixed = t_overlap + t_nc + t_store * n_points
        per_call = (cpu1 - fixed) / calls.sum()  # CPU of the serial scan, fixed costs out
        print(
            f"FIXED COSTS: imports {t_imp:.2f} s wall, {cpu_imp:.2f} s CPU (a fresh interpreter "
            f"as a whole, best of 3); storing "
            f"(+ reading the parent's positions) {1e3 * t_store:.1f} ms/point ({t_store * n_points:.2f} s for {n_points}); "
            f"ispes.nc {t_nc:.2f} s; overlap check of {n_points} points {t_overlap:.2f} s; "
            f"sum without imports {fixed:.2f} s, {load()}",
            flush=True,
        )
        print(
            f"PER CALL (CPU): {1e3 * per_call:.2f} ms in the serial scan vs LAMMPS's own "
            f"{1e3 * t_call:.2f} ms per force evaluation: overhead "
            f"{100 * (per_call - t_call) / t_call:.0f} % ({calls.sum()} calls), {load()}",
            flush=True,
        )
        print(
            f"FORCE CALLS per point: median {np.median(calls):.0f}, mean {calls.mean():.1f}, "
            f"converged {int(r1.dataset.converged.sum())}/{n_points}",
            flush=True,
        )
        if "native" in wanted:
            # -- native script
            sa, sb = grid.shifts()
            script = write_inputs(
                reference, spec, list(sa), list(sb), list(zs), FMAX, tmp / "native"
            )
            native = run_script(script)
            e_nat = np.full(e_tool.shape, np.nan)
            order = np.argsort(zs)
            rank = np.empty_like(order)
            rank[order] = np.arange(len(zs))
            for (ia, ib, iz), e in native["energies"].items():
                e_nat[ia, ib, rank[iz]] = e
            print(
                f"NATIVE LAMMPS script (cg, same max-norm fmax, snake order): {native['wall']:.1f} s "
                f"(CPU {native['cpu']:.1f} s), {native['force_evaluations'] / n_points:.1f} force "
                f"evaluations/point; flatcontact serial {wall1:.1f} s (CPU {cpu1:.1f} s), "
                f"{calls.mean():.1f} calls/point: ratio {wall1 / native['wall']:.2f} wall, "
                f"{cpu1 / native['cpu']:.2f} CPU, "
                f"{calls.mean() / (native['force_evaluations'] / n_points):.2f} force calls; "
                f"max |ΔU| {np.nanmax(np.abs(e_nat - e_tool)):.1e} eV, {load()}",
                flush=True,
            )
            in_minimize = native["cpu"] / native["force_evaluations"]
            print(
                f"PER CALL against LAMMPS inside its own minimize (the issue's baseline: CPU of "
                f"the native script per force evaluation, neighbour rebuilds and line search "
                f"included): {1e3 * per_call:.2f} ms vs {1e3 * in_minimize:.2f} ms, overhead "
                f"{100 * (per_call - in_minimize) / in_minimize:.0f} %",
                flush=True,
            )
        if "parallel" in wanted:
            # -- parallel efficiency, measured and modelled
            wall2 = runs[2][0]
            print(
                f"PARALLEL measured ({n_points} points, start included): 1 worker {wall1:.1f} s, "
                f"2 workers {wall2:.1f} s: speed-up {wall1 / wall2:.2f}, efficiency "
                f"{wall1 / (2 * wall2):.0%}, {load()}",
                flush=True,
            )
            parent6 = search_tree(
                (*GRID, len(zs)), (0, 0, int(np.argmin(np.abs(np.asarray(zs) - z_ref)))), "columns"
            )
            by_kind: dict[str, list[int]] = {}
            stored = {(row.i_a, row.i_b, row.i_z): row.force_calls for row in rows}
            for idx in parent6:
                by_kind.setdefault(start_kind(parent6, idx), []).append(stored[idx])
            median = {k: float(np.median(v)) for k, v in by_kind.items()}
            parent = search_tree(PAPER_SHAPE, (0, 0, PAPER_SHAPE[2] // 2), "columns")
            cost = {
                i: median.get(start_kind(parent, i), median["lateral"]) * per_call for i in parent
            }
            total = sum(cost.values())
            line = []
            for w in (1, 2, 4, 8, 16):
                span = simulate(parent, cost, w, t_store)
                line.append(f"{w}: {total / (w * span):.0%}")
            print(
                f"PARALLEL model, paper grid {PAPER_SHAPE} ({len(parent)} points, calls/point by "
                f"start {median}, driver {1e3 * t_store:.1f} ms/point): efficiency "
                + ", ".join(line),
                flush=True,
            )
    if "large" in wanted:
        # -- large cells
        for system, n in (("cu", 8), ("cu", 14), ("quartz", 4)):
            for threads in (1, 2):
                d = large_point(system, n, threads)
                print(
                    f"LARGE {system} {d['atoms']} atoms, {threads} thread(s): one point "
                    f"{d['seconds_point']:.2f} s (CPU {d['cpu_seconds_point']:.2f} s), {d['force_calls']} "
                    f"force calls, {d['cpu_ms_per_call']:.2f} CPU ms/call (LAMMPS alone {d['ms_per_call_lammps']:.2f}), "
                    f"peak memory {d['peak_rss_mb']:.0f} MB, load {d['load']:.1f}",
                    flush=True,
                )


if __name__ == "__main__":
    main(sys.argv[1:])
