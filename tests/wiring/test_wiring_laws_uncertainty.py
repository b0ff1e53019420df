"""Issue 12 wiring: both energy forms in the laws stage, the laws' uncertainty carried to the
contact outputs, and ``validate-potential --ispes``.

The cobblestone landscape (tests/studies/test_energy_forms.py) has exact laws in each
form: internal k = 0, enthalpy k = 4π|δ|/a (δ the gap modulation), the same τ0.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.analysis import synthetic as syn
from flatcontact.config import MEASURED_LAW_UNCERTAINTY, build_config
from flatcontact.contact import mindlin
from flatcontact.foundation import units
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.layout import FRICTION_CSV, LAWS_JSON, OTHER_FORM_JSON
from flatcontact.stages.analyze import AnalyzeInputs, analyze_stage
from flatcontact.stages.contact import ContactInputs, contact_stage
from flatcontact.stages.laws import LawsInputs, laws_stage

A = 4.916
A1, A2 = syn.hexagonal_cell(A)
P_GPA = [0.0, 0.5, 1.0, 2.0]
V, DELTA = -2e-4, -0.02
LAW_KEYS = ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa")
STDERR = {
    "k_mpa_per_gpa": "k_stderr_mpa_per_gpa",
    "tau0_mpa": "tau0_stderr_mpa",
    "mu_mpa_per_gpa": "mu_stderr_mpa_per_gpa",
    "sigma0_mpa": "sigma0_stderr_mpa",
}
UNC = {
    "convergence_internal": {"tau0_mpa": 3.0, "k_mpa_per_gpa": 1.0},
    "model_spread_internal": {"tau0_mpa": 4.0},
    "convergence_enthalpy": {"k_mpa_per_gpa": 2.0},
    "coverage": 2.0,
    "source": "test numbers",
}
pytestmark = pytest.mark.filterwarnings("ignore::flatcontact.analysis.diagnostics.AnalysisWarning")


@pytest.fixture(scope="module")
def stages(tmp_path_factory):
    """analyze -> laws (both forms) on the cobblestone ISPES, as the run chains them."""
    root = tmp_path_factory.mktemp("forms")
    z = np.linspace(24.3, 26.4, 36)
    grid = syn.SyntheticInterface(
        A1, A2, syn.three_cosine(A1, A2), corrugation_ev_per_a2=V, gap_modulation_angstrom=DELTA
    ).grid(9, 9, z)
    ispes = root / "ispes.nc"
    grid.to_netcdf(ispes, engine="h5netcdf")
    cfg = build_config(
        {
            "analysis": {"p_gpa": P_GPA, "direction_deg": 0.0},
            "uncertainty": UNC,
            "report": {"svg": False},
        }
    )
    analyze_stage(cfg, AnalyzeInputs(ispes), root / "analyze")
    inputs = LawsInputs.read(root / "analyze" / FRICTION_CSV, root / "analyze" / OTHER_FORM_JSON)
    laws_stage(cfg, inputs, root / "laws")
    laws = json.loads((root / "laws" / LAWS_JSON).read_text())
    return cfg, laws, root


ROOT = Path(__file__).resolve().parents[2]


def test_laws_json_has_both_forms_with_their_exact_slopes(stages):
    _, laws, root = stages
    tau0 = 4 * np.pi * -V / A * units.EV_PER_A3_TO_MPA
    k_enthalpy = 4 * np.pi * -DELTA / A * 1e3  # MPa/GPa
    tol = 5e-3 * tau0
    assert laws["energy_form"] == "internal"
    assert laws["internal"]["k_mpa_per_gpa"] == pytest.approx(0.0, abs=tol)
    assert laws["enthalpy"]["k_mpa_per_gpa"] == pytest.approx(k_enthalpy, abs=tol)
    assert laws["internal"]["tau0_mpa"] == pytest.approx(laws["enthalpy"]["tau0_mpa"], rel=5e-3)
    # the top level (what the contact stage reads) is the configured form's block
    for key in LAW_KEYS:
        assert laws[key] == laws["internal"][key]
    assert laws["intervals"] == laws["internal"]["intervals"]
    # per-load values of both forms, at the analysed loads
    for form in ("internal", "enthalpy"):
        assert [r["p_gpa"] for r in laws[form]["loads"]] == P_GPA
    assert (root / "laws" / "fig3_laws.png").is_file()


def test_the_laws_stage_fits_the_analyze_stages_other_form_and_analyses_nothing(
    stages, monkeypatch
):
    """The other form's block of laws.json is what analysing the ISPES in that form gives
    (laws_both_forms on the grid, computed here), and the laws stage gets it from the analyze
    stage's other_form.json: with the analysis disabled it writes the same laws.json."""
    import flatcontact.analysis.analyze as analyze_module
    import flatcontact.analysis.energy_forms as energy_forms
    from flatcontact.analysis.energy_forms import laws_both_forms
    from flatcontact.analysis.options import AnalysisOptions
    from flatcontact.ispes.contract import open_ispes

    cfg, laws, root = stages
    direct = laws_both_forms(
        open_ispes(root / "ispes.nc"), P_GPA, AnalysisOptions(direction_deg=0.0)
    )
    want = direct["forms"]["enthalpy"]
    assert json.dumps(laws["enthalpy"]["loads"]) == json.dumps(want["loads"])
    assert laws["enthalpy"]["warnings"] == want["warnings"]
    for key in (*LAW_KEYS, *STDERR.values()):
        assert laws["enthalpy"][key] == want["laws"][key]

    def refused(*args, **kwargs):
        raise AssertionError("the laws stage analysed the ISPES")

    monkeypatch.setattr(analyze_module, "analyze_ispes", refused)
    monkeypatch.setattr(energy_forms, "analyze_ispes", refused)
    analyze = root / "analyze"
    again = laws_stage(
        cfg, LawsInputs.read(analyze / FRICTION_CSV, analyze / OTHER_FORM_JSON), None
    )
    assert json.dumps(again.to_json()) == json.dumps(laws)


