"""Output formats of ``gearcli solve -o`` (issue 11): CSV (``--precision``, the compiled
writer byte-identical to Python's ``%g``), Parquet, Feather, NPZ; units metadata; refusals."""
from __future__ import annotations

import errno
import io
import os
import re
from pathlib import Path

import numpy as np
import pyarrow.feather as feather
import pyarrow.parquet as pq
import pytest

from gearcli import analyse, load_mechanism
from gearcli.report import table_files
from gearcli.report.columns import column_names, column_unit, column_units
from gearcli.report.csv_text import FAST_DIGITS, compiled_rows

ROOT = Path(__file__).resolve().parents[1]
MECH = ROOT / "mechanisms" / "bendix_wrist.yaml"
TRAJ = ROOT / "mechanisms" / "bendix_wrist_traj.csv"


def printf_rows(tab: np.ndarray, digits: int) -> str:
    """Reference: every value through Python's own ``%.<digits>g``, negative zero as 0."""
    fmt = f"%.{digits}g"
    return "".join(",".join(fmt % (float(x) + 0.0) for x in row) + "\n" for row in tab)


def hostile_values(rng, n: int) -> np.ndarray:
    """Values that stress a formatter: all magnitudes (subnormal to huge), exact integers,
    exact ties at 9 and 10 digits, negative zeros, neighbours of powers of ten and of the
    switch between fixed and exponent notation, non-finite values."""
    with np.errstate(over="ignore"):
        parts = [rng.normal(size=n) * 10.0 ** rng.integers(-320, 309, n),
                 rng.normal(size=n) * 10.0 ** rng.integers(-8, 12, n),
                 np.round(rng.normal(size=n) * 1e6), np.round(rng.normal(size=n) * 1e10) + 0.5,
                 rng.integers(-2**53, 2**53, n).astype(float), np.full(n, -0.0), np.zeros(n),
                 rng.choice([1e-4, 9.99999999e-5, 9.999999995e-5, 9.9999999949e-5, 999999999.5, 999999998.5,
                             1e9, 0.5, 1.5, 2.5, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308,
                             0.1, 1 / 3, 1e-280, 1e280, 1e-281, 1e281, 123456789.5, 1e22, 1e23, 1e16,
                             np.nan, np.inf], n) * rng.choice([-1.0, 1.0], n),
                 np.nextafter(10.0 ** rng.integers(-10, 12, n), rng.choice([0.0, np.inf], n))]
    v = np.concatenate(parts)
    rng.shuffle(v)
    return v


