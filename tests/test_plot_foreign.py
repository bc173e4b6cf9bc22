"""``gearcli plot`` on loads files other programs wrote (issue 17): npz arrays that do not fit
together, Arrow types that are not numbers (timestamps, structs, lists, strings, dictionaries),
values matplotlib cannot lay out, thousands of columns, megabyte names, library warnings.

The contract: exit 0 with a figure (and a ``warning:`` line naming what was left out), or
exit 2 with one line naming the file and the place; never a traceback, never a library's
warning on stderr, never a partial figure, never a changed input.
"""
from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("matplotlib")
pa = pytest.importorskip("pyarrow")
import pyarrow.feather as pf  # noqa: E402
import pyarrow.parquet as pq  # noqa: E402

T = np.linspace(0.0, 1.0, 11)


def refused(r, *parts):
    assert r.exit_code == 2, (r.exit_code, r.stdout, r.stderr)
    lines = r.stderr.strip("\n").splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr and "Warning" not in r.stderr, r.stderr
    for p in parts:
        assert p in lines[0], (p, lines[0])


def drawn(r, fig):
    assert r.exit_code == 0, (r.exit_code, r.stderr)
    assert "Traceback" not in r.stderr and "Warning:" not in r.stderr, r.stderr
    assert fig.stat().st_size > 0
    return [ln for ln in r.stderr.splitlines() if ln]


@pytest.fixture
def legends(monkeypatch):
    """The legend texts and axis labels of the figure ``plot`` saves (what the user sees)."""
    from gearcli.report import plots

    seen = {}
    save = plots._save

    def spy(fig, path):
        seen["legend"] = [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]
        seen["axes"] = len(fig.axes)
        seen["xlabel"] = fig.axes[-1].get_xlabel()
        seen["ylabels"] = [ax.get_ylabel() for ax in fig.axes]
        seen["title"] = fig.axes[0].get_title()
        seen["x"] = fig.axes[0].get_lines()[0].get_xdata()
        save(fig, path)
    monkeypatch.setattr(plots, "_save", spy)
    return seen


def arrow(path, columns: dict, names=None):
    table = pa.Table.from_arrays([pa.array(v) if not isinstance(v, (pa.Array, pa.ChunkedArray)) else v
                                  for v in columns.values()], names=names or list(columns))
    (pq.write_table if path.suffix == ".parquet" else pf.write_feather)(table, path)
    return path


def unchanged(path, before: bytes):
    assert path.read_bytes() == before


# --- npz ----------------------------------------------------------------------------------
@pytest.mark.parametrize("arrays, parts", [
    ({"columns": np.array(["t", "motor:a", "motor:b"]), "units": np.array(["s"]), "loads": np.c_[T, T, T]},
     ("'units': 1 entry for 3 columns",)),                                # was KeyError: 'motor:a'
    ({"columns": np.array("t"), "units": np.array("s"), "loads": np.c_[T]},
     ("'columns': a 1-D array of names expected, got a 0-d array of strings",)),   # was TypeError
    ({"columns": np.array(["t", "m"]), "units": np.array(["s", "N"]), "loads": np.float64(3.0)},
     ("'loads': an array of shape (rows, 2) expected for 2 columns, got shape ()",)),
    ({"columns": np.array(["t", "m"]), "units": np.array(["s", "N"]), "loads": np.c_[T, T, T]},
     ("'loads': an array of shape (rows, 2) expected", "got shape (11, 3)")),
    ({"columns": np.array([1.0, 2.0]), "loads": np.c_[T, T]}, ("'columns': a 1-D array of names expected",)),
    ({"columns": np.array(["t", "m"]), "loads": np.c_[T, T].astype(complex)}, ("'loads': holds complex numbers",)),
    ({"columns": np.array(["t", "m"]), "loads": np.zeros((0, 2))}, ("no data rows",)),
    ({"t": T, "m": T}, ("not a loads table written by gearcli solve (no array 'columns' or 'loads')",)),
])
def test_npz_whose_arrays_do_not_fit_is_refused_in_one_line(run_cli, tmp_path, arrays, parts):
    path = tmp_path / "bad.npz"
    np.savez(path, **arrays)
    before = path.read_bytes()
    refused(run_cli("plot", path, "*", "-o", tmp_path / "fig.png"), "bad.npz: ", *parts)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.npz"]
    unchanged(path, before)


