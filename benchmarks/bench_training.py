"""Costs of SNAP training and of the trained potential.

Prints: compute-snap design rows per second (2J = 6, 8), the cost of one SNAP force
call on a 54-atom quartz slab (2J = 6, 8, and the bundled sio2-snap), the ridge
solve time on a synthetic design matrix, the teacher's labelling cost per atom
(when CHGNet is installed) and the force calls of one relaxed-ion elastic tensor.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np


def _quartz_slab54():
    from flatcontact.structures.slab import quartz_0001_slab

    slab = quartz_0001_slab(layers=6, cut=2).repeat((3, 1, 1))
    slab.pbc = True
    return slab


def main() -> None:
    from flatcontact.training.descriptors import SnapDescriptors
    from flatcontact.training.fit import FitSettings, WeightedSystem, assemble
    from flatcontact.training.lammps_bulk import snap_calculator
    from flatcontact.training.polymorphs import build_polymorph
    from flatcontact.training.snapfiles import SnapCoefficients, SnapHyper, write_snap_files

    rng = np.random.default_rng(0)
    bulk = build_polymorph("alpha_quartz").repeat((2, 2, 2))
    slab = _quartz_slab54()
    print(f"slab: {len(slab)} atoms; bulk: {len(bulk)} atoms")
    with tempfile.TemporaryDirectory() as tmp:
        for twoj in (6, 8):
            hyper = SnapHyper(twojmax=twoj, rcutfac=4.5)
            desc = SnapDescriptors(hyper, ["Si", "O"])
            t0 = time.perf_counter()
            n = 10
            for _ in range(n):
                desc(bulk)
            dt = (time.perf_counter() - t0) / n
            print(
                f"2J={twoj}: design rows of a {len(bulk)}-atom cell: {dt * 1e3:.1f} ms ({dt / len(bulk) * 1e3:.2f} ms/atom)"
            )
            beta = rng.normal(0, 1e-3, desc.n_columns)
            coeff, param = write_snap_files(
                Path(tmp) / f"b{twoj}",
                SnapCoefficients(("Si", "O"), hyper, desc.coefficients_from_vector(beta)),
            )
            _time_force_calls(f"2J={twoj} random SNAP", snap_calculator(coeff, param), slab)
    try:
        from flatcontact.potentials.engines import bulk_calculator

        _time_force_calls("bundled sio2-snap", bulk_calculator("sio2-snap"), slab)
    except Exception as exc:  # not bundled yet
        print(f"bundled sio2-snap: not available ({exc})")

    # ridge solve on a design set the size of the bundled training set
    from flatcontact.training.descriptors import DesignBlock

    ncol = 2 * 56
    blocks, frames = [], []
    for _ in range(300):
        a = build_polymorph("alpha_quartz").repeat((2, 1, 1))
        from flatcontact.training.dataset import labelled

        frames.append(labelled(a, 0.0, rng.normal(size=(len(a), 3)), rng.normal(size=6)))
        blocks.append(
            DesignBlock(
                rng.normal(size=ncol),
                rng.normal(size=(3 * len(a), ncol)),
                rng.normal(size=(6, ncol)),
                len(a),
            )
        )
    ds = assemble(frames, blocks, ["Si", "O"])
    t0 = time.perf_counter()
    system = WeightedSystem(ds, FitSettings(), np.zeros(2))
    t1 = time.perf_counter()
    for ridge in (1e-9, 1e-7, 1e-5, 1e-3):
        system.solve(ridge)
    t2 = time.perf_counter()
    rows = len(ds.y_energy) + len(ds.y_force) + len(ds.y_stress)
    print(
        f"ridge: SVD of {rows} x {ncol} in {t1 - t0:.2f} s; 4 ridge solves in {(t2 - t1) * 1e3:.1f} ms"
    )

    from flatcontact.potentials.chgnet import chgnet_available

    if chgnet_available():
        from flatcontact.training.label import teacher_calculator

        calc = teacher_calculator()
        a = bulk.copy()
        a.calc = calc
        a.get_forces()  # warm-up
        t0 = time.perf_counter()
        for k in range(3):
            a.positions[0, 0] += 0.01 * (k + 1)
            a.get_forces()
        dt = (time.perf_counter() - t0) / 3
        print(
            f"teacher CHGNet r2SCAN: {dt:.3f} s per {len(a)}-atom labelling ({dt / len(a) * 1e3:.2f} ms/atom)"
        )
    else:
        print("teacher CHGNet: not installed")

    from flatcontact.elastic import elastic_tensor, relax_cell
    from flatcontact.training.lammps_bulk import vashishta_calculator

    calc = vashishta_calculator()
    q = relax_cell(build_polymorph("alpha_quartz"), calc, fmax=1e-4)
    calls0 = calc.force_calls
    t0 = time.perf_counter()
    elastic_tensor(q, calc)
    print(
        f"relaxed-ion elastic tensor (Vashishta, 9 atoms): {calc.force_calls - calls0} force calls, "
        f"{time.perf_counter() - t0:.2f} s"
    )


def _time_force_calls(label, calc, atoms, n=20):
    a = atoms.copy()
    a.calc = calc
    a.get_forces()
    calls0 = calc.force_calls
    t0 = time.perf_counter()
    for k in range(n):
        a.positions[k % len(a), 0] += 1e-3
        a.get_forces()
    dt = (time.perf_counter() - t0) / (calc.force_calls - calls0)
    print(
        f"{label}: {dt * 1e3:.2f} ms per force call ({len(a)} atoms, {calc.force_calls - calls0} calls)"
    )
