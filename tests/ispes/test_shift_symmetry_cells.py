"""The fast shift-space group search (modulo the slabs' own lattices) against the exhaustive
pair search, and its lift onto a scan grid of a twist cell (issue 22/23: large cells).

Reference: :mod:`tests.ispes.exhaustive_shift_group` tries every pair of the two slabs'
translations for every point operation; the fast search infers them from each slab's own
translations. Both must give the same group, operation by operation, on the interfaces the
scan meets: fcc(111), AB graphene, h-BN AA′ (index 1) and commensurate twist cells (index N²,
or N²/3 when m − n is a multiple of 3).
"""

from __future__ import annotations

import numpy as np
import pytest
from tests.examples.test_examples import EXAMPLES
from tests.ispes.exhaustive_shift_group import exhaustive_group

from flatcontact.config.load import load_config
from flatcontact.ispes.shift_lattice import reindex, shift_lattice_of
from flatcontact.ispes.shift_symmetry import shift_space_group
from flatcontact.structures.construct import build_interface


def _example(name):
    atoms, _ = build_interface(load_config(EXAMPLES / f"{name}.yaml").structure)
    return atoms


def _twisted(m: int, n: int):
    atoms, _ = build_interface(
        {"kind": "sheets", "sheet": "graphene", "layers": 1, "twist": [m, n]}
    )
    return atoms


def _keys(group) -> set:
    return {
        (op.matrix, tuple(float(v) for v in np.round(op.translation, 6) % 1.0), op.swaps_slabs)
        for op in group.operations
    }


@pytest.mark.parametrize(
    ("atoms", "order"),
    [
        (lambda: _example("cu111-eam"), 6),
        (lambda: _example("graphene-bilayer-kc"), 12),
        (lambda: _example("hbn-bilayer-ilp"), 6),
        (lambda: _twisted(1, 2), 12 * 49),
    ],
    ids=["cu111", "ab-graphene", "hbn", "twist-1-2"],
)
def test_the_fast_search_finds_the_exhaustive_searchs_group(atoms, order):
    atoms = atoms()
    fast = shift_space_group(atoms)
    assert fast.order == order
    assert _keys(fast) == exhaustive_group(atoms)
    # listed modulo the translations: one operation per point operation (and swap) class
    lattice = shift_lattice_of(atoms)
    reduced = shift_space_group(atoms, modulo_translations=True)
    assert reduced.order * lattice.index == order
    assert len(reduced.translations) == lattice.index


@pytest.mark.parametrize(
    ("mn", "n", "order"), [((1, 2), 6, 12), ((1, 2), 8, 6), ((1, 4), 8, 12), ((1, 4), 10, 12)]
)
def test_the_lift_onto_a_grid_is_the_whole_groups_restriction(mn, n, order):
    """The scan's group (modulo the translations, lifted onto the n × n grid over the
    supercell) equals the whole group's operations that map the grid onto itself: for n
    coprime to the index, at most one element per point operation class, whatever the N²
    translations. On one period the hexagonal landscape keeps 6mm about AA; its three-fold
    operations about the AB registries translate by thirds of a period, on the grid only
    when 3 divides n for (1, 2) (12 on 6 × 6, 6 on 8 × 8). (1, 4) has the non-diagonal shift
    lattice of index 21²/3, whose period holds those thirds: 12 on 8 × 8 and 10 × 10."""
    atoms = _twisted(*mn)
    lattice = shift_lattice_of(atoms)
    lifted = shift_space_group(atoms, modulo_translations=True).for_grid(n, n)
    whole = shift_space_group(atoms).for_grid(n, n)
    assert _keys(lifted) == _keys(whole)
    assert lifted.order == order
    # on the grid, each operation is the restated one on one period: the reindexed image of
    # a point under g is g's image of the reindexed point
    ta, tb = reindex(lattice, n, n)
    images = lifted.grid_images(n, n)
    k = lattice.to_shift_cell.astype(float)
    for op, img in zip(lifted.operations, images, strict=True):
        m2 = np.round(k @ np.array(op.matrix, float) @ np.linalg.inv(k)).astype(int)
        t2 = k @ np.asarray(op.translation)
        for ia, ib in ((1, 0), (0, 1), (2, 3)):
            u = np.array([ta[ia, ib], tb[ia, ib]]) / n
            expected = (m2 @ u + t2) % 1.0 * n
            ja, jb = img[ia, ib]
            got = np.array([ta[ja, jb], tb[ja, jb]], float)
            diff = (expected - got + n / 2) % n - n / 2
            np.testing.assert_allclose(diff, 0.0, atol=1e-6)


@pytest.mark.slow
def test_the_fast_search_on_the_1_4_twist_matches_the_exhaustive_one():
    """(1, 4): 84 atoms, index 147 (m − n multiple of 3), 12 × 147 operations."""
    atoms = _twisted(1, 4)
    fast = shift_space_group(atoms)
    assert fast.order == 12 * 147
    assert _keys(fast) == exhaustive_group(atoms)


def _every_self_translation(atoms, slab, tol):
    """Each slab's translations by a full match per candidate atom (the exhaustive helper)."""
    from tests.ispes.exhaustive_shift_group import _every_translation

    from flatcontact.ispes.shift_symmetry import _labels
    from flatcontact.structures.interface_contract import in_plane_vectors

    lattice = np.column_stack(in_plane_vectors(atoms))
    mask = np.asarray(atoms.arrays["slab"]) == slab
    part = (atoms.positions[mask], _labels(atoms)[mask], np.asarray(atoms.arrays["layer"])[mask])
    found = _every_translation(*part, *part, np.eye(3), lattice, tol)
    return _fractions([t for t in found if abs(t[2]) <= tol], lattice)


def _fractions(taus, lattice):
    inv = np.linalg.inv(lattice)
    return sorted(tuple(float(v) for v in np.round((inv @ t[:2]) % 1.0, 6) % 1.0) for t in taus)


@pytest.mark.parametrize("displaced", [0.0, 0.01])
@pytest.mark.parametrize("mn", [(1, 2), (1, 4), (2, 3)])
def test_each_slabs_translations_equal_a_full_match_per_candidate(mn, displaced):
    """The slab's translations, found as the group generated by the screened and matched
    ones, are those a full match of every candidate finds: N for the N-cell sheet, and only
    the identity once one atom of slab 1 is moved 0.01 Å (above the 1e-3 Å tolerance; within
    0.05 Å all N again)."""
    from flatcontact.ispes.shift_symmetry import self_translations
    from flatcontact.structures.interface_contract import in_plane_vectors

    m, n = mn
    atoms = _twisted(m, n)
    atoms.positions[np.flatnonzero(atoms.arrays["slab"] == 1)[3], 0] += displaced
    lattice = np.column_stack(in_plane_vectors(atoms))
    cells = m * m + m * n + n * n
    for slab, tol in ((1, 1e-3), (2, 1e-3), (1, 0.05)):
        fast = _fractions(self_translations(atoms, slab, tol), lattice)
        assert fast == _every_self_translation(atoms, slab, tol)
        assert len(fast) == (1 if (displaced and slab == 1 and tol < displaced) else cells)
