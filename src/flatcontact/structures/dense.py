"""The "dense" (1×1) reconstruction of α-quartz (0001): reaching it and verifying it.

Target (Rignanese et al., PRB 61, 13250 (2000); Goumans et al., PCCP 9, 2146 (2007)):
each face's two outermost O–Si–O units merge into one flat layer in which the Si
atoms form a honeycomb bridged by O (six-membered Si rings in the surface plane),
with three-membered rings underneath; stoichiometric, every Si 4-fold, every O 2-fold.

Verification (:func:`verify_dense_slab`), all with the Si–O cutoff of
:mod:`flatcontact.structures.topology`:

1. stoichiometry SiO₂;
2. every Si 4-coordinated and every O 2-coordinated;
3. each face layer (the ``2·atoms_per_layer`` outermost atoms, two O–Si–O units)
   contains six-membered rings: the smallest ring *within the face layer* through each
   of its Si atoms has 6 Si (12 bonds);
4. flat: the peak-to-peak height spread of the face-layer Si atoms is at most
   ``FLAT_SI_SPREAD_ANGSTROM`` (bulk stacking would give c/3 = 1.80 Å).
"""

from __future__ import annotations

import numpy as np
from ase import Atoms
from ase.optimize import FIRE

from flatcontact.foundation.errors import require
from flatcontact.structures.quartz_layers import DENSE_FACE_LAYERS
from flatcontact.structures.topology import bonds, coordination_defects, height_spread, ring_sizes

#: Maximum height spread (Å) of the Si atoms of a face layer for it to count as flat.
FLAT_SI_SPREAD_ANGSTROM = 0.5
#: Si–O bond length (Å) used to place a seeded O.
SI_O_BOND_ANGSTROM = 1.61
#: Atoms per O–Si–O unit in the 1×1 (0001) cell.
QUARTZ_ATOMS_PER_LAYER = 3


def face_masks(slab: Atoms, face_atoms: int) -> tuple[np.ndarray, np.ndarray]:
    """Boolean masks of the ``face_atoms`` lowest (bottom face) and highest (top face) atoms."""
    order = np.argsort(slab.positions[:, 2], kind="stable")
    bottom = np.zeros(len(slab), bool)
    top = np.zeros(len(slab), bool)
    bottom[order[:face_atoms]] = True
    top[order[-face_atoms:]] = True
    return bottom, top


