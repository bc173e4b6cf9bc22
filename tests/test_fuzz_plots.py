"""Property-based fuzzing of ``gearcli plot`` on loads files other programs wrote (issue 17).

Foreign tables built with numpy and pyarrow: Parquet, Feather, NPZ and CSV files whose
columns have random types (floats, float16, integers at their extremes, booleans, decimals,
timestamps with and without a time zone, durations, dates, times of day, strings, bytes,
structs, lists, dictionary-encoded strings and numbers, nulls), random values (NaN-only,
partly missing, infinite, ±1e308, subnormal, constant), random names (output-column names,
unicode, control characters, ``$`` mathtext, duplicates, ``_hidden``, 1 MB long), up to 3,000
columns and 0..50 rows, a first column that is or is not ``t`` (numbers, timestamps, strings,
NaN); npz files whose ``columns``/``units``/``loads`` do not fit together (0-d, fewer units,
other shapes, strings, complex, pickled objects, missing arrays); some files then cut or
bit-flipped (:func:`test_fuzz.apply`).  Plotted with random names and globs into random
output names (``.png``/``.svg``/``.pdf``, upper case, a bad extension, no extension, a
directory, a missing directory, the input itself).  Every run must give:

* exit status 0 or 2, never a traceback or a hang (:data:`test_fuzz.HANG_SECONDS`);
* no library warning (any ``warnings`` category, or ``...Warning:`` text on stderr);
* on status 2, exactly one line on stderr and no figure; on status 0, a figure in the format
  of its extension and only ``warning:`` lines on stderr;
* the input unchanged and no other file in the directory.

Profiles and recording as in :mod:`test_fuzz` (``GEARCLI_FUZZ=ci`` default, fast;
``GEARCLI_FUZZ=long``: 2,500 inputs per target; ``GEARCLI_FUZZ_RECORD=stats.jsonl`` records one
JSON line per input, with its run time in seconds, instead of failing).
"""
from __future__ import annotations

import io
import os
import re
import signal
import tempfile
import time
import warnings
from pathlib import Path

import pytest

pytest.importorskip("hypothesis")
pytest.importorskip("matplotlib")
np = pytest.importorskip("numpy")
pa = pytest.importorskip("pyarrow")
import pyarrow.feather as pf  # noqa: E402
import pyarrow.parquet as pq  # noqa: E402
from hypothesis import given, reject, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from test_fuzz import HANG_SECONDS, PROFILE, RECORD, Hang, _alarm, apply, mutation, verdict  # noqa: E402

SLOW_SECONDS = 10
"""A run slower than this is a finding of a recorded (long) run; the ci profile fails only on
a hang (timings in unit tests flake on a busy machine)."""
RECORD_TIMES = RECORD and RECORD + ".times"
"""With GEARCLI_FUZZ_RECORD: one line per run, 'target<TAB>seconds<TAB>exit status'."""

# --- columns ----------------------------------------------------------------------------
NUMERIC = ["float", "float", "int", "uint", "bool", "float16", "decimal", "dict_int", "constant"]
ODD_VALUES = ["nan_only", "partial_nan", "inf", "huge", "tiny", "nulls"]
NOT_NUMBERS = ["timestamp", "timestamp_tz", "duration", "date", "time", "string", "large_string", "binary",
               "struct", "list", "dict_str", "null"]
KINDS = NUMERIC + ODD_VALUES + NOT_NUMBERS
T_KINDS = ["float", "float", "float", "int", "timestamp", "timestamp_tz", "duration", "string", "partial_nan",
           "huge", "inf", "struct", "date", "extreme_timestamp", "not_t"]
NAMES = ["motor:m1", "motor:m1:speed", "gear:4-1:t", "tau:J1", "joint:J1:fx", "q:J1", "t", "", "$\\frac{x", "_u",
         "a\nb", "x\x00y", "荷重", "é", "\u200b", " ", "*", "[", "motor:m1"]


