"""Load-law fits, standard errors and the end of the linear regime."""

import numpy as np
import pytest
from scipy import stats

from flatcontact.analysis.diagnostics import LinearFitWarning
from flatcontact.analysis.laws import fit_linear_law, fit_load_laws

P = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0])


def test_exact_line_is_recovered_and_never_departs():
    law = fit_linear_law(P, 4.52 * P + 26.7)
    assert law.slope == pytest.approx(4.52, rel=1e-12)
    assert law.intercept == pytest.approx(26.7, rel=1e-12)
    assert law.slope_stderr < 1e-6 and law.n_points == 7 and law.p_max_gpa == 3.0
    assert law.linear_until_gpa == 6.0 and law.departs_at_gpa is None


def test_standard_errors_are_the_ols_ones():
    rng = np.random.default_rng(4)
    y = 0.21 * P + 11.1 + rng.normal(scale=0.05, size=P.size)
    law = fit_linear_law(P, y)
    ref = stats.linregress(P[P <= 3], y[P <= 3])
    assert law.slope_stderr == pytest.approx(ref.stderr)
    assert law.intercept_stderr == pytest.approx(ref.intercept_stderr)
    # a point above the threshold within the noise is still on the law
    assert law.departs_at_gpa is None or law.departs_at_gpa > 3.0


def test_sharp_rise_above_the_threshold_is_detected_at_the_first_departing_point():
    rng = np.random.default_rng(5)
    y = 4.52 * P + 26.7 + rng.normal(scale=0.05, size=P.size)
    y[P >= 5.0] += 8.0 * (P[P >= 5.0] - 4.0) ** 2  # plastic onset between 4 and 5 GPa
    law = fit_linear_law(P, y)
    assert law.linear_until_gpa == 4.0 and law.departs_at_gpa == 5.0


def test_too_few_points_warn_and_give_undefined_errors():
    with pytest.warns(LinearFitWarning, match="only 2 points"):
        law = fit_linear_law([0.5, 1.0, 4.0], [1.0, 2.0, 9.0])
    assert law.slope == pytest.approx(2.0) and np.isnan(law.slope_stderr)
    assert law.departs_at_gpa == 4.0
    with pytest.warns(LinearFitWarning, match="1 point"):
        laws = fit_load_laws([1.0], [2.0], [1.0])
    data = laws.to_json()
    assert data["k_mpa_per_gpa"] is None and data["p_max_gpa"] is None


def test_laws_json_has_the_contract_keys():
    laws = fit_load_laws(P, 4.52 * P + 26.7, 0.21 * P + 11.1)
    data = laws.to_json()
    for key in (
        "k_mpa_per_gpa",
        "tau0_mpa",
        "mu_mpa_per_gpa",
        "sigma0_mpa",
        "k_stderr_mpa_per_gpa",
        "tau0_stderr_mpa",
        "mu_stderr_mpa_per_gpa",
        "sigma0_stderr_mpa",
        "p_max_gpa",
    ):
        assert key in data
    assert data["mu_mpa_per_gpa"] == pytest.approx(0.21) and data["sigma0_mpa"] == pytest.approx(
        11.1
    )
