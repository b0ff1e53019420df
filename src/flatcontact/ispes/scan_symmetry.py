"""The scan's symmetry plan: one round of the grid, reduced by the shift-space group or in full.

With the reduction on (:mod:`flatcontact.ispes.reduction`) a round relaxes one representative
per orbit, then a few verified mapped points, checks them against their representatives and,
if the relaxation breaks the symmetry, computes every point of the grid after all. The plan's
``mapping`` and ``record`` exist from the start and follow each step, so a round stopped
partway (Ctrl-C) still assembles the mapped points of its stored representatives.

A fallback is final: the reason and the verification that refuted the symmetry go into the
store's ``resolved`` metadata (:data:`FALLBACK_KEY`), and every later round of the grid (a
thickness added to bracket the loads) and every resumed scan computes every point too, so
that no round maps points that an earlier one found to break the group, and a resumed scan
follows the rounds of an uninterrupted one. A stored row at a point the last plan maps is
not used (:meth:`flatcontact.ispes.store.PointStore.rows_outside_plan`); the plan's record
names such rows (``rows_not_used``) and :meth:`SymmetryPlan.rows_left_out` says why.
"""

from __future__ import annotations

import collections

import numpy as np
from ase import Atoms

from flatcontact.ispes.contract import cell_area
from flatcontact.ispes.geometry import in_plane_vectors
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.order import tree_in_store_order
from flatcontact.ispes.phases import phase
from flatcontact.ispes.reduction import (
    SymmetrySettings,
    choose_verify,
    fallback_reason,
    plan_reduction,
    symmetry_broken,
    verification,
)
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan_scheduler import Scheduler
from flatcontact.ispes.shift_symmetry import shift_space_group
from flatcontact.ispes.store import PointStore

#: The key of the store's ``resolved`` metadata that records a fallback to the full grid:
#: ``{"reason": ..., "verification": ...}`` (module docstring).
FALLBACK_KEY = "symmetry_fallback"
#: meV per eV.
_MEV = 1e3


class ScanRound:
    """One round of the grid: its thicknesses ``z`` (the store's order), the warm-start root
    and the trees over it.

    The root is shift (0, 0) at the largest thickness, the least loaded plane: that plane is
    spread laterally first and every column is then walked one way, towards compression, so
    a column has one step without an extrapolation in z where a root inside the range gave
    two, and the lateral relaxations run where they are cheapest. On the 6 × 6 × 8 quartz
    SNAP grid of ``benchmarks/bench_scanspeed.py`` 19.23 force calls per point against 21.80
    with the root at the thickness nearest the reference's (docs/performance.md, "Fewer
    force calls per point").
    """

    def __init__(self, z: np.ndarray, n_a: int, n_b: int, order: str):
        self.z = z
        self.shape = (n_a, n_b, z.size)
        self.root = (0, 0, int(np.argmax(z)))
        self.order = order
        self.full_tree = self.tree()

    def tree(self, allowed: set | None = None) -> dict:
        """The warm-start tree over ``allowed`` (every point: None), in the store's indices
        (:func:`flatcontact.ispes.order.tree_in_store_order`)."""
        return tree_in_store_order(self.z, self.shape, self.root, self.order, allowed)


