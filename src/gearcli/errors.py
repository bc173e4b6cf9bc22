"""Input problems: collected with their source location, reported once.

Every check appends an :class:`Issue` (file, YAML path or element, line, message) to a
list; :class:`MechanismError` carries the whole list.  The CLI prints one line per issue
(``file:line: path: message``) and exits with status 2.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Issue:
    """One problem in an input file."""

    file: str
    path: str
    line: int | None
    message: str

    def __str__(self) -> str:
        """``file[:line]: [path: ]message`` on one line, path and message capped to
        :data:`MAX_PATH` and :data:`MAX_MESSAGE` characters (a 100 kB name in the input is
        not echoed whole)."""
        where = self.file if self.line is None else f"{self.file}:{self.line}"
        message = capped(self.message, MAX_MESSAGE)
        return f"{where}: {capped(self.path, MAX_PATH)}: {message}" if self.path else f"{where}: {message}"


MAX_PATH = 160
MAX_MESSAGE = 400


class LocatedWarning(str):
    """A warning of the reader (``Mechanism.warnings``): the text ``file:line: place: what``
    of its :class:`Issue`, which it keeps as ``issue`` so that the commands print it as every
    other warning, ``file:line: place: warning: what``."""

    def __new__(cls, issue):
        obj = super().__new__(cls, str(issue))
        obj.issue = issue
        return obj

    def shown(self) -> str:
        """The warning as the commands print it."""
        i = self.issue
        return str(Issue(i.file, i.path, i.line, f"warning: {i.message}")) if isinstance(i, Issue) else f"warning: {self}"


def capped(text: str, limit: int) -> str:
    """``text`` on one line, cut to ``limit`` characters with an ellipsis."""
    text = " ".join(str(text).splitlines())
    return text if len(text) <= limit else text[:limit - 1] + "…"


def plural(n: int, noun: str, nouns: str | None = None) -> str:
    """``noun`` in the number of ``n``: ``plural(1, "joint")`` is ``joint``, ``plural(2,
    "joint")`` is ``joints`` (``nouns``: an irregular plural)."""
    return noun if n == 1 else nouns or noun + "s"


def counted(n: int, noun: str, nouns: str | None = None) -> str:
    """``n`` and its noun agreeing: ``1 gear pair``, ``3 gear pairs``, ``0 samples``."""
    return f"{n} {plural(n, noun, nouns)}"


MAX_SHOWN = 50
"""Problems the command line prints of one error; the rest are counted on one more line
(a file with 20,000 unknown keys gives 50 lines and ``… and 19,950 more problems``)."""


def shown(lines: list[str], limit: int = MAX_SHOWN) -> list[str]:
    """The first ``limit`` of ``lines`` and, when some are left out, a last line counting
    them: ``… and 19,950 more problems``."""
    if len(lines) <= limit:
        return list(lines)
    rest = len(lines) - limit
    return lines[:limit] + [f"… and {rest:,} more {plural(rest, 'problem')}"]


class GearcliError(Exception):
    """Base class of the errors gearcli reports as bad input (exit status 2)."""

    def __str__(self) -> str:
        """The message; a subclass that builds its lines itself (no message given to the
        constructor) shows them, so that a traceback or ``str(exc)`` is never empty."""
        text = super().__str__()
        if text or type(self).lines is GearcliError.lines:
            return text
        return "\n".join(self.lines())

    def lines(self) -> list[str]:
        """One line per problem, ``file:line: place: what is wrong``."""
        return [str(self)]


class MechanismError(GearcliError):
    """A mechanism file is invalid; ``issues`` lists every problem found."""

    def __init__(self, issues: list[Issue]):
        self.issues = list(issues)
        super().__init__("\n".join(str(i) for i in self.issues))

    def lines(self) -> list[str]:
        """One line per problem, ``file:line: place: what is wrong``."""
        return [str(i) for i in self.issues]


class IncompleteMechanismError(MechanismError):
    """Problems found while reading a mechanism file that did not stop it from being built:
    ``mechanism`` is what was built despite them, for the graph analysis to find the problems
    that remain (``gearcli check`` reports every problem at once: a wrong ring tooth count
    breaks both the planets' assembly and the ring's mesh geometry).  Never a usable
    mechanism: it is raised, not returned."""

    def __init__(self, issues: list[Issue], mechanism):
        super().__init__(issues)
        self.mechanism = mechanism


class TrajectoryError(GearcliError):
    """A trajectory file or array is invalid; ``issue`` (an :class:`Issue`: file, place
    such as ``column 2 'q:J1'``, line, message) says where when it is known."""

    def __init__(self, issue: Issue | str):
        self.issue = issue if isinstance(issue, Issue) else None
        super().__init__(str(issue))


class Collector:
    """Collects issues of one file, locating YAML paths through a path -> line map."""

    def __init__(self, file: str, lines: dict[str, int] | None = None):
        self.file = file
        self.lines = lines if lines is not None else {}
        self.issues: list[Issue] = []
        self._seen: set[Issue] = set()   # the issues[:_counted] as a set: add() is O(1)
        self._counted = 0

    def line_of(self, path: str) -> int | None:
        """Line of ``path`` or of its nearest enclosing node."""
        p = path
        while p:
            if p in self.lines:
                return self.lines[p]
            cut = max(p.rfind("."), p.rfind("["))
            p = p[:cut] if cut > 0 else ""
        return self.lines.get("", None)

    def add(self, path: str, message: str) -> None:
        """Record a problem at YAML/element ``path`` (its line looked up), once (the copies
        of a ``planets: N`` item report at their original's path)."""
        issue = Issue(self.file, path, self.line_of(path), message)
        if len(self.issues) < self._counted:      # the list was replaced by a shorter one
            self._seen, self._counted = set(), 0
        if len(self.issues) > self._counted:      # issues appended directly (readers merge lists)
            self._seen.update(self.issues[self._counted:])
            self._counted = len(self.issues)
        if issue not in self._seen:
            self.issues.append(issue)
            self._seen.add(issue)
            self._counted += 1

    def raise_if_any(self) -> None:
        """Raise a :class:`MechanismError` with every problem recorded so far, if any."""
        if self.issues:
            raise MechanismError(self.issues)
