"""The disk cache of solution schedules (:func:`.schedule.solution_schedule`).

Every command analyses its mechanism, and the schedule's maximum flow and strong components
are scipy.sparse.csgraph's, whose import (~0.25 s with the scipy.sparse and numpy modules it
pulls in) was a third of a ``gearcli check``.  The schedule is a pure function of the
equation/unknown incidence, the links' levels and which links are primary (the blocks and
their partial order do not depend on the matching found), so a process analysing a
mechanism some earlier process scheduled reads the blocks from
``<cache dir>/schedule/<key>.json`` (:func:`gearcli.io.cache_root.cache_root`) instead.

* The key hashes those inputs, :data:`FORMAT` and the source of :mod:`.schedule` (a changed
  scheduler never reads an older one's entries).
* Only schedules are stored: a mechanism whose loads are not determined is found out by the
  flow in every process (its messages need it).
* An entry holds its key, the blocks and their SHA-256; one that does not match, or whose
  blocks are not a partition of the moving links, is deleted and the schedule recomputed.
* Like the kernel cache: a location that cannot be created or written is no error (nothing
  is cached), writes are atomic, and after a write the oldest entries beyond
  :data:`MAX_ENTRIES` go.
"""
from __future__ import annotations

import hashlib
import json
import os
from functools import lru_cache
from pathlib import Path

from ..io.cache_root import cache_root
from ..io.output import OutputError, atomic_output

FORMAT = 1
MAX_ENTRIES = 2000


def cache_dir() -> Path:
    """The folder of the schedule entries (not created here)."""
    return cache_root() / "schedule"


@lru_cache(maxsize=1)
def scheduler_digest() -> str | None:
    """SHA-256 of :mod:`.schedule`'s source (None: it cannot be read; then nothing is cached)."""
    try:
        return hashlib.sha256((Path(__file__).parent / "schedule.py").read_bytes()).hexdigest()
    except OSError:
        return None


def schedule_key(moving, groups, redundant: bool, level, primary) -> str | None:
    """The entry name of the schedule of moving links ``moving`` with unknown groups
    ``groups`` (their links and sizes, in order), ``level`` per link and the ``primary``
    links (None: no caching)."""
    digest = scheduler_digest()
    if digest is None:
        return None
    moving = [int(x) for x in moving]
    parts = [FORMAT, digest, moving, [[[int(x) for x in g.links], int(g.size)] for g in groups], bool(redundant),
             [int(level[x]) for x in moving], sorted(int(x) for x in primary if x in set(moving))]
    return hashlib.sha256(json.dumps(parts, separators=(",", ":")).encode()).hexdigest()


def _blocks_sha(blocks) -> str:
    return hashlib.sha256(json.dumps(blocks, separators=(",", ":")).encode()).hexdigest()


def load(key: str | None, moving) -> tuple[tuple[int, ...], ...] | None:
    """The schedule stored under ``key`` (blocks of link ids), or None (absent, or not whole
    or not a partition of ``moving``: then deleted)."""
    if key is None:
        return None
    path = cache_dir() / f"{key}.json"
    try:
        entry = json.loads(path.read_text())
    except FileNotFoundError:
        return None
    except (OSError, ValueError):
        return _remove(path)
    try:
        blocks = entry["blocks"]
        ok = (entry["key"] == key and entry["sha"] == _blocks_sha(blocks)
              and all(isinstance(x, int) for b in blocks for x in b) and all(blocks)
              and sorted(x for b in blocks for x in b) == sorted(int(x) for x in moving))
    except (KeyError, TypeError):
        ok = False
    if not ok:
        return _remove(path)
    try:
        os.utime(path)              # the newest again: pruned last
    except OSError:
        pass
    return tuple(tuple(b) for b in blocks)


def store(key: str | None, blocks) -> bool:
    """Keep ``blocks`` under ``key``; False where the cache is not writable (or no key)."""
    if key is None:
        return False
    blocks = [[int(x) for x in b] for b in blocks]
    text = json.dumps({"key": key, "blocks": blocks, "sha": _blocks_sha(blocks)})
    d = cache_dir()
    try:
        d.mkdir(parents=True, exist_ok=True)
        with atomic_output(d / f"{key}.json") as f:
            f.write(text)
    except (OSError, OutputError):
        return False
    prune(d)
    return True


def prune(d: Path, max_entries: int = MAX_ENTRIES) -> None:
    """Delete the oldest entries of ``d`` beyond ``max_entries``."""
    try:
        files = sorted((e.stat().st_mtime, e.path) for e in os.scandir(d) if e.name.endswith(".json"))
    except OSError:
        return
    for _, path in files[:max(0, len(files) - max_entries)]:
        _remove(Path(path))


def _remove(path: Path) -> None:
    try:
        path.unlink()
    except OSError:
        pass
