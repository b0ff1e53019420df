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
breaks the symmetry: the scan then computes every point of the grid and says why
(:func:`fallback_reason`: the whole grid, since the check samples the relaxation, not one orbit).

The energy tolerance is relative to the landscape it verifies (:func:`energy_tolerances`).
At thickness z (the verified point's) with R(z) the range (max − min) of the energy per area of
the points computed at z and F(z) their round-off floor,

    tol(z) = max(F(z), min(energy_tolerance_mev_per_a2, energy_tolerance_fraction · R(z)))

meV/Å²: the absolute setting (0.01 by default) caps it, so a landscape of several meV/Å²
(Cu(111), AB graphene, quartz) is checked as before; a fraction of R (5 % by default, half the
``broken_symmetry`` gate's 10 % of a map's range, since two sampled points do not bound the
largest deviation) takes over on a flat landscape, where 0.01 meV/Å² is the whole corrugation
(a twist cell: 1.2e-2 meV/Å² for (1, 2), 2e-4 for a relaxed (2, 3)) and would accept any
breaking; F(z) = :data:`ROUND_OFF_RELATIVE` · max |E| / area at z keeps the check above the
engine's round-off, where no relaxation can settle a difference (a rigid (3, 4) twist cell's
whole range, 8e-9 meV/Å², is at its round-off floor, 3.7e-9). The scan does not measure the
relaxation's force-tolerance floor (:mod:`flatcontact.ispes.relax_noise`, 12 relaxations, which
the approximant study measures after the scan): a relaxed landscape whose range is at that floor
(the relaxed (2, 3) twist at fmax 0.005 eV/Å) breaks the symmetry by a large fraction of its
range, is computed in full, and the ``broken_symmetry`` gate sees it.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.shift_symmetry import ShiftGroup

Index = tuple[int, int, int]
#: eV/Å² → meV/Å².
_MEV = 1e3
#: Default fraction of the energy range at a thickness that a verified point may differ from
#: its representative (module docstring): half the broken-symmetry gate's 10 % of a map's range
#: (``flatcontact.analysis.gates.SYMMETRY_GATE_TOLERANCE``).
ENERGY_RANGE_FRACTION = 0.05
#: Round-off of a computed total energy relative to its magnitude, for the verification's floor.
#: Measured 2.5e-12 to 5.5e-12 on the REBO + KC twist cells (the same structure one
#: shift-lattice vector apart: 1.4e-8 to 3.1e-8 meV/Å² on |E|/area of 5.6 eV/Å²,
#: docs/incommensurate.md); 1e-11 is above both.
ROUND_OFF_RELATIVE = 1e-11


@dataclasses.dataclass(frozen=True)
class SymmetrySettings:
    """How a scan uses the shift-space group.

    ``enabled``: relax one registry per orbit (false: every point, the group is not searched).
    ``verify_points``: mapped points also relaxed and compared. ``tolerance_angstrom``: the
    structural tolerance of the group (:func:`~flatcontact.ispes.shift_symmetry.shift_space_group`).
    ``energy_tolerance_mev_per_a2``: the largest accepted energy difference between a
    verified point and its representative (meV/Å²), capped further on a flat landscape by
    ``energy_tolerance_fraction`` of its range at that thickness, never below the round-off
    (:func:`energy_tolerances`, module docstring). ``stress_tolerance_gpa``: the largest
    accepted normal-load difference (GPa, absolute).
    """

    enabled: bool = True
    verify_points: int = 2
    tolerance_angstrom: float = 1e-3
    energy_tolerance_mev_per_a2: float = 1e-2
    stress_tolerance_gpa: float = 0.5
    energy_tolerance_fraction: float = ENERGY_RANGE_FRACTION

    def __post_init__(self) -> None:
        if int(self.verify_points) != self.verify_points or self.verify_points < 0:
            raise InputError(
                f"symmetry verify_points: expected an integer >= 0, got {self.verify_points}"
            )
        for name in (
            "tolerance_angstrom",
            "energy_tolerance_mev_per_a2",
            "stress_tolerance_gpa",
            "energy_tolerance_fraction",
        ):
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


def energy_tolerances(
    records: dict, area_angstrom2: float, settings: SymmetrySettings
) -> dict[int, dict]:
    """The verification's energy tolerance at each thickness of ``records`` (module docstring).

    ``records``: the computed points (index -> record with ``energy_ev``, the cell's total
    energy in eV), ``area_angstrom2``: the cell's area. Per thickness index ``iz`` with a finite
    energy: ``{"range_mev_per_a2": R, "round_off_mev_per_a2": F, "tolerance_mev_per_a2":
    max(F, min(energy_tolerance_mev_per_a2, energy_tolerance_fraction · R))}``, R the range
    (max − min) and F = :data:`ROUND_OFF_RELATIVE` · max |E| of those points, per area in meV/Å².
    """
    by_z: dict[int, list[float]] = {}
    for (_, _, iz), record in records.items():
        e = float(record["energy_ev"])
        if np.isfinite(e):
            by_z.setdefault(int(iz), []).append(e)
    out = {}
    for iz, values in sorted(by_z.items()):
        e = np.asarray(values) / area_angstrom2 * _MEV
        spread = float(np.ptp(e))
        round_off = ROUND_OFF_RELATIVE * float(np.max(np.abs(e)))
        tol = max(
            round_off,
            min(settings.energy_tolerance_mev_per_a2, settings.energy_tolerance_fraction * spread),
        )
        out[iz] = {
            "range_mev_per_a2": spread,
            "round_off_mev_per_a2": round_off,
            "tolerance_mev_per_a2": tol,
        }
    return out


