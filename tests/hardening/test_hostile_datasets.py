"""Training sets that lie: ``train-snap --data`` and ``validate-potential --heldout`` read
extxyz through the checked structure reader
(:func:`flatcontact.structures.structure_file.read_structures`) before the labels: a frame
that claims 10¹² atoms, a NaN position or cell, overlapping atoms, a sliver cell or an
empty file is one ``error:`` line naming the file (and the frame), exit 2, no traceback,
nothing written outside ``--out`` and no ``--out`` created. A good set still reads."""

from __future__ import annotations

import numpy as np
import pytest
from ase.build import bulk
from tests.hardening.helpers import assert_refused_cleanly

from flatcontact.training.dataset import labelled, read_dataset, write_dataset


def _frame(a=5.43, shift=0.0):
    atoms = bulk("Si", "diamond", a=a) * (1, 1, 1)
    atoms.positions[1] += shift
    n = len(atoms)
    return labelled(atoms, -10.0 * n, np.zeros((n, 3)), np.zeros(6))


@pytest.fixture
def good(tmp_path):
    return write_dataset([_frame(), _frame(5.5)], tmp_path / "good.extxyz")


def _lines(path):
    return path.read_text().splitlines(keepends=True)


def _claims_many(path, tmp):
    lines = _lines(path)
    lines[0] = "1000000000000\n"
    return "".join(lines)


def _nan_position(path, tmp):
    lines = _lines(path)
    parts = lines[2].split()
    parts[1] = "nan"
    lines[2] = " ".join(parts) + "\n"
    return "".join(lines)


def _overlap(path, tmp):
    bad = tmp / "src.extxyz"
    atoms = _frame()
    atoms.positions[1] = atoms.positions[0] + [0.1, 0.0, 0.0]
    write_dataset([_frame(), atoms], bad)
    return bad.read_text()


def _sliver(path, tmp):
    lines = _lines(path)
    # Lattice="..." of the first frame: the third vector almost in the plane of the others
    head = lines[1]
    start = head.index('Lattice="') + len('Lattice="')
    end = head.index('"', start)
    lines[1] = head[:start] + "5 0 0 0 5 0 5 5 1e-6" + head[end:]
    return "".join(lines)


#: case -> (how the file is spoilt, words of the line besides the file)
CASES = {
    "claims-1e12-atoms": (_claims_many, "atoms claimed"),
    "nan-position": (_nan_position, "non-finite position"),
    "overlapping-atoms": (_overlap, "frame 1"),
    "sliver-cell": (_sliver, "degenerate cell"),
    "empty-file": (lambda path, tmp: "", "no frames"),
}


@pytest.mark.parametrize("case", sorted(CASES))
@pytest.mark.parametrize("command", ["train-snap", "validate-potential"])
def test_a_lying_training_set_is_one_line_naming_it(case, command, good, tmp_path, capsys):
    spoil, words = CASES[case]
    data = tmp_path / "data" / f"{case}.extxyz"
    data.parent.mkdir()
    data.write_text(spoil(good, tmp_path))
    out = tmp_path / "out"
    if command == "train-snap":
        argv = ["train-snap", "--data", data, "--out", out]
    else:
        argv = ["validate-potential", "vashishta", "--heldout", data]
    assert_refused_cleanly(argv, capsys, tmp_path, [str(data), words])
    assert not out.exists()


def test_a_good_training_set_still_reads(good):
    frames = read_dataset(good, ["Si"])
    assert len(frames) == 2 and frames[1].cell.lengths()[0] == pytest.approx(5.5 / 2**0.5)
