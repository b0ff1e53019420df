"""The bond rule (covalent radii × 1.2) accepts real bond lengths and keeps gaps apart.

Geometry is written here from textbook values: diamond a = 3.567 Å (C–C = a·√3/4 =
1.5446 Å), C–H 1.09 Å, graphite interlayer 3.35 Å, α-quartz Si–O 1.61 Å.
"""

import numpy as np
import pytest
from ase import Atoms
from ase.build import diamond111
from ase.neighborlist import neighbor_list

from flatcontact.foundation.errors import InputError
from flatcontact.structures.bulk import alpha_quartz
from flatcontact.structures.layers import bonded_components, sheet_layers
from flatcontact.structures.sheets import builtin_sheet, check_sheet, stack_sheets
from flatcontact.structures.topology import SILICA_CUTOFFS, bond_radii, bonds

DIAMOND_A_ANGSTROM = 3.567
CH_ANGSTROM = 1.09


def _pieces(atoms: Atoms) -> int:
    return int(bonded_components(atoms).max()) + 1


def _diamond_slab(planes: int = 6) -> Atoms:
    """A 2×2 diamond(111) slab ending on the bilayer surfaces: one dangling bond per surface
    carbon, along ±z (ASE's ``diamond111`` ends on singly bonded atoms: they are removed)."""
    slab = diamond111("C", (2, 2, planes + 2), a=DIAMOND_A_ANGSTROM, vacuum=8.0)
    z = slab.positions[:, 2]
    del slab[(z < z.min() + 0.1) | (z > z.max() - 0.1)]
    slab.pbc = (True, True, False)
    return slab


def _hydrogenated(slab: Atoms) -> Atoms:
    """``slab`` with an H at 1.09 Å on each dangling bond of its 3-fold carbons.

    For a tetrahedral carbon missing one neighbour the dangling bond points along minus
    the sum of its three bond vectors.
    """
    i, _, vec = _cc_bonds(slab)
    out = slab.copy()
    for atom in np.flatnonzero(np.bincount(i, minlength=len(slab)) == 3):
        direction = -vec[i == atom].sum(axis=0)
        direction /= np.linalg.norm(direction)
        out.append("H")
        out.positions[-1] = slab.positions[atom] + CH_ANGSTROM * direction
    return out


def _cc_bonds(slab: Atoms):
    """C–C bonds of a pure-carbon structure (i, j, vector): all pairs closer than 1.7 Å."""
    return neighbor_list("ijD", slab, 1.7)


def test_tolerance_separates_bond_from_contact_for_an_isolated_pair():
    """Two C atoms: bonded at diamond's 1.545 Å (longer than 2 r_C = 1.52 Å), not at 2 Å."""
    for d, bonded in ((1.5446, True), (1.80, True), (1.85, False), (2.52, False)):
        pair = Atoms("C2", positions=[(0, 0, 0), (0, 0, d)], cell=[20, 20, 20])
        assert (_pieces(pair) == 1) is bonded, d
    ch = Atoms("CH", positions=[(0, 0, 0), (0, 0, CH_ANGSTROM)], cell=[20, 20, 20])
    assert _pieces(ch) == 1
    radii = bond_radii(ch)
    assert radii[0] + radii[1] == pytest.approx(1.2 * (0.76 + 0.31))


def test_diamond111_slab_is_one_piece_and_a_valid_sheet_source():
    slab = _diamond_slab()
    _, _, vec = _cc_bonds(slab)
    assert np.linalg.norm(vec, axis=1) == pytest.approx(DIAMOND_A_ANGSTROM * np.sqrt(3) / 4)
    assert _pieces(slab) == 1
    check_sheet(slab, "diamond(111)")  # refused as '16 separate bonded pieces' with 1.52 Å


def test_h_terminated_diamond111_slab_is_one_piece():
    slab = _hydrogenated(_diamond_slab())
    n_h = slab.get_chemical_symbols().count("H")
    assert n_h == 8  # one dangling bond per surface carbon, 4 per face of the 2×2 cell
    z = slab.positions[:, 2]
    h = np.array(slab.get_chemical_symbols()) == "H"
    assert z[h].max() == pytest.approx(z[~h].max() + CH_ANGSTROM)  # the (111) bond is along z
    assert _pieces(slab) == 1
    check_sheet(slab, "H-diamond(111)")


def test_two_slabs_three_angstrom_apart_are_two_pieces():
    lower = _hydrogenated(_diamond_slab())
    upper = lower.copy()
    z = lower.positions[:, 2]
    upper.positions[:, 2] += z.max() - z.min() + 3.0  # H···H = 3 Å across the gap
    pair = lower + upper
    pair.cell[2, 2] = upper.positions[:, 2].max() + 10.0
    assert _pieces(pair) == 2
    assert sorted(set(sheet_layers(pair).tolist())) == [1, 2]
    with pytest.raises(InputError, match="2 separate bonded pieces"):
        check_sheet(pair, "two slabs")


def test_graphene_one_piece_and_graphite_layers_apart():
    sheet = builtin_sheet("graphene")
    assert _pieces(sheet) == 1
    stack = stack_sheets(sheet.repeat((3, 3, 1)), 3, "AB", 3.35)
    assert _pieces(stack) == 3
    assert sheet_layers(stack).tolist() == np.asarray(stack.arrays["layer"]).tolist()


def test_quartz_bonds_are_exactly_the_silica_rule():
    """In α-quartz the general rule finds the Si–O bonds of the silica rule and nothing else."""
    quartz = alpha_quartz().repeat((2, 2, 2))
    i, j, _ = bonds(quartz)
    i2, j2 = neighbor_list("ij", quartz, bond_radii(quartz))
    assert sorted(zip(i.tolist(), j.tolist(), strict=True)) == sorted(
        zip(i2.tolist(), j2.tolist(), strict=True)
    )
    counts = np.bincount(i2, minlength=len(quartz))
    symbols = np.array(quartz.get_chemical_symbols())
    assert set(counts[symbols == "Si"]) == {4} and set(counts[symbols == "O"]) == {2}
    assert _pieces(quartz) == 1
    assert SILICA_CUTOFFS == {("Si", "O"): 2.0}
