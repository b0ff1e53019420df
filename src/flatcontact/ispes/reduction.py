"""Irreducible registries: which grid points a symmetric scan relaxes, which it maps, and the check.

With the shift-space group ``G`` of the interface (:mod:`flatcontact.ispes.shift_symmetry`,
restricted to the operations that map the lateral grid onto itself) the lateral grid falls
into orbits; every thickness has the same orbits. The scan relaxes one *representative* per
orbit and thickness (the orbit's first point in the warm-start tree's visiting order, so the
root is one) and fills the other points of the orbit with its energy and normal load
(``mapped`` points). Verify, never trust: ``verify_points`` mapped points, one in each of the
orbits whose representative has the highest energy (where a symmetric registry is unstable
and a relaxation breaks the symmetry; :func:`choose_verify`), are relaxed as well, warm-started
from a relaxed lateral neighbour, and compared with their representative; the largest differences (energy per area in
meV/Å², normal load in GPa) are reported. One above the tolerance means the relaxation
breaks the symmetry: the scan then computes every point of the grid and says so.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from flatcontact.errors import InputError
from flatcontact.ispes.shift_symmetry import ShiftGroup

Index = tuple[int, int, int]
#: eV/Å² → meV/Å².
_MEV = 1e3


@dataclasses.dataclass(frozen=True)
class SymmetrySettings:
    """How a scan uses the shift-space group.

    ``enabled``: relax one registry per orbit (false: every point, the group is not searched).
    ``verify_points``: mapped points also relaxed and compared. ``tolerance_angstrom``: the
    structural tolerance of the group (:func:`~flatcontact.ispes.shift_symmetry.shift_space_group`).
    ``energy_tolerance_mev_per_a2``, ``stress_tolerance_gpa``: largest accepted difference
    between a verified point and its representative.
    """

    enabled: bool = True
    verify_points: int = 2
    tolerance_angstrom: float = 1e-3
    energy_tolerance_mev_per_a2: float = 1e-2
    stress_tolerance_gpa: float = 0.5

    def __post_init__(self) -> None:
        if int(self.verify_points) != self.verify_points or self.verify_points < 0:
            raise InputError(
                f"symmetry verify_points: expected an integer >= 0, got {self.verify_points}"
            )
        for name in ("tolerance_angstrom", "energy_tolerance_mev_per_a2", "stress_tolerance_gpa"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise InputError(f"symmetry {name}: expected a positive number, got {value}")

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclasses.dataclass(frozen=True)
class Reduction:
    """The plan of a reduced scan: representative of each point, and the verified points."""

    group: ShiftGroup
    representative: dict[Index, Index]  #: every grid point -> the point it takes its values from
    verify: tuple[Index, ...]  #: mapped points relaxed as well

    @property
    def computed(self) -> set[Index]:
        """The points the reduced scan relaxes (representatives and verified points)."""
        return {rep for rep in self.representative.values()} | set(self.verify)

    def to_json(self) -> dict:
        return {**self.group.as_dict(), "verify_points": [list(v) for v in self.verify]}


def plan_reduction(
    group: ShiftGroup,
    shape: tuple[int, int, int],
    visiting_order: list[Index],
) -> Reduction:
    """Representatives of the grid ``shape`` (see the module docstring); no verified point yet.

    ``visiting_order``: the full grid's warm-start tree in visiting order
    (:func:`flatcontact.ispes.order.search_tree`); ``group`` maps the lateral grid onto itself.
    """
    n_a, n_b, n_z = shape
    images = group.grid_images(n_a, n_b)
    first: dict[tuple[int, int], int] = {}
    for k, (ia, ib, _) in enumerate(visiting_order):
        first.setdefault((ia, ib), k)
    lateral_rep: dict[tuple[int, int], tuple[int, int]] = {}
    for ia in range(n_a):
        for ib in range(n_b):
            orbit = {tuple(int(v) for v in images[g, ia, ib]) for g in range(group.order)}
            lateral_rep[(ia, ib)] = min(orbit, key=lambda p: first[p])
    representative = {
        (ia, ib, iz): (*lateral_rep[(ia, ib)], iz)
        for ia in range(n_a)
        for ib in range(n_b)
        for iz in range(n_z)
    }
    return Reduction(group, representative, ())


def choose_verify(
    reduction: Reduction, records: dict, shape: tuple[int, int, int], n: int
) -> Reduction:
    """The plan with ``n`` verified points chosen from the relaxed representatives.

    Symmetric relaxations break where the registry is unstable: at the high-energy
    stackings. So the orbits are ranked by their representative's energy (highest first,
    every thickness), and each verified point is a mapped member of the orbit next to a
    relaxed point of the same thickness (its warm start), one per orbit.
    """
    n_a, n_b, _ = shape
    reps = set(reduction.representative.values())
    members: dict[Index, list[Index]] = {}
    for idx, rep in reduction.representative.items():
        if idx != rep:
            members.setdefault(rep, []).append(idx)
    ranked = sorted(
        (rep for rep in members if rep in records),
        key=lambda r: (-records[r]["energy_ev"], r),
    )
    verify: list[Index] = []
    for rep in ranked:
        if len(verify) >= n:
            break
        for ia, ib, iz in sorted(members[rep]):
            near = [
                ((ia + 1) % n_a, ib, iz),
                ((ia - 1) % n_a, ib, iz),
                (ia, (ib + 1) % n_b, iz),
                (ia, (ib - 1) % n_b, iz),
            ]
            if any(q in reps for q in near):
                verify.append((ia, ib, iz))
                break
    return dataclasses.replace(reduction, verify=tuple(verify))


def verification(reduction: Reduction, records: dict, area_angstrom2: float) -> dict:
    """Largest differences between the verified points and their representatives.

    ``records``: the store's finished points (index -> record with ``energy_ev`` and
    ``normal_stress_gpa``). Returns ``{"points": n, "max_energy_difference_mev_per_a2",
    "max_stress_difference_gpa", "worst_point"}`` over the verified points present.
    """
    de, dp, worst, n = 0.0, 0.0, None, 0
    for idx in reduction.verify:
        rep = reduction.representative[idx]
        if idx not in records or rep not in records:
            continue
        n += 1
        e = abs(records[idx]["energy_ev"] - records[rep]["energy_ev"]) / area_angstrom2 * _MEV
        p = abs(records[idx]["normal_stress_gpa"] - records[rep]["normal_stress_gpa"])
        if worst is None or e > de or p > dp:
            worst = list(idx)
        de, dp = max(de, e), max(dp, p)
    return {
        "points": n,
        "max_energy_difference_mev_per_a2": de,
        "max_stress_difference_gpa": dp,
        "worst_point": worst,
    }


def symmetry_broken(check: dict, settings: SymmetrySettings) -> bool:
    """Whether a verified difference exceeds the settings' tolerances."""
    return (
        check["max_energy_difference_mev_per_a2"] > settings.energy_tolerance_mev_per_a2
        or check["max_stress_difference_gpa"] > settings.stress_tolerance_gpa
    )
