"""Fast unit tests of the task engine: ready order, dispatch-time checks, failures, handlers, jobserver."""

from __future__ import annotations

import os
import time

import pytest

from roc.engine.events import (
    RunFinished,
    TaskFailed,
    TaskFinished,
    TaskQueued,
    TaskSkipped,
    TaskStarted,
    Tick,
    task_key,
)
from roc.engine.executor import execute
from roc.engine.jobserver import Jobserver, jobs_from_makeflags
from roc.engine.process import TaskError
from roc.engine.ready import ReadyQueue, Task


def _noop(context) -> None:
    pass


def _fail(context) -> None:
    raise TaskError("boom")


def _task(name: str, deps: tuple[str, ...] = (), action=_noop, **fields) -> Task:
    return Task(name, set(deps), action, **fields)


def _run(tasks: list[Task], handlers=(), **options):
    seen: list = []
    result = execute(tasks, [lambda e: None if isinstance(e, Tick) else seen.append(e), *handlers], workers=1,
                     **options)
    return result, seen


def test_task_key_names_builds_by_package_and_other_kinds_by_kind() -> None:
    assert task_key("build", "a") == "a"
    assert task_key("test", "a") == "test:a"
    assert _task("a", kind="idl").key == "idl:a"
    assert TaskFinished("a", "probe").key == "probe:a"


def test_ready_queue_pops_the_longest_chain_first_then_alphabetically() -> None:
    # a -> c (heavy); b alone; both a and b are ready at once, but a leads to the heavy c
    tasks = {t.key: t for t in (_task("b", weight=2.0), _task("a"), _task("c", ("a",), weight=5.0),
                                _task("d"), _task("e"))}
    queue = ReadyQueue(tasks)
    order = [queue.pop().name for _ in range(4)]
    assert order == ["a", "b", "d", "e"]
    assert not queue.has_ready()
    queue.done("a")
    assert queue.pop().name == "c"


def test_ready_queue_downstream_and_cycle() -> None:
    tasks = {t.key: t for t in (_task("a"), _task("b", ("a",)), _task("c", ("b",)), _task("d"))}
    assert sorted(ReadyQueue(tasks).downstream("a")) == ["b", "c"]
    assert ReadyQueue(tasks).downstream("d") == []
    with pytest.raises(ValueError, match="cycle"):
        ReadyQueue({t.key: t for t in (_task("x", ("y",)), _task("y", ("x",)))})


def test_dependencies_outside_the_graph_are_ignored() -> None:
    queue = ReadyQueue({"a": _task("a", ("not-selected",))})
    assert queue.pop().name == "a"


def test_check_at_dispatch_empty_is_cached_a_list_gives_the_reasons() -> None:
    ran: list[str] = []
    tasks = [
        _task("cached", action=lambda c: ran.append("cached"), check=lambda: []),
        _task("stale", action=lambda c: ran.append("stale"), check=lambda: ["files changed: x.c"]),
        _task("unchecked", action=lambda c: ran.append("unchecked")),
    ]
    result, seen = _run(tasks)
    assert result.ok and sorted(result.finished) == ["cached", "stale", "unchecked"]
    assert sorted(ran) == ["stale", "unchecked"]
    finished = {e.task: e for e in seen if isinstance(e, TaskFinished)}
    assert finished["cached"].cached is True and finished["stale"].cached is False
    started = {e.task: e.reasons for e in seen if isinstance(e, TaskStarted)}
    assert started == {"stale": ("files changed: x.c",), "unchecked": ()}


def test_check_runs_after_dependencies_finished() -> None:
    order: list[str] = []
    tasks = [_task("dep", action=lambda c: order.append("dep ran")),
             _task("top", ("dep",), check=lambda: order.append("top checked") or ["x"])]
    _run(tasks)
    assert order == ["dep ran", "top checked"]


def test_raising_check_fails_its_task_and_skips_dependents() -> None:
    def broken() -> list[str]:
        raise OSError("disk gone")

    tasks = [_task("a", check=broken), _task("b", ("a",)), _task("c")]
    result, seen = _run(tasks, continue_on_error=True)
    assert result.failed == ["a"] and result.skipped == {"b": "a"} and "c" in result.finished
    failed = [e for e in seen if isinstance(e, TaskFailed)]
    assert [(e.task, e.reason) for e in failed] == [("a", "up-to-date check failed: disk gone")]
    assert [(e.task, e.because_of) for e in seen if isinstance(e, TaskSkipped)] == [("b", "a")]
    assert not result.ok


