"""Passivated crystal faces (recipe ``passivate: H | OH``) against the bulk's own coordination.

Bulk geometry from textbook values written here: diamond a = 3.567 Å (C–C 1.5446 Å), Si
a = 5.431 Å, α-quartz from :func:`flatcontact.structures.bulk.alpha_quartz`. The dangling bonds
are counted here independently of the builder: the unpassivated slab's coordination against
the bulk's (4 for C and Si in diamond, 4 for Si and 2 for O in quartz, from a neighbour list
of the bulk crystal itself).
"""

from __future__ import annotations

import numpy as np
import pytest
from ase import Atoms
from ase.build import bulk
from ase.neighborlist import neighbor_list

from flatcontact.foundation.errors import InputError
from flatcontact.structures.bulk import alpha_quartz
from flatcontact.structures.construct import build_interface
from flatcontact.structures.crystal import crystal_slab, orient, passivated_crystal_slab
from flatcontact.structures.interface_io import read_interface, write_interface
from flatcontact.structures.layers import bonded_components
from flatcontact.structures.recipe import parse_recipe
from flatcontact.structures.topology import bond_radii

DIAMOND = bulk("C", "diamond", a=3.567, cubic=True)
SILICON = bulk("Si", "diamond", a=5.431, cubic=True)


def _cn(atoms: Atoms) -> np.ndarray:
    i = neighbor_list("i", atoms, bond_radii(atoms))
    return np.bincount(i, minlength=len(atoms))


def _bulk_cn(crystal: Atoms) -> dict[str, int]:
    cn = _cn(crystal)
    out: dict[str, int] = {}
    for s, c in zip(crystal.get_chemical_symbols(), cn.tolist(), strict=True):
        assert out.setdefault(s, c) == c  # one coordination per element in these crystals
    return out


def _missing(slab: Atoms, bulk_cn: dict[str, int]) -> np.ndarray:
    cn = _cn(slab)
    return np.array([bulk_cn[s] for s in slab.get_chemical_symbols()]) - cn


@pytest.mark.parametrize(
    ("crystal", "ch"), [(DIAMOND, ("C", 1.09)), (SILICON, ("Si", 1.48))], ids=["C", "Si"]
)
@pytest.mark.parametrize("faces", [("top",), ("bottom", "top")])
def test_one_h_per_dangling_bond_along_the_broken_bond(crystal, ch, faces):
    """(111), widest-gap cut: H count = missing bonds of the chosen faces (bulk CN − slab CN),
    each H at the element's bond length from its atom, every crystal atom 4-fold afterwards,
    and no H on a face not chosen."""
    oriented = orient(crystal, (1, 1, 1))
    plain = crystal_slab(oriented, 4, 0)
    missing = _missing(plain, _bulk_cn(crystal))
    z = plain.positions[:, 2]
    mid = 0.5 * (z.min() + z.max())
    top, bottom = missing[z > mid].sum(), missing[z < mid].sum()
    assert top == 1 and bottom == 1  # C(111)/Si(111) 1x1: one dangling bond per face atom
    slab, record = passivated_crystal_slab(oriented, 4, 0, faces, "H")
    h = np.array(slab.get_chemical_symbols()) == "H"
    assert h.sum() == (top if faces == ("top",) else top + bottom)
    assert record["top_dangling_bonds"] == top
    host = ~h
    cn = _cn(slab)
    assert np.all(cn[h] == 1)
    i, d = neighbor_list("id", slab, bond_radii(slab))
    hd = d[h[i]]
    assert hd == pytest.approx(ch[1], abs=1e-9)
    # every atom of a passivated face 4-fold; a bare face keeps its dangling bond
    zs = slab.positions[:, 2]
    zc = zs[host]
    assert cn[host & (zs > 0.5 * (zc.min() + zc.max()))].min() == 4
    bottom_cn = cn[host & (zs < 0.5 * (zc.min() + zc.max()))].min()
    assert bottom_cn == (4 if "bottom" in faces else 3)
    # the H of the top face lies along the normal (the broken bond of (111)), above the slab
    if faces == ("top",):
        above = slab.positions[h][0] - slab.positions[host][np.argmax(zc)]
        assert above == pytest.approx([0.0, 0.0, ch[1]], abs=1e-9)
    assert bonded_components(slab).max() == 0  # one bonded piece


