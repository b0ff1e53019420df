"""Multi-load fit of stiffness curves: recovery from synthetic noisy data, inputs, comparison."""

import numpy as np
import pytest

from flatcontact.contact import fit, mindlin
from flatcontact.contact.measured import LoadCurve, load_fit_data
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation.errors import InputError

TRUE = ContactParameters(tau0_mpa=40.0)
LOADS = (1.0, 1.77, 3.0)


def _synthetic(params, noise_fraction, seed, n=25):
    """Model lock-in curves at LOADS with Gaussian noise of noise_fraction·k0 (known sd)."""
    rng = np.random.default_rng(seed)
    curves, sds = [], []
    for p0 in LOADS:
        gross = float(mindlin.peak_force(p0 * 1e9, params).force_n)
        a = float(mindlin.contact_radius(p0 * 1e9, params))
        stress = np.linspace(0.05, 1.15, n) * gross / (np.pi * a * a)
        clean = fit.model_stiffness(LoadCurve(p0, stress, stress * 0, "syn"), params)
        sd = noise_fraction * float(mindlin.initial_lateral_stiffness(p0 * 1e9, params))
        curves.append(LoadCurve(p0, stress, clean + rng.normal(0.0, sd, n), f"syn{p0}"))
        sds.append(sd)
    return curves, sds


def test_fit_recovers_known_parameters_within_its_errors():
    curves, _ = _synthetic(TRUE, 0.01, seed=7)
    start = ContactParameters(tau0_mpa=30.0, k_mpa_per_gpa=8.0, shear_modulus_gpa=25.0)
    free = ("tau0_mpa", "k_mpa_per_gpa", "shear_modulus_gpa")
    res = fit.fit_stiffness_curves(curves, start, free)
    assert res.success
    for name in free:
        err = res.standard_errors[name]
        assert err > 0
        assert abs(getattr(res.params, name) - getattr(TRUE, name)) < 3.5 * err, name
    # the fixed ones stay where they were
    assert res.params.mu_mpa_per_gpa == start.mu_mpa_per_gpa
    # the errors are about right: the scatter of the residuals is the noise put in
    assert res.correlation.shape == (3, 3)
    np.testing.assert_allclose(np.diag(res.correlation), 1.0, rtol=1e-9)
    assert np.all(np.abs(res.correlation) <= 1.0 + 1e-9)


def test_standard_errors_match_the_scatter_over_noise_draws():
    # the stated error of τ0 (τ0 alone free) against the spread of τ0 over 8 noise draws
    fits = []
    errs = []
    for seed in range(8):
        curves, _ = _synthetic(TRUE, 0.02, seed=100 + seed, n=15)
        r = fit.fit_stiffness_curves(curves, TRUE.replace(tau0_mpa=32.0), ("tau0_mpa",))
        fits.append(r.params.tau0_mpa)
        errs.append(r.standard_errors["tau0_mpa"])
    spread = np.std(fits, ddof=1)
    assert 0.4 < spread / np.mean(errs) < 2.5
    assert abs(np.mean(fits) - 40.0) < 3 * spread / np.sqrt(len(fits)) + 0.05


def test_modified_beats_classical_on_modified_data():
    curves, _ = _synthetic(TRUE, 0.01, seed=3)
    cmp = fit.fit_and_compare(
        curves, TRUE.replace(tau0_mpa=35.0), ("tau0_mpa", "shear_modulus_gpa")
    )
    out = cmp.to_json()
    assert out["preferred_model"] == "modified"
    assert out["delta_aicc_classical_minus_modified"] > 10
    assert cmp.classical.free == ("shear_modulus_gpa",)
    assert sum(r.size for r in cmp.modified.residuals_n_per_m) == cmp.modified.n_points
    # AIC from its definition
    m = cmp.modified
    assert m.aic == pytest.approx(m.n_points * np.log(m.rss / m.n_points) + 2 * m.n_free)


