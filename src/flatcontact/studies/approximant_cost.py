"""What an approximant study will cost in seconds, before it runs (``study approximants --list``).

Per cell of :func:`flatcontact.studies.approximants.plan` the cell is built as the preflight
builds it (unrelaxed: milliseconds), its interaction model is set up and one force call is
timed (:func:`time_force_call`: the median of :data:`TIMED_CALLS` calls after a warm-up, CPU
seconds of this process, in which LAMMPS runs). The cell's cost, in seconds of one core:

    seconds = points · (calls_per_point · t_call + overhead_per_point) + fixed_per_cell

* ``points``: the planned grid points (``grid_x · grid_y · thicknesses``; the load bracket
  may add a thickness);
* ``calls_per_point``: exactly 1 for a ``rigid`` scan and for a cell whose atoms are all held
  (nothing relaxes); otherwise measured on a finished cell of the same study (``--out DIR``
  holding one: the median force calls per point of its ``scan.json``), else assumed
  (:data:`ASSUMED_CALLS_PER_POINT`, stated on the console as assumed);
* ``overhead_per_point``: the scan's work per point beyond the force calls (placement,
  bookkeeping, the point store), :data:`POINT_OVERHEAD_S`;
* ``fixed_per_cell``: build, noise floor, analysis with figures, laws and gates,
  :data:`CELL_FIXED_S`.

Every term is CPU seconds (what a free core spends); a finished cell's stage records hold
wall seconds, which carry the machine's load, so only its force calls per point (a count)
calibrate the estimate.

The wall time on the study's executor: the cells run side by side on ``workers`` processes,
each cell's scan serial, so the study takes at least ``max(Σ seconds / workers, max
seconds)``. A study whose wall time on the local machine exceeds :data:`DASK_THRESHOLD_S`
is said to need a Dask cluster (docs/cluster.md; ``scan.dask_address`` or
``scan.jobqueue``); a single cell above it gains nothing from more workers (its scan is
serial in the study) and is said so.

When the machine's load average exceeds its cores the console says by how much the wall time
may stretch (load / cores).
"""

from __future__ import annotations

import math
import os
import statistics
import time
from pathlib import Path

import numpy as np

from flatcontact.config.run import RunConfig
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import read_json_file
from flatcontact.foundation.layout import SCAN_JSON, STAGES
from flatcontact.foundation.result_json import read_result_json
from flatcontact.foundation.rundir import RECORD_NAME
from flatcontact.ispes.executors import default_workers
from flatcontact.studies.study_dir import RUNS, folder_name

#: Force calls per grid point when no finished cell measured them and something relaxes:
#: ``rigid-layers`` 3.6 measured on the H-diamond(111)/graphene lock (examples/README.md),
#: rounded up; ``normal`` a median of 12 and 15 on twisted 2+2-sheet graphene
#: (docs/incommensurate.md); ``full`` relaxes at least as much as ``normal`` (a lower bound).
ASSUMED_CALLS_PER_POINT = {"rigid-layers": 4.0, "normal": 15.0, "full": 15.0}
#: CPU seconds per grid point beyond its force calls: the rigid twisted graphene scans
#: (1, 2), (2, 3), (3, 4) spent 2.8, 2.9, 3.8 CPU s on 144 points, of which 0.3, 0.6, 1.0 s
#: were force calls (timed): 0.016–0.019 s per point, rounded up.
POINT_OVERHEAD_S = 0.02
#: CPU seconds per cell outside its scan: build 1.3–2.0 s, then noise floor, analysis,
#: laws and gates 6.1 and 7.5 s for the resolved (1, 2) and (2, 3) cells (0.35 s for the
#: unresolved (3, 4), which is not analysed); rounded up.
CELL_FIXED_S = 10.0
#: A study longer than this on the local workers is said to need Dask: more than a night.
DASK_THRESHOLD_S = 8 * 3600.0
#: Force calls timed per cell after the warm-up call.
TIMED_CALLS = 3


