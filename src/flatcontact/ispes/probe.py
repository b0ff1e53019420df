"""Probe relaxations: the rigid energy and load of every stacking, and relaxed columns along z.

A pressure-range grid chooses its thicknesses from a few columns of the grid relaxed
along z. :func:`rigid_stackings` evaluates every lateral shift once, unrelaxed, at the
reference thickness; :func:`probed_stackings` picks the extreme columns from it (the
lowest and highest energy, the most and least repulsive); :func:`probe_column` relaxes
one column from compression up to separation (a :class:`ColumnProbe`: energies in eV,
loads in GPa, > 0 pressed, thicknesses in Å ascending). The thicknesses are chosen from
the probes in :mod:`flatcontact.ispes.thicknesses`, the work of separation in
:mod:`flatcontact.ispes.separation`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
from ase import Atoms

from flatcontact.errors import InputError
from flatcontact.ispes.contract import cell_area
from flatcontact.ispes.geometry import in_plane_vectors, place_slab2, thickness
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.relax import normal_stress_gpa


@dataclasses.dataclass(frozen=True)
class ColumnProbe:
    """Relaxed energies and loads along z at one lateral stacking (ascending z)."""

    shift: tuple[float, float]
    thickness_angstrom: np.ndarray
    energy_ev: np.ndarray
    normal_stress_gpa: np.ndarray
    force_calls: int
    area_angstrom2: float

    def as_dict(self) -> dict:
        return {
            "shift": list(self.shift),
            "thickness_angstrom": self.thickness_angstrom.tolist(),
            "energy_ev": self.energy_ev.tolist(),
            "normal_stress_gpa": self.normal_stress_gpa.tolist(),
            "force_calls": self.force_calls,
            "area_angstrom2": self.area_angstrom2,
        }

    @classmethod
    def from_dict(cls, d: dict) -> ColumnProbe:
        return cls(
            shift=tuple(d["shift"]),
            thickness_angstrom=np.asarray(d["thickness_angstrom"], dtype=float),
            energy_ev=np.asarray(d["energy_ev"], dtype=float),
            normal_stress_gpa=np.asarray(d["normal_stress_gpa"], dtype=float),
            force_calls=int(d["force_calls"]),
            area_angstrom2=float(d["area_angstrom2"]),
        )


@dataclasses.dataclass(frozen=True)
class RigidStackings:
    """Rigid (unrelaxed) energy (eV) and normal load (GPa, > 0 pressed) of every lateral
    grid shift at the reference thickness, shape ``(n_a, n_b)``; NaN where the slabs overlap."""

    energy_ev: np.ndarray
    normal_stress_gpa: np.ndarray


def rigid_stackings(reference: Atoms, calc, grid: GridSpec) -> RigidStackings:
    """One single-point evaluation per lateral grid shift at the reference thickness.

    The load is the net z-force on slab 2 per area
    (:func:`flatcontact.ispes.relax.normal_stress_gpa`, the scan's own definition).
    """
    z_ref = thickness(reference)
    sa, sb = grid.shifts()
    energy = np.full(grid.shape_lateral, np.nan)
    load = np.full(grid.shape_lateral, np.nan)
    for i, a in enumerate(sa):
        for j, b in enumerate(sb):
            try:
                atoms = place_slab2(reference, float(a), float(b), z_ref)
            except InputError:
                continue
            atoms.calc = calc
            energy[i, j] = atoms.get_potential_energy()
            load[i, j] = normal_stress_gpa(atoms, atoms.get_forces(apply_constraint=False))
            atoms.calc = None
    return RigidStackings(energy, load)


def _first_extreme(values: np.ndarray, grid: GridSpec, highest: bool) -> tuple[float, float]:
    """Shift of the smallest (largest) finite value; ties (1e-12) go to the first in grid order."""
    v = np.asarray(values, dtype=float)
    if not np.any(np.isfinite(v)):
        raise InputError(
            "probe column: the slabs overlap at every lateral shift of the reference thickness"
        )
    flat = v.ravel()
    if highest:
        k = int(np.flatnonzero(flat >= np.nanmax(flat) - 1e-12)[0])
    else:
        k = int(np.flatnonzero(flat <= np.nanmin(flat) + 1e-12)[0])
    sa, sb = grid.shifts()
    i, j = np.unravel_index(k, v.shape)
    return float(sa[i]), float(sb[j])


def extreme_stackings(
    energies: np.ndarray, grid: GridSpec
) -> tuple[tuple[float, float], tuple[float, float]]:
    """The lateral shifts of the lowest and of the highest rigid energy (NaN = overlap, skipped).

    Ties go to the first shift in (shift_a, shift_b) order within 1e-12 eV. Returns
    ``(lowest, highest)``; they coincide for a landscape without corrugation.
    """
    return _first_extreme(energies, grid, False), _first_extreme(energies, grid, True)


def probed_stackings(
    rigid: RigidStackings, grid: GridSpec
) -> list[tuple[str, tuple[float, float]]]:
    """The columns a pressure-range grid probes, as ``(role, shift)``, duplicates removed.

    ``"lowest energy"`` first (the paper's probe, which also gives the adhesion), then
    ``"highest energy"``, ``"most repulsive"`` and ``"least repulsive"`` (the largest and
    the smallest rigid load at the reference thickness): the columns whose loads at a
    given z are the extremes of the grid, so thicknesses that bracket the requested
    loads at them bracket them at the other stackings too.
    """
    wanted = [
        ("lowest energy", _first_extreme(rigid.energy_ev, grid, False)),
        ("highest energy", _first_extreme(rigid.energy_ev, grid, True)),
        ("most repulsive", _first_extreme(rigid.normal_stress_gpa, grid, True)),
        ("least repulsive", _first_extreme(rigid.normal_stress_gpa, grid, False)),
    ]
    out: list[tuple[str, tuple[float, float]]] = []
    for role, shift in wanted:
        if all(shift != s for _, s in out):
            out.append((role, shift))
    return out


#: default z offsets (Å, relative to the reference thickness) for probing tension and separation
_UP_OFFSETS = np.concatenate(
    [np.arange(1, 11) * 0.1, 1.0 + np.arange(1, 13) * 0.25, 4.0 + np.arange(1, 17) * 1.0]
)


def probe_column(
    relax: Callable[[float, float, float, np.ndarray | None, float | None], tuple],
    reference: Atoms,
    shift: tuple[float, float],
    p_hi_gpa: float,
    dz_down_angstrom: float = 0.1,
    max_down_steps: int = 80,
    separated_gpa: float = 1e-4,
    stop_at_gpa: float | None = None,
) -> ColumnProbe:
    """Relax a column at ``shift`` from compression up to separation.

    Parameters
    ----------
    relax
        ``relax(shift_a, shift_b, z, start_positions, start_z) -> (energy_ev,
        normal_stress_gpa, force_calls, positions)``; consecutive probe points are
        warm-started from the previous one.
    reference
        The reference interface (its thickness is the starting z).
    shift
        Lateral stacking of the column.
    p_hi_gpa
        Compress in steps of ``dz_down_angstrom`` until the load reaches this value.
    separated_gpa
        Beyond the tensile maximum, stop once |p| is below this (GPa) — the slabs are
        separated — or at the last default offset (reference + 20 Å).
    """
    z_ref = thickness(reference)
    a, b = shift
    records: dict[float, tuple[float, float]] = {}
    calls = 0

    e, p, n, pos = relax(a, b, z_ref, None, None)
    records[z_ref] = (e, p)
    calls += n
    start, start_z = pos, z_ref
    # compress
    k = 0
    while p < p_hi_gpa:
        k += 1
        if k > max_down_steps:
            raise InputError(
                f"p-range-gpa: the load did not reach {p_hi_gpa} GPa within {max_down_steps * dz_down_angstrom:.3g} Å "
                f"of compression (reached {p:.3g} GPa)"
            )
        z = z_ref - k * dz_down_angstrom
        try:
            e, p, n, pos = relax(a, b, z, start, start_z)
        except InputError as exc:
            raise InputError(
                f"p-range-gpa: the slabs overlap before the load reaches {p_hi_gpa} GPa ({exc})"
            ) from None
        records[z] = (e, p)
        calls += n
        start, start_z = pos, z
    # stretch to separation
    start, start_z = None, None
    p_min = records[z_ref][1]
    for dz in _UP_OFFSETS:
        z = z_ref + float(dz)
        e, p, n, pos = relax(a, b, z, start, start_z)
        records[z] = (e, p)
        calls += n
        start, start_z = pos, z
        past_min = p > p_min
        p_min = min(p_min, p)
        if stop_at_gpa is not None and (p <= stop_at_gpa or past_min):
            break
        if past_min and p_min < 0 and abs(p) < separated_gpa:
            break
    zs = np.array(sorted(records))
    a1, a2 = in_plane_vectors(reference)
    return ColumnProbe(
        shift=(float(a), float(b)),
        thickness_angstrom=zs,
        energy_ev=np.array([records[z][0] for z in zs]),
        normal_stress_gpa=np.array([records[z][1] for z in zs]),
        force_calls=calls,
        area_angstrom2=cell_area(a1, a2),
    )
