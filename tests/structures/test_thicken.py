"""Thicker dense quartz slabs: bulk c-repeats inserted into the shipped slab (structures.thicken)."""

import numpy as np
import pytest
from ase.filters import FrechetCellFilter
from ase.optimize import BFGS

from flatcontact.foundation.errors import InputError
from flatcontact.potentials.engines import bulk_calculator
from flatcontact.structures.bulk import QUARTZ_C_ANGSTROM, alpha_quartz
from flatcontact.structures.dense import face_masks, verify_dense_slab
from flatcontact.structures.slab import quartz_0001_slab
from flatcontact.structures.thicken import insert_bulk_repeats, interior_mask, si_planes


def _lateral_mi(d: np.ndarray, cell2d: np.ndarray) -> np.ndarray:
    """Lateral minimum image of displacement rows ``d`` (z untouched)."""
    frac = np.linalg.solve(cell2d.T, d[:, :2].T).T
    frac -= np.round(frac)
    out = d.copy()
    out[:, :2] = frac @ cell2d
    return out


def _worst_match(a, b) -> float:
    """Largest distance (Å) from an atom of ``a`` to the nearest same-species atom of ``b``
    (laterally periodic), with equal species counts; both as they are (no alignment)."""
    sa, sb = np.array(a.get_chemical_symbols()), np.array(b.get_chemical_symbols())
    assert sorted(sa) == sorted(sb)
    c2 = a.cell.array[:2, :2]
    return max(
        np.linalg.norm(_lateral_mi(b.positions[sb == s] - p, c2), axis=1).min()
        for p, s in zip(a.positions, sa, strict=True)
    )


@pytest.mark.parametrize("cut", [0, 1, 2])
@pytest.mark.parametrize("repeats", [1, 2])
def test_inserting_repeats_into_an_ideal_cut_gives_the_thicker_ideal_cut(cut, repeats):
    """An unrelaxed 6-layer cut of α-quartz with m bulk c-repeats inserted is, atom for atom,
    the (6 + 3m)-layer cut of the same crystal at the same plane (independent construction)."""
    slab = quartz_0001_slab(layers=6, cut=cut)
    thick, record = insert_bulk_repeats(slab, alpha_quartz(), repeats)
    expected = quartz_0001_slab(layers=6 + 3 * repeats, cut=cut)
    assert record["registration_rms_angstrom"] < 1e-9
    assert len(thick) == len(expected) == 18 + 9 * repeats
    assert _worst_match(thick, expected) < 1e-8 and _worst_match(expected, thick) < 1e-8
    assert thick.cell.array[2, 2] == pytest.approx(
        slab.cell.array[2, 2] + repeats * QUARTZ_C_ANGSTROM
    )


def test_zero_repeats_returns_the_slab_unchanged():
    slab = quartz_0001_slab(layers=6, cut=2)
    same, _ = insert_bulk_repeats(slab, alpha_quartz(), 0)
    np.testing.assert_array_equal(same.positions, slab.positions)
    np.testing.assert_array_equal(same.numbers, slab.numbers)


def test_an_interior_that_is_not_quartz_is_refused():
    slab = quartz_0001_slab(layers=6, cut=2)
    rng = np.random.default_rng(0)
    inner = np.flatnonzero(interior_mask(slab))
    slab.positions[inner] += rng.uniform(-1.2, 1.2, (inner.size, 3))
    with pytest.raises(InputError, match="not bulk-like enough") as err:
        insert_bulk_repeats(slab, alpha_quartz(), 1)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("layers", [7, 8, 10])
def test_layer_counts_the_shipped_slab_cannot_reach_are_one_line_errors(layers):
    from flatcontact.potentials import InteractionModel
    from flatcontact.structures.build import build_quartz_interface
    from flatcontact.structures.recipe import parse_recipe

    with pytest.raises(InputError) as err:
        parse_recipe({"kind": "quartz-dense", "layers": layers, "source": "shipped"})
    text = str(err.value)
    assert "\n" not in text and f"layers={layers}" in text and "expected 6, 9, 12" in text
    with pytest.raises(InputError, match=f"layers={layers}: the shipped dense slab"):
        build_quartz_interface(InteractionModel(intra="vashishta"), layers, source="shipped")


