"""``asperity.tip: slab1``: the interface turned upside down (a proper rotation), so a cap of
slab 1's crystal — e.g. the passivated diamond of the passivated-tip examples — presses on a
flat of slab 2's."""

from pathlib import Path

import numpy as np
import pytest
from ase.calculators.emt import EMT

from flatcontact.asperity import builder
from flatcontact.cli.settings import resolve_config
from flatcontact.foundation.errors import InputError
from flatcontact.structures.construct import build_interface

EXAMPLES = Path(__file__).parents[2] / "examples"


@pytest.fixture(scope="module")
def h_diamond():
    cfg = resolve_config(EXAMPLES / "passivated-tip-h-diamond-graphene.yaml", None, {}, {})
    small, _ = build_interface(builder.deep_recipe(cfg.structure, 3))
    return cfg, small


def _energy(atoms):
    a = atoms.copy()
    a.calc = EMT()
    return a.get_potential_energy()


def test_flipping_is_a_rotation_of_the_interface(h_diamond):
    _, small = h_diamond
    flip = builder.flipped(small)
    # the same body: every distance (minimum image) and the energy of an independent
    # calculator (ASE's EMT knows H and C) are unchanged; slab labels swap
    assert np.allclose(
        flip.get_all_distances(mic=True), small.get_all_distances(mic=True), atol=1e-9
    )
    assert _energy(flip) == pytest.approx(_energy(small), abs=1e-9)
    assert np.array_equal(flip.arrays["slab"], 3 - small.arrays["slab"])
    # a right-handed cell with a2 in the upper half-plane, a1 along x
    cell = flip.cell.array
    assert cell[0, 1] == pytest.approx(0.0, abs=1e-12) and cell[1, 1] > 0 and cell[2, 2] > 0
    # twice is the identity
    back = builder.flipped(flip)
    assert np.allclose(back.positions, small.positions, atol=1e-12)
    assert np.allclose(back.cell.array, small.cell.array, atol=1e-12)
    assert np.array_equal(back.arrays["slab"], small.arrays["slab"])


def test_a_passivated_diamond_cap_on_graphite(h_diamond):
    """tip: slab1 on the H-diamond/graphene example: the cap is diamond with its H-terminated
    face at the apex, the flat is graphene sheets; every H is in the tip and the facing gap
    is the built interface's."""
    cfg, small = h_diamond
    atoms, sizes = builder.build_asperity(cfg.structure, "cylinder", 60.0, 1.0, 69.64, tip="slab1")
    slab = atoms.arrays["slab"]
    symbols = np.array(atoms.get_chemical_symbols())
    assert set(symbols[slab == 1]) == {"C"}
    assert np.all(slab[symbols == "H"] == 2)
    z = atoms.positions[:, 2]
    lowest_tip = np.argmin(np.where(slab == 2, z, np.inf))
    assert symbols[lowest_tip] == "H"  # the apex is the passivated face
    s = small.arrays["slab"]
    gap_built = small.positions[s == 2, 2].min() - small.positions[s == 1, 2].max()
    gap_here = z[slab == 2].min() - z[slab == 1].max()
    assert gap_here == pytest.approx(gap_built, abs=1e-9)
    # the flat's planes are graphene sheets: the spacing is the sheets' (not diamond's bilayers)
    assert atoms.info["plane_spacing_angstrom"] == pytest.approx(3.35, abs=0.1)
    # each body is the planned depth (two rigid blocks) in its own planes: many more diamond
    # planes than graphite sheets for the same height
    for body in (1, 2):
        assert np.ptp(z[slab == body]) >= 2 * sizes.rigid_angstrom - 1e-6
    assert sizes.tip_layers > 2 * sizes.flat_layers


def test_an_unknown_tip_is_refused(h_diamond):
    with pytest.raises(InputError, match="tip must be one of slab2, slab1"):
        builder.oriented(h_diamond[1], "slab3")
