"""The scan's own driver on W virtual workers: what a many-worker scan does, in virtual time.

``python -m benchmarks.schedule_replay --record FILE`` runs the paper preset's scan through
:func:`flatcontact.ispes.scan.run_scan` with a :class:`VirtualExecutor` of 16, 8, 4, 2 and
1 workers in turn. The executor computes each task the driver submits in this process (or
takes it from the tasks already computed: one cache over the runs), measures its CPU
seconds, and places it on the first free of W virtual workers in submission order (the
executors' FIFO queue); ``wait_first``/``result`` advance the driver's clock to the task's
end. The driver is the real one: its own CPU between executor calls (storing points,
choosing the next, assembling and writing ``ispes.nc``, the bracket check) advances its
clock as measured. So every schedule decision (the probe's segments started as workers
free, the grid's warm-start tree, the bracket check's rounds, the in-flight cap) is the
scan's, by construction; only the costs are replayed. The record (``FILE``, gzip pickle:
every task's result and CPU seconds; positions dropped) replays without LAMMPS:
``python -m benchmarks.schedule_replay --from FILE``.

Efficiency at W = T(1) / (W · T(W)), T(W) the driver's clock when ``run_scan`` returns,
T(1) the serial scan (probe in the driver, the columns in sequence). Left out: worker start
(spawn, imports, LAMMPS setup: a real local scan prestarts its workers; here the first
tasks start at once), pickling, and contention between processes on shared cores (the
measured 2-worker efficiency against the machine's ceiling is the check on those).
Task keys (:func:`task_key`) name a grid point by its indices and warm-start parent, not
its thickness: the 1- and 2-worker runs (columns probed in sequence) choose thicknesses
that differ from the many-worker ones within the force tolerance, and take those points'
costs from the many-worker run.
"""

from __future__ import annotations

import argparse
import dataclasses
import gzip
import heapq
import os
import pickle
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

WORKERS = (16, 8, 4, 2, 1)


def task_key(fn: Any, args: tuple) -> tuple:
    """A task's identity across runs: what it computes, without the context or positions."""
    name = getattr(fn, "__name__", repr(fn))
    rest = args[1:]  # args[0] is the ScanContext
    if name == "run_task":
        task = rest[0]
        return (name, tuple(task.index), task.start_index and tuple(task.start_index))
    if name in ("rigid_rows_task", "overlap_check_task"):
        return (name, tuple(rest[1]))
    if name == "warm_worker":
        return (name,)
    return (name, *(tuple(v) if isinstance(v, list | tuple) else v for v in rest))


@dataclasses.dataclass
class Handle:
    """A submitted task: its result (or exception), virtual start and end, order."""

    key: tuple
    result: Any
    error: BaseException | None
    start: float
    end: float
    seq: int
    executor: Any = None

    def done(self) -> bool:
        """Finished by the driver's clock now (as ``Future.done``: the next wait won't block)."""
        self.executor._tick()
        return self.end <= self.executor.clock

    def __hash__(self) -> int:
        return self.seq

    def __eq__(self, other) -> bool:
        return self is other


