"""Small file helpers shared by every stage: atomic writes, checked reads of user files,
the SHA-256 of a file's content.

A file a stage produces either appears whole or not at all: write to a temporary sibling,
then ``os.replace`` it into place. No write follows a symbolic link: the temporary sibling is
created with ``O_CREAT | O_EXCL | O_NOFOLLOW`` in the target's own folder (a folder that is a
link is refused), ``os.replace`` swaps the directory entry (a link planted at the target is
replaced, its target never written) and files appended to in place are opened with
``O_NOFOLLOW`` (:func:`open_nofollow`). Temporary files are named ``.<name>.<random>.part``;
they are removed on every exit path that Python sees (an interruption between a file's
creation and its guard included: :func:`remove_live_temporaries`) and swept by
:func:`sweep_temporary` on the next run after a ``kill -9``.
"""

from __future__ import annotations

import contextlib
import errno
import hashlib
import json
import os
import secrets
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from flatcontact.foundation.errors import InputError

#: Longest file or folder name in bytes (``NAME_MAX`` of Linux and macOS file systems).
NAME_MAX = 255
#: Longest path in bytes (``PATH_MAX`` of Linux).
PATH_MAX = 4096
#: Suffixes of the temporary files this package writes (always hidden: ``.<name>.*``).
TEMPORARY_SUFFIXES = (".part", ".tmp")
_PART_SUFFIX = ".part"
_RANDOM_CHARS = 8


def check_path_length(path: str | os.PathLike[str], what: str) -> None:
    """Refuse a path with a name over :data:`NAME_MAX` or a length over :data:`PATH_MAX` bytes.

    Parameters
    ----------
    path
        The path as the user wrote it.
    what
        How the user named it, first in the message (``"--out"``, ``"config file"``).

    Raises
    ------
    InputError
        One line naming ``what``, the offending name (shortened) and the limit.
    """
    raw = os.fsencode(path)
    if len(raw) > PATH_MAX:
        raise InputError(f"{what}: path of {len(raw)} bytes is longer than {PATH_MAX} bytes")
    for part in raw.split(b"/"):
        if len(part) > NAME_MAX:
            shown = os.fsdecode(part[:40])
            raise InputError(
                f"{what}: name {shown!r}... is {len(part)} bytes, longer than the "
                f"{NAME_MAX} bytes a file system allows for one name"
            )


def refuse_link(path: str | os.PathLike[str], what: str = "") -> None:
    """Refuse ``path`` if it is a symbolic link (flatcontact never writes through one).

    Raises
    ------
    InputError
        One line naming the path and where the link points.
    """
    path = Path(path)
    if path.is_symlink():
        try:
            where = os.readlink(path)
        except OSError:
            where = "?"
        kind = f" ({what})" if what else ""
        raise InputError(
            f"{path}: is a symbolic link{kind} to {where!r}; flatcontact does not write through "
            "links: remove the link and rerun"
        )


def open_nofollow(
    path: str | os.PathLike[str], append: bool = False, readable: bool = False, mode: int = 0o666
) -> int:
    """Open ``path`` for writing without following a symbolic link; return the descriptor.

    ``append`` keeps what is there (``O_APPEND``), otherwise the file is created or truncated;
    ``readable`` opens it for reading too. The file is created if missing, with ``mode`` less
    the umask.

    Raises
    ------
    InputError
        If ``path`` is a symbolic link (``ELOOP``) or not a regular file.
    """
    flags = (os.O_RDWR if readable else os.O_WRONLY) | os.O_CREAT | os.O_CLOEXEC
    flags |= os.O_APPEND if append else os.O_TRUNC
    return _open_checked(path, flags, mode)


def _open_checked(path: str | os.PathLike[str], flags: int, mode: int) -> int:
    """``os.open`` with ``O_NOFOLLOW``; a link or a non-regular file is one InputError line."""
    try:
        fd = os.open(path, flags | os.O_NOFOLLOW | os.O_NONBLOCK, mode)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            refuse_link(path)
        if exc.errno == errno.ENXIO:  # a FIFO without a reader
            raise InputError(f"{path}: is not a regular file; remove it and rerun") from None
        raise
    if not stat.S_ISREG(os.fstat(fd).st_mode):  # a FIFO, a device planted there
        os.close(fd)
        raise InputError(f"{path}: is not a regular file; remove it and rerun")
    os.set_blocking(fd, True)
    return fd


