"""Propagation of the law uncertainties (flatcontact.analysis.uncertainty)."""

import numpy as np
import pytest

from flatcontact.analysis.uncertainty import (
    committee_spread,
    law_half_widths,
    law_intervals,
    model_spread,
    propagate_box,
)
from flatcontact.foundation.errors import InputError

LAWS = {
    "k_mpa_per_gpa": 16.5,
    "tau0_mpa": 30.2,
    "mu_mpa_per_gpa": 4.58,
    "sigma0_mpa": 7.51,
    "k_stderr_mpa_per_gpa": 3.0,
    "tau0_stderr_mpa": 4.0,
    "mu_stderr_mpa_per_gpa": 0.4,
    "sigma0_stderr_mpa": 0.64,
}


def _linear(x):
    return {"f": 2.0 * x["a"] - 3.0 * x["b"] + 1.0, "g": x["a"] * x["b"]}


def test_linear_output_gets_the_exact_worst_case_interval():
    out = propagate_box(_linear, {"a": 1.0, "b": 2.0}, {"a": 0.1, "b": 0.2})
    lo, mid, hi = out["f"]
    assert mid == pytest.approx(2 - 6 + 1)
    assert lo == pytest.approx(mid - (2 * 0.1 + 3 * 0.2))
    assert hi == pytest.approx(mid + (2 * 0.1 + 3 * 0.2))
    # product of positives: the corners (0.9, 1.8) and (1.1, 2.2)
    assert out["g"][0] == pytest.approx(0.9 * 1.8) and out["g"][2] == pytest.approx(1.1 * 2.2)


def test_intervals_contain_the_central_value_even_for_a_non_monotone_output():
    out = propagate_box(lambda x: {"q": (x["a"] - 1.0) ** 2}, {"a": 1.0}, {"a": 0.5})
    lo, mid, hi = out["q"]
    assert lo <= mid <= hi and mid == 0.0 and hi == pytest.approx(0.25)


def test_zero_input_error_gives_zero_width():
    hw = law_half_widths({k: v for k, v in LAWS.items() if "stderr" not in k})
    assert all(h == 0 for h in hw.values())
    central = {k: LAWS[k] for k in hw}
    out = propagate_box(lambda x: {"tau_1gpa": x["k_mpa_per_gpa"] + x["tau0_mpa"]}, central, hw)
    lo, mid, hi = out["tau_1gpa"]
    assert lo == mid == hi == pytest.approx(46.7)


def test_sources_add_in_quadrature_and_scale_with_coverage():
    hw = law_half_widths(LAWS, convergence={"tau0_mpa": 3.0}, model={"tau0_mpa": 12.0}, coverage=2)
    assert hw["tau0_mpa"] == pytest.approx(2 * 13.0)  # sqrt(4² + 3² + 12²) = 13
    assert hw["k_mpa_per_gpa"] == pytest.approx(2 * 3.0)
    iv = law_intervals(LAWS, hw)
    assert iv["tau0_mpa"]["low"] == pytest.approx(30.2 - 26) and iv["tau0_mpa"][
        "high"
    ] == pytest.approx(56.2)


def test_model_spread_is_half_the_range():
    spread = model_spread(
        {"snap": LAWS, "teacher": {**LAWS, "tau0_mpa": 40.2, "mu_mpa_per_gpa": None}}
    )
    assert spread["tau0_mpa"] == pytest.approx(5.0)
    assert spread["k_mpa_per_gpa"] == 0.0 and spread["mu_mpa_per_gpa"] == 0.0
    with pytest.raises(InputError, match="at least two"):
        model_spread({"snap": LAWS})


def _tau_at_p0(laws, spread, p0=1.77):
    hw = law_half_widths(laws, model=spread)
    return propagate_box(
        lambda x: {"tau": x["k_mpa_per_gpa"] * p0 + x["tau0_mpa"]}, {k: laws[k] for k in hw}, hw
    )["tau"]


def test_spread_is_over_all_models_and_a_repeated_teacher_does_not_widen_it():
    teacher_a = {**LAWS, "tau0_mpa": 40.2, "k_mpa_per_gpa": 14.5}
    teacher_b = {**LAWS, "tau0_mpa": 24.2, "k_mpa_per_gpa": 17.0}
    two = model_spread({"snap": LAWS, "a": teacher_a})
    three = model_spread({"snap": LAWS, "a": teacher_a, "b": teacher_b})
    # half the max - min range over SNAP and every teacher: τ0 in [24.2, 40.2], k in [14.5, 17]
    assert three["tau0_mpa"] == pytest.approx(8.0) and three["k_mpa_per_gpa"] == pytest.approx(1.25)
    assert two["tau0_mpa"] == pytest.approx(5.0) and two["k_mpa_per_gpa"] == pytest.approx(1.0)
    # a teacher repeating another's numbers (or lying inside the range) adds no width
    again = model_spread({"snap": LAWS, "a": teacher_a, "b": teacher_b, "a-again": dict(teacher_a)})
    inside = model_spread(
        {"snap": LAWS, "a": teacher_a, "b": teacher_b, "mid": {**LAWS, "tau0_mpa": 30}}
    )
    assert again == three and inside == three
    assert _tau_at_p0(LAWS, again) == _tau_at_p0(LAWS, three)
    lo2, mid2, hi2 = _tau_at_p0(LAWS, two)
    lo3, mid3, hi3 = _tau_at_p0(LAWS, three)
    assert mid2 == mid3 and lo3 < lo2 <= mid2 <= hi2 < hi3  # a teacher outside does widen


def test_committee_spread_reads_the_comparison_results():
    results = {
        "snap": {"laws": LAWS, "force_calls": 10},
        "teacher": {"laws": {**LAWS, "sigma0_mpa": 8.51}, "force_calls": 12},
    }
    spread = committee_spread(results)
    assert spread["sigma0_mpa"] == pytest.approx(0.5) and spread["tau0_mpa"] == 0.0
    with pytest.raises(InputError, match=r"teacher.*laws"):
        committee_spread({"snap": results["snap"], "teacher": {"rows": []}})


def test_nonnegative_inputs_are_clipped_at_the_corners():
    out = propagate_box(lambda x: {"v": x["k"]}, {"k": 1.0}, {"k": 3.0}, nonnegative=["k"])
    assert out["v"] == (0.0, 1.0, 4.0)


def test_bad_half_widths_are_refused():
    with pytest.raises(InputError, match="not an input"):
        propagate_box(_linear, {"a": 1.0, "b": 2.0}, {"c": 0.1})
    with pytest.raises(InputError, match=">= 0"):
        propagate_box(_linear, {"a": 1.0, "b": 2.0}, {"a": -0.1})
    with pytest.raises(InputError, match="at most"):
        many = {f"x{i}": 1.0 for i in range(9)}
        propagate_box(lambda x: {"s": sum(x.values())}, many, dict.fromkeys(many, 0.1))


def test_shear_strength_band_at_the_hertz_peak_from_the_law_box():
    """τ(p) = k p + τ0 at the Hertz peak p0 = 1.77 GPa: band = central ± (h_k p0 + h_τ0)."""
    p0 = 1.77
    hw = law_half_widths(LAWS)
    out = propagate_box(
        lambda x: {"tau_p0_mpa": x["k_mpa_per_gpa"] * p0 + x["tau0_mpa"]},
        {k: LAWS[k] for k in hw},
        hw,
    )
    lo, mid, hi = out["tau_p0_mpa"]
    assert mid == pytest.approx(16.5 * p0 + 30.2)
    np.testing.assert_allclose([mid - lo, hi - mid], 3.0 * p0 + 4.0)
