"""The shift-space group by the exhaustive pair search (the scan's search before issue 22's
large-cell work), kept as the reference the fast search is tested against.

For every point operation R of the lattice and slab swap σ: every translation τ₁ that maps
slab 1 onto itself under W = diag(R, σ) (every target atom of the anchor's species tried), every
τ₂ for slab 2, and every pair (τ₁, τ₂) checked on the stack at two generic shifts. It shares
the atom matcher, the per-slab translation search in its exhaustive mode (``_translations``
without the slab's own translations) and the stack check with
:mod:`flatcontact.ispes.shift_symmetry`, not the group search: no translation is inferred
from another. Cost: N² stack checks per point operation
for a twist cell of N primitive cells per layer (4 s for the (1, 2) cell, 100–230 s for
(2, 3)): tests use it on small cells only.
"""

from __future__ import annotations

from itertools import product

import numpy as np

from flatcontact.ispes.shift_symmetry import (
    ShiftOperation,
    _labels,
    _point_operations,
    _stack_maps,
    _translations,
)
from flatcontact.structures.interface_contract import in_plane_vectors


def _every_translation(src, src_lab, src_layer, dst, dst_lab, dst_layer, w, lattice, tol):
    """Every τ with ``W src + τ ≡ dst``: the package's matcher without the slab's own
    translations (every target atom of the anchor's species tried), as the old search did."""
    return _translations(src, src_lab, src_layer, dst, dst_lab, dst_layer, w, lattice, tol)


def exhaustive_group(reference, tol: float = 1e-3, spread_compression: bool = True) -> set:
    """The whole group as a set of ``(M, t rounded to 1e-6, swaps_slabs)``; an operation found
    with and without a slab swap is listed without (as the scan's group lists it)."""
    lattice = np.column_stack(in_plane_vectors(reference))
    inv = np.linalg.inv(lattice)
    lab = _labels(reference)
    layer = np.asarray(reference.arrays.get("layer", np.zeros(len(reference), int)))
    slab = np.asarray(reference.arrays["slab"])
    parts = {k: (reference.positions[slab == k], lab[slab == k], layer[slab == k]) for k in (1, 2)}

    def frac(v):
        f = inv @ np.asarray(v, float)[:2]
        f = np.round(f - np.floor(f + 1e-9), 6) % 1.0
        return (float(f[0]) + 0.0, float(f[1]) + 0.0)

    found = {}
    for r in _point_operations(lattice):
        m = np.round(inv @ r @ lattice).astype(int)
        for sigma in (1, -1):
            w = np.eye(3)
            w[:2, :2], w[2, 2] = r, sigma
            if sigma == 1:
                pairs = product(
                    _every_translation(*parts[1], *parts[1], w, lattice, tol),
                    _every_translation(*parts[2], *parts[2], w, lattice, tol),
                )
                for tau1, tau2 in pairs:
                    if abs(tau1[2]) > tol or abs(tau2[2]) > tol:
                        continue
                    mat = tuple(tuple(int(v) for v in row) for row in m)
                    op = ShiftOperation(mat, frac(tau1 - tau2), False)
                    if _stack_maps(reference, w, op, lambda d, t=tau1: t, tol, spread_compression):
                        found[(op.matrix, op.translation)] = False
            else:
                pairs = product(
                    _every_translation(*parts[1], *parts[2], w, lattice, tol),
                    _every_translation(*parts[2], *parts[1], w, lattice, tol),
                )
                for tau_a, tau_b in pairs:
                    if abs(tau_a[2] - tau_b[2]) > tol:
                        continue
                    mat = tuple(tuple(int(-v) for v in row) for row in m)
                    op = ShiftOperation(mat, frac(tau_b - tau_a), True)

                    def tau_of_shift(d, tau_b=tau_b, r=r):
                        out = tau_b.copy()
                        out[:2] -= r @ d
                        return out

                    if _stack_maps(reference, w, op, tau_of_shift, tol, spread_compression):
                        found.setdefault((op.matrix, op.translation), True)
    return {(m, t, swaps) for (m, t), swaps in found.items()}