def test_an_other_form_file_of_the_wrong_form_is_refused(stages, tmp_path):
    cfg, _, root = stages
    stored = json.loads((root / "analyze" / OTHER_FORM_JSON).read_text())
    assert stored["form"] == "enthalpy"
    wrong = tmp_path / OTHER_FORM_JSON
    wrong.write_text(json.dumps(stored | {"form": "internal"}))
    with pytest.raises(InputError, match=r"other_form\.json: holds the 'internal' energy form"):
        laws_stage(cfg, LawsInputs.read(root / "analyze" / FRICTION_CSV, wrong), None)


def test_half_widths_combine_fit_convergence_and_model_spread(stages):
    _, laws, _ = stages
    for form in ("internal", "enthalpy"):
        block = laws[form]
        for key in LAW_KEYS:
            se = block[STDERR[key]] or 0.0
            conv = UNC.get(f"convergence_{form}", {}).get(key, 0.0)
            model = UNC.get(f"model_spread_{form}", {}).get(key, 0.0)
            # the run's own grid estimate: the three-cosine landscape lives on the 3×3 sub-grid
            # of the 9×9 one, so only the columns' spline error (not band-limited) is left
            grid = block["intervals"][key]["components"]["grid"]
            assert grid is not None and 0 <= grid <= 1e-3 * abs(block["tau0_mpa"])
            assert laws["uncertainty"]["grid"][form][key] == grid
            want = UNC["coverage"] * math.sqrt(se**2 + conv**2 + model**2 + grid**2)
            assert block["half_widths"][key] == pytest.approx(want, rel=1e-12)
            iv = block["intervals"][key]
            # the interval contains the central value, symmetric by the half-width
            assert iv["low"] <= iv["value"] == block[key] <= iv["high"]
            assert iv["high"] - iv["value"] == pytest.approx(want, rel=1e-12)
    assert laws["uncertainty"]["source"] == "test numbers"


def test_contact_intervals_contain_the_central_values_and_match_the_tau0_edges(stages):
    _, laws, _ = stages
    # the contact model takes the fitted τ0 (and its interval); k, μ, σ0 from the settings
    doc = laws | {"tau0_mpa": 26.7}
    doc["internal"] = laws["internal"] | {"tau0_mpa": 26.7}
    contact_cfg = build_config(
        {
            "contact": {
                "p0_gpa": [1.0, 2.0],
                "k_mpa_per_gpa": 4.52,
                "mu_mpa_per_gpa": 0.21,
                "sigma0_mpa": 11.1,
            },
            "report": {"svg": False},
        }
    )
    res = contact_stage(contact_cfg, ContactInputs(laws=doc), None)
    iv = res.to_json()["intervals"]
    h = laws["internal"]["half_widths"]["tau0_mpa"]
    assert iv["half_widths"] == {
        "k_mpa_per_gpa": 0.0,
        "tau0_mpa": h,
        "mu_mpa_per_gpa": 0.0,
        "sigma0_mpa": 0.0,
    }
    for r in iv["results"]:
        for key in (
            "effective_shear_strength_mpa",
            "collapse_stress_mpa",
            "knee_stress_amplitude_mpa",
        ):
            assert r[key]["low"] < r[key]["value"] < r[key]["high"]
        # Q_peak/πa² grows with τ0: its edges are the values at τ0 ∓ h, computed here directly
        p0 = r["p0_gpa"] * units.GPA_TO_PA
        for edge, sign in (("low", -1), ("high", 1)):
            prm = res.params.replace(tau0_mpa=max(26.7 + sign * h, 0.0))
            a = float(mindlin.contact_radius(p0, prm))
            want = float(mindlin.peak_force(p0, prm).force_n) / (np.pi * a**2) / 1e6
            assert r["effective_shear_strength_mpa"][edge] == pytest.approx(want, rel=1e-9)
    central = {r["p0_gpa"]: r for r in res.to_json()["results"]}
    for r in iv["results"]:
        assert r["effective_shear_strength_mpa"]["value"] == pytest.approx(
            central[r["p0_gpa"]]["effective_shear_strength_mpa"], rel=1e-12
        )


