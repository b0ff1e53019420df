"""The grid's own estimate of its discretisation error (flatcontact.analysis.grid_error).

Two analytic landscapes of :mod:`flatcontact.analysis.synthetic` (Morse adhesion, c = 0, so
the internal constant-pressure landscape is exactly const + V·g at every load):

* smooth: g = cos 2π s_a + cos 2π s_b on a rectangular a × b cell pulled along y. The path
  runs along s_a = 1/2 from the minimum (1/2, 1/2): e(t) = V(−1 − cos 2πt/b), so in closed
  form τ = 2πV/b, σ_MSS = 2V/b (one barrier 2V per period b), G_int = V(2π/b)². Every
  interpolant the estimators compare holds its one harmonic: each estimate must vanish;
* sharp: Σ_k (−1)^k cos(2πk s_b)/k³ + ½ Σ_k cos(2πk s_a)/k³ (k ≤ 12): coefficients falling as
  k^−3, the curvature-jump class the assumed order stands for. τ moves by 4 % from 8×8 to
  16×16; a 48×48 grid holds every harmonic and gives the exact τ.

And the real case of issue 32: the docs' Al(111) example (Zhou EAM, cut at the CIF's 4.05 Å: the
stored 6×6 and 9×9 scans of docs/measured/examples/al111-file-lattice-*), whose τ moves by 6 %
from 6×6 to 9×9.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flatcontact.analysis import gates
from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.analyze import analyze_ispes
from flatcontact.analysis.diagnostics import GridResolutionWarning
from flatcontact.analysis.grid_error import (
    ESTIMATORS,
    UNRESOLVED_FRACTION,
    coarse_grid,
    observed_order,
    richardson,
)
from flatcontact.analysis.options import AnalysisOptions
from flatcontact.analysis.uncertainty import grid_law_components, law_half_widths
from flatcontact.foundation import units
from flatcontact.ispes.contract import open_ispes

MEASURED = Path(__file__).resolve().parents[2] / "docs" / "measured" / "examples"
A_ANGSTROM, B_ANGSTROM = 4.0, 5.0
A1, A2 = syn.rectangular_cell(A_ANGSTROM, B_ANGSTROM)
V = 1e-3  # eV/Å²
Z = np.linspace(23.6, 27.0, 12)
SMOOTH = syn.cosine_sum([(1, 0, 1.0), (0, 1, 1.0)])
SHARP = syn.cosine_sum(
    [(0, k, (-1) ** k / k**3) for k in range(1, 13)] + [(k, 0, 0.5 / k**3) for k in range(1, 13)]
)


def _analyse(pattern, n: int, p_gpa=(0.0,)):
    ds = syn.SyntheticInterface(A1, A2, pattern, corrugation_ev_per_a2=V).grid(n, n, Z)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = analyze_ispes(
            ds,
            list(p_gpa),
            AnalysisOptions(direction_deg=90.0, with_symmetry=False, with_stackings=False),
        )
    grid_warnings = [str(w.message) for w in caught if w.category is GridResolutionWarning]
    return result, grid_warnings


@pytest.fixture(scope="module")
def sharp():
    """τ and its grid estimate of the sharp landscape per grid (48: exact)."""
    out = {}
    for n in (6, 8, 12, 16, 24, 48):
        result, caught = _analyse(SHARP, n)
        out[n] = (float(result.column("tau_mpa")[0]), result.grid, caught)
    return out


def test_smooth_landscape_matches_the_closed_form_and_its_grid_part_vanishes():
    result, caught = _analyse(SMOOTH, 8, p_gpa=(0.0, 0.5, 1.0))
    tau = 2 * np.pi * V / B_ANGSTROM * units.EV_PER_A3_TO_MPA
    sigma = 2 * V / B_ANGSTROM * units.EV_PER_A3_TO_MPA
    stiffness = V * (2 * np.pi / B_ANGSTROM) ** 2 * units.EV_PER_A3_TO_GPA * 10  # GPa/nm
    np.testing.assert_allclose(result.column("tau_mpa"), tau, rtol=1e-7)
    np.testing.assert_allclose(result.column("sigma_mss_mpa"), sigma, rtol=1e-7)
    np.testing.assert_allclose(result.column("shear_stiffness_gpa_per_nm"), stiffness, rtol=1e-6)
    grid = result.grid
    assert grid.grid.points == (4, 4) and set(grid.estimates) == set(ESTIMATORS)
    np.testing.assert_allclose(grid.values["sub-grid"]["tau_mpa"], tau, rtol=1e-7)
    for estimates in grid.estimates.values():
        for q, scale in (("tau_mpa", tau), ("sigma_mss_mpa", sigma)):
            assert np.max(np.abs(estimates[q])) <= 1e-7 * scale
        assert np.max(np.abs(estimates["shear_stiffness_gpa_per_nm"])) <= 1e-6 * stiffness
    assert not np.any(grid.unresolved) and grid.recommended_grid() is None and caught == []
    # the laws' grid part is the fit of those estimates: zero within round-off
    parts = grid_law_components(
        result.p_gpa,
        result.column("tau_mpa"),
        result.column("sigma_mss_mpa"),
        grid.error["tau_mpa"],
        grid.error["sigma_mss_mpa"],
        3.0,
    )
    assert all(v is not None and v <= 1e-6 * tau for v in parts.values())


@pytest.mark.parametrize(("coarse", "fine"), [(8, 16), (12, 24), (12, 48), (16, 48)])
def test_grid_part_covers_the_change_to_a_finer_grid(sharp, coarse, fine):
    tau_c, grid_c, _ = sharp[coarse]
    tau_f = sharp[fine][0]
    assert abs(tau_f - tau_c) > 1e-3 * tau_c  # τ really moves with the grid
    assert abs(grid_c.error["tau_mpa"][0]) >= abs(tau_f - tau_c)


def test_grid_part_covers_the_error_to_the_exact_tau_where_a_sub_grid_exists(sharp):
    exact = sharp[48][0]
    # 48×48 holds every harmonic of the pattern: its 24×24 sub-grid does too (estimate 0)
    assert abs(sharp[48][1].error["tau_mpa"][0]) <= 1e-6 * exact
    for n in (8, 12, 16):
        tau, grid, _ = sharp[n]
        assert grid.source["tau_mpa"] == "sub-grid"
        assert abs(grid.error["tau_mpa"][0]) >= abs(tau - exact)


def test_the_stated_limit_aliasing_on_a_grid_without_a_usable_sub_grid(sharp):
    """grid_error's docstring: the k^-3 tail aliased into a 6×6 grid escapes the interpolant
    and last-shell estimators (no 4×4 sub-grid exists); this test keeps that statement true."""
    exact = sharp[48][0]
    tau, grid, _ = sharp[6]
    assert grid.grid is None and grid.source["tau_mpa"] != "sub-grid"
    assert abs(grid.error["tau_mpa"][0]) < abs(tau - exact) / 5


def test_an_unresolved_grid_says_so_and_its_recommended_grid_resolves_tau(sharp):
    tau8, grid8, caught = sharp[8]
    exact = sharp[48][0]
    assert abs(tau8 - exact) > UNRESOLVED_FRACTION * exact  # 8×8 is really 6 % off
    assert bool(grid8.unresolved[0])
    (line,) = caught
    rec = grid8.recommended_grid()
    assert "does not resolve τ" in line and f"about {rec[0]}×{rec[1]}" in line
    assert rec[0] == rec[1] and rec[0] % 2 == 0 and rec[0] > 8
    finer, caught_rec = _analyse(SHARP, rec[0])
    assert abs(finer.column("tau_mpa")[0] - exact) <= UNRESOLVED_FRACTION * exact
    assert not bool(finer.grid.unresolved[0]) and caught_rec == []


@pytest.mark.filterwarnings("ignore::flatcontact.analysis.diagnostics.AnalysisWarning")
def test_real_al111_grid_part_covers_the_6_to_9_change():
    """Issue 32: the docs' Al(111) example moves τ by 6 % from 6×6 to 9×9 while its fit's
    interval was ±4.6 MPa. The 6×6 grid's own estimate must cover that move at every load,
    say that the grid does not resolve τ, and have the right sign (τ falls on the finer grid)."""
    loads = [0.0, 1.5]
    coarse = analyze_ispes(
        open_ispes(MEASURED / "al111-file-lattice-6" / "02-scan" / "ispes.nc"),
        loads,
        AnalysisOptions(direction_deg=0.0, with_symmetry=False, threshold_gpa=None),
    )
    fine = analyze_ispes(
        open_ispes(MEASURED / "al111-file-lattice-9" / "02-scan" / "ispes.nc"),
        loads,
        AnalysisOptions(
            direction_deg=0.0, with_symmetry=False, with_grid_error=False, threshold_gpa=None
        ),
    )
    change = fine.column("tau_mpa") - coarse.column("tau_mpa")
    assert np.all(np.abs(change) > 0.04 * coarse.column("tau_mpa"))
    err = coarse.grid.error["tau_mpa"]
    assert np.all(np.abs(err) >= np.abs(change)) and np.all(np.sign(err) == -np.sign(change))
    assert np.all(coarse.grid.unresolved)


@pytest.mark.parametrize(
    ("shape", "points", "ratio"),
    [((6, 6), None, None), ((9, 9), None, None), ((7, 7), None, None), ((8, 8), (4, 4), 2.0),
     ((12, 12), (6, 6), 2.0), ((12, 8), (6, 4), 2.0), ((15, 15), (5, 5), 3.0)],
)  # fmt: skip
def test_sub_grid_rule(shape, points, ratio):
    grid = coarse_grid(shape)
    if points is None:
        assert grid is None  # only a 3×3 sub-grid, or none: not used
        return
    assert grid.points == points and grid.ratio == pytest.approx(ratio)


def test_a_grid_without_sub_grid_uses_the_interpolant_estimators():
    result, caught = _analyse(SMOOTH, 3)
    grid = result.grid
    assert grid.grid is None and set(grid.estimates) == {"interpolant", "last shell"}
    # a landscape of one harmonic: both interpolants agree, the estimate is made and is 0
    assert abs(grid.error["tau_mpa"][0]) <= 1e-7 * result.column("tau_mpa")[0]
    assert caught == []


@settings(max_examples=40, deadline=None)
@given(
    exact=st.floats(-1e3, 1e3),
    c=st.floats(-1e3, 1e3).filter(lambda v: abs(v) > 1e-3),
    order=st.floats(0.5, 4.0),
    r=st.sampled_from([2.0, 3.0]),
    r2=st.sampled_from([2.0, 3.0]),
    h=st.floats(0.05, 0.5),
)
def test_richardson_and_observed_order_are_exact_for_a_power_law(exact, c, order, r, r2, h):
    """q(h) = q* + C h^p: the estimate is the fine value's error, the order is p."""

    def q(step):
        return exact + c * step**order

    fine, coarse, coarsest = q(h), q(r * h), q(r * r2 * h)
    assert richardson(fine, coarse, r, order) == pytest.approx(fine - exact, abs=1e-9 * abs(c))
    assert observed_order(fine, coarse, coarsest, r, r2) == pytest.approx(order, rel=1e-6)