def test_npz_without_units_or_with_byte_names_is_drawn(run_cli, tmp_path, legends):
    path = tmp_path / "ok.npz"
    np.savez(path, columns=np.array([b"t", b"motor:a", b"motor:b"]), loads=np.c_[T, T, 2 * T].astype(np.float32))
    drawn(run_cli("plot", path, "motor:*", "-o", tmp_path / "fig.png"), tmp_path / "fig.png")
    assert legends["legend"] == ["motor:a", "motor:b"] and legends["ylabels"] == ["value"]


# --- Arrow types --------------------------------------------------------------------------
@pytest.mark.parametrize("ext", [".parquet", ".feather"])
def test_timestamp_t_is_drawn_as_seconds_since_the_first_row(run_cli, tmp_path, legends, ext):
    stamps = np.datetime64("2026-11-26T05:00:00") + (T * 1000).astype("timedelta64[ms]")
    path = arrow(tmp_path / f"ts{ext}", {"t": pa.array(stamps), "motor:a": T})  # was DTypePromotionError
    drawn(run_cli("plot", path, "motor:a", "-o", tmp_path / "fig.png"), tmp_path / "fig.png")
    np.testing.assert_allclose(legends["x"], T, rtol=0, atol=1e-12)
    assert legends["xlabel"] == "t [s] since 2026-11-26T05:00:00.000"


def test_duration_t_is_seconds(run_cli, tmp_path, legends):
    path = arrow(tmp_path / "d.feather", {"t": pa.array((T * 1e6).astype("timedelta64[us]")), "motor:a": T})
    drawn(run_cli("plot", path, "motor:a", "-o", tmp_path / "fig.png"), tmp_path / "fig.png")
    np.testing.assert_allclose(legends["x"], T, rtol=0, atol=1e-12)
    assert legends["xlabel"] == "t [s]"


@pytest.mark.parametrize("t, parts", [
    (pa.array(["0", "1"] * 5 + ["2"]), ("column 't': holds strings, not numbers (t must be numbers of seconds",)),
    (pa.array([{"x": 1.0}] * 11), ("column 't': holds structs, not numbers",)),
    (pa.array([0.0, 1.0, None] + [2.0] * 8), ("column 't', row 3: a missing time",)),
    (pa.array(np.r_[0.0, np.inf, T[2:]]), ("column 't', row 2: not a finite number",)),
    (pa.array(np.r_[0.0, 1e308, T[2:]]), ("column 't', row 2: 1e+308 s is beyond ±1e+300 s and cannot be drawn",)),
    (pa.array([np.datetime64("2026-01-01", "ns"), None] + [np.datetime64("2026-01-02", "ns")] * 9),
     ("column 't', row 2: a missing time",)),
])
def test_t_that_is_not_seconds_is_refused_naming_the_row(run_cli, tmp_path, t, parts):
    path = arrow(tmp_path / "bad.parquet", {"t": t, "motor:a": T})
    refused(run_cli("plot", path, "motor:a", "-o", tmp_path / "fig.png"), "bad.parquet: ", *parts)
    assert not (tmp_path / "fig.png").exists()


def test_columns_that_are_not_numbers_are_left_out_and_named(run_cli, tmp_path, legends):
    n = len(T)
    path = arrow(tmp_path / "mixed.parquet", {
        "t": T, "s": pa.array([{"x": 1.0}] * n), "l": pa.array([[1.0, 2.0]] * n), "name": pa.array(["a"] * n),
        "cat": pa.array(["a", "b"] * 5 + ["a"]).dictionary_encode(), "when": pa.array(np.arange(n).astype("datetime64[s]")),
        "i": pa.array(np.arange(n, dtype=np.int64)), "b": pa.array([True, False] * 5 + [True]),
        "di": pa.array([1, 2] * 5 + [1]).dictionary_encode(), "u8": pa.array(np.arange(n, dtype=np.uint64) * 2**60),
        "dec": pa.array([1, 2] * 5 + [3], type=pa.int64()).cast(pa.decimal128(25, 2)),
        "f16": pa.array(T.astype(np.float16)), "nul": pa.nulls(n), "nan": pa.array(np.full(n, np.nan)),
        "huge": pa.array(np.r_[1e308, -1e308, T[2:]])})      # struct was TypeError, 1e308 matplotlib's ValueError
    r = run_cli("plot", path, "*", "-o", tmp_path / "fig.png")
    lines = drawn(r, tmp_path / "fig.png")
    assert lines == ["warning: " + str(path) + ": left out 8 columns that cannot be drawn: 's' (holds structs, not numbers), "
                     "'l' (holds lists, not numbers), 'name' (holds strings, not numbers) and 5 more"]
    # u8 (to 1e19) has an axis of its own (peaks 10x apart: issue 34); the others keep file order
    assert legends["legend"] == ["u8", "t", "i", "b", "di", "dec", "f16"]
    assert "(7 columns)" in r.stdout