SNAP = {"intra": "snap:sio2-snap"}


@pytest.fixture(scope="module")
def snap_builds():
    """6-, 9- and 12-layer interfaces built from the shipped slab with the bundled SNAP (+ LJ)."""
    from flatcontact.potentials import InteractionModel
    from flatcontact.structures.build import build_quartz_interface

    spec = InteractionModel(**SNAP)
    return spec, {n: build_quartz_interface(spec, n, source="shipped") for n in (6, 9, 12)}


def test_six_layers_is_the_shipped_slab_path_unchanged(snap_builds, monkeypatch):
    """6 layers never reaches the thickening code and records no insertion: rebuilding with
    the thickening disabled gives the same interface bit for bit."""
    from flatcontact.structures import build

    spec, builds = snap_builds
    six, report = builds[6]

    def boom(*args, **kwargs):
        raise AssertionError("the 6-layer build must not thicken")

    monkeypatch.setattr(build, "thicken_shipped_slab", boom)
    again, _ = build.build_quartz_interface(spec, 6, source="auto")
    np.testing.assert_array_equal(again.positions, six.positions)
    assert again.info["recipe"] == six.info["recipe"]
    assert "bulk_repeats_inserted" not in six.info["recipe"] and "slab_interior" not in report


def _lateral_bulk_c(spec, a_angstrom: float) -> float:
    """c (Å) of α-quartz relaxed with ``spec`` at a fixed a (Frechet filter, zz free only):
    computed here independently of the builder's own bulk relaxation."""
    bulk = alpha_quartz(a_angstrom, QUARTZ_C_ANGSTROM)
    bulk.calc = bulk_calculator(spec, bulk)
    BFGS(FrechetCellFilter(bulk, mask=[0, 0, 1, 0, 0, 0]), logfile=None).run(fmax=1e-4, steps=500)
    return float(bulk.cell.array[2, 2])


def test_nine_layer_slab_has_dense_faces_and_a_bulk_like_interior(snap_builds):
    """9 layers = 27 atoms per slab (Si9O18), layers 6+3·5+6 atoms, both faces dense in both slabs
    after the interface relaxation; every interior O–Si–O unit spacing within 2 % of c/3 of
    the SNAP's own bulk at the same a (measured: ≤ 0.9 %), their mean within 1 % (−0.5 %); the
    inserted repeat adds one bulk c between the face-Si planes within 2 % (−1.1 %); each face
    layer keeps the 6-layer slab's geometry within 0.2 Å (0.10 Å)."""
    from flatcontact.structures.interface_contract import validate_interface

    spec, builds = snap_builds
    nine, report = builds[9]
    six, _ = builds[6]
    validate_interface(nine)
    assert len(nine) == 54 and nine.get_chemical_formula() == "O36Si18"
    c = _lateral_bulk_c(spec, float(nine.cell.array[0, 0]))
    gaps = {}
    faces = {}
    for n, atoms in ((6, six), (9, nine)):
        for which in (1, 2):
            part = atoms[atoms.arrays["slab"] == which]
            assert len(part) == 3 * n
            layer = part.arrays["layer"] - part.arrays["layer"].min() + 1
            assert [int(np.sum(layer == k)) for k in range(1, n - 1)] == [6] + [3] * (n - 4) + [6]
            verdict = verify_dense_slab(part)
            assert verdict["dense"], verdict["failures"]
            planes = si_planes(part)
            assert planes.size == n - 2  # two Si per flat face plane, one per interior unit
            gaps[n, which] = planes[-1] - planes[0]
            if which == 1:
                faces[n] = [part[m] for m in face_masks(part, 6)]
                spacings = np.diff(planes[1:-1])
                if n == 9:
                    rel = spacings / (c / 3) - 1
                    assert np.abs(rel).max() < 0.02, rel
                    assert abs(rel.mean()) < 0.01, rel
    for which in (1, 2):
        assert gaps[9, which] - gaps[6, which] == pytest.approx(c, rel=0.02)
    for k in range(2):
        assert _face_shape_change(faces[6][k], faces[9][k]) < 0.2
    assert report["slab_interior"]["max_abs_spacing_rel_dev"] < 0.02
    assert report["start"]["thickening"]["bulk"]["c_angstrom"] == pytest.approx(c, abs=1e-3)


