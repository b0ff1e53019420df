"""The scan driver: validate, open the store, resolve thicknesses, schedule, assemble.

:func:`run_scan` is the whole ISPES stage from Python; ``flatcontact scan`` is a thin
wrapper. The driver validates everything before any relaxation (grid size,
thicknesses that would make the slabs overlap, the store's settings, the executor),
then computes only the points missing from ``points.db``, each committed as soon as it
returns, and finally writes ``ispes.nc`` atomically. Interrupted (Ctrl-C, or a kill of
the driver), the store keeps every finished point and a rerun continues from there;
because each point's warm start comes from a fixed neighbour
(:mod:`flatcontact.ispes.order`), the resumed grid equals an uninterrupted one.
"""

from __future__ import annotations

import collections
import dataclasses
import functools
import heapq
import json
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from ase import Atoms

from flatcontact.errors import InputError
from flatcontact.ispes import contract, executors
from flatcontact.ispes.contract import (
    DIM_A,
    DIM_B,
    DIM_Z,
    VAR_ENERGY,
    VAR_STRESS,
    cell_area,
)
from flatcontact.ispes.geometry import in_plane_vectors, thickness, validate_interface
from flatcontact.ispes.grid import GridSpec, check_rows, check_thicknesses
from flatcontact.ispes.grid_bracket import MAX_EXTENSIONS, bracket_targets_gpa, check_grid
from flatcontact.ispes.order import PREFERENCES, search_tree
from flatcontact.ispes.probe import (
    CompressionSegments,
    RigidStackings,
    compress_chain,
    compress_segment,
    extreme_stackings,
    join_column,
    next_segments,
    rigid_rows,
    stretch_chain,
)
from flatcontact.ispes.probe_units import ProbeUnits, probe_settings
from flatcontact.ispes.reduction import (
    SymmetrySettings,
    choose_verify,
    fallback_reason,
    plan_reduction,
    symmetry_broken,
    verification,
)
from flatcontact.ispes.relax import (
    PointTask,
    RelaxSettings,
    ScanContext,
    relax_point,
    run_task,
    worker_calculator,
)
from flatcontact.ispes.shift_symmetry import shift_space_group
from flatcontact.ispes.store import PointStore, discard_store, interface_hash
from flatcontact.ispes.thicknesses import probe_thicknesses
from flatcontact.ispes.work_of_separation import ideal_work_of_separation
from flatcontact.layout import ISPES_NC, POINTS_DB, PROBE_JSON


@dataclasses.dataclass
class ScanResult:
    """What a scan did. ``dataset`` is the assembled ``ispes.nc`` content."""

    dataset: Any
    ispes_path: Path
    store_path: Path
    points_total: int
    points_done: int
    points_computed: int
    seconds: float
    force_calls_computed: list[int]
    adhesion: dict | None
    notes: list[str]
    interrupted: bool = False
    #: the shift-space group, the verification and whether the grid was computed in full
    #: (:mod:`flatcontact.ispes.reduction`); None when the scan computed every point
    symmetry: dict | None = None
    #: relaxed points in the store (``points_done`` also counts the points filled by symmetry)
    points_stored: int = 0
    #: folds of the probed and of the grid's columns and the loads they refuse
    #: (:meth:`flatcontact.ispes.thicknesses.LoadFold.record`; ``scan.json`` ``load_folds``)
    load_folds: list[dict] = dataclasses.field(default_factory=list)


def check_interface(atoms: Atoms) -> None:
    """One-line InputError unless ``atoms`` follows the interface contract.

    An interface whose atoms are all held (a bilayer of monolayers) is valid: every grid
    point is then a rigid-slab point (see :mod:`flatcontact.ispes.relax`).
    """
    validate_interface(atoms, "interface")


def scan_settings(
    reference: Atoms,
    factory: Any,
    grid: GridSpec,
    relax: RelaxSettings,
    symmetry: SymmetrySettings | None = None,
) -> dict:
    """The store fingerprint of a scan (everything that changes the numbers).

    The symmetry settings enter only when the reduction is on, so a store of a scan that
    computes every point keeps its fingerprint.
    """
    out = {
        "interface_sha256": interface_hash(reference),
        "potential": json.loads(factory.fingerprint),
        "relax": relax.as_dict(),
        "grid": grid.as_dict(),
    }
    if symmetry is not None and symmetry.enabled:
        out["symmetry"] = symmetry.as_dict()
    return out


#: From this many workers on, the probe runs as many short chains (:func:`_probe_many`):
#: the rigid single points on the workers, each column's compression in segments started
#: cold (:class:`~flatcontact.ispes.probe.CompressionSegments`), the ideal work of
#: separation beside the grid. Below, the columns are relaxed exactly as in sequence (a
#: 1-2 worker run keeps its numbers); a segment's cold start moves the probe's loads, and
#: the thicknesses with them, within the force tolerance.
MANY_WORKERS = 4

#: The grid's stored points are committed at most this often (s) while results keep
#: arriving, and always before the driver waits for the next result (or, with the serial
#: executor, relaxes the next point itself) and at the end:
#: a ``kill -9`` loses at most the points stored in the last ``COMMIT_INTERVAL_S`` of the
#: driver's uninterrupted storing (and the points in flight); SIGINT and a normal end lose
#: none (the store commits when it closes). One commit per point was 0.3 ms of the
#: driver's ≈ 1-2 ms per stored point (docs/performance.md).
COMMIT_INTERVAL_S = 0.5


def _any_done(handles) -> bool:
    """Whether a handle is already finished (the next wait will not block).

    Futures (``concurrent.futures``, Dask) have ``done()``; a handle without it counts as
    not done, so the store commits before every wait."""
    for handle in handles:
        done = getattr(handle, "done", None)
        if done is not None and done():
            return True
    return False


