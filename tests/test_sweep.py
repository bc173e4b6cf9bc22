"""gearcli sweep (issue 37): a design manifest verified over a grid of mechanism values.

Each variant's checks are those plain ``gearcli verify`` reports on the mechanism file edited
by hand (text replacement, not the sweep's YAML editing); the table is the same bytes with
local processes or on a Dask cluster; bad paths and values are located errors before
anything runs, nothing written."""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

ROOT = Path(__file__).resolve().parents[1]
DESIGN = ROOT / "designs" / "paper_arm_duty.yaml"
MECH = ROOT / "mechanisms" / "paper_2dof_rated.yaml"
TRAJ = ROOT / "mechanisms" / "paper_2dof_traj.csv"
FOREARM = '  - name: "2"                     # forearm; frame at the wrist\n    mass: 2.5\n'


def _read_csv(path: Path) -> tuple[list[str], list[list[str]]]:
    lines = path.read_text().splitlines()
    import csv
    rows = list(csv.reader(lines))
    return rows[0], rows[1:]


def _design(tmp_path: Path, mech_text: str, name: str = "d.yaml") -> Path:
    (tmp_path / "m.yaml").write_text(mech_text)
    d = tmp_path / name
    d.write_text(DESIGN.read_text().replace("../mechanisms/paper_2dof_rated.yaml", str(tmp_path / "m.yaml"))
                 .replace("../mechanisms/paper_2dof_traj.csv", str(TRAJ)))
    return d


def test_each_variant_is_what_verify_says_of_the_edited_file(run_cli, tmp_path):
    """Three forearm masses: every check's value, limit and margin in the sweep's table equal
    those of gearcli verify --json on the mechanism file with the mass edited by hand (the
    table's 9 digits), the worst margin is the least margin of the row and 'passed' is verify's
    exit status."""
    text = MECH.read_text()
    assert FOREARM in text
    design = _design(tmp_path, text)
    out = tmp_path / "sweep.csv"
    r = run_cli("sweep", design, "--vary", "links.2.mass=2.5,3.4,4", "-o", out)
    assert r.exit_code == 0, r.stderr
    header, rows = _read_csv(out)
    assert header[0] == "links.2.mass" and [float(row[0]) for row in rows] == [2.5, 3.4, 4.0]
    for row, mass in zip(rows, ("2.5", "3.4", "4")):
        edited = tmp_path / f"e{mass}"
        edited.mkdir()
        d = _design(edited, text.replace(FOREARM, FOREARM.replace("mass: 2.5", f"mass: {mass}")))
        js = edited / "r.json"
        v = run_cli("verify", d, "--json", js, "-j", "1")
        checks = json.loads(js.read_text())["checks"]
        assert len(header) == 1 + 3 * len(checks) + 3
        cells = dict(zip(header, row))
        for c in checks:
            name = f"{c['case']}: {c['component']}: {c['quantity']}"
            unit = f" [{c['unit']}]" if c["unit"] else ""
            for key, field in (("value", f"value{unit}"), ("limit", f"limit{unit}"), ("margin_pct", "margin %")):
                want = c[key] if c[key] is not None else math.inf
                assert float(cells[f"{name}: {field}"]) == pytest.approx(want, rel=1e-8), (name, key)
        margins = [c["margin_pct"] for c in checks]
        assert float(cells["worst_margin_%"]) == pytest.approx(min(margins), rel=1e-8)
        assert cells["passed"] == ("true" if v.exit_code == 0 else "false")
    assert [r[-1] for r in rows] == ["true", "false", "false"]   # 3.4 kg fails, as verify says


