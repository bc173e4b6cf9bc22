"""Fuzzing of this session's inputs (issue 34, section 5: the fuzz profile covers the new
inputs): ``simulate`` options and drive inputs (with ``attach:`` columns), stick-slip friction
keys (``static``), ``payloads:`` and the ``attach:`` columns of a trajectory, mutated byte-wise
and field by field.  The promises of :mod:`test_fuzz` hold (no traceback, no hang, exit 0 or
2 with a message, no stray or non-finite output, inputs unchanged), and ``simulate`` may also
stop early with exit 1 when it says so and has written the trajectory up to there."""
from __future__ import annotations

import re
import tempfile
from pathlib import Path

import pytest

pytest.importorskip("hypothesis")
from hypothesis import given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from test_fuzz import MECH_DIR, NASTY_NUMBERS, apply, few, mutations, problems, run_cli, verdict  # noqa: E402

ARM = b"""name: arm
gravity: [0, 0, -9.81]
base: frame
end_effector: arm
links:
  - name: frame
  - {name: arm, mass: 2.0, com: [0.2, 0, 0], inertia: [0.001, 0.03, 0.03]}
joints:
  - {name: J, parent: frame, child: arm, axis: [0, -1, 0], friction: {coulomb: 0.5, static: 0.8, viscous: 0.01}}
motors:
  - {name: m, link: arm}
payloads:
  - {name: box, link: arm, mass: 1.5, com: [0.4, 0, 0], inertia: [0.002, 0.002, 0.002]}
"""
ARM_INPUT = b"t,motor:m,attach:box\n0,5,0\n0.05,5,1\n0.1,9.5,1\n0.15,4,0\n0.2,4,0\n"
PICK = b"t,q:J,attach:box\n" + b"".join(f"{i / 100!r},{0.5 * i / 100!r},{int(3 <= i < 7)}\n".encode()
                                         for i in range(11))
FIELDS = [b"static", b"coulomb", b"viscous", b"mass", b"com", b"inertia", b"link", b"name"]
VALUES = [b"0", b"-1", b"0.1", b"0.5", b"1e9", b"1e-300", b".nan", b"x", b"[]", b"[0, 0, 0]", b"arm", b"frame",
          b"box", b"null", b"{}", b"[1, 2]"]
OPTIONS = [[], ["--t-end", "0.1"], ["--t-end", "1e-12"], ["--t-end", "-1"], ["--dt", "1e300"], ["--dt", "0"],
           ["--dt", "1e-4"], ["--rtol", "1e-300"], ["--rtol", "1e-12"], ["--method", "Radau"], ["--method", "x"],
           ["--q0", "0.3"], ["--q0", "1,2"], ["--qd0", "nan"], ["--atol", "inf"]]


@st.composite
def field_mutation(draw):
    return draw(st.sampled_from(FIELDS)), draw(st.integers(0, 1 << 30)), draw(
        st.one_of(st.sampled_from(VALUES), st.sampled_from(NASTY_NUMBERS)))


def apply_any(data: bytes, m) -> bytes:
    if isinstance(m[0], bytes):
        key, a, blob = m
        hits = list(re.finditer(rb"(?<![A-Za-z_])" + key + rb":\s*(\[[^\]\n]*\]|[^,}\n#]+)", data))
        if not hits:
            return data
        h = hits[a % len(hits)]
        return data[:h.start(1)] + blob + data[h.end(1):]
    return apply(data, m)


any_mutations = st.lists(st.one_of(st.tuples(st.just(0)).flatmap(lambda _: mutations.map(lambda ms: ms[0])),
                                   field_mutation()), min_size=1, max_size=3)


def run(target: str, files: dict, args_of, outputs) -> None:
    with tempfile.TemporaryDirectory(prefix="gearcli-fuzz-") as d:
        work = Path(d)
        for name, data in files.items():
            (work / name).write_bytes(data)
        result, hung = run_cli(args_of(work))
        found = problems(result, hung, work, files, outputs)
        if not hung and result.exit_code == 1 and "stopped:" in result.stderr and (work / outputs[0]).is_file():
            found = [p for p in found if not p.startswith("bad exit")]          # simulate's early stop
        verdict(target, found, files, None if hung else result.exit_code)


@few(15)
@given(muts=any_mutations, opts=st.sampled_from(OPTIONS), which=st.sampled_from(["mech", "input"]))
def test_fuzz_simulate(muts, opts, which):
    mech, inp = ARM, ARM_INPUT
    for m in muts:
        if which == "mech":
            mech = apply_any(mech, m)
        else:
            inp = apply_any(inp, m)
    run("simulate", {"mech.yaml": mech, "in.csv": inp},
        lambda w: ["simulate", w / "mech.yaml", w / "in.csv", "-o", w / "traj.csv", *opts], ("traj.csv",))


@few(15)
@given(muts=any_mutations, which=st.sampled_from(["mech", "traj"]))
def test_fuzz_payloads_and_attach_columns(muts, which):
    mech, traj = ARM, PICK
    for m in muts:
        if which == "mech":
            mech = apply_any(mech, m)
        else:
            traj = apply_any(traj, m)
    run("attach", {"mech.yaml": mech, "traj.csv": traj},
        lambda w: ["solve", w / "mech.yaml", w / "traj.csv", "-o", w / "out.csv"], ("out.csv",))


@few(8)
@given(muts=any_mutations)
def test_fuzz_stick_slip_example(muts):
    mech = (MECH_DIR / "turntable_dwell.yaml").read_bytes()
    for m in muts:
        mech = apply_any(mech, m)
    inp = (MECH_DIR / "turntable_dwell_torque.csv").read_bytes().replace(b"\n2.4,0\n", b"\n0.4,0\n")
    inp = b"".join(ln for ln in inp.splitlines(keepends=True) if not ln[:1].isdigit() or float(ln.split(b",")[0]) <= 0.4)
    run("stick-slip", {"mech.yaml": mech, "in.csv": inp},
        lambda w: ["simulate", w / "mech.yaml", w / "in.csv", "-o", w / "traj.csv", "--t-end", "0.4"], ("traj.csv",))
