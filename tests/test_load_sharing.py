"""Redundant gear sets (issue 9): a planetary with N planets shares its load by the mesh
stiffness model (min sum t^2/k subject to every Newton-Euler equation).

The checks are independent of the solver's minimisation:

* symmetry and an equivalent determinate mechanism: with equal stiffness each of the N
  planets carries exactly 1/N of the tooth force of ONE planet with N times the mass and
  inertia (the determinate mechanism solved by the ordinary square solve; same total
  carrier-axis inertia, since sum (I_zz + m r^2) over the planets = N I_zz + (N m) r^2);
* a static hand calculation with unequal stiffness (t_i proportional to k_i);
* block schedule (constant frame, rectangular map) against the full world-frame solve;
* the Newton-Euler residual of every link (``--verify``).
"""
from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest
import yaml

from gearcli import analyse, load_mechanism
from gearcli.dynamics.blocks import make_plans
from gearcli.dynamics.sharing import SharingError, least_load_map, null_directions_without_t
from gearcli.dynamics.solve import solve
from gearcli.io.trajectory import read_trajectory
from gearcli.io.yaml_reader import parse_mechanism

TOL = 1e-12


@pytest.fixture(scope="module")
def bundled(mech_dir):
    return (mech_dir / "planetary_3p.yaml").read_text()


def variant(text: str, edit) -> object:
    """Analysis of the bundled planetary's YAML after ``edit(data)``."""
    data = yaml.safe_load(text)
    edit(data)
    return analyse(parse_mechanism(yaml.safe_dump(data), "variant.yaml"))


def with_planets(n: int):
    def edit(data):
        next(j for j in data["joints"] if j["name"] == "JP")["planets"] = n
    return edit


def lumped(n: int):
    """One planet with n times the planet's mass and inertia (from the file's own data)."""
    def edit(data):
        jp = next(j for j in data["joints"] if j["name"] == "JP")
        del jp["planets"]
        planet = next(x for x in data["links"] if x["name"] == "planet")
        planet["mass"] = n * planet["mass"]
        planet["inertia"] = [n * v for v in planet["inertia"]]
    return edit


def trajectory(mech_dir, an):
    traj = read_trajectory(mech_dir / "planetary_3p_traj.csv", an.independent_names)
    return traj.q[::20], traj.qd[::20], traj.qdd[::20]


def gear_index(an, name: str) -> int:
    return next(ci for ci, c in enumerate(an.circuits) if an.mech.gears[c.gear].name == name)


def close(a, b, tol=TOL):
    scale = max(np.max(np.abs(a)), np.max(np.abs(b)), 1e-300)
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * scale)


# --- the bundled planetary: names, notes, equal sharing, one-planet equivalent ----------------------

def test_expanded_names_and_note(run_cli, mech_dir):
    res = run_cli("graph", mech_dir / "planetary_3p.yaml", "--json")
    assert res.exit_code == 0, res.stderr
    import json

    d = json.loads(res.stdout)
    assert d["dof"] == 1
    assert d["secondary"] == ["sun", "planet1", "planet2", "planet3"]
    assert d["carriers"] == {"sun": "housing", "planet1": "carrier", "planet2": "carrier", "planet3": "carrier"}
    pairs = ["sun-planet1", "sun-planet2", "sun-planet3", "planet-ring1", "planet-ring2", "planet-ring3"]
    assert d["load_sharing"] == [{"pairs": pairs, "model": "load shared by mesh stiffness, min sum t^2/k",
                                  "stiffness": [3.0e8] * 3 + [3.5e8] * 3}]
    text = run_cli("graph", mech_dir / "planetary_3p.yaml").stdout
    assert "JP2: carrier -> planet2" in text
    assert text.splitlines()[-1].startswith("note: redundant gear set 'sun-planet1', ")


