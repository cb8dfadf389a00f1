"""Reading a file that a spec names (a CSV table, a load table, any input beside the spec): the
one way balpipe opens such a file.

Guarantees of :func:`read_input` (and :func:`read_input_text`):

- only a path relative to the spec's folder is read, and only if it stays inside that folder
  once every symlink is resolved (``../x.csv``, ``/etc/passwd`` and a link pointing outside are
  refused before anything is opened);
- only a regular file is read: a FIFO, a device (``/dev/zero``, ``/dev/urandom``), a socket or a
  folder is refused; the path is checked with ``stat`` before it is opened, opened with
  ``O_NONBLOCK`` (a FIFO swapped in after the check cannot block the open) and checked again on
  the open descriptor with ``fstat`` before a byte is read;
- the size limit is enforced while reading: never more than ``limit + 1`` bytes are read, whatever
  ``st_size`` says;
- an :class:`InputFileError` message names the file as the spec wrote it and the remedy, and
  quotes nothing of the file's content nor any path of the machine (it may be published).
"""

from __future__ import annotations

import os
import stat

#: largest CSV table read (bytes): the motion tables of a spec
MAX_TABLE_BYTES = 20_000_000


class InputFileError(ValueError):
    """A spec-named file that is refused or cannot be read; the message is safe to publish."""


def _kind(mode: int) -> str | None:
    if stat.S_ISREG(mode):
        return None
    if stat.S_ISDIR(mode):
        return "a folder"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "not a regular file"


def read_input(folder: str | os.PathLike, name: str, limit: int, what: str = "file") -> bytes:
    """The bytes of the file ``name`` (as written in the spec) of the spec folder ``folder``, at
    most ``limit`` bytes; raises :class:`InputFileError` (``what``: how the message calls it,
    e.g. "table") when the file is outside the folder, not a regular file, larger than ``limit``
    or unreadable."""
    label = f"the {what} {name!r}"
    if not name or "\0" in name:
        raise InputFileError(f"{label}: not a file name")
    if os.path.isabs(name) or name.startswith("~"):  # not quoted: it is a path of the machine
        raise InputFileError(f"the {what} is given by an absolute path; give a path relative to the spec's "
                             "folder and keep the file there")
    try:
        base = os.path.realpath(folder)
        real = os.path.realpath(os.path.join(base, name))
    except (OSError, ValueError) as exc:
        raise InputFileError(f"{label}: cannot resolve the path ({_reason(exc)})") from None
    if os.path.commonpath([base, real]) != base:
        raise InputFileError(f"{label} is outside the spec's folder (after resolving links); "
                             "only files in the spec's folder or below it are read: copy it there")
    return read_regular(real, limit, label, follow=False)


def read_regular(path: str | os.PathLike, limit: int, label: str, follow: bool = True) -> bytes:
    """The bytes of ``path`` if it is a regular file of at most ``limit`` bytes (checked before
    opening, on the open descriptor, and while reading: at most ``limit + 1`` bytes are read);
    else :class:`InputFileError` whose message calls the file ``label`` (e.g. "the table 'x.csv'").
    ``follow=False``: a symlink at ``path`` itself is refused (``path`` was resolved already)."""
    real = os.fspath(path)
    try:
        kind = _kind(os.stat(real).st_mode)
    except OSError as exc:
        raise InputFileError(f"cannot read {label}: {_reason(exc)}") from None
    if kind:
        raise InputFileError(f"{label} is {kind}, not a regular file; give a file")
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_CLOEXEC", 0)
    if not follow:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    try:
        fd = os.open(real, flags)
    except OSError as exc:
        raise InputFileError(f"cannot read {label}: {_reason(exc)}") from None
    try:
        kind = _kind(os.fstat(fd).st_mode)
        if kind:
            raise InputFileError(f"{label} is {kind}, not a regular file; give a file")
        chunks: list[bytes] = []
        size = 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as exc:
        raise InputFileError(f"cannot read {label}: {_reason(exc)}") from None
    finally:
        os.close(fd)
    if size > limit:
        raise InputFileError(f"{label} is larger than {_size(limit)} (the limit); make it smaller")
    return b"".join(chunks)


def read_input_text(folder: str | os.PathLike, name: str, limit: int, what: str = "file") -> str:
    """:func:`read_input` decoded as UTF-8; a leading byte-order mark is dropped (it would
    otherwise become part of the first column's name). Text that is not UTF-8 is an
    :class:`InputFileError` with the line of the first bad byte, not the byte itself."""
    raw = read_input(folder, name, limit, what)
    if raw.startswith(b"\xef\xbb\xbf"):
        raw = raw[3:]
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise InputFileError(f"the {what} {name!r}:{line}: not UTF-8 text; save it as UTF-8") from None


def _reason(exc: BaseException) -> str:
    return getattr(exc, "strerror", None) or type(exc).__name__


def _size(n: int) -> str:
    return f"{n // 10**6} MB" if n >= 10**6 and n % 10**6 == 0 else f"{n} bytes"