class SymmetryPlan:
    """Which points a round relaxes and how the others are filled.

    ``reduction``: the :class:`~flatcontact.ispes.reduction.Reduction` (None: symmetry off or
    a trivial group, every point relaxed). ``mapping``: grid point -> the point whose values
    it takes, for the store's assembly (None: every point its own). ``record``: the
    ``symmetry`` entry of ``ispes.nc`` and ``scan.json`` (None without a reduction).
    """

    def __init__(
        self,
        reference: Atoms,
        grid: GridSpec,
        relax: RelaxSettings,
        symmetry: SymmetrySettings,
        round_: ScanRound,
    ):
        self.reference, self.settings, self.round = reference, symmetry, round_
        self.reduction = None
        if symmetry.enabled:
            # modulo the pure translations, lifted onto the grid: a twist cell's N²
            # translations are never enumerated against each other
            group = shift_space_group(
                reference,
                symmetry.tolerance_angstrom,
                spread_compression=relax.mode != "rigid",
                modulo_translations=True,
            ).for_grid(grid.n_a, grid.n_b)
            self.reduction = plan_reduction(group, round_.shape, list(round_.full_tree))
        self.mapping, self.record = None, None
        if self.reduced:
            # the record and the mapping exist from the start, so a scan stopped partway
            # writes the mapped points of its stored representatives
            self.mapping = self.reduction.representative
            self.record = {
                **self.reduction.to_json(),
                "verification": None,
                "computed_in_full": False,
            }

    @property
    def reduced(self) -> bool:
        """Whether the round relaxes only representatives (a group of order > 1)."""
        return self.reduction is not None and self.reduction.group.order > 1

    def run(self, scheduler: Scheduler, notes: list[str]) -> None:
        """Relax the round's points with ``scheduler``: every point, or the representatives,
        the verified points and, if the check fails, every point (the reason appended to
        ``notes``)."""
        round_, store = self.round, scheduler.store
        if not self.reduced:
            scheduler.run(round_.full_tree, round_.z)
            return
        fallback = (store.resolved or {}).get(FALLBACK_KEY)
        if isinstance(fallback, dict) and isinstance(fallback.get("reason"), str):
            # an earlier round (or the interrupted run) found the symmetry broken
            self._compute_in_full(
                scheduler, notes, fallback["reason"], fallback.get("verification")
            )
            return
        # progress over the grid: a representative fills its orbit, a verified point counts
        # one more
        fills = collections.Counter(self.reduction.representative.values())
        grid_points = int(np.prod(round_.shape))
        scheduler.run(
            round_.tree(self.reduction.computed),
            round_.z,
            weight=fills,
            total=grid_points + self.settings.verify_points,
        )
        if all(rep in store for rep in self.reduction.computed):
            # chosen from the complete representatives only: a resumed scan verifies the
            # same points as an uninterrupted one
            self.reduction = choose_verify(
                self.reduction, store.done(), round_.shape, self.settings.verify_points
            )
            self.record.update(self.reduction.to_json())
            scheduler.run(
                round_.tree(self.reduction.computed),
                round_.z,
                weight=fills,
                total=grid_points + len(self.reduction.verify),
            )
        if all(idx in store for idx in self.reduction.computed):
            with phase("grid/verification"):
                self._verify(scheduler, notes)

    def _verify(self, scheduler: Scheduler, notes: list[str]) -> None:
        """Compare the verified points with their representatives; on a broken symmetry
        compute the whole grid."""
        # the plan's points only: a scan resumed partway through its fallback has more
        # points stored, which must not move the tolerances (a function of the grid)
        computed = self.reduction.computed
        records = {idx: r for idx, r in scheduler.store.done().items() if idx in computed}
        area = cell_area(*in_plane_vectors(self.reference))
        check = verification(self.reduction, records, area, self.settings)
        self.record["verification"] = check
        if symmetry_broken(check, self.settings):
            reason = fallback_reason(check, self.settings, self.reduction.group.order)
            store = scheduler.store
            store.set_resolved(
                {**store.resolved, FALLBACK_KEY: {"reason": reason, "verification": check}}
            )
            self._compute_in_full(scheduler, notes, reason, check)

    def _compute_in_full(
        self, scheduler: Scheduler, notes: list[str], reason: str, check: dict | None
    ) -> None:
        """Relax every point of the round (the symmetry found broken, ``reason``)."""
        self.record["verification"] = check
        self.record["computed_in_full"] = True
        self.record["computed_in_full_reason"] = reason
        notes.append(reason)
        self.mapping = None
        scheduler.run(self.round.full_tree, self.round.z)

    def rows_left_out(self, store: PointStore) -> str | None:
        """Why the assembly leaves stored rows out (None: it uses every row).

        The rows at points this plan maps (:meth:`PointStore.rows_outside_plan`) are
        listed in the record's ``rows_not_used`` (``points``, ``reason``); the reason
        names the file, the row farthest from its representative and the energy between
        them (meV/Å²)."""
        rows = store.rows_outside_plan(self.mapping, self.record)
        if not rows:
            if self.record is not None:
                self.record.pop("rows_not_used", None)
            return None
        done = store.done()
        area = cell_area(*in_plane_vectors(self.reference))

        def apart(idx):  # |E(row) - E(representative)| per area, meV/Å² (-1: no representative)
            rep = self.mapping[idx]
            if rep not in done:
                return -1.0
            return abs(done[idx]["energy_ev"] - done[rep]["energy_ev"]) / area * _MEV

        worst = max(rows, key=apart)
        gap = apart(worst)
        said = f", {gap:.3g} meV/Å² from it" if gap >= 0 else ", not stored yet"
        reason = (
            f"{store.path}: {len(rows)} stored row(s) at points this symmetry-reduced scan maps "
            f"are not used (the farthest, {worst}, has the representative "
            f"{self.mapping[worst]}{said}): a mapped point takes its representative's values "
            "(ispes.nc declares the group); such rows come from another scan, an edit of the "
            "store, or an earlier round of this grid"
        )
        self.record["rows_not_used"] = {"points": [list(r) for r in rows], "reason": reason}
        return reason
