"""Progress bars that appear only when a run is slow enough to need one.

:class:`LateProgress` wraps a progress bar (a ``rich.progress.Progress`` with one task, on
stderr, disabled when stderr is not a terminal) and shows it once the run has taken
:data:`SHOW_AFTER` seconds, whatever the number of samples: a 9 s solve of 60,000 samples
shows a bar, a 0.3 s one shows none (the old rule, more than four chunks of samples, showed
nothing below 80,001 samples however long they took).  The moment is checked at every
update and by a timer thread, so a bar also appears during a long first chunk (a kernel
compile).  The clock and the timer are injectable, so the decision is tested without
waiting.
"""
from __future__ import annotations

import threading
import time
from typing import Callable

SHOW_AFTER = 1.0
"""Seconds of work after which the progress bar appears."""


class LateProgress:
    """``bar`` (``start``, ``stop``, ``add_task``, ``update``, ``disable``) shown once
    :data:`SHOW_AFTER` seconds have passed since :meth:`start`.

    ``update(total=..., advance=...)`` records the work (``total`` once, then ``advance``
    per finished piece); the bar, once shown, starts with what was done so far.  ``clock``
    gives seconds (default :func:`time.monotonic`); ``timer`` False leaves the checks to
    :meth:`update` and :meth:`poll` (tests)."""

    def __init__(self, bar, description: str, after: float = SHOW_AFTER,
                 clock: Callable[[], float] = time.monotonic, timer: bool = True):
        self.bar, self.description, self.after, self.clock, self.timer = bar, description, after, clock, timer
        self.total: float | None = None
        self.done = 0
        self.task = None
        self.started_at: float | None = None
        self.lock = threading.Lock()
        self._timer: threading.Timer | None = None

    @property
    def shown(self) -> bool:
        return self.task is not None

    def start(self) -> LateProgress:
        """Start the clock (and the timer that shows the bar when no update comes)."""
        self.started_at = self.clock()
        if self.timer and not self.bar.disable:
            self._timer = threading.Timer(self.after, self.poll)
            self._timer.daemon = True
            self._timer.start()
        return self

    def poll(self) -> None:
        """Show the bar if the run has taken :attr:`after` seconds, its total is known and
        stderr is a terminal."""
        with self.lock:
            if self.shown or self.bar.disable or self.started_at is None or self.total is None:
                return
            if self.clock() - self.started_at >= self.after:
                self.bar.start()
                self.task = self.bar.add_task(self.description, total=self.total, completed=self.done)

    def update(self, total: float | None = None, advance: float | None = None) -> None:
        """Record the total or a finished piece of work, then show or move the bar."""
        with self.lock:
            if total is not None:
                self.total = total
            if advance is not None:
                self.done += advance
            if self.shown:
                self.bar.update(self.task, total=self.total, completed=self.done)
        self.poll()

    def stop(self) -> None:
        """Stop the timer, and the bar if it was shown."""
        if self._timer is not None:
            self._timer.cancel()
        with self.lock:
            if self.shown:
                self.bar.stop()
            self.started_at = None     # a late timer shows nothing

    def __enter__(self) -> LateProgress:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()
