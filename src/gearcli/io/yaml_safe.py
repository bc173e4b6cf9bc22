"""YAML text -> Python data and a map YAML path -> line, within limits.

The file is parsed by libyaml's event parser when PyYAML has it (pure-Python PyYAML
otherwise), and the node graph is composed here, iteratively, so that hostile files fail
fast and small with one located message:

* a file larger than :data:`~gearcli.io.limits.MAX_BYTES`;
* nesting deeper than :data:`MAX_DEPTH` (``[[[[...``), more than :data:`MAX_NODES` nodes;
* an alias to a node that contains it (``a: &a [*a]``);
* aliases that expand the document beyond ``ALIAS_FACTOR`` times its own node count plus
  ``ALIAS_SLACK`` nodes (a "billion laughs" alias bomb): the expanded size is counted
  on the node graph, never by expanding it;
* integers of more than :data:`MAX_INT_DIGITS` digits;
* duplicate mapping keys, YAML syntax errors, several documents in one file.

Limits leave ordinary files of 100,000 lines far inside them.
"""
from __future__ import annotations

import gc
import re
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

import yaml
from yaml.events import (AliasEvent, MappingEndEvent, MappingStartEvent, ScalarEvent,
                         SequenceEndEvent, SequenceStartEvent, StreamEndEvent)
from yaml.nodes import MappingNode, ScalarNode, SequenceNode

from ..errors import Collector, Issue, MechanismError
from .limits import read_bytes

MAX_DEPTH = 64
MAX_NODES = 2_000_000
MAX_INT_DIGITS = 4000   # Python refuses to convert longer ones (sys.int_info)
ALIAS_FACTOR = 10
ALIAS_SLACK = 100_000
_CAP = ALIAS_FACTOR * MAX_NODES + ALIAS_SLACK + 1   # sizes are counted up to this

_Base = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class Loader(_Base):  # type: ignore[misc, valid-type]
    """SafeLoader (libyaml's when available) that reads floats as YAML 1.2 does: ``1e-4``
    is a number, not a string."""


Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
                |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
                |\.[0-9_]+(?:[eE][-+]?[0-9]+)?
                |[-+]?\.(?:inf|Inf|INF)
                |\.(?:nan|NaN|NAN))$""", re.X),
    list("-+0123456789."),
)


def _fail(file: str, mark, message: str):
    line = mark.line + 1 if mark is not None else None
    raise MechanismError([Issue(file, "", line, message)])


@contextmanager
def _lines_within(text: str) -> Iterator[None]:
    """Errors raised in the block cite a line of ``text``: libyaml puts the end of a
    stream that lacks its final newline on the line after it (a truncated file was
    reported one line past its end); such a line becomes the last one."""
    try:
        yield
    except MechanismError as exc:
        last = text.count("\n") + 1     # the last line (empty after a final newline)
        if all(i.line is None or i.line <= last for i in exc.issues):
            raise
        raise MechanismError([Issue(i.file, i.path, i.line if i.line is None else min(i.line, last), i.message)
                              for i in exc.issues]) from None


def read_text(path: str | Path, kind: str = "mechanism file") -> str:
    """The UTF-8 text of ``path``; raises MechanismError (one located line) when the file
    cannot be read, is larger than :data:`~gearcli.io.limits.MAX_BYTES` or is not UTF-8."""
    data = read_bytes(path, kind)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise MechanismError([Issue(str(path), "", line, f"not a UTF-8 text file (byte {exc.start})")]) from None


@contextmanager
def _gc_paused():
    """Composing creates millions of objects that all live on: pausing the cyclic garbage
    collector meanwhile saves its repeated full scans (2-3 times faster on big files)."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


