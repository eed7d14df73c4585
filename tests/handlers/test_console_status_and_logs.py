"""The event handlers: the console's lines and summary, the status line's redraws, the JSON events,
colcon's log folders and result files, and the --event-handlers switches."""

from __future__ import annotations

import io
import json
import os
from pathlib import Path

import pytest

from roc.engine.events import (
    RunFinished,
    TaskFailed,
    TaskFinished,
    TaskOutput,
    TaskQueued,
    TaskSkipped,
    TaskStarted,
    TestFailures,
    Tick,
)
from roc.errors import UsageError
from roc.handlers import EVENT_HANDLERS, handler_switches
from roc.handlers.console import ConsoleHandler
from roc.handlers.logs import LogHandler, new_log_directory, task_log_folder


class FakeLive:
    def __init__(self) -> None:
        self.updates: list[str] = []

    def start(self) -> None:
        pass

    def stop(self) -> None:
        pass

    def update(self, renderable, refresh: bool = False) -> None:
        self.updates.append(str(renderable))


def test_status_line_redraws_only_on_change_and_at_most_four_times_a_second():
    from rich.console import Console

    from roc.handlers.status import StatusLine

    now = [100.0]
    live = FakeLive()
    status = StatusLine(console=Console(file=io.StringIO(), width=120), live=live, clock=lambda: now[0])
    status(TaskQueued("a"))
    status(TaskStarted("a"))  # within 0.25 s of the first draw: not drawn
    assert live.updates == ["[0s] [0/1 done] [0 running] "]
    for _ in range(100):  # a burst of output in the same instant: no redraw
        status(TaskOutput("a", data=b"compiling"))
    assert len(live.updates) == 1
    now[0] += 0.3
    status(Tick(""))
    assert live.updates[-1] == "[0s] [0/1 done] [1 running] a"
    now[0] += 0.3
    for _ in range(100):  # unchanged text: never redrawn, however long it goes on
        status(TaskOutput("a", data=b"no progress here"))
        now[0] += 0.001
    assert len(live.updates) == 2
    status(TaskOutput("a", data=b"[ 45%] Building"))
    assert live.updates[-1] == "[0s] [0/1 done] [1 running] a 45%"
    # 10 s of events every 10 ms, the text changing each second: one redraw per change
    for _ in range(1000):
        now[0] += 0.01
        status(Tick(""))
    assert len(live.updates) == 3 + 10


def test_the_summary_separates_names_that_have_spaces() -> None:
    from roc.engine.events import RunFinished, TaskFailed, TaskStarted
    from roc.handlers.console import ConsoleHandler

    out = io.StringIO()
    console = ConsoleHandler(out, kind="probe", noun="probe", cached_label="")
    for name in ("topic /imu", "node /ghost_node", "parameter /motor_controller max_speed"):
        console(TaskStarted(name, "probe"))
        console(TaskFailed(name, "probe", reason="fail: no"))
    console(RunFinished("", "probe"))
    assert ("  3 probes failed: node /ghost_node, parameter /motor_controller max_speed, topic /imu\n"
            in out.getvalue())
    packages = io.StringIO()
    console = ConsoleHandler(packages)
    for name in ("b", "a"):
        console(TaskFailed(name, reason="failed"))
    console(RunFinished(""))
    assert "  2 packages failed: a b\n" in packages.getvalue()  # as colcon


def test_the_last_json_event_carries_the_run_s_kind() -> None:
    from roc.engine.executor import execute
    from roc.engine.ready import Task
    from roc.handlers.logs import JsonEventsHandler

    out = io.StringIO()
    execute([Task(name="node /a", dependencies=set(), action=lambda context: None, kind="probe")],
            [JsonEventsHandler(out)], 0, kind="probe")
    last = json.loads(out.getvalue().splitlines()[-1])
    assert (last["event"], last["kind"]) == ("RunFinished", "probe")


def test_handler_switches() -> None:
    defaults = handler_switches([])
    assert defaults == {name: default for name, (default, _) in EVENT_HANDLERS.items()}
    assert defaults["console_direct"] is False and defaults["status"] is True
    switches = handler_switches(["console_direct+", "status-", "desktop_notification-"])
    assert switches["console_direct"] is True and switches["status"] is False
    assert switches["desktop_notification"] is False  # colcon's, accepted when disabled


@pytest.mark.parametrize(("value", "message"), [
    ("statuz-", "--event-handlers: unknown handler 'statuz'; known: "),
    ("status", "--event-handlers: 'status' must be a name followed by + or -"),
    ("+", "--event-handlers: '+' must be a name followed by + or -"),
    ("desktop_notification+", "--event-handlers: roc does not support 'desktop_notification' yet"),
])
def test_handler_switches_reject_bad_values_in_one_line(value: str, message: str) -> None:
    with pytest.raises(UsageError) as error:
        handler_switches([value])
    text = str(error.value)
    assert text.startswith(message) and "\n" not in text
    if "unknown" in message:
        assert "status" in text.split("known: ")[1].split(", ")


def test_task_log_folder_per_kind() -> None:
    assert task_log_folder(TaskStarted("p", "build"), "build") == "p"
    assert task_log_folder(TaskStarted("p", "idl"), "build") == "p/idl"
    assert task_log_folder(TaskStarted("p", "test"), "test") == "p"
    assert task_log_folder(TaskStarted("p", "build"), "test") == "p/build"


