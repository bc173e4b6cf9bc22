"""The disk cache of the generated llvm kernels' machine code (:class:`.llvm_driver.Jit`).

An entry is the object code MCJIT made of one IR module for one host, in
``<cache dir>/llvm/<key>.obj``: the key hashes the IR text, the target triple, the host
CPU's name and features, the llvmlite and LLVM versions and :data:`FORMAT`, so a second
process compiling the same IR on the same machine loads the object code instead of
optimising and generating it again.  The cache dir is ``$GEARCLI_CACHE_DIR`` if set, else
``$XDG_CACHE_HOME/gearcli`` or ``~/.cache/gearcli``.

* A location that cannot be created or written is no error: the kernel is compiled in
  memory as without a cache (every failure of this module is silent, by design).
* Writes are atomic (:func:`gearcli.io.output.atomic_output`: an anonymous file in the
  same folder, named when whole): concurrent processes or threads storing the same key
  each leave a whole entry.
* An entry holds :data:`MAGIC`, its payload's length and SHA-256 before the payload; one
  that does not match (truncated, corrupted) is deleted and the kernel recompiled.
* Bounded: after a write the oldest entries (by modification time, which a hit renews)
  go beyond :data:`MAX_ENTRIES` or :data:`MAX_BYTES`.

``<program key>.prog`` files name the object key of a kernel program (its arrays and
loads, hashed without building the IR, see :func:`program_key`): :func:`.backends.
llvm_compile_estimate` asks :func:`has_program` whether a compile would be a load, and
:class:`.llvm_driver.Jit` loads the object code through :func:`load_program` without
generating the IR at all (~0.05 s for the Bendix wrist) when the program key also hashes
the source of the IR generator (:func:`.llvm_driver.generator_digest`).
"""
from __future__ import annotations

import hashlib
import os
import time
from pathlib import Path

import numpy as np

from ..io.cache_root import cache_root
from ..io.output import OutputError, atomic_output

FORMAT = 1                          # ours: change when the entry layout or the key changes
MAGIC = b"gearcli-llvm-obj\x00"
_HEAD = len(MAGIC) + 8 + 32         # magic, payload length (little endian), SHA-256
MAX_ENTRIES = 500
MAX_BYTES = 200 * 2**20
_STALE_TEMP_SECONDS = 3600.0


def cache_dir() -> Path:
    """The folder of the llvm entries (not created here)."""
    return cache_root() / "llvm"


def _sha(parts) -> str:
    h = hashlib.sha256()
    for p in parts:
        b = p if isinstance(p, bytes) else str(p).encode()
        h.update(len(b).to_bytes(8, "little") + b)
    return h.hexdigest()


def object_key(ir: str, host: str) -> str:
    """The entry name of the object code of IR text ``ir`` on ``host`` (:func:`.llvm_driver.host_identity`)."""
    return _sha(["object", FORMAT, host, ir])


def program_key(prog, loads: list, host: str, version: str) -> str:
    """A key of what the IR is generated from: the kernel program's arrays and fields, the
    external loads (:func:`.llvm_driver.mech_loads`), the host and gearcli's version."""
    parts = ["program", FORMAT, host, version, prog.ncols, sorted(prog.offsets.items()), prog.signed,
             prog.names, prog.covered]
    for a in (*prog.ints, *prog.flts):
        a = np.ascontiguousarray(a)
        parts += [a.dtype.str, a.shape, a.tobytes()]
    for link, in_link, point in loads:
        parts += [link, in_link, np.asarray(point, float).tobytes()]
    return _sha(parts)


def load(key: str) -> bytes | None:
    """The object code stored under ``key``, or None (absent, unreadable or not whole: then deleted)."""
    path = cache_dir() / f"{key}.obj"
    try:
        data = path.read_bytes()
    except OSError:
        return None
    payload = data[_HEAD:]
    n = int.from_bytes(data[len(MAGIC):len(MAGIC) + 8], "little") if len(data) >= _HEAD else -1
    if (data[:len(MAGIC)] != MAGIC or n != len(payload) or not payload
            or data[len(MAGIC) + 8:_HEAD] != hashlib.sha256(payload).digest()):
        _remove(path)
        return None
    try:
        os.utime(path)              # the newest again: pruned last
    except OSError:
        pass
    return payload


def _write(path: Path, data: bytes) -> bool:
    """``data`` into ``path`` atomically (False where that fails)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_output(path, binary=True) as f:
            f.write(data)
        return True
    except (OSError, OutputError):
        return False


def store(key: str, payload: bytes) -> bool:
    """Keep ``payload`` (object code) under ``key``; False where the cache is not writable."""
    head = MAGIC + len(payload).to_bytes(8, "little") + hashlib.sha256(payload).digest()
    ok = _write(cache_dir() / f"{key}.obj", head + bytes(payload))
    if ok:
        prune(cache_dir())
    return ok


def note_program(pkey: str, key: str) -> None:
    """Remember that program key ``pkey`` compiles to object key ``key`` (for the estimate)."""
    path = cache_dir() / f"{pkey}.prog"
    try:
        if path.read_text() == key:
            return
    except (OSError, ValueError):
        pass
    _write(path, key.encode())


def load_program(pkey: str) -> tuple[str, bytes] | None:
    """(object key, object code) noted for program key ``pkey``, or None (no note, or its
    entry absent or not whole)."""
    try:
        key = (cache_dir() / f"{pkey}.prog").read_text()
    except (OSError, ValueError):
        return None
    payload = load(key) if len(key) == 64 else None
    return None if payload is None else (key, payload)


def has_program(pkey: str) -> bool:
    """True when program key ``pkey``'s object code is in the cache (a compile would be a load)."""
    d = cache_dir()
    try:
        key = (d / f"{pkey}.prog").read_text()
        return len(key) == 64 and (d / f"{key}.obj").is_file()
    except (OSError, ValueError):
        return False


def prune(d: Path, max_entries: int = MAX_ENTRIES, max_bytes: int = MAX_BYTES) -> None:
    """Delete the oldest entries of ``d`` beyond ``max_entries`` / ``max_bytes`` (objects and
    program notes counted apart) and temporary files left by a killed writer."""
    try:
        files = [(e.stat().st_mtime, e.stat().st_size, Path(e.path)) for e in os.scandir(d) if e.is_file()]
    except OSError:
        return
    now = time.time()
    for suffix in (".obj", ".prog"):
        kept, size = 0, 0
        for mtime, nbytes, path in sorted((f for f in files if f[2].suffix == suffix), reverse=True):
            kept, size = kept + 1, size + nbytes
            if kept > max_entries or size > max_bytes:
                _remove(path)
    for mtime, _, path in files:
        if path.name.startswith(".gearcli.") and now - mtime > _STALE_TEMP_SECONDS:
            _remove(path)


def _remove(path: Path) -> None:
    try:
        path.unlink()
    except OSError:
        pass
