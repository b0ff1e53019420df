"""The ISPES grid: lateral shifts over the primitive cell and a list of thicknesses.

Lateral: ``n_a × n_b`` fractional shifts of slab 2 along a1, a2 in [0, 1), endpoint
excluded (:func:`flatcontact.ispes.contract.fractional_shifts`). Normal: either an
explicit list of thicknesses z (Å, distance between surfaces 1 and 4, the paper's z)
or a target pressure range ``(lo_gpa, hi_gpa, n)`` from which z is chosen by
probing one column (:func:`probe_column`, :func:`thicknesses_for_pressures`).

Work of separation (per area, J/m²) from the probed column (paper's z-scan):
W = [U(z_sep) - U(z_eq)] / A = -∫_{z_eq}^{z_sep} p dz, with z_eq the thickness of
zero load and z_sep a thickness where the slabs no longer interact (p ≈ 0 beyond the
tensile maximum). Both forms are reported; they agree when the cross-interface
potential is continuous at its cutoff and the relaxations are converged.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np
from ase import Atoms

from flatcontact.errors import InputError
from flatcontact.ispes.contract import cell_area, fractional_shifts
from flatcontact.ispes.geometry import in_plane_vectors, place_slab2, thickness
from flatcontact.units import EV_PER_A2_TO_J_PER_M2


@dataclasses.dataclass(frozen=True)
class GridSpec:
    """Which points to compute.

    Exactly one of ``thickness_angstrom`` (explicit z list, Å) and ``p_range_gpa``
    (``(lo, hi, n)``: n thicknesses whose loads at the lowest-energy stacking are
    evenly spaced from lo to hi GPa) is given. With ``bracket_all_stackings`` (default)
    the extreme stackings are probed too and thicknesses are added until every one of
    them brackets the loads (:func:`probe_thicknesses`); ``False`` probes the
    lowest-energy stacking only (the rule before; it enters the store fingerprint only
    when ``False``).
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

    @property
    def shape_lateral(self) -> tuple[int, int]:
        return (self.n_a, self.n_b)

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
    sa, sb = grid.shifts()
    for z in thicknesses:
        for a in sa:
            for b in sb:
                place_slab2(
                    reference,
                    float(a),
                    float(b),
                    float(z),
                    spread_compression=spread_compression,
                )


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
    from flatcontact.ispes.relax import normal_stress_gpa

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


def lowest_energy_stacking(reference: Atoms, calc, grid: GridSpec) -> tuple[float, float]:
    """The lateral shift with the lowest rigid (unrelaxed) energy at the reference thickness.

    One single-point evaluation per lateral grid point; shifts that overlap are skipped.
    """
    return extreme_stackings(rigid_stackings(reference, calc, grid).energy_ev, grid)[0]


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


@dataclasses.dataclass(frozen=True)
class Adhesion:
    """Equilibrium, tensile strength and work of separation of a probed column."""

    equilibrium_thickness_angstrom: float
    max_tension_gpa: float
    max_tension_thickness_angstrom: float
    work_of_separation_j_per_m2: float
    work_of_separation_integral_j_per_m2: float
    separated: bool

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def adhesion(probe: ColumnProbe) -> Adhesion:
    """Equilibrium thickness (p = 0), maximum tension and work of separation of a column.

    z_eq is the zero of p(z) between the last compressed and first tensile sample
    (linear interpolation); U(z_eq) is interpolated linearly (U is stationary there).
    W = [U(z_last) - U(z_eq)]/A and W_int = -∫ p dz (trapezoid from z_eq to z_last), in
    J/m² (``EV_PER_A2_TO_J_PER_M2``; p in GPa -> eV/Å³ by division with
    ``EV_PER_A3_TO_GPA``).
    """
    from flatcontact.units import EV_PER_A3_TO_GPA

    z, e, p = probe.thickness_angstrom, probe.energy_ev, probe.normal_stress_gpa
    sign_change = np.nonzero((p[:-1] >= 0) & (p[1:] < 0))[0]
    if sign_change.size == 0:
        raise InputError(
            "probe column: the load never changes sign from compression to tension; no equilibrium thickness"
        )
    k = int(sign_change[0])
    z_eq = z[k] + (z[k + 1] - z[k]) * p[k] / (p[k] - p[k + 1])
    e_eq = np.interp(z_eq, z[k : k + 2], e[k : k + 2])
    above = z > z_eq
    zz = np.concatenate([[z_eq], z[above]])
    pp = np.concatenate([[0.0], p[above]]) / EV_PER_A3_TO_GPA  # eV/Å³
    integral = -float(np.sum(0.5 * (pp[1:] + pp[:-1]) * np.diff(zz)))  # eV/Å²
    i_min = int(np.argmin(p))
    return Adhesion(
        equilibrium_thickness_angstrom=float(z_eq),
        max_tension_gpa=float(p[i_min]),
        max_tension_thickness_angstrom=float(z[i_min]),
        work_of_separation_j_per_m2=float(
            (e[-1] - e_eq) / probe.area_angstrom2 * EV_PER_A2_TO_J_PER_M2
        ),
        work_of_separation_integral_j_per_m2=integral * EV_PER_A2_TO_J_PER_M2,
        separated=bool(i_min < len(p) - 1 and abs(p[-1]) < 0.01 * abs(p[i_min])),
    )


