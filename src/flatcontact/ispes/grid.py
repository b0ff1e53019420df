"""The ISPES grid: lateral shifts over the primitive cell and a list of thicknesses.

Lateral: ``n_a × n_b`` fractional shifts of slab 2 along a1, a2 in [0, 1), endpoint
excluded (:func:`flatcontact.ispes.contract.fractional_shifts`). Normal: either an
explicit list of thicknesses z (Å, distance between surfaces 1 and 4, the paper's z)
or a target pressure range ``(lo_gpa, hi_gpa, n)`` from which z is chosen by probing
columns of the grid (:mod:`flatcontact.ispes.probe`,
:mod:`flatcontact.ispes.thicknesses`).

:class:`GridSpec` says which points to compute; :func:`check_thicknesses` refuses a
grid whose slabs would overlap at any of its points, before any relaxation.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.contract import fractional_shifts
from flatcontact.ispes.geometry import validate_interface
from flatcontact.structures.placement import place_slab2


@dataclasses.dataclass(frozen=True)
class GridSpec:
    """Which points to compute.

    Exactly one of ``thickness_angstrom`` (explicit z list, Å) and ``p_range_gpa``
    (``(lo, hi, n)``: n thicknesses whose loads at the lowest-energy stacking are
    evenly spaced from lo to hi GPa) is given. With ``bracket_all_stackings`` (default)
    the extreme stackings are probed too and thicknesses are added until every one of
    them brackets the loads (:func:`flatcontact.ispes.thicknesses.probe_thicknesses`);
    ``False`` probes the lowest-energy stacking only (the rule before; it enters the store
    fingerprint only when ``False``).
    """

    n_a: int
    n_b: int
    thickness_angstrom: tuple[float, ...] | None = None
    p_range_gpa: tuple[float, float, int] | None = None
    bracket_all_stackings: bool = True

    def __post_init__(self) -> None:
        for name in ("n_a", "n_b"):
            n = getattr(self, name)
            if int(n) != n or n < 1:
                raise InputError(f"grid {name}: expected at least 1 lateral point, got {n}")
        if (self.thickness_angstrom is None) == (self.p_range_gpa is None):
            raise InputError(
                "grid: give either a list of thicknesses or a pressure range (p-range-gpa LO HI N), not both or neither"
            )
        if self.thickness_angstrom is not None:
            z = np.asarray(self.thickness_angstrom, dtype=float)
            if z.size < 1:
                raise InputError(
                    "thickness: expected at least one thickness (Å), got an empty list"
                )
            if not np.all(np.isfinite(z)) or np.any(z <= 0):
                raise InputError(
                    f"thickness: expected positive finite values in Å, got {z.tolist()}"
                )
            if np.unique(z).size != z.size:
                raise InputError(f"thickness: values repeat in {z.tolist()}")
            object.__setattr__(self, "thickness_angstrom", tuple(float(v) for v in np.sort(z)))
        else:
            lo, hi, n = self.p_range_gpa
            if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
                raise InputError(f"p-range-gpa: expected LO < HI (GPa), got {lo} {hi}")
            if hi <= 0:
                raise InputError(f"p-range-gpa: HI must be a compressive load > 0 GPa, got {hi}")
            if int(n) != n or n < 2:
                raise InputError(f"p-range-gpa: N must be an integer >= 2, got {n}")
            object.__setattr__(self, "p_range_gpa", (float(lo), float(hi), int(n)))

    def shifts(self) -> tuple[np.ndarray, np.ndarray]:
        return fractional_shifts(self.n_a), fractional_shifts(self.n_b)

    def as_dict(self) -> dict:
        d = {"n_a": self.n_a, "n_b": self.n_b}
        if self.thickness_angstrom is not None:
            d["thickness_angstrom"] = list(self.thickness_angstrom)
        else:
            d["p_range_gpa"] = list(self.p_range_gpa)
            if not self.bracket_all_stackings:
                d["bracket_all_stackings"] = False
        return d


def check_thicknesses(
    reference: Atoms,
    grid: GridSpec,
    thicknesses: Sequence[float],
    *,
    spread_compression: bool = True,
) -> None:
    """Raise InputError if any (shift, z) of the grid makes the slabs overlap.

    ``place_slab2`` performs the overlap check (closest inter-slab distance, with the
    compression spread over the stack where allowed: ``spread_compression``, false for
    rigid slabs); this runs it for every lateral shift at every thickness, before any
    relaxation.
    """
    items = [(float(z), row) for z in thicknesses for row in range(grid.n_a)]
    check_rows(reference, grid, items, spread_compression=spread_compression)


def check_rows(
    reference: Atoms,
    grid: GridSpec,
    items: Sequence[tuple[float, int]],
    *,
    spread_compression: bool = True,
) -> None:
    """:func:`check_thicknesses` for the ``(z, i_a)`` pairs in ``items``: every shift
    ``shift_b`` of row ``i_a`` at thickness z (Å), in that order (the scan with many
    workers splits the check into blocks of pairs on its workers)."""
    sa, sb = grid.shifts()
    if items:  # once, place_slab2's first check, not at every point
        validate_interface(reference, "reference interface")
    for z, row in items:
        for b in sb:
            place_slab2(
                reference,
                float(sa[row]),
                float(b),
                float(z),
                spread_compression=spread_compression,
                validate_reference=False,
            )