def test_failure_without_continue_starts_nothing_more() -> None:
    tasks = [_task("a", action=_fail, weight=10.0), _task("b", ("a",)), _task("c")]
    result, seen = _run(tasks)
    assert result.failed == ["a"]
    assert sorted(result.not_started) == ["b", "c"] and result.finished == []
    end = seen[-1]
    assert isinstance(end, RunFinished) and sorted(end.not_started) == ["b", "c"]
    assert [e.reason for e in seen if isinstance(e, TaskFailed)] == ["boom"]


def test_a_bug_in_an_action_fails_the_task_with_its_traceback() -> None:
    result, seen = _run([_task("a", action=lambda c: 1 / 0)])
    assert result.failed == ["a"]
    reason = next(e.reason for e in seen if isinstance(e, TaskFailed))
    assert "ZeroDivisionError" in reason and "Traceback" in reason


def test_events_carry_kind_and_key() -> None:
    result, seen = _run([_task("p", kind="idl"), _task("p", ("idl:p",))])
    assert result.finished == ["idl:p", "p"]
    keys = [(type(e).__name__, e.kind, e.key) for e in seen if not isinstance(e, RunFinished)]
    assert keys == [("TaskQueued", "idl", "idl:p"), ("TaskQueued", "build", "p"),
                    ("TaskStarted", "idl", "idl:p"), ("TaskFinished", "idl", "idl:p"),
                    ("TaskStarted", "build", "p"), ("TaskFinished", "build", "p")]


def test_raising_handler_is_warned_about_and_disabled_while_the_run_goes_on(capsys) -> None:
    calls: list = []

    def broken(event) -> None:
        calls.append(event)
        raise RuntimeError("no space")

    broken.name = "my_handler"
    result, seen = _run([_task("a"), _task("b", ("a",))], handlers=[broken])
    assert result.ok and result.finished == ["a", "b"]
    assert len(calls) == 1 and isinstance(calls[0], TaskQueued)
    err = capsys.readouterr().err
    assert "event handler 'my_handler' failed and was disabled: RuntimeError: no space" in err
    assert err.count("my_handler") == 1
    assert isinstance(seen[-1], RunFinished)


def test_broken_pipe_in_a_handler_stops_the_run_and_is_raised() -> None:
    ran: list[str] = []

    def closed_stdout(event) -> None:
        if isinstance(event, TaskStarted):
            raise BrokenPipeError

    tasks = [_task("a", action=lambda c: ran.append("a")), _task("b", ("a",), action=lambda c: ran.append("b"))]
    with pytest.raises(BrokenPipeError):
        execute(tasks, [closed_stdout], workers=1)
    assert "b" not in ran


def test_jobs_from_makeflags() -> None:
    assert jobs_from_makeflags("-j8") == 8
    assert jobs_from_makeflags("k --jobs=3 s") == 3
    assert jobs_from_makeflags("-j 4") == 4
    assert jobs_from_makeflags("-k -s") is None
    assert jobs_from_makeflags("-j") is None  # unlimited: no number


def test_jobserver_holds_jobs_minus_one_tokens_and_rewrites_makeflags() -> None:
    server = Jobserver(4)
    try:
        os.set_blocking(server.read_fd, False)
        assert os.read(server.read_fd, 100) == b"+++"
        flags = server.makeflags("-k -j2 --jobserver-auth=7,8")
        assert flags == f"-k -j4 --jobserver-auth={server.read_fd},{server.write_fd}"
    finally:
        server.close()
    single = Jobserver(1)
    try:
        os.set_blocking(single.read_fd, False)
        with pytest.raises(BlockingIOError):
            os.read(single.read_fd, 1)
    finally:
        single.close()


def test_a_failure_aborts_the_running_tasks_and_stops_their_processes() -> None:
    def long_command(context) -> None:
        context.run(["sleep", "30"], cwd="/", env=os.environ)

    def fail_soon(context) -> None:
        time.sleep(0.3)
        raise TaskError("broken")

    tasks = [_task("long", action=long_command, weight=10.0), _task("bad", action=fail_soon),
             _task("after", ("long",))]
    start = time.monotonic()
    result = execute(tasks, [], workers=2)
    assert time.monotonic() - start < 10
    assert result.failed == ["bad"] and result.aborted == ["long"] and result.not_started == ["after"]
    assert not result.ok


def test_a_command_that_cannot_start_fails_its_task() -> None:
    def missing(context) -> None:
        context.run(["/nonexistent/tool"], cwd="/", env=os.environ)

    result, seen = _run([_task("a", action=missing)])
    assert result.failed == ["a"]
    assert [e.reason for e in seen if isinstance(e, TaskFailed)] == [
        "cannot run '/nonexistent/tool': No such file or directory"]