def test_nothing_drawable_is_refused(run_cli, tmp_path):
    path = arrow(tmp_path / "s.parquet", {"t": T, "motor:s": pa.array([{"x": 1.0}] * 11)})
    refused(run_cli("plot", path, "motor:*", "-o", tmp_path / "fig.png"),
            "s.parquet: nothing to draw: 'motor:s' (holds structs, not numbers)")
    path = arrow(tmp_path / "h.feather", {"t": T, "a": np.full(11, np.nan), "b": np.full(11, -1e308)})
    refused(run_cli("plot", path, "*[ab]", "-o", tmp_path / "fig.png"),
            "h.feather: none of the 2 matching columns can be drawn: 'a' (no finite value), "
            "'b' (values beyond ±1e+300 cannot be drawn)")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["h.feather", "s.parquet"]


def test_missing_values_are_gaps_and_said(run_cli, tmp_path, legends):
    path = arrow(tmp_path / "g.parquet", {"t": T, "motor:a": pa.array([1, None, 3] + [4] * 8)})
    lines = drawn(run_cli("plot", path, "motor:a", "-o", tmp_path / "fig.png"), tmp_path / "fig.png")
    assert lines == [f"warning: {path}: missing values drawn as gaps: 'motor:a' (1 of 11)"]


@pytest.mark.parametrize("ext", [".feather", ".parquet"])
def test_duplicate_names_are_drawn_apart(run_cli, tmp_path, legends, ext):
    """A Parquet file with a duplicated name could not be read ('Multiple matches for FieldRef')."""
    path = arrow(tmp_path / f"dup{ext}", {"t": T, "a": T, "b": 2 * T, "c": 3 * T}, names=["t", "m", "x", "m"])
    drawn(run_cli("plot", path, "m", "-o", tmp_path / "fig.png"), tmp_path / "fig.png")
    assert legends["legend"] == ["m [column 2]", "m [column 4]"]


# --- size: columns, names -----------------------------------------------------------------
def test_thousands_of_columns_draw_a_capped_figure_and_say_so(run_cli, tmp_path, legends):
    """5,000 columns took minutes (one legend entry each); a 2,000-column parquet printed
    matplotlib's 'UserWarning: Tight layout not applied' with a source path, exit 0."""
    path = tmp_path / "wide.csv"
    names = ["t"] + [f"motor:m{i}" for i in range(5000)]
    path.write_text(",".join(names) + "\n" + "\n".join(",".join(["0.5"] * len(names)) for _ in range(3)) + "\n")
    r = run_cli("plot", path, "*", "-o", tmp_path / "fig.svg")
    lines = drawn(r, tmp_path / "fig.svg")
    assert lines == [f"warning: {path}: drew 24 of 5,001 matching columns (at most 24 lines on 6 axes); "
                     "name fewer columns or a narrower pattern to see the others"]
    assert len(legends["legend"]) == 24 and "(24 columns)" in r.stdout
    wide = arrow(tmp_path / "wide.parquet", {"t": T, **{f"c{i}": T * i for i in range(2000)}},
                 names=["t"] + [f"c{i}" for i in range(2000)])
    for n in (1, 7):       # units: at most 6 (each split further by magnitude: c_i = i T)
        table = pq.read_table(wide)
        fields = [table.schema.field(i).with_metadata({b"unit": f"u{i % n}".encode()}) for i in range(table.num_columns)]
        pq.write_table(pa.Table.from_arrays(table.columns, schema=pa.schema(fields)), wide)
        r = run_cli("plot", wide, "c*", "-o", tmp_path / "w.png")
        lines = drawn(r, tmp_path / "w.png")
        assert lines == [f"warning: {wide}: drew 24 of 2,000 matching columns (at most 24 lines on 6 axes); "
                         "name fewer columns or a narrower pattern to see the others"]
        assert len(set(legends["ylabels"])) == min(n, 6) and legends["axes"] <= 3 * min(n, 6)


