"""compare_ispes: the same interface scanned with several models, side by side (no torch needed)."""

import json

import numpy as np
import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.potentials import InteractionModel
from flatcontact.training.ispes_check import (
    QUARTZ_CIJ_EXPERIMENT_GPA,
    compare_ispes,
    comparison_table,
    elastic_table,
    teacher_spec,
)

LOADS = (0.0, 0.5, 1.0)
# a 3×3 grid is noisy by design here; the noise warning is tested in tests/analysis
pytestmark = pytest.mark.filterwarnings("ignore::flatcontact.analysis.diagnostics.AnalysisWarning")


@pytest.fixture(scope="module")
def interface():
    from flatcontact.structures.build import build_quartz_interface

    atoms, _ = build_quartz_interface(InteractionModel(intra="vashishta"), 6, source="shipped")
    return atoms


@pytest.fixture(scope="module")
def committee(interface, tmp_path_factory):
    out = tmp_path_factory.mktemp("committee")
    from flatcontact.config import default_potential

    lj = {**default_potential()["lj"], "cutoff_angstrom": 8.0}
    models = {
        "vashishta": InteractionModel(intra="vashishta", lj=lj),
        "tersoff": InteractionModel(intra="tersoff", lj=lj),
        "vashishta-again": InteractionModel(intra="vashishta", lj=lj),
    }
    results = {}
    table = compare_ispes(
        models,
        interface,
        out,
        grid=(3, 3),
        p_range_gpa=(-0.5, 2.5, 6),
        p_gpa=LOADS,
        fmax_ev_per_angstrom=0.01,
        results=results,
    )
    return table, results


def test_reference_rows_have_zero_difference_and_others_are_model_minus_reference(committee):
    table, results = committee
    assert list(table["model"].unique()) == ["vashishta", "tersoff", "vashishta-again"]
    ref = table[table.model == "vashishta"]
    for q in ("tau_mpa", "sigma_mss_mpa", "work_of_separation_j_per_m2"):
        assert (ref[f"d_{q}"] == 0).all()
    ter = table[table.model == "tersoff"].set_index("p_gpa")
    van = ref.set_index("p_gpa")
    for q in ("tau_mpa", "sigma_mss_mpa", "shear_stiffness_gpa_per_nm"):
        np.testing.assert_allclose(ter[f"d_{q}"], ter[q] - van[q])
        np.testing.assert_allclose(ter[f"rel_{q}"], (ter[q] - van[q]) / van[q].abs())
    # two physically different silica models give different friction on the same interface
    assert np.abs(ter["d_tau_mpa"]).max() > 0.1
    # per-model results carry the laws and a positive work of separation
    for label in ("vashishta", "tersoff"):
        assert results[label]["work_of_separation_j_per_m2"] > 0
        assert set(results[label]["laws"]) >= {"k_mpa_per_gpa", "tau0_mpa"}


def test_the_same_model_twice_gives_the_same_numbers(committee):
    """The committee member scanned twice agrees to round-off. Not bit for bit: the engine
    sends each atom at the image nearest the one LAMMPS holds, and a second scan in the same
    process starts from the images the first left, so the last bits of the positions differ
    (measured: ≤ 8.4e-9 MPa on τ of tens of MPa, 2e-10 relative)."""
    table, _ = committee
    again = table[table.model == "vashishta-again"]
    for q in ("tau_mpa", "sigma_mss_mpa", "shear_stiffness_gpa_per_nm"):
        np.testing.assert_allclose(again[f"d_{q}"], 0.0, atol=1e-7)


