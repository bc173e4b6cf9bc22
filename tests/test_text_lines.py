"""io/text_lines.line_chunks (block reading of trajectory rows) against a plain
line-by-line reader: same lines, line numbers, chunks and the same too-long error, for
random texts and block sizes (lines spanning blocks, blank and whitespace-only lines)."""
from __future__ import annotations

import io

import numpy as np
import pytest

import gearcli.io.text_lines as text_lines


class TooLong(Exception):
    pass


def reference(text: str, chunk: int, max_line: int):
    """What the former readline loop yielded (and raised)."""
    f = io.StringIO(text)
    out, lines, nos, lineno = [], [], [], 1
    while True:
        line = f.readline(max_line)
        lineno += 1
        if len(line) == max_line and not line.endswith("\n"):
            out.append(("too long", lineno))
            return out
        if not line:
            break
        if line.strip():
            lines.append(line.rstrip("\n"))
            nos.append(lineno)
        if len(lines) == chunk:
            out.append((lines, nos))
            lines, nos = [], []
    if lines:
        out.append((lines, nos))
    return out


def blocked(text: str, chunk: int, max_line: int):
    out = []
    try:
        for lines, nos in text_lines.line_chunks(io.StringIO(text), 1, chunk, max_line, TooLong):
            out.append((list(lines), list(nos)))
    except TooLong as exc:
        out.append(("too long", exc.args[0]))
    return out


@pytest.mark.parametrize("seed", range(40))
def test_line_chunks_equal_a_line_by_line_reader(seed, monkeypatch):
    rng = np.random.default_rng(seed)
    pieces = ["1,2,3", "", "  ", "\t", "\xa0", "0.5,-1e-3,7", "x" * int(rng.integers(1, 30)), " 4 , 5 "]
    lines = [pieces[i] for i in rng.integers(0, len(pieces), int(rng.integers(0, 60)))]
    text = "\n".join(lines) + ("\n" if rng.random() < 0.5 else "")
    monkeypatch.setattr(text_lines, "BLOCK", int(rng.integers(1, 40)))
    for chunk in (1, 3, 7, 100):
        for max_line in (8, 20, 1 << 20):
            assert blocked(text, chunk, max_line) == reference(text, chunk, max_line), (chunk, max_line)


TOKENS = ["1", "-1", "+1", "1.", ".5", "-.5", "1e5", "1E+05", "1e-400", "1e400", "inf", "-inf", "nan", "NaN",
          "Infinity", "-Infinity", "INF", " 1", "1 ", '"1.5"', "", "1_0", "0x10", "1d5", "1,5", "\u0661",
          "1.5e", "e5", ".", "-", "+", "--1", "1e", "00012", "0.1e-2", "\t2", "1.7976931348623157e308",
          "4.9e-324", "2.4703282292062327e-324", "nan(1)", "+nan", "-nan", "1.0\x00", '"', '""']


@pytest.mark.parametrize("seed", range(5))
def test_fast_number_parsing_agrees_with_loadtxt(seed):
    """parse_floats either declines (None) or returns exactly loadtxt's values."""
    from gearcli.io.csv_numbers import parse_floats

    rng = np.random.default_rng(seed)
    accepted = 0
    for _ in range(400):
        n, ncol = int(rng.integers(1, 4)), int(rng.integers(1, 4))
        lines = [",".join(str(rng.choice(TOKENS)) if rng.random() < 0.3 else
                          repr(float(rng.normal() * 10.0 ** rng.integers(-300, 300))) for _ in range(ncol))
                 for _ in range(n)]
        fast = parse_floats(lines, ncol, ",")
        if fast is None:
            continue
        accepted += 1
        ref = np.loadtxt(lines, delimiter=",", quotechar='"', comments=None, ndmin=2, dtype=float)
        assert ref.shape == (n, ncol) and np.array_equal(fast.view(np.int64), ref.view(np.int64)), lines
    assert accepted > 50


