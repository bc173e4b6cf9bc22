"""`gearcli verify`: verdicts against hand statics, exit codes, reports, batch execution."""
from schema_keys import schema_keys
import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
DESIGNS = ROOT / "designs"

# A rotor: one link on a vertical axis (joint J, z up), centre of mass at (r, 0, h) in the
# joint frame, turning at a constant rate w.  By hand (Newton-Euler, principal axes along the
# joint frame, no angular acceleration): the reaction on the rotor is F = m (a - g) with
# a = -w^2 r e_x, i.e. F = (-m w^2 r, 0, m g); its moment about the joint origin is
# c x F = (0, -m r (h w^2 + g), 0).  The radial resultant m w^2 r therefore acts at the
# height z* = h + g / w^2, and two bearings at 0 and L share it by the lever rule.
M, R, H, W, G, T = 2.0, 0.05, 0.03, 10.0, 9.81, 2.0
L = 0.1


def rotor_yaml(bearings: str) -> str:
    return f"""
name: rotor
base: "0"
end_effector: "1"
links:
  - name: "0"
  - {{name: "1", mass: {M}, com: [{R}, 0, {H}], inertia: [0.01, 0.01, 0.02]}}
joints:
  - name: J
    parent: "0"
    child: "1"
    origin: {{xyz: [0, 0, 0]}}
    bearings: {bearings}
motors:
  - {{name: m, link: "1", rating: {{peak_torque: 1, rms_torque: 0.5, max_speed: 20}}}}
"""


def write_rotor_case(tmp_path, bearings, life=1000.0, name="rotor"):
    (tmp_path / f"{name}.yaml").write_text(rotor_yaml(bearings))
    t = np.linspace(0, T, 401)
    np.savetxt(tmp_path / f"{name}.csv", np.column_stack([t, W * t, np.full_like(t, W), 0 * t]),
               delimiter=",", header="t,q:J,qd:J,qdd:J", comments="")
    return (f"  - {{name: {name}, mechanism: {name}.yaml, trajectories: [{name}.csv], cycles_per_hour: {3600 / T},"
            f" bearing_life_h: {life}, min_static_safety: 1.5}}\n")


def run_json(run_cli, tmp_path, manifest_text, *args):
    man = tmp_path / "design.yaml"
    man.write_text(manifest_text)
    out = tmp_path / "out.json"
    r = run_cli("verify", man, "--json", out, "-j", "1", *args)
    return r, (json.loads(out.read_text()) if out.exists() else None)


def by_name(doc):
    return {(c["case"], c["component"], c["quantity"]): c for c in doc["checks"]}


def l10h_closed_form(C, P):
    # constant load and speed: L10h = (C/P)^3 1e6 / (3600 n[rev/s])
    return (C / P) ** 3 * 1e6 / (3600 * W / (2 * math.pi))


def test_two_bearing_rotor_life_and_static_safety_by_hand(run_cli, tmp_path):
    case = write_rotor_case(tmp_path, f"[{{name: a, position: 0, C: 5000, C0: 2000, type: ball, locating: true}},"
                                      f" {{name: b, position: {L}, C: 5000, C0: 2000, type: ball}}]")
    r, doc = run_json(run_cli, tmp_path, "cases:\n" + case)
    assert r.exit_code == 0, r.stdout + r.stderr
    checks = by_name(doc)
    Fr_total, Fa = M * W**2 * R, M * G
    z_star = H + G / W**2
    Fr_b = Fr_total * z_star / L                  # 12.81 N
    Fr_a = abs(Fr_total * (L - z_star) / L)       # 2.81 N (the resultant acts beyond b)
    # ISO 281 Table 3 (catalogue column, no f0): Fa/C0 = 19.62/2000 = 0.0098 is below the
    # first row 0.014, whose e = 0.19 and Y = 2.30 are held; Fa/Fr = 7 > e: X Fr + Y Fa
    P_a = 0.56 * Fr_a + 2.30 * Fa
    P_b = Fr_b                                    # no axial load on the floating bearing
    life_a = checks[("rotor", "bearing J/a", "L10 life")]["value"]
    life_b = checks[("rotor", "bearing J/b", "L10 life")]["value"]
    assert life_a == pytest.approx(l10h_closed_form(5000, P_a), rel=1e-6)
    assert life_b == pytest.approx(l10h_closed_form(5000, P_b), rel=1e-6)
    s0_a = checks[("rotor", "bearing J/a", "static safety s0")]["value"]
    assert s0_a == pytest.approx(2000 / max(0.6 * Fr_a + 0.5 * Fa, Fr_a), rel=1e-6)
    s0_b = checks[("rotor", "bearing J/b", "static safety s0")]["value"]
    assert s0_b == pytest.approx(2000 / Fr_b, rel=1e-6)


def test_single_bearing_takes_the_whole_reaction_and_its_moment(run_cli, tmp_path):
    case = write_rotor_case(tmp_path, "[{name: x, position: 0, C: 3000, C0: 3000, type: roller, M: 1.2}]")
    r, doc = run_json(run_cli, tmp_path, "cases:\n" + case)
    checks = by_name(doc)
    Fr, Fa = M * W**2 * R, M * G
    P = 0.4 * Fr + 1.49 * Fa                           # roller defaults, Fa/Fr > e = 0.4
    life = checks[("rotor", "bearing J/x", "L10 life")]["value"]
    assert life == pytest.approx((3000 / P) ** (10 / 3) * 1e6 / (3600 * W / (2 * math.pi)), rel=1e-6)
    moment = checks[("rotor", "bearing J/x", "tilting moment")]
    assert moment["value"] == pytest.approx(M * R * (H * W**2 + G), rel=1e-9)   # 1.281 N*m
    assert not moment["passed"] and r.exit_code == 1                              # above M = 1.2
    assert moment["margin_pct"] == pytest.approx(100 * (1.2 - 1.281) / 1.2, rel=1e-6)


def test_bundled_example_passes_and_writes_junit_json_markdown(run_cli, tmp_path):
    xml, js, md = tmp_path / "r.xml", tmp_path / "r.json", tmp_path / "r.md"
    r = run_cli("verify", DESIGNS / "ci_example.yaml", "--junit", xml, "--json", js, "--markdown", md, "-j", "1")
    assert r.exit_code == 0, r.stdout + r.stderr
    doc = json.loads(js.read_text())
    assert doc["passed"] and len(doc["checks"]) > 40
    root = ET.parse(xml).getroot()
    cases = root.findall(".//testcase")
    assert len(cases) == len(doc["checks"]) and not root.findall(".//failure")
    assert int(root.get("tests")) == len(cases) and root.get("failures") == "0"
    text = md.read_text()
    assert "All" in text and text.count("\n|") == len(doc["checks"]) + 2
    kinds = {c["component"].split()[0] for c in doc["checks"]}
    assert kinds == {"motor", "bearing", "gear", "column"}