def test_observed_order_is_undefined_without_monotone_convergence():
    assert np.isnan(observed_order(1.0, 2.0, 1.5, 2.0, 2.0))  # oscillating
    assert np.isnan(observed_order(1.0, 1.0, 2.0, 2.0, 2.0))  # no change at the fine level


@settings(max_examples=30, deadline=None)
@given(
    loads=st.lists(st.floats(0.0, 3.0), min_size=3, max_size=6, unique=True),
    a=st.floats(-50, 50),
    b=st.floats(-50, 50),
    m=st.floats(-5, 5),
    s=st.floats(-5, 5),
)
def test_grid_law_components_of_linear_estimates_are_their_coefficients(loads, a, b, m, s):
    """The fit is linear in the data: estimates δτ = a·P + b give |a|, |b| exactly."""
    p = np.array(loads)
    if np.ptp(p) < 1e-3:
        return
    parts = grid_law_components(p, 100 + 3 * p, 10 + p, a * p + b, m * p + s, 3.0)
    assert parts["k_mpa_per_gpa"] == pytest.approx(abs(a), abs=1e-7 * (1 + abs(b) / np.ptp(p)))
    assert parts["tau0_mpa"] == pytest.approx(abs(b), abs=1e-7 * (1 + abs(a) * 3))
    assert parts["mu_mpa_per_gpa"] == pytest.approx(abs(m), abs=1e-7 * (1 + abs(s) / np.ptp(p)))
    assert parts["sigma0_mpa"] == pytest.approx(abs(s), abs=1e-7 * (1 + abs(m) * 3))