def time_force_call(cell_config: dict) -> dict:
    """Seconds of one force call on the cell of ``cell_config`` (a validated configuration's
    ``to_dict()``), built unrelaxed as the preflight builds it.

    Returns
    -------
    dict
        ``cpu_s`` and ``wall_s`` (medians of :data:`TIMED_CALLS` calls after a warm-up, each
        on slightly moved atoms so no cached result is returned), ``n_atoms``,
        ``all_held`` (no atom is free: every scan mode is a rigid scan).
    """
    from flatcontact.potentials.engines import make_calculator
    from flatcontact.stages import _calculator
    from flatcontact.structures.construct import build_interface
    from flatcontact.structures.interface_contract import fixed_mask

    cfg = RunConfig.model_validate(cell_config)
    atoms, _ = build_interface(cfg.structure)
    calc = make_calculator(_calculator.model(cfg), atoms)
    atoms.calc = calc
    cpu, wall = [], []
    try:
        for k in range(TIMED_CALLS + 1):
            atoms.positions[0, 2] += 1e-4 * (-1) ** k
            c0, w0 = time.process_time(), time.perf_counter()
            atoms.get_forces()
            if k:
                cpu.append(time.process_time() - c0)
                wall.append(time.perf_counter() - w0)
    finally:
        close = getattr(calc, "close", None)
        if close is not None:
            close()
    return {
        "cpu_s": statistics.median(cpu),
        "wall_s": statistics.median(wall),
        "n_atoms": len(atoms),
        "all_held": bool(np.all(fixed_mask(atoms))),
    }


def measured_cell(folder: str | Path) -> dict | None:
    """What a finished cell's scan measured (``DIR/runs/<label>``), or None if it has none:
    ``points``, ``force_calls``, ``median_calls_per_point`` and ``scan_s`` (wall, for the
    record: it carries the machine's load)."""
    scan_dir = Path(folder) / f"{STAGES['scan']:02d}-scan"
    try:
        scan = read_result_json(scan_dir / SCAN_JSON)
        record = read_json_file(scan_dir / RECORD_NAME, "stage record", 1_000_000)
    except InputError:  # no finished cell there (or not one): the assumed calls stand
        return None
    if not isinstance(record, dict):
        return None
    points = int(scan.get("points_computed") or scan.get("points_total") or 0)
    calls = int(scan.get("force_calls_total") or 0)
    seconds = record.get("seconds")
    if points <= 0 or calls <= 0 or seconds is None:
        return None
    return {
        "points": points,
        "force_calls": calls,
        "median_calls_per_point": float(scan.get("median_force_calls_per_point") or calls / points),
        "scan_s": float(seconds),
    }


def executor_workers(cfg: RunConfig) -> tuple[str, int | None]:
    """(executor name, local workers) the study would use; ``None`` workers for a Dask
    cluster given by address or jobqueue (its size is the cluster's)."""
    scan = cfg.scan
    if scan.dask_address is not None or scan.jobqueue is not None:
        return "dask (external cluster)", None
    if scan.executor == "serial" or scan.workers == 1:
        return "serial", 1
    return scan.executor, scan.workers or default_workers()


