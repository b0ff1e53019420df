"""fileio.py: atomic writes, the file hash."""

import os

import pytest


def test_atomic_write_leaves_usual_permissions_and_no_partial_file(tmp_path):
    import os
    import stat

    from flatcontact.foundation.fileio import atomic_path, write_text_atomic

    mask = os.umask(0o022)
    try:
        path = write_text_atomic(tmp_path / "out.txt", "x")
        assert stat.S_IMODE(path.stat().st_mode) == 0o644
        with pytest.raises(RuntimeError), atomic_path(tmp_path / "never.txt") as tmp:
            tmp.write_text("half")
            raise RuntimeError("interrupted")
    finally:
        os.umask(mask)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]


def test_file_sha256_is_the_sha256_of_the_bytes_read_in_blocks(tmp_path):
    import hashlib

    from flatcontact.foundation.fileio import file_sha256

    data = bytes(range(256)) * 9000  # more than one 1 MiB block
    path = tmp_path / "data.bin"
    path.write_bytes(data)
    assert file_sha256(path) == hashlib.sha256(data).hexdigest()
    (tmp_path / "empty").write_bytes(b"")
    assert file_sha256(tmp_path / "empty") == hashlib.sha256(b"").hexdigest()


def test_link_file_atomic_stores_the_bytes_once_and_replaces_a_planted_link(tmp_path, monkeypatch):
    import os

    from flatcontact.foundation.fileio import link_file_atomic, write_text_atomic

    src = write_text_atomic(tmp_path / "stage" / "report.html", "<html>1</html>")
    elsewhere = tmp_path / "elsewhere.html"
    elsewhere.write_text("not mine")
    target = tmp_path / "report.html"
    target.symlink_to(elsewhere)  # planted: replaced, not written through
    link_file_atomic(src, target)
    assert not target.is_symlink() and os.path.samefile(src, target)
    assert src.stat().st_nlink == 2 and elsewhere.read_text() == "not mine"
    link_file_atomic(src, target)  # again: the same link, no temporary left behind
    assert os.path.samefile(src, target)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["elsewhere.html", "report.html", "stage"]
    # a rewrite of the stage's file (atomic: a new file) leaves the old link's bytes alone
    write_text_atomic(src, "<html>2</html>")
    assert target.read_text() == "<html>1</html>"
    # a filesystem without hard links: a copy
    monkeypatch.setattr(os, "link", lambda *a, **k: (_ for _ in ()).throw(PermissionError()))
    link_file_atomic(src, target)
    assert target.read_text() == "<html>2</html>" and not os.path.samefile(src, target)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["elsewhere.html", "report.html", "stage"]


def test_an_interruption_between_creating_a_temporary_file_and_guarding_it_leaves_none(
    tmp_path, monkeypatch
):
    """SIGTERM (raised as an exception) or Ctrl-C can arrive between the temporary file's
    creation and the ``try`` that would remove it; the file is registered before it exists, so
    ``remove_live_temporaries`` (run by the command line on an interruption) removes it."""
    from flatcontact.foundation import fileio

    real = fileio._open_checked

    def created_then_interrupted(path, flags, mode):
        os.close(real(path, flags, mode))
        raise KeyboardInterrupt

    monkeypatch.setattr(fileio, "_open_checked", created_then_interrupted)
    with pytest.raises(KeyboardInterrupt), fileio.atomic_path(tmp_path / "out.txt"):
        pass
    left = sorted(p.name for p in tmp_path.iterdir())
    assert len(left) == 1 and left[0].startswith(".out.txt.") and left[0].endswith(".part")
    monkeypatch.setattr(fileio, "_open_checked", real)
    assert fileio.remove_live_temporaries() == [tmp_path / left[0]]
    assert list(tmp_path.iterdir()) == []
    # a completed and a failed write leave nothing registered
    fileio.write_text_atomic(tmp_path / "done.txt", "x")
    with pytest.raises(ValueError), fileio.atomic_path(tmp_path / "failed.txt"):
        raise ValueError("the writer failed")
    assert fileio._LIVE_TEMPORARIES == set()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["done.txt"]