def test_grid_law_components_need_an_estimate_at_every_fitted_load():
    p = np.array([0.0, 0.5, 1.0, 4.0])
    tau = np.array([1.0, 2.0, 3.0, 4.0])
    # a missing estimate above the threshold does not matter, one on a fitted load does
    ok = grid_law_components(p, tau, tau, [1.0, 1.0, 1.0, np.nan], [0.0] * 4, 3.0)
    assert ok["tau0_mpa"] == pytest.approx(1.0) and ok["k_mpa_per_gpa"] == pytest.approx(0.0)
    bad = grid_law_components(p, tau, tau, [1.0, np.nan, 1.0, 1.0], None, 3.0)
    assert bad == dict.fromkeys(("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa"))


def test_the_grid_part_enters_the_half_width_in_quadrature():
    laws = {"k_mpa_per_gpa": 1.0, "k_stderr_mpa_per_gpa": 3.0, "tau0_mpa": 5.0}
    hw = law_half_widths(laws, grid={"k_mpa_per_gpa": 4.0, "tau0_mpa": None}, coverage=2.0)
    assert hw["k_mpa_per_gpa"] == pytest.approx(2.0 * 5.0)  # 2·√(3² + 4²)
    assert hw["tau0_mpa"] == 0.0  # no fit error, grid not estimated


