"""Hostile input files: a YAML billion laughs and structure files that lie (a claimed 10¹²
atoms, random overlapping atoms, NaN positions, sliver and huge skewed cells, no atoms).

Each is refused in seconds with exit 2 and one ``error:`` line naming the file, before
anything is written (the folder holding --out stays as it was).
"""

from __future__ import annotations

import numpy as np
import pytest
from ase import Atoms
from ase.io import write
from tests.hardening.helpers import assert_refused_cleanly

from flatcontact.structures.structure_file import (
    MAX_LENGTH_ANGSTROM,
    MIN_CELL_HEIGHT_ANGSTROM,
    MIN_DISTANCE_ANGSTROM,
)


def _laughs(levels: int = 9) -> str:
    """The classic billion-laughs document: 9 aliases of 9 aliases ... (9**levels leaves)."""
    lines = ['l0: &l0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for k in range(1, levels):
        lines.append(f"l{k}: &l{k} [" + ", ".join([f"*l{k - 1}"] * 9) + "]")
    return "\n".join(lines) + "\n"


@pytest.mark.timeout(60)
@pytest.mark.parametrize("command", [["config", "--check"], ["run"]])
def test_billion_laughs_is_one_line_before_any_work(tmp_path, capsys, command):
    conf = tmp_path / "laughs.yaml"
    conf.write_text(_laughs())
    out = tmp_path / "out"
    argv = [*command, conf] + (["--out", out] if command == ["run"] else [])
    line = assert_refused_cleanly(argv, capsys, tmp_path, [str(conf), "aliases"], out)
    assert "100000" in line


@pytest.mark.timeout(60)
def test_an_alias_inside_its_own_anchor_is_one_line(tmp_path, capsys):
    conf = tmp_path / "loop.yaml"
    conf.write_text("scan: &s {grid: [3, 3], again: *s}\n")
    assert_refused_cleanly(["config", "--check", conf], capsys, tmp_path, [str(conf), "alias"])


def test_a_few_plain_aliases_are_still_read(tmp_path, capsys):
    from flatcontact.config.yaml_io import parse_yaml

    data = parse_yaml("a: &p [0.5, 1.0]\nb: *p\n", "c.yaml")
    assert data == {"a": [0.5, 1.0], "b": [0.5, 1.0]}


# ---- structure files ---------------------------------------------------------------------


def _slab(n_xy: int = 2) -> Atoms:
    """A simple-square two-layer slab (2.5 Å spacing) in a cell with 10 Å vacuum."""
    a, d = 2.5, 2.5
    pos = [(i * a, j * a, 10.0 + k * d) for i in range(n_xy) for j in range(n_xy) for k in (0, 1)]
    return Atoms("Cu" * len(pos), positions=pos, cell=[n_xy * a, n_xy * a, 20.0 + d], pbc=True)


def _write(path, atoms, fmt):
    write(path, atoms, format="vasp" if fmt == "vasp" else "extxyz")


def _claims_too_many(path, fmt):
    path.write_text(
        '1000000000000\nLattice="5 0 0 0 5 0 0 0 20" Properties=species:S:1:pos:R:3\nCu 0 0 0\n'
    )


def _random_atoms(path, fmt):
    rng = np.random.default_rng(0)
    atoms = Atoms("Cu20000", positions=rng.random((20000, 3)) * 60.0, cell=[60.0] * 3, pbc=True)
    _write(path, atoms, fmt)


def _nan_position(path, fmt):
    atoms = _slab()
    atoms.positions[3, 2] = np.nan
    write(path, atoms, format="extxyz")


def _sliver_cell(path, fmt):
    atoms = _slab()
    atoms.set_cell([[5.0, 0, 0], [5.0, 1e-9, 0], [0, 0, 22.5]], scale_atoms=False)
    _write(path, atoms, fmt)


def _huge_skewed_cell(path, fmt):
    atoms = _slab()
    atoms.set_cell([[5.0, 0, 0], [1e7, 5.0, 0], [0, 0, 22.5]], scale_atoms=False)
    _write(path, atoms, fmt)


def _no_atoms(path, fmt):
    path.write_text('0\nLattice="5 0 0 0 5 0 0 0 20" Properties=species:S:1:pos:R:3\n')


def _overlapping(path, fmt):
    atoms = _slab()
    atoms.positions[1] = atoms.positions[0] + [0.1, 0.0, 0.0]
    _write(path, atoms, fmt)


#: name -> (writer, words of the refusal)
HOSTILE = {
    "claims_1e12_atoms": (_claims_too_many, "atoms claimed"),
    "random_20000": (_random_atoms, "overlapping"),
    "nan_position": (_nan_position, "non-finite position"),
    "sliver_cell": (_sliver_cell, "degenerate cell"),
    "huge_skewed_cell": (_huge_skewed_cell, "spans"),
    "no_atoms": (_no_atoms, "no atoms"),
    "overlapping": (_overlapping, "overlapping"),
}


@pytest.mark.timeout(60)
@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_hostile_structure_file_in_build_is_one_line(tmp_path, capsys, name):
    make, defect = HOSTILE[name]
    vasp = name in ("random_20000", "sliver_cell", "huge_skewed_cell", "overlapping")
    bad = tmp_path / (f"POSCAR_{name}" if vasp else f"{name}.extxyz")
    make(bad, "vasp" if vasp else "extxyz")
    out = tmp_path / "out"
    assert_refused_cleanly(
        ["build", "--structure", bad, "--out", out], capsys, tmp_path, [str(bad), defect], out
    )


@pytest.mark.timeout(60)
@pytest.mark.parametrize("kind", ["slab", "file"])
@pytest.mark.parametrize("name", sorted(HOSTILE))
def test_hostile_structure_file_in_config_check_is_one_line(tmp_path, capsys, name, kind):
    make, defect = HOSTILE[name]
    bad = tmp_path / f"{name}.extxyz"
    make(bad, "extxyz")
    conf = tmp_path / "run.yaml"
    conf.write_text(f"structure: {{kind: {kind}, file: '{bad}'}}\n")
    assert_refused_cleanly(
        ["config", "--check", conf], capsys, tmp_path, [str(bad), defect, "structure.file"]
    )


def test_the_bounds_are_stated_and_leave_real_solids_alone():
    """Shortest bond (H2 0.74 Å) above the minimum distance; a copper slab passes."""
    from flatcontact.structures.structure_file import check_structure

    assert MIN_DISTANCE_ANGSTROM < 0.74 < MIN_CELL_HEIGHT_ANGSTROM * 2
    assert MAX_LENGTH_ANGSTROM >= 500.0
    check_structure(_slab(4), "slab")
    h2 = Atoms("H2", positions=[(0, 0, 0), (0, 0, 0.74)])
    check_structure(h2, "h2")
