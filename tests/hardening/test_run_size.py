"""A run directory a user can keep (issue 33): nothing stored twice.

The default run's size itself (at most 10 MB, report.html at most 2 MB) is measured by
``python -m benchmarks run`` and its record checked in tests/pipeline/test_benchmark_record.py;
here the finished toy run shows the layout that keeps it there.
"""

from __future__ import annotations

import hashlib
import os
import sqlite3

#: Files at least this large are checked for a second copy of their bytes.
LARGE_BYTES = 16_384


def test_no_large_file_is_stored_twice_and_the_report_is_one_file(finished_toy):
    _, run = finished_toy
    assert os.path.samefile(run / "report.html", run / "07-report" / "report.html")
    seen: dict[str, tuple] = {}
    for path in sorted(p for p in run.rglob("*") if p.is_file() and not p.is_symlink()):
        st = path.stat()
        if st.st_size < LARGE_BYTES:
            continue
        digest = hashlib.sha256(path.read_bytes()).hexdigest()
        inode = (st.st_dev, st.st_ino)
        if digest in seen:
            other, other_inode = seen[digest]
            assert other_inode == inode, f"{path} repeats the bytes of {other}"
        seen[digest] = (path, inode)
    assert len(seen) >= 3  # the check saw the large files (points.db, report, figures)


def test_the_point_store_keeps_each_key_value_once(finished_toy):
    _, run = finished_toy
    con = sqlite3.connect(f"file:{run / '02-scan' / 'points.db'}?mode=ro", uri=True)
    try:
        kinds = dict(con.execute("SELECT name, type FROM sqlite_master"))
        rows = con.execute("SELECT COUNT(*) FROM systems").fetchone()[0]
        pairs = con.execute("SELECT COUNT(*) FROM number_key_values").fetchone()[0]
    finally:
        con.close()
    assert kinds["keys"] == kinds["number_key_values"] == kinds["text_key_values"] == "view"
    assert [k for k, t in kinds.items() if t == "index"] == ["sqlite_autoindex_systems_1"]
    # the views read the rows: 13 numbers (bool included) and one text per point
    assert rows > 0 and pairs == 13 * rows
