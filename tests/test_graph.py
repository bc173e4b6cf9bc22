"""Graph analysis of the bundled mechanisms, through the library and ``gearcli graph --json``.

Expected values come from the paper (Fig. 2, Eq. 22, the Fig. 6 description in ERRATA item
9) and from the mesh geometry written in the YAML files, re-derived by hand below.
"""
from __future__ import annotations

import json
import random

import numpy as np
import pytest
import yaml

from gearcli import analyse, load_mechanism, parse_mechanism
from gearcli.report.graph_json import analysis_dict
from gearcli.report.dot import to_dot

MECHS = ("paper_2dof", "bendix_wrist", "coaxial_fig5")

EXPECTED = {
    "paper_2dof": {
        "dof": 2,
        "levels": {"0": 0, "1": 1, "2": 2, "3": 1, "4": 2, "5": 1},
        "primary": ["0", "1", "2"],
        "carriers": {"3": "0", "4": "1", "5": "0"},
        "transmission_lines": {("3", "4", "2"), ("5", "1")},
        "pseudo_triangular": True,
    },
    "bendix_wrist": {
        "dof": 3,
        "levels": {"0": 0, "1": 1, "2": 2, "3": 3, "4": 1, "5": 1, "6": 2, "7": 1, "8": 2},
        "primary": ["0", "1", "2", "3"],
        "carriers": {"4": "0", "5": "0", "6": "1", "7": "0", "8": "1"},
        "transmission_lines": {("5", "6", "3"), ("7", "8", "3"), ("4", "1")},
        "pseudo_triangular": False,
    },
}
EXPECTED["coaxial_fig5"] = EXPECTED["paper_2dof"]  # same canonical graph (Fig. 5 variant)


# --------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------
def lib_dict(mech_dir, name: str) -> dict:
    return analysis_dict(analyse(load_mechanism(mech_dir / f"{name}.yaml")))


def cli_dict(run_cli, mech_dir, name: str) -> dict:
    res = run_cli("graph", mech_dir / f"{name}.yaml", "--json")
    assert res.exit_code == 0, res.stderr
    return json.loads(res.stdout)


@pytest.fixture(params=["lib", "cli"])
def summary(request, run_cli, mech_dir):
    """``summary(name)``: the analysis dict from the library or from ``graph --json``."""
    if request.param == "lib":
        return lambda name: lib_dict(mech_dir, name)
    return lambda name: cli_dict(run_cli, mech_dir, name)


def ratios(d: dict) -> dict[str, float]:
    """Circuit ratio e_kj of each gear pair, by pair name."""
    return {c["pair"]: c["ratio"] for c in d["fundamental_circuits"]}


def rolling_ratio(o_j, z_j, o_k, z_k, P) -> float:
    """e_kj = dtheta_j / dtheta_k of two gears rolling at pitch point P without slip.

    A unit rotation of gear x about its axis (point o_x, unit direction z_x) moves the
    tooth at P with velocity z_x x (P - o_x); rolling means equal velocities at P.
    Written independently of gearcli.gears.
    """
    o_j, z_j, o_k, z_k, P = (np.asarray(v, float) for v in (o_j, z_j, o_k, z_k, P))
    v_j = np.cross(z_j, P - o_j)
    v_k = np.cross(z_k, P - o_k)
    assert np.linalg.norm(np.cross(v_j, v_k)) < 1e-12  # both tangent to the same line
    return float(v_k @ v_j / (v_j @ v_j))


def unknowns(an) -> list[tuple[str, int, set[str]]]:
    """(name, scalar count, links whose equations contain it) of every load unknown:
    5 per revolute joint, 1 tangential force per gear mesh, 1 torque per motor."""
    n, base = an.names, an.mech.base
    out = [(f"joint {jt.name}", 5, {jt.parent, jt.child} - {base}) for jt in an.mech.joints]
    for c in an.circuits:
        links = {n[c.j], n[c.k]} | (set() if c.geometry is not None else {n[c.carrier]})
        out.append((f"mesh {an.mech.gears[c.gear].name}", 1, links - {base}))
    for m, x, s in zip(an.mech.motors, an.motor_links, an.motor_stators):
        out.append((f"motor {m.name}", 1, {n[x], n[s]} - {base}))
    return out


