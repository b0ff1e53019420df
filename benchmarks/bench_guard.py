"""The preconditioner's slip guard on the notebook's Cu(111) EMT example (issue 33).

``python -m benchmarks guard``: about 10 s. The interface of :mod:`flatcontact.notebook`'s
doctest (Cu(111), EMT, a 1 × 1 cell of three planes per slab, one atom each, the outer plane
of each slab held; mode ``full``, fmax 0.01 eV/Å, 3 × 3 grid, 15 thicknesses for -1 … 3 GPa),
scanned three ways in this process:

- ``plain``: the γ-scaled L-BFGS (``LBFGS-scaled`` without the reference's Hessian);
- ``unguarded``: the reference's Hessian as H0 with the slip guard switched off (the guard's
  test replaced by one that never fires: how the preconditioner was before the guard);
- ``guarded``: the scan's default.

Printed per variant: the grid's force calls (exact, load-independent) and the Hessian's, the
largest in-slab slip of any point (Å, :mod:`flatcontact.ispes.slip`; the ``in_slab_slip``
threshold is 0.25), and the largest jump of the energy between neighbouring thicknesses of a
column relative to a smooth column (the largest |second difference| of U(z) over the
columns, eV: a column that changes relaxation branch shows a jump of its own size). The
numbers are in ``docs/performance.md``, "The reference interface's Hessian as H0".
"""

from __future__ import annotations

import contextlib
import tempfile
from pathlib import Path
from unittest import mock

import numpy as np


def interface():
    """The notebook doctest's interface (Cu(111), a = 3.59 Å, three planes per slab)."""
    from ase.build import fcc111

    from flatcontact import make_interface

    slab = fcc111("Cu", size=(1, 1, 3), a=3.59, orthogonal=False, periodic=True)
    return make_interface(slab, gap_angstrom=2.1, face_atoms=1)


def scan(reference, precondition: bool, guarded: bool, out: Path):
    """ScanResult of the notebook's scan with or without the preconditioner and its guard."""
    from ase.calculators.emt import EMT

    from flatcontact.ispes import relax
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.scan import run_scan
    from flatcontact.notebook import _scan_factory

    settings = relax.RelaxSettings(0.01, mode="full", precondition=precondition)
    spec = GridSpec(3, 3, p_range_gpa=(-1.0, 3.0, 5))
    factory = _scan_factory(EMT(), 1, None)
    never = mock.patch.object(relax, "slips_inside_slab", lambda *a: False)
    with contextlib.nullcontext() if guarded else never:
        return run_scan(
            reference, factory, spec, out, settings, executor_options={"kind": "serial"}
        )


def largest_second_difference_ev(ds) -> float:
    """max over columns of |U(z_{k+1}) - 2 U(z_k) + U(z_{k-1})| (eV)."""
    energy = np.asarray(ds["energy"].values, dtype=float)
    return float(np.nanmax(np.abs(np.diff(energy, n=2, axis=2))))


def main() -> None:
    from flatcontact.ispes.slip import slip_table, store_points

    reference = interface()
    with tempfile.TemporaryDirectory(prefix="bench-guard-") as tmp:
        for name, precondition, guarded in (
            ("plain", False, True),
            ("unguarded", True, False),
            ("guarded", True, True),
        ):
            r = scan(reference, precondition, guarded, Path(tmp) / name)
            ds = r.dataset
            table = slip_table(reference, store_points(r.store_path))
            print(
                f"  {name:10s} force calls {int(np.nansum(ds['force_calls'].values)):5d}"
                + (f" (+ the driver's Hessian, {r.hessian_force_calls})" if precondition else "")
                + ", largest in-slab slip "
                f"{float(table.max_by_gap().max()):.3f} A at {len(table.slipped())} points, "
                f"largest |d2U| along a column {largest_second_difference_ev(ds):.4f} eV",
                flush=True,
            )


if __name__ == "__main__":
    main()