@pytest.mark.parametrize("bad", ["x", "", "nan(1)", "1e999", "1,5", '"2'])
def test_reader_reports_the_same_error_with_and_without_the_fast_parser(tmp_path, monkeypatch, bad):
    import gearcli.io.trajectory as trajectory
    from gearcli.errors import TrajectoryError

    t = np.arange(3000) * 1e-3
    rows = [f"{float(a)!r},{float(np.sin(a))!r},{float(np.cos(a))!r}" for a in t]
    rows[2500] = f"{float(t[2500])!r},{bad},0.5"
    path = tmp_path / "traj.csv"
    path.write_text("t,q:J1,q:J2\n" + "\n".join(rows) + "\n")
    messages = []
    for fast_rows in (2000, 10**9):
        monkeypatch.setattr(trajectory, "FAST_PARSE_ROWS", fast_rows)
        reader = trajectory.TrajectoryReader(path, ["J1", "J2"], chunk=5000)
        with pytest.raises(TrajectoryError) as err:
            reader.check()
        messages.append(str(err.value))
    assert messages[0] == messages[1] and ":2502:" in messages[0], messages


@pytest.mark.parametrize("row", [0, 1000])
def test_a_byte_order_mark_opening_a_chunk_is_not_a_number(tmp_path, monkeypatch, row):
    """pyarrow silently drops a UTF-8 byte-order mark at the start of what it parses: a data
    row opening a chunk with one must still be refused, at its line, with or without the fast
    parser (long fuzz, session 4: '\\ufeff1' was read as 1 there)."""
    import gearcli.io.trajectory as trajectory
    from gearcli.errors import TrajectoryError

    t = np.arange(3000) * 1e-3
    rows = [f"{float(a)!r},{float(np.sin(a))!r},{float(np.cos(a))!r}" for a in t]
    rows[row] = "\ufeff" + rows[row]
    path = tmp_path / "traj.csv"
    path.write_text("t,q:J1,q:J2\n" + "\n".join(rows) + "\n", encoding="utf-8")
    messages = []
    for fast_rows in (500, 10**9):
        monkeypatch.setattr(trajectory, "FAST_PARSE_ROWS", fast_rows)
        with pytest.raises(TrajectoryError) as err:
            trajectory.TrajectoryReader(path, ["J1", "J2"], chunk=1000).check()
        messages.append(str(err.value))
    assert messages[0] == messages[1] and f":{row + 2}:" in messages[0] and "not a number" in messages[0], messages


ODD_LINES = ["", "  ", "\r", "1e999,0,0", "x,1,2", '"{t}",0.5,0.25', "{t},1\r,2", "{t},0.5,\u00e9",
             "{t},1,2,3", "{t};1;2", "{t},nan,0", "{t}," + "1" * 90 + ",0", "{t},1,2\r"]


def odd_trajectory(rng) -> bytes:
    """Rows t, q:J1, q:J2 (increasing t), a few of them odd (blank, CRLF, quoted, bad,
    non-ASCII, too long, ...), at random places; sometimes no final newline."""
    n = int(rng.integers(300, 700))
    rows = [f"{i * 1e-3!r},{float(np.sin(i))!r},{float(np.cos(i))!r}" for i in range(n)]
    for _ in range(int(rng.integers(0, 3))):
        i = int(rng.integers(0, n))
        rows[i] = str(rng.choice(ODD_LINES)).replace("{t}", repr(i * 1e-3))
    if rng.random() < 0.3:
        rows = [r + "\r" for r in rows]
    text = "t,q:J1,q:J2\n" + "\n".join(rows) + ("\n" if rng.random() < 0.7 else "")
    return text.encode("utf-8")


def read_all(path, chunk):
    from gearcli.errors import TrajectoryError
    from gearcli.io.trajectory import TrajectoryReader

    try:
        return [(d.tobytes(), n.tolist()) for d, n in TrajectoryReader(path, ["J1", "J2"], chunk=chunk)._raw()]
    except TrajectoryError as exc:
        return str(exc)


