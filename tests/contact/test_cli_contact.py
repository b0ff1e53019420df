"""`flatcontact contact`: JSON keys, outputs, the experiment flow and one-line input errors."""

import json

import numpy as np
import pytest

from flatcontact.cli import main
from flatcontact.contact import experiment as ex
from flatcontact.contact.parameters import ContactParameters

KEYS = {
    "p0_gpa",
    "contact_radius_nm",
    "normal_load_un",
    "peak_lateral_force_un",
    "displacement_at_peak_nm",
    "effective_shear_strength_mpa",
    "effective_shear_strength_rms_mpa",
    "gross_sliding_stress_mpa",
    "uniform_shear_strength_mpa",
}


def _run(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main([*argv])
    out = capsys.readouterr()
    return exc.value.code, out.out, out.err


def test_json_keys_and_paper_values(capsys):
    code, out, _ = _run(["contact", "--p0-gpa", "1.0", "--p0-gpa", "0.5,2", "--json"], capsys)
    assert code in (0, None)
    doc = json.loads(out)
    res = doc["results"]
    assert [r["p0_gpa"] for r in res] == [1.0, 0.5, 2.0]
    for r in res:
        assert KEYS <= set(r)
        assert "contact_radius_dmt_nm" not in r
    assert res[0]["contact_radius_nm"] == pytest.approx(149.6, abs=0.05)
    assert res[0]["normal_load_un"] == pytest.approx(46.87, abs=0.005)
    assert res[0]["effective_shear_strength_mpa"] < res[0]["uniform_shear_strength_mpa"]
    assert doc["parameters"]["tau0_mpa"] == 26.7


def test_json_with_adhesion(capsys):
    _code, out, _ = _run(
        [
            "contact",
            "--p0-gpa",
            "0.5",
            "--work-of-adhesion-j-per-m2",
            "0.2",
            "--maugis-lambda",
            "1",
            "--json",
        ],
        capsys,
    )
    r = json.loads(out)["results"][0]
    assert (
        r["hertz_contact_radius_nm"]
        < r["contact_radius_dmt_nm"]
        < r["contact_radius_maugis_dugdale_nm"]
        < r["contact_radius_jkr_nm"]
    )
    # λ = 1 is the Maugis–Dugdale regime: its radius is the contact's (issue 32)
    assert r["contact_radius_nm"] == pytest.approx(r["contact_radius_maugis_dugdale_nm"])
    # pull-off: 2πwR (DMT) > Maugis–Dugdale (λ = 1) > 1.5πwR (JKR), in µN
    w, radius = 0.2, 5e-6
    assert r["pull_off_force_dmt_un"] == pytest.approx(2 * np.pi * w * radius * 1e6)
    assert r["pull_off_force_jkr_un"] == pytest.approx(1.5 * np.pi * w * radius * 1e6)
    assert r["pull_off_force_jkr_un"] < r["pull_off_force_maugis_dugdale_un"]
    assert r["pull_off_force_maugis_dugdale_un"] < r["pull_off_force_dmt_un"]


def test_out_dir_and_experiment(tmp_path, capsys):
    # synthetic "measurement" made by the model at tau0 = 40 MPa (no real data is shipped)
    truth = ContactParameters(tau0_mpa=40.0)
    p0 = 1.77e9
    cs = ex.model_collapse_stress(p0, truth)
    stress = np.linspace(0.02, 1.4, 40) * cs
    k = ex.model_stiffness_at_stress(stress, p0, truth)
    csv = tmp_path / "synthetic.csv"
    csv.write_text(
        "mean shear stress [MPa],lateral stiffness [N/m]\n"
        + "".join(f"{s / 1e6},{v}\n" for s, v in zip(stress, k, strict=True))
    )
    out = tmp_path / "run"
    code, stdout, _ = _run(
        [
            "contact",
            "--p0-gpa",
            "1,1.77",
            "--experiment-csv",
            str(csv),
            "--out",
            str(out),
            "--json",
        ],
        capsys,
    )
    assert code in (0, None)
    doc = json.loads(stdout)
    assert doc["experiment"]["fitted_tau0_mpa"] == pytest.approx(40.0, rel=0.02)
    names = {p.name for p in out.iterdir()}
    for stem in ("fig4_traction", "fig5_force_stiffness", "fig6_experiment"):
        assert {f"{stem}.png", f"{stem}.svg"} <= names
    assert {"summary.json", "contact.nc"} <= names
    assert not [n for n in names if n.endswith(".part")]
    import xarray as xr

    with xr.open_dataset(out / "contact.nc", engine="h5netcdf") as ds:
        assert ds.lateral_stiffness.attrs["units"] == "N/m"
        assert ds.p0.attrs["units"] == "GPa"
        np.testing.assert_allclose(
            ds.contact_radius.values, [r["contact_radius_nm"] for r in doc["results"]]
        )


@pytest.mark.parametrize(
    "argv,needle",
    [
        (["--radius-um", "-5"], "--radius-um"),
        (["--contact-modulus-gpa", "0"], "--contact-modulus-gpa"),
        (["--k-mpa-per-gpa", "-1", "--tau0-mpa", "0"], "--k-mpa-per-gpa"),
        # k < 0 is a law the model takes, but not at a p0 where τ(centre) = k·p0 + τ0 <= 0
        (["--k-mpa-per-gpa", "-20", "--p0-gpa", "1,2"], "τ(centre)"),
        (["--mu-mpa-per-gpa", "-10", "--p0-gpa", "2"], "σ(centre)"),
        (["--tau0-mpa", "nan"], "--tau0-mpa"),
        (["--p0-gpa", "0"], "--p0-gpa"),
        (["--p0-gpa", "abc"], "--p0-gpa"),
        (["--work-of-adhesion-j-per-m2", "-0.1"], "--work-of-adhesion-j-per-m2"),
        (["--maugis-lambda", "1"], "--maugis-lambda"),
        (["--experiment-csv", "/nonexistent.csv"], "does not exist"),
    ],
)
def test_bad_input_one_line_exit_2(argv, needle, capsys, tmp_path):
    code, _out, err = _run(["contact", "--out", str(tmp_path / "o"), *argv], capsys)
    assert code == 2
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and needle in lines[0]
    assert not (tmp_path / "o").exists()


def test_bad_csv_exit_2(tmp_path, capsys):
    f = tmp_path / "x.csv"
    f.write_text("stress,stiffness\n1,2\n2,3\n3,4\n4,5\n")
    code, _, err = _run(["contact", "--experiment-csv", str(f)], capsys)
    assert code == 2 and "no unit" in err and len(err.strip().splitlines()) == 1


def test_negative_slope_runs_and_reports_the_stick_annulus(capsys):
    # k = −10 MPa/GPa: at 2 GPa (> τ0/(2|k|) = 1.335 GPa) the peak comes after the centre
    # has slipped, with a stick annulus; at 1 GPa the stick zone is a disc
    code, out, _ = _run(["contact", "--k-mpa-per-gpa", "-10", "--p0-gpa", "1,2", "--json"], capsys)
    assert code in (0, None)
    low, high = json.loads(out)["results"]
    assert low["stick_inner_radius_at_peak_nm"] == 0.0
    assert 0.0 < high["stick_inner_radius_at_peak_nm"] < high["stick_radius_at_peak_nm"]
    for r in (low, high):
        assert r["uniform_shear_strength_mpa"] == pytest.approx(26.7 - 10 * 2 / 3 * r["p0_gpa"])
        assert 0.0 < r["knee_stress_amplitude_mpa"] < r["effective_shear_strength_mpa"]