def assert_valid_schedule(an) -> None:
    """Each block's equations (6 per link) contain exactly 6 * len(block) unknowns not
    determined by earlier blocks, and every moving link is solved exactly once."""
    known: set[str] = set()
    solved: list[str] = []
    for block in (an.name_of(b) for b in an.schedule):
        new = [(u, size) for u, size, links in unknowns(an) if u not in known and links & set(block)]
        assert sum(size for _, size in new) == 6 * len(block), (block, new)
        known |= {u for u, _ in new}
        solved += block
    assert sorted(solved) == sorted(an.name_of(an.tree.moving))
    assert known == {u for u, _, _ in unknowns(an)}


# --------------------------------------------------------------------------------------
# solve order
# --------------------------------------------------------------------------------------
def test_paper_solve_order(summary):
    order = summary("paper_2dof")["solve_order"]
    assert order[:3] == [["2"], ["4"], ["1"]]
    assert sorted(order[3:]) == [["3"], ["5"]]  # 3 and 5 in either order


def test_bendix_solve_order(summary):
    order = summary("bendix_wrist")["solve_order"]
    assert len(order) == 7
    assert set(order[0]) == {"2", "3"}
    assert sorted(order[1:3]) == [["6"], ["8"]]
    assert order[3] == ["1"]
    assert sorted(order[4:]) == [["4"], ["5"], ["7"]]


@pytest.mark.parametrize("name", MECHS)
def test_solve_order_is_valid(mech_dir, name):
    assert_valid_schedule(analyse(load_mechanism(mech_dir / f"{name}.yaml")))


# --------------------------------------------------------------------------------------
# topology
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", MECHS)
def test_topology(summary, name):
    d, exp = summary(name), EXPECTED[name]
    assert d["dof"] == exp["dof"]
    assert d["levels"] == exp["levels"]
    assert d["primary"] == exp["primary"]
    assert d["carriers"] == exp["carriers"]
    assert {tuple(line) for line in d["transmission_lines"]} == exp["transmission_lines"]
    assert len(d["transmission_lines"]) == len(exp["transmission_lines"])
    assert d["pseudo_triangular"] is exp["pseudo_triangular"]


def test_bendix_coaxial_groups(summary):
    groups = {(g["carrier"], frozenset(g["links"])) for g in summary("bendix_wrist")["coaxial_groups"]}
    assert groups == {("0", frozenset({"1", "5", "7"})), ("1", frozenset({"2", "6", "8"}))}


# --------------------------------------------------------------------------------------
# structure matrix (paper Eq. 22)
# --------------------------------------------------------------------------------------
# Pitch geometry of paper_2dof.yaml, at the home pose, in each pair's carrier frame.
#
# 5-1, carrier 0 (base frame): gear 1 turns about z0 through the origin (J1: D-H, d = 0);
#   pinion 5 about +z0 through (0.12, 0, -0.05) (J5).  Mesh point P = (0.09, 0, -0.05):
#   r_1 = 0.09 m, r_5 = 0.03 m, P between the axes (external pair), so the gears turn in
#   opposite senses: e_15 = -r_1 / r_5 = -3.
# 3-4, carrier 1 (link 1's frame: origin at the elbow, x1 along the arm, a1 = 0.4 m):
#   shaft 3 turns about z0, which is the line x1 = -0.4 in link 1's frame, direction +z1;
#   shaft 4 about +x1 through (-0.2, 0, 0.05) (J4).  P = (-0.37, 0, 0.08): cone apex
#   (-0.4, 0, 0.05), r_3 = r_4 = 0.03 m, both cone angles 45 deg.  A positive turn of 3
#   moves its tooth at P (radius +x1) along z1 x x1 = +y1; a positive turn of 4 moves its
#   tooth at P (radius +z1) along x1 x z1 = -y1.  Rolling: dtheta_3 = -dtheta_4, e_43 = -1.
# 4-2, carrier 1: link 2 turns about z1 through the elbow (J2); P = (-0.04, 0, 0.07):
#   r_2 = 0.04 m (radius -x1), r_4 = 0.02 m (radius +z1).  Positive turns move the teeth
#   along z1 x (-x1) = -y1 (gear 2) and x1 x z1 = -y1 (gear 4): same sense, so
#   0.04 dtheta_2 = 0.02 dtheta_4 and e_24 = +2 (teeth 20:40 agree in magnitude).
E15, E43, E24 = -3.0, -1.0, 2.0
GEOMETRY = {  # pair: (o_j, z_j, o_k, z_k, P), pair "j-k", carrier frame, m
    "5-1": ((0.12, 0, -0.05), (0, 0, 1), (0, 0, 0), (0, 0, 1), (0.09, 0, -0.05)),
    "3-4": ((-0.4, 0, 0), (0, 0, 1), (-0.2, 0, 0.05), (1, 0, 0), (-0.37, 0, 0.08)),
    "4-2": ((-0.2, 0, 0.05), (1, 0, 0), (0, 0, 0), (0, 0, 1), (-0.04, 0, 0.07)),
}


