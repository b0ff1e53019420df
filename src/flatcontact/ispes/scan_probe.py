"""The scan's probe driver: resolve a pressure-range grid's thicknesses and the adhesion record.

Before the grid, a scan given a pressure range (``GridSpec.p_range_gpa``) probes columns of
the interface to choose its thicknesses (:func:`flatcontact.ispes.thicknesses.probe_thicknesses`)
and computes the ideal work of separation (:mod:`flatcontact.ispes.work_of_separation`);
:func:`resolve` stores both in the store's ``resolved`` entry once. Every finished unit (a
row of single points, a chain, a segment, the work of separation) is recorded in
``probe.json`` (:mod:`flatcontact.ispes.probe_units`) as the driver gets it, so an
interrupted probe resumes with the same values, hence the same thicknesses.

With one worker everything runs in the driver. With workers, the rigid single points run
on them while the driver computes the reference Hessian (:class:`RigidRows`) and the ideal
work of separation beside the grid (:class:`PendingWork`); with two or three the columns'
chains run on the workers exactly as in sequence; from :data:`MANY_WORKERS` on the
compressions run as cold-started segments (:func:`probe_many`).
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
from ase import Atoms

from flatcontact.ispes.executors import Executor
from flatcontact.ispes.geometry import in_plane_vectors
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.phases import phase
from flatcontact.ispes.probe import (
    CompressionSegments,
    RigidStackings,
    compress_chain,
    extreme_stackings,
    join_column,
    next_segments,
    rigid_rows,
    stretch_chain,
)
from flatcontact.ispes.probe_units import ProbeUnits
from flatcontact.ispes.relax import RelaxSettings, ScanContext, worker_calculator
from flatcontact.ispes.scan_tasks import (
    probe_chain_task,
    probe_segment_task,
    relax_column_point,
    rigid_rows_task,
    work_of_separation_task,
)
from flatcontact.ispes.store import PointStore
from flatcontact.ispes.thicknesses import probe_thicknesses
from flatcontact.ispes.work_of_separation import ideal_work_of_separation

#: From this many workers on, the probe runs as many short chains (:func:`probe_many`):
#: each column's compression in segments started cold
#: (:class:`~flatcontact.ispes.probe.CompressionSegments`). Below, the columns are relaxed
#: exactly as in sequence (a 1-3 worker run keeps its numbers); a segment's cold start
#: moves the probe's loads, and the thicknesses with them, within the force tolerance.
MANY_WORKERS = 4


class PendingWork:
    """The ideal work of separation still running on a worker (any scan with workers): the
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
    return _joined(parts)


def _joined(parts: list[tuple]) -> RigidStackings:
    """The rows' ``(energy, load)`` units, in row order, as one :class:`RigidStackings`."""
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


def early_rigid_rows(
    store: PointStore,
    executor: Executor,
    units: ProbeUnits,
    context: ScanContext,
    grid: GridSpec,
) -> RigidRows | None:
    """The probe's rigid single points submitted now, if the probe will run and has workers
    (:class:`RigidRows`): the store is not resolved yet, the grid is given by a pressure
    range and the executor is not the driver itself. One row per task: the workers start
    one after the other, the driver hands them their next rows between the Hessian's
    columns (:meth:`~flatcontact.ispes.executors.ProcessExecutor.serve`) and the probe
    waits for the last row, so the smaller the tasks the shorter that wait. None otherwise."""
    if executor.inline or store.resolved is not None or grid.thickness_angstrom is not None:
        return None
    return RigidRows(executor, units, context, grid, blocks=grid.n_a)


