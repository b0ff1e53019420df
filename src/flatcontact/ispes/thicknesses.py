"""The thicknesses of a pressure-range grid, chosen from probed columns.

A grid given as a load range ``(lo_gpa, hi_gpa, n)`` needs thicknesses z (Å) whose
loads span it: :func:`probe_thicknesses` probes the extreme columns
(:mod:`flatcontact.ispes.probe`), inverts the lowest-energy column's p(z) for ``n``
evenly spaced loads (:func:`thicknesses_for_pressures`) and adds thicknesses until every
probed column brackets the loads (:func:`thicknesses_spanning_columns`); it reports the
work of separation of the lowest-energy column beside them
(:func:`flatcontact.ispes.separation.adhesion`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.contract import branch_run
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.probe import ColumnProbe, RigidStackings, probe_column, probed_stackings
from flatcontact.ispes.separation import adhesion

#: No two thicknesses of a pressure-range grid are closer than this (Å). The analysis reads
#: the load from the energy, p = -(1/A) dU/dz of a spline through neighbouring nodes, whose
#: error is about δU / (A h) for relaxed energies converged to δU and nodes h apart: two nodes
#: 0.0047 Å apart (Au(111) with ``Au_u3.eam``, 7.2 Å² cell) turned the relaxation residual
#: into a p(z) that rose by 0.08 GPa between them. At 0.02 Å the same residual costs a
#: quarter of that, below the load step of any grid. Of two thicknesses closer than this
#: the outer one (farther from the middle of the list) is kept
#: (:func:`merge_close_thicknesses`), so the bracket never shrinks.
MIN_THICKNESS_SPACING_ANGSTROM = 0.02

#: The two causes of a fold on the compressed side and their remedies, as the notes and the
#: analysis stage name them. A plane that slips changes the stack (``scan.json`` ``layer_slip``
#: lists in-slab slip above 0.25 Å); without one, the fold is the relaxation's: points that
#: stopped at ``scan.fmax_ev_per_angstrom`` short of their minimum, an error that grows along a
#: warm-started column (12-layer α-quartz at 0.005 eV/Å: 0.7-6.5 meV per point, a fold of
#: 0.44 GPa of -(1/A) dU/dz that is gone at 0.0005 eV/Å; docs/convergence.md, "Slab layers at
#: high load"; tests/ispes/test_fold_relaxation.py).
FOLD_REMEDY = (
    "if a plane slips (scan.json layer_slip), hold the slabs' inner planes laterally "
    "(scan.relax_mode: normal); if none does, the relaxation stopped short of its minimum: "
    "tighten scan.fmax_ev_per_angstrom"
)


@dataclasses.dataclass(frozen=True)
class LoadFold:
    """A probed column whose p(z) rises with z before its tensile maximum (a fold).

    Loads are read on one branch that falls from compression to the tensile maximum; past a
    fold (a plane that slips or opens, a collapse) the compressed side is another branch.
    The loads above the fold's ``p_gpa`` (the load at ``z_angstrom``, where the tensile-side
    branch begins) are refused: ``loads_refused_gpa`` lists the requested loads above it.
    ``below_*`` is the neighbouring compressed sample (z smaller, p not larger). GPa, Å.
    """

    column: str
    z_angstrom: float
    p_gpa: float
    below_z_angstrom: float
    below_p_gpa: float
    loads_refused_gpa: tuple[float, ...] = ()

    def record(self) -> dict:
        """The ``scan.json`` ``load_folds`` entry (docs/file-contracts.md)."""
        return {
            "column": self.column,
            "z_angstrom": float(self.z_angstrom),
            "p_gpa": float(self.p_gpa),
            "loads_refused_gpa": [float(v) for v in self.loads_refused_gpa],
        }

    def message(self) -> str:
        """One line: the column, the fold's z and p, the loads refused and the remedy."""
        refused = ", ".join(f"{v:.4g}" for v in self.loads_refused_gpa)
        refused = f"refused: {refused} GPa" if refused else "none of the requested loads"
        return (
            f"p-range-gpa: the {self.column} folds: p = {self.below_p_gpa:.4g} GPa at z = "
            f"{self.below_z_angstrom:.4g} Å rises to {self.p_gpa:.4g} GPa at z = "
            f"{self.z_angstrom:.4g} Å; loads above {self.p_gpa:.4g} GPa are not on one branch "
            f"with P = 0 ({refused}); {FOLD_REMEDY}; or lower "
            f"scan.p_range_gpa.hi_gpa to at most {self.p_gpa:.3g} GPa"
        )


