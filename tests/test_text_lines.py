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
