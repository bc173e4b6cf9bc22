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
* An entry holds its key, the blocks, the maximum flow they were found from and a SHA-256
  of both.  A checksum is no proof (anyone can recompute one): the blocks are used only
  when the flow is a maximum flow of *this* incidence and the schedule derived from it in
  plain Python (:func:`.schedule_proof.proven_blocks`) is the stored one.  An entry that
  fails any of this (truncated, foreign, forged, not JSON, nested 100,000 deep, larger than
  :data:`MAX_ENTRY_BYTES`, a FIFO or symlink, :func:`gearcli.io.cache_root.read_entry`) is
  deleted and the schedule recomputed: :func:`load` never raises.
* Like the kernel cache: a location that cannot be created or written is no error (nothing
  is cached), writes are atomic (:func:`gearcli.io.cache_root.write_entry`), and after a
  write the oldest entries beyond :data:`MAX_ENTRIES` go.
"""
from __future__ import annotations

import hashlib
import json
import os
import time
from functools import lru_cache
from pathlib import Path

from ..io.cache_root import BadEntry, cache_root, read_entry, remove_entry, write_entry
from .schedule_proof import proven_blocks

FORMAT = 2
MAX_ENTRIES = 2000
MAX_ENTRY_BYTES = 64 * 2**20        # 10,000 links: ~1 MB
_STALE_TEMP_SECONDS = 3600.0


def cache_dir() -> Path:
    """The folder of the schedule entries (not created here)."""
    return cache_root() / "schedule"


@lru_cache(maxsize=1)
def scheduler_digest() -> str | None:
    """SHA-256 of the source of :mod:`.schedule` and :mod:`.schedule_proof` (None: one cannot
    be read; then nothing is cached)."""
    h = hashlib.sha256()
    try:
        for name in ("schedule.py", "schedule_proof.py"):
            h.update(hashlib.sha256((Path(__file__).parent / name).read_bytes()).digest())
    except OSError:
        return None
    return h.hexdigest()


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


def _entry_sha(blocks, flow) -> str:
    return hashlib.sha256(json.dumps([blocks, flow], separators=(",", ":")).encode()).hexdigest()


def load(key: str | None, moving, groups=None, level=None, primary=()) -> tuple[tuple[int, ...], ...] | None:
    """The schedule stored under ``key`` (blocks of link ids), or None (absent; or not whole,
    not this key's, or not the schedule its maximum flow proves for ``moving`` links,
    unknown ``groups``, ``level`` and ``primary`` links (:func:`.schedule_proof.proven_blocks`):
    then deleted).  Never raises: a special file, a huge or deeply nested entry is damage too."""
    if key is None:
        return None
    path = cache_dir() / f"{key}.json"
    try:
        entry = json.loads(read_entry(path, MAX_ENTRY_BYTES))
    except FileNotFoundError:
        return None
    except BadEntry:
        return remove_entry(path)
    except OSError:                 # unreadable: leave it
        return None
    except (ValueError, RecursionError, MemoryError):
        return remove_entry(path)
    blocks = _proven(entry, key, moving, groups, level, primary)
    if blocks is None:
        return remove_entry(path)
    try:
        os.utime(path)              # the newest again: pruned last
    except OSError:
        pass
    return blocks


def _proven(entry, key, moving, groups, level, primary):
    """The blocks of ``entry`` when it is whole, ``key``'s, and its flow proves them."""
    if not (isinstance(entry, dict) and entry.get("key") == key and isinstance(entry.get("blocks"), list)):
        return None
    blocks, flow = entry["blocks"], entry.get("flow")
    try:
        if entry.get("sha") != _entry_sha(blocks, flow) or groups is None:
            return None
    except (ValueError, TypeError, RecursionError):
        return None
    proven = proven_blocks(flow, moving, groups, level, primary)
    return proven if proven is not None and [list(b) for b in proven] == blocks else None


def store(key: str | None, blocks, flow) -> bool:
    """Keep ``blocks`` and the maximum ``flow`` they come from ([link, group index, scalars]
    triples, :func:`.schedule.matched_flow`) under ``key``; False where the cache is not
    writable (or no key)."""
    if key is None:
        return False
    blocks = [[int(x) for x in b] for b in blocks]
    flow = [[int(v) for v in t] for t in flow]
    text = json.dumps({"key": key, "blocks": blocks, "flow": flow, "sha": _entry_sha(blocks, flow)})
    d = cache_dir()
    if not write_entry(d / f"{key}.json", text.encode()):
        return False
    prune(d)
    return True


def prune(d: Path, max_entries: int = MAX_ENTRIES) -> None:
    """Delete the oldest entries of ``d`` beyond ``max_entries`` and temporary files left
    by a killed writer (on a system without ``O_TMPFILE``) an hour ago or earlier."""
    try:
        files = sorted((e.stat(follow_symlinks=False).st_mtime, e.path) for e in os.scandir(d)
                       if e.name.endswith(".json") or e.name.startswith(".gearcli."))
    except OSError:
        return
    entries = [f for f in files if f[1].endswith(".json")]
    for _, path in entries[:max(0, len(entries) - max_entries)]:
        remove_entry(Path(path))
    now = time.time()
    for mtime, path in files:
        if os.path.basename(path).startswith(".gearcli.") and now - mtime > _STALE_TEMP_SECONDS:
            remove_entry(Path(path))
