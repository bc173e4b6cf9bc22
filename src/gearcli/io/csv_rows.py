"""Rows of a trajectory CSV: cells to numbers, and the first bad cell located and named.

:func:`parse_rows` reads lines of numbers (pyarrow's parser for long chunks, numpy's
``loadtxt`` as the arbiter); when a chunk does not parse, :func:`_bad_cell` finds its first
bad line by bisection (whole halves parsed in C: about two parses of the chunk, where a
Python loop over its lines took 8 s for a bad row near the end of 20,000) and says what is
wrong with it: a wrong number of cells, a cell that is not a number (a decimal comma
named as such), or a row that does not read as numbers.  :func:`check_values` refuses
non-finite and out-of-range values.  Errors are :class:`~gearcli.errors.TrajectoryError`
with an :class:`~gearcli.errors.Issue` (file, line, ``column N 'name'``).
"""
from __future__ import annotations

import csv
import math
import re

import numpy as np

from ..errors import Issue, TrajectoryError, counted
from .csv_numbers import parse_floats

MAX_ABS = 1e12        # largest |value| accepted, SI units (s, rad, m and their rates)
_DECIMAL_COMMA = re.compile(r"[+-]?\d*,\d+(?:[eE][+-]?\d+)?")   # one cell: 0,5 or -1,5e-3
_INTEGER = re.compile(r"[+-]?\d+")                # 0,5 split by a ',' separator: '0' and '5'
_FRACTION = re.compile(r"\d+(?:[eE][+-]?\d+)?")
_NUMBER = re.compile(r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan)", re.I)


def show(text: str, limit: int = 40) -> str:
    """``text`` for a one-line message: control characters escaped, at most ``limit``."""
    text = text.encode("unicode_escape", "backslashreplace").decode("ascii") \
        if not text.isprintable() else text
    return text if len(text) <= limit else text[:limit - 1] + "…"


def fail(file: str, line: int | None, place: str, message: str) -> TrajectoryError:
    return TrajectoryError(Issue(file, place, line, message))


def column_place(header: list[str], c: int) -> str:
    return f"column {c + 1} '{show(header[c])}'" if c < len(header) else f"column {c + 1}"


def check_utf8(file: str, lines: list[str], linenos: list[int]) -> None:
    """Refuse text read with ``surrogateescape`` that held bytes other than UTF-8."""
    try:
        "".join(lines).encode("utf-8")
        return
    except UnicodeEncodeError:
        pass
    for text, ln in zip(lines, linenos):
        try:
            text.encode("utf-8")
        except UnicodeEncodeError as exc:
            byte = ord(text[exc.start]) - 0xDC00
            raise fail(file, ln, f"character {exc.start + 1}", f"byte 0x{byte:02x} is not UTF-8 "
                       "(save the file as UTF-8 or ASCII text)") from None


def split_row(line: str, sep: str) -> list[str]:
    try:
        return [c.strip() for c in next(csv.reader([line.rstrip("\r\n")], delimiter=sep, quotechar='"'), [""])]
    except csv.Error:
        return line.rstrip("\r\n").split(sep)


def _readable(lines: list[str], ncol: int, sep: str, fast_rows: int) -> bool:
    """Whether every one of ``lines`` reads as ``ncol`` numbers: pyarrow's parser from
    ``fast_rows`` lines (faster; its None may be a NaN cell), else or then ``np.loadtxt``,
    the arbiter."""
    if len(lines) >= fast_rows and parse_floats(lines, ncol, sep) is not None:
        return True
    try:
        return np.loadtxt(lines, delimiter=sep, quotechar='"', comments=None, ndmin=2, dtype=float).shape \
            == (len(lines), ncol)
    except ValueError:
        return False


def _first_unreadable(lines: list[str], ncol: int, sep: str, fast_rows: int) -> int:
    """Index of the first of ``lines`` (which do not read as a whole) that does not read as
    ``ncol`` numbers, by bisection: about one parse of ``lines`` in all, instead of one
    Python pass per line.  Lines are read independently unless a quote runs across them;
    with quotes, the lines before the one found are checked to read together, else 0 is
    returned (the caller then looks at every line)."""
    lo, hi = 0, len(lines)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if _readable(lines[lo:mid], ncol, sep, fast_rows):
            lo = mid
        else:
            hi = mid
    if lo and '"' in "".join(lines[:lo]) and not _readable(lines[:lo], ncol, sep, fast_rows):
        return 0
    return lo


