"""ISPES scan throughput: grid points per second and force calls per point, warm vs cold.

Systems
-------
- quartz: the α-quartz (0001) two-slab interface (6 O–Si–O layers per slab, 1×1 cell,
  108 atoms) cut with :func:`flatcontact.structures.slab.quartz_0001_slab` at the
  Vashishta lattice and relaxed with Vashishta 1990 + TS-LJ (all atoms free). STAND-IN:
  the faces are the relaxed cleaved faces, not the verified "dense" reconstruction
  (the builder of ``flatcontact build`` owns that); the scan's cost does not depend on it.
- SNAP (2J = 8): until a bundled ``sio2-snap`` exists, the cost of one force call is
  timed with a Si/O SNAP of 2J = 8 whose coefficients are all zero (the bispectrum
  evaluation, which is the cost, does not depend on the coefficient values); the grid
  time is then extrapolated as points × median force calls per point (measured with
  Vashishta) × seconds per SNAP call / workers. Printed as an extrapolation.

Run: ``python -m benchmarks scan`` (several minutes on 2 cores).
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np

os.environ.setdefault("OMP_NUM_THREADS", "1")

SUBSET = (4, 4, 8)  # n_a, n_b, n_z measured here
TARGET = (12, 12, 8)  # the brief's target grid
FMAX = 0.005


def quartz_standin(spec):
    from ase.optimize import FIRE

    from flatcontact.potentials import make_calculator
    from flatcontact.structures.interface import make_interface
    from flatcontact.structures.slab import quartz_0001_slab

    slab = quartz_0001_slab(layers=6, cut=0, a_angstrom=4.829, c_angstrom=5.309)
    atoms = make_interface(
        slab, gap_angstrom=2.5, face_atoms=3, recipe={"bench": "vashishta stand-in"}
    )
    atoms.calc = make_calculator(spec, atoms)
    FIRE(atoms, logfile=None).run(fmax=0.005, steps=3000)
    atoms.calc = None
    return atoms


def zero_snap_files(directory: Path) -> Path:
    """A 2J = 8 Si/O SNAP with zero coefficients (timing only)."""
    ncoeff = 56  # 55 bispectrum components for 2J = 8, plus the constant
    lines = [f"2 {ncoeff}"]
    for element, radius in (("Si", 0.5), ("O", 0.5)):
        lines.append(f"{element} {radius} 1.0")
        lines += ["0.0"] * ncoeff
    coeff = directory / "zero8.snapcoeff"
    coeff.write_text("\n".join(lines) + "\n")
    (directory / "zero8.snapparam").write_text(
        "rcutfac 4.7\ntwojmax 8\nrfac0 0.99363\nrmin0 0\nbzeroflag 0\nquadraticflag 0\n"
    )
    return coeff


def seconds_per_call(spec, atoms, n=20) -> float:
    from flatcontact.potentials import make_calculator

    calc = make_calculator(spec, atoms)
    atoms = atoms.copy()
    atoms.calc = calc
    atoms.get_forces()
    t0 = time.perf_counter()
    for k in range(n):
        atoms.positions[0, 2] += 1e-4 * (-1) ** k
        atoms.get_forces()
    return (time.perf_counter() - t0) / n


def scan_subset(reference, factory, order, workers, out):
    from flatcontact.ispes.executors import make_executor
    from flatcontact.ispes.geometry import thickness
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan

    z0 = thickness(reference)
    grid = GridSpec(
        SUBSET[0], SUBSET[1], thickness_angstrom=tuple(z0 + np.linspace(-0.4, 0.3, SUBSET[2]))
    )
    ex = make_executor("processes", workers=workers)
    try:
        t0 = time.perf_counter()
        r = run_scan(
            reference, factory, grid, out, RelaxSettings(FMAX, "LBFGS"), order=order, executor=ex
        )
        wall = time.perf_counter() - t0
    finally:
        ex.close()
    return r, wall


def _calls_by_start(db_path: Path) -> dict:
    """Median force calls per point grouped by how the point was started."""
    import ase.db

    groups: dict[str, list[int]] = {}
    rows = {(r.i_a, r.i_b, r.i_z): r for r in ase.db.connect(str(db_path)).select()}
    for (ia, ib, _iz), row in rows.items():
        start = tuple(int(x) for x in row.start.split(",")) if row.get("start") else None
        if start is None:
            kind = "cold"
        elif start[:2] != (ia, ib):
            kind = "lateral-parent"
        else:
            grand = rows[start].get("start")
            grand = tuple(int(x) for x in grand.split(",")) if grand else None
            kind = "z-extrapolated" if grand is not None and grand[:2] == (ia, ib) else "z-parent"
        groups.setdefault(kind, []).append(row.force_calls)
    return {k: f"{np.median(v):.0f} (n={len(v)})" for k, v in sorted(groups.items())}


def main() -> None:
    from flatcontact.ispes.calculators import PotentialFactory
    from flatcontact.potentials import PotentialSpec

    classical = PotentialSpec(intra="vashishta")
    t0 = time.perf_counter()
    reference = quartz_standin(classical)
    print(
        f"quartz stand-in interface: {len(reference)} atoms, built and relaxed in {time.perf_counter() - t0:.1f} s"
    )
    factory = PotentialFactory.from_spec(classical)
    n_points = int(np.prod(SUBSET))
    medians = {}
    with tempfile.TemporaryDirectory() as tmp:
        for order in ("cold", "columns", "planes"):
            for workers in (1, 2):
                r, wall = scan_subset(
                    reference, factory, order, workers, Path(tmp) / f"{order}{workers}"
                )
                med = float(np.median(r.force_calls_computed))
                medians[order] = med
                by_start = _calls_by_start(Path(tmp) / f"{order}{workers}" / "points.db")
                print(
                    f"vashishta {SUBSET[0]}x{SUBSET[1]}x{SUBSET[2]} order={order:7s} workers={workers}: "
                    f"{n_points / wall:.2f} points/s, median force calls/point {med:.0f}, "
                    f"converged {int(r.dataset.converged.sum())}/{n_points}, wall {wall:.1f} s; "
                    f"median calls by start: {by_start}"
                )
        print(
            f"warm/cold median force calls: columns {medians['columns'] / medians['cold']:.2f}, "
            f"planes {medians['planes'] / medians['cold']:.2f}"
        )
        coeff = zero_snap_files(Path(tmp))
        snap = PotentialSpec(intra=f"snap:{coeff}")
        t_snap = seconds_per_call(snap, reference)
        t_vash = seconds_per_call(classical, reference)
        print(
            f"seconds per force call ({len(reference)} atoms, 1 core): SNAP 2J=8 {t_snap * 1e3:.2f} ms, "
            f"Vashishta {t_vash * 1e3:.2f} ms"
        )
        best = min(medians["columns"], medians["planes"])
        target = int(np.prod(TARGET))
        for workers in (1, 2):
            est = target * best * t_snap / workers
            print(
                f"EXTRAPOLATED SNAP 2J=8 {TARGET[0]}x{TARGET[1]}x{TARGET[2]} grid, warm, {workers} worker(s): "
                f"{target} points x {best:.0f} calls x {t_snap * 1e3:.2f} ms / {workers} = {est / 60:.1f} min "
                "(force calls measured with Vashishta; SNAP call cost timed with zero coefficients)"
            )


if __name__ == "__main__":
    main()
