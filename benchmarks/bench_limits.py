"""The resource-limit floors, measured: the smallest ``ulimit -v`` and ``ulimit -f`` each command runs under.

``python -m benchmarks limits`` (all three workloads, both limits: about 15 min on a loaded
2-core machine, most of it the two runs) or ``python -m benchmarks.bench_limits WORKLOAD ...``
(``import``, ``toy``, ``lammps``). Writes ``benchmarks/limits_measured.json``, from which
``docs/measured/resource-floors.md``'s table is made (``python -m benchmarks.bench_limits --table``).

The floors it measures:

- :data:`flatcontact.cli.memory_floor.MIN_ADDRESS_SPACE_BYTES` (``ulimit -v``): below it the
  command line refuses to start, in one line, because a library would fail to load (an
  ``ImportError`` stack from numpy) or OpenBLAS would give up as it starts;
- :data:`flatcontact.potentials.lammps_runtime.MPI_MIN_FILE_BYTES` (``ulimit -f``): below it a
  LAMMPS model is refused before MPI starts, because MPI_Init aborts the process with a
  multi-line stack when it cannot write its shared-memory pool.

Each workload runs in a child process whose limit is set as ``ulimit`` sets it (``setrlimit``
of the soft limit before ``exec``, so the interpreter's own start counts), with both floors
switched off in the child (the memory-floor module replaced by an empty one, the MPI floor set to
0), so the child meets the real failure. The smallest limit at which it exits 0 is found by
bisection (8 MiB steps for the address space, 64 KiB for the file size; a run is one fresh
``--out``). Workloads: ``libraries`` = numpy, SciPy, pandas, xarray, h5netcdf, matplotlib, ASE
and a LAMMPS instance (MPI started) imported and made without the command line,
``import`` = ``flatcontact --help`` (the command line and every command
module imported), ``toy`` = ``flatcontact run`` of the toy Lennard-Jones study of
``tests/hardening`` (3×3 grid, every stage), ``lammps`` = ``flatcontact run`` of a 3-layer
Cu(111) with Mishin's EAM (3×3 grid, serial executor: LAMMPS loaded, MPI started).
"""

from __future__ import annotations

import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from tests.hardening.helpers import TOY_YAML  # the toy study the hardening tests run

HERE = Path(__file__).resolve().parent
RECORD = HERE / "limits_measured.json"
MIB = 1024 * 1024

LAMMPS_YAML = """\
structure: {kind: fcc111, element: Cu, layers: 3}
potential: {preset: cu-eam}
scan: {grid: [3, 3], p_range_gpa: {lo_gpa: 0.0, hi_gpa: 1.0, n: 3}, executor: serial, relax_mode: normal}
analysis: {p_gpa: [0.0, 0.5]}
contact: {contact_modulus_gpa: 100, shear_modulus_gpa: 40, p0_gpa: [0.5], accept_untrusted: [broken_symmetry, negative_slope, in_slab_slip, degenerate_minima]}
report: {svg: false}
"""
#: The child: both floors off, then the command line (the limit is already set).
CHILD = """\
import sys, types
sys.modules["flatcontact.cli.memory_floor"] = types.ModuleType("flatcontact.cli.memory_floor")
import flatcontact.potentials.lammps_runtime as runtime
runtime.MPI_MIN_FILE_BYTES = 0
from flatcontact.cli import main
main(sys.argv[1:])
"""
#: The libraries a run loads, without the command line: what the address-space floor is for.
LIBRARIES = """\
import sys, types
sys.modules["flatcontact.cli.memory_floor"] = types.ModuleType("flatcontact.cli.memory_floor")
import numpy, scipy.optimize, scipy.interpolate, pandas, xarray, h5netcdf, matplotlib.pyplot
import ase.db, ase.optimize
import flatcontact.potentials.lammps_runtime as runtime
runtime.MPI_MIN_FILE_BYTES = 0
runtime.new_lammps().close()  # the LAMMPS library mapped and MPI started
"""
#: workload -> (config text or None, the command's arguments after the config); the workload
#: ``libraries`` runs :data:`LIBRARIES` instead of the command line
WORKLOADS = {
    "libraries": (None, []),
    "import": (None, ["--help"]),
    "toy": (TOY_YAML, ["run"]),
    "lammps": (LAMMPS_YAML, ["run"]),
}
#: limit -> (resource, bisection step in bytes, range searched in bytes)
LIMITS = {
    "ulimit -v": (resource.RLIMIT_AS, 8 * MIB, (64 * MIB, 2048 * MIB)),
    "ulimit -f": (resource.RLIMIT_FSIZE, 64 * 1024, (0, 64 * MIB)),
}


def attempt(workload: str, limit: str, value: int, folder: Path) -> tuple[bool, str]:
    """Run ``workload`` under ``limit`` = ``value`` bytes in a fresh folder: (exit 0, what it
    said: the status, the count of stderr lines and the last one)."""
    text, args = WORKLOADS[workload]
    folder.mkdir(parents=True)
    argv = list(args)
    if text is not None:
        (folder / "run.yaml").write_text(text)
        argv += ["run.yaml", "--out", "out"]
    kind = LIMITS[limit][0]

    def apply() -> None:
        resource.setrlimit(kind, (value, resource.getrlimit(kind)[1]))

    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    code = LIBRARIES if workload == "libraries" else CHILD
    proc = subprocess.run(
        [sys.executable, "-c", code, *argv],
        cwd=folder,
        env=env,
        preexec_fn=apply,
        capture_output=True,
        text=True,
        timeout=900,
    )
    # the folder is a temporary one: named by where the command ran (its working directory)
    text = proc.stderr.replace(str(folder), ".").replace(tempfile.gettempdir(), "TMP")
    lines = [x for x in text.strip().splitlines() if x.strip()]
    said = (lines or [""])[-1][:160]
    return proc.returncode == 0, f"exit {proc.returncode}, {len(lines)} stderr line(s): {said}"