def values(kind: str, n: int, rng) -> pa.Array:
    """A column of ``n`` values of ``kind`` (an Arrow array)."""
    v = rng.standard_normal(n) * 10.0 ** rng.integers(-5, 6)
    ticks = rng.integers(0, 10**12, n)
    if kind == "float":
        return pa.array(v)
    if kind == "int":
        return pa.array(rng.integers(-2**63, 2**63 - 1, n, dtype=np.int64))
    if kind == "uint":
        return pa.array(rng.integers(0, 2**64 - 1, n, dtype=np.uint64))
    if kind == "bool":
        return pa.array(v > 0)
    if kind == "float16":
        with np.errstate(over="ignore"):
            return pa.array(v.astype(np.float16))
    if kind == "decimal":
        return pa.array(np.round(v, 2).astype(str).tolist()).cast(pa.decimal128(38, 2)) if n else \
            pa.array([], pa.decimal128(38, 2))
    if kind == "dict_int":
        return pa.array(rng.integers(0, 3, n)).dictionary_encode()
    if kind == "constant":
        return pa.array(np.full(n, rng.choice([0.0, -0.0, 1e-300, 7.5, -1e300])))
    if kind == "nan_only":
        return pa.array(np.full(n, np.nan))
    if kind == "partial_nan":
        return pa.array(np.where(rng.random(n) < 0.3, np.nan, v))
    if kind == "inf":
        return pa.array(np.where(rng.random(n) < 0.3, rng.choice([np.inf, -np.inf]), v))
    if kind == "huge":
        return pa.array(np.where(rng.random(n) < 0.5, rng.choice([1e308, -1e308, 1.7976931348623157e308, 1e301]), v))
    if kind == "tiny":
        return pa.array(np.where(rng.random(n) < 0.5, 5e-324, -5e-324))
    if kind == "nulls":
        return pa.array([None if x < 0.4 else float(y) for x, y in zip(rng.random(n), v)], pa.float64())
    if kind == "timestamp":
        return pa.array(ticks.astype("datetime64[ms]"))
    if kind == "timestamp_tz":
        return pa.array(ticks, pa.timestamp("us", tz=str(rng.choice(["UTC", "Europe/Berlin", "+05:30"]))))
    if kind == "extreme_timestamp":
        return pa.array(rng.choice([-2**63 + 1, 2**63 - 1, 0], n), pa.timestamp("ns"))
    if kind == "duration":
        return pa.array(ticks, pa.duration(str(rng.choice(["s", "ms", "us", "ns"]))))
    if kind == "date":
        return pa.array(ticks % 10**5, pa.int32()).cast(pa.date32())
    if kind == "time":
        return pa.array(ticks % 86400, pa.int32()).cast(pa.time32("s"))
    if kind in ("string", "large_string", "dict_str"):
        arr = pa.array([str(x) for x in v], pa.string() if kind != "large_string" else pa.large_string())
        return arr.dictionary_encode() if kind == "dict_str" else arr
    if kind == "binary":
        return pa.array([bytes([i % 256]) * 3 for i in range(n)])
    if kind == "struct":
        return pa.array([{"x": float(x), "s": "a"} for x in v], pa.struct([("x", pa.float64()), ("s", pa.string())]))
    if kind == "list":
        return pa.array([[float(x)] * 2 for x in v], pa.list_(pa.float64()))
    if kind == "null":
        return pa.nulls(n)
    return pa.array(v)


def csv_cells(arr: pa.Array) -> list[str]:
    """A column as CSV text: numbers by repr, missing values empty, anything else by its str
    (commas made semicolons)."""
    values = np.asarray(arr.to_numpy(zero_copy_only=False))
    if values.dtype.kind in "biuf":
        return [repr(float(x)) for x in values]
    return ["" if x is None else str(x).replace(",", ";") for x in values]