def test_tight_manifest_exits_1_naming_the_limit_and_plots_it(run_cli, tmp_path):
    xml, plots = tmp_path / "r.xml", tmp_path / "plots"
    r = run_cli("verify", DESIGNS / "ci_tight.yaml", "--junit", xml, "--plots", plots, "-j", "1")
    assert r.exit_code == 1
    assert "FAILED wrist_motion: column motor:motor5" in r.stdout
    failures = ET.parse(xml).getroot().findall(".//testcase/failure/..")
    assert [f.get("name") for f in failures] == ["column motor:motor5: max abs"]
    assert "limit 0.25" in failures[0].find("failure").get("message")
    pngs = sorted(plots.glob("*.png"))
    assert pngs and all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in pngs)
    assert any("motor5" in p.name for p in pngs)


def test_bad_manifest_lists_every_problem_before_running(run_cli, tmp_path):
    (tmp_path / "bad.yaml").write_text("name: x\nbase: '0'\n")      # not a valid mechanism
    man = tmp_path / "design.yaml"
    man.write_text(f"""cases:
  - mechanism: {ROOT / 'mechanisms' / 'bendix_wrist_rated.yaml'}
    trajectories: [missing_*.csv]
    bearing_life_h: 100
    limits:
      - {{column: "gear:4-1:tt", max_abs: 1}}
  - mechanism: bad.yaml
    trajectories: {ROOT / 'mechanisms' / 'bendix_wrist_traj.csv'}
    speed: 3
""")
    xml = tmp_path / "r.xml"
    r = run_cli("verify", man, "--junit", xml)
    assert r.exit_code == 2 and not xml.exists()
    lines = r.stderr.strip().splitlines()
    # one round: the schema's problem (an unknown key) and those of the valid parts together
    assert f"{man}:9: cases[1].speed: unknown key 'speed' (allowed: name, mechanism, trajectories, service_life_h, " \
           "degrees, cycles_per_hour, bearing_life_h, gear_life_h, reducer_life_h, screw_life_h, min_worm_efficiency, " \
           "min_static_safety, " \
           "min_bending_safety, min_contact_safety, limits)" in lines
    assert f"{man}:3: cases[0].trajectories[0]: no trajectory file matches 'missing_*.csv' (relative to {tmp_path})" \
        in lines
    assert f"{man}:4: cases[0].bearing_life_h: a bearing life in hours needs the duty's cycles_per_hour" in lines
    assert f"{man}:6: cases[0].limits[0].column: unknown output column 'gear:4-1:tt' (did you mean 'gear:4-1:t'?)" \
        in lines
    assert any(x.startswith(str(tmp_path / "bad.yaml")) for x in lines)
    assert "Traceback" not in r.stderr
    r = run_cli("verify", man.with_name("d2.yaml"))
    assert r.exit_code == 2 and "cannot read file" in r.stderr


def test_rating_problems_in_the_mechanism_file_name_their_line(run_cli, tmp_path):
    text = (ROOT / "mechanisms" / "bendix_wrist_rated.yaml").read_text()
    bad = text.replace("locating: true}\n      - {name: upper, position: 0.05, C: 4490",
                       "locating: false}\n      - {name: upper, position: 0.05, C: 4490", 1)
    path = tmp_path / "wrist.yaml"
    path.write_text(bad)
    r = run_cli("check", path)
    assert r.exit_code == 2
    line = next(i for i, x in enumerate(bad.splitlines(), 1) if "name: J1" in x) + 5
    assert f"wrist.yaml:{line}: joints[0].bearings: with two bearings, exactly one needs 'locating: true'" in r.stderr
    path.write_text(text.replace("rating: {module: 0.002", "rating: {module: 0.0025", 1))
    man = tmp_path / "d.yaml"
    man.write_text(f"cases:\n  - {{mechanism: wrist.yaml, trajectories: {ROOT / 'mechanisms' / 'bendix_wrist_traj.csv'}}}\n")
    r = run_cli("verify", man)
    assert r.exit_code == 2
    assert "gears[1].rating.module: module 0.0025 m x 25 teeth / 2 = 0.03125 m disagrees with the pitch radius 0.025 m" in r.stderr


def test_parallel_and_dask_runs_give_identical_results(run_cli, tmp_path):
    pytest.importorskip("dask.distributed")
    from dask.distributed import LocalCluster

    case = write_rotor_case(tmp_path, "[{name: x, position: 0, C: 3000, C0: 3000, type: ball}]")
    (tmp_path / "rotor2.csv").write_text((tmp_path / "rotor.csv").read_text())
    wrist = ROOT / "mechanisms"
    text = ("cases:\n" + case.replace("[rotor.csv]", "[rotor.csv, rotor2.csv]")
            + f"  - {{name: wrist, mechanism: {wrist / 'bendix_wrist_rated.yaml'}, "
              f"trajectories: [{wrist / 'bendix_wrist_traj.csv'}], cycles_per_hour: 100, bearing_life_h: 1000}}\n")
    _, serial = run_json(run_cli, tmp_path, text)
    _, pool = run_json(run_cli, tmp_path, text, "-j", "2")
    with LocalCluster(n_workers=1, processes=False, threads_per_worker=1, dashboard_address=None) as cluster:
        _, dask = run_json(run_cli, tmp_path, text, "--dask", cluster.scheduler_address)
    assert serial is not None and len(serial["checks"]) > 40
    assert pool == serial
    assert dask == serial


def test_plot_command_draws_matching_columns(run_cli, tmp_path):
    loads = tmp_path / "w.csv"
    assert run_cli("solve", ROOT / "mechanisms" / "bendix_wrist.yaml", ROOT / "mechanisms" / "bendix_wrist_traj.csv",
                   "-o", loads).exit_code == 0
    fig = tmp_path / "f.svg"
    r = run_cli("plot", loads, "motor:motor?", "gear:4-1:t", "motor:*:power", "-o", fig)
    assert r.exit_code == 0, r.stderr
    assert "(7 columns)" in r.stdout and fig.read_text().lstrip().startswith("<?xml")
    r = run_cli("plot", loads, "motor:nothing*", "-o", tmp_path / "g.png")
    assert r.exit_code == 2 and "no column matches 'motor:nothing*'" in r.stderr
    assert not (tmp_path / "g.png").exists()
    r = run_cli("plot", loads, "t", "-o", tmp_path / "g.gif")
    assert r.exit_code == 2 and "format" in r.stderr


