"""Dilatancy of a stored scan (flatcontact.studies.dilatancy) on a small toy scan: the load
term of h, the compliance sign, the split of z* into gap and slabs, one model against itself."""

import json

import numpy as np
import pytest
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.studies.dilatancy import dilatancy

LOADS = [0.0, 0.25, 0.5]


@pytest.fixture(scope="module")
def scan(tmp_path_factory):
    from tests.studies.toy import toy_scan

    out = tmp_path_factory.mktemp("dilatancy")
    res = toy_scan(out, grid=3, n_thicknesses=7, fmax_ev_per_angstrom=1e-3)
    res.dataset.to_netcdf(out / "ispes.nc", engine="h5netcdf")
    return out


def test_dilatancy_figures_obey_their_definitions(scan):
    d = dilatancy(scan, LOADS)
    # h = U/A + P z*: at P = 0 the two corrugations are the same; the load term grows it
    assert d["h_range_mj_per_m2"][0] == pytest.approx(d["u_range_mj_per_m2"][0], rel=1e-9)
    assert d["h_range_mj_per_m2"][2] > d["h_range_mj_per_m2"][1] > d["h_range_mj_per_m2"][0]
    # the interface compresses under load
    assert all(s < 0 for s in d["dz_dp_angstrom_per_gpa"])
    # the toy's thickness is the atoms' z extent: gap + slabs = z*, point by point, so the
    # linear interpolation at z* keeps it
    np.testing.assert_allclose(
        np.add(d["gap_mean_angstrom"], d["slabs_mean_angstrom"]), d["z_mean_angstrom"], rtol=1e-6
    )


def test_a_model_against_itself_has_correlation_one_and_ratios_one(scan, tmp_path, capsys):
    out = tmp_path / "d.json"
    argv = ["study", "dilatancy", str(out), f"a={scan}", f"b={scan}"]
    code, stdout, err = run_cli([*argv, "--p-gpa", ",".join(map(str, LOADS))], capsys)
    assert code in (0, None), err
    doc = json.loads(out.read_text())
    assert doc["reference"] == "a"
    assert doc["models"]["a"]["p_gpa"] == LOADS
    b = doc["models"]["b"]
    np.testing.assert_allclose(b["z_pattern_correlation_with_reference"], 1.0, rtol=1e-12)
    np.testing.assert_allclose(b["h_range_mj_per_m2_over_reference"], 1.0, rtol=1e-12)
    assert "z_range_angstrom_over_reference" in stdout


@pytest.mark.parametrize(
    ("scans", "named"),
    [(["a"], "LABEL=DIR"), (["=x"], "LABEL=DIR"), (["a=nowhere"], "not a directory")],
)
def test_bad_scan_arguments_are_one_line_naming_them(scans, named, tmp_path, capsys):
    out = tmp_path / "d.json"
    code, _, err = run_cli(["study", "dilatancy", str(out), *scans], capsys)
    assert named in one_error_line(code, err)
    assert not out.exists()


def test_a_label_given_twice_is_refused(scan, tmp_path, capsys):
    code, _, err = run_cli(
        ["study", "dilatancy", str(tmp_path / "d.json"), f"a={scan}", f"a={scan}"], capsys
    )
    assert "given twice" in one_error_line(code, err)
