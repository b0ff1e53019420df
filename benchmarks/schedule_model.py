"""Modelled parallel efficiency of the whole paper-preset scan at 1 … 16 workers (issue 22).

This analytic model describes the schedule of a scan with 1-3 workers (and of every scan
before the many-worker probe); a scan with ``flatcontact.ispes.scan.MANY_WORKERS`` or more
workers is replayed, with its own driver, by ``benchmarks/schedule_replay.py``.

``python -m benchmarks.schedule_model`` runs the paper preset's scan once, serially, and
records every relaxation it makes: the probe's single points of every stacking, each probed
column's points (shift, thickness, cold or warm start, force calls, CPU seconds), the ideal
work of separation, and every grid point (its warm-start parent, force calls, CPU seconds),
plus the driver's own CPU per stored point. The records go to a JSON file
(``--record FILE``, default ``schedule_record.json`` in the current directory);
``python -m benchmarks.schedule_model --from FILE`` models from a record without scanning.

The model replays the scan's dependency graph on W identical workers, each task costing what
it cost in the serial run (measured, not calls × an assumed cost):

1. the rigid single points of every stacking (in the driver, serial);
2. the probed columns: each column is one or more chains of relaxations, a point starting
   when the previous one of its chain is done (``old``: one chain per column, the schedule
   before this change; ``new``: the compression and the stretching of a column are two
   chains, :func:`flatcontact.ispes.probe.probe_column_chains`); the driver waits for all;
3. the ideal work of separation: ``old`` in the driver after the probe; ``new`` one more
   chain on a worker, started with the probe's columns, joined before the grid is stored
   (it does not gate the grid);
4. the grid: a point is submitted once its warm-start parent is stored, in the tree's order,
   to the first free worker; the driver stores one result at a time at its measured cost
   (:func:`benchmarks.scale_report.simulate`).

Efficiency = (sum of all task costs) / (W × makespan). Left out: worker start (overlapped by
the probe) and contention between processes (the measured 2-worker efficiency against the
machine's ceiling, ``python -m benchmarks parallel``, is the check on that).
"""

from __future__ import annotations

import argparse
import heapq
import itertools
import json
import os
import tempfile
import time
from pathlib import Path

WORKERS = (1, 2, 4, 8, 16)


