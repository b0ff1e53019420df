"""A study's directory keeps a run's rules: nothing written through a link planted at
``runs`` or at a variant's folder, one study writer per --out (a second is one line, not a
failed variant), one folder per variant whose name cannot collide or leave ``runs``."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest
from tests.hardening.helpers import refused, run_cli, tree
from tests.studies.toy import toy_data, toy_model, write_yaml

from flatcontact.foundation.errors import InputError
from flatcontact.studies.study_dir import folder_name, variant_folders


def _study_yaml(tmp_path):
    return write_yaml(
        tmp_path / "toy.yaml", toy_data(refine={"settings": ["thicknesses"], "max_steps": 1})
    )


@pytest.mark.parametrize("planted", ["runs", "runs/base", "runs/thicknesses1"])
def test_a_link_in_a_studys_runs_is_refused_before_anything_is_written(tmp_path, capsys, planted):
    conf = _study_yaml(tmp_path)
    out, outside = tmp_path / "study", tmp_path / "outside"
    outside.mkdir()
    (outside / "bait.txt").write_text("the user's\n")
    link = out / planted
    link.parent.mkdir(parents=True, exist_ok=True)
    link.symlink_to(outside)
    before = tree(outside)
    code, _, err = run_cli(["study", "convergence", conf, "--out", out], capsys)
    refused(code, err, str(link), "symbolic link")
    assert tree(outside) == before, "the study wrote through the link"
    assert not (out / "study.json").exists()


def test_a_second_study_on_the_same_out_is_one_line(tmp_path, capsys):
    """A real second process holds the study's lock (as a running study does)."""
    conf = _study_yaml(tmp_path)
    out = tmp_path / "study"
    out.mkdir()
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time; from flatcontact.foundation.rundir import RunLock; "
            "lock = RunLock(sys.argv[1]).acquire(); print('held', flush=True); time.sleep(60)",
            str(out),
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout.readline().strip() == "held"
        t0 = time.perf_counter()
        code, _, err = run_cli(["study", "convergence", conf, "--out", out], capsys)
        line = refused(code, err, str(out), f"pid {holder.pid}", "another flatcontact process")
        assert "failed" not in line
        assert time.perf_counter() - t0 < 20
        assert not (out / "runs").exists(), "a variant started"
    finally:
        holder.kill()
        holder.wait()


def test_variant_folders_cannot_collide_or_escape():
    labels = ["m a", "m_a", ".", "..", "a/b", "toy-a", "x" * 80]
    folders = variant_folders(labels)
    assert len(set(folders.values())) == len(labels)
    assert folders["toy-a"] == "toy-a" and folders["m_a"] == "m_a"
    for name in folders.values():
        assert name not in (".", "..") and not name.startswith(".") and "/" not in name
        assert len(name) <= 70
    assert folder_name("m a") == folder_name("m a")  # deterministic: a rerun finds its runs
    with pytest.raises(InputError, match=r"'A'.*'a'.*share the run folder"):
        variant_folders(["A", "a"])


@pytest.mark.slow
def test_models_named_alike_run_into_their_own_folders_inside_runs(tmp_path, capsys):
    """'m a.yaml' and 'm_a.yaml' (one slug before), '..yaml' (stem '.', the runs folder
    itself before): three models, three run directories, all inside runs."""
    conf = write_yaml(tmp_path / "toy.yaml", toy_data())
    names = ["m a.yaml", "m_a.yaml", "..yaml"]
    for name, eps in zip(names, (0.01, 0.02, 0.015), strict=True):
        write_yaml(tmp_path / name, {"potential": toy_model(eps)})
    out = tmp_path / "study"
    argv = ["study", "models", conf, "--out", out]
    for name in names:
        argv += ["--models", tmp_path / name]
    code, _, err = run_cli(argv, capsys)
    assert code == 0, err
    runs = sorted(p.name for p in (out / "runs").iterdir())
    assert len(runs) == 3 and "m_a" in runs, runs
    assert not (out / "runs" / "run.json").exists(), "a run was written into runs itself"
    for run in runs:
        assert (out / "runs" / run / "04-laws" / "laws.json").is_file()
