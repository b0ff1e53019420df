"""The asperity driver against a plain LAMMPS input script doing the same relaxation.

One press (:func:`flatcontact.asperity.driver.relax`) of a Cu(111) cylinder (EAM inside, LJ
across) against the same minimisation written as a native LAMMPS input: the same data (written
by the same LAMMPS setup), pair commands, groups, ``fix setforce`` / ``fix aveforce``,
``min_style fire``, ``min_modify norm max`` and tolerance, run by ``lmp.file`` (LAMMPS's own
loop). Prints the wall time, LAMMPS's iteration counts (one force call per FIRE iteration) and
the seconds per force call of each, and their ratio (the driver's time includes its own
overhead: a fresh instance, the gathers and the force evaluation of the flat alone). Each is
run twice, alternating, and the faster kept.

``ASPERITY_BENCH_RADIUS_ANGSTROM`` (default 800) sets the size: 800 Å gives 12,114 atoms.
The 100,000-atom cylinder over 1 and 2 MPI ranks: ``bench_asperity_large.py``.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np


def native_script(model, atoms, positions, protocol, folder: Path) -> Path:
    """The relaxation of :func:`flatcontact.asperity.driver.relax` as a plain LAMMPS input
    (``folder/asperity.in`` reading ``folder/asperity.data``, written by the same LAMMPS
    setup): the same pair commands, groups, fixes, FIRE and tolerance."""
    from flatcontact.asperity.driver import _lammps_for, group_commands
    from flatcontact.potentials.lammps_setup import compile_setup

    setup = compile_setup(model, atoms)
    lmp = _lammps_for(model, atoms, positions)
    try:
        lmp.command("run 0")
        lmp.command(f"write_data {folder / 'asperity.data'} nocoeff")
    finally:
        lmp.close()
    block = np.asarray(atoms.arrays["block"])
    n_tip = int(np.sum(block == 2))
    per_atom = -protocol.normal_force_ev_per_angstrom / n_tip
    ftol = min(
        protocol.fmax_ev_per_angstrom,
        protocol.normal_tolerance * abs(protocol.normal_force_ev_per_angstrom) / n_tip,
    )
    script = [
        "units metal",
        f"atom_style {setup.atom_style}",
        "atom_modify map array sort 0 0.0",
        "boundary " + " ".join("p" if p else "s" for p in atoms.pbc),
        f"read_data {folder / 'asperity.data'}",
        *setup.commands,
        "neighbor 1.0 bin",
        "neigh_modify every 1 delay 0 check yes",
        *group_commands(block),
        "fix hold flatblock setforce 0.0 0.0 0.0",
        "fix tiplat tipblock setforce 0.0 0.0 NULL",
        f"fix press tipblock aveforce NULL NULL {per_atom:.17g}",
        "min_style fire",
        "min_modify norm max",
        f"minimize 0.0 {ftol:.17g} {protocol.max_iterations} {10 * protocol.max_iterations}",
    ]
    path = folder / "asperity.in"
    path.write_text("\n".join(script) + "\n")
    return path


def _native(model, atoms, positions, protocol, folder: Path) -> tuple[float, int]:
    """Seconds and FIRE iterations of the plain script run in process (``lmp.file``)."""
    from flatcontact.potentials.lammps_runtime import new_lammps

    path = native_script(model, atoms, positions, protocol, folder)
    lmp = new_lammps()
    try:
        t0 = time.perf_counter()
        lmp.file(str(path))
        seconds = time.perf_counter() - t0
        iterations = int(lmp.extract_global("ntimestep"))
    finally:
        lmp.close()
    return seconds, iterations


def cu_model():
    """The benchmarks' interaction model: Cu EAM (Mishin) inside each body, LJ (10 Å) across."""
    from flatcontact.potentials.model import InteractionModel

    return InteractionModel.model_validate(
        {
            "intra": [{"pair_style": "eam/alloy", "pair_coeff": ["Cu_mishin1.eam.alloy"]}],
            "coupling": "lj",
            "lj": {"cutoff_angstrom": 10.0},
        }
    )


def cu_recipe(layers: int = 3):
    """The benchmarks' interface recipe: Cu(111) on Cu(111), 3 Å gap."""
    from flatcontact.structures.recipe import parse_recipe

    return parse_recipe(
        {
            "kind": "fcc111",
            "element": "Cu",
            "a_angstrom": 3.615,
            "layers": layers,
            "gap_angstrom": 3.0,
        }
    )


def cu_cylinder(radius_angstrom: float):
    """The Cu(111) LJ cylinder of radius R at p0 = 1 GPa (E* 73 GPa, bodies 3 Hertz half-widths
    deep) and the normal force (eV/Å) of that p0 over the cell's axis length: (atoms, force)."""
    from flatcontact.asperity.builder import build_asperity
    from flatcontact.asperity.experiment import GPA_ANGSTROM2_TO_EV_PER_ANGSTROM

    atoms, sizes = build_asperity(
        cu_recipe(), "cylinder", radius_angstrom, 1.0, 73.0, depth_factor=3.0
    )
    a = sizes.hertz_half_width_angstrom
    axis = float(np.linalg.norm(atoms.cell.array[0]))
    # the 2D Hertz load per length P' = pi a p0 / 2 (Johnson, Contact Mechanics, section 7.2;
    # contact/line_contact.py) times the axis length
    return atoms, np.pi * a * 1.0 / 2.0 * axis * GPA_ANGSTROM2_TO_EV_PER_ANGSTROM


def main() -> None:
    from flatcontact.asperity.driver import Protocol, relax

    radius = float(os.environ.get("ASPERITY_BENCH_RADIUS_ANGSTROM", "800"))
    model = cu_model()
    atoms, force = cu_cylinder(radius)
    protocol = Protocol(force, 0.05, 1)
    # alternated twice, the faster of each kept (the machine is shared: its load drifts)
    tools, natives = [], []
    for _ in range(2):
        t0 = time.perf_counter()
        state = relax(model, atoms, atoms.positions.copy(), protocol)
        tools.append(time.perf_counter() - t0)
        with tempfile.TemporaryDirectory() as tmp:
            seconds, n_native = _native(model, atoms, atoms.positions.copy(), protocol, Path(tmp))
        natives.append(seconds)
    tool, native = min(tools), min(natives)
    print(f"cylinder R = {radius:g} Å, {len(atoms):,} atoms, press to {force:.4g} eV/Å")
    print(
        f"driver: {tool:.1f} s, {state.iterations} iterations, "
        f"{tool / state.iterations * 1e3:.2f} ms per force call"
    )
    print(
        f"plain LAMMPS script: {native:.1f} s, {n_native} iterations, "
        f"{native / n_native * 1e3:.2f} ms per force call"
    )
    print(
        f"ratio per force call (driver / script): {tool / state.iterations / (native / n_native):.3f}"
    )