def _negative(k_grid):
    parts = {"fit": 0.2, "convergence": 0.0, "models": 0.0}
    if k_grid != "absent":
        parts["grid"] = k_grid
    return {
        "k_mpa_per_gpa": -2.0,
        "tau0_mpa": 30.0,
        "p_max_gpa": 1.5,
        "threshold_gpa": 3.0,
        "intervals": {
            "k_mpa_per_gpa": {"value": -2.0, "low": -2.5, "high": -1.5, "components": parts}
        },
    }


def test_negative_slope_remedy_names_the_grid_where_it_applies():
    big = gates.negative_slope(_negative(0.4)).message
    assert "lateral grid" in big and "±0.4 MPa/GPa" in big and "scan.grid" in big
    unknown = gates.negative_slope(_negative(None)).message
    assert "could not be estimated" in unknown and "scan.grid" in unknown
    for small in (gates.negative_slope(_negative(0.05)), gates.negative_slope(_negative("absent"))):
        assert "grid" not in small.message
        assert "contact.k_mpa_per_gpa" in small.message


def test_console_note_of_the_analyze_stage(tmp_path):
    """The run's console prints the grid's verdict after the analyze stage (StageEvent message)."""
    from flatcontact.cli.progress import StageLines
    from flatcontact.pipeline import StageEvent
    from flatcontact.stages.analyze import grid_note

    doc = {"grid": {"grid": [6, 6], "resolved": False, "relative_tau_error": [0.02, 0.162]}}
    doc["grid"]["recommended_grid"] = [20, 20]
    (tmp_path / "analyze.json").write_text(json.dumps(doc))
    note = grid_note(tmp_path)
    assert "6×6 grid does not resolve τ" in note and "16.2 %" in note and "20×20" in note
    printed = []

    class Console:
        def print(self, text, **kw):
            printed.append(text)

    StageLines(Console())(StageEvent("end", "analyze", 3, "ran", 1.0, note))
    assert printed[-1] == f"   warning: {note}"
    doc["grid"]["resolved"] = True
    (tmp_path / "analyze.json").write_text(json.dumps(doc))
    assert grid_note(tmp_path) == "" and grid_note(tmp_path / "missing") == ""


def test_a_comparison_path_that_never_ends_is_abandoned_and_named():
    """The 8×8 three-cosine landscape pulled along y: the last-shell interpolant's path at
    P = 0.5 GPa halves its step towards the floor for minutes (measured before the evaluation
    budget). The analysis now finishes, every load keeps an estimate from another estimator,
    and every abandoned one is named."""
    a1, a2 = syn.hexagonal_cell(4.916)
    iface = syn.SyntheticInterface(
        a1, a2, syn.three_cosine(a1, a2), corrugation_ev_per_a2=-2e-4, gap_modulation_angstrom=-0.02
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = analyze_ispes(
            iface.grid(8, 8, np.linspace(24.3, 26.4, 36)),
            [0.5, 2.0],
            AnalysisOptions(with_symmetry=False),
        )
    grid = result.grid
    assert np.all(np.isfinite(grid.error["tau_mpa"]))
    for name, estimates in grid.estimates.items():
        for p, value in zip(grid.p_gpa, estimates["tau_mpa"], strict=True):
            if not np.isfinite(value):
                assert f"{name} at P = {p:g} GPa" in grid.unavailable


def test_a_two_load_fit_stays_without_interval_whatever_its_grid_part():
    """A fit through two loads has no standard error (laws.json: null): its slope's sign is not
    significant, and a grid part does not make it so (used as fitted, with a note)."""
    laws = _negative(0.4)
    laws["k_stderr_mpa_per_gpa"] = None
    assert gates.negative_slope(laws) is None
    assert any("without an interval" in n for n in gates.negative_slope_notes(laws))


def test_a_load_the_chosen_estimator_lost_takes_the_largest_other_estimate():
    """One abandoned path (a NaN of the estimator used) must not take the grid part out of the
    laws' intervals: the load takes the largest-magnitude estimate the others have there, and
    says which; where none has one it stays NaN; the chosen one's own values are kept."""
    from flatcontact.analysis.grid_error import fill_missing

    nan = float("nan")
    estimates = {
        "last shell": np.array([33.2, 38.4, nan, 34.5, nan]),
        "interpolant": np.array([6.8, 1.5, -3.4, -2.0, nan]),
        "sub-grid": np.array([nan, nan, 2.1, nan, nan]),
    }
    filled, used = fill_missing("last shell", estimates)
    np.testing.assert_array_equal(filled[[0, 1, 3]], [33.2, 38.4, 34.5])
    assert filled[2] == -3.4 and used == [None, None, "interpolant", None, None]
    assert np.isnan(filled[4])
    whole, none_used = fill_missing("interpolant", estimates)
    np.testing.assert_array_equal(whole[:4], estimates["interpolant"][:4])
    assert none_used == [None] * 5
