"""Thicker dense α-quartz (0001) slabs: whole bulk repeats inserted into the slab's interior.

The dense reconstruction lives in the two face layers; between them the slab is α-quartz.
A slab of ``6 + 3·m`` O–Si–O layers is made from a dense 6-layer slab by

1. relaxing α-quartz with the same potential at the slab's lateral cell (``c`` and the ions
   free, a1 and a2 held: the bulk strained laterally exactly as the slab's interior is);
2. registering that bulk on the slab's interior (the atoms strictly between the two face-Si
   planes): the rigid translation that puts every interior atom nearest an atom of the same
   species of the periodic bulk, least-squares refined (no rotation: the slab was cut from
   the same crystal with the same in-plane axes);
3. cutting the slab between two atomic planes of its interior (the gap of at least
   ``MIN_CUT_GAP_ANGSTROM`` nearest the mid-height between the face-Si planes), lifting
   everything above the cut by ``m·c`` and filling the opening with the ``9·m`` registered
   bulk atoms between the cut and ``cut + m·c``. (With the bundled SNAP the relaxed 9-layer
   slab's energy changes by at most 2.2 meV, 0.08 meV/atom, over the seven gaps between the
   face-Si planes.)

A c-repeat (three O–Si–O units; the 3₂ screw axis rotates consecutive units by 120°) is the
smallest insertion that is a pure translation, so both faces keep their exact geometry and
their registry; the layer counts reachable are 6, 9, 12, .... The caller relaxes the result
with the potential and verifies it (:func:`~flatcontact.structures.dense.verify_dense_slab`,
:func:`interior_report`). Lengths in Å, energies in eV.
"""

from __future__ import annotations

import numpy as np
from ase import Atoms
from ase.filters import UnitCellFilter
from ase.optimize import BFGS
from ase.units import GPa

from flatcontact.foundation.errors import InputError, require
from flatcontact.structures.bulk import QUARTZ_C_ANGSTROM, alpha_quartz
from flatcontact.structures.dense import QUARTZ_ATOMS_PER_LAYER, face_masks
from flatcontact.structures.quartz_layers import DENSE_FACE_LAYERS, UNITS_PER_REPEAT

#: Largest RMS distance (Å) between the slab's interior atoms and the registered bulk for the
#: interior to count as α-quartz (a wrong registration or another phase gives > 1 Å; the
#: surface-strained interior of the shipped 6-layer slab relaxed with the bundled SNAP, 0.40 Å).
REGISTRATION_MAX_RMS_ANGSTROM = 0.6
#: Atomic heights within this (Å) are one plane (Si planes of the interior report).
PLANE_TOLERANCE_ANGSTROM = 0.05
#: Narrowest gap (Å) between atomic heights of the interior that the insertion cut may use.
MIN_CUT_GAP_ANGSTROM = 0.3
#: Force (eV/Å) and stress tolerance of the laterally clamped bulk relaxation (BFGS on ASE's
#: unit-cell filter, only the zz stress component free).
BULK_FMAX = 1e-4


def lateral_bulk(bulk_calc_for, cell2d: np.ndarray, c_angstrom: float = QUARTZ_C_ANGSTROM):
    """α-quartz relaxed at the in-plane cell ``cell2d`` (2×2, Å): c and the ions free.

    ``bulk_calc_for(atoms)`` returns the potential's bulk calculator. Returns (relaxed
    9-atom cell, record with the relaxed c, the remaining zz stress in GPa and the steps).
    """
    a1, a2 = np.asarray(cell2d, float)
    a = float(np.linalg.norm(a1))
    require(
        abs(np.linalg.norm(a2) - a) < 1e-6 and abs(a1 @ a2 / a**2 + 0.5) < 1e-6,
        f"slab cell: expected the hexagonal α-quartz (0001) 1x1 cell, got a1={a1}, a2={a2}",
    )
    bulk = alpha_quartz(a, c_angstrom)
    bulk.set_cell(
        [[a1[0], a1[1], 0.0], [a2[0], a2[1], 0.0], [0.0, 0.0, c_angstrom]], scale_atoms=True
    )
    bulk.calc = bulk_calc_for(bulk)
    opt = BFGS(UnitCellFilter(bulk, mask=[0, 0, 1, 0, 0, 0]), logfile=None)
    converged = bool(opt.run(fmax=BULK_FMAX, steps=1000))
    record = {
        "a_angstrom": a,
        "c_angstrom": float(bulk.cell.array[2, 2]),
        "stress_zz_gpa": float(bulk.get_stress(voigt=True)[2] / GPa),
        "energy_ev": float(bulk.get_potential_energy()),
        "steps": int(opt.nsteps),
        "converged": converged,
    }
    bulk.calc = None
    return bulk, record