def verification(
    reduction: Reduction, records: dict, area_angstrom2: float, settings: SymmetrySettings
) -> dict:
    """Differences between the verified points and their representatives, and the tolerances.

    ``records``: the store's finished points (index -> record with ``energy_ev`` and
    ``normal_stress_gpa``). Returns ``{"points": n, "max_energy_difference_mev_per_a2",
    "max_stress_difference_gpa", "worst_point", "checked"}`` over the verified points
    present; ``checked`` lists each as ``{"point", "representative",
    "energy_difference_mev_per_a2", "stress_difference_gpa", "energy_tolerance_mev_per_a2",
    "range_mev_per_a2"}`` (absolute differences; the tolerance and the range of the computed
    points at the point's thickness, :func:`energy_tolerances`).
    """
    tolerances = energy_tolerances(records, area_angstrom2, settings)
    de, dp, worst = 0.0, 0.0, None
    checked = []
    for idx in reduction.verify:
        rep = reduction.representative[idx]
        if idx not in records or rep not in records:
            continue
        e = abs(records[idx]["energy_ev"] - records[rep]["energy_ev"]) / area_angstrom2 * _MEV
        p = abs(records[idx]["normal_stress_gpa"] - records[rep]["normal_stress_gpa"])
        at_z = tolerances.get(int(idx[2]), {})
        checked.append(
            {
                "point": list(idx),
                "representative": list(rep),
                "energy_difference_mev_per_a2": e,
                "stress_difference_gpa": p,
                "energy_tolerance_mev_per_a2": at_z.get(
                    "tolerance_mev_per_a2", settings.energy_tolerance_mev_per_a2
                ),
                "range_mev_per_a2": at_z.get("range_mev_per_a2", float("nan")),
            }
        )
        if worst is None or e > de or p > dp:
            worst = list(idx)
        de, dp = max(de, e), max(dp, p)
    return {
        "points": len(checked),
        "max_energy_difference_mev_per_a2": de,
        "max_stress_difference_gpa": dp,
        "worst_point": worst,
        "checked": checked,
    }


def symmetry_broken(check: dict, settings: SymmetrySettings) -> bool:
    """Whether a verified difference exceeds the settings' tolerances."""
    return bool(failing_points(check, settings))


def failing_points(check: dict, settings: SymmetrySettings) -> list[dict]:
    """The entries of ``check["checked"]`` whose difference exceeds a tolerance (the energy's
    at the point's thickness, :func:`energy_tolerances`; the absolute setting for an entry
    without one)."""
    return [
        c
        for c in check.get("checked", ())
        if c["energy_difference_mev_per_a2"]
        > c.get("energy_tolerance_mev_per_a2", settings.energy_tolerance_mev_per_a2)
        or c["stress_difference_gpa"] > settings.stress_tolerance_gpa
    ]


def fallback_reason(check: dict, settings: SymmetrySettings, order: int) -> str:
    """Why a reduced scan computes every grid point (scan.json and the log), in one sentence.

    The whole grid, not only the failing orbits: a verified point is a sample of the
    relaxation's symmetry, not of its own orbit's. The structure obeys the group (checked on
    the atoms), so a difference comes from the relaxation (a registry unstable against a
    lateral slide, or warm starts that reach different local minima), and nothing shows that
    the unverified orbits are free of it: mapping them would keep the assumption that the
    failed check has just refuted.
    """
    bad = failing_points(check, settings)
    listed = ", ".join(
        f"{tuple(c['point'])} vs {tuple(c['representative'])}: "
        f"{c['energy_difference_mev_per_a2']:.3g} meV/Å² (tolerance "
        f"{c.get('energy_tolerance_mev_per_a2', settings.energy_tolerance_mev_per_a2):.3g}), "
        f"{c['stress_difference_gpa']:.3g} GPa"
        for c in bad
    )
    return (
        f"symmetry: {len(bad)} of {check['points']} verified points differ from their "
        f"representative beyond the tolerance (energy: the smaller of "
        f"{settings.energy_tolerance_mev_per_a2:g} meV/Å² and "
        f"{100 * settings.energy_tolerance_fraction:g} % of the range at its thickness, not "
        f"below round-off; {settings.stress_tolerance_gpa:g} GPa) [{listed}]: the relaxation breaks the "
        f"interface's shift-space symmetry (order {order}), so every grid point is computed "
        "(not only the failing orbits: the difference comes from the relaxation, not from one "
        "orbit, and the unverified orbits were never checked)"
    )