def test_committee_spread_is_half_the_range_and_the_repeated_member_adds_nothing(committee):
    """The laws' model spread over the whole committee (analysis.uncertainty.committee_spread)."""
    from flatcontact.analysis.uncertainty import LAW_COEFFICIENTS, committee_spread

    _, results = committee
    spread = committee_spread(results)
    # the repeated member equals the first to round-off (see the test above): it adds nothing
    pair = committee_spread({k: results[k] for k in ("vashishta", "tersoff")})
    assert spread.keys() == pair.keys()
    # round-off of the laws (≤ 1e-9 relative) on a spread that is a small difference of them
    # (μ: 0.0198 of 1.06): 1e-9 MPa absolute, measured; 1e-7 allowed
    assert all(spread[k] == pytest.approx(pair[k], rel=1e-8, abs=1e-7) for k in pair)
    for key in LAW_COEFFICIENTS:
        a, b = (results[m]["laws"][key] for m in ("vashishta", "tersoff"))
        assert spread[key] == pytest.approx(abs(a - b) / 2, rel=1e-8, abs=1e-7)
    assert max(spread.values()) > 0  # two different silica models: a non-zero spread


def test_comparison_table_round_trips_through_json(committee):
    _, results = committee
    back = json.loads(json.dumps(results, default=float))
    table = comparison_table({k: back[k] for k in ("tersoff", "vashishta")})
    ref = table[table.model == "tersoff"]
    assert (ref["d_tau_mpa"] == 0).all()  # now tersoff is the reference


def test_bad_models_are_refused_before_any_scan(interface, tmp_path):
    with pytest.raises(InputError, match="label"):
        compare_ispes({"a/b": InteractionModel(intra="vashishta")}, interface, tmp_path)
    with pytest.raises(InputError, match="expected an InteractionModel"):
        compare_ispes({"x": "vashishta"}, interface, tmp_path)
    with pytest.raises(InputError, match="exactly one"):
        compare_ispes(
            {"v": InteractionModel(intra="vashishta")},
            interface,
            tmp_path,
            p_range_gpa=None,
            thickness_angstrom=None,
        )
    assert not any(tmp_path.iterdir())
    with pytest.raises(InputError, match="teacher"):
        teacher_spec("mace")


def test_teacher_calculator_refuses_an_unknown_teacher_in_one_line():
    from flatcontact.training.ispes_check import TEACHERS, teacher_calculator

    with pytest.raises(InputError, match=r"teacher 'mace': .*expected one of chgnet-r2scan"):
        teacher_calculator("mace")
    assert all(t.factory.count(":") == 1 for t in TEACHERS.values())


def test_elastic_table_errors_are_relative_to_experiment():
    report = {
        "label": "half",
        "lattice": {"a_angstrom": 4.9, "c_angstrom": 5.4},
        "cij_gpa": {k: v / 2 for k, v in QUARTZ_CIJ_EXPERIMENT_GPA.items()},
        "rel_error": {k: -0.5 for k in QUARTZ_CIJ_EXPERIMENT_GPA},
        "moduli_gpa": {"e_star": 30.0},
    }
    t = elastic_table([report]).set_index("model")
    assert t.loc["experiment", "C11"] == 86.8 and t.loc["half", "C11"] == pytest.approx(43.4)
    assert t.loc["half", "max_rel_error_c11_c33_c44"] == pytest.approx(0.5)


def test_bundled_snap_elastic_constants_match_the_measured_values():
    """The bundled SNAP's α-quartz C11 is 54 GPa (NOTES.md, `flatcontact elastic`): 38 % soft."""
    from flatcontact.potentials.engines import bulk_calculator
    from flatcontact.training.ispes_check import quartz_elastic_vs_experiment

    doc = quartz_elastic_vs_experiment(bulk_calculator("sio2-snap"), "snap")
    assert doc["cij_gpa"]["C11"] == pytest.approx(54.0, abs=1.0)
    assert doc["rel_error"]["C11"] == pytest.approx(doc["cij_gpa"]["C11"] / 86.8 - 1)
    assert doc["cij_gpa"]["C14"] > 0  # |C14|
    # trigonal relation C66 = (C11 - C12)/2 holds for the measured tensor
    c = doc["cij_gpa"]
    assert c["C66"] == pytest.approx((c["C11"] - c["C12"]) / 2, rel=0.03)
