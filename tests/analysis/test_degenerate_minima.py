"""τ when the landscape has (nearly) degenerate inequivalent minima (:mod:`.starts`).

The two-minima construction is separable on a rectangular cell,
``g = -cos 2π s_a + f(s_b)`` with ``f(u) = cos 2πu + γ cos 4πu (+ δ sin 2πu)``:
pulled along y the zero-perpendicular-force path is the straight line
``s_a = 0`` and the energy along it is ``V f(y/b)``. For ``δ = 0`` and
``γ > 1/4`` ``f`` has two minima per period at ``cos 2πu = -1/(4γ)``, i.e.
``u0`` and ``1 - u0`` (exactly degenerate by the mirror ``u → -u``), between a
low top at ``u = 1/2`` and a high top at ``u = 0``; τ out of each is ``V/b``
times the largest ``f'`` on its climb, at the inflection ``8γc² + c - 4γ = 0``
(``c = cos 2πu``).
"""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.analyze import analyze_ispes
from flatcontact.analysis.diagnostics import DegenerateMinimaWarning
from flatcontact.analysis.friction import friction_along_path
from flatcontact.analysis.options import AnalysisOptions
from flatcontact.analysis.path import zero_perpendicular_force_path
from flatcontact.analysis.periodic import PeriodicSurface
from flatcontact.analysis.starts import (
    DEGENERACY_FLOOR_MEV_PER_A2,
    TAU_TIE_RTOL,
    choose_start,
    degeneracy_tolerance_ev_per_a2,
    paths_from_near_degenerate_minima,
)
from flatcontact.foundation.units import EV_PER_A2_TO_MEV_PER_A2, EV_PER_A3_TO_MPA

V = 1e-3  # eV/Å²
A, B = 3.0, 4.0  # Å, rectangular cell
GAMMA = 0.6
TWO_PI = 2 * np.pi


def _two_minima(delta: float = 0.0):
    terms = [(1, 0, -1.0), (0, 1, 1.0), (0, 2, GAMMA)]
    if delta:
        terms.append((0, 1, delta, -np.pi / 2))  # δ cos(2πu - π/2) = δ sin 2πu
    return syn.cosine_sum(terms)


def _surface(pattern, a1, a2, n=8):
    sa = np.arange(n) / n
    s = np.stack(np.meshgrid(sa, sa, indexing="ij"), -1)
    return PeriodicSurface(V * pattern(s)[0], a1, a2)


def _fprime(u):
    """df/du of f(u) = cos 2πu + γ cos 4πu."""
    return TWO_PI * (-np.sin(TWO_PI * u) - 2 * GAMMA * np.sin(2 * TWO_PI * u))


def _analytic_taus() -> tuple[float, float]:
    """τ (eV/Å³) out of the minimum before the low top (u0) and before the high top (1 - u0)."""
    c_low, c_high = np.sort(np.roots([8 * GAMMA, 1.0, -4 * GAMMA]).real)
    u_a = np.arccos(c_low) / TWO_PI  # in (u0, 1/2): c runs from -1/(4γ) to -1
    u_b = 1 - np.arccos(c_high) / TWO_PI  # in (1 - u0, 1): c runs from -1/(4γ) to 1
    return V / B * _fprime(u_a), V / B * _fprime(u_b)


def test_local_minima_of_an_inversion_symmetric_hexagonal_landscape_are_the_two_hollows():
    a1, a2 = syn.hexagonal_cell()
    surf = _surface(syn.three_cosine(a1, a2, (1.0, 0.9, 1.1)), a1, a2)
    minima = surf.local_minima()
    assert len(minima) == 2
    (xa, va), (xb, vb) = minima
    assert va == pytest.approx(vb, abs=1e-15)  # e(r) = e(-r): exactly degenerate
    s = surf.fractional(xa) + surf.fractional(xb)
    np.testing.assert_allclose(s - np.round(s), 0.0, atol=1e-9)  # related by inversion
    for xy, _ in minima:
        sv = surf.evaluate(xy)
        assert np.linalg.norm(sv.gradient) < 1e-7 * V  # stationary: |Δr| ~ 1e-7 Å
        assert np.all(np.linalg.eigvalsh(sv.hessian) > 0)
    # the opposite sign has one minimum per cell, on the lattice points
    (only,) = PeriodicSurface(-surf.values, a1, a2).local_minima()
    s = surf.fractional(only[0])
    np.testing.assert_allclose(s - np.round(s), 0.0, atol=1e-9)