def estimate_cost(cfg: RunConfig, cells: list[dict], out: str | Path | None = None) -> dict:
    """The seconds of every cell of ``cells`` (:func:`flatcontact.studies.approximants.plan`)
    and of the study on its executor (module docstring).

    Parameters
    ----------
    cfg
        The study's configuration (its ``scan:`` executor and relax mode).
    cells
        The plan.
    out
        The study folder; a finished cell in ``out/runs/<label>`` calibrates the force calls
        per point (the smallest finished cell).

    Returns
    -------
    dict
        ``cells`` (per cell: ``label``, ``n_atoms``, ``points``, ``calls_per_point`` and its
        ``calls_source`` (exact | measured on <label> | assumed), ``force_calls``,
        ``call_cpu_s``, ``call_wall_s``, ``overhead_per_point_s``, ``seconds``),
        ``cpu_seconds`` (all cells one after another), ``wall_seconds`` (on the executor;
        None for an external Dask cluster), ``executor``, ``workers``, ``largest_cell_s``,
        ``dask_threshold_s``, ``needs_dask``, ``calibration`` (the finished cell used, or None).
    """
    mode = cfg.scan.relax_mode
    timed = {c["label"]: time_force_call(c["config"]) for c in cells}
    calibration = None
    if out is not None:
        for c in sorted(cells, key=lambda c: c["n_atoms"]):
            m = measured_cell(Path(out) / RUNS / folder_name(c["label"]))
            if m is not None:
                calibration = {"label": c["label"], **m}
                break
    rows = []
    for c in cells:
        t = timed[c["label"]]
        if mode == "rigid" or t["all_held"]:
            per_point, source = 1.0, "exact (nothing relaxes)"
        elif calibration is not None:
            per_point = calibration["median_calls_per_point"]
            source = f"measured on {calibration['label']}"
        else:
            per_point, source = ASSUMED_CALLS_PER_POINT[mode], f"assumed for {mode}"
        overhead, fixed = POINT_OVERHEAD_S, CELL_FIXED_S
        points = int(c["points_planned"])
        calls = per_point * points
        seconds = calls * t["cpu_s"] + points * overhead + fixed
        rows.append(
            {
                "label": c["label"],
                "n_atoms": c["n_atoms"],
                "points": points,
                "calls_per_point": per_point,
                "calls_source": source,
                "force_calls": round(calls),
                "call_cpu_s": t["cpu_s"],
                "call_wall_s": t["wall_s"],
                "overhead_per_point_s": overhead,
                "fixed_s": fixed,
                "seconds": seconds,
            }
        )
    executor, workers = executor_workers(cfg)
    total = sum(r["seconds"] for r in rows)
    largest = max((r["seconds"] for r in rows), default=0.0)
    wall = None if workers is None else max(total / workers, largest)
    local = max(total / default_workers(), largest) if workers is None else wall
    return {
        "cells": rows,
        "cpu_seconds": total,
        "wall_seconds": wall,
        "executor": executor,
        "workers": workers,
        "largest_cell_s": largest,
        "dask_threshold_s": DASK_THRESHOLD_S,
        "needs_dask": bool(local > DASK_THRESHOLD_S),
        "calibration": calibration,
        "load_average": os.getloadavg()[0],
        "cores": default_workers(),
    }


def cost_lines(est: dict) -> list[str]:
    """The estimate as console lines: one per cell, the totals and the Dask verdict."""
    lines = []
    for r in est["cells"]:
        lines.append(
            f"  {r['label']}: ~{r['force_calls']} force calls ({r['calls_per_point']:.3g} per "
            f"point, {r['calls_source']}) x {1e3 * r['call_cpu_s']:.3g} ms CPU (timed; "
            f"{1e3 * r['call_wall_s']:.3g} ms wall) + {r['points']} points x "
            f"{r['overhead_per_point_s']:.3g} s + {r['fixed_s']:.3g} s analysis: "
            f"~{duration(r['seconds'])}"
        )
    cal = est["calibration"]
    basis = (
        f"force calls per point measured on the finished cell {cal['label']}"
        if cal
        else "no finished cell in --out"
    )
    if est["wall_seconds"] is None:
        where = f"on the Dask cluster: ~max({duration(est['cpu_seconds'])} / its workers, "
        where += f"{duration(est['largest_cell_s'])})"
    else:
        where = (
            f"~{duration(est['wall_seconds'])} wall on {est['executor']} with "
            f"{est['workers']} worker(s) (cells side by side, each cell's scan serial)"
        )
    lines.append(
        f"cost: ~{duration(est['cpu_seconds'])} CPU (one core, all cells one after another), "
        f"{where}; {basis}"
    )
    slowdown = est["load_average"] / max(est["cores"], 1)
    if slowdown > 1:
        lines.append(
            f"  the machine is loaded now (load average {est['load_average']:.1f} on "
            f"{est['cores']} core(s)): expect up to ~{slowdown:.1f}x that wall time"
        )
    threshold = duration(est["dask_threshold_s"])
    if est["needs_dask"]:
        verdict = (
            f"needs a Dask cluster (docs/cluster.md: scan.dask_address or scan.jobqueue): "
            f"more than {threshold} on the local cores"
        )
        if est["largest_cell_s"] > est["dask_threshold_s"]:
            verdict += (
                f"; the largest cell alone takes ~{duration(est['largest_cell_s'])} (its scan "
                "is serial in the study: more workers do not shorten it; lower max_atoms)"
            )
    else:
        verdict = f"fits the local cores (Dask, docs/cluster.md, pays above {threshold})"
    lines.append(f"  {verdict}")
    return lines


def duration(seconds: float) -> str:
    """Seconds as ``12 s``, ``35 min`` or ``3.2 h``."""
    if not math.isfinite(seconds):
        return "?"
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"
