"""The scan's cost per force call against LAMMPS alone, on large cells of cheap potentials.

``python -m benchmarks.optimiser_cost`` runs one cold ISPES point per system and size, each
in its own process (:func:`benchmarks.large_cells.run`): the 36-atom quartz cell, the
Cu(111) bicrystal (``cu-eam``) at 1,536, 4,704 and 20,184 atoms and AB bilayer graphene
(``graphene-rebo-kc``, three sheets per slab) at 1,452, 4,800 and 20,172 atoms. It prints,
per row, the force calls of the point, the CPU ms per call of the scan and of LAMMPS alone
(``run N pre no post no`` on the relaxed cell), their ratio, and the L-BFGS memory the
rule chose; then the per-step algebra timed in isolation (:func:`algebra_ms`). System names
as arguments run those only (``python -m benchmarks.optimiser_cost cu quartz``). With
``--write-docs`` it replaces the table between the markers in ``docs/performance.md``.

CPU times on a shared machine are upper bounds; the ratio is taken within one process.
"""

from __future__ import annotations

import re
import sys
import time
from pathlib import Path

from benchmarks.large_cells import run

#: (system, lateral repeat) -> 36 (quartz), ~1,500, ~4,700 and ~20,000 atoms
CASES = (
    ("quartz", 1),
    ("cu", 8),
    ("cu", 14),
    ("cu", 29),
    ("graphene", 11),
    ("graphene", 20),
    ("graphene", 41),
)
DOCS = Path(__file__).resolve().parents[1] / "docs" / "performance.md"
BEGIN, END = "<!-- optimiser_cost:begin -->", "<!-- optimiser_cost:end -->"


def algebra_ms(n_coords: int, memory: int, steps: int = 20) -> float:
    """CPU ms of one L-BFGS step's algebra (:meth:`TwoLoopMemory.push`) with a full memory."""
    import numpy as np

    from flatcontact.ispes.lbfgs import TwoLoopMemory

    rng = np.random.default_rng(0)
    curv = rng.uniform(0.5, 60.0, n_coords)
    mem = TwoLoopMemory(n_coords, memory)
    x = rng.normal(size=n_coords)
    g = curv * x
    d = mem.inverse_hessian_times(g)
    spent = 0.0
    for k in range(memory + steps):
        x_new = x - 0.3 * d
        g_new = curv * x_new
        t0 = time.process_time()
        d = mem.push(x_new - x, g_new - g, g_new, -0.3)
        if k >= memory:
            spent += time.process_time() - t0
        x, g = x_new, g_new
    return 1e3 * spent / steps


def table(rows: list[dict]) -> str:
    from flatcontact.ispes.lbfgs import memory_for

    lines = [
        "| system | atoms | L-BFGS memory | force calls | scan CPU ms/call | LAMMPS alone ms/call "
        "| ratio | algebra ms/step (isolated) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        m = memory_for(3 * r["atoms"])
        lines.append(
            f"| {r['system']} | {r['atoms']:,} | {m} | {r['force_calls']} | "
            f"{r['cpu_ms_per_call']:.2f} | {r['ms_per_call_lammps']:.2f} | "
            f"{r['cpu_ms_per_call'] / r['ms_per_call_lammps']:.2f} | "
            f"{algebra_ms(3 * r['atoms'], m):.3f} |"
        )
    return "\n".join(lines)


def main(argv: list[str]) -> None:
    only = [a for a in argv if not a.startswith("--")]  # e.g. "cu quartz": those systems only
    rows = []
    for system, n in CASES:
        if only and system not in only:
            continue
        r = run(system, n)
        rows.append(r)
        print(
            f"{system:9s} {r['atoms']:6d} atoms: {r['force_calls']:4d} calls, scan "
            f"{r['cpu_ms_per_call']:.2f} ms/call, LAMMPS alone {r['ms_per_call_lammps']:.2f}, "
            f"ratio {r['cpu_ms_per_call'] / r['ms_per_call_lammps']:.2f} (load {r['load']:.1f})",
            flush=True,
        )
    text = table(rows)
    print(text)
    if "--write-docs" in argv:
        doc = DOCS.read_text()
        pattern = re.compile(re.escape(BEGIN) + ".*?" + re.escape(END), re.S)
        if not pattern.search(doc):
            sys.exit(f"error: {DOCS} has no {BEGIN} … {END} block")
        DOCS.write_text(pattern.sub(lambda _: f"{BEGIN}\n{text}\n{END}", doc))


if __name__ == "__main__":
    main(sys.argv[1:])
