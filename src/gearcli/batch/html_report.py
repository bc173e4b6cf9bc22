"""``gearcli verify --html REPORT.html``: one self-contained design report for a CI artefact.

No network: the styles and the table-sorting script are inline, every plot is an inline PNG
(a ``data:`` URI) and each case's graph an inline SVG.  The report holds the pass/fail
summary with the plot of the tightest check (the failing one of least margin, else the
passing one of least margin: what a reader opens first), every check (value, limit, margin;
the table sorts by any column), per check the
plot of its quantity against its limit along the duty cycle (:func:`gearcli.batch.verify.write_plots`),
each case's mechanism graph (canonical thin edges by level, heavy edges for the gear pairs and
drive elements) and the backend and versions that ran it.
"""
from __future__ import annotations

import base64
import html
import platform
from pathlib import Path

from .outputs import WARN_MARGIN, fmt

STYLE = """
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.15em; margin-top: 1.6em; }
.pass { color: #1a7f37; } .fail { color: #c0111f; } .tight { color: #9a6700; }
table { border-collapse: collapse; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.5em; }
th { background: #f3f3f3; cursor: pointer; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
details { margin: 0.4em 0; } img { max-width: 100%; }
.meta { color: #555; font-size: 0.85em; }
"""

SORT_SCRIPT = """
document.querySelectorAll('table.sortable th').forEach(function (th, col) {
  th.addEventListener('click', function () {
    var body = th.closest('table').tBodies[0];
    var rows = Array.from(body.rows);
    var asc = th.dataset.asc !== '1';
    th.dataset.asc = asc ? '1' : '0';
    rows.sort(function (a, b) {
      var x = a.cells[col].dataset.v, y = b.cells[col].dataset.v;
      var nx = parseFloat(x), ny = parseFloat(y);
      var c = (!isNaN(nx) && !isNaN(ny)) ? nx - ny : String(x).localeCompare(String(y));
      return asc ? c : -c;
    });
    rows.forEach(function (r) { body.appendChild(r); });
  });
});
"""

COLUMNS = ("status", "case", "component", "quantity", "worst", "limit", "unit", "margin %", "trajectory", "t [s]")


def _status(row) -> str:
    return "FAIL" if not row.passed else ("tight" if row.margin < WARN_MARGIN else "ok")


def _cell(text: str, value=None, num: bool = False) -> str:
    v = html.escape(str(text if value is None else value), quote=True)
    return f'<td{" class=num" if num else ""} data-v="{v}">{html.escape(str(text))}</td>'


def _row(r) -> str:
    s = _status(r)
    cls = {"FAIL": "fail", "tight": "tight", "ok": "pass"}[s]
    cells = [f'<td class="{cls}" data-v="{s}">{s}</td>', _cell(r.case), _cell(r.component), _cell(r.quantity),
             _cell(r.shown(), r.value, True), _cell(fmt(r.limit), r.limit, True), _cell(r.unit),
             _cell(fmt(r.margin), r.margin, True), _cell(r.trajectory), _cell(f"{r.time:.4g}", r.time, True)]
    return "<tr>" + "".join(cells) + "</tr>"


def _png(path: Path) -> str:
    return "data:image/png;base64," + base64.b64encode(Path(path).read_bytes()).decode("ascii")


def _versions() -> str:
    import numpy  # noqa: PLC0415

    from ..pipeline import __version__  # noqa: PLC0415  (the package version, as the loads files record it)
    parts = [f"gearcli {__version__}", f"Python {platform.python_version()}", f"numpy {numpy.__version__}"]
    try:
        import llvmlite  # noqa: PLC0415
        parts.append(f"llvmlite {llvmlite.__version__}")
    except ImportError:
        parts.append("llvmlite not installed")
    return ", ".join(parts) + f"; {platform.machine()} {platform.system()}"


def _tightest(rows, plots: dict) -> list[str]:
    """The summary's figure: the plot of the failing check of least margin, else of the passing
    one of least margin (none without a plot)."""
    drawn = [r for r in rows if (r.case, r.component, r.quantity) in plots]
    if not drawn:
        return []
    r = min(drawn, key=lambda r: (r.passed, r.margin))
    p = plots[(r.case, r.component, r.quantity)]
    return [f'<h2 id="tightest">{"Failing" if not r.passed else "Tightest"} check: {html.escape(r.case)}: '
            f"{html.escape(r.name)} (margin {html.escape(fmt(r.margin))} %)</h2>",
            f'<img class="tightest" alt="{html.escape(r.name)}" src="{_png(p)}">']


def html_report(rows, results, manifest: str, plots: dict, graphs: dict) -> str:
    """The report's HTML (a string).  ``plots``: {(case, component, quantity): PNG path};
    ``graphs``: {case: inline SVG of its mechanism's graph}."""
    failed = sum(not r.passed for r in rows)
    tight = sum(r.passed and r.margin < WARN_MARGIN for r in rows)
    verdict = (f'<p class="fail"><b>{failed} of {len(rows)} checks failed.</b></p>' if failed else
               f'<p class="pass"><b>All {len(rows)} checks passed.</b></p>')
    backends = "".join(f"<li>{html.escape(c)}: {html.escape(b)}</li>" for c, b in dict((r.case, r.backend) for r in rows).items())
    out = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
           f"<title>Design checks: {html.escape(manifest)}</title>", f"<style>{STYLE}</style></head><body>",
           f"<h1>Design checks: {html.escape(manifest)}</h1>", verdict,
           f"<p>{len(rows) - failed} passed ({tight} with less than {WARN_MARGIN:g} % margin), {failed} failed.</p>",
           f"<p class=meta>Solver backend per case:</p><ul class=meta>{backends}</ul>",
           f"<p class=meta>Ran with {html.escape(_versions())}.</p>", *_tightest(rows, plots),
           "<h2>Checks</h2><p class=meta>Click a column's header to sort by it.</p>",
           '<table class="sortable"><thead><tr>' + "".join(f"<th>{html.escape(c)}</th>" for c in COLUMNS)
           + "</tr></thead><tbody>", *(_row(r) for r in rows), "</tbody></table>",
           "<h2>Each check along its duty cycle</h2>"]
    for r in rows:
        p = plots.get((r.case, r.component, r.quantity))
        body = (f'<img alt="{html.escape(r.name)}" src="{_png(p)}">' if p is not None
                else "<p class=meta>(no plot for this check)</p>")
        out.append(f"<details{' open' if not r.passed else ''}><summary>{html.escape(r.case)}: "
                   f"{html.escape(r.name)} ({_status(r)}, margin {html.escape(fmt(r.margin))} %)</summary>{body}</details>")
    out.append("<h2>Mechanisms</h2>")
    for case, svg in graphs.items():
        out.append(f"<h3>{html.escape(case)}</h3>{svg}")
    out += [f"<script>{SORT_SCRIPT}</script>", "</body></html>"]
    return "\n".join(out) + "\n"