class PendingWork:
    """The ideal work of separation still running on a worker (:func:`_probe_many`): the
    scan stores it once the grid is done (``handle``: the executor's, or a :class:`Known`
    unit of ``probe.json``)."""

    def __init__(self, handle: Any, units: ProbeUnits | None = None, shift: Any = None):
        self.handle = handle
        self.units = units
        self.shift = shift

    def result(self, executor: Any) -> Any:
        """The work of separation, recorded in ``probe.json`` (:func:`unit_result`)."""
        return unit_result(executor, self.units, "work", (*self.shift,), self.handle)


class Known:
    """A probe unit read back from ``probe.json``, in place of an executor's handle."""

    def __init__(self, value: Any):
        self.value = value


def unit_submit(executor: Any, units: ProbeUnits | None, kind: str, inputs: tuple, fn, *args):
    """The finished unit ``kind`` with ``inputs`` from ``probe.json`` (a :class:`Known`) or
    ``fn(*args)`` submitted to the executor (its handle)."""
    value = None if units is None else units.get(kind, *inputs)
    return Known(value) if value is not None else executor.submit(fn, *args)


def unit_result(executor: Any, units: ProbeUnits | None, kind: str, inputs: tuple, handle):
    """The value of a :func:`unit_submit` handle; a computed unit is recorded at once."""
    if isinstance(handle, Known):
        return handle.value
    value = executor.result(handle)
    return value if units is None else units.put(kind, inputs, value)


def _cached(units: ProbeUnits | None, kind: str, inputs: tuple, compute) -> Any:
    return compute() if units is None else units.cached(kind, inputs, compute)


def _rigid_serial(
    reference: Atoms, calc, grid: GridSpec, units: ProbeUnits | None
) -> RigidStackings:
    """:func:`flatcontact.ispes.probe.rigid_stackings`, one ``probe.json`` unit per row."""
    sa, sb = grid.shifts()
    parts = [
        _cached(
            units,
            "rigid",
            _rigid_inputs(sa, sb, row),
            lambda row=row: rigid_rows(reference, calc, grid, [row]),
        )
        for row in range(grid.n_a)
    ]
    return RigidStackings(
        np.concatenate([e for e, _ in parts]), np.concatenate([p for _, p in parts])
    )


def _rigid_inputs(sa, sb, row: int) -> tuple:
    """The key inputs of the rigid unit of lateral row ``row``: its shift_a, every shift_b."""
    return (float(sa[row]), [float(b) for b in sb])


def _submit_stretchings(executor, units, context, specs) -> list:
    """One stretching chain per probed column ``(shift, p_hi, stop)``, each a probe unit
    (reused from ``probe.json`` when it finished before)."""
    return [
        unit_submit(
            executor,
            units,
            "stretch",
            (*shift, None, stop),
            probe_chain_task,
            context,
            "stretch",
            shift,
            p_hi,
            stop,
        )
        for shift, p_hi, stop in specs
    ]


def _probe(
    reference: Atoms,
    factory: Any,
    grid: GridSpec,
    relax: RelaxSettings,
    executor: Any = None,
    units: ProbeUnits | None = None,
) -> tuple[dict, list[str], Any]:
    """Resolve the thicknesses of a pressure-range grid
    (:func:`flatcontact.ispes.thicknesses.probe_thicknesses`) and, with more than one
    worker, the ideal work of separation beside them.

    The single points of every stacking run here. With more than one worker the rest runs
    on the workers as independent chains of relaxations, at once: each probed column's
    compression and stretching (:func:`flatcontact.ispes.probe.compress_chain`,
    :func:`~flatcontact.ispes.probe.stretch_chain`, joined exactly as the sequential column
    by :func:`~flatcontact.ispes.probe.join_column`) and the ideal work of separation at the
    lowest rigid stacking (a chain of its own, independent of the thicknesses). Returns
    ``(resolved, notes, work)``: ``work`` the
    :class:`~flatcontact.ispes.work_of_separation.WorkOfSeparation` (serial: computed here
    after the probe, from the same single points of every stacking).

    ``units`` (``probe.json``, :mod:`flatcontact.ispes.probe_units`) records every finished
    unit (a row of single points, a chain, a segment, the work of separation) as the driver
    gets it, and gives back those a resumed probe finished before: the same values, so the
    same thicknesses.
    """
    workers = 1 if executor is None else getattr(executor, "workers", 1)
    if workers >= MANY_WORKERS:
        return _probe_many(reference, factory, grid, relax, executor, units)
    calc = worker_calculator(factory, reference)
    relax_one = functools.partial(relax_column_point, reference, calc, relax)
    rigid = _rigid_serial(reference, calc, grid, units)
    lowest = extreme_stackings(rigid.energy_ev, grid)[0]
    if workers <= 1:

        def probe_columns_here(specs):
            # probe_column's two chains, one after the other, each a unit of probe.json
            out = []
            for shift, p_hi, stop in specs:
                down = _cached(
                    units,
                    "compress",
                    (*shift, p_hi),
                    lambda shift=shift, p_hi=p_hi: compress_chain(
                        relax_one, reference, shift, p_hi
                    ),
                )
                p_ref = down.normal_stress_gpa[0]
                up = _cached(
                    units,
                    "stretch",
                    (*shift, p_ref, stop),
                    lambda shift=shift, p_ref=p_ref, stop=stop: stretch_chain(
                        relax_one, reference, shift, p_ref, stop_at_gpa=stop
                    ),
                )
                out.append(join_column(reference, shift, down, up, stop_at_gpa=stop))
            return out

        extra, notes = probe_thicknesses(relax_one, reference, rigid, grid, probe_columns_here)
        work = _cached(
            units,
            "work",
            (*lowest,),
            lambda: ideal_work_of_separation(reference, factory, relax, lowest, calc=calc),
        )
        return extra, notes, work
    context = ScanContext(reference, factory, relax)
    work = []

    def probe_columns(specs):
        # the stretchings, the work of separation, then the compressions (on quartz the
        # compressions are the long chains, 19-21 points of ~30 force calls; past its first
        # point a stretching costs ~1 call per point: benchmarks/schedule_model.py)
        up = _submit_stretchings(executor, units, context, specs)
        work.append(
            unit_submit(
                executor, units, "work", (*lowest,), work_of_separation_task, context, lowest
            )
        )
        down = [
            unit_submit(
                executor,
                units,
                "compress",
                (*shift, p_hi),
                probe_chain_task,
                context,
                "compress",
                shift,
                p_hi,
                stop,
            )
            for shift, p_hi, stop in specs
        ]
        return [
            join_column(
                reference,
                shift,
                unit_result(executor, units, "compress", (*shift, p_hi), d),
                unit_result(executor, units, "stretch", (*shift, None, stop), u),
                stop_at_gpa=stop,
            )
            for (shift, p_hi, stop), d, u in zip(specs, down, up, strict=True)
        ]

    extra, notes = probe_thicknesses(relax_one, reference, rigid, grid, probe_columns)
    w = unit_result(executor, units, "work", (*lowest,), work[0]) if work else None
    return extra, notes, w


