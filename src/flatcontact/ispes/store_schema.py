"""The file layout of a new ``points.db``: ASE's database, stored without its duplicates.

``ase.db`` keeps a row's key-value pairs twice: as JSON in the row itself
(``systems.key_value_pairs``, what ASE reads back) and again, one row per key, in three
tables for its queries (``keys``, ``number_key_values``, ``text_key_values``), with an
index on each, besides indexes on ``unique_id`` (twice), ``ctime``, ``username``,
``calculator`` and ``species``. On the default run (2,160 points of 36 atoms, 14 keys a
row) those copies and indexes took 2.8 of its 7.4 MB.

A new store therefore gets (:func:`create`, then :func:`replace_key_tables` once ASE has
made its tables):

- 8 kB pages (:data:`PAGE_SIZE`): a row (≈ 1.5 kB, its positions 864 bytes) left a quarter
  of each 4 kB page empty;
- none of ASE's optional indexes (``ase.db.connect(..., create_indices=False)``);
- the three key tables as views of the rows' own JSON (SQLite's ``json_each``), with
  ``INSTEAD OF`` triggers that drop writes into them (ASE's inserts and deletes, any
  update: the row's JSON is what they show): ASE's queries
  (``ase db points.db i_z=3``, ``db.select(i_a=4)``, a bare key) read the views and find what
  they found in the tables, and ASE writes its rows as before. Where this SQLite has no JSON
  functions the tables stay as ASE made them (a bigger file, the same behaviour).

A store made before keeps its layout; both are ASE databases, row for row.

A store is read (:func:`stored_rows`) on one connection, closed when the rows are read: a
query of ``ase.db`` outside its ``with`` leaves its connection to the garbage collector (a
``sqlite3`` connection is a reference cycle), and while one is open SQLite keeps
``points.db-wal`` and ``-shm`` beside the store; closing the last one folds the log into
the file and removes both.
"""

from __future__ import annotations

import sqlite3
from collections.abc import Iterator
from pathlib import Path
from typing import Any

#: SQLite page size of a new store (bytes).
PAGE_SIZE = 8192

#: ASE's key tables as views of ``systems.key_value_pairs`` (ASE stores True as 1.0 among the
#: numbers; JSON's ``true`` reads as 1).
_VIEWS = {
    "keys": "SELECT j.key AS key, s.id AS id",
    "number_key_values": "SELECT j.key AS key, j.value AS value, s.id AS id",
    "text_key_values": "SELECT j.key AS key, j.value AS value, s.id AS id",
}
_TYPES = {
    "keys": "",
    "number_key_values": " AND j.type IN ('integer', 'real', 'true', 'false')",
    "text_key_values": " AND j.type = 'text'",
}


def create(path: Path) -> None:
    """Create an empty file with :data:`PAGE_SIZE` pages in write-ahead-log mode (a page
    size is fixed when a file is first written: here, before ``ase.db`` makes its tables)."""
    con = sqlite3.connect(str(path))
    try:
        con.execute(f"PRAGMA page_size={PAGE_SIZE}")
        con.execute("PRAGMA journal_mode=WAL")  # writes the header: the page size is kept
    finally:
        con.close()


def has_json(con: sqlite3.Connection) -> bool:
    """Whether this SQLite has the JSON functions (built in since 3.38)."""
    try:
        con.execute("SELECT json_each.key FROM json_each('{\"a\": 1}')").fetchall()
    except sqlite3.OperationalError:
        return False
    return True


def replace_key_tables(path: Path) -> bool:
    """In a new, empty store made by ``ase.db``: ASE's three key tables become views of the
    rows' JSON (module docstring). Returns False, leaving the tables, where SQLite has no
    JSON functions or the store already holds rows."""
    con = sqlite3.connect(str(path), isolation_level=None)
    try:
        if not has_json(con) or con.execute("SELECT COUNT(*) FROM systems").fetchone()[0]:
            return False
        statements = ["BEGIN"]
        for name, select in _VIEWS.items():
            statements += [
                f"DROP TABLE {name}",
                f"CREATE VIEW {name} AS {select} FROM systems AS s, json_each(CASE WHEN "
                "json_valid(s.key_value_pairs) THEN s.key_value_pairs ELSE '{}' END) AS j "
                f"WHERE 1{_TYPES[name]}",
                f"CREATE TRIGGER {name}_insert INSTEAD OF INSERT ON {name} "
                "BEGIN SELECT RAISE(IGNORE); END",
                f"CREATE TRIGGER {name}_delete INSTEAD OF DELETE ON {name} "
                "BEGIN SELECT RAISE(IGNORE); END",
                f"CREATE TRIGGER {name}_update INSTEAD OF UPDATE ON {name} "
                "BEGIN SELECT RAISE(IGNORE); END",
            ]
        con.executescript(";\n".join([*statements, "COMMIT"]) + ";")
    finally:
        con.close()
    return True


def stored_rows(path: str | Path) -> Iterator[Any]:
    """Every row of the point store at ``path`` (``ase.db`` rows, in id order), read on one
    connection that is closed when the rows are read or the iteration is given up (module
    docstring): no ``-wal``, ``-shm`` left by the reader."""
    import ase.db

    db = ase.db.connect(str(path), type="db", use_lock_file=False)
    with db:
        yield from db.select()
