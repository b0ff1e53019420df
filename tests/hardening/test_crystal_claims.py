"""Crystals that are not what they claim: a CIF site of partial occupancy or a mixed site is
one line naming the site (ASE built a full Cu site of a 30 %-occupied one, pure Ni of
Cu0.5Ni0.5); atoms a symmetry expansion puts closer than half a bond are refused before any
relaxation; a build relaxation that moves the slabs apart beyond its bound is an error naming
it; passivate: OH on a crystal without O is refused naming the species and the element."""

from __future__ import annotations

import numpy as np
import pytest
from ase.build import bulk
from tests.hardening.helpers import assert_refused_cleanly

from flatcontact.foundation.errors import InputError
from flatcontact.structures import construct
from flatcontact.structures.crystal import orient, passivated_crystal_slab, read_bulk

_HEADER = """data_test
_symmetry_space_group_name_H-M 'F m -3 m'
_symmetry_Int_Tables_number 225
_cell_length_a {a}
_cell_length_b {a}
_cell_length_c {a}
_cell_angle_alpha 90
_cell_angle_beta 90
_cell_angle_gamma 90
loop_
_atom_site_label
_atom_site_type_symbol
_atom_site_fract_x
_atom_site_fract_y
_atom_site_fract_z
_atom_site_occupancy
"""

CIFS = {
    "partial": ("Cu1 Cu 0 0 0 0.30(2)\n", ["site Cu1 (Cu)", "occupancy 0.3", "partly occupied"]),
    "mixed": (
        "Cu1 Cu 0 0 0 0.5\nNi1 Ni 0 0 0 0.5\n",
        ["sites Cu1 and Ni1", "mixed site"],
    ),
    "mixed-full": ("Cu1 Cu 0 0 0 1\nNi1 Ni 1 1 0 1\n", ["sites Cu1 and Ni1", "mixed site"]),
    "expanded-too-close": (
        "Cu1 Cu 0 0 0 1\nCu2 Cu 0.1 0.1 0 1\n",
        ["atoms 1 (Cu) and", "0.511 Å apart", "symmetry expansion"],
    ),
}


def _cif(path, sites: str, a: float = 3.615):
    path.write_text(_HEADER.format(a=a) + sites)
    return path


@pytest.mark.parametrize("case", sorted(CIFS))
def test_a_disordered_or_overlapping_cif_is_one_line_naming_the_site(tmp_path, case):
    sites, names = CIFS[case]
    path = _cif(tmp_path / f"{case}.cif", sites)
    with pytest.raises(InputError) as info:
        read_bulk(path, "structure.bulk")
    text = str(info.value)
    assert "\n" not in text and text.startswith(f"structure.bulk: {path}")
    for name in names:
        assert name in text, (name, text)


def test_an_ordered_cif_still_reads_as_the_crystal_it_is(tmp_path):
    """fcc Cu, every site full: 4 atoms, nearest neighbours a/sqrt(2)."""
    from ase.neighborlist import neighbor_list

    atoms = read_bulk(_cif(tmp_path / "cu.cif", "Cu1 Cu 0 0 0 1.0\n"), "structure.bulk")
    assert atoms.get_chemical_formula() == "Cu4"
    assert neighbor_list("d", atoms, 3.0).min() == pytest.approx(3.615 / np.sqrt(2))


def test_a_partial_cif_in_a_run_is_refused_before_any_stage(tmp_path, capsys):
    _cif(tmp_path / "partial.cif", CIFS["partial"][0])
    (tmp_path / "run.yaml").write_text(
        "structure: {kind: crystal, bulk: partial.cif, miller: [1, 1, 1], layers: 3}\n"
        "potential: {preset: cu-eam}\n"
        "scan: {grid: [3, 3], executor: serial}\n"
    )
    out = tmp_path / "out"
    assert_refused_cleanly(
        ["run", tmp_path / "run.yaml", "--out", out],
        capsys,
        tmp_path,
        ["partial.cif", "site Cu1"],
        out,
    )


def test_passivating_a_crystal_without_oxygen_with_oh_is_refused():
    oriented = orient(bulk("Si", "diamond", a=5.431, cubic=True), (1, 1, 1))
    with pytest.raises(InputError, match=r"passivate=OH: the crystal has no O \(elements Si\)"):
        passivated_crystal_slab(oriented, 3, 0, ("top",), "OH")
    _slab, record = passivated_crystal_slab(oriented, 3, 0, ("top",), "H")
    assert record["species"] == "H" and record["added_atoms"] == {"H": record["top_dangling_bonds"]}


def test_a_build_relaxation_that_separates_the_slabs_is_an_error(monkeypatch):
    """The relaxation (a stand-in that lifts slab 2 by 45 Å, as the 0.51 Å CIF's did) is
    refused naming the bound; a relaxation within it passes."""
    from flatcontact.structures.recipe import parse_recipe

    recipe = parse_recipe({"kind": "fcc111", "element": "Cu", "layers": 3, "a_angstrom": 3.615})

    def lifting(lift):
        def relax(atoms, calc, fmax_ev_per_angstrom):
            atoms.positions[atoms.arrays["slab"] == 2, 2] += lift
            return {"converged": True, "steps": 1}

        return relax

    monkeypatch.setattr(construct, "relax", lifting(45.0))
    with pytest.raises(InputError, match=r"moved the slabs apart by 45 Å.*more than the 5 Å"):
        construct.build_interface(recipe, relax_calculator=object())
    monkeypatch.setattr(construct, "relax", lifting(0.2))
    _atoms, report = construct.build_interface(recipe, relax_calculator=object())
    assert report["interface_relaxation"]["converged"]
