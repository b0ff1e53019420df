"""A tiny end-to-end SNAP training on a dataset made in the test, and the CLI around it."""

import json

import numpy as np
import pytest

from flatcontact.training.dataset import labelled, write_dataset
from flatcontact.training.fit import FitSettings
from flatcontact.training.lammps_bulk import snap_calculator, vashishta_calculator
from flatcontact.training.polymorphs import build_polymorph
from flatcontact.training.recipe import strain_cell
from flatcontact.training.snapfiles import SnapHyper
from flatcontact.training.train import train_snap


@pytest.fixture(scope="module")
def vashishta_dataset(tmp_path_factory):
    """18 distorted alpha-quartz/cristobalite frames labelled by the Vashishta potential."""
    rng = np.random.default_rng(11)
    calc = vashishta_calculator()
    frames = []
    for k in range(18):
        base = build_polymorph("alpha_quartz" if k % 3 else "cristobalite")
        a = strain_cell(base.repeat((1, 1, 2) if k % 2 else (1, 1, 1)), rng.uniform(-0.03, 0.03, 6))
        a.positions += rng.normal(0, 0.04, a.positions.shape)
        a.calc = calc
        f = labelled(a, a.get_potential_energy(), a.get_forces(), a.get_stress())
        f.info["config_type"] = "quartz" if k % 3 else "cristobalite"
        frames.append(f)
    return write_dataset(frames, tmp_path_factory.mktemp("data") / "vashishta.extxyz")


def test_end_to_end_fit_writes_working_lammps_files(vashishta_dataset, tmp_path):
    hypers = [SnapHyper(twojmax=4, rcutfac=4.0), SnapHyper(twojmax=6, rcutfac=4.5)]
    report = train_snap(
        tmp_path,
        data=vashishta_dataset,
        name="tiny",
        hypers=hypers,
        settings_grid=[FitSettings(30.0, 300.0)],
        seed=3,
    )
    for f in (
        "tiny.snapcoeff",
        "tiny.snapparam",
        "fit_report.json",
        "parity.png",
        "provenance.json",
    ):
        assert (tmp_path / f).is_file()
    on_disk = json.loads((tmp_path / "fit_report.json").read_text())
    assert on_disk["hyper"] == report["hyper"]
    assert len(on_disk["search"]) == 2 * 4  # two descriptors x four ridge strengths
    # the fit learns: test forces well below the spread of the labels
    from flatcontact.training.dataset import labels, read_dataset

    frames = read_dataset(vashishta_dataset)
    spread = np.sqrt(np.mean(np.concatenate([labels(a)[1].ravel() for a in frames]) ** 2)) * 1e3
    assert report["errors"]["test"]["force_rmse_mev_per_angstrom"] < 0.5 * spread
    # LAMMPS with the written files reproduces the report's RMSE on the test split
    calc = snap_calculator(tmp_path / "tiny.snapcoeff")
    split_idx = _split(tmp_path)
    test = [frames[i] for i in split_idx["test"]]
    de, df = [], []
    for a in test:
        e, f, _ = labels(a)
        b = a.copy()
        b.calc = calc
        de.append((b.get_potential_energy() - e) / len(a))
        df.append((b.get_forces() - f).ravel())
    rmse_f = np.sqrt(np.mean(np.concatenate(df) ** 2)) * 1e3
    rmse_e = np.sqrt(np.mean(np.square(de))) * 1e3
    assert rmse_f == pytest.approx(
        report["errors"]["test"]["force_rmse_mev_per_angstrom"], rel=1e-6
    )
    assert rmse_e == pytest.approx(report["errors"]["test"]["energy_rmse_mev_per_atom"], rel=1e-6)


def _split(out):
    from flatcontact.training.dataset import read_dataset
    from flatcontact.training.fit import split_indices

    prov = json.loads((out / "provenance.json").read_text())
    frames = read_dataset(prov["dataset_file"])
    return split_indices([a.info["config_type"] for a in frames], prov["split_seed"])


def run_cli(args, capsys):
    """Run ``flatcontact ARGS``; return (exit status, stdout, stderr)."""
    from flatcontact.cli import main

    try:
        main(args)
        code = 0
    except SystemExit as exc:
        code = exc.code
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_cli_rejects_bad_dataset(tmp_path, capsys):
    from ase.io import write

    write(tmp_path / "bad.extxyz", [build_polymorph("alpha_quartz")], format="extxyz")
    code, _, err = run_cli(
        ["train-snap", "--data", str(tmp_path / "bad.extxyz"), "--out", str(tmp_path / "o")], capsys
    )
    assert code == 2
    assert "bad.extxyz frame 0: missing energy" in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o" / "snap.snapcoeff").exists()


def test_cli_needs_exactly_one_source(tmp_path, capsys):
    code, _, err = run_cli(["train-snap", "--out", str(tmp_path)], capsys)
    assert code == 2
    assert "exactly one of --data" in err


def test_cli_elastic_unknown_potential(capsys):
    code, _, err = run_cli(["elastic", "--potential", "no-such-potential"], capsys)
    assert code == 2
    assert "potential 'no-such-potential'" in err


def test_cli_elastic_json_vashishta(capsys):
    code, out, _ = run_cli(["elastic", "--potential", "vashishta", "--json"], capsys)
    assert code == 0
    data = json.loads(out)
    m = data["moduli_gpa"]
    assert m["g_star_paper"] == pytest.approx(4 * m["g_star_johnson"])
    assert data["a_angstrom"] == pytest.approx(4.829, abs=2e-3)
