"""The contact stage's range: the adhesion regime (Tabor parameter, DMT/JKR/Maugis–Dugdale
radius in the modified Mindlin model) and where concurrent slip stops (critical radius of
dislocation-assisted slip, elastic bound of superlubricity). Closed forms written out here,
independently of the code."""

from __future__ import annotations

import math

import numpy as np
import pytest

from flatcontact.config.load import build_config
from flatcontact.contact import adhesion, slip_size
from flatcontact.contact.adhesion_regime import (
    LAMBDA_PER_TABOR,
    adhesion_regime,
    tabor_parameter,
)
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation.errors import InputError
from flatcontact.stages.contact import ContactInputs, contact_stage

#: Cu(111)/Cu(111) with the Mishin EAM (examples/README.md: laws, W, elastic stage's moduli).
CU = dict(
    radius_um=5.0,
    contact_modulus_gpa=73.0,
    shear_modulus_gpa=57.7,
    k_mpa_per_gpa=-5.3,
    tau0_mpa=3786.4,
    mu_mpa_per_gpa=-1.18,
    sigma0_mpa=1100.3,
    work_of_adhesion_j_per_m2=2.479,
)
CU_GAP_ANGSTROM = 3.615 / math.sqrt(3.0)  # (111) plane spacing of fcc Cu
MEV_A2 = 0.01602176634  # J/m² per meV/Å² (e = 1.602176634e-19 C)


def _cu_facts(recipe=None):
    return {
        "gap_angstrom": CU_GAP_ANGSTROM,
        "recipe": recipe if recipe is not None else {"match": {"kind": "identity"}},
        "path": {
            "p_gpa": 0.0,
            "unstable_stacking_j_per_m2": 10.16 * MEV_A2,
            "burgers_angstrom": 2.556,
            "tau_max_mpa": 3786.0,
        },
    }


# --------------------------------------------------------------------------- Part A


def test_tabor_parameter_is_the_closed_form():
    r, w, e, z0 = 5e-6, 2.479, 73e9, 2.087e-10
    assert tabor_parameter(w, r, e, z0) == pytest.approx((r * w * w / (e * e * z0**3)) ** (1 / 3))
    # Johnson & Greenwood: λ = 2σ0 (R/(πwK²))^(1/3), σ0 = 1.03 w/z0, K = 4E*/3
    lam = 2 * 1.03 * w / z0 * (r / (math.pi * w * (4 * e / 3) ** 2)) ** (1 / 3)
    assert LAMBDA_PER_TABOR * tabor_parameter(w, r, e, z0) == pytest.approx(lam, rel=1e-12)
    assert LAMBDA_PER_TABOR == pytest.approx(1.16, abs=0.005)


@pytest.mark.parametrize("p_un", [0.0, 3.0, 80.0])
def test_dmt_and_jkr_radii_against_johnsons_closed_forms(p_un):
    r, w, e = 5e-6, 0.3, 60e9
    p = p_un * 1e-6
    k = 4 * e / 3
    a_dmt = ((p + 2 * math.pi * w * r) * r / k) ** (1 / 3)
    a_jkr = (
        r
        / k
        * (
            p
            + 3 * math.pi * w * r
            + math.sqrt(6 * math.pi * w * r * p + (3 * math.pi * w * r) ** 2)
        )
    ) ** (1 / 3)
    assert adhesion.dmt_contact_radius(p, w, r, e) == pytest.approx(a_dmt, rel=1e-12)
    assert adhesion.jkr_contact_radius(p, w, r, e) == pytest.approx(a_jkr, rel=1e-12)


def test_maugis_dugdale_tends_to_dmt_and_jkr():
    r, w, e, p = 5e-6, 0.3, 60e9, 5e-6
    a_dmt = adhesion.dmt_contact_radius(p, w, r, e)
    a_jkr = adhesion.jkr_contact_radius(p, w, r, e)
    assert adhesion.maugis_dugdale_contact_radius(p, w, r, e, 0.01) == pytest.approx(
        a_dmt, rel=0.02
    )
    assert adhesion.maugis_dugdale_contact_radius(p, w, r, e, 30.0) == pytest.approx(
        a_jkr, rel=0.02
    )


