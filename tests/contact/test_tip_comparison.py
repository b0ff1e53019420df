"""The experiment comparison's contact side: the moduli of the tip's bodies by their closed
forms, and the collapse stress's independence of E*, G* and R (they scale a and u out of
Q/(π a²) and k/k0), against the paper's laws' collapse computed independently."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from flatcontact.contact.moduli import (
    contact_modulus,
    johnson_effective_shear_modulus,
    paper_shear_modulus,
)
from flatcontact.contact.oscillation import stiffness_curve
from flatcontact.contact.parameters import ContactParameters
from flatcontact.contact.tip_comparison import compare_collapse
from flatcontact.foundation.reference import (
    DIAMOND_ISOTROPIC,
    FUSED_SILICA_ISOTROPIC,
    PAPER,
    PAPER_EXPERIMENT_COLLAPSE_MPA,
    PAPER_EXPERIMENT_P0_GPA,
)

EXAMPLES = Path(__file__).parents[2] / "examples"
TIP = sorted(EXAMPLES.glob("passivated-tip-*.yaml"))
LAWS = {k: PAPER[k] for k in ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa")}


def _bodies():
    d, s = DIAMOND_ISOTROPIC, FUSED_SILICA_ISOTROPIC
    return (
        d["youngs_modulus_gpa"],
        d["poisson_ratio"],
        s["youngs_modulus_gpa"],
        s["poisson_ratio"],
    )


def test_contact_modulus_limits_and_the_tip_on_silica():
    """E* of identical bodies is E/(2(1 − ν²)); of a rigid indenter E/(1 − ν²); diamond on
    fused silica (1141, 0.07; 72, 0.17 GPa) is 69.64 GPa, computed here term by term."""
    assert contact_modulus(100.0, 0.25, 100.0, 0.25) == pytest.approx(100.0 / (2 * (1 - 0.0625)))
    assert contact_modulus(1e12, 0.3, 70.0, 0.2) == pytest.approx(70.0 / (1 - 0.04), rel=1e-9)
    e1, n1, e2, n2 = _bodies()
    by_hand = 1.0 / ((1 - 0.07**2) / 1141.0 + (1 - 0.17**2) / 72.0)
    assert contact_modulus(e1, n1, e2, n2) == pytest.approx(by_hand, rel=1e-12)
    assert by_hand == pytest.approx(69.64, abs=0.005)


def test_paper_shear_modulus_is_four_johnson_from_e_and_nu():
    """G* (paper) = 4 G*_J with G = E/(2(1 + ν)); identical bodies: G*_J = G/(2(2 − ν))."""
    e, nu = 100.0, 0.25
    g = e / (2 * (1 + nu))
    assert paper_shear_modulus(e, nu, e, nu) == pytest.approx(4 * g / (2 * (2 - nu)))
    e1, n1, e2, n2 = _bodies()
    gj = johnson_effective_shear_modulus(e1 / (2 * (1 + n1)), n1, e2 / (2 * (1 + n2)), n2)
    assert paper_shear_modulus(e1, n1, e2, n2) == pytest.approx(4 * gj)
    assert paper_shear_modulus(e1, n1, e2, n2) == pytest.approx(63.40, abs=0.005)


@pytest.mark.parametrize("path", TIP, ids=lambda p: p.stem)
def test_the_tip_examples_state_the_closed_form_moduli_and_the_experiment(path):
    """Each experiment example gives E*, G* of diamond on silica (to the digits written), the
    paper's R and p0, and asks for the comparison."""
    contact = yaml.safe_load(path.read_text())["contact"]
    assert contact["contact_modulus_gpa"] == pytest.approx(contact_modulus(*_bodies()), abs=0.005)
    assert contact["shear_modulus_gpa"] == pytest.approx(paper_shear_modulus(*_bodies()), abs=0.005)
    assert contact["radius_um"] == PAPER["radius_um"]
    assert contact["experiment"] == {"compare": "passivated-tip", "p0_gpa": PAPER_EXPERIMENT_P0_GPA}
    assert PAPER_EXPERIMENT_P0_GPA in contact["p0_gpa"]


def _collapse_from_curve(p0_gpa: float, params: ContactParameters) -> float:
    """The collapse stress (MPa) read off a dense stiffness curve: the first amplitude stress
    where k < 0.2 k0, linearly interpolated — no root finding."""
    frac = np.linspace(0.0, 1.0, 4001)[:-1]
    c = stiffness_curve(p0_gpa * 1e9, params, q_max_over_peak=frac)
    ratio = c.stiffness_n_per_m / c.initial_stiffness_n_per_m
    i = int(np.nonzero(ratio < 0.2)[0][0]) if np.any(ratio < 0.2) else None
    if i is None:  # still above at the last point: the collapse is Q_peak itself
        return c.collapse_stress_amplitude_pa / 1e6
    x, y = c.stress_amplitude_pa / 1e6, ratio
    return float(x[i - 1] + (0.2 - y[i - 1]) * (x[i] - x[i - 1]) / (y[i] - y[i - 1]))