@st.composite
def table_spec(draw):
    """(format, rows, [(name, kind)], unit metadata, seed, byte mutations)."""
    fmt = draw(st.sampled_from(["parquet", "feather", "npz", "csv"]))
    rows = draw(st.sampled_from([50, 5, 2, 1, 50, 50, 0]))
    t_kind = draw(st.sampled_from(T_KINDS))
    n = draw(st.sampled_from([3, 5, 1, 2, 8, 0, 30, 3000]))
    names = st.one_of(st.sampled_from(NAMES), st.text(max_size=12),
                      st.builds(lambda c, k: c * k, st.sampled_from(["x", "é", "$", "荷", "\n"]),
                                st.sampled_from([61, 5000, 1_000_000])))
    if n > 30:
        cols = [(f"motor:m{i}" if draw(st.booleans()) else f"c{i}", draw(st.sampled_from(KINDS[:6]))) for i in range(2)]
        cols += [(f"motor:m{i}", "float") for i in range(2, n)]
    else:
        kinds = KINDS if fmt != "npz" else NUMERIC * 3 + ODD_VALUES + ["string"]   # npz: one array, one dtype
        cols = [(draw(names), draw(st.sampled_from(kinds))) for _ in range(n)]
        if fmt == "csv" and draw(st.sampled_from([True] * 4 + [False])):   # mostly one line, one cell a name
            cols = [(re.sub(r"[,\r\n\x0b\x0c\x1c-\x1e\x85\u2028\u2029]", "_", c), k) for c, k in cols]
    cols.insert(0, ("t" if t_kind != "not_t" else draw(names), t_kind if t_kind != "not_t" else "float"))
    units = draw(st.sampled_from([None, "N*m", "", "rad/s", "$N$", "\n", "u" * 100_000, "per-column"]))
    muts = draw(st.sampled_from([0] * 5 + [1]).flatmap(lambda k: st.lists(mutation(), min_size=k, max_size=2 * k)))
    return fmt, rows, cols, units, draw(st.integers(0, 2**32 - 1)), muts


def build(spec) -> bytes:
    """The file of ``spec`` (bytes), mutated; rejected when pyarrow cannot write it."""
    fmt, rows, cols, units, seed, muts = spec
    rng = np.random.default_rng(seed)
    arrays = [values(k, rows, rng) for _, k in cols]
    unit_of = [units if units != "per-column" else f"u{i % 9}" for i in range(len(cols))]
    buf = io.BytesIO()
    if fmt in ("parquet", "feather"):
        fields = [pa.field(name, a.type, metadata=None if u is None else {b"unit": u.encode("utf-8", "surrogateescape")})
                  for (name, _), a, u in zip(cols, arrays, unit_of)]
        try:
            table = pa.Table.from_arrays(arrays, schema=pa.schema(fields))
            (pq.write_table if fmt == "parquet" else pf.write_feather)(table, buf)
        except (pa.ArrowException, ValueError, TypeError, UnicodeError):
            reject()
    elif fmt == "npz":
        parts = [np.asarray(a.to_numpy(zero_copy_only=False)) for a in arrays]
        numbers = all(p.dtype.kind in "biuf" for p in parts)
        loads = (np.column_stack([p if numbers else p.astype(str) for p in parts]) if rows
                 else np.zeros((0, len(cols))))
        extra = {} if units is None else {"units": np.array(unit_of if units != "\n" else unit_of[:-1])}
        np.savez(buf, columns=np.array([c for c, _ in cols]), loads=loads, **extra)
    else:
        text = [",".join(c for c, _ in cols)] + [",".join(r) for r in zip(*[csv_cells(a) for a in arrays])]
        buf.write(("\n".join(text) + "\n").encode("utf-8", "surrogatepass"))
    data = buf.getvalue()
    for m in muts if len(data) < 1 << 20 else ():   # a 'duplicated line' of a 3,000-column file made 400 MB
        data = apply(data, m)
    return data


