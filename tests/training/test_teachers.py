"""The one registry of offline teachers (flatcontact.potentials.teachers); no torch needed."""

import importlib

import pytest
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.foundation.errors import InputError
from flatcontact.potentials import teachers as reg

#: What each registered teacher must say about itself: (package, checkpoint, head, functional).
EXPECTED = {
    "chgnet-r2scan": ("chgnet", "r2scan", None, "r2SCAN"),
    "sevennet-0": ("sevenn", "7net-0", None, "PBE"),
    "sevennet-mf-0-r2scan": ("sevenn", "7net-mf-0", "R2SCAN", "r2SCAN"),
    "sevennet-mf-0-pbe": ("sevenn", "7net-mf-0", "PBE", "PBE"),
}


def test_registry_holds_the_measured_teachers_with_their_metadata():
    assert set(reg.TEACHERS) == set(EXPECTED)
    for name, (package, model, head, functional) in EXPECTED.items():
        t = reg.TEACHERS[name]
        assert t.name == name
        assert (t.package, t.model, t.head, t.functional) == (package, model, head, functional)
        # a multi-fidelity head names the DFT level of its labels
        assert t.head is None or t.head.lower() == t.functional.lower()
        meta = reg.teacher_info(name)
        assert meta["teacher"] == name and meta["factory"] == t.factory
        assert f"{package}_version" in meta and "torch_version" in meta
        # the factory is a real, importable no-argument callable (nothing is constructed here)
        module, _, attr = t.factory.partition(":")
        fn = getattr(importlib.import_module(module), attr)
        assert callable(fn)


def test_alias_chgnet_is_the_r2scan_model():
    assert reg.get_teacher("chgnet") is reg.TEACHERS["chgnet-r2scan"]
    assert reg.is_teacher(" chgnet ") and not reg.is_teacher("sio2-snap")


def test_unknown_teacher_is_refused_in_one_line_naming_the_field():
    with pytest.raises(InputError) as info:
        reg.get_teacher("mace-mp-0", "--label")
    msg = str(info.value)
    assert "\n" not in msg and msg.startswith("--label 'mace-mp-0'")
    for name in EXPECTED:
        assert name in msg


def test_train_snap_refuses_unknown_teacher_before_any_work(tmp_path, capsys):
    out = tmp_path / "never"
    code, _, err = run_cli(
        ["train-snap", "--recipe", "sio2", "--label", "mace", "--out", str(out)], capsys
    )
    line = one_error_line(code, err)
    assert "--label 'mace'" in line and "sevennet-mf-0-r2scan" in line
    assert not out.exists()

    from flatcontact.training.train import train_snap

    with pytest.raises(InputError, match="--label 'mace'"):
        train_snap(out, recipe="sio2", label="mace")
    assert not out.exists()


def test_every_consumer_resolves_teachers_through_the_registry():
    """ISPES specs, bulk potentials and labelling see the same names and factories."""
    from flatcontact.potentials.names import snapcoeff_path
    from flatcontact.training import ispes_check, label

    assert ispes_check.TEACHERS is reg.TEACHERS and label.TEACHERS is reg.TEACHERS
    assert label.teacher_calculator is reg.teacher_calculator
    for name, t in reg.TEACHERS.items():
        assert ispes_check.teacher_spec(name).intra == f"ase:{t.factory}"
        assert snapcoeff_path(name) is None  # a teacher, not a SNAP file
    assert (
        ispes_check.teacher_spec("chgnet").intra == f"ase:{reg.TEACHERS['chgnet-r2scan'].factory}"
    )


def test_validate_potential_reference_lists_the_teachers_when_unknown(capsys):
    code, _, err = run_cli(["validate-potential", "sio2-snap", "--reference", "mace"], capsys)
    line = one_error_line(code, err)
    assert line.startswith("error: --reference") and "'mace'" in line
    assert all(name in line for name in EXPECTED)