def test_contact_intervals_of_each_part_alone_and_the_report_shows_them(stages):
    """Q_peak/πa² grows with τ0: over the box of one part alone (coverage × fit s.e., × δ_conv
    or × δ_model of τ0) its edges are the values at τ0 ∓ that half-width, computed here; the
    laws table and the contact table of the report show the parts beside the intervals."""
    from flatcontact.report.sections.contact import interval_tables
    from flatcontact.report.sections.laws import laws_tables

    _, laws, _ = stages
    doc = laws | {"tau0_mpa": 26.7}
    doc["internal"] = laws["internal"] | {"tau0_mpa": 26.7}
    cfg = build_config(
        {
            "contact": {
                "p0_gpa": [1.0],
                "k_mpa_per_gpa": 4.52,
                "mu_mpa_per_gpa": 0.21,
                "sigma0_mpa": 11.1,
            },
            "report": {"svg": False},
        }
    )
    res = contact_stage(cfg, ContactInputs(laws=doc), None)
    iv = res.to_json()["intervals"]
    parts = laws["internal"]["intervals"]["tau0_mpa"]["components"]
    assert parts == pytest.approx(
        {
            "fit": laws["internal"]["tau0_stderr_mpa"],
            "convergence": 3.0,
            "models": 4.0,
            "grid": laws["uncertainty"]["grid"]["internal"]["tau0_mpa"],
        }
    )
    # k, μ, σ0 are set in contact: no part of theirs is carried
    for part, hw in iv["component_half_widths"].items():
        assert hw == pytest.approx(
            {
                "k_mpa_per_gpa": 0.0,
                "tau0_mpa": UNC["coverage"] * parts[part],
                "mu_mpa_per_gpa": 0.0,
                "sigma0_mpa": 0.0,
            }
        )
    (r,) = iv["results"]
    p0 = r["p0_gpa"] * units.GPA_TO_PA
    for part, (lo, hi) in r["effective_shear_strength_mpa"]["components"].items():
        h = UNC["coverage"] * parts[part]
        for got, sign in ((lo, -1), (hi, 1)):
            prm = res.params.replace(tau0_mpa=max(26.7 + sign * h, 0.0))
            a = float(mindlin.contact_radius(p0, prm))
            want = float(mindlin.peak_force(p0, prm).force_n) / (np.pi * a**2) / 1e6
            assert got == pytest.approx(want, rel=1e-9)
    # the report: a fit / convergence / models / grid column per form, the parts in the
    # contact cells
    (table,) = laws_tables(laws)
    head = "internal: fit / convergence / models / grid"
    assert head in table.headers
    row = dict(
        zip(table.headers, next(r for r in table.rows if r[0].startswith("τ0")), strict=True)
    )
    fit = laws["internal"]["tau0_stderr_mpa"]
    assert row[head] == f"{fit:.3g} / 3 / 4 / {parts['grid']:.3g}"
    (ct,) = interval_tables(res.to_json())
    cell = ct.rows[0][1]
    lo, hi = r["effective_shear_strength_mpa"]["components"]["models"]
    assert f"models ±{(hi - lo) / 2:.2g}" in cell and "conv. ±" in cell and "fit ±" in cell


def test_zero_input_error_gives_zero_width(capsys):
    # the CLI gives every law coefficient as a number: no fit, convergence or model error
    code, out, err = run_cli(["contact", "--p0-gpa", "1,1.77", "--json"], capsys)
    assert code in (0, None), err
    iv = json.loads(out)["intervals"]
    assert not any(iv["half_widths"].values())
    for r in iv["results"]:
        for q in r.values():
            if isinstance(q, dict):
                assert q["low"] == q["value"] == q["high"]