def test_the_manifest_reference_documents_every_manifest_key():
    import re

    from gearcli.batch.manifest import design_schema

    generated = (ROOT / "docs" / "reference" / "design-manifest.md").read_text()
    missing = sorted({k for k in schema_keys(design_schema())
                      if not re.search(rf"^\| `([\w.]+\.)?{k}`( \(required\))? \|", generated, re.M)})
    assert not missing, f"docs/reference/design-manifest.md lacks entries for {missing} (run python docs/gen_reference.py)"
    readme = (ROOT / "docs" / "reference" / "manifest.md").read_text()

    missing = sorted({k for k in schema_keys(design_schema()) if not re.search(rf"`[^`\n]*\b{k}\b[^`\n]*`", readme)})
    assert not missing, f"docs/reference/manifest.md lacks manifest keys {missing}"


def test_unreachable_dask_scheduler_is_bad_input(run_cli, tmp_path, monkeypatch):
    pytest.importorskip("dask.distributed")
    from gearcli.batch import runner

    monkeypatch.setattr(runner, "DASK_TIMEOUT", 0.5)
    r = run_cli("verify", DESIGNS / "ci_example.yaml", "--dask", "tcp://127.0.0.1:9")
    assert r.exit_code == 2
    assert r.stderr.startswith("--dask: cannot connect to the scheduler at 'tcp://127.0.0.1:9'")


def test_bevel_tooth_stresses_of_the_rated_wrist_by_hand(run_cli, tmp_path, mech_dir):
    # Pair 5-6: 25:25 bevel gears, pitch radius 25 mm at the mesh point, cone angles 45 deg,
    # m = 2 mm, b = 8 mm, 20 deg.  Tredgold's virtual spur gears: z_v = 25 / cos 45 = 35.36,
    # d_v = 50 mm / cos 45.  Lewis Y(35.36) interpolated in Shigley's Table 14-2 between
    # 34 (0.371) and 38 (0.384); Hertz from the radii of curvature r = d_v sin(phi) / 2.
    from gearcli import analyse, load_mechanism, named_columns, solve
    from gearcli.io.trajectory import read_trajectory

    js = tmp_path / "r.json"
    assert run_cli("verify", DESIGNS / "ci_example.yaml", "--json", js, "-j", "1").exit_code == 0
    checks = by_name(json.loads(js.read_text()))
    an = analyse(load_mechanism(mech_dir / "bendix_wrist_rated.yaml"))
    tr = read_trajectory(mech_dir / "bendix_wrist_traj.csv", an.independent_names)
    t_peak = np.abs(named_columns(an, solve(an, tr.q, tr.qd, tr.qdd), tr.t)["gear:5-6:t"]).max()
    zv = 25 / math.cos(math.pi / 4)
    Y = 0.371 + (zv - 34) / (38 - 34) * (0.384 - 0.371)
    sigma_F = t_peak / (0.008 * 0.002 * Y)
    assert checks[("wrist_motion", "gear 5-6", "bending safety")]["value"] == pytest.approx(2e8 / sigma_F, rel=1e-9)
    phi = math.radians(20)
    r_v = 0.05 / math.cos(math.pi / 4) * math.sin(phi) / 2
    ZE = math.sqrt(1 / (math.pi * 2 * (1 - 0.3**2) / 206e9))      # steel on steel, Z_E by definition
    sigma_H = ZE * math.sqrt(t_peak / (0.008 * math.cos(phi)) * (2 / r_v))
    assert checks[("wrist_motion", "gear 5-6", "contact safety")]["value"] == pytest.approx(9e8 / sigma_H, rel=2e-3)


def test_degrees_case_gives_the_radian_results(run_cli, tmp_path):
    case = write_rotor_case(tmp_path, "[{name: x, position: 0, C: 3000, C0: 3000, type: ball}]")
    data = np.loadtxt(tmp_path / "rotor.csv", delimiter=",", skiprows=1)
    data[:, 1:] = np.degrees(data[:, 1:])
    np.savetxt(tmp_path / "rotor_deg.csv", data, delimiter=",", header="t,q:J,qd:J,qdd:J", comments="")
    _, rad = run_json(run_cli, tmp_path, "cases:\n" + case)
    deg_case = case.replace("[rotor.csv]", "[rotor_deg.csv]").replace("cycles_per_hour", "degrees: true, cycles_per_hour")
    _, deg = run_json(run_cli, tmp_path, "cases:\n" + deg_case)
    for a, b in zip(rad["checks"], deg["checks"]):
        assert (a["component"], a["quantity"]) == (b["component"], b["quantity"])
        assert b["value"] == pytest.approx(a["value"], rel=1e-9)
    assert by_name(rad)[("rotor", "motor m", "speed")]["value"] == pytest.approx(W, rel=1e-12)


def test_unwritable_reports_are_refused_before_running(run_cli, tmp_path):
    (tmp_path / "file").write_text("x")
    r = run_cli("verify", DESIGNS / "ci_example.yaml", "--plots", tmp_path / "file")
    assert r.exit_code == 2 and "--plots: cannot create the directory" in r.stderr
    r = run_cli("verify", DESIGNS / "ci_example.yaml", "--junit", tmp_path / "no" / "r.xml")
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1
    r = run_cli("verify", DESIGNS / "ci_example.yaml", "--json", DESIGNS / "ci_example.yaml")
    assert r.exit_code == 2 and "Design checks" not in r.stdout


@pytest.mark.parametrize("option", ["--junit", "--json", "--markdown"])
def test_report_name_ending_in_a_slash_is_refused(run_cli, tmp_path, option):
    target = f"{tmp_path}/r.out/"
    r = run_cli("verify", DESIGNS / "ci_example.yaml", option, target)
    assert r.exit_code == 2 and r.stderr.splitlines() == [
        f"{target}: {option}: names a directory (ends with '/'); give a file name"]
    assert list(tmp_path.iterdir()) == []


