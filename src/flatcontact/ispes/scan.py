"""The scan driver: validate, open the store, resolve thicknesses, schedule, assemble.

:func:`run_scan` is the whole ISPES stage from Python; ``flatcontact scan`` is a thin
wrapper. The driver validates everything before any relaxation (grid size,
thicknesses that would make the slabs overlap, the store's settings, the executor),
then computes only the points missing from ``points.db``, each committed as soon as it
returns, and finally writes ``ispes.nc`` atomically. Interrupted (Ctrl-C, or a kill of
the driver), the store keeps every finished point and a rerun continues from there;
because each point's warm start comes from a fixed neighbour
(:mod:`flatcontact.ispes.order`) and each point starts its calculator afresh
(:func:`flatcontact.ispes.relax.start_afresh`), the resumed grid equals an uninterrupted
one bit for bit, as do the grids of any number of workers below
:data:`~flatcontact.ispes.scan_probe.MANY_WORKERS` (whose probe starts segments cold).

The rooms of the driver, in the order :func:`run_scan` goes through them:

- :mod:`~flatcontact.ispes.shared_hessian`: the reference interface's Hessian of the
  preconditioner, computed once here and handed to every process that relaxes;
- :mod:`~flatcontact.ispes.scan_probe`: resolve the thicknesses and the adhesion record
  (the probe of a pressure-range grid);
- :mod:`~flatcontact.ispes.scan_symmetry`: the plan of a round (every point, or the
  irreducible registries, their verification and the fallback);
- :mod:`~flatcontact.ispes.scan_scheduler`: relax the points of a warm-start tree;
- :mod:`~flatcontact.ispes.scan_extend`: the overlap check of a round's thicknesses, and
  the grid's extension until it brackets the loads;
- :mod:`~flatcontact.ispes.scan_tasks`: what runs on the workers;
- :mod:`~flatcontact.ispes.executors`: where it runs.
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.layout import ISPES_NC, POINTS_DB, PROBE_JSON
from flatcontact.ispes import contract, executors
from flatcontact.ispes.executors import Executor
from flatcontact.ispes.geometry import validate_interface
from flatcontact.ispes.grid import GridSpec, check_thicknesses
from flatcontact.ispes.order import PREFERENCES
from flatcontact.ispes.phases import phase, recording
from flatcontact.ispes.probe_units import ProbeUnits, probe_settings
from flatcontact.ispes.reduction import SymmetrySettings
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan_extend import check_overlaps, extend_grid
from flatcontact.ispes.scan_probe import early_rigid_rows, resolve, store_pending_work
from flatcontact.ispes.scan_scheduler import Scheduler, commit_interval_s
from flatcontact.ispes.scan_symmetry import ScanRound, SymmetryPlan
from flatcontact.ispes.shared_hessian import HessianSharing
from flatcontact.ispes.store import PointStore, discard_store, interface_hash
from flatcontact.potentials.guarded import failing_at


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
    #: relaxed points in ``ispes.nc`` (``points_done`` also counts the points filled by
    #: symmetry; a stored row at a mapped point is not counted, ``symmetry["rows_not_used"]``)
    points_stored: int = 0
    #: folds of the probed and of the grid's columns and the loads they refuse
    #: (:meth:`flatcontact.ispes.thicknesses.LoadFold.record`; ``scan.json`` ``load_folds``)
    load_folds: list[dict] = dataclasses.field(default_factory=list)
    #: the driver's wall seconds per phase (:mod:`flatcontact.ispes.phases`): ``open store``,
    #: ``reference Hessian`` (:mod:`~flatcontact.ispes.shared_hessian`),
    #: ``probe`` (``probe/rigid points``, ``probe/ideal W``), ``overlap check``, ``symmetry``,
    #: ``grid`` (``grid/verification``), ``assemble``, ``extend``, ``ideal W after grid``,
    #: ``write``
    phase_seconds: dict[str, float] = dataclasses.field(default_factory=dict)
    #: force calls of the reference interface's Hessian (``RelaxSettings.precondition``): the
    #: driver's one computation of this attempt (:mod:`flatcontact.ispes.shared_hessian`; 0
    #: when nothing relaxed, or the process had it for the same model); in no point's count
    hessian_force_calls: int = 0


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


@dataclasses.dataclass(frozen=True)
class _Job:
    """What :func:`run_scan` was asked to compute (its arguments, validated)."""

    reference: Atoms
    factory: Any
    grid: GridSpec
    relax: RelaxSettings
    order: str
    symmetry: SymmetrySettings
    bracket_loads_gpa: Sequence[float] | None


@dataclasses.dataclass
class _Scanned:
    """What the rounds of a scan left for the assembly."""

    plan: SymmetryPlan | None
    resolved: dict
    notes: list[str]
    interrupted: bool
    computed_calls: list[int]
    #: the force calls of the driver's reference Hessian (:class:`HessianSharing`): the
    #: scan's processes are handed its root and compute none of their own
    hessian_calls: int = 0

    @property
    def mapping(self) -> dict | None:
        return None if self.plan is None else self.plan.mapping

    @property
    def symmetry_record(self) -> dict | None:
        return None if self.plan is None else self.plan.record


def run_scan(
    reference: Atoms,
    factory: Any,
    grid: GridSpec,
    out_dir: str | Path,
    relax: RelaxSettings | None = None,
    order: str = "columns",
    executor: Executor | None = None,
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
        An :class:`~flatcontact.ispes.executors.Executor` (the serial executor, local
        processes, Dask); if None, one is built from ``executor_options``
        (:func:`~flatcontact.ispes.executors.make_executor` keywords) after validation.
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
    _check_inputs(reference, grid, relax, order)
    out_dir = Path(out_dir)
    store_path = out_dir / POINTS_DB
    fresh_dir, fresh_store = not out_dir.exists(), not store_path.exists()
    store = None
    try:
        with (
            recording() as clock,
            PointStore(
                store_path,
                scan_settings(reference, factory, grid, relax, symmetry),
                reference,
                commit_interval_s=commit_interval_s(),
            ) as store,
        ):
            clock.add("open store", time.perf_counter() - t0)  # with the input checks
            own_executor = executor is None
            with HessianSharing(out_dir, reference, factory, relax) as sharing:
                if own_executor:
                    executor = executors.make_executor(**(executor_options or {}))
                try:
                    job = _Job(reference, factory, grid, relax, order, symmetry, bracket_loads_gpa)
                    scanned = _drive(
                        store, executor, job, out_dir, progress, max_new_points, sharing
                    )
                finally:
                    if own_executor:
                        executor.close(cancel=True)
            scanned.hessian_calls = sharing.hessian_force_calls
            with phase("write"):
                result = _assemble(store, scanned, out_dir, t0)
            result.phase_seconds = dict(clock.seconds)
    except Exception:
        # a run that failed before storing a point (executor not reachable, probe error)
        # leaves no store behind that would refuse the corrected rerun
        if fresh_store and (store is None or len(store) == 0):
            discard_store(store_path, remove_parent=fresh_dir)
        raise

    if result.interrupted:
        raise ScanInterrupted(result)
    return result


def _drive(
    store: PointStore,
    executor: Executor,
    job: _Job,
    out_dir: Path,
    progress: Callable[[int, int], None] | None,
    max_new_points: int | None,
    sharing: HessianSharing,
) -> _Scanned:
    """Resolve, then the rounds of the grid, then the work of separation left running."""
    reference, factory, grid, relax = job.reference, job.factory, job.grid, job.relax
    context = sharing.plain_context()
    # the probe's finished units, beside the store (a resumed probe reuses them)
    units = ProbeUnits(out_dir / PROBE_JSON, probe_settings(store.settings))
    rigid = None
    if _points_missing(store, grid):
        executor.prestart(factory, reference)  # worker start overlaps the probe
        # the probe's single points need no Hessian: on the workers while it is computed
        rigid = early_rigid_rows(store, executor, units, context, grid)
        with phase("reference Hessian"):  # computed once, here; overlaps the workers' start
            context = sharing.context(executor)
    with phase("probe"), failing_at("probe"):
        resolved, notes, pending = resolve(
            store, reference, factory, grid, relax, executor, units, context.hessian, rigid
        )
    scheduler = Scheduler(store, executor, context, grid.shifts(), progress, max_new_points)
    scanned = _rounds(store, scheduler, job, resolved, notes, sharing)
    if pending is not None and not scanned.interrupted:
        # the ideal work of separation ran beside the grid (a resumed scan
        # whose store lacks it computed it in the driver, in resolve)
        with phase("ideal W after grid"):
            store_pending_work(store, pending, executor)
        scanned.resolved = store.resolved
    kept = list(store.resolved.get("notes", []))
    scanned.notes = kept + [n for n in scanned.notes if n not in kept]
    return scanned


def _check_inputs(reference: Atoms, grid: GridSpec, relax: RelaxSettings, order: str) -> None:
    """What :func:`run_scan` refuses before it opens the store: the tree preference, the
    interface contract, given thicknesses at which the slabs would overlap."""
    if order not in PREFERENCES:
        raise InputError(f"order: expected one of {', '.join(PREFERENCES)}, got {order!r}")
    check_interface(reference)
    if grid.thickness_angstrom is not None:
        check_thicknesses(
            reference, grid, grid.thickness_angstrom, spread_compression=relax.mode != "rigid"
        )


def _points_missing(store: PointStore, grid: GridSpec) -> bool:
    """Whether the store lacks grid points (so the workers will be needed)."""
    known = store.resolved
    return known is None or len(store) < grid.n_a * grid.n_b * len(known["thickness_angstrom"])


def _rounds(
    store: PointStore,
    scheduler: Scheduler,
    job: _Job,
    resolved: dict,
    notes: list[str],
    sharing: HessianSharing,
) -> _Scanned:
    """The rounds of the grid: check the round's new thicknesses, plan, relax (and verify),
    then extend the grid if a column ends short of the loads, until none is added or a
    Ctrl-C stops a round (``interrupted``). The points an extension adds relax with the
    driver's reference Hessian (computed then if the store held every point before)."""
    reference, grid, relax = job.reference, job.grid, job.relax
    checked: set[float] = set()  # thicknesses whose overlap check passed
    plan, interrupted = None, False
    while True:
        notes = list(resolved.get("notes", notes))
        z = np.asarray(resolved["thickness_angstrom"], dtype=float)
        if grid.thickness_angstrom is None:
            new_z = [float(v) for v in z if float(v) not in checked]
            with phase("overlap check"):
                check_overlaps(scheduler.executor, scheduler.context, grid, new_z)
            checked.update(new_z)
        round_ = ScanRound(z, grid.n_a, grid.n_b, job.order)
        with phase("symmetry"):  # the group's search and the reduction's plan
            plan = SymmetryPlan(reference, grid, relax, job.symmetry, round_)
        try:
            with phase("grid"):
                plan.run(scheduler, notes)
        except KeyboardInterrupt:
            interrupted = True
            break
        with phase("assemble"):
            ds = store.assemble(plan.mapping, plan.record)
        limit = scheduler.max_new_points
        with phase("extend"):
            extended = extend_grid(store, reference, grid, relax, limit, job.bracket_loads_gpa, ds)
        if not extended:
            break
        scheduler.context = sharing.context(scheduler.executor)
        resolved = store.resolved
    return _Scanned(plan, resolved, notes, interrupted, scheduler.computed_calls)


