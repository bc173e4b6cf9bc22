"""gearcli select (issue 37): one part per slot from catalogues, every check passing, least
total mass.  The choice is checked against brute force: every combination written out by
hand (text edits of the mechanism file) and verified with plain ``gearcli verify``.  The
catalogues here are test data, written for these tests (their source column says so)."""
from __future__ import annotations

import itertools
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MECH = ROOT / "mechanisms" / "paper_2dof_rated.yaml"
RATING = "    rating: {peak_torque: 16.0, rms_torque: 9.5, max_speed: 30, max_power: 200, thermal_window: 1.0}\n"
FOREARM = '  - name: "2"                     # forearm; frame at the wrist\n    mass: 2.5\n'
MOTORS = [("M-S", 1.0, 12, 7, 30, 150), ("M-M", 1.4, 13.5, 9.5, 30, 200), ("M-L", 2.0, 16, 11, 30, 250),
          ("M-XL", 3.0, 22, 14, 30, 300)]
SLOTS = """slots:
  - name: motor5
    catalogue: motors.csv
    set: {peak_torque: motors.motor5.rating.peak_torque, rms_torque: motors.motor5.rating.rms_torque,
          max_speed: motors.motor5.rating.max_speed, max_power: motors.motor5.rating.max_power}
  - name: tool
    catalogue: tools.csv
    add: {mass: links.2.mass}
"""


def _catalogues(tmp: Path, motors=MOTORS, tools=(("T-0", 0.0), ("T-3", 0.3))) -> None:
    rows = ["name,source,mass,peak_torque,rms_torque,max_speed,max_power"]
    rows += [f"{n},test data for tests/test_select.py,{m},{p},{r},{s},{w}" for n, m, p, r, s, w in motors]
    (tmp / "motors.csv").write_text("\n".join(rows) + "\n")
    (tmp / "tools.csv").write_text("name,source,mass\n" + "".join(f"{n},test data,{m}\n" for n, m in tools))


def _design(tmp: Path, slots: str = SLOTS, mech: Path = MECH) -> Path:
    text = (ROOT / "designs" / "paper_arm_duty.yaml").read_text()
    text = text.replace("../mechanisms/paper_2dof_rated.yaml", str(mech))
    text = text.replace("../mechanisms/paper_2dof_traj.csv", str(ROOT / "mechanisms" / "paper_2dof_traj.csv"))
    (tmp / "d.yaml").write_text(text + slots)
    return tmp / "d.yaml"


def _by_hand(run_cli, tmp: Path, motor, tool_mass) -> bool:
    """Plain gearcli verify of the mechanism file edited by hand for this combination."""
    n, _, p, r, s, w = motor
    text = MECH.read_text()
    assert RATING in text and FOREARM in text
    text = text.replace(RATING, RATING.replace("peak_torque: 16.0, rms_torque: 9.5, max_speed: 30, max_power: 200",
                                               f"peak_torque: {p}, rms_torque: {r}, max_speed: {s}, max_power: {w}"))
    text = text.replace(FOREARM, FOREARM.replace("mass: 2.5", f"mass: {2.5 + tool_mass!r}"))
    d = tmp / f"{n}_{tool_mass}"
    d.mkdir()
    (d / "m.yaml").write_text(text)
    design = _design(d, "", d / "m.yaml")
    return run_cli("verify", design, "-j", "1").exit_code == 0


def test_the_choice_is_the_lightest_that_plain_verify_passes(run_cli, tmp_path):
    _catalogues(tmp_path)
    table = tmp_path / "ranked.csv"
    r = run_cli("select", _design(tmp_path), "--table", table)
    assert r.exit_code == 0, r.stderr
    feasible = {}
    for motor, (tool, mass) in itertools.product(MOTORS, (("T-0", 0.0), ("T-3", 0.3))):
        if _by_hand(run_cli, tmp_path, motor, mass):
            feasible[(motor[0], tool)] = motor[1] + mass
    best = min(feasible, key=feasible.get)
    assert f"chosen: motor5 = {best[0]}, tool = {best[1]}: total mass {feasible[best]:.6g}" in r.stdout
    assert f"8 combinations of 2 slots: {len(feasible)} feasible" in r.stdout
    rows = [ln.split(",") for ln in table.read_text().splitlines()]
    assert rows[0][:4] == ["rank", "motor5", "tool", "total_mass"]
    shown = {(row[1], row[2]) for row in rows[1:] if row[6] == "true"}
    assert shown == set(feasible)
    masses = [float(row[3]) for row in rows[1:] if row[6] == "true"]
    assert masses == sorted(masses)                 # feasible first, lightest first


