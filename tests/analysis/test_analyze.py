"""The whole analysis from a contract grid: exact load laws, convergence, invariances, noise."""

import numpy as np
import pytest

from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.analyze import analyze_ispes
from flatcontact.analysis.options import AnalysisOptions
from flatcontact.foundation import units
from flatcontact.foundation.errors import InputError

A = 4.916
A1, A2 = syn.hexagonal_cell(A)
Z = np.linspace(24.3, 26.4, 36)
P_GPA = [0.0, 0.5, 1.0, 2.0]
# single-load analyses cannot fit load laws; that warning is tested in test_laws.py
pytestmark = pytest.mark.filterwarnings("ignore::flatcontact.analysis.diagnostics.LinearFitWarning")


def _cobblestone(v=-2e-4, delta=-0.02, pattern=None, a1=A1, a2=A2):
    """c = 0: internal landscape = const + V g, enthalpy landscape = const + (V + P δ) g, exactly."""
    return syn.SyntheticInterface(
        a1,
        a2,
        pattern or syn.three_cosine(a1, a2),
        corrugation_ev_per_a2=v,
        gap_modulation_angstrom=delta,
    )


@pytest.mark.parametrize("form", ["internal", "enthalpy"])
@pytest.mark.parametrize("load_source", ["stress", "energy"])
def test_load_laws_are_exact_for_the_cobblestone_model(form, load_source):
    v, delta = -2e-4, -0.02
    ds = _cobblestone(v, delta).grid(9, 9, Z)
    res = analyze_ispes(
        ds,
        P_GPA,
        AnalysisOptions(direction_deg=0.0, form=form, with_symmetry=False, load_source=load_source),
    )
    # the cubic spline's -dU/dz errs as h³ (p's spline as h⁴); the internal form feels it at
    # first order (P δz), the enthalpy form at second
    rtol = 5e-3 if (load_source, form) == ("energy", "internal") else 2e-4
    p_ev = np.array(P_GPA) / units.EV_PER_A3_TO_GPA
    amp = -(v + p_ev * delta) if form == "enthalpy" else -v * np.ones_like(p_ev)
    tau = 4 * np.pi * amp / A * units.EV_PER_A3_TO_MPA
    sigma = 4 * amp / A * units.EV_PER_A3_TO_MPA
    stiff = 2 * amp * (2 * np.pi / A) ** 2 * units.EV_PER_A3_TO_GPA / units.ANGSTROM_TO_NM
    # limited by the cubic-spline interpolation in z (36 points), tested for convergence elsewhere
    np.testing.assert_allclose(res.column("tau_mpa"), tau, rtol=rtol)
    np.testing.assert_allclose(res.column("sigma_mss_mpa"), sigma, rtol=rtol)
    np.testing.assert_allclose(res.column("shear_stiffness_gpa_per_nm"), stiff, rtol=rtol)
    laws = res.laws.to_json()
    k_exact = (4 * np.pi * -delta / A * 1e3) if form == "enthalpy" else 0.0  # MPa/GPa
    assert laws["k_mpa_per_gpa"] == pytest.approx(k_exact, abs=rtol * abs(tau[0]))
    assert laws["tau0_mpa"] == pytest.approx(tau[0], rel=rtol)
    assert laws["mu_mpa_per_gpa"] == pytest.approx(k_exact / np.pi, abs=rtol * abs(tau[0]))
    assert laws["p_max_gpa"] == 2.0


def test_results_converge_with_lateral_resolution():
    a, b, w = 4.0, 6.0, 0.5
    a1, a2 = syn.rectangular_cell(a, b)
    model = _cobblestone(2e-4, 0.0, syn.canyon(1, 0.08, w), a1, a2)
    exact_tau = 2e-4 * w * 2 * np.pi / b * units.EV_PER_A3_TO_MPA
    errors = []
    for n in (8, 12, 16, 24):
        res = analyze_ispes(model.grid(n, n, Z), [1.0], AnalysisOptions(with_symmetry=False))
        errors.append(abs(res.column("tau_mpa")[0] - exact_tau) / exact_tau)
    assert errors[0] > errors[1] > errors[2] > errors[3]
    assert errors[-1] < 1e-6  # spectral convergence of the lateral interpolant


def test_shifting_the_grid_laterally_or_adding_a_constant_changes_nothing():
    pattern = syn.three_cosine(A1, A2, (1.0, 0.8, 1.15))
    model = syn.SyntheticInterface(
        A1, A2, pattern, depth_modulation=0.2, corrugation_ev_per_a2=-2e-4
    )
    base = analyze_ispes(model.grid(12, 12, Z), [0.5, 1.5], AnalysisOptions(with_symmetry=True))
    moved_model = syn.SyntheticInterface(
        A1,
        A2,
        syn.shifted(pattern, (0.137, 0.291)),
        depth_modulation=0.2,
        corrugation_ev_per_a2=-2e-4,
    )
    ds = moved_model.grid(12, 12, Z)
    ds["energy"] = ds.energy + 123.456
    moved = analyze_ispes(ds, [0.5, 1.5], AnalysisOptions(with_symmetry=True))
    for name in ("tau_mpa", "sigma_mss_mpa", "shear_stiffness_gpa_per_nm"):
        np.testing.assert_allclose(moved.column(name), base.column(name), rtol=1e-3)
    # the fractional shift is not a grid multiple, so the comparison is limited by the
    # lateral interpolation of a non-band-limited surface (c != 0); symmetry likewise
    for pa, pb in zip(base.pressures, moved.pressures, strict=True):
        assert pa.symmetry.kept == pb.symmetry.kept
        np.testing.assert_allclose(
            [op.deviation for op in pa.symmetry.operations],
            [op.deviation for op in pb.symmetry.operations],
            atol=2e-3,
        )