class VirtualExecutor:
    """W workers in virtual time; tasks run in this process (or come from ``cache``).

    A task starts on the first free worker, not before it is submitted nor before the task
    submitted before it (FIFO), and lasts its CPU seconds (``cache[key] = (result, error,
    seconds)``). The driver's clock advances by the driver's own CPU between executor calls
    (live task computations excluded) and, in ``wait_first``/``result``, to the end of the
    task waited for (``driver_cpu`` False: the driver takes no time, a deterministic
    schedule; ``driver_scale``: the driver's CPU times this, for a driver measured at
    another load than the tasks). ``log`` lists ``(event, key, driver clock, start, end)``.
    """

    name = "virtual"
    inline = False

    def __init__(
        self,
        workers: int,
        cache: dict | None = None,
        driver_cpu: bool = True,
        driver_scale: float = 1.0,
    ):
        self.workers = int(workers)
        self.driver_cpu = driver_cpu
        self.driver_scale = float(driver_scale)
        self.cache = {} if cache is None else cache
        self.clock = 0.0
        self._free = [0.0] * self.workers
        self._last_start = 0.0
        self._mark = time.process_time()
        self._seq = 0
        self.log: list[tuple] = []
        self.busy_s = 0.0

    def _tick(self) -> None:
        now = time.process_time()
        if self.driver_cpu:
            self.clock += self.driver_scale * (now - self._mark)
        self._mark = now

    def submit(self, fn, *args) -> Handle:
        self._tick()
        key = task_key(fn, args)
        if key not in self.cache:
            t0 = time.process_time()
            try:
                out, err = fn(*args), None
            except Exception as exc:  # raised again by result(), as a future does
                out, err = None, exc
            seconds = time.process_time() - t0
            self.cache[key] = (out, err, seconds)
            self._mark += seconds  # the worker's time, not the driver's
        result, error, seconds = self.cache[key]
        free = heapq.heappop(self._free)
        start = max(self.clock, free, self._last_start)
        self._last_start = start
        heapq.heappush(self._free, start + seconds)
        self.busy_s += seconds
        self._seq += 1
        handle = Handle(key, result, error, start, start + seconds, self._seq, self)
        self.log.append(("submit", key, self.clock, start, start + seconds))
        return handle

    def wait_first(self, handles, timeout: float | None = None) -> tuple[set, set]:
        self._tick()
        handles = set(handles)
        first = min(handles, key=lambda h: (h.end, h.seq))
        if timeout is not None and first.end > self.clock + timeout:
            self.clock += timeout  # nothing finished in time: the driver commits, waits again
            return set(), handles
        self.clock = max(self.clock, first.end)
        return {first}, handles - {first}

    @staticmethod
    def done(handle: Handle) -> bool:
        return handle.done()

    def prestart(self, factory: Any, reference: Any) -> None:
        """No workers to start: tasks run at submission (or come from the cache)."""

    def result(self, handle: Handle) -> Any:
        self._tick()
        self.clock = max(self.clock, handle.end)
        self.log.append(("result", handle.key, self.clock, handle.start, handle.end))
        if handle.error is not None:
            raise handle.error
        return handle.result

    def close(self, cancel: bool = False) -> None:
        self._tick()


def paper_inputs():
    """The paper preset's interface, factory, grid and relaxation settings."""
    from flatcontact.config import load_config
    from flatcontact.stages import _calculator
    from flatcontact.stages.build import BuildInputs, build_stage
    from flatcontact.stages.scan import grid_spec, relax_settings

    settings = load_config(preset_name="paper")
    reference = build_stage(settings, BuildInputs(), None).atoms
    return (
        reference,
        _calculator.factory(settings),
        grid_spec(settings.scan),
        relax_settings(settings.scan),
        settings.scan.order,
    )


def warm_up() -> None:
    """A toy scan first, so that no replayed run pays the process's first-use costs (imports,
    the netCDF writer, the database driver: seconds under load, docs/performance.md)."""
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.potentials.model import InteractionModel
    from flatcontact.structures.toy import toy_interface

    factory = calculator_factory(
        InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    )
    grid = GridSpec(3, 3, p_range_gpa=(-0.05, 1.0, 4))
    with tempfile.TemporaryDirectory() as tmp:
        run_scan(
            toy_interface(layers=3),
            factory,
            grid,
            Path(tmp) / "toy",
            RelaxSettings(fmax_ev_per_angstrom=1e-3),
            executor=VirtualExecutor(4),
        )