def test_a_heavier_outer_part_changes_the_inner_joints_choice(run_cli, tmp_path):
    """The tool sits on the forearm (outer); motor 5 drives the upper arm (inner).  With the
    light tool the 13.5 N*m motor suffices; the 0.3 kg tool raises motor 5's peak torque past
    it and the choice moves to the 16 N*m one, each combination verified with its own loads."""
    chosen = {}
    for tools in ((("T-0", 0.0),), (("T-3", 0.3),)):
        d = tmp_path / tools[0][0]
        d.mkdir()
        _catalogues(d, tools=tools)
        r = run_cli("select", _design(d))
        assert r.exit_code == 0, r.stderr
        chosen[tools[0][0]] = r.stdout.split("chosen: motor5 = ", 1)[1].split(",", 1)[0]
    assert chosen == {"T-0": "M-M", "T-3": "M-L"}


def test_the_chosen_design_is_written_and_verify_passes_it(run_cli, tmp_path):
    _catalogues(tmp_path, tools=(("T-3", 0.3),))
    out = tmp_path / "chosen"
    r = run_cli("select", _design(tmp_path), "-o", out, "--plot", tmp_path / "pareto.png")
    assert r.exit_code == 0, r.stderr
    mech, design = out / MECH.name, out / "d.yaml"
    assert mech.is_file() and design.is_file() and (tmp_path / "pareto.png").read_bytes()[:4] == b"\x89PNG"
    js = tmp_path / "v.json"
    v = run_cli("verify", design, "--json", js, "-j", "1")
    assert v.exit_code == 0, v.stdout + v.stderr
    import yaml
    data = yaml.safe_load(mech.read_text())
    assert next(m for m in data["motors"] if m["name"] == "motor5")["rating"]["peak_torque"] == 16
    assert next(L for L in data["links"] if L["name"] == "2")["mass"] == pytest.approx(2.8)
    assert "slots" not in yaml.safe_load(design.read_text())
    assert len(json.loads(js.read_text())["checks"]) == 42


def test_nothing_feasible_shows_the_closest_and_what_fails_them(run_cli, tmp_path):
    _catalogues(tmp_path, motors=MOTORS[:1])
    out = tmp_path / "chosen"
    r = run_cli("select", _design(tmp_path), "-o", out)
    assert r.exit_code == 1
    assert "0 feasible" in r.stdout and "no combination passes every check; the closest:" in r.stdout
    assert "motor5 = M-S, tool = T-0: worst margin" in r.stdout and "motor motor5: peak torque" in r.stdout
    assert not out.exists()


@pytest.mark.parametrize("motors, tools, slots, said", [
    ("name,source,mass,peak_torque\nA,x,1,twelve\n", None, None, "motors.csv:2: column 'peak_torque': expected a number"),
    ("name,mass\nA,1\n", None, None, "motors.csv:1: no 'source' column"),
    ("name,source,mass\nA,x,1\nA,x,2\n", None, None, "motors.csv:3: part 'A' twice (first on line 2)"),
    ("name,source,mass\nA,,1\n", None, None, "motors.csv:2: column 'source': empty"),
    ("name,source,mass\nA,x,-1\n", None, None, "motors.csv:2: column 'mass': expected at least 0"),
    (None, "name,source\nT,x\n", None, "has no number column 'mass'"),
    (None, None, SLOTS.replace("links.2.mass", "links.forearm.mass"), "no link named 'forearm'"),
    (None, None, SLOTS.replace("motors.csv", "nowhere.csv"), "nowhere.csv: cannot read the catalogue"),
    (None, None, "", "no slots"),
    (None, None, SLOTS.replace("    add: {mass: links.2.mass}\n", ""), "slots[1]: give set or add (or both)"),
    (None, None, SLOTS.replace("add: {mass: links.2.mass}", "add: {mass: []}"),
     "slots[1].add.mass: expected a path of the mechanism files (e.g. links.arm.mass) or a list of such paths"),
    (None, None, SLOTS.replace("add: {mass: links.2.mass}", "add: {mass: [links.2.mass, links.2.mass]}"),
     "slots[1].add.mass: 'links.2.mass' is listed twice"),
    (None, None, SLOTS.replace("add: {mass: links.2.mass}", "set: {mass: motors.motor5.rating.peak_torque}"),
     "slots[1].set.mass: 'motors.motor5.rating.peak_torque' is also set by slots[0].set.peak_torque"),
    (None, None, SLOTS.replace("add: {mass: links.2.mass}", "add: {mass: motors.motor5.rating.max_power}"),
     "slots[1].add.mass: 'motors.motor5.rating.max_power' is also set by slots[0].set.max_power"),
])
def test_bad_catalogues_and_slots_are_located(run_cli, tmp_path, motors, tools, slots, said):
    _catalogues(tmp_path)
    if motors is not None:
        (tmp_path / "motors.csv").write_text(motors)
    if tools is not None:
        (tmp_path / "tools.csv").write_text(tools)
    out = tmp_path / "chosen"
    r = run_cli("select", _design(tmp_path, SLOTS if slots is None else slots), "-o", out)
    assert r.exit_code == 2 and said in r.stderr, r.stderr
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr and not out.exists()