def _face_shape_change(a, b) -> float:
    """Largest atom displacement (Å) between two face layers after putting one Si on one Si
    (the best of the Si pairings): how much the face's own geometry differs."""
    c2 = a.cell.array[:2, :2]
    sa, sb = np.array(a.get_chemical_symbols()), np.array(b.get_chemical_symbols())
    best = np.inf
    for i in np.flatnonzero(sa == "Si"):
        for j in np.flatnonzero(sb == "Si"):
            ra = _lateral_mi(a.positions - a.positions[i], c2)
            rb = _lateral_mi(b.positions - b.positions[j], c2)
            worst = max(
                np.linalg.norm(_lateral_mi(rb[sb == s] - p, c2), axis=1).min()
                for p, s in zip(ra, sa, strict=True)
            )
            best = min(best, worst)
    return best


def test_from_nine_layers_on_a_repeat_adds_exactly_the_bulk_energy(snap_builds):
    """E(12) − E(9) of the relaxed single slabs equals the energy of one bulk c-repeat (9 atoms
    at the same lateral cell) within 5 meV per cell (measured 0.1 meV): from 9 layers on the two
    dense surfaces no longer feel each other. The 6-layer slab is 57 meV below that line (its
    2-unit interior, 0.40 Å RMS from bulk, couples the surfaces), so it is not checked here."""
    _, builds = snap_builds
    e = {n: builds[n][1]["slab_relaxation"]["energy_ev"] for n in (9, 12)}
    bulk = builds[12][1]["start"]["thickening"]["bulk"]
    assert bulk["converged"] and abs(bulk["stress_zz_gpa"]) < 0.01
    assert e[12] - e[9] == pytest.approx(bulk["energy_ev"], abs=5e-3)
    assert len(builds[12][0]) == 72 and builds[12][1]["slab_interior"]["interior_si_planes"] == 8


def test_a_thickened_slab_whose_interior_is_not_bulk_like_is_refused(monkeypatch):
    """The build refuses a thickened slab whose interior unit spacing deviates more than
    INTERIOR_MAX_SPACING_DEV from c/3 (the check is forced here by a doctored report)."""
    from flatcontact.potentials import InteractionModel
    from flatcontact.structures import build

    real = build.interior_report

    def doctored(slab, bulk):
        report = real(slab, bulk)
        report["max_abs_spacing_rel_dev"] = 2 * build.INTERIOR_MAX_SPACING_DEV
        return report

    monkeypatch.setattr(build, "interior_report", doctored)
    with pytest.raises(InputError, match="interior is not bulk-like") as err:
        build.build_quartz_interface(InteractionModel(**SNAP), 9, source="shipped")
    assert "\n" not in str(err.value)


def test_the_dense_faces_are_converged_from_nine_layers(snap_builds):
    """The face layers of the 9- and 12-layer interfaces agree within 0.01 Å per atom
    (measured 0.003 Å) while the 6-layer ones differ from both by about 0.1 Å: the shape
    of the dense surface stops changing once the interior is a whole bulk repeat thick."""
    _, builds = snap_builds
    faces = {}
    for n in (6, 9, 12):
        atoms = builds[n][0]
        part = atoms[atoms.arrays["slab"] == 1]
        faces[n] = [part[m] for m in face_masks(part, 6)]
    for k in range(2):
        assert _face_shape_change(faces[9][k], faces[12][k]) < 0.01
        assert _face_shape_change(faces[6][k], faces[12][k]) > 0.05
