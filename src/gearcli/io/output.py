"""Output files: one atomic writer for every file gearcli writes (loads CSV, URDF).

:func:`output_target` checks an ``-o`` argument before any work is done: ``"-"`` means
stdout; anything else must resolve (symlinks followed, ``./x`` normalised) to a regular
file or a new name in an existing, writable directory, and never to one of the input
files (compared by resolved path and by inode, so hard links count too).  A symlink is
never replaced: the file it points to is written.

:func:`atomic_output` writes the text to an anonymous file in the target's directory and
gives it its name only when everything succeeded.  On Linux the file is created with
``O_TMPFILE`` and named with ``linkat``, so even SIGKILL leaves nothing behind; elsewhere
(or on file systems without ``O_TMPFILE``) it is a hidden ``.NAME.XXXX.tmp`` file that is
removed on every error path (and on SIGTERM when the CLI turns it into an exception).  The
new file's mode is ``0o666`` minus the umask, like a file created by the shell.  Every
operating-system failure (missing or read-only directory, full disk, ...) becomes an
:class:`OutputError`: one line ``NAME: -o: what is wrong``, exit status 2.
"""
from __future__ import annotations

import errno
import os
import stat
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Iterable, Iterator

from ..errors import GearcliError, Issue


BINARY_BUFFER = 1 << 20
"""Bytes buffered by a binary output file: pyarrow writes Parquet pages of ~160 kB; gathered
into 1 MB writes, the kernel's copy of 0.92 GB into the page cache took ~20% less time."""


class OutputError(GearcliError):
    """An output file cannot be written; ``issue`` says which and why."""

    def __init__(self, name: str, message: str, place: str = "-o"):
        self.issue = Issue(name, place, None, message)
        super().__init__(str(self.issue))


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _file_id(path: str) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_dev, st.st_ino


def output_target(path: str | os.PathLike, inputs: Iterable[str | os.PathLike] = (),
                  option: str = "-o") -> str | None:
    """The resolved file name to write for ``-o path`` (``None`` for ``"-"``, stdout).

    Raises :class:`OutputError` (naming ``option``, the command-line option that gave
    ``path``) when ``path`` is empty, ends with ``/`` (or is ``.``/``..``: a directory's
    name, which the operating system would quietly strip to ``out.csv``), names an input file (also through a symlink, ``./``,
    or a hard link), is a directory, device, FIFO or socket, or lies in a directory that
    does not exist or is not writable.
    """
    name = os.fspath(path)
    if name == "-":
        return None
    if name == "":
        raise OutputError(option, "empty file name (give a file name, or '-' for stdout)", place="")
    if name.endswith(("/", os.sep)) or os.path.basename(name) in (".", ".."):
        raise OutputError(name, "names a directory (ends with '/'); give a file name", option)
    real = os.path.realpath(name)
    ident = _file_id(real)
    for inp in inputs:
        inp = os.fspath(inp)
        if os.path.realpath(inp) == real or (ident is not None and _file_id(inp) == ident):
            raise OutputError(name, f"is the input file '{inp}'; choose another output file name", option)
    if os.path.lexists(real):
        try:
            st = os.stat(real)
        except OSError as exc:
            raise OutputError(name, f"cannot use it: {exc.strerror}", option) from None
        if stat.S_ISDIR(st.st_mode):
            raise OutputError(name, "is a directory (give a file name)", option)
        if not stat.S_ISREG(st.st_mode):
            raise OutputError(name, "is not a regular file (a device, FIFO or socket); use '-' for stdout", option)
        if not os.access(real, os.W_OK):
            raise OutputError(name, "file is not writable (permission denied)", option)
    parent = os.path.dirname(real) or "."
    if not os.path.isdir(parent):
        raise OutputError(name, f"directory '{parent}' does not exist", option)
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(name, f"directory '{parent}' is not writable (permission denied)", option)
    return real


