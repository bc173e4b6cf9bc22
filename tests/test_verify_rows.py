"""verify reads each trajectory file once: the manifest's check keeps the rows for the job
in this process (io.trajectory.keep_rows), a file changed in between is read again."""
import json

import numpy as np

import gearcli.io.trajectory as trajectory
from gearcli.batch.manifest import load_manifest
from gearcli.batch.verify import run_verify
from test_verify import write_rotor_case

BEARINGS = ("[{name: a, position: 0, C: 5000, C0: 2000, type: ball, locating: true},"
            " {name: b, position: 0.1, C: 5000, C0: 2000, type: ball}]")


def _reads(monkeypatch) -> list:
    """Count the reads of trajectory files (every read of the rows starts at plain_chunks)."""
    calls = []
    real = trajectory.plain_chunks

    def counted(f, *a, **k):
        calls.append(f.name)
        return real(f, *a, **k)

    monkeypatch.setattr(trajectory, "plain_chunks", counted)
    return calls


def _manifest(tmp_path):
    text = "cases:\n" + write_rotor_case(tmp_path, BEARINGS)
    rows = np.loadtxt(tmp_path / "rotor.csv", delimiter=",", skiprows=1)
    for k in range(2):                       # two more trajectories of the same rotor, faster
        r = rows.copy()
        r[:, 1:3] *= 1.2 + 0.3 * k
        np.savetxt(tmp_path / f"rotor{k}.csv", r, delimiter=",", header="t,q:J,qd:J,qdd:J", comments="")
    text = text.replace("trajectories: [rotor.csv]", "trajectories: [rotor.csv, rotor0.csv, rotor1.csv]")
    (tmp_path / "design.yaml").write_text(text)
    return tmp_path / "design.yaml"


def test_serial_verify_reads_each_trajectory_once_with_the_same_report(tmp_path, monkeypatch):
    man = _manifest(tmp_path)
    reads = _reads(monkeypatch)
    run_verify(man, jobs=1, json_path=tmp_path / "kept.json")
    assert len(reads) == 3 and len(set(reads)) == 3          # the check's read only
    assert not trajectory._KEPT                               # every kept row taken or dropped
    reads.clear()
    monkeypatch.setattr(trajectory, "KEEP_BYTES", 0)          # nothing kept: check and job read
    run_verify(man, jobs=1, json_path=tmp_path / "read.json")
    assert len(reads) == 6
    kept, read = (json.loads((tmp_path / f"{n}.json").read_text()) for n in ("kept", "read"))
    assert kept["checks"] == read["checks"]


def test_a_trajectory_changed_after_the_check_is_read_again(tmp_path, monkeypatch):
    man = _manifest(tmp_path)
    manifest = load_manifest(man)                 # checks and keeps the rows of the three files
    rows = np.loadtxt(tmp_path / "rotor1.csv", delimiter=",", skiprows=1)
    rows[:, 1:3] *= 2.0                           # twice as fast: 4x the bearing's radial load
    np.savetxt(tmp_path / "rotor1.csv", rows, delimiter=",", header="t,q:J,qd:J,qdd:J", comments="")
    reads = _reads(monkeypatch)
    run_verify(man, jobs=1, manifest=manifest, json_path=tmp_path / "stale.json")
    assert len(reads) == 1 and reads[0].endswith("rotor1.csv")
    run_verify(man, jobs=1, json_path=tmp_path / "fresh.json")    # a new check of the new file
    stale, fresh = (json.loads((tmp_path / f"{n}.json").read_text()) for n in ("stale", "fresh"))
    assert stale["checks"] == fresh["checks"]
    speed = next(c for c in fresh["checks"] if c["quantity"] == "speed")
    assert speed["value"] == np.abs(rows[:, 2]).max()          # the changed file's rate, not the kept one's


def test_rows_kept_in_chunks_read_back_as_the_file_reads(tmp_path):
    # the check read 1,000 rows in chunks of 200; the whole-file reader gets them as one,
    # a reader of chunks of 300 as its own chunks: the same samples as reading the file
    t = np.linspace(0.0, 1.0, 1000)
    trajectory.write_trajectory(tmp_path / "m.csv", ["J1", "J2"], t, np.column_stack([np.sin(3 * t), t ** 2]))
    fresh = trajectory.read_trajectory(tmp_path / "m.csv", ["J1", "J2"])
    fresh_parts = list(trajectory.TrajectoryReader(tmp_path / "m.csv", ["J1", "J2"], chunk=300))
    for chunk, read in ((None, lambda: [trajectory.read_trajectory(tmp_path / "m.csv", ["J1", "J2"])]),
                        (300, lambda: list(trajectory.TrajectoryReader(tmp_path / "m.csv", ["J1", "J2"], chunk=300)))):
        assert trajectory.TrajectoryReader(tmp_path / "m.csv", ["J1", "J2"], chunk=200).check(keep=True) == 1000
        assert len(trajectory._KEPT) == 1
        got = read()
        assert not trajectory._KEPT
        want = [fresh] if chunk is None else fresh_parts
        assert len(got) == len(want)
        for g, w in zip(got, want):
            for f in ("t", "q", "qd", "qdd", "line"):
                assert getattr(g, f).tobytes() == getattr(w, f).tobytes()
