"""Named stackings, symmetry classes and MEP barrier on landscapes with closed-form stationary points.

First-star (three-cosine) model of a hexagonal bilayer, ``e = V g``,
``g = Σ_{i=1..3} cos(G_i·(r - r_AA))`` over the three shortest reciprocal vectors
(V > 0). With ``θ_i = G_i·(r - r_AA)``:

- AA (``r_AA``, all ``θ_i = 0``): ``g = 3``, the maximum;
- AB, BA (the three-fold sites ``(a + b)/3``, ``2(a + b)/3``; ``θ_i ∈ {±2π/3}``):
  ``g = 3 cos(2π/3) = -3/2``, the minima;
- SP (half lattice vectors; one ``θ = 0``, two ``θ = π``): ``g = -1``, the saddles.

Hence ``E_AA - E_AB = 9V/2`` and ``E_SP - E_AB = V/2``. An index-1 saddle joins
AB to BA; a net lattice translation needs two saddles of different orientation
(AB → SP → BA → SP' → AB + a), so the mountain-pass (MEP) barrier to an
equivalent minimum is exactly ``V/2`` and its shortest translation is a primitive
vector (length a). With unequal weights ``w_i`` the saddles stay at the half
lattice vectors (every ``sin θ_i = 0`` there) with ``g = w_i - w_j - w_k``, and the
barrier becomes the *second* lowest of them minus the minimum.

Separable rectangular/oblique model ``g = -cos 2π s_a - w cos 2π s_b`` (0 < w < 1):
minimum ``-1 - w`` at s = (0, 0), saddles ``-1 + w`` at (0, 1/2) and ``1 - w`` at
(1/2, 0), maximum ``1 + w`` at (1/2, 1/2); barrier ``2w`` along ``a2``, ``2`` along ``a1``.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize

from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.analyze import analyze_ispes
from flatcontact.analysis.options import AnalysisOptions
from flatcontact.analysis.path import minimum_energy_path
from flatcontact.analysis.periodic import PeriodicSurface
from flatcontact.analysis.stackings import analyze_stackings, lattice_kind
from flatcontact.analysis.starts import (
    degeneracy_tolerance_ev_per_a2,
    paths_from_near_degenerate_minima,
)

V = 1e-3  # eV/Å²


def _surface(pattern, a1, a2, n=12, scale=V):
    s = np.arange(n) / n
    grid = np.stack(np.meshgrid(s, s, indexing="ij"), -1)
    return PeriodicSurface(scale * pattern(grid)[0], a1, a2)


def _frac_equal(surface, xy, s_expected, atol=1e-8):
    ds = surface.fractional(xy) - np.asarray(s_expected)
    ds -= np.round(ds)
    return np.linalg.norm(surface.cartesian(ds)) < atol


def _first_star(a=2.46, rotation=0.0, shift=(0.0, 0.0), sixty=False):
    a1, a2 = syn.hexagonal_cell(a, rotation)
    pattern = syn.shifted(syn.three_cosine(a1, a2), shift)
    if sixty:  # the same lattice and landscape on the 60° cell (a1, a1 + a2)
        b = a1 + a2
        base = syn.three_cosine(a1, b)
        shift60 = (shift[0] - shift[1], shift[1])  # r_AA = s_a a1 + s_b a2 = (s_a - s_b) a1 + s_b b
        return a1, b, syn.shifted(base, shift60)
    return a1, a2, pattern


@settings(max_examples=12, deadline=None)
@given(
    rotation=st.floats(0, 360),
    sa=st.floats(0, 1, exclude_max=True),
    sb=st.floats(0, 1, exclude_max=True),
    sixty=st.booleans(),
)
def test_first_star_hexagonal_stackings_are_found_named_and_exact(rotation, sa, sb, sixty):
    a1, a2, pattern = _first_star(rotation=rotation, shift=(sa, sb), sixty=sixty)
    surf = _surface(pattern, a1, a2)
    res = analyze_stackings(surf)
    assert res.lattice == "hexagonal" and res.euler_ok
    assert len(res.operations) == 11  # the landscape keeps the full 6mm: 11 non-identity ops
    e = res.energies()
    assert set(e) == {"AA", "AB", "BA", "SP"}
    assert e["AA"] == pytest.approx(3 * V, abs=1e-12)
    assert e["AB"] == pytest.approx(-1.5 * V, abs=1e-12)
    assert e["BA"] == pytest.approx(-1.5 * V, abs=1e-12)
    assert e["SP"] == pytest.approx(-V, abs=1e-12)
    kinds = res.kinds()
    assert kinds == {"AA": "maximum", "AB": "minimum", "BA": "minimum", "SP": "saddle"}
    assert sum(p.name == "SP" for p in res.points) == 3
    # AA where the pattern was moved; AB/BA at the three-fold sites (a + b)/3, 2(a + b)/3
    r_aa = sa * syn.hexagonal_cell(2.46, rotation)[0] + sb * syn.hexagonal_cell(2.46, rotation)[1]
    b = a2 if np.dot(a1, a2) > 0 else a1 + a2
    where = {p.name: p.xy_angstrom for p in res.points if p.name != "SP"}
    assert _frac_equal(surf, where["AA"], surf.fractional(r_aa))
    assert _frac_equal(surf, where["AB"], surf.fractional(r_aa + (a1 + b) / 3))
    assert _frac_equal(surf, where["BA"], surf.fractional(r_aa + 2 * (a1 + b) / 3))
    # AB and BA are one symmetry class (inversion/mirrors map them onto each other)
    (ab,) = [i for i, p in enumerate(res.points) if p.name == "AB"]
    assert {res.points[i].name for i in res.equivalent_minima(ab)} == {"AB", "BA"}
    # MEP barrier V/2 to an equivalent minimum, over a primitive translation
    assert res.barrier == pytest.approx(V / 2, rel=1e-9)
    assert np.linalg.norm(res.barrier_vector_angstrom) == pytest.approx(2.46, rel=1e-12)
    angle = (res.barrier_direction_deg - rotation) % 60.0
    assert min(angle, 60.0 - angle) < 1e-6  # along a lattice vector
    # any lattice translation is reached over the same saddles
    assert res.barrier_for(a1 + 2 * a2) == pytest.approx(V / 2, rel=1e-9)


def test_string_method_agrees_with_the_saddle_graph_barrier():
    a1, a2, pattern = _first_star(shift=(0.1, 0.3))
    surf = _surface(pattern, a1, a2)
    res = analyze_stackings(surf)
    start = res.points[res.start_index].xy_angstrom
    mep = minimum_energy_path(surf, start, start + res.barrier_vector_angstrom, n_images=61)
    assert mep.converged
    assert mep.barrier == pytest.approx(res.barrier, rel=1e-6)
    saddle = res.points[res.barrier_saddle_index]
    assert saddle.kind == "saddle" and saddle.energy - res.points[res.start_index].energy == (
        pytest.approx(res.barrier, rel=1e-12)
    )


def test_unequal_weights_split_the_saddles_and_the_barrier_is_the_second_lowest():
    w = (1.0, 0.8, 1.15)
    a1, a2 = syn.hexagonal_cell(3.0)
    pattern = syn.three_cosine(a1, a2, w)
    surf = _surface(pattern, a1, a2)
    res = analyze_stackings(surf)
    saddles = sorted(p.energy for p in res.points if p.kind == "saddle")
    expected = sorted(V * np.array([w[0] - w[1] - w[2], w[1] - w[0] - w[2], w[2] - w[0] - w[1]]))
    np.testing.assert_allclose(saddles, expected, atol=1e-12)
    assert {p.name for p in res.points if p.kind == "saddle"} == {"SP1", "SP2", "SP3"}
    # independent minimum of the analytic pattern (Nelder–Mead from the hollow)
    lat = np.column_stack([a1, a2])
    inv = np.linalg.inv(lat)
    best = minimize(
        lambda x: V * pattern(inv @ x)[0],
        lat @ [2 / 3, 1 / 3],
        method="Nelder-Mead",
        options={"xatol": 1e-12, "fatol": 1e-18},
    )
    e_min = min(p.energy for p in res.points if p.kind == "minimum")
    assert e_min == pytest.approx(best.fun, abs=1e-12)
    assert res.barrier == pytest.approx(expected[1] - best.fun, abs=1e-12)
    assert res.lattice == "hexagonal" and res.euler_ok
    # inversion (C2) is kept, the six-fold and the mirrors are not: AB and BA still one class
    assert len(res.operations) == 1
    mins = [i for i, p in enumerate(res.points) if p.kind == "minimum"]
    assert len(mins) == 2 and res.equivalent_minima(mins[0]) == mins


@pytest.mark.parametrize(
    ("a1", "a2", "lattice"),
    [
        ((3.0, 0.0), (0.0, 4.5), "rectangular"),
        ((3.0, 0.0), (1.0, 2.5), "oblique"),
        ((3.0, 0.0), (0.0, 3.0), "square"),
    ],
)
def test_separable_landscape_on_rectangular_oblique_and_square_cells(a1, a2, lattice):
    w = 0.35
    a1, a2 = np.array(a1), np.array(a2)
    pattern = syn.cosine_sum([(1, 0, -1.0), (0, 1, -w)])
    surf = _surface(pattern, a1, a2, n=8)
    res = analyze_stackings(surf)
    assert res.lattice == lattice == lattice_kind(a1, a2) and res.euler_ok
    assert res.energies() == pytest.approx(
        {"min1": -(1 + w) * V, "saddle1": (w - 1) * V, "saddle2": (1 - w) * V, "max1": (1 + w) * V},
        abs=1e-12,
    )
    where = {p.name: p.fractional for p in res.points}
    for name, s in {
        "min1": (0, 0),
        "saddle1": (0, 0.5),
        "saddle2": (0.5, 0),
        "max1": (0.5, 0.5),
    }.items():
        assert _frac_equal(surf, surf.cartesian(where[name]), s)
    assert res.barrier == pytest.approx(2 * w * V, rel=1e-9)
    np.testing.assert_allclose(res.barrier_vector_angstrom, a2, atol=1e-12)
    assert res.barrier_for(a1) == pytest.approx(2 * V, rel=1e-9)
    assert res.barrier_for(a1 + a2) == pytest.approx(2 * V, rel=1e-9)


@settings(max_examples=10, deadline=None)
@given(
    rotation=st.floats(0, 360),
    sa=st.floats(0, 1, exclude_max=True),
    sb=st.floats(0, 1, exclude_max=True),
)
def test_energies_and_barriers_are_invariant_under_rotation_and_translation(rotation, sa, sb):
    """A landscape rotated with its lattice and translated keeps its stackings and barriers."""
    w = (1.0, 0.8, 1.15)
    ref = analyze_stackings(
        _surface(syn.three_cosine(*syn.hexagonal_cell(3.0), w), *syn.hexagonal_cell(3.0))
    )
    a1, a2 = syn.hexagonal_cell(3.0, rotation)
    moved = analyze_stackings(_surface(syn.shifted(syn.three_cosine(a1, a2, w), (sa, sb)), a1, a2))
    assert moved.energies() == pytest.approx(ref.energies(), abs=1e-12)
    assert moved.barrier == pytest.approx(ref.barrier, abs=1e-12)
    # the lowest-barrier translation rotates with the landscape (the canonical pick among
    # equal lengths need not): same length, and the rotated one has the same barrier
    assert np.linalg.norm(moved.barrier_vector_angstrom) == pytest.approx(
        np.linalg.norm(ref.barrier_vector_angstrom), rel=1e-12
    )
    th = np.radians(rotation)
    rot = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    assert moved.barrier_for(rot @ ref.barrier_vector_angstrom) == pytest.approx(
        ref.barrier, abs=1e-12
    )
    for k in (1, 2):  # and so do the barriers to other translations
        v = k * syn.hexagonal_cell(3.0)[1]
        assert moved.barrier_for(rot @ v) == pytest.approx(ref.barrier_for(v), abs=1e-12)


def test_equivalent_minima_give_identical_tau_along_the_lowest_barrier_direction():
    a1, a2 = syn.hexagonal_cell(2.46)
    model = syn.SyntheticInterface(a1, a2, syn.three_cosine(a1, a2), corrugation_ev_per_a2=1e-4)
    ds = model.grid(9, 9, np.linspace(24.3, 25.6, 12))
    res = analyze_ispes(
        ds, [0.5, 1.0, 2.0, 3.0], AnalysisOptions(direction_deg="auto", with_symmetry=False)
    )
    assert res.direction_deg == 0.0 and res.direction_rule.startswith("lowest-barrier")
    starts = set()
    for pa in res.pressures:
        taus = [o.tau_mpa for o in pa.starts]
        assert len(taus) == 2  # AB and BA
        assert taus[0] == pytest.approx(taus[1], rel=1e-7)
        starts.add(round(float(pa.surface.fractional(pa.minimum_xy_angstrom)[0]), 9))
        # σ_MSS closed form: two climbs of V/2 per lattice period a
        assert pa.friction.sigma_ev_per_a3 == pytest.approx(1e-4 / 2.46, rel=1e-6)
        assert pa.stackings.barrier == pytest.approx(0.5e-4, rel=1e-6)
    assert len(starts) == 1  # the same representative at every load


@pytest.mark.parametrize("direction", [90.0, 10.0, 0.0])
def test_tau_from_an_equivalent_minimum_is_tau_along_the_mapped_direction(direction):
    """τ(BA, d) = τ(AB, R⁻¹d) for every kept operation T(r) = R r + t with T(AB) = BA."""
    a1, a2 = syn.hexagonal_cell(2.46)
    surf = _surface(syn.three_cosine(a1, a2), a1, a2, n=9, scale=1e-4)
    res = analyze_stackings(surf)
    tol = degeneracy_tolerance_ev_per_a2(0.0)
    ab = next(p for p in res.points if p.name == "AB")
    ba = next(p for p in res.points if p.name == "BA")

    def tau_from(point, angle):
        starts, _ = paths_from_near_degenerate_minima(surf, angle, tol, stackings=res)
        return next(
            o.tau_mpa for o in starts if _frac_equal(surf, o.xy_angstrom, point.fractional, 1e-6)
        )

    d = np.array([np.cos(np.radians(direction)), np.sin(np.radians(direction))])
    checked = 0
    for op in res.operations:
        if not _frac_equal(surf, op(ab.xy_angstrom), ba.fractional, 1e-6):
            continue
        back = op.matrix.T @ d  # R is orthogonal: R⁻¹ = Rᵀ
        angle = float(np.degrees(np.arctan2(back[1], back[0])))
        assert tau_from(ba, direction) == pytest.approx(tau_from(ab, angle), rel=1e-7)
        checked += 1
    assert checked == 6  # half of the 12 elements of 6mm exchange AB and BA


def test_a_pinning_like_splitting_of_ab_and_ba_keeps_the_start_rule_stable():
    """The issue's graphene case: AB/BA unequal by a tiny, load-dependent amount.

    ``g = Σ cos θ_i + ε_k Σ sin θ_i`` breaks inversion (AB − BA = ∓ε 3√3/2 V) with a
    sign that alternates between "loads" k. The old rule (degeneracy tolerance
    only) sees one start, the lower one, which flips between AB and BA and τ jumps;
    with the symmetry classes both are always starts and the reported τ and start
    are the same at every load.
    """
    a1, a2 = syn.hexagonal_cell(2.46)
    third = (-1, 1)
    tol = degeneracy_tolerance_ev_per_a2(0.0)
    old, new, chosen = [], [], []
    previous = None
    for eps in (2e-3, -2e-3, 1.5e-3, -1e-3):
        pattern = syn.cosine_sum(
            [(1, 0, 1.0), (0, 1, 1.0), (*third, 1.0)]
            + [(k, m, eps, -np.pi / 2) for k, m in ((1, 0), (0, 1), third)]
        )
        surf = _surface(pattern, a1, a2, n=9)
        res = analyze_stackings(surf)
        e = res.energies()
        assert abs(e["AB"] - e["BA"]) > 10 * tol  # a splitting the degeneracy test resolves
        plain, k = paths_from_near_degenerate_minima(surf, 90.0, tol)
        old.append(plain[k].tau_mpa)
        starts, k = paths_from_near_degenerate_minima(
            surf, 90.0, tol, stackings=res, previous_xy=previous
        )
        assert len(starts) == 2
        previous = starts[k].xy_angstrom
        new.append(starts[k].tau_mpa)
        chosen.append(tuple(np.round(surf.fractional(previous) % 1.0, 2)))  # minima move by ~ε
    assert max(old) / min(old) > 2  # the old rule flips (τ from AB vs BA along y)
    assert max(new) / min(new) < 1.05  # the new rule reports the same start's τ
    assert len(set(chosen)) == 1


def test_outputs_carry_the_stackings_barriers_and_rules(tmp_path):
    """friction.csv/.nc and the JSON summary: named energies (closed form), barrier, rules."""
    import csv
    import json

    import xarray as xr

    from flatcontact.analysis.outputs import (
        CSV_COLUMNS,
        friction_csv_text,
        friction_dataset,
        summary_json,
    )

    v = 1e-4
    a1, a2 = syn.hexagonal_cell(2.46)
    model = syn.SyntheticInterface(a1, a2, syn.three_cosine(a1, a2), corrugation_ev_per_a2=v)
    ds = model.grid(9, 9, np.linspace(24.3, 25.6, 12))
    res = analyze_ispes(ds, [0.5, 1.0], AnalysisOptions(direction_deg="auto", energy_zero="each"))
    (tmp_path / "friction.csv").write_text(friction_csv_text(res))
    friction_dataset(res).to_netcdf(tmp_path / "friction.nc", engine="h5netcdf")
    mev = 1e3
    with open(tmp_path / "friction.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == list(CSV_COLUMNS)
    for row in rows:
        named = dict(item.split("=") for item in row["stacking_energies_mev_per_a2"].split(";"))
        assert float(named["AA"]) - float(named["AB"]) == pytest.approx(4.5 * v * mev, rel=1e-6)
        assert float(named["SP"]) - float(named["BA"]) == pytest.approx(0.5 * v * mev, rel=1e-6)
        assert float(row["lowest_barrier_mev_per_a2"]) == pytest.approx(0.5 * v * mev, rel=1e-6)
        assert float(row["direction_deg"]) == 0.0 == float(row["lowest_barrier_direction_deg"])
        assert row["start_stacking"] in ("AB", "BA")
    assert len({row["start_stacking"] for row in rows}) == 1
    nc = xr.open_dataset(tmp_path / "friction.nc")
    assert sorted(nc.stacking.values.tolist()) == ["AA", "AB", "BA", "SP"]
    kinds = dict(zip(nc.stacking.values.tolist(), nc.stacking_kind.values.tolist(), strict=True))
    assert kinds == {"AA": "maximum", "AB": "minimum", "BA": "minimum", "SP": "saddle"}
    e = nc.stacking_energy_mev_per_a2.sel(stacking="AA") - nc.stacking_energy_mev_per_a2.sel(
        stacking="AB"
    )
    np.testing.assert_allclose(e.values, 4.5 * v * mev, rtol=1e-6)
    assert nc.attrs["direction_rule"].startswith("lowest-barrier")
    assert "symmetry-equivalent" in nc.attrs["tau_start_rule"]
    summary = json.loads(json.dumps(summary_json(res)))  # JSON-serialisable
    assert summary["direction_rule"] == res.direction_rule
    first = summary["pressures"][0]
    assert first["stackings"]["SP"]["multiplicity"] == 3
    assert first["stackings"]["AA"]["kind"] == "maximum"
    assert first["barrier_along_direction_mev_per_a2"] == pytest.approx(0.5 * v * mev, rel=1e-6)


@pytest.mark.parametrize("bad", ["north", "Auto"])
def test_an_unknown_direction_word_is_a_one_line_error(bad):
    from flatcontact.foundation.errors import InputError

    a1, a2 = syn.hexagonal_cell(2.46)
    ds = syn.SyntheticInterface(a1, a2, syn.three_cosine(a1, a2)).grid(
        4, 4, np.linspace(24.3, 25.6, 8)
    )
    with pytest.raises(InputError, match="direction_deg") as err:
        analyze_ispes(ds, [1.0], AnalysisOptions(direction_deg=bad))
    assert "\n" not in str(err.value)


def test_without_equivalent_minima_the_results_are_those_of_the_old_rule():
    """A quartz-like landscape (hexagonal cell, no kept operation relating its minima):
    τ, σ_MSS, G_int and the start are bit-for-bit those of the analysis without stackings."""
    a1, a2 = syn.hexagonal_cell(4.916)
    pattern = syn.cosine_sum(
        [(1, 0, 1.0), (0, 1, 0.9), (-1, 1, 1.1), (1, 0, 0.3, -np.pi / 2), (1, 1, 0.2, 0.4)]
    )
    model = syn.SyntheticInterface(
        a1, a2, pattern, corrugation_ev_per_a2=-2e-4, gap_modulation_angstrom=-0.02
    )
    ds = model.grid(12, 12, np.linspace(24.3, 25.6, 12))
    p = [0.0, 1.0, 2.0, 3.0]
    new = analyze_ispes(ds, p)
    old = analyze_ispes(ds, p, AnalysisOptions(with_stackings=False))
    for name in ("tau_mpa", "sigma_mss_mpa", "shear_stiffness_gpa_per_nm"):
        np.testing.assert_array_equal(new.column(name), old.column(name))
    for a, b in zip(new.pressures, old.pressures, strict=True):
        np.testing.assert_array_equal(a.minimum_xy_angstrom, b.minimum_xy_angstrom)
        assert len(a.starts) == len(b.starts)
        assert a.stackings.euler_ok and np.isfinite(a.stackings.barrier)
    assert new.direction_deg == 90.0 and new.direction_rule == "given"


def test_a_shift_lattice_landscape_names_its_points_by_kind_not_as_bilayer_stackings():
    """The ISPES of a twisted or coincidence cell on one period of its shift lattice
    (``shift_lattice_index`` > 1, as the scan stage writes it) is hexagonal with one maximum,
    like a bilayer's, but its minima are no AB/BA stacking: friction.csv names them by kind
    and rank (min1, saddle1, max1). The same grid without the attribute (or index 1) keeps
    AB/BA/SP/AA. The energies are those of the closed form either way."""
    import csv
    import io

    from flatcontact.analysis.outputs import friction_csv_text

    v = 1e-4
    mev = 1e3
    a1, a2 = syn.hexagonal_cell(0.93)  # the (1, 2) twist's shift-lattice period
    model = syn.SyntheticInterface(a1, a2, syn.three_cosine(a1, a2), corrugation_ev_per_a2=v)
    base = model.grid(9, 9, np.linspace(24.3, 25.6, 12))
    names = {}
    for index in (None, 1, 49):
        ds = base.copy()
        if index is not None:
            ds.attrs["shift_lattice_index"] = index
        res = analyze_ispes(
            ds, [0.5, 1.0], AnalysisOptions(direction_deg="auto", energy_zero="each")
        )
        rows = list(csv.DictReader(io.StringIO(friction_csv_text(res))))
        for row in rows:
            named = {
                k: float(e)
                for k, e in (
                    item.split("=") for item in row["stacking_energies_mev_per_a2"].split(";")
                )
            }
            names.setdefault(index, set()).update(named)
            names.setdefault((index, "start"), set()).add(row["start_stacking"])
            if index == 49:
                # AB and BA are one class (three-cosine landscape): one minimum name
                assert named["max1"] - named["min1"] == pytest.approx(4.5 * v * mev, rel=1e-6)
                assert named["saddle1"] - named["min1"] == pytest.approx(0.5 * v * mev, rel=1e-6)
    assert names[None] == names[1] == {"AA", "AB", "BA", "SP"}
    assert names[(None, "start")] <= {"AB", "BA"}
    assert names[49] == {"min1", "saddle1", "max1"}
    assert names[(49, "start")] == {"min1"}
