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

from collections.abc import Callable, Sequence

import numpy as np
from ase import Atoms

from flatcontact.errors import InputError
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.probe import ColumnProbe, RigidStackings, probe_column, probed_stackings
from flatcontact.ispes.separation import adhesion


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

    The columns of :func:`flatcontact.ispes.probe.probed_stackings` are probed along z
    (:func:`flatcontact.ispes.probe.probe_column`;
    all but the first stop stretching once their load is at most LO or past their
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
