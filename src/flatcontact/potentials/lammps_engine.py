"""The LAMMPS engine: one in-process LAMMPS instance per calculator, positions updated in place.

Atom types: for each group g = 1..G (the ``slab`` array of an interface; one group for a
single slab) and each element e (sorted alphabetically), type = (g−1)·n_elements + index(e) + 1;
for the quartz interface 1 = O(slab 1), 2 = Si(slab 1), 3 = O(slab 2), 4 = Si(slab 2).

Pair style: ``hybrid/overlay`` with one instance of the intra-slab style per group, each
mapped with ``pair_coeff * * <style> <k> <file> ...`` to its own group's types and ``NULL``
for all others, plus ``lj/cut`` on the cross-group type pairs only. LAMMPS builds a skip
neighbour list for each sub-style containing only the atoms whose types that sub-style is
mapped to, so many-body terms (Vashishta three-body, Tersoff bond order, SNAP bispectrum)
of slab 1 never see slab 2 atoms and vice versa: the energy is exactly
E_intra(slab 1) + E_intra(slab 2) + E_LJ(cross) (tested).

Geometry: the in-plane cell (a1, a2) is mapped by an orthogonal 2×2 transform Q (rotation,
or reflection for a left-handed cell) onto LAMMPS's restricted triclinic form (a1 ∥ x,
a2 in the upper half plane, |xy| ≤ lx/2 after adding lattice vectors); positions are wrapped
into that box, forces are mapped back with Qᵀ. z is shrink-wrapped (``s``) unless periodic.
"""

from __future__ import annotations

import ctypes

import numpy as np
from ase.data import atomic_masses, atomic_numbers

from flatcontact.errors import InputError
from flatcontact.potentials.lammps_runtime import new_lammps
from flatcontact.potentials.lj import LJPair, pair_key


def _lammps_frame(cell: np.ndarray) -> tuple[np.ndarray, float, float, float]:
    """Orthogonal Q (2×2) with Q·a1 = (|a1|, 0), (Q·a2)_y > 0; and (lx, ly, xy) reduced tilt."""
    a1, a2 = cell[0, :2], cell[1, :2]
    lx = float(np.hypot(*a1))
    e1 = a1 / lx
    e2 = np.array([-e1[1], e1[0]])
    q = np.array([e1, e2])
    b2 = q @ a2
    if b2[1] < 0:  # left-handed cell: reflect y
        q[1] *= -1.0
        b2 = q @ a2
    xy = float(b2[0])
    xy = float(xy - lx * np.round(xy / lx))  # |xy| <= lx/2
    return q, lx, float(b2[1]), xy