def test_paper_preset_carries_the_measured_uncertainty():
    cfg = build_config({}, "paper")
    assert cfg.uncertainty.convergence_internal == MEASURED_LAW_UNCERTAINTY["convergence_internal"]
    # docs/convergence.md "Measured law uncertainty of the paper preset": internal τ0 ± 48.0
    # MPa for the paper preset, from its fit s.e. (the convergence study's base run, stored
    # in docs/measured/quartz-study), the convergence and the model spread, in quadrature
    study = json.loads(
        (ROOT / "docs" / "measured" / "quartz-study" / "convergence" / "study.json").read_text()
    )
    base = next(v for v in study["variants"] if v["name"] == "base")
    se = base["laws"]["internal"]["tau0_stderr_mpa"]
    assert se == pytest.approx(5.332, abs=5e-4)  # the paper preset's own fit (docs/teachers.md)
    h = math.sqrt(
        se**2
        + cfg.uncertainty.convergence_internal["tau0_mpa"] ** 2
        + cfg.uncertainty.model_spread_internal["tau0_mpa"] ** 2
    )
    assert f"τ0 25.2 ± {h:.1f}" in (ROOT / "docs" / "convergence.md").read_text()
    assert build_config({}).uncertainty.convergence_internal == {}


def test_bad_uncertainty_fields_name_the_field():
    from flatcontact.foundation.errors import InputError

    with pytest.raises(InputError, match=r"uncertainty\.convergence_internal"):
        build_config({"uncertainty": {"convergence_internal": {"kappa": 1.0}}})
    with pytest.raises(InputError, match=r"uncertainty\.model_spread_enthalpy"):
        build_config({"uncertainty": {"model_spread_enthalpy": {"tau0_mpa": -1.0}}})


# ------------------------------------------------------------------ validate-potential --ispes

ISPES_ARGS = [
    "--grid",
    "3",
    "3",
    "--p-range-gpa",
    "-0.5",
    "2.5",
    "6",
    "--p-gpa",
    "0,0.5,1",
    "--fmax-ev-per-angstrom",
    "0.01",
    "--lj-cutoff-angstrom",
    "8",
]


@pytest.mark.filterwarnings("ignore")
def test_validate_potential_ispes_compares_two_classical_models(tmp_path, capsys):
    out = tmp_path / "report.json"
    code, stdout, err = run_cli(
        [
            "validate-potential",
            "tersoff",
            "--ispes",
            "--reference",
            "vashishta",
            *ISPES_ARGS,
            "--ispes-dir",
            str(tmp_path / "scans"),
            "--out",
            str(out),
            "--json",
        ],
        capsys,
    )
    assert code in (0, None), err
    report = json.loads(stdout)
    assert json.loads(out.read_text()) == report
    assert report["reference"] == "vashishta"
    rows = report["table"]
    ref = {r["p_gpa"]: r for r in rows if r["model"] == "vashishta"}
    other = [r for r in rows if r["model"] == "tersoff"]
    assert sorted(ref) == [0.0, 0.5, 1.0] and len(other) == 3
    for r in ref.values():
        assert r["d_tau_mpa"] == 0 and r["d_sigma_mss_mpa"] == 0
    for r in other:
        base = ref[r["p_gpa"]]
        assert r["d_tau_mpa"] == pytest.approx(r["tau_mpa"] - base["tau_mpa"], rel=1e-9)
        assert r["rel_sigma_mss_mpa"] == pytest.approx(
            (r["sigma_mss_mpa"] - base["sigma_mss_mpa"]) / abs(base["sigma_mss_mpa"]), rel=1e-9
        )
        assert 0 < r["work_of_separation_j_per_m2"] < 1
    for label in ("vashishta", "tersoff"):
        assert report["models"][label]["force_calls"] > 0
        assert set(report["models"][label]["laws"]) >= set(LAW_KEYS)
    # the model spread a run's uncertainty section takes: half the range of the two laws
    for key in LAW_KEYS:
        a, b = (report["models"][m]["laws"][key] for m in ("vashishta", "tersoff"))
        assert report["model_spread"][key] == pytest.approx(abs(a - b) / 2, rel=1e-12)
    # the scans are resumable: a second call recomputes nothing
    code, stdout2, _ = run_cli(
        [
            "validate-potential",
            "tersoff",
            "--ispes",
            "--reference",
            "vashishta",
            *ISPES_ARGS,
            "--ispes-dir",
            str(tmp_path / "scans"),
            "--json",
        ],
        capsys,
    )
    assert json.loads(stdout2)["table"] == report["table"]


@pytest.mark.parametrize(
    "extra,needle",
    [
        ([], "--reference"),
        (["--reference", "vashishta", "--energy-form", "gibbs"], "--energy-form"),
        (["--reference", "vashishta", "--grid", "1", "3"], "--grid"),
        (["--reference", "nonsense-model"], "--reference"),
        (["--reference", "vashishta", "--p-range-gpa", "2", "1", "5"], "--p-range-gpa"),
        (["--reference", "tersoff"], "distinct"),
    ],
)
def test_validate_potential_ispes_bad_input_is_one_line_before_work(
    extra, needle, tmp_path, capsys
):
    scans = tmp_path / "scans"
    code, _, err = run_cli(
        ["validate-potential", "tersoff", "--ispes", *extra, "--ispes-dir", str(scans)], capsys
    )
    assert needle in one_error_line(code, err)
    assert not scans.exists()
