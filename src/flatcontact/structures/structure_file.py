"""The one checked reader of every structure file a user gives (interface, slab, bulk, sheet,
training set).

:func:`read_structure` reads a file (:func:`read_structures` every frame of it) with ASE between two sets of checks, each refusal one
:class:`~flatcontact.foundation.errors.InputError` naming the field, the file and the defect:

Before parsing (nothing allocated from what the file claims):

- the file is at most ``structure_mb`` MB (:mod:`flatcontact.foundation.limits`,
  ``FLATCONTACT_MAX_STRUCTURE_MB``);
- an XYZ / extended XYZ file (by the format ASE detects) is walked frame by frame: each
  frame's first line is an atom count between 0 and the ``atoms`` bound
  (``FLATCONTACT_MAX_ATOMS``) whose lines the file actually holds. ASE's reader skips
  ``count`` lines per frame, so a file claiming 10¹² atoms would otherwise never end.

After parsing (before anything is built, relaxed or handed to LAMMPS):

- 1 ≤ atoms ≤ the ``atoms`` bound;
- every position and cell component finite;
- every cell vector and the spread of the positions along x, y, z at most
  :data:`MAX_LENGTH_ANGSTROM` (LAMMPS bins the bounding box of the cell);
- the periodic cell not degenerate: a cell vector marked periodic is not zero; with three
  periodic vectors each cell height (volume / area of the opposite face) is at least
  :data:`MIN_CELL_HEIGHT_ANGSTROM` and the volume per atom at most
  :data:`MAX_VOLUME_PER_ATOM_ANGSTROM3`; with two, the same in the plane (heights = area /
  length of the other vector, area per atom at most :data:`MAX_AREA_PER_ATOM_ANGSTROM2`);
- no two atoms (periodic images included) closer than :data:`MIN_DISTANCE_ANGSTROM`;
- a CIF has no partly occupied and no mixed site (:mod:`flatcontact.structures.site_checks`,
  checked before parsing).

The bounds are far outside any solid (the shortest bond, H₂, is 0.74 Å; the shortest
lattice repeat of a crystal ~2 Å; a solid holds 5-50 Å³ per atom) and well inside what a
neighbour list or a LAMMPS box can hold.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
from ase import Atoms
from ase.io import read
from ase.io.formats import filetype
from ase.neighborlist import neighbor_list

from flatcontact.foundation import limits
from flatcontact.foundation.errors import InputError

#: Closest two atoms may be (Å), periodic images included.
MIN_DISTANCE_ANGSTROM = 0.5
#: Smallest height of a periodic cell (Å): volume (3D) or area (2D) over the opposite face.
MIN_CELL_HEIGHT_ANGSTROM = 1.0
#: Longest cell vector and widest spread of positions along x, y or z (Å).
MAX_LENGTH_ANGSTROM = 1000.0
#: Largest volume per atom of a cell periodic in 3D (Å³): vacuum of a slab included.
MAX_VOLUME_PER_ATOM_ANGSTROM3 = 1.0e4
#: Largest in-plane area per atom of a cell periodic in 2D (Å²).
MAX_AREA_PER_ATOM_ANGSTROM2 = 1.0e3

_XYZ_FORMATS = ("xyz", "extxyz")


def read_structure(
    path: str | os.PathLike[str],
    field: str = "",
    *,
    format: str | None = None,
    index: int | None = None,
) -> Atoms:
    """Read one frame of a structure file, checked before and after parsing.

    Parameters
    ----------
    path
        The file (any format ASE reads).
    field
        The config field or flag that named the file, put in front of every message.
    format, index
        As for :func:`ase.io.read` (default: format detected, last frame).

    Raises
    ------
    InputError
        One line ``"<field>: <path>: <defect>"``.
    """
    path, label = _checked_file(path, field, format)
    atoms = _read(path, label, format, -1 if index is None else index)
    if not isinstance(atoms, Atoms):
        raise InputError(f"{label}: expected one structure, found {type(atoms).__name__}")
    check_structure(atoms, label)
    return atoms


def read_structures(
    path: str | os.PathLike[str], field: str = "", *, format: str | None = None
) -> list[Atoms]:
    """Every frame of a structure file (a training set), each checked as
    :func:`read_structure` checks one; messages name ``"<path> frame <k>"`` (from 0).

    Raises
    ------
    InputError
        One line naming the file (and the frame) and the first defect; a file without
        frames is one too.
    """
    path, label = _checked_file(path, field, format)
    frames = _read(path, label, format, ":")
    frames = [frames] if isinstance(frames, Atoms) else list(frames)
    if not frames:
        raise InputError(f"{label}: no frames")
    for k, atoms in enumerate(frames):
        check_structure(atoms, f"{label} frame {k}")
    return frames


def _checked_file(path, field: str, format: str | None) -> tuple[Path, str]:
    """(path, label) of a file that exists and passed :func:`check_file`."""
    path = Path(path)
    label = f"{field}: {path}" if field else str(path)
    if not path.is_file():
        raise InputError(f"{label}: file not found")
    check_file(path, label, format)
    return path, label


def _read(path: Path, label: str, format: str | None, index):
    """ASE's reader, its warnings silenced and any failure one line naming the file."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # ASE's warnings on odd files are not the user's
            return read(path, format=format, index=index)
    except Exception as exc:  # any reader error (or MemoryError) is the user's file to fix
        said = " ".join(str(exc).split())[:200]
        raise InputError(
            f"{label}: not a structure file ASE can read ({type(exc).__name__}: {said})"
        ) from None