def _probe_many(
    reference: Atoms,
    factory: Any,
    grid: GridSpec,
    relax: RelaxSettings,
    executor: Any,
    units: ProbeUnits | None = None,
) -> tuple[dict, list[str], PendingWork]:
    """:func:`_probe` with many workers: nothing relaxes in the driver.

    1. The rigid single points, a block of rows of the lateral grid per worker
       (:func:`rigid_rows_task`).
    2. At once: each probed column's stretching (one chain), the compressions as segments
       of :data:`~flatcontact.ispes.probe.COMPRESS_SEGMENT_STEPS` steps
       (:func:`probe_segment_task`), as many as there are free workers
       (:func:`~flatcontact.ispes.probe.next_segments`), one more whenever a probe chain
       finishes, until each column's segments reach HI; then the ideal work of separation at
       the lowest rigid stacking (one chain, left running beside the grid: a
       :class:`PendingWork`).
    3. The columns joined (:meth:`~flatcontact.ispes.probe.CompressionSegments.join`,
       :func:`~flatcontact.ispes.probe.join_column`) and the thicknesses chosen as in
       sequence. Segments started beyond a column's end are left to finish unused.

    ``benchmarks/schedule_model.py`` replays this order. Units finished before (``units``,
    ``probe.json``) are not submitted: a row block holds only the rows still missing, a
    finished segment is added to its column at once without taking a worker.
    """
    context = ScanContext(reference, factory, relax)
    workers = executor.workers
    sa, sb = grid.shifts()
    rows: dict[int, tuple] = {}
    if units is not None:
        for row in range(grid.n_a):
            known = units.get("rigid", *_rigid_inputs(sa, sb, row))
            if known is not None:
                rows[row] = known
    missing = np.array([row for row in range(grid.n_a) if row not in rows], dtype=int)
    blocks = [b for b in np.array_split(missing, min(workers, max(missing.size, 1))) if b.size]
    handles = [executor.submit(rigid_rows_task, context, grid, b.tolist()) for b in blocks]
    for block, handle in zip(blocks, handles, strict=True):
        energy, load = executor.result(handle)
        for k, row in enumerate(block.tolist()):
            part = (energy[k : k + 1], load[k : k + 1])
            rows[row] = (
                part if units is None else units.put("rigid", _rigid_inputs(sa, sb, row), part)
            )
    parts = [rows[row] for row in range(grid.n_a)]
    rigid = RigidStackings(
        np.concatenate([e for e, _ in parts]), np.concatenate([p for _, p in parts])
    )
    work = []

    def probe_columns(specs):
        up = _submit_stretchings(executor, units, context, specs)
        plans = [CompressionSegments(p_hi) for _, p_hi, _ in specs]
        in_flight: dict[Any, tuple[int, int]] = {}

        def segment_inputs(c, j):
            shift, p_hi, _ = specs[c]
            return (*shift, p_hi, j, plans[c].n_steps)

        def start(slots):
            while slots > 0:
                picked = next_segments(plans, 1)
                if not picked:
                    break
                c, j = picked[0]
                shift, p_hi, _ = specs[c]
                handle = unit_submit(
                    executor,
                    units,
                    "segment",
                    segment_inputs(c, j),
                    probe_segment_task,
                    context,
                    shift,
                    p_hi,
                    j,
                )
                if isinstance(handle, Known):  # finished before: no worker taken
                    plans[c].add(j, handle.value)
                    continue
                in_flight[handle] = (c, j)
                slots -= 1

        start(max(len(specs), workers - len(specs)))
        # the work of separation after the first segments (FIFO): it gates nothing
        lowest = extreme_stackings(rigid.energy_ev, grid)[0]
        work.append(
            PendingWork(
                unit_submit(
                    executor, units, "work", (*lowest,), work_of_separation_task, context, lowest
                ),
                units,
                lowest,
            )
        )
        waiting = {u: c for c, u in enumerate(up) if not isinstance(u, Known)}
        stretched: dict[int, Any] = {}
        while any(plan.join() is None for plan in plans):
            done, _ = executor.wait_first(set(in_flight) | set(waiting))
            for handle in done:
                if handle in waiting:
                    c = waiting.pop(handle)
                    shift, _, stop = specs[c]
                    stretched[c] = unit_result(
                        executor, units, "stretch", (*shift, None, stop), handle
                    )
                else:
                    c, j = in_flight.pop(handle)
                    plans[c].add(
                        j, unit_result(executor, units, "segment", segment_inputs(c, j), handle)
                    )
                start(1)
        return [
            join_column(
                reference,
                shift,
                plan.join(),
                stretched[c]
                if c in stretched
                else unit_result(executor, units, "stretch", (*shift, None, stop), u),
                stop_at_gpa=stop,
            )
            for c, ((shift, _, stop), plan, u) in enumerate(zip(specs, plans, up, strict=True))
        ]

    extra, notes = probe_thicknesses(None, reference, rigid, grid, probe_columns)
    return extra, notes, work[0]