def resolve(
    store: PointStore,
    reference: Atoms,
    factory: Any,
    grid: GridSpec,
    relax: RelaxSettings,
    executor: Executor,
    units: ProbeUnits,
    hessian: Any = None,
    rigid: RigidRows | None = None,
) -> tuple[dict, list[str], PendingWork | None]:
    """The store's ``resolved`` entry, computed and stored if the store has none yet.

    ``resolved``: the lattice vectors, the potential's label, the thicknesses (given, or
    chosen by the probe: :func:`probe`) and the ``adhesion`` record
    (:func:`adhesion_record`). Returns ``(resolved, notes, pending)``: ``notes`` the probe's,
    ``pending`` the ideal work of separation still running on a worker (with workers: the
    driver stores it after the grid, :func:`store_pending_work`), else None. A store
    resolved before the ideal work of separation existed gets it here (in the returned
    entry, not in the store). ``hessian``: the driver's root of the reference's Hessian
    (:class:`~flatcontact.ispes.precondition.SharedRoot`) for the probe's tasks; ``rigid``
    the probe's single points already on the workers (:func:`early_rigid_rows`).
    """
    notes: list[str] = []
    pending = None
    if store.resolved is None:
        a1, a2 = in_plane_vectors(reference)
        resolved = {"a1": a1.tolist(), "a2": a2.tolist(), "potential_label": factory.label}
        work = None
        if grid.thickness_angstrom is not None:
            resolved["thickness_angstrom"] = list(grid.thickness_angstrom)
        else:
            extra, notes, work = probe(
                reference, factory, grid, relax, executor, units, hessian, rigid
            )
            resolved.update(extra)
        if isinstance(work, PendingWork):  # stored once the grid is done
            pending = work
            resolved["adhesion"] = pull_off_record(resolved.get("adhesion"))
        else:
            with phase("probe/ideal W"):  # computed here for given thicknesses
                resolved["adhesion"] = adhesion_record(
                    reference, factory, grid, relax, resolved.get("adhesion"), work, units
                )
        units.announce()
        store.set_resolved(resolved)
    resolved = store.resolved
    if pending is None and "work_of_separation_shift_a" not in (resolved.get("adhesion") or {}):
        # a store resolved before the ideal W existed: its W was the pull-off's
        resolved = {
            **resolved,
            "adhesion": adhesion_record(
                reference, factory, grid, relax, resolved.get("adhesion"), units=units
            ),
        }
    return resolved, notes, pending


def store_pending_work(store: PointStore, pending: PendingWork, executor: Executor) -> None:
    """The ideal work of separation that ran beside the grid, into the store's ``adhesion``."""
    w = pending.result(executor)
    adhesion = {**(store.resolved.get("adhesion") or {}), **w.record()}
    store.set_resolved({**store.resolved, "adhesion": adhesion})


