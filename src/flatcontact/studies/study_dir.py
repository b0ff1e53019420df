"""A study's directory: the link and lock rules of a run directory, for ``--out`` of a study.

A study (``flatcontact study convergence|models|approximants --out DIR``) writes its own files
(``study.json``, ``study.csv``, figures, ``uncertainty.yaml``) into ``DIR`` and one ordinary
run directory per variant into ``DIR/runs/<folder>``. The rules are a run's
(:mod:`flatcontact.foundation.rundir`, :mod:`flatcontact.foundation.fileio`):

- nothing is written through a symbolic link: ``DIR/runs`` or one of its entries planted as
  a link is refused in one line naming it, before any variant runs (a run directory may
  itself be a link the user made, a variant's folder may not: the study made it);
- one study writer per ``DIR``: :func:`study_directory` holds the run lock
  (:class:`flatcontact.foundation.rundir.RunLock`) on ``DIR`` while the study runs and writes its
  files, so a second study on the same ``--out`` is refused in one line instead of failing
  its variants one by one;
- one folder per variant, whose name can neither collide with another's nor leave ``runs``
  (:func:`variant_folders`): a label that is not already a plain name (``'m a'``, ``'.'``,
  ``'..'``) gets a folder of its safe characters plus 8 hex digits of the label's SHA-256.
"""

from __future__ import annotations

import contextlib
import hashlib
import re
from collections.abc import Iterable, Iterator
from pathlib import Path

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import refuse_link
from flatcontact.foundation.rundir import RunLock

#: The folder of a study's run directories.
RUNS = "runs"
#: Longest folder name kept from a label (before the hash suffix).
_NAME_CHARS = 60
_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]+")


def folder_name(label: str) -> str:
    """The folder of the variant ``label`` below ``runs``: the label itself when it is a
    plain name (letters, digits, ``_ . -``, not starting with a dot, at most 60 characters),
    else its safe characters plus ``-`` and the first 8 hex digits of its SHA-256."""
    safe = _UNSAFE.sub("_", label).lstrip(".")[:_NAME_CHARS]
    if safe == label and safe:
        return safe
    digest = hashlib.sha256(label.encode("utf-8", "surrogatepass")).hexdigest()[:8]
    return f"{safe or 'variant'}-{digest}"


def variant_folders(labels: Iterable[str], what: str = "--models") -> dict[str, str]:
    """Label -> folder name below ``runs`` (:func:`folder_name`), refusing two labels whose
    folders would be one (equal up to case: one folder on a case-insensitive file system).

    Raises
    ------
    InputError
        One line naming ``what`` and both labels.
    """
    out: dict[str, str] = {}
    seen: dict[str, str] = {}
    for label in labels:
        name = folder_name(label)
        other = seen.get(name.casefold())
        if other is not None and other != label:
            raise InputError(
                f"{what}: {other!r} and {label!r} would share the run folder {name!r}; "
                "rename one of them"
            )
        seen[name.casefold()] = label
        out[label] = name
    return out


def refuse_study_links(out: str | Path) -> None:
    """Refuse ``out/runs`` or any entry of it that is a symbolic link (one line naming it)."""
    runs = Path(out) / RUNS
    refuse_link(runs, "a study's runs folder")
    if runs.is_dir():
        for entry in sorted(runs.iterdir()):
            refuse_link(entry, "a study's variant folder")


@contextlib.contextmanager
def study_directory(out: str | Path) -> Iterator[Path]:
    """Hold ``out`` as the one writer of a study: links refused, the run lock taken.

    ``out`` is created if missing; a study refused before it wrote anything leaves ``out``
    as it found it (the lock file removed, and ``out`` too when this call created it).

    Raises
    ------
    InputError
        A link at ``out/runs`` or among its entries, or another flatcontact process writing
        ``out`` (one line naming it and its pid).
    """
    root = Path(out)
    refuse_study_links(root)
    created = not root.exists()
    root.mkdir(parents=True, exist_ok=True)
    lock = RunLock(root)
    try:
        lock.acquire()
    except BaseException:
        if created:
            with contextlib.suppress(OSError):
                root.rmdir()
        raise
    try:
        refuse_study_links(root)  # again, now that no other study can be making them
        yield root
    finally:
        lock.release(tidy="created" if created else True)
