"""fileio.py: atomic writes, the file hash."""

import pytest


def test_atomic_write_leaves_usual_permissions_and_no_partial_file(tmp_path):
    import os
    import stat

    from flatcontact.fileio import atomic_path, write_text_atomic

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

    from flatcontact.fileio import file_sha256

    data = bytes(range(256)) * 9000  # more than one 1 MiB block
    path = tmp_path / "data.bin"
    path.write_bytes(data)
    assert file_sha256(path) == hashlib.sha256(data).hexdigest()
    (tmp_path / "empty").write_bytes(b"")
    assert file_sha256(tmp_path / "empty") == hashlib.sha256(b"").hexdigest()
