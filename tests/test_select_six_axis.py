"""gearcli select on the bundled six-axis strain-wave arm with the bundled catalogues (issue
37): every joint's motor and strain-wave unit chosen, the choice checked by plain ``gearcli
verify`` and against every lighter (motor, unit) pair of each joint; the catalogues' rows
agree with the bundled mechanisms that quote the same catalogue; and the data kernel that
solves the candidates (ratings and masses varied, a payload carried) equals the numpy path."""
from __future__ import annotations

import csv
import math
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
CATALOGUES = ROOT / "catalogues"
DESIGN = ROOT / "designs" / "cobot_6axis_select.yaml"


def _rows(name: str) -> dict[str, dict]:
    from gearcli.batch.select import read_catalogue
    return {p.name: p.values for p in read_catalogue(CATALOGUES / name)}


def test_every_bundled_catalogue_reads_and_cites_each_row():
    """Each catalogue file reads (schemas/catalogue.schema.json), has at least 8 parts, each
    row naming its vendor, document and the caveat of a transcription, and is listed in
    catalogues/README.md."""
    from gearcli.batch.select import read_catalogue
    vendors = {"skf_deep_groove_60.csv": "SKF", "harmonic_drive_csf_2uh.csv": "Harmonic Drive",
               "nabtesco_rv_e.csv": "Nabtesco", "thk_rb_crossed_roller.csv": "THK", "robodrive_ilm.csv": "TQ-RoboDrive"}
    files = sorted(p.name for p in CATALOGUES.glob("*.csv"))
    assert files == sorted(vendors)
    readme = (CATALOGUES / "README.md").read_text()
    for name, vendor in vendors.items():
        parts = read_catalogue(CATALOGUES / name)
        assert len(parts) >= 8, name
        assert all(vendor in p.source and "catalogue" in p.source.lower() or "datasheet" in p.source
                   for p in parts), name
        assert all("check against the current" in p.source for p in parts), name
        assert all(p.name.removesuffix("-2UH") in p.source or "series table" in p.source for p in parts), name
        assert f"`{name}`" in readme


def test_the_catalogue_rows_agree_with_the_mechanisms_that_quote_them():
    """The CSF-25-100 and CSF-14-100 rows hold the ratings and crossed-roller data that
    cobot_joint.yaml and cobot_joint_csf14.yaml quote, the RV-40E-121 row rv_turret.yaml's
    (speeds in rad/s from the catalogue's rpm)."""
    hd, rv = _rows("harmonic_drive_csf_2uh.csv"), _rows("nabtesco_rv_e.csv")
    for row, mech in (("CSF-25-100-2UH", "cobot_joint.yaml"), ("CSF-14-100-2UH", "cobot_joint_csf14.yaml")):
        data = yaml.safe_load((ROOT / "mechanisms" / mech).read_text())
        rating = data["gears"][0]["rating"]
        bearing = [b for j in data["joints"] for b in j.get("bearings", [])][0]
        r = hd[row]
        for key in ("rated_torque", "repeated_peak_torque", "average_torque_limit", "rated_life"):
            assert r[key] == rating[key], (row, key)
        for key in ("rated_input_speed", "max_input_speed", "average_input_speed_limit"):
            assert r[key] == pytest.approx(rating[key], abs=0.05), (row, key)
        assert (r["bearing_C"], r["bearing_C0"], r["bearing_pitch_diameter"]) == (
            bearing["C"], bearing["C0"], bearing["pitch_diameter"])
    rating = yaml.safe_load((ROOT / "mechanisms" / "rv_turret.yaml").read_text())["gears"][0]["rating"]
    r = rv["RV-40E-121"]
    assert (r["rated_torque"], r["repeated_peak_torque"], r["rated_life"]) == (412, 1029, 6000)
    assert r["rated_torque"] == rating["rated_torque"] and r["repeated_peak_torque"] == rating["repeated_peak_torque"]
    assert r["rated_input_speed"] == pytest.approx(rating["rated_input_speed"], abs=0.01)
    assert r["max_input_speed"] == pytest.approx(rating["max_input_speed"], abs=0.05)


def _chosen(stdout: str) -> dict[str, str]:
    line = stdout.split("chosen: ", 1)[1].split("\n", 1)[0]
    return dict(item.split(" = ") for item in line.rsplit(": total", 1)[0].split(", "))


