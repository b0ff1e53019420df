"""The hand-written baseline: one native LAMMPS input script over a whole ISPES grid.

What a researcher writes without flatcontact: the same interface, the same pair commands
(compiled from the same interaction model), the held atoms of both slabs zeroed with
``fix setforce``, slab 2 moved point to point with ``displace_atoms`` in a snake order
(each point warm-started from the previous one), ``minimize`` with ``cg`` to the same
max-norm force tolerance (``min_modify norm max``), the energy and the net z-force on slab 2
printed per point. :func:`write_inputs` writes ``interface.data`` and ``ispes.in``;
:func:`run_script` runs it in one LAMMPS instance (``lmp.file``: LAMMPS's own loop, no
Python between force calls) and returns the wall time, the energies and LAMMPS's count of
force evaluations (summed from its minimisation statistics).
"""

from __future__ import annotations

import re
import time
from pathlib import Path

import numpy as np


def write_inputs(reference, model, shifts_a, shifts_b, thicknesses, fmax, folder) -> Path:
    """Write ``interface.data`` and ``ispes.in`` into ``folder``; return the script path.

    Grid order: thickness planes in the given order, each a snake over (a, b); the first
    point is displaced from the reference. ``fmax`` (eV/Å) is the max-norm force tolerance.
    """
    from flatcontact.ispes.geometry import fixed_mask, in_plane_vectors, thickness
    from flatcontact.potentials.lammps_engine import LammpsEngine
    from flatcontact.potentials.lammps_setup import compile_setup

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    setup = compile_setup(model, reference)
    engine = LammpsEngine(setup, reference.cell.array, reference.pbc, label=model.label)
    try:
        engine.compute(reference.positions)
        engine.lmp.command(f"write_data {folder / 'interface.data'} nocoeff")
        q = engine.box.q  # in-plane frame: caller -> LAMMPS
    finally:
        engine.close()
    ids = np.arange(1, len(reference) + 1)
    held = fixed_mask(reference)
    top = np.asarray(reference.arrays["slab"]) == 2
    a1, a2 = in_plane_vectors(reference)
    z_ref = thickness(reference)
    lines = [
        "units metal",
        f"atom_style {setup.atom_style}",
        "atom_modify map array sort 0 0.0",
        "boundary " + " ".join("p" if p else "s" for p in reference.pbc),
        f"read_data {folder / 'interface.data'}",
        *setup.commands,
        "neighbor 1.0 bin",
        "neigh_modify every 1 delay 0 check yes",
        f"group held id {' '.join(str(i) for i in ids[held])}",
        f"group top id {' '.join(str(i) for i in ids[top])}",
        "fix hold held setforce 0.0 0.0 0.0",
        "compute fz top reduce sum fz",
        "thermo_style custom step pe c_fz",
        "thermo_modify norm no",
        "min_style cg",
        "min_modify norm max",
        "variable e equal pe",
        "variable f equal c_fz",
    ]
    current = (0.0, 0.0, z_ref)
    for iz, z in enumerate(thicknesses):
        for ia, a in enumerate(shifts_a):
            row = shifts_b if ia % 2 == 0 else shifts_b[::-1]
            for b in row:
                ib = int(np.flatnonzero(np.isclose(shifts_b, b))[0])
                d_ab = (a - current[0]) * a1 + (b - current[1]) * a2
                dx, dy = q @ d_ab
                dz = z - current[2]
                current = (a, b, z)
                lines += [
                    f"displace_atoms top move {dx:.17g} {dy:.17g} {dz:.17g} units box",
                    f"minimize 0.0 {fmax} 2000 100000",
                    f'print "POINT {ia} {ib} {iz} ${{e}} ${{f}}"',
                ]
    script = folder / "ispes.in"
    script.write_text("\n".join(lines) + "\n")
    return script


def run_script(script: Path) -> dict:
    """Run ``script`` in one LAMMPS instance; wall seconds, energies and force evaluations."""
    from flatcontact.potentials.lammps_runtime import new_lammps

    log = script.with_suffix(".log")
    lmp = new_lammps(["-log", str(log)])
    try:
        t0, c0 = time.perf_counter(), time.process_time()
        lmp.file(str(script))
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    finally:
        lmp.close()
    text = log.read_text()
    energies = {}
    for m in re.finditer(r"^POINT (\d+) (\d+) (\d+) (\S+) (\S+)$", text, re.M):
        energies[tuple(int(g) for g in m.groups()[:3])] = float(m.group(4))
    evals = [
        int(m.group(1))
        for m in re.finditer(r"Iterations, force evaluations\s*=\s*\d+\s+(\d+)", text)
    ]
    return {"wall": wall, "cpu": cpu, "energies": energies, "force_evaluations": int(sum(evals))}
