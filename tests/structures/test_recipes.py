"""Interface recipes: hetero coincidence lattices, commensurate twists, AA′, bad input."""

import json

import numpy as np
import pytest
from ase.build import bulk
from ase.io import write
from ase.neighborlist import neighbor_list

from flatcontact.foundation.errors import InputError
from flatcontact.structures.construct import build_interface
from flatcontact.structures.interface_contract import thickness
from flatcontact.structures.match import twist_angle_deg
from flatcontact.structures.recipe import parse_recipe

A_GRAPHENE, A_HBN = 2.46, 2.504


def _lateral_offsets(atoms, lower, upper):
    """Minimum-image in-plane distance from each atom of ``upper`` to the closest of ``lower``."""
    cell = atoms.cell.array[:2, :2]
    out = []
    for q in atoms.positions[upper, :2]:
        d = np.linalg.solve(cell.T, (q - atoms.positions[lower, :2]).T).T
        d -= np.round(d)
        out.append(np.linalg.norm(d @ cell, axis=1))
    return np.array(out)


def test_graphene_on_hbn_strain_is_the_lattice_mismatch():
    base = {
        "kind": "sheets",
        "sheet": "graphene",
        "stacking": "A",
        "slab2": {"sheet": "h-BN", "stacking": "A"},
    }
    atoms, report = build_interface(base)
    match = report["recipe"]["match"]
    assert match["kind"] == "coincidence" and match["n_atoms"] == len(atoms) == 4
    # strain on slab 2 (default): h-BN compressed onto graphene's lattice
    expected = 100 * (A_GRAPHENE / A_HBN - 1.0)  # -1.757 %
    np.testing.assert_allclose(match["slab2_strain_percent"], [expected, expected], atol=1e-5)
    np.testing.assert_allclose(match["slab1_strain_percent"], [0.0, 0.0], atol=1e-9)
    assert match["slab2_rotation_deg"] == pytest.approx(0.0, abs=1e-9)
    assert np.linalg.norm(atoms.cell[0]) == pytest.approx(A_GRAPHENE, abs=1e-9)
    assert atoms.info["material"] == "graphene/h-BN"
    # shared: both slabs strained to the mean lattice, opposite signs
    atoms, report = build_interface({**base, "match": {"strain_on": "both"}})
    match = report["recipe"]["match"]
    mean = 0.5 * (A_GRAPHENE + A_HBN)
    np.testing.assert_allclose(
        match["slab1_strain_percent"], 100 * (mean / A_GRAPHENE - 1), atol=1e-5
    )
    np.testing.assert_allclose(match["slab2_strain_percent"], 100 * (mean / A_HBN - 1), atol=1e-5)
    assert np.linalg.norm(atoms.cell[0]) == pytest.approx(mean, abs=1e-9)
    # graphene/h-BN interlayer: mean of graphite and h-BN
    assert thickness(atoms) == pytest.approx(0.5 * (3.35 + 3.33), abs=1e-9)


def test_tighter_strain_bound_gives_a_larger_exact_coincidence_cell():
    atoms, report = build_interface(
        {
            "kind": "sheets",
            "sheet": "graphene",
            "stacking": "A",
            "slab2": {"sheet": "h-BN", "stacking": "A"},
            "match": {"max_strain_percent": 1.0, "max_atoms": 200},
        }
    )
    match = report["recipe"]["match"]
    assert max(abs(s) for s in match["slab2_strain_percent"]) <= 1.0
    p1, p2 = np.array(match["slab1_supercell"]), np.array(match["slab2_supercell"])
    n1, n2 = round(abs(np.linalg.det(p1))), round(abs(np.linalg.det(p2)))
    assert 2 * n1 + 2 * n2 == len(atoms) == match["n_atoms"] <= 200
    symbols = np.array(atoms.get_chemical_symbols())
    assert np.sum(symbols == "C") == 2 * n1 and np.sum(symbols == "B") == n2
    # the common cell's area is n1 graphene cells, and n2 h-BN cells strained as reported
    area = abs(np.linalg.det(atoms.cell.array[:2, :2]))
    assert area == pytest.approx(n1 * A_GRAPHENE**2 * np.sqrt(3) / 2, rel=1e-9)
    e = np.array(match["slab2_strain_percent"]) / 100
    assert area == pytest.approx(n2 * A_HBN**2 * np.sqrt(3) / 2 * (1 + e[0]) * (1 + e[1]), rel=1e-7)
    # every B-N bond of slab 2 keeps its strained length
    slab2 = atoms[atoms.arrays["slab"] == 2]
    d = neighbor_list("d", slab2, 1.6)
    np.testing.assert_allclose(d, A_HBN / np.sqrt(3) * (1 + e[0]), atol=1e-6)


