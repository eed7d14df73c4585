"""Unit tests of roc's task engine (roc/engine): order, checks at dispatch, failures, handlers, kinds."""

from __future__ import annotations

import threading

import pytest

from roc.engine.events import (
    RunFinished,
    TaskFailed,
    TaskFinished,
    TaskQueued,
    TaskSkipped,
    TaskStarted,
    task_key,
)
from roc.engine.executor import execute
from roc.engine.process import TaskError
from roc.engine.ready import ReadyQueue, Task


def _task(name: str, *dependencies: str, kind: str = "build", weight: float = 1.0, check=None, action=None,
          log: list | None = None) -> Task:
    def run(_context) -> None:
        if log is not None:
            log.append(task_key(kind, name))
        if action is not None:
            action()
    return Task(name, set(dependencies), run, kind=kind, weight=weight, check=check)


class Recorder:
    def __init__(self) -> None:
        self.events: list = []

    def __call__(self, event) -> None:
        self.events.append(event)

    def of(self, kind: type) -> list:
        return [e for e in self.events if isinstance(e, kind)]


def test_ready_queue_runs_the_longest_chain_first_and_respects_dependencies() -> None:
    tasks = {t.key: t for t in (_task("a"), _task("b", weight=5), _task("c", "a", weight=10), _task("d", "b"))}
    ready = ReadyQueue(tasks)
    assert ready.pop().name == "a"  # a then c (11) is longer than b then d (6)
    assert ready.pop().name == "b" and not ready.has_ready()
    ready.done("a")
    assert ready.pop().name == "c"
    with pytest.raises(ValueError, match="cycle"):
        ReadyQueue({t.key: t for t in (_task("x", "y"), _task("y", "x"))})


def test_dependencies_finish_before_dependents_across_kinds() -> None:
    log: list = []
    tasks = [_task("pkg", "idl:pkg", log=log), _task("pkg", kind="idl", log=log), _task("user", "pkg", log=log)]
    recorder = Recorder()
    result = execute(tasks, [recorder], workers=2)
    assert result.ok and log == ["idl:pkg", "pkg", "user"]
    assert [(e.kind, e.task, e.key) for e in recorder.of(TaskQueued)][:2] == [("build", "pkg", "pkg"),
                                                                             ("idl", "pkg", "idl:pkg")]
    assert isinstance(recorder.events[-1], RunFinished)


def test_the_check_runs_at_dispatch_after_the_dependencies() -> None:
    log: list = []
    seen_at_check: list = []
    tasks = [_task("first", log=log),
             _task("cached", "first", check=lambda: seen_at_check.append(list(log)) or [], log=log),
             _task("stale", "first", check=lambda: ["files changed: a.cpp"], log=log),
             _task("broken", check=lambda: 1 / 0, log=log)]
    recorder = Recorder()
    result = execute(tasks, [recorder], workers=1, continue_on_error=True)
    assert seen_at_check == [["first"]]  # the check saw what its dependency had done
    assert "cached" not in log and [e.task for e in recorder.of(TaskFinished) if e.cached] == ["cached"]
    assert [e.reasons for e in recorder.of(TaskStarted) if e.task == "stale"] == [("files changed: a.cpp",)]
    failed = recorder.of(TaskFailed)
    assert [(e.task, e.reason) for e in failed] == [("broken", "up-to-date check failed: division by zero")]
    assert result.failed == ["broken"]


def test_a_failure_skips_its_dependents_or_stops_the_run() -> None:
    def fail() -> None:
        raise TaskError("exit code 2")
    recorder = Recorder()
    result = execute([_task("bad", action=fail), _task("after", "bad"), _task("other")], [recorder], workers=1,
                     continue_on_error=True)
    assert (result.failed, result.skipped, result.finished) == (["bad"], {"after": "bad"}, ["other"])
    assert [(e.task, e.because_of) for e in recorder.of(TaskSkipped)] == [("after", "bad")]
    stopped = execute([_task("bad", action=fail, weight=9), _task("later", "bad"), _task("other")], [], workers=1)
    assert stopped.failed == ["bad"] and set(stopped.not_started) == {"later", "other"} and not stopped.ok


def test_a_failing_handler_is_disabled_and_the_run_goes_on(capsys) -> None:
    calls = []

    def broken(event) -> None:
        calls.append(event)
        raise RuntimeError("disk full")
    recorder = Recorder()
    result = execute([_task("a"), _task("b", "a")], [broken, recorder], workers=1)
    assert result.ok and len(calls) == 1
    assert [e.task for e in recorder.of(TaskFinished)] == ["a", "b"]
    assert "event handler 'broken' failed and was disabled: RuntimeError: disk full" in capsys.readouterr().err


def test_a_closed_stdout_stops_the_run_and_is_raised_at_its_end() -> None:
    started = threading.Event()

    def closed(event) -> None:
        if isinstance(event, TaskStarted):
            started.set()
            raise BrokenPipeError
    with pytest.raises(BrokenPipeError):
        execute([_task("a"), _task("b", "a")], [closed], workers=1)
    assert started.is_set()
