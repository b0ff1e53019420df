"""Issue 13 wiring: ``contact --cycle/--cycle-model/--fit-csv`` and the same settings in a run config.

The CLI and the contact stage of ``flatcontact run`` (``contact_stage`` with a config read by
``load_config``) must give the same cycle rows and fit results; the cycle rows must obey
the first-harmonic energy identity W = π·Q_amp·u″₁ and, for ``classical``, Johnson's
Mindlin–Deresiewicz energy with μ = k and G*_J = G*/4 (computed here independently).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.config import load_config
from flatcontact.contact import fit
from flatcontact.contact.cycle import CycleModel
from flatcontact.contact.measured import LoadCurve
from flatcontact.contact.parameters import ContactParameters
from flatcontact.stages.contact import ContactInputs, contact_stage

ROW_KEYS = {
    "p0_gpa",
    "lateral_force_amplitude_un",
    "dissipated_energy_per_cycle_fj",
    "lockin_stiffness_n_per_m",
    "lockin_quadrature_nm",
}
LAWS = {"k_mpa_per_gpa": 4.52, "tau0_mpa": 26.7, "mu_mpa_per_gpa": 0.21, "sigma0_mpa": 11.1}


def _cli_json(argv, capsys) -> dict:
    code, out, err = run_cli(["contact", *argv, "--json"], capsys)
    assert code in (0, None), err
    return json.loads(out)


def test_cycle_rows_keys_and_first_harmonic_energy(capsys):
    doc = _cli_json(["--p0-gpa", "1,1.77", "--cycle"], capsys)
    rows = doc["cycle"]
    assert len(rows) == 2 * 6  # default six amplitudes per p0
    assert [r["p0_gpa"] for r in rows] == [1.0] * 6 + [1.77] * 6
    for r in rows:
        assert ROW_KEYS <= set(r) and r["model"] == "modified"
        # fJ = µN·nm: W = π Q_amp u''_1 with no unit factor
        w = np.pi * r["lateral_force_amplitude_un"] * r["lockin_quadrature_nm"]
        assert r["dissipated_energy_per_cycle_fj"] == pytest.approx(w, rel=1e-5)
        # k' = Q_amp/u'_1 (N/m = µN/nm × 1e3), below the initial full-stick 2G*a
        k = r["lateral_force_amplitude_un"] / r["lockin_in_phase_nm"] * 1e3
        assert r["lockin_stiffness_n_per_m"] == pytest.approx(k, rel=1e-12)
        assert r["lockin_stiffness_n_per_m"] < r["initial_stiffness_n_per_m"]
    # the existing per-p0 keys are still there; the cycle's gross sliding is their Q_peak
    by_p0 = {r["p0_gpa"]: r for r in doc["results"]}
    for r in rows:
        assert r["gross_sliding_force_un"] == pytest.approx(
            by_p0[r["p0_gpa"]]["peak_lateral_force_un"], rel=1e-9
        )
    # the default fractions: 0.2 of gross sliding at 1 GPa gives the documented 8157 N/m
    assert rows[0]["lockin_stiffness_n_per_m"] == pytest.approx(8157, abs=1)


def test_classical_model_is_mindlin_deresiewicz_with_mu_equal_k(capsys):
    doc = _cli_json(
        [
            "--p0-gpa",
            "1",
            "--cycle",
            "--cycle-model",
            "classical",
            "--cycle-amplitude-fractions",
            "0.5,0.9",
        ],
        capsys,
    )
    # Johnson (7.59) with friction coefficient μ = k·1e-3, Hertz P and a, G*_J = G*/4
    mu = 4.52e-3
    e_star, radius, g_j = 52.5e9, 5e-6, 29e9 / 4
    p0 = 1e9
    a = np.pi * p0 * radius / (2 * e_star)
    load = 2 / 3 * np.pi * a**2 * p0
    assert doc["cycle"][0]["gross_sliding_force_un"] == pytest.approx(mu * load * 1e6, rel=1e-9)
    for r, x in zip(doc["cycle"], (0.5, 0.9), strict=True):
        assert r["model"] == "classical"
        w = (
            9
            * mu**2
            * load**2
            / (10 * g_j * a)
            * (1 - (1 - x) ** (5 / 3) - 5 * x / 6 * (1 + (1 - x) ** (2 / 3)))
        )
        assert r["dissipated_energy_per_cycle_fj"] == pytest.approx(w * 1e15, rel=1e-6)
        # initial stiffness of Cattaneo–Mindlin: 8 G*_J a = 2 G* a
        assert r["initial_stiffness_n_per_m"] == pytest.approx(8 * g_j * a, rel=1e-9)
    assert "mu = k" in doc["conventions"]["cycle"] and "G*_J = G*/4" in doc["conventions"]["cycle"]


def _synthetic_table(path: Path, truth: ContactParameters, loads=(1.0, 1.77)) -> None:
    """Lock-in curves made by the model at ``truth`` (no noise), with a p0 column."""
    lines = ["mean shear stress [MPa],lateral stiffness [N/m],p0 [GPa]"]
    for p0 in loads:
        mdl = CycleModel("modified", p0 * 1e9, truth)
        smax = mdl.gross / (np.pi * mdl.a**2)
        stress = np.linspace(0.05, 1.1, 12) * smax
        k = fit.model_stiffness(LoadCurve(p0, stress, np.zeros(12), "t"), truth)
        lines += [f"{s / 1e6:.10g},{v:.10g},{p0}" for s, v in zip(stress, k, strict=True)]
    path.write_text("\n".join(lines) + "\n")


def test_cli_and_run_config_give_the_same_cycle_and_fit(tmp_path, capsys):
    truth = ContactParameters(tau0_mpa=35.0)
    data = tmp_path / "data" / "curves.csv"
    data.parent.mkdir()
    _synthetic_table(data, truth)
    # the run's config: laws given (the laws stage is upstream in a run), the fit file
    # relative to the config file
    cfg_path = tmp_path / "run.yaml"
    cfg_path.write_text(
        "contact:\n"
        "  p0_gpa: [1.0, 2.0]\n"
        + "".join(f"  {k}: {v}\n" for k, v in LAWS.items())
        + "  cycle: {enabled: true, model: modified, amplitude_fractions: [0.3, 0.7]}\n"
        "  fit:\n"
        "    csv: [data/curves.csv]\n"
        "    free: [tau0_mpa]\n"
        "    fixed: [k_mpa_per_gpa]\n"
        "report:\n  svg: false\n"
    )
    cfg = load_config(cfg_path)
    assert cfg.contact.fit.csv == [str(data.resolve())]
    run_doc = contact_stage(cfg, ContactInputs(), tmp_path / "stage").to_json()
    cli_doc = _cli_json(
        [
            "--p0-gpa",
            "1,2",
            "--cycle",
            "--cycle-model",
            "modified",
            "--cycle-amplitude-fractions",
            "0.3,0.7",
            "--fit-csv",
            str(data),
            "--fit-free",
            "tau0_mpa",
            "--fit-fixed",
            "k_mpa_per_gpa",
            "--out",
            str(tmp_path / "cli"),
            "--no-svg",
        ],
        capsys,
    )
    assert cli_doc["cycle"] == run_doc["cycle"]
    assert cli_doc["fit"] == run_doc["fit"]
    assert cli_doc["results"] == run_doc["results"]
    # the fit recovers the τ0 the data were made with, within its stated error (noise-free)
    mod = cli_doc["fit"]["modified"]
    assert mod["fitted"]["tau0_mpa"] == pytest.approx(
        35.0, abs=max(3 * mod["standard_errors"]["tau0_mpa"], 1e-3)
    )
    assert cli_doc["fit"]["preferred_model"] == "modified"
    assert cli_doc["fit"]["files"][0]["name"] == "curves.csv"
    # both doors wrote the same fit.json, the loops and the fit figure
    for folder in (tmp_path / "stage", tmp_path / "cli"):
        names = {p.name for p in folder.iterdir()}
        assert {"fit.json", "fig6_fit.png", "fig5c_cycle_loops.png", "fig6_lockin.png"} <= names
        assert json.loads((folder / "fit.json").read_text()) == cli_doc["fit"]
        with xr.open_dataset(folder / "contact.nc", engine="h5netcdf") as ds:
            assert ds.cycle_loop_force.dims == ("p0", "cycle_amplitude", "loop_point")
            assert list(ds.p0.values) == [1.0, 2.0]
            # each loop is closed and reaches ±Q_amp
            loop_q = ds.cycle_loop_force.values
            amp = ds.cycle_force_amplitude.values
            np.testing.assert_allclose(loop_q[..., 0], -amp, rtol=1e-9)
            np.testing.assert_allclose(loop_q[..., -1], -amp, rtol=1e-9)
            np.testing.assert_allclose(
                np.nanmax(loop_q, axis=-1), ds.cycle_force_amplitude.values, rtol=1e-9
            )
            np.testing.assert_allclose(
                ds.cycle_dissipated_energy.values,
                [
                    [
                        r["dissipated_energy_per_cycle_fj"]
                        for r in cli_doc["cycle"]
                        if r["p0_gpa"] == p
                    ]
                    for p in (1.0, 2.0)
                ],
                rtol=1e-12,
            )


@pytest.mark.parametrize(
    "argv,needle",
    [
        (["--cycle", "--cycle-amplitudes-un", "2", "--p0-gpa", "1"], "--cycle-amplitudes-un"),
        (["--cycle", "--cycle-amplitude-fractions", "1"], "--cycle-amplitude-fractions"),
        (["--cycle", "--cycle-model", "hertz"], "--cycle-model"),
        (["--cycle", "--sigma0-mpa", "30"], "--sigma0-mpa"),
        (
            [
                "--fit-csv",
                "A",
                "--fit-free",
                "tau0_mpa,k_mpa_per_gpa",
                "--fit-fixed",
                "k_mpa_per_gpa",
            ],
            "--fit-fixed",
        ),
        (["--fit-csv", "A", "--fit-free", "tau0"], "--fit-free"),
        (["--fit-csv", "A,B"], "--fit-csv"),
        (["--fit-csv", "A", "--fit-stiffness", "secant"], "--fit-stiffness"),
    ],
)
def test_bad_cycle_and_fit_input_is_one_line_naming_the_flag(argv, needle, tmp_path, capsys):
    plain = "mean shear stress [MPa],lateral stiffness [N/m]\n" + "".join(
        f"{s},{8000 - 100 * s}\n" for s in range(1, 7)
    )
    for name in ("A", "B"):
        (tmp_path / f"{name}.csv").write_text(plain)
    files = {"A": str(tmp_path / "A.csv"), "A,B": f"{tmp_path / 'A.csv'},{tmp_path / 'B.csv'}"}
    argv = [files.get(a, a) for a in argv]
    code, _, err = run_cli(["contact", "--out", str(tmp_path / "o"), *argv], capsys)
    line = one_error_line(code, err)
    assert needle in line
    assert not (tmp_path / "o").exists()


def test_several_loads_without_a_load_column_name_the_p0_flag(tmp_path, capsys):
    plain = "mean shear stress [MPa],lateral stiffness [N/m]\n" + "".join(
        f"{s},{8000 - 100 * s}\n" for s in range(1, 7)
    )
    files = []
    for name in ("a", "b"):
        (tmp_path / f"{name}.csv").write_text(plain)
        files.append(str(tmp_path / f"{name}.csv"))
    code, _, err = run_cli(["contact", "--fit-csv", ",".join(files)], capsys)
    line = one_error_line(code, err)
    assert "no load column" in line and "--fit-p0-gpa" in line and "a.csv" in line


def test_config_file_errors_name_the_field(tmp_path):
    from flatcontact.foundation.errors import InputError

    bad = tmp_path / "bad.yaml"
    bad.write_text("contact:\n  fit: {csv: [missing.csv]}\n")
    with pytest.raises(InputError, match=r"contact\.fit\.csv: file .*missing\.csv not found"):
        load_config(bad)
    bad.write_text("contact:\n  cycle: {amplitude_fractions: [0.5, 1.2]}\n")
    with pytest.raises(InputError, match=r"contact\.cycle\.amplitude_fractions"):
        load_config(bad)