def column_name(probe: ColumnProbe, role: str | None = None) -> str:
    """``"<role> column at shift (a, b)"``: how messages and ``load_folds`` name a column."""
    a, b = probe.shift
    return f"{role + ' ' if role else ''}column at shift ({a:.4g}, {b:.4g})"


def repulsive_branch(
    probe: ColumnProbe, role: str | None = None
) -> tuple[np.ndarray, np.ndarray, LoadFold | None]:
    """``(z, p, fold)``: the part of the probe that carries P = 0, p falling with z.

    The samples up to the global tensile maximum are split where p rises with z; the
    branch is the first falling run that reaches p <= 0 (the last run if none does). Its
    end is the column's tensile maximum for the thickness choice: a second, deeper well
    further out (two gaps opening one after the other) is never read. Without a rise this
    is the whole run from the most compressed sample to the global tensile maximum
    (``fold`` None). A rise before the branch (on the compressed side) is a fold: loads
    above the branch's first sample are on another branch, and ``fold`` names it (without
    refused loads; :func:`thicknesses_spanning_columns` fills them in). A branch of one
    sample leaves nothing to read: one-line InputError naming the column, z and p.
    """
    z, p = probe.thickness_angstrom, probe.normal_stress_gpa
    s, e = branch_run(p)
    fold = None
    if s > 0:
        fold = LoadFold(column_name(probe, role), z[s], p[s], z[s - 1], p[s - 1])
    if e - s < 1:
        raise InputError(
            f"p-range-gpa: the {column_name(probe, role)} folds where it crosses P = 0: p = "
            f"{p[s - 1]:.4g} GPa at z = {z[s - 1]:.4g} Å rises to {p[s]:.4g} GPa at z = "
            f"{z[s]:.4g} Å and falls no further; hold the slabs' inner planes laterally "
            "(scan.relax_mode: normal) or give scan.thickness_angstrom"
        )
    return z[s : e + 1], p[s : e + 1], fold


def thicknesses_for_pressures(
    probe: ColumnProbe, lo_gpa: float, hi_gpa: float, n: int
) -> tuple[np.ndarray, list[str]]:
    """Thicknesses whose loads at the probe stacking are evenly spaced in [lo, hi] GPa.

    Uses the repulsive branch of p(z) (:func:`repulsive_branch`: from the most compressed
    sample, or from a fold, up to the tensile maximum; p decreases with z there) and
    inverts it by linear interpolation. ``lo`` below the maximum tension (a load the
    interface cannot carry) is raised to it, with a note in the returned messages. ``hi``
    above the branch is an InputError (a fold above ``hi`` is not; the caller
    :func:`thicknesses_spanning_columns` lowers ``hi`` to a fold first).
    """
    zb, pb, _ = repulsive_branch(probe)
    notes = []
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


def merge_close_thicknesses(
    z: Sequence[float], min_spacing_angstrom: float = MIN_THICKNESS_SPACING_ANGSTROM
) -> np.ndarray:
    """Sorted distinct thicknesses with no two closer than ``min_spacing_angstrom`` (Å).

    The smallest and the largest are kept; an inner thickness closer than the minimum to
    the last one kept below it, or to the largest, is dropped (the outer of two close
    thicknesses survives, so the range never shrinks). A list that respects the minimum is
    returned as it is (sorted); a list whose whole range is narrower than the minimum
    keeps its two ends.
    """
    z = np.unique(np.asarray(z, dtype=float))
    if z.size <= 2 or np.all(np.diff(z) >= min_spacing_angstrom):
        return z
    kept = [z[0]]
    for v in z[1:-1]:
        if v - kept[-1] >= min_spacing_angstrom and z[-1] - v >= min_spacing_angstrom:
            kept.append(v)
    kept.append(z[-1])
    return np.array(kept)


#: A probed column whose load at the end thickness misses its target by less than this
#: fraction of the requested load range (HI - LO) counts as bracketed by the probe (no extra
#: thickness; e.g. two columns whose tensile maxima differ by a few MPa). The grid's own
#: loads are checked after the scan (:mod:`flatcontact.ispes.grid_bracket`), without slack.
BRACKET_RTOL = 0.01


