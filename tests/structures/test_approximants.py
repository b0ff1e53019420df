"""Commensurate approximant sequences: closed-form twist cells, the strain ladder, exact builds."""

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from flatcontact.config.approximants import parse_approximants
from flatcontact.config.merge import merge_config
from flatcontact.foundation.errors import InputError
from flatcontact.structures.approximants import approximant_sequence, coprime_twists
from flatcontact.structures.construct import build_interface
from flatcontact.structures.sheets import builtin_sheet

GRAPHENE = {"kind": "sheets", "sheet": "graphene", "layers": 1}


def _build(structure, approximant):
    """The interface of ``structure`` with the approximant's override merged the way a run
    configuration merges a section (nested mappings key by key)."""
    merged = merge_config({"structure": structure}, {"structure": approximant.structure_override})
    return build_interface(merged["structure"])


def _cross(u, v) -> float:
    return float(u[0] * v[1] - u[1] * v[0])


def _coincidence_cells(theta_deg: float, radius_cells: int = 40) -> int:
    """Primitive cells of graphene's lattice L in the coincidence lattice L ∩ R(θ)L, by brute
    force: the two shortest non-collinear vectors of L that R(θ)L also holds (a reduced
    basis of the coincidence lattice) span its cell."""
    a = builtin_sheet("graphene").cell.array[:2, :2]
    t = np.radians(theta_deg)
    rot = np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])
    inv_rotated = np.linalg.inv((rot @ a.T).T)
    r = np.arange(-radius_cells, radius_cells + 1)
    ij = np.array([(i, j) for i in r for j in r if (i, j) != (0, 0)], float)
    v = ij @ a
    frac = v @ inv_rotated
    common = v[np.all(np.abs(frac - np.round(frac)) < 1e-6, axis=1)]
    common = common[np.argsort(np.linalg.norm(common, axis=1))]
    first = common[0]
    second = next(w for w in common[1:] if abs(_cross(first, w)) > 1e-6)
    return round(abs(_cross(first, second)) / abs(np.linalg.det(a)))


def test_small_angle_family_is_the_closed_form_with_the_stated_atom_counts():
    """No target: (1,2), (2,3), (3,4), ... with cos θ = (m²+4mn+n²)/(2(m²+mn+n²)) and
    4(m²+mn+n²) atoms for a graphene bilayer (two atoms per cell per layer)."""
    seq = approximant_sequence(GRAPHENE, parse_approximants({"max_atoms": 400}))
    assert [a.label for a in seq] == [
        "twist-1-2",
        "twist-2-3",
        "twist-3-4",
        "twist-4-5",
        "twist-5-6",
    ]
    expected = [(21.787, 28), (13.174, 76), (9.430, 148), (7.341, 244), (6.009, 364)]
    for a, (theta, atoms) in zip(seq, expected, strict=True):
        assert a.twist_deg == pytest.approx(theta, abs=5e-4)
        assert a.n_atoms == atoms
        assert a.angle_error_deg == 0.0
        assert a.strain_percent_slab1 == a.strain_percent_slab2 == (0.0, 0.0)
    for a in seq:
        m, n = a.structure_override["twist"]
        cos = (m * m + 4 * m * n + n * n) / (2 * (m * m + m * n + n * n))
        assert math.degrees(math.acos(cos)) == pytest.approx(a.twist_deg, abs=1e-9)
        # area: m²+mn+n² primitive cells of graphene, √3/2·a² each
        cells = m * m + m * n + n * n
        assert a.cells_per_layer == cells
        assert a.area_angstrom2 == pytest.approx(cells * math.sqrt(3) / 2 * 2.46**2, rel=1e-9)
    assert len(approximant_sequence(GRAPHENE, parse_approximants({"max_cells": 2}))) == 2


@pytest.mark.parametrize("target", [30.0, 1.1, 7.0, 45.0])
def test_angle_error_falls_strictly_with_size_and_no_smaller_cell_is_closer(target):
    seq = approximant_sequence(
        GRAPHENE, parse_approximants({"twist_deg": target, "max_atoms": 3000, "max_cells": 50})
    )
    assert len(seq) >= 3
    sizes = [a.n_atoms for a in seq]
    errors = [abs(a.angle_error_deg) for a in seq]
    assert sizes == sorted(sizes) and len(set(sizes)) == len(sizes)
    assert all(b < a for a, b in itertools.pairwise(errors))
    for a in seq:
        assert a.angle_error_deg == pytest.approx(a.twist_deg - target, abs=1e-12)
    # the best approximant within the bound: no twist of the brute-force coincidence
    # enumeration up to the largest cell is closer to the target than the last one
    last = seq[-1]
    for m, n in coprime_twists(last.cells_per_layer):
        theta = math.degrees(math.acos((m * m + 4 * m * n + n * n) / (2 * (m * m + m * n + n * n))))
        assert abs(theta - target) >= errors[-1] - 1e-9


