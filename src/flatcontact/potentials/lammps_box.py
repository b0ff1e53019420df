"""The one LAMMPS box builder: an ASE cell, pbc and typed atoms -> a LAMMPS box with atoms.

Used by the interface engine (:mod:`flatcontact.potentials.lammps_engine`) and by the
single-body evaluations of training (:func:`flatcontact.training.lammps_bulk.setup_box`).

Two frames, chosen by the periodicity:

- **3D periodic** (bulk crystals): ASE's :class:`ase.calculators.lammps.Prism` rotates any
  cell onto LAMMPS's restricted triclinic form; positions are wrapped into the box.
- **slab/interface** (z not periodic): the in-plane cell (a1, a2) must lie in the x-y plane;
  an orthogonal 2×2 transform Q (rotation, or reflection for a left-handed cell) maps it onto
  LAMMPS's form (a1 ∥ x, a2 in the upper half plane, |xy| ≤ lx/2 after adding lattice
  vectors); positions are wrapped in-plane, z is shrink-wrapped (``s``), forces map back with Qᵀ.

Atom ids follow the order of the ASE atoms and LAMMPS never sorts them, so per-atom rows
map one-to-one. ``atom_style full`` boxes get molecule ids (interlayer potentials need one
per layer).
"""

from __future__ import annotations

import ctypes
from collections.abc import Sequence

import numpy as np
from ase.calculators.lammps import Prism
from ase.data import atomic_masses, atomic_numbers
from ase.units import bar

from flatcontact.foundation.errors import InputError

#: Voigt pairs in ASE order (xx, yy, zz, yz, xz, xy).
VOIGT_PAIRS = ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))

#: z bounds (Å) of a slab's box as created; the first setup shrink-wraps them to the atoms.
SLAB_Z_BOUNDS = (-1.0, 1.0)


def voigt_to_tensor(v: np.ndarray) -> np.ndarray:
    """Voigt 6-vector(s) ``(..., 6)`` (xx, yy, zz, yz, xz, xy) -> symmetric tensors ``(..., 3, 3)``."""
    v = np.asarray(v, dtype=float)
    t = np.empty((*v.shape[:-1], 3, 3))
    for k, (i, j) in enumerate(VOIGT_PAIRS):
        t[..., i, j] = v[..., k]
        t[..., j, i] = v[..., k]
    return t


def tensor_to_voigt(t: np.ndarray) -> np.ndarray:
    """Symmetric tensors ``(..., 3, 3)`` -> Voigt 6-vectors ``(..., 6)`` (xx, yy, zz, yz, xz, xy)."""
    t = np.asarray(t, dtype=float)
    return np.stack([t[..., i, j] for i, j in VOIGT_PAIRS], axis=-1)


def _inplane_frame(cell: np.ndarray) -> tuple[np.ndarray, float, float, float]:
    """Orthogonal Q (2×2) with Q·a1 = (|a1|, 0), (Q·a2)_y > 0; and (lx, ly, xy) reduced tilt.

    An a1 along ±x to round-off (|a1_y| within four ulps of |a1|: e.g. 1e-33 Å left by a
    cell's construction) is taken as exactly along it: Q is then ±I or a reflection, exactly,
    and the usual cell (a1 along +x) needs no rotation per call (``LammpsBox.same_frame``).
    The rotation dropped is below the round-off of applying it.
    """
    a1, a2 = cell[0, :2], cell[1, :2]
    lx = float(np.hypot(*a1))
    e1 = a1 / lx
    if abs(e1[1]) <= 4 * np.finfo(float).eps:
        e1 = np.array([np.copysign(1.0, e1[0]), 0.0])
    e2 = np.array([-e1[1], e1[0]])
    q = np.array([e1, e2])
    b2 = q @ a2
    if b2[1] < 0:  # left-handed cell: reflect y
        q[1] *= -1.0
        b2 = q @ a2
    xy = float(b2[0])
    xy = float(xy - lx * np.round(xy / lx))  # |xy| <= lx/2
    return q, lx, float(b2[1]), xy