def test_exact_grid_shift_and_constant_give_identical_numbers():
    model = _cobblestone()
    base = analyze_ispes(
        model.grid(12, 12, Z), [0.5], AnalysisOptions(direction_deg=20.0, with_symmetry=False)
    )
    moved_model = _cobblestone(pattern=syn.shifted(syn.three_cosine(A1, A2), (5 / 12, 7 / 12)))
    ds = moved_model.grid(12, 12, Z)
    ds["energy"] = ds.energy - 1e3
    moved = analyze_ispes(ds, [0.5], AnalysisOptions(direction_deg=20.0, with_symmetry=False))
    for name in ("tau_mpa", "sigma_mss_mpa", "shear_stiffness_gpa_per_nm"):
        np.testing.assert_allclose(moved.column(name), base.column(name), rtol=1e-9)


def test_noise_moves_the_numbers_in_proportion_to_its_size():
    model = _cobblestone()
    clean = analyze_ispes(
        model.grid(12, 12, Z), [1.0], AnalysisOptions(direction_deg=0.0, with_symmetry=False)
    )
    corrugation_ev = 4.5 * 2e-4 * model.area  # peak-to-peak of the lateral landscape (eV per cell)
    errs = []
    for rel in (1e-4, 1e-3):
        ds = model.grid(12, 12, Z, energy_noise_ev=rel * corrugation_ev, seed=7)
        noisy = analyze_ispes(ds, [1.0], AnalysisOptions(direction_deg=0.0, with_symmetry=False))
        errs.append(abs(noisy.column("tau_mpa")[0] / clean.column("tau_mpa")[0] - 1))
        assert (
            abs(noisy.column("sigma_mss_mpa")[0] / clean.column("sigma_mss_mpa")[0] - 1) < 30 * rel
        )
    assert errs[0] < 30 * 1e-4 and errs[1] < 30 * 1e-3
    assert errs[1] > errs[0]


def test_bad_arguments_fail_before_any_work():
    """Each error names the parameter (the CLI and the run translate it to their flag or path)."""
    ds = _cobblestone().grid(4, 4, Z)
    with pytest.raises(InputError, match=r"^p_gpa: give at least one"):
        analyze_ispes(ds, [])
    with pytest.raises(InputError, match="distinct"):
        analyze_ispes(ds, [1.0, 1.0])
    with pytest.raises(InputError, match=r"^form: expected one of internal, enthalpy"):
        analyze_ispes(ds, [1.0], AnalysisOptions(form="gibbs"))
    with pytest.raises(InputError, match=r"^energy_zero: expected one of"):
        analyze_ispes(ds, [1.0], AnalysisOptions(energy_zero="min"))
    with pytest.raises(InputError, match=r"^direction_deg: expected a finite angle"):
        analyze_ispes(ds, [1.0], AnalysisOptions(direction_deg=float("nan")))
    with pytest.raises(InputError, match="outside the data"):
        analyze_ispes(ds, [1.0, 80.0])


def test_options_are_checked_on_construction_and_on_replace():
    """The options object is frozen and refuses a bad field when made or changed, naming the
    field; a mapping in its place is refused naming the parameter."""
    import dataclasses

    ds = _cobblestone().grid(4, 4, Z)
    with pytest.raises(InputError, match=r"^options: expected an AnalysisOptions, got dict"):
        analyze_ispes(ds, [1.0], {"form": "internal"})
    base = AnalysisOptions(form="enthalpy", threshold_gpa=2.0)
    with pytest.raises(InputError, match=r"^load_source: expected one of energy, stress"):
        dataclasses.replace(base, load_source="virial")
    with pytest.raises(InputError, match=r"^threshold_gpa: expected a positive pressure"):
        dataclasses.replace(base, threshold_gpa=0.0)
    with pytest.raises(InputError, match=r"^direction_deg auto: needs the stackings"):
        AnalysisOptions(direction_deg="auto", with_stackings=False)
    with pytest.raises(InputError, match=r"^direction_deg: expected an angle in degrees or 'auto'"):
        AnalysisOptions(direction_deg="north")
    with pytest.raises(dataclasses.FrozenInstanceError):
        base.form = "internal"
    assert dataclasses.replace(base, form="internal").threshold_gpa == 2.0


def test_energy_zero_at_the_lowest_pressure_minimum():
    res = analyze_ispes(
        _cobblestone().grid(8, 8, Z), [0.5, 2.0], AnalysisOptions(with_symmetry=False)
    )
    low, high = res.pressures
    assert low.path.energy[0] == pytest.approx(0.0, abs=1e-12)
    assert np.min(low.surface.values) >= -1e-12
    # the internal energy at z*(P) rises with P (compression): U(P) - U(0.5) = -∫ P A dz > 0
    assert high.path.energy[0] > 0
