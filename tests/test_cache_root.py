"""Where the disk caches live and how their entries are read and written (io/cache_root.py):
relative locations are ignored; only regular files of bounded size are read, never
blocking; writes are atomic, replace a symlink instead of following it, and leave nothing
behind when they fail."""
from __future__ import annotations

import errno
import os
from pathlib import Path

import pytest

from cache_faults import in_thread
from gearcli.io import cache_root as cr


@pytest.mark.parametrize("gearcli, xdg, expect", [
    ("/abs/g", "/abs/x", "/abs/g"),
    ("", "/abs/x", "/abs/x/gearcli"),
    ("rel/g", "/abs/x", "/abs/x/gearcli"),         # a relative GEARCLI_CACHE_DIR is ignored ...
    ("", "rel/x", "HOME/.cache/gearcli"),          # ... and so is a relative XDG_CACHE_HOME (XDG spec)
    ("./g", ".", "HOME/.cache/gearcli"),
    ("", "", "HOME/.cache/gearcli"),
])
def test_cache_root_ignores_relative_values(monkeypatch, tmp_path, gearcli, xdg, expect):
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.setenv("GEARCLI_CACHE_DIR", gearcli)
    monkeypatch.setenv("XDG_CACHE_HOME", xdg)
    assert cr.cache_root() == Path(expect.replace("HOME", str(tmp_path)))


def test_cache_root_of_a_relative_xdg_is_not_in_the_working_directory(monkeypatch, tmp_path):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    monkeypatch.delenv("GEARCLI_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", "cache")
    assert cr.cache_root().is_absolute() and cr.cache_root() == tmp_path / "home" / ".cache" / "gearcli"


def test_read_entry_reads_a_regular_file(tmp_path):
    (tmp_path / "e").write_bytes(b"abc")
    assert cr.read_entry(tmp_path / "e", 3) == b"abc"
    with pytest.raises(FileNotFoundError):
        cr.read_entry(tmp_path / "missing", 3)


@pytest.mark.parametrize("kind", ["fifo", "symlink to /dev/zero", "symlink to a regular file", "folder", "too large"])
def test_read_entry_refuses_what_is_not_a_small_regular_file(tmp_path, kind):
    path = tmp_path / "e"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "symlink to /dev/zero":
        path.symlink_to("/dev/zero")
    elif kind == "symlink to a regular file":
        (tmp_path / "t").write_bytes(b"x")
        path.symlink_to(tmp_path / "t")
    elif kind == "folder":
        path.mkdir()
    else:
        path.write_bytes(b"x" * 101)
    with pytest.raises(cr.BadEntry):
        in_thread(lambda: cr.read_entry(path, 100))
    cr.remove_entry(path)
    assert not os.path.lexists(path)
    assert kind != "symlink to a regular file" or (tmp_path / "t").read_bytes() == b"x"


def test_write_entry_replaces_a_symlink_not_its_target(tmp_path):
    (tmp_path / "victim").write_bytes(b"keep")
    (tmp_path / "c").mkdir()
    (tmp_path / "c" / "e").symlink_to(tmp_path / "victim")
    assert cr.write_entry(tmp_path / "c" / "e", b"new")
    assert (tmp_path / "victim").read_bytes() == b"keep"
    assert not (tmp_path / "c" / "e").is_symlink() and (tmp_path / "c" / "e").read_bytes() == b"new"


@pytest.mark.parametrize("tmpfile", ["O_TMPFILE", "named temporary file"])
def test_a_failed_write_leaves_nothing(tmp_path, monkeypatch, tmpfile):
    """A full disk (ENOSPC from write) is no error and leaves no file, whichever kind of
    temporary file the system gives; the entry before stays as it was."""
    if tmpfile != "O_TMPFILE":
        monkeypatch.delattr(os, "O_TMPFILE", raising=False)
    (tmp_path / "e").write_bytes(b"old")

    def full(fd, data):
        raise OSError(errno.ENOSPC, "No space left on device")
    monkeypatch.setattr(os, "write", full)
    assert cr.write_entry(tmp_path / "e", b"new") is False
    monkeypatch.undo()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e"] and (tmp_path / "e").read_bytes() == b"old"


@pytest.mark.parametrize("where", ["a file, not a folder", "below a file", "under /proc"])
def test_an_unusable_folder_is_no_error(tmp_path, where):
    (tmp_path / "f").write_text("x")
    d = {"a file, not a folder": tmp_path / "f", "below a file": tmp_path / "f" / "d",
         "under /proc": Path("/proc/gearcli-test")}[where]
    assert cr.write_entry(d / "e", b"x") is False
    assert (tmp_path / "f").read_text() == "x" and sorted(p.name for p in tmp_path.iterdir()) == ["f"]

