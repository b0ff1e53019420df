"""The scan's cost per force call against LAMMPS alone, on large cells of cheap potentials.

``python -m benchmarks.optimiser_cost`` relaxes one cold ISPES point per system and size
(:func:`benchmarks.large_cells.case`: the 36-atom quartz cell, the Cu(111) stacking fault
(``cu-eam``) at 1,536, 4,704 and 20,184 atoms, AB bilayer graphene (``graphene-rebo-kc``,
three sheets per slab) at 1,452, 4,800 and 20,172 atoms), each size in its own process, and
measures it two ways:

- **CPU time, interleaved** (``repeats`` times in one process): the scan's relaxation of the
  point (:func:`flatcontact.ispes.relax.relax_point`, N force calls), then LAMMPS alone on
  the same engine at the relaxed positions, ``run N pre no post no`` with ``thermo 1`` (the
  energy on every step, as each of the scan's calls has it). The ratio is taken per pair, so
  a load that changes between pairs moves both sides; the table gives the median of the
  pairs and their range. A first, untimed relaxation warms the engine (its full setup, the
  first neighbour build), as every point but the first of a scan finds it.
- **Instructions** (``valgrind --tool=callgrind``, one process, the same sequence with one
  pair): counts that do not depend on the load. A tiny C library (compiled here with gcc
  from ``valgrind/callgrind.h``) starts the instrumentation after the warm-up
  (``--instr-atstart=no``: the imports run uninstrumented) and dumps the counts between the
  phases; LAMMPS's share of the scan is the inclusive count of ``Input::one`` (what
  ``lammps_command`` runs) in its dump, so the table splits the scan's instructions per
  call into LAMMPS's and ours. The 20,184-atom count stops the relaxation after 40 steps
  (valgrind is ~50× slower). Instructions do not see memory stalls (the L-BFGS algebra is
  bandwidth-bound on large cells), so both columns are given.

- **Cache misses** (``--cache-sim``: the same callgrind run with ``--cache-sim=yes`` and this
  machine's per-core caches, 32 KiB 8-way L1d and 1 MiB 8-way L2, 64 B lines): the bytes
  per call that miss the simulated L2 (read and write misses × 64 B), for the scan, LAMMPS's
  share of it and LAMMPS alone. Instructions do not show memory traffic; this does (it
  does not model the shared 32 MiB L3, whose hit rate depends on the other processes).

The large REBO+KC cells relax a fixed number of force calls (``max_steps`` in
:data:`CASES`: 0.6-2.7 s per call) and skip the instruction count (valgrind is ~50× slower).
System names as arguments run those only (``cu quartz``), ``system:repeat`` one size
(``graphene:20``); ``--repeats=N`` pairs (default 7), ``--no-instructions`` skips valgrind,
``--table-only`` measures nothing, ``--counts-only`` runs the callgrind count alone and
adds it to the newest stored row of that system and size (the timed pairs taken in a quiet
window with ``--no-instructions``, the load-independent counts afterwards).
Every row measured is appended to ``benchmarks/optimiser_cost_measured.jsonl`` (with its
date and load); the table has the newest row of each system and size, and ``--write-docs``
replaces it between the markers in ``docs/performance.md``.
"""

from __future__ import annotations