def test_passivation_only_adds_atoms():
    """The passivated slab's crystal atoms are the plain cut's (same positions up to one
    translation, same layers): the deeper block and the window change nothing else."""
    for crystal, miller in ((DIAMOND, (1, 1, 1)), (alpha_quartz(), (0, 0, 1))):
        oriented = orient(crystal, miller)
        plain = crystal_slab(oriented, 3, 0)
        slab, _ = passivated_crystal_slab(oriented, 3, 0, ("top",), "H")
        own = slice(0, len(plain))
        assert slab.get_chemical_symbols()[own] == plain.get_chemical_symbols()
        cell = plain.cell.array[:2, :2]

        def relative(atoms, n, cell=cell):  # from atom 0, in-plane fractions wrapped
            d = atoms.positions[:n] - atoms.positions[0]
            frac = np.linalg.solve(cell.T, d[:, :2].T).T
            return np.column_stack([(frac + 1e-9) % 1.0, d[:, 2]])

        np.testing.assert_allclose(
            relative(slab, len(plain)), relative(plain, len(plain)), atol=1e-8
        )
        assert np.array_equal(slab.arrays["layer"][own], plain.arrays["layer"])
        assert np.allclose(slab.cell.array[:2], plain.cell.array[:2])


def test_quartz_hydroxylated_faces_are_fully_coordinated_and_neutral():
    """α-quartz (0001), OH: every Si 4-fold (O neighbours), every O 2-fold (Si or H), every H
    1-fold; added = n H2O (charge-neutral: Si + 2 O per formula unit plus whole waters);
    Si–O(H) 1.63 Å, O–H 0.96 Å, Si–O–H 118°."""
    quartz = alpha_quartz()
    oriented = orient(quartz, (0, 0, 1))
    for termination in range(len(oriented.cuts_angstrom)):
        slab, record = passivated_crystal_slab(oriented, 3, termination, ("bottom", "top"), "OH")
        sym = np.array(slab.get_chemical_symbols())
        cn = _cn(slab)
        assert np.all(cn[sym == "Si"] == 4)
        assert np.all(cn[sym == "O"] == 2)
        assert np.all(cn[sym == "H"] == 1)
        n_si, n_o, n_h = (int((sym == s).sum()) for s in ("Si", "O", "H"))
        waters = n_o - 2 * n_si
        assert waters > 0 and n_h == 2 * waters
        i, j, d, v = neighbor_list("ijdD", slab, bond_radii(slab))
        oh = (sym[i] == "O") & (sym[j] == "H")
        assert d[oh] == pytest.approx(0.96, abs=1e-9)
        added_o = np.arange(len(slab)) >= 9 * 3
        si_oh = (sym[i] == "Si") & added_o[j]
        assert d[si_oh] == pytest.approx(1.63, abs=1e-9)
        for k in np.flatnonzero(added_o & (sym == "O")):
            to_si = v[(i == k) & (sym[j] == "Si")][0]
            to_h = v[(i == k) & (sym[j] == "H")][0]
            cos = to_si @ to_h / np.linalg.norm(to_si) / np.linalg.norm(to_h)
            assert np.degrees(np.arccos(cos)) == pytest.approx(118.0, abs=1e-6)
        assert record["species"] == "OH"


def test_crowded_dihydride_is_refused_in_one_line():
    """Diamond(100) 1×1: two dangling bonds per surface C; the ideal dihydride puts H atoms of
    neighbouring C 0.74 Å apart, which is no surface (the real one reconstructs 2×1)."""
    oriented = orient(DIAMOND, (1, 0, 0))
    with pytest.raises(InputError) as exc:
        passivated_crystal_slab(oriented, 3, 0, ("top",), "H", "structure.passivate")
    text = str(exc.value)
    assert "\n" not in text and text.startswith("structure.passivate=H") and "0.74" in text


@pytest.fixture
def diamond_cif(tmp_path):
    path = tmp_path / "diamond.cif"
    DIAMOND.write(path)
    return str(path)


def test_recipe_diamond_h_against_graphene(diamond_cif, tmp_path):
    """From the recipe: slab 1 is H-terminated diamond(111) (H only on the face towards the
    sheet, in the face layer), slab 2 graphene strained onto diamond's 1×1 cell; each slab is
    one bonded piece; the interface file round-trips."""
    recipe = {
        "kind": "crystal",
        "bulk": diamond_cif,
        "miller": [1, 1, 1],
        "layers": 4,
        "passivate": "H",
        "gap_angstrom": 2.6,
        "slab2": {"sheet": "graphene"},
    }
    atoms, report = build_interface(recipe)
    sym = np.array(atoms.get_chemical_symbols())
    slab = atoms.arrays["slab"]
    assert sym.tolist().count("H") == 1 and slab[sym == "H"][0] == 1
    h = np.flatnonzero(sym == "H")[0]
    assert atoms.arrays["surface"][h] == 2  # the free face layer of slab 1
    z = atoms.positions[:, 2]
    assert z[h] == z[slab == 1].max()
    assert z[slab == 2].min() - z[h] == pytest.approx(2.6, abs=1e-9)
    for which in (1, 2):
        assert bonded_components(atoms[slab == which]).max() == 0
    match = report["recipe"]["match"]
    assert match["slab2_strain_percent"] == pytest.approx([2.530483, 2.530483], abs=1e-5)
    assert report["recipe"]["slab1"]["passivation"]["top_dangling_bonds"] == 1
    assert atoms.info["material"] == "C(111)/graphene"
    back = read_interface(write_interface(atoms, tmp_path / "interface.extxyz"))
    assert back.get_chemical_symbols() == atoms.get_chemical_symbols()
    np.testing.assert_allclose(back.positions, atoms.positions, atol=1e-9)
    for key in ("slab", "surface", "layer", "held"):
        assert np.array_equal(back.arrays[key], atoms.arrays[key])