def test_bad_trajectory_rows_are_listed_with_the_other_problems(run_cli, tmp_path):
    case = write_rotor_case(tmp_path, "[{name: x, position: 0, C: 3000, C0: 3000, type: ball}]")
    lines = (tmp_path / "rotor.csv").read_text().splitlines()
    lines[5] = lines[5].replace(",", ",x", 1)
    (tmp_path / "rotor.csv").write_text("\n".join(lines) + "\n")
    man = tmp_path / "design.yaml"
    man.write_text("cases:\n" + case.replace("min_static_safety: 1.5", "min_static_safety: 1.5, limits: [{column: nope, max_abs: 1}]"))
    r = run_cli("verify", man)
    assert r.exit_code == 2
    err = r.stderr.strip().splitlines()
    assert any(x.startswith(f"{tmp_path / 'rotor.csv'}:6:") for x in err), err
    assert any("unknown output column 'nope'" in x for x in err), err


def test_pool_workers_share_the_cores(monkeypatch):
    """-j N worker processes each get cores // N solver threads (no oversubscription), and
    the partials do not depend on the solver's thread count."""
    from gearcli.batch import runner

    submitted = []

    class FakePool:
        def __init__(self, max_workers):
            self.workers = max_workers

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def submit(self, fn, job, threads):
            from concurrent.futures import Future

            submitted.append((self.workers, threads))
            fut = Future()
            fut.set_result(fn(job, threads))
            return fut

    monkeypatch.setattr(runner, "ProcessPoolExecutor", FakePool)
    monkeypatch.setattr(runner.os, "cpu_count", lambda: 8)
    from gearcli.batch.manifest import load_manifest

    manifest = load_manifest(DESIGNS / "ci_example.yaml")
    import dataclasses

    job = runner.jobs_of(manifest)[0]
    todo = [dataclasses.replace(job, trajectory=i) for i in range(3)]
    pooled = runner._run_local(todo, 4, None)
    assert submitted == [(3, 2)] * 3          # 3 jobs -> 3 workers, 8 // 3 = 2 threads each
    serial = runner._run_local(todo, 1, None)
    assert pooled.keys() == serial.keys()
    for k in serial:
        assert repr(pooled[k]) == repr(serial[k])


@pytest.mark.parametrize("key, needs", [("min_bending_safety", "gears[].rating"),
                                        ("min_contact_safety", "gears[].rating")])
def test_a_requirement_that_checks_nothing_is_refused(run_cli, tmp_path, key, needs):
    """The rotor has bearings but no gears: a gear requirement would silently check nothing."""
    case = write_rotor_case(tmp_path, "[{name: x, position: 0, C: 3000, C0: 3000, type: ball}]")
    good, _ = run_json(run_cli, tmp_path, "cases:\n" + case)
    assert good.exit_code == 0, good.stderr
    (tmp_path / "out.json").unlink()
    r, doc = run_json(run_cli, tmp_path, "cases:\n" + case.replace("min_static_safety: 1.5", f"{key}: 2"))
    assert r.exit_code == 2 and doc is None
    assert f"design.yaml:2: cases[0].{key}: checks nothing: 'rotor.yaml' has no {needs}" in r.stderr
    assert "Traceback" not in r.stderr


def test_rms_on_a_non_uniform_grid_is_the_time_integral_in_verify_and_the_solve_summary(run_cli, tmp_path):
    # The rotor driven with qdd = A sin(2 pi t / P) over two whole periods, sampled on a
    # grid much denser where |sin| is small: the motor torque is tau = J qdd with
    # J = Izz + m r^2 (no other moment about the vertical axis), so its RMS over time is
    # J A / sqrt(2) exactly; a plain mean over the samples gives 10 % less here.
    A, P, Tt = 3.0, 1.0, 2.0
    u = np.linspace(0.0, 1.0, 1201)
    t = Tt * (u - 0.9 * np.sin(4 * np.pi * u) / (4 * np.pi))          # strictly increasing, uneven steps
    qdd = A * np.sin(2 * np.pi * t / P)
    qd = A * P / (2 * np.pi) * (1 - np.cos(2 * np.pi * t / P))
    q = A * P / (2 * np.pi) * (t - P / (2 * np.pi) * np.sin(2 * np.pi * t / P))
    (tmp_path / "rotor.yaml").write_text(rotor_yaml("[{name: x, position: 0, C: 3000, C0: 3000, type: ball}]"))
    np.savetxt(tmp_path / "rotor.csv", np.column_stack([t, q, qd, qdd]), delimiter=",",
               header="t,q:J,qd:J,qdd:J", comments="")
    J = 0.02 + M * R**2
    tau = J * qdd
    hand = 0.0                                                        # trapezoid by hand, sample by sample
    for k in range(len(t) - 1):
        hand += (tau[k] ** 2 + tau[k + 1] ** 2) / 2 * (t[k + 1] - t[k])
    hand = math.sqrt(hand / (t[-1] - t[0]))
    assert hand == pytest.approx(J * A / math.sqrt(2), rel=1e-4)       # the exact time RMS
    assert np.sqrt(np.mean(tau**2)) < 0.95 * hand                      # the plain mean is far off
    r, doc = run_json(run_cli, tmp_path, "cases:\n  - {name: rotor, mechanism: rotor.yaml, trajectories: [rotor.csv]}\n")
    assert r.exit_code in (0, 1), r.stderr
    verify_rms = by_name(doc)[("rotor", "motor m", "RMS torque")]["value"]
    assert verify_rms == pytest.approx(hand, rel=1e-9)
    # the solve summary (chunks of 100 samples: the trapezoid runs across chunk boundaries)
    r = run_cli("solve", tmp_path / "rotor.yaml", tmp_path / "rotor.csv", "-o", tmp_path / "out.csv", "--chunk", "100")
    assert r.exit_code == 0, r.stderr
    rows = [[c.strip() for c in line.split("│")] for line in (r.stdout + r.stderr).splitlines()]
    (row,) = [c for c in rows if len(c) > 4 and c[1] == "motor m"]
    assert float(row[4]) == pytest.approx(verify_rms, rel=1e-5)        # the RMS column, printed to 6 digits


def test_a_iso_multiplies_the_life_and_names_the_modified_life(run_cli, tmp_path):
    base = "{name: x, position: 0, C: 3000, C0: 3000, type: tapered_roller"
    r, doc = run_json(run_cli, tmp_path, "cases:\n" + write_rotor_case(tmp_path, f"[{base}}}]"))
    l10 = by_name(doc)[("rotor", "bearing J/x", "L10 life")]["value"]
    r, doc = run_json(run_cli, tmp_path, "cases:\n" + write_rotor_case(tmp_path, f"[{base}, a_ISO: 2.5}}]"))
    assert by_name(doc)[("rotor", "bearing J/x", "Lnm life (a_ISO)")]["value"] == pytest.approx(2.5 * l10, rel=1e-12)


