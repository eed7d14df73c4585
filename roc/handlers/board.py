"""A live board of a run's tasks: one row per task with its state, elapsed time, current step and
stderr, kept up to date from engine events. ``roc tui``'s build view draws it; it prints nothing.

The executor calls a handler from one thread and a view reads the board from another, so every read
and write holds the board's lock (``rows`` returns copies).
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field, replace
from pathlib import PurePath

from roc.engine.events import (
    CommandStarted,
    Event,
    RunFinished,
    TaskAborted,
    TaskFailed,
    TaskFinished,
    TaskOutput,
    TaskQueued,
    TaskSkipped,
    TaskStarted,
)
from roc.handlers.status import progress_of

# states, in the order a task goes through them
QUEUED, RUNNING, FINISHED, CACHED, FAILED, ABORTED, SKIPPED, NOT_STARTED = (
    "queued", "running", "finished", "up to date", "failed", "aborted", "skipped", "not started")


@dataclass
class TaskRow:
    key: str
    label: str  # the task's name for the run's own kind, else its key (as the console names it)
    state: str = QUEUED
    started: float | None = None  # time.monotonic()
    duration: float | None = None  # once ended
    step: str = ""  # what it runs now: "configure", "build", "setup.py develop", ...
    progress: int | None = None  # percent, from make's or ninja's output
    stderr: bytes = b""
    reason: str = ""  # why it failed, or which task's failure skipped it

    def elapsed(self, now: float | None = None) -> float | None:
        if self.duration is not None:
            return self.duration
        return None if self.started is None else (now or time.monotonic()) - self.started

    def step_text(self) -> str:
        return f"{self.step} {self.progress}%" if self.progress is not None and self.step else self.step


def step_name(command: tuple[str, ...]) -> str:
    """A command as a build step: ``cmake --build`` -> ``build``, ``setup.py develop`` -> ``setup.py
    develop``, ``cmake SRC`` -> ``configure``, anything else its program's name."""
    if not command:
        return ""
    program = PurePath(command[0]).name
    if program == "cmake":
        for option, step in (("--build", "build"), ("--install", "install")):
            if option in command:
                return step
        return "configure"
    for index, word in enumerate(command):
        if word.endswith("setup.py") and index + 1 < len(command):
            return f"setup.py {next((w for w in command[index + 1:] if not w.startswith('-')), '')}".strip()
    return program


@dataclass
class TaskBoard:
    """The handler: ``rows()`` in queue order, ``finished`` once the run ended."""

    kind: str = "build"
    _rows: dict[str, TaskRow] = field(default_factory=dict)
    _lock: threading.Lock = field(default_factory=threading.Lock)
    finished: bool = False
    interrupted: bool = False
    changes: int = 0  # counts every change, so a view redraws only when it moved
    started_at: float | None = None  # the time of the run's first event, and of its end (time.time())
    ended_at: float | None = None

    def rows(self) -> list[TaskRow]:
        with self._lock:
            return [replace(row) for row in self._rows.values()]

    def __call__(self, event: Event) -> None:
        with self._lock:
            self._take(event)
            self.changes += 1

    def _take(self, event: Event) -> None:
        self.started_at = event.time if self.started_at is None else self.started_at
        if isinstance(event, RunFinished):
            self.finished, self.interrupted, self.ended_at = True, event.interrupted, event.time
            for key in event.not_started:  # the run stopped first (a failure, Ctrl+C)
                if key in self._rows:
                    self._rows[key].state = NOT_STARTED
            return
        if isinstance(event, TaskQueued):
            label = event.task if event.kind == self.kind else event.key
            self._rows[event.key] = TaskRow(event.key, label)
            return
        row = self._rows.get(event.key)
        if row is None:
            return
        if isinstance(event, TaskStarted):
            row.state, row.started = RUNNING, time.monotonic()
        elif isinstance(event, CommandStarted):
            row.step, row.progress = step_name(event.command), None
        elif isinstance(event, TaskOutput):
            if event.stream == "stderr":
                row.stderr += event.data
            percent = progress_of(event.data)
            row.progress = row.progress if percent is None else percent
        elif isinstance(event, TaskFinished):
            row.state = CACHED if event.cached else FINISHED
            row.duration, row.progress = (0.0 if event.cached else event.duration), None
            row.step = f"on {event.worker}" if event.worker else ""
        elif isinstance(event, TaskFailed):
            row.state, row.duration, row.reason = FAILED, event.duration, event.reason.strip()
        elif isinstance(event, TaskAborted):
            row.state, row.duration = ABORTED, event.duration
        elif isinstance(event, TaskSkipped):
            row.state, row.reason = SKIPPED, f"needs {event.because_of}"