def record_scan(path: Path) -> dict:
    """Run the paper preset's scan serially, recording every relaxation; write ``path``."""
    import flatcontact.ispes.scan as scan_mod
    import flatcontact.ispes.scan_probe as probe_mod
    import flatcontact.ispes.scan_scheduler as scheduler_mod
    from flatcontact.config import load_config
    from flatcontact.ispes.executors import SerialExecutor
    from flatcontact.ispes.geometry import thickness
    from flatcontact.stages import _calculator
    from flatcontact.stages.build import BuildInputs, build_stage
    from flatcontact.stages.scan import grid_spec, relax_settings

    settings = load_config(preset_name="paper")
    s = settings.scan
    reference = build_stage(settings, BuildInputs(), None).atoms
    factory = _calculator.factory(settings)
    relax = relax_settings(s)
    grid = grid_spec(s)
    rec: dict = {
        "atoms": len(reference),
        "grid": [grid.n_a, grid.n_b],
        "z_ref": float(thickness(reference)),
        "rigid_s": [],
        "probe": [],
        "work_of_separation": [],
        "grid_points": [],
        "store_s": [],
    }
    phase = {"name": None}

    def timed(name, fn):
        def wrapper(*args, **kwargs):
            t0 = time.process_time()
            out = fn(*args, **kwargs)
            dt = time.process_time() - t0
            if name == "rigid":
                rec["rigid_s"].append(dt)
            elif name == "column":
                a, b, z, start = args[3], args[4], args[5], args[6]
                rec[phase["name"] or "probe"].append(
                    {
                        "shift": [a, b],
                        "z": z,
                        "cold": start is None,
                        "p": out[1],
                        "calls": out[2],
                        "s": dt,
                    }
                )
            elif name == "task":
                task = args[1]
                rec["grid_points"].append(
                    {
                        "index": list(task.index),
                        "parent": None if task.start_index is None else list(task.start_index),
                        "calls": out.force_calls,
                        "s": dt,
                    }
                )
            return out

        return wrapper

    def in_phase(name, fn):
        def wrapper(*args, **kwargs):
            phase["name"] = name
            try:
                return fn(*args, **kwargs)
            finally:
                phase["name"] = None

        return wrapper

    from flatcontact.ispes import relax as relax_mod
    from flatcontact.ispes import store as store_mod
    from flatcontact.ispes import work_of_separation as wos

    orig_relax_point = wos.relax_point

    def wos_relax_point(ref, calc, task, settings):
        t0 = time.process_time()
        r = orig_relax_point(ref, calc, task, settings)
        rec["work_of_separation"].append(
            {
                "z": task.thickness,
                "cold": task.start_positions is None,
                "calls": r.force_calls,
                "s": time.process_time() - t0,
            }
        )
        return r

    orig_write = store_mod.PointStore.write

    def write(self, result):
        t0 = time.process_time()
        out = orig_write(self, result)
        rec["store_s"].append(time.process_time() - t0)
        return out

    orig_adhesion = probe_mod.adhesion_record

    def adhesion_record(*args, **kwargs):
        t0 = time.process_time()
        out = orig_adhesion(*args, **kwargs)
        rec["adhesion_record_s"] = time.process_time() - t0
        return out

    probe_mod.adhesion_record = adhesion_record
    orig_extend = scan_mod.extend_grid

    def extend(*args, **kwargs):
        added = orig_extend(*args, **kwargs)
        if added:  # the next points are a new round of the grid
            rec.setdefault("round_starts", []).append(len(rec["grid_points"]))
        return added

    scan_mod.extend_grid = extend
    orig_work = probe_mod.ideal_work_of_separation

    def ideal_work(*args, **kwargs):
        t0 = time.process_time()
        out = orig_work(*args, **kwargs)
        rec["work_s"] = time.process_time() - t0
        return out

    probe_mod.ideal_work_of_separation = ideal_work
    probe_mod.rigid_rows = timed("rigid", probe_mod.rigid_rows)
    probe_mod.relax_column_point = timed("column", probe_mod.relax_column_point)
    scheduler_mod.run_task = timed("task", relax_mod.run_task)
    wos.relax_point = wos_relax_point
    store_mod.PointStore.write = write
    with tempfile.TemporaryDirectory() as tmp:
        t0, c0 = time.perf_counter(), time.process_time()
        r = scan_mod.run_scan(
            reference,
            factory,
            grid,
            Path(tmp) / "scan",
            relax,
            order=s.order,
            executor=SerialExecutor(),
        )
        rec["wall_s"] = time.perf_counter() - t0
        rec["cpu_s"] = time.process_time() - c0
        rec["thickness_angstrom"] = [float(v) for v in r.dataset["thickness"].values]
        rec["load"] = os.getloadavg()[0]
    path.write_text(json.dumps(rec))
    return rec


# -- the model -------------------------------------------------------------------------------


def probe_chains(rec: dict, split: bool) -> list[list[float]]:
    """The probed columns as chains of point costs (s), in the order the driver submits them.

    One chain per column (``split`` False: the schedule before issue 22's change), or two per
    column (:func:`flatcontact.ispes.probe.compress_chain`: the reference thickness, cold,
    and the points below it; :func:`~flatcontact.ispes.probe.stretch_chain`: the points above
    it, from their own cold start), the stretchings first, as ``scan_probe.probe`` submits them.
    """
    columns: dict = {}
    for p in rec["probe"]:
        columns.setdefault(tuple(p["shift"]), []).append(p)
    if not split:
        return [[p["s"] for p in points] for points in columns.values()]
    z_ref = rec["z_ref"] + 1e-9
    up = [[p["s"] for p in points if p["z"] > z_ref] for points in columns.values()]
    down = [[p["s"] for p in points if p["z"] <= z_ref] for points in columns.values()]
    return [c for c in up if c] + [c for c in down if c]


def chains_makespan(chains: list[list[float]], workers: int, start: float = 0.0) -> float:
    """When the last of ``chains`` ends: each chain runs on one worker (its points one after
    the other, each from the previous one's result), the chains in submission order, each to
    the first free worker (the executors' FIFO queue)."""
    free = [start] * workers
    heapq.heapify(free)
    for chain in chains:
        t = heapq.heappop(free)
        heapq.heappush(free, t + sum(chain))
    return max(free)


