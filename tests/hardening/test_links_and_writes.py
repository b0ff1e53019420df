"""Writes and links: nothing is written through a symbolic link or outside --out, an empty
or over-long --out is one line before anything is touched, and temporary files of a killed
writer are swept by the next run (whose results equal an uninterrupted run's).

One toy study (seconds) is run once per module; each test works on a copy.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest
from tests.hardening.helpers import (
    assert_refused_cleanly,
    refused,
    run_cli,
    tree,
)
from tests.hardening.test_run_directory import _same_content

from flatcontact.ispes.geometry import thickness
from flatcontact.structures.interface_io import write_interface
from flatcontact.structures.toy import toy_interface

TOY = ["--calculator", "flatcontact.ispes.toy:toy_calculator"]
OUTPUTS = ("02-scan/ispes.nc", "03-analyze/friction.nc", "06-contact/summary.json")


@pytest.fixture(scope="module")
def finished(finished_toy):
    """(config folder, run directory) of one finished toy study (built once per process)."""
    return finished_toy


@pytest.fixture
def copy(finished, tmp_path):
    """(config, run directory, an outside folder holding a bait file) of a copy."""
    conf, run = finished
    shutil.copytree(conf, tmp_path / "conf")
    shutil.copytree(run, tmp_path / "run")
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "bait.txt").write_text("the user's file\n")
    return tmp_path / "conf" / "run.yaml", tmp_path / "run", outside


# ---- --out itself ------------------------------------------------------------------------


@pytest.mark.parametrize("command", ["run", "scan", "contact", "build"])
@pytest.mark.parametrize("value", ["", "  ", "x" * 256, "ok/" + "é" * 128])
def test_empty_or_over_long_out_is_one_line_touching_nothing(
    tmp_path, monkeypatch, capsys, command, value
):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "summary.json").write_text('{"mine": true}\n')
    assert_refused_cleanly([command, "--out", value], capsys, tmp_path, ["--out"])
    assert_refused_cleanly([command, f"--out={value}"], capsys, tmp_path, ["--out"])
    assert (tmp_path / "summary.json").read_text() == '{"mine": true}\n'


def test_over_long_input_file_name_is_one_line(tmp_path, capsys):
    config = tmp_path / ("c" * 300 + ".yaml")
    assert_refused_cleanly(["config", "--check", config], capsys, tmp_path, ["255 bytes"])


# ---- links planted in a run directory ------------------------------------------------------


@pytest.mark.parametrize(
    "name", [".flatcontact.lock", "run.log", ".report.html.tmp", "report.html", "03-analyze"]
)
def test_a_link_planted_in_the_run_directory_is_refused_and_its_target_kept(copy, capsys, name):
    config, run, outside = copy
    bait = outside / "bait.txt"
    if (run / name).is_dir():
        shutil.rmtree(run / name)
    (run / name).unlink(missing_ok=True)
    (run / name).symlink_to(bait)
    before, bait_stat = tree(outside), bait.stat()
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    refused(code, err, str(run / name), "symbolic link")
    assert tree(outside) == before
    assert (
        bait.read_text() == "the user's file\n" and bait.stat().st_mtime_ns == bait_stat.st_mtime_ns
    )


@pytest.mark.parametrize("stage", ["02-scan", "04-laws", "07-report"])
def test_a_stage_folder_that_is_a_link_is_refused_and_its_target_kept(copy, capsys, stage):
    config, run, outside = copy
    target = outside / stage
    shutil.move(run / stage, target)
    (run / stage).symlink_to(target)
    before = tree(outside)
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    refused(code, err, str(run / stage), "symbolic link")
    assert tree(outside) == before


@pytest.mark.parametrize("name", ["02-scan/points.db", "06-contact/summary.json"])
def test_a_link_inside_a_stage_folder_is_refused(copy, capsys, name):
    config, run, outside = copy
    bait = outside / "bait.txt"
    (run / name).unlink()
    (run / name).symlink_to(bait)
    before = tree(outside)
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    refused(code, err, str(run / name), "symbolic link")
    assert tree(outside) == before


@pytest.mark.parametrize("name", [".flatcontact.lock", "points.db", "points.db-wal"])
def test_a_link_planted_in_a_scan_out_is_refused(tmp_path, capsys, name):
    reference = toy_interface(layers=3)
    iface = write_interface(reference, tmp_path / "iface.extxyz")
    out = tmp_path / "out"
    out.mkdir()
    bait = tmp_path / "bait.txt"
    bait.write_text("keep\n")
    (out / name).symlink_to(bait)
    argv = ["scan", "--interface", iface, *TOY, "--grid", "2", "2"]
    argv += ["--thickness-angstrom", f"{thickness(reference):.4f}"]
    code, _, err = run_cli([*argv, "--out", out], capsys)
    refused(code, err, str(out / name), "symbolic link")
    assert bait.read_text() == "keep\n"
    assert {p.name for p in out.iterdir()} <= {name, ".flatcontact.lock"}


# ---- temporary files of a killed writer ------------------------------------------------------


def test_temporary_files_of_a_killed_run_are_swept_and_results_equal(copy, finished, capsys):
    """The state ``kill -9`` leaves in the scan and in the contact stage: records ``running``,
    half-written figures and files (``.<name>.<random>.part``) and a report copy in flight."""
    config, run, _ = copy
    for stage, stray in (
        ("02-scan", ".scan_columns.png.1a2b3c4d.part"),
        ("06-contact", ".contact.nc.5e6f7a8b.part"),
        ("06-contact", ".cycle.svg.9c0d1e2f.part"),
    ):
        record_path = run / stage / "stage.json"
        record = json.loads(record_path.read_text())
        record["state"] = "running"
        record.pop("outputs", None)
        record_path.write_text(json.dumps(record))
        (run / stage / stray).write_bytes(b"\x89PNG half a figure")
    (run / "06-contact" / "summary.json").unlink()
    (run / ".report.html.tmp").write_text("<html>half")
    (run / ".config.yaml.0badf00d.part").write_text("half")
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    assert code == 0, err
    left = [p for p in run.rglob("*") if p.name.endswith((".part", ".tmp"))]
    assert left == [], left
    for name in OUTPUTS:
        _same_content(run / name, finished[1] / name)


def test_a_failing_write_leaves_no_temporary_file(copy, monkeypatch, capsys):
    """An exception inside a stage's write (here: saving a figure) removes its ``.part``."""
    import matplotlib.figure

    config, run, _ = copy
    (run / "06-contact" / "summary.json").unlink()

    def broken(self, fname, *args, **kwargs):
        Path(fname).write_bytes(b"half")
        raise KeyboardInterrupt

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", broken)
    code, _, _ = run_cli(["run", config, "--out", run], capsys)
    assert code == 130
    assert [p for p in run.rglob("*") if p.name.endswith((".part", ".tmp"))] == []