NPZ_FAULTS = {
    "0-d columns": dict(columns=np.array("t"), units=np.array("s"), loads=np.zeros((3, 1))),
    "fewer units": dict(columns=np.array(["t", "motor:a", "motor:b"]), units=np.array(["s"]), loads=np.zeros((3, 3))),
    "more units": dict(columns=np.array(["t"]), units=np.array(["s", "N"]), loads=np.zeros((3, 1))),
    "2-d columns": dict(columns=np.array([["t", "a"]]), loads=np.zeros((3, 2))),
    "1-d loads": dict(columns=np.array(["t"]), loads=np.zeros(3)),
    "3-d loads": dict(columns=np.array(["t", "a"]), loads=np.zeros((3, 2, 2))),
    "loads of strings": dict(columns=np.array(["t", "a"]), loads=np.array([["0", "x"], ["1", "y"]])),
    "loads of objects": dict(columns=np.array(["t", "a"]), loads=np.array([[0, None], [1, "y"]], dtype=object)),
    "complex loads": dict(columns=np.array(["t", "a"]), loads=np.ones((2, 2), complex)),
    "bool loads": dict(columns=np.array(["t", "a"]), loads=np.ones((2, 2), bool)),
    "int loads": dict(columns=np.array(["t", "a"]), loads=np.array([[0, -2**63], [1, 2**63 - 1]])),
    "datetime loads": dict(columns=np.array(["t", "a"]), loads=np.zeros((2, 2), "datetime64[s]")),
    "number columns": dict(columns=np.array([0.0, 1.0]), loads=np.zeros((2, 2))),
    "object columns": dict(columns=np.array(["t", None], dtype=object), loads=np.zeros((2, 2))),
    "byte columns": dict(columns=np.array([b"t", b"\xff\xfe"]), loads=np.zeros((2, 2))),
    "surrogate name": dict(columns=np.array(["t", "\ud800"]), units=np.array(["s", "\udfff"]), loads=np.zeros((2, 2))),
    "no loads": dict(columns=np.array(["t"])),
    "no columns": dict(loads=np.zeros((2, 2))),
    "plain arrays": dict(t=np.zeros(3), a=np.ones(3)),
    "empty": dict(),
}


def npz_fault(name: str) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **NPZ_FAULTS[name])
    return buf.getvalue()


# --- running and checking -------------------------------------------------------------
OUTPUTS = ["fig.png", "fig.svg", "fig.pdf", "FIG.PNG", "fig.Svg", "fig.gif", "fig", ".png", "fig.png.txt",
           "dir.png", "missing/fig.png", "INPUT", "old.png", "link.png"]
MAGIC = {".png": b"\x89PNG", ".svg": b"<?xml", ".pdf": b"%PDF"}
PATTERNS = ["*", "*", "motor:*", "t", "c1", "motor:m1", "[", "[!t]*", "?", "", "x" * 1000, "*:*", "**", "荷重",
            "$\\frac{x", "_u", "c*", "gear:4-1:t"]
LIBRARY_WARNING = re.compile(r"\b[A-Z]\w*Warning\b|warnings\.warn|site-packages")


def run_plot(args) -> tuple[object, bool, float, list[str]]:
    """(CliRunner result, hung?, seconds, warnings of any category) of ``gearcli plot args``."""
    from typer.testing import CliRunner

    from gearcli.cli import app

    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(HANG_SECONDS)
    start = time.perf_counter()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = CliRunner().invoke(app, ["plot"] + [str(a) for a in args])
        hung = bool(result.exc_info and isinstance(result.exc_info[1], Hang))
        return result, hung, time.perf_counter() - start, [f"{w.category.__name__}: {w.message}" for w in caught]
    except Hang:
        return None, True, time.perf_counter() - start, []
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def plot_problems(result, hung, caught, work: Path, inputs: dict, out: str, setup: set) -> list[str]:
    """Every broken promise of one plot run (empty when it behaved)."""
    if hung:
        return [f"hang (> {HANG_SECONDS} s)"]
    found = []
    if result.exit_code not in (0, 2):
        exc = result.exc_info
        detail = "".join(__import__("traceback").format_exception(*exc))[-1500:] if exc else result.stderr[-500:]
        found.append(f"{'traceback' if exc and not isinstance(exc[1], SystemExit) else 'bad exit'}: "
                     f"exit {result.exit_code}: {detail}")
    if caught:
        found.append(f"library warning: {caught[0]}"[:300])
    if LIBRARY_WARNING.search(result.stderr) or "Traceback" in result.stdout + result.stderr:
        found.append(f"library text on stderr: {result.stderr[:300]}")
    lines = result.stderr.splitlines()
    target = work / out
    if result.exit_code == 2 and len(lines) != 1:
        found.append(f"exit 2 with {len(lines)} stderr lines: {result.stderr[:300]}")
    if result.exit_code == 0:
        if not all(ln.startswith("warning: ") for ln in lines):
            found.append(f"stderr line that is not a warning: {result.stderr[:300]}")
        magic = MAGIC.get(target.suffix.lower())
        if magic is None or not target.is_file() or not target.read_bytes().startswith(magic):
            found.append(f"exit 0 without a {target.suffix} figure at {out}")
    for name, data in inputs.items():
        if (work / name).read_bytes() != data:
            found.append(f"input {name} changed")
    expected = set(inputs) | setup | ({out} if result.exit_code == 0 else set())
    for p in work.iterdir():
        if p.name not in expected:
            found.append(f"leftover file {p.name}")
    if result.exit_code == 2 and out == "old.png" and (work / "old.png").read_bytes() != b"old figure":
        found.append("the old figure was replaced although the exit status is 2")
    return found


