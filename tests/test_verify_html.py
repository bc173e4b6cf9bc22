"""gearcli verify --html (issue 38): one self-contained report a CI job can publish."""
from __future__ import annotations

import json
from pathlib import Path

import lxml.etree
import lxml.html

ROOT = Path(__file__).resolve().parents[1]


def test_html_report_holds_every_check_with_its_plot_inline(run_cli, tmp_path):
    """The bundled reducer design (one failing check of 7): the report has the failure in its
    summary, one table row per check with the same values as the JSON report, one inline PNG
    per check (the failing one open), the case's graph as inline SVG, the backend and the
    versions, and nothing it would fetch (every src/href a data: URI)."""
    out, js = tmp_path / "r.html", tmp_path / "r.json"
    r = run_cli("verify", ROOT / "designs" / "cobot_joint_reducer.yaml", "--html", out, "--json", js, "-j", "1")
    assert r.exit_code == 1, r.stderr
    doc = lxml.html.parse(str(out)).getroot()
    checks = json.loads(js.read_text())["checks"]
    rows = doc.xpath('//table[@class="sortable"]/tbody/tr')
    assert len(rows) == len(checks) == 7
    text = [[c.text_content() for c in row.xpath("td")] for row in rows]
    assert sum(t[0] == "FAIL" for t in text) == 1 and "1 of 7 checks failed" in doc.text_content()
    by_name = {(t[2], t[3]): t for t in text}
    for c in checks:
        t = by_name[(c["component"], c["quantity"])]
        assert float(t[5]) == c["limit"] or abs(float(t[5]) - c["limit"]) <= 1e-3 * abs(c["limit"])
    imgs = doc.xpath("//details/img")
    assert len(imgs) == 7 and all(i.get("src").startswith("data:image/png;base64,") for i in imgs)
    assert len(doc.xpath("//details[@open]")) == 1
    assert [a for a in doc.xpath("//@src | //@href") if not a.startswith("data:")] == []
    svgs = doc.xpath("//*[local-name()='svg']")
    assert len(svgs) == 1 and {"housing", "wave_generator", "arm", "hd"} <= set(svgs[0].itertext())
    body = doc.text_content()
    assert "Solver backend per case" in body and "gearcli " in body and "numpy " in body
    assert "sortable" in out.read_text() and "addEventListener" in out.read_text()


def test_html_report_never_overwrites_an_input(run_cli, tmp_path):
    """--html naming the manifest: refused before any work, exit 2, the manifest unchanged."""
    man = tmp_path / "d.yaml"
    text = (f"cases:\n  - {{name: c, mechanism: {ROOT / 'mechanisms' / 'cobot_joint.yaml'}, "
            f"trajectories: [{ROOT / 'mechanisms' / 'cobot_joint_traj.csv'}], limits: [{{column: 'motor:motor', max_abs: 1}}]}}\n")
    man.write_text(text)
    r = run_cli("verify", man, "--html", man)
    assert r.exit_code == 2 and "--html" in r.stderr and man.read_text() == text


def test_graph_svg_writes_the_drawing_of_the_report(run_cli, tmp_path):
    """gearcli graph --svg FILE: the canonical graph as the HTML report draws it (every link
    and pair named), the tables still on stdout; '-' and an input file are refused, exit 2,
    nothing written."""
    from gearcli import analyse, load_mechanism
    from gearcli.report.graph_svg import graph_svg
    mech = ROOT / "mechanisms" / "bendix_wrist.yaml"
    out = tmp_path / "g.svg"
    r = run_cli("graph", mech, "--svg", out)
    assert r.exit_code == 0 and "Structure matrix" in r.stdout
    text = out.read_text()
    assert text == graph_svg(analyse(load_mechanism(mech)))
    svg = lxml.etree.fromstring(text.encode())
    assert {"0", "3", "5-6", "7-8"} <= set(svg.itertext())
    for bad in ("-", str(mech)):
        r = run_cli("graph", mech, "--svg", bad)
        assert r.exit_code == 2 and "--svg" in r.stderr and r.stderr.count("\n") == 1
    assert mech.read_text().startswith(("#", "name")) and sorted(tmp_path.iterdir()) == [out]