def test_sweep_removes_only_hidden_temporary_files(tmp_path):
    from flatcontact.foundation.fileio import sweep_temporary

    for name in (".a.png.1234.part", "keep.part", ".report.html.tmp", "notes.tmp", "b.png"):
        (tmp_path / name).write_text("x")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / ".c.nc.abcd.part").write_text("x")
    removed = sweep_temporary(tmp_path)
    assert sorted(p.name for p in removed) == [".a.png.1234.part", ".report.html.tmp"]
    assert (tmp_path / "sub" / ".c.nc.abcd.part").exists()
    assert [p.name for p in sweep_temporary(tmp_path, recursive=True)] == [".c.nc.abcd.part"]
    assert sorted(os.listdir(tmp_path)) == ["b.png", "keep.part", "notes.tmp", "sub"]


def test_an_atomic_write_replaces_a_planted_link_instead_of_writing_through(tmp_path):
    from flatcontact.foundation.fileio import write_text_atomic

    bait = tmp_path / "bait.txt"
    bait.write_text("keep\n")
    (tmp_path / "out").mkdir()
    link = tmp_path / "out" / "summary.json"
    link.symlink_to(bait)
    write_text_atomic(link, "new\n")
    assert not link.is_symlink() and link.read_text() == "new\n"
    assert bait.read_text() == "keep\n"
    # a long target name still gets a temporary name within NAME_MAX
    write_text_atomic(tmp_path / "out" / ("n" * 255), "x")
    assert (tmp_path / "out" / ("n" * 255)).read_text() == "x"


def test_a_refused_command_leaves_the_folder_above_out_untouched(tmp_path, monkeypatch, capsys):
    """``--out`` is probed (created, written, removed) before the command fails later."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "parent").mkdir()
    before = (tmp_path / "parent").stat().st_mtime_ns
    argv = ["contact", "--experiment-csv", tmp_path / "missing.csv", "--out", "parent/new/run"]
    assert_refused_cleanly(argv, capsys, tmp_path, ["missing.csv"])
    assert (tmp_path / "parent").stat().st_mtime_ns == before
    assert list((tmp_path / "parent").iterdir()) == []