def test_planets_equally_spaced(mech_dir):
    """The expanded pins sit at 0, 120 and 240 degrees on the 21 mm circle (carrier frame)."""
    mech = load_mechanism(mech_dir / "planetary_3p.yaml")
    pins = {j.name: j.p_pj for j in mech.joints if j.name.startswith("JP")}
    for k, name in enumerate(("JP1", "JP2", "JP3")):
        a = 2 * np.pi * k / 3
        close(pins[name], [0.021 * np.cos(a), 0.021 * np.sin(a), -0.01], 1e-15)
    sun_mesh = {g.name: g.mesh_point for g in mech.gears}
    close(sun_mesh["sun-planet3"], [0.012 * np.cos(4 * np.pi / 3), 0.012 * np.sin(4 * np.pi / 3), -0.01], 1e-15)


@pytest.mark.parametrize("n", [2, 3, 4, 7, 42])
def test_each_planet_carries_one_nth_of_the_lumped_planet(mech_dir, bundled, n):
    """(7 planets: 14 signed meshes in one block, 16384 sign patterns; 42: 2^84 patterns,
    more than an index fits: the maps are made only for the patterns the motion meets.)"""
    an = variant(bundled, with_planets(n))
    one = variant(bundled, lumped(n))
    assert an.dof == one.dof == 1
    assert len(an.redundant) == 1 and not one.redundant
    q, qd, qdd = trajectory(mech_dir, an)
    res, ref = solve(an, q, qd, qdd), solve(one, q, qd, qdd)
    close(res.motor, ref.motor)
    for pair in ("sun-planet", "planet-ring"):
        t_ref = ref.gear_t[:, gear_index(one, pair)]
        sep_ref = ref.gear_sep[:, gear_index(one, pair)]
        for i in range(1, n + 1):
            ci = gear_index(an, f"{pair}{i}")
            close(res.gear_t[:, ci], t_ref / n)
            close(res.gear_sep[:, ci], sep_ref / n)
    assert np.min(np.abs(ref.gear_t[:, 0])) > 1.0     # the comparison is not between zeros


def test_every_planet_bearing_loaded(mech_dir):
    an = analyse(load_mechanism(mech_dir / "planetary_3p.yaml"))
    res = solve(an, *trajectory(mech_dir, an))
    names = [j.name for j in an.mech.joints]
    radial = [np.hypot(res.joint[:, names.index(f"JP{i}"), 0], res.joint[:, names.index(f"JP{i}"), 1])
              for i in (1, 2, 3)]
    t = np.abs(res.gear_t[:, gear_index(an, "sun-planet1")])
    for r in radial:
        assert np.all(r > 1.5 * t)          # the pin carries both tooth forces (about 2 t)
        close(r, radial[0], 1e-12)


