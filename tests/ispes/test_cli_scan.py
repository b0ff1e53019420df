"""``flatcontact scan``: a toy run, resume, and one-line errors before any work."""

import json

import pytest

from flatcontact.cli import main
from flatcontact.ispes.contract import open_ispes
from flatcontact.ispes.geometry import thickness
from flatcontact.structures.interface import write_interface

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
    cfg = tmp_path / "scan.yaml"
    cfg.write_text(
        f"scan:\n  grid: [2, 2]\n  thickness: [{z0 - 0.2}, {z0 + 0.2}]\n  fmax_ev_per_a: 0.001\n"
    )
    argv = [
        "scan",
        str(cfg),
        "--interface",
        toy_file,
        "--calculator",
        TOY,
        "--workers",
        "1",
        "--out",
        str(tmp_path / "o"),
        "--json",
    ]
    code, out, _ = _run(argv, capsys)
    assert code in (0, None)
    summary = json.loads(out)
    assert summary["points_computed"] == summary["points_total"] == 8
    ds = open_ispes(tmp_path / "o" / "ispes.nc")
    assert ds.attrs["fmax_ev_per_a"] == 0.001 and ds.converged.all()
    code, out, _ = _run(argv, capsys)
    assert json.loads(out)["points_computed"] == 0


@pytest.mark.parametrize(
    ("extra", "match"),
    [
        (["--potential", "nosuchpot", "--thickness", "11"], "unknown potential 'nosuchpot'"),
        (["--potential", "/nope/X.snapcoeff", "--thickness", "11"], "not found"),
        (["--potential", "vashishta", "--thickness", "11"], "element"),
        (["--calculator", TOY, "--grid", "0", "2", "--thickness", "11"], "n_a"),
        (["--calculator", TOY, "--thickness", "5"], "overlap"),
        (
            ["--calculator", TOY, "--thickness", "11", "--dask-address", "tcp://127.0.0.1:9"],
            "no Dask scheduler",
        ),
        (["--calculator", TOY], "--thickness"),
        (["--calculator", TOY, "--thickness", "11", "--optimizer", "Newton"], "optimizer"),
    ],
)
def test_bad_input_is_one_line_before_work(tmp_path, toy_file, capsys, extra, match):
    out_dir = tmp_path / "o"
    code, _, err = _run(["scan", "--interface", toy_file, "--out", str(out_dir), *extra], capsys)
    assert code == 2
    assert match in err and err.strip().count("\n") == 0
    assert not (out_dir / "ispes.nc").exists()