def test_cell_size_rule_of_coprime_twists_against_brute_force_coincidence():
    """The cell built for coprime (m, n) is the coincidence cell when 3 ∤ m − n, three
    times it when 3 | m − n (Shallcross et al. 2010)."""
    for m, n in coprime_twists(60):
        seq_cells = m * m + m * n + n * n
        theta = math.degrees(math.acos((m * m + 4 * m * n + n * n) / (2 * (m * m + m * n + n * n))))
        true = _coincidence_cells(theta)
        assert seq_cells == (3 * true if (m - n) % 3 == 0 else true), (m, n)


@pytest.mark.parametrize("target", [None, 30.0])
def test_each_twist_override_builds_the_stated_cell(target):
    settings = parse_approximants({"twist_deg": target, "max_atoms": 400, "max_cells": 4})
    for a in approximant_sequence(GRAPHENE, settings):
        atoms, report = _build(GRAPHENE, a)
        record = report["recipe"]
        assert len(atoms) == a.n_atoms
        assert record["twist_angle_deg"] == pytest.approx(a.twist_deg, abs=1e-9)
        assert record["match"]["kind"] == "twist"
        assert abs(np.linalg.det(atoms.cell.array[:2, :2])) == pytest.approx(
            a.area_angstrom2, rel=1e-9
        )


def test_twist_of_thicker_slabs_counts_every_layer():
    structure = {"kind": "sheets", "sheet": "graphene", "layers": 2, "stacking": "AB"}
    seq = approximant_sequence(structure, parse_approximants({"max_atoms": 400}))
    assert [a.n_atoms for a in seq] == [56, 152, 296]  # 2 slabs × 2 layers × 2 atoms × cells
    atoms, _ = _build(structure, seq[1])
    assert len(atoms) == 152


def test_bad_combinations_are_refused_naming_the_field():
    with pytest.raises(InputError, match=r"approximants\.strain_percent"):
        approximant_sequence(GRAPHENE, parse_approximants({"strain_percent": [1.0]}))
    with pytest.raises(InputError, match=r"approximants\.max_atoms=20"):
        approximant_sequence(GRAPHENE, parse_approximants({"max_atoms": 20}))
    with pytest.raises(InputError, match=r"structure\.kind='toy-lj'"):
        approximant_sequence({"kind": "toy-lj"}, parse_approximants({}))
    square = {"kind": "fcc111", "element": "Cu"}  # hexagonal: accepted
    assert approximant_sequence(square, parse_approximants({"max_atoms": 200}))[0].n_atoms == 84


GRAPHENE_ON_HBN = {
    "kind": "sheets",
    "sheet": "graphene",
    "stacking": "A",
    "slab2": {"sheet": "h-BN", "stacking": "A"},
}
A_GRAPHENE, A_HBN = 2.46, 2.504