def test_two_exactly_degenerate_minima_report_both_analytic_taus_and_the_largest():
    a1, a2 = syn.rectangular_cell(A, B)
    surf = _surface(_two_minima(), a1, a2)
    tau_low_top, tau_high_top = _analytic_taus()
    assert tau_high_top > 1.5 * tau_low_top  # a real difference to resolve
    starts, k = paths_from_near_degenerate_minima(surf, 90.0, degeneracy_tolerance_ev_per_a2(0.0))
    assert len(starts) == 2
    u0 = np.arccos(-1 / (4 * GAMMA)) / TWO_PI
    by_u = {round(float(surf.fractional(o.xy_angstrom)[1]), 9): o for o in starts}
    assert sorted(by_u) == pytest.approx(sorted([u0, 1 - u0]), abs=1e-9)
    o_a, o_b = by_u[min(by_u)], by_u[max(by_u)]
    assert o_a.friction.tau_ev_per_a3 == pytest.approx(tau_low_top, rel=1e-9)
    assert o_b.friction.tau_ev_per_a3 == pytest.approx(tau_high_top, rel=1e-9)
    assert starts[k] is o_b  # reported: the largest τ
    # σ_MSS is a whole-period quantity: the same two barriers from either start
    f_min = -1 / (8 * GAMMA) - GAMMA
    sigma = V * ((-1 + GAMMA - f_min) + (1 + GAMMA - f_min)) / B
    for o in starts:
        assert o.friction.sigma_ev_per_a3 == pytest.approx(sigma, rel=1e-9)
        assert o.friction.tau_period_ev_per_a3 == pytest.approx(tau_high_top, rel=1e-9)


def test_pipeline_warns_and_reports_the_largest_tau_for_exactly_degenerate_minima():
    a1, a2 = syn.rectangular_cell(A, B)
    model = syn.SyntheticInterface(a1, a2, _two_minima(), corrugation_ev_per_a2=V)
    ds = model.grid(8, 8, np.linspace(24.3, 25.6, 12))
    with pytest.warns(DegenerateMinimaWarning) as rec:
        res = analyze_ispes(ds, [0.5, 1.5], AnalysisOptions(with_symmetry=False))
    tau_low_top, tau_high_top = (t * EV_PER_A3_TO_MPA for t in _analytic_taus())
    msg = str(rec[0].message)
    assert f"{tau_low_top:.4g} MPa" in msg and f"{tau_high_top:.4g} MPa" in msg
    # the message states how far apart the starts are, not only the tolerance
    spread = max(o.above_lowest_mev_per_a2 for o in res.pressures[0].starts)
    assert f"up to {spread:.2g} meV/Å² apart" in msg
    for pa in res.pressures:
        assert sorted(o.tau_mpa for o in pa.starts) == pytest.approx(
            [tau_low_top, tau_high_top], rel=1e-4
        )
        assert pa.friction.tau_mpa == pytest.approx(tau_high_top, rel=1e-4)
        assert pa.path is pa.starts[pa.selected_start].path


def test_a_clearly_deeper_minimum_is_unchanged_and_does_not_warn():
    delta = 0.05
    a1, a2 = syn.rectangular_cell(A, B)
    surf = _surface(_two_minima(delta), a1, a2)
    minima = surf.local_minima()
    assert len(minima) == 2
    gap_mev = (minima[1][1] - minima[0][1]) * EV_PER_A2_TO_MEV_PER_A2
    assert gap_mev > 100 * DEGENERACY_FLOOR_MEV_PER_A2
    # dense 1-D reference along s_a = 0: deepest minimum, then max f' up to the next top
    u = np.linspace(0.0, 2.0, 2_000_001)
    f = np.cos(TWO_PI * u) + GAMMA * np.cos(2 * TWO_PI * u) + delta * np.sin(TWO_PI * u)
    fp = _fprime(u) + delta * TWO_PI * np.cos(TWO_PI * u)
    i0 = int(np.argmin(f[u < 1]))
    top = i0 + int(np.argmax((fp[i0 + 1 :] < 0) & (fp[i0:-1] >= 0))) + 1
    tau_ref = V / B * float(np.max(fp[i0:top]))

    with warnings.catch_warnings():
        warnings.simplefilter("error", DegenerateMinimaWarning)
        starts, k = paths_from_near_degenerate_minima(
            surf, 90.0, degeneracy_tolerance_ev_per_a2(0.0)
        )
        model = syn.SyntheticInterface(a1, a2, _two_minima(delta), corrugation_ev_per_a2=V)
        res = analyze_ispes(model.grid(8, 8, np.linspace(24.3, 25.6, 12)), [1.0])
    assert len(starts) == 1 and k == 0
    assert starts[0].friction.tau_ev_per_a3 == pytest.approx(tau_ref, rel=1e-8)
    # the same as the paper's path from the global minimum
    old = friction_along_path(zero_perpendicular_force_path(surf, 90.0))
    assert starts[0].friction.tau_ev_per_a3 == old.tau_ev_per_a3
    pa = res.pressures[0]
    assert len(pa.starts) == 1
    assert pa.friction.tau_mpa == pytest.approx(tau_ref * EV_PER_A3_TO_MPA, rel=1e-4)