@pytest.mark.parametrize("extra, message", [
    ("kappa: 1, e_C: 0.5", "bearings[0].kappa: a_ISO from kappa, e_C, Cu needs all three: Cu missing"),
    ("a_ISO: 2, kappa: 1, e_C: 0.5, Cu: 100", "bearings[0].a_ISO: give a_ISO or kappa, e_C, Cu to compute it, not both"),
    ("kappa: 0.05, e_C: 0.5, Cu: 100", "bearings[0].kappa: kappa 0.05 is below 0.1, outside ISO 281's a_ISO method"),
])
def test_bad_life_factor_keys_are_one_line_each(run_cli, tmp_path, extra, message):
    (tmp_path / "rotor.yaml").write_text(rotor_yaml(f"[{{name: x, position: 0, C: 3000, C0: 3000, type: ball, {extra}}}]"))
    r = run_cli("check", tmp_path / "rotor.yaml")
    assert r.exit_code == 2 and len(r.stderr.strip().splitlines()) == 1 and message in r.stderr, r.stderr


def test_running_rms_over_the_thermal_window_is_checked(run_cli, tmp_path):
    # The rotor accelerated at qdd = 5 rad/s^2 for the first 0.2 s, then coasting: tau = J qdd.
    # Over the 2 s cycle the RMS is J 5 sqrt(0.2/2) (trapezoid: the ramp at 0.2 s adds a half
    # step); over a 0.5 s window the worst running RMS is J 5 sqrt(0.2/0.5), 2.2x more.
    t = np.linspace(0, 2.0, 2001)
    qdd = np.where(t <= 0.2 + 1e-12, 5.0, 0.0)
    qd = np.cumsum(np.r_[0.0, np.diff(t)] * qdd)
    q = np.cumsum(np.r_[0.0, np.diff(t)] * qd)
    text = rotor_yaml("[{name: x, position: 0, C: 3000, C0: 3000, type: ball}]").replace(
        "max_speed: 20}", "max_speed: 20, thermal_window: 0.5}")
    (tmp_path / "rotor.yaml").write_text(text)
    np.savetxt(tmp_path / "rotor.csv", np.column_stack([t, q, qd, qdd]), delimiter=",", header="t,q:J,qd:J,qdd:J",
               comments="")
    r, doc = run_json(run_cli, tmp_path, "cases:\n  - {name: rotor, mechanism: rotor.yaml, trajectories: [rotor.csv]}\n")
    checks = by_name(doc)
    J = 0.02 + M * R**2
    run = checks[("rotor", "motor m", "running RMS torque (0.5 s)")]
    assert run["value"] == pytest.approx(J * 5 * math.sqrt((0.2 + 0.0005) / 0.5), rel=1e-6)
    assert checks[("rotor", "motor m", "RMS torque")]["value"] == pytest.approx(J * 5 * math.sqrt(0.2005 / 2), rel=1e-6)
    assert run["limit"] == 0.5


def test_mission_profile_shares_weight_every_life(run_cli, tmp_path):
    # Two motions (the same rotor file twice): a fraction 0.5 of the time, i.e. 0.5 * 3600 / 2 s
    # = 900 repetitions an hour, and 1000 h of a 4000 h service life, i.e. 450 an hour.  The
    # bearing turns W T / 2 pi per repetition under a constant load: its life is the
    # closed form at 1350 repetitions an hour, i.e. 1800/1350 of continuous rotation's.
    write_rotor_case(tmp_path, "[{name: x, position: 0, C: 3000, C0: 3000, type: tapered_roller}]")
    (tmp_path / "rotor2.csv").write_bytes((tmp_path / "rotor.csv").read_bytes())
    case = ("cases:\n  - {name: rotor, mechanism: rotor.yaml, service_life_h: 4000, bearing_life_h: 1000,\n"
            "     trajectories: [{file: rotor.csv, fraction: 0.5}, {file: rotor2.csv, hours: 1000}]}\n")
    r, doc = run_json(run_cli, tmp_path, case)
    assert r.exit_code in (0, 1), r.stderr
    Fr, Fa = M * W**2 * R, M * G
    P = 0.4 * Fr + 1.49 * Fa                           # tapered roller defaults, Fa/Fr > e
    closed = (3000 / P) ** (10 / 3) * 1e6 / (3600 * W / (2 * math.pi))
    assert by_name(doc)[("rotor", "bearing J/x", "L10 life")]["value"] == pytest.approx(closed * 1800 / 1350, rel=1e-6)
    r, doc = run_json(run_cli, tmp_path, case.replace("hours: 1000}", "cycles_per_hour: 450}"))
    assert by_name(doc)[("rotor", "bearing J/x", "L10 life")]["value"] == pytest.approx(closed * 1800 / 1350, rel=1e-6)


def test_mission_profile_hours_need_the_service_life(run_cli, tmp_path):
    write_rotor_case(tmp_path, "[{name: x, position: 0, C: 3000, C0: 3000, type: ball}]")
    man = tmp_path / "design.yaml"
    man.write_text("cases:\n  - {mechanism: rotor.yaml, bearing_life_h: 10, trajectories: [{file: rotor.csv, hours: 5}]}\n")
    r = run_cli("verify", man, "-j", "1")
    assert r.exit_code == 2 and "cases[0].trajectories[0].hours: hours of the profile need the case's service_life_h" \
        in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr


@pytest.mark.parametrize("share,message", [
    ("hours: 0", "hours: must be positive, got 0"),
    ("cycles_per_hour: -3", "cycles_per_hour: must be positive, got -3"),
    ("hours: 1.0e-13", "hours: 1e-13 is out of range (1e-12 <= x <= 1e12 in SI units)"),
    ("fraction: 1.5", "fraction: expected at most 1, got 1.5"),
])
def test_mission_profile_share_out_of_range_worded_as_the_case_numbers(run_cli, tmp_path, share, message):
    """A share's number is worded as the case's own numbers (``cases[0].cycles_per_hour: must be
    positive, got 0``), not in the schema's words of a bound; a fraction keeps its own range."""
    write_rotor_case(tmp_path, "[{name: x, position: 0, C: 3000, C0: 3000, type: ball}]")
    man = tmp_path / "design.yaml"
    man.write_text("cases:\n  - {mechanism: rotor.yaml, service_life_h: 100, bearing_life_h: 10,\n"
                   f"     trajectories: [{{file: rotor.csv, {share}}}]}}\n")
    r = run_cli("verify", man, "-j", "1")
    lines = r.stderr.strip().splitlines()
    assert r.exit_code == 2 and r.stdout == "" and lines == [f"{man}:3: cases[0].trajectories[0].{message}"], r.stderr


