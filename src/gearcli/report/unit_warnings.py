"""Plausibility findings (:mod:`gearcli.model.plausibility`) as located warnings, or errors.

A warning is one line, ``file:line: place: warning: what``, and leaves the exit status
alone; with ``--strict`` the same findings are errors (:class:`StrictError`, exit status 2,
nothing written).  :func:`mechanism_issues` locates the findings of a mechanism in its file;
:class:`RateWatch` looks at the samples of a trajectory, chunk by chunk, and reports each
implausible column once, at its first sample.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import Collector, GearcliError, Issue
from ..model.plausibility import (MAX_ANGLE, MAX_JOINT_RATE, MAX_MOTOR_SPEED, fast_joints, fast_motors,
                                 mechanism_findings, turned_joints)

STRICT = " (--strict)"


def warning_lines(issues: list[Issue]) -> list[str]:
    """``file:line: place: warning: message`` of every issue."""
    return [str(Issue(i.file, i.path, i.line, f"warning: {i.message}")) for i in issues]


class StrictError(GearcliError):
    """Warnings made errors by ``--strict``: ``lines`` the located warnings (``issues``, and
    ``others``: warnings already written as lines), each marked ``(--strict)``."""

    def __init__(self, issues: list[Issue], others: list[str] = ()):
        self.issues, self.others = list(issues), list(others)
        super().__init__("\n".join(self.lines()))

    def lines(self) -> list[str]:
        return [f"{line}{STRICT}" for line in list(self.others) + [str(i) for i in self.issues]]


SHOWN = 3
"""Findings of one kind shown one by one; the others are counted in one more line."""


def mechanism_issues(an) -> list[Issue]:
    """The plausibility findings of the analysed mechanism ``an``, located in its file: the
    first :data:`SHOWN` of each kind, then how many more."""
    col = Collector(an.mech.source, an.mech.lines)
    for kind, found in mechanism_findings(an).items():
        for f in found[:SHOWN]:
            col.add(f.path, f.message)
        if len(found) > SHOWN:
            col.issues.append(Issue(col.file, "", None, f"{len(found) - SHOWN} more {kind}"))
    return col.issues


def _rpm(w: float) -> str:
    return f"{abs(w) * 30.0 / math.pi:,.0f} rpm"


class RateWatch:
    """Implausible joint angles, joint rates and motor speeds in a trajectory read by
    ``reader`` (:class:`~gearcli.io.trajectory.TrajectoryReader`) for the analysis ``an``.

    :meth:`see` takes every chunk (:class:`~gearcli.io.trajectory.Trajectory`, SI units)
    and returns the issues it found that were not reported before (one per joint and kind,
    one per motor); with ``strict`` it raises :class:`StrictError` at the first one.
    """

    def __init__(self, reader, an, strict: bool = False):
        from .columns import motor_linear  # noqa: PLC0415  (imports the solver: not for check)

        self.reader, self.an, self.strict = reader, an, strict
        joints = an.mech.joints
        self.revolute = np.array([ji >= 0 and joints[ji].type == "revolute" for ji in an.independent], bool)
        self.rotary = np.array([not motor_linear(an, m.name) for m in an.mech.motors], bool)
        self.seen: set = set()
        self.issues: list[Issue] = []
        self.hint = ("the trajectory was read in degrees (--degrees): are its angles degrees?" if reader.degrees
                     else "is the trajectory in degrees? (give --degrees)")

    def _column(self, kind: str, j: int) -> str:
        """Where joint ``j``'s ``kind`` (``q``, ``qd``) is in the file: its column, or the
        column it is derived from."""
        header, cols = self.reader.header, self.reader.cols
        name = self.an.independent_names[j]
        if cols[kind] is not None:
            return f"column {cols[kind][j] + 1} '{header[cols[kind][j]]}'"
        return f"{kind}:{name} (derived from column {cols['q'][j] + 1} '{header[cols['q'][j]]}')"

    def see(self, part) -> list[Issue]:
        """New issues in the chunk ``part`` (raises :class:`StrictError` with ``strict``)."""
        new = []
        names = self.an.independent_names

        def add(key, row, place, message):
            if key in self.seen:
                return
            self.seen.add(key)
            line = None if part.line is None else int(part.line[row])
            new.append(Issue(self.reader.file, place, line, f"{message}: {self.hint}"))

        for row, j, v in turned_joints(part.q, self.revolute):
            add(("q", j), row, self._column("q", j), f"joint '{names[j]}' at {v:.4g} rad ({abs(v) / (2 * math.pi):.3g} "
                f"turns from zero), beyond {MAX_ANGLE:.3g} rad (two turns)")
        for row, j, v in fast_joints(part.qd, self.revolute):
            add(("qd", j), row, self._column("qd", j), f"joint '{names[j]}' turns at {v:.4g} rad/s ({_rpm(v)}), "
                f"above {MAX_JOINT_RATE:g} rad/s")
        if self.rotary.any():
            speed = part.qd @ self.an.A
            for row, m, v in fast_motors(speed, self.rotary):
                add(("motor", m), row, f"sample t = {part.t[row]:.9g} s", f"motor '{self.an.mech.motors[m].name}' "
                    f"turns at {v:.4g} rad/s ({_rpm(v)}), above {MAX_MOTOR_SPEED:,.0f} rad/s")
        if new and self.strict:
            raise StrictError(new)
        self.issues += new
        return new