def sweep_temporary(folder: str | os.PathLike[str], recursive: bool = False) -> list[Path]:
    """Remove the temporary files an interrupted writer left in ``folder``; return them.

    Temporary files are hidden files ending in one of :data:`TEMPORARY_SUFFIXES`
    (``.<name>.<random>.part`` of :func:`atomic_path`, ``.report.html.tmp``). Call it only
    while holding the folder's writer lock: another writer's files would go too. Links are
    removed as links, never followed.
    """
    folder = Path(folder)
    removed = []
    if not folder.is_dir() or folder.is_symlink():
        return removed
    for dirpath, dirnames, filenames in os.walk(folder):
        for name in filenames + [d for d in dirnames if (Path(dirpath) / d).is_symlink()]:
            if name.startswith(".") and name.endswith(TEMPORARY_SUFFIXES):
                path = Path(dirpath) / name
                with contextlib.suppress(FileNotFoundError):
                    path.unlink()
                    removed.append(path)
        if not recursive:
            break
    return removed


def _umask() -> int:
    """The process umask (read by setting it and restoring it)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; move it onto ``path`` on success.

    On an exception the temporary file is removed and ``path`` is untouched. The temporary
    file is created ``O_EXCL | O_NOFOLLOW`` in ``path``'s folder; ``os.replace`` then swaps
    the directory entry, so a symbolic link planted at ``path`` is replaced, not written
    through.

    Raises
    ------
    InputError
        If ``path``'s name is longer than :data:`NAME_MAX` bytes or its folder is a link.
    """
    target = Path(path)
    check_path_length(target.name, str(target.parent))
    target.parent.mkdir(parents=True, exist_ok=True)
    refuse_link(target.parent, "a folder flatcontact writes into")
    tmp = _create_temporary(target)
    try:
        yield tmp
        if tmp.exists():  # the temporary file is 0600; give the result the usual permissions
            os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, target)
    finally:
        _drop_temporary(tmp)


def file_sha256(path: str | os.PathLike[str]) -> str:
    """SHA-256 of a file's bytes, as hex (read in 1 MiB blocks).

    The one file hash of flatcontact: input files enter stage fingerprints by content,
    stage records keep the digest of each output, recipes record their source files.
    """
    digest = hashlib.sha256()
    if not stat.S_ISREG(os.stat(path).st_mode):  # a FIFO would block, a device never end
        raise InputError(f"{quoted(path)}: is not a regular file; expected a file to hash")
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


#: The temporary files of this process not yet moved onto their target or removed. A name is
#: registered before its file is created and dropped after the file is gone, so an
#: interruption (SIGTERM or Ctrl-C raised between any two bytecodes, even between the file's
#: creation and the ``try`` that would remove it) never leaves a file nobody knows of:
#: :func:`remove_live_temporaries` removes what the unwinding missed.
_LIVE_TEMPORARIES: set[Path] = set()


def remove_live_temporaries() -> list[Path]:
    """Remove this process's temporary files that an interruption left; return them."""
    removed = []
    for tmp in list(_LIVE_TEMPORARIES):
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
            removed.append(tmp)
        _LIVE_TEMPORARIES.discard(tmp)
    return removed


