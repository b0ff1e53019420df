"""One ISPES point on large interfaces: time, force calls, per-call cost and memory vs atoms.

System: a Cu(111) bicrystal (``fcc111`` recipe, ``cu-eam`` = Mishin EAM), 12 close-packed
planes per slab (the outer one held), repeated n×n laterally (n = 2 … 14: 96 … 4704 atoms);
slab 2 is slid by (1/3, 1/3) of the primitive cell at the perfect-crystal thickness, so the
point is a relaxed stacking fault (a real relaxation, LBFGS to 0.005 eV/Å, cold start).
And the α-quartz interface (``sio2-snap`` + LJ, 36 atoms) repeated n×n (n = 1 … 6: 36 …
1296 atoms), slid by (1/2, 0) of the primitive cell, cold start.

Each size runs in its own process (``python -m benchmarks.large_cells SYSTEM N THREADS``) so that its
peak resident memory (``ru_maxrss``) is its own; printed as one JSON line per run.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time

LATERAL = (2, 4, 6, 8, 10, 14)
QUARTZ_LATERAL = (1, 2, 4, 6)
LAYERS = 12
FMAX = 0.005


def cu_interface(n: int):
    from flatcontact.structures.construct import build_interface

    ref, _ = build_interface({"kind": "fcc111", "element": "Cu", "layers": LAYERS})
    big = ref.repeat((n, n, 1))
    return big


def quartz_interface(n: int):
    from flatcontact.potentials import InteractionModel
    from flatcontact.structures.build import build_quartz_interface

    ref, _ = build_quartz_interface(
        InteractionModel(intra="snap:sio2-snap"), layers=6, source="shipped"
    )
    return ref.repeat((n, n, 1))


def graphene_interface(n: int):
    """AB bilayer graphene, three sheets per slab (the outer one held), repeated n×n."""
    from flatcontact.structures.construct import build_interface

    ref, _ = build_interface({"kind": "sheets", "sheet": "graphene", "layers": 3, "stacking": "AB"})
    return ref.repeat((n, n, 1))


def case(system: str, n: int):
    """(interface, interaction model, lateral shift as fractions of the big cell) of a system
    (``cu``, ``graphene``, ``quartz``) repeated n×n: the point every benchmark here relaxes."""
    from flatcontact.potentials import InteractionModel

    if system == "cu":
        ref = cu_interface(n)
        model = InteractionModel(preset="cu-eam")
        shift = (1 / (3 * n), 1 / (3 * n))
    elif system == "graphene":
        ref = graphene_interface(n)
        model = InteractionModel(preset="graphene-rebo-kc")
        shift = (1 / (6 * n), 1 / (6 * n))
    else:
        ref = quartz_interface(n)
        model = InteractionModel(intra="snap:sio2-snap")
        shift = (1 / (2 * n), 0.0)
    return ref, model, shift


def one_point(system: str, n: int, threads: int) -> dict:
    """Build, relax one point, report seconds, calls and memory."""
    from flatcontact.ispes.geometry import thickness
    from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point
    from flatcontact.potentials.calculator import LammpsInterfaceCalculator

    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    ref, model, shift = case(system, n)
    t0 = time.perf_counter()
    calc = LammpsInterfaceCalculator(model, ref)
    if threads > 1:  # rebuild the engine with OpenMP threads
        from flatcontact.potentials.lammps_engine import LammpsEngine
        from flatcontact.potentials.lammps_setup import compile_setup

        calc.engine.close()
        setup = compile_setup(model, ref)
        calc.engine = LammpsEngine(setup, ref.cell.array, ref.pbc, threads=threads)
    t_build = time.perf_counter() - t0
    task = PointTask((0, 0, 0), *shift, thickness(ref))
    t0, c0 = time.perf_counter(), time.process_time()
    r = relax_point(ref, calc, task, RelaxSettings(FMAX))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    lmp = calc.engine.lmp
    calls = 100 if len(ref) < 1000 else 20
    t1 = time.process_time()
    lmp.command(f"run {calls} pre no post no")
    per_call_lammps = (time.process_time() - t1) / calls  # CPU time: the machine is shared
    # the same with the energy on every step (``thermo 1``), as each of the scan's calls has it
    # (``run N`` with ``thermo 0`` tallies the energy on its last step only)
    lmp.command("thermo 1")
    t1 = time.process_time()
    lmp.command(f"run {calls} pre no post no")
    per_call_lammps_energy = (time.process_time() - t1) / calls
    cg = lammps_minimize(ref, model, task, calc)
    return {
        "system": system,
        "atoms": len(ref),
        "threads": threads,
        "seconds_point": wall,
        "cpu_seconds_point": cpu,
        "force_calls": r.force_calls,
        "converged": r.converged,
        "ms_per_call": 1e3 * wall / r.force_calls,
        "cpu_ms_per_call": 1e3 * cpu / r.force_calls,
        "ms_per_call_lammps": 1e3 * per_call_lammps,
        "ms_per_call_lammps_energy": 1e3 * per_call_lammps_energy,
        "cg_force_calls": cg["force_calls"],
        "cg_cpu_seconds_point": cg["cpu_seconds"],
        "cg_energy_ev": cg["energy_ev"],
        "build_s": t_build,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "rss_start_mb": rss0 / 1024,
        "energy_ev": r.energy_ev,
        "load": os.getloadavg()[0],
    }


def lammps_minimize(ref, model, task, calc) -> dict:
    """The same point relaxed by LAMMPS's own minimiser from the same start: ``min_style cg``,
    ``min_modify norm max`` (the largest per-atom force norm, the scan's criterion), ``fix
    setforce`` on the held atoms, ``minimize 0 FMAX``; its force evaluations (from LAMMPS's
    log), CPU seconds and final energy."""
    import re
    import tempfile

    import numpy as np

    from flatcontact.ispes.geometry import fixed_mask, place_slab2
    from flatcontact.potentials.calculator import LammpsInterfaceCalculator

    placed = place_slab2(ref, task.shift_a, task.shift_b, task.thickness)
    held = np.flatnonzero(fixed_mask(placed)) + 1
    calc = LammpsInterfaceCalculator(model, ref)
    engine = calc.engine
    engine.compute(placed.positions)
    lmp = engine.lmp
    with tempfile.TemporaryDirectory() as tmp:
        log = f"{tmp}/min.log"
        lmp.commands_list(
            [
                "group held id " + " ".join(map(str, held)),
                "fix hold held setforce 0.0 0.0 0.0",
                "min_style cg",
                "min_modify norm max",
                "thermo 0",
                f"log {log}",
            ]
        )
        t0 = time.process_time()
        lmp.command(f"minimize 0 {FMAX} 100000 1000000")
        cpu = time.process_time() - t0
        lmp.command("log none")
        text = open(log).read()
    evals = int(re.search(r"Iterations, force evaluations = \d+ (\d+)", text).group(1))
    energy = float(lmp.get_thermo("pe"))
    engine.close()
    return {"force_calls": evals, "cpu_seconds": cpu, "energy_ev": energy}


def run(system: str, n: int, threads: int = 1) -> dict:
    """``one_point`` in a fresh process (its own peak memory)."""
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    out = subprocess.run(
        [sys.executable, "-m", "benchmarks.large_cells", system, str(n), str(threads)],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


if __name__ == "__main__":
    print(json.dumps(one_point(sys.argv[1], int(sys.argv[2]), int(sys.argv[3]))), flush=True)


def plot(rows: list[dict], path) -> None:
    """Log-log plot of CPU seconds per force call (tool and LAMMPS alone) against atoms."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, ax = plt.subplots(figsize=(5.5, 4))
    for system, label, marker in (
        ("cu", "Cu(111) bicrystal, cu-eam", "o"),
        ("quartz", "α-quartz interface, sio2-snap + LJ", "s"),
    ):
        sel = sorted(
            (r for r in rows if r["system"] == system and r["threads"] == 1),
            key=lambda r: r["atoms"],
        )
        if not sel:
            continue
        n = np.array([r["atoms"] for r in sel])
        tool = np.array([r["cpu_ms_per_call"] for r in sel])
        lmp = np.array([r["ms_per_call_lammps"] for r in sel])
        ax.loglog(n, tool, marker + "-", label=f"{label}: flatcontact")
        ax.loglog(n, lmp, marker + "--", mfc="none", label=f"{label}: LAMMPS alone")
        slope = (
            np.polyfit(np.log(n[n >= 300]), np.log(lmp[n >= 300]), 1)[0]
            if (n >= 300).sum() > 1
            else np.nan
        )
        ax.annotate(
            f"slope {slope:.2f}",
            (n[-1], lmp[-1]),
            textcoords="offset points",
            xytext=(-60, -14),
            fontsize=8,
        )
    ax.set_xlabel("atoms in the cell")
    ax.set_ylabel("CPU ms per force call (1 core)")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