def test_the_dmt_contact_is_the_hertz_contact_at_load_plus_pull_off():
    """Inside a DMT contact the pressure is Hertzian at P + 2πwR: the model's peak pressure
    is p1 = 2E*a/(πR), and the law bound is 0 (the tension acts outside)."""
    prm = ContactParameters(work_of_adhesion_j_per_m2=0.2)
    reg = adhesion_regime([0.5], prm, maugis_lambda=0.05)
    c = reg.contacts[0]
    assert c.model == "dmt"
    r, e, w = prm.radius_m, prm.contact_modulus_pa, 0.2
    a_h = math.pi * r * 0.5e9 / (2 * e)
    load = 2 / 3 * math.pi * a_h**2 * 0.5e9
    a = (3 * r * (load + 2 * math.pi * w * r) / (4 * e)) ** (1 / 3)
    assert c.radius_m == pytest.approx(a, rel=1e-12)
    assert c.contact_p0_pa == pytest.approx(2 * e * a / (math.pi * r), rel=1e-12)
    assert c.pull_off_per_load == pytest.approx(2 * math.pi * w * r / load, rel=1e-12)
    assert c.law_bound == 0.0


def test_a_strongly_adhesive_cu_contact_is_named_jkr_and_uses_the_adhesive_radius():
    cfg = build_config({"contact": {**CU, "p0_gpa": [0.5, 1.0]}})
    doc = contact_stage(cfg, ContactInputs(interface=_cu_facts()), None).to_json()
    reg = doc["adhesion_regime"]
    # μ_T by hand with z0 = the (111) spacing: ≈ 8.6 -> λ ≈ 10 > 5: JKR
    mu = (5e-6 * 2.479**2 / (73e9**2 * (CU_GAP_ANGSTROM * 1e-10) ** 3)) ** (1 / 3)
    assert reg["tabor_parameter"] == pytest.approx(mu, rel=1e-9)
    assert reg["sentence"].startswith("adhesion regime JKR")
    row = reg["results"][0]
    assert row["regime"] == "JKR"
    assert row["pull_off_over_load"] > 10  # the pull-off dwarfs the load at 0.5 GPa
    assert 3.0 < row["radius_over_hertz"] < 6.0
    res = doc["results"][0]
    assert res["contact_radius_nm"] == pytest.approx(row["contact_radius_nm"], rel=1e-9)
    # Q_peak/πa² over the adhesive area: ≈ τ0-dominated (|k| tiny), and the load unchanged
    area = math.pi * (res["contact_radius_nm"] * 1e-9) ** 2
    assert res["effective_shear_strength_mpa"] == pytest.approx(
        res["peak_lateral_force_un"] * 1e-6 / area * 1e-6, rel=1e-9
    )
    assert res["normal_load_un"] == pytest.approx(row["normal_load_un"], rel=1e-12)


def test_where_no_model_applies_the_stage_refuses_in_one_line():
    """A JKR contact whose laws depend strongly on pressure: the adhesive tension inside the
    contact changes the laws' forces by more than the bound; refused naming contact.p0_gpa."""
    prm = dict(CU, k_mpa_per_gpa=800.0, tau0_mpa=50.0, mu_mpa_per_gpa=300.0, sigma0_mpa=10.0)
    cfg = build_config({"contact": {**prm, "p0_gpa": [0.5]}})
    with pytest.raises(InputError, match=r"contact.p0_gpa = 0.5 GPa: no contact model") as exc:
        contact_stage(cfg, ContactInputs(interface=_cu_facts()), None)
    assert "\n" not in str(exc.value)
    cfg = build_config({"contact": {**prm, "p0_gpa": [0.5], "contact_radius": "hertz"}})
    doc = contact_stage(cfg, ContactInputs(interface=_cu_facts()), None).to_json()
    assert doc["results"][0]["contact_radius_nm"] == pytest.approx(
        math.pi * 5e-6 * 0.5e9 / (2 * 73e9) * 1e9, rel=1e-12
    )


