"""The driver's row writer for ``points.db``: ASE's rows, with one prepared ``INSERT`` per point.

``ase.db`` writes a row (``SQLite3Database._write``) by rebuilding every column from the
row each time: the species, cell, pbc, mass, volume and data of a scan's rows never change
(every point has the reference's atoms in the reference's cell), yet each write recomputed
them, encoded them again and inserted the key-value pairs a second time into ASE's three key
tables (views in a store made by :mod:`flatcontact.ispes.store_schema`, whose triggers drop
those inserts). :class:`RowWriter` computes the constant columns once, from ASE's own row
of the reference (:class:`ase.db.row.AtomsRow` and the database's ``blob``/``encode``), and
per point only what changes: ``unique_id``, the time, the positions, the energy and the
key-value pairs (JSON, as ``ase.db`` encodes them). The row written is the row ``ase.db``
writes from ``Atoms(numbers, positions, cell, pbc)`` with a ``SinglePointCalculator(energy)``
and those key-value pairs, column for column and with the same ``species`` rows
(``tests/ispes/test_store_rows.py`` compares every column with a file ASE wrote itself).

Where the database is not the layout this writer knows (another ASE schema version or other
columns), :meth:`RowWriter.for_database` returns None and the store writes through ``ase.db``.
A store of the older layout (ASE's key tables as tables) gets the key tables' rows as ASE
writes them.
"""

from __future__ import annotations

import numbers
import os
import sqlite3
import uuid

import numpy as np
from ase import Atoms

#: The ``systems`` columns of ASE's database format 9 (``ase.db.sqlite``), in order; the
#: writer fills them and nothing else.
SYSTEMS_COLUMNS = (
    "id", "unique_id", "ctime", "mtime", "username", "numbers", "positions", "cell", "pbc",
    "initial_magmoms", "initial_charges", "masses", "tags", "momenta", "constraints",
    "calculator", "calculator_parameters", "energy", "free_energy", "forces", "stress",
    "dipole", "magmoms", "magmom", "charges", "key_value_pairs", "data", "natoms", "fmax",
    "smax", "volume", "mass", "charge",
)  # fmt: skip
#: ASE's database format this writer writes.
FORMAT_VERSION = 9
#: ASE's key tables (views of the rows' JSON in a new store).
KEY_TABLES = ("keys", "number_key_values", "text_key_values")


class RowWriter:
    """Writes the rows of one scan (atoms of ``reference``) into ``db`` (an open
    ``ase.db`` SQLite database on its one connection). Use :meth:`for_database`."""

    def __init__(self, db, reference: Atoms, key_tables: bool):
        from ase.db.row import AtomsRow

        template = {
            "numbers": reference.numbers,
            "positions": reference.positions,
            "calculator": "unknown",  # SinglePointCalculator.name
            "calculator_parameters": {},
        }
        if reference.pbc.any():
            template["pbc"] = reference.pbc
        if reference.cell.any():
            template["cell"] = reference.cell.array
        row = AtomsRow(template)
        blob = db.blob
        volume = row.get("volume")  # None for a cell of zero volume, as ASE's AttributeError
        self._user = os.getenv("USER")
        self._numbers = bytes(blob(row.numbers))
        self._n_atoms = len(row.numbers)
        self._cell = bytes(blob(row.cell))
        self._pbc = int(np.dot(row.pbc, [1, 2, 4]))
        self._calculator = (row.calculator, db.encode(row.calculator_parameters))
        self._data = db.encode(row._data, binary=True)
        self._tail = (
            self._n_atoms,
            None,  # fmax: no forces stored
            None,  # smax: no stress stored
            None if volume is None else float(volume),
            float(row.mass),
            float(row.charge),
        )
        self._species = [(_atomic_number(symbol), n) for symbol, n in row.count_atoms().items()]
        self._encode = db.encode
        self._key_tables = key_tables
        self._insert = (
            f"INSERT INTO systems VALUES (NULL, {', '.join('?' * (len(SYSTEMS_COLUMNS) - 1))})"
        )

    @classmethod
    def for_database(cls, db, reference: Atoms) -> RowWriter | None:
        """The writer for ``db``, or None where its layout is not ASE's format
        :data:`FORMAT_VERSION` with :data:`SYSTEMS_COLUMNS` (the store then writes through
        ``ase.db``). ``db`` holds its connection (``db.__enter__()``)."""
        con = db.connection
        try:
            columns = tuple(row[1] for row in con.execute("PRAGMA table_info(systems)"))
            kinds = dict(
                con.execute(
                    "SELECT name, type FROM sqlite_master WHERE name IN (?, ?, ?)", KEY_TABLES
                )
            )
        except sqlite3.Error:
            return None
        if db.version != FORMAT_VERSION or columns != SYSTEMS_COLUMNS:
            return None
        if set(kinds) != set(KEY_TABLES) or set(kinds.values()) - {"view", "table"}:
            return None
        return cls(db, reference, key_tables=any(kind == "table" for kind in kinds.values()))

    def write(
        self, con: sqlite3.Connection, positions: np.ndarray, energy_ev: float, kvp: dict
    ) -> int:
        """Insert the row of one point (positions in Å, energy in eV, the key-value pairs
        checked by the caller) on ``con``; its id."""
        from ase.db.core import now

        positions = np.ascontiguousarray(positions, dtype=float)
        if positions.shape != (self._n_atoms, 3):
            raise ValueError(f"positions of shape {positions.shape}; expected ({self._n_atoms}, 3)")
        if not np.little_endian:  # pragma: no cover - ASE stores little-endian blobs
            positions = positions.byteswap()
        mtime = now()
        values = (
            uuid.uuid4().hex,
            mtime,  # ctime: the row is new
            mtime,
            self._user,
            self._numbers,
            positions.tobytes(),
            self._cell,
            self._pbc,
            None,  # initial_magmoms
            None,  # initial_charges
            None,  # masses
            None,  # tags
            None,  # momenta
            None,  # constraints
            *self._calculator,
            float(energy_ev),
            None,  # free_energy
            None,  # forces
            None,  # stress
            None,  # dipole
            None,  # magmoms
            None,  # magmom
            None,  # charges
            self._encode(kvp),
            self._data,
            *self._tail,
        )
        cur = con.execute(self._insert, values)
        row_id = cur.lastrowid
        cur.executemany(
            "INSERT INTO species VALUES (?, ?, ?)", [(z, n, row_id) for z, n in self._species]
        )
        if self._key_tables:  # a store of ASE's own layout: its key tables, as ASE fills them
            text, number = [], []
            for key, value in kvp.items():
                if isinstance(value, (numbers.Real, np.bool_)):
                    number.append((key, float(value), row_id))
                else:
                    text.append((key, value, row_id))
            cur.executemany("INSERT INTO text_key_values VALUES (?, ?, ?)", text)
            cur.executemany("INSERT INTO number_key_values VALUES (?, ?, ?)", number)
            cur.executemany("INSERT INTO keys VALUES (?, ?)", [(key, row_id) for key in kvp])
        return row_id


def _atomic_number(symbol: str) -> int:
    from ase.data import atomic_numbers

    return atomic_numbers[symbol]