def test_commensurate_twist_1_2():
    theta = twist_angle_deg(1, 2)
    assert theta == pytest.approx(np.degrees(np.arccos(13 / 14)), abs=1e-12)
    assert theta == pytest.approx(21.787, abs=5e-4)
    for layers in (1, 2):
        atoms, report = build_interface(
            {
                "kind": "sheets",
                "sheet": "graphene",
                "stacking": "AB",
                "layers": layers,
                "twist": [1, 2],
            }
        )
        m, n = 1, 2
        # closed form: 2 atoms per graphene cell, m²+mn+n² cells per layer, 2·layers layers
        assert len(atoms) == 2 * (m * m + m * n + n * n) * 2 * layers
        rec = report["recipe"]
        assert rec["twist_angle_deg"] == pytest.approx(theta, abs=1e-9)
        assert rec["match"]["slab2_rotation_deg"] == pytest.approx(theta, abs=1e-6)
        np.testing.assert_allclose(rec["match"]["slab2_strain_percent"], 0.0, atol=1e-9)
        # unstrained: every C-C bond 1.42 Å, three per atom, in both slabs
        i, d = neighbor_list("id", atoms, 1.6)
        np.testing.assert_allclose(d, A_GRAPHENE / np.sqrt(3), atol=1e-9)
        assert np.all(np.bincount(i, minlength=len(atoms)) == 3)
    # the bond directions of the two facing layers differ by θ (mod 60°)
    lay = atoms.arrays["layer"]
    angles = []
    for k in (2, 3):
        sub = atoms[lay == k]
        _, vec = neighbor_list("iD", sub, 1.6)
        angles.append(np.degrees(np.arctan2(vec[0, 1], vec[0, 0])) % 60.0)
    assert (angles[1] - angles[0]) % 60.0 == pytest.approx(theta, abs=1e-6) or (
        angles[0] - angles[1]
    ) % 60.0 == pytest.approx(theta, abs=1e-6)


def test_hbn_slab2_rotated_180_is_AA_prime():
    atoms, report = build_interface(
        {"kind": "sheets", "sheet": "h-BN", "stacking": "A", "rotate_deg": 180}
    )
    sym = np.array(atoms.get_chemical_symbols())
    slab = atoms.arrays["slab"]
    for top, below in (("B", "N"), ("N", "B")):
        offsets = _lateral_offsets(atoms, (slab == 1) & (sym == below), (slab == 2) & (sym == top))
        assert offsets.min() < 1e-9  # B over N and N over B
    assert "rotated 180" in report["recipe"]["slab2_operation"]
    # the stacking letters say the same: AA'
    primed, _ = build_interface({"kind": "sheets", "sheet": "h-BN", "stacking": "AA'"})
    np.testing.assert_allclose(primed.positions, atoms.positions, atol=1e-9)
    # unrotated AA: B over B
    aa, _ = build_interface({"kind": "sheets", "sheet": "h-BN", "stacking": "A"})
    sym = np.array(aa.get_chemical_symbols())
    assert _lateral_offsets(aa, (slab == 1) & (sym == "B"), (slab == 2) & (sym == "B")).min() < 1e-9


def test_flip_and_terminations_of_a_polar_crystal(tmp_path):
    cif = tmp_path / "NaCl.cif"
    write(cif, bulk("NaCl", "rocksalt", a=5.64, cubic=True))
    base = {"kind": "crystal", "bulk": str(cif), "miller": [1, 1, 1], "layers": 3}
    plain, report = build_interface(base)
    assert report["recipe"]["slab1"]["terminations"] == 2
    sym = np.array(plain.get_chemical_symbols())
    layer = plain.arrays["layer"]
    for k in np.unique(layer):  # every layer is one Na and one Cl plane (stoichiometric)
        assert sorted(sym[layer == k]) == ["Cl", "Na"]

    def ends(atoms):
        sym, z, sl = (
            np.array(atoms.get_chemical_symbols()),
            atoms.positions[:, 2],
            atoms.arrays["slab"],
        )
        lo1 = sym[sl == 1][np.argmin(z[sl == 1])]
        hi1 = sym[sl == 1][np.argmax(z[sl == 1])]
        lo2 = sym[sl == 2][np.argmin(z[sl == 2])]
        return lo1, hi1, lo2

    lo1, hi1, lo2 = ends(plain)
    assert lo1 != hi1  # polar (111) slab: a Na face and a Cl face
    assert lo2 == lo1  # continuation: slab 2 starts like slab 1 (the bulk across the cut)
    flipped, report = build_interface({**base, "flip": True})
    lo1f, hi1f, lo2f = ends(flipped)
    assert (lo1f, hi1f) == (lo1, hi1) and lo2f == hi1  # flipped: the same face on both sides
    assert "flipped" in report["recipe"]["slab2_operation"]
    other, _ = build_interface({**base, "termination": 1})
    assert ends(other)[0] == hi1  # the other termination puts the other species at the bottom