def test_the_grid_its_order_and_ranges(run_cli, tmp_path):
    """a:b:n and log:a:b:n give their n values, the grid runs the last --vary fastest, and a
    value-by-value edit of one case's mechanism (CASE:PATH) leaves the file's other numbers."""
    from gearcli.batch.sweep import values_of
    assert values_of("1:2:3", "x") == (1.0, 1.5, 2.0)
    assert np.allclose(values_of("log:1:100:3", "x"), (1.0, 10.0, 100.0), rtol=1e-15)
    assert values_of("-0.2, 0.5", "x") == (-0.2, 0.5)
    out = tmp_path / "s.parquet"
    r = run_cli("sweep", DESIGN, "--vary", "pick_and_place:links.2.mass=2:3:2", "--vary", "links.2.com[0]=-0.2,-0.15",
                "-o", out)
    assert r.exit_code == 0, r.stderr
    t = pq.read_table(out).to_pydict()
    assert t["pick_and_place:links.2.mass"] == [2.0, 2.0, 3.0, 3.0]
    assert t["links.2.com[0]"] == [-0.2, -0.15, -0.2, -0.15]
    assert "4 variants" in r.stdout and "Wrote the table" in r.stdout


def test_local_processes_and_dask_give_the_same_bytes(run_cli, tmp_path):
    from dask.distributed import LocalCluster
    args = ["sweep", DESIGN, "--vary", "links.2.mass=2:4:6"]
    one, two, dsk = (tmp_path / f"{n}.csv" for n in ("one", "two", "dask"))
    assert run_cli(*args, "-o", one).exit_code == 0
    assert run_cli(*args, "-o", two, "-j", "2").exit_code == 0
    with LocalCluster(n_workers=2, processes=False, threads_per_worker=1, dashboard_address=None) as cluster:
        r = run_cli(*args, "-o", dsk, "--dask", cluster.scheduler_address)
    assert r.exit_code == 0, r.stderr
    assert one.read_bytes() == two.read_bytes() == dsk.read_bytes()


def test_the_plot_of_one_and_two_values(run_cli, tmp_path):
    for varies in (["--vary", "links.2.mass=2:4:3"], ["--vary", "links.2.mass=2:4:3", "--vary", "links.2.com[0]=-0.2,-0.1"]):
        fig = tmp_path / f"p{len(varies)}.png"
        r = run_cli("sweep", DESIGN, *varies, "--plot", fig)
        assert r.exit_code == 0, r.stderr
        assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("vary, said", [
    ("links.arm.mass=1,2", "no link named 'arm' (the file has 0, 1, 2, 3, 4, 5"),
    ("links.2.inertia=1,2", "is a list in the file, not a number"),
    ("links.2.inertia[7]=1", "has 3 elements, no [7]"),
    ("links.2.colour=1", "no key 'colour' in links.2"),
    ("links.2.mass=-1,2", "the value -1: links[2].mass"),
    ("links.2.mass=a,b", "expected a number, got 'a'"),
    ("links.2.mass=1:2", "expected a:b:n"),
    ("links.2.mass=log:0:1:3", "a log range needs a > 0"),
    ("links.2.mass=1:2:0", "expected 1 <= n"),
    ("links.2.mass", "expected PATH=VALUES"),
    ("elsewhere:links.2.mass=1", "no case named 'elsewhere'"),
    ("gears.5-1.ratio=-3,2", "the value 2: gears[0].ratio: ratio 2 contradicts the mesh geometry"),
    ("gears.5-1.ratio=-3,-2.5", "the value -2.5: gears[0].teeth: tooth counts 30:90 give |ratio| 3, but the mesh "
     "geometry gives 2.5 (gear pair '5-1' gives both ratio and teeth: remove its ratio and vary its teeth)"),
    ("gears.5-1.ratio=-3,0", "gear pair '5-1': a gear ratio must be finite and nonzero, got 0"),
    ("gears.5-1.teeth[0]=30,0", "the value 0: gears[0].teeth[0]: expected at least 1, got 0"),
])
def test_bad_paths_and_values_are_located_before_anything_runs(run_cli, tmp_path, vary, said):
    out = tmp_path / "s.csv"
    r = run_cli("sweep", DESIGN, "--vary", vary, "-o", out)
    assert r.exit_code == 2, r.stdout
    assert r.stderr.count("\n") == 1 and f"--vary '{vary}'" in r.stderr and said in r.stderr, r.stderr
    assert "Traceback" not in r.stderr and not out.exists()