def check_file(path: Path, label: str, format: str | None = None) -> None:
    """The checks before parsing: file size, and frame atom counts of an XYZ file."""
    size_mb = path.stat().st_size / 1e6
    if size_mb > limits.bound("structure_mb"):
        raise InputError(f"{label}: {limits.message('structure_mb', size_mb, 'MB')}")
    if format is None:
        try:
            format = filetype(str(path), guess=True)
        except Exception:  # ASE's reader will say what it cannot read
            return
    if format in _XYZ_FORMATS:
        _check_xyz_frames(path, label)
    if format == "cif":  # disordered sites: ASE would build one full atom per site
        from flatcontact.structures.site_checks import check_cif_sites

        check_cif_sites(path, label)


def _check_xyz_frames(path: Path, label: str) -> None:
    """Each frame's atom count (first line) within the bound and held by the file."""
    limit = limits.bound("atoms")
    header, claimed, line_no = 0, 0, 0
    with path.open("rb") as handle:
        for line in handle:
            if line_no == header:
                text = line.strip()
                if not text:  # ASE stops at a blank count line
                    return
                try:
                    claimed = int(text)
                except ValueError:
                    raise InputError(
                        f"{label}: line {line_no + 1}: expected the atom count of a frame, "
                        f"found {text[:40].decode(errors='replace')!r}"
                    ) from None
                if claimed < 0:
                    raise InputError(f"{label}: line {line_no + 1}: negative atom count {claimed}")
                if claimed > limit:
                    raise InputError(
                        f"{label}: line {line_no + 1}: "
                        + limits.message("atoms", claimed, "atoms claimed")
                    )
                header = line_no + claimed + 2
            line_no += 1
    if header > line_no:
        raise InputError(
            f"{label}: a frame claims {claimed} atoms but the file ends after {line_no} lines"
        )


def _periodic_vectors(atoms: Atoms, label: str) -> np.ndarray:
    cell = atoms.cell.array
    lengths = np.linalg.norm(cell, axis=1)
    for k in range(3):
        if atoms.pbc[k] and lengths[k] == 0.0:
            raise InputError(f"{label}: periodic along cell vector {k + 1}, which is zero")
    return cell[np.asarray(atoms.pbc, dtype=bool)]


def check_structure(atoms: Atoms, label: str) -> None:
    """The checks after parsing (see the module docstring); one-line InputError."""
    n = len(atoms)
    if n == 0:
        raise InputError(f"{label}: holds no atoms")
    if n > limits.bound("atoms"):
        raise InputError(f"{label}: {limits.message('atoms', n, 'atoms')}")
    pos, cell = atoms.positions, atoms.cell.array
    bad = np.flatnonzero(~np.isfinite(pos).all(axis=1))
    if bad.size:
        raise InputError(f"{label}: atom {bad[0] + 1} has a non-finite position {pos[bad[0]]}")
    if not np.isfinite(cell).all():
        raise InputError(f"{label}: the cell has a non-finite component")
    longest = float(np.linalg.norm(cell, axis=1).max())
    spread = float(np.ptp(pos, axis=0).max())
    if max(longest, spread) > MAX_LENGTH_ANGSTROM:
        what = "a cell vector" if longest >= spread else "the atoms"
        raise InputError(
            f"{label}: {what} spans {max(longest, spread):.4g} Å; expected at most "
            f"{MAX_LENGTH_ANGSTROM:g} Å"
        )
    _check_cell_shape(_periodic_vectors(atoms, label), n, label)
    _check_distances(atoms, label)


def _check_cell_shape(vectors: np.ndarray, n: int, label: str) -> None:
    """Heights ≥ the minimum and volume (or area) per atom ≤ the maximum."""
    if len(vectors) == 3:
        volume = abs(float(np.linalg.det(vectors)))
        faces = [
            np.linalg.norm(np.cross(vectors[j], vectors[k])) for j, k in ((1, 2), (2, 0), (0, 1))
        ]
        heights = [volume / f if f > 0 else 0.0 for f in faces]
        per_atom, unit, limit = volume / n, "Å³ per atom", MAX_VOLUME_PER_ATOM_ANGSTROM3
    elif len(vectors) == 2:
        area = float(np.linalg.norm(np.cross(vectors[0], vectors[1])))
        heights = [area / np.linalg.norm(v) for v in vectors[::-1]]
        per_atom, unit, limit = area / n, "Å² per atom", MAX_AREA_PER_ATOM_ANGSTROM2
    elif len(vectors) == 1:
        heights, per_atom, unit, limit = [float(np.linalg.norm(vectors[0]))], 0.0, "", 1.0
    else:
        return
    if min(heights) < MIN_CELL_HEIGHT_ANGSTROM:
        raise InputError(
            f"{label}: degenerate cell (smallest height {min(heights):.3g} Å); expected every "
            f"periodic cell height at least {MIN_CELL_HEIGHT_ANGSTROM:g} Å"
        )
    if per_atom > limit:
        raise InputError(
            f"{label}: {per_atom:.4g} {unit}; expected at most {limit:g} (not a solid)"
        )


def _check_distances(atoms: Atoms, label: str) -> None:
    """No two atoms (periodic images included) closer than :data:`MIN_DISTANCE_ANGSTROM`."""
    probe = atoms.copy()
    probe.calc = None
    if not probe.pbc.any():
        probe.cell = np.zeros((3, 3))
    i, j, d = neighbor_list("ijd", probe, MIN_DISTANCE_ANGSTROM, self_interaction=False)
    if len(d):
        k = int(np.argmin(d))
        raise InputError(
            f"{label}: atoms {i[k] + 1} and {j[k] + 1} are {d[k]:.3g} Å apart; expected at "
            f"least {MIN_DISTANCE_ANGSTROM:g} Å (overlapping atoms)"
        )
