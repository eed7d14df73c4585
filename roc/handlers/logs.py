"""colcon's log layout: ``<log-base>/<verb>_<time>/`` with an events log and per-package logs,
``latest_<verb>`` and ``latest`` links, and each package's result in ``<build-base>/<pkg>/colcon_<kind>.rc``.

A run's own kind of task (``build`` for ``roc work build``) logs in ``<pkg>/`` as colcon does; any other
kind of task in the same run (code generation before a build, say) logs in ``<pkg>/<kind>/``."""

from __future__ import annotations

import json
import os
import shlex
import time
from pathlib import Path

from roc.engine.events import (
    CommandEnded,
    CommandStarted,
    Event,
    RunFinished,
    TaskAborted,
    TaskFailed,
    TaskFinished,
    TaskOutput,
    TestFailures,
    Tick,
)
from roc.fsutil import write_text_atomic, write_text_if_changed
from roc.workspace.selection import INTERRUPTED_RESULT

TYPE_CHECKING = False  # typing is not imported at run time (start-up time of every build)
if TYPE_CHECKING:
    from typing import BinaryIO


def event_json(event: Event) -> str:
    """One event as a JSON object: its kind, task, time and fields (output decoded as text)."""
    record = {"event": type(event).__name__, **event.fields()}
    if isinstance(event, TaskOutput):
        record["data"] = event.data.decode(errors="replace")
    return json.dumps(record)


def new_log_directory(log_base: Path, verb: str = "build") -> Path:
    stamp = time.strftime("%Y-%m-%d_%H-%M-%S")
    directory = log_base / f"{verb}_{stamp}"
    suffix = 0
    while directory.exists():
        suffix += 1
        directory = log_base / f"{verb}_{stamp}_{suffix}"
    directory.mkdir(parents=True)
    if not (log_base / "COLCON_IGNORE").exists():
        write_text_atomic(log_base / "COLCON_IGNORE", "")
    for name, target in ((f"latest_{verb}", directory.name), ("latest", f"latest_{verb}")):
        point_link(log_base / name, target)
    return directory


def point_link(link: Path, target: str) -> None:
    """Make the symbolic link ``link`` point to ``target``, replacing it at once; a real file or folder by
    that name is left alone (as colcon and the launch library leave it)."""
    if link.exists() and not link.is_symlink():
        return
    temporary = link.with_name(f".{link.name}.tmp")
    temporary.unlink(missing_ok=True)
    temporary.symlink_to(target)
    os.replace(temporary, link)


def task_log_folder(event: Event, run_kind: str) -> str:
    """A task's log folder, relative to the run's log directory."""
    return event.task if event.kind == run_kind else f"{event.task}/{event.kind}"


class LogHandler:
    """Per-package logs (commands in command.log unless ``log_command-``), and (unless ``event_log-``)
    every event in ``events.log``."""

    def __init__(self, directory: Path, events: bool = True, commands: bool = True, kind: str = "build"):
        self.directory = directory
        self.kind = kind
        self.commands = commands
        self._events = open(directory / "events.log", "a", buffering=1) if events else None
        self._files: dict[tuple[str, str], BinaryIO] = {}

    def task_directory(self, event: Event) -> Path:
        return self.directory / task_log_folder(event, self.kind)

    def _file(self, event: Event, name: str):
        key = (event.key, name)
        if key not in self._files:
            directory = self.task_directory(event)
            directory.mkdir(parents=True, exist_ok=True)
            self._files[key] = open(directory / name, "ab")
        return self._files[key]

    def __call__(self, event: Event) -> None:
        if isinstance(event, Tick):
            return
        if isinstance(event, TaskOutput):
            self._file(event, f"{event.stream}.log").write(event.data)
            self._file(event, "stdout_stderr.log").write(event.data)
            self._file(event, "streams.log").write(event.data)
        elif isinstance(event, CommandStarted) and self.commands:
            text = f"Invoking command in '{event.cwd}': {shlex.join(event.command)}\n".encode()
            self._file(event, "command.log").write(text)
            self._file(event, "streams.log").write(text)
        elif isinstance(event, CommandEnded) and self.commands:
            text = f"Invoked command '{shlex.join(event.command)}' returned '{event.returncode}'\n".encode()
            self._file(event, "command.log").write(text)
            self._file(event, "streams.log").write(text)
        if self._events is not None:
            self._events.write(event_json(event) + "\n")
        if isinstance(event, RunFinished):
            self.close()

    def close(self) -> None:
        for handle in self._files.values():
            handle.close()
        self._files.clear()
        if self._events is not None:
            self._events.close()


# Where each kind of task leaves its result, as colcon does (other kinds keep none).
RESULT_FILES = {"build": "colcon_build.rc", "test": "colcon_test.rc"}
# colcon's result of a test task that finished with failing tests (--packages-select-test-failures).
TEST_FAILURES_RESULT = "test failures"


class ResultStore:
    """Writes each package's result where --packages-select-build-failed (or -test-failures) looks:
    0, 1, SIGINT, or "test failures" for a task that finished after a ``TestFailures`` event. A task of a
    kind that keeps no result (``idl:pkg``) that fails or is aborted sets the result of the run's own
    ``kind`` for its package: that package's build did not succeed either."""

    def __init__(self, build_base: Path, kind: str = "build"):
        self.build_base = build_base
        self.kind = kind
        self.test_failures: set[str] = set()  # task keys

    def __call__(self, event: Event) -> None:
        if isinstance(event, TestFailures):
            self.test_failures.add(event.key)
            return
        results = {TaskFinished: "0", TaskFailed: "1", TaskAborted: INTERRUPTED_RESULT}
        result = results.get(type(event))
        kind = event.kind if event.kind in RESULT_FILES or result == "0" else self.kind
        if result is None or kind not in RESULT_FILES:
            return
        if result == "0" and event.key in self.test_failures:
            result = TEST_FAILURES_RESULT
        write_text_if_changed(self.build_base / event.task / RESULT_FILES[kind], result + "\n")


class JsonEventsHandler:
    """``--output json``: one JSON object per event on stdout, for CI."""

    def __init__(self, stream):
        self.stream = stream

    def __call__(self, event: Event) -> None:
        if isinstance(event, Tick):
            return
        self.stream.write(event_json(event) + "\n")
        self.stream.flush()