def pull_off_record(pull_off: dict | None) -> dict:
    """The probe's pull-off record (:class:`flatcontact.ispes.separation.Adhesion`), the
    ``work_of_separation_*`` keys of an older scan renamed to ``pull_off_*``."""
    pulled = {}
    for key, value in (pull_off or {}).items():
        if key.startswith("work_of_separation"):
            key = key.replace("work_of_separation", "pull_off_work", 1)
        pulled[key] = value
    return pulled


def adhesion_record(
    reference: Atoms,
    factory: Any,
    grid: GridSpec,
    relax: RelaxSettings,
    pull_off: dict | None = None,
    work: Any = None,
    units: ProbeUnits | None = None,
) -> dict:
    """The ``adhesion`` entry of a scan: the ideal work of separation and the probe's pull-off.

    W (``work_of_separation_j_per_m2``) is that of the lowest rigid energy among the grid's
    lateral shifts (:func:`flatcontact.ispes.work_of_separation.ideal_work_of_separation`),
    whatever the thicknesses; ``work``, if given, is that W already computed (on a worker,
    :func:`_probe`). ``pull_off`` is the probe's record
    (:class:`flatcontact.ispes.separation.Adhesion`, absent for given thicknesses). A
    record of an older scan whose ``work_of_separation_*`` keys were the pull-off's is
    renamed to ``pull_off_*``. ``units`` (``probe.json``) gives back the single points and
    the W a resumed scan finished before and records those it computes.
    """
    pulled = pull_off_record(pull_off)
    if work is None:
        calc = worker_calculator(factory, reference)
        shift = extreme_stackings(_rigid_serial(reference, calc, grid, units).energy_ev, grid)[0]
        work = _cached(
            units,
            "work",
            (*shift,),
            lambda: ideal_work_of_separation(reference, factory, relax, shift, calc=calc),
        )
    return {**pulled, **work.record()}


def _tree_in_store_order(
    z: np.ndarray, shape: tuple, root: tuple, order: str, allowed: set | None = None
) -> dict:
    """The warm-start tree (:func:`flatcontact.ispes.order.search_tree`) over the
    thicknesses in ascending order, in the store's indices (``root``, ``allowed`` and the
    result): ``i_z`` is the position in the resolved list, which a thickness added below
    the smallest after the scan (:func:`_extend`) joins at its end. For an ascending list
    (every scan before such an addition) this is the tree itself."""
    rank = np.argsort(z, kind="stable")  # sorted position -> store index
    if np.array_equal(rank, np.arange(z.size)):
        return search_tree(shape, root, order, allowed=allowed)
    position = np.empty_like(rank)
    position[rank] = np.arange(z.size)  # store index -> sorted position

    def to_sorted(idx):
        return (idx[0], idx[1], int(position[idx[2]]))

    def to_store(idx):
        return None if idx is None else (idx[0], idx[1], int(rank[idx[2]]))

    sorted_allowed = None if allowed is None else {to_sorted(i) for i in allowed}
    tree = search_tree(shape, to_sorted(root), order, allowed=sorted_allowed)
    return {to_store(idx): to_store(par) for idx, par in tree.items()}


def _extend(
    store,
    reference: Atoms,
    grid: GridSpec,
    relax: RelaxSettings,
    max_new_points,
    loads_gpa,
    ds,
) -> bool:
    """After a pressure-range grid ``ds`` (the store assembled, symmetry-mapped points
    filled) is complete, check it brackets its loads
    (:func:`flatcontact.ispes.grid_bracket.check_grid`): a thickness beyond the largest
    if a column ends short of the low target, one below the smallest if a column ends
    short of the high target (unless the slabs would overlap there), appended to the
    resolved list so the stored points keep their ``i_z`` (:func:`_tree_in_store_order`);
    True when one was added (the caller computes the new points, at most
    ``MAX_EXTENSIONS`` rounds). Otherwise the folds and the columns still short go into
    ``resolved`` (``load_folds``, ``notes``). Given thicknesses are never changed."""
    resolved = store.resolved
    tension = None
    if grid.p_range_gpa is not None and resolved.get("bracket_gpa"):
        raised = float(resolved["bracket_gpa"][0])
        tension = raised if raised > grid.p_range_gpa[0] else None  # LO was raised to it
    targets = (
        list(bracket_targets_gpa(grid.p_range_gpa, loads_gpa, tension))
        if grid.p_range_gpa
        else None
    )
    if (
        grid.p_range_gpa is None
        or max_new_points is not None
        or not np.all(np.isfinite(ds[VAR_ENERGY].values))
        or resolved.get("grid_checked_gpa") == targets
    ):
        return False
    low, high = targets
    n_z = ds.sizes[DIM_Z]
    z = ds[DIM_Z].values
    verdict = check_grid(
        z,
        ds[VAR_ENERGY].values.reshape(-1, n_z),
        ds[VAR_STRESS].values.reshape(-1, n_z),
        float(ds.attrs["area"]),
        [(float(a), float(b)) for a in ds[DIM_A].values for b in ds[DIM_B].values],
        grid.p_range_gpa,
        loads_gpa,
        tension,
    )
    added = resolved.get("thicknesses_added_after_scan", 0)
    notes = list(resolved.get("notes", []))
    new = []
    if added < MAX_EXTENSIONS:
        if verdict.z_above is not None:
            new.append(verdict.z_above)
            notes.append(
                f"p-range-gpa: a column of the grid ends above {low:g} GPa (P = 0, LO and "
                f"the loads analysed) at z = {z.max():.4g} Å; added z = {verdict.z_above:.4g} Å"
            )
        if verdict.z_below is not None:
            try:
                check_thicknesses(
                    reference, grid, [verdict.z_below], spread_compression=relax.mode != "rigid"
                )
            except InputError:
                pass  # the slabs would overlap: the column stays short, noted below
            else:
                new.append(verdict.z_below)
                notes.append(
                    f"p-range-gpa: a column of the grid ends below {high:g} GPa (the highest "
                    f"load analysed, else HI) at z = {z.min():.4g} Å; added z = "
                    f"{verdict.z_below:.4g} Å"
                )
    if new:
        store.set_resolved(
            {
                **resolved,
                "thickness_angstrom": [*resolved["thickness_angstrom"], *new],
                "notes": notes,
                "thicknesses_added_after_scan": added + 1,
            }
        )
        return True
    folds = list(resolved.get("load_folds", [])) + [f.record() for f in verdict.folds]
    notes += [f.message() for f in verdict.folds[:1]]
    if len(verdict.folds) > 1:
        notes.append(f"p-range-gpa: {len(verdict.folds)} grid columns fold (scan.json load_folds)")
    if verdict.short and verdict.z_below is not None:
        notes += verdict.short[:1]
    if verdict.z_above is not None:
        notes.append(
            f"p-range-gpa: after {added} added thickness(es) a grid column still ends above "
            f"{low:g} GPa at z = {z.max():.4g} Å; give scan.thickness_angstrom beyond it"
        )
    store.set_resolved(
        {**resolved, "load_folds": folds, "notes": notes, "grid_checked_gpa": targets}
    )
    return False