def test_a_slot_path_and_the_objective_are_checked(run_cli, tmp_path):
    _catalogues(tmp_path)
    d = _design(tmp_path)
    r = run_cli("select", d, "--objective", "cost")
    assert r.exit_code == 2 and "motors.csv:2: part 'M-S' has no 'cost'" in r.stderr
    r = run_cli("select", d, "--objective", "beauty")
    assert r.exit_code == 2 and "--objective: expected one of mass, cost, inertia" in r.stderr
    slots = SLOTS.replace("links.2.mass", "links.2.inertia")
    r = run_cli("select", _design(tmp_path, slots))
    assert r.exit_code == 2 and "slots[1].add.mass" in r.stderr and "is a list in the file, not a number" in r.stderr


def test_the_bundled_bearing_catalogue_and_the_slot_conditions(run_cli, tmp_path):
    """catalogues/skf_deep_groove_60.csv reads (9 parts, each cited; 6001's ratings are the
    tutorial's elbow bearings'), and a slot's match/at_least keep the parts that fit: on the
    12 mm elbow shaft only the 6001 is considered, so select chooses it for both bearings; a
    condition no part meets is a located error."""
    from gearcli.batch.select import read_catalogue
    cat = ROOT / "catalogues" / "skf_deep_groove_60.csv"
    parts = read_catalogue(cat)
    assert len(parts) == 9 and all("SKF" in p.source for p in parts)
    by = {p.name: p.values for p in parts}
    assert (by["6001"]["bore"], by["6001"]["C"], by["6001"]["C0"]) == (0.012, 5400, 2360)
    assert "C: 5400, C0: 2360" in (ROOT / "docs" / "examples" / "geared_joint.yaml").read_text()
    bores = [p.values["bore"] for p in parts]
    assert bores == sorted(bores) and [p.values["C"] for p in parts] == sorted(p.values["C"] for p in parts)
    design = (ROOT / "docs" / "examples" / "geared_joint_design.yaml").read_text()
    design = design.replace("geared_joint.yaml", str(ROOT / "docs" / "examples" / "geared_joint.yaml"))
    design = design.replace("geared_joint_traj.csv", str(ROOT / "docs" / "examples" / "geared_joint_traj.csv"))
    slots = "slots:\n" + "".join(
        f"  - name: {b}\n    catalogue: {cat}\n    set: {{C: joints.Je.bearings.{b}.C, C0: joints.Je.bearings.{b}.C0}}\n"
        f"    match: {{bore: 0.012}}\n    at_least: {{C0: 1000}}\n" for b in ("near", "far"))
    (tmp_path / "d.yaml").write_text(design + slots)
    r = run_cli("select", tmp_path / "d.yaml")
    assert r.exit_code == 0, r.stderr
    assert "1 combination of 2 slots: 1 feasible" in r.stdout and "chosen: near = 6001, far = 6001" in r.stdout
    (tmp_path / "d.yaml").write_text(design + slots.replace("bore: 0.012", "bore: 0.013", 1))
    r = run_cli("select", tmp_path / "d.yaml")
    assert r.exit_code == 2 and "slots[0].match.bore: no part of" in r.stderr and "has bore = 0.013" in r.stderr


def test_an_empty_slot_mapping_is_worded_by_gearcli(run_cli, tmp_path):
    _catalogues(tmp_path)
    r = run_cli("select", _design(tmp_path, SLOTS.replace("add: {mass: links.2.mass}", "add: {}")))
    assert r.exit_code == 2 and "slots[1].add: must not be empty (give at least one column)" in r.stderr, r.stderr


