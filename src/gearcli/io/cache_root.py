"""Where gearcli keeps its disk caches (the llvm kernels' machine code, solution schedules),
and how their entries are read and written.

The root is ``$GEARCLI_CACHE_DIR`` if set to an absolute path, else ``$XDG_CACHE_HOME/gearcli``
if that is absolute, else ``~/.cache/gearcli``.  A relative value of either variable is
ignored, as the XDG Base Directory specification says of its own variables: the working
directory changes from command to command, and a cache inside it would scatter entries
among the user's files.

Entries are read by :func:`read_entry`, which opens only regular files (``O_NOFOLLOW``, then
``fstat``, with ``O_NONBLOCK`` so that a FIFO put in an entry's place cannot block the open)
of bounded size, and written by :func:`write_entry`: an anonymous file in the folder named
only when whole (:func:`.output.replace_file`, gearcli's one atomic writer), replacing whatever has
the name (a symlink is replaced, never followed).  Neither raises for an unusable cache:
every failure of a cache is silent by design (the caller computes what it wanted instead).
"""
from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

from .output import replace_file


def cache_root() -> Path:
    """The root folder of gearcli's disk caches (not created here; see the module docstring)."""
    root = os.environ.get("GEARCLI_CACHE_DIR", "")
    if os.path.isabs(root):
        return Path(root)
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    base = xdg if os.path.isabs(xdg) else os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "gearcli"


class BadEntry(OSError):
    """A cache entry that is not a regular file of at most the allowed size: to be removed."""


def read_entry(path: Path, max_bytes: int) -> bytes:
    """The bytes of cache entry ``path``.

    Raises FileNotFoundError when there is none, :class:`BadEntry` when ``path`` is a
    symlink, a FIFO, a device, a directory or a socket, or holds more than ``max_bytes``
    (never blocks, never reads more than ``max_bytes + 1`` bytes), and OSError otherwise
    (unreadable)."""
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        if exc.errno == errno.ELOOP:           # a symlink (O_NOFOLLOW)
            raise BadEntry(errno.ELOOP, "a symlink", str(path)) from None
        raise
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise BadEntry(errno.EINVAL, "not a regular file", str(path))
        if st.st_size > max_bytes:
            raise BadEntry(errno.EFBIG, "too large", str(path))
        chunks, total = [], 0
        while True:
            chunk = os.read(fd, max_bytes + 1 - total)
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > max_bytes:              # grew since fstat
                raise BadEntry(errno.EFBIG, "too large", str(path))
        return b"".join(chunks)
    finally:
        os.close(fd)


def write_entry(path: Path, data: bytes) -> bool:
    """``data`` into cache entry ``path`` atomically, creating its folder (False where that
    fails: no folder can be made, not writable, full disk; nothing is left behind then)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        replace_file(path, data)
        return True
    except OSError:
        return False


def remove_entry(path: Path) -> None:
    """Delete cache entry ``path`` (a file, symlink, FIFO or an empty folder), quietly."""
    try:
        path.unlink()
    except IsADirectoryError:
        try:
            path.rmdir()
        except OSError:
            pass
    except OSError:
        pass