def test_same_crystal_both_interface_faces_passivated(diamond_cif):
    """No slab2: slab 2 is the same crystal, its bottom face passivated (or its top before a
    flip); ``both`` passivates the held outer faces too."""
    base = {"kind": "crystal", "bulk": diamond_cif, "miller": [1, 1, 1], "layers": 3}
    for extra, n_h in (({}, 2), ({"flip": True}, 2), ({"passivate_faces": "both"}, 4)):
        atoms, _ = build_interface({**base, "passivate": "H", "gap_angstrom": 2.0, **extra})
        sym = np.array(atoms.get_chemical_symbols())
        assert (sym == "H").sum() == n_h
        surface = atoms.arrays["surface"][sym == "H"]
        assert {2, 3} <= set(surface.tolist())
        assert atoms.info["material"] == "C(111)"
        slab = atoms.arrays["slab"]
        z = atoms.positions[:, 2]
        gap = z[slab == 2].min() - z[slab == 1].max()
        assert gap == pytest.approx(2.0, abs=1e-9)  # H to H across the interface


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        ({"passivate": "H"}, "gap_angstrom: required"),
        ({"slab2": {"sheet": "graphene"}}, "gap_angstrom: required"),
        ({"passivate": "F", "gap_angstrom": 2}, "structure.passivate"),
        ({"passivate_faces": "top"}, "structure.passivate_faces"),
        (
            {"slab2": {"sheet": "graphene", "layers": 0}, "gap_angstrom": 2},
            "structure.slab2.layers",
        ),
        ({"slab2": {"bulk": "y.cif"}}, "structure.slab2.miller"),
    ],
)
def test_bad_passivation_settings_name_the_field(extra, needle):
    with pytest.raises(InputError) as exc:
        parse_recipe({"kind": "crystal", "bulk": "x.cif", "miller": [1, 1, 1], **extra})
    assert needle in str(exc.value) and "\n" not in str(exc.value)


def test_config_check_refuses_h_for_a_carbon_only_potential(diamond_cif, tmp_path):
    """``config --check`` builds the passivated interface and refuses H for REBO set up for C
    only: one line naming the element and the potential, before any work."""
    from flatcontact.config import load_config
    from flatcontact.stages.preflight import check_inputs

    path = tmp_path / "c.yaml"
    path.write_text(
        f"structure: {{kind: crystal, bulk: {diamond_cif}, miller: [1, 1, 1], layers: 3, "
        "passivate: H, gap_angstrom: 2.6, slab2: {sheet: graphene}}\n"
        "potential: {intra: [{pair_style: rebo, pair_coeff: [CH.rebo], elements: [C]}], "
        "coupling: same}\n"
        "contact: {contact_modulus_gpa: 50, shear_modulus_gpa: 30}\n"
    )
    with pytest.raises(InputError) as exc:
        check_inputs(load_config(path), str(path))
    text = str(exc.value)
    assert "\n" not in text and "['H']" in text and "rebo(CH.rebo)" in text
    # with AIREBO (C and H) the same structure passes
    path.write_text(
        path.read_text().replace(
            "{pair_style: rebo, pair_coeff: [CH.rebo], elements: [C]}",
            "{pair_style: airebo 3.0 1 1, pair_coeff: [CH.airebo], elements: [C, H]}",
        )
    )
    check_inputs(load_config(path), str(path))


def test_preflight_elements_include_the_passivation_and_slab2(tmp_path):
    """A hydroxylated quartz crystal or quartz against graphene is not the paper's α-quartz:
    the moduli check sees H and C (it read only slab 1's bulk file before)."""
    from flatcontact.config import load_config
    from flatcontact.stages.build import structure_elements
    from flatcontact.stages.contact import check_moduli_source

    alpha_quartz().write(tmp_path / "q.cif")
    for extra, want in (
        ("", {"Si", "O"}),
        (", passivate: OH, gap_angstrom: 2", {"Si", "O", "H"}),
        (", gap_angstrom: 3, slab2: {sheet: graphene}", {"Si", "O", "C"}),
    ):
        path = tmp_path / "c.yaml"
        path.write_text(f"structure: {{kind: crystal, bulk: q.cif, miller: [0, 0, 1]{extra}}}\n")
        cfg = load_config(path)
        assert structure_elements(cfg.structure) == want
        if want == {"Si", "O"}:
            check_moduli_source(cfg, want)
        else:
            with pytest.raises(InputError, match=r"contact\.contact_modulus_gpa"):
                check_moduli_source(cfg, want)
