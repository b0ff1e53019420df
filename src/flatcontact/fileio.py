"""Small file helpers shared by every stage: atomic writes, checked reads of user files,
the SHA-256 of a file's content.

A file a stage produces either appears whole or not at all: write to a
temporary sibling, then ``os.replace`` it into place.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from flatcontact.errors import InputError


def _umask() -> int:
    """The process umask (read by setting it and restoring it)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; move it onto ``path`` on success.

    On an exception the temporary file is removed and ``path`` is untouched.
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        yield tmp
        if tmp.exists():  # mkstemp makes 0600 files; give the result the usual permissions
            os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, target)
    finally:
        if tmp.exists():
            tmp.unlink()


def file_sha256(path: str | os.PathLike[str]) -> str:
    """SHA-256 of a file's bytes, as hex (read in 1 MiB blocks).

    The one file hash of flatcontact: input files enter stage fingerprints by content,
    stage records keep the digest of each output, recipes record their source files.
    """
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def write_text_atomic(path: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` to ``path`` atomically and return the path."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    return Path(path)


def write_json_atomic(path: str | os.PathLike[str], data: Any) -> Path:
    """Write ``data`` as indented JSON to ``path`` atomically."""
    return write_text_atomic(path, json.dumps(data, indent=2, sort_keys=False) + "\n")


def read_text_file(path: str | Path, what: str, max_bytes: int) -> str:
    """The text of a small user file, every failure one :class:`InputError` line naming it.

    Parameters
    ----------
    path
        The file.
    what
        What the file is, for the messages (``"config file"``, ``"measured stiffness CSV"``).
    max_bytes
        Largest size read; a bigger file is refused (it is not a file of this kind).

    Raises
    ------
    InputError
        Missing, a directory, unreadable (permissions, ``/proc/self/mem``), larger than
        ``max_bytes`` or not UTF-8 text.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: no such {what}")
    if path.is_dir():
        raise InputError(f"{path}: is a directory, expected a {what}")
    try:
        with path.open("rb") as handle:
            raw = handle.read(max_bytes + 1)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise InputError(f"{path}: cannot read the {what} ({reason})") from None
    if len(raw) > max_bytes:
        raise InputError(f"{path}: larger than {max_bytes} bytes, expected a {what}")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{path}: not UTF-8 text (byte 0x{raw[exc.start]:02x} at offset {exc.start}); "
            f"expected a {what} saved as UTF-8"
        ) from None
