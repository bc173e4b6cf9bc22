"""Reports of a verification run: rich table, JUnit XML, JSON, Markdown.

One row per check: case, component, quantity, worst value, limit, margin in % (positive
when the check passes), worst trajectory and the time in it; failures first.  Each case
also states the solver path that ran (``backend``: "llvm", or "numpy (auto: why)"): a
field of every JSON check, a ``backend`` property of every JUnit test suite, a line of the
Markdown report.  An
infinite life is written as its reason, "no damage (below the endurance limit)" for a gear
whose Miner sum is 0 and "no revolutions (the bearing does not turn)" for a bearing, "no load" for a
safety factor, in text, and as ``null`` with that reason (``value_note``) in JSON.  A gear
check's JSON entry adds the stresses it used (:func:`gearcli.design.evaluate.details_of`):
``peak_stress_MPa``, and for fatigue ``rainflow_MPa_per_hour`` [[stress, cycles an hour],
...] and ``tooth_passes_per_hour``.
"""
from __future__ import annotations

import json
import re
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from rich.table import Table
from rich.text import Text

from ..errors import counted
from ..io.output import write_text


def file_slug(text: str) -> str:
    """``text`` as a file-name part: runs of other characters than [A-Za-z0-9_.-] become _."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_")


WARN_MARGIN = 10.0
"""%: a passing check with less margin is flagged (and plotted with ``--plots``)."""


@dataclass(frozen=True)
class Row:
    case: str
    component: str
    quantity: str
    value: float
    limit: float
    unit: str
    margin: float
    passed: bool
    trajectory: str
    time: float
    backend: str = ""
    kind: str = ""          # the check's kind (Check.kind): "life", "fatigue", "peak", ...
    details: dict = field(default_factory=dict, compare=False)   # Verdict.details: a gear check's stresses

    @property
    def name(self) -> str:
        return f"{self.component}: {self.quantity}"

    @property
    def note(self) -> str:
        """Why the value is infinite ("" when it is finite): the words the reports print."""
        if not math.isinf(self.value):
            return ""
        return INFINITE_NOTES.get(self.kind, "inf")

    def shown(self) -> str:
        """The value as the text reports print it: its reason when infinite, else :func:`fmt`."""
        return self.note or fmt(self.value)


INFINITE_NOTES = {"fatigue": "no damage (below the endurance limit)",
                  "life": "no revolutions (the bearing does not turn)",
                  "safety": "no load (a safety factor over a zero load)",
                  "reducer_life": "no load or no turning (the reducer's input does not turn, or carries no torque)",
                  "screw_life": "no load or no turning (the screw does not turn, or carries no axial load)",
                  "slack": "no effective pull (both spans at the pretension)",
                  "worm_efficiency": "no power flows (the pair does not turn, or carries no load)"}
"""What an infinite value of a check kind means: the reports print it in place of "inf"."""


def rows_of(results) -> list[Row]:
    """Every verdict as a :class:`Row`, failures first (then by margin), stable otherwise."""
    rows = []
    for r in results:
        for v in r.verdicts:
            traj = r.case.trajectories[v.trajectory]
            rows.append(Row(r.case.name, v.check.component, v.check.quantity, v.value, v.check.limit,
                            v.check.unit, v.margin, v.passed, Path(traj).name, v.time, r.backend, v.check.kind, v.details))
    return sorted(rows, key=lambda row: (row.passed, row.margin))


def fmt(x: float) -> str:
    return "inf" if math.isinf(x) else f"{x:.4g}"


def with_unit(x: float, unit: str) -> str:
    """``x`` (:func:`fmt`) and its unit, if it has one (a safety factor has none)."""
    return f"{fmt(x)} {unit}" if unit else fmt(x)


def rich_table(rows: list[Row]) -> Table:
    table = Table(title="Design checks")
    for head, just in (("", "left"), ("case", "left"), ("component", "left"), ("quantity", "left"),
                       ("worst", "right"), ("limit", "right"), ("unit", "left"), ("margin %", "right"),
                       ("trajectory", "left"), ("t [s]", "right")):
        table.add_column(head, justify=just)
    for r in rows:
        style = "red" if not r.passed else ("yellow" if r.margin < WARN_MARGIN else "green")
        table.add_row(Text("FAIL" if not r.passed else "ok", style=style), r.case, r.component, r.quantity,
                      r.shown(), fmt(r.limit), r.unit, Text(fmt(r.margin), style=style), r.trajectory,
                      f"{r.time:.4g}")
    return table


def write_junit(rows: list[Row], path, suite: str) -> None:
    """JUnit XML: one ``<testsuite>`` per case, one ``<testcase>`` per check; a failing
    check has a ``<failure>`` with the worst value, limit and margin."""
    root = ET.Element("testsuites", name=suite, tests=str(len(rows)),
                      failures=str(sum(not r.passed for r in rows)))
    for case in dict.fromkeys(r.case for r in rows):
        mine = [r for r in rows if r.case == case]
        ts = ET.SubElement(root, "testsuite", name=case, tests=str(len(mine)),
                           failures=str(sum(not r.passed for r in mine)), errors="0", skipped="0")
        props = ET.SubElement(ts, "properties")
        ET.SubElement(props, "property", name="backend", value=mine[0].backend)
        for r in mine:
            tc = ET.SubElement(ts, "testcase", classname=f"{suite}.{case}", name=r.name, time="0")
            text = (f"{r.name}: worst {r.note or with_unit(r.value, r.unit)} (limit {with_unit(r.limit, r.unit)}), margin "
                    f"{fmt(r.margin)} %, in {r.trajectory} at t = {r.time:.4g} s")
            if r.passed:
                ET.SubElement(tc, "system-out").text = text
            else:
                ET.SubElement(tc, "failure", message=text, type="DesignCheckFailed").text = text
    ET.indent(root)
    write_text(path, '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n")


def _num(x: float):
    """``x`` for JSON: null when it is not finite (an unturned bearing's infinite life)."""
    return x if math.isfinite(x) else None


def write_json(rows: list[Row], path, manifest: str) -> None:
    doc = {"manifest": manifest, "passed": all(r.passed for r in rows),
           "checks": [{"case": r.case, "component": r.component, "quantity": r.quantity, "value": _num(r.value),
                       **({"value_note": r.note} if r.note else {}),
                       "limit": _num(r.limit), "unit": r.unit, "margin_pct": _num(r.margin), "passed": r.passed,
                       "trajectory": r.trajectory, "time": _num(r.time), "backend": r.backend, **r.details}
                      for r in rows]}
    write_text(path, json.dumps(doc, indent=2, allow_nan=False) + "\n")   # strict JSON: never NaN/Infinity


def backends(rows: list[Row]) -> dict:
    """{case: the solver path that ran} in row order."""
    return {r.case: r.backend for r in rows}


def markdown(rows: list[Row], manifest: str) -> str:
    failed = sum(not r.passed for r in rows)
    head = (f"## Design checks: {manifest}\n\n"
            + (f"**{failed} of {counted(len(rows), 'check')} failed.**\n\n" if failed else
               f"{'All ' if len(rows) > 1 else ''}{counted(len(rows), 'check')} passed.\n\n"))
    head += "".join(f"Solver backend of {case}: {backend}\n\n" for case, backend in backends(rows).items())
    lines = ["| | case | component | quantity | worst | limit | unit | margin % | trajectory | t [s] |",
             "|---|---|---|---|---:|---:|---|---:|---|---:|"]
    for r in rows:
        mark = "❌" if not r.passed else ("⚠️" if r.margin < WARN_MARGIN else "✅")
        cells = [mark, r.case, r.component, r.quantity, r.shown(), fmt(r.limit), r.unit, fmt(r.margin),
                 r.trajectory, f"{r.time:.4g}"]
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    return head + "\n".join(lines) + "\n"


def write_markdown(rows: list[Row], path, manifest: str) -> None:
    write_text(path, markdown(rows, manifest))
