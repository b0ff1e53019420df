"""Convergence comparison (flatcontact.analysis.convergence) and a refinement on a small scan."""

import numpy as np
import pytest

from flatcontact.analysis.convergence import (
    law_changes,
    monotonic_violations,
    per_load_changes,
    summarize,
)
from flatcontact.foundation.errors import InputError


def _rows(p, tau, sigma, noise=None):
    out = []
    for i, pi in enumerate(p):
        row = {"p_gpa": pi, "tau_mpa": tau[i], "sigma_mss_mpa": sigma[i]}
        if noise is not None:
            row["force_noise_mpa"] = noise[i]
        out.append(row)
    return out


P = [0.0, 1.0, 2.0, 3.0]
TAU = [30.0, 40.0, 50.0, 60.0]
SIG = [10.0, 12.0, 14.0, 16.0]


def test_relative_change_and_bound_follow_their_definitions():
    ref = _rows(P, TAU, SIG)
    new = _rows(P, [t * 1.03 for t in TAU], [s * 0.92 for s in SIG])
    ch = per_load_changes(ref, new, rel_tol=0.05)
    tau = ch[ch.quantity == "tau_mpa"]
    np.testing.assert_allclose(tau["rel_change"], 0.03, rtol=1e-12)
    np.testing.assert_allclose(tau["bound"], 0.05 * np.array(TAU))
    assert tau["within"].all()
    sig = ch[ch.quantity == "sigma_mss_mpa"]
    np.testing.assert_allclose(sig["rel_change"], -0.08, rtol=1e-12)
    assert not sig["within"].any()
    s = summarize(ch)
    assert s["tau_mpa"]["all_within"] and not s["sigma_mss_mpa"]["all_within"]
    assert s["sigma_mss_mpa"]["failing_p_gpa"] == P
    assert s["tau_mpa"]["max_abs_rel_change"] == pytest.approx(0.03)


def test_a_change_within_the_combined_noise_passes():
    # Δτ = 4 at P = 0 (13 % of 30) but the combined noise hypot(3, 4) = 5 covers it
    ref = _rows(P, TAU, SIG, noise=[3.0] * 4)
    new = _rows(P, [34.0, 40.0, 50.0, 60.0], SIG, noise=[4.0] * 4)
    ch = per_load_changes(ref, new, rel_tol=0.05, noise_multiple=1.0)
    first = ch[(ch.quantity == "tau_mpa") & (ch.p_gpa == 0.0)].iloc[0]
    assert first["noise"] == pytest.approx(5.0)
    assert first["bound"] == pytest.approx(5.0) and first["within"]
    strict = per_load_changes(ref, new, rel_tol=0.05, noise_multiple=0.5)
    assert not strict[(strict.quantity == "tau_mpa") & (strict.p_gpa == 0.0)]["within"].iloc[0]


def test_identical_runs_do_not_change_and_disjoint_loads_are_refused():
    ref = _rows(P, TAU, SIG)
    ch = per_load_changes(ref, ref)
    assert (ch["change"] == 0).all() and ch["within"].all()
    with pytest.raises(InputError, match="no load"):
        per_load_changes(ref, _rows([5.0], [1.0], [1.0]))


def test_law_change_is_in_combined_standard_errors():
    a = {
        "k_mpa_per_gpa": 10.0,
        "k_stderr_mpa_per_gpa": 3.0,
        "tau0_mpa": 20.0,
        "tau0_stderr_mpa": 1.0,
    }
    b = {
        "k_mpa_per_gpa": 15.0,
        "k_stderr_mpa_per_gpa": 4.0,
        "tau0_mpa": 20.0,
        "tau0_stderr_mpa": 2.0,
    }
    z = law_changes(a, b).set_index("coefficient")["z"]
    assert z["k_mpa_per_gpa"] == pytest.approx(1.0)  # 5 / hypot(3, 4)
    assert z["tau0_mpa"] == 0.0
    assert np.isnan(z["mu_mpa_per_gpa"])  # not fitted in either


def test_monotonic_violations_ignore_drops_within_noise():
    p = [0.0, 1.0, 2.0, 3.0]
    tau = [40.0, 38.0, 50.0, 45.0]
    assert monotonic_violations(p, tau, noise=0.0) == [
        {"from_p_gpa": 0.0, "to_p_gpa": 1.0, "drop": 2.0, "noise": 0.0},
        {"from_p_gpa": 2.0, "to_p_gpa": 3.0, "drop": 5.0, "noise": 0.0},
    ]
    # noise 3 per load: the 2 MPa drop is within hypot(3, 3) = 4.2, the 5 MPa one is not
    out = monotonic_violations(p, tau, noise=[3.0] * 4)
    assert [v["from_p_gpa"] for v in out] == [2.0]


@pytest.mark.slow
def test_halving_the_thickness_spacing_of_a_toy_scan_moves_tau_and_sigma_below_one_percent(
    tmp_path,
):
    """Scan the toy LJ interface once on 13 thicknesses; the analysis on every second one
    (spacing ×2) must agree per load within 1 % (measured: < 0.2 %) in τ and σ_MSS."""
    import io

    import pandas as pd
    from tests.studies.toy import toy_scan

    from flatcontact.analysis.analyze import analyze_ispes
    from flatcontact.analysis.options import AnalysisOptions
    from flatcontact.analysis.outputs import friction_csv_text

    ds = toy_scan(tmp_path, grid=4, n_thicknesses=13, fmax_ev_per_angstrom=1e-4).dataset
    loads = [0.25, 0.5, 0.75, 1.0]

    def table(grid):
        res = analyze_ispes(grid, loads, AnalysisOptions(direction_deg=90.0, with_symmetry=False))
        return pd.read_csv(io.StringIO(friction_csv_text(res)))

    fine, coarse = table(ds), table(ds.isel(thickness=slice(None, None, 2)))
    ch = per_load_changes(coarse, fine, rel_tol=0.01, noise_multiple=0.0)
    assert set(ch.quantity) >= {"tau_mpa", "sigma_mss_mpa"}
    main = ch[ch.quantity.isin(["tau_mpa", "sigma_mss_mpa"])]
    assert main["within"].all(), main.to_string()
    assert (fine["tau_mpa"] > fine["sigma_mss_mpa"]).all()  # τ ≥ σ_MSS on this landscape
