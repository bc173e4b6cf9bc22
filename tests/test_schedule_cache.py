"""The disk cache of solution schedules (analysis/schedule_cache.py): a schedule read back is
the one scipy's flow finds; damaged entries are recomputed; keys follow every input."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from big_mechanisms import geared_chain, serial_chain
from cache_faults import SPECIAL, in_thread, make_special
from gearcli import analyse, load_mechanism, parse_mechanism
from gearcli.analysis import schedule_cache
from gearcli.analysis.schedule import UnknownGroup

MECH = Path(__file__).resolve().parents[1] / "mechanisms"
FILES = ["paper_2dof", "bendix_wrist", "coaxial_fig5", "helical_reduction", "planetary_3p", "rack_axis"]


def entries(cache: Path) -> list[Path]:
    return sorted((cache / "schedule").glob("*.json"))


def mechanisms():
    yield from (load_mechanism(MECH / f"{n}.yaml") for n in FILES)
    yield parse_mechanism(serial_chain(6))
    yield parse_mechanism(geared_chain(4))


def test_a_read_schedule_is_the_computed_one(tmp_path, monkeypatch):
    """Each mechanism: computed with no cache, computed and stored, read back: the same."""
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))
    for i, mech in enumerate(mechanisms()):
        with monkeypatch.context() as m:
            m.setattr(schedule_cache, "scheduler_digest", lambda: None)     # no caching at all
            plain = analyse(mech).schedule
        assert len(entries(tmp_path)) == i
        stored = analyse(mech).schedule
        assert len(entries(tmp_path)) == i + 1
        calls = []
        real = schedule_cache.load
        monkeypatch.setattr(schedule_cache, "load", lambda *a: calls.append(real(*a)) or calls[-1])
        read = analyse(mech).schedule
        monkeypatch.setattr(schedule_cache, "load", real)
        assert calls and calls[0] is not None                                # it was read from disk
        assert plain == stored == read and len(plain) > 0
        assert len(entries(tmp_path)) == i + 1


@pytest.mark.parametrize("damage", ["not json", "empty", "flip a number", "not a partition", "other key"])
def test_a_damaged_entry_is_recomputed(tmp_path, monkeypatch, damage):
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))
    mech = load_mechanism(MECH / "bendix_wrist.yaml")
    good = analyse(mech).schedule
    (path,) = entries(tmp_path)
    entry = json.loads(path.read_text())
    if damage == "not json":
        path.write_text(path.read_text()[:-10])
    elif damage == "empty":
        path.write_text("")
    elif damage == "flip a number":      # the order changed, the checksum not
        b = entry["blocks"]
        b[0], b[-1] = b[-1], b[0]
        path.write_text(json.dumps(entry))
    elif damage == "not a partition":    # consistent checksum, but a link is missing
        entry["blocks"] = entry["blocks"][1:]
        entry["sha"] = schedule_cache._entry_sha(entry["blocks"], entry["flow"])
        path.write_text(json.dumps(entry))
    else:
        entry["key"] = "0" * 64
        path.write_text(json.dumps(entry))
    assert analyse(mech).schedule == good                      # recomputed ...
    (again,) = entries(tmp_path)
    assert json.loads(again.read_text())["blocks"] == [list(b) for b in good]    # ... and stored whole


def test_keys_follow_every_input():
    g = [UnknownGroup("joint", 0, 5, (1,)), UnknownGroup("motor", 0, 1, (1,))]
    base = dict(moving=[1, 2], groups=g, redundant=False, level={1: 1, 2: 2}, primary=[1])
    key = schedule_cache.schedule_key(**base)
    assert len(key) == 64 and key == schedule_cache.schedule_key(**base)
    changed = [dict(base, moving=[1, 3], level={1: 1, 3: 2}), dict(base, groups=g[:1]),
               dict(base, groups=[g[0], UnknownGroup("motor", 0, 1, (2,))]), dict(base, redundant=True),
               dict(base, level={1: 2, 2: 2}), dict(base, primary=[2])]
    keys = {schedule_cache.schedule_key(**c) for c in changed}
    assert len(keys) == len(changed) and key not in keys


@pytest.mark.parametrize("where", ["a file, not a folder", "below a file"])
def test_an_unusable_location_only_computes(tmp_path, monkeypatch, where):
    (tmp_path / "f").write_text("x")
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path / "f" if where == "a file, not a folder" else
                                                 tmp_path / "f" / "deeper"))
    mech = load_mechanism(MECH / "bendix_wrist.yaml")
    assert analyse(mech).schedule == analyse(mech).schedule
    assert (tmp_path / "f").read_text() == "x"


def test_prune_keeps_the_newest(tmp_path):
    import os  # noqa: PLC0415
    import time  # noqa: PLC0415

    for i in range(5):
        (tmp_path / f"{i}.json").write_text("{}")
        os.utime(tmp_path / f"{i}.json", (1000 + i, 1000 + i))
    for name, age in ((".gearcli.old.tmp", 7200), (".gearcli.new.tmp", 10)):   # a killed writer's, a live one's
        (tmp_path / name).write_text("")
        os.utime(tmp_path / name, (time.time() - age, time.time() - age))
    schedule_cache.prune(tmp_path, max_entries=3)
    assert sorted(p.stem for p in tmp_path.glob("*.json")) == ["2", "3", "4"]
    assert [p.name for p in tmp_path.glob(".gearcli.*")] == [".gearcli.new.tmp"]


def forge(entry: dict, blocks=None, flow=None) -> str:
    """``entry`` with other blocks or flow and its checksum recomputed (a checksum is no proof)."""
    entry = dict(entry, blocks=entry["blocks"] if blocks is None else blocks,
                 flow=entry["flow"] if flow is None else flow)
    entry["sha"] = schedule_cache._entry_sha(entry["blocks"], entry["flow"])
    return json.dumps(entry)


def other_flow(flow):
    """A scalar of the first link's first matched group moved to another link of the group
    (the link sums no longer 6: not a maximum flow of this incidence)."""
    flow = [list(t) for t in flow]
    flow[0][2] -= 1
    return flow if flow[0][2] > 0 else flow[1:]


@pytest.mark.parametrize("forgery", ["blocks reversed", "blocks merged", "flow changed", "another mechanism's entry",
                                     "booleans for ids", "no flow", "flow of strings"])
def test_a_forged_entry_with_its_checksum_is_recomputed(tmp_path, monkeypatch, forgery):
    """A cached schedule is used only when its flow proves it (issue 17: blocks reversed with
    the checksum recomputed gave a false 'statically indeterminate' error)."""
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))
    mech = load_mechanism(MECH / "bendix_wrist.yaml")
    good = analyse(mech).schedule
    (path,) = entries(tmp_path)
    entry = json.loads(path.read_text())
    if forgery == "blocks reversed":
        text = forge(entry, blocks=entry["blocks"][::-1])
    elif forgery == "blocks merged":
        text = forge(entry, blocks=[entry["blocks"][0] + entry["blocks"][1]] + entry["blocks"][2:])
    elif forgery == "flow changed":
        text = forge(entry, flow=other_flow(entry["flow"]))
    elif forgery == "another mechanism's entry":
        analyse(load_mechanism(MECH / "paper_2dof.yaml"))
        (other,) = set(entries(tmp_path)) - {path}
        text = forge(dict(json.loads(other.read_text()), key=entry["key"]))
    elif forgery == "booleans for ids":
        text = forge(entry, flow=[[x, g, True if a == 1 else a] for x, g, a in entry["flow"]])
    elif forgery == "no flow":
        text = forge(entry, flow=[])
    else:
        text = forge(entry, flow=[[str(v) for v in t] for t in entry["flow"]])
    path.write_text(text)
    assert analyse(mech).schedule == good
    assert json.loads(path.read_text()) == entry                         # rewritten whole


@pytest.mark.parametrize("damage", ["100,000 deep", "larger than the bound", *SPECIAL])
def test_a_hostile_entry_is_recomputed(tmp_path, monkeypatch, damage):
    """Deep JSON raised RecursionError, a FIFO or /dev/zero blocked for ever (issue 17)."""
    monkeypatch.setenv("GEARCLI_CACHE_DIR", str(tmp_path))
    mech = load_mechanism(MECH / "bendix_wrist.yaml")
    good = analyse(mech).schedule
    (path,) = entries(tmp_path)
    if damage == "100,000 deep":
        path.write_text("[" * 100_000 + "]" * 100_000)
    elif damage == "larger than the bound":
        monkeypatch.setattr(schedule_cache, "MAX_ENTRY_BYTES", 100)
        path.write_text(" " * 101 + "{}")
    else:
        make_special(path, damage)
    assert in_thread(lambda: analyse(mech).schedule) == good
    assert path.is_file() and not path.is_symlink()
    if damage != "larger than the bound":
        assert schedule_cache.load(path.stem, *_inputs(mech)) == good     # rewritten whole


def _inputs(mech):
    from gearcli.analysis.schedule import unknown_groups  # noqa: PLC0415

    an = analyse(mech)
    return an.tree.moving, unknown_groups(an), an.level, an.primary