class _Composer:
    """Iterative composer of one YAML document (PyYAML's Composer without recursion),
    counting distinct nodes and the size the document would have with its aliases
    expanded."""

    def __init__(self, loader, file: str):
        self.ld, self.file = loader, file
        self.anchors: dict[str, object] = {}
        self.size: dict[int, int] = {}      # id(node) -> expanded size, once complete
        self.nodes = 0
        self.worst_alias = (0, None)        # (expanded size, mark) of the biggest alias

    def document(self):
        ld = self.ld
        ld.get_event()  # stream start
        if ld.check_event(StreamEndEvent):
            return None, 0
        ld.get_event()  # document start
        root, size = self._node()
        ld.get_event()  # document end
        if not ld.check_event(StreamEndEvent):
            _fail(self.file, ld.get_event().start_mark,
                  "YAML syntax error: expected a single document in the stream, but found another document")
        return root, size

    def _anchor(self, event, node) -> None:
        if event.anchor is None:
            return
        if event.anchor in self.anchors:
            _fail(self.file, event.start_mark, f"YAML syntax error: duplicate anchor '&{_short(event.anchor)}'")
        self.anchors[event.anchor] = node

    def _alias(self, event):
        node = self.anchors.get(event.anchor)
        if node is None:
            _fail(self.file, event.start_mark, f"YAML syntax error: undefined alias '*{_short(event.anchor)}'")
        if id(node) not in self.size:
            _fail(self.file, event.start_mark,
                  f"alias '*{_short(event.anchor)}' refers to a node that contains it (a recursive structure)")
        size = self.size[id(node)]
        if size > self.worst_alias[0]:
            self.worst_alias = (size, event.start_mark)
        return node, size

    def _scalar(self, event):
        tag = event.tag
        if tag is None or tag == "!":
            tag = self.ld.resolve(ScalarNode, event.value, event.implicit)
        if tag == "tag:yaml.org,2002:int" and len(event.value) > MAX_INT_DIGITS:
            _fail(self.file, event.start_mark,
                  f"an integer of {len(event.value)} digits is out of range (|x| <= 1e12 in SI units)")
        node = ScalarNode(tag, event.value, event.start_mark, event.end_mark, style=event.style)
        self.size[id(node)] = 1   # complete: an alias may name it (a shared efficiency, &eta 0.985)
        self._anchor(event, node)
        return node

    def _collection(self, event, depth: int):
        if depth >= MAX_DEPTH:
            _fail(self.file, event.start_mark, f"YAML nesting deeper than {MAX_DEPTH} levels")
        kind = SequenceNode if isinstance(event, SequenceStartEvent) else MappingNode
        tag = event.tag
        if tag is None or tag == "!":
            tag = self.ld.resolve(kind, None, event.implicit)
        node = kind(tag, [], event.start_mark, None, flow_style=event.flow_style)
        self._anchor(event, node)
        return node

    def _node(self):
        """Compose the next node (and everything below it); returns (node, expanded size)."""
        ld = self.ld
        stack: list[list] = []   # open collections: [node, expanded size, pending key]
        while True:
            event = ld.get_event()
            if isinstance(event, AliasEvent):
                node, size = self._alias(event)
            elif isinstance(event, ScalarEvent):
                node, size = self._scalar(event), 1
            elif isinstance(event, (SequenceStartEvent, MappingStartEvent)):
                stack.append([self._collection(event, len(stack)), 1, None])
                self._count(event)
                continue
            elif isinstance(event, (SequenceEndEvent, MappingEndEvent)):
                node, size, _ = stack.pop()
                node.end_mark = event.end_mark
                self.size[id(node)] = size
            else:  # pragma: no cover (the parser only yields the events above here)
                _fail(self.file, event.start_mark, f"YAML syntax error: unexpected {type(event).__name__}")
            if isinstance(event, ScalarEvent):
                self._count(event)
            if not stack:
                return node, size
            top = stack[-1]
            top[1] = min(top[1] + size, _CAP)
            if isinstance(top[0], SequenceNode):
                top[0].value.append(node)
            elif top[2] is None:
                top[2] = (node,)
            else:
                top[0].value.append((top[2][0], node))
                top[2] = None

    def _count(self, event) -> None:
        self.nodes += 1
        if self.nodes > MAX_NODES:
            _fail(self.file, event.start_mark, f"more than {MAX_NODES:,} YAML nodes")


_FLOW_TOKEN = re.compile(r"""[\[\]{}'"#\n]""")
_BLOCK_VALUE_START = re.compile(r"""(?:^|[:?-][ \t])[ \t]*(?:[!&][^ \t]*[ \t]+)*$""", re.M)


def flow_depth_guard(text: str, file: str) -> None:
    """Refuse flow nesting (``[[[[...``) deeper than :data:`MAX_DEPTH` before any YAML
    parser sees the text.

    libyaml's scanner reads a flow collection ahead of the events it emits (to find
    simple keys), so its own nesting limit (1,000 levels since PyYAML 6.0.4, none before)
    would fire before the composer's depth check; this guard makes the message gearcli's
    whatever the PyYAML version.  It counts ``[``/``{`` that open a flow collection: any
    inside a flow collection, and in block context one that starts a value (after
    indentation, ``key:``, ``-``, ``?``, a tag or an anchor).  Quoted scalars and comments
    are skipped.  Block nesting is left to the composer (the parser streams it)."""
    if text.count("[") + text.count("{") <= MAX_DEPTH:
        return
    depth, pos, line = 0, 0, 1
    n = len(text)
    while pos < n:
        m = _FLOW_TOKEN.search(text, pos)
        if m is None:
            return
        c, i = m.group(), m.start()
        pos = i + 1
        if c == "\n":
            line += 1
        elif c == "#":
            if i == 0 or text[i - 1] in " \t\n":
                j = text.find("\n", i)
                pos = n if j < 0 else j
        elif c in "'\"":
            if depth == 0 and not _BLOCK_VALUE_START.search(text, text.rfind("\n", 0, i) + 1, i):
                continue
            pos, line = _skip_quoted(text, i, c, line)
        elif c in "[{":
            if depth == 0 and not _BLOCK_VALUE_START.search(text, text.rfind("\n", 0, i) + 1, i):
                continue
            depth += 1
            if depth > MAX_DEPTH:
                raise MechanismError([Issue(file, "", line, f"YAML nesting deeper than {MAX_DEPTH} levels")])
        elif depth > 0:  # ] or }
            depth -= 1


