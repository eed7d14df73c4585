"""The live status line on a terminal: elapsed time, done/total, running packages with progress.

Progress is read from the build tools' own output: make's ``[ 45%]`` and ninja's ``[12/50]``.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable

from roc.engine.events import (
    Event,
    RunFinished,
    TaskAborted,
    TaskFailed,
    TaskFinished,
    TaskOutput,
    TaskQueued,
    TaskRestoring,
    TaskSkipped,
    TaskStarted,
)

_MAKE_PROGRESS = re.compile(rb"\[\s*(\d{1,3})%\]")
_NINJA_PROGRESS = re.compile(rb"\[(\d+)/(\d+)\]")


def progress_of(data: bytes) -> int | None:
    """The last progress percentage in a chunk of make or ninja output."""
    found = None
    for match in _MAKE_PROGRESS.finditer(data):
        found = int(match.group(1))
    for match in _NINJA_PROGRESS.finditer(data):
        done, total = int(match.group(1)), int(match.group(2))
        if total:
            found = 100 * done // total
    return found


class StatusLine:
    """Keeps a rich Live line under the normal output; ``print`` writes above it.

    The line is redrawn only when its text changes, and at most every ``MIN_INTERVAL`` seconds (a build
    sends hundreds of output events; redrawing for each costs terminal bandwidth and flickers)."""

    MIN_INTERVAL = 0.25

    def __init__(self, console=None, live=None, clock: Callable[[], float] = time.monotonic,
                 kind: str = "build") -> None:
        from rich.console import Console
        from rich.live import Live

        self.console = console or Console(highlight=False)
        self.live = live or Live(console=self.console, auto_refresh=False, transient=True)
        self.live.start()
        self.clock = clock
        self.kind = kind  # the run's own kind: its tasks are shown by name, others by key (idl:pkg)
        self.started = clock()
        self.drawn_text: str | None = None
        self.drawn_at = float("-inf")
        self.total = 0
        self.done = 0
        self.running: dict[str, int | None] = {}  # task key -> percent
        self._labels: dict[str, str] = {}

    def print(self, text: str) -> None:
        self.console.print(text, markup=False, highlight=False, soft_wrap=True)

    def __call__(self, event: Event) -> None:
        if isinstance(event, TaskQueued):
            self.total += 1
        elif isinstance(event, (TaskStarted, TaskRestoring)):
            self.running[event.key] = None
            self._labels[event.key] = event.task if event.kind == self.kind else event.key
        elif isinstance(event, TaskOutput) and event.key in self.running:
            percent = progress_of(event.data)
            if percent is not None:
                self.running[event.key] = percent
        elif isinstance(event, (TaskFinished, TaskFailed, TaskAborted, TaskSkipped)):
            self.running.pop(event.key, None)
            self.done += 1
        elif isinstance(event, RunFinished):
            self.live.stop()
            return
        self._refresh()

    def _refresh(self) -> None:
        from rich.text import Text

        now = self.clock()
        if now - self.drawn_at < self.MIN_INTERVAL:
            return
        running = " ".join(f"{self._labels.get(key, key)}{f' {p}%' if p is not None else ''}"
                           for key, p in self.running.items())
        line = f"[{int(now - self.started)}s] [{self.done}/{self.total} done] [{len(self.running)} running] {running}"
        line = line[: (self.console.width or 80) - 1]
        if line == self.drawn_text:
            return
        self.drawn_text, self.drawn_at = line, now
        self.live.update(Text(line, style="bold"), refresh=True)
