"""The disk cache of the generated llvm kernels' machine code (:class:`.driver.Jit`).

An entry is the object code MCJIT made of one IR module for one host, in
``<cache dir>/llvm/<key>.obj``: the key hashes the IR text, the target triple, the host
CPU's name and features, the llvmlite and LLVM versions and :data:`FORMAT`, so a second
process compiling the same IR on the same machine loads the object code instead of
optimising and generating it again.  The cache dir is :func:`gearcli.io.cache_root.cache_root`
(``$GEARCLI_CACHE_DIR``, ``$XDG_CACHE_HOME/gearcli`` or ``~/.cache/gearcli``).

* A location that cannot be created or written is no error: the kernel is compiled in
  memory as without a cache (every failure of this module is silent, by design).
* Writes are atomic (:func:`gearcli.io.cache_root.write_entry`: an anonymous file in the
  same folder, named when whole): concurrent processes or threads storing the same key
  each leave a whole entry.
* An entry holds :data:`MAGIC`, the lengths of its header and payload and the SHA-256 of
  both, then the header (the entry's own object key and the fingerprints of the kernel
  programs it is the code of, :func:`program_fingerprint`: the one it was compiled for,
  and those whose IR was found to hash to its key) and the payload.  One that
  does not match (truncated, corrupted) or that is not the entry of the key asked for (a
  foreign entry: another kernel's file under this name, an entry copied from another
  cache) is deleted, the kernel recompiled and the entry written again: machine code is
  run only when its entry proves it is the code of this key (and, loaded by program, of
  this program), checked before the first call.
* Only regular files of at most :data:`MAX_ENTRY_BYTES` are read (:func:`gearcli.io.
  cache_root.read_entry`): a FIFO, a device, a symlink or a folder in an entry's place is
  removed, never opened for reading in a way that could block.
* Bounded: after a write the oldest entries (by modification time, which a hit renews)
  go beyond :data:`MAX_ENTRIES` or :data:`MAX_BYTES`.

The IR, hence the object code, holds no value of the mechanism: its constants are read
from a pool declared as zeros (:class:`.build.ConstantPool`), whose values :class:`.driver.Jit`
writes where it loads the code.  So mechanisms that differ only in values (a sweep's
variants of a ratio, a mass, an efficiency) share one entry.
``<program key>.prog`` notes hold their own program key, the object key of that kernel
program (its arrays and loads, hashed without building the IR, see :func:`program_key`),
the SHA-256 of the rest and the values of its constant pools; a note that does not name
itself (moved from another program's name) or whose digest does not match is deleted.
:func:`..backends.llvm_on_disk` (the first-call rule) asks :func:`has_program` whether a compile would be a load, and
:class:`.driver.Jit` loads the object code through :func:`load_program` without
generating the IR at all (~0.05 s for the Bendix wrist) when the program key also hashes
the source of the IR generator (:func:`.driver.generator_digest`).
"""
from __future__ import annotations

import hashlib
import os
import time
from pathlib import Path

import numpy as np

from ...io.cache_root import BadEntry, cache_root, read_entry, remove_entry, write_entry

FORMAT = 4                          # ours: change when the entry layout, the key or what an IR compiles to
# changes (3: the middle-end passes skipped for a large IR, driver.pass_level; 4: the constant pools
# are data, kept in the program notes)
MAGIC = b"gearcli-llvm-obj\x00"
_HEAD = len(MAGIC) + 8 + 8 + 32     # magic, header and payload lengths (little endian), SHA-256
MAX_ENTRIES = 500
MAX_BYTES = 200 * 2**20
MAX_ENTRY_BYTES = 64 * 2**20        # one kernel's object code is 15-300 kB
MAX_PROGRAMS = 16                   # kernel programs noted in one entry (same IR: loads differ, names differ)
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
    """The entry name of the object code of IR text ``ir`` on ``host`` (:func:`.driver.host_identity`)."""
    return _sha(["object", FORMAT, host, ir])


