"""Issue 36 checked against issue 35: the bonded Cu(111) asperities in atoms (stored runs)
against the critical size of concurrent slip. The docs' table is the generator's output, and
the physics it states holds in the stored data: below a_c the atoms slide at the concurrent
number; past it they fall below it, toward τ_dis(a)."""

import math

import pytest
from benchmarks import slip_crossover as crossover

from flatcontact.contact.slip_size import critical_radius, dislocation_strength


def test_the_docs_table_is_the_stored_runs():
    text = crossover.DOC.read_text(encoding="utf-8")
    block = text.split(crossover.BEGIN, 1)[1].split(crossover.END, 1)[0]
    assert block.strip() == crossover.table().strip(), (
        "rerun python -m benchmarks.slip_crossover --write"
    )


def test_tau_dis_and_a_c_are_the_closed_forms():
    """√(8 G γ/(π a)) and 8 G γ/(π τ²) written out: a_c is where τ_dis(a_c) = τ_c."""
    g, gamma, tau_c = 57.7e9, 0.163, 2.4e9
    a_c = float(critical_radius(tau_c, g, gamma))
    assert a_c == pytest.approx(8 * g * gamma / (math.pi * tau_c**2), rel=1e-12)
    assert float(dislocation_strength(a_c, g, gamma)) == pytest.approx(tau_c, rel=1e-12)


def test_the_crossover_is_where_the_estimate_puts_it():
    rows = crossover.rows()
    assert [r["radius_nm"] for r in rows] == [20.0, 40.0, 80.0]
    below = [r for r in rows if r["a_nm"] < r["a_c_nm"]]
    past = [r for r in rows if r["a_nm"] > r["a_c_nm"]]
    assert below and past
    # below a_c: the concurrent number holds (atoms within 15 % of it)
    for r in below:
        assert r["regime"] == "concurrent"
        assert r["atoms_mpa"] == pytest.approx(r["concurrent_mpa"], rel=0.15)
    # past a_c: the atoms fall below the concurrent number, and further with size
    for r in past:
        assert r["atoms_mpa"] < 0.9 * r["concurrent_mpa"]
    atoms = [r["atoms_mpa"] for r in rows]
    assert atoms == sorted(atoms, reverse=True)
    # where the peak was reached, the size-limited estimate is within 10 % of the atoms
    for r in past:
        if r["peak_reached"]:
            assert r["atoms_mpa"] == pytest.approx(r["tau_dis_mpa"], rel=0.10)