@pytest.mark.parametrize("seed", range(40))
def test_reader_straight_from_bytes_equals_line_by_line(tmp_path, monkeypatch, seed):
    """Chunks read from the bytes (plain_chunks + pyarrow) give the same rows, line
    numbers and errors as the line-by-line reader (FAST_PARSE_ROWS huge: never from the bytes)."""
    import gearcli.io.trajectory as trajectory

    rng = np.random.default_rng(seed)
    path = tmp_path / "traj.csv"
    path.write_bytes(odd_trajectory(rng))
    monkeypatch.setattr(trajectory, "MAX_LINE", 80)
    monkeypatch.setattr(text_lines, "BLOCK", int(rng.integers(50, 5000)))
    for chunk in (129, 200, 1 << 40):
        got = []
        for fast_rows in (2, 1 << 40):
            monkeypatch.setattr(trajectory, "FAST_PARSE_ROWS", fast_rows)
            got.append(read_all(path, chunk))
        assert got[0] == got[1], (chunk, got[0] if isinstance(got[0], str) else len(got[0]))


def test_plain_chunks_stop_before_the_first_part_with_a_non_ascii_or_too_long_line():
    data = b"h\n1,2\n3,4\n5,6\n\n7,8\n9,\xc3\xa9\n"      # blank lines are the parser's to refuse
    assert list(text_lines.plain_chunks(io.BytesIO(data), 2, 1, 2, 100)) == [
        (b"1,2\n3,4\n", 2, 2, 2), (b"5,6\n\n", 10, 4, 2)]
    long = b"h\n1,2\n" + b"9" * 200 + b"\n3,4"
    assert list(text_lines.plain_chunks(io.BytesIO(long), 2, 1, 1, 100)) == [(b"1,2\n", 2, 2, 1)]
    assert list(text_lines.plain_chunks(io.BytesIO(long), 2, 1, 5, 300)) == [(long[2:], 2, 2, 3)]


@pytest.mark.parametrize("bad_rows", [[19_500], [19_999], [0], [7_000, 19_500], [12_345, 12_346]])
@pytest.mark.parametrize("fast_rows", [2000, 10**9])
def test_the_first_bad_row_of_a_long_chunk_is_found_without_a_pass_per_line(tmp_path, monkeypatch, bad_rows,
                                                                             fast_rows):
    """The first bad row of a chunk is found by bisection, and only it is looked at cell by
    cell (a Python pass over the 19,500 rows before it took 8 s; issue 17)."""
    import gearcli.io.csv_rows as csv_rows
    import gearcli.io.trajectory as trajectory
    from gearcli.errors import TrajectoryError

    t = np.arange(20_000) * 1e-3
    rows = [f"{float(a)!r},{float(np.sin(a))!r},{float(np.cos(a))!r}" for a in t]
    for r in bad_rows:
        rows[r] = rows[r].replace(",", ",x", 1)
    path = tmp_path / "traj.csv"
    path.write_text("t,q:J1,q:J2\n" + "\n".join(rows) + "\n")
    split = csv_rows.split_row
    calls = []
    monkeypatch.setattr(csv_rows, "split_row", lambda *a: calls.append(1) or split(*a))
    monkeypatch.setattr(trajectory, "FAST_PARSE_ROWS", fast_rows)
    with pytest.raises(TrajectoryError) as err:
        trajectory.TrajectoryReader(path, ["J1", "J2"], chunk=50_000).check()
    first = bad_rows[0]
    assert str(err.value) == f"{path}:{first + 2}: column 2 'q:J1': not a number: 'x{float(np.sin(t[first]))!r}'"
    assert len(calls) == 1


def test_a_quote_across_lines_still_gives_the_first_bad_row(tmp_path):
    """A quoted cell may hold a newline for the CSV parser: bisection cannot trust halves
    then, and the rows are looked at one by one (the same first bad row is reported)."""
    from gearcli.errors import TrajectoryError
    from gearcli.io.trajectory import TrajectoryReader

    t = np.arange(3000) * 1e-3
    rows = [f"{float(a)!r},{float(np.sin(a))!r},{float(np.cos(a))!r}" for a in t]
    rows[100] = f'{float(t[100])!r},"0.5,0.25'
    rows[2900] = rows[2900].replace(",", ",x", 1)
    path = tmp_path / "traj.csv"
    path.write_text("t,q:J1,q:J2\n" + "\n".join(rows) + "\n")
    with pytest.raises(TrajectoryError) as err:
        TrajectoryReader(path, ["J1", "J2"], chunk=50_000).check()
    assert f"{path}:102: " in str(err.value)
