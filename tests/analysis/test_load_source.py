"""Energy vs stress as the source of the load, and the noise estimate of the load's error."""

import numpy as np
import pytest

from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.analyze import analyze_ispes
from flatcontact.analysis.constant_pressure import constant_pressure
from flatcontact.analysis.friction import merge_shallow_minima
from flatcontact.analysis.options import AnalysisOptions
from flatcontact.foundation import units
from flatcontact.foundation.errors import InputError

A1, A2 = syn.hexagonal_cell()
MODEL = syn.SyntheticInterface(A1, A2, syn.three_cosine(A1, A2), corrugation_ev_per_a2=-2e-4)
Z = np.linspace(24.2, 25.3, 24)  # steep repulsive branch only: noise cannot fold it
P_GPA = np.array([0.5, 1.0, 2.0, 3.0])
SIGMA_GPA = 0.03
pytestmark = pytest.mark.filterwarnings("ignore::flatcontact.analysis.diagnostics.AnalysisWarning")


def _exact(res):
    s = np.stack(np.meshgrid(res.shift_a, res.shift_b, indexing="ij"), -1)
    pev = P_GPA / units.EV_PER_A3_TO_GPA
    return np.stack([MODEL.landscape(s, p) for p in pev])


def _rms_lateral(x):
    x = x - x.mean(axis=(1, 2), keepdims=True)  # the constant does not matter
    return np.sqrt(np.mean(x**2, axis=(1, 2)))


def test_stress_noise_leaves_the_energy_source_unchanged_and_moves_the_stress_source():
    clean = MODEL.grid(12, 12, Z)
    noisy = MODEL.grid(12, 12, Z, stress_noise_gpa=SIGMA_GPA, seed=3)
    e_clean = constant_pressure(clean, P_GPA, load_source="energy")
    # the energy source reads the stored stress only at the end nodes (spline end slopes)
    inner_noise = noisy.copy(deep=True)
    ends = {"thickness": [0, -1]}
    inner_noise["normal_stress"][ends] = clean["normal_stress"][ends]
    e_noisy = constant_pressure(inner_noise, P_GPA, load_source="energy")
    np.testing.assert_array_equal(e_noisy.energy_ev_per_a2, e_clean.energy_ev_per_a2)
    exact = _exact(e_clean)
    err_energy = _rms_lateral(e_clean.energy_ev_per_a2 - exact)
    s_noisy = constant_pressure(noisy, P_GPA, load_source="stress")
    err_stress = _rms_lateral(s_noisy.energy_ev_per_a2 - exact)
    # predicted: P δp / |dp/dz| at first order (δp of the stress spline at z*)
    pred = s_noisy.noise.energy_noise_mev_per_a2 / units.EV_PER_A2_TO_MEV_PER_A2
    ratio = err_stress / pred
    assert np.all((ratio > 1 / 1.5) & (ratio < 1.5)), ratio
    assert np.all(err_energy < 0.05 * err_stress)


def test_noise_estimate_recovers_the_injected_stress_noise():
    for sigma in (0.01, 0.03):
        res = constant_pressure(
            MODEL.grid(12, 12, Z, stress_noise_gpa=sigma, seed=5), P_GPA, load_source="stress"
        )
        assert 1 / 1.5 < res.noise.delta_p_gpa / sigma < 1.5
        # the energy source's own δp does not see the stress noise
        e = constant_pressure(
            MODEL.grid(12, 12, Z, stress_noise_gpa=sigma, seed=5), P_GPA, load_source="energy"
        )
        assert e.noise.delta_p_gpa < 0.1 * sigma
        # same mismatch up to the spline used for dU/dz (clamped ends for the energy source)
        assert e.noise.stress_energy_mismatch_rms_gpa == pytest.approx(
            res.noise.delta_p_gpa, rel=0.05
        )