def _face_si_heights(slab: Atoms) -> tuple[float, float]:
    """Highest Si height of the bottom face layer and lowest of the top face layer (Å)."""
    symbols = np.array(slab.get_chemical_symbols())
    bottom, top = face_masks(slab, DENSE_FACE_LAYERS * QUARTZ_ATOMS_PER_LAYER)
    z = slab.positions[:, 2]
    return float(z[bottom & (symbols == "Si")].max()), float(z[top & (symbols == "Si")].min())


def interior_mask(slab: Atoms) -> np.ndarray:
    """Atoms strictly between the bottom face's Si plane and the top face's (by height)."""
    lo, hi = _face_si_heights(slab)
    z = slab.positions[:, 2]
    return (z > lo + PLANE_TOLERANCE_ANGSTROM) & (z < hi - PLANE_TOLERANCE_ANGSTROM)


#: Lattice offsets (fractions of a1, a2, c) searched around the rounded image: with the 120°
#: hexagonal cell the nearest image is not always the rounded one.
_IMAGES = np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)])


def _residuals(slab: Atoms, index: np.ndarray, bulk: Atoms, shift: np.ndarray) -> np.ndarray:
    """Vector from the nearest same-species atom of the periodic ``bulk + shift`` to each atom."""
    cell = bulk.cell.array
    bulk_symbols = np.array(bulk.get_chemical_symbols())
    symbols = np.array(slab.get_chemical_symbols())
    out = np.empty((len(index), 3))
    for row, i in enumerate(index):
        delta = slab.positions[i] - (bulk.positions[bulk_symbols == symbols[i]] + shift)
        frac = np.linalg.solve(cell.T, delta.T).T
        frac -= np.round(frac)
        cart = (frac[:, None, :] + _IMAGES[None, :, :]).reshape(-1, 3) @ cell
        out[row] = cart[np.argmin(np.linalg.norm(cart, axis=1))]
    return out


def register_bulk(slab: Atoms, bulk: Atoms, mask: np.ndarray) -> tuple[np.ndarray, float]:
    """Translation (Å) of ``bulk`` that best matches the ``mask`` atoms of ``slab``, and its RMS.

    Candidates put the lowest masked Si on each bulk Si; each is refined by the mean residual
    (least squares for a pure translation, 10 passes); the smallest RMS wins (ties: first).
    """
    index = np.flatnonzero(mask)
    symbols = np.array(slab.get_chemical_symbols())
    si = index[symbols[index] == "Si"]
    require(si.size > 0, "slab interior: no Si between the two dense face layers")
    anchor = si[np.argmin(slab.positions[si, 2])]
    best = None
    for j in np.flatnonzero(np.array(bulk.get_chemical_symbols()) == "Si"):
        shift = slab.positions[anchor] - bulk.positions[j]
        for _ in range(10):
            shift = shift + _residuals(slab, index, bulk, shift).mean(axis=0)
        rms = float(np.sqrt((_residuals(slab, index, bulk, shift) ** 2).sum(axis=1).mean()))
        if best is None or rms < best[1] - 1e-9:
            best = (shift, rms)
    return best


def _cut_height(slab: Atoms, mask: np.ndarray) -> float:
    """Cut plane (Å): the middle of the gap between consecutive heights of the ``mask`` atoms
    that is at least ``MIN_CUT_GAP_ANGSTROM`` wide and nearest the mid-height of the face-Si
    planes (ties: the lower)."""
    lo, hi = _face_si_heights(slab)
    z = np.sort(slab.positions[mask, 2])
    gaps = np.diff(z)
    mids = [z[k] + 0.5 * gaps[k] for k in range(gaps.size) if gaps[k] >= MIN_CUT_GAP_ANGSTROM]
    require(bool(mids), "dense slab interior: no gap between atomic planes to insert bulk at")
    middle = 0.5 * (lo + hi)
    return float(min(mids, key=lambda h: (round(abs(h - middle), 6), h)))


