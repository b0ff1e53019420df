"""`flatcontact analyze`: flags, JSON, files, one-line errors."""

import json

import numpy as np
import pytest
import xarray as xr

from flatcontact.analysis import synthetic as syn
from flatcontact.cli import main
from flatcontact.ispes.contract import write_ispes

A1, A2 = syn.hexagonal_cell()


@pytest.fixture(scope="module")
def grid_file(tmp_path_factory):
    model = syn.SyntheticInterface(
        A1,
        A2,
        syn.three_cosine(A1, A2, (1.0, 0.9, 1.1)),
        corrugation_ev_per_a2=-2e-4,
        gap_modulation_angstrom=-0.02,
    )
    path = tmp_path_factory.mktemp("grid") / "ispes.nc"
    write_ispes(model.grid(10, 10, np.linspace(24.3, 26.4, 16)), path)
    return path


def _run(args, capsys):
    with pytest.raises(SystemExit) as info:
        main(args)
    out = capsys.readouterr()
    return info.value.code, out.out, out.err


def test_json_output_with_values_after_one_flag_including_negative(grid_file, capsys):
    code, out, _ = _run(
        ["analyze", str(grid_file), "--p-gpa", "-0.2", "0.5", "1", "2", "--json"], capsys
    )
    assert code == 0
    data = json.loads(out)
    assert [row["p_gpa"] for row in data["pressures"]] == [-0.2, 0.5, 1.0, 2.0]
    for row in data["pressures"]:
        assert row["tau_mpa"] > row["sigma_mss_mpa"] > 0 and row["shear_stiffness_gpa_per_nm"] > 0
    assert set(data["laws"]) >= {
        "k_mpa_per_gpa",
        "tau0_mpa",
        "mu_mpa_per_gpa",
        "sigma0_mpa",
        "p_max_gpa",
    }


def test_out_writes_contract_files_and_figures(grid_file, tmp_path, capsys):
    out = tmp_path / "res"
    code, _, _ = _run(
        [
            "analyze",
            str(grid_file),
            "--p-gpa",
            "0.5,1",
            "--p-gpa",
            "2",
            "--energy-form",
            "enthalpy",
            "--out",
            str(out),
            "--no-svg",
        ],
        capsys,
    )
    assert code == 0
    names = {p.name for p in out.iterdir()}
    assert {
        "friction.csv",
        "friction.nc",
        "laws.json",
        "fig3_laws.png",
        "fig2_p0.5gpa.png",
    } <= names
    assert not [n for n in names if n.endswith(".part")]
    header = (out / "friction.csv").read_text().splitlines()[0].split(",")
    assert header[:4] == ["p_gpa", "tau_mpa", "sigma_mss_mpa", "shear_stiffness_gpa_per_nm"]
    ds = xr.open_dataset(out / "friction.nc", engine="h5netcdf")
    assert ds.tau_mpa.attrs["units"] == "MPa" and ds.energy_map.shape == (3, 10, 10)
    laws = json.loads((out / "laws.json").read_text())
    assert laws["k_mpa_per_gpa"] > 0  # enthalpy form of a cobblestone: friction grows with load
    ds.close()


@pytest.mark.parametrize(
    "args, message",
    [
        (
            ["--p-gpa", "0.5", "--energy-form", "gibbs"],
            "error: --energy-form: expected 'internal' or 'enthalpy', got \"gibbs\"",
        ),
        (["--p-gpa", "90"], "error: P = 90 GPa is outside the data of"),
        ([], "error: --p-gpa: give at least one target pressure"),
    ],
)
def test_bad_input_is_one_line_exit_2(grid_file, capsys, args, message):
    code, _, err = _run(["analyze", str(grid_file), *args], capsys)
    assert code == 2
    assert err.strip().startswith(message) and len(err.strip().splitlines()) == 1


def test_missing_file_is_one_line(tmp_path, capsys):
    code, _, err = _run(["analyze", str(tmp_path / "nope.nc"), "--p-gpa", "1"], capsys)
    assert code == 2 and "no such ISPES file" in err


def test_a_core_error_names_the_flag_for_the_cli_and_the_settings_path_for_the_run(
    grid_file, tmp_path, capsys
):
    """The core names its parameter (allow_missing); the analyze stage renames it to the
    settings path a YAML user wrote (analysis.allow_missing), the CLI to the flag it offers."""
    from flatcontact.config import build_config
    from flatcontact.foundation.errors import InputError
    from flatcontact.ispes.contract import open_ispes
    from flatcontact.stages.analyze import AnalyzeInputs, analyze_stage

    holed = open_ispes(grid_file).load()
    holed["energy"][2, 1, 5] = np.nan
    holed["converged"][2, 1, 5] = False
    path = tmp_path / "holed.nc"
    write_ispes(holed, path)
    code, _, err = _run(["analyze", str(path), "--p-gpa", "0.5,1"], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "1 grid points are missing" in err and "(--allow-missing)" in err
    settings = build_config({"analysis": {"p_gpa": [0.5, 1.0]}})
    with pytest.raises(InputError, match=r"missing.*\(analysis\.allow_missing\)$"):
        analyze_stage(settings, AnalyzeInputs(path), None)
    # allowed: the hole is interpolated and both doors give the same τ
    code, out, _ = _run(
        ["analyze", str(path), "--p-gpa", "0.5,1", "--allow-missing", "--json"], capsys
    )
    assert code == 0
    allowed = build_config({"analysis": {"p_gpa": [0.5, 1.0], "allow_missing": True}})
    tau = analyze_stage(allowed, AnalyzeInputs(path), None).analysis.column("tau_mpa")
    np.testing.assert_array_equal([r["tau_mpa"] for r in json.loads(out)["pressures"]], tau)