def test_enthalpy_noise_is_second_order():
    res_i = constant_pressure(
        MODEL.grid(6, 6, Z, stress_noise_gpa=0.03), P_GPA, "internal", load_source="stress"
    )
    res_h = constant_pressure(
        MODEL.grid(6, 6, Z, stress_noise_gpa=0.03), P_GPA, "enthalpy", load_source="stress"
    )
    nz_i, nz_h = res_i.noise, res_h.noise
    dp, s = nz_i.delta_p_gpa, nz_i.slope_gpa_per_angstrom
    gpa_a_to_mev = units.EV_PER_A2_TO_MEV_PER_A2 / units.EV_PER_A3_TO_GPA
    np.testing.assert_allclose(nz_h.energy_noise_mev_per_a2, 0.5 * dp**2 / s * gpa_a_to_mev)
    np.testing.assert_allclose(
        nz_i.energy_noise_mev_per_a2, (P_GPA * dp / s + 0.5 * dp**2 / s) * gpa_a_to_mev
    )
    spacing = np.linalg.norm(A1) / 6
    np.testing.assert_allclose(
        nz_i.force_noise_mpa,
        nz_i.energy_noise_mev_per_a2
        / units.EV_PER_A2_TO_MEV_PER_A2
        / spacing
        * units.EV_PER_A3_TO_MPA,
    )


@pytest.mark.parametrize("form", ["internal", "enthalpy"])
def test_both_sources_give_the_closed_form_friction(form):
    ds = MODEL.grid(9, 9, np.linspace(24.2, 25.3, 36))
    a = np.linalg.norm(A1)
    res = {
        src: analyze_ispes(
            ds,
            [0.5, 2.0],
            AnalysisOptions(direction_deg=0.0, form=form, with_symmetry=False, load_source=src),
        )
        for src in ("energy", "stress")
    }
    for r in res.values():
        # three-cosine with V < 0 and c = δ = 0: τ = 4π|V|/a for both forms (no z coupling)
        np.testing.assert_allclose(
            r.column("tau_mpa"), 4 * np.pi * 2e-4 / a * 1.602176634e5, rtol=2e-3
        )
        np.testing.assert_allclose(
            r.column("sigma_mss_mpa"), 4 * 2e-4 / a * 1.602176634e5, rtol=2e-3
        )


def test_merge_shallow_minima_drops_noise_dips_only():
    ev = [
        ("max", 0.2, 0.15, False),
        ("min", 0.3, 0.10, False),
        ("max", 2.0, 1.5, False),
        ("min", 4.0, 0.0, False),
        ("max", 6.0, 1.4, False),
        ("min", 6.2, 1.35, False),
    ]
    out = merge_shallow_minima(ev, 0.0, 0.2)
    # the bump next to the start goes with its dip; the last dip (no maximum after it) alone
    assert out == [("max", 2.0, 1.5, False), ("min", 4.0, 0.0, False), ("max", 6.0, 1.4, False)]
    deep = [("max", 1.0, 1.0, False), ("min", 2.0, 0.5, False), ("max", 3.0, 0.55, False)]
    assert merge_shallow_minima(deep, 0.0, 0.2) == [("max", 1.0, 1.0, False)]
    assert merge_shallow_minima(ev, 0.0, 0.0) == ev
    assert merge_shallow_minima(ev, 0.0, 0.01) == ev


def test_lateral_grid_too_small_is_named():
    ds = MODEL.grid(1, 6, Z)
    with pytest.raises(InputError, match=r"lateral grid is 1×6.*at least 3 points per axis"):
        analyze_ispes(ds, [1.0])


def test_energy_source_is_accurate_at_a_widely_spaced_end_node():
    """A coarse scan: dense thicknesses under load, one far node at low load (as the automatic
    thickness choice makes). The energy source takes its end slopes from the stored stress,
    so the branch reaches the stored p there and Ũ(P) near that end stays accurate."""
    z = np.array([24.20, 24.30, 24.42, 24.56, 24.75, 25.30])
    grid = MODEL.grid(6, 6, z)
    p_end_gpa = float(grid.normal_stress.isel(thickness=-1).max())
    p_read = np.array([p_end_gpa + 0.05, 1.0])
    res = constant_pressure(grid, p_read, load_source="energy")
    assert res.common_p_range_gpa[0] == pytest.approx(p_end_gpa, abs=1e-9)
    s = np.stack(np.meshgrid(res.shift_a, res.shift_b, indexing="ij"), -1)
    for i, p in enumerate(p_read / units.EV_PER_A3_TO_GPA):
        err = _rms_lateral(res.energy_ev_per_a2[i : i + 1] - MODEL.landscape(s, p)[None])
        corrugation = np.ptp(MODEL.landscape(s, p))
        assert err[0] < 0.02 * corrugation
