"""Property-based fuzzing of ``gearcli sweep`` and ``gearcli select`` (in-process CLI): random
``--vary`` texts (valid paths and junk, values non-finite, huge, malformed, ranges) on the
rated Bendix wrist's design, and byte-mutated catalogues and slots of a select design.  Every
run must give exit 0, 1 (select: nothing feasible) or 2, never a traceback or a hang, at least
one line on stderr on status 2 with no table or design written, and no stray file; the inputs
unchanged.  Profiles and recording are those of :mod:`test_fuzz` (``GEARCLI_FUZZ=long``)."""
from __future__ import annotations

import tempfile
from pathlib import Path

import pytest

pytest.importorskip("hypothesis")
from hypothesis import given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from test_fuzz import MECH_DIR, NASTY_NUMBERS, apply, few, mutation, problems, run_cli, short_csv, verdict  # noqa: E402

DESIGN = (Path(__file__).resolve().parents[1] / "designs" / "ci_example.yaml").read_text()
PATHS = ["links.3.mass", "links.3.com[0]", "links.3.inertia.izz", "links.3.inertia", "links.9.mass", "links.3",
         "gears.4-1.teeth[0]", "joints.J1.bearings.lower.C", "joints.J1.bearings.lower.position", "motors",
         "gravity[2]", "gravity[9]", "name", "payloads.x.mass",
         "wrist_motion:links.3.mass", "x:links.3.mass", "", ".", "links..mass", "links.3.mass[0]", "loads.x.force[2]"]
VALUES = ["1", "0.5,1", "0:1:3", "log:0.1:1:3", "-1", "0", "1e300", "nan", "inf", "1:2", "log:0:1:2", "1:2:0",
          "1:2:1e9", "a,b", "", ",", "1,,2", "1e999", "0x10"] + [v.decode() for v in NASTY_NUMBERS if v]


def _files() -> dict:
    design = DESIGN.replace("../mechanisms/bendix_wrist_rated.yaml", "mech.yaml")
    design = design.replace("../mechanisms/bendix_wrist_traj.csv", "traj.csv")
    return {"design.yaml": design.encode(), "mech.yaml": (MECH_DIR / "bendix_wrist_rated.yaml").read_bytes(),
            "traj.csv": short_csv("bendix_wrist_traj.csv", 40)}


def _run(target: str, files: dict, args_of) -> None:
    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        work = Path(d)
        for name, data in files.items():
            (work / name).write_bytes(data)
        result, hung = run_cli(args_of(work))
        if not hung and result.exit_code == 1 and target == "select":
            result.exit_code = 0          # nothing feasible: a verdict, not a failure
        verdict(target, problems(result, hung, work, files, {"out.csv", "chosen"}), files,
                None if hung else result.exit_code)


@few(20)
@given(varies=st.lists(st.tuples(st.sampled_from(PATHS), st.sampled_from(VALUES)), min_size=1, max_size=3),
       samples=st.one_of(st.none(), st.integers(-1, 5)))
def test_fuzz_sweep_vary(varies, samples):
    def args(work):
        out = ["sweep", work / "design.yaml", "-o", work / "out.csv"]
        for p, v in varies:
            out += ["--vary", f"{p}={v}"]
        return out + (["--samples", str(samples)] if samples is not None else [])
    _run("sweep", _files(), args)


CATALOGUE = b"name,source,mass,C,C0\nA,test data,0.05,4490,2900\nB,test data,0.08,6000,4000\n"
SLOTS = b"""slots:
  - name: lower
    catalogue: parts.csv
    set: {C: joints.J1.bearings.lower.C, C0: joints.J1.bearings.lower.C0}
    add: {mass: [links.3.mass, links.2.mass]}
    at_least: {C0: 100}
"""


@few(20)
@given(muts=st.lists(mutation(), min_size=1, max_size=3), where=st.sampled_from(["catalogue", "slots"]))
def test_fuzz_select_catalogues_and_slots(muts, where):
    files = _files()
    catalogue, slots = CATALOGUE, SLOTS
    for m in muts:
        if where == "catalogue":
            catalogue = apply(catalogue, m)
        else:
            slots = apply(slots, m)
    files["design.yaml"] += b"\n" + slots
    files["parts.csv"] = catalogue
    _run("select", files, lambda work: ["select", work / "design.yaml", "-o", work / "chosen"])