def test_a_paper_like_quartz_contact_keeps_its_hertz_numbers_within_the_adhesion_change():
    """Quartz with the paper's laws and moduli, w = 0 (the paper's contact): unchanged, to
    the digit; with the run's w the DMT-like change is small above 1 GPa."""
    q = {
        "p0_gpa": [0.5, 1.0, 1.77],
        "k_mpa_per_gpa": 4.52,
        "tau0_mpa": 26.7,
        "mu_mpa_per_gpa": 0.21,
        "sigma0_mpa": 11.1,
    }
    hertz = contact_stage(
        build_config({"contact": {**q, "work_of_adhesion_j_per_m2": 0.0}}), ContactInputs(), None
    ).to_json()
    assert hertz["results"][1]["contact_radius_nm"] == pytest.approx(149.6, abs=0.05)  # NOTES
    assert hertz["adhesion_regime"]["sentence"].startswith("adhesion: none")
    run = contact_stage(
        build_config({"contact": {**q, "work_of_adhesion_j_per_m2": 0.062}}), ContactInputs(), None
    ).to_json()
    for h, r in zip(hertz["results"], run["results"], strict=True):
        change = r["effective_shear_strength_mpa"] / h["effective_shear_strength_mpa"] - 1
        assert 0 <= change < (0.05 if h["p0_gpa"] < 1 else 0.01)


def test_the_paper_moduli_with_another_material_are_reported():
    cfg = build_config(
        {"contact": {**CU, "contact_modulus_gpa": 52.5, "shear_modulus_gpa": 29.0, "p0_gpa": [1.0]}}
    )
    from flatcontact.stages.contact_range import foreign_moduli_note

    prm = ContactParameters(**{**CU, "contact_modulus_gpa": 52.5, "shear_modulus_gpa": 29.0})
    cu = cfg.model_copy(update={"structure": cfg.structure.model_copy(update={"kind": "file"})})
    note = foreign_moduli_note(cu, {"moduli": "config"}, prm)
    assert note is not None and "another material or potential" in note
    assert foreign_moduli_note(cfg, {"moduli": "config"}, prm) is None  # quartz-dense + SNAP


# --------------------------------------------------------------------------- Part B


def test_critical_radius_and_dislocation_strength_by_hand():
    """Energy-release form of the Hurtado–Kim estimate, written out: U = Q²/(4G*a) for the
    stuck contact (stiffness 2G*a), G = (dU/da)/(2πa) = γ_us at nucleation."""
    g, gus, tau_c = 57.7e9, 0.1628, 2.2e9
    a = np.geomspace(1e-9, 1e-6, 7)
    q = np.sqrt(gus * 2 * np.pi * a * 4 * g * a**2)  # dU/da = Q²/(4 G* a²) = 2πa γ_us
    assert slip_size.dislocation_strength(a, g, gus) == pytest.approx(q / (np.pi * a**2), rel=1e-12)
    ac = slip_size.critical_radius(tau_c, g, gus)
    assert ac == pytest.approx(8 * g * gus / (math.pi * tau_c**2), rel=1e-12)
    assert slip_size.dislocation_strength(ac, g, gus) == pytest.approx(tau_c, rel=1e-12)
    # the sinusoidal γ-surface: γ_us = τ_max b/π -> a_c = 8 G* b/(π² τ_max) for τ_c = τ_max
    b = 2.556e-10
    assert slip_size.critical_radius(tau_c, g, tau_c * b / math.pi) == pytest.approx(
        8 * g * b / (math.pi**2 * tau_c), rel=1e-12
    )


def test_regime_choice_from_the_structure_record():
    kind = slip_size.structure_regime
    assert kind({"match": {"kind": "identity"}})[0] == "commensurate"
    assert kind(None)[0] == "commensurate"
    assert kind({"twist_angle_deg": 21.787, "match": {"kind": "twist"}})[0] == "twisted"
    lock = {
        "kind": "coincidence",
        "slab1_supercell": [[1, 0], [0, 1]],
        "slab2_supercell": [[1, 0], [0, 1]],
        "slab1_rotation_deg": 0.0,
        "slab2_rotation_deg": 0.0,
    }
    assert kind({"match": lock})[0] == "commensurate"
    approx = {**lock, "slab2_supercell": [[7, 2], [-2, 5]], "slab2_rotation_deg": 10.893}
    assert kind({"match": approx})[0] == "approximant"