def test_bad_outputs_are_refused(run_cli, tmp_path):
    for args, said in ((["-o", tmp_path / "s.txt"], "-o: expected a .csv"),
                       (["-o", TRAJ], "is the input file"),
                       (["--plot", tmp_path / "p.gif"], "--plot: expected a .png"),
                       (["--vary", "links.1.mass=1,2", "--vary", "links.3.mass=1", "--plot", tmp_path / "p.png"],
                        "one or two varied values")):
        before = TRAJ.read_text()
        r = run_cli("sweep", DESIGN, "--vary", "links.2.mass=2,3", *args)
        assert r.exit_code == 2 and said in r.stderr, r.stderr
        assert TRAJ.read_text() == before
    assert list(tmp_path.iterdir()) == []


def test_an_interrupted_sweep_resumes_to_the_same_table(run_cli, tmp_path, monkeypatch):
    """A sweep stopped after its first chunks keeps them in TABLE.partial; --resume runs only
    the rest and writes the table an uninterrupted sweep writes, byte for byte, then removes
    the partial file.  Without --resume the partial file is not overwritten (exit 2)."""
    from gearcli.batch import sweep
    args = ["sweep", DESIGN, "--vary", "links.2.mass=2:4:9"]
    whole = tmp_path / "whole.csv"
    assert run_cli(*args, "-o", whole).exit_code == 0
    out = tmp_path / "t.csv"
    real, calls = sweep._run_chunk, []

    def stops(*a):
        calls.append(len(a[2]))
        if len(calls) > 3:
            raise KeyboardInterrupt
        return real(*a)
    monkeypatch.setattr(sweep, "_run_chunk", stops)
    r = run_cli(*args, "-o", out)
    assert r.exit_code != 0 and not out.exists()
    partial = tmp_path / "t.csv.partial"
    kept = partial.read_text().splitlines()
    assert len(kept) == 1 + sum(calls[:3])          # the header and each finished variant
    r = run_cli(*args, "-o", out)
    assert r.exit_code == 2 and "--resume" in r.stderr and partial.read_text().splitlines() == kept
    calls.clear()
    monkeypatch.setattr(sweep, "_run_chunk", lambda *a: (calls.append(len(a[2])), real(*a))[1])
    r = run_cli(*args, "-o", out, "--resume")
    assert r.exit_code == 0, r.stderr
    assert sum(calls) == 9 - (len(kept) - 1) and f"({len(kept) - 1} from {partial})" in r.stdout
    assert out.read_bytes() == whole.read_bytes() and not partial.exists()


def test_resume_refuses_another_sweeps_partial_file(run_cli, tmp_path):
    out = tmp_path / "t.csv"
    partial = tmp_path / "t.csv.partial"
    partial.write_text('{"plan": "0123"}\n')
    r = run_cli("sweep", DESIGN, "--vary", "links.2.mass=2,3", "-o", out, "--resume")
    assert r.exit_code == 2 and f"{partial}:1: written by a sweep of other variants" in r.stderr
    r = run_cli("sweep", DESIGN, "--vary", "links.2.mass=2,3", "--resume")
    assert r.exit_code == 2 and "--resume: give -o TABLE" in r.stderr
    partial.unlink()
    r = run_cli("sweep", DESIGN, "--vary", "links.2.mass=2,3", "-o", out, "--resume")
    assert r.exit_code == 2 and "no interrupted sweep" in r.stderr and not out.exists()


def test_a_variant_that_cannot_run_is_a_row_saying_why(run_cli, tmp_path):
    """Values valid alone but not together (the triangle inequality of an inertia given by
    two varied entries): that variant's row has no check values, its reason, passed false;
    the others run."""
    mech = MECH.read_text()
    design = _design(tmp_path, mech)
    out = tmp_path / "s.csv"
    assert "inertia: [0.003, 0.025, 0.025]" in mech     # alone each value keeps I1 + I2 >= I3; 0.048 with 0.0225 does not
    r = run_cli("sweep", design, "--vary", "links.2.inertia[0]=0.003,0.048", "--vary", "links.2.inertia[1]=0.025,0.0225",
                "-o", out)
    assert r.exit_code == 0, r.stderr
    header, rows = _read_csv(out)
    bad = [row for row in rows if row[header.index("worst_check")].startswith("not run: ")]
    assert bad and all("triangle inequality" in row[header.index("worst_check")] for row in bad)
    assert len(bad) == 1 and bad[0][:2] == ["0.048", "0.0225"]
    assert all(row[-1] == "false" and row[2] == "nan" for row in bad)
    assert len(bad) < len(rows) and "could not run" in r.stdout


