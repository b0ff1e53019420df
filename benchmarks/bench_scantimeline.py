"""Where a two-worker scan leaves a core idle: CPU per process sampled every 5 ms (issue 33).

``python -m benchmarks scantimeline``: one command, about 40 s on a quiet 2-core Linux
machine. The 12 × 12 quartz scan of ``python -m benchmarks scanspeed`` runs once on 2
local workers (after an untimed warm-up, the driver's Hessian forgotten:
:mod:`benchmarks.scan_fairness`) while a separate sampler process reads the CPU time
(``/proc/<pid>/schedstat``, nanoseconds) of the driver and of every process below it
every 5 ms. For each of the scan's phases (:mod:`flatcontact.ispes.phases`) it prints the
wall seconds, the core-seconds the two cores stood idle (2 × wall − the CPU all the
scan's processes used) and the driver's own CPU seconds; then the same over the whole
scan, and over the grid phase in 0.5 s slices.

An idle core-second on 2 cores is half a wall second the scan could lose. The sampler
itself uses ~2 % of a core (it is not counted). Linux only (``/proc``).
"""

from __future__ import annotations

import itertools
import logging
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: seconds between two samples
SAMPLE_S = 0.005

_SAMPLER = r"""
import select, sys, time
pid, seconds, step = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])

def below(p):
    try:
        with open(f"/proc/{p}/task/{p}/children") as f:
            kids = [int(x) for x in f.read().split()]
    except OSError:
        return []
    return kids + [g for k in kids for g in below(k)]

def sample():
    row = {}
    for p in [pid] + below(pid):
        try:
            with open(f"/proc/{p}/schedstat") as f:
                row[p] = int(f.read().split()[0])
        except OSError:
            pass
    rows.append((time.monotonic(), row))

end, rows = time.monotonic() + seconds, []
while time.monotonic() < end:
    sample()
    if select.select([sys.stdin], [], [], step)[0]:  # closed: the scan is over
        break
sample()
print(repr(rows))
"""


class _PhaseEnds(logging.Handler):
    """(name, start, end) on ``time.monotonic`` of each phase, from the phases' DEBUG log."""

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.spans: list[tuple[str, float, float]] = []

    def emit(self, record: logging.LogRecord) -> None:
        name, seconds = record.getMessage().rsplit(" ", 1)
        end = time.monotonic()
        self.spans.append((name, end - float(seconds), end))


def usage(rows, driver: int, start: float, end: float, cores: int = 2) -> tuple[float, float]:
    """(idle core-seconds, driver CPU seconds) over the sample intervals inside [start, end].

    ``rows``: the sampler's (monotonic time, {pid: CPU ns}); a process that appears or
    ends inside an interval counts from or until its first or last sample."""
    idle = driver_cpu = 0.0
    for (ta, a), (tb, b) in itertools.pairwise(rows):
        if ta < start or tb > end:
            continue
        used = sum(b[p] - a[p] for p in b if p in a) / 1e9
        idle += cores * (tb - ta) - used
        driver_cpu += (b.get(driver, 0) - a.get(driver, 0)) / 1e9
    return idle, driver_cpu


def main() -> None:
    if not Path("/proc/self/schedstat").exists():
        print("scantimeline: needs Linux's /proc/<pid>/schedstat; skipped")
        return
    from benchmarks.bench_scan import build
    from benchmarks.bench_scanspeed import FMAX, GRID, P_RANGE_GPA
    from benchmarks.scan_fairness import forget_hessian, warm_up
    from flatcontact.ispes.executors import make_executor
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan

    print(f"== scan timeline (issue 33), {os.cpu_count()} cores ==", flush=True)
    _, reference, factory = build("snap:sio2-snap")
    warm_up(reference, factory)
    phases = _PhaseEnds()
    logger = logging.getLogger("flatcontact.ispes.phases")
    logger.addHandler(phases)
    level = logger.level
    logger.setLevel(logging.DEBUG)
    sampler = subprocess.Popen(
        [sys.executable, "-c", _SAMPLER, str(os.getpid()), "120", str(SAMPLE_S)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    time.sleep(0.2)
    try:
        with tempfile.TemporaryDirectory() as tmp:
            forget_hessian()
            executor = make_executor("processes", workers=2)
            t0 = time.monotonic()
            try:
                result = run_scan(
                    reference, factory, GridSpec(*GRID, p_range_gpa=P_RANGE_GPA),
                    Path(tmp) / "scan", RelaxSettings(FMAX), executor=executor,
                )  # fmt: skip
            finally:
                executor.close()
            t1 = time.monotonic()
    finally:
        logger.removeHandler(phases)
        logger.setLevel(level)
        out = sampler.communicate(input="")[0]  # its stdin closed: it prints and ends
    rows = eval(out or "[]")  # the sampler's own repr
    if not rows or rows[-1][0] < t1:
        print("scantimeline: the sampler ended before the scan (a slow machine?)")
        return
    me = os.getpid()
    idle, driver = usage(rows, me, t0, t1)
    print(
        f"  12x12x{result.dataset.sizes['thickness']}, 2 workers: {t1 - t0:.2f} s wall, "
        f"idle {idle:.2f} core-s, driver CPU {driver:.2f} s"
    )
    print(f"  {'phase':24s} {'wall s':>7s} {'idle core-s':>12s} {'driver CPU s':>13s}")
    for name, start, end in phases.spans:
        if end - start >= 0.02:
            idle, driver = usage(rows, me, start, end)
            print(f"  {name:24s} {end - start:7.2f} {idle:12.2f} {driver:13.2f}")
    grid = next((s, e) for n, s, e in phases.spans if n == "grid")
    edges = [grid[0] + 0.5 * k for k in range(int((grid[1] - grid[0]) / 0.5) + 1)] + [grid[1]]
    slices = [usage(rows, me, a, b)[0] for a, b in itertools.pairwise(edges) if b > a]
    print("  grid, idle core-s per 0.5 s: " + " ".join(f"{x:.2f}" for x in slices), flush=True)