def _split_decimal_comma(cells: list[str], ncol: int, sep: str) -> str:
    """``: '0,5' looks like a decimal comma: write 0.5`` when a ``,``-separated row has more
    cells than the header and reads as the header's count with decimal commas: every cell
    an integer or digits (no '.': the row's writer does not use decimal points) and, for
    every extra cell, an integer cell followed by a cell of digits (``0`` ``5`` from
    ``0,5``); else ``""``."""
    extra = len(cells) - ncol
    if sep != "," or extra <= 0 or not all(_INTEGER.fullmatch(c) or _FRACTION.fullmatch(c) for c in cells):
        return ""
    pairs, i = [], 0
    while i + 1 < len(cells):
        if _INTEGER.fullmatch(cells[i]) and _FRACTION.fullmatch(cells[i + 1]):
            pairs.append(i)
            i += 2
        else:
            i += 1
    if len(pairs) < extra:
        return ""
    a, b = cells[pairs[0]], cells[pairs[0] + 1]
    return f": '{show(a)},{show(b)}' looks like a decimal comma: write {show(a)}.{show(b)}"


def _bad_cell(lines: list[str], linenos: list[int], header: list[str], sep: str, file: str,
              fast_rows: int) -> TrajectoryError:
    """The error for the first unreadable cell (called when fast parsing failed): the
    first bad line is found by :func:`_first_unreadable`, then looked at cell by cell."""
    start = _first_unreadable(lines, len(header), sep, fast_rows)
    for text, ln in zip(lines[start:], linenos[start:]):
        cells = split_row(text, sep)
        if len(cells) != len(header):
            return fail(file, ln, "", f"row has {counted(len(cells), 'column')}, the header has {len(header)} "
                        f"(separator '{show(sep)}')" + _split_decimal_comma(cells, len(header), sep))
        for c, cell in enumerate(cells):
            if not _NUMBER.fullmatch(cell):
                comma = _DECIMAL_COMMA.fullmatch(cell)
                hint = f" looks like a decimal comma: write {cell.replace(',', '.')}" if comma else ""
                what = "empty cell" if not cell else f"not a number: '{show(cell)}'{hint}"
                return fail(file, ln, column_place(header, c), what)
        try:
            np.loadtxt([text], delimiter=sep, quotechar='"', comments=None, ndmin=2)
        except ValueError:
            return fail(file, ln, "", "cannot read the row as numbers")
    return fail(file, linenos[0], "", "cannot read the rows as numbers")


def parse_rows(lines: list[str], linenos: list[int], header: list[str], sep: str, file: str,
               fast_rows: int) -> np.ndarray:
    """Rows of floats (n, ncol); on failure, find and report the first bad cell.  From
    ``fast_rows`` lines pyarrow's parser is tried first (its import costs ~0.2 s)."""
    check_utf8(file, lines, linenos)
    data = parse_floats(lines, len(header), sep) if len(lines) >= fast_rows else None
    if data is not None:
        return data
    try:
        data = np.loadtxt(lines, delimiter=sep, quotechar='"', comments=None, ndmin=2, dtype=float)
        ok = data.shape == (len(lines), len(header))
    except ValueError:
        ok = False
    if not ok:
        raise _bad_cell(lines, linenos, header, sep, file, fast_rows)
    return data


def check_values(data: np.ndarray, si: np.ndarray, lines: list[str], linenos: list[int],
                  header: list[str], sep: str, file: str) -> None:
    """Refuse non-finite values and values beyond ``MAX_ABS`` in SI units."""
    bad = ~np.isfinite(data) | (np.abs(si) > MAX_ABS)
    if not bad.any():
        return
    r, c = (int(x) for x in np.argwhere(bad)[0])
    cell = show(split_row(lines[r], sep)[c]) if c < len(split_row(lines[r], sep)) else str(data[r, c])
    if not math.isfinite(data[r, c]):
        raise fail(file, linenos[r], column_place(header, c), f"value '{cell}' is not a finite number (NaN or infinite)")
    raise fail(file, linenos[r], column_place(header, c), f"value {cell} is out of range (|x| <= {MAX_ABS:g} "
               "in SI units: s, rad, m and their rates)")