import ctypes
import dataclasses
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: (system, lateral repeat, optimiser step cap or None, instructions: False, or the step
#: cap of the counted relaxation (0: none))
CASES = (
    ("quartz", 1, None, 0),
    ("cu", 8, None, 0),
    ("cu", 14, None, 0),
    ("cu", 29, None, 40),
    ("graphene", 11, None, False),
    ("graphene", 20, 8, False),
    ("graphene", 41, 8, False),
)
REPEATS = 7
WARMUP_STEPS = 2
#: every row measured (JSON lines, newest last): ``--write-docs`` tables the newest of each
MEASURED = Path(__file__).with_name("optimiser_cost_measured.jsonl")
DOCS = Path(__file__).resolve().parents[1] / "docs" / "performance.md"
BEGIN, END = "<!-- optimiser_cost:begin -->", "<!-- optimiser_cost:end -->"
#: callgrind's cache simulation: this machine's per-core L1 (32 KiB, 8-way) and L2 (1 MiB,
#: 8-way) as the simulated first and last level, 64 B lines
CACHE_SIM = ("--cache-sim=yes", "--I1=32768,8,64", "--D1=32768,8,64", "--LL=1048576,8,64")
LINE_BYTES = 64
MARK_SOURCE = """#include <valgrind/callgrind.h>
void fc_start(void) { CALLGRIND_START_INSTRUMENTATION; }
void fc_dump(const char *s) { CALLGRIND_DUMP_STATS_AT(s); }
"""


def measure(system: str, n: int, repeats: int, max_steps: int | None, mark: str | None) -> dict:
    """In this process: a warm-up relaxation, then ``repeats`` pairs (scan, LAMMPS alone).

    ``mark``: path of the callgrind marker library (instruction counts: dumps named
    ``warmup``, ``scan``, ``alone`` after each phase of the first pair), else ``None``.
    """
    from benchmarks.large_cells import FMAX, case
    from flatcontact.ispes.geometry import thickness
    from flatcontact.ispes.lbfgs import memory_for
    from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point
    from flatcontact.potentials.calculator import LammpsInterfaceCalculator

    marks = ctypes.CDLL(mark) if mark else None
    dump = marks.fc_dump if mark else (lambda label: None)
    ref, model, shift = case(system, n)
    calc = LammpsInterfaceCalculator(model, ref)
    task = PointTask((0, 0, 0), *shift, thickness(ref))
    settings = RelaxSettings(FMAX, max_steps=max_steps or RelaxSettings.max_steps)
    lmp = calc.engine.lmp
    # warm-up: the engine's full setup and first neighbour build (two steps are enough)
    relax_point(ref, calc, task, dataclasses.replace(settings, max_steps=WARMUP_STEPS))
    if marks is not None:  # valgrind ran uninstrumented (--instr-atstart=no) up to here
        marks.fc_start()
    dump(b"warmup")
    scan, alone, calls = [], [], 0
    for _ in range(repeats):
        c0 = time.process_time()
        result = relax_point(ref, calc, task, settings)
        cpu = time.process_time() - c0
        dump(b"scan")
        calls = result.force_calls
        lmp.command("thermo 1")
        c0 = time.process_time()
        lmp.command(f"run {calls} pre no post no")
        alone.append(1e3 * (time.process_time() - c0) / calls)
        lmp.command("thermo 0")
        dump(b"alone")
        scan.append(1e3 * cpu / calls)
        dump = lambda label: None  # noqa: E731 - counts of the first pair only
    ratios = [s / a for s, a in zip(scan, alone, strict=True)]
    return {
        "system": system,
        "atoms": len(ref),
        "memory": memory_for(3 * len(ref)),
        "force_calls": calls,
        "converged": bool(result.converged),
        "capped": max_steps is not None,
        "scan_ms": statistics.median(scan),
        "alone_ms": statistics.median(alone),
        "ratio": statistics.median(ratios),
        "ratio_range": (min(ratios), max(ratios)),
        "repeats": repeats,
        "load": os.getloadavg()[0],
    }


def _marker_library(folder: str) -> str | None:
    """The callgrind marker library compiled into ``folder``, or None (no gcc, no header)."""
    if not (shutil.which("valgrind") and shutil.which("gcc")):
        return None
    src, lib = os.path.join(folder, "mark.c"), os.path.join(folder, "libmark.so")
    Path(src).write_text(MARK_SOURCE)
    built = subprocess.run(["gcc", "-O2", "-shared", "-fPIC", "-o", lib, src], capture_output=True)
    return lib if built.returncode == 0 else None


def _totals(path: str) -> dict[str, int]:
    """The event totals of a callgrind dump: {"Ir": …} (and "DLmr", "DLmw" with the cache
    simulation)."""
    text = Path(path).read_text()
    names = re.search(r"^events: (.+)$", text, re.M).group(1).split()
    values = re.search(r"^totals: (.+)$", text, re.M).group(1).split()
    return dict(zip(names, map(int, values), strict=True))


def _lammps_share(path: str) -> dict[str, int]:
    """Inclusive events of LAMMPS's ``Input::one`` (what each ``lammps_command`` runs:
    LAMMPS's part of the scan) in a callgrind dump, as :func:`_totals`."""
    names = list(_totals(path))
    out = subprocess.run(
        ["callgrind_annotate", "--inclusive=yes", "--threshold=100", path],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    found = re.search(r"^\s*([\d,. ()%]+?)\s+\S*:LAMMPS_NS::Input::one\(", out, re.M)
    if found is None:
        raise RuntimeError(f"{path}: no LAMMPS_NS::Input::one in callgrind's annotation")
    counts = re.sub(r"\([^)]*\)", " ", found.group(1)).split()  # drop the percentages
    return {
        k: 0 if v == "." else int(v.replace(",", "")) for k, v in zip(names, counts, strict=True)
    }


def _miss_mb(events: dict[str, int], calls: int) -> float:
    """MB per call that missed the simulated last level (read and write misses)."""
    return (events["DLmr"] + events["DLmw"]) * LINE_BYTES / calls / 1e6


def instructions(system: str, n: int, max_steps: int | None, cache: bool = False) -> dict:
    """Instructions per force call of the scan (LAMMPS's part and ours) and of LAMMPS alone:
    one pair under callgrind in a fresh process; ``cache``: with the cache simulation
    (:data:`CACHE_SIM`), and the MB per call that missed it."""
    with tempfile.TemporaryDirectory() as tmp:
        lib = _marker_library(tmp)
        if lib is None:
            return {}
        out = os.path.join(tmp, "cg.out")
        args = [system, str(n), "1", str(max_steps or 0), lib]
        subprocess.run(
            [
                *("valgrind", "--tool=callgrind", "--instr-atstart=no"),
                *(CACHE_SIM if cache else ()),
                *(f"--callgrind-out-file={out}", sys.executable),
                *("-m", "benchmarks.optimiser_cost", "--one", *args),
            ],
            capture_output=True,
            check=True,
            env=_env(),
        )
        dumps = {}
        for path in Path(tmp).glob("cg.out.*"):
            label = re.search(r"^desc: Trigger: Client Request: (\w+)", path.read_text(), re.M)
            if label:
                dumps[label.group(1)] = str(path)
        row = json.loads(Path(out + ".json").read_text())
        calls = row["force_calls"]  # of the counted relaxation
        scan, alone = _totals(dumps["scan"]), _totals(dumps["alone"])
        lammps = _lammps_share(dumps["scan"])
    out = {
        "instr_calls": calls,
        "scan_minstr": scan["Ir"] / calls / 1e6,
        "alone_minstr": alone["Ir"] / calls / 1e6,
        "lammps_in_scan_minstr": lammps["Ir"] / calls / 1e6,
        "instr_ratio": scan["Ir"] / alone["Ir"],
    }
    if cache:
        out.update(
            scan_miss_mb=_miss_mb(scan, calls),
            lammps_in_scan_miss_mb=_miss_mb(lammps, calls),
            alone_miss_mb=_miss_mb(alone, calls),
        )
    return out


def _env() -> dict:
    return dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")


def run_case(
    system: str, n: int, max_steps: int | None, count: int | None, repeats: int, cache: bool
) -> dict:
    """One row: the timed pairs in a fresh process, then (``count`` not None) the instruction
    count, of a relaxation capped at ``count`` steps if ``count`` > 0 (``cache``: with the
    cache simulation)."""
    rest = (str(repeats), str(max_steps or 0), "")
    out = subprocess.run(
        [sys.executable, "-m", "benchmarks.optimiser_cost", "--one", system, str(n), *rest],
        capture_output=True,
        text=True,
        env=_env(),
        check=True,
    )
    row = json.loads(out.stdout.strip().splitlines()[-1])
    if count is not None:
        row.update(instructions(system, n, count or max_steps, cache))
    return row


def table(rows: list[dict]) -> str:
    lines = [
        "| system | atoms | L-BFGS memory | force calls | scan CPU ms/call | LAMMPS alone "
        "ms/call (energy too) | ratio: median [range] of pairs | M instructions/call: scan "
        "(LAMMPS; ours), alone | instruction ratio | MB/call past a 1 MiB cache: scan "
        "(LAMMPS), alone |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lo, hi = r["ratio_range"]
        calls = f"{r['force_calls']}" + (" (capped)" if r["capped"] else "")
        if "instr_ratio" in r:
            ours = r["scan_minstr"] - r["lammps_in_scan_minstr"]
            first = r["instr_calls"]
            over = "" if first == r["force_calls"] else f" (first {first} calls)"
            instr = (
                f"{r['scan_minstr']:.2f} ({r['lammps_in_scan_minstr']:.2f}; {ours:.2f}), "
                f"{r['alone_minstr']:.2f}{over} | {r['instr_ratio']:.3f}"
            )
        else:
            instr = "— | —"
        if "scan_miss_mb" in r:
            instr += (
                f" | {r['scan_miss_mb']:.2f} ({r['lammps_in_scan_miss_mb']:.2f}), "
                f"{r['alone_miss_mb']:.2f}"
            )
        else:
            instr += " | —"
        lines.append(
            f"| {r['system']} | {r['atoms']:,} | {r['memory']} | {calls} | {r['scan_ms']:.2f} | "
            f"{r['alone_ms']:.2f} | {r['ratio']:.2f} [{lo:.2f}–{hi:.2f}] ×{r['repeats']} | {instr} |"
        )
    return "\n".join(lines)


def _add_counts(system: str, n: int, counts: dict) -> None:
    """Put ``counts`` (of :func:`instructions`) into the newest stored row of ``system`` at
    lateral repeat ``n`` (the row's own counts, if any, are replaced)."""
    from benchmarks.large_cells import case

    atoms = len(case(system, n)[0])
    lines = MEASURED.read_text().splitlines()
    for k in range(len(lines) - 1, -1, -1):
        row = json.loads(lines[k])
        if (row["system"], row["atoms"]) == (system, atoms):
            row.update(counts, counts_date=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()))
            lines[k] = json.dumps(row)
            MEASURED.write_text("\n".join(lines) + "\n")
            print(json.dumps(row), flush=True)
            return
    sys.exit(f"error: no stored row of {system} with {atoms} atoms to add the counts to")


def main(argv: list[str]) -> None:
    if argv and argv[0] == "--one":  # in the child: one row, as JSON
        system, n, repeats, cap, mark = argv[1:6]
        row = measure(system, int(n), int(repeats), int(cap) or None, mark or None)
        if mark:  # under callgrind stdout is valgrind's too: leave the row beside the dumps
            out = Path(mark).with_name("cg.out.json")
            out.write_text(json.dumps(row))
        print(json.dumps(row), flush=True)
        return
    only = [a for a in argv if not a.startswith("--")]
    repeats = REPEATS
    for a in argv:
        if a.startswith("--repeats="):
            repeats = int(a.split("=", 1)[1])
    cache = "--cache-sim" in argv
    for system, n, cap, count in CASES:
        if "--table-only" in argv:  # no measurement: the table of the stored rows
            break
        if only and system not in only and f"{system}:{n}" not in only:
            continue
        if "--counts-only" in argv:
            if count is not False:
                _add_counts(system, n, instructions(system, n, count or cap, cache))
            continue
        count = None if count is False or "--no-instructions" in argv else count
        r = run_case(system, n, cap, count, repeats, cache)
        r["date"] = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
        with MEASURED.open("a") as fh:
            fh.write(json.dumps(r) + "\n")
        print(json.dumps(r), flush=True)
    newest = {}
    for line in MEASURED.read_text().splitlines() if MEASURED.exists() else []:
        r = json.loads(line)
        newest[(r["system"], r["atoms"])] = r
    order = {s: k for k, s in enumerate(dict.fromkeys(c[0] for c in CASES))}
    rows = sorted(newest.values(), key=lambda r: (order[r["system"]], r["atoms"]))
    text = table(rows)
    print(text)
    if "--write-docs" in argv:
        doc = DOCS.read_text()
        pattern = re.compile(re.escape(BEGIN) + ".*?" + re.escape(END), re.S)
        if not pattern.search(doc):
            sys.exit(f"error: {DOCS} has no {BEGIN} … {END} block")
        DOCS.write_text(pattern.sub(lambda _: f"{BEGIN}\n{text}\n{END}", doc))


if __name__ == "__main__":
    main(sys.argv[1:])