class LammpsEngine:
    """Energy and forces of atoms split into groups, intra-group model + cross-group LJ.

    Parameters
    ----------
    resolved
        :class:`~flatcontact.potentials.spec.ResolvedIntra` with a LAMMPS style
        (``vashishta``, ``tersoff``, ``snap`` or ``none``).
    symbols
        Chemical symbols, one per atom (fixed order).
    groups
        Group (slab) index per atom, values 1..G.
    cell, pbc
        ASE cell (3×3) and pbc; cell vectors 1, 2 in the x-y plane; if periodic in z,
        cell vector 3 must be along z.
    lj_table, lj_cutoff_angstrom
        Cross-group LJ parameters keyed by element pair (``None``: no cross interaction).
    """

    def __init__(
        self, resolved, symbols, groups, cell, pbc, lj_table=None, lj_cutoff_angstrom=10.0
    ):
        self.symbols = list(symbols)
        self.groups = np.asarray(groups, dtype=int)
        self.elements = sorted(set(self.symbols))
        self.group_ids = sorted(set(self.groups.tolist()))
        self.n = len(self.symbols)
        cell = np.asarray(cell, dtype=float)
        self.pbc = tuple(bool(p) for p in pbc)
        if abs(cell[0, 2]) > 1e-8 or abs(cell[1, 2]) > 1e-8:
            raise InputError("LAMMPS engine: cell vectors 1 and 2 must lie in the x-y plane")
        if self.pbc[2] and (abs(cell[2, 0]) > 1e-8 or abs(cell[2, 1]) > 1e-8):
            raise InputError("LAMMPS engine: a z-periodic cell needs cell vector 3 along z")
        self.q, self.lx, self.ly, self.xy = _lammps_frame(cell)
        self.lz = float(cell[2, 2])
        ne = len(self.elements)
        gindex = {g: k for k, g in enumerate(self.group_ids)}
        eindex = {e: k for k, e in enumerate(self.elements)}
        self.types = np.array(
            [
                gindex[g] * ne + eindex[s] + 1
                for g, s in zip(self.groups.tolist(), self.symbols, strict=True)
            ],
            dtype=np.int32,
        )
        self.ntypes = ne * len(self.group_ids)
        self.lmp = new_lammps()
        try:
            self._setup(resolved, lj_table, lj_cutoff_angstrom)
        except Exception as exc:
            self.close()
            if isinstance(exc, InputError):
                raise
            raise InputError(
                f"LAMMPS could not set up the potential '{resolved.style}': {exc}"
            ) from None

    # ------------------------------------------------------------------ setup
    def _setup(self, resolved, lj_table, cutoff):
        lmp = self.lmp
        bnd = " ".join("p" if p else "s" for p in self.pbc)
        zlo, zhi = (0.0, self.lz) if self.pbc[2] else (-1.0, 1.0)
        lmp.commands_list(
            [
                "units metal",
                "atom_style atomic",
                "atom_modify map array sort 0 0.0",
                f"boundary {bnd}",
                f"region box prism 0 {self.lx:.17g} 0 {self.ly:.17g} {zlo:.17g} {zhi:.17g} {self.xy:.17g} 0 0 units box",
                f"create_box {self.ntypes} box",
            ]
        )
        ne = len(self.elements)
        for g in range(len(self.group_ids)):
            for k, e in enumerate(self.elements):
                lmp.command(f"mass {g * ne + k + 1} {atomic_masses[atomic_numbers[e]]:.17g}")
        ng = len(self.group_ids)
        cross = lj_table is not None and ng > 1
        style = resolved.style
        if style == "none" and not cross:
            raise InputError(
                "LAMMPS engine: nothing to compute (no intra model and no cross-slab LJ)"
            )
        if style != "none":
            unknown = set(self.elements) - set(resolved.elements or ())
            if unknown:
                raise InputError(
                    f"potential '{style}' has no parameters for element(s) {sorted(unknown)} "
                    f"(it knows {list(resolved.elements)})"
                )
        files = " ".join(resolved.files)

        def mapping(g: int) -> str:
            names = []
            for h in range(ng):
                names += self.elements if h == g else ["NULL"] * ne
            return " ".join(names)

        if style != "none" and not cross and ng == 1:
            lmp.command(f"pair_style {style}")
            lmp.command(f"pair_coeff * * {files} {mapping(0)}")
        elif style == "none":  # LJ only: plain lj/cut, zero within each group
            lmp.command(f"pair_style lj/cut {cutoff:.17g}")
            for g in range(ng):
                lo, hi = g * ne + 1, (g + 1) * ne
                lmp.command(f"pair_coeff {lo}*{hi} {lo}*{hi} 0.0 1.0")
            self._cross_coeffs(lj_table, "")
            lmp.command("pair_modify shift yes")
        else:
            substyles = [style] * ng + ([f"lj/cut {cutoff:.17g}"] if cross else [])
            lmp.command("pair_style hybrid/overlay " + " ".join(substyles))
            for g in range(ng):
                lmp.command(f"pair_coeff * * {style} {g + 1} {files} {mapping(g)}")
            if cross:
                self._cross_coeffs(lj_table, "lj/cut")
                lmp.command("pair_modify pair lj/cut shift yes")
        lmp.commands_list(
            [
                "neighbor 1.0 bin",
                "neigh_modify every 1 delay 0 check yes",
                "thermo_style custom pe",
                "thermo_modify norm no",
            ]
        )
        x = np.zeros((self.n, 3))
        ids = list(range(1, self.n + 1))
        self.lmp.create_atoms(self.n, ids, self.types.tolist(), x.ravel().tolist())
        self._xbuf = (ctypes.c_double * (3 * self.n))()

    def _cross_coeffs(self, lj_table, substyle: str) -> None:
        ne = len(self.elements)
        ng = len(self.group_ids)
        for g in range(ng):
            for h in range(g + 1, ng):
                for a, ea in enumerate(self.elements):
                    for b, eb in enumerate(self.elements):
                        ti, tj = sorted((g * ne + a + 1, h * ne + b + 1))
                        p: LJPair = lj_table[pair_key(ea, eb)]
                        self.lmp.command(
                            f"pair_coeff {ti} {tj} {substyle} {p.epsilon_ev:.17g} {p.sigma_angstrom:.17g}"
                        )

    # ------------------------------------------------------------------ evaluation
    def _to_box(self, positions: np.ndarray) -> np.ndarray:
        p = np.asarray(positions, dtype=float)
        xy = p[:, :2] @ self.q.T
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

    def compute(self, positions: np.ndarray) -> tuple[float, np.ndarray]:
        """Energy (eV) and forces (eV/Å, in the caller's frame) at ``positions`` (Å)."""
        box = self._to_box(positions)
        self._xbuf[:] = box.ravel().tolist()
        self.lmp.scatter_atoms("x", 1, 3, self._xbuf)
        self.lmp.command("run 0 post no")
        energy = float(self.lmp.get_thermo("pe"))
        f = np.ctypeslib.as_array(self.lmp.gather_atoms("f", 1, 3), shape=(3 * self.n,)).reshape(
            self.n, 3
        )
        forces = f.copy()
        forces[:, :2] = f[:, :2] @ self.q  # back to the caller's frame (Qᵀ applied row-wise)
        return energy, forces

    def close(self) -> None:
        lmp = getattr(self, "lmp", None)
        if lmp is not None:
            try:
                lmp.close()
            finally:
                self.lmp = None

    def __del__(self):  # pragma: no cover - best effort
        try:
            self.close()
        except Exception:
            pass