def relax_column_point(reference, calc, relax, a, b, z, start, start_z) -> tuple:
    """One probe point: ``(energy_ev, normal_stress_gpa, force_calls, positions)``."""
    task = PointTask((0, 0, 0), a, b, z, start, (a, b) if start is not None else None, start_z)
    r = relax_point(reference, calc, task, relax)
    return r.energy_ev, r.normal_stress_gpa, r.force_calls, r.positions


def probe_chain_task(context: ScanContext, kind: str, shift, p_hi_gpa, stop_at_gpa):
    """Worker entry point: one chain of a probed column with this worker's cached
    calculator: ``kind`` ``"compress"`` (:func:`flatcontact.ispes.probe.compress_chain`) or
    ``"stretch"`` (:func:`flatcontact.ispes.probe.stretch_chain`, without the load at the
    reference thickness: :func:`flatcontact.ispes.probe.join_column` cuts it)."""
    calc = worker_calculator(context.factory, context.reference)
    relax_one = functools.partial(relax_column_point, context.reference, calc, context.settings)
    if kind == "compress":
        return compress_chain(relax_one, context.reference, shift, p_hi_gpa)
    return stretch_chain(relax_one, context.reference, shift, None, stop_at_gpa=stop_at_gpa)


def _check_overlaps(executor: Any, context: ScanContext, grid: GridSpec, z: list[float]) -> None:
    """The overlap check of every lateral shift at the thicknesses ``z`` before they are
    scanned (:func:`flatcontact.ispes.grid.check_thicknesses`: one InputError naming the
    first overlap). With :data:`MANY_WORKERS` or more workers the ``(z, row)`` pairs are
    split into a block per worker (:func:`overlap_check_task`; at the paper preset's
    3,168 points the check is seconds of the driver's time); else in the driver."""
    spread = context.settings.mode != "rigid"
    workers = getattr(executor, "workers", 1)
    if workers < MANY_WORKERS:
        check_thicknesses(context.reference, grid, z, spread_compression=spread)
        return
    items = [(v, row) for v in z for row in range(grid.n_a)]
    blocks = [b for b in np.array_split(np.arange(len(items)), workers) if b.size]
    handles = [
        executor.submit(overlap_check_task, context, grid, [items[k] for k in b]) for b in blocks
    ]
    for handle in handles:  # in order: the first overlap in the grid's order is named
        executor.result(handle)


def overlap_check_task(context: ScanContext, grid: GridSpec, items: list[tuple[float, int]]):
    """Worker entry point: :func:`flatcontact.ispes.grid.check_rows` of ``items``."""
    check_rows(context.reference, grid, items, spread_compression=context.settings.mode != "rigid")


def probe_segment_task(context: ScanContext, shift, p_hi_gpa, index: int):
    """Worker entry point: segment ``index`` of a probed column's compression
    (:func:`flatcontact.ispes.probe.compress_segment`) with this worker's cached calculator."""
    calc = worker_calculator(context.factory, context.reference)
    relax_one = functools.partial(relax_column_point, context.reference, calc, context.settings)
    segments = CompressionSegments(p_hi_gpa)
    return compress_segment(
        relax_one, context.reference, shift, p_hi_gpa, index * segments.n_steps, segments.n_steps
    )


def rigid_rows_task(context: ScanContext, grid: GridSpec, rows: list[int]):
    """Worker entry point: the rigid single points of the lateral rows ``rows``
    (:func:`flatcontact.ispes.probe.rigid_rows`)."""
    calc = worker_calculator(context.factory, context.reference)
    return rigid_rows(context.reference, calc, grid, rows)


def work_of_separation_task(context: ScanContext, shift):
    """Worker entry point: the ideal work of separation at ``shift``
    (:func:`flatcontact.ispes.work_of_separation.ideal_work_of_separation`)."""
    calc = worker_calculator(context.factory, context.reference)
    return ideal_work_of_separation(
        context.reference, context.factory, context.settings, shift, calc=calc
    )