@pytest.mark.parametrize(
    ("recipe", "field"),
    [
        ({"kind": "crystal", "bulk": "CU", "miller": [0, 0, 0]}, "structure.miller"),
        (
            {"kind": "crystal", "bulk": "CU", "miller": [1, 1, 1], "termination": 3},
            "structure.termination",
        ),
        ({"kind": "crystal", "bulk": "missing.cif", "miller": [1, 1, 1]}, "structure.bulk"),
        ({"kind": "crystal", "bulk": "GARBAGE", "miller": [1, 1, 1]}, "structure.bulk"),
        ({"kind": "fcc111", "element": "Xx"}, "element"),
        ({"kind": "fcc111", "element": "Fe"}, "element"),
        ({"kind": "sheets", "sheet": "graphyne"}, "structure.sheet"),
        ({"kind": "sheets", "sheet": "graphene", "stacking": "AX"}, "structure.stacking"),
        ({"kind": "sheets", "sheet": "graphene", "layers": 0}, "structure.layers"),
        (
            {"kind": "sheets", "sheet": "graphene", "layers": 50, "match": {"max_atoms": 100}},
            "structure.match.max_atoms",
        ),
        (
            {"kind": "sheets", "sheet": "graphene", "twist": [3, 5], "match": {"max_atoms": 100}},
            "structure.match.max_atoms",
        ),
        (
            {
                "kind": "sheets",
                "sheet": "graphene",
                "slab2": {"sheet": "MoS2"},
                "match": {"max_strain_percent": 0.1, "max_atoms": 60},
            },
            "structure.slab2",
        ),
        ({"kind": "sheets", "sheet": "graphene", "rotate_deg": 17}, "structure.rotate_deg"),
        (
            {"kind": "fcc111", "element": "Cu", "layers": 3, "held_layers": 3},
            "structure.held_layers",
        ),
    ],
)
def test_bad_input_is_one_line_naming_the_field_before_any_work(recipe, field, tmp_path):
    cu = tmp_path / "Cu.cif"
    write(cu, bulk("Cu", "fcc", a=3.615, cubic=True))
    garbage = tmp_path / "garbage.cif"
    garbage.write_text("this is not a crystal\n")
    recipe = json.loads(
        json.dumps(recipe)
        .replace('"CU"', json.dumps(str(cu)))
        .replace('"GARBAGE"', json.dumps(str(garbage)))
    )

    def must_not_run(atoms):
        raise AssertionError("the calculator was built before the input was checked")

    with pytest.raises(InputError) as err:
        build_interface(recipe, relax_calculator=must_not_run)
    message = str(err.value)
    assert field in message and "\n" not in message


def test_parse_recipe_names_the_field():
    with pytest.raises(InputError, match=r"^structure\.miller"):
        parse_recipe({"kind": "crystal", "bulk": "x.cif", "miller": [1, 1]})
    with pytest.raises(InputError, match=r"^structure\.match\.max_strain_percent"):
        parse_recipe({"kind": "sheets", "sheet": "graphene", "match": {"max_strain_percent": -1}})
    for data in ({"kind": "nanotube"}, {"sheet": "graphene"}):
        with pytest.raises(InputError, match=r"^structure\.kind=.*expected one of quartz-dense"):
            parse_recipe(data)
    recipe = parse_recipe({"kind": "quartz-dense"})
    assert recipe.layers == 6 and recipe.source == "auto" and recipe.gap_angstrom == 3.0


def test_slab_files_monolayer_sheets_and_metal(tmp_path):
    """A monolayer file (the case that once could not be tagged), a 3-sheet file, a Cu slab."""
    from ase.build import fcc111, graphene

    from flatcontact.structures.interface_contract import validate_interface

    mono = graphene(formula="C2", a=2.46, vacuum=8.0)
    write(tmp_path / "g1.extxyz", mono)
    atoms, report = build_interface(
        {"kind": "slab", "file": str(tmp_path / "g1.extxyz"), "gap_angstrom": 3.35}
    )
    assert atoms.arrays["surface"].tolist() == [2, 2, 3, 3] and atoms.arrays["held"].all()
    assert thickness(atoms) == pytest.approx(3.35, abs=1e-9)
    validate_interface(atoms)
    three, _ = build_interface(
        {"kind": "sheets", "sheet": "graphene", "layers": 3, "stacking": "AB"}
    )
    write(tmp_path / "g3.extxyz", three[three.arrays["slab"] == 1])
    atoms, report = build_interface({"kind": "slab", "file": str(tmp_path / "g3.extxyz")})
    assert (
        report["recipe"]["layer_rule"] == "bonded sheets"
        and report["recipe"]["layers_per_slab"] == 3
    )
    assert atoms.arrays["layer"].tolist() == [1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6]
    cu = fcc111("Cu", size=(1, 1, 5), a=3.615, vacuum=6.0)
    cu.info.clear()
    write(tmp_path / "cu.extxyz", cu)
    atoms, report = build_interface(
        {"kind": "slab", "file": str(tmp_path / "cu.extxyz"), "held_layers": 2}
    )
    assert report["recipe"]["layer_rule"] == "atomic planes"
    assert atoms.arrays["surface"].tolist() == [1, 1, 0, 0, 2, 3, 0, 0, 4, 4]
    with pytest.raises(InputError, match=r"structure\.held_layers"):
        build_interface({"kind": "slab", "file": str(tmp_path / "cu.extxyz"), "held_layers": 5})
    with pytest.raises(InputError, match=r"structure\.file"):
        build_interface({"kind": "slab", "file": str(tmp_path / "none.extxyz")})


