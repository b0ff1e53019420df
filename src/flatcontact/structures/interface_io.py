"""Reading and writing the interface file (``interface.extxyz``, extended XYZ).

What the file holds and its checks: :mod:`flatcontact.structures.interface_contract`.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
from ase import Atoms
from ase.io import write

from flatcontact.foundation.errors import require
from flatcontact.foundation.fileio import atomic_path
from flatcontact.structures.interface_contract import (
    fixed_mask,
    in_plane_vectors,
    validate_interface,
)
from flatcontact.structures.layers import interface_layers
from flatcontact.structures.structure_file import read_structure


def write_interface(atoms: Atoms, path: str | os.PathLike[str]) -> Path:
    """Write the interface as extended XYZ (arrays and info kept), atomically."""
    validate_interface(atoms, str(path))
    out = atoms.copy()
    out.calc = None
    a1, a2 = in_plane_vectors(out)
    out.info = {
        "a1": np.asarray(a1, dtype=float),
        "a2": np.asarray(a2, dtype=float),
        "recipe": str(atoms.info.get("recipe", "{}")),
    }
    if atoms.info.get("material"):
        out.info["material"] = str(atoms.info["material"])
    out.arrays["slab"] = np.asarray(out.arrays["slab"], dtype=int)
    out.arrays["surface"] = np.asarray(out.arrays["surface"], dtype=int)
    if "layer" in out.arrays:
        out.arrays["layer"] = np.asarray(out.arrays["layer"], dtype=int)
    if "held" in out.arrays:
        out.arrays["held"] = np.asarray(out.arrays["held"], dtype=bool)
    with atomic_path(path) as tmp:
        write(tmp, out, format="extxyz")
    return Path(path)


def read_interface(path: str | os.PathLike[str]) -> Atoms:
    """Read an ``interface.extxyz`` and validate it (one-line :class:`InputError` if not valid).

    The file is read by :func:`flatcontact.structures.structure_file.read_structure` (size,
    atom count, finite positions, cell shape, minimum distance) before the contract's checks.

    A file without ``layer`` gets one found from the structure
    (:func:`flatcontact.structures.layers.interface_layers`); without ``held`` the
    contract's default (surfaces 1 and 4) is stored explicitly.
    """
    path = Path(path)
    require(path.is_file(), f"{path}: interface file not found")
    atoms = read_structure(path, format="extxyz", index=-1)
    validate_interface(atoms, str(path))
    atoms.arrays["slab"] = np.asarray(atoms.arrays["slab"], dtype=int)
    atoms.arrays["surface"] = np.asarray(atoms.arrays["surface"], dtype=int)
    atoms.arrays["held"] = fixed_mask(atoms)
    if "layer" in atoms.arrays:
        atoms.arrays["layer"] = np.asarray(atoms.arrays["layer"], dtype=int)
    else:
        atoms.arrays["layer"] = interface_layers(atoms)
        validate_interface(atoms, str(path))
    a1, a2 = in_plane_vectors(atoms)
    recipe = atoms.info.get("recipe", "{}")
    if not isinstance(recipe, str):
        recipe = json.dumps(recipe)
    info = {"a1": a1, "a2": a2, "recipe": recipe}
    if atoms.info.get("material"):
        info["material"] = str(atoms.info["material"])
    atoms.info = info
    return atoms