def _open_anonymous(directory: str) -> tuple[int, str | None]:
    """(fd, temp name or None): an O_TMPFILE file in ``directory`` when the system has
    it (name None: nothing to clean up), else a hidden mkstemp file."""
    flag = getattr(os, "O_TMPFILE", 0)
    if flag and os.path.isdir("/proc/self/fd"):
        try:
            return os.open(directory, flag | os.O_WRONLY, 0o666), None   # the kernel applies the umask
        except OSError as exc:
            if exc.errno not in (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL, errno.ENOENT):
                raise
    fd, tmp = tempfile.mkstemp(prefix=".gearcli.", suffix=".tmp", dir=directory)
    try:
        os.fchmod(fd, 0o666 & ~_umask())
    except BaseException:
        os.close(fd)
        os.unlink(tmp)
        raise
    return fd, tmp


def _link_anonymous(fd: int, target: str) -> None:
    """Give the O_TMPFILE file ``fd`` the name ``target`` (replacing an existing file)."""
    root = os.open("/", os.O_RDONLY)
    try:
        _link_proc_fd(fd, target, root)
    finally:
        os.close(root)


def _link_proc_fd(fd: int, target: str, root: int) -> None:
    # a src_dir_fd makes os.link call linkat(AT_SYMLINK_FOLLOW) (plain link() would try to
    # link the /proc symlink itself)
    src = f"/proc/self/fd/{fd}"
    try:
        os.link(src, target, src_dir_fd=root, follow_symlinks=True)
        return
    except FileExistsError:
        pass
    d = os.path.dirname(target)
    for _ in range(100):
        tmp = os.path.join(d, f".gearcli.{os.urandom(6).hex()}.tmp")
        try:
            os.link(src, tmp, src_dir_fd=root, follow_symlinks=True)
            break
        except FileExistsError:
            continue
    else:  # pragma: no cover
        raise FileExistsError(errno.EEXIST, "no free temporary name", d)
    try:
        os.replace(tmp, target)
    except BaseException:
        os.unlink(tmp)
        raise


@contextmanager
def atomic_output(path: str | os.PathLike, inputs: Iterable[str | os.PathLike] = (),
                  encoding: str = "utf-8", binary: bool = False) -> Iterator[IO]:
    """Context manager yielding a text file (a binary one with ``binary``) that becomes
    ``path`` only on success.

    ``path`` is checked by :func:`output_target` (``"-"`` is refused here: the caller
    writes to stdout itself).  On any exception, nothing is left: neither a partial output
    nor a temporary file, and an existing file at ``path`` is unchanged.  Operating-system
    errors become :class:`OutputError`.
    """
    name = os.fspath(path)
    target = output_target(name, inputs)
    if target is None:
        raise OutputError(name, "stdout is not a file; write to sys.stdout instead")
    try:
        fd, tmp = _open_anonymous(os.path.dirname(target) or ".")
    except OSError as exc:
        raise OutputError(name, f"cannot create the file: {exc.strerror}") from None
    f = None
    try:
        f = os.fdopen(fd, "wb", buffering=BINARY_BUFFER) if binary else \
            os.fdopen(fd, "w", encoding=encoding, newline="")
        yield f
        f.flush()
        if tmp is None:
            _link_anonymous(fd, target)
        else:
            os.replace(tmp, target)
            tmp = None
    except OSError as exc:
        raise OutputError(name, f"cannot write: {exc.strerror or exc}") from None
    finally:
        _close_quietly(f, fd)
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)


def _close_quietly(f, fd: int) -> None:
    """Close the file (or the bare descriptor), ignoring errors of a failed write."""
    try:
        if f is not None:
            f.close()
        else:
            os.close(fd)
    except OSError:
        pass


def write_text(path: str | os.PathLike, text: str, inputs: Iterable[str | os.PathLike] = ()) -> None:
    """Write ``text`` to ``path`` atomically (see :func:`atomic_output`)."""
    with atomic_output(path, inputs) as f:
        f.write(text)


def replace_file(path: str | os.PathLike, data: bytes) -> None:
    """``data`` as file ``path``, atomically, replacing whatever has that name: a symlink is
    replaced, not followed (for gearcli's own files, the disk caches' entries: none of
    :func:`output_target`'s checks of an ``-o`` argument).  Raises OSError; nothing is left
    behind on failure (no temporary file, the old file unchanged)."""
    target = os.fspath(path)
    fd, tmp = _open_anonymous(os.path.dirname(target) or ".")
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view):]
        if tmp is None:
            _link_anonymous(fd, target)
        else:
            os.replace(tmp, target)
            tmp = None
    finally:
        _close_quietly(None, fd)
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)
