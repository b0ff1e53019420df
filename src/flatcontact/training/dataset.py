"""Training datasets: extxyz files with energies, forces and (optionally) stresses.

Conventions (ASE): energy in eV (total, per configuration), forces in eV/Å,
stress in eV/Å³, Voigt order (xx, yy, zz, yz, xz, xy), positive = tensile
(``stress = (1/V) dE/d(strain)``). Each frame may carry
``info["config_type"]`` (a group name used for weights, splits and reports).

:func:`read_dataset` validates everything before any work starts and raises a
one-line :class:`~flatcontact.foundation.errors.InputError` that names the file and frame: first the
checked structure reader (:func:`flatcontact.structures.structure_file.read_structures`:
file size and claimed atom counts before parsing; atom count, finite positions and cell,
cell shape and minimum distance per frame), then the labels (:func:`validate_frame`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from ase import Atoms
from ase.calculators.singlepoint import SinglePointCalculator
from ase.io import write
from ase.neighborlist import neighbor_list

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import atomic_path
from flatcontact.structures.structure_file import read_structures

#: Two atoms closer than this (Å) make a frame unphysical.
MIN_DISTANCE_ANGSTROM = 0.6


def labelled(atoms: Atoms, energy: float, forces: np.ndarray, stress: np.ndarray | None) -> Atoms:
    """A copy of ``atoms`` carrying the labels on a :class:`SinglePointCalculator`."""
    out = atoms.copy()
    results = {"energy": float(energy), "forces": np.asarray(forces, dtype=float)}
    if stress is not None:
        results["stress"] = np.asarray(stress, dtype=float).reshape(6)
    out.calc = SinglePointCalculator(out, **results)
    return out


def labels(atoms: Atoms) -> tuple[float, np.ndarray, np.ndarray | None]:
    """``(energy, forces, stress or None)`` stored on a frame."""
    res = atoms.calc.results
    stress = res.get("stress")
    if stress is not None:
        stress = np.asarray(stress, dtype=float)
        if stress.shape == (3, 3):
            stress = stress[[0, 1, 2, 1, 0, 0], [0, 1, 2, 2, 2, 1]]
    return float(res["energy"]), np.asarray(res["forces"], dtype=float), stress


def validate_frame(atoms: Atoms, where: str, elements: Sequence[str] | None = None) -> None:
    """Check one labelled frame; raise :class:`InputError` naming ``where`` on the first problem."""
    n = len(atoms)
    if n == 0:
        raise InputError(f"{where}: frame has no atoms")
    symbols = set(atoms.get_chemical_symbols())
    if elements is not None and not symbols <= set(elements):
        raise InputError(
            f"{where}: unknown element(s) {sorted(symbols - set(elements))}; expected only {list(elements)}"
        )
    if not atoms.pbc.all():
        raise InputError(
            f"{where}: pbc={atoms.pbc.tolist()}; training frames must be periodic in x, y and z "
            "(put slabs and clusters in a box with vacuum)"
        )
    cell = np.asarray(atoms.cell)
    vol = abs(np.linalg.det(cell))
    if not np.isfinite(cell).all() or vol < 1e-6 * max(1.0, np.linalg.norm(cell) ** 3):
        raise InputError(f"{where}: cell {cell.tolist()} is degenerate (volume {vol:.3g} Å^3)")
    if not np.isfinite(atoms.positions).all():
        raise InputError(f"{where}: non-finite positions")
    if n > 1:
        d = neighbor_list("d", atoms, MIN_DISTANCE_ANGSTROM)
        if len(d):
            raise InputError(
                f"{where}: atoms {d.min():.3f} Å apart (< {MIN_DISTANCE_ANGSTROM} Å); "
                "positions and cell are inconsistent"
            )
    if atoms.calc is None or "energy" not in atoms.calc.results:
        raise InputError(f"{where}: missing energy")
    if "forces" not in atoms.calc.results:
        raise InputError(f"{where}: missing forces")
    energy, forces, stress = labels(atoms)
    if not np.isfinite(energy):
        raise InputError(f"{where}: non-finite energy {energy}")
    if forces.shape != (n, 3) or not np.isfinite(forces).all():
        raise InputError(
            f"{where}: forces have shape {forces.shape}, expected ({n}, 3) finite values"
        )
    if stress is not None and (stress.shape != (6,) or not np.isfinite(stress).all()):
        raise InputError(
            f"{where}: stress has shape {stress.shape}, expected 6 finite Voigt values"
        )


def read_dataset(path: str | Path, elements: Sequence[str] | None = None) -> list[Atoms]:
    """Read and validate an extxyz training set (every frame labelled)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: dataset file not found")
    # the checked structure reader: size, claimed atom counts before parsing; atom count,
    # finite positions and cell, cell shape, minimum distance of every frame after
    frames = read_structures(path, format="extxyz")
    for k, atoms in enumerate(frames):
        validate_frame(atoms, f"{path} frame {k}", elements)
        atoms.info.setdefault("config_type", "default")
    return frames


def write_dataset(frames: Sequence[Atoms], path: str | Path) -> Path:
    """Write labelled frames as extxyz atomically."""
    path = Path(path)
    with atomic_path(path) as tmp:
        write(tmp, list(frames), format="extxyz")
    return path