class LammpsBox:
    """The frame between an ASE cell and its LAMMPS box (see the module docstring).

    Parameters
    ----------
    cell, pbc
        ASE cell (3×3, Å) and periodicity. Without full periodicity, cell vectors 1 and 2
        must lie in the x-y plane and a z-periodic cell needs cell vector 3 along z.
    """

    def __init__(self, cell, pbc):
        cell = np.asarray(cell, dtype=float)
        self._scratch = None  # (box, difference) arrays of place()
        self.pbc = tuple(bool(p) for p in pbc)
        self.bulk = all(self.pbc)
        if self.bulk:
            self.prism = Prism(cell)
            xhi, yhi, zhi, xy, xz, yz = (float(v) for v in self.prism.get_lammps_prism())
            self._lattice = (xhi, yhi, zhi, xy, xz, yz)
            return
        self.prism = None
        if abs(cell[0, 2]) > 1e-8 or abs(cell[1, 2]) > 1e-8:
            raise InputError("LAMMPS engine: cell vectors 1 and 2 must lie in the x-y plane")
        if self.pbc[2] and (abs(cell[2, 0]) > 1e-8 or abs(cell[2, 1]) > 1e-8):
            raise InputError("LAMMPS engine: a z-periodic cell needs cell vector 3 along z")
        self.q, self.lx, self.ly, self.xy = _inplane_frame(cell)
        # a1 along x (the usual cell): no rotation at all, exactly (saves two small products per call)
        self._aligned = bool(np.array_equal(self.q, np.eye(2)))
        self.lz = float(cell[2, 2])
        self._lattice = (self.lx, self.ly, self.lz if self.pbc[2] else 0.0, self.xy, 0.0, 0.0)

    @property
    def same_frame(self) -> bool:
        """Vectors (forces) need no conversion: a slab cell with a1 along x (LAMMPS's frame
        is the caller's)."""
        return not self.bulk and self._aligned

    def commands(self, type_elements: Sequence[str], atom_style: str = "atomic") -> list[str]:
        """``units`` … ``create_box`` and ``mass`` commands for types 1..len(type_elements)."""
        if self.bulk:
            xhi, yhi, zhi, xy, xz, yz = (float(v) for v in self.prism.get_lammps_prism())
            bnd = "p p p"
            region = (
                f"region box prism 0 {xhi!r} 0 {yhi!r} 0 {zhi!r} {xy!r} {xz!r} {yz!r} units box"
            )
        else:
            bnd = " ".join("p" if p else "s" for p in self.pbc)
            zlo, zhi = (0.0, self.lz) if self.pbc[2] else SLAB_Z_BOUNDS
            region = (
                f"region box prism 0 {self.lx:.17g} 0 {self.ly:.17g} {zlo:.17g} {zhi:.17g} "
                f"{self.xy:.17g} 0 0 units box"
            )
        lines = [
            "units metal",
            f"atom_style {atom_style}",
            "atom_modify map array sort 0 0.0",
            f"boundary {bnd}",
            region,
            f"create_box {len(type_elements)} box",
        ]
        lines += [
            f"mass {k + 1} {float(atomic_masses[atomic_numbers[e]]):.17g}"
            for k, e in enumerate(type_elements)
        ]
        return lines

    def to_lammps(self, positions: np.ndarray) -> np.ndarray:
        """Positions (Å, caller's frame) -> wrapped LAMMPS box coordinates."""
        p = np.asarray(positions, dtype=float)
        if self.bulk:
            return self.prism.vector_to_lammps(p, wrap=True)
        xy = p[:, :2] if self._aligned else p[:, :2] @ self.q.T
        # fractional along LAMMPS's (a1, a2) = ((lx, 0), (xy, ly)), wrapped into [0, 1)
        fb = xy[:, 1] / self.ly
        fa = (xy[:, 0] - fb * self.xy) / self.lx
        fa -= np.floor(fa)
        fb -= np.floor(fb)
        out = np.empty_like(p)
        out[:, 0] = fa * self.lx + fb * self.xy
        out[:, 1] = fb * self.ly
        out[:, 2] = p[:, 2] - (np.floor(p[:, 2] / self.lz) * self.lz if self.pbc[2] else 0.0)
        return out

    def nearest_images(self, box: np.ndarray, current: np.ndarray) -> np.ndarray:
        """``box`` (LAMMPS frame, Å) moved by lattice vectors onto the images nearest to
        ``current`` (LAMMPS's own coordinates), in place; returns ``box``.

        :meth:`to_lammps` wraps into [0, 1) along each periodic axis, LAMMPS remaps into its
        box only when it rebuilds the neighbour lists; an atom on the cell's boundary (a
        lattice site at fractional 0, or one that crossed since the last rebuild) can sit at
        the other image in each. Handing LAMMPS the other image moves that atom by a lattice
        vector, more than half the skin, and forces a neighbour rebuild on every call
        (measured: 7 ms of 11 per call on a 4,704-atom Cu(111) cell). With the nearest images
        LAMMPS rebuilds only when atoms really moved, as in its own minimiser. Lattice
        vectors of the LAMMPS box: a = (lx, 0, 0), b = (xy, ly, 0), c = (xz, yz, lz) (c only
        when z is periodic).
        """
        lx, ly, lz, xy, xz, yz = self._lattice
        d = box - current
        if np.abs(d).max() < 0.25 * min(lx, ly, lz or np.inf):  # nothing crossed (usual)
            return box
        nc = np.round(d[:, 2] / lz) if lz else np.zeros(len(d))
        nb = np.round((d[:, 1] - nc * yz) / ly)
        na = np.round((d[:, 0] - nb * xy - nc * xz) / lx)
        box[:, 0] -= na * lx + nb * xy + nc * xz
        box[:, 1] -= nb * ly + nc * yz
        box[:, 2] -= nc * lz
        return box

    def place(self, positions: np.ndarray, current: np.ndarray, offsets: np.ndarray) -> None:
        """Write ``positions`` (Å, caller's frame) into ``current`` (LAMMPS's own coordinates,
        modified in place) at the images nearest to ``current``.

        ``offsets`` (n, 3, LAMMPS frame, Å; the caller keeps it between calls, zeros at first)
        holds the lattice vector by which each atom's LAMMPS copy differs from the caller's
        (an atom at a lattice site on the cell boundary, or one LAMMPS re-wrapped at a
        neighbour rebuild). A relaxation step moves atoms by far less than a quarter of the
        cell, so usually the positions go in as positions + offsets without any wrapping:
        one subtraction checks that no atom is a lattice vector away from LAMMPS's copy.
        Otherwise (a first call, a re-wrap) the images come from :meth:`nearest_images` and
        ``offsets`` is updated. 3D-periodic cells: :meth:`to_lammps` then
        :meth:`nearest_images`, every call.
        """
        if self.bulk:
            current[...] = self.nearest_images(self.to_lammps(positions), current)
            return
        p = np.asarray(positions, dtype=float)
        if not self._aligned:
            p = p.copy()
            p[:, :2] = positions[:, :2] @ self.q.T
        # two scratch arrays kept between calls: a fresh (n, 3) array per call costs more than
        # the arithmetic on a large cell (the allocator returns and re-faults its pages)
        if self._scratch is None or self._scratch[0].shape != p.shape:
            self._scratch = (np.empty(p.shape), np.empty(p.shape))
        box, d = self._scratch
        np.add(p, offsets, out=box)
        np.subtract(current, box, out=d)
        lx, ly, lz = self._lattice[:3]
        if max(d.max(), -d.min()) >= 0.25 * min(lx, ly, lz or np.inf):  # an atom crossed
            box = self.nearest_images(box, current)
            np.subtract(box, p, out=offsets)
        current[...] = box

    def vectors_to_lammps(self, v: np.ndarray) -> np.ndarray:
        """Per-atom vectors (or positions, unwrapped) from the caller's frame to LAMMPS's
        (slab frame: the in-plane rotation Q; a new array)."""
        v = np.array(v, dtype=float)
        if self.bulk:
            return self.prism.vector_to_lammps(v)
        if not self._aligned:
            v[:, :2] = v[:, :2] @ self.q.T
        return v

    def vectors_to_caller(self, f: np.ndarray) -> np.ndarray:
        """Per-atom vectors (forces) from the LAMMPS frame back to the caller's."""
        f = np.asarray(f, dtype=float)
        if self.bulk:
            return self.prism.vector_to_ase(f)
        out = f.copy()
        if not self._aligned:
            out[:, :2] = f[:, :2] @ self.q  # Qᵀ applied row-wise
        return out

    def stress_to_caller(self, pressure_voigt_bar: Sequence[float]) -> np.ndarray:
        """LAMMPS pressure tensor (bar; pxx, pyy, pzz, pyz, pxz, pxy) -> ASE stress (eV/Å³, Voigt).

        ASE's sign: stress = −pressure (positive = tensile). Only for 3D-periodic boxes.
        """
        if not self.bulk:
            raise InputError("stress is only defined for a 3D-periodic cell")
        tensor = voigt_to_tensor(np.asarray(pressure_voigt_bar, dtype=float))
        return tensor_to_voigt(-self.prism.tensor2_to_ase(tensor) * bar)