def test_block_equals_full_and_rectangular_plan(mech_dir):
    an = analyse(load_mechanism(mech_dir / "planetary_3p.yaml"))
    plans = make_plans(an)
    assert len(plans) == 1                   # sun, carrier and planets: one redundant block
    p = plans[0]
    assert an.names[p.F] == "carrier"       # a constant frame: the least-t^2/k map is constant
    assert p.Ainv[0].shape == (int(p.offs[-1]), 6 * len(p.links)) and p.offs[-1] == 6 * len(p.links) + 2
    q, qd, qdd = trajectory(mech_dir, an)
    blk = solve(an, q, qd, qdd, method="block", verify=True)
    full = solve(an, q, qd, qdd, method="full", verify=True)
    for f in ("motor", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial"):
        close(getattr(blk, f), getattr(full, f), 1e-11)
    assert blk.residual < 1e-13 and full.residual < 1e-13


def test_cli_verify_residual_at_rounding_level(run_cli, mech_dir, tmp_path):
    out = tmp_path / "loads.csv"
    res = run_cli("solve", mech_dir / "planetary_3p.yaml", mech_dir / "planetary_3p_traj.csv", "-o", out, "--verify")
    assert res.exit_code == 0, res.stderr
    worst = float(re.search(r"Worst Newton-Euler residual \(relative\): (\S+)", res.stdout).group(1))
    assert worst < 1e-13
    assert "note: redundant gear set 'sun-planet1', 'sun-planet2', 'sun-planet3', 'planet-ring1', " in res.stdout


# --- unequal stiffness: static hand check -----------------------------------------------------------

@pytest.mark.parametrize("k", [(1.0e8, 2.0e8, 3.0e8), (5.0e8, 1.0e8, 1.0e8)])
def test_unequal_stiffness_shares_in_proportion(mech_dir, k):
    """At rest (gravity along the axis) a resisting torque M on the carrier needs the motor
    torque M / 3.5 (ratio 1 + 60/24); the sun's torque balance: sum t_i = (M / 3.5) / r_sun.
    Each planet path i has both its meshes of stiffness k_i; the planets at rest carry equal
    sun and ring forces t_i, and min sum 2 t_i^2 / k_i subject to sum t_i = T gives
    t_i = T k_i / sum k (Lagrange).  Weights ignored would give T / 3 each."""
    mech = load_mechanism(mech_dir / "planetary_3p.yaml")
    M = 3.5
    stiff = {f"{pair}{i + 1}": k[i] for i in range(3) for pair in ("sun-planet", "planet-ring")}
    loads = (dataclasses.replace(mech.loads[0], force=np.zeros(3), moment=np.array([0.0, 0.0, -M])),)
    mech = dataclasses.replace(mech, gears=tuple(dataclasses.replace(g, stiffness=stiff[g.name]) for g in mech.gears),
                               loads=loads)
    an = analyse(mech)
    z = np.zeros((1, 1))
    for method in ("block", "full"):
        res = solve(an, z, z, z, method=method, verify=True)
        assert res.residual < 1e-13
        assert res.motor[0, 0] == pytest.approx(M / 3.5, rel=1e-12)
        T = (M / 3.5) / 0.012
        for i in range(3):
            for pair in ("sun-planet", "planet-ring"):
                t = res.gear_t[0, gear_index(an, f"{pair}{i + 1}")]
                assert abs(t) == pytest.approx(T * k[i] / sum(k), rel=1e-12)


def test_default_stiffness_is_equal_sharing(mech_dir, bundled):
    """Without stiffness (default equal) the symmetric planetary shares equally too, and the
    note says which stiffness applied."""
    def edit(data):
        for g in data["gears"]:
            g.pop("stiffness")
    an = variant(bundled, edit)
    res = solve(an, *trajectory(mech_dir, an))
    t = res.gear_t[:, [gear_index(an, f"sun-planet{i}") for i in (1, 2, 3)]]
    close(t[:, 1], t[:, 0])
    close(t[:, 2], t[:, 0])


# --- the sharing map itself, and what it refuses ------------------------------------------------------

def test_least_load_map_two_parallel_springs():
    """x = (t1, t2, R): t1 + t2 = T, R = 5 (a reaction): min t1^2/k1 + t2^2/k2 -> t_i = T k_i / (k1 + k2)."""
    A = np.array([[1.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    k1, k2 = 2.0, 6.0
    X = least_load_map(A, np.array([1 / k1, 1 / k2, 0.0]))
    x = X @ np.array([8.0, 5.0])
    np.testing.assert_allclose(x, [2.0, 6.0, 5.0], rtol=1e-14)


def test_redundancy_without_tooth_force_is_refused():
    """x = (R1, R2, t): R1 + R2 = F, t = T: the split of R1, R2 changes no tooth force."""
    A = np.array([[1.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    w = np.array([0.0, 0.0, 1.0])
    assert null_directions_without_t(A, w) == (2, 1)
    with pytest.raises(SharingError):
        least_load_map(A, w)


# --- export round trip ------------------------------------------------------------------------------

def test_export_round_trip(run_cli, mech_dir, tmp_path):
    out = tmp_path / "p3.urdf"
    res = run_cli("export", mech_dir / "planetary_3p.yaml", "-o", out)
    assert res.exit_code == 0, res.stderr
    assert 'stiffness="300000000.0"' in out.read_text()
    a = analyse(load_mechanism(mech_dir / "planetary_3p.yaml"))
    b = analyse(load_mechanism(out))
    assert [g.name for g in b.mech.gears] == [g.name for g in a.mech.gears]
    assert [g.stiffness for g in b.mech.gears] == [g.stiffness for g in a.mech.gears]
    assert [[b.mech.gears[b.circuits[i].gear].name for i in s] for s in b.redundant] == \
           [[a.mech.gears[a.circuits[i].gear].name for i in s] for s in a.redundant]
    q, qd, qdd = trajectory(mech_dir, a)
    ra, rb = solve(a, q, qd, qdd), solve(b, q, qd, qdd)
    close(rb.gear_t, ra.gear_t, 1e-9)
    close(rb.motor, ra.motor, 1e-9)
    check = run_cli("check", out)
    assert check.exit_code == 0 and "note: redundant gear set 'sun-planet1'" in check.stdout


def test_urdf_stiffness_not_positive(run_cli, mech_dir, tmp_path):
    out = tmp_path / "p3.urdf"
    run_cli("export", mech_dir / "planetary_3p.yaml", "-o", out)
    text = out.read_text().replace('stiffness="300000000.0"', 'stiffness="-1"', 1)
    bad = tmp_path / "bad.urdf"
    bad.write_text(text)
    res = run_cli("check", bad)
    assert res.exit_code == 2 and "Traceback" not in res.stderr
    lines = res.stderr.splitlines()
    assert len(lines) == 1 and re.search(r"bad\.urdf:\d+: gearcli:gear 'sun-planet1': mesh stiffness must be "
                                         r"positive, got -1 N/m$", lines[0]), lines


# --- joints[].planets: bad input ------------------------------------------------------------------

def _line(text: str, needle: str) -> int:
    return next(i + 1 for i, s in enumerate(text.splitlines()) if needle in s)


@pytest.mark.parametrize("old, new, needle, place, reason", [
    ("    planets: 3", "    planets: 1", "planets: 1", "joints[2].planets", "^expected at least 2, got 1$"),
    ("    planets: 3", "    planets: 2.5", "planets: 2.5", "joints[2].planets", "^expected a whole number, got 2.5$"),
    ("    planets: 3", "    planets: 100000", "planets: 100000", "joints[2].planets",
     "^expected at most 64, got 100000$"),
    ("    planets: 3", "    planets: 5", "planets: 5", "joints[2].planets",
     r"^5 equally spaced planets do not fit: \(z_sun \+ z_ring\) / N = 84/5 is not a whole number"),
    ("  - {name: motor, link: sun}", "  - {name: motor, link: planet}", "    planets: 3", "joints[2].planets",
     r"^planet link 'planet' cannot be used by motors\[0\]: only its joint on the carrier and its gear pairs "
     r"are copied$"),
    ("    parent: carrier\n    child: planet\n    origin: {xyz: [0.021, 0, -0.01]}\n    axis: [0, 0, 1]",
     "    parent: carrier\n    child: planet\n    dh: {d: -0.01, a: 0.021}", "    planets: 3", "joints[2].planets",
     r"^planets need a revolute joint given by origin/axis \(not dh\)$"),
    ("    parent: carrier\n    child: planet", "    parent: housing\n    child: planet", "    planets: 3",
     "joints[2].planets", r"^the planets' carrier 'housing' turns on no joint"),
])
def test_planets_bad_input(run_cli, tmp_path, bundled, old, new, needle, place, reason):
    assert bundled.count(old) == 1
    text = bundled.replace(old, new)
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2 and res.stdout == "" and "Traceback" not in res.stderr
    lines = res.stderr.splitlines()
    assert len(lines) == 1, lines
    prefix = f"{path}:{_line(text, needle)}: {place}: "
    assert lines[0].startswith(prefix), (lines[0], prefix)
    assert re.search(reason, lines[0][len(prefix):]), lines[0]


def test_planet_copy_error_points_at_the_original(run_cli, tmp_path, bundled):
    """A problem in a copied pair is reported at the pair the user wrote (its YAML path and
    line), naming the copy."""
    text = bundled.replace("    teeth: [18, 60]", "    teeth: [17, 60]")
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2
    lines = res.stderr.splitlines()
    assert lines and all(ln.startswith(f"{path}:{_line(text, '[17, 60]')}: gears[1].teeth: ") for ln in lines), lines


# --- another topology: a duplicated mesh (two pinions' worth of teeth on one pair of gears) ---------

@pytest.mark.parametrize("snippet", [
    '  - {name: "5-1b", links: ["5", "1"], ratio: -3.0, mesh_point: [0.09, 0, -0.05], stiffness: 3.0e8}\n',
    '  - {name: "5-1b", links: ["5", "1"], teeth: [20, 60], mesh_point: [0.09, 0, -0.06], stiffness: 3.0e8}\n',
])
def test_duplicated_mesh_splits_in_proportion_to_stiffness(mech_dir, snippet):
    """The paper's arm with a second mesh between gears 5 and 1 (at the same pitch point, or
    10 mm lower on the same teeth), stiffness 1e8 and 3e8 N/m: only the sum of the two
    tangential forces is fixed (the torques on 5 and 1 about their axes; the rest goes into
    the bearings), so t_b / t_a = k_b / k_a = 3 at every sample, whatever the motion and the
    sign of t (random states exercise the sign resolution of Eq. 14)."""
    text = (mech_dir / "paper_2dof.yaml").read_text()
    text = text.replace('    ratio: -3.0   ', '    stiffness: 1.0e8\n    ratio: -3.0   ', 1)
    an = analyse(parse_mechanism(text.replace("\nmotors:", "\n" + snippet + "motors:"), "dup.yaml"))
    assert an.dof == 2 and len(an.redundant) == 1
    a, b = gear_index(an, "5-1"), gear_index(an, "5-1b")
    rng = np.random.default_rng(3)
    q, qd, qdd = rng.uniform(-3, 3, (300, 2)), 3 * rng.normal(size=(300, 2)), 20 * rng.normal(size=(300, 2))
    blk = solve(an, q, qd, qdd, verify=True)
    full = solve(an, q, qd, qdd, method="full", verify=True)
    assert np.any(blk.gear_t[:, a] > 0) and np.any(blk.gear_t[:, a] < 0)
    close(blk.gear_t[:, b], 3.0 * blk.gear_t[:, a])
    for f in ("motor", "joint", "gear_t", "gear_sep"):
        close(getattr(blk, f), getattr(full, f), 1e-11)
    assert blk.residual < 1e-12 and full.residual < 1e-12


def test_stiffness_for_all_pairs_of_a_set_or_none(run_cli, tmp_path, bundled):
    text = bundled.replace("    stiffness: 3.5e8\n", "")
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2 and res.stdout == ""
    lines = res.stderr.splitlines()
    assert len(lines) == 1
    assert lines[0].startswith(f"{path}:{_line(text, 'name: planet-ring')}: gears[1]: gear pair 'planet-ring1' has "
                               "no stiffness but other pairs of its redundant gear set have: give stiffness for "
                               "every pair of the set ('sun-planet1' (gears[0]), "), lines[0]


def test_schedule_puts_the_excess_in_the_redundant_block(mech_dir):
    """Dulmage-Mendelsohn with more unknowns than equations: the blocks that do not hold a
    redundant set stay square, the redundant set's block has exactly G - rank(circuit rows)
    unknowns more than equations, and every unknown is solved once (checked from the
    equation incidence: unknowns of a block = those of its links not solved earlier)."""
    text = (mech_dir / "paper_2dof.yaml").read_text()
    text = text.replace("\nmotors:", '\n  - {name: "5-1b", links: ["5", "1"], ratio: -3.0, '
                        "mesh_point: [0.09, 0, -0.05]}\nmotors:")
    for an in (analyse(parse_mechanism(text, "dup.yaml")), analyse(load_mechanism(mech_dir / "planetary_3p.yaml"))):
        base = an.tree.base
        unknowns = [(f"joint {ji}", 5, {jt.parent, jt.child} - {an.mech.base}) for ji, jt in enumerate(an.mech.joints)]
        unknowns += [(f"mesh {ci}", 1, {an.names[c.j], an.names[c.k]} - {an.mech.base}) for ci, c in enumerate(an.circuits)]
        unknowns += [(f"motor {mi}", 1, {an.names[x], an.names[s]} - {an.names[base]})
                     for mi, (x, s) in enumerate(zip(an.motor_links, an.motor_stators))]
        rows = np.array([c.row for c in an.circuits])
        excess = len(an.circuits) - np.linalg.matrix_rank(rows, tol=1e-9)
        redundant_links = {an.names[x] for s in an.redundant for i in s for x in (an.circuits[i].j, an.circuits[i].k)}
        known, extra = set(), 0
        for block in (set(an.name_of(b)) for b in an.schedule):
            new = [(u, n) for u, n, links in unknowns if u not in known and links & block]
            more = sum(n for _, n in new) - 6 * len(block)
            assert more == 0 or (more > 0 and block & redundant_links), (block, more)
            extra += more
            known |= {u for u, _ in new}
        assert extra == excess == 1 + (an.mech.name == "planetary_3p")
        assert known == {u for u, _, _ in unknowns}


# --- a split-path drive: one pinion, two idlers, one output gear (all on the housing) -----------------

def split_path(k1: float, k2: float) -> str:
    """Pinion A (20 teeth, module 2 mm) drives gear C (30 teeth) through two idlers B1, B2
    (15 teeth) at +-60 degrees: two parallel paths A-Bi-C, stiffness k_i on both meshes of
    path i.  Gear C carries a resisting moment of 3 N*m (a load); no gravity."""
    rA, rB, rC = 0.02, 0.015, 0.03
    b = [np.array([np.cos(a), np.sin(a), 0.0]) * (rA + rB) for a in (np.pi / 3, -np.pi / 3)]
    xc = b[0][0] + np.sqrt((rB + rC) ** 2 - b[0][1] ** 2)
    c = np.array([xc, 0.0, 0.0])
    links = ["  - {name: H}"] + [f"  - {{name: {n}, mass: 0.1, inertia: [1.0e-5, 1.0e-5, 2.0e-5]}}" for n in "A B1 B2 C".split()]
    joints = [f"  - {{name: J{n}, parent: H, child: {n}, origin: {{xyz: {list(map(float, o))}}}}}"
              for n, o in (("A", np.zeros(3)), ("B1", b[0]), ("B2", b[1]), ("C", c))]
    gears = []
    for i, (bi, k) in enumerate(zip(b, (k1, k2))):
        pa = bi * rA / (rA + rB)
        pc = bi + (c - bi) * rB / (rB + rC)
        gears.append(f"  - {{name: A-B{i + 1}, links: [A, B{i + 1}], teeth: [20, 15], mesh_point: {list(map(float, pa))}, stiffness: {k}}}")
        gears.append(f"  - {{name: B{i + 1}-C, links: [B{i + 1}, C], teeth: [15, 30], mesh_point: {list(map(float, pc))}, stiffness: {k}}}")
    return ("name: split\ngravity: [0, 0, 0]\nbase: H\nend_effector: C\nlinks:\n" + "\n".join(links)
            + "\njoints:\n" + "\n".join(joints) + "\ngears:\n" + "\n".join(gears)
            + "\nmotors:\n  - {name: M, link: A}\nloads:\n  - {name: out, link: C, frame: base, moment: [0, 0, -3.0]}\n")


@pytest.mark.parametrize("k", [(1.0e8, 1.0e8), (1.0e8, 4.0e8)])
def test_split_path_drive_by_hand(k):
    """At rest: motor torque = 3 N*m x r_A / r_C = 2 N*m; each idler carries equal forces
    on its two meshes (its own torque balance), and the pinion's balance fixes their sum:
    t_1 + t_2 = 2 / r_A = 100 N, split t_i = 100 k_i / (k_1 + k_2) (min sum 2 t_i^2 / k_i)."""
    an = analyse(parse_mechanism(split_path(*k), "split.yaml"))
    assert an.dof == 1 and len(an.redundant) == 1
    z = np.zeros((1, 1))
    for method in ("block", "full"):
        res = solve(an, z, z, z, method=method, verify=True)
        assert res.residual < 1e-13
        assert res.motor[0, 0] == pytest.approx(2.0, rel=1e-12)
        for i in (0, 1):
            for pair in (f"A-B{i + 1}", f"B{i + 1}-C"):
                assert abs(res.gear_t[0, gear_index(an, pair)]) == pytest.approx(100 * k[i] / sum(k), rel=1e-12)
    q = np.linspace(-3, 3, 40)[:, None]
    blk = solve(an, q, 4 * np.cos(q), 30 * np.sin(3 * q), verify=True)
    full = solve(an, q, 4 * np.cos(q), 30 * np.sin(3 * q), method="full", verify=True)
    close(blk.gear_t, full.gear_t, 1e-11)
    close(blk.joint, full.joint, 1e-11)
    assert blk.residual < 1e-13


def test_urdf_mimic_gear_stiffness(mech_dir, tmp_path):
    """stiffness is read from a gearcli:gear inside a <joint> with <mimic> too."""
    text = (mech_dir / "geared_arm.urdf").read_text()
    assert text.count('<gearcli:gear name="pinion-shoulder"') == 1
    path = tmp_path / "arm.urdf"
    path.write_text(text.replace('<gearcli:gear name="pinion-shoulder"', '<gearcli:gear name="pinion-shoulder" stiffness="2.5e8"'))
    mech = load_mechanism(path)
    assert [g.stiffness for g in mech.gears if g.name == "pinion-shoulder"] == [2.5e8]


@pytest.mark.parametrize("value", ["0", "-5"])
def test_bad_stiffness_of_a_planet_pair_is_reported_once(run_cli, tmp_path, bundled, value):
    """The three copies of 'sun-planet' printed the same line three times."""
    text = bundled.replace("stiffness: 3.0e8", f"stiffness: {value}")
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2
    assert res.stderr.splitlines() == [f"{path}:{_line(text, 'stiffness: ' + value)}: gears[0].stiffness: mesh "
                                       f"stiffness must be positive, got {value} N/m"]


def test_a_wrong_ring_tooth_count_reports_every_problem(run_cli, tmp_path, bundled):
    """Ring 61 teeth instead of 60: the planets' equal spacing does not fit and the ring's
    tooth ratio contradicts its mesh radius; `check` reports both (it reported only the first,
    issue 34, section 3), `solve` and `verify` as well, and the library raises as before."""
    import gearcli
    from gearcli.errors import MechanismError
    assert bundled.count("    teeth: [18, 60]") == 1
    text = bundled.replace("    teeth: [18, 60]", "    teeth: [18, 61]")
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    res = run_cli("check", path)
    assert res.exit_code == 2 and res.stdout == "" and "Traceback" not in res.stderr
    lines = res.stderr.splitlines()
    assert lines == [
        f"{path}:{_line(text, '    planets: 3')}: joints[2].planets: 3 equally spaced planets do not fit: "
        "(z_sun + z_ring) / N = 85/3 is not a whole number (the planets' teeth cannot mesh the sun and the ring at "
        "every position)",
        f"{path}:{_line(text, 'teeth: [18, 61]')}: gears[1].teeth: tooth counts 18:61 give |ratio| 3.38889, but the "
        "mesh geometry gives 3.33333"]
    traj = tmp_path / "t.csv"
    traj.write_text("t,q:JC\n0,0\n1,1\n")
    res = run_cli("solve", path, traj, "-o", tmp_path / "o.csv")
    assert res.exit_code == 2 and res.stderr.splitlines() == lines and not (tmp_path / "o.csv").exists()
    with pytest.raises(MechanismError) as exc:
        gearcli.load_mechanism(path)
    assert [str(i) for i in exc.value.issues] == lines[:1]
