"""When solve and verify show a progress bar: once the run has taken about a second
(:data:`gearcli.report.progress.SHOW_AFTER`), whatever the number of samples, and only on a
terminal.  The decision is tested with an injected clock, never with real time."""
from __future__ import annotations

import pytest

from gearcli.report.progress import SHOW_AFTER, LateProgress


class Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


class Bar:
    """What LateProgress uses of rich's Progress, recording the calls."""

    def __init__(self, disable=False):
        self.disable, self.calls, self.tasks = disable, [], {}

    def start(self):
        self.calls.append("start")

    def stop(self):
        self.calls.append("stop")

    def add_task(self, description, total=None, completed=0):
        self.calls.append(("add_task", description, total, completed))
        self.tasks[0] = (total, completed)
        return 0

    def update(self, task, total=None, completed=None):
        self.calls.append(("update", total, completed))
        self.tasks[task] = (total, completed)


def late(bar, clock):
    return LateProgress(bar, "solve", clock=clock, timer=False).start()


def test_a_slow_run_of_few_samples_shows_the_bar_after_a_second():
    """60,000 samples in 3 chunks over 9 s: the bar appears at the first update after
    1 s with what was done so far, then moves (the old rule, more than 4 chunks = 80,000
    samples, showed nothing)."""
    assert SHOW_AFTER == 1.0
    clock, bar = Clock(), Bar()
    p = late(bar, clock)
    p.update(total=60_000)
    clock.now += 0.5
    p.poll()
    assert bar.calls == []
    clock.now += 2.5
    p.update(advance=20_000)
    assert bar.calls == ["start", ("add_task", "solve", 60_000, 20_000)]
    clock.now += 3
    p.update(advance=20_000)
    assert bar.tasks[0] == (60_000, 40_000)
    p.stop()
    assert bar.calls[-1] == "stop"


def test_the_timer_shows_the_bar_during_a_long_first_chunk():
    clock, bar = Clock(), Bar()
    p = late(bar, clock)
    p.update(total=20_000)
    clock.now += SHOW_AFTER
    p.poll()                      # what the timer thread calls
    assert bar.calls == ["start", ("add_task", "solve", 20_000, 0)]


def test_a_fast_run_of_many_samples_shows_nothing():
    clock, bar = Clock(), Bar()
    p = late(bar, clock)
    p.update(total=10_000_000)
    for _ in range(50):
        clock.now += 0.019
        p.update(advance=200_000)
    p.stop()
    assert bar.calls == []


@pytest.mark.parametrize("case", ["not a terminal", "no total yet", "stopped"])
def test_no_bar(case):
    clock, bar = Clock(), Bar(disable=case == "not a terminal")
    p = late(bar, clock)
    if case != "no total yet":
        p.update(total=1_000)
    if case == "stopped":
        p.stop()
    clock.now += 10 * SHOW_AFTER
    p.poll()
    assert bar.calls == []


def test_the_real_timer_calls_poll(monkeypatch):
    """With timer=True a threading.Timer of SHOW_AFTER s is started (daemon) and cancelled
    by stop; it calls poll (no waiting here: the Timer is replaced)."""
    made = []

    class FakeTimer:
        def __init__(self, interval, function):
            self.interval, self.function, self.cancelled, self.daemon = interval, function, False, False
            made.append(self)

        def start(self):
            pass

        def cancel(self):
            self.cancelled = True

    import gearcli.report.progress as progress
    monkeypatch.setattr(progress.threading, "Timer", FakeTimer)
    clock, bar = Clock(), Bar()
    p = LateProgress(bar, "verify", clock=clock).start()
    p.update(total=3)
    assert [(t.interval, t.daemon) for t in made] == [(SHOW_AFTER, True)]
    clock.now += SHOW_AFTER
    made[0].function()
    assert bar.calls == ["start", ("add_task", "verify", 3, 0)]
    p.stop()
    assert made[0].cancelled and bar.calls[-1] == "stop"


@pytest.mark.parametrize("mech, traj, backend", [("servo_joint_rated.yaml", "servo_joint_duty.csv", "llvm"),
                                                 ("paper_2dof.yaml", "paper_2dof_traj.csv", "numpy")])
def test_the_bar_moves_within_a_chunk_and_the_result_is_the_same(tmp_path, mech, traj, backend):
    """A run shorter than one 20,000-sample chunk moved the bar once, at its end (issue 34,
    section 4): the part is solved in steps of ~1/40 of the run (multiples of the kernel's
    256-sample warm-start runs), and the table is the same bytes as without a bar."""
    from pathlib import Path

    from gearcli.pipeline import solve_file
    root = Path(__file__).resolve().parents[1] / "mechanisms"
    steps = []

    def progress(total=None, advance=None):
        if advance is not None:
            steps.append(advance)
    solve_file(root / mech, root / traj, tmp_path / "a.csv", precision=17, backend=backend, progress=progress)
    solve_file(root / mech, root / traj, tmp_path / "b.csv", precision=17, backend=backend)
    rows = len((root / traj).read_text().splitlines()) - 1
    assert sum(steps) == rows and len(steps) >= min(8, rows // 256)
    assert all(s % 256 == 0 for s in steps[:-1])
    assert (tmp_path / "a.csv").read_bytes() == (tmp_path / "b.csv").read_bytes()