def test_collapse_stress_does_not_depend_on_the_moduli_or_radius():
    """The same laws with silica (E* 69.6, G* 63.4 GPa) and with a graphite-like soft
    counter-body (E* 24.5, G* 10 GPa) and another R: a, P differ, the collapse stress does
    not; it equals the value read off a dense stiffness curve, and with the paper's laws it
    lies just below Q_peak/πa² = 19.27 MPa at 1.77 GPa (NOTES: checked independently against
    the paper's equations)."""
    silica = ContactParameters(
        radius_um=5.0, contact_modulus_gpa=69.64, shear_modulus_gpa=63.40, **LAWS
    )
    graphite = silica.replace(contact_modulus_gpa=24.5, shear_modulus_gpa=10.0, radius_um=2.0)
    docs = [
        compare_collapse("x", p, PAPER_EXPERIMENT_P0_GPA, PAPER_EXPERIMENT_COLLAPSE_MPA, {})
        for p in (silica, graphite)
    ]
    a = [d["run"]["contact_radius_nm"] for d in docs]
    assert a[0] == pytest.approx(math.pi * 5e3 * 1.77 / (2 * 69.64))  # a = πRp0/(2E*), nm
    assert a[1] < 0.5 * a[0] * 69.64 / 24.5
    s = [d["run"]["collapse_stress_mpa"] for d in docs]
    assert s[0] == pytest.approx(s[1], rel=1e-9)
    assert s[0] == pytest.approx(_collapse_from_curve(1.77, silica), rel=2e-3)
    # Q_peak/πa² with the paper's laws is 19.27 MPa; k reaches 0.2 k0 just below it (< 1.5 %)
    peak = docs[0]["run"]["effective_shear_strength_mpa"]
    assert peak == pytest.approx(19.27, abs=0.01)
    assert 0.985 * peak < s[0] < peak
    ratio = docs[0]["run"]["ratio_to_measured"]
    assert ratio["graphene-passivated SiOx"] == pytest.approx(s[0] / 26.7)
    assert ratio["bare SiOx"] == pytest.approx(s[0] / 145.0)


def test_reference_rows_carry_their_own_laws():
    """A reference law set replaces the run's laws and nothing else: with τ0 doubled (k, μ, σ0
    fixed) its collapse rises; with the run's own laws it equals the run's row."""
    run = ContactParameters(radius_um=5.0, contact_modulus_gpa=70.0, shear_modulus_gpa=60.0, **LAWS)
    refs = {"same": LAWS, "double tau0": {**LAWS, "tau0_mpa": 2 * LAWS["tau0_mpa"]}}
    doc = compare_collapse("run", run, 1.77, PAPER_EXPERIMENT_COLLAPSE_MPA, refs)
    same, double = doc["references"]
    assert same["collapse_stress_mpa"] == pytest.approx(doc["run"]["collapse_stress_mpa"])
    assert double["tau0_mpa"] == 2 * LAWS["tau0_mpa"]
    assert double["collapse_stress_mpa"] > 1.5 * same["collapse_stress_mpa"]


def test_an_adhesive_run_row_is_its_contact_at_p1_and_the_references_stay_at_p0():
    """With adhesion the contact stage evaluates the model at p1 (the Hertzian part over the
    adhesive radius) and stores that curve in contact.nc; the run's row is that contact's:
    the row at p1, its radius the closed-form Hertz radius at p1 (the slow example test reads
    the collapse off contact.nc). The references keep the adhesion-free p0 (the same as
    without contact_p0_gpa)."""
    run = ContactParameters(radius_um=5.0, contact_modulus_gpa=70.0, shear_modulus_gpa=60.0, **LAWS)
    p0, p1 = 1.77, 1.98
    plain = compare_collapse("run", run, p0, PAPER_EXPERIMENT_COLLAPSE_MPA, {"q": LAWS})
    doc = compare_collapse(
        "run", run, p0, PAPER_EXPERIMENT_COLLAPSE_MPA, {"q": LAWS}, contact_p0_gpa=p1
    )
    assert doc["p0_gpa"] == p0 and doc["contact_p0_gpa"] == p1 and plain["contact_p0_gpa"] == p0
    assert doc["references"] == plain["references"]
    at_p1 = compare_collapse("run", run, p1, PAPER_EXPERIMENT_COLLAPSE_MPA, {})["run"]
    assert doc["run"] == at_p1
    assert doc["run"]["collapse_stress_mpa"] > 1.01 * plain["run"]["collapse_stress_mpa"]
    a_m = 2.0 * p1 * 1e9 * 5e-6 / (4.0 * 70e9 / math.pi)  # Hertz: p1 = 2 E* a / (π R)
    assert doc["run"]["contact_radius_nm"] == pytest.approx(a_m * 1e9, rel=1e-9)


def test_the_report_section_states_the_lock_and_every_row():
    """The section reads build.json's coincidence match (strain per slab) and tables the run,
    each reference and each measurement, with the ratios from the document."""
    from flatcontact.report.sections.experiment import experiment_section, lock_text

    build = {
        "recipe": {
            "match": {
                "kind": "coincidence",
                "slab1_supercell": [[1, 0], [0, 1]],
                "slab2_supercell": [[1, 0], [0, 1]],
                "n_atoms": 15,
                "slab1_strain_percent": [0.0, 0.0],
                "slab2_strain_percent": [2.53, 2.53],
            }
        }
    }
    assert "slab 2 +2.53, +2.53 %" in lock_text(build)
    assert "slab 1" not in lock_text(build).split("strain")[1]
    assert lock_text({}) == "no coincidence lock (one material)"
    run = ContactParameters(radius_um=5.0, contact_modulus_gpa=70.0, shear_modulus_gpa=60.0, **LAWS)
    doc = compare_collapse("tip", run, 1.77, PAPER_EXPERIMENT_COLLAPSE_MPA, {"q": LAWS})
    section = experiment_section({"experiment_comparison": doc}, build)
    (table,) = section.tables
    labels = [r[0] for r in table.rows]
    assert labels == [
        "tip (this run)",
        "q",
        "measured: graphene-passivated SiOx",
        "measured: bare SiOx",
    ]
    assert table.rows[0][4] == f"{doc['run']['collapse_stress_mpa'] / 26.7:.3g}"
    assert "+2.53" in section.paragraphs[0]
    assert experiment_section({}, build) is None
