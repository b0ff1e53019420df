"""Common in-plane cells of two slabs: identity, commensurate twist, coincidence lattice (ZSL).

A :class:`Match` gives integer supercell matrices P1, P2 (rows: supercell vectors in the
slab's own in-plane basis, T_i = P_i·A_i) and the common cell C. Each slab's supercell
is mapped onto C by the linear map F_i (C = T_i·F_iᵀ); F_i = R_i·U_i (polar
decomposition): R_i a rotation (the twist put on slab i), U_i − 1 the strain put on it
(principal values reported, in %).

- Same lattice, no twist: P1 = P2 = 1, F = 1.
- Commensurate twist (m, n) of a hexagonal lattice (Lopes dos Santos, Peres & Castro
  Neto, PRL 99, 256802 (2007); Shallcross et al., PRB 81, 165105 (2010)): with the 60°
  basis b1 = a1, b2 = a1 + a2, slab 1's supercell is T1 = m·b1 + n·b2, T2 = R60·T1, and
  slab 2 (rotated by θ) uses n·b1 + m·b2: cos θ = (m² + 4mn + n²) / (2(m² + mn + n²)),
  m² + mn + n² primitive cells per layer, no strain. (1, 2): θ = 21.787°, 7 cells.
- Hetero-interfaces: Zur & McGill coincidence lattices (J. Appl. Phys. 55, 378 (1984)),
  ``pymatgen.analysis.interfaces.zsl.ZSLGenerator``; the smallest match (fewest atoms,
  then least strain) whose strains and atom count are within the bounds. The strain is
  put on slab 2 (``strain_on="slab2"``: slab 1 keeps its lattice) or shared
  (``"both"``: C is the mean of the two aligned supercells).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from ase import Atoms
from ase.build import make_supercell

from flatcontact.foundation import limits
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.limits import Deadline
from flatcontact.structures.cell2d import (
    integer_matrix,
    is_hexagonal,
    lattice_is_invariant,
    rotation,
)


@dataclass(frozen=True)
class Match:
    """Supercells of the two slabs on one common in-plane cell (see module docstring)."""

    p1: np.ndarray  # 2×2 int
    p2: np.ndarray  # 2×2 int
    cell: np.ndarray  # 2×2 common cell (rows), Å
    kind: str  # "identity" | "twist" | "coincidence"

    def deformation(self, which: int, a: np.ndarray) -> np.ndarray:
        """F_i (2×2, column convention) with C = T_i·F_iᵀ for slab ``which`` of in-plane cell ``a``."""
        p = self.p1 if which == 1 else self.p2
        t = p @ np.asarray(a, float)[:, :2]
        return np.linalg.solve(t, self.cell).T

    def report(self, a1: np.ndarray, a2: np.ndarray, n1: int, n2: int) -> dict:
        """JSON-ready record: matrices, common cell, strain and rotation per slab, atom count."""
        out = {
            "kind": self.kind,
            "slab1_supercell": self.p1.tolist(),
            "slab2_supercell": self.p2.tolist(),
            "common_cell_angstrom": np.round(self.cell, 6).tolist(),
            "n_atoms": atom_count(self, n1, n2),
        }
        for which, a in ((1, a1), (2, a2)):
            strains, angle = strain_and_rotation(self.deformation(which, a))
            out[f"slab{which}_strain_percent"] = [round(100 * s, 6) for s in strains]
            out[f"slab{which}_rotation_deg"] = round(angle, 6)
        return out


def strain_and_rotation(f: np.ndarray) -> tuple[list[float], float]:
    """Principal strains (U − 1 eigenvalues, ascending) and rotation angle (deg) of F = R·U."""
    u_sq = f.T @ f
    w, v = np.linalg.eigh(u_sq)
    u = v @ np.diag(np.sqrt(w)) @ v.T
    r = f @ np.linalg.inv(u)
    return [float(s) - 1.0 for s in np.sqrt(w)], float(np.degrees(np.arctan2(r[1, 0], r[0, 0])))


def atom_count(match: Match, n1: int, n2: int) -> int:
    """Atoms of the interface: n_i atoms per primitive cell of slab i times det P_i."""
    return round(float(n1 * abs(np.linalg.det(match.p1)) + n2 * abs(np.linalg.det(match.p2))))


def identity_match(a: np.ndarray) -> Match:
    """Both slabs on the same primitive cell."""
    eye = np.eye(2, dtype=int)
    return Match(eye, eye.copy(), np.asarray(a, float)[:, :2].copy(), "identity")


def twist_angle_deg(m: int, n: int) -> float:
    """Commensurate twist angle of a hexagonal bilayer: cos θ = (m² + 4mn + n²)/(2(m² + mn + n²))."""
    return float(
        np.degrees(np.arccos((m * m + 4 * m * n + n * n) / (2.0 * (m * m + m * n + n * n))))
    )


def twist_match(a: np.ndarray, m: int, n: int, field: str = "twist") -> tuple[Match, float]:
    """The commensurate (m, n) twist of a hexagonal lattice ``a`` (rows, 120° convention).

    Returns the match (slab 2's supercell maps onto slab 1's by a pure rotation θ) and θ in
    degrees (counter-clockwise rotation of slab 2).
    """
    a = np.asarray(a, float)[:, :2]
    if not is_hexagonal(a):
        raise InputError(f"{field}: a commensurate twist needs a hexagonal in-plane lattice")
    if not (
        isinstance(m, int) and isinstance(n, int) and m >= 0 and n >= 0 and m != n and m + n > 0
    ):
        raise InputError(f"{field}=[{m}, {n}]: expected two different non-negative integers")
    b1, b2 = a[0], a[0] + a[1]
    if abs(np.degrees(np.arccos(b1 @ b2 / (b1 @ b1))) - 60.0) > 1e-4:
        b2 = a[1]  # the cell was given in the 60° convention already
    basis = np.array([b1, b2])
    t = np.array([[m, n], [-n, m + n]]) @ basis
    v = np.array([[n, m], [-m, m + n]]) @ basis
    p1 = integer_matrix(t, a, field)
    p2 = integer_matrix(v, a, field)
    cross = v[0, 0] * t[0, 1] - v[0, 1] * t[0, 0]
    theta = float(np.degrees(np.arctan2(cross, v[0] @ t[0])))
    return Match(p1, p2, t, "twist"), theta


def check_search_size(max_atoms: int, field: str) -> None:
    """Refuse a search for cells above the ``atoms`` bound (:mod:`flatcontact.foundation.limits`) before
    it starts: its candidates grow with the square of the largest cell."""
    if max_atoms > limits.bound("atoms"):
        raise InputError(
            f"{field}: " + limits.message("atoms", max_atoms, "atoms of the largest cell searched")
        )


def _deadline(field: str, max_atoms: int, max_strain: float) -> Deadline:
    return Deadline(
        f"{field}: the coincidence search (cells of at most {max_atoms} atoms, strain at most "
        f"{100 * max_strain:g} %)",
        "lower the atom bound (match.max_atoms, approximants.max_atoms) or raise the strain "
        "bound (match.max_strain_percent, approximants.strain_percent)",
    )


def coincidence_match(
    a1: np.ndarray,
    a2: np.ndarray,
    n1: int,
    n2: int,
    *,
    max_strain: float,
    max_atoms: int,
    strain_on: str = "slab2",
    field: str = "slab2",
    orientation_deg: tuple[float, float] | None = None,
) -> Match:
    """The smallest coincidence lattice of slabs with in-plane cells ``a1`` (below) and ``a2``.

    ``n1``, ``n2``: atoms per primitive in-plane cell of each slab (all its layers). The
    accepted match has every principal strain of both slabs ≤ ``max_strain`` (a fraction)
    and at most ``max_atoms`` atoms; with ``orientation_deg`` = (target, tolerance) also
    the rotation it puts on slab 2 within the tolerance of the target, modulo the rotation
    symmetry of slab 2's lattice (:func:`oriented_coincidence_match`, a direct search in
    place of the ZSL enumeration). InputError naming ``field`` when none exists.
    """
    from pymatgen.analysis.interfaces.zsl import ZSLGenerator

    if strain_on not in ("slab2", "both"):
        raise InputError(f"strain_on='{strain_on}': expected slab2 or both")
    a1 = np.asarray(a1, float)[:, :2]
    a2 = np.asarray(a2, float)[:, :2]
    check_search_size(max_atoms, field)
    if orientation_deg is not None:
        found = oriented_coincidence_match(
            a1,
            a2,
            n1,
            n2,
            max_strain=max_strain,
            max_atoms=max_atoms,
            target_deg=orientation_deg[0],
            tolerance_deg=orientation_deg[1],
            strain_on=strain_on,
            deadline=_deadline(field, max_atoms, max_strain),
        )
        if found is None:
            raise InputError(
                f"{field}: no coincidence lattice with strain <= {100 * max_strain:g}% on each "
                f"slab, <= {max_atoms} atoms and slab 2 rotated {orientation_deg[0]:g} ± "
                f"{orientation_deg[1]:g}° (raise the strain or atom bound)"
            )
        return found
    area1, area2 = abs(np.linalg.det(a1)), abs(np.linalg.det(a2))
    density = n1 / area1 + n2 / area2
    max_area = max_atoms / density * (1.0 + max_strain) ** 2
    deadline = _deadline(field, max_atoms, max_strain)
    gen = ZSLGenerator(
        max_area_ratio_tol=(1.0 + max_strain) ** 2 - 1.0,
        max_area=max_area,
        max_length_tol=max_strain,
        max_angle_tol=max_strain,
    )
    pad = np.zeros((2, 1))
    best: tuple | None = None
    best_area = None
    for zm in gen(np.hstack([a2, pad]), np.hstack([a1, pad])):
        deadline.check()
        area = float(zm.match_area)
        if best_area is not None and area > best_area * (1.0 + 1e-6):
            break
        f0 = np.asarray(zm.film_sl_vectors, float)[:, :2]
        s0 = np.asarray(zm.substrate_sl_vectors, float)[:, :2]
        for f, s in _proper_pairs(f0, s0, a2):
            try:
                p1 = integer_matrix(s, a1, field)
                p2 = integer_matrix(f, a2, field)
            except InputError:
                continue
            match = Match(p1, p2, common_cell(s, f, strain_on), "coincidence")
            worst = max(
                max(abs(x) for x in strain_and_rotation(match.deformation(k, a))[0])
                for k, a in ((1, a1), (2, a2))
            )
            n_atoms = atom_count(match, n1, n2)
            if worst > max_strain + 1e-12 or n_atoms > max_atoms:
                continue
            # ties (same size and strain, e.g. the 0.3 % diamond(111)/graphene cells at 9.18°
            # and 18.61°): the smaller rotation modulo slab 2's lattice symmetry, whatever
            # representative pymatgen's enumeration yields
            rotation = strain_and_rotation(match.deformation(2, a2))[1]
            rotation_deg = abs(orientation_error_deg(rotation, 0.0, a2))
            key = (n_atoms, round(worst, 9), round(rotation_deg, 6))
            if best is None or key < best[0]:
                best, best_area = (key, match), area
    if best is None:
        raise InputError(
            f"{field}: no coincidence lattice with strain <= {100 * max_strain:g}% on each slab "
            f"and <= {max_atoms} atoms (raise match.max_strain or match.max_atoms)"
        )
    return _without_lattice_rotation(best[1], a2, field)


def _proper_pairs(f: np.ndarray, s: np.ndarray, a2: np.ndarray):
    """The ZSL pair ``(f, s)`` (film = slab 2, substrate = slab 1 supercell vectors) as
    pairs of one handedness, so that the map from one to the other is a rotation.

    A pair of opposite handedness (the map would be a reflection) is not dropped: the film's
    vectors swapped (same lengths when its reduced cell is hexagonal or square, paired the
    other way) and, when slab 2's lattice has a mirror, the film's pair through that mirror
    (another pair of its lattice vectors, same lengths and angle) are both proper candidates;
    the strain check decides. (pymatgen 2026.10 yields only reflected pairs for the 0.3 %
    diamond(111)/graphene cell, which the approximant study then lost.)
    """
    if np.linalg.det(f) * np.linalg.det(s) > 0:
        candidates = [f]
    else:
        mirror = lattice_mirror(a2)
        candidates = [f[::-1]] + ([] if mirror is None else [f @ mirror.T])
    for fc in candidates:
        if np.linalg.det(s) < 0:
            yield fc[::-1], s[::-1]
        else:
            yield fc, s


def lattice_mirror(cell2: np.ndarray) -> np.ndarray | None:
    """A mirror (2×2, acting on column vectors) that maps the 2D lattice ``cell2`` onto
    itself, or None: the reflections across the lines of ``a1``, ``a2``, ``a1 ± a2`` and their
    normals are tried (every 2D Bravais lattice with a mirror has one of these among its
    mirror lines)."""
    a = np.asarray(cell2, float)[:, :2]
    for v in (a[0], a[1], a[0] + a[1], a[0] - a[1]):
        for phi in (np.arctan2(v[1], v[0]), np.arctan2(v[1], v[0]) + 0.5 * np.pi):
            c, s = np.cos(2 * phi), np.sin(2 * phi)
            m = np.array([[c, s], [s, -c]])
            if lattice_is_invariant(a, m):
                return m
    return None


def rotation_symmetry_deg(cell2: np.ndarray) -> float:
    """The smallest rotation (deg) that maps the 2D lattice ``cell2`` onto itself: 60
    (hexagonal), 90 (square) or 180 (any lattice)."""
    for angle in (60.0, 90.0):
        if lattice_is_invariant(cell2, rotation(angle)):
            return angle
    return 180.0


def orientation_error_deg(rotation_deg: float, target_deg: float, cell2: np.ndarray) -> float:
    """``rotation_deg`` − ``target_deg`` reduced modulo the rotation symmetry of the lattice
    ``cell2`` into [−s/2, s/2) (rotations that differ by a symmetry give the same lattice)."""
    sym = rotation_symmetry_deg(cell2)
    return float((rotation_deg - target_deg + 0.5 * sym) % sym - 0.5 * sym)


def oriented_coincidence_match(
    a1: np.ndarray,
    a2: np.ndarray,
    n1: int,
    n2: int,
    *,
    max_strain: float,
    max_atoms: int,
    target_deg: float,
    tolerance_deg: float,
    strain_on: str = "slab2",
    deadline: Deadline | None = None,
) -> Match | None:
    """The smallest compact coincidence cell that rotates slab 2 by ``target_deg`` ±
    ``tolerance_deg`` (modulo its lattice's rotation symmetry), or None.

    A direct search: every vector v of slab 1's lattice no longer than R = √(2·A_max)
    (A_max: the area of ``max_atoms`` atoms, strained) is paired with the nearest vector u
    of slab 2's lattice rotated by the target; v is a candidate when |v|/|u| − 1 is within
    ``max_strain`` and the angle between them within the tolerance plus asin(max_strain).
    Every right-handed Gauss-reduced pair of candidates (increasing area) is a cell; the
    first areas whose principal strains (:func:`common_cell` with ``strain_on``) are all
    within ``max_strain`` and whose rotation of slab 2 is within the tolerance give the
    match (fewest atoms, then least strain, then least angle error). Cells with a reduced
    vector longer than R (aspect ratio above about 2 at A_max) are not searched.
    """
    a1 = np.asarray(a1, float)[:, :2]
    a2 = np.asarray(a2, float)[:, :2]
    area1, area2 = abs(np.linalg.det(a1)), abs(np.linalg.det(a2))
    density = n1 / area1 + n2 / area2
    max_area = max_atoms / density * (1.0 + max_strain) ** 2
    radius = float(np.sqrt(2.0 * max_area))
    nmax = int(np.ceil(radius / np.linalg.svd(a1, compute_uv=False).min())) + 1
    r = np.arange(-nmax, nmax + 1)
    p = np.array(np.meshgrid(r, r, indexing="ij")).reshape(2, -1).T
    v = p @ a1
    length = np.linalg.norm(v, axis=1)
    keep = (length > 1e-9) & (length <= radius)
    p, v, length = p[keep], v[keep], length[keep]
    b2 = a2 @ rotation(target_deg).T  # slab 2's lattice rotated by the target (rows)
    w = np.round(v @ np.linalg.inv(b2)).astype(int)
    u = w @ b2
    ulen = np.linalg.norm(u, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = length / ulen
        cos = np.einsum("ij,ij->i", v, u) / (length * ulen)
    angle = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    slack = tolerance_deg + np.degrees(np.arcsin(min(max_strain, 1.0))) + 1e-9
    ok = (ulen > 1e-9) & (np.abs(ratio - 1.0) <= max_strain + 1e-12) & (angle <= slack)
    p, v, w, length = p[ok], v[ok], w[ok], length[ok]
    if len(p) < 2:
        return None
    order = np.argsort(length, kind="stable")
    p, v, w, length = p[order], v[order], w[order], length[order]
    pairs = []
    for i in range(len(v)):
        if deadline is not None:
            deadline.check()
        cross = v[i, 0] * v[:, 1] - v[i, 1] * v[:, 0]
        dot = v @ v[i]
        j = np.nonzero(
            (cross > 1e-9)
            & (length >= length[i] - 1e-9)
            & (np.abs(dot) <= 0.5 * length[i] ** 2 + 1e-9)
            & (cross <= max_area * (1 + 1e-9))
        )[0]
        pairs += [(float(cross[k]), i, int(k)) for k in j]
    pairs.sort()
    best, best_area = None, None
    for area, i, k in pairs:
        if best_area is not None and area > best_area * (1.0 + 1e-6):
            break
        if deadline is not None:
            deadline.check()
        p1 = np.array([p[i], p[k]])
        p2 = np.array([w[i], w[k]])
        if round(np.linalg.det(p2)) <= 0:
            continue
        match = Match(p1, p2, common_cell(p1 @ a1, p2 @ a2, strain_on), "coincidence")
        worst = max(
            max(abs(x) for x in strain_and_rotation(match.deformation(which, a))[0])
            for which, a in ((1, a1), (2, a2))
        )
        rot = strain_and_rotation(match.deformation(2, a2))[1]
        error = abs(orientation_error_deg(rot, target_deg, a2))
        n_atoms = atom_count(match, n1, n2)
        if worst > max_strain + 1e-12 or error > tolerance_deg + 1e-9 or n_atoms > max_atoms:
            continue
        key = (n_atoms, round(worst, 9), round(error, 6))
        if best is None or key < best[0]:
            best, best_area = (key, match), area
    return None if best is None else best[1]


def common_cell(s: np.ndarray, f: np.ndarray, strain_on: str) -> np.ndarray:
    """The common cell (2×2 rows, Å) of slab 1's supercell ``s`` and slab 2's ``f``:
    ``s`` itself (``strain_on="slab2"``) or the mean of ``s`` and ``f`` rotated onto it by
    the rotation of the polar decomposition (``"both"``)."""
    if strain_on == "slab2":
        return np.asarray(s, float).copy()
    rot, _ = _polar(np.linalg.solve(f, s).T)
    return 0.5 * (s + f @ rot.T)


def explicit_match(
    a1: np.ndarray,
    a2: np.ndarray,
    p1,
    p2,
    *,
    max_strain: float,
    strain_on: str = "slab2",
    field: str = "match",
) -> Match:
    """The coincidence lattice of the given supercells P1, P2 (2×2 int, rows in each slab's
    own basis): the cell :func:`coincidence_match` would make of them.

    InputError naming ``field`` when a principal strain of either slab exceeds
    ``max_strain`` (a fraction) or a supercell is degenerate or left-handed.
    """
    if strain_on not in ("slab2", "both"):
        raise InputError(f"strain_on='{strain_on}': expected slab2 or both")
    a1 = np.asarray(a1, float)[:, :2]
    a2 = np.asarray(a2, float)[:, :2]
    p1, p2 = np.asarray(p1, int), np.asarray(p2, int)
    for which, p in (("slab1", p1), ("slab2", p2)):
        if p.shape != (2, 2) or round(np.linalg.det(p)) <= 0:
            raise InputError(
                f"{field}.{which}_supercell={p.tolist()}: expected a 2×2 integer matrix of "
                "positive determinant (right-handed supercell)"
            )
    s, f = p1 @ a1, p2 @ a2
    match = Match(p1, p2, common_cell(s, f, strain_on), "coincidence")
    for which, a in ((1, a1), (2, a2)):
        strains, _ = strain_and_rotation(match.deformation(which, a))
        worst = max(abs(x) for x in strains)
        if worst > max_strain + 1e-9:
            raise InputError(
                f"{field}.slab{which}_supercell: the cell strains slab {which} by "
                f"{100 * worst:.4g}% > max_strain_percent={100 * max_strain:g}"
            )
    return match


def _without_lattice_rotation(match: Match, a2: np.ndarray, field: str) -> Match:
    """The same match with slab 2's supercell re-chosen so that it is not rotated, when the
    rotation the match puts on slab 2 is a symmetry of slab 2's lattice (e.g. 60° hexagonal)."""
    angle = strain_and_rotation(match.deformation(2, a2))[1]
    if abs(angle) < 1e-6 or not lattice_is_invariant(a2, rotation(angle)):
        return match
    t2 = match.p2 @ a2
    p2 = integer_matrix(t2 @ rotation(angle).T, a2, field)
    return Match(match.p1, p2, match.cell, match.kind)


def _polar(f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    u_sq = f.T @ f
    w, v = np.linalg.eigh(u_sq)
    u = v @ np.diag(np.sqrt(w)) @ v.T
    return f @ np.linalg.inv(u), u


def apply_supercell(slab: Atoms, p: np.ndarray, cell: np.ndarray) -> Atoms:
    """``slab``'s supercell P (2×2 int) mapped onto the common in-plane ``cell`` (fractions kept).

    Heights are unchanged; per-atom arrays are kept.
    """
    p3 = np.eye(3, dtype=int)
    p3[:2, :2] = p
    big = make_supercell(slab, p3, wrap=True)
    new = big.cell.array.copy()
    new[0, :2], new[1, :2] = cell[0], cell[1]
    new[0, 2] = new[1, 2] = 0.0
    big.set_cell(new, scale_atoms=True)
    big.wrap()
    return big
