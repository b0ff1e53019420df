"""The shift-space group of an interface: which lateral shifts of slab 2 give the same interface.

Convention: the interface at fractional shift ``s = (s_a, s_b)`` is the reference with slab 2
moved by ``d = L s`` (``L`` the 2×2 matrix of columns a1, a2, Å;
:func:`flatcontact.structures.placement.place_slab2`). A *shift operation* ``g = (M, t)``
maps ``s`` to ``g·s = M s + t`` (mod 1), ``M`` a 2×2 integer matrix in the fractional basis,
``t`` a fractional translation. It belongs to the group when a Euclidean operation of space
``x ↦ W x + τ(s)`` (``W = diag(R, σ)``, ``R`` a 2-D point operation of the lattice, ``σ = ±1``)
maps the whole stack at ``s`` onto the stack at ``g·s``, modulo the in-plane lattice and a
permutation of atoms that keeps the species, the held flag and the layer partition (so the
scan's constraints and, in ``rigid-layers`` mode, its rigid bodies are mapped onto themselves).
Every relaxation mode of the scan (full, normal = along z only, rigid layers, rigid) is
invariant under such an operation, so the relaxed energy and normal load are equal at ``s``
and ``g·s``: E(g·s) = E(s).

Two kinds, from the symmetry of each slab (Cartesian, in-plane translations mod the lattice):

- ``σ = +1`` (slabs stay in place): ``R S₁ + τ₁ ≡ S₁`` and ``R S₂ + τ₂ ≡ S₂`` with the same
  ``R``; then ``g·s = M s + L⁻¹(τ₁ − τ₂)`` with ``M = L⁻¹ R L``.
- ``σ = −1`` (the operation swaps the slabs, e.g. a two-fold axis in the interface plane):
  ``W S₁ + τ_a ≡ S₂`` and ``W S₂ + τ_b ≡ S₁`` with equal z-components of ``τ_a``, ``τ_b``;
  then ``g·s = −M s + L⁻¹(τ_b − τ_a)`` (derivation: apply ``τ = τ_b − R d`` to the stack at
  ``d``). This assumes both slabs see the same potential (the same interaction model on
  either side, as every bundled preset); the scan's verification relaxations catch a model
  that is not.

Each candidate is then checked on the atoms: the stack at two generic shifts, mapped by
the Euclidean operation, must coincide with the stack at ``g·s`` to
``tolerance_angstrom``. Only operations that map the scan's lateral grid onto itself
(:meth:`ShiftGroup.for_grid`) are used by a scan.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from itertools import product

import numpy as np
from ase import Atoms
from scipy.spatial import cKDTree

from flatcontact.structures.interface_contract import fixed_mask, in_plane_vectors
from flatcontact.structures.placement import place_slab2

#: Default largest displacement (Å) between an atom mapped by an operation and its image.
DEFAULT_TOLERANCE_ANGSTROM = 1e-3
#: Generic shifts at which every candidate operation is checked on the whole stack.
_CHECK_SHIFTS = ((0.1370, 0.2910), (0.6180, 0.0730))


@dataclass(frozen=True)
class ShiftOperation:
    """One operation ``s ↦ M s + t`` (mod 1) of the shift-space group (fractional basis)."""

    matrix: tuple[tuple[int, int], tuple[int, int]]  #: M, integer 2×2
    translation: tuple[float, float]  #: t, fractional, in [0, 1)
    swaps_slabs: bool  #: the space operation exchanges slab 1 and slab 2 (σ = −1)

    def apply(self, s: np.ndarray) -> np.ndarray:
        """``g·s`` reduced into [0, 1) for fractional shifts ``s`` (…, 2)."""
        s = np.asarray(s, dtype=float)
        out = s @ np.asarray(self.matrix, float).T + np.asarray(self.translation)
        return out - np.floor(out + 1e-9)

    @property
    def is_identity(self) -> bool:
        t = np.asarray(self.translation)
        return np.array_equal(self.matrix, ((1, 0), (0, 1))) and bool(
            np.all(np.minimum(t, 1 - t) < 1e-9)
        )

    def as_dict(self) -> dict:
        return {
            "matrix": [list(r) for r in self.matrix],
            "translation": list(self.translation),
            "swaps_slabs": self.swaps_slabs,
        }


@dataclass(frozen=True)
class ShiftGroup:
    """The operations of the shift-space group (identity first) and the tolerance used."""

    operations: tuple[ShiftOperation, ...]
    tolerance_angstrom: float
    #: |a1|, |a2| (Å) of the interface the group was found on; None: unknown
    cell_lengths_angstrom: tuple[float, float] | None = None
    #: the group's pure translations (fractional, in [0, 1), (0, 0) first) when
    #: ``operations`` lists one operation per coset of them (``modulo_translations``);
    #: None: ``operations`` is the whole group
    translations: tuple[tuple[float, float], ...] | None = None

    @property
    def order(self) -> int:
        """The number of operations listed (cosets of the translations when they are kept apart)."""
        return len(self.operations)

    def for_grid(self, n_a: int, n_b: int) -> ShiftGroup:
        """The subgroup whose operations map the ``n_a × n_b`` grid of shifts onto itself.

        An image counts as a grid point when it lies within the structure tolerance of one:
        ``tolerance_angstrom / |a_i|`` in fractions of a_i (× n_i in grid steps), the
        precision to which the operation's translation is known from the atoms (a quartz
        two-fold axis found 1.5e-7 off a half-cell translation is kept). Without the cell
        lengths, 1e-6 grid steps.

        A group listed modulo its pure translations (:attr:`translations`) is lifted: every
        ``(M, t + λ)``, λ a translation, that maps the grid onto itself is kept, which is
        exactly the subgroup the whole group would give (for a twist cell on a grid coprime
        to the shift-lattice index, one element per coset, :mod:`flatcontact.ispes.shift_lattice`).
        """
        ia, ib = np.meshgrid(np.arange(n_a), np.arange(n_b), indexing="ij")
        s = np.stack([ia.ravel() / n_a, ib.ravel() / n_b], -1)
        n = np.array([n_a, n_b], dtype=float)
        if self.cell_lengths_angstrom is None:
            atol = np.full(2, 1e-6)
        else:
            atol = n * self.tolerance_angstrom / np.asarray(self.cell_lengths_angstrom, float)
        atol = np.minimum(atol, 0.25)  # an image a quarter step off is not on the grid
        kept = []
        for op in self._lifted_to(n, atol):
            g = op.apply(s) * n
            # the nearest grid index, periodic: an image just below 1 is index 0
            if np.all(np.abs(g - np.round(g)) <= atol):
                kept.append(op)
        return ShiftGroup(tuple(kept), self.tolerance_angstrom, self.cell_lengths_angstrom)

    def _lifted_to(self, n: np.ndarray, atol: np.ndarray) -> list[ShiftOperation]:
        """The operations ``(M, t + λ)`` whose translation lies on the grid of ``n`` steps
        (λ every pure translation); the operations themselves without :attr:`translations`.

        ``M s + t`` maps the grid ``s ∈ Z²/n`` onto itself exactly when ``t`` is on it, so
        only the translations need testing: ``order × index`` checks, vectorised."""
        if self.translations is None:
            return list(self.operations)
        lam = np.asarray(self.translations, float).reshape(-1, 2)
        out = []
        for op in self.operations:
            t = np.asarray(op.translation, float) + lam
            t -= np.floor(t + 1e-9)
            g = t * n
            on = np.all(np.abs(g - np.round(g)) <= atol, axis=1)
            for k in np.flatnonzero(on):
                out.append(dataclasses.replace(op, translation=_fraction_tuple(t[k])))
        return out

    def grid_images(self, n_a: int, n_b: int) -> np.ndarray:
        """Index images ``out[k, ia, ib] = (ja, jb)`` of every grid point under operation k.

        Shape ``(order, n_a, n_b, 2)``; the group must map the grid onto itself
        (:meth:`for_grid`).
        """
        ia, ib = np.meshgrid(np.arange(n_a), np.arange(n_b), indexing="ij")
        s = np.stack([ia / n_a, ib / n_b], -1)
        out = []
        for op in self.operations:
            g = np.round(op.apply(s) * (n_a, n_b)).astype(int)
            out.append(np.stack([g[..., 0] % n_a, g[..., 1] % n_b], -1))
        return np.array(out)

    def orbits(self, n_a: int, n_b: int) -> list[list[tuple[int, int]]]:
        """The orbits of the lateral grid points, each sorted, in order of their first point."""
        images = self.grid_images(n_a, n_b)
        seen: set[tuple[int, int]] = set()
        out = []
        for ia in range(n_a):
            for ib in range(n_b):
                if (ia, ib) in seen:
                    continue
                orbit = sorted(
                    {tuple(int(v) for v in images[k, ia, ib]) for k in range(self.order)}
                )
                seen.update(orbit)
                out.append(orbit)
        return out

    def as_dict(self) -> dict:
        """``order``, ``tolerance_angstrom`` and ``operations`` (as listed)."""
        return {
            "order": self.order,
            "tolerance_angstrom": self.tolerance_angstrom,
            "operations": [op.as_dict() for op in self.operations],
        }


# ----------------------------------------------------------------------------- atoms
def _labels(atoms: Atoms) -> np.ndarray:
    """Per-atom integer label: species and held flag (what an operation must keep)."""
    return np.asarray(atoms.numbers, np.int64) * 2 + fixed_mask(atoms).astype(np.int64)


class _Matcher:
    """Nearest same-label atom of a target set, modulo the in-plane lattice."""

    def __init__(self, positions: np.ndarray, labels: np.ndarray, lattice: np.ndarray):
        self.lattice = lattice
        self.inverse = np.linalg.inv(lattice)
        self.labels = labels
        self.trees = {}
        images = np.array([[i, j] for i in (-1, 0, 1) for j in (-1, 0, 1)], float) @ lattice.T
        for lab in np.unique(labels):
            idx = np.flatnonzero(labels == lab)
            p = self._wrap(positions[idx])
            rep = np.concatenate([p + np.array([v[0], v[1], 0.0]) for v in images], axis=0)
            self.trees[int(lab)] = (cKDTree(rep), np.tile(idx, len(images)))

    def _wrap(self, p: np.ndarray) -> np.ndarray:
        p = np.array(p, float, copy=True)
        f = p[:, :2] @ self.inverse.T
        f -= np.floor(f)
        p[:, :2] = f @ self.lattice.T
        return p

    def match(self, positions: np.ndarray, labels: np.ndarray, tol: float) -> np.ndarray | None:
        """Index of the matching target atom for each position, or None if one has none."""
        p = self._wrap(positions)
        out = np.empty(len(p), int)
        for lab in np.unique(labels):
            if int(lab) not in self.trees:
                return None
            tree, idx = self.trees[int(lab)]
            sel = np.flatnonzero(labels == lab)
            d, j = tree.query(p[sel], k=1, distance_upper_bound=tol)
            if not np.all(np.isfinite(d)):
                return None
            out[sel] = idx[j]
        if np.unique(out).size != out.size:
            return None
        return out


def _keeps_layers(perm: np.ndarray, src_layer: np.ndarray, dst_layer: np.ndarray) -> bool:
    """Whether the atom map sends every layer of the source onto one layer of the target."""
    pairs = np.unique(np.stack([src_layer, dst_layer[perm]], axis=1), axis=0)
    # a function (each source layer once) that is one-to-one (each target layer once)
    return len(np.unique(pairs[:, 0])) == len(pairs) == len(np.unique(pairs[:, 1]))


def _translations(
    src: np.ndarray,
    src_lab: np.ndarray,
    src_layer: np.ndarray,
    dst: np.ndarray,
    dst_lab: np.ndarray,
    dst_layer: np.ndarray,
    w: np.ndarray,
    lattice: np.ndarray,
    tol: float,
    dst_translations: list[np.ndarray] | None = None,
) -> list[np.ndarray]:
    """Every τ (3-vector, Å, in-plane part reduced to the cell) with ``W src + τ ≡ dst``.

    With ``dst_translations`` (the translations mapping ``dst`` onto itself, e.g.
    :func:`self_translations`): one τ only, or none. Every other τ differs from it by one of
    them (``W src + τ ≡ dst ≡ W src + τ'`` makes ``τ' − τ`` map ``dst`` onto itself), and
    candidates are tried once per class of target atoms modulo them, the atoms of the
    slab's primitive content: a handful of matches whatever the supercell, where every
    target atom of the anchor's species is a candidate without them.
    """
    if len(src) != len(dst) or not np.array_equal(np.sort(src_lab), np.sort(dst_lab)):
        return []
    matcher = _Matcher(dst, dst_lab, lattice)
    labels, counts = np.unique(src_lab, return_counts=True)
    anchor_label = labels[np.argmin(counts)]
    anchor = int(np.flatnonzero(src_lab == anchor_label)[0])
    moved = src @ w.T
    found: list[np.ndarray] = []
    inv = np.linalg.inv(lattice)
    candidates = np.flatnonzero(dst_lab == anchor_label)
    covered = np.zeros(len(dst), bool)
    shifts = None if dst_translations is None else np.asarray(dst_translations, float)
    for j in candidates:
        if covered[j]:
            continue
        if shifts is not None:
            # the class of j: its images under dst's own translations (each gives a τ that
            # differs by one of them, so j stands for all)
            images = matcher.match(dst[j] + shifts, np.full(len(shifts), anchor_label), tol)
            covered[j if images is None else images] = True
        tau = dst[j] - moved[anchor]
        f = inv @ tau[:2]
        tau[:2] = lattice @ (f - np.floor(f + 1e-9))
        perm = matcher.match(moved + tau, src_lab, tol)
        if perm is None or not _keeps_layers(perm, src_layer, dst_layer):
            continue
        if not any(_same_translation(tau, t, lattice, tol) for t in found):
            found.append(tau)
        if shifts is not None:
            break
    return found


def _same_translation(t1: np.ndarray, t2: np.ndarray, lattice: np.ndarray, tol: float) -> bool:
    d = np.asarray(t1) - np.asarray(t2)
    f = np.linalg.inv(lattice) @ d[:2]
    f -= np.round(f)
    return bool(np.linalg.norm(lattice @ f) < tol and abs(d[2]) < tol)


def _point_operations(lattice: np.ndarray, rtol: float = 1e-6) -> list[np.ndarray]:
    """Cartesian 2×2 point operations R of the lattice (identity included): ``L⁻¹ R L`` integer."""
    inv = np.linalg.inv(lattice)
    ops = []
    for entries in product((-1, 0, 1), repeat=4):
        m = np.array(entries, float).reshape(2, 2)
        if abs(abs(np.linalg.det(m)) - 1) > 0.5:
            continue
        r = lattice @ m @ inv
        if np.allclose(r.T @ r, np.eye(2), atol=rtol):
            ops.append(r)
    return ops


def _stack_maps(
    reference: Atoms,
    w: np.ndarray,
    op: ShiftOperation,
    tau_of_shift,
    tol: float,
    spread_compression: bool,
) -> bool:
    """Check ``W·stack(s) + τ(s) ≡ stack(g·s)`` on the placed atoms at generic shifts."""
    from flatcontact.structures.interface_contract import thickness

    lattice = np.column_stack(in_plane_vectors(reference))
    labels = _labels(reference)
    layer = np.asarray(reference.arrays.get("layer", np.zeros(len(reference), int)))
    z = thickness(reference)
    for s in _CHECK_SHIFTS:
        s = np.asarray(s)
        gs = op.apply(s)
        a = place_slab2(
            reference, float(s[0]), float(s[1]), z, spread_compression=spread_compression
        )
        b = place_slab2(
            reference, float(gs[0]), float(gs[1]), z, spread_compression=spread_compression
        )
        moved = a.positions @ w.T + tau_of_shift(lattice @ s)
        perm = _Matcher(b.positions, labels, lattice).match(moved, labels, tol)
        if perm is None or not _keeps_layers(perm, layer, layer):
            return False
        slab = np.asarray(reference.arrays["slab"])
        if op.swaps_slabs != bool(np.all(slab[perm] != slab)):
            return False
    return True


def shift_space_group(
    reference: Atoms,
    tolerance_angstrom: float = DEFAULT_TOLERANCE_ANGSTROM,
    *,
    spread_compression: bool = True,
    modulo_translations: bool = False,
) -> ShiftGroup:
    """The shift-space group of ``reference`` (see the module docstring), identity first.

    The search works modulo the slabs' own lattices. Each slab's translations ``T_i`` (the
    in-plane translations mapping it onto itself, :func:`self_translations`) are found once;
    their differences ``τ₁ − τ₂`` are the group's pure translations, the shift lattice
    Λ_1 + Λ_2 (:mod:`flatcontact.ispes.shift_lattice`; one translation, zero, for a 1×1 cell).
    For each point operation and slab swap one space translation per slab is then enough
    (the others differ from it by ``T_i``) and is found among one candidate per atom of the
    slab's primitive content, by a KD-tree match of the whole slab; each such operation is
    checked on the stack at two generic shifts. Cost: ``|T_i|`` slab matches once, then a few
    per point operation, where trying every pair of ``T_1 × T_2`` costs ``N²`` stack checks
    per point operation for a twist cell of N primitive cells per layer (227 s for the
    76-atom (2, 3) cell; benchmarks/bench_symcell.py).

    Parameters
    ----------
    reference
        The reference interface (interface contract: slabs, held layers, layer ids).
    tolerance_angstrom
        Largest distance (Å) between a mapped atom and its image for an operation to count.
    spread_compression
        As the scan's placement of slab 2 (false in ``rigid`` mode).
    modulo_translations
        List one operation per coset of the pure translations (point operation and slab
        swap) and keep the translations apart in :attr:`ShiftGroup.translations`;
        :meth:`ShiftGroup.for_grid` lifts them onto a grid (the scan's use), and on one
        period of the shift lattice they are all the identity (the gates' use). False: the
        whole group, every coset times every translation (``order × index`` operations;
        588 for the (1, 2) twist cell).

    Returns
    -------
    ShiftGroup
        Operations ``s ↦ M s + t`` sorted with the identity first, then by (M, t, swaps).
    """
    tol = float(tolerance_angstrom)
    lattice = np.column_stack(in_plane_vectors(reference))
    inv = np.linalg.inv(lattice)
    pos = reference.positions
    lab = _labels(reference)
    layer = np.asarray(reference.arrays.get("layer", np.zeros(len(reference), int)))
    slab = np.asarray(reference.arrays["slab"])
    parts = {k: (pos[slab == k], lab[slab == k], layer[slab == k]) for k in (1, 2)}
    own = {k: _self_translations(*parts[k], lattice, tol) for k in (1, 2)}
    pure = _pure_translations(own[1], own[2], inv)
    ops: list[ShiftOperation] = []

    def fractional(v: np.ndarray) -> tuple[float, float]:
        return _fraction_tuple(inv @ np.asarray(v, float)[:2])

    def known(op: ShiftOperation) -> bool:
        # the same coset of the pure translations (a slab swap that acts on shifts like an
        # operation without one is the same shift-space operation)
        return any(
            u.matrix == op.matrix
            and _in_translations(np.subtract(u.translation, op.translation), pure)
            for u in ops
        )

    def add(op: ShiftOperation, w: np.ndarray, tau_of_shift) -> None:
        if not known(op) and _stack_maps(reference, w, op, tau_of_shift, tol, spread_compression):
            ops.append(op)

    # the operations without a slab swap first: one with a swap that acts on shifts like
    # one of them is kept as the one without
    for sigma, r in product((1, -1), _point_operations(lattice)):
        m_int = np.round(inv @ r @ lattice).astype(int)
        w = np.eye(3)
        w[:2, :2] = r
        w[2, 2] = sigma
        if sigma == 1:
            t1 = _translations(*parts[1], *parts[1], w, lattice, tol, own[1])
            t2 = _translations(*parts[2], *parts[2], w, lattice, tol, own[2]) if t1 else []
            if not t2 or abs(t1[0][2]) > tol or abs(t2[0][2]) > tol:
                continue
            tau1, tau2 = t1[0], t2[0]
            m = tuple(tuple(int(v) for v in row) for row in m_int)
            add(ShiftOperation(m, fractional(tau1 - tau2), False), w, lambda d, t=tau1: t)
        else:
            ta = _translations(*parts[1], *parts[2], w, lattice, tol, own[2])
            tb = _translations(*parts[2], *parts[1], w, lattice, tol, own[1]) if ta else []
            if not tb or abs(ta[0][2] - tb[0][2]) > tol:
                continue
            tau_a, tau_b = ta[0], tb[0]
            m = tuple(tuple(int(-v) for v in row) for row in m_int)

            def tau_of_shift(d, tau_b=tau_b, r=r):
                out = tau_b.copy()
                out[:2] -= r @ d
                return out

            add(ShiftOperation(m, fractional(tau_b - tau_a), True), w, tau_of_shift)
    lengths = (float(np.linalg.norm(lattice[:, 0])), float(np.linalg.norm(lattice[:, 1])))
    if modulo_translations:
        return ShiftGroup(_sorted(ops), tol, lengths, translations=pure)
    whole = []
    for op in ops:
        t = np.asarray(op.translation) + np.asarray(pure)
        whole += [dataclasses.replace(op, translation=_fraction_tuple(v)) for v in t]
    return ShiftGroup(_sorted(whole), tol, lengths)


def _sorted(ops: list[ShiftOperation]) -> tuple[ShiftOperation, ...]:
    """Identity first, then by (M, t, swaps)."""
    return tuple(
        sorted(ops, key=lambda o: (not o.is_identity, o.matrix, o.translation, o.swaps_slabs))
    )


def _fraction_tuple(f: np.ndarray) -> tuple[float, float]:
    """Fractions reduced into [0, 1) and rounded to 1e-12 (a stable key)."""
    f = np.asarray(f, float) - np.floor(np.asarray(f, float) + 1e-9)
    f[np.abs(f - 1.0) < 1e-9] = 0.0
    return (float(round(f[0], 12)) + 0.0, float(round(f[1], 12)) + 0.0)


def _pure_translations(
    own1: list[np.ndarray], own2: list[np.ndarray], inv: np.ndarray
) -> tuple[tuple[float, float], ...]:
    """The pure translations ``τ₁ − τ₂`` of the group (fractional, (0, 0) first, distinct)."""
    a = np.array([inv @ t[:2] for t in own1])
    b = np.array([inv @ t[:2] for t in own2])
    diff = (a[:, None, :] - b[None, :, :]).reshape(-1, 2)
    diff -= np.floor(diff + 1e-9)
    diff[np.abs(diff - 1.0) < 1e-9] = 0.0
    keys = np.round(diff * 1e6).astype(np.int64) % 1000000
    _, first = np.unique(keys, axis=0, return_index=True)
    out = np.round(diff[first], 12) + 0.0  # as _fraction_tuple, vectorised
    out[out >= 1.0] = 0.0
    out = out[np.lexsort((out[:, 1], out[:, 0]))]
    return tuple((float(a), float(b)) for a, b in out)


def _in_translations(d: np.ndarray, pure: tuple[tuple[float, float], ...]) -> bool:
    """Whether the fractional difference ``d`` is one of the pure translations (mod 1)."""
    e = np.asarray(pure) - np.asarray(d, float)
    e -= np.round(e)
    return bool(np.any(np.all(np.abs(e) < 1e-6, axis=1)))


#: Atoms per slab on which every candidate self-translation is screened before a full match.
_SCREEN_ATOMS = 12


def _self_translations(
    pos: np.ndarray, lab: np.ndarray, layer: np.ndarray, lattice: np.ndarray, tol: float
) -> list[np.ndarray]:
    """The in-plane translations mapping one slab onto itself (identity first), 3-vectors with
    zero z, the in-plane part reduced to the cell.

    They form a group T (the slab's primitive lattice modulo the cell), so not every one
    needs a full match: each candidate (an atom of the anchor's species minus the anchor) is
    screened on :data:`_SCREEN_ATOMS` atoms spread over the slab (one vectorised KD-tree
    query), and the survivors are taken in turn: one already in the group generated by the
    fully matched ones is a member (a sum of symmetries is one); another is matched on the
    whole slab (species, held flags, layers) and, if it maps, joins the generators. Full
    matches: the generators (two for a 2-D lattice) and any survivor of the screen that is
    not a symmetry, instead of one per atom of the anchor's species.
    """
    inv = np.linalg.inv(lattice)
    labels, counts = np.unique(lab, return_counts=True)
    anchor_label = labels[np.argmin(counts)]
    anchor = int(np.flatnonzero(lab == anchor_label)[0])
    candidates = np.flatnonzero(lab == anchor_label)
    frac = (pos[candidates, :2] - pos[anchor, :2]) @ inv.T
    frac -= np.floor(frac + 1e-9)
    same_height = np.abs(pos[candidates, 2] - pos[anchor, 2]) <= tol
    frac = frac[same_height]
    matcher = _Matcher(pos, lab, lattice)
    # screen: a few atoms spread over the slab (every k-th), each candidate at once
    sample = np.unique(np.linspace(0, len(pos) - 1, min(_SCREEN_ATOMS, len(pos))).astype(int))
    keep = np.ones(len(frac), bool)
    for i in sample:
        moved = pos[i] + np.column_stack([frac @ lattice.T, np.zeros(len(frac))])
        p = matcher._wrap(moved)
        tree, _ = matcher.trees[int(lab[i])]
        d, _ = tree.query(p, k=1, distance_upper_bound=tol)
        keep &= np.isfinite(d)
    group = np.zeros((1, 2))  # the group generated by the matched translations (fractions)

    def member(f: np.ndarray) -> bool:
        e = group - f
        e -= np.round(e)
        return bool(np.any(np.all(np.abs(e @ lattice.T) < tol, axis=1)))

    for f in frac[keep]:
        if member(f):
            continue
        tau = np.array([*(lattice @ f), 0.0])
        perm = matcher.match(pos + tau, lab, tol)
        if perm is None or not _keeps_layers(perm, layer, layer):
            continue
        group = _generated(group, f, tol, lattice, len(frac))
    return [np.array([*(lattice @ f), 0.0]) for f in group]


def _generated(
    group: np.ndarray, f: np.ndarray, tol: float, lattice: np.ndarray, bound: int
) -> np.ndarray:
    """The finite group (fractions mod 1) generated by ``group`` and the translation ``f``:
    ``group + k f`` for k up to the order of ``f`` modulo ``group`` (at most ``bound``)."""
    out = [group]
    step = np.asarray(f, float)
    for _ in range(bound):
        e = group - step
        e -= np.round(e)
        if np.any(np.all(np.abs(e @ lattice.T) < tol, axis=1)):
            break
        shifted = group + step
        out.append(shifted - np.floor(shifted + 1e-9))
        step = step + f
    return np.concatenate(out)


def self_translations(
    reference: Atoms, slab: int, tolerance_angstrom: float = DEFAULT_TOLERANCE_ANGSTROM
) -> list[np.ndarray]:
    """In-plane translations τ (3-vectors, Å, reduced to the cell) that map slab ``slab`` of
    ``reference`` onto itself modulo the in-plane lattice, keeping species, held flags and
    layers: the primitive lattice of that slab modulo the supercell (identity included).
    The pure translations of the shift-space group are differences of slab 1's and slab 2's
    (:mod:`flatcontact.ispes.shift_lattice`)."""
    lattice = np.column_stack(in_plane_vectors(reference))
    lab = _labels(reference)
    layer = np.asarray(reference.arrays.get("layer", np.zeros(len(reference), int)))
    mask = np.asarray(reference.arrays["slab"]) == slab
    return _self_translations(
        reference.positions[mask], lab[mask], layer[mask], lattice, float(tolerance_angstrom)
    )
