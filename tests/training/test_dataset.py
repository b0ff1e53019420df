"""Dataset validation: bad training sets are rejected before any work, naming file and frame."""

import numpy as np
import pytest
from ase import Atoms
from ase.io import write

from flatcontact.foundation.errors import InputError
from flatcontact.training.dataset import labelled, labels, read_dataset, write_dataset
from flatcontact.training.polymorphs import build_polymorph


def frame(seed=0, **changes):
    rng = np.random.default_rng(seed)
    a = build_polymorph("alpha_quartz")
    a.positions += rng.normal(0, 0.02, a.positions.shape)
    return labelled(a, -80.0 + seed, rng.normal(0, 0.1, (len(a), 3)), rng.normal(0, 1e-3, 6))


def test_round_trip(tmp_path):
    frames = [frame(k) for k in range(3)]
    for k, f in enumerate(frames):
        f.info["config_type"] = f"group{k}"
    path = write_dataset(frames, tmp_path / "d.extxyz")
    back = read_dataset(path, ["Si", "O"])
    assert [f.info["config_type"] for f in back] == ["group0", "group1", "group2"]
    for a, b in zip(frames, back, strict=True):
        ea, fa, sa = labels(a)
        eb, fb, sb = labels(b)
        assert ea == pytest.approx(eb)
        np.testing.assert_allclose(fa, fb, atol=1e-7)
        np.testing.assert_allclose(sa, sb, atol=1e-9)


def test_missing_forces(tmp_path):
    bad = build_polymorph("alpha_quartz")
    from ase.calculators.singlepoint import SinglePointCalculator

    bad.calc = SinglePointCalculator(bad, energy=-80.0)
    path = tmp_path / "noforces.extxyz"
    write(path, [frame(0), bad], format="extxyz")
    with pytest.raises(InputError, match=r"noforces.extxyz frame 1: missing forces"):
        read_dataset(path, ["Si", "O"])


def test_missing_energy(tmp_path):
    path = tmp_path / "noenergy.extxyz"
    write(path, [build_polymorph("alpha_quartz")], format="extxyz")
    with pytest.raises(InputError, match=r"frame 0: missing energy"):
        read_dataset(path, ["Si", "O"])


def test_unknown_element(tmp_path):
    a = frame(1)
    b = Atoms("SiOH", positions=[[0, 0, 0], [1.6, 0, 0], [3.0, 1.0, 0]], cell=[8, 8, 8], pbc=True)
    b = labelled(b, -10.0, np.zeros((3, 3)), np.zeros(6))
    path = write_dataset([a, b], tmp_path / "h.extxyz")
    with pytest.raises(InputError, match=r"h.extxyz frame 1: unknown element\(s\) \['H'\]"):
        read_dataset(path, ["Si", "O"])


def test_inconsistent_cell(tmp_path):
    """Positions that the cell makes overlap (a cell shrunk without scaling atoms)."""
    a = frame(2)
    a.set_cell(a.cell * 0.3, scale_atoms=False)
    path = write_dataset([frame(0), a], tmp_path / "cell.extxyz")
    with pytest.raises(InputError, match=r"cell.extxyz frame 1: atoms .* apart"):
        read_dataset(path, ["Si", "O"])


def test_degenerate_or_nonperiodic_cell(tmp_path):
    a = frame(3)
    a.pbc = [True, True, False]
    path = write_dataset([a], tmp_path / "pbc.extxyz")
    with pytest.raises(InputError, match=r"frame 0: pbc="):
        read_dataset(path)


def test_wrong_force_shape_and_missing_file(tmp_path):
    with pytest.raises(InputError, match="not found"):
        read_dataset(tmp_path / "nope.extxyz")
    a = frame(4)
    a.calc.results["forces"] = np.zeros((3, 3))
    from flatcontact.training.dataset import validate_frame

    with pytest.raises(InputError, match=r"x frame 0: forces have shape \(3, 3\)"):
        validate_frame(a, "x frame 0")
