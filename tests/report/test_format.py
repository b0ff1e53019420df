"""How the report writes a value with its standard error (:func:`flatcontact.report.format.pm`)."""

from __future__ import annotations

import pytest

from flatcontact.report.format import pm


@pytest.mark.parametrize(
    ("value", "err"),
    [(5876.023, 0.869), (1758.726, 0.129), (158.863, 0.242), (3784.98, 2.6)],
)
def test_the_value_keeps_every_digit_its_error_resolves(value, err):
    """Ni(111)'s τ0 was written '5.88e+03 ± 0.87': the value rounded to tens beside an error of
    a hundredth. The value is written to the error's second significant digit, and reading
    the text back gives the value to within half that digit."""
    text = pm(value, err)
    v, e = (float(x) for x in text.split(" ± "))
    assert e == pytest.approx(err, rel=0.06)
    last = 10.0 ** -len(text.split(" ± ")[0].split(".")[1])
    assert abs(v - value) <= last / 2 + 1e-12
    assert last <= err / 5  # finer than the error


@pytest.mark.parametrize(
    ("value", "err", "text"),
    [(-1.733, 0.929, "-1.73 ± 0.93"), (-0.9, 0.3, "-0.9 ± 0.3"), (30.5, 9.7, "30.5 ± 9.7")],
)
def test_a_value_as_precise_as_its_error_keeps_three_significant_digits(value, err, text):
    assert pm(value, err) == text
    assert pm(value, None) == f"{value:.3g}" and pm(None, err) == "n/a"