def test_load_spectra_sum_to_the_duty_and_its_revolutions(run_cli, tmp_path):
    # The rotor at constant rate W for 2 s, 1800 times an hour: every spectrum holds 3600 s
    # per hour, and the bearing's turns W T / 2 pi x 1800 per hour, all in the one bin of its
    # constant equivalent load.
    case = write_rotor_case(tmp_path, "[{name: x, position: 0, C: 3000, C0: 3000, type: tapered_roller}]")
    man = tmp_path / "design.yaml"
    man.write_text("cases:\n" + case)
    r = run_cli("verify", man, "-j", "1", "--spectra", tmp_path / "sp")
    assert r.exit_code in (0, 1) and "load spectra of 1 case in" in r.stdout, r.stdout + r.stderr
    doc = json.loads((tmp_path / "sp" / "rotor__spectra.json").read_text())
    by = {(s["component"], s["quantity"]): s for s in doc["spectra"]}
    bearing = by[("bearing J/x", "equivalent load P")]
    assert sum(bearing["seconds_per_hour"]) == pytest.approx(3600.0)
    assert sum(bearing["revolutions_per_hour"]) == pytest.approx(W * T / (2 * math.pi) * 1800, rel=1e-9)
    assert bearing["seconds_per_hour"][-1] == pytest.approx(3600.0)          # constant load: the top bin
    assert sum(by[("motor m", "torque")]["fraction_of_time"]) == pytest.approx(1.0)
    rows = (tmp_path / "sp" / "rotor__spectra.csv").read_text().splitlines()
    assert rows[0] == "component,quantity,unit,load_from,load_to,seconds_per_hour,fraction_of_time,revolutions_per_hour"
    assert len(rows) == 1 + 2 * 20


def test_mission_profile_shares_cannot_exceed_the_service_time(run_cli, tmp_path):
    write_rotor_case(tmp_path, "[{name: x, position: 0, C: 3000, C0: 3000, type: ball}]")
    man = tmp_path / "design.yaml"
    man.write_text("cases:\n  - {mechanism: rotor.yaml, bearing_life_h: 10, service_life_h: 100, trajectories:"
                   " [{file: rotor.csv, hours: 60}, {file: rotor.csv, fraction: 0.5}]}\n")
    r = run_cli("verify", man, "-j", "1")
    assert r.exit_code == 2 and "cases[0].trajectories: the profile's shares add up to 1.1 of the service time" \
        in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr


def test_reports_state_the_backend_each_case_ran_on(run_cli, tmp_path, monkeypatch):
    """JSON (every check), JUnit (a ``backend`` property per suite), Markdown and the
    printed summary name the solver path of each case: a 401-sample rotor with an empty
    disk cache is solved by numpy (the first-call rule, said so), a 6,001-sample one by llvm."""
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path / "cache"))
    bearings = "[{name: a, position: 0, C: 5000, C0: 2000, type: ball, locating: true}]"
    short = write_rotor_case(tmp_path, bearings, name="short")
    long_ = short.replace("short", "long")
    (tmp_path / "long.yaml").write_text(rotor_yaml(bearings))
    t = np.linspace(0, T, 6001)
    np.savetxt(tmp_path / "long.csv", np.column_stack([t, W * t, np.full_like(t, W), 0 * t]),
               delimiter=",", header="t,q:J,qd:J,qdd:J", comments="")
    man = tmp_path / "m.yaml"
    man.write_text("cases:\n" + short + long_)
    xml, js, md = tmp_path / "r.xml", tmp_path / "r.json", tmp_path / "r.md"
    r = run_cli("verify", man, "--junit", xml, "--json", js, "--markdown", md, "-j", "1")
    assert r.exit_code in (0, 1), r.stdout + r.stderr
    first = ("numpy (auto: first-call rule: fewer than 5,000 samples, and the kernel is neither compiled "
             "nor in the disk cache)")
    expect = {"short": first, "long": "llvm"}
    assert {c["case"]: c["backend"] for c in json.loads(js.read_text())["checks"]} == expect
    suites = ET.parse(xml).getroot().findall("testsuite")
    assert {s.get("name"): s.find("properties/property[@name='backend']").get("value") for s in suites} == expect
    text = md.read_text()
    assert f"Solver backend of short: {first}\n" in text and "Solver backend of long: llvm\n" in text
    assert f"Backend of short: {first}" in r.stdout.splitlines() and "Backend of long: llvm" in r.stdout.splitlines()


def test_life_plot_labels_the_equivalent_load_the_life_uses(run_cli, tmp_path, monkeypatch):
    """The plot's "P_eq of the profile" is the mission-weighted P_eq the reported life is
    computed from, not the plain mean of the trajectories' (issue 34, section 3)."""
    import gearcli.report.check_plots as check_plots
    seen = []
    real = check_plots.plot_life
    monkeypatch.setattr(check_plots, "plot_life", lambda traces, P_eq, *a: (seen.append((traces, P_eq)), real(traces, P_eq, *a)))
    write_rotor_case(tmp_path, "[{name: x, position: 0, C: 3000, C0: 3000, type: ball}]")
    t = np.linspace(0, T, 401)                        # rotor2: the same rotor at 3 W (9x the radial load)
    np.savetxt(tmp_path / "rotor2.csv", np.column_stack([t, 3 * W * t, np.full_like(t, 3 * W), 0 * t]),
               delimiter=",", header="t,q:J,qd:J,qdd:J", comments="")
    rates = (1500.0, 100.0)
    case = ("cases:\n  - {name: rotor, mechanism: rotor.yaml, bearing_life_h: 1.0e12,\n"
            f"     trajectories: [{{file: rotor.csv, cycles_per_hour: {rates[0]}}}, "
            f"{{file: rotor2.csv, cycles_per_hour: {rates[1]}}}]}}\n")
    r, doc = run_json(run_cli, tmp_path, case, "--plots", tmp_path / "plots")
    assert r.exit_code == 1, r.stderr
    (traces, P_eq), = seen
    P = [tr[3] for tr in traces]
    assert P[1] > 1.5 * P[0]
    revs = [rate * w * T / (2 * math.pi) for rate, w in zip(rates, (W, 3 * W))]     # revolutions an hour
    by_hand = (sum(n * p**3 for n, p in zip(revs, P)) / sum(revs)) ** (1 / 3)
    assert P_eq == pytest.approx(by_hand, rel=1e-9)
    life = by_name(doc)[("rotor", "bearing J/x", "L10 life")]["value"]
    assert life == pytest.approx((3000 / P_eq) ** 3 * 1e6 / sum(revs), rel=1e-9)