def _create_temporary(target: Path) -> Path:
    """A new empty hidden file ``.<name>.<random>.part`` beside ``target`` (name <= NAME_MAX),
    registered in :data:`_LIVE_TEMPORARIES` until :func:`_drop_temporary`."""
    room = NAME_MAX - len(_PART_SUFFIX) - _RANDOM_CHARS - 2
    stem = os.fsdecode(os.fsencode(target.name)[:room])
    for _ in range(100):
        tmp = target.parent / f".{stem}.{secrets.token_hex(_RANDOM_CHARS // 2)}{_PART_SUFFIX}"
        _LIVE_TEMPORARIES.add(tmp)
        try:
            fd = _open_checked(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        except OSError as error:  # not created (an interruption is no OSError: it stays)
            _LIVE_TEMPORARIES.discard(tmp)
            if isinstance(error, FileExistsError):
                continue
            raise
        os.close(fd)
        return tmp
    raise FileExistsError(errno.EEXIST, "no free temporary name", str(target))


def _drop_temporary(tmp: Path) -> None:
    """Remove ``tmp`` if it is still there (not moved onto its target) and forget it."""
    tmp.unlink(missing_ok=True)
    _LIVE_TEMPORARIES.discard(tmp)


def copy_file_atomic(source: str | os.PathLike[str], path: str | os.PathLike[str]) -> Path:
    """Copy ``source`` onto ``path`` atomically (see :func:`atomic_path`); return ``path``."""
    with atomic_path(path) as tmp, open(source, "rb") as src, open(tmp, "wb") as dst:
        while block := src.read(1 << 20):
            dst.write(block)
    return Path(path)


def link_file_atomic(source: str | os.PathLike[str], path: str | os.PathLike[str]) -> Path:
    """Make ``path`` a second hard link to ``source``'s file, atomically; return ``path``.

    The file's bytes are stored once (``du`` counts them once; ``cp -a``, ``tar`` and
    ``rsync -H`` keep the link). Where the filesystem has no hard links, or ``source`` is a
    symbolic link, ``path`` becomes a copy (:func:`copy_file_atomic`). Either way a symbolic
    link planted at ``path`` is replaced, not written through; later atomic writes to either
    name replace that name only.
    """
    source, target = Path(source), Path(path)
    if source.is_symlink():
        return copy_file_atomic(source, target)
    check_path_length(target.name, str(target.parent))
    target.parent.mkdir(parents=True, exist_ok=True)
    refuse_link(target.parent, "a folder flatcontact writes into")
    tmp = _create_temporary(target)  # reserves a fresh name beside the target
    try:
        tmp.unlink()
        os.link(source, tmp, follow_symlinks=False)
        os.replace(tmp, target)  # a no-op when target is already a link to the same file
    except OSError:
        return copy_file_atomic(source, target)
    finally:
        _drop_temporary(tmp)
    return target


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
        A name longer than :data:`NAME_MAX` bytes, missing, a directory, unreadable (permissions, ``/proc/self/mem``), larger than
        ``max_bytes`` or not UTF-8 text.
    """
    path = Path(path)
    check_path_length(path, quoted(path) if len(os.fsencode(path)) <= 200 else what)
    refuse_special(path, what)  # a FIFO would block here, a device never end
    try:
        with path.open("rb") as handle:
            raw = handle.read(max_bytes + 1)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise InputError(f"{quoted(path)}: cannot read the {what} ({reason})") from None
    if len(raw) > max_bytes:
        raise InputError(f"{quoted(path)}: larger than {max_bytes} bytes, expected a {what}")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{quoted(path)}: not UTF-8 text (byte 0x{raw[exc.start]:02x} at offset {exc.start}); "
            f"expected a {what} saved as UTF-8"
        ) from None


def refuse_special(path: str | os.PathLike[str], what: str) -> Path:
    """Refuse ``path`` unless it is a regular file, before it is opened (a FIFO would block the
    reader, a device would be read without end); a link to a regular file is followed (the
    user may keep their files anywhere). Returns ``path``.

    Raises
    ------
    InputError
        One line naming the path and ``what`` was expected: missing, a directory, or a FIFO,
        socket or device.
    """
    path = Path(path)
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise InputError(f"{quoted(path)}: no such {what}") from None
    except OSError as exc:
        raise InputError(
            f"{quoted(path)}: cannot read the {what} ({exc.strerror or type(exc).__name__})"
        ) from None
    if stat.S_ISDIR(mode):
        raise InputError(f"{quoted(path)}: is a directory, expected a {what}")
    if not stat.S_ISREG(mode):
        raise InputError(
            f"{quoted(path)}: is not a regular file (a FIFO, socket or device), expected a {what}"
        )
    return path


def read_json_file(path: str | os.PathLike[str], what: str, max_bytes: int) -> Any:
    """The parsed JSON of a small file, every failure one :class:`InputError` line naming it.

    The file must be a regular file (:func:`refuse_special`, checked before it is opened), at
    most ``max_bytes``, UTF-8 and one complete JSON document (a truncated write, a foreign
    file: refused, never a ``JSONDecodeError`` traceback). What the document must hold is its
    reader's business (:mod:`flatcontact.foundation.result_json`).
    """
    text = read_text_file(refuse_special(path, what), what, max_bytes)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(
            f"{quoted(path)}: not a complete JSON document ({exc.msg}: line {exc.lineno}, "
            f"column {exc.colno}); expected a {what}"
        ) from None
    except RecursionError:
        raise InputError(f"{quoted(path)}: nested too deeply, expected a {what}") from None


def quoted(path: str | os.PathLike[str]) -> str:
    """``path`` as text for a one-line message: as it is, or ``repr``-quoted when it holds a
    newline or another control character (which would split or garble the line)."""
    text = os.fsdecode(path)
    if any(ord(c) < 0x20 or ord(c) == 0x7F for c in text):
        return repr(text)
    return text
