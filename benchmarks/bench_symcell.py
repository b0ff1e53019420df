"""The shift-space group search on twisted bilayer graphene cells: seconds before and after.

``python -m benchmarks symcell`` (or ``python -m benchmarks.bench_symcell [MAX_EXHAUSTIVE_N]``).
For the commensurate (m, m+1) twist cells (one graphene sheet per slab, the structure of
``flatcontact study approximants``): atoms, the shift-lattice index N², and wall seconds of

- ``pairs``: the exhaustive pair search the scan used before (every pair of the two slabs'
  translations per point operation; :mod:`tests.ispes.exhaustive_shift_group`), run only for
  cells up to ``MAX_EXHAUSTIVE_N`` cells per layer (default 37, the (3, 4) cell: ~10 min);
- ``whole``: the new search listing the whole group (``order × index`` operations);
- ``scan``: what the scan now does, the group modulo the translations lifted onto its grid
  (``shift_space_group(..., modulo_translations=True).for_grid(n, n)``, n × n the grid the
  scan stage chooses for a 6 × 6 base grid);
- ``stage``: the scan stage's other checks before the first point (the shift lattice read
  from the atoms and the near-period refusal, :func:`flatcontact.stages.scan._shift_lattice_grid`),

and the orders and orbit counts: ``order`` of the whole group, ``grid order`` of the lifted
one and the lateral orbits of the grid (the registries relaxed per thickness, of n²).
Both searches must give the same group (checked where both ran). Times on a shared machine
are upper bounds.
"""

from __future__ import annotations

import sys
import time
from types import SimpleNamespace

import numpy as np

CELLS = ((1, 2), (2, 3), (3, 4), (4, 5), (5, 6), (7, 8))


def _twisted(m: int, n: int):
    from flatcontact.structures.construct import build_interface

    atoms, _ = build_interface(
        {
            "kind": "sheets",
            "sheet": "graphene",
            "layers": 1,
            "twist": [m, n],
            "match": {"max_atoms": 4 * (m * m + m * n + n * n)},
        }
    )
    return atoms


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def main(argv: list[str] | None = None) -> None:
    from tests.ispes.exhaustive_shift_group import exhaustive_group

    from flatcontact.ispes.shift_symmetry import shift_space_group
    from flatcontact.stages.scan import _shift_lattice_grid

    max_pairs = int((argv or ["37"])[0])
    print(
        "cell | atoms | index | pairs (s) | whole (s) | scan (s) | stage (s) | order | "
        "grid | grid order | orbits | same group"
    )
    for m, n in CELLS:
        atoms = _twisted(m, n)
        cells = m * m + m * n + n * n
        scan = SimpleNamespace(grid=[6, 6], symmetry=SimpleNamespace(tolerance_angstrom=1e-3))
        (lattice, lateral, _), t_stage = _timed(lambda a=atoms, s=scan: _shift_lattice_grid(s, a))
        lifted, t_scan = _timed(
            lambda a=atoms, g=lateral: shift_space_group(a, modulo_translations=True).for_grid(*g)
        )
        whole, t_whole = _timed(lambda a=atoms: shift_space_group(a))
        pairs, t_pairs, same = None, float("nan"), "-"
        if cells <= max_pairs:
            pairs, t_pairs = _timed(lambda a=atoms: exhaustive_group(a))
            keys = {
                (o.matrix, tuple(float(v) for v in np.round(o.translation, 6) % 1.0), o.swaps_slabs)
                for o in whole.operations
            }
            same = "yes" if keys == pairs else "NO"
        orbits = len(lifted.orbits(*lateral))
        print(
            f"({m}, {n}) | {len(atoms)} | {lattice.index} | {t_pairs:.2f} | {t_whole:.2f} | "
            f"{t_scan:.3f} | {t_stage:.3f} | {whole.order} | {lateral[0]}x{lateral[1]} | "
            f"{lifted.order} | {orbits} | {same}",
            flush=True,
        )


if __name__ == "__main__":
    main(sys.argv[1:])