def test_megabyte_names_and_units_are_cut_with_an_ellipsis(run_cli, tmp_path, legends):
    long = "x" * 1_000_000
    field = pa.field(long, pa.float64(), metadata={b"unit": b"N" * 100_000})
    table = pa.Table.from_arrays([pa.array(T), pa.array(T), pa.array([{"a": 1}] * 11)],
                                 schema=pa.schema([pa.field("t", pa.float64()), field, pa.field("y" * 1_000_000,
                                                   pa.struct([("a", pa.int64())]))]))
    path = tmp_path / "long.parquet"
    pq.write_table(table, path)
    r = run_cli("plot", path, "*", "-o", tmp_path / "fig.pdf")
    lines = drawn(r, tmp_path / "fig.pdf")
    assert legends["legend"] == ["t", "x" * 59 + "…"]
    assert legends["ylabels"] == ["value", "[" + "N" * 19 + "…]"]
    assert len(lines) == 1 and len(lines[0]) - len(str(path)) < 150 and "'" + "y" * 39 + "…' (holds structs" in lines[0]
    refused(run_cli("plot", path, "z" * 100_000, "-o", tmp_path / "g.png"), "no column matches 'zzz")
    assert len(run_cli("plot", path, "z" * 100_000, "-o", tmp_path / "g.png").stderr) < 300


@pytest.mark.parametrize("name, shown", [
    ("$\\frac{", "\\$\\frac{"),            # mathtext would fail to parse it
    ("a\nb\x00c", "a\\nb\\x00c"),
    ("_hidden", "_hidden"),                # a label starting with '_' is no legend entry to matplotlib
    ("\ud800x", "\\ud800x"),               # a lone surrogate cannot be printed or drawn
])
def test_odd_names_are_drawn_literally(run_cli, tmp_path, legends, name, shown):
    path = tmp_path / "odd.npz"
    np.savez(path, columns=np.array(["t", name]), units=np.array(["s", "$N"]), loads=np.c_[T, T])
    drawn(run_cli("plot", path, "*", "-o", tmp_path / "fig.png"), tmp_path / "fig.png")
    assert legends["legend"][1] == shown
    assert legends["ylabels"] == ["[s]", "[\\$N]"]


def test_library_warnings_become_gearcli_words(run_cli, tmp_path):
    """Glyphs missing from the font: matplotlib's UserWarning (with its source path) was
    printed; now one gearcli line."""
    path = tmp_path / "cjk.csv"
    path.write_text("t,荷重\n0,1\n1,2\n")
    lines = drawn(run_cli("plot", path, "*", "-o", tmp_path / "fig.png"), tmp_path / "fig.png")
    assert lines == ["warning: some characters of the names are not in the figure's font and show as boxes"]


# --- CSV ----------------------------------------------------------------------------------
def test_csv_strings_refused_where_drawn_ignored_elsewhere(run_cli, tmp_path):
    path = tmp_path / "s.csv"
    path.write_text("t,name,motor:a\n0,x,1\n1,y,2\n")
    refused(run_cli("plot", path, "name", "-o", tmp_path / "fig.png"), "s.csv:2: column 2 'name': not a number")
    drawn(run_cli("plot", path, "motor:a", "-o", tmp_path / "fig.png"), tmp_path / "fig.png")


@pytest.mark.parametrize("text, parts", [
    ("", ("e.csv: empty file",)),
    ("t,motor:a\n", ("e.csv: no data rows",)),
    ("t,motor:a\n0,1\n1\n", ("e.csv:3: 1 cell, the header has 2",)),
    ("t,motor:a\n0,1\nnan,2\n", ("e.csv:3: column 1 't': not a finite number",)),
    ("t,motor:a\n0,nan\n1,nan\n", ("e.csv: nothing to draw: 'motor:a' (no finite value)",)),
    ("t,motor:a\n0,1\n1,inf\n", ("e.csv: nothing to draw: 'motor:a' (infinite values)",)),
])
def test_bad_csv_is_refused_in_one_line(run_cli, tmp_path, text, parts):
    path = tmp_path / "e.csv"
    path.write_text(text)
    refused(run_cli("plot", path, "motor:*", "-o", tmp_path / "fig.png"), *parts)
    assert not (tmp_path / "fig.png").exists()