def run_scan(
    reference: Atoms,
    factory: Any,
    grid: GridSpec,
    out_dir: str | Path,
    relax: RelaxSettings | None = None,
    order: str = "columns",
    executor: Any = None,
    executor_options: dict | None = None,
    progress: Callable[[int, int], None] | None = None,
    max_new_points: int | None = None,
    symmetry: SymmetrySettings | None = None,
    bracket_loads_gpa: Sequence[float] | None = None,
) -> ScanResult:
    """Compute the ISPES grid of ``reference`` with ``factory``'s calculator into ``out_dir``.

    Parameters
    ----------
    reference
        The relaxed reference interface (slab 2 at shift (0, 0)), interface contract.
    factory
        A picklable calculator factory with a ``fingerprint`` (see
        :func:`flatcontact.potentials.engines.calculator_factory`).
    grid
        The lateral grid and thicknesses or pressure range.
    out_dir
        Receives ``points.db``, ``probe.json`` (the probe's finished units: a scan
        interrupted in its probe resumes it, :mod:`flatcontact.ispes.probe_units`) and
        ``ispes.nc``.
    relax
        Relaxation settings (tolerance, optimiser, step cap).
    order
        Warm-start tree preference: ``"columns"`` (default), ``"planes"`` or ``"cold"``
        (:mod:`flatcontact.ispes.order`).
    executor
        An executor object (:mod:`flatcontact.ispes.executors`); if None, one is built
        from ``executor_options`` (``make_executor`` keywords) after validation.
    progress
        Called as ``progress(done, total)`` (grid points done, points of the grid) once
        the grid is known and after every stored point, like an observer attached to an ASE
        dynamics; the CLI draws its progress bar from it. A reduced scan counts the grid
        points a stored representative fills by symmetry and its verified points
        (``total`` = grid points + verified points), one bar to 100 %; a fallback to the
        full grid counts the grid's stored points from there.
    max_new_points
        Stop after computing this many new points (benchmarks); the store stays resumable.
    symmetry
        Irreducible registries (:mod:`flatcontact.ispes.reduction`): relax one point per orbit
        of the interface's shift-space group, verify some mapped points, fill the rest.
        ``None``: every point is relaxed (``SymmetrySettings(enabled=False)``).
    bracket_loads_gpa
        The loads the analysis will read (GPa), if known: a pressure-range grid is
        extended until every column brackets them, P = 0 and LO (without them: P = 0, LO
        and HI; :func:`flatcontact.ispes.grid_bracket.check_grid`). Not part of the store
        fingerprint; a finished store is re-checked when they change.

    Returns
    -------
    ScanResult
    """
    t0 = time.perf_counter()
    relax = relax or RelaxSettings()
    symmetry = symmetry or SymmetrySettings(enabled=False)
    if order not in PREFERENCES:
        raise InputError(f"order: expected one of {', '.join(PREFERENCES)}, got {order!r}")
    check_interface(reference)
    if grid.thickness_angstrom is not None:
        check_thicknesses(
            reference, grid, grid.thickness_angstrom, spread_compression=relax.mode != "rigid"
        )
    out_dir = Path(out_dir)
    store_path = out_dir / POINTS_DB
    fresh_dir, fresh_store = not out_dir.exists(), not store_path.exists()
    store = None
    try:
        with PointStore(
            store_path,
            scan_settings(reference, factory, grid, relax, symmetry),
            reference,
            commit_interval_s=COMMIT_INTERVAL_S,
        ) as store:
            own_executor = executor is None
            if own_executor:
                executor = executors.make_executor(**(executor_options or {}))
            known = store.resolved
            if hasattr(executor, "prestart") and (
                known is None or len(store) < grid.n_a * grid.n_b * len(known["thickness_angstrom"])
            ):
                executor.prestart(factory, reference)  # worker start overlaps the probe
            notes: list[str] = []
            interrupted = False
            computed_calls: list[int] = []
            pending_work = None
            # the probe's finished units, beside the store (a resumed probe reuses them)
            units = ProbeUnits(out_dir / PROBE_JSON, probe_settings(store.settings))
            try:
                if store.resolved is None:
                    a1, a2 = in_plane_vectors(reference)
                    resolved = {
                        "a1": a1.tolist(),
                        "a2": a2.tolist(),
                        "potential_label": factory.label,
                    }
                    work = None
                    if grid.thickness_angstrom is not None:
                        resolved["thickness_angstrom"] = list(grid.thickness_angstrom)
                    else:
                        extra, notes, work = _probe(
                            reference, factory, grid, relax, executor, units
                        )
                        resolved.update(extra)
                    if isinstance(work, PendingWork):  # stored once the grid is done
                        pending_work = work
                        resolved["adhesion"] = pull_off_record(resolved.get("adhesion"))
                    else:
                        resolved["adhesion"] = adhesion_record(
                            reference, factory, grid, relax, resolved.get("adhesion"), work, units
                        )
                    units.announce()
                    store.set_resolved(resolved)
                resolved = store.resolved
                if pending_work is None and "work_of_separation_shift_a" not in (
                    resolved.get("adhesion") or {}
                ):
                    # a store resolved before the ideal W existed: its W was the pull-off's
                    resolved = {
                        **resolved,
                        "adhesion": adhesion_record(
                            reference, factory, grid, relax, resolved.get("adhesion"), units=units
                        ),
                    }
                sa, sb = grid.shifts()
                context = ScanContext(reference, factory, relax)
                recent = PositionsCache()
                checked: set[float] = set()  # thicknesses whose overlap check passed
                while True:
                    notes = list(resolved.get("notes", notes))
                    z = np.asarray(resolved["thickness_angstrom"], dtype=float)
                    if grid.thickness_angstrom is None:
                        new_z = [float(v) for v in z if float(v) not in checked]
                        _check_overlaps(executor, context, grid, new_z)
                        checked.update(new_z)
                    shape = (grid.n_a, grid.n_b, z.size)
                    root = (0, 0, int(np.argmin(np.abs(z - thickness(reference)))))
                    full_tree = _tree_in_store_order(z, shape, root, order)
                    reduction = None
                    if symmetry.enabled:
                        # modulo the pure translations, lifted onto the grid: a twist
                        # cell's N² translations are never enumerated against each other
                        group = shift_space_group(
                            reference,
                            symmetry.tolerance_angstrom,
                            spread_compression=relax.mode != "rigid",
                            modulo_translations=True,
                        ).for_grid(grid.n_a, grid.n_b)
                        reduction = plan_reduction(group, shape, list(full_tree))

                    def converged(idx):
                        return idx is not None and idx in store and store.record(idx)["converged"]

                    def positions(idx):
                        cached = recent.get(idx)
                        return cached if cached is not None else store.positions(idx)

                    def run_points(parent, z=z, weight=None, total=None):
                        """Relax the points of the tree ``parent`` missing from the store.

                        Progress counts ``weight[idx]`` (default 1) per stored point out of
                        ``total`` (default: the tree's points): a representative of a reduced
                        scan counts the grid points it fills, so one bar runs to the grid.
                        """
                        weight = weight or {}

                        def make_task(idx):
                            par = parent[idx]
                            ia, ib, iz = idx
                            if not converged(par):
                                return PointTask(idx, float(sa[ia]), float(sb[ib]), float(z[iz]))
                            pa, pb, pz = par
                            grand = parent[par]
                            previous = {}
                            if converged(grand) and grand[:2] == par[:2] == idx[:2]:
                                previous = {
                                    "previous_positions": positions(grand),
                                    "previous_thickness": float(z[grand[2]]),
                                }
                            return PointTask(
                                idx,
                                float(sa[ia]),
                                float(sb[ib]),
                                float(z[iz]),
                                positions(par),
                                (float(sa[pa]), float(sb[pb])),
                                float(z[pz]),
                                par,
                                **previous,
                            )

                        rank = {idx: k for k, idx in enumerate(parent)}
                        if getattr(executor, "workers", 1) >= MANY_WORKERS:
                            rank = deepest_first(parent, rank)
                        pending = {idx for idx in parent if idx not in store}
                        if total is None:
                            total = len(parent)
                        stored = sum(weight.get(idx, 1) for idx in parent if idx in store)
                        if progress is not None:
                            progress(stored, total)
                        in_flight: dict[Any, tuple] = {}
                        cap = 2 * max(1, getattr(executor, "workers", 1))
                        queue = ReadyQueue(parent, rank, store, pending)
                        inline = getattr(executor, "name", None) == "serial"
                        while pending or in_flight:
                            if (
                                max_new_points is not None
                                and len(computed_calls) + len(in_flight) >= max_new_points
                                and not in_flight
                            ):
                                break
                            while (
                                queue
                                and len(in_flight) < cap
                                and (
                                    max_new_points is None
                                    or len(computed_calls) + len(in_flight) < max_new_points
                                )
                            ):
                                idx = queue.pop()
                                if inline:
                                    store.flush()  # the submit relaxes the point in the driver
                                handle = executor.submit(run_task, context, make_task(idx))
                                in_flight[handle] = idx
                                pending.discard(idx)
                            if not in_flight:
                                break
                            if not _any_done(in_flight):
                                store.flush()  # the driver is about to wait: commit first
                            done, _ = executor.wait_first(in_flight)
                            for handle in done:
                                idx = in_flight.pop(handle)
                                result = executor.result(handle)
                                store.write(result)
                                recent.put(idx, result.positions)
                                queue.stored(idx)
                                computed_calls.append(result.force_calls)
                                stored += weight.get(idx, 1)
                                if progress is not None:
                                    progress(stored, total)
                        store.flush()  # before the assembly and the checks that follow

                    symmetry_record, mapping = None, None
                    try:
                        if reduction is None or reduction.group.order == 1:
                            run_points(full_tree)
                        else:
                            # the record and the mapping exist from the start, so a scan
                            # stopped partway writes the mapped points of its stored
                            # representatives
                            mapping = reduction.representative
                            symmetry_record = {
                                **reduction.to_json(),
                                "verification": None,
                                "computed_in_full": False,
                            }
                            # progress over the grid: a representative fills its orbit,
                            # a verified point counts one more
                            fills = collections.Counter(reduction.representative.values())
                            grid_points = int(np.prod(shape))
                            run_points(
                                _tree_in_store_order(z, shape, root, order, reduction.computed),
                                weight=fills,
                                total=grid_points + symmetry.verify_points,
                            )
                            if all(rep in store for rep in reduction.computed):
                                # chosen from the complete representatives only: a resumed
                                # scan verifies the same points as an uninterrupted one
                                reduction = choose_verify(
                                    reduction, store.done(), shape, symmetry.verify_points
                                )
                                symmetry_record.update(reduction.to_json())
                                run_points(
                                    _tree_in_store_order(z, shape, root, order, reduction.computed),
                                    weight=fills,
                                    total=grid_points + len(reduction.verify),
                                )
                            if all(idx in store for idx in reduction.computed):
                                area = cell_area(*in_plane_vectors(reference))
                                check = verification(reduction, store.done(), area, symmetry)
                                symmetry_record["verification"] = check
                                if symmetry_broken(check, symmetry):
                                    reason = fallback_reason(check, symmetry, reduction.group.order)
                                    symmetry_record["computed_in_full"] = True
                                    symmetry_record["computed_in_full_reason"] = reason
                                    notes.append(reason)
                                    mapping = None
                                    run_points(full_tree)
                    except KeyboardInterrupt:
                        interrupted = True
                    if interrupted:
                        break
                    if not _extend(
                        store,
                        reference,
                        grid,
                        relax,
                        max_new_points,
                        bracket_loads_gpa,
                        store.assemble(mapping, symmetry_record),
                    ):
                        break
                    resolved = store.resolved
                if pending_work is not None and not interrupted:
                    # the ideal work of separation ran beside the grid (a resumed scan
                    # whose store lacks it computes it in the driver, above)
                    w = pending_work.result(executor)
                    adhesion = {**(store.resolved.get("adhesion") or {}), **w.record()}
                    store.set_resolved({**store.resolved, "adhesion": adhesion})
                    resolved = store.resolved
                kept = list(store.resolved.get("notes", []))
                notes = kept + [n for n in notes if n not in kept]
            finally:
                if own_executor:
                    executor.close(cancel=True)
            ds = store.assemble(mapping, symmetry_record)
            path = contract.write_ispes(ds, out_dir / ISPES_NC)
            result = ScanResult(
                dataset=ds,
                ispes_path=path,
                store_path=store.path,
                points_total=int(np.prod(shape)),
                points_done=int(ds.attrs["points_done"]),
                points_computed=len(computed_calls),
                seconds=time.perf_counter() - t0,
                force_calls_computed=computed_calls,
                adhesion=resolved.get("adhesion"),
                notes=notes,
                interrupted=interrupted,
                symmetry=symmetry_record,
                points_stored=len(store),
                load_folds=list(store.resolved.get("load_folds", [])),
            )
    except Exception:
        # a run that failed before storing a point (executor not reachable, probe error)
        # leaves no store behind that would refuse the corrected rerun
        if fresh_store and (store is None or len(store) == 0):
            discard_store(store_path, remove_parent=fresh_dir)
        raise

    if interrupted:
        raise ScanInterrupted(result)
    return result