def test_a_sweep_builds_one_kernel_for_all_its_variants(run_cli, tmp_path, monkeypatch):
    """A design with a servo-sizing check (the load-to-rotor inertia ratio, from the mass
    matrix) over 6,000 samples (past the first-call rule).  Varying a link's inertia, the one
    data kernel (inertial values at run time) solves every variant, the inertia seen at the
    motor included (the mass matrix's columns solved on it): one kernel built for three
    variants (a kernel of constants would be a compile per variant).  Varying the rotor's
    rated inertia (read by the checks alone), the same data kernel: none built anew.  The
    ratio follows the varied load inertia: the disc's J over n^2 J_rotor."""
    from test_sizing import J_ROTOR, N_RATIO, disc_trajectory, rated_stage

    from gearcli.dynamics.llvm import driver
    text = rated_stage(f", rotor_inertia: {J_ROTOR}, max_inertia_ratio: 50")
    (tmp_path / "stage.yaml").write_text(text)
    t = np.linspace(0, 1, 6000)
    disc_trajectory(tmp_path / "tr.csv", t, np.sin(t), np.cos(t), -np.sin(t))
    (tmp_path / "d.yaml").write_text("cases:\n  - {name: c, mechanism: stage.yaml, trajectories: [tr.csv], "
                                     "cycles_per_hour: 100}\n")
    disc = next(ln for ln in text.splitlines() if "name: disc" in ln)
    assert "inertia: [" in disc
    built, real = [], driver.Jit.__init__
    monkeypatch.setattr(driver.Jit, "__init__", lambda self, *a, **k: (built.append(1), real(self, *a, **k))[1])
    out = tmp_path / "s.csv"
    r = run_cli("sweep", tmp_path / "d.yaml", "--vary", "links.disc.inertia[2]=0.01,0.02,0.03", "-o", out)
    assert r.exit_code == 0, r.stderr
    assert len(built) == 1
    built.clear()
    r = run_cli("sweep", tmp_path / "d.yaml", "--vary", f"motors.servo.rating.rotor_inertia={J_ROTOR},{2 * J_ROTOR}")
    assert r.exit_code == 0 and built == [], r.stderr
    header, rows = _read_csv(out)
    ratio = header.index("c: motor servo: inertia ratio: value")
    values = [float(row[ratio]) for row in rows]
    assert values[1] == pytest.approx(2 * values[0], rel=1e-6) and values[2] == pytest.approx(3 * values[0], rel=1e-6)
    assert values[0] == pytest.approx(0.01 / (N_RATIO ** 2 * J_ROTOR), rel=1e-3)


@pytest.mark.parametrize("design, vary", [
    ("servo_joint_losses.yaml", "loads.payload.force[2]=-30,-5"),      # a load's wrench: a run-time input
    ("cobot_joint_reducer.yaml", "payloads.part.mass=1,4.5"),          # a payload picked and placed
    ("cobot_joint_reducer.yaml", "gears.hd.rating.rated_torque=7.8,10"),   # read by the checks alone
])
def test_payload_load_and_rating_variants_take_the_data_kernel(monkeypatch, design, vary):
    """A payload's mass, a load's wrench and a rating change no constant of the kernel: the
    data kernel solves their variants (one kernel), and every check value equals the numpy
    path's (the variant's mechanism analysed afresh) to 1e-11; a load's point is a constant
    of the kernel, and so takes the numpy path."""
    import gearcli.batch.sweep as sweep
    from gearcli.batch.manifest import load_manifest
    path = str(ROOT / "designs" / design)
    v = sweep.parse_vary(vary)
    assert sweep.data_kernel_applies([v])
    assert not sweep.data_kernel_applies([sweep.parse_vary("loads.payload.point[0]=0.1")])
    plan = sweep.plan_sweep(load_manifest(path), [v])
    kernel = [sweep.run_variant(path, plan.varies, values) for values in plan.variants]
    monkeypatch.setattr(sweep, "data_kernel_applies", lambda varies: False)
    numpy = [sweep.run_variant(path, plan.varies, values) for values in plan.variants]
    assert kernel[0] != kernel[1]                      # the value matters
    for a, b in zip(kernel, numpy):
        assert [x[:4] + x[5:6] + x[7:] for x in a] == [x[:4] + x[5:6] + x[7:] for x in b]
        for x, y in zip(a, b):
            assert x[4] == pytest.approx(y[4], rel=1e-11, abs=1e-300), x[:3]