@dataclasses.dataclass(frozen=True)
class ChosenThicknesses:
    """What :func:`thicknesses_spanning_columns` chose: thicknesses (Å, ascending), notes,
    the folds whose loads are refused, and the load range bracketed (GPa)."""

    thickness_angstrom: np.ndarray
    notes: list[str]
    load_folds: list[LoadFold]
    lo_gpa: float
    hi_gpa: float


def thicknesses_spanning_columns(
    probes: Sequence[ColumnProbe],
    lo_gpa: float,
    hi_gpa: float,
    n: int,
    roles: Sequence[str | None] | None = None,
) -> ChosenThicknesses:
    """Thicknesses whose loads span P = 0 and [lo, hi] GPa at every probed stacking.

    The first probe (the lowest-energy stacking) sets ``n`` thicknesses exactly as
    :func:`thicknesses_for_pressures` (loads evenly spaced from lo to hi there). Every
    probed column ``c`` (e.g. the most repulsive stacking, whose load at a given z is
    larger) must also be bracketed on its repulsive branch: its load at the largest
    thickness must be at most ``lo_c = max(min(lo, 0), its maximum tension)`` and at the
    smallest thickness at least ``hi``. Where it is not, thicknesses are appended beyond
    the largest (or prepended below the smallest) with the mean spacing of the first
    probe's thicknesses, the last one exactly at the z where ``p_c = lo_c`` (or ``hi``),
    each by linear inversion of the probe's ``p_c(z)``. ``lo`` here is the first column's
    (raised to its maximum tension if below). When the first column already brackets
    every other one and P = 0, the result is that of :func:`thicknesses_for_pressures`
    unchanged. Notes name every extension.

    Folds (:func:`repulsive_branch`): a column whose branch starts below ``hi`` lowers
    ``hi`` to its fold's load for every column, and the requested loads
    ``linspace(lo, hi, n)`` above it are refused (:class:`LoadFold`, one note each). A
    fold at or below ``max(lo, 0)`` leaves no requested load: one-line InputError.

    Last, no two thicknesses closer than ``MIN_THICKNESS_SPACING_ANGSTROM``
    (:func:`merge_close_thicknesses`; a list that respects it is unchanged).
    """
    if not probes:
        raise InputError("probe column: no probed column to choose thicknesses from")
    roles = list(roles) if roles is not None else [None] * len(probes)
    branches = [repulsive_branch(p, r) for p, r in zip(probes, roles, strict=True)]
    requested = np.linspace(lo_gpa, hi_gpa, n)
    folds = []
    for _, pb, fold in branches:
        if fold is not None and pb[0] < hi_gpa:
            refused = tuple(float(v) for v in requested if v > pb[0])
            folds.append(dataclasses.replace(fold, loads_refused_gpa=refused))
    notes = []
    if folds:
        top = min(f.p_gpa for f in folds)
        worst = min(folds, key=lambda f: f.p_gpa)
        if top <= max(lo_gpa, 0.0):
            raise InputError(
                worst.message().split("; loads above")[0]
                + f", at or below the lowest requested load {max(lo_gpa, 0.0):.4g} GPa; hold the "
                "slabs' inner planes laterally (scan.relax_mode: normal) or give "
                "scan.thickness_angstrom"
            )
        hi_gpa = float(top)
        notes += [f.message() for f in folds]
    z, first_notes = thicknesses_for_pressures(probes[0], lo_gpa, hi_gpa, n)
    notes = first_notes + notes
    lo_gpa = max(lo_gpa, float(branches[0][1][-1]))
    lo_bracket = min(lo_gpa, 0.0)  # P = 0 is always bracketed
    slack = BRACKET_RTOL * (hi_gpa - lo_gpa)
    dz = float(np.ptp(z)) / max(n - 1, 1)
    for k, (probe, (zb, pb, _)) in enumerate(zip(probes, branches, strict=True)):
        if hi_gpa > pb[0]:
            raise InputError(
                f"p-range-gpa: HI={hi_gpa} GPa above the most compressed probe load {pb[0]:.3g} GPa "
                f"at shift {probe.shift}"
            )
        lo_c = max(lo_bracket, float(pb[-1]))
        z_lo_c = float(np.interp(lo_c, pb[::-1], zb[::-1]))  # thickness where p_c = lo_c
        z_hi_c = float(np.interp(hi_gpa, pb[::-1], zb[::-1]))  # thickness where p_c = hi
        top, bottom = float(z.max()), float(z.min())
        name = "stacking" if k else "lowest-energy stacking"
        if z_lo_c > top + 1e-9 and float(np.interp(top, zb, pb)) > lo_c + slack:
            extra = _thicknesses_beyond(top, z_lo_c, dz)
            m = extra.size
            z = np.concatenate([z, extra])
            notes.append(
                f"p-range-gpa: the {name} at shift ({probe.shift[0]:.4g}, {probe.shift[1]:.4g}) "
                f"is still at {float(np.interp(top, zb, pb)):.3g} GPa at z = {top:.4g} Å; added "
                f"{m} thickness(es) up to {z_lo_c:.4g} Å where its load is {lo_c:.4g} GPa"
            )
        if z_hi_c < bottom - 1e-9 and float(np.interp(bottom, zb, pb)) < hi_gpa - slack:
            extra = _thicknesses_beyond(bottom, z_hi_c, dz)
            m = extra.size
            z = np.concatenate([z, extra])
            notes.append(
                f"p-range-gpa: the {name} at shift ({probe.shift[0]:.4g}, {probe.shift[1]:.4g}) "
                f"is only at {float(np.interp(bottom, zb, pb)):.3g} GPa at z = {bottom:.4g} Å; added "
                f"{m} thickness(es) down to {z_hi_c:.4g} Å where its load is {hi_gpa:.4g} GPa"
            )
    z = np.sort(z)
    merged = merge_close_thicknesses(z)
    if merged.size < z.size:
        notes.append(
            f"p-range-gpa: dropped {z.size - merged.size} thickness(es) closer than "
            f"{MIN_THICKNESS_SPACING_ANGSTROM} Å to a neighbour (the outer one kept)"
        )
    return ChosenThicknesses(merged, notes, folds, lo_gpa, hi_gpa)


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

    The columns of :func:`flatcontact.ispes.probe.probed_stackings` are probed along z
    (:func:`flatcontact.ispes.probe.probe_column`;
    all but the first stop stretching once their load is at most min(LO, 0) or past their
    tensile maximum); the thicknesses bracket the requested loads at every one of them
    (:func:`thicknesses_spanning_columns`). The adhesion is that of the lowest-energy
    column (the paper's z-scan).

    The columns are independent chains of relaxations: ``probe_columns(specs)``, given the
    list of ``(shift, p_hi_gpa, stop_at_gpa)``, returns their :class:`~flatcontact.ispes.probe.ColumnProbe` in the
    same order (the scan driver runs them on its workers); by default they run here, one
    after the other, with ``relax``.

    Returns
    -------
    resolved, notes
        ``resolved`` holds ``thickness_angstrom``, ``probe`` (the lowest-energy
        column, as before), ``probes`` (every probed column with its ``role``),
        ``adhesion``, ``notes``, ``load_folds`` (:meth:`LoadFold.record`) and
        ``bracket_gpa`` (the loads the thicknesses bracket: LO raised to the first
        column's tension, HI lowered to a fold).
    """
    lo, hi, n = grid.p_range_gpa
    columns = probed_stackings(rigid, grid)
    if not grid.bracket_all_stackings:
        columns = columns[:1]
    stop = min(lo, 0.0)  # every column is stretched at least to P = 0
    specs = [(shift, hi, None if k == 0 else stop) for k, (_, shift) in enumerate(columns)]
    if probe_columns is None:
        probes = [
            probe_column(relax, reference, shift, p_hi, stop_at_gpa=stop)
            for shift, p_hi, stop in specs
        ]
    else:
        probes = list(probe_columns(specs))
    adh = adhesion(probes[0])
    chosen = thicknesses_spanning_columns(probes, lo, hi, n, [role for role, _ in columns])
    notes = chosen.notes
    return {
        "thickness_angstrom": chosen.thickness_angstrom.tolist(),
        "probe": probes[0].as_dict(),
        "probes": [
            {"role": role, **p.as_dict()} for (role, _), p in zip(columns, probes, strict=True)
        ],
        "adhesion": adh.as_dict(),
        "notes": notes,
        "load_folds": [f.record() for f in chosen.load_folds],
        "bracket_gpa": [chosen.lo_gpa, chosen.hi_gpa],
    }, notes