def verify_dense_slab(
    slab: Atoms,
    atoms_per_layer: int = QUARTZ_ATOMS_PER_LAYER,
    flat_si_spread_angstrom: float = FLAT_SI_SPREAD_ANGSTROM,
) -> dict:
    """Check the dense (0001) reconstruction on both faces; return a JSON-ready report.

    The report has ``dense`` (bool), ``failures`` (list of one-line reasons) and the
    measured numbers: coordination defects, per-face ring sizes (Si count) within the face
    layer and through the whole slab, face-layer Si/O height spreads (Å).
    """
    symbols = np.array(slab.get_chemical_symbols())
    n_si = int(np.count_nonzero(symbols == "Si"))
    n_o = int(np.count_nonzero(symbols == "O"))
    failures = []
    if n_o != 2 * n_si or n_si + n_o != len(slab):
        failures.append(f"not stoichiometric SiO2: {n_si} Si, {n_o} O, {len(slab)} atoms")
    defects = coordination_defects(slab)
    if defects:
        failures.append(
            "coordination defects: "
            + ", ".join(f"{d['symbol']}{d['index']} {d['cn']}-fold" for d in defects)
        )
    faces = {}
    for name, mask in zip(
        ("bottom", "top"), face_masks(slab, DENSE_FACE_LAYERS * atoms_per_layer), strict=True
    ):
        si = np.flatnonzero(mask & (symbols == "Si"))
        in_layer = ring_sizes(slab, si, within=mask)
        overall = ring_sizes(slab, si)
        to_si = [None if r is None else r // 2 for r in in_layer]
        faces[name] = {
            "si_indices": si.tolist(),
            "smallest_ring_in_face_layer_si": to_si,
            "smallest_ring_overall_si": [None if r is None else r // 2 for r in overall],
            "si_height_spread_angstrom": height_spread(slab, mask & (symbols == "Si")),
            "o_height_spread_angstrom": height_spread(slab, mask & (symbols == "O")),
        }
        if any(r != 6 for r in to_si):
            failures.append(f"{name} face: smallest in-layer rings {to_si} (Si), expected 6")
        spread = faces[name]["si_height_spread_angstrom"]
        if spread > flat_si_spread_angstrom:
            failures.append(
                f"{name} face: Si height spread {spread:.2f} Å > {flat_si_spread_angstrom} Å (not flat)"
            )
    return {
        "dense": not failures,
        "failures": failures,
        "n_si": n_si,
        "n_o": n_o,
        "coordination_defects": defects,
        "faces": faces,
        "criteria": {
            "si_o_cutoff_angstrom": 2.0,
            "face_layer_atoms": DENSE_FACE_LAYERS * atoms_per_layer,
            "flat_si_spread_angstrom": flat_si_spread_angstrom,
        },
    }


def relax(atoms: Atoms, calc, fmax_ev_per_angstrom: float = 0.01, steps: int = 5000) -> dict:
    """FIRE relaxation of ``atoms`` in place (lateral cell fixed).

    Returns steps, converged, energy (eV) and the largest remaining force on an atom
    (``max_force_ev_per_angstrom``). ``fmax_ev_per_angstrom`` must be finite and > 0.
    """
    require(
        bool(np.isfinite(fmax_ev_per_angstrom)) and fmax_ev_per_angstrom > 0,
        f"fmax_ev_per_angstrom={fmax_ev_per_angstrom!r}: expected a finite value > 0 eV/Å",
    )
    atoms.calc = calc
    opt = FIRE(atoms, logfile=None)
    converged = bool(opt.run(fmax=fmax_ev_per_angstrom, steps=steps))
    forces = atoms.get_forces(apply_constraint=True)
    return {
        "steps": int(opt.nsteps),
        "converged": converged,
        "energy_ev": float(atoms.get_potential_energy()),
        "max_force_ev_per_angstrom": float(np.linalg.norm(forces, axis=1).max()),
    }


def _lateral_min_image(delta: np.ndarray, a1: np.ndarray, a2: np.ndarray) -> np.ndarray:
    """Minimum-image lateral part of ``delta`` (2-vector) for the in-plane lattice (a1, a2)."""
    basis = np.array([a1, a2]).T
    frac = np.linalg.solve(basis, delta)
    frac -= np.round(frac)
    return basis @ frac


def seed_dense_face(slab: Atoms, top: bool, site: int, vertical: int = 0) -> Atoms:
    """Move the atoms of one cut-2 face of a 1×1 quartz (0001) slab towards the dense topology.

    The cut-2 face has a 3-fold Si (Sa), a 1-fold O and, one layer down, a 4-fold Si (Sb)
    bonded through two O to the third-layer Si (Sc). The seed: Sa goes into Sb's plane on one
    of the two honeycomb sites of Sb's triangular lattice (``site`` 0: Sb + (2a1 + a2)/3,
    1: Sb + (a1 + 2a2)/3); the three outermost O go to the midpoints of the three Sa–Sb
    bridges (greedy nearest assignment); of Sb's two downward O, the one whose Sc lies
    laterally nearest (``vertical`` = 0) or next nearest (1) to Sa is moved onto the Sa–Sc line at 1.61 Å from Sa (it becomes Sa's
    fourth bond and closes a three-membered Sa–Sb–Sc ring). Only a starting guess: the
    relaxation must form the bonds, and :func:`verify_dense_slab` checks the result.
    """
    if site not in (0, 1):
        raise ValueError(f"site must be 0 or 1, got {site}")
    s = slab.copy()
    sign = 1.0 if top else -1.0
    height = slab.positions[:, 2] * sign
    symbols = np.array(s.get_chemical_symbols())
    si = np.flatnonzero(symbols == "Si")
    ox = np.flatnonzero(symbols == "O")
    sa, sb = si[np.argsort(-height[si], kind="stable")[:2]]
    cell = s.cell.array
    a1, a2 = cell[0], cell[1]
    offset = ((2 * a1 + a2) / 3, (a1 + 2 * a2) / 3)[site]
    target = s.positions[sb] + offset
    target[2] = s.positions[sb, 2]
    s.positions[sa] = target
    images = np.array(
        [s.positions[sb] + i * a1 + j * a2 for i in range(-2, 3) for j in range(-2, 3)]
    )
    nearest = images[
        np.argsort(np.linalg.norm(images[:, :2] - target[:2], axis=1), kind="stable")[:3]
    ]
    bridges = 0.5 * (nearest + target)
    outer_o = ox[np.argsort(-height[ox], kind="stable")[:3]]
    free = list(range(3))
    for k in outer_o:
        dist = [
            np.linalg.norm(_lateral_min_image(s.positions[k, :2] - bridges[m, :2], a1[:2], a2[:2]))
            for m in free
        ]
        m = free.pop(int(np.argmin(dist)))
        s.positions[k] = bridges[m]
    # Sb's downward O (bonded to Sb, not among the outer three) and their other Si (Sc)
    i, j, shifts = bonds(slab)
    options = []
    for o_index, o_shift in zip(j[i == sb].tolist(), shifts[i == sb], strict=True):
        if o_index in set(outer_o.tolist()):
            continue
        p_o = slab.positions[o_index] + o_shift @ cell
        for sc, sc_shift in zip(j[i == o_index].tolist(), shifts[i == o_index], strict=True):
            if sc == sb:
                continue
            p_sc = p_o + (slab.positions[sc] + sc_shift @ cell - slab.positions[o_index])
            d = _lateral_min_image(p_sc[:2] - target[:2], a1[:2], a2[:2])
            options.append(
                (
                    float(np.linalg.norm(d)),
                    o_index,
                    target + np.array([d[0], d[1], p_sc[2] - target[2]]),
                )
            )
    options.sort(key=lambda item: (round(item[0], 6), item[1]))
    if len(options) > vertical:
        _, o_index, p_sc = options[vertical]
        u = (p_sc - target) / np.linalg.norm(p_sc - target)
        s.positions[o_index] = target + SI_O_BOND_ANGSTROM * u
    s.wrap()
    return s


def dense_candidates(slab: Atoms) -> list[tuple[tuple[int, int, int, int], Atoms]]:
    """The 16 seeded starts (top site, top vertical, bottom site, bottom vertical), fixed order."""
    out = []
    for ts in (0, 1):
        for tv in (0, 1):
            for bs in (0, 1):
                for bv in (0, 1):
                    seeded = seed_dense_face(seed_dense_face(slab, True, ts, tv), False, bs, bv)
                    out.append(((ts, tv, bs, bv), seeded))
    return out
