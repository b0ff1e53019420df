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
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from ase import Atoms

from flatcontact.errors import InputError
from flatcontact.ispes import contract, executors
from flatcontact.ispes.contract import cell_area
from flatcontact.ispes.geometry import in_plane_vectors, thickness, validate_interface
from flatcontact.ispes.grid import GridSpec, check_thicknesses
from flatcontact.ispes.order import PREFERENCES, search_tree
from flatcontact.ispes.probe import extreme_stackings, probe_column, rigid_stackings
from flatcontact.ispes.reduction import (
    SymmetrySettings,
    choose_verify,
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
from flatcontact.layout import ISPES_NC, POINTS_DB


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


def _probe(
    reference: Atoms,
    factory: Any,
    grid: GridSpec,
    relax: RelaxSettings,
    executor: Any = None,
) -> tuple[dict, list[str]]:
    """Resolve the thicknesses of a pressure-range grid
    (:func:`flatcontact.ispes.thicknesses.probe_thicknesses`).

    The single points of every stacking run here; the probed columns, independent chains,
    run on the executor's workers when it has more than one (they are the serial part of a
    scan: 4 % of the paper preset's serial time, which by Amdahl's law alone capped two
    workers at 96 %).
    """
    calc = worker_calculator(factory, reference)
    relax_one = functools.partial(relax_column_point, reference, calc, relax)
    rigid = rigid_stackings(reference, calc, grid)
    probe_columns = None
    if executor is not None and getattr(executor, "workers", 1) > 1:
        context = ScanContext(reference, factory, relax)

        def probe_columns(specs):
            handles = [executor.submit(probe_column_task, context, *spec) for spec in specs]
            return [executor.result(h) for h in handles]

    return probe_thicknesses(relax_one, reference, rigid, grid, probe_columns)


def adhesion_record(
    reference: Atoms,
    factory: Any,
    grid: GridSpec,
    relax: RelaxSettings,
    pull_off: dict | None = None,
) -> dict:
    """The ``adhesion`` entry of a scan: the ideal work of separation and the probe's pull-off.

    W (``work_of_separation_j_per_m2``) is that of the lowest rigid energy among the grid's
    lateral shifts (:func:`flatcontact.ispes.work_of_separation.ideal_work_of_separation`),
    whatever the thicknesses; ``pull_off`` is the probe's record
    (:class:`flatcontact.ispes.separation.Adhesion`, absent for given thicknesses). A
    record of an older scan whose ``work_of_separation_*`` keys were the pull-off's is
    renamed to ``pull_off_*``.
    """
    calc = worker_calculator(factory, reference)
    shift = extreme_stackings(rigid_stackings(reference, calc, grid).energy_ev, grid)[0]
    pulled = {}
    for key, value in (pull_off or {}).items():
        if key.startswith("work_of_separation"):
            key = key.replace("work_of_separation", "pull_off_work", 1)
        pulled[key] = value
    w = ideal_work_of_separation(reference, factory, relax, shift, calc=calc)
    return {**pulled, **w.record()}


def relax_column_point(reference, calc, relax, a, b, z, start, start_z) -> tuple:
    """One probe point: ``(energy_ev, normal_stress_gpa, force_calls, positions)``."""
    task = PointTask((0, 0, 0), a, b, z, start, (a, b) if start is not None else None, start_z)
    r = relax_point(reference, calc, task, relax)
    return r.energy_ev, r.normal_stress_gpa, r.force_calls, r.positions


def probe_column_task(context: ScanContext, shift, p_hi_gpa, stop_at_gpa):
    """Worker entry point: one probed column (:func:`flatcontact.ispes.probe.probe_column`)
    with this worker's cached calculator."""
    calc = worker_calculator(context.factory, context.reference)
    relax_one = functools.partial(relax_column_point, context.reference, calc, context.settings)
    return probe_column(relax_one, context.reference, shift, p_hi_gpa, stop_at_gpa=stop_at_gpa)


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
        Receives ``points.db`` and ``ispes.nc``.
    relax
        Relaxation settings (tolerance, optimiser, step cap).
    order
        Warm-start tree preference: ``"columns"`` (default), ``"planes"`` or ``"cold"``
        (:mod:`flatcontact.ispes.order`).
    executor
        An executor object (:mod:`flatcontact.ispes.executors`); if None, one is built
        from ``executor_options`` (``make_executor`` keywords) after validation.
    progress
        Called as ``progress(done, total)`` (points in the store, points of the grid) once
        the grid is known and after every stored point, like an observer attached to an ASE
        dynamics; the CLI draws its progress bar from it.
    max_new_points
        Stop after computing this many new points (benchmarks); the store stays resumable.
    symmetry
        Irreducible registries (:mod:`flatcontact.ispes.reduction`): relax one point per orbit
        of the interface's shift-space group, verify some mapped points, fill the rest.
        ``None``: every point is relaxed (``SymmetrySettings(enabled=False)``).

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
            store_path, scan_settings(reference, factory, grid, relax, symmetry), reference
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
            try:
                if store.resolved is None:
                    a1, a2 = in_plane_vectors(reference)
                    resolved = {
                        "a1": a1.tolist(),
                        "a2": a2.tolist(),
                        "potential_label": factory.label,
                    }
                    if grid.thickness_angstrom is not None:
                        resolved["thickness_angstrom"] = list(grid.thickness_angstrom)
                    else:
                        extra, notes = _probe(reference, factory, grid, relax, executor)
                        resolved.update(extra)
                    resolved["adhesion"] = adhesion_record(
                        reference, factory, grid, relax, resolved.get("adhesion")
                    )
                    store.set_resolved(resolved)
                resolved = store.resolved
                if "work_of_separation_shift_a" not in (resolved.get("adhesion") or {}):
                    # a store resolved before the ideal W existed: its W was the pull-off's
                    resolved = {
                        **resolved,
                        "adhesion": adhesion_record(
                            reference, factory, grid, relax, resolved.get("adhesion")
                        ),
                    }
                notes = list(resolved.get("notes", notes))
                z = np.asarray(resolved["thickness_angstrom"], dtype=float)
                if grid.thickness_angstrom is None:
                    check_thicknesses(reference, grid, z, spread_compression=relax.mode != "rigid")
                shape = (grid.n_a, grid.n_b, z.size)
                sa, sb = grid.shifts()
                root = (0, 0, int(np.argmin(np.abs(z - thickness(reference)))))
                full_tree = search_tree(shape, root, order)
                reduction = None
                if symmetry.enabled:
                    group = shift_space_group(
                        reference,
                        symmetry.tolerance_angstrom,
                        spread_compression=relax.mode != "rigid",
                    ).for_grid(grid.n_a, grid.n_b)
                    reduction = plan_reduction(group, shape, list(full_tree))
                context = ScanContext(reference, factory, relax)
                recent = PositionsCache()

                def converged(idx):
                    return idx is not None and idx in store and store.record(idx)["converged"]

                def positions(idx):
                    cached = recent.get(idx)
                    return cached if cached is not None else store.positions(idx)

                def run_points(parent):
                    """Relax the points of the tree ``parent`` missing from the store."""

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
                    pending = {idx for idx in parent if idx not in store}
                    total = len(parent)
                    stored = total - len(pending)
                    if progress is not None:
                        progress(stored, total)
                    in_flight: dict[Any, tuple] = {}
                    cap = 2 * max(1, getattr(executor, "workers", 1))
                    queue = ReadyQueue(parent, rank, store, pending)
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
                            handle = executor.submit(run_task, context, make_task(idx))
                            in_flight[handle] = idx
                            pending.discard(idx)
                        if not in_flight:
                            break
                        done, _ = executor.wait_first(in_flight)
                        for handle in done:
                            idx = in_flight.pop(handle)
                            result = executor.result(handle)
                            store.write(result)
                            recent.put(idx, result.positions)
                            queue.stored(idx)
                            computed_calls.append(result.force_calls)
                            stored += 1
                            if progress is not None:
                                progress(stored, total)

                symmetry_record = None
                try:
                    if reduction is None or reduction.group.order == 1:
                        run_points(full_tree)
                    else:
                        run_points(search_tree(shape, root, order, allowed=reduction.computed))
                        reduction = choose_verify(
                            reduction, store.done(), shape, symmetry.verify_points
                        )
                        run_points(search_tree(shape, root, order, allowed=reduction.computed))
                        area = cell_area(*in_plane_vectors(reference))
                        check = verification(reduction, store.done(), area)
                        symmetry_record = {
                            **reduction.to_json(),
                            "verification": check,
                            "computed_in_full": False,
                        }
                        if all(idx in store for idx in reduction.computed) and symmetry_broken(
                            check, symmetry
                        ):
                            symmetry_record["computed_in_full"] = True
                            notes.append(
                                f"symmetry: a verified point differs from its representative by "
                                f"{check['max_energy_difference_mev_per_a2']:.3g} meV/Å², "
                                f"{check['max_stress_difference_gpa']:.3g} GPa (tolerance "
                                f"{symmetry.energy_tolerance_mev_per_a2:g} meV/Å², "
                                f"{symmetry.stress_tolerance_gpa:g} GPa): the relaxation breaks "
                                f"the interface's shift-space symmetry (order "
                                f"{reduction.group.order}); every grid point is computed"
                            )
                            run_points(full_tree)
                except KeyboardInterrupt:
                    interrupted = True
            finally:
                if own_executor:
                    executor.close(cancel=True)
            mapping = None
            if symmetry_record is not None and not symmetry_record["computed_in_full"]:
                mapping = reduction.representative
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