def simulate_tree(
    parent: dict, cost: dict, free_at: list[float], driver_s: float, start: float
) -> float:
    """Makespan of the driver's schedule of a warm-start tree: a point is submitted once its
    parent is stored, in tree order, to the first free worker (``free_at``: when each worker
    is free, some busy with other chains); the driver stores one result at a time
    (``driver_s`` each). As :func:`benchmarks.scale_report.simulate`, with busy workers."""
    rank = {idx: k for k, idx in enumerate(parent)}
    children: dict = {}
    for idx, par in parent.items():
        children.setdefault(par, []).append(idx)
    ready = [(rank[i], i) for i in children.get(None, [])]
    heapq.heapify(ready)
    free = sorted(max(start, t) for t in free_at)
    heapq.heapify(free)
    running: list = []
    t_driver = start
    while ready or running:
        while ready and free and free[0] <= t_driver:
            _, idx = heapq.heappop(ready)
            heapq.heappop(free)
            heapq.heappush(running, (t_driver + cost[idx], idx))
        if ready and free and (not running or free[0] < running[0][0]):
            t_driver = free[0]  # a worker busy with another chain is free first
            continue
        t_fin, idx = heapq.heappop(running)
        heapq.heappush(free, t_fin)
        t_driver = max(t_driver, t_fin) + driver_s
        for child in children.get(idx, []):
            heapq.heappush(ready, (rank[child], child))
    return t_driver


def grid_makespan(rec: dict, workers: int, start: float = 0.0, busy=()) -> float:
    """The grid on its measured warm-start tree (:func:`simulate_tree`), from ``start``, with
    ``busy`` the times at which workers still running other chains become free.

    A thickness the grid's bracket check added after the scan (``scan_extend.extend_grid``) is a round
    of its own: its points start once every point before is stored (``round_starts``, the
    positions in the record where a round begins); a parent in an earlier round is stored.
    """
    points = rec["grid_points"]
    bounds = [0, *rec.get("round_starts", []), len(points)]
    driver = sum(rec["store_s"]) / max(1, len(rec["store_s"]))
    t = start
    for lo, hi in itertools.pairwise(bounds):
        here = {tuple(p["index"]) for p in points[lo:hi]}
        parent = {
            tuple(p["index"]): (
                tuple(p["parent"]) if p["parent"] and tuple(p["parent"]) in here else None
            )
            for p in points[lo:hi]
        }
        cost = {tuple(p["index"]): p["s"] for p in points[lo:hi]}
        late = sorted(b for b in busy if b > t)[:workers]
        free_at = late + [t] * (workers - len(late))
        t = simulate_tree(parent, cost, free_at, driver, t)
    return t


def parts(rec: dict) -> dict:
    """The measured serial parts (CPU s): rigid single points (one pass), the ideal work of
    separation (its record less its own rigid pass), the grid's relaxations, the stores, and
    the driver's rest (assembling, writing, scheduling: serial at any W)."""
    rigid = rec["rigid_s"][0]
    # the ideal W's own time (an older record: its adhesion record less its rigid pass)
    work = rec.get("work_s", rec["adhesion_record_s"] - sum(rec["rigid_s"][1:]))
    probe = sum(p["s"] for p in rec["probe"])
    grid = sum(p["s"] for p in rec["grid_points"])
    store = sum(rec["store_s"])
    rest = rec["cpu_s"] - sum(rec["rigid_s"]) - probe - work - grid - store
    return {
        "rigid": rigid,
        "work": work,
        "probe": probe,
        "grid": grid,
        "store": store,
        "rest": max(0.0, rest),
    }