def thicknesses_for_pressures(
    probe: ColumnProbe, lo_gpa: float, hi_gpa: float, n: int
) -> tuple[np.ndarray, list[str]]:
    """Thicknesses whose loads at the probe stacking are evenly spaced in [lo, hi] GPa.

    Uses the monotonic branch of p(z) from the most compressed sample up to the
    tensile maximum (p decreases with z there) and inverts it by linear
    interpolation. ``lo`` below the maximum tension (a load the interface cannot
    carry) is raised to it, with a note in the returned messages.
    """
    z, p = probe.thickness_angstrom, probe.normal_stress_gpa
    i_min = int(np.argmin(p))
    zb, pb = z[: i_min + 1], p[: i_min + 1]
    notes = []
    if np.any(np.diff(pb) >= 0):
        raise InputError(
            "probe column: p(z) is not monotonic between compression and the tensile maximum; give explicit thicknesses"
        )
    if hi_gpa > pb[0]:
        raise InputError(
            f"p-range-gpa: HI={hi_gpa} GPa above the most compressed probe load {pb[0]:.3g} GPa"
        )
    if lo_gpa < pb[-1]:
        notes.append(
            f"p-range-gpa: LO={lo_gpa} GPa is below the maximum adhesive tension {pb[-1]:.4g} GPa; using {pb[-1]:.4g} GPa"
        )
        lo_gpa = float(pb[-1])
    targets = np.linspace(lo_gpa, hi_gpa, n)
    zs = np.interp(targets, pb[::-1], zb[::-1])
    return np.sort(zs), notes


def _repulsive_branch(probe: ColumnProbe) -> tuple[np.ndarray, np.ndarray]:
    """``(z, p)`` from the most compressed sample up to the tensile maximum (p decreasing)."""
    z, p = probe.thickness_angstrom, probe.normal_stress_gpa
    i_min = int(np.argmin(p))
    zb, pb = z[: i_min + 1], p[: i_min + 1]
    if np.any(np.diff(pb) >= 0):
        raise InputError(
            f"probe column at shift {probe.shift}: p(z) is not monotonic between compression "
            "and the tensile maximum; give explicit thicknesses"
        )
    return zb, pb


#: A probed column whose load at the end thickness misses its target by less than this
#: fraction of the requested load range (HI - LO) counts as bracketed (no extra thickness).
BRACKET_RTOL = 0.01