def eq22_AT(e15: float, e24: float, e43: float) -> np.ndarray:
    """A^T of Eq. (22): [theta_3,0, theta_5,0] = A^T [theta_1,0, theta_2,1]."""
    return np.array([[1.0, e24 * e43], [e15, 0.0]])


def test_hand_derived_ratios_match_rolling():
    assert rolling_ratio(*GEOMETRY["5-1"]) == pytest.approx(E15)
    assert rolling_ratio(*GEOMETRY["3-4"]) == pytest.approx(E43)
    assert rolling_ratio(*GEOMETRY["4-2"]) == pytest.approx(E24)


@pytest.mark.parametrize("name", ["paper_2dof", "coaxial_fig5"])
def test_structure_matrix_eq22(summary, name):
    d = summary(name)
    e = ratios(d)
    assert d["motors"] == ["motor3", "motor5"]
    assert d["independent_joints"] == ["J1", "J2"]
    A = np.array(d["structure_matrix"])
    # from the ratios the analysis reports
    np.testing.assert_allclose(A.T, eq22_AT(e["5-1"], e["4-2"], e["3-4"]), atol=1e-12)
    # independently, from the mesh geometry
    assert e["5-1"] == pytest.approx(E15)
    assert e["3-4"] == pytest.approx(E43)
    assert e["4-2"] == pytest.approx(E24)
    np.testing.assert_allclose(A.T, eq22_AT(E15, E24, E43), atol=1e-12)


def test_json_floats_are_rounded(run_cli, mech_dir):
    d = cli_dict(run_cli, mech_dir, "paper_2dof")
    assert ratios(d)["3-4"] == -1.0  # exactly, not -0.9999999999999991
    assert d["structure_matrix"] == [[1.0, -3.0], [-2.0, 0.0]]


# --------------------------------------------------------------------------------------
# canonicalisation (coaxial_fig5: shaft 3 borne by link 1, as in the paper's Fig. 5)
# --------------------------------------------------------------------------------------
def test_fig5_canonical_graph(summary):
    d, p = summary("coaxial_fig5"), summary("paper_2dof")
    thin = {(e["parent"], e["child"]) for e in d["canonical_graph"]["thin_edges"]}
    assert thin == {("0", "1"), ("1", "2"), ("0", "3"), ("1", "4"), ("0", "5")}
    assert d["carriers"]["3"] == "0" and d["levels"]["3"] == 1
    assert d["primary"] == ["0", "1", "2"]
    assert d["dof"] == p["dof"] == 2
    np.testing.assert_allclose(d["structure_matrix"], p["structure_matrix"], atol=1e-12)
    groups = [(g["carrier"], set(g["links"])) for g in d["coaxial_groups"]]
    assert groups == [("0", {"1", "3"})]
    # 3 and 1 turn about one line: same axis label on their canonical edges
    labels = {e["child"]: e["label"] for e in d["canonical_graph"]["thin_edges"]}
    assert labels["3"] == labels["1"]


def test_fig5_real_joint_is_kept(mech_dir):
    an = analyse(load_mechanism(mech_dir / "coaxial_fig5.yaml"))
    j3 = next(j for j in an.mech.joints if j.name == "J3")
    assert (j3.parent, j3.child) == ("1", "3")
    assert an.name_of([an.tree.parent[an.tree.index["3"]]]) == ["1"]  # real bearing
    assert an.name_of([an.canonical_parent[an.tree.index["3"]]]) == ["0"]  # canonical


def test_fig5_solve_order(mech_dir):
    """The schedule works on the real bearings: with 3 borne by link 1, link 3's joint
    unknowns enter link 1's equations, so 3 is solved before 1 ({2},{4},{3},{1},{5})."""
    an = analyse(load_mechanism(mech_dir / "coaxial_fig5.yaml"))
    order = [an.name_of(b) for b in an.schedule]
    assert all(len(b) == 1 for b in order)
    assert order[:2] == [["2"], ["4"]]
    assert sorted(order) == [["1"], ["2"], ["3"], ["4"], ["5"]]
    assert_valid_schedule(an)