def replay(inputs, workers: int, cache: dict, driver_scale: float = 1.0) -> dict:
    """One scan on ``workers`` virtual workers; its makespan, work and what it did."""
    from flatcontact.ispes.scan import run_scan

    reference, factory, grid, relax, order = inputs
    ex = VirtualExecutor(workers, cache, driver_scale=driver_scale)
    with tempfile.TemporaryDirectory() as tmp:
        r = run_scan(reference, factory, grid, Path(tmp) / "scan", relax, order, executor=ex)
    ex._tick()
    kinds: dict = {}
    for event, key, *_ in ex.log:
        if event == "submit":
            kinds[key[0]] = kinds.get(key[0], 0) + 1
    first_point = min(
        (s for e, k, _, s, _ in ex.log if e == "submit" and k[0] == "run_task"), default=None
    )
    return {
        "workers": workers,
        "makespan_s": ex.clock,
        "task_s": ex.busy_s,
        "tasks": kinds,
        "grid_starts_s": first_point,
        "thickness_angstrom": [float(v) for v in r.dataset["thickness"].values],
        "points": int(r.points_computed),
        "log": ex.log,
    }


def strip(cache: dict) -> dict:
    """The cache without the grid points' positions (the replay only schedules them)."""
    out = {}
    shared = None
    for key, (res, err, s) in cache.items():
        if key[0] == "run_task" and res is not None:
            shared = np.zeros_like(res.positions) if shared is None else shared
            res = dataclasses.replace(res, positions=shared)
        out[key] = (res, err, s)
    return out


def table(runs: list[dict]) -> str:
    t1 = next(r["makespan_s"] for r in runs if r["workers"] == 1)
    ws = sorted(r["workers"] for r in runs)
    by = {r["workers"]: r for r in runs}
    head = "| | " + " | ".join(f"{w} workers" for w in ws) + " |"
    rows = [head, "|---|" + "---|" * len(ws)]
    rows.append(
        "| efficiency T(1)/(W T(W)) | "
        + " | ".join(f"{t1 / (w * by[w]['makespan_s']):.1%}" for w in ws)
        + " |"
    )
    rows.append("| T(W), s | " + " | ".join(f"{by[w]['makespan_s']:.2f}" for w in ws) + " |")
    rows.append(
        "| grid's first point starts, s | "
        + " | ".join(f"{by[w]['grid_starts_s'] or 0:.2f}" for w in ws)
        + " |"
    )
    rows.append(
        "| tasks' CPU s (waste: segments beyond HI) | "
        + " | ".join(f"{by[w]['task_s']:.1f}" for w in ws)
        + " |"
    )
    return "\n".join(rows)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.schedule_replay")
    parser.add_argument(
        "--record", type=Path, default=None, help="write the tasks (with any new ones) here"
    )
    parser.add_argument("--from", dest="source", type=Path, default=None)
    parser.add_argument("--workers", type=int, nargs="*", default=list(WORKERS))
    parser.add_argument(
        "--driver-scale",
        type=float,
        default=1.0,
        help="the driver's measured CPU times this (the tasks were recorded at another load)",
    )
    args = parser.parse_args(argv)
    cache = {}
    if args.source:
        with gzip.open(args.source, "rb") as fh:
            cache = pickle.load(fh)["cache"]
    inputs = paper_inputs()
    warm_up()
    runs = []
    for w in args.workers:
        t0 = time.perf_counter()
        run = replay(inputs, w, cache, args.driver_scale)
        runs.append(run)
        print(
            f"{w} workers: T {run['makespan_s']:.2f} s, tasks {run['task_s']:.1f} s CPU "
            f"{run['tasks']}, grid starts {run['grid_starts_s']}, "
            f"{len(run['thickness_angstrom'])} thicknesses ({time.perf_counter() - t0:.0f} s wall, "
            f"load {os.getloadavg()[0]:.1f})",
            flush=True,
        )
        if args.record:
            with gzip.open(args.record, "wb") as fh:
                pickle.dump(
                    {
                        "cache": strip(cache),
                        "runs": [{k: v for k, v in r.items() if k != "log"} for r in runs],
                    },
                    fh,
                )
    if 1 in args.workers:
        print(table(runs))


if __name__ == "__main__":
    main()
