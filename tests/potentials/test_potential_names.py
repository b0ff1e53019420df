"""One potential, one canonical name: every spelling that a command accepts resolves the same."""

import shutil

import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.potentials import InteractionModel
from flatcontact.potentials.files import BUNDLED_DIR
from flatcontact.potentials.names import normalize_potential_name, resolve_intra

BUNDLED = "sio2-snap"
needs_bundled = pytest.mark.skipif(
    not (BUNDLED_DIR / BUNDLED / f"{BUNDLED}.snapcoeff").is_file(), reason="no bundled SNAP"
)


@pytest.fixture()
def snap_copy(tmp_path):
    """A SNAP outside the package: X.snapcoeff + X.snapparam in tmp_path/p."""
    d = tmp_path / "p"
    d.mkdir()
    for ext in ("snapcoeff", "snapparam"):
        shutil.copy(BUNDLED_DIR / BUNDLED / f"{BUNDLED}.{ext}", d / f"X.{ext}")
    return d / "X.snapcoeff"


@needs_bundled
def test_bundled_spellings_agree():
    assert normalize_potential_name(BUNDLED) == normalize_potential_name(f"snap:{BUNDLED}")
    assert normalize_potential_name(f" {BUNDLED} ") == f"snap:{BUNDLED}"
    assert InteractionModel(intra=BUNDLED) == InteractionModel(intra=f"snap:{BUNDLED}")


@needs_bundled
def test_path_spellings_agree(snap_copy):
    forms = [str(snap_copy), f"snap:{snap_copy}", str(snap_copy.parent)]
    canonical = {normalize_potential_name(f) for f in forms}
    assert canonical == {f"snap:{snap_copy}"}
    files = {resolve_intra(f).files for f in forms}
    assert files == {(str(snap_copy), str(snap_copy.with_suffix(".snapparam")))}
    assert resolve_intra(str(snap_copy)).elements == ("Si", "O")


@needs_bundled
@pytest.mark.parametrize(
    "name", ["vashishta", "tersoff", "none", "ase:flatcontact.ispes.toy:toy_calculator", BUNDLED]
)
def test_normalize_is_idempotent(name):
    once = normalize_potential_name(name)
    assert normalize_potential_name(once) == once
    assert InteractionModel(intra=name).intra == once


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("reaxff", "unknown potential 'reaxff': expected vashishta, tersoff, snap:"),
        ("snap:", "expected a bundled SNAP name or a .snapcoeff path"),
        ("snap:nosuch", "no bundled SNAP named 'nosuch'"),
        ("/nonexistent/X.snapcoeff", "not found"),
        ("snap:/tmp/x.txt", "a SNAP path must end in .snapcoeff"),
    ],
)
def test_bad_names_are_one_line(name, message):
    with pytest.raises(InputError, match=message.replace("(", r"\(")):
        resolve_intra(name)


def test_directory_with_two_snapcoeffs_is_refused(tmp_path):
    for stem in ("a", "b"):
        (tmp_path / f"{stem}.snapcoeff").write_text("")
    with pytest.raises(InputError, match=r"holds 2 \.snapcoeff files"):
        normalize_potential_name(str(tmp_path))
