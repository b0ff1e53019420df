"""CPU cost per force call of SNAP descriptors on the 576-atom α-quartz interface.

The interface is ``benchmarks.large_cells``' quartz one (the shipped 36-atom dense (0001)
build, 6 layers per slab, repeated 4×4) with the default LJ across; the cost is LAMMPS's
static loop (``run N pre no post no``, CPU time: the machine is shared), as there. A scan's
cost is this per-call cost times its force calls.

Usage (no torch)::

    python -m benchmarks.snap_cost sio2-snap sio2-snap-mf0 2J=6 2J=8 [--lateral 4]

An argument is a bundled name, a ``.snapcoeff`` path, or ``2J=<n>``: a quadratic SNAP of
that band limit at rcutfac 4.5 with random coefficients (the cost does not depend on their
values). Prints one JSON line per argument: atoms, ms per call of three repeats.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from pathlib import Path

CALLS = 20
REPEATS = 3


def random_snap(twojmax: int, folder: Path) -> Path:
    """A quadratic Si–O SNAP of band limit ``twojmax`` with random coefficients (cost only)."""
    import numpy as np

    from flatcontact.training.snapfiles import SnapCoefficients, SnapHyper, write_snap_files

    hyper = SnapHyper(
        twojmax=twojmax,
        rcutfac=4.5,
        radii={"Si": 0.5, "O": 0.5},
        weights={"Si": 1.0, "O": 1.0},
        quadratic=True,
    )
    rng = np.random.default_rng(0)
    beta = {e: 1e-6 * rng.standard_normal(1 + hyper.n_descriptor) for e in ("Si", "O")}
    coeff, _ = write_snap_files(
        folder / f"random-2j{twojmax}", SnapCoefficients(("Si", "O"), hyper, beta)
    )
    return coeff


def ms_per_call(intra: str, lateral: int) -> tuple[list[float], int]:
    """CPU ms per force call (repeats) and atoms of ``snap:<intra>`` + LJ, quartz interface ``lateral``²."""
    from flatcontact.potentials import InteractionModel
    from flatcontact.potentials.calculator import LammpsInterfaceCalculator
    from flatcontact.structures.build import build_quartz_interface

    ref, _ = build_quartz_interface(
        InteractionModel(intra="snap:sio2-snap"), layers=6, source="shipped"
    )
    big = ref.repeat((lateral, lateral, 1))
    calc = LammpsInterfaceCalculator(InteractionModel(intra=f"snap:{intra}"), big)
    atoms = big.copy()
    atoms.calc = calc
    atoms.get_forces()
    out = []
    for _ in range(REPEATS):
        t0 = time.process_time()
        calc.engine.lmp.command(f"run {CALLS} pre no post no")
        out.append(1e3 * (time.process_time() - t0) / CALLS)
    return out, len(big)


def main(argv: list[str] | None = None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    lateral = 4
    if "--lateral" in argv:
        k = argv.index("--lateral")
        lateral = int(argv[k + 1])
        argv = argv[:k] + argv[k + 2 :]
    if not argv:
        sys.exit("usage: python -m benchmarks.snap_cost NAME|COEFF|2J=N [...] [--lateral N]")
    with tempfile.TemporaryDirectory() as tmp:
        for arg in argv:
            intra = str(random_snap(int(arg[3:]), Path(tmp))) if arg.startswith("2J=") else arg
            ms, n_atoms = ms_per_call(intra, lateral)
            row = {"snap": arg, "atoms": n_atoms, "cpu_ms_per_call": ms, "load": os.getloadavg()[0]}
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