def model(rec: dict, schedule: str, workers: int) -> tuple[float, float]:
    """``(makespan, serial work)`` in seconds of the whole scan with ``workers`` workers.

    ``old``: one chain per probed column on the workers, then the rigid points again and the
    work of separation in the driver, then the grid. ``new``: the rigid points once, the
    columns' chains split in two and the work of separation as one more chain, all at once,
    then the grid. The serial work is that of the ``new`` schedule for both (the work the
    scan needs), so the old row's efficiency also charges its repeated rigid pass.
    """
    q = parts(rec)
    total = sum(q.values())
    if workers == 1:
        return total + (q["rigid"] if schedule == "old" else 0.0), total
    serial = q["rest"]
    if schedule == "old":
        t = q["rigid"] + chains_makespan(probe_chains(rec, False), workers)
        t += q["rigid"] + q["work"]
    else:
        chains = probe_chains(rec, True)
        n_up = sum(1 for _ in {tuple(p["shift"]) for p in rec["probe"]})
        ordered = [*chains[:n_up], [q["work"]], *chains[n_up:]]
        t = chains_makespan(ordered, workers, q["rigid"])
    if schedule == "overlap":
        return _overlap_makespan(rec, workers, q) + serial, total
    if schedule == "independent":
        # what-if: every compressed point of a column its own chain (a cold start at its
        # thickness), at the cost measured warm (an assumption: cold starts were not measured
        # there), the stretchings as in ``new``
        z_ref = rec["z_ref"] + 1e-9
        ups = [c for c in probe_chains(rec, True)[: len({tuple(p["shift"]) for p in rec["probe"]})]]
        downs = [[p["s"]] for p in rec["probe"] if p["z"] <= z_ref]
        t = chains_makespan([*ups, [q["work"]], *downs], workers, q["rigid"])
        return grid_makespan(rec, workers, t) + serial, total
    return grid_makespan(rec, workers, t) + serial, total


def _split_first_stretch(rec: dict) -> tuple[list[float], list[float]]:
    """The lowest-energy column's stretching (CPU s per point) split where the thicknesses
    are decided: up to the first point past its tensile maximum below zero load (the
    repulsive branch ends there, :func:`flatcontact.ispes.thicknesses.repulsive_branch`), and
    the rest, relaxed on to separation only for the pull-off work."""
    first = tuple(rec["probe"][0]["shift"])
    points = [p for p in rec["probe"] if tuple(p["shift"]) == first]
    p_min = points[0]["p"]  # the reference thickness: the compression's first point
    up = [p for p in points if p["z"] > rec["z_ref"] + 1e-9]
    for k, p in enumerate(up):
        past = p["p"] > p_min
        p_min = min(p_min, p["p"])
        if past and p_min < 0:
            return [q["s"] for q in up[: k + 1]], [q["s"] for q in up[k + 1 :]]
    return [q["s"] for q in up], []


def _overlap_makespan(rec: dict, workers: int, q: dict) -> float:
    """``overlap`` (modelled, not implemented): as ``new``, but the grid starts once the
    thicknesses are decided; the lowest-energy column's stretching past that point and the
    ideal work of separation run on beside the grid (they feed only scan.json's adhesion)."""
    chains = probe_chains(rec, True)
    n_up = len({tuple(p["shift"]) for p in rec["probe"]})
    head, tail = _split_first_stretch(rec)
    free = [q["rigid"]] * workers
    heapq.heapify(free)
    gate, busy = q["rigid"], []
    for k, chain in enumerate([chains[0], *chains[1:n_up], [q["work"]], *chains[n_up:]]):
        t = heapq.heappop(free)
        if k == 0:  # the first column's stretching: its head gates the grid
            gate = max(gate, t + sum(head))
            end = t + sum(head) + sum(tail)
            busy.append(end)
        elif k == n_up:  # the work of separation: beside the grid
            end = t + sum(chain)
            busy.append(end)
        else:
            end = t + sum(chain)
            gate = max(gate, end)
        heapq.heappush(free, end)
    return grid_makespan(rec, workers, gate, [b for b in busy if b > gate])


