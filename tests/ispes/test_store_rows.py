"""The driver's store rows: built directly, batched into one transaction, committed on SIGTERM.

``PointStore.write`` builds the ASE row itself (no ``Atoms`` + ``SinglePointCalculator`` for
``ase.db`` to take apart) and commits at most every ``commit_interval_s``; the rows must be
the ones ASE itself writes from the atoms, the batched store must hold the same rows as the
unbatched one, and a kill loses only what was not yet committed.
"""

import json
import signal
import sqlite3
import subprocess
import sys
import textwrap
import uuid

import ase.db
import numpy as np
import pytest
from ase import Atoms
from ase.calculators.singlepoint import SinglePointCalculator

from flatcontact.ispes.relax import PointResult
from flatcontact.ispes.store import PointStore
from flatcontact.ispes.store_schema import stored_rows
from flatcontact.structures.toy import toy_interface

COLUMNS = (
    "numbers", "positions", "cell", "pbc", "energy", "calculator",
    "calculator_parameters", "key_value_pairs",
)  # fmt: skip


def _result(ref, k, n=12):
    return PointResult(
        index=(k % n, k // n, 0),
        shift_a=(k % n) / n,
        shift_b=(k // n) / n,
        thickness=10.0 + 0.1 * k,
        energy_ev=-1.0 - k / 7,
        normal_stress_gpa=0.5 - k / 9,
        reaction_stress_gpa=0.01 * k,
        force_calls=10 + k,
        steps=9 + k,
        converged=k % 5 != 3,
        max_force_ev_per_a=1e-4 * k,
        seconds=0.1 * k,
        positions=ref.positions + 1e-3 * k,
        start_index=((k - 1) % n, (k - 1) // n, 0) if k else None,
    )


def _ase_rows(path):
    """Every row's columns as ASE reads them, by grid index."""
    out = {}
    for row in stored_rows(path):  # one connection, closed after: no -wal left beside
        out[(row.i_a, row.i_b, row.i_z)] = {key: row.get(key) for key in COLUMNS}
    return out


def _assert_same_rows(a, b):
    assert a.keys() == b.keys()
    for index in a:
        for key in COLUMNS:
            x, y = a[index][key], b[index][key]
            if isinstance(x, np.ndarray):
                np.testing.assert_array_equal(x, y, err_msg=f"{index} {key}")
            else:
                assert x == y, (index, key)


def _kvp(r):
    """The key-value pairs of a point as written independently of the store."""
    return {
        "i_a": r.index[0], "i_b": r.index[1], "i_z": r.index[2],
        "shift_a": r.shift_a, "shift_b": r.shift_b, "thickness": r.thickness,
        "normal_stress_gpa": r.normal_stress_gpa,
        "reaction_stress_gpa": r.reaction_stress_gpa, "force_calls": r.force_calls,
        "steps": r.steps, "converged": bool(r.converged),
        "max_force_ev_per_a": r.max_force_ev_per_a, "seconds": r.seconds,
        "start": ",".join(map(str, r.start_index)) if r.start_index else "",
    }  # fmt: skip


def _written_by_ase(path, ref, n: int):
    """The first ``n`` points of :func:`_result` written by ase.db itself, from Atoms and a
    SinglePointCalculator, into ``path``; the database."""
    plain = ase.db.connect(str(path))
    for k in range(n):
        r = _result(ref, k)
        atoms = Atoms(numbers=ref.numbers, positions=r.positions, cell=ref.cell, pbc=ref.pbc)
        atoms.calc = SinglePointCalculator(atoms, energy=r.energy_ev)
        plain.write(atoms, key_value_pairs=_kvp(r))
    return plain


def test_rows_are_the_ones_ase_writes_from_the_atoms(tmp_path):
    """Independent: the same points written by ase.db from Atoms + SinglePointCalculator."""
    ref = toy_interface(layers=3)
    with PointStore(tmp_path / "points.db", {"test": "rows"}, ref) as store:
        for k in range(30):
            store.write(_result(ref, k))
    plain = _written_by_ase(tmp_path / "plain.db", ref, 30)
    ours, theirs = _ase_rows(tmp_path / "points.db"), _ase_rows(tmp_path / "plain.db")
    _assert_same_rows(ours, theirs)
    # the key tables too: ase.db's queries by key find the same rows
    db = ase.db.connect(str(tmp_path / "points.db"))
    assert db.count("i_a=3,converged=True") == plain.count("i_a=3,converged=True") > 0
    assert db.count("thickness>11.5") == plain.count("thickness>11.5") > 0
    assert db.get(i_a=4, i_b=1).toatoms() == plain.get(i_a=4, i_b=1).toatoms()


#: columns that differ between any two writes (a random id, the time of writing)
VOLATILE = ("id", "unique_id", "ctime", "mtime")


def _raw(path):
    """Every column of every row of ``systems`` (raw SQLite values, by grid index) and the
    ``species`` rows, as stored: what any reader of the file sees."""
    with sqlite3.connect(str(path)) as con:
        con.row_factory = sqlite3.Row
        rows = {}
        for row in con.execute("SELECT * FROM systems"):
            kvp = json.loads(row["key_value_pairs"])
            rows[(kvp["i_a"], kvp["i_b"], kvp["i_z"])] = dict(row)
        species = {}
        for z, n, row_id in con.execute("SELECT Z, n, id FROM species ORDER BY rowid"):
            species.setdefault(row_id, []).append((z, n))
    con.close()
    return rows, species


@pytest.mark.parametrize("layout", ["store", "ase"])
def test_every_column_and_species_row_is_the_one_ase_writes(tmp_path, layout, monkeypatch):
    """Column for column (raw SQLite values: blobs, JSON text, the derived natoms, volume,
    mass, charge, data) and species row for species row, the store's rows are those ase.db
    writes from Atoms + SinglePointCalculator, except the random id and the write time; in
    the store's layout and in ASE's own (key tables as tables, filled as ASE fills them)."""
    from flatcontact.ispes import store_schema

    if layout == "ase":  # a store of the older layout: ASE's key tables are tables
        monkeypatch.setattr(store_schema, "replace_key_tables", lambda path: False)
    ref = toy_interface(layers=3)
    ref.set_tags(np.arange(len(ref)) % 3)  # the reference's own arrays stay out of the rows
    with PointStore(tmp_path / "points.db", {"test": "raw"}, ref) as store:
        assert store._rows is not None  # the prepared writer, not ase.db's
        for k in range(12):
            store.write(_result(ref, k))
    _written_by_ase(tmp_path / "plain.db", ref, 12)
    (ours, our_species), (theirs, their_species) = (
        _raw(tmp_path / "points.db"),
        _raw(tmp_path / "plain.db"),
    )
    assert ours.keys() == theirs.keys()
    for index in ours:
        a, b = ours[index], theirs[index]
        assert a.keys() == b.keys()
        for column in a:
            if column not in VOLATILE:
                assert a[column] == b[column], (index, column)
        assert a["ctime"] == a["mtime"] and len(a["unique_id"]) == 32
        assert uuid.UUID(a["unique_id"]).version == 4
        assert our_species[a["id"]] == their_species[b["id"]]
    if layout == "ase":  # ASE's key tables hold what ASE puts there
        for table in ("keys", "number_key_values", "text_key_values"):
            with (
                sqlite3.connect(str(tmp_path / "points.db")) as x,
                sqlite3.connect(str(tmp_path / "plain.db")) as y,
            ):
                query = f"SELECT * FROM {table} ORDER BY id, rowid"
                assert x.execute(query).fetchall() == y.execute(query).fetchall(), table
            x.close()
            y.close()


def test_a_layout_the_writer_does_not_know_is_written_through_ase(tmp_path, monkeypatch):
    """Another ASE format version (or other columns): the store writes through ase.db, and the
    rows are still ASE's own."""
    from flatcontact.ispes import store_rows

    monkeypatch.setattr(store_rows, "FORMAT_VERSION", store_rows.FORMAT_VERSION + 1)
    ref = toy_interface(layers=3)
    with PointStore(tmp_path / "points.db", {"test": "fallback"}, ref) as store:
        assert store._rows is None
        for k in range(6):
            store.write(_result(ref, k))
    plain = ase.db.connect(str(tmp_path / "plain.db"))
    for k in range(6):
        r = _result(ref, k)
        atoms = Atoms(numbers=ref.numbers, positions=r.positions, cell=ref.cell, pbc=ref.pbc)
        atoms.calc = SinglePointCalculator(atoms, energy=r.energy_ev)
        plain.write(atoms, key_value_pairs=_kvp(r))
    _assert_same_rows(_ase_rows(tmp_path / "points.db"), _ase_rows(tmp_path / "plain.db"))


def _commits(store):
    statements = []
    store._db.connection.set_trace_callback(statements.append)
    return statements


def test_batched_store_holds_the_rows_of_the_unbatched_one(tmp_path):
    ref = toy_interface(layers=3)
    counts = {}
    for name, interval in (("each", 0.0), ("batched", 3600.0)):
        with PointStore(tmp_path / f"{name}.db", {"t": 1}, ref, commit_interval_s=interval) as s:
            statements = _commits(s)
            for k in range(40):
                s.write(_result(ref, k))
                if k % 10 == 9:
                    s.flush()  # results that arrived together: one transaction
            counts[name] = sum(1 for x in statements if x.strip().upper() == "COMMIT")
            s.flush()
            assert s.uncommitted == 0
        with PointStore(tmp_path / f"{name}.db", {"t": 1}, ref) as s:
            assert len(s) == 40
    assert counts == {"each": 40, "batched": 4}
    _assert_same_rows(_ase_rows(tmp_path / "each.db"), _ase_rows(tmp_path / "batched.db"))


WRITER = textwrap.dedent(
    """
    import sys, time
    from flatcontact.ispes.store import PointStore
    from flatcontact.structures.toy import toy_interface
    sys.path.insert(0, sys.argv[2])
    from test_store_rows import _result

    ref = toy_interface(layers=3)
    with PointStore(sys.argv[1], {"test": "kill"}, ref, commit_interval_s=3600) as store:
        for k in range(25):
            store.write(_result(ref, k))
        store.flush()
        for k in range(25, 30):
            store.write(_result(ref, k))
        print("written", store.uncommitted, flush=True)
        time.sleep(600)
    """
)


@pytest.mark.parametrize(
    "signum, kept", [(signal.SIGKILL, 25), (signal.SIGTERM, 30), (signal.SIGINT, 30)]
)
def test_a_kill_loses_only_the_uncommitted_points(tmp_path, signum, kept):
    """SIGKILL loses the points written since the last commit (here 5, deliberately never
    committed); SIGTERM and SIGINT unwind, and the store commits them as it closes."""
    db = tmp_path / "points.db"
    here = str(__import__("pathlib").Path(__file__).parent)
    proc = subprocess.Popen(
        [sys.executable, "-c", WRITER, str(db), here],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        # SIGINT at its default in the child, as a terminal gives it (a suite started in the
        # background inherits it ignored, and the child would never see the signal)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        assert proc.stdout.readline().split() == ["written", "5"]
    finally:
        proc.send_signal(signum)
        proc.wait(timeout=60)
    with sqlite3.connect(db) as con:
        assert con.execute("select count(*) from systems").fetchone()[0] == kept
    ref = toy_interface(layers=3)
    with PointStore(db, {"test": "kill"}, ref) as store:
        assert sorted(store.done()) == sorted(_result(ref, k).index for k in range(kept))
        np.testing.assert_array_equal(store.positions((0, 2, 0)), ref.positions + 0.024)


KILLED_SCAN = textwrap.dedent(
    """
    import sys
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.potentials.model import InteractionModel
    from flatcontact.ispes.executors import ProcessExecutor
    from flatcontact.ispes.geometry import thickness
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan
    from flatcontact.structures.toy import toy_interface

    ref = toy_interface(layers=3)
    z0 = thickness(ref)
    toy = InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    pool = ProcessExecutor(2)
    try:
        run_scan(ref, calculator_factory(toy),
                 GridSpec(6, 6, thickness_angstrom=(z0 - 0.25, z0 + 0.3)), sys.argv[1],
                 RelaxSettings(fmax_ev_per_angstrom=1e-4, optimizer="FIRE"), executor=pool,
                 progress=lambda done, total: print(done, flush=True))
    finally:
        pool.close(cancel=True)
    """
)


@pytest.mark.slow
@pytest.mark.parametrize("signum", [signal.SIGKILL, signal.SIGTERM])
def test_scan_killed_mid_grid_on_workers_resumes_to_the_uninterrupted_grid(
    tmp_path, toy_reference, toy_factory, signum
):
    """Batched commits on two worker processes: a scan killed mid-grid (SIGKILL: the
    uncommitted points are lost and recomputed; SIGTERM: none is lost) resumes to the grid
    of an uninterrupted serial scan, value for value."""
    import os

    from flatcontact.ispes.contract import open_ispes
    from flatcontact.ispes.executors import SerialExecutor
    from flatcontact.ispes.geometry import thickness
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan

    out = tmp_path / "killed"
    proc = subprocess.Popen(
        [sys.executable, "-c", KILLED_SCAN, str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
        env={**os.environ, "OMP_NUM_THREADS": "1"},
    )
    try:
        stored = 0
        for line in proc.stdout:
            stored = int(line)
            if stored >= 20:
                break
    finally:
        proc.send_signal(signum)
        proc.wait(timeout=120)
    with sqlite3.connect(out / "points.db") as con:
        kept = con.execute("select count(*) from systems").fetchone()[0]
    assert 0 < kept < 72, "the scan was not killed mid-grid"
    if signum == signal.SIGTERM:
        assert kept >= stored, "SIGTERM lost stored points"
    settings = RelaxSettings(fmax_ev_per_angstrom=1e-4, optimizer="FIRE")
    z0 = thickness(toy_reference)
    grid = GridSpec(6, 6, thickness_angstrom=(z0 - 0.25, z0 + 0.3))
    resumed = run_scan(toy_reference, toy_factory, grid, out, settings, executor=SerialExecutor())
    assert resumed.points_computed == 72 - kept
    run_scan(
        toy_reference, toy_factory, grid, tmp_path / "whole", settings, executor=SerialExecutor()
    )
    a, b = open_ispes(out / "ispes.nc"), open_ispes(tmp_path / "whole" / "ispes.nc")
    for name in ("energy", "normal_stress", "converged"):
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)


def test_store_is_compact_and_still_answers_ase_queries(tmp_path):
    """A new store: 8 kB pages, none of ase.db's optional indexes, ASE's key tables as views of
    the rows' JSON; under 0.6 of the file ase.db itself makes of the same rows, and ASE's
    queries (key values, ranges, bare keys, sorting, a row written by ase.db itself, a
    deletion) answer exactly as on ASE's own file."""
    from flatcontact.ispes.store_schema import PAGE_SIZE

    ref = toy_interface(layers=3)
    n = 400
    with PointStore(tmp_path / "points.db", {"test": "size"}, ref) as store:
        for k in range(n):
            store.write(_result(ref, k, n=20))
    plain = ase.db.connect(str(tmp_path / "plain.db"), use_lock_file=False)
    with plain:  # one transaction, as ase.db's own bulk write
        for k in range(n):
            r = _result(ref, k, n=20)
            atoms = Atoms(numbers=ref.numbers, positions=r.positions, cell=ref.cell, pbc=ref.pbc)
            atoms.calc = SinglePointCalculator(atoms, energy=r.energy_ev)
            plain.write(atoms, key_value_pairs=_kvp(r))
    path = tmp_path / "points.db"
    with sqlite3.connect(str(path)) as con:
        con.execute("PRAGMA wal_checkpoint(TRUNCATE)")
        assert con.execute("PRAGMA page_size").fetchone()[0] == PAGE_SIZE
        kinds = dict(con.execute("SELECT name, type FROM sqlite_master"))
    con.close()
    assert [k for k, t in kinds.items() if t == "index"] == ["sqlite_autoindex_systems_1"]
    assert {k: kinds[k] for k in ("keys", "number_key_values", "text_key_values")} == dict.fromkeys(
        ("keys", "number_key_values", "text_key_values"), "view"
    )
    ours, theirs = path.stat().st_size, (tmp_path / "plain.db").stat().st_size
    assert ours < 0.6 * theirs, (ours, theirs)
    db = ase.db.connect(str(path), use_lock_file=False)
    for other in (db, plain):  # the same row written by ase.db itself into each
        atoms = Atoms(numbers=ref.numbers, positions=ref.positions, cell=ref.cell, pbc=ref.pbc)
        other.write(atoms, i_a=99, converged=False, start="planted", thickness=1e3)
    for query in (
        "", "i_a=3,converged=True", "converged=False", "thickness>11.5", "converged",
        "start=planted", "i_a=99", "steps<20,i_b=2", "max_force_ev_per_a>=0.02",
    ):  # fmt: skip
        assert db.count(query) == plain.count(query), query
        assert [r.id for r in db.select(query, sort="thickness")] == [
            r.id for r in plain.select(query, sort="thickness")
        ], query
    assert db.get(i_a=4, i_b=1).toatoms() == plain.get(i_a=4, i_b=1).toatoms()
    assert sorted(db.get(i_a=99).key_value_pairs) == ["converged", "i_a", "start", "thickness"]
    for other in (db, plain):
        other.delete([other.get(i_a=99).id])
    assert db.count("i_a=99") == 0 and db.count() == n
