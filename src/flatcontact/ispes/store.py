"""The resumable point store ``points.db`` (ASE SQLite database) and ``ispes.nc`` assembly.

One row per finished grid point, keyed by ``i_a``, ``i_b``, ``i_z`` (key-value pairs),
holding the relaxed structure (positions; the energy in the row's ``energy``) and the
record ``shift_a``, ``shift_b``, ``thickness`` (Å), ``normal_stress_gpa``, ``reaction_stress_gpa``,
``force_calls``, ``steps``, ``converged``, ``max_force_ev_per_a``, ``seconds`` and
``start`` (the neighbour it was warm-started from, ``"i_a,i_b,i_z"``, empty if cold).

The database metadata holds ``settings`` (the fingerprint: interface hash, potential,
relaxation settings, grid request) and ``resolved`` (the thicknesses actually used,
a1, a2, the potential label, the probe column and adhesion if the thicknesses were
chosen from a pressure range). A store whose settings differ from the current ones is
refused with a line naming the first difference.

Size: a new store keeps each key-value pair once, in its row, and none of ``ase.db``'s
optional indexes; ASE's key tables are views of the rows, so ASE's queries still answer
(:mod:`flatcontact.ispes.store_schema`).

Crash safety: only the driver process writes, on one connection, into SQLite's write-ahead
log with ``synchronous=NORMAL``: a commit is a write, not an fsync (an fsync per point cost
2-16 ms on a shared disk), and it survives the death of the process however it dies; only an
operating-system crash or power loss can lose the last commits. With ``commit_interval_s = 0``
(the default) each point is committed at once; the scan opens its store with
``scan.COMMIT_INTERVAL_S`` (0.5 s) and commits (:meth:`PointStore.flush`) as soon as a point
written has waited that long, also while the driver waits for results
(:meth:`PointStore.commit_due_in_s`, :class:`flatcontact.ispes.scan_scheduler.Scheduler`), so
the results that arrive within 0.5 s are one transaction (``FLATCONTACT_COMMIT_INTERVAL_S`` sets
another interval; 0 commits every point) and a ``kill -9`` loses at most the
points stored in the last 0.5 s, besides the points in flight (in a serial scan, where the
driver relaxes the points itself: the points stored within 0.5 s before the relaxation it
was killed in, if the one before took less than the time left). Ctrl-C, SIGTERM (raised as :class:`StoreTerminated` while a store is open) and a
normal end commit everything when the store closes. A point is never committed before the
point it was warm-started from (one connection, rows in order), so a resumed grid equals an
uninterrupted one. ASE's own lock file is disabled: after a
``kill -9`` inside a write it would stay behind and block every later run forever.
Instead the driver holds an advisory ``flock`` on ``points.db.driver`` for as long as
the store is open, and removes the file, the lock still held, when it closes the store
(:class:`_DriverLock`); the kernel releases the lock when the process dies, however it
dies (``kill -9`` leaves the file, which the next driver takes over), and a second driver
on the same store is refused with one line.

Validation when a store is opened (a store is never used unchecked):

- the file: a link at ``points.db`` or its side files is refused (SQLite would write through
  it); a file SQLite cannot read, or whose pages fail ``PRAGMA quick_check``, is refused in
  one line naming it and the defect (remove it to recompute the scan);
- the metadata: ``format``, ``settings`` equal to the current ones, ``resolved`` with
  finite thicknesses and in-plane vectors;
- every row against the store contract (:mod:`flatcontact.ispes.store_checks`): a row
  that fails is deleted with one warning
  (:class:`~flatcontact.ispes.store_checks.PointStoreRepaired`) and the scan recomputes
  exactly those points; the other rows are kept.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import os
import signal
import sqlite3
import time
import types
import uuid
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import open_nofollow, refuse_link
from flatcontact.foundation.interrupts import raise_on_sigterm
from flatcontact.ispes import contract, store_schema
from flatcontact.ispes.relax import Index, PointResult
from flatcontact.ispes.store_checks import (
    quick_check,
    repair_rows,
    resolved_defect,
    settings_difference,
)
from flatcontact.ispes.store_rows import RowWriter

if TYPE_CHECKING:
    import xarray as xr

FORMAT = "flatcontact.points/1"
#: Side files of a store (SQLite journals, the driver lock); never links.
SIDE_SUFFIXES = ("-wal", "-shm", "-journal", ".driver")


class _DriverLock:
    """The driver's exclusive advisory ``flock`` on ``<store>.driver`` (module docstring).

    Taken when the store opens, or an InputError if another live driver holds it. Given up
    by :meth:`release`, which removes the file first, the lock still held, and only in the
    process that took it and while the path still names the file it locked. A driver that
    opened the file before it was removed gets the lock of a removed file: it sees the path
    name another file (or none), lets go and opens the path again, so there is one driver. A
    driver killed outright leaves the file; the kernel dropped its lock, so the next takes it.
    """

    def __init__(self, store: Path):
        self.path = store.with_name(store.name + ".driver")
        self._pid = os.getpid()
        for _ in range(5):  # a file removed by the driver that just stopped: open it again
            handle = open(open_nofollow(self.path, append=True), "a", closefd=True)
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                handle.close()
                raise InputError(
                    f"{store}: another flatcontact scan is writing to this store; wait for it "
                    "to finish or use another --out"
                ) from None
            if _names(self.path, handle):
                self._handle = handle
                return
            handle.close()
        raise InputError(f"{store}: could not take the lock {self.path.name}; retry")

    def release(self) -> None:
        """Remove the lock file (as the class says) and let the lock go; idempotent."""
        if self._handle is None:
            return
        if self._pid == os.getpid():
            with contextlib.suppress(OSError):  # a directory gone read-only: the file stays
                if _names(self.path, self._handle):
                    self.path.unlink()
        self._handle.close()
        self._handle = None


def _names(path: Path, handle) -> bool:
    """Whether ``path`` is (still) the file open as ``handle``."""
    try:
        now = os.stat(path, follow_symlinks=False)
    except FileNotFoundError:
        return False
    mine = os.fstat(handle.fileno())
    return (now.st_dev, now.st_ino) == (mine.st_dev, mine.st_ino)


def interface_hash(atoms: Atoms) -> str:
    """SHA-256 of what defines an interface: species, positions, cell, pbc, slab/surface tags,
    the held atoms when they differ from the default (surfaces 1 and 4) and the layer ids.

    Positions and cell are rounded to 1e-6 Å so that a file round trip gives the same hash.
    """
    h = hashlib.sha256()
    h.update(np.asarray(atoms.numbers, dtype=np.int64).tobytes())
    h.update(np.round(atoms.positions, 6).astype(np.float64).tobytes())
    h.update(np.round(atoms.cell.array, 6).astype(np.float64).tobytes())
    h.update(np.asarray(atoms.pbc, dtype=np.int8).tobytes())
    for key in ("slab", "surface"):
        h.update(np.asarray(atoms.arrays[key], dtype=np.int64).tobytes())
    held = np.asarray(atoms.arrays.get("held", np.isin(atoms.arrays["surface"], (1, 4))), bool)
    if not np.array_equal(held, np.isin(atoms.arrays["surface"], (1, 4))):
        h.update(b"held")  # held atoms other than the default surfaces 1 and 4
        h.update(held.astype(np.int8).tobytes())
    if "layer" in atoms.arrays:  # molecule IDs of interlayer potentials, rigid-layer bodies
        h.update(b"layer")
        h.update(np.asarray(atoms.arrays["layer"], dtype=np.int64).tobytes())
    return h.hexdigest()


def discard_store(path: str | os.PathLike[str], remove_parent: bool = False) -> None:
    """Remove the store ``path`` and its side files (SQLite journals, ``.driver`` lock).

    Used when a scan fails before storing any point, so that a corrected rerun (other grid,
    other executor) is not refused as "made with different settings". ``remove_parent``
    also removes the directory if it is then empty (the failed run created it).
    """
    path = Path(path)
    for suffix in ("", *SIDE_SUFFIXES):
        path.with_name(path.name + suffix).unlink(missing_ok=True)
    if remove_parent:
        try:
            path.parent.rmdir()
        except OSError:
            pass


def _one_line(exc: BaseException) -> str:
    return " ".join(f"{exc.__class__.__name__}: {exc}".split())


class StoreTerminated(KeyboardInterrupt):
    """SIGTERM while a store is open: unwinds like Ctrl-C, so the store commits and closes."""


class PointStore:
    """A ``points.db`` opened for one set of settings (the driver's single writer).

    Parameters
    ----------
    path
        The database file (created if missing).
    settings
        The fingerprint dict (JSON-serialisable). An existing store with other
        settings raises InputError naming the first difference.
    reference
        The reference interface; stored rows keep only positions and energy, the
        rest (species, cell, tags) comes from it.
    commit_interval_s
        Points are committed at most this often (s) and at :meth:`close`; 0 commits each.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        settings: dict,
        reference: Atoms,
        commit_interval_s: float = 0.0,
    ):
        # ase.db (≈0.2 s of imports, ase.io) only where a store is opened: the driver's;
        # scan workers import this module for its records but never open a store
        import ase.db

        self.commit_interval_s = float(commit_interval_s)
        self._last_commit = time.monotonic()
        self._checked_keys = False
        self._uncommitted = 0

        self.path = Path(path)
        self.settings = json.loads(json.dumps(settings))
        self.reference = reference
        self.path.parent.mkdir(parents=True, exist_ok=True)
        for suffix in ("", *SIDE_SUFFIXES):
            refuse_link(self.path.with_name(self.path.name + suffix), "a point store file")
        self._driver_lock: _DriverLock | None = _DriverLock(self.path)
        try:
            new = not self.path.exists() or self.path.stat().st_size == 0
            if new:  # the layout of a new store: store_schema
                store_schema.create(self.path)
            self._db = ase.db.connect(
                str(self.path), type="db", append=True, use_lock_file=False, create_indices=False
            )
            # one connection for the store's lifetime, closed by close(): a query of ase.db
            # outside its `with` leaves its connection to the garbage collector (a sqlite3
            # connection is a reference cycle), and an open one keeps -wal and -shm beside
            # the store; also one commit per point (ASE commits, an fsync each, in every write)
            self._db.__enter__()
            n_rows = self._db.count()  # creates the tables of a new store
            if new:
                store_schema.replace_key_tables(self.path)
            if n_rows:
                quick_check(self.path)
            meta = self._db.metadata
            rows = list(self._db.select()) if n_rows else []
        except InputError:
            self.close()
            raise
        except (sqlite3.Error, ValueError, TypeError, KeyError, AttributeError) as exc:
            self.close()  # garbled pages, JSON errors in the metadata, foreign tables
            raise InputError(
                f"{self.path}: not a readable points database ({_one_line(exc)}); remove it "
                "to recompute the scan"
            ) from None
        if not isinstance(meta, dict):
            self.close()
            raise InputError(f"{self.path}: not a flatcontact point store (metadata not a map)")
        if meta.get("format") is not None and meta.get("format") != FORMAT:
            self.close()
            raise InputError(
                f"{self.path}: not a flatcontact point store (format {meta.get('format')!r})"
            )
        if "settings" in meta:
            diff = settings_difference(meta["settings"], self.settings)
            if diff is not None:
                self.close()
                raise InputError(
                    f"{self.path} was made with different settings ({diff}); use another --out or remove the store"
                )
        elif n_rows:
            self.close()
            raise InputError(
                f"{self.path}: has {n_rows} rows but no flatcontact settings; refusing to mix"
            )
        else:
            meta = {"format": FORMAT, "settings": self.settings}
            self._db.metadata = meta
        self._meta = meta
        defect = resolved_defect(meta.get("resolved"))
        if defect is not None:
            self.close()
            raise InputError(f"{self.path}: metadata 'resolved' {defect}; remove it to rescan")
        try:
            kept = repair_rows(
                self._db, rows, self.settings, meta.get("resolved"), len(self.reference), self.path
            )
        except sqlite3.Error as exc:
            self.close()
            raise InputError(
                f"{self.path}: not a writable points database ({_one_line(exc)}); remove it "
                "to recompute the scan"
            ) from None
        self._done: dict[Index, dict] = {index: self._record(row) for index, row in kept.items()}
        # ase.db looks the database's external tables up (a query) for every row written as
        # a row; the store creates none, so the list read once at opening stays exact
        external = list(self._db._get_external_table_names())
        self._db._get_external_table_names = lambda db_con=None: list(external)
        # write-ahead log without an fsync per commit: a commit survives the death of the
        # process (kill -9), only an operating-system crash can lose the last ones
        self._db.connection.commit()
        self._db.connection.execute("PRAGMA journal_mode=WAL")
        self._db.connection.execute("PRAGMA synchronous=NORMAL")
        # the rows with one prepared INSERT, the columns that never change computed once
        # (store_rows); None for a layout it does not know: ase.db writes them
        self._rows = RowWriter.for_database(self._db, reference)
        self._catch_sigterm()

    def _catch_sigterm(self) -> None:
        """While open, SIGTERM raises :class:`StoreTerminated` in the driver (as SIGINT raises
        KeyboardInterrupt), so that the points written but not yet committed are committed
        when the store closes; only where SIGTERM would otherwise kill the process at once
        (the main thread, the default action). A process forked from the driver gets the
        default action back."""
        self._old_sigterm = raise_on_sigterm(
            lambda signum: StoreTerminated(
                f"SIGTERM; the points stored so far are kept in {self.path}"
            )
        )

    def _commit(self) -> None:
        if self._db.connection is not None:
            self._db.connection.commit()
        self._last_commit = time.monotonic()
        self._uncommitted = 0

    def flush(self) -> None:
        """Commit the points written since the last commit, if any (one transaction).

        The scan calls it before it blocks waiting for a result, so that with
        ``commit_interval_s > 0`` a point is never left uncommitted while the driver
        waits: the results that arrive together are one transaction."""
        if self._uncommitted:
            self._commit()

    @property
    def uncommitted(self) -> int:
        """Points written but not yet committed."""
        return self._uncommitted

    def commit_due_in_s(self) -> float:
        """Seconds until the points written but not committed are due (``commit_interval_s``
        after the last commit; 0 if overdue); ``inf`` with none uncommitted."""
        if not self._uncommitted:
            return float("inf")
        return max(0.0, self._last_commit + self.commit_interval_s - time.monotonic())

    def close(self) -> None:
        """Commit, close the database connection and release the driver lock (its file
        removed: :class:`_DriverLock`)."""
        con = getattr(getattr(self, "_db", None), "connection", None)
        if con is not None:
            self._db.connection = None
            try:
                con.commit()
            finally:  # the last connection closed: SQLite removes -wal and -shm
                con.close()
        if self._driver_lock is not None:
            self._driver_lock.release()
            self._driver_lock = None
        if getattr(self, "_old_sigterm", None) is not None:
            signal.signal(signal.SIGTERM, self._old_sigterm)
            self._old_sigterm = None

    def __enter__(self) -> PointStore:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    @staticmethod
    def _record(row) -> dict:
        start = getattr(row, "start", "")
        return {
            "id": row.id,
            "energy_ev": float(row.energy),
            "normal_stress_gpa": float(row.normal_stress_gpa),
            "force_calls": int(row.force_calls),
            "converged": bool(row.converged),
            "shift": (float(row.shift_a), float(row.shift_b)),
            "thickness": float(row.thickness),
            "start": tuple(int(s) for s in start.split(",")) if start else None,
        }

    # -- metadata -------------------------------------------------------------------
    @property
    def resolved(self) -> dict | None:
        """What the run resolved once (thicknesses, a1, a2, probe), or None if not yet."""
        return self._meta.get("resolved")

    def set_resolved(self, resolved: dict) -> None:
        meta = dict(self._meta)
        meta["resolved"] = json.loads(json.dumps(resolved))
        self._db.metadata = meta
        self._commit()
        self._meta = meta

    # -- points ---------------------------------------------------------------------
    def done(self) -> dict[Index, dict]:
        """Finished points: index -> record (energy_ev, normal_stress_gpa, converged, ...)."""
        return dict(self._done)

    def record(self, index: Index) -> dict:
        """The record of one finished point (KeyError if it is not stored)."""
        return self._done[tuple(index)]

    def __contains__(self, index: Index) -> bool:
        return tuple(index) in self._done

    def __len__(self) -> int:
        return len(self._done)

    def positions(self, index: Index) -> np.ndarray:
        """Relaxed positions (Å) of a finished point."""
        return self._db.get(id=self._done[tuple(index)]["id"]).positions.copy()

    def _row(self, result: PointResult, kvp: dict):
        """The ASE row of one point, built directly (what ``ase.db`` would make of
        ``Atoms(numbers, positions, cell, pbc)`` with a ``SinglePointCalculator(energy=...)``),
        for ``ase.db``'s own writer: used where :class:`~flatcontact.ispes.store_rows.RowWriter`
        does not know the store's layout.

        Building an ``Atoms`` and a calculator only for ``ase.db`` to take them apart again
        (``atoms2dict``: a state check comparing the atoms with ``allclose``, a formula per
        key) was two thirds of the driver's cost per stored point; the row holds the same
        columns (``tests/ispes/test_store_rows.py`` compares them with ASE's own).
        """
        from ase.db.core import now
        from ase.db.row import AtomsRow

        reference = self.reference
        dct = {
            "numbers": reference.numbers,
            "positions": np.asarray(result.positions, dtype=float),
            "unique_id": uuid.uuid4().hex,
            "calculator": "unknown",  # SinglePointCalculator.name
            "calculator_parameters": {},
            "energy": float(result.energy_ev),
            "key_value_pairs": kvp,
        }
        if reference.pbc.any():
            dct["pbc"] = reference.pbc
        if reference.cell.any():
            dct["cell"] = reference.cell.array
        row = AtomsRow(dct)
        row.ctime = now()
        row.user = os.getenv("USER")
        return row

    def write(self, result: PointResult) -> None:
        """Store one finished point (committed within ``commit_interval_s``, and at close).

        A point already stored is ignored."""
        import ase.db.core

        index = tuple(result.index)
        if index in self._done:
            return
        kvp = {
            "i_a": index[0],
            "i_b": index[1],
            "i_z": index[2],
            "shift_a": result.shift_a,
            "shift_b": result.shift_b,
            "thickness": result.thickness,
            "normal_stress_gpa": result.normal_stress_gpa,
            "reaction_stress_gpa": result.reaction_stress_gpa,
            "force_calls": result.force_calls,
            "steps": result.steps,
            "converged": bool(result.converged),
            "max_force_ev_per_a": result.max_force_ev_per_a,
            "seconds": result.seconds,
            "start": ",".join(str(i) for i in result.start_index) if result.start_index else "",
        }
        if not self._checked_keys:  # ase.db's key check, once: the keys and types never change
            ase.db.core.check(kvp)
            self._checked_keys = True
        if self._rows is not None:
            row_id = self._rows.write(self._db.connection, result.positions, result.energy_ev, kvp)
        else:
            # the database's own row writer; the key-value pairs travel in the row (ase.db's
            # rule for a row written without pairs: it keeps its own), so that ase.db's key
            # check, a formula parse per key (a quarter of the write), runs once, above
            row_id = self._db._write(self._row(result, kvp), {}, {}, None)
        self._uncommitted += 1
        if time.monotonic() - self._last_commit >= self.commit_interval_s:
            self._commit()  # everything written so far, in order
        # the record from what was just written (SQLite stores these doubles and integers
        # exactly), not read back: a select per point was a third of the driver's store cost
        self._done[index] = self._record(
            types.SimpleNamespace(id=row_id, energy=float(result.energy_ev), **kvp)
        )

    # -- assembly -------------------------------------------------------------------
    def assemble(self, mapping: dict | None = None, symmetry: dict | None = None) -> xr.Dataset:
        """The ``ispes.nc`` dataset of this store (missing points NaN, ``converged=False``).

        ``mapping`` (a symmetry-reduced scan, :mod:`flatcontact.ispes.reduction`): grid index
        -> the index of its representative; every point the reduced plan does not relax
        takes its representative's energy, normal stress and convergence, with
        ``mapped = True`` and ``force_calls = 0``. A stored row at such a point (one that is
        neither a representative nor one of ``symmetry["verify_points"]``,
        :meth:`rows_outside_plan`) is not used: the file declares the group, so a mapped
        point's value is its representative's, whatever the store holds there (the scan
        driver notes the rows left out). ``symmetry``: the scan's group record; its
        operations are stored as attributes (``symmetry_order``, ``symmetry_matrices``,
        ``symmetry_translations``, see :mod:`flatcontact.ispes.contract`) when the points
        were mapped, else the identity. ``computed_points`` counts the rows used.
        """
        resolved = self.resolved
        if resolved is None:
            raise InputError(f"{self.path}: the grid is not resolved yet (no thicknesses recorded)")
        grid = self.settings["grid"]
        z = np.asarray(resolved["thickness_angstrom"], dtype=float)
        extra = {
            "fmax_ev_per_a": self.settings["relax"]["fmax_ev_per_a"],
            "optimizer": self.settings["relax"]["optimizer"],
            "interface_sha256": self.settings["interface_sha256"],
            "points_total": int(grid["n_a"] * grid["n_b"] * z.size),
            "grid_points": int(grid["n_a"] * grid["n_b"] * z.size),
        }
        outside = set(self.rows_outside_plan(mapping, symmetry))
        used = {idx: rec for idx, rec in self._done.items() if idx not in outside}
        extra["computed_points"] = len(used)
        ops = (symmetry or {}).get("operations") if mapping is not None else None
        if not ops:
            ops = [{"matrix": [[1, 0], [0, 1]], "translation": [0.0, 0.0]}]
        extra.update(contract.symmetry_attrs(ops))
        for key, value in (resolved.get("adhesion") or {}).items():
            extra[key] = (
                int(value) if isinstance(value, bool) else value
            )  # netCDF has no bool attrs
        ds = contract.empty_grid(
            grid["n_a"],
            grid["n_b"],
            np.sort(z),  # i_z is the position in the resolved list, which need not be sorted
            resolved["a1"],
            resolved["a2"],
            resolved["potential_label"],
            **extra,
        )
        order = np.argsort(z)
        rank = np.empty_like(order)
        rank[order] = np.arange(z.size)
        # the variables' own arrays, looked up once (an xarray lookup per point and variable
        # was 0.16 s of the driver's time per assembly at the paper preset's 3,312 points)
        energy = ds[contract.VAR_ENERGY].values
        stress = ds[contract.VAR_STRESS].values
        converged = ds[contract.VAR_CONVERGED].values
        calls = ds[contract.VAR_FORCE_CALLS].values
        for (ia, ib, iz), rec in used.items():
            k = int(rank[iz])
            energy[ia, ib, k] = rec["energy_ev"]
            stress[ia, ib, k] = rec["normal_stress_gpa"]
            converged[ia, ib, k] = rec["converged"]
            calls[ia, ib, k] = rec["force_calls"]
        mapped = np.zeros(energy.shape, dtype=bool)
        for (ia, ib, iz), rep in (mapping or {}).items():
            if (ia, ib, iz) in used or tuple(rep) not in used:
                continue
            rec, k = self._done[tuple(rep)], int(rank[iz])
            energy[ia, ib, k] = rec["energy_ev"]
            stress[ia, ib, k] = rec["normal_stress_gpa"]
            converged[ia, ib, k] = rec["converged"]
            mapped[ia, ib, k] = True
        ds[contract.VAR_MAPPED] = (contract.DIMS, mapped)
        ds.attrs["points_done"] = len(used) + int(mapped.sum())
        return ds

    def rows_outside_plan(self, mapping: dict | None, symmetry: dict | None) -> list[Index]:
        """Stored points a symmetry-reduced plan did not relax (sorted; empty without one).

        ``mapping`` and ``symmetry`` as in :meth:`assemble`: the plan relaxes the
        representatives (the values of ``mapping``) and the verified points
        (``symmetry["verify_points"]``); a row at any other point is a mapped point's, whose
        value is its representative's. Such a row comes from another scan, a hand edit, or
        an earlier round of this one that computed points the last round's plan maps (a
        fallback to the full grid recorded before this rule, a verified point the last
        round no longer verifies)."""
        if mapping is None:
            return []
        planned = {tuple(rep) for rep in mapping.values()}
        planned |= {tuple(int(i) for i in v) for v in (symmetry or {}).get("verify_points", ())}
        return sorted(idx for idx in self._done if idx in mapping and idx not in planned)

    def write_ispes(self, path: str | os.PathLike[str]) -> Path:
        """Assemble and write ``ispes.nc`` atomically."""
        return contract.write_ispes(self.assemble(), path)
