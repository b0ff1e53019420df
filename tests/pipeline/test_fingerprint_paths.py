"""A measured file enters the contact stage's fingerprint by its name and content, never by
its folder: moving a configuration folder reruns nothing (rundir.portable)."""

import shutil

import pytest

from flatcontact.config import build_config
from flatcontact.stages import fingerprints


@pytest.fixture
def measured_csv(tmp_path):
    """A two-column measured stiffness curve (contact/measured.py's format)."""
    rows = "\n".join(f"{s:.1f},{800.0 - 20.0 * s:.1f}" for s in range(1, 20))
    path = tmp_path / "measured.csv"
    path.write_text("mean_shear_stress_mpa,lateral_stiffness_n_per_m\n" + rows + "\n")
    return path


def _contact_inputs(csv):
    cfg = build_config({"contact": {"experiment": {"csv": str(csv)}, "fit": {"csv": [str(csv)]}}})
    return fingerprints.contact(cfg)


def test_moving_the_measured_files_keeps_the_contact_fingerprint(tmp_path, measured_csv):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    shutil.copy(measured_csv, a / "m.csv")
    shutil.copy(measured_csv, b / "m.csv")
    here, there = _contact_inputs(a / "m.csv"), _contact_inputs(b / "m.csv")
    assert here == there
    assert str(tmp_path) not in repr(here)


def test_other_content_changes_the_contact_fingerprint(tmp_path, measured_csv):
    (tmp_path / "m.csv").write_text(measured_csv.read_text() + "\n", encoding="utf-8")
    assert _contact_inputs(tmp_path / "m.csv") != _contact_inputs(measured_csv)