def test_log_handler_writes_each_kind_in_its_folder_and_every_event(tmp_path: Path) -> None:
    from roc.engine.events import CommandEnded, CommandStarted, RunFinished, TaskOutput

    handler = LogHandler(tmp_path, kind="build")
    for event in (CommandStarted("p", "idl", command=("gen", "a b"), cwd="/w"), TaskOutput("p", "idl", data=b"gen\n"),
                  CommandEnded("p", "idl", command=("gen", "a b"), returncode=0),
                  TaskOutput("p", "build", stream="stderr", data=b"warn\n"), RunFinished("")):
        handler(event)
    files = {p.relative_to(tmp_path).as_posix(): p.read_text() for p in tmp_path.rglob("*") if p.is_file()}
    assert set(files) == {"events.log", "p/idl/command.log", "p/idl/streams.log", "p/idl/stdout.log",
                          "p/idl/stdout_stderr.log", "p/stderr.log", "p/stdout_stderr.log", "p/streams.log"}
    assert files["p/idl/command.log"] == ("Invoking command in '/w': gen 'a b'\n"
                                          "Invoked command 'gen 'a b'' returned '0'\n")
    assert files["p/stderr.log"] == "warn\n"
    assert [line.split('"')[3] for line in files["events.log"].splitlines()] == [
        "CommandStarted", "TaskOutput", "CommandEnded", "TaskOutput", "RunFinished"]


def test_latest_links_follow_new_runs_but_leave_real_folders_alone(tmp_path: Path) -> None:
    """As colcon: ``latest`` links move to each new run; a real folder by that name (a workspace copied
    with its links followed) is kept and does not stop the build."""
    first = new_log_directory(tmp_path)
    assert os.readlink(tmp_path / "latest_build") == first.name
    assert os.readlink(tmp_path / "latest") == "latest_build"
    (tmp_path / "latest_build").unlink()
    (tmp_path / "latest_build").mkdir()
    second = new_log_directory(tmp_path)
    assert second != first and (tmp_path / "latest_build").is_dir() and not (tmp_path / "latest_build").is_symlink()
    assert os.readlink(tmp_path / "latest") == "latest_build"
    assert not list(tmp_path.glob(".*.tmp"))


def test_console_names_the_runs_own_kind_as_colcon_and_other_kinds_by_key() -> None:
    """``roc work test`` prints ``Starting >>> pkg`` for its test tasks (as colcon test does); a task of
    another kind in the same run is named by its key."""
    stream = io.StringIO()
    console = ConsoleHandler(stream, kind="test", cached_label="cached",
                             finished_note=lambda key: "\t[ with test failures ]" if key == "test:b" else "")
    for event in (TaskQueued("a", "test"), TaskQueued("b", "test"), TaskQueued("c", "test"), TaskQueued("d", "test"),
                  TaskQueued("x"), TaskStarted("x"), TaskFinished("x", duration=1.0),
                  TaskFinished("a", "test", cached=True),
                  TaskStarted("b", "test"), TaskOutput("b", "test", stream="stderr", data=b"oops\n"),
                  TestFailures("b", "test"),
                  TaskFinished("b", "test", duration=1.0), TaskStarted("c", "test"),
                  TaskFailed("c", "test", duration=1.0, reason="ctest exited with code 2"),
                  TaskSkipped("d", "test", because_of="test:c"), RunFinished("")):
        console(event)
    lines = stream.getvalue().splitlines()
    assert lines[:9] == ["Starting >>> x", "Finished <<< x [1.00s]",
                         "Starting >>> b", "--- stderr: b", "oops", "---",
                         "Finished <<< b [1.00s]\t[ with test failures ]", "Starting >>> c",
                         "Failed   <<< c [1.00s, ctest exited with code 2]"]
    assert lines[11:] == ["  1 package cached: a", "  1 package failed: c",
                          "  1 package skipped because a dependency failed: d (needs c)",
                          "  1 package had stderr output: b", "  1 package had test failures: b"]

    build = io.StringIO()
    console = ConsoleHandler(build, kind="build")
    for event in (TaskQueued("a", "idl"), TaskStarted("a", "idl"), TaskFinished("a", "idl", duration=1.0),
                  TaskStarted("a"), TaskFinished("a", duration=1.0), TaskQueued("b", "idl"),
                  TaskFinished("b", "idl", cached=True), TaskFinished("b", cached=True), TaskQueued("c"),
                  RunFinished("", not_started=("idl:c", "c"))):
        console(event)
    lines = build.getvalue().splitlines()
    assert lines[:4] == ["Starting >>> idl:a", "Finished <<< idl:a [1.00s]", "Starting >>> a", "Finished <<< a [1.00s]"]
    assert lines[5].startswith("Summary: 2 packages and 2 idl tasks finished [")
    assert lines[6:] == ["  1 package and 1 idl task up to date (not rebuilt): b idl:b",
                         "  1 package and 1 idl task not processed"]


def test_status_line_names_the_runs_own_kind_by_package() -> None:
    from rich.console import Console

    from roc.handlers.status import StatusLine

    class Live:
        def __init__(self) -> None:
            self.updates: list[str] = []

        def start(self) -> None: ...

        def update(self, renderable, refresh: bool = False) -> None:
            self.updates.append(str(renderable))

    live = Live()
    status = StatusLine(console=Console(file=io.StringIO(), width=120), live=live, clock=lambda: 0.0, kind="test")
    status.MIN_INTERVAL = -1.0
    for event in (TaskQueued("a", "test"), TaskQueued("a", "idl"), TaskStarted("a", "test"), TaskStarted("a", "idl")):
        status(event)
    assert live.updates[-1] == "[0s] [0/2 done] [2 running] a idl:a"