def _skip_quoted(text: str, start: int, quote: str, line: int) -> tuple[int, int]:
    """Position after the quoted scalar opening at ``start``, and the line there."""
    i = start + 1
    n = len(text)
    while i < n:
        j = text.find(quote, i)
        if j < 0:
            j = n
        if quote == '"':
            k = j - 1
            while k >= i and text[k] == "\\":
                k -= 1
            if (j - 1 - k) % 2 == 1 and j < n:   # an escaped quote
                line += text.count("\n", i, j + 1)
                i = j + 1
                continue
        elif j + 1 < n and text[j + 1] == "'":   # '' inside a single-quoted scalar
            line += text.count("\n", i, j + 2)
            i = j + 2
            continue
        line += text.count("\n", i, j)
        return j + 1, line
    return n, line


def compose(text: str, file: str):
    """Root node of the single YAML document in ``text`` (None if empty), within the
    limits of the module docstring; raises MechanismError."""
    flow_depth_guard(text, file)
    loader = Loader(text)
    with _lines_within(text):
        try:
            with _gc_paused():
                comp = _Composer(loader, file)
                root, size = comp.document()
        except yaml.YAMLError as exc:
            mark = getattr(exc, "problem_mark", None)
            problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
            _fail(file, mark, f"YAML syntax error: {problem}")
        finally:
            loader.dispose()
    limit = ALIAS_FACTOR * comp.nodes + ALIAS_SLACK
    if size > limit:
        _fail(file, comp.worst_alias[1], f"YAML aliases expand the document to more than {limit:,} nodes "
              f"({ALIAS_FACTOR} times its {comp.nodes:,} nodes + {ALIAS_SLACK:,})")
    return root


def node_lines(root, file: str) -> dict[str, int]:
    """Map YAML path (``joints[2].dh.a``) -> 1-based line; a key's path maps to the key's
    line.  Nodes reached again through an alias are not walked again (their paths map to
    the alias's enclosing line).  Duplicate keys raise MechanismError, every one reported."""
    lines: dict[str, int] = {}
    col = Collector(file, lines)
    seen: set[int] = set()
    stack = [(root, "", False)] if root is not None else []
    while stack:
        node, path, dup = stack.pop()
        if dup:
            col.add(path, f"duplicate key '{_short(path.rsplit('.', 1)[-1])}'")
        lines.setdefault(path, node.start_mark.line + 1)
        if id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, MappingNode):
            keys: set = set()
            entries = []
            for key, value in node.value:
                k = key.value if isinstance(key, ScalarNode) else "?"
                sub = f"{path}.{k}" if path else str(k)
                lines[sub] = key.start_mark.line + 1
                entries.append((value, sub, k in keys))
                keys.add(k)
            stack.extend(reversed(entries))
        elif isinstance(node, SequenceNode):
            stack.extend((node.value[i], f"{path}[{i}]", False) for i in range(len(node.value) - 1, -1, -1))
    col.raise_if_any()
    return lines


def yaml_lines(text: str, file: str) -> tuple[object, dict[str, int]]:
    """Parse YAML ``text``; return the data and a map YAML path -> 1-based line.

    Syntax errors, duplicate keys and the limits of the module docstring raise
    :class:`~gearcli.errors.MechanismError`.
    """
    root = compose(text, file)
    lines = node_lines(root, file)
    if root is None:
        return None, lines
    loader = Loader("")
    try:
        with _gc_paused():
            data = loader.construct_document(root)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        _fail(file, mark, f"YAML error: {problem}")
    except ValueError as exc:  # e.g. a malformed timestamp
        _fail(file, None, f"YAML error: {_short(str(exc))}")
    finally:
        loader.dispose()
    return data, lines


def _short(s: str, n: int = 60) -> str:
    s = str(s)
    return s if len(s) <= n else s[:n] + "…"