@pytest.mark.parametrize("digits", range(1, FAST_DIGITS + 1))
def test_compiled_csv_text_equals_printf(digits):
    v = hostile_values(np.random.default_rng(digits), 1500)
    for ncol in (1, 7, 115):
        tab = v[: v.size // ncol * ncol].reshape(-1, ncol)
        got = compiled_rows(tab, digits)
        assert got == printf_rows(tab, digits)
        assert compiled_rows(np.asfortranarray(tab), digits) == got      # column-major input
    assert "-0," not in got and "\n-0\n" not in got


def solve_cli(run_cli, out: Path, *extra):
    r = run_cli("solve", MECH, TRAJ, "-o", out, *extra)
    assert r.exit_code == 0, r.stderr
    return out


@pytest.fixture(scope="module")
def bendix():
    return analyse(load_mechanism(MECH))


@pytest.fixture
def reference(run_cli, tmp_path):
    """The loads of the Bendix trajectory in full float64 (NPZ) and the column names."""
    z = np.load(solve_cli(run_cli, tmp_path / "ref.npz"), allow_pickle=False)
    return z["loads"], list(z["columns"])


@pytest.mark.parametrize("compiled", [False, True])
def test_default_csv_is_9_significant_digits_of_the_loads(run_cli, tmp_path, monkeypatch, reference, compiled):
    monkeypatch.setattr(table_files, "COMPILED_MIN_VALUES", 0 if compiled else 10**12)
    loads, names = reference
    text = solve_cli(run_cli, tmp_path / "out.csv").read_text()
    header, body = text.split("\n", 1)
    assert header.split(",") == names
    assert body == printf_rows(loads, 9)
    assert solve_cli(run_cli, tmp_path / "p9.csv", "--precision", "9").read_text() == text


@pytest.mark.parametrize("compiled", [False, True])
def test_precision_17_round_trips_float64_exactly(run_cli, tmp_path, monkeypatch, reference, compiled):
    monkeypatch.setattr(table_files, "COMPILED_MIN_VALUES", 0 if compiled else 10**12)
    loads, _ = reference
    back = np.loadtxt(solve_cli(run_cli, tmp_path / "out.csv", "--precision", "17"), delimiter=",", skiprows=1)
    assert np.array_equal((back + 0.0).view(np.int64), (loads + 0.0).view(np.int64))
    nine = np.loadtxt(solve_cli(run_cli, tmp_path / "nine.csv"), delimiter=",", skiprows=1)
    assert not np.array_equal(nine, loads)   # 9 digits do not round-trip: the test can fail


def test_low_precision_digits(run_cli, tmp_path, reference):
    loads, _ = reference
    text = solve_cli(run_cli, tmp_path / "out.csv", "--precision", "3").read_text()
    assert text.split("\n", 1)[1] == printf_rows(loads, 3)


@pytest.mark.parametrize("ext, read", [
    (".parquet", lambda p: pq.read_table(p)),
    (".feather", lambda p: feather.read_table(p)),
])
def test_arrow_formats_hold_full_float64_units_and_metadata(run_cli, tmp_path, reference, bendix, ext, read):
    loads, names = reference
    t = read(solve_cli(run_cli, tmp_path / f"out{ext}"))
    assert t.column_names == names == column_names(bendix)
    got = np.column_stack([t.column(i).to_numpy() for i in range(t.num_columns)])
    assert np.array_equal(got.view(np.int64), loads.view(np.int64))
    units = [t.schema.field(n).metadata[b"unit"].decode() for n in names]
    assert units == [u.replace("·", "*") for u in column_units(bendix)]
    assert units[:2] == ["s", "N*m"] and "rad/s" in units and "W" in units and "N" in units
    meta = t.schema.metadata
    assert meta[b"mechanism"].decode() == str(MECH) and meta[b"trajectory"].decode() == str(TRAJ)
    assert re.fullmatch(rb"\d+\.\d+\.\d+.*", meta[b"gearcli_version"])
    assert b"parent on the child" in meta[b"conventions"] and b"\n" not in meta[b"conventions"]


def test_parquet_is_uncompressed_with_time_statistics_only(run_cli, tmp_path, reference):
    """Float64 loads hardly compress: pages are stored plain; only ``t`` has min/max (row-group
    pruning by time) and they are the chunk's first and last times."""
    loads, _ = reference
    meta = pq.ParquetFile(solve_cli(run_cli, tmp_path / "out.parquet")).metadata
    rg = meta.row_group(0)
    assert {rg.column(i).compression for i in range(meta.num_columns)} == {"UNCOMPRESSED"}
    st = rg.column(0).statistics
    assert rg.column(0).is_stats_set and (st.min, st.max) == (loads[0, 0], loads[rg.num_rows - 1, 0])
    assert not any(rg.column(i).is_stats_set for i in range(1, meta.num_columns))


def test_npz_holds_one_2d_array_with_names_and_units(run_cli, tmp_path, bendix):
    z = np.load(solve_cli(run_cli, tmp_path / "out.npz"), allow_pickle=False)
    names = column_names(bendix)
    assert z["loads"].shape == (2001, len(names)) and z["loads"].dtype == np.float64
    assert list(z["columns"]) == names
    assert list(z["units"]) == [u.replace("·", "*") for u in column_units(bendix)]
    assert str(z["mechanism"]) == str(MECH)
    csv_loads = np.loadtxt(solve_cli(run_cli, tmp_path / "x.csv"), delimiter=",", skiprows=1)
    np.testing.assert_allclose(csv_loads, z["loads"], rtol=6e-9, atol=1e-300)


def test_npz_skips_blank_lines_like_the_reader(run_cli, tmp_path):
    lines = TRAJ.read_text().splitlines(keepends=True)[:40]
    traj = tmp_path / "t.csv"
    traj.write_text("".join(lines[:10]) + "\n  \n" + "".join(lines[10:]) + "\n\n")
    r = run_cli("solve", MECH, traj, "-o", tmp_path / "o.npz")
    assert r.exit_code == 0, r.stderr
    assert np.load(tmp_path / "o.npz")["loads"].shape[0] == 39


def snapshot(d: Path) -> dict:
    return {p.name: p.read_bytes() for p in d.iterdir()}


def refused(r, *parts):
    assert r.exit_code == 2, (r.exit_code, r.stderr)
    lines = r.stderr.strip("\n").splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    for p in parts:
        assert p in lines[0], (p, lines[0])


@pytest.mark.parametrize("out, extra, parts", [
    ("out.txt", (), ("out.txt: -o: unknown output format '.txt'", ".parquet")),
    ("out.xlsx", (), ("unknown output format '.xlsx'",)),
    ("out.csv", ("--precision", "0"), ("--precision: expected 1 to 17", "got 0")),
    ("out.csv", ("--precision", "18"), ("--precision: expected 1 to 17", "got 18")),
    ("out.parquet", ("--precision", "12"), ("--precision applies to CSV output only",)),
])
def test_bad_output_format_or_precision_writes_nothing(run_cli, tmp_path, out, extra, parts):
    (tmp_path / "keep.csv").write_text("x\n")
    before = snapshot(tmp_path)
    refused(run_cli("solve", MECH, TRAJ, "-o", tmp_path / out, *extra), *parts)
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("name, fmt", [(".parquet", "parquet"), (".npz", "npz"), (".feather", "feather"),
                                       (".csv", "csv"), ("out", "csv"), (".hidden", None), ("dir.v2/out", "csv")])
def test_format_of_a_name_that_is_only_an_extension(name, fmt):
    """``-o .parquet`` writes Parquet (it wrote CSV into a file named .parquet: pathlib sees a
    hidden file without extension); a hidden name with another extension is refused."""
    assert table_files.format_of(name) == fmt


def test_dot_parquet_output_is_parquet(run_cli, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = run_cli("solve", MECH, TRAJ, "-o", ".parquet")
    assert r.exit_code == 0, r.stderr
    assert pq.read_table(tmp_path / ".parquet").num_rows > 0
    refused(run_cli("solve", MECH, TRAJ, "-o", ".loads"), "unknown output format '.loads'")
    assert not (tmp_path / ".loads").exists()


class Failing(io.FileIO):
    """A binary file whose writes fail with ENOSPC after ``budget`` bytes."""

    budget = 0

    def write(self, b):
        Failing.budget -= len(b)
        if Failing.budget < 0:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return super().write(b)


@pytest.mark.parametrize("ext", [".parquet", ".feather", ".npz"])
@pytest.mark.parametrize("budget", [0, 5000, 1_000_000])
def test_full_disk_binary_formats_leave_nothing(run_cli, tmp_path, monkeypatch, ext, budget):
    import gearcli.io.output as output

    def fdopen(fd, mode="r", **kw):
        assert "b" in mode
        Failing.budget = budget
        return Failing(fd, "w")

    monkeypatch.setattr(output.os, "fdopen", fdopen)
    (tmp_path / f"out{ext}").write_bytes(b"previous")
    before = snapshot(tmp_path)
    refused(run_cli("solve", MECH, TRAJ, "-o", tmp_path / f"out{ext}"), "-o: cannot write: No space left")
    assert snapshot(tmp_path) == before


def _column_reference() -> list[tuple[str, str, str]]:
    """(regex, unit, meaning) of each row of the column reference (docs/reference/outputs.md)."""
    text = (ROOT / "docs" / "reference" / "outputs.md").read_text()
    table = text.split("\n## ", 1)[0]
    out = []
    for cols, unit, meaning in re.findall(r"^\| (`[^|]+`) \| ([^|]+) \| (.*) \|$", table, flags=re.M):
        for pattern in re.findall(r"`([^`]+)`", cols):
            pattern = pattern if ":" in pattern or pattern == "t" else "joint:<joint>:" + pattern
            rx = "^" + re.sub(r"<[a-z]+>", "[^:]+", re.escape(pattern).replace(r"\<", "<").replace(r"\>", ">")) + "$"
            out.append((rx, unit.strip(), meaning))
    return out


@pytest.mark.parametrize("mech", sorted(p.name for p in (ROOT / "mechanisms").iterdir()
                                        if p.suffix in (".yaml", ".urdf")))
def test_the_column_reference_names_every_column_with_its_code_unit(mech):
    """Every output column of every bundled mechanism (gears, racks, reducers, screws, belts,
    worm pairs, losses, prismatic joints) has a row in the column reference, whose unit is the
    one the code writes (column_unit, the one source of units; a prismatic joint's force unit
    is named in the row's text)."""
    rows = _column_reference()
    assert len(rows) >= 20
    an = analyse(load_mechanism(ROOT / "mechanisms" / mech))
    for n in column_names(an):
        hits = [(unit, meaning) for rx, unit, meaning in rows if re.match(rx, n)]
        assert hits, f"column {n} of {mech} is missing from docs/reference/outputs.md"
        u = column_unit(n)
        assert any(u == unit or (u in ("N", "m/s") and u in meaning) for unit, meaning in hits), (n, u, hits)


def test_column_units_follow_prismatic_inputs(tmp_path):
    from factories_own import urdf_prismatic_chain

    path = tmp_path / "chain.urdf"
    path.write_text(urdf_prismatic_chain(0)[0])
    an = analyse(load_mechanism(path))
    units = dict(zip(column_names(an), column_units(an)))
    assert [units[f"motor:{j}"] for j in ("J1", "J2", "J3")] == ["N·m", "N", "N·m"]
    assert [units[f"tau:{j}"] for j in ("J1", "J2", "J3")] == ["N·m", "N", "N·m"]
    assert units["motor:J2:speed"] == "m/s" and units["motor:J1:speed"] == "rad/s"
    assert units["motor:J2:power"] == "W" and units["joint:J2:fx"] == "N" and units["joint:J2:mx"] == "N·m"


@pytest.mark.parametrize("ext", [".parquet", ".feather", ".npz"])
def test_plot_reads_binary_outputs(run_cli, tmp_path, ext):
    pytest.importorskip("matplotlib")
    from gearcli.report.plots import read_loads

    out = solve_cli(run_cli, tmp_path / f"loads{ext}")
    header, data, units = read_loads(out)
    csv_header, csv_data, csv_units = read_loads(solve_cli(run_cli, tmp_path / "loads.csv"))
    assert header == csv_header and units == csv_units
    np.testing.assert_allclose(data, csv_data, rtol=6e-9, atol=1e-300)
    r = run_cli("plot", out, "motor:*", "gear:4-1:t", "-o", tmp_path / "fig.png")
    assert r.exit_code == 0, r.stderr
    assert (tmp_path / "fig.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("ext", [".parquet", ".feather", ".npz"])
def test_plot_refuses_a_corrupt_binary_file(run_cli, tmp_path, ext):
    bad = tmp_path / f"bad{ext}"
    bad.write_bytes(b"PAR1 not really" * 10)
    refused(run_cli("plot", bad, "motor:*", "-o", tmp_path / "fig.png"), f"bad{ext}: cannot read the")
    assert not (tmp_path / "fig.png").exists()


@pytest.mark.parametrize("ext", [".parquet", ".feather", ".npz", ".csv"])
@pytest.mark.parametrize("content", [b"", b"garbage", b"\x93NUMPY"])
def test_plot_refuses_an_empty_or_foreign_file(run_cli, tmp_path, ext, content):
    """An empty .npz gave exit 1 'Aborted!' (np.load's EOFError is click's abort) and a text
    file in .npz talked of pickled data: now exit 2 with one line."""
    bad = tmp_path / f"bad{ext}"
    bad.write_bytes(content)
    r = run_cli("plot", bad, "motor:*", "-o", tmp_path / "fig.png")
    refused(r, f"bad{ext}")
    assert "pickle" not in r.stderr
    assert not (tmp_path / "fig.png").exists()


def test_plot_refuses_npz_loads_that_are_not_numbers(run_cli, tmp_path):
    bad = tmp_path / "bad.npz"
    np.savez(bad, columns=np.array(["t", "motor:m"]), units=np.array(["s", "N*m"]),
             loads=np.array([["0", "x"], ["1", "y"]]))
    refused(run_cli("plot", bad, "motor:*", "-o", tmp_path / "fig.png"), "bad.npz: 'loads': holds strings, not numbers")


@pytest.mark.parametrize("jobs", [1, 3])
def test_write_rows_in_threads_writes_the_same_text(tmp_path, jobs):
    from gearcli.report.csv_text import write_rows

    tab = hostile_values(np.random.default_rng(7), 800).reshape(-1, 9)
    expect = printf_rows(tab, 9)
    with open(tmp_path / "a.csv", "w", encoding="utf-8", newline="") as f:   # bytes to f.buffer
        f.write("h\n")
        write_rows(f, tab, 9, compiled=True, jobs=jobs)
    assert (tmp_path / "a.csv").read_text() == "h\n" + expect
    s = io.StringIO()                                                       # str path
    write_rows(s, tab, 9, compiled=True, jobs=jobs)
    assert s.getvalue() == expect


@pytest.mark.parametrize("ext", [".parquet", ".feather", ".npz"])
def test_interrupt_and_sigterm_mid_binary_write_leave_nothing(run_cli, tmp_path, monkeypatch, ext):
    import signal

    import gearcli.pipeline as pipeline

    (tmp_path / f"out{ext}").write_bytes(b"previous")
    before = snapshot(tmp_path)
    real = pipeline.solve
    calls = []

    def late(exc):
        def solve(*a, **k):
            calls.append(1)
            if len(calls) == 2:            # after the first chunk was written
                if exc is None:
                    os.kill(os.getpid(), signal.SIGTERM)
                else:
                    raise exc
            return real(*a, **k)
        return solve

    monkeypatch.setattr(pipeline, "solve", late(KeyboardInterrupt()))
    r = run_cli("solve", MECH, TRAJ, "-o", tmp_path / f"out{ext}", "--chunk", "500")
    assert r.exit_code == 130 and r.stderr.strip() == "gearcli: interrupted", r.stderr
    assert snapshot(tmp_path) == before and len(calls) == 2
    calls.clear()
    monkeypatch.setattr(pipeline, "solve", late(None))
    r = run_cli("solve", MECH, TRAJ, "-o", tmp_path / f"out{ext}", "--chunk", "500")
    assert r.exit_code == 143 and r.stderr.strip() == "gearcli: terminated (SIGTERM)", r.stderr
    assert snapshot(tmp_path) == before
