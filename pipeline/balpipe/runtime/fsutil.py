"""Writing the output folder safely: a file or a page folder replaced in one step (a reader sees
the old or the new one, never a part), never through a planted symlink, and the temporaries of an
interrupted build removed."""

from __future__ import annotations

import errno
import os
import secrets
import shutil
from pathlib import Path
from typing import BinaryIO, Protocol

#: what to do about an OS error, by its errno
_REMEDIES = {
    errno.ENOSPC: "the disk is full: free space there (or write to another folder) and run again",
    errno.EDQUOT: "the disk quota is used up: free space there (or write to another folder) and run again",
    errno.EROFS: "the file system is read-only: write to another folder",
    errno.EACCES: "permission denied: make it writable for this user (or write to another folder)",
    errno.EPERM: "not permitted: make it writable for this user (or write to another folder)",
    errno.ENOTDIR: "a file stands where a folder is expected: move it away",
    errno.EISDIR: "a folder stands where a file is expected: move it away",
    errno.EEXIST: "something of that name is in the way: move it away",
    errno.ENAMETOOLONG: "the path is too long: use a shorter output folder",
    errno.EMFILE: "too many open files: raise the limit (ulimit -n) or use fewer -j",
    errno.EIO: "an input/output error of the disk: check it",
}


def describe(exc: OSError, path: str | os.PathLike | None = None) -> str:
    """An OS error as a user reads it: the path (``path``, else the error's own; "" for none), the
    reason and what to do, e.g. ``out/x: No space left on device; the disk is full: ...``."""
    where = os.fspath(path) if path is not None else exc.filename
    reason = exc.strerror or type(exc).__name__
    remedy = _REMEDIES.get(exc.errno or 0)
    return (f"{where}: " if where else "") + reason + (f"; {remedy}" if remedy else "")


TMP_MARK = ".balpipe-tmp-"  # temporary files and folders in the output folder carry this


def tmp_name(name: str) -> str:
    return f".{name[:100]}{TMP_MARK}{os.getpid()}-{secrets.token_hex(4)}"


def write_new(path: Path, content: "str | bytes | Streamed") -> None:
    """Create ``path`` (it must not exist: never writes through a planted symlink) with
    ``content`` (text as UTF-8, bytes, or a :class:`Streamed` that writes itself piece by piece,
    never whole in memory); mode from the umask."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o666)
    if hasattr(content, "write_to"):
        with os.fdopen(fd, "wb") as fb:
            content.write_to(fb)
        return
    if isinstance(content, bytes):
        with os.fdopen(fd, "wb") as fb:
            fb.write(content)
        return
    with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
        f.write(content)


class Streamed(Protocol):
    """File content written by pieces: ``write_to(f)`` writes it to the binary file ``f``."""

    def write_to(self, f: BinaryIO) -> None: ...


def remove_path(path: Path) -> None:
    """Remove a file, a symlink (not its target) or a folder tree (rmtree does not follow links)."""
    if path.is_symlink() or path.is_file():
        path.unlink()
    elif path.is_dir():
        shutil.rmtree(path, ignore_errors=True)


def write_file_atomic(path: Path, content: str | bytes) -> None:
    """Replace ``path`` in one step: a reader sees the old or the new file, never a part; a
    symlink at ``path`` is replaced by the file, its target is left alone."""
    tmp = path.with_name(tmp_name(path.name))
    try:
        write_new(tmp, content)
        os.replace(tmp, path)
    except BaseException:
        if tmp.exists():
            tmp.unlink()
        raise


def write_atomic_dir(target: Path, files: "dict[str, str | bytes | Streamed]") -> None:
    """Write a page folder next to ``target`` and move it into place when complete. Modes follow
    the umask (os.mkdir(0o777)), not tempfile's 0700. An :class:`OSError` before the move leaves
    ``target`` as it was; :class:`LeftBehind` after it: the new folder is in place, the earlier
    copy beside it could not be removed (:func:`remove_tree`)."""
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(tmp_name(target.name))
    os.mkdir(tmp, 0o777)
    try:
        for name, content in files.items():
            write_new(tmp / name, content)
        old = None
        if target.is_symlink() or target.is_file():
            target.unlink()  # planted: replace the link itself
        elif target.exists():
            old = target.with_name(tmp_name(target.name + ".old"))
            target.rename(old)
        tmp.rename(target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    if old is not None:
        remove_tree(old)


def remove_tree(folder: Path) -> None:
    """Remove the folder tree ``folder``; a folder in it without write permission is made
    writable first (balpipe wrote it). Raises :class:`OSError` naming ``folder`` when it stays
    (a read-only file system, a folder of another user): never left behind silently."""
    shutil.rmtree(folder, ignore_errors=True)
    if not os.path.lexists(folder):
        return
    for root, dirs, _ in os.walk(folder):
        for d in [root, *(os.path.join(root, x) for x in dirs)]:
            try:
                if not os.path.islink(d):
                    os.chmod(d, 0o700)
            except OSError:
                pass
    try:
        shutil.rmtree(folder)
    except OSError as exc:
        raise LeftBehind(exc.errno, exc.strerror, str(folder)) from None


class LeftBehind(OSError):
    """A page folder was replaced, but its earlier copy (``filename``) could not be removed."""


def remove_temporaries(out: Path) -> None:
    """Remove what an interrupted build left: temporaries of balpipe's own naming only."""
    try:
        entries = list(out.iterdir())
    except OSError:
        return
    for e in entries:
        if e.name.startswith(".") and TMP_MARK in e.name:
            try:
                remove_path(e)
            except OSError:
                pass
        elif e.is_dir() and not e.is_symlink():  # a page folder: its failed/ is written inside
            try:
                inner = [f for f in e.iterdir() if f.name.startswith(".") and TMP_MARK in f.name]
            except OSError:
                continue
            for f in inner:
                try:
                    remove_path(f)
                except OSError:
                    pass
