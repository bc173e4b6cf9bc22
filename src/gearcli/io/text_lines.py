"""Non-blank lines of a text file with their line numbers, read in large blocks.

:func:`line_chunks` replaces a ``readline`` loop (about 8 us a line in Python) by
``read`` of 4 MB blocks split at newlines (a fraction of a microsecond a line), keeping
what the loop checked: a line of ``max_line`` characters or more is refused (memory stays
bounded whatever the file holds), blank (whitespace-only) lines are skipped but counted.
:func:`plain_chunks` goes further for the usual file: chunks of plain lines (ASCII, not too
long) as bytes, for pyarrow's parser, with no Python object per line.
"""
from __future__ import annotations

from typing import Callable, Iterator

BLOCK = 1 << 22     # characters read at once


def line_chunks(f, lineno: int, chunk: int, max_line: int,
                too_long: Callable[[int], Exception]) -> Iterator[tuple[list[str], list[int]]]:
    """Yield (lines, line numbers) of up to ``chunk`` non-blank lines of the text file
    ``f`` (lines without their newline), the first read line being number ``lineno + 1``.

    ``too_long(n)`` is the exception raised for line ``n`` of ``max_line`` characters or
    more (without its newline).
    """
    lines: list[str] = []
    nos: list[int] = []
    rest = ""
    while True:
        block = f.read(BLOCK)
        parts = (rest + block).split("\n")
        rest = parts.pop() if block else ""
        bad = None
        if parts and max(map(len, parts)) >= max_line:
            bad = next(i for i, p in enumerate(parts) if len(p) >= max_line)
        elif len(rest) >= max_line:
            bad = len(parts)
        if bad is not None:      # the lines before it are still yielded by full chunks, as a
            parts = parts[:bad]  # line-by-line reader would have done before meeting it
        if "" not in parts and not any(map(str.isspace, parts)):   # no blank line (usual)
            nos += range(lineno + 1, lineno + 1 + len(parts))
            lines += parts
        else:
            kept = [(n, p) for n, p in enumerate(parts, lineno + 1) if p and not p.isspace()]
            nos += [n for n, _ in kept]
            lines += [p for _, p in kept]
        lineno += len(parts)
        while len(lines) >= chunk:
            yield lines[:chunk], nos[:chunk]
            del lines[:chunk], nos[:chunk]
        if bad is not None:
            raise too_long(lineno + 1)
        if not block:
            if lines:
                yield lines, nos
            return


def plain_chunks(f, offset: int, lineno: int, chunk: int, max_line: int) -> Iterator[tuple[bytes, int, int, int]]:
    """Yield (bytes of ``chunk`` lines, their byte offset, number of their first line, number
    of lines) of
    the binary file ``f`` from byte ``offset`` (line ``lineno + 1``), the last part with
    the lines left (the final line may lack its newline), as long as every line of a part
    is plain: ASCII and shorter than ``max_line``.  Stops before the first part that is not
    (the caller reads the rest line by line: :func:`line_chunks`, which also handles the
    blank lines this does not look for).  Newlines are found by numpy, with no Python
    object per line; memory stays bounded by ``chunk`` lines and ``max_line``.
    """
    import numpy as np  # noqa: PLC0415

    f.seek(offset)
    blocks, size, nl, eof = [], 0, [np.zeros(0, dtype=np.int64)], False
    while True:
        have = sum(map(len, nl))
        while not eof and have < chunk and size - _after_last(nl) < max_line:
            block = f.read(BLOCK)
            eof = not block
            nl.append(np.flatnonzero(np.frombuffer(block, np.uint8) == 10) + size)
            blocks.append(block)
            size += len(block)
            have += len(nl[-1])
        ends = np.concatenate(nl)
        cut = int(ends[chunk - 1]) + 1 if len(ends) >= chunk else size
        if cut == 0 or (len(ends) < chunk and not eof):
            return                   # the end, or a line of max_line or more
        buf = blocks[0] if len(blocks) == 1 else b"".join(blocks)
        part, ends = buf[:cut], ends[:chunk]
        starts = np.concatenate([[0], ends[:-1] + 1])[:len(ends)]
        last = cut - int(ends[-1]) - 1 if len(ends) else cut      # an unterminated last line
        if max(int((ends - starts).max(initial=0)), last) >= max_line or not part.isascii():
            return
        rows = len(ends) + (last > 0)
        yield part, offset, lineno + 1, rows
        lineno += rows
        offset += cut
        blocks, size, nl = [buf[cut:]], size - cut, [np.concatenate(nl)[len(ends):] - cut]


def _after_last(nl) -> int:
    """Byte position after the last newline of the positions ``nl`` (arrays), 0 if none."""
    last = next((a for a in reversed(nl) if len(a)), None)
    return 0 if last is None else int(last[-1]) + 1