def test_an_infinite_life_is_reported_with_its_reason(run_cli, tmp_path):
    """The rated arm held at rest (its joints vertical: gravity loads no tooth and turns no
    bearing): no fatigue damage and no revolutions.  The lives print their reason, not
    "inf" or 1e+66 h, and the JSON has null with the reason (issue 34, section 3)."""
    t = np.linspace(0, 1, 11)
    np.savetxt(tmp_path / "rest.csv", np.column_stack([t, 0 * t, 0.3 + 0 * t]), delimiter=",",
               header="t,q:J1,q:J2", comments="")
    case = (f"cases:\n  - {{name: rest, mechanism: {ROOT / 'mechanisms' / 'paper_2dof_rated.yaml'}, "
            "trajectories: [rest.csv], cycles_per_hour: 100, bearing_life_h: 20000, gear_life_h: 20000}\n")
    r, doc = run_json(run_cli, tmp_path, case, "--markdown", tmp_path / "r.md")
    assert r.exit_code == 0, r.stderr
    fatigue = [c for c in doc["checks"] if c["quantity"].endswith("fatigue life")]
    lives = [c for c in doc["checks"] if c["quantity"] == "L10 life"]
    assert len(fatigue) == 6 and lives
    for c in fatigue:
        assert c["value"] is None and c["value_note"] == "no damage (below the endurance limit)"
    for c in lives:
        assert c["value"] is None and c["value_note"] == "no revolutions (the bearing does not turn)"
    assert all("value_note" not in c for c in doc["checks"] if c["value"] is not None)
    md = (tmp_path / "r.md").read_text()
    assert md.count("| no damage (below the endurance limit) |") == 6
    values = [ln.split(" | ")[4] for ln in md.splitlines() if ln.startswith("| ✅")]
    assert len(values) == len(doc["checks"]) and "inf" not in values
    assert "no damage" in r.stdout      # (the table wraps its cells to the terminal)


@pytest.mark.parametrize("option", ["--plots", "--spectra"])
def test_an_empty_directory_name_is_refused_as_the_file_names_are(run_cli, tmp_path, monkeypatch, option):
    """--plots '' wrote into the current folder, where --junit '' is refused (issue 34, section 5)."""
    monkeypatch.chdir(tmp_path)
    r = run_cli("verify", DESIGNS / "ci_example.yaml", option, "")
    assert r.exit_code == 2 and r.stderr.strip() == f"{option}: empty directory name (give a directory for the files)"
    assert list(tmp_path.iterdir()) == []


def test_first_call_rule_counts_the_whole_command(run_cli, tmp_path, monkeypatch):
    """Three trajectories of 2,001 samples of one mechanism, an empty kernel cache: 6,003
    samples are one compile's worth, so verify solves them with llvm (each was a small first
    call sent to numpy: 73 s for a new lossy SCARA; issue 34, section 4).  One trajectory
    alone (run first: nothing compiled yet) stays with numpy, and says why."""
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path / "cache"))
    bearings = "[{name: a, position: 0, C: 5000, C0: 2000, type: ball, locating: true}]"
    write_rotor_case(tmp_path, bearings, name="rotor")
    t = np.linspace(0, T, 2001)
    for k in range(3):
        np.savetxt(tmp_path / f"r{k}.csv", np.column_stack([t, W * t, np.full_like(t, W), 0 * t]),
                   delimiter=",", header="t,q:J,qd:J,qdd:J", comments="")
    backends = []
    for trajs in ("[r0.csv]", "[r0.csv, r1.csv, r2.csv]"):
        (tmp_path / "m.yaml").write_text(f"cases:\n  - {{name: c, mechanism: rotor.yaml, trajectories: {trajs}, "
                                         "cycles_per_hour: 100, bearing_life_h: 1000}\n")
        r = run_cli("verify", tmp_path / "m.yaml", "--json", tmp_path / "r.json", "-j", "1")
        assert r.exit_code in (0, 1), r.stderr
        backends.append({c["backend"] for c in json.loads((tmp_path / "r.json").read_text())["checks"]})
    assert backends == [{"numpy (auto: first-call rule: fewer than 5,000 samples, and the kernel is neither "
                         "compiled nor in the disk cache)"}, {"llvm"}]


@pytest.mark.parametrize("d_p", [0.1, 2.0])
def test_crossed_roller_life_and_static_safety_by_hand(run_cli, tmp_path, d_p):
    """One crossed-roller bearing carries the rotor's radial force m w^2 r, its weight m g
    axially and its tilting moment m r (h w^2 + g) (module notes).  P_c = x (F_r + 2 M/d_p)
    + y F_a: d_p = 0.1 m gives F_a/F = 0.55 (x = 1, y = 0.45), d_p = 2 m gives 1.74 (x = y =
    0.67); L10h = (C/P_c)^(10/3) 1e6 / revolutions an hour; static P0 = F + 0.44 F_a (issue 35:
    read as a plain radial load, the life came out 1,150x too long)."""
    bearing = (f"[{{name: xrb, position: 0, C: 5000, C0: 8000, type: crossed_roller, pitch_diameter: {d_p}}}]")
    r, doc = run_json(run_cli, tmp_path, "cases:\n" + write_rotor_case(tmp_path, bearing))
    assert r.exit_code in (0, 1), r.stderr
    Fr, Fa, Mt = M * W ** 2 * R, M * G, M * R * (H * W ** 2 + G)
    F = Fr + 2 * Mt / d_p
    x, y = (1.0, 0.45) if Fa / F <= 1.5 else (0.67, 0.67)
    assert (Fa / F <= 1.5) == (d_p == 0.1)
    P = x * F + y * Fa
    life = by_name(doc)[("rotor", "bearing J/xrb", "L10 life")]["value"]
    assert life == pytest.approx((5000 / P) ** (10 / 3) * 1e6 / (3600 * W / (2 * math.pi)), rel=1e-9)
    s0 = by_name(doc)[("rotor", "bearing J/xrb", "static safety s0")]["value"]
    assert s0 == pytest.approx(8000 / (F + 0.44 * Fa), rel=1e-9)
    if d_p == 0.1:      # the moment left out (a plain radial bearing): a life 17x too long
        assert (P / (x * Fr + y * Fa)) ** (10 / 3) > 15