def insert_bulk_repeats(slab: Atoms, bulk: Atoms, repeats: int) -> tuple[Atoms, dict]:
    """``slab`` with ``repeats`` c-repeats of ``bulk`` inserted at its mid-height (see module).

    ``bulk`` must share the slab's in-plane cell (:func:`lateral_bulk`). Returns the new slab
    (``3·UNITS_PER_REPEAT·repeats`` more atoms, cell height grown by ``repeats·c``; atoms
    below the cut, then the inserted ones, then the lifted ones) and a record of the cut.
    """
    require(
        isinstance(repeats, int) and repeats >= 0, f"repeats={repeats!r}: expected an integer >= 0"
    )
    require(
        np.allclose(slab.cell.array[:2, :2], bulk.cell.array[:2, :2], atol=1e-6),
        "bulk and slab must share the in-plane cell",
    )
    mask = interior_mask(slab)
    shift, rms = register_bulk(slab, bulk, mask)
    if rms > REGISTRATION_MAX_RMS_ANGSTROM:
        raise InputError(
            f"dense slab interior: RMS distance {rms:.2f} Å to the registered α-quartz bulk "
            f"> {REGISTRATION_MAX_RMS_ANGSTROM} Å; its interior is not bulk-like enough to "
            "insert bulk repeats"
        )
    cut = _cut_height(slab, mask)
    c = float(bulk.cell.array[2, 2])
    record = {
        "repeats": repeats,
        "registration_rms_angstrom": rms,
        "registration_shift_angstrom": shift.tolist(),
        "cut_height_angstrom": cut,
        "bulk_c_angstrom": c,
    }
    if repeats == 0:
        return slab.copy(), record
    z = slab.positions[:, 2]
    registered = bulk.copy()
    registered.positions += shift
    first = int(np.floor((cut - shift[2]) / c)) - 1
    stack = registered.repeat((1, 1, repeats + 3))
    stack.positions[:, 2] += first * c
    zs = stack.positions[:, 2]
    fill = stack[(zs >= cut) & (zs < cut + repeats * c)]
    per_repeat = len(bulk)
    require(
        len(fill) == per_repeat * repeats,
        f"cut at z={cut:.3f} Å: {len(fill)} bulk atoms selected, expected {per_repeat * repeats}",
    )
    below, above = slab[z < cut], slab[z > cut]
    above.positions[:, 2] += repeats * c
    out = below + fill + above
    cell = slab.cell.array.copy()
    cell[2, 2] += repeats * c
    out.set_cell(cell, scale_atoms=False)
    out.pbc = slab.pbc
    out.wrap()
    out.info = dict(slab.info)
    return out, record


def si_planes(slab: Atoms) -> np.ndarray:
    """Mean heights (Å, ascending) of the Si planes (heights within the plane tolerance)."""
    symbols = np.array(slab.get_chemical_symbols())
    z = np.sort(slab.positions[symbols == "Si", 2])
    planes = [[z[0]]]
    for value in z[1:]:
        if value - planes[-1][-1] > PLANE_TOLERANCE_ANGSTROM:
            planes.append([value])
        else:
            planes[-1].append(value)
    return np.array([np.mean(p) for p in planes])


def interior_report(slab: Atoms, bulk: Atoms) -> dict:
    """How bulk-like the interior of a dense slab is, against ``bulk`` (same in-plane cell).

    Spacings of consecutive Si planes strictly between the two face-Si planes (each one
    O–Si–O unit; bulk value c/3 by the 3₂ screw axis) and their relative deviation from
    c/3; the RMS distance of the interior atoms to the registered bulk.
    """
    lo, hi = _face_si_heights(slab)
    planes = si_planes(slab)
    inner = planes[
        (planes > lo + PLANE_TOLERANCE_ANGSTROM) & (planes < hi - PLANE_TOLERANCE_ANGSTROM)
    ]
    unit = float(bulk.cell.array[2, 2]) / UNITS_PER_REPEAT
    spacings = np.diff(inner)
    rel = spacings / unit - 1.0
    _, rms = register_bulk(slab, bulk, interior_mask(slab))
    return {
        "bulk_unit_height_angstrom": unit,
        "interior_si_planes": int(inner.size),
        "interior_si_spacings_angstrom": spacings.tolist(),
        "interior_spacing_rel_dev": rel.tolist(),
        "max_abs_spacing_rel_dev": float(np.abs(rel).max()) if rel.size else 0.0,
        "mean_spacing_rel_dev": float(rel.mean()) if rel.size else 0.0,
        "face_to_interior_si_angstrom": [
            float(inner[0] - lo) if inner.size else None,
            float(hi - inner[-1]) if inner.size else None,
        ],
        "interior_rms_to_bulk_angstrom": rms,
    }
