"""In-plane cells of slabs: reduced, oriented (a1 ∥ x, a2 in the x-y plane), and lattice maps.

Convention (the interface contract): cell vectors 1 and 2 are the in-plane primitive
vectors, Gauss-reduced (|a1| ≤ |a2| ≤ |a2 ± a1|) and taken obtuse (a1·a2 ≤ 0, e.g. 120°
for a hexagonal lattice, ASE's graphene convention), a1 along x, a2 with y > 0; cell
vector 3 is (0, 0, c); pbc = (True, True, False).
"""

from __future__ import annotations

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError

#: Relative tolerance for "same length" / "integer" tests of lattice vectors.
LATTICE_RTOL = 1e-6


def gauss_reduce(a1: np.ndarray, a2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gauss (Lagrange) reduction of a 2D basis, made obtuse (a1·a2 ≤ 0)."""
    a1, a2 = np.asarray(a1, float).copy(), np.asarray(a2, float).copy()
    while True:
        if a1 @ a1 > a2 @ a2:
            a1, a2 = a2, a1
        m = np.round((a1 @ a2) / (a1 @ a1))
        if m == 0:
            break
        a2 = a2 - m * a1
    if a1 @ a2 > 0:
        a2 = a2 - a1 if np.linalg.norm(a2 - a1) <= np.linalg.norm(a2) * (1 + 1e-9) else -a2
        if a1 @ a2 > 0:  # pragma: no cover - both choices acute cannot happen for a reduced basis
            a2 = -a2
    return a1, a2


def standard_slab(atoms: Atoms, vacuum_angstrom: float = 10.0) -> Atoms:
    """``atoms`` (periodic along cell vectors 1, 2) with a reduced, oriented in-plane cell.

    Positions are rotated rigidly so that the reduced a1 lies along x and the surface
    normal along +z (right-handed a1, a2), wrapped into the new cell; cell vector 3 is
    (0, 0, height + 2·vacuum), the lowest atom at z = vacuum. Per-atom arrays are kept.
    """
    cell = atoms.cell.array
    normal = np.cross(cell[0], cell[1])
    if np.linalg.norm(normal) < 1e-8:
        raise InputError("in-plane cell vectors 1 and 2 are degenerate")
    a1, a2 = gauss_reduce(cell[0], cell[1])
    n = normal / np.linalg.norm(normal)
    if np.cross(a1, a2) @ n < 0:  # right-handed about the normal, still reduced and obtuse
        a1, a2 = a2, a1
    ex = a1 / np.linalg.norm(a1)
    ey = np.cross(n, ex)
    rot = np.array([ex, ey, n])  # rows: new axes in old coordinates
    out = atoms.copy()
    out.calc = None
    out.positions = atoms.positions @ rot.T
    new_a1, new_a2 = a1 @ rot.T, a2 @ rot.T
    new_a1[2] = new_a2[2] = 0.0
    z = out.positions[:, 2]
    out.positions[:, 2] += vacuum_angstrom - z.min()
    c = float(np.ptp(z)) + 2.0 * vacuum_angstrom
    out.set_cell([new_a1, new_a2, [0.0, 0.0, c]], scale_atoms=False)
    out.pbc = (True, True, False)
    out.wrap()
    return out


def integer_matrix(target: np.ndarray, basis: np.ndarray, what: str) -> np.ndarray:
    """Integer matrix M with ``target = M @ basis`` (2×2 rows), or InputError naming ``what``."""
    m = np.asarray(target, float)[:, :2] @ np.linalg.inv(np.asarray(basis, float)[:, :2])
    r = np.round(m)
    if not np.allclose(m, r, atol=1e-5):
        raise InputError(f"{what}: the vectors are not lattice vectors of the slab's cell")
    return r.astype(int)


def lattice_is_invariant(cell2: np.ndarray, op: np.ndarray) -> bool:
    """True if the 2×2 linear map ``op`` (acting on column vectors) maps the lattice onto itself."""
    basis = np.asarray(cell2, float)[:, :2]
    image = (op @ basis.T).T
    m = image @ np.linalg.inv(basis)
    return bool(np.allclose(m, np.round(m), atol=1e-5) and abs(abs(np.linalg.det(m)) - 1) < 1e-5)


def is_hexagonal(cell2: np.ndarray) -> bool:
    """|a1| = |a2| and an angle of 60° or 120° between them."""
    a1, a2 = np.asarray(cell2, float)[0, :2], np.asarray(cell2, float)[1, :2]
    la, lb = np.linalg.norm(a1), np.linalg.norm(a2)
    cos = a1 @ a2 / (la * lb)
    return bool(abs(la - lb) < 1e-5 * la and abs(abs(cos) - 0.5) < 1e-5)


def rotation(angle_deg: float) -> np.ndarray:
    """2×2 counter-clockwise rotation about z."""
    t = np.radians(angle_deg)
    return np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])
