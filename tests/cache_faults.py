"""Faults of gearcli's disk caches, for the cache tests and their fuzzing: special files in
an entry's place, and a time limit for calls that must not block."""
from __future__ import annotations

import os
import threading
from pathlib import Path

SPECIAL = ["fifo", "symlink to /dev/zero", "folder"]


def make_special(path: Path, kind: str, full: bool = False) -> None:
    """Put a FIFO, a symlink to /dev/zero or a folder (``full``: not empty, so it can be
    neither removed nor replaced) at ``path`` (whatever was there goes)."""
    if path.is_dir() and not path.is_symlink():
        for p in path.iterdir():
            p.unlink()
        path.rmdir()
    elif os.path.lexists(path):
        path.unlink()
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