def program_fingerprint(prog, loads: list) -> str:
    """SHA-256 of what a kernel's IR is generated from: the kernel program's arrays and
    fields and the external loads (:func:`.driver.mech_loads`); kept in each entry."""
    parts = ["fingerprint", FORMAT, prog.ncols, sorted(prog.offsets.items()), prog.signed, prog.names, prog.covered]
    for name, a in prog.arrays():
        a = np.ascontiguousarray(a)
        parts += [name, str(a.dtype), a.shape, a.tobytes()]
    parts += [prog.base]
    for link, in_link, point in loads:
        parts += [link, in_link, np.asarray(point, float).tobytes()]
    if getattr(prog, "losses", None) is not None:
        parts += ["losses", *prog.losses.parts()]
    return _sha(parts)


def program_key(fingerprint: str, host: str, version: str) -> str:
    """A key of what the IR is generated from (the :func:`program_fingerprint` of its kernel
    program), the host and gearcli's version (with its generator's source digest)."""
    return _sha(["program", FORMAT, host, version, fingerprint])


def _read(path: Path, max_bytes: int = MAX_ENTRY_BYTES) -> bytes | None:
    """The bytes of entry ``path``, or None (absent or unreadable; a special file, symlink
    or oversized entry is removed)."""
    try:
        return read_entry(path, max_bytes)
    except BadEntry:
        remove_entry(path)
    except OSError:
        pass
    return None


def load(key: str, fingerprint: str | None = None, adopt: str = "") -> bytes | None:
    """The object code stored under ``key``, or None (absent, unreadable, not whole or not
    this key's entry: then deleted).  With ``fingerprint``, only an entry compiled for that
    kernel program (:func:`program_fingerprint`) is taken; another's is left in place.
    ``adopt``: a program whose IR is ``key``'s (the caller generated and hashed it), added
    to the entry's programs (at most :data:`MAX_PROGRAMS`, the newest kept) so that it is
    found by program next time."""
    path = cache_dir() / f"{key}.obj"
    data = _read(path)
    if data is None:
        return None
    entry = _parse(data)
    if entry is None or entry[0] != key:
        remove_entry(path)
        return None
    if fingerprint is not None and fingerprint not in entry[1]:
        return None
    if adopt and adopt not in entry[1]:
        write_entry(path, entry_bytes(key, entry[2], (*entry[1], adopt)[-MAX_PROGRAMS:]))
    try:
        os.utime(path)              # the newest again: pruned last
    except OSError:
        pass
    return entry[2]


def _parse(data: bytes) -> tuple[str, tuple[str, ...], bytes] | None:
    """(object key, program fingerprints, payload) of an entry's bytes (None: not whole)."""
    if len(data) < _HEAD or data[:len(MAGIC)] != MAGIC:
        return None
    nh = int.from_bytes(data[len(MAGIC):len(MAGIC) + 8], "little")
    npl = int.from_bytes(data[len(MAGIC) + 8:len(MAGIC) + 16], "little")
    body = data[_HEAD:]
    if nh + npl != len(body) or npl == 0 or data[_HEAD - 32:_HEAD] != hashlib.sha256(body).digest():
        return None
    try:
        key, *fingerprints = body[:nh].decode("ascii").split("\n")
    except UnicodeDecodeError:
        return None
    return key, tuple(fingerprints), body[nh:]


def entry_bytes(key: str, payload: bytes, fingerprints: tuple[str, ...] = ()) -> bytes:
    """The entry of object code ``payload`` under ``key`` for the kernel programs ``fingerprints``."""
    header = "\n".join((key, *fingerprints)).encode("ascii")
    body = header + bytes(payload)
    return MAGIC + len(header).to_bytes(8, "little") + len(payload).to_bytes(8, "little") + \
        hashlib.sha256(body).digest() + body


def store(key: str, payload: bytes, fingerprint: str = "") -> bool:
    """Keep ``payload`` (object code of program ``fingerprint``) under ``key``; False where
    the cache is not writable."""
    ok = write_entry(cache_dir() / f"{key}.obj", entry_bytes(key, payload, (fingerprint,) if fingerprint else ()))
    if ok:
        prune(cache_dir())
    return ok


