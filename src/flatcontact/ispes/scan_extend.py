"""The thicknesses of a scan round: their overlap check before, the grid's extension after.

Before a round relaxes points at new thicknesses, every lateral shift is checked for
overlapping slabs there (:func:`check_overlaps`). After a pressure-range grid is complete,
:func:`extend_grid` checks that every column brackets the loads the analysis will read and,
where one ends short, appends a thickness to the store's resolved list (at most
:data:`~flatcontact.ispes.grid_bracket.MAX_EXTENSIONS` rounds); the scan then computes the
new points in another round.
"""

from __future__ import annotations

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.contract import DIM_A, DIM_B, DIM_Z, VAR_ENERGY, VAR_STRESS
from flatcontact.ispes.executors import Executor
from flatcontact.ispes.grid import GridSpec, check_thicknesses
from flatcontact.ispes.grid_bracket import MAX_EXTENSIONS, bracket_targets_gpa, check_grid
from flatcontact.ispes.relax import RelaxSettings, ScanContext
from flatcontact.ispes.scan_tasks import overlap_check_task
from flatcontact.ispes.store import PointStore

#: blocks of (thickness, row) pairs per worker in the overlap check (one block each left a
#: worker idle for half the check: 0.079 against 0.040 s on the 12×12 quartz grid)
OVERLAP_BLOCKS_PER_WORKER = 4


def check_overlaps(
    executor: Executor, context: ScanContext, grid: GridSpec, z: list[float]
) -> None:
    """The overlap check of every lateral shift at the thicknesses ``z`` before they are
    scanned (:func:`flatcontact.ispes.grid.check_thicknesses`: one InputError naming the
    first overlap). With worker processes the ``(z, row)`` pairs are split into a block per
    worker (:func:`~flatcontact.ispes.scan_tasks.overlap_check_task`): the workers are idle
    between the probe and the grid, and at the paper preset's 3,168 points the check is
    seconds of the driver's time (0.14 s of the 12×12 quartz grid's 1,296); serially in the
    driver."""
    spread = context.settings.mode != "rigid"
    workers = executor.workers
    if executor.inline or workers < 2:
        check_thicknesses(context.reference, grid, z, spread_compression=spread)
        return
    items = [(v, row) for v in z for row in range(grid.n_a)]
    # blocks in grid order, several per worker: their costs differ with the thickness
    blocks = [
        b
        for b in np.array_split(np.arange(len(items)), OVERLAP_BLOCKS_PER_WORKER * workers)
        if b.size
    ]
    handles = [
        executor.submit(overlap_check_task, context, grid, [items[k] for k in b]) for b in blocks
    ]
    for handle in handles:  # in order: the first overlap in the grid's order is named
        executor.result(handle)


def extend_grid(
    store: PointStore,
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
    resolved list so the stored points keep their ``i_z`` (:func:`flatcontact.ispes.order.tree_in_store_order`);
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