def test_the_six_axis_arm_gets_the_lightest_motor_and_unit_of_every_joint(run_cli, tmp_path):
    """designs/cobot_6axis_select.yaml: 12 slots (a motor and a strain-wave unit per joint)
    from the bundled catalogues.  The search chooses a design that plain ``gearcli verify``
    passes, and for every joint no lighter (motor, unit) pair passes with the other joints as
    chosen (each such pair verified here, outside the search): the lightest feasible motor
    and unit of every joint.  The shoulder (joint 2, the largest torques) takes a larger
    unit than the wrist.  (-j 2: one pool of workers serves every round of the search.)"""
    from gearcli.batch.manifest import load_manifest
    from gearcli.batch.select import plan_of, prepare, slots_of
    from gearcli.batch.sweep import run_sweep
    r = run_cli("select", DESIGN, "-o", tmp_path / "chosen", "--table", tmp_path / "ranked.csv",
                "--plot", tmp_path / "pareto.png", "-j", "2")
    assert r.exit_code == 0, r.stderr
    chosen = _chosen(r.stdout)
    assert len(chosen) == 12 and (tmp_path / "pareto.png").stat().st_size > 0
    v = run_cli("verify", tmp_path / "chosen" / "cobot_6axis_select.yaml", "-j", "1")
    assert v.exit_code == 0, v.stdout[-2000:]
    m = load_manifest(DESIGN)
    slots = slots_of(m)
    index = {s.name: {p.name: k for k, p in enumerate(s.parts)} for s in slots}
    combo = [index[s.name][chosen[s.name]] for s in slots]
    mass = {s.name: [p.values["mass"] for p in s.parts] for s in slots}
    lighter = []
    for j in range(1, 7):
        a, b = slots[2 * j - 2], slots[2 * j - 1]
        here = mass[a.name][combo[2 * j - 2]] + mass[b.name][combo[2 * j - 1]]
        for ka in range(len(a.parts)):
            for kb in range(len(b.parts)):
                if mass[a.name][ka] + mass[b.name][kb] < here - 1e-12:
                    c = list(combo)
                    c[2 * j - 2], c[2 * j - 1] = ka, kb
                    lighter.append(tuple(c))
    assert len(lighter) > 20
    results = run_sweep(plan_of(m, prepare(m, slots, "mass"), slots, lighter))
    passing = [c for c, res in zip(lighter, results) if not isinstance(res, str) and all(x[7] for x in res)]
    assert passing == []
    sizes = {s: int(chosen[s].split("-")[1]) for s in ("reducer2", "reducer5")}
    assert sizes["reducer2"] > sizes["reducer5"]
    rows = list(csv.DictReader((tmp_path / "ranked.csv").open()))
    assert rows[0]["feasible"] == "true" and math.isfinite(float(rows[0]["largest_inertia_ratio"]))


def test_the_data_kernel_solves_rated_and_carried_variants_as_the_numpy_path(monkeypatch):
    """A candidate of the six-axis selection changes ratings (read by the checks alone) and
    links' masses and inertias, and its trajectory carries a payload: the data kernel solves
    it (one compile), group by group of the payloads carried, with the motors' inertia
    (the inertia-ratio checks) from the mass matrix's columns solved on the kernel.  Every
    check value equals the numpy path's (the variant's mechanism analysed afresh) to 1e-11."""
    import gearcli.batch.sweep as sweep
    from gearcli.batch.select import prepare, slots_of, values_of_combo
    m = sweep._manifest(str(DESIGN))
    slots = slots_of(m)
    varies = prepare(m, slots, "mass")
    assert sweep.data_kernel_applies(varies)
    assert not sweep.data_kernel_applies([sweep.parse_vary("joints.J2.origin.xyz[0]=0.1")])
    assert not sweep.data_kernel_applies([sweep.parse_vary("joints.J2.bearings.xrb.position=0.01")])
    assert sweep.data_kernel_applies([sweep.parse_vary("joints.J2.bearings.xrb.C0=3e4")])
    combos = [tuple(0 for _ in slots), tuple(len(s.parts) // 2 for s in slots)]
    kernel = [sweep.run_variant(str(DESIGN), varies, values_of_combo(slots, c)) for c in combos]
    monkeypatch.setattr(sweep, "data_kernel_applies", lambda v: False)
    numpy = [sweep.run_variant(str(DESIGN), varies, values_of_combo(slots, c)) for c in combos]
    ratios = 0
    for a, b in zip(kernel, numpy):
        assert [x[:4] for x in a] == [x[:4] for x in b]
        for x, y in zip(a, b):
            assert x[4] == pytest.approx(y[4], rel=1e-11, abs=1e-300), x[:3]
            assert x[7] == y[7]
            ratios += x[2] == "inertia ratio"
    assert ratios == 12