def test_a_variant_reuses_only_the_parts_its_values_leave_alone():
    """A variant's mechanism takes the joints, gears and motors built for an earlier variant
    only when it shares those sections of the file (yaml_reader._build's reuse): a link's
    mass changes no joint object, a bearing's rating gets its own joints; each equals the
    mechanism built from scratch with the schema's checks."""
    from gearcli.batch.manifest import load_manifest
    from gearcli.batch.sweep import parse_vary, variant_data
    from gearcli.io.yaml_reader import mechanism_from_data

    manifest = load_manifest(DESIGN)
    case = manifest.cases[0]
    mass = (parse_vary("links.2.mass=2,3"),)
    rating = (parse_vary("joints.J1.bearings.lower.C=1000,2000"),)

    def built(varies, value, schema=False):
        return mechanism_from_data(variant_data(manifest, varies, (value,))[case.name], str(case.mechanism),
                                   schema=schema)
    a, b = built(mass, 2.0), built(mass, 3.0)
    assert b.joints is a.joints and b.gears is a.gears and b.motors is a.motors
    assert b.links[2].mass == 3.0 and a.links[2].mass == 2.0
    c, d = built(rating, 1000.0), built(rating, 2000.0)
    assert c.joints is not d.joints and c.joints is not a.joints
    assert (c.joints[0].bearings[0].C, d.joints[0].bearings[0].C) == (1000.0, 2000.0)
    fresh = built(rating, 2000.0, schema=True)
    assert [(j.name, [(x.name, x.C, x.C0) for x in j.bearings or ()]) for j in fresh.joints] == \
        [(j.name, [(x.name, x.C, x.C0) for x in j.bearings or ()]) for j in d.joints]


def test_a_variant_of_a_loads_wrench_rereads_the_trajectory_and_of_its_mass_does_not(tmp_path, monkeypatch):
    """The trajectory a variant reads is kept for the next while what the reading depends on
    is unchanged: the loads' names and wrenches (a load: column replaces one component of the
    file's wrench).  With a load:payload:fz column, a variant of the payload's force along x
    (not a column) changes the solve, equal to the numpy path's; a variant of its mass reads
    the file once for all."""
    import gearcli.batch.sweep as sweep
    import gearcli.io.trajectory as trajectory
    from gearcli.batch.manifest import load_manifest
    rows = (ROOT / "mechanisms" / "servo_joint_duty.csv").read_text().splitlines()
    (tmp_path / "duty.csv").write_text("\n".join([rows[0] + ",load:payload:fz"] + [r + ",-25" for r in rows[1:]]) + "\n")
    mech = (ROOT / "mechanisms" / "servo_joint_rated.yaml").read_text()
    assert mech.count("force: [0, -10, -19.62]}") == 1
    (tmp_path / "m.yaml").write_text(mech.replace("force: [0, -10, -19.62]}", "force: [0, -10, -19.62], mass: 1.0}"))
    (tmp_path / "d.yaml").write_text("cases:\n  - {name: c, mechanism: m.yaml, trajectories: [duty.csv], "
                                     "min_static_safety: 2.0}\n")
    path = str(tmp_path / "d.yaml")
    reads, real = [], trajectory.read_trajectory
    monkeypatch.setattr(trajectory, "read_trajectory", lambda *a, **k: (reads.append(1), real(*a, **k))[1])

    def run(vary):
        plan = sweep.plan_sweep(load_manifest(path), [sweep.parse_vary(vary)])
        reads.clear()
        sweep._TRAJECTORIES.clear()
        return [sweep.run_variant(path, plan.varies, values) for values in plan.variants]
    kernel = run("loads.payload.force[0]=0,40,80")
    assert len(reads) == 3 and len({tuple(r) for r in kernel}) == 3
    monkeypatch.setattr(sweep, "data_kernel_applies", lambda varies: False)
    numpy = run("loads.payload.force[0]=0,40,80")
    for a, b in zip(kernel, numpy):
        for x, y in zip(a, b):
            assert x[4] == pytest.approx(y[4], rel=1e-11, abs=1e-300), x[:3]
    monkeypatch.undo()
    monkeypatch.setattr(trajectory, "read_trajectory", lambda *a, **k: (reads.append(1), real(*a, **k))[1])
    masses = run("loads.payload.mass=0.5,1,2")
    assert len(reads) == 1 and len({tuple(r) for r in masses}) == 3