def test_probe_landscape_gives_the_same_tau_for_every_thickness_grid_and_load_source():
    """The hexagonal three-cosine (1, 0.9, 1.1) landscape: τ flipped 60.49 ↔ 180.43 MPa."""
    a1, a2 = syn.hexagonal_cell()
    pattern = syn.three_cosine(a1, a2, (1.0, 0.9, 1.1))
    model = syn.SyntheticInterface(a1, a2, pattern)
    # the exact landscape is const + V g: its starts give the reference τ values
    exact, _ = paths_from_near_degenerate_minima(
        _surface(pattern, a1, a2, n=8), 90.0, degeneracy_tolerance_ev_per_a2(0.0)
    )
    mpa = EV_PER_A3_TO_MPA * model.corrugation_ev_per_a2 / V
    ref = sorted(o.friction.tau_ev_per_a3 * mpa for o in exact)
    assert ref[1] > 2 * ref[0]
    taus, sigmas = [], []
    for z in (
        np.linspace(24.3, 25.3, 12),
        np.linspace(24.3, 26.4, 16),
        np.linspace(24.6, 25.3, 12),
    ):
        ds = model.grid(8, 8, z)
        for source in ("energy", "stress"):
            with pytest.warns(DegenerateMinimaWarning):
                res = analyze_ispes(
                    ds, [0.5], AnalysisOptions(load_source=source, with_symmetry=False)
                )
            pa = res.pressures[0]
            assert sorted(o.tau_mpa for o in pa.starts) == pytest.approx(ref, rel=1e-4)
            taus.append(pa.friction.tau_mpa)
            sigmas += [o.friction.sigma_mss_mpa for o in pa.starts]
    assert taus == pytest.approx([ref[1]] * len(taus), rel=1e-4)
    assert sigmas == pytest.approx([sigmas[0]] * len(sigmas), rel=1e-6)  # start-independent


@settings(max_examples=50, deadline=None)
@given(
    st.lists(st.tuples(st.floats(0.0, 100.0), st.floats(-1.0, 1.0)), min_size=1, max_size=5),
    st.randoms(use_true_random=False),
)
def test_choose_start_does_not_depend_on_the_order_of_the_starts(pairs, rnd):
    taus, energies = map(np.array, zip(*pairs, strict=True))
    k = choose_start(taus, energies)
    # τ within TAU_TIE_RTOL of the largest are equal (a 5e-324 MPa difference is no difference)
    top = np.max(taus)
    tied = taus >= top - TAU_TIE_RTOL * max(abs(top), 1e-300)
    assert tied[k]
    assert energies[k] == np.min(energies[tied])
    order = list(range(len(pairs)))
    rnd.shuffle(order)
    j = choose_start(taus[order], energies[order])
    # the same start up to the tie: equal energy, τ equal within the tie tolerance
    assert energies[order][j] == energies[k]
    assert abs(taus[order][j] - taus[k]) <= TAU_TIE_RTOL * max(abs(top), 1e-300)


def _assert_same_point(
    surf: PeriodicSurface, xy: np.ndarray, other: np.ndarray, atol: float = 1e-9
) -> None:
    """``xy`` and ``other`` (Å) coincide modulo the lattice to ``atol`` (Å)."""
    ds = surf.fractional(np.asarray(xy) - np.asarray(other))
    np.testing.assert_allclose(surf.cartesian(ds - np.round(ds)), 0.0, atol=atol)