def smallest(workload: str, limit: str, root: Path) -> dict:
    """The smallest passing value of ``limit`` for ``workload`` (bisection, module docstring)."""
    _, step, (lo, hi) = LIMITS[limit]
    tries = 0

    def ok(value: int) -> tuple[bool, str]:
        nonlocal tries
        tries += 1
        return attempt(workload, limit, value, root / f"{limit[-1]}-{workload}-{tries}")

    passed, said = ok(hi)
    if not passed:
        return {"passes_at_bytes": None, "fails_at_bytes": hi, "failure": said, "tries": tries}
    passed, failure = ok(lo)
    if passed:
        return {"passes_at_bytes": lo, "fails_at_bytes": None, "failure": "", "tries": tries}
    while hi - lo > step:
        mid = (lo + hi) // 2 // step * step
        passed, said = ok(mid)
        if passed:
            hi = mid
        else:
            lo, failure = mid, said
    return {"passes_at_bytes": hi, "fails_at_bytes": lo, "failure": failure, "tries": tries}


def main(workloads: list[str] | None = None) -> None:
    from flatcontact.cli.memory_floor import MIN_ADDRESS_SPACE_BYTES
    from flatcontact.potentials.lammps_runtime import MPI_MIN_FILE_BYTES

    wanted = workloads or list(WORKLOADS)
    record = json.loads(RECORD.read_text()) if RECORD.exists() else {}
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        for workload in wanted:
            for limit in LIMITS:
                t0 = time.perf_counter()
                found = smallest(workload, limit, Path(tmp))
                found["seconds"] = round(time.perf_counter() - t0, 1)
                record.setdefault(workload, {})[limit] = found
                passes = found["passes_at_bytes"]
                shown = "none in range" if passes is None else f"{passes / MIB:.3f} MiB"
                print(
                    f"{workload:7s} {limit}: passes at {shown}, fails at "
                    f"{_mib(found['fails_at_bytes'])} ({found['tries']} runs, "
                    f"{found['seconds']} s): {found['failure']}",
                    flush=True,
                )
    record["floors_bytes"] = {"ulimit -v": MIN_ADDRESS_SPACE_BYTES, "ulimit -f": MPI_MIN_FILE_BYTES}
    record["load_average_at_start"] = round(load, 2)
    record["machine"] = f"{os.cpu_count()} cores"
    RECORD.write_text(json.dumps(record, indent=1) + "\n")
    print(table(record))


#: Limits (MiB of address space) at which :func:`modes` records how a workload fails with
#: the floor off: the round-3 corpus's 40 000 and 100 000 kB, steps up to the floor and above
#: it up to what a LAMMPS run needs.
MODE_LIMITS_MIB = (39, 98, 195, 256, 384, 448, 511, 576, 640, 704, 768)


def modes(workloads: list[str]) -> None:
    """How each workload ends under ``ulimit -v`` below the floor, with the floor off: the
    record's ``modes`` (limit in MiB -> what it said), printed as they come."""
    record = json.loads(RECORD.read_text()) if RECORD.exists() else {}
    with tempfile.TemporaryDirectory() as tmp:
        for workload in workloads:
            seen = record.setdefault("modes", {}).setdefault(workload, {})
            for mib in MODE_LIMITS_MIB:
                _, said = attempt(workload, "ulimit -v", mib * MIB, Path(tmp) / f"{workload}-{mib}")
                seen[str(mib)] = said
                print(f"{workload:7s} ulimit -v {mib} MiB: {said}", flush=True)
    RECORD.write_text(json.dumps(record, indent=1) + "\n")


def _mib(value: int | None) -> str:
    return "— (passes at the lower end)" if value is None else f"{value / MIB:.3f} MiB"


def table(record: dict) -> str:
    """The Markdown table of docs/measured/resource-floors.md from the record."""
    rows = [
        "| workload | limit | smallest passing | largest failing | how it fails just below |",
        "|---|---|---|---|---|",
    ]
    for workload in WORKLOADS:
        for limit in LIMITS:
            found = (record.get(workload) or {}).get(limit)
            if found is None:
                continue
            passes = found["passes_at_bytes"]
            shown = "—" if passes is None else f"{passes / MIB:.2f} MiB"
            failure = re.sub(r"/tmp/\S*?/(out|run\.yaml)", r"./\1", found["failure"])
            failure = failure.replace("|", "\\|")
            rows.append(
                f"| {workload} | `{limit}` | {shown} | {_mib(found['fails_at_bytes'])} | "
                f"{failure} |"
            )
    modes_seen = record.get("modes") or {}
    if modes_seen:
        rows += [
            "",
            "| workload | `ulimit -v`, floor off | how it ends |",
            "|---|---|---|",
        ]
        for workload in WORKLOADS:
            for mib, said in (modes_seen.get(workload) or {}).items():
                said = re.sub(r"/\S*/(site-packages|lib)/", r"…/\1/", said).replace("|", "\\|")
                rows.append(f"| {workload} | {mib} MiB | {said} |")
    return "\n".join(rows)


if __name__ == "__main__":
    args = sys.argv[1:]
    if args == ["--table"]:
        print(table(json.loads(RECORD.read_text())))
    elif args[:1] == ["--modes"]:
        modes(args[1:] or list(WORKLOADS))
    else:
        main(args or None)