# --------------------------------------------------------------------------------------
# invariance under re-ordering of the file
# --------------------------------------------------------------------------------------
def comparable(d: dict) -> dict:
    """The parts of an analysis that must not depend on the order of the file's lists.

    Axis labels are auto-generated in file order, so they are compared as the partition
    of links they induce; structure-matrix columns are keyed by motor name.
    """
    edges = d["canonical_graph"]["thin_edges"]
    by_label: dict[str, set] = {}
    for e in edges:
        by_label.setdefault(e["label"], set()).add(e["child"])
    A = np.array(d["structure_matrix"])
    return {
        "dof": d["dof"],
        "levels": d["levels"],
        "primary": d["primary"],
        "carriers": d["carriers"],
        "thin": {(e["parent"], e["child"]) for e in edges},
        "label_partition": {frozenset(s) for s in by_label.values()},
        "heavy": {(e["pair"], tuple(e["links"]), e["carrier"]) for e in d["canonical_graph"]["heavy_edges"]},
        "circuits": {c["pair"]: (c["j"], c["k"], c["carrier"], round(c["ratio"], 9))
                     for c in d["fundamental_circuits"]},
        "groups": {(g["carrier"], frozenset(g["links"])) for g in d["coaxial_groups"]},
        "lines": {tuple(t) for t in d["transmission_lines"]},
        "independent": d["independent_joints"],
        "A": {m: tuple(np.round(A[:, i], 9)) for i, m in enumerate(d["motors"])},
        "pseudo_triangular": d["pseudo_triangular"],
        "blocks": sorted(sorted(b) for b in d["solve_order"]),
    }


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("name", ["paper_2dof", "bendix_wrist"])
def test_shuffled_file_same_analysis(mech_dir, name, seed):
    text = (mech_dir / f"{name}.yaml").read_text()
    data = yaml.safe_load(text)
    rng = random.Random(seed)
    for key in ("links", "joints", "gears", "motors"):
        rng.shuffle(data[key])
    shuffled = parse_mechanism(yaml.safe_dump(data, sort_keys=False), f"{name}-shuffled.yaml")
    got = analysis_dict(analyse(shuffled))
    assert comparable(got) == comparable(lib_dict(mech_dir, name))
    if name == "paper_2dof":
        order = got["solve_order"]
        assert order[:3] == [["2"], ["4"], ["1"]] and sorted(order[3:]) == [["3"], ["5"]]
    else:
        order = got["solve_order"]
        assert set(order[0]) == {"2", "3"} and sorted(order[1:3]) == [["6"], ["8"]]
        assert order[3] == ["1"] and sorted(order[4:]) == [["4"], ["5"], ["7"]]


# --------------------------------------------------------------------------------------
# DOT output
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", MECHS)
def test_dot_output(run_cli, mech_dir, name):
    res = run_cli("graph", mech_dir / f"{name}.yaml", "--dot")
    assert res.exit_code == 0, res.stderr
    dot = res.stdout
    an = analyse(load_mechanism(mech_dir / f"{name}.yaml"))
    assert dot.lstrip().startswith("digraph") and dot.rstrip().endswith("}")
    assert dot.count("{") == dot.count("}")
    for link in an.names:
        assert f'"{link}" [' in dot
    assert 'shape="box"' in dot and 'shape="doublecircle"' in dot
    for i in an.tree.moving:
        parent = an.names[an.canonical_parent[i]]
        assert f'"{parent}" -> "{an.names[i]}" [label="{an.label[i]}", penwidth=1]' in dot
    heavy = [line for line in dot.splitlines() if "penwidth=4" in line]
    assert len(heavy) == len(an.mech.gears)
    for gp in an.mech.gears:
        assert any(f'"{gp.j}" -> "{gp.k}"' in h and f'label="{gp.name}"' in h and 'dir="none"' in h
                   for h in heavy)
    assert dot == to_dot(an)


def test_dot_real_joints(run_cli, mech_dir):
    res = run_cli("graph", mech_dir / "coaxial_fig5.yaml", "--dot", "--real-joints")
    assert res.exit_code == 0, res.stderr
    assert '"1" -> "3"' in res.stdout and '"0" -> "3"' not in res.stdout
    canon = run_cli("graph", mech_dir / "coaxial_fig5.yaml", "--dot").stdout
    assert '"0" -> "3"' in canon and '"1" -> "3"' not in canon


def test_bendix_axis_labels_follow_errata_item_9(mech_dir):
    """Primary axes a, b, c; inputs 5 and 7 on axis a (concentric with link 1); 6 and 8 on
    axis b; pinion 4 on an axis of its own."""
    from gearcli import analyse
    from gearcli import load_mechanism

    an = analyse(load_mechanism(mech_dir / "bendix_wrist.yaml"))
    lab = dict(zip(an.names, an.label))
    assert (lab["1"], lab["2"], lab["3"]) == ("a", "b", "c")
    assert lab["5"] == lab["7"] == "a" and lab["6"] == lab["8"] == "b"
    assert lab["4"] not in ("a", "b", "c")