def deepest_first(parent: dict, rank: dict) -> dict:
    """Ranks for :class:`ReadyQueue` that put, of the ready points, the one with the longest
    chain of descendants below it first (ties: the tree's visiting order ``rank``).

    With many workers the warm-start tree's long branches then start early and the grid's
    last points leave fewer workers idle (the paper preset at 16 workers: 0.15 s of a 15.7 s
    round, ``benchmarks/schedule_model.py``). Each point keeps its warm-start parent, so the
    numbers do not change; only the order in which points are computed does.
    """
    children: dict = {}
    for idx, par in parent.items():
        children.setdefault(par, []).append(idx)
    order, stack = [], list(children.get(None, []))
    while stack:  # parents before children
        idx = stack.pop()
        order.append(idx)
        stack.extend(children.get(idx, []))
    height: dict = {}
    for idx in reversed(order):
        height[idx] = 1 + max((height[c] for c in children.get(idx, [])), default=0)
    ranked = sorted(parent, key=lambda idx: (-height.get(idx, 1), rank[idx]))
    return {idx: k for k, idx in enumerate(ranked)}


class ReadyQueue:
    """The points whose warm-start parent is stored, in the search tree's visiting order.

    A heap keyed by the point's rank in the tree: each stored point pushes its children,
    so scheduling costs O(log n) per point (scanning every pending point for readiness
    after each stored point cost O(n) each, O(n²) per scan: seconds of driver CPU on a
    paper-size grid, taken from the workers' cores).
    """

    def __init__(self, parent: dict, rank: dict, store: Any, pending: set):
        self._rank = rank
        self._pending = pending
        self._children: dict = {}
        for idx, par in parent.items():
            if par is not None:
                self._children.setdefault(par, []).append(idx)
        self._heap = [
            (rank[idx], idx) for idx in pending if parent[idx] is None or parent[idx] in store
        ]
        heapq.heapify(self._heap)

    def __bool__(self) -> bool:
        return bool(self._heap)

    def pop(self):
        """The earliest ready point in visiting order."""
        return heapq.heappop(self._heap)[1]

    def stored(self, idx) -> None:
        """``idx`` is stored: its pending children become ready."""
        for child in self._children.get(idx, ()):
            if child in self._pending:
                heapq.heappush(self._heap, (self._rank[child], child))