@pytest.mark.parametrize("strain_on", ["slab2", "both"])
def test_strain_ladder_cells_within_their_bounds_strain_falling_and_built_exactly(strain_on):
    settings = parse_approximants(
        {"strain_percent": [3.0, 2.5, 1.0, 0.3], "strain_on": strain_on, "max_atoms": 300}
    )
    seq = approximant_sequence(GRAPHENE_ON_HBN, settings)
    # 2.5 % is met by the 3 % cell already (mismatch 1.76 %): skipped; 0.3 %: none <= 300 atoms
    assert [a.label for a in seq] == ["zsl-3pct", "zsl-1pct"]
    worst = [max(map(abs, a.strain_percent_slab1 + a.strain_percent_slab2)) for a in seq]
    assert all(b < a for a, b in itertools.pairwise(worst))
    for a, bound in zip(seq, (3.0, 1.0), strict=True):
        assert a.kind == "coincidence" and a.angle_error_deg == 0.0
        assert worst[seq.index(a)] <= bound
        assert a.n_atoms <= 300
        # independent: the isotropic strain is the ratio of the two supercells' vector lengths
        m = a.structure_override["match"]
        t1 = np.array(m["slab1_supercell"]) @ builtin_sheet("graphene").cell.array[:2, :2]
        t2 = np.array(m["slab2_supercell"]) @ builtin_sheet("h-BN").cell.array[:2, :2]
        ratio = np.linalg.norm(t1[0]) / np.linalg.norm(t2[0])
        assert np.linalg.norm(t1[1]) / np.linalg.norm(t2[1]) == pytest.approx(ratio, rel=1e-6)
        if strain_on == "slab2":
            assert a.strain_percent_slab1 == (0.0, 0.0)
            np.testing.assert_allclose(a.strain_percent_slab2, 100 * (ratio - 1), atol=1e-5)
        else:  # the mean cell: opposite strains, (1 + e1)·ratio... = mean length
            mean = 0.5 * (1.0 + 1.0 / ratio)
            np.testing.assert_allclose(a.strain_percent_slab1, 100 * (mean - 1), atol=1e-5)
            np.testing.assert_allclose(a.strain_percent_slab2, 100 * (mean * ratio - 1), atol=1e-5)
        atoms, report = _build(GRAPHENE_ON_HBN, a)
        match = report["recipe"]["match"]
        assert len(atoms) == match["n_atoms"] == a.n_atoms
        np.testing.assert_allclose(match["slab1_strain_percent"], a.strain_percent_slab1)
        np.testing.assert_allclose(match["slab2_strain_percent"], a.strain_percent_slab2)
        assert abs(np.linalg.det(atoms.cell.array[:2, :2])) == pytest.approx(
            a.area_angstrom2, rel=1e-9
        )
    # the smallest cell is the 1×1 lock: h-BN compressed onto graphene (closed form)
    if strain_on == "slab2":
        np.testing.assert_allclose(
            seq[0].strain_percent_slab2, 2 * [100 * (A_GRAPHENE / A_HBN - 1)], atol=1e-5
        )


def test_explicit_supercells_are_checked_naming_the_field():
    base = {**GRAPHENE_ON_HBN, "match": {"max_atoms": 600}}
    good = {"slab1_supercell": [[4, 6], [-2, 4]], "slab2_supercell": [[6, 3], [3, 6]]}
    atoms, report = build_interface({**base, "match": {"max_atoms": 600, **good}})
    assert len(atoms) == 110 and report["recipe"]["match"]["supercells"].startswith("given")
    cases = [
        ({"slab1_supercell": [[1, 0], [0, 1]]}, r"structure\.match: .*slab2_supercell"),
        (
            {"slab1_supercell": [[0, 1], [1, 0]], "slab2_supercell": [[1, 0], [0, 1]]},
            r"structure\.match.*slab1_supercell.*positive determinant",
        ),
        (  # 1×1 on 1×1 strains h-BN by 1.76 % > 1 %
            {
                "slab1_supercell": [[1, 0], [0, 1]],
                "slab2_supercell": [[1, 0], [0, 1]],
                "max_strain_percent": 1.0,
            },
            r"structure\.match\.slab2_supercell: the cell strains slab 2 by 1\.7",
        ),
    ]
    for match, pattern in cases:
        with pytest.raises(InputError, match=pattern):
            build_interface({**base, "match": {"max_atoms": 600, **match}})
    with pytest.raises(InputError, match=r"structure\.match\.slab1_supercell: explicit"):
        build_interface({**GRAPHENE, "match": good})


def test_ladder_refusals_name_the_field():
    with pytest.raises(InputError, match=r"approximants\.strain_percent=1: .* at 0 ± 0\.5°"):
        approximant_sequence(  # aligned graphene/h-BN within 1 % needs n = 37: 5330 atoms
            GRAPHENE_ON_HBN,
            parse_approximants({"twist_deg": 0.0, "strain_percent": [1.0], "max_atoms": 2000}),
        )
    with pytest.raises(InputError, match=r"approximants\.strain_percent=0\.01"):
        approximant_sequence(
            GRAPHENE_ON_HBN, parse_approximants({"strain_percent": [0.01], "max_atoms": 200})
        )


def test_aligned_ladder_is_the_homothetic_n_on_n_minus_1_cell():
    """Slab 2 held at 0° (tolerance 0.001°): the only coincidence cells are n×n graphene on
    m×m h-BN; the smallest within 1.7 % has the least n with |n·a_g/((n−1)·a_hBN) − 1| ≤ 1.7 %
    (found here by a plain loop)."""
    n = next(n for n in range(2, 200) if abs(n * A_GRAPHENE / ((n - 1) * A_HBN) - 1) <= 0.017)
    settings = parse_approximants(
        {
            "twist_deg": 0.0,
            "angle_tolerance_deg": 0.001,
            "strain_percent": [3.0, 1.7],
            "max_atoms": 2 * n * n + 2 * (n - 1) ** 2,
        }
    )
    first, aligned = approximant_sequence(GRAPHENE_ON_HBN, settings)
    assert first.n_atoms == 4 and first.twist_deg == 0.0
    assert aligned.n_atoms == 2 * n * n + 2 * (n - 1) ** 2  # 3482 for n = 30
    assert aligned.cells_per_layer == n * n
    expected = 100 * (n * A_GRAPHENE / ((n - 1) * A_HBN) - 1)
    np.testing.assert_allclose(aligned.strain_percent_slab2, [expected, expected], atol=1e-5)
    assert abs(aligned.angle_error_deg) < 1e-6