def test_the_iterative_search_reaches_the_same_choice_here(run_cli, tmp_path):
    """--search iterate (slot by slot from the most capable parts, each candidate verified with
    its own loads) on the small case: the exhaustive search's choice, verifying fewer
    combinations; its ranked table holds only those it verified."""
    _catalogues(tmp_path)
    d = _design(tmp_path)
    full = run_cli("select", d, "--search", "exhaustive")
    it = run_cli("select", d, "--search", "iterate", "--table", tmp_path / "it.csv")
    assert full.exit_code == 0 and it.exit_code == 0, it.stderr
    pick = (lambda out: out.split("chosen: ", 1)[1].split(":", 1)[0])
    assert pick(it.stdout) == pick(full.stdout)
    n = len((tmp_path / "it.csv").read_text().splitlines()) - 1
    assert f"{n} of 8 combinations of 2 slots verified by the iterative search" in it.stdout and n <= 8


def test_iterate_descends_and_stops(monkeypatch):
    """The search on a feasibility given by hand: it starts from the heaviest parts, takes the
    lightest feasible part slot by slot, and stops where no one-slot change is lighter (here
    (1, 0): (0, 0) would be lighter but fails, and (0, 1) too)."""
    from gearcli.batch.select import Part, Slot, iterate
    slots = tuple(Slot(n, Path("x.csv"), tuple(Part(f"{n}{k}", "test", {"mass": float(k + 1)}, k + 2)
                                                for k in range(3)), ()) for n in "ab")
    ok = {(1, 0), (2, 0), (2, 1), (2, 2), (1, 1), (1, 2)}
    seen = []

    def evaluate(combos):
        seen.extend(combos)
        return [[("c", "x", "q", "", 0.0, 1.0, 1.0 if c in ok else -1.0, c in ok)] for c in combos]
    verified, choice = iterate(slots, "mass", evaluate)
    assert choice == (1, 0) and seen[0] == (0, 2) and len(seen) == len(set(seen)) == len(verified)


def test_iterate_climbs_to_a_passing_choice_when_the_most_capable_parts_fail(monkeypatch):
    """The most capable (heaviest) part can fail a check a smaller one passes (a large motor's
    speed): from a failing start the search takes, slot by slot, the part that most reduces
    the summed shortfall of the failing checks, and once a choice passes it descends as
    before.  Here the heaviest parts (2, 2) fail two checks; slot a's part 1 fixes one,
    slot b's part 0 the other; no one-slot change from the start passes."""
    from gearcli.batch.select import Part, Slot, iterate
    slots = tuple(Slot(n, Path("x.csv"), tuple(Part(f"{n}{k}", "test", {"mass": float(k + 1)}, k + 2)
                                                for k in range(3)), ()) for n in "ab")

    def checks(c):
        a_ok, b_ok = c[0] != 2, c[1] == 0
        return [("c", "x", "speed a", "", 0.0, 1.0, 5.0 if a_ok else -10.0 - c[0], a_ok),
                ("c", "x", "speed b", "", 0.0, 1.0, 5.0 if b_ok else -10.0 - c[1], b_ok)]
    verified, choice = iterate(slots, "mass", lambda combos: [checks(c) for c in combos])
    assert choice == (0, 0) and all(r[0][7] and r[1][7] for c, r in verified.items() if c == choice)


def test_a_slot_column_onto_several_numbers(run_cli, tmp_path):
    """One catalogue column onto a list of paths: the part's value goes to each (here the
    tool's mass added to both the forearm and the upper arm: the choice's loads rise as the
    sum says); a bad path in the list is located by the column."""
    from gearcli.batch.manifest import load_manifest
    from gearcli.batch.select import prepare, slots_of
    from gearcli.batch.sweep import variant_data
    _catalogues(tmp_path)
    d = _design(tmp_path, SLOTS.replace("add: {mass: links.2.mass}", "add: {mass: [links.2.mass, links.1.mass]}"))
    m = load_manifest(d)
    slots = slots_of(m)
    varies = prepare(m, slots, "mass")
    assert [v.path for v in varies][-2:] == ["links.2.mass", "links.1.mass"]
    data = variant_data(m, varies, (12, 7, 30, 150, 0.3, 0.3))[m.cases[0].name]
    base = variant_data(m, (), ())[m.cases[0].name]
    by = {str(link["name"]): link for link in data["links"]}
    was = {str(link["name"]): link for link in base["links"]}
    assert by["2"]["mass"] == pytest.approx(was["2"]["mass"] + 0.3) and by["1"]["mass"] == pytest.approx(was["1"]["mass"] + 0.3)
    r = run_cli("select", _design(tmp_path, SLOTS.replace("add: {mass: links.2.mass}",
                                                          "add: {mass: [links.2.mass, links.9.mass]}")))
    assert r.exit_code == 2 and "slots[1].add.mass" in r.stderr and "no link named '9'" in r.stderr