def report(rec: dict) -> str:
    n = len(rec["grid_points"])
    calls = [p["calls"] for p in rec["grid_points"]]
    probe_calls = [p["calls"] for p in rec["probe"]]
    lines = [
        f"paper preset: {rec['atoms']} atoms, grid {rec['grid'][0]}x{rec['grid'][1]}x"
        f"{len(rec['thickness_angstrom'])} = {n} points, serial wall {rec['wall_s']:.1f} s "
        f"(CPU {rec['cpu_s']:.1f} s, load {rec['load']:.1f} after)",
        f"  rigid single points: {len(rec['rigid_s'])} passes, {sum(rec['rigid_s']):.2f} s",
        f"  probe: {len(rec['probe'])} points, {sum(probe_calls)} calls, "
        f"{sum(p['s'] for p in rec['probe']):.2f} s; chains old "
        + str([round(sum(c), 2) for c in probe_chains(rec, False)])
        + " s, new "
        + str([round(sum(c), 2) for c in probe_chains(rec, True)])
        + " s",
        f"  work of separation: {len(rec['work_of_separation'])} relaxations, "
        f"{sum(p['calls'] for p in rec['work_of_separation'])} calls, "
        f"{parts(rec)['work']:.2f} s; driver rest (assemble, write, schedule) "
        f"{parts(rec)['rest']:.2f} s",
        f"  grid: {sum(calls)} calls ({sum(calls) / n:.1f}/point), "
        f"{sum(p['s'] for p in rec['grid_points']):.1f} s, "
        f"{1e3 * sum(p['s'] for p in rec['grid_points']) / max(1, sum(calls)):.2f} ms/call; "
        f"driver store {1e3 * sum(rec['store_s']) / max(1, len(rec['store_s'])):.2f} ms/point",
        "| schedule | " + " | ".join(f"{w} workers" for w in WORKERS) + " |",
        "|---|" + "---|" * len(WORKERS),
    ]
    schedules = ("old", "new", "independent")
    if "p" in rec["probe"][0]:
        schedules += ("overlap",)
    for schedule in schedules:
        cells = []
        for w in WORKERS:
            span, total = model(rec, schedule, w)
            cells.append(f"{total / (w * span):.1%} ({span:.1f} s)")
        lines.append(f"| {schedule} | " + " | ".join(cells) + " |")
    q = parts(rec)
    grid_work = q["grid"] + q["store"]
    for w in (8, 16):
        chains = probe_chains(rec, True)
        n_up = len({tuple(p["shift"]) for p in rec["probe"]})
        t_probe = chains_makespan([*chains[:n_up], [q["work"]], *chains[n_up:]], w, 0.0)
        t_grid = grid_makespan(rec, w)
        lines.append(
            f"  new at {w} workers: rigid {q['rigid']:.2f} s + probe chains and W {t_probe:.2f} s "
            f"+ grid {t_grid:.2f} s (alone {grid_work / (w * t_grid):.0%} efficient, rounds "
            f"{len(rec.get('round_starts', [])) + 1}) + driver rest {q['rest']:.2f} s"
        )
    return "\n".join(lines)


def add_probe_loads(rec: dict) -> dict:
    """A record written without the probe's loads: the probe alone again (serial, the same
    relaxations: deterministic), its loads added point by point (matched by shift and z)."""
    import functools

    import flatcontact.ispes.scan_probe as probe_mod
    from flatcontact.config import load_config
    from flatcontact.ispes.probe import rigid_stackings
    from flatcontact.stages import _calculator
    from flatcontact.stages.build import BuildInputs, build_stage
    from flatcontact.stages.scan import grid_spec, relax_settings

    settings = load_config(preset_name="paper")
    reference = build_stage(settings, BuildInputs(), None).atoms
    loads = {}
    original = probe_mod.relax_column_point

    def relax_column_point(*args):
        out = original(*args)
        loads[(args[3], args[4], args[5])] = out[1]
        return out

    probe_mod.relax_column_point = relax_column_point
    try:
        probe = probe_mod.probe_thicknesses
        grid = grid_spec(settings.scan)
        calc = probe_mod.worker_calculator(_calculator.factory(settings), reference)
        relax_one = functools.partial(
            relax_column_point, reference, calc, relax_settings(settings.scan)
        )
        probe(relax_one, reference, rigid_stackings(reference, calc, grid), grid)
    finally:
        probe_mod.relax_column_point = original
    for p in rec["probe"]:
        p["p"] = loads[(p["shift"][0], p["shift"][1], p["z"])]
    return rec


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.schedule_model")
    parser.add_argument("--record", default="schedule_record.json", type=Path)
    parser.add_argument("--from", dest="source", type=Path, default=None)
    parser.add_argument(
        "--add-loads", action="store_true", help="a record without the probe's loads: add them"
    )
    args = parser.parse_args(argv)
    rec = json.loads(args.source.read_text()) if args.source else record_scan(args.record)
    if "p" not in rec["probe"][0] and args.add_loads:
        rec = add_probe_loads(rec)
        args.source.write_text(json.dumps(rec))
    print(report(rec), flush=True)


if __name__ == "__main__":
    main()