def test_oriented_ladder_keeps_the_target_rotation_and_builds_exactly():
    settings = parse_approximants(
        {"twist_deg": 30.0, "strain_percent": [3.0, 1.0, 0.3], "max_atoms": 1000}
    )
    seq = approximant_sequence(GRAPHENE_ON_HBN, settings)
    assert len(seq) == 3
    worst = [max(map(abs, a.strain_percent_slab1 + a.strain_percent_slab2)) for a in seq]
    assert all(b < a for a, b in itertools.pairwise(worst))
    for a, bound in zip(seq, (3.0, 1.0, 0.3), strict=True):
        assert worst[seq.index(a)] <= bound
        assert abs(a.angle_error_deg) <= 0.5 + 1e-9
        # the rotation modulo the hexagonal 60°: 30° ± 0.5°
        assert abs((a.twist_deg - 30.0 + 30.0) % 60.0 - 30.0) <= 0.5 + 1e-9
        atoms, report = _build(GRAPHENE_ON_HBN, a)
        match = report["recipe"]["match"]
        assert len(atoms) == a.n_atoms
        assert match["slab2_rotation_deg"] == pytest.approx(a.twist_deg, abs=1e-5)
        np.testing.assert_allclose(match["slab2_strain_percent"], a.strain_percent_slab2)


def test_approximants_of_zero_twist_are_the_small_angle_family():
    """Toward 0° the best approximant of each size is (n, n+1): the no-target sequence."""
    big = {"max_atoms": 4000, "max_cells": 50}
    toward_zero = approximant_sequence(GRAPHENE, parse_approximants({"twist_deg": 0.0, **big}))
    family = approximant_sequence(GRAPHENE, parse_approximants(big))
    assert [a.label for a in toward_zero] == [a.label for a in family]
    assert [a.label for a in family][:3] == ["twist-1-2", "twist-2-3", "twist-3-4"]


def test_two_materials_of_one_lattice_are_refused_naming_slab2():
    """Cu(111) against Cu(111) given as another material: one lattice, no twist possible."""
    same = {"kind": "fcc111", "element": "Cu", "layers": 1, "slab2": {"element": "Cu", "layers": 1}}
    with pytest.raises(InputError, match=r"structure\.slab2: .* same in-plane lattice"):
        approximant_sequence(same, parse_approximants({}))


def test_diamond_graphene_ladder_keeps_the_cells_zsl_yields_with_the_other_handedness():
    """Issue 32: the approximant example lost its 0.3 % cell when pymatgen 2026.10 yielded
    that coincidence cell only as vector pairs of opposite handedness. The ladder of the
    example has three cells again, each the smallest of its bound: checked independently by
    the lengths of the two supercells' vectors (37 diamond cells against 39 graphene cells
    for 0.3 %: |a_g|√39 / |a_d|√37 − 1 = the strain) and by building it."""
    from flatcontact.config.load import load_config

    cfg = load_config(
        Path(__file__).parents[2]
        / "examples"
        / "passivated-tip-bare-diamond-graphene-approximants.yaml"
    )
    seq = approximant_sequence(cfg.section("structure"), cfg.approximants)
    assert [a.label for a in seq] == ["zsl-3pct", "zsl-1pct", "zsl-0.3pct"]
    assert [a.n_atoms for a in seq] == [14, 380, 522]
    third = seq[2]
    m = third.structure_override["match"]
    assert abs(round(np.linalg.det(m["slab1_supercell"]))) == 37
    assert abs(round(np.linalg.det(m["slab2_supercell"]))) == 39
    a_d, a_g = 2.52224989, 2.46  # the example's diamond(111) and graphene cells (Å)
    want = 100 * (a_d * math.sqrt(37) / (a_g * math.sqrt(39)) - 1)
    np.testing.assert_allclose(third.strain_percent_slab2, [want, want], atol=2e-3)
    atoms, report = _build(cfg.section("structure"), third)
    assert len(atoms) == 522 == report["recipe"]["match"]["n_atoms"]