def test_reference_relaxation_with_a_calculator_or_a_factory():
    """With a calculator the interface is relaxed once (nothing held); the recipe records the
    relaxed thickness. The toy LJ minimum (2^(1/6)·2.5 Å) is wider than Cu's spacing."""
    from flatcontact.ispes.toy import toy_calculator
    from flatcontact.structures.toy import ToyPairCalculator

    recipe = {"kind": "fcc111", "element": "Cu", "layers": 3, "fmax_ev_per_angstrom": 1e-3}
    ideal, _ = build_interface(recipe)
    for calc in (ToyPairCalculator(), toy_calculator):
        atoms, report = build_interface(recipe, relax_calculator=calc)
        relaxation = report["interface_relaxation"]
        assert relaxation["converged"] and relaxation["max_force_ev_per_angstrom"] < 1e-3
        assert thickness(atoms) > thickness(ideal) + 0.1
        assert json.loads(atoms.info["recipe"])["thickness_angstrom"] == thickness(atoms)
        assert atoms.calc is None
        np.testing.assert_array_equal(atoms.arrays["held"], ideal.arrays["held"])


def test_sheet_from_a_poscar_equals_the_built_in(tmp_path):
    from ase.build import graphene

    sheet = graphene(formula="C2", a=A_GRAPHENE, vacuum=10.0)
    sheet.pbc = True
    write(tmp_path / "POSCAR", sheet, format="vasp")
    recipe = {"kind": "sheets", "layers": 2, "stacking": "AB", "interlayer_angstrom": 3.35}
    from_file, report = build_interface({**recipe, "sheet": str(tmp_path / "POSCAR")})
    built_in, _ = build_interface({**recipe, "sheet": "graphene"})
    np.testing.assert_allclose(from_file.positions, built_in.positions, atol=1e-6)
    np.testing.assert_array_equal(from_file.arrays["layer"], built_in.arrays["layer"])
    assert report["recipe"]["slab1"]["file"] == "POSCAR"
    with pytest.raises(InputError, match=r"structure\.interlayer_angstrom: required"):
        build_interface({"kind": "sheets", "sheet": str(tmp_path / "POSCAR")})
    two = built_in[built_in.arrays["slab"] == 1]  # two sheets in one file: not a monolayer
    write(tmp_path / "two.extxyz", two)
    with pytest.raises(InputError, match="2 separate bonded pieces"):
        build_interface({**recipe, "sheet": str(tmp_path / "two.extxyz")})


def test_resolve_paths_and_input_files(tmp_path):
    from flatcontact.structures.recipe import input_files, resolve_paths

    write(tmp_path / "Cu.cif", bulk("Cu", "fcc", a=3.615, cubic=True))
    write(tmp_path / "Ni.cif", bulk("Ni", "fcc", a=3.52, cubic=True))
    recipe = parse_recipe(
        {
            "kind": "crystal",
            "bulk": "Cu.cif",
            "miller": [1, 1, 1],
            "layers": 2,
            "slab2": {"bulk": "Ni.cif", "miller": [1, 1, 1], "layers": 2},
        }
    )
    resolved = resolve_paths(recipe, tmp_path)
    assert input_files(resolved) == [tmp_path / "Cu.cif", tmp_path / "Ni.cif"]
    atoms, report = build_interface(resolved)
    assert atoms.info["material"] == "Cu(111)/Ni(111)"
    a_cu, a_ni = 3.615 / np.sqrt(2), 3.52 / np.sqrt(2)
    np.testing.assert_allclose(
        report["recipe"]["match"]["slab2_strain_percent"], 100 * (a_cu / a_ni - 1), atol=1e-5
    )
    sheets = parse_recipe({"kind": "sheets", "sheet": "graphene", "slab2": {"sheet": "h-BN"}})
    assert input_files(resolve_paths(sheets, tmp_path)) == []
