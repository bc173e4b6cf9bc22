"""Faults of gearcli's disk caches, for the cache tests and their fuzzing: special files in
an entry's place, and a time limit for calls that must not block."""
from __future__ import annotations

import os
import threading
from pathlib import Path

SPECIAL = ["fifo", "symlink to /dev/zero", "folder"]


def clear(path: Path) -> None:
    """Remove whatever is at ``path`` (a file, symlink, FIFO or a folder of files)."""
    if path.is_dir() and not path.is_symlink():
        for p in path.iterdir():
            p.unlink()
        path.rmdir()
    elif os.path.lexists(path):
        path.unlink()


def put(path: Path, data: bytes) -> None:
    """``data`` as the regular file ``path`` (writing into a FIFO left by an earlier fault
    would block)."""
    clear(path)
    path.write_bytes(data)


def make_special(path: Path, kind: str, full: bool = False) -> None:
    """Put a FIFO, a symlink to /dev/zero or a folder (``full``: not empty, so it can be
    neither removed nor replaced) at ``path`` (whatever was there goes)."""
    clear(path)
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "symlink to /dev/zero":
        path.symlink_to("/dev/zero")
    else:
        path.mkdir()
        if full:
            (path / "x").write_text("x")


def in_thread(fn, seconds: float = 60.0):
    """fn() on a daemon thread: its result or exception; a call still blocked after
    ``seconds`` fails the test (instead of hanging the suite)."""
    box = {}

    def run():
        try:
            box["value"] = fn()
        except BaseException as exc:  # noqa: BLE001
            box["error"] = exc
    t = threading.Thread(target=run, daemon=True)
    t.start()
    t.join(seconds)
    assert not t.is_alive(), f"blocked for more than {seconds} s"
    if "error" in box:
        raise box["error"]
    return box["value"]


# --- gearcli in a forked child (a forkserver process: clean, single-threaded) --------------
def cli_child(args: list[str], cwd: str, env: dict, out_path: str, err_path: str, options: dict) -> None:
    """Run ``gearcli args`` in this (forked) process with ``env`` (GEARCLI_CACHE_DIR,
    XDG_CACHE_HOME and HOME only from it), stdout/stderr into files, and exit with its
    status.  ``options``: ``disk_full_after`` (bytes the cache writer may write before
    ENOSPC), ``deny_writes`` (the cache writer gets EACCES, as in a read-only folder),
    ``no_tmpfile`` (the system has no O_TMPFILE: named temporary files),
    ``max_schedule_bytes`` (the schedule cache's entry size bound)."""
    import errno  # noqa: PLC0415
    import sys  # noqa: PLC0415
    import traceback  # noqa: PLC0415

    os.chdir(cwd)
    for k in ("GEARCLI_CACHE_DIR", "XDG_CACHE_HOME", "HOME"):
        os.environ.pop(k, None)
    os.environ.update(env)
    for fd, path in ((1, out_path), (2, err_path)):
        new = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.dup2(new, fd)
        os.close(new)
    from gearcli.analysis import schedule_cache  # noqa: PLC0415
    from gearcli.cli import app  # noqa: PLC0415
    from gearcli.io import cache_root  # noqa: PLC0415

    if options.get("no_tmpfile") and hasattr(os, "O_TMPFILE"):
        del os.O_TMPFILE
    if "max_schedule_bytes" in options:
        schedule_cache.MAX_ENTRY_BYTES = options["max_schedule_bytes"]
    real_replace = getattr(cache_root, "replace_file", None)

    def limited(path, data):
        if options.get("deny_writes"):
            raise PermissionError(errno.EACCES, "Permission denied", str(path))
        budget = [options["disk_full_after"]]
        real_write = os.write

        def write(fd, b):
            if budget[0] <= 0:
                raise OSError(errno.ENOSPC, "No space left on device")
            n = min(len(b), budget[0])
            budget[0] -= n
            return real_write(fd, bytes(b[:n]))
        os.write = write
        try:
            real_replace(path, data)
        finally:
            os.write = real_write
    if options.get("deny_writes") or "disk_full_after" in options:
        cache_root.replace_file = limited
    code = 1
    try:
        app(args, prog_name="gearcli")
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    except BaseException:  # noqa: BLE001 (the finding)
        traceback.print_exc()
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    finally:
        os._exit(code)


_CTX = []


def forkserver():
    """The multiprocessing context whose children fork from a clean server that has
    gearcli's CLI imported (a few ms per child instead of a new interpreter)."""
    if not _CTX:
        import multiprocessing  # noqa: PLC0415

        ctx = multiprocessing.get_context("forkserver")
        ctx.set_forkserver_preload(["cache_faults", "gearcli.cli", "gearcli.pipeline", "numpy", "yaml"])
        _CTX.append(ctx)
    return _CTX[0]


def start_cli(args, cwd: Path, env: dict, options: dict | None = None, tag: str = "run"):
    """A started child running ``gearcli args`` (:func:`cli_child`); its stdout and stderr
    go to ``<cwd>/../<tag>.out`` / ``.err`` (outside the working directory)."""
    out, err = Path(cwd).parent / f"{tag}.out", Path(cwd).parent / f"{tag}.err"
    p = forkserver().Process(target=cli_child, args=([str(a) for a in args], str(cwd), env, str(out), str(err),
                                                     options or {}))
    p.start()
    p.paths = out, err
    return p


def finish_cli(p, seconds: float) -> tuple[int | None, str, str]:
    """(exit status, negative for a signal, None for a hang; stdout; stderr) of a child from
    :func:`start_cli`, killed after ``seconds``."""
    p.join(seconds)
    hung = p.is_alive()
    if hung:
        p.kill()
        p.join()
    out, err = (x.read_text(errors="replace") if x.exists() else "" for x in p.paths)
    return None if hung else p.exitcode, out, err


def stale_files(root: Path) -> list[str]:
    """Temporary files (``.gearcli.*``) anywhere below cache root ``root``."""
    found = []
    if root.is_dir() and not root.is_symlink():
        for d, dirs, files in os.walk(root):
            found += [os.path.join(d, f) for f in files + dirs if f.startswith(".gearcli.")]
    return found
