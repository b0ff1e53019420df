"""The asperity at >= 100,000 atoms on 1 and 2 MPI ranks against plain LAMMPS (issue 35).

``python -m benchmarks asperity_large`` (under 5 minutes on an idle 2-core machine).

One press of a Cu(111) cylinder (EAM inside each body, LJ across, cutoff 10 Å; R = 2600 Å,
107,594 atoms) as the asperity stage runs it — :func:`flatcontact.asperity.driver.compute_step`
in this process for 1 rank, :func:`flatcontact.asperity.ranks.run_steps` (``mpiexec -n 2``, the
ranks' Python started, the job read, the state saved) for 2 — against the same minimisation
written as a plain LAMMPS input script (``bench_asperity.native_script``: the same data, pair
commands, groups, fixes, FIRE and tolerance) run by ``mpiexec -n N lmp -in`` (the wheel's
``lmp``). Every run stops at the same FIRE iteration cap (``ASPERITY_LARGE_ITERATIONS``,
default 200; a slide step of the measured 80 nm cylinder took ~2000), one force call per iteration, so
the cost per force call compares like with like; the driver's time includes all its own
overhead (a fresh LAMMPS instance, the atoms scattered, the groups, the gathers, the force
evaluation of the flat alone), the script's its start and ``read_data``.

Printed: atoms, iterations and force evaluations, seconds and seconds per force call of each
run, the ratios driver / script at each rank count and the speed-up of 2 ranks over 1 of
each, the memory estimate of the up-front check at 1 and 2 ranks against the largest
resident set measured, and the load average before and after (flagged above 0.5 per core:
the figures are then upper bounds and the speed-up reads low).

``ASPERITY_LARGE_RADIUS_ANGSTROM`` sets the size (2600: 107,594 atoms), ``ASPERITY_LARGE_REPEATS``
the repetitions (default 1; with more, each run's fastest is kept).
"""

from __future__ import annotations

import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _load() -> float:
    return os.getloadavg()[0]


def _breakdown(text: str) -> str:
    """LAMMPS's processor grid and task timing breakdown (average seconds per section) as
    one line."""
    grid = re.search(r"(\d+) by (\d+) by (\d+) MPI processor grid", text)
    rows = re.findall(r"^(Pair|Neigh|Comm|Output|Modify|Other)\s*\|(.*)$", text, re.M)
    parts = []
    for name, rest in rows:
        cells = [c.strip() for c in rest.split("|")]
        parts.append(f"{name} {float(cells[1]):.2f}")  # the average over ranks
    where = "x".join(grid.groups()) + " grid; " if grid else ""
    return where + ", ".join(parts) + " s"


def _script(script: Path, ranks: int, folder: Path) -> tuple[float, int, int, float, str]:
    """(wall s, iterations, force evaluations, LAMMPS loop s, its timing breakdown) of
    ``mpiexec -n ranks lmp``."""
    from flatcontact.asperity.ranks import mpiexec

    log = folder / f"script_{ranks}.log"
    lmp = Path(sys.executable).parent / "lmp"
    cmd = [mpiexec(), "-n", str(ranks), str(lmp), "-in", str(script), "-log", str(log)]
    cmd += ["-screen", "none", "-nocite"]
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
    seconds = time.perf_counter() - t0
    text = log.read_text()
    m = re.search(r"Iterations, force evaluations\s*=\s*(\d+)\s+(\d+)", text)
    loop = re.search(r"Loop time of ([\d.eE+-]+) on (\d+) procs", text)
    if m is None or loop is None or int(loop.group(2)) != ranks:
        raise RuntimeError(f"unexpected LAMMPS log {log}")
    return seconds, int(m.group(1)), int(m.group(2)), float(loop.group(1)), _breakdown(text)


def _driver(model, atoms, protocol, ranks: int, folder: Path) -> tuple[float, int, bool]:
    """(wall s, iterations, converged) of the press as the asperity stage runs it."""
    from flatcontact.asperity.driver import compute_step, load_state, step_path
    from flatcontact.asperity.ranks import run_steps

    t0 = time.perf_counter()
    if ranks == 1:
        state = compute_step(model, atoms, atoms.positions.copy(), protocol, 0)
    else:
        sub = folder / f"driver_{ranks}"
        sub.mkdir()
        run_steps(model, atoms, protocol, sub, 0, None, ranks)
        state = load_state(step_path(sub, 0))
        assert state.ranks == ranks
    return time.perf_counter() - t0, state.iterations, state.converged