def _note(pkey: str) -> tuple[str, dict] | None:
    """(object key, constant pools) of program key ``pkey``'s note (None: no note; one that
    is not ``pkey``'s own, or damaged, is deleted).  The pools are the values of the
    kernel's constant pools (:class:`.build.ConstantPool`: {symbol: float64 array}), data
    that the object code does not hold."""
    path = cache_dir() / f"{pkey}.prog"
    data = _read(path, MAX_NOTE_BYTES)
    if data is None:
        return None
    head, _, body = data.partition(b"\n")
    parts = head.split(b" ")
    pools = _pools(body) if len(parts) == 3 and parts[2] == hashlib.sha256(body).hexdigest().encode() else None
    if pools is None or parts[0] != pkey.encode() or len(parts[1]) != 64 or not parts[1].isalnum():
        remove_entry(path)
        return None
    return parts[1].decode(), pools


MAX_NOTE_BYTES = 8 * 2**20          # a note's pools: 8 bytes a constant, some thousands


def _pools(body: bytes) -> dict | None:
    """The {symbol: values} a note's body holds (a line "symbol count ..." then the doubles), or None."""
    line, _, raw = body.partition(b"\n")
    try:
        words = line.decode("ascii").split()
        names, counts = words[0::2], [int(c) for c in words[1::2]]
    except (UnicodeDecodeError, ValueError):
        return None
    if len(names) != len(counts) or 8 * sum(counts) != len(raw):
        return None
    values = np.frombuffer(raw, "<f8")
    cuts = np.cumsum([0] + counts)
    return {n: values[a:b].copy() for n, a, b in zip(names, cuts, cuts[1:])}


def note_program(pkey: str, key: str, pools: dict) -> None:
    """Remember that program key ``pkey`` compiles to object key ``key`` with these constant
    pools ({symbol: values}, the data of its code)."""
    names = sorted(pools)
    body = (" ".join(f"{n} {len(pools[n])}" for n in names) + "\n").encode() + b"".join(
        np.ascontiguousarray(pools[n], "<f8").tobytes() for n in names)
    path = cache_dir() / f"{pkey}.prog"
    content = f"{pkey} {key} {hashlib.sha256(body).hexdigest()}\n".encode() + body
    if _read(path, MAX_NOTE_BYTES) != content:
        write_entry(path, content)


def load_program(pkey: str, fingerprint: str | None = None) -> tuple[str, bytes, dict] | None:
    """(object key, object code, constant pools) noted for program key ``pkey`` (and kernel
    program ``fingerprint``), or None (no note, or its entry absent, not whole or another program's)."""
    note = _note(pkey)
    payload = None if note is None else load(note[0], fingerprint)
    return None if payload is None else (note[0], payload, note[1])


def has_program(pkey: str) -> bool:
    """True when program key ``pkey``'s object code is in the cache (a compile would be a
    load; a guess: the entry is not read)."""
    note = _note(pkey)
    try:
        return note is not None and (cache_dir() / f"{note[0]}.obj").is_file()
    except OSError:
        return False


def prune(d: Path, max_entries: int = MAX_ENTRIES, max_bytes: int = MAX_BYTES) -> None:
    """Delete the oldest entries of ``d`` beyond ``max_entries`` / ``max_bytes`` (objects and
    program notes counted apart) and temporary files left by a killed writer."""
    try:
        files = []
        for e in os.scandir(d):
            if e.is_file(follow_symlinks=False):
                st = e.stat(follow_symlinks=False)
                files.append((st.st_mtime, st.st_size, Path(e.path)))
    except OSError:
        return
    now = time.time()
    for suffix in (".obj", ".prog"):
        kept, size = 0, 0
        for mtime, nbytes, path in sorted((f for f in files if f[2].suffix == suffix), reverse=True):
            kept, size = kept + 1, size + nbytes
            if kept > max_entries or size > max_bytes:
                remove_entry(path)
    for mtime, _, path in files:
        if path.name.startswith(".gearcli.") and now - mtime > _STALE_TEMP_SECONDS:
            remove_entry(path)