def _clearly_deeper_reference_tau(delta: float) -> float:
    """τ (eV/Å³) out of the deepest minimum of ``_two_minima(delta)``, dense 1-D along s_a = 0."""
    u = np.linspace(0.0, 2.0, 2_000_001)
    f = np.cos(TWO_PI * u) + GAMMA * np.cos(2 * TWO_PI * u) + delta * np.sin(TWO_PI * u)
    fp = _fprime(u) + delta * TWO_PI * np.cos(TWO_PI * u)
    i0 = int(np.argmin(f[u < 1]))
    top = i0 + int(np.argmax((fp[i0 + 1 :] < 0) & (fp[i0:-1] >= 0))) + 1
    return V / B * float(np.max(fp[i0:top]))


@pytest.mark.parametrize("n", [4, 8])
@pytest.mark.parametrize("offset_ev_per_a2", [0.0, 0.055, 0.3, 1.0])
def test_a_constant_offset_does_not_lose_the_global_minimum(n, offset_ev_per_a2):
    """Regression: the trust region stalled on the value's round-off under a large offset.

    At offsets ≥ 0.3 eV/Å² (300× the corrugation V) the deeper minimum was refined only to
    |∇e| a / ptp(e) ≈ 2e-7, rejected as not stationary, and τ came from the shallower
    minimum (129 MPa instead of 499 MPa). The minima, the start and τ must not depend on a
    constant added to the landscape.
    """
    delta = 0.05
    a1, a2 = syn.rectangular_cell(A, B)
    flat = _surface(_two_minima(delta), a1, a2, n=n)
    surf = PeriodicSurface(flat.values + offset_ev_per_a2, a1, a2)
    reference = flat.local_minima()
    minima = surf.local_minima()
    assert len(reference) == len(minima) == 2
    for (x, v), (x0, v0) in zip(minima, reference, strict=True):
        _assert_same_point(surf, x, x0)
        assert v - offset_ev_per_a2 == pytest.approx(v0, abs=1e-15)
    gx, gv = surf.global_minimum()
    _assert_same_point(surf, minima[0][0], gx, atol=1e-6)  # global_minimum: trust region only
    assert minima[0][1] <= gv + 1e-15
    starts, k = paths_from_near_degenerate_minima(surf, 90.0, degeneracy_tolerance_ev_per_a2(0.0))
    assert len(starts) == 1
    _assert_same_point(surf, starts[k].xy_angstrom, minima[0][0])
    tau_ref = _clearly_deeper_reference_tau(delta)
    assert starts[k].friction.tau_ev_per_a3 == pytest.approx(tau_ref, rel=1e-8)


#: The constant-pressure landscape (eV/Å², above its lowest sample) of the bundled-SNAP
#: teacher-comparison scan (4×4 lateral grid, quartz (0001), enthalpy form) at 0.5 GPa, and
#: the constant it sat on there (energy zero at the 0 GPa global minimum).
SNAP_4X4_0P5GPA = [
    [0.0, 0.0004180172312047148, 0.0004852633001704021, 0.0004221233755465903],
    [0.0005211914204004131, 0.000418017571185203, 0.0006862494842856393, 0.0007638580601678768],
    [0.0012890158954981246, 0.0007676704985684069, 0.000488522931803459, 0.000764241494241702],
    [0.0005211901696107191, 0.0007673609011611404, 0.0006856230769365368, 0.0004221237036574621],
]
SNAP_4X4_0P5GPA_OFFSET = 0.0550539703464743


def test_snap_4x4_landscape_starts_at_its_global_minimum_whatever_its_offset():
    """Regression: τ was 13.2 or 1.85 MPa (round-off-dependent) from a metastable minimum.

    The sample at s = (0, 0) is 0.49 meV/Å² below every other minimum of the interpolant; the
    trust region stalled next to it, so the slider started in the shallow minimum near
    s = (1/2, 1/2) or near s = (0, 1/2), whose first barriers (0.028, 0.0025 meV/Å²) set τ.
    """
    a1, a2 = syn.hexagonal_cell(4.916)
    values = np.array(SNAP_4X4_0P5GPA)
    flat = PeriodicSurface(values, a1, a2)
    surf = PeriodicSurface(values + SNAP_4X4_0P5GPA_OFFSET, a1, a2)
    assert len(flat.local_minima()) == len(surf.local_minima()) == 3
    gx, _ = surf.global_minimum()
    s = surf.fractional(gx)
    np.testing.assert_allclose(s - np.round(s), 0.0, atol=1e-3)  # next to the lowest sample
    taus = []
    for landscape in (flat, surf):
        starts, k = paths_from_near_degenerate_minima(
            landscape, 90.0, degeneracy_tolerance_ev_per_a2(0.0)
        )
        assert len(starts) == 1
        _assert_same_point(surf, starts[k].xy_angstrom, gx, atol=1e-6)
        taus.append(starts[k].tau_mpa)
        # the first climb out of the global minimum is the hardest one of the period
        assert starts[k].tau_mpa == pytest.approx(starts[k].friction.tau_period_mpa, rel=1e-9)
    assert taus[1] == pytest.approx(taus[0], rel=1e-9)