def thicknesses_spanning_columns(
    probes: Sequence[ColumnProbe], lo_gpa: float, hi_gpa: float, n: int
) -> tuple[np.ndarray, list[str]]:
    """Thicknesses whose loads span [lo, hi] GPa at every probed stacking.

    The first probe (the lowest-energy stacking) sets ``n`` thicknesses exactly as
    :func:`thicknesses_for_pressures` (loads evenly spaced from lo to hi there). Every
    other probed column ``c`` (e.g. the most repulsive stacking, whose load at a given
    z is larger) must also be bracketed on its repulsive branch: its load at the
    largest thickness must be at most ``lo_c = max(lo, its maximum tension)`` and at
    the smallest thickness at least ``hi``. Where it is not, thicknesses are appended
    beyond the largest (or prepended below the smallest) with the mean spacing of the
    first probe's thicknesses, the last one exactly at the z where ``p_c = lo_c``
    (or ``hi``), each by linear inversion of the probe's ``p_c(z)``. ``lo`` here is
    the first column's (raised to its maximum tension if below). A miss smaller than
    ``BRACKET_RTOL`` × (HI − LO) is not extended (e.g. two columns whose tensile
    maxima differ by a few MPa). When the first column already brackets every other
    one, the result is that of :func:`thicknesses_for_pressures` unchanged. Notes
    name every extension.
    """
    if not probes:
        raise InputError("probe column: no probed column to choose thicknesses from")
    z, notes = thicknesses_for_pressures(probes[0], lo_gpa, hi_gpa, n)
    lo_gpa = max(lo_gpa, float(_repulsive_branch(probes[0])[1][-1]))
    slack = BRACKET_RTOL * (hi_gpa - lo_gpa)
    dz = float(np.ptp(z)) / max(n - 1, 1)
    for probe in probes[1:]:
        zb, pb = _repulsive_branch(probe)
        if hi_gpa > pb[0]:
            raise InputError(
                f"p-range-gpa: HI={hi_gpa} GPa above the most compressed probe load {pb[0]:.3g} GPa "
                f"at shift {probe.shift}"
            )
        lo_c = max(lo_gpa, float(pb[-1]))
        z_lo_c = float(np.interp(lo_c, pb[::-1], zb[::-1]))  # thickness where p_c = lo_c
        z_hi_c = float(np.interp(hi_gpa, pb[::-1], zb[::-1]))  # thickness where p_c = hi
        top, bottom = float(z.max()), float(z.min())
        if z_lo_c > top + 1e-9 and float(np.interp(top, zb, pb)) > lo_c + slack:
            extra = _thicknesses_beyond(top, z_lo_c, dz)
            m = extra.size
            z = np.concatenate([z, extra])
            notes.append(
                f"p-range-gpa: the stacking at shift ({probe.shift[0]:.4g}, {probe.shift[1]:.4g}) "
                f"is still at {float(np.interp(top, zb, pb)):.3g} GPa at z = {top:.4g} Å; added "
                f"{m} thickness(es) up to {z_lo_c:.4g} Å where its load is {lo_c:.4g} GPa"
            )
        if z_hi_c < bottom - 1e-9 and float(np.interp(bottom, zb, pb)) < hi_gpa - slack:
            extra = _thicknesses_beyond(bottom, z_hi_c, dz)
            m = extra.size
            z = np.concatenate([z, extra])
            notes.append(
                f"p-range-gpa: the stacking at shift ({probe.shift[0]:.4g}, {probe.shift[1]:.4g}) "
                f"is only at {float(np.interp(bottom, zb, pb)):.3g} GPa at z = {bottom:.4g} Å; added "
                f"{m} thickness(es) down to {z_hi_c:.4g} Å where its load is {hi_gpa:.4g} GPa"
            )
    return np.sort(z), notes


def _thicknesses_beyond(edge: float, target: float, dz: float) -> np.ndarray:
    """Thicknesses from just past ``edge`` to ``target`` (Å), evenly spaced at most ``dz``
    apart (at least one: ``target`` itself; one if ``dz`` is not positive)."""
    m = max(1, int(np.ceil(abs(target - edge) / dz - 1e-9))) if dz > 0 else 1
    return np.linspace(edge, target, m + 1)[1:]


def probe_thicknesses(
    relax: Callable[[float, float, float, np.ndarray | None, float | None], tuple],
    reference: Atoms,
    rigid: RigidStackings,
    grid: GridSpec,
    probe_columns: Callable[[list[tuple]], list[ColumnProbe]] | None = None,
) -> tuple[dict, list[str]]:
    """Probe the extreme columns and choose the thicknesses of a pressure-range grid.

    The columns of :func:`probed_stackings` are probed along z (:func:`probe_column`;
    all but the first stop stretching once their load is at most LO or past their
    tensile maximum); the thicknesses bracket the requested loads at every one of them
    (:func:`thicknesses_spanning_columns`). The adhesion is that of the lowest-energy
    column (the paper's z-scan).

    The columns are independent chains of relaxations: ``probe_columns(specs)``, given the
    list of ``(shift, p_hi_gpa, stop_at_gpa)``, returns their :class:`ColumnProbe` in the
    same order (the scan driver runs them on its workers); by default they run here, one
    after the other, with ``relax``.

    Returns
    -------
    resolved, notes
        ``resolved`` holds ``thickness_angstrom``, ``probe`` (the lowest-energy
        column, as before), ``probes`` (every probed column with its ``role``),
        ``adhesion`` and ``notes``.
    """
    lo, hi, n = grid.p_range_gpa
    columns = probed_stackings(rigid, grid)
    if not grid.bracket_all_stackings:
        columns = columns[:1]
    specs = [(shift, hi, None if k == 0 else lo) for k, (_, shift) in enumerate(columns)]
    if probe_columns is None:
        probes = [
            probe_column(relax, reference, shift, p_hi, stop_at_gpa=stop)
            for shift, p_hi, stop in specs
        ]
    else:
        probes = list(probe_columns(specs))
    adh = adhesion(probes[0])
    z, notes = thicknesses_spanning_columns(probes, lo, hi, n)
    return {
        "thickness_angstrom": z.tolist(),
        "probe": probes[0].as_dict(),
        "probes": [
            {"role": role, **p.as_dict()} for (role, _), p in zip(columns, probes, strict=True)
        ],
        "adhesion": adh.as_dict(),
        "notes": notes,
    }, notes
