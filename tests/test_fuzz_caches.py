"""Property-based fuzzing of gearcli's disk caches (issue 17): the llvm kernel cache and the
schedule cache under faults, through ``gearcli solve --backend llvm`` in a child process.

Each input is a cache made of the whole entries two or three bundled mechanisms left in
clean runs (kernel objects ``.obj``, program notes ``.prog``, schedules ``.json``), with
faults applied to the entries of the mechanism solved:

* foreign entries: swapped with or copied over from another mechanism's (entries, notes,
  schedules);
* truncated entries, flipped bytes;
* special files in an entry's place: a FIFO, a symlink to ``/dev/zero``, an empty or a
  full folder;
* deep (100,000 levels), huge (beyond the entry bound) and forged (blocks reversed or
  merged, checksum recomputed) schedule JSON;
* odd cache folders: a file where the root, ``llvm/`` or ``schedule/`` folder should be, a
  path below a file, under ``/proc``, ``/dev/null``, relative ``GEARCLI_CACHE_DIR`` or
  ``XDG_CACHE_HOME``; writes denied (a read-only folder: the tests run as root, for whom
  permissions do not apply, so the cache writer is made to get EACCES) or the disk full
  after a random number of bytes, with and without ``O_TMPFILE``;
* concurrent cold compiles: 2-4 processes solving the same and different mechanisms at
  once against an empty cache.

Oracle (every run): exit status 0, never a crash signal, never a hang (a time limit); the
loads table (``--precision 17``) bit for bit the clean run's (an empty cache); no
traceback; no temporary file left in the cache, nothing written in the working directory
but the table; inputs unchanged.  Children fork from a clean server process
(:func:`cache_faults.start_cli`): a crash or hang fails the example, not pytest.

Profiles and recording as :mod:`test_fuzz` (``GEARCLI_FUZZ=ci`` default, fast;
``GEARCLI_FUZZ=long`` ~1,000 inputs; ``GEARCLI_FUZZ_RECORD=stats.jsonl`` records one JSON
line per input instead of failing).
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
from pathlib import Path

import pytest

pytest.importorskip("llvmlite")
pytest.importorskip("hypothesis")
from hypothesis import example, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from cache_faults import finish_cli, make_special, put, stale_files, start_cli  # noqa: E402
from test_fuzz import HANG_SECONDS, MECH_DIR, PROFILE, short_csv, verdict  # noqa: E402

MECHS = ["paper_2dof.yaml", "bendix_wrist.yaml", "rack_axis.yaml"]
KINDS = [".obj", ".prog", ".json"]
SECONDS = 4 * HANG_SECONDS        # a cold compile of the Bendix wrist on a busy 2-core machine: ~2 s


def count(ci: int, long: int):
    return settings(max_examples=ci if PROFILE == "ci" else long)


def inputs_of(name: str) -> dict[str, bytes]:
    traj = name.replace(".yaml", "_traj.csv")
    return {name: (MECH_DIR / name).read_bytes(), traj: short_csv(traj, 30)}


def solve_args(name: str, work: Path, out: str = "out.csv") -> list[str]:
    return ["solve", work / name, work / name.replace(".yaml", "_traj.csv"), "-o", work / out,
            "--backend", "llvm", "--precision", "17", "-j", "1"]


def new_work(base: Path, name: str, files: dict) -> Path:
    work = base / f"work-{name}"
    work.mkdir()
    for k, v in files.items():
        (work / k).write_bytes(v)
    return work


_CLEAN: dict = {}


def clean() -> dict:
    """Per mechanism: (the clean run's table bytes, {suffix: (entry name, bytes)} of the
    entries its clean run left in an empty cache)."""
    if not _CLEAN:
        base = Path(tempfile.mkdtemp(prefix="gearcli-fuzz-clean-"))
        for name in MECHS:
            work = new_work(base, name, inputs_of(name))
            cache = base / f"cache-{name}"
            code, _, err = finish_cli(start_cli(solve_args(name, work), work, {"GEARCLI_CACHE_DIR": str(cache)}),
                                      SECONDS)
            assert code == 0, err
            entries = {p.suffix: (str(p.relative_to(cache)), p.read_bytes()) for p in cache.rglob("*") if p.is_file()}
            assert sorted(entries) == sorted(KINDS), entries
            _CLEAN[name] = (work / "out.csv").read_bytes(), entries
        shutil.rmtree(base, ignore_errors=True)
    return _CLEAN


def problems(code, out: str, err: str, work: Path, files: dict, table: bytes, cache: Path | None,
             outputs=("out.csv",)) -> list[str]:
    """Every broken promise of one run (empty when it behaved)."""
    if code is None:
        return [f"hang (> {SECONDS} s)"]
    found = []
    if code < 0:
        found.append(f"crash: signal {-code}")
    elif code != 0:
        found.append(f"exit {code}: {err[-800:]}")
    if "Traceback" in out + err:
        found.append("traceback: " + err[-800:])
    for name, data in files.items():
        if not (work / name).is_file() or (work / name).read_bytes() != data:
            found.append(f"input {name} changed")
    for p in work.iterdir():
        if p.name not in files and p.name not in outputs:
            found.append(f"file {p.name} written in the working directory")
    for o in outputs:
        if code == 0 and (not (work / o).is_file() or (work / o).read_bytes() != table):
            found.append(f"{o} differs from the clean run's")
    if cache is not None:
        found += [f"stale file {p}" for p in stale_files(cache)]
    return found


# --- faults on the entries ----------------------------------------------------------------
@st.composite
def entry_fault(draw):
    kind = draw(st.sampled_from(["swap", "copy", "truncate", "flip", "special", "schedule"]))
    suffix = draw(st.sampled_from(KINDS))
    return {"kind": kind, "suffix": suffix, "a": draw(st.integers(0, 1 << 30)), "b": draw(st.integers(0, 255)),
            "special": draw(st.sampled_from(["fifo", "symlink to /dev/zero", "folder", "full folder"])),
            "schedule": draw(st.sampled_from(["deep", "huge", "reversed", "merged", "not json"]))}


def forged(data: bytes, how: str) -> bytes:
    """A schedule entry with its blocks reversed or merged and its checksum recomputed."""
    entry = json.loads(data)
    b = entry["blocks"]
    entry["blocks"] = b[::-1] if how == "reversed" else [b[0] + b[1]] + b[2:] if len(b) > 1 else b
    text = json.dumps([entry["blocks"], entry["flow"]], separators=(",", ":"))
    entry["sha"] = hashlib.sha256(text.encode()).hexdigest()
    return json.dumps(entry).encode()


def apply_fault(cache: Path, own: dict, other: dict, fault: dict) -> dict:
    """Apply ``fault`` to the entries ``own`` ({suffix: (name, bytes)}) in ``cache`` (``other``:
    another mechanism's); options for the child."""
    name, data = own[fault["suffix"]]
    path, other_path = cache / name, cache / other[fault["suffix"]][0]
    kind = fault["kind"]
    if kind == "swap":
        put(path, other[fault["suffix"]][1])
        put(other_path, data)
    elif kind == "copy":
        put(path, other[fault["suffix"]][1])
    elif kind == "truncate":
        put(path, data[:fault["a"] % max(1, len(data))])
    elif kind == "flip":
        i = fault["a"] % len(data)
        put(path, data[:i] + bytes([data[i] ^ (fault["b"] or 1)]) + data[i + 1:])
    elif kind == "special":
        make_special(path, "folder" if fault["special"] == "full folder" else fault["special"],
                     full=fault["special"] == "full folder")
    else:
        s = cache / own[".json"][0]
        how = fault["schedule"]
        if how == "deep":
            put(s, b"[" * 100_000 + b"]" * 100_000)
        elif how == "huge":
            put(s, own[".json"][1] + b" " * 20_000)
            return {"max_schedule_bytes": 10_000}
        elif how == "not json":
            put(s, own[".json"][1][: fault["a"] % len(own[".json"][1])] + b"\xff{")
        else:
            put(s, forged(own[".json"][1], how))
    return {}


def fill_cache(cache: Path, entries: dict) -> None:
    """Write every mechanism's clean entries ({mechanism: {suffix: (name, bytes)}}) into ``cache``."""
    for per_mech in entries.values():
        for name, data in per_mech.values():
            (cache / name).parent.mkdir(parents=True, exist_ok=True)
            (cache / name).write_bytes(data)


@count(6, 600)
@example(target="bendix_wrist.yaml", other="paper_2dof.yaml", faults=[   # a FIFO, then written over (harness)
    dict(kind="special", suffix=".obj", a=0, b=0, special="fifo", schedule="deep"),
    dict(kind="truncate", suffix=".obj", a=100, b=0, special="fifo", schedule="deep")])
@given(target=st.sampled_from(MECHS), other=st.sampled_from(MECHS), faults=st.lists(entry_fault(), min_size=1,
                                                                                      max_size=3))
def test_fuzz_cache_entries(target, other, faults):
    ref = clean()
    if other == target:
        other = MECHS[(MECHS.index(target) + 1) % len(MECHS)]
    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        base = Path(d)
        files = inputs_of(target)
        work, cache = new_work(base, target, files), base / "cache"
        fill_cache(cache, {m: ref[m][1] for m in MECHS})
        options = {}
        for f in faults:
            options.update(apply_fault(cache, ref[target][1], ref[other][1], f))
        code, out, err = finish_cli(start_cli(solve_args(target, work), work, {"GEARCLI_CACHE_DIR": str(cache)},
                                              options), SECONDS)
        found = problems(code, out, err, work, files, ref[target][0], cache)
        if not found and code == 0:             # repaired (or left alone when unrepairable): a second run agrees
            (work / "out.csv").unlink()
            code, out, err = finish_cli(start_cli(solve_args(target, work), work, {"GEARCLI_CACHE_DIR": str(cache)}),
                                        SECONDS)
            found = [f"second run: {p}" for p in problems(code, out, err, work, files, ref[target][0], cache)]
        verdict("cache entries", found, {"faults.json": json.dumps([target, other, faults, options]).encode()}, code)


# --- odd cache folders, denied writes, full disks -----------------------------------------
FOLDERS = ["a file as the root", "a file as llvm/", "a file as schedule/", "below a file", "/proc", "/dev/null",
           "relative GEARCLI_CACHE_DIR", "relative XDG_CACHE_HOME", "writes denied", "disk full", "fine"]


@count(8, 300)
@given(target=st.sampled_from(MECHS), folder=st.sampled_from(FOLDERS), warm=st.booleans(),
       budget=st.integers(0, 400_000), tmpfile=st.booleans())
def test_fuzz_cache_folders(target, folder, warm, budget, tmpfile):
    ref = clean()
    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        base = Path(d)
        files = inputs_of(target)
        work, cache = new_work(base, target, files), base / "cache"
        if warm:
            fill_cache(cache, {target: ref[target][1]})
        env, options = {"GEARCLI_CACHE_DIR": str(cache), "HOME": str(base / "home")}, {"no_tmpfile": not tmpfile}
        if folder == "a file as the root":
            shutil.rmtree(cache, ignore_errors=True)
            cache.write_text("x")
        elif folder in ("a file as llvm/", "a file as schedule/"):
            sub = cache / folder.split()[-1].rstrip("/")
            shutil.rmtree(sub, ignore_errors=True)
            cache.mkdir(exist_ok=True)
            sub.write_text("x")
        elif folder == "below a file":
            (base / "f").write_text("x")
            env["GEARCLI_CACHE_DIR"] = str(base / "f" / "cache")
        elif folder == "/proc":
            env["GEARCLI_CACHE_DIR"] = "/proc/gearcli-fuzz"
        elif folder == "/dev/null":
            env["GEARCLI_CACHE_DIR"] = "/dev/null"
        elif folder == "relative GEARCLI_CACHE_DIR":
            env["GEARCLI_CACHE_DIR"] = "cache"
        elif folder == "relative XDG_CACHE_HOME":
            del env["GEARCLI_CACHE_DIR"]
            env["XDG_CACHE_HOME"] = "cache"
        elif folder == "writes denied":
            options["deny_writes"] = True
        elif folder == "disk full":
            options["disk_full_after"] = budget
        code, out, err = finish_cli(start_cli(solve_args(target, work), work, env, options), SECONDS)
        found = problems(code, out, err, work, files, ref[target][0], cache)
        found += [f"stale file {p}" for p in stale_files(base / "home")]
        if folder.startswith("relative") and not (base / "home" / ".cache" / "gearcli" / "llvm").is_dir():
            found.append("a relative cache location was not ignored for the default")
        verdict("cache folders", found, {"case.json": json.dumps([target, folder, warm, budget, tmpfile]).encode()},
                code)


# --- concurrent cold compiles ---------------------------------------------------------------
@count(2, 100)
@given(targets=st.lists(st.sampled_from(MECHS), min_size=2, max_size=4))
def test_fuzz_concurrent_cold_compiles(targets):
    """2-4 processes solving the same and different mechanisms at once against an empty
    cache: every one exits 0 with the clean table, the cache is left whole (a third wave
    loads from it, same tables)."""
    ref = clean()
    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        base, cache = Path(d), Path(d) / "cache"
        found = []
        for wave in ("cold", "warm"):
            runs = []
            for i, name in enumerate(targets):
                files = inputs_of(name)
                work = new_work(base, f"{wave}{i}-{name}", files)
                runs.append((name, work, files, start_cli(solve_args(name, work), work,
                                                          {"GEARCLI_CACHE_DIR": str(cache)}, tag=f"{wave}{i}")))
            for name, work, files, p in runs:
                code, out, err = finish_cli(p, 2 * SECONDS)
                found += [f"{wave} {name}: {x}" for x in problems(code, out, err, work, files, ref[name][0], cache)]
        names = sorted(p.name for p in cache.rglob("*") if p.is_file())
        expect = sorted(Path(e[0]).name for m in set(targets) for e in ref[m][1].values())
        if names != expect:
            found.append(f"cache holds {names}, expected {expect}")
        verdict("concurrent cold compiles", found, {"targets.json": json.dumps(targets).encode()})


def test_the_oracle_sees_a_foreign_table(tmp_path):
    """The oracle flags a table that is not the clean run's, a crash signal, a hang and a
    temporary file left in the cache (so a passing fuzz run means something)."""
    work, cache = tmp_path / "w", tmp_path / "c"
    work.mkdir()
    (work / "in.yaml").write_bytes(b"x")
    (work / "out.csv").write_bytes(b"t\n1\n")
    (cache / "llvm").mkdir(parents=True)
    files = {"in.yaml": b"x"}
    assert problems(0, "", "", work, files, b"t\n1\n", cache) == []
    assert problems(0, "", "", work, files, b"t\n2\n", cache) == ["out.csv differs from the clean run's"]
    assert problems(-11, "", "", work, files, b"t\n1\n", cache) == ["crash: signal 11"]
    assert problems(None, "", "", work, files, b"t\n1\n", cache) == [f"hang (> {SECONDS} s)"]
    (work / "cache").mkdir()
    assert problems(0, "", "", work, files, b"t\n1\n", cache) == ["file cache written in the working directory"]
    (work / "cache").rmdir()
    (cache / "llvm" / ".gearcli.x.tmp").write_bytes(b"")
    assert problems(0, "", "", work, files, b"t\n1\n", cache)[0].startswith("stale file")