@pytest.mark.parametrize(
    ("floor_mev_per_a2", "n_starts"),
    [
        (None, 1),  # a plain run: no measured floor, the fixed 1e-4 window
        (5e-5, 1),  # a measured floor below the fixed window does not narrow it
        (2.7e-4, 2),  # the H-diamond(111)/graphene 1 % cell's floor at fmax 0.005 eV/Å
    ],
)
def test_a_measured_noise_floor_widens_the_degeneracy_window(tmp_path, floor_mev_per_a2, n_starts):
    """Two inequivalent minima (the mirror broken by δ = 0.05, far beyond the 2 % that makes
    minima symmetry-equivalent) 2.0e-4 meV/Å² apart: above the fixed window, below the
    relaxation floor the approximant study measures on the rigid-layers H-diamond(111)/graphene
    cells at fmax 0.005 (2.7e-4 to 4.7e-4 meV/Å², docs/incommensurate.md). The study writes
    its floor into the cell's ``ispes.nc`` (:func:`write_energy_floor`); the analysis then
    takes both minima as starts, the window being the floor."""
    from flatcontact.ispes.contract import open_ispes, write_ispes
    from flatcontact.studies.approximants import write_energy_floor

    delta, v_small = 0.05, 2.2e-6  # eV/Å²: the gap 2 δ sin(2π u0) V ≈ 2.0e-4 meV/Å²
    a1, a2 = syn.rectangular_cell(A, B)
    minima = PeriodicSurface(
        _surface(_two_minima(delta), a1, a2).values * (v_small / V), a1, a2
    ).local_minima()
    assert len(minima) == 2
    gap_mev = (minima[1][1] - minima[0][1]) * EV_PER_A2_TO_MEV_PER_A2
    assert DEGENERACY_FLOOR_MEV_PER_A2 < gap_mev < 2.7e-4
    model = syn.SyntheticInterface(a1, a2, _two_minima(delta), corrugation_ev_per_a2=v_small)
    path = tmp_path / "ispes.nc"
    # 40 thicknesses: the load's noise estimate 2 ε stays below the fixed window (with 12 it is
    # 7.7e-4 meV/Å² on this grid and would decide alone)
    write_ispes(model.grid(8, 8, np.linspace(24.3, 25.6, 40)), path)
    if floor_mev_per_a2 is not None:
        write_energy_floor(path, floor_mev_per_a2)
    ds = open_ispes(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DegenerateMinimaWarning)
        res = analyze_ispes(ds, [1.0], AnalysisOptions(with_symmetry=False))
    pa = res.pressures[0]
    # 2 ε below the window here: the window or the floor
    expected = max(DEGENERACY_FLOOR_MEV_PER_A2, floor_mev_per_a2 or 0.0)
    tolerance_mev = pa.degeneracy_tolerance_ev_per_a2 * EV_PER_A2_TO_MEV_PER_A2
    assert tolerance_mev == pytest.approx(expected, rel=1e-12)
    assert len(pa.starts) == n_starts
    if n_starts == 2:
        spread = max(o.above_lowest_mev_per_a2 for o in pa.starts)
        assert spread == pytest.approx(gap_mev, rel=0.05)


def test_degeneracy_tolerance_is_the_largest_of_noise_window_and_measured_floor():
    mev = EV_PER_A2_TO_MEV_PER_A2
    window = DEGENERACY_FLOOR_MEV_PER_A2 / mev
    assert degeneracy_tolerance_ev_per_a2(0.0) == window
    assert degeneracy_tolerance_ev_per_a2(float("nan"), float("nan")) == window
    assert degeneracy_tolerance_ev_per_a2(3 * window, 2 * window) == 3 * window
    assert degeneracy_tolerance_ev_per_a2(0.5 * window, 4.7 * window) == 4.7 * window
    assert degeneracy_tolerance_ev_per_a2(float("nan"), 0.1 * window) == window