def test_single_row_is_drawn_as_a_point(run_cli, tmp_path, monkeypatch):
    from gearcli.report import plots

    markers = []
    save = plots._save
    monkeypatch.setattr(plots, "_save", lambda fig, p: (markers.extend(ln.get_marker() for ln in fig.axes[0].get_lines()),
                                                        save(fig, p)))
    path = tmp_path / "one.csv"
    path.write_text("t,motor:a\n0,1\n")
    drawn(run_cli("plot", path, "motor:a", "-o", tmp_path / "fig.png"), tmp_path / "fig.png")
    assert markers == ["."]


@pytest.mark.parametrize("kind", ["fifo", "dir", "dev", "missing"])
def test_loads_that_is_not_a_regular_file_is_refused(run_cli, tmp_path, kind):
    """A FIFO as LOADS blocked for ever, /dev/zero would never end."""
    import os

    path = {"fifo": tmp_path / "l.csv", "dir": tmp_path / "d.parquet", "dev": "/dev/zero",
            "missing": tmp_path / "no.npz"}[kind]
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "dir":
        path.mkdir()
    r = run_cli("plot", path, "*", "-o", tmp_path / "fig.png")
    refused(r, f"{path}: ", "not a regular file" if kind != "missing" else "cannot read file")
    assert not (tmp_path / "fig.png").exists()


def test_long_patterns_are_names_or_refused(run_cli, tmp_path):
    """A 130,000-character pattern '*x*x...' took 8 s in fnmatch; a long name without * ? [
    is compared as it is."""
    name = "x" * 100_000
    path = arrow(tmp_path / "l.feather", {"t": T, name: T})
    drawn(run_cli("plot", path, name, "-o", tmp_path / "fig.png"), tmp_path / "fig.png")
    refused(run_cli("plot", path, "*x" * 65_000, "-o", tmp_path / "g.png"),
            "a pattern with * ? [ of 130,000 characters is too long (at most 1,000")
    assert not (tmp_path / "g.png").exists()


def test_bad_npz_archive_leaves_no_file_open(tmp_path):
    """A zip that np.load cannot read as npz: refused, and the file is closed (np.load left
    its own file object open, a ResourceWarning the long fuzz run found)."""
    import gc
    import warnings
    import zipfile
    from gearcli.report.loads_files import open_loads
    path = tmp_path / "loads.npz"
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("columns.npy", b"not an npy array")
    data = path.read_bytes()                      # a central directory entry with a bad magic number
    path.write_bytes(data.replace(b"PK\x01\x02", b"PK\x01\x03"))
    assert zipfile.is_zipfile(path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(Exception):
            open_loads(path)
        gc.collect()
    assert not [w for w in caught if issubclass(w.category, ResourceWarning)]


def test_columns_of_one_unit_ten_times_apart_get_axes_of_their_own(run_cli, tmp_path, legends):
    """A 0.5 N*m motor torque and a 50 N*m bearing moment: two axes, each with its own
    columns (issue 34, section 3); columns within 10x share one."""
    t = np.linspace(0, 1, 50)
    cols = {"motor:m": 0.5 * np.sin(6 * t), "motor:n": 0.3 * np.cos(6 * t), "joint:J1:mx": 50 * np.cos(3 * t),
            "joint:J1:my": 20 * t, "joint:J1:fx": 100 * t}
    path = tmp_path / "loads.csv"
    path.write_text("t," + ",".join(cols) + "\n" + "\n".join(
        ",".join(repr(float(v)) for v in [t[i]] + [c[i] for c in cols.values()]) for i in range(len(t))) + "\n")
    r = run_cli("plot", path, "motor:*", "joint:J1:*", "-o", tmp_path / "f.png")
    assert r.exit_code == 0, r.stderr
    assert legends["axes"] == 3
    # N*m (the motors' unit, first in the file): the moments' axis, then the torques'; then N
    assert legends["legend"] == ["joint:J1:mx", "joint:J1:my", "motor:m", "motor:n", "joint:J1:fx"]
    assert legends["ylabels"] == ["[N·m]", "[N·m]", "[N]"]