@pytest.mark.parametrize("bearings, message", [
    ("[{name: a, position: 0, C: 5000, C0: 8000, type: crossed_roller}]", "needs its pitch_diameter"),
    ("[{name: a, position: 0, C: 5000, C0: 8000, type: ball, pitch_diameter: 0.1}]", "pitch_diameter is for a crossed_roller"),
    ("[{name: a, position: 0, C: 5000, C0: 8000, type: crossed_roller, pitch_diameter: 0.1}, "
     "{name: b, position: 0.1, C: 5000, C0: 8000, type: ball}]", "a crossed-roller bearing is a joint's only bearing"),
])
def test_crossed_roller_input_problems_are_located(run_cli, tmp_path, bearings, message):
    (tmp_path / "rotor.yaml").write_text(rotor_yaml(bearings))
    r = run_cli("check", tmp_path / "rotor.yaml")
    assert r.exit_code == 2 and message in r.stderr and "rotor.yaml:" in r.stderr


def test_crossed_roller_survives_the_urdf_round_trip(run_cli, tmp_path):
    bearing = "[{name: xrb, position: 0, C: 5000, C0: 8000, type: crossed_roller, pitch_diameter: 0.1}]"
    (tmp_path / "rotor.yaml").write_text(rotor_yaml(bearing))
    assert run_cli("export", tmp_path / "rotor.yaml", "-o", tmp_path / "rotor.urdf").exit_code == 0
    from gearcli import load_mechanism
    b = load_mechanism(tmp_path / "rotor.urdf").joints[0].bearings[0]
    assert (b.type, b.pitch_diameter, b.C, b.C0) == ("crossed_roller", 0.1, 5000.0, 8000.0)


def _json_differences(a, b, path=""):
    """(path, a, b) of every leaf of two JSON reports that differ: floats beyond 1e-12 of
    the larger, anything else at all."""
    if isinstance(a, dict) and isinstance(b, dict) and a.keys() == b.keys():
        return [d for k in a for d in _json_differences(a[k], b[k], f"{path}/{k}")]
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in _json_differences(x, y, f"{path}[{i}]")]
    if isinstance(a, float) and isinstance(b, float):
        return [] if a == b or abs(a - b) <= 1e-12 * max(abs(a), abs(b)) else [(path, a, b)]
    return [] if a == b else [(path, a, b)]


@pytest.mark.parametrize("design", [
    DESIGNS / "paper_arm_duty.yaml",          # motors (peak, RMS, running RMS), bearings, gears (safety, fatigue)
    DESIGNS / "cobot_joint_reducer.yaml",     # a strain-wave reducer's averages and life, a crossed roller
    DESIGNS / "scara_belt_bearings.yaml",     # bearings whose friction enters the solve
])
def test_a_long_trajectory_is_solved_in_parts_with_the_same_verdicts(run_cli, tmp_path, monkeypatch, design):
    """verify solves a long trajectory STREAM samples at a time.  The checks that reduce to
    extremes and sums are evaluated part by part (each part with the last sample of the one
    before) and merged; only the columns of the others (a gear's fatigue, a running RMS) are
    kept whole (1e6 samples of the rated arm: 1.48 GB, then 0.63 GB, now under twice
    solve's peak; issue 34, section 5).  The report equals one whole solve's: every verdict,
    time and count the same, every number to 1e-12 (the sums are added in another order),
    with parts of 512 and of 1000 samples (a multiple of the kernel's warm-start run, and
    not)."""
    import json

    import gearcli.batch.runner as runner
    import gearcli.dynamics.backends as backends
    monkeypatch.setattr(backends, "FIRST_CALL_SAMPLES", 0)      # every run on the kernel, whatever came before
    reports = []
    for stream in (1 << 40, 512, 1000):
        monkeypatch.setattr(runner, "STREAM", stream)
        out = tmp_path / f"r{stream}.json"
        r = run_cli("verify", design, "--json", out, "-j", "1")
        assert r.exit_code in (0, 1), r.stderr
        reports.append(json.loads(out.read_text()))
    assert len(reports[0]["checks"]) >= 4
    for other in reports[1:]:
        assert _json_differences(reports[0], other) == []


def test_the_merged_partials_of_parts_are_the_whole_trajectorys():
    """merge_partials on a signal cut in three parts, each starting on the sample the one
    before ended on: peak (and its time, the earliest on a tie), RMS sums and score, a
    bearing's life sums and equivalent load, a worm's least efficiency equal the whole's;
    a part left out (a deliberate gap) changes the RMS."""
    import numpy as np

    from gearcli.design.checks import Check
    from gearcli.design.evaluate import Samples, merge_partials, partials

    rng = np.random.default_rng(3)
    n = 301
    t = np.sort(rng.uniform(0.0, 3.0, n))
    x = rng.normal(size=n)
    x[200] = x[100] = np.abs(x).max() + 1.0                 # a tie: the earlier one wins
    checks = [Check("c", "peak", "", 1.0, "peak", ("abs", "x"), ""), Check("c", "rms", "", 1.0, "rms", ("col", "x"), "")]
    whole = partials(checks, Samples(t, {"x": x}, np.zeros((n, 1))), None)
    cuts = [(0, 101), (100, 201), (200, n)]
    parts = [partials(checks, Samples(t[a:b], {"x": x[a:b]}, np.zeros((b - a, 1))), None) for a, b in cuts]
    for k, ch in enumerate(checks):
        merged = merge_partials(ch, [p[k] for p in parts])
        assert merged[:2] == whole[k][:2] and merged[1] == t[100]
        assert np.allclose(merged[2:7], whole[k][2:7], rtol=1e-13, atol=0.0)
    gap = [partials(checks, Samples(t[a:b], {"x": x[a:b]}, np.zeros((b - a, 1))), None) for a, b in ((0, 100), (100, n))]
    assert merge_partials(checks[1], [p[1] for p in gap])[2] != pytest.approx(whole[1][2], rel=1e-6)