def create_box(
    lmp,
    cell,
    pbc,
    types: Sequence[int],
    type_elements: Sequence[str],
    atom_style: str = "atomic",
    molecules: Sequence[int] | None = None,
    positions: np.ndarray | None = None,
    charges: Sequence[float] | None = None,
) -> LammpsBox:
    """Create the box and atoms in the empty LAMMPS instance ``lmp``; return the frame.

    Parameters
    ----------
    types
        LAMMPS type (1-based) of each atom, in the atoms' order; ``type_elements[t - 1]`` is
        the element of type ``t`` (its mass is set from ASE's table).
    atom_style
        ``atomic``, or ``full`` for styles that need molecule ids (``molecules``, one per atom)
        or charges (``charges``, e, one per atom).
    positions
        Initial positions (caller's frame); zeros when not given (set before the first run).
    """
    box = LammpsBox(cell, pbc)
    lmp.commands_list(box.commands(type_elements, atom_style))
    n = len(types)
    x = np.zeros((n, 3)) if positions is None else box.to_lammps(positions)
    lmp.create_atoms(n, list(range(1, n + 1)), [int(t) for t in types], x.ravel().tolist())
    if molecules is not None:
        if atom_style != "full":
            raise InputError("molecule ids need atom_style full")
        buf = (ctypes.c_int * n)(*[int(m) for m in molecules])
        lmp.scatter_atoms("molecule", 0, 1, buf)
    if charges is not None:
        if atom_style != "full":
            raise InputError("charges need atom_style full")
        lmp.scatter_atoms("q", 1, 1, (ctypes.c_double * n)(*[float(q) for q in charges]))
    return box