def test_load_column_csv_p0_and_normal_load(tmp_path):
    curves, _ = _synthetic(TRUE, 0.0, seed=0, n=6)
    rows = ["mean shear stress [MPa],lateral stiffness [N/m],p0 [GPa]"]
    rows_load = ["normal_load_un,mean_shear_stress_mpa,lateral_stiffness_kn_per_m"]
    for c in curves:
        a = float(mindlin.contact_radius(c.p0_gpa * 1e9, TRUE))
        load_un = 2 / 3 * np.pi * a * a * c.p0_gpa * 1e9 * 1e6
        for s, k in zip(c.stress_pa, c.stiffness_n_per_m, strict=True):
            rows.append(f"{s / 1e6:.17g},{k:.17g},{c.p0_gpa:.17g}")
            rows_load.append(f"{load_un:.17g},{s / 1e6:.17g},{k / 1e3:.17g}")
    (tmp_path / "all.csv").write_text("\n".join(rows) + "\n")
    (tmp_path / "load.csv").write_text(
        "# normal load instead of p0\n" + "\n".join(rows_load) + "\n"
    )
    for name in ("all.csv", "load.csv"):
        got = load_fit_data([tmp_path / name], TRUE)
        assert [c.p0_gpa for c in got] == pytest.approx(list(LOADS), rel=1e-9)
        for g, c in zip(got, curves, strict=True):
            np.testing.assert_allclose(g.stress_pa, c.stress_pa, rtol=1e-12)
            np.testing.assert_allclose(g.stiffness_n_per_m, c.stiffness_n_per_m, rtol=1e-12)


def test_one_file_per_load(tmp_path):
    curves, _ = _synthetic(TRUE, 0.0, seed=0, n=5)
    paths = []
    for c in curves:
        p = tmp_path / f"p{c.p0_gpa}.csv"
        lines = ["mean_shear_stress_mpa,lateral_stiffness_n_per_m"] + [
            f"{s / 1e6:.17g},{k:.17g}"
            for s, k in zip(c.stress_pa, c.stiffness_n_per_m, strict=True)
        ]
        p.write_text("\n".join(lines) + "\n")
        paths.append(p)
    got = load_fit_data(paths, TRUE, p0_gpa=LOADS)
    assert [c.p0_gpa for c in got] == list(LOADS)
    with pytest.raises(InputError, match=r"^p1.0.csv has no load column .*with 3 files"):
        load_fit_data(paths, TRUE)
    with pytest.raises(InputError, match=r"^fit_p0_gpa: 2 values for 3 files"):
        load_fit_data(paths, TRUE, p0_gpa=[1.0, 2.0])


def test_parameter_names_fixed_and_freed():
    curves, _ = _synthetic(TRUE, 0.0, seed=0, n=5)
    with pytest.raises(InputError, match=r"^fit parameter tau0_mpa is both fixed and freed$"):
        fit.fit_stiffness_curves(curves, TRUE, ("tau0_mpa",), ("tau0_mpa",))
    with pytest.raises(InputError, match=r"^fit parameter 'tau' is unknown"):
        fit.fit_stiffness_curves(curves, TRUE, ("tau",))
    with pytest.raises(InputError, match=r"does not enter the classical model"):
        fit.fit_stiffness_curves(curves, TRUE, ("tau0_mpa",), model="classical")


def test_fit_figure_shows_data_models_and_residuals():
    import matplotlib

    matplotlib.use("Agg")
    from flatcontact.plots.cycle import fig_fit

    curves, _ = _synthetic(TRUE, 0.01, seed=5, n=8)
    cmp = fit.fit_and_compare(curves, TRUE, ("tau0_mpa",))
    fig = fig_fit(cmp)
    ax, bx = fig.axes
    # per load: data, modified, classical; residuals of both models
    assert len(ax.get_lines()) == 3 * len(LOADS)
    assert len(bx.get_lines()) == 2 * len(LOADS) + 1
    _, r = bx.get_lines()[0].get_data()
    np.testing.assert_allclose(r, cmp.modified.residuals_n_per_m[0])
