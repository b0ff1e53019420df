"""The memory limit a command starts under, checked when the command line is imported.

Imported first by :mod:`flatcontact.cli` (before typer, numpy and the settings): under a
memory limit (``ulimit -v``) below :data:`MIN_ADDRESS_SPACE_BYTES` a library fails to load
(an ``ImportError`` stack from deep inside numpy) or OpenBLAS gives up as it starts (exit 1,
its own line); here the command stops with one ``error:`` line naming the limit, status 2.
"""

import resource as _resource
import sys as _sys

#: Smallest memory limit (ulimit -v, bytes of address space) a command starts under. Measured
#: with this floor off (``python -m benchmarks limits``, tables in
#: docs/measured/resource-floors.md; 2-core Linux, the pinned wheels): below about 195 MiB a
#: command dies in numpy's import (a MemoryError stack, 39 MiB) or in OpenBLAS's own line (exit
#: 1, 98 MiB); the libraries of a LAMMPS run (numpy, SciPy, pandas, xarray, matplotlib, ASE,
#: LAMMPS) with MPI started need 432 MiB, and just below, MPI_Init aborts the process with a
#: 6-line stack (exit 143: at 424 MiB alone, at 448 MiB in a Cu(111) EAM run). 512 MiB is the
#: power of two above that window; from there up to what a run needs (a toy run 656 MiB, a
#: 3x3 Cu(111) EAM run 816 MiB) a run ends in the one "out of memory" line of the command line.
MIN_ADDRESS_SPACE_BYTES = 512 * 1024 * 1024
_limit = _resource.getrlimit(_resource.RLIMIT_AS)[0]
if _limit != _resource.RLIM_INFINITY and _limit < MIN_ADDRESS_SPACE_BYTES:
    _sys.stderr.write(
        f"error: the memory limit of this process (ulimit -v: {_limit // 1024} kB) is below the "
        f"{MIN_ADDRESS_SPACE_BYTES // (1024 * 1024)} MiB flatcontact needs to load its numerical "
        "libraries; raise it (ulimit -v) and rerun\n"
    )
    _sys.exit(2)