def test_check_determinate_reports_singular_equations(mech_dir):
    """The numerical safety net behind the structural schedule: a mesh whose tooth force
    direction has been zeroed leaves its tangential force undetermined."""
    import dataclasses

    from gearcli.errors import Collector
    from gearcli import analyse
    from gearcli import load_mechanism
    from gearcli.dynamics.determinacy import check_determinate

    an = analyse(load_mechanism(mech_dir / "paper_2dof.yaml"))
    col = Collector("paper_2dof.yaml")
    check_determinate(an, col)
    assert not col.issues
    c = an.circuits[0]
    broken = dataclasses.replace(c, geometry=dataclasses.replace(c.geometry, ut=0 * c.geometry.ut,
                                                                  us=0 * c.geometry.us))
    object.__setattr__(an, "circuits", (broken,) + an.circuits[1:])
    check_determinate(an, col)
    assert len(col.issues) == 1 and "statically indeterminate" in col.issues[0].message


TWO_STAGE = """\
name: two_stage
base: housing
end_effector: carrier2
links:
  - name: housing
  - {name: sun, mass: 0.08, inertia: [1.2e-5, 1.2e-5, 4.0e-6]}
  - {name: carrier1, mass: 0.2, inertia: [1.0e-4, 1.0e-4, 1.5e-4]}
  - {name: planet1, mass: 0.02, inertia: [6.0e-7, 6.0e-7, 8.0e-7]}
  - {name: carrier2, mass: 0.35, inertia: [2.5e-4, 2.5e-4, 3.8e-4]}
  - {name: planet2, mass: 0.02, inertia: [6.0e-7, 6.0e-7, 8.0e-7]}
joints:
  - {name: JS, parent: housing, child: sun, origin: {xyz: [0, 0, 0]}, axis: [0, 0, 1]}
  - {name: JC1, parent: housing, child: carrier1, origin: {xyz: [0, 0, 0.01]}, axis: [0, 0, 1]}
  - {name: JP1, parent: carrier1, child: planet1, origin: {xyz: [0.021, 0, -0.01]}, axis: [0, 0, 1]}
  - {name: JC2, parent: housing, child: carrier2, origin: {xyz: [0, 0, 0.05]}, axis: [0, 0, 1]}
  - {name: JP2, parent: carrier2, child: planet2, origin: {xyz: [0.021, 0, -0.01]}, axis: [0, 0, 1]}
gears:
  - {name: s1, links: [sun, planet1], teeth: [24, 18], mesh_point: [0.012, 0, -0.01]}
  - {name: r1, links: [planet1, housing], kind: internal, teeth: [18, 60], mesh_point: [0.030, 0, -0.01]}
  - {name: s2, links: [carrier1, planet2], teeth: [24, 18], mesh_point: [0.012, 0, -0.01]}
  - {name: r2, links: [planet2, housing], kind: internal, teeth: [18, 60], mesh_point: [0.030, 0, -0.01]}
motors:
  - {name: motor, link: sun}
"""


def test_a_two_stage_planetary_line_runs_through_both_stages(run_cli, tmp_path, mech_dir):
    """A planet in a fixed ring drives its carrier: the line goes on to the carrier, and on
    into the second stage, instead of ending at the housing (issue 34, section 3: `graph`
    showed 'sun -> planet1 -> housing' and no second stage).  The ratio of the line, 1/(1 +
    60/24) per stage, is the structure matrix's."""
    path = tmp_path / "two_stage.yaml"
    path.write_text(TWO_STAGE)
    r = run_cli("graph", path)
    assert r.exit_code == 0, r.stderr
    assert "  sun -> planet1 -> carrier1 -> planet2 -> carrier2" in r.stdout.splitlines()
    d = json.loads(run_cli("graph", path, "--json").stdout)
    assert d["transmission_lines"] == [["sun", "planet1", "carrier1", "planet2", "carrier2"]]
    assert np.array(d["structure_matrix"]).ravel() == pytest.approx([(1 + 60 / 24) ** 2])
    lines = {tuple(t) for t in lib_dict(mech_dir, "planetary_3p")["transmission_lines"]}
    assert lines == {("sun", f"planet{k}", "carrier") for k in (1, 2, 3)}