def _assemble(store: PointStore, scanned: _Scanned, out_dir: Path, t0: float) -> ScanResult:
    """``ispes.nc`` from the store (mapped points filled) and the scan's result."""
    left_out = None if scanned.plan is None else scanned.plan.rows_left_out(store)
    if left_out is not None and left_out not in scanned.notes:
        scanned.notes.append(left_out)
    ds = store.assemble(scanned.mapping, scanned.symmetry_record)
    path = contract.write_ispes(ds, out_dir / ISPES_NC)
    return ScanResult(
        dataset=ds,
        ispes_path=path,
        store_path=store.path,
        points_total=int(np.prod(scanned.plan.round.shape)),
        points_done=int(ds.attrs["points_done"]),
        points_computed=len(scanned.computed_calls),
        seconds=time.perf_counter() - t0,
        force_calls_computed=scanned.computed_calls,
        hessian_force_calls=scanned.hessian_calls,
        adhesion=scanned.resolved.get("adhesion"),
        notes=scanned.notes,
        interrupted=scanned.interrupted,
        symmetry=scanned.symmetry_record,
        points_stored=int(ds.attrs["computed_points"]),
        load_folds=list(store.resolved.get("load_folds", [])),
    )


class ScanInterrupted(KeyboardInterrupt):
    """Raised after Ctrl-C, once the store is consistent and a partial ``ispes.nc`` is written."""

    def __init__(self, result: ScanResult):
        super().__init__(
            f"interrupted: {result.points_done} of {result.points_total} points stored"
        )
        self.result = result
