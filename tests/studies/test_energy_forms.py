"""Both energy forms from one grid: the cobblestone model's exact laws in each form."""

import numpy as np
import pytest

from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.energy_forms import laws_both_forms
from flatcontact.analysis.options import AnalysisOptions
from flatcontact.foundation import units
from flatcontact.foundation.errors import InputError

A = 4.916
A1, A2 = syn.hexagonal_cell(A)
Z = np.linspace(24.3, 26.4, 36)
P_GPA = [0.0, 0.5, 1.0, 2.0]


@pytest.fixture(scope="module")
def cobblestone():
    # internal landscape = const + V g (load-independent); enthalpy = const + (V + P δ) g
    v, delta = -2e-4, -0.02
    grid = syn.SyntheticInterface(
        A1, A2, syn.three_cosine(A1, A2), corrugation_ev_per_a2=v, gap_modulation_angstrom=delta
    ).grid(9, 9, Z)
    return grid, v, delta


def test_each_form_gives_its_exact_load_slope(cobblestone):
    grid, v, delta = cobblestone
    out = laws_both_forms(grid, P_GPA, AnalysisOptions(direction_deg=0.0))
    internal = out["forms"]["internal"]["laws"]
    enthalpy = out["forms"]["enthalpy"]["laws"]
    tau0 = 4 * np.pi * -v / A * units.EV_PER_A3_TO_MPA
    k_enthalpy = 4 * np.pi * -delta / A * 1e3  # MPa/GPa, = 51.12
    tol = 5e-3 * tau0  # cubic-spline z interpolation on 36 points (tests/analysis)
    assert internal["k_mpa_per_gpa"] == pytest.approx(0.0, abs=tol)
    assert enthalpy["k_mpa_per_gpa"] == pytest.approx(k_enthalpy, abs=tol)
    # both forms coincide at P = 0 (h = U/A there)
    assert internal["tau0_mpa"] == pytest.approx(enthalpy["tau0_mpa"], rel=5e-3)
    assert internal["tau0_mpa"] == pytest.approx(tau0, rel=5e-3)


def test_side_by_side_table_matches_the_per_form_results(cobblestone):
    grid, _, _ = cobblestone
    out = laws_both_forms(grid, P_GPA, AnalysisOptions(direction_deg=0.0))
    rows = out["table"]
    assert [r["p_gpa"] for r in rows] == P_GPA
    for form in ("internal", "enthalpy"):
        per = out["forms"][form]["loads"]
        assert [r[f"tau_mpa_{form}"] for r in rows] == [r["tau_mpa"] for r in per]
    laws = {r["coefficient"]: r for r in out["laws_table"]}
    assert laws["k_mpa_per_gpa"]["enthalpy"] == out["forms"]["enthalpy"]["laws"]["k_mpa_per_gpa"]
    assert laws["k_mpa_per_gpa"]["internal_stderr"] is not None


def test_unknown_form_is_refused(cobblestone):
    grid, _, _ = cobblestone
    with pytest.raises(InputError, match="forms"):
        laws_both_forms(grid, P_GPA, forms=("gibbs",))