def probe(
    reference: Atoms,
    factory: Any,
    grid: GridSpec,
    relax: RelaxSettings,
    executor: Executor | None = None,
    units: ProbeUnits | None = None,
    hessian: Any = None,
    rigid: RigidRows | None = None,
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
    :class:`~flatcontact.ispes.work_of_separation.WorkOfSeparation` computed here after the
    probe, from the same single points of every stacking (one worker), or with workers a
    :class:`PendingWork` still running beside the grid (stored after it).

    ``units`` (``probe.json``, :mod:`flatcontact.ispes.probe_units`) records every finished
    unit (a row of single points, a chain, a segment, the work of separation) as the driver
    gets it, and gives back those a resumed probe finished before: the same values, so the
    same thicknesses. ``hessian`` (the driver's reference Hessian) goes with the tasks.
    ``rigid``: the single points already submitted to the workers (:class:`RigidRows`), else
    they run here (one or two or three workers) or on the workers (many).
    """
    workers = 1 if executor is None else executor.workers
    if workers >= MANY_WORKERS:
        return probe_many(reference, factory, grid, relax, executor, units, hessian, rigid)
    calc = worker_calculator(factory, reference)
    relax_one = functools.partial(relax_column_point, reference, calc, relax)
    with phase("probe/rigid points"):
        if rigid is not None:  # on the workers, since they were asked to start
            rigid = rigid.stackings()
        else:
            rigid = _rigid_serial(reference, calc, grid, units)
    lowest = extreme_stackings(rigid.energy_ev, grid)[0]
    if workers <= 1:
        columns = functools.partial(_probe_columns_here, relax_one, reference, units)
        extra, notes = probe_thicknesses(relax_one, reference, rigid, grid, columns)
        with phase("probe/ideal W"):
            work = _cached(
                units,
                "work",
                (*lowest,),
                lambda: ideal_work_of_separation(reference, factory, relax, lowest, calc=calc),
            )
        return extra, notes, work
    context = ScanContext(reference, factory, relax, hessian)
    work: list = []
    columns = functools.partial(_probe_columns_on_workers, executor, units, context, lowest, work)
    extra, notes = probe_thicknesses(relax_one, reference, rigid, grid, columns)
    return extra, notes, PendingWork(work[0], units, lowest) if work else None


def _probe_columns_here(relax_one, reference: Atoms, units: ProbeUnits | None, specs) -> list:
    """The probed columns ``specs`` relaxed in the driver: each column's two chains
    (:func:`flatcontact.ispes.probe.probe_column`'s), one after the other, each a unit of
    ``probe.json``."""
    out = []
    for shift, p_hi, stop in specs:
        down = _cached(
            units,
            "compress",
            (*shift, p_hi),
            lambda shift=shift, p_hi=p_hi: compress_chain(relax_one, reference, shift, p_hi),
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


def _probe_columns_on_workers(
    executor: Executor, units, context: ScanContext, lowest, work: list, specs
) -> list:
    """The probed columns ``specs`` as chains on two or three workers: the stretchings,
    the compressions (on quartz the compressions are the long chains, 19-21 points of ~30
    force calls; past its first point a stretching costs ~1 call per point:
    benchmarks/schedule_model.py), then the work of separation (its handle appended to
    ``work``: the driver does not wait for it, it runs on the first free worker, beside the
    last chains or the grid's first points)."""
    reference = context.reference
    up = _submit_stretchings(executor, units, context, specs)
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
    work.append(
        unit_submit(executor, units, "work", (*lowest,), work_of_separation_task, context, lowest)
    )
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


def probe_many(
    reference: Atoms,
    factory: Any,
    grid: GridSpec,
    relax: RelaxSettings,
    executor: Executor,
    units: ProbeUnits | None = None,
    hessian: Any = None,
    rigid: RigidRows | None = None,
) -> tuple[dict, list[str], PendingWork]:
    """:func:`probe` with many workers: nothing relaxes in the driver.

    1. The rigid single points, a block of rows of the lateral grid per worker
       (:func:`~flatcontact.ispes.scan_tasks.rigid_rows_task`; ``rigid``: submitted
       before, :class:`RigidRows`).
    2. At once: each probed column's stretching (one chain), the compressions as segments
       of :data:`~flatcontact.ispes.probe.COMPRESS_SEGMENT_STEPS` steps
       (:func:`~flatcontact.ispes.scan_tasks.probe_segment_task`), as many as there are free
       workers (:func:`~flatcontact.ispes.probe.next_segments`), one more whenever a probe
       chain finishes, until each column's segments reach HI; then the ideal work of
       separation at the lowest rigid stacking (one chain, left running beside the grid: a
       :class:`PendingWork`).
    3. The columns joined (:meth:`~flatcontact.ispes.probe.CompressionSegments.join`,
       :func:`~flatcontact.ispes.probe.join_column`) and the thicknesses chosen as in
       sequence. Segments started beyond a column's end are left to finish unused.

    ``benchmarks/schedule_model.py`` replays this order. Units finished before (``units``,
    ``probe.json``) are not submitted: a row block holds only the rows still missing, a
    finished segment is added to its column at once without taking a worker.
    """
    context = ScanContext(reference, factory, relax, hessian)
    with phase("probe/rigid points"):
        early = rigid or RigidRows(executor, units, context, grid)
        rigid = early.stackings()
    work: list = []
    columns = functools.partial(
        _SegmentedColumns.probe, executor, units, context, rigid, grid, work
    )
    extra, notes = probe_thicknesses(None, reference, rigid, grid, columns)
    return extra, notes, work[0]


class RigidRows:
    """The rigid single points of the lateral grid on the workers, submitted as soon as the
    workers are asked to start (:func:`flatcontact.ispes.scan._drive`, before the driver
    computes the reference Hessian, which they do not need), collected by the probe.

    The rows still missing from ``probe.json`` (``units``) go out in ``blocks`` tasks of
    whole rows (:func:`~flatcontact.ispes.scan_tasks.rigid_rows_task`); each row is a
    ``probe.json`` unit once collected. A single point is a function of its stacking alone
    (:func:`flatcontact.ispes.probe.rigid_rows` starts the calculator afresh), so the values
    are those of the driver's own evaluation (:func:`_rigid_serial`), wherever they ran.
    """

    def __init__(
        self,
        executor: Executor,
        units: ProbeUnits | None,
        context: ScanContext,
        grid: GridSpec,
        blocks: int | None = None,
    ):
        self.executor, self.units, self.grid = executor, units, grid
        sa, sb = grid.shifts()
        self.inputs = [_rigid_inputs(sa, sb, row) for row in range(grid.n_a)]
        self.rows: dict[int, tuple] = {}
        if units is not None:
            for row, inputs in enumerate(self.inputs):
                known = units.get("rigid", *inputs)
                if known is not None:
                    self.rows[row] = known
        missing = np.array([r for r in range(grid.n_a) if r not in self.rows], dtype=int)
        blocks = executor.workers if blocks is None else blocks
        self.blocks = [
            b for b in np.array_split(missing, min(blocks, max(missing.size, 1))) if b.size
        ]
        self.handles = [
            executor.submit(rigid_rows_task, context, grid, b.tolist()) for b in self.blocks
        ]

    def stackings(self) -> RigidStackings:
        """Every row's energies and loads (waiting for the blocks still running)."""
        for block, handle in zip(self.blocks, self.handles, strict=True):
            energy, load = self.executor.result(handle)
            for k, row in enumerate(block.tolist()):
                part = (energy[k : k + 1], load[k : k + 1])
                if self.units is not None:
                    part = self.units.put("rigid", self.inputs[row], part)
                self.rows[row] = part
        self.blocks, self.handles = [], []
        return _joined([self.rows[row] for row in range(self.grid.n_a)])


class _SegmentedColumns:
    """Step 2 of :func:`probe_many` for the probed columns ``specs``: stretchings and
    compression segments in flight, the work of separation after the first segments."""

    def __init__(self, executor: Executor, units, context: ScanContext, specs):
        self.executor, self.units, self.context, self.specs = executor, units, context, specs
        self.plans = [CompressionSegments(p_hi) for _, p_hi, _ in specs]
        self.in_flight: dict[Any, tuple[int, int]] = {}

    @classmethod
    def probe(cls, executor, units, context, rigid, grid, work: list, specs) -> list:
        """The joined columns of ``specs``; the work of separation's handle into ``work``."""
        self = cls(executor, units, context, specs)
        up = _submit_stretchings(executor, units, context, specs)
        self.start(max(len(specs), executor.workers - len(specs)))
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
        stretched = self.wait(up)
        return [
            join_column(
                context.reference,
                shift,
                plan.join(),
                stretched[c]
                if c in stretched
                else unit_result(executor, units, "stretch", (*shift, None, stop), u),
                stop_at_gpa=stop,
            )
            for c, ((shift, _, stop), plan, u) in enumerate(zip(specs, self.plans, up, strict=True))
        ]

    def segment_inputs(self, c: int, j: int) -> tuple:
        shift, p_hi, _ = self.specs[c]
        return (*shift, p_hi, j, self.plans[c].n_steps)

    def start(self, slots: int) -> None:
        """Submit up to ``slots`` next segments; a segment finished before takes no slot."""
        while slots > 0:
            picked = next_segments(self.plans, 1)
            if not picked:
                break
            c, j = picked[0]
            shift, p_hi, _ = self.specs[c]
            handle = unit_submit(
                self.executor,
                self.units,
                "segment",
                self.segment_inputs(c, j),
                probe_segment_task,
                self.context,
                shift,
                p_hi,
                j,
            )
            if isinstance(handle, Known):  # finished before: no worker taken
                self.plans[c].add(j, handle.value)
                continue
            self.in_flight[handle] = (c, j)
            slots -= 1

    def wait(self, up: list) -> dict[int, Any]:
        """Until every column's segments reach HI: each finished chain starts one more
        segment. Returns the stretchings received meanwhile (by column)."""
        executor, units = self.executor, self.units
        waiting = {u: c for c, u in enumerate(up) if not isinstance(u, Known)}
        stretched: dict[int, Any] = {}
        while any(plan.join() is None for plan in self.plans):
            done, _ = executor.wait_first(set(self.in_flight) | set(waiting))
            for handle in done:
                if handle in waiting:
                    c = waiting.pop(handle)
                    shift, _, stop = self.specs[c]
                    stretched[c] = unit_result(
                        executor, units, "stretch", (*shift, None, stop), handle
                    )
                else:
                    c, j = self.in_flight.pop(handle)
                    self.plans[c].add(
                        j,
                        unit_result(executor, units, "segment", self.segment_inputs(c, j), handle),
                    )
                self.start(1)
        return stretched


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