class PositionsCache:
    """Relaxed positions of recently stored points, kept in memory for the warm starts.

    The driver has each result's positions in hand when it stores it; its children and
    grandchildren start from them moments later. Keeping them (least recently used out,
    at most ``budget_bytes``) spares a database read per submitted point; a point not in
    the cache is read from the store (the same float64 array, bit for bit).
    """

    def __init__(self, budget_bytes: int = 64 * 2**20):
        self._budget = int(budget_bytes)
        self._bytes = 0
        self._items: collections.OrderedDict = collections.OrderedDict()

    def put(self, idx, positions: np.ndarray) -> None:
        arr = np.asarray(positions, dtype=float)
        if arr.nbytes > self._budget:
            return
        self._items[idx] = arr
        self._bytes += arr.nbytes
        while self._bytes > self._budget:
            _, old = self._items.popitem(last=False)
            self._bytes -= old.nbytes

    def get(self, idx) -> np.ndarray | None:
        arr = self._items.get(idx)
        if arr is not None:
            self._items.move_to_end(idx)
            return arr.copy()
        return None


class ScanInterrupted(KeyboardInterrupt):
    """Raised after Ctrl-C, once the store is consistent and a partial ``ispes.nc`` is written."""

    def __init__(self, result: ScanResult):
        super().__init__(
            f"interrupted: {result.points_done} of {result.points_total} points stored"
        )
        self.result = result