@pytest.mark.parametrize("radius_um, exceeded", [(0.001, False), (5.0, True)])
def test_the_box_appears_exactly_when_a_exceeds_the_critical_size(radius_um, exceeded):
    from flatcontact.report.sections.contact import range_boxes

    cfg = build_config(
        {
            "contact": {
                **CU,
                "radius_um": radius_um,
                "p0_gpa": [1.0],
                "work_of_adhesion_j_per_m2": 0.0,
            }
        }
    )
    doc = contact_stage(cfg, ContactInputs(interface=_cu_facts()), None).to_json()
    row = doc["slip_size"]["results"][0]
    assert row["exceeded"] is exceeded
    assert (row["contact_radius_nm"] > row["critical_radius_nm"]) is exceeded
    boxes = [b for b in range_boxes(doc) if "critical radius" in b]
    assert len(boxes) == int(exceeded)
    # wherever the report prints the concurrent number, it says so past a_c
    from flatcontact.report.sections.contact import slip_note

    assert bool(slip_note(doc, 0)) is exceeded
    if exceeded:
        assert f"{row['critical_radius_nm']:.3g} nm" in boxes[0]
        assert row["reported"] == "size-limited"
        assert row["size_limited_strength_mpa"] < row["concurrent_strength_mpa"]
    else:
        assert row["reported"] == "concurrent"


def test_slip_regime_concurrent_keeps_the_mindlin_number_but_still_says_so():
    cfg = build_config({"contact": {**CU, "p0_gpa": [1.0], "slip_regime": "concurrent"}})
    doc = contact_stage(cfg, ContactInputs(interface=_cu_facts()), None).to_json()
    row = doc["slip_size"]["results"][0]
    assert row["exceeded"] and row["reported"] == "concurrent"
    assert row["reported_strength_mpa"] == row["concurrent_strength_mpa"]
    from flatcontact.contact.slip_size import slip_sentences

    assert len(slip_sentences(doc["slip_size"])) == 1


def test_an_approximant_cell_gets_the_elastic_bound():
    twisted = {"twist_angle_deg": 21.787}
    facts = _cu_facts(twisted)
    cfg = build_config(
        {
            "contact": {
                **CU,
                "tau0_mpa": 0.02,
                "k_mpa_per_gpa": 0.0076,
                "mu_mpa_per_gpa": 0.0034,
                "sigma0_mpa": 0.0063,
                "p0_gpa": [1.0],
                "work_of_adhesion_j_per_m2": 0.0,
            }
        }
    )
    doc = contact_stage(cfg, ContactInputs(interface=facts), None).to_json()
    s = doc["slip_size"]
    assert s["structure"] == "twisted"
    row = s["results"][0]
    tau = row["concurrent_strength_mpa"] * 1e6
    assert row["critical_radius_nm"] == pytest.approx(57.7e9 * 2.556e-10 / (math.pi * tau) * 1e9)
    assert row["size_limited_strength_mpa"] is None


def _cli(argv, capsys):
    from flatcontact.cli import main

    with pytest.raises(SystemExit) as exc:
        main([*argv])
    out = capsys.readouterr()
    return exc.value.code, out.out, out.err


def test_the_cli_reports_the_critical_size_and_draws_both_regimes(tmp_path, capsys):
    """The paper's quartz laws and moduli (R = 20 µm) with a given γ_us: a_c by hand, the box sentence on
    the console exactly for the p0 past it, and fig_slip_size written."""
    gus = 3.9e-3  # J/m²: the quick quartz run's barrier, 0.244 meV/Å²
    code, out, err = _cli(
        [
            "contact",
            "--p0-gpa",
            "0.5,3",
            "--radius-um",
            "20",
            "--unstable-stacking-mj-per-m2",
            "3.9",
            "--out",
            str(tmp_path / "c"),
            "--no-svg",
        ],
        capsys,
    )
    assert code in (0, None), err
    assert (tmp_path / "c" / "fig_slip_size.png").is_file()
    import json

    doc = json.loads((tmp_path / "c" / "summary.json").read_text())
    for row in doc["slip_size"]["results"]:
        ac = 8 * 29e9 * gus / (math.pi * (row["concurrent_strength_mpa"] * 1e6) ** 2)
        assert row["critical_radius_nm"] == pytest.approx(ac * 1e9, rel=1e-9)
    exceeded = [r["p0_gpa"] for r in doc["slip_size"]["results"] if r["exceeded"]]
    assert exceeded == [3.0]  # a = 1.8 µm > a_c ≈ 0.65 µm; at 0.5 GPa a = 0.3 µm < 0.94 µm
    text = " ".join(out.split())
    assert text.count("exceeds the critical radius") == len(exceeded)