def test_a_constant_of_the_kernel_gets_a_data_kernel_per_value(monkeypatch):
    """A load's point is a constant of the kernel; with 8 variants of run-time values for each
    of its two values (at least sweep.STRUCTURE_VARIANTS), each point gets one data kernel,
    which solves its 8 variants: 2 kernels for 16 variants, one compile (the second point's
    kernel is the first's code with its own constant pool), and every check's value equal
    to the numpy path's (each variant's mechanism analysed afresh) to 1e-11.  With fewer
    variants a value (one each, or random points that rarely repeat one), the numpy path."""
    import gearcli.batch.sweep as sweep
    from gearcli.batch.manifest import load_manifest
    from gearcli.dynamics.llvm import driver
    path = str(ROOT / "designs" / "servo_joint_losses.yaml")
    varies = [sweep.parse_vary(t) for t in ("loads.payload.point[0]=0.05,0.08", "links.carrier.mass=0.3:0.6:4",
                                             "loads.payload.force[2]=-19.62,-30")]
    manifest = load_manifest(path)
    plan = sweep.plan_sweep(manifest, varies)
    assert not sweep.data_kernel_applies(varies) and plan.per_value_kernels
    assert not sweep.plan_sweep(manifest, varies[:1]).per_value_kernels               # 1 variant a point: numpy
    spread = [sweep.parse_vary("loads.payload.point[0]=0.02:0.09:8")] + varies[1:]
    assert not sweep.plan_sweep(manifest, spread, samples=8, seed=1).per_value_kernels    # ~1 a point: numpy
    sweep._STRUCTURES.clear()
    monkeypatch.setattr(driver, "_RECENT", {})
    monkeypatch.setenv("GEARCLI_CACHE_DIR", "/dev/null/none")      # no disk cache: sharing in memory
    built, real = [], driver.Jit.__init__
    monkeypatch.setattr(driver.Jit, "__init__", lambda self, *a, **k: (real(self, *a, **k), built.append(self))[0])
    kernel = sweep.run_sweep(plan)
    assert len(plan.variants) == 16 and len(built) == 2 and [j.from_cache for j in built] == [False, True]
    numpy = sweep.run_sweep(dataclasses.replace(plan, per_value_kernels=False))
    assert len(built) == 2 and len({tuple(r) for r in kernel}) == 16
    for a, b in zip(kernel, numpy):
        assert [x[:4] + x[5:6] + x[7:] for x in a] == [x[:4] + x[5:6] + x[7:] for x in b]
        for x, y in zip(a, b):
            assert x[4] == pytest.approx(y[4], rel=1e-11, abs=1e-300), x[:3]


