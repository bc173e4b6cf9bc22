"""Reading an input file whole, within a size limit (every reader goes through here).

Only regular files are read: a FIFO, a device, a socket or a directory given as an input
is refused with one line instead of blocking for ever (a FIFO with no writer) or reading
without end (``/dev/zero``).  The file is opened without blocking and checked on the open
descriptor (``fstat``), so a name swapped for a FIFO between a check and the read cannot
block either.
"""
from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import BinaryIO

from ..errors import Issue, MechanismError

MAX_BYTES = 16 * 2**20
"""Largest mechanism file read (16 MiB: a 100,000-line file is a few MiB)."""

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def not_regular(mode: int) -> str | None:
    """``"not a regular file (a FIFO)"`` (directory, device, socket) for a file of
    ``st_mode`` ``mode`` that is not a regular file; None for a regular file."""
    if stat.S_ISREG(mode):
        return None
    what = next((name for test, name in _KINDS if test(mode)), "a special file")
    return f"not a regular file ({what})"


def input_problem(path: str | Path) -> str | None:
    """Why ``path`` cannot be an input file, found without opening it (``stat``): it does
    not exist, is not a regular file, or its name has a NUL byte; None when it can be read."""
    try:
        return not_regular(os.stat(path).st_mode)
    except ValueError:      # os.stat: "embedded null byte"
        return "cannot read file: the name contains a NUL byte"
    except OSError as exc:
        return f"cannot read file: {exc.strerror}"


def open_regular(path: str | Path) -> BinaryIO:
    """``path`` opened for binary reading; raises :class:`~gearcli.errors.MechanismError`
    (one line, ``path: message``) when it cannot be opened or is not a regular file."""
    def fail(message: str):
        return MechanismError([Issue(str(path), "", None, message)])

    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except ValueError:      # "embedded null byte"
        raise fail("cannot read file: the name contains a NUL byte") from None
    except OSError as exc:
        raise fail(f"cannot read file: {exc.strerror}") from None
    try:
        why = not_regular(os.fstat(fd).st_mode)
    except OSError as exc:  # pragma: no cover (fstat of an open descriptor)
        why = f"cannot read file: {exc.strerror}"
    if why:
        os.close(fd)
        raise fail(why)
    return open(fd, "rb")      # (not os.fdopen: tests replace it to fake a full disk)


def read_bytes(path: str | Path, kind: str = "mechanism file") -> bytes:
    """The bytes of ``path``; raises :class:`~gearcli.errors.MechanismError` (one line)
    when the file cannot be read, is not a regular file or is larger than :data:`MAX_BYTES`."""
    path = Path(path) if not isinstance(path, Path) else path
    try:
        with open_regular(path) as fh:
            data = fh.read(MAX_BYTES + 1)
    except OSError as exc:
        raise MechanismError([Issue(str(path), "", None, f"cannot read file: {exc.strerror}")]) from None
    if len(data) > MAX_BYTES:
        raise MechanismError([Issue(str(path), "", None, f"file is larger than {MAX_BYTES // 2**20} MiB, "
                                    f"the limit for a {kind}")])
    return data