def test_the_cli_refuses_an_unknown_structure_in_one_line(capsys):
    code, _, err = _cli(["contact", "--burgers-angstrom", "2.5", "--structure", "moire"], capsys)
    assert code == 2
    assert "--structure" in err and len(err.strip().splitlines()) == 1


def test_the_run_facts_from_a_constructed_path_and_interface():
    """γ_us, b and τ_max of a sinusoidal path E = (γ/2)(1 − cos 2πt/b) along 30°, and the
    gap between two slabs; the MEP barrier wins where friction.nc has one."""
    import xarray as xr
    from ase import Atoms

    from flatcontact.stages.contact_range import interface_gap_angstrom, path_facts

    b, gamma = 2.5, 3.0  # Å, meV/Å²
    t = np.linspace(0.0, b, 61)
    e = gamma / 2 * (1 - np.cos(2 * np.pi * t / b))
    f = gamma / 2 * 2 * np.pi / b * np.sin(2 * np.pi * t / b) * 160.21766  # meV/Å³ -> MPa
    d = np.radians(30.0)
    ds = xr.Dataset(
        {
            "path_energy": (("p_gpa", "sample"), np.vstack([e, 2 * e])),
            "path_x": (("p_gpa", "sample"), np.vstack([t * np.cos(d)] * 2)),
            "path_y": (("p_gpa", "sample"), np.vstack([t * np.sin(d)] * 2)),
            "path_force": (("p_gpa", "sample"), np.vstack([f, 2 * f])),
        },
        coords={"p_gpa": [1.0, 0.0]},
    )
    got = path_facts(ds)
    assert got["p_gpa"] == 0.0  # the lowest load: the contact's edge
    assert got["unstable_stacking_j_per_m2"] == pytest.approx(2 * gamma * MEV_A2, rel=1e-9)
    assert got["burgers_angstrom"] == pytest.approx(b, rel=1e-12)
    # sinusoid: τ_max = π γ/b, so the shape factor π γ_us/(τ_max b) is 1
    shape = math.pi * got["unstable_stacking_j_per_m2"] / (got["tau_max_mpa"] * 1e6 * b * 1e-10)
    assert shape == pytest.approx(1.0, rel=1e-3)
    ds["barrier_along_direction_mev_per_a2"] = ("p_gpa", [9.0, 1.5])
    assert path_facts(ds)["unstable_stacking_j_per_m2"] == pytest.approx(1.5 * MEV_A2, rel=1e-12)
    atoms = Atoms("H4", positions=[(0, 0, 0), (0, 0, 2.0), (0, 0, 5.1), (0, 0, 7.0)])
    atoms.arrays["slab"] = np.array([1, 1, 2, 2])
    assert interface_gap_angstrom(atoms) == pytest.approx(3.1)


def test_the_maugis_dugdale_tension_moves_inside_the_contact_from_dmt_to_jkr():
    """The cohesive zone's σ_D π (c² − a²) is the whole adhesive tension P1 − P as λ -> 0
    (DMT: adhesion outside the contact) and none of it as λ -> ∞ (JKR: inside)."""
    from flatcontact.contact.adhesion_regime import adhesive_contact, dugdale_zone_force

    prm = ContactParameters(work_of_adhesion_j_per_m2=0.3, k_mpa_per_gpa=10.0)
    fractions = []
    for lam in (0.1, 0.3, 1.0, 3.0, 4.9):  # the Maugis–Dugdale range of the regime map
        c = adhesive_contact(0.5e9, prm, lam)
        out = dugdale_zone_force(c.radius_m, 0.3, prm.radius_m, prm.contact_modulus_pa, lam)
        assert 0.0 <= out <= c.adhesive_tension_n * (1 + 1e-9)
        fractions.append(c.tension_inside_n / c.adhesive_tension_n)
    assert fractions[0] < 0.2 and fractions[-1] > 0.8
    assert fractions == sorted(fractions)
    # the regime's ends: DMT puts none inside, JKR all
    assert adhesive_contact(0.5e9, prm, 0.05).tension_inside_n == 0.0
    jkr = adhesive_contact(0.5e9, prm, 6.0)
    assert jkr.tension_inside_n == jkr.adhesive_tension_n > 0.0