def test_a_ratio_variant_moves_the_mesh_point_and_shares_the_compile(monkeypatch):
    """A gear pair's ratio varied moves its mesh point along the line of centres (the centre
    distance kept: the Bendix wrist's pinion 4 and link 1, 0.08 m apart, at e = -2.5 have
    pitch radii 0.08/3.5 and 0.08 - 0.08/3.5, by hand), and its tooth counts varied move a
    bevel pair's along the pitch cone; each ratio gets a data kernel, all of them one
    compile, and every check's value equals the numpy path's to 1e-11."""
    import gearcli.batch.sweep as sweep
    from gearcli.batch.manifest import load_manifest
    from gearcli.dynamics.llvm import driver
    from gearcli import analyse
    from gearcli.io.yaml_reader import mechanism_from_data
    path = str(ROOT / "designs" / "ci_example.yaml")
    manifest = load_manifest(path)
    varies = [sweep.parse_vary(t) for t in ("gears.4-1.ratio=-2.5,-3.5", "gears.5-6.teeth[1]=25,30",
                                             "links.3.mass=0.7,0.9")]
    data = sweep.variant_data(manifest, varies, (-2.5, 30, 0.7))["wrist_motion"]
    pairs = {g["name"]: g for g in data["gears"]}
    r_4 = 0.08 / 3.5
    assert np.allclose(pairs["4-1"]["mesh_point"], [0.08 - r_4, 0.0, 0.3], rtol=0, atol=1e-15)
    an = analyse(mechanism_from_data(data, path))        # the geometry of the moved points, from the mechanism
    ratio = {an.mech.gears[c.gear].name: c.geometry.ratio for c in an.circuits if c.geometry is not None}
    assert abs(ratio["4-1"] + 2.5) < 1e-12 and abs(abs(ratio["5-6"]) - 30 / 25) < 1e-12
    plan = sweep.plan_sweep(manifest, varies)
    assert plan.per_value_kernels and len(plan.variants) == 8
    sweep._STRUCTURES.clear()
    monkeypatch.setattr(driver, "_RECENT", {})
    monkeypatch.setenv("GEARCLI_CACHE_DIR", "/dev/null/none")
    built, real = [], driver.Jit.__init__
    monkeypatch.setattr(driver.Jit, "__init__", lambda self, *a, **k: (real(self, *a, **k), built.append(self))[0])
    kernel = sweep.run_sweep(plan)
    compiles = sum(not j.from_cache for j in built)
    assert len(built) == 4 and compiles <= 2     # the 25:25 bevel folds its ratio of 1: another IR
    numpy = sweep.run_sweep(dataclasses.replace(plan, per_value_kernels=False))
    assert len({tuple(map(tuple, r)) for r in kernel}) == 8
    for a, b in zip(kernel, numpy):
        assert [x[:4] + x[5:6] + x[7:] for x in a] == [x[:4] + x[5:6] + x[7:] for x in b]
        for x, y in zip(a, b):
            assert x[4] == pytest.approx(y[4], rel=1e-11, abs=1e-300), x[:3]


@pytest.mark.parametrize("kind, P, axis_k, ratio", [
    ("external", [0.02, 0, 0.1], ([0.08, 0, 0], [0, 0, 1]), -2.0),
    ("internal", [0.03, 0, 0], ([-0.02, 0, 0], [0, 0, 1]), 2.5),
    ("bevel", [0.025, 0, 0.075], ([0, 0, 0.1], [1, 0, 0]), -1.6),
    ("bevel", [0.02, 0, 0.05], ([0, 0, 0], [np.sin(1.2), 0, np.cos(1.2)]), 0.5),
])
def test_the_mesh_point_of_a_ratio_gives_that_ratio(kind, P, axis_k, ratio):
    """mesh_point_for_ratio moves a pair's mesh point so that the geometry (gear_geometry, its
    own code) gives |ratio|, the centre distance (parallel axes) or the cone distance
    (intersecting) kept; an internal pair's ratio cannot cross 1."""
    from gearcli.model.gears import gear_geometry, mesh_point_for_ratio
    axes = ([0, 0, 0], [0, 0, 1]) + axis_k
    g, problems = gear_geometry(kind, np.array(P, float), *axes)
    assert not problems
    P2 = mesh_point_for_ratio(g, ratio)
    g2, problems = gear_geometry(kind, P2, *axes)
    assert not problems and abs(abs(g2.ratio) - abs(ratio)) < 1e-12 * abs(ratio)
    if kind == "bevel":
        apex = np.array([0.0, 0.0, 0.1 if axis_k[0][2] else 0.0])
        assert abs(np.linalg.norm(P2 - apex) - np.linalg.norm(np.array(P) - apex)) < 1e-15
    else:
        d = (lambda G: G.r_j + G.r_k if kind == "external" else abs(G.r_k - G.r_j))
        assert abs(d(g2) - d(g)) < 1e-15
    if kind == "internal":
        with pytest.raises(ValueError, match="must stay above 1"):
            mesh_point_for_ratio(g, 0.8)
