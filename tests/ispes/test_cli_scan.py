"""``flatcontact scan``: the run configuration, a toy run, resume, and one-line errors before work."""

import json

import pytest

from flatcontact.cli import main
from flatcontact.cli.scan import resolve_config
from flatcontact.config import default_potential, load_config, preset
from flatcontact.ispes.contract import open_ispes
from flatcontact.ispes.geometry import thickness
from flatcontact.structures.interface_io import write_interface

TOY = "flatcontact.ispes.toy:toy_calculator"


@pytest.fixture()
def toy_file(tmp_path, toy_reference):
    return str(write_interface(toy_reference, tmp_path / "interface.extxyz"))


def _run(argv, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    out, err = capsys.readouterr()
    return exit_info.value.code, out, err


def test_cli_scan_and_rerun(tmp_path, toy_file, toy_reference, capsys):
    z0 = thickness(toy_reference)
    cfg = tmp_path / "run.yaml"
    cfg.write_text(
        "potential:\n"
        "  calculator:\n"
        f"    target: {TOY}\n"
        "scan:\n"
        "  grid: [2, 2]\n"
        f"  thickness_angstrom: [{z0 - 0.2}, {z0 + 0.2}]\n"
        "  fmax_ev_per_angstrom: 0.001\n"
    )
    argv = ["scan", str(cfg), "--interface", toy_file, "--workers", "1"]
    argv += ["--out", str(tmp_path / "o"), "--json"]
    code, out, _ = _run(argv, capsys)
    assert code in (0, None)
    summary = json.loads(out)
    assert summary["points_computed"] == summary["points_total"] == 8
    ds = open_ispes(tmp_path / "o" / "ispes.nc")
    assert ds.attrs["fmax_ev_per_a"] == 0.001 and ds.converged.all()
    code, out, _ = _run(argv, capsys)
    assert json.loads(out)["points_computed"] == 0
    # the same store with another tolerance (flag over the file) is refused before any work
    code, _, err = _run([*argv, "--fmax-ev-per-angstrom", "0.002"], capsys)
    assert code == 2 and "different settings" in err and err.strip().count("\n") == 0
    assert "0.001" in err and "0.002" in err


def test_one_run_config_serves_run_and_scan(tmp_path, toy_file, toy_reference, capsys):
    """A YAML written for ``flatcontact run`` is read by ``flatcontact scan`` unchanged."""
    z0 = thickness(toy_reference)
    cfg = tmp_path / "run.yaml"
    cfg.write_text(
        "preset: quick\n"
        "potential:\n"
        "  intra: vashishta\n"
        "scan:\n"
        "  grid: [2, 3]\n"
        f"  thickness_angstrom: [{z0}]\n"
        "  max_steps: 300\n"
        "contact:\n"
        "  p0_gpa: [1.0, 2.0]\n"
    )
    assert load_config(cfg).scan.grid == (2, 3)  # what `flatcontact run` reads
    # the file's potential is the one used: vashishta refuses the toy's elements, before work
    code, _, err = _run(["scan", str(cfg), "--interface", toy_file, "--out", "x"], capsys)
    assert code == 2 and "potential 'vashishta'" in err and err.strip().count("\n") == 0
    # with a calculator flag over it, the file's grid is scanned
    out_dir = tmp_path / "o"
    argv = ["scan", str(cfg), "--interface", toy_file, "--calculator", TOY]
    code, out, _ = _run([*argv, "--executor", "serial", "--out", str(out_dir), "--json"], capsys)
    assert code in (0, None)
    assert json.loads(out)["points_total"] == 2 * 3 * 1
    ds = open_ispes(out_dir / "ispes.nc")
    assert (ds.sizes["shift_a"], ds.sizes["shift_b"], ds.sizes["thickness"]) == (2, 3, 1)


@pytest.mark.parametrize(
    ("yaml_text", "match"),
    [
        ("scan:\n  grdi: [2, 2]\n", "scan.grdi: unknown field"),
        ("scan:\n  fmax_ev_per_a: 0.001\n", "scan.fmax_ev_per_a: unknown field"),  # old schema
        ("scan:\n  grid: [2, -1]\n", "scan.grid: expected two positive integers, got [2, -1]"),
        ("scan:\n  workers: 0\n", "scan.workers: expected a value >= 1, got 0"),
        ("scan:\n  optimizer: Newton\n", "scan.optimizer: expected one of"),
        ("potential:\n  intra: nosuchpot\n", "potential.intra"),
    ],
)
def test_bad_run_config_is_one_line_naming_the_field(tmp_path, toy_file, capsys, yaml_text, match):
    cfg = tmp_path / "run.yaml"
    cfg.write_text(yaml_text)
    out_dir = tmp_path / "o"
    argv = ["scan", str(cfg), "--interface", toy_file, "--calculator", TOY, "--out", str(out_dir)]
    code, _, err = _run(argv, capsys)
    assert code == 2
    assert err.strip().count("\n") == 0 and str(cfg) in err and match in err
    assert not out_dir.exists()


def test_defaults_are_the_quick_preset(tmp_path):
    quick = preset("quick")["scan"]
    cfg = resolve_config(None, None, {"scan": {}})
    assert list(cfg.scan.grid) == quick["grid"]
    assert cfg.scan.p_range_gpa.model_dump() == quick["p_range_gpa"]
    assert cfg.scan.thickness_angstrom is None
    assert cfg.scan.fmax_ev_per_angstrom == quick["fmax_ev_per_angstrom"]
    assert cfg.potential.intra == default_potential()["intra"] and cfg.calculator is None


def test_flags_override_the_file_and_keep_the_rest(tmp_path):
    cfg = tmp_path / "run.yaml"
    cfg.write_text(
        "preset: paper\n"
        "potential:\n  intra: tersoff\n  lj:\n    cutoff_angstrom: 9.0\n"
        "scan:\n  grid: [5, 4]\n  p_range_gpa: {lo_gpa: -0.5, hi_gpa: 3.0, n: 4}\n"
    )
    flags = {
        "scan": {"thickness_angstrom": [11.0, 11.5], "workers": 3},
        "potential": {"intra": "vashishta"},
    }
    resolved = resolve_config(cfg, None, flags)
    assert resolved.scan.thickness_angstrom == [11.0, 11.5] and resolved.scan.p_range_gpa is None
    assert resolved.scan.grid == (5, 4) and resolved.scan.workers == 3
    assert resolved.scan.fmax_ev_per_angstrom == preset("paper")["scan"]["fmax_ev_per_angstrom"]
    assert resolved.potential.intra == "vashishta" and resolved.potential.lj.cutoff_angstrom == 9.0
    # a pressure range flag replaces the file's explicit thicknesses the same way
    back = resolve_config(cfg, None, {"scan": {"p_range_gpa": {"lo_gpa": 0, "hi_gpa": 2, "n": 3}}})
    assert back.scan.p_range_gpa.n == 3 and back.scan.thickness_angstrom is None


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (
            ["--potential", "nosuchpot", "--thickness-angstrom", "11"],
            "unknown potential 'nosuchpot'",
        ),
        (["--potential", "/nope/X.snapcoeff", "--thickness-angstrom", "11"], "not found"),
        (["--potential", "vashishta", "--thickness-angstrom", "11"], "element"),
        (["--thickness-angstrom", "11"], f"potential '{default_potential()['intra']}'"),
        (["--potential", "/nope/spec.json"], "no such potential spec file"),
        (["--potential", "vashishta", "--calculator", TOY], "not both"),
        (["--calculator", TOY, "--grid", "0", "2"], "--grid: expected two positive integers"),
        (["--calculator", TOY, "--thickness-angstrom", "5"], "overlap"),
        (
            ["--calculator", TOY, "--thickness-angstrom", "11,x"],
            "--thickness-angstrom: 'x' is not a number",
        ),
        (
            ["--calculator", TOY, "--thickness-angstrom", "-1"],
            "--thickness-angstrom (scan.thickness_angstrom.0): expected 0.1 <= value <= 1000 Å",
        ),
        (["--calculator", TOY, "--p-range-gpa", "2", "1", "4"], "--p-range-gpa"),
        (
            ["--calculator", TOY, "--thickness-angstrom", "11", "--p-range-gpa", "0", "1", "3"],
            "not both",
        ),
        (
            [
                "--calculator",
                TOY,
                "--thickness-angstrom",
                "11",
                "--dask-address",
                "tcp://127.0.0.1:9",
            ],
            "no Dask scheduler",
        ),
        (["--calculator", TOY, "--workers", "0"], "--workers: expected a value >= 1, got 0"),
        (["--calculator", TOY, "--optimizer", "Newton"], "--optimizer: expected one of"),
        (["--calculator", TOY, "--executor", "mpi"], "--executor: expected"),
        (["--calculator", TOY, "--order", "random"], "--order: expected one of"),
        (["--calculator", TOY, "--preset", "huge"], "preset: expected quick or paper"),
    ],
)
def test_bad_flag_is_one_line_before_work(tmp_path, toy_file, capsys, extra, match):
    out_dir = tmp_path / "o"
    code, _, err = _run(["scan", "--interface", toy_file, "--out", str(out_dir), *extra], capsys)
    assert code == 2
    assert match in err and err.strip().count("\n") == 0
    assert not (out_dir / "ispes.nc").exists()