def run_plot_case(target: str, name: str, data: bytes, patterns: list[str], out: str) -> None:
    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        work = Path(d)
        (work / name).write_bytes(data)
        setup = set()
        if out == "dir.png":
            (work / "dir.png").mkdir()
            setup.add("dir.png")
        elif out == "old.png":
            (work / "old.png").write_bytes(b"old figure")
            setup.add("old.png")
        elif out == "link.png":
            (work / "link.png").symlink_to(name)     # the input, through a symlink
            setup.add("link.png")
        elif out == "INPUT":
            out = name
        result, hung, seconds, caught = run_plot([work / name, "-o", work / out, "--", *patterns])
        found = plot_problems(result, hung, caught, work, {name: data}, out, setup)
        if RECORD and seconds > SLOW_SECONDS:
            found.append(f"slow: {seconds:.1f} s")
        if out in ("dir.png", "missing/fig.png", name, "link.png", "fig.gif", "fig", "fig.png.txt") \
                and not hung and result.exit_code != 2:
            found.append(f"output {out} not refused (exit {result.exit_code})")
        verdict(target, found, {name: data, "args": repr([*patterns, "-o", out]).encode()},
                None if hung else result.exit_code)
        if RECORD_TIMES:
            with open(RECORD_TIMES, "a") as f:
                first = "" if hung else (result.stderr.splitlines() or [""])[0]
                f.write(f"{target}\t{seconds:.3f}\t{None if hung else result.exit_code}\t{first[:200]!r}\n")


def few(n: int):
    """``n`` examples in the ci profile, the profile's count otherwise."""
    return settings(max_examples=n) if PROFILE == "ci" else settings()


# --- targets ----------------------------------------------------------------------------
@st.composite
def patterns_for(draw, names: list[str]):
    """1-3 patterns: mostly names or globs of the table's own columns, sometimes junk."""
    own = st.sampled_from(names).flatmap(lambda n: st.sampled_from([n, n[:3] + "*", "*" + n[-2:], n.replace(":", "?")]))
    return draw(st.lists(st.one_of(own, own, st.sampled_from(PATTERNS)), min_size=1, max_size=3))


@few(60)
@given(spec=table_spec(), data=st.data(), out=st.sampled_from(OUTPUTS[:3] * 8 + OUTPUTS))
def test_fuzz_plot_foreign_tables(spec, data, out):
    patterns = data.draw(patterns_for([c for c, _ in spec[2]]))
    run_plot_case("plot", f"loads.{spec[0]}", build(spec), patterns, out)


@few(20)
@given(fault=st.sampled_from(sorted(NPZ_FAULTS)), patterns=st.lists(st.sampled_from(PATTERNS), min_size=1, max_size=2),
       out=st.sampled_from(OUTPUTS), muts=st.lists(mutation(), max_size=1))
def test_fuzz_plot_npz_arrays(fault, patterns, out, muts):
    data = npz_fault(fault)
    for m in muts:
        data = apply(data, m)
    run_plot_case("plot-npz", "loads.npz", data, patterns, out)