def _setup():
    from benchmarks.bench_asperity import cu_cylinder, cu_model
    from flatcontact.asperity.driver import Protocol

    radius = float(os.environ.get("ASPERITY_LARGE_RADIUS_ANGSTROM", "2600"))
    iterations = int(os.environ.get("ASPERITY_LARGE_ITERATIONS", "200"))
    model = cu_model()
    atoms, force = cu_cylinder(radius)
    # steps 0: the press alone; the cap makes every run the same number of force calls
    protocol = Protocol(force, 0.05, 0, 1e-3, max_iterations=iterations)
    return radius, model, atoms, protocol


def main() -> None:
    from benchmarks.bench_asperity import native_script
    from flatcontact.asperity.builder import check_machine

    cores = os.cpu_count() or 1
    radius, model, atoms, protocol = _setup()
    repeats = int(os.environ.get("ASPERITY_LARGE_REPEATS", "1"))
    n = len(atoms)
    print(
        f"cylinder R = {radius:g} Å, {n:,} atoms, press to "
        f"{protocol.normal_force_ev_per_angstrom:.4g} eV/Å, FIRE capped at "
        f"{protocol.max_iterations} iterations; {cores} cores",
        flush=True,
    )
    before = _load()
    best: dict[tuple[str, int], tuple[float, int]] = {}
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        script = native_script(model, atoms, atoms.positions.copy(), protocol, tmp)
        for rep in range(repeats):
            for ranks in (2, 1):
                # 2 ranks' driver first: the children's largest resident set is then a rank's
                run = tmp / f"rep{rep}"
                run.mkdir(exist_ok=True)
                sec, it, _ = _driver(model, atoms, protocol, ranks, run)
                if ranks == 2 and rep == 0:
                    rss_rank = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
                print(f"  driver  {ranks} rank(s): {sec:7.1f} s, {it} iterations", flush=True)
                if ("driver", ranks) not in best or sec < best["driver", ranks][0]:
                    best["driver", ranks] = (sec, it)
                sec, it, ev, loop, sections = _script(script, ranks, tmp)
                print(
                    f"  script  {ranks} rank(s): {sec:7.1f} s ({loop:.1f} s in LAMMPS's loop: "
                    f"{sections}), {it} iterations, {ev} force evaluations",
                    flush=True,
                )
                if ("script", ranks) not in best or sec < best["script", ranks][0]:
                    best["script", ranks] = (sec, it)
                if ("loop", ranks) not in best or loop < best["loop", ranks][0]:
                    best["loop", ranks] = (loop, it)
    after = _load()
    rss_self = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    per_call = {key: sec / it for key, (sec, it) in best.items()}
    print(f"atoms {n:,}; iterations {protocol.max_iterations} (one force call each)")
    for ranks in (1, 2):
        d, s, lp = (per_call[who, ranks] for who in ("driver", "script", "loop"))
        print(
            f"{ranks} rank(s): driver {d * 1e3:.1f} ms per force call, plain LAMMPS script "
            f"{s * 1e3:.1f} ms ({lp * 1e3:.1f} ms in its loop); ratio driver / script "
            f"{d / s:.3f} (driver / script's loop {d / lp:.3f})"
        )
    for who, label in (("driver", "driver"), ("script", "script"), ("loop", "script's loop")):
        print(f"speed-up of 2 ranks over 1, {label}: {per_call[who, 1] / per_call[who, 2]:.2f}")
    est1 = check_machine(n, 100)
    est2 = check_machine(n, 100, ranks=2)
    print(
        f"memory: estimate {est1 / 1e9:.2f} GB on 1 rank, {est2 / 1e9:.2f} GB on 2 ranks; "
        f"measured largest resident set: this process {rss_self / 1e9:.2f} GB, a rank "
        f"{rss_rank / 1e9:.2f} GB"
    )
    flag = (
        "  (LOADED: upper bounds, the speed-up reads low)"
        if max(before, after) > 0.5 * cores
        else ""
    )
    print(f"load average before {before:.2f}, after {after:.2f}{flag}")
