"""Builds in roc tui: the TaskBoard handler (unit), and a real build of a small workspace started from
the TUI's packages list, with a failed package's stderr a keypress away."""

from __future__ import annotations

import asyncio
import os
import subprocess
from pathlib import Path

import psutil
import pytest
from helpers.build import BIN, ros_env
from helpers.graph import graph_env, stop_daemon
from helpers.tui import CMAKE, MANIFEST, SIZE, make_workspace, table, until

from roc.engine.events import (
    CommandStarted,
    RunFinished,
    TaskFailed,
    TaskFinished,
    TaskOutput,
    TaskQueued,
    TaskSkipped,
    TaskStarted,
)
from roc.handlers.board import TaskBoard, step_name


def test_the_board_follows_a_run() -> None:
    board = TaskBoard()
    for name in ("a", "b", "c"):
        board(TaskQueued(name))
    board(TaskQueued("b", kind="idl"))
    board(TaskStarted("a"))
    board(CommandStarted("a", command=("cmake", "--build", "/ws/build/a")))
    board(TaskOutput("a", data=b"[ 45%] Building CXX object"))
    rows = {row.key: row for row in board.rows()}
    assert rows["a"].state == "running" and rows["a"].step_text() == "build 45%"
    assert rows["idl:b"].label == "idl:b" and rows["b"].label == "b"
    board(TaskOutput("a", stream="stderr", data=b"error: nope\n"))
    board(TaskFailed("a", duration=1.5, reason="CMake failed\nbuild of 'a' failed"))
    board(TaskSkipped("c", because_of="a"))
    board(TaskFinished("b", cached=True))
    board(TaskQueued("d"))
    board(RunFinished("", not_started=("d",)))
    rows = {row.key: row for row in board.rows()}
    assert rows["d"].state == "not started"
    assert (rows["a"].state, rows["a"].stderr, rows["a"].elapsed()) == ("failed", b"error: nope\n", 1.5)
    assert (rows["c"].state, rows["c"].reason) == ("skipped", "needs a")
    assert rows["b"].state == "up to date" and board.finished
    assert [row.key for row in board.rows()] == ["a", "b", "c", "idl:b", "d"]


def test_step_names() -> None:
    assert step_name(("cmake", "/ws/src/a", "-DCMAKE_INSTALL_PREFIX=/ws/install")) == "configure"
    assert step_name(("/usr/bin/cmake", "--install", "/ws/build/a")) == "install"
    assert step_name(("python3", "-W", "x", "setup.py", "egg_info", "develop")) == "setup.py egg_info"
    assert step_name(("make",)) == "make"


@pytest.mark.slow
def test_a_build_started_from_the_packages_list(tmp_path: Path, monkeypatch) -> None:
    from roc.commands.work.build import build_runner
    from roc.tui.app import RocApp
    from roc.tui.packages import WorkspaceView

    root = make_workspace(tmp_path / "ws")
    tools = {k: v for k, v in ros_env().items() if k in ("AMENT_PREFIX_PATH", "PATH")}
    env = graph_env(37, tmp_path / "runtime", **tools)
    (tmp_path / "runtime").mkdir()
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    monkeypatch.chdir(root)

    async def test() -> None:
        app = RocApp(workspace=WorkspaceView(root), new_build=build_runner)
        async with app.run_test(size=SIZE) as pilot:
            await pilot.press("5")
            packages = table(app, "#packages-table")
            await until(pilot, lambda: set(packages.rows_by_key) == {"good", "broken", "after"})
            assert packages.rows_by_key["good"].cells[2] == "not built"
            await pilot.press("B")
            await until(pilot, lambda: app.build is not None and app.build.board.finished, 120, "the build")
            tasks = table(app, "#tasks")
            await until(pilot, lambda: "after" in tasks.rows_by_key and tasks.rows_by_key["after"].cells[1] == "not started",
                        what="the end of the run listed")
            states = {key: row.cells[1] for key, row in tasks.rows_by_key.items()}
            # the first failure stops the run (no --continue-on-error): good may be stopped too
            assert states["broken"] == "failed" and states["after"] == "not started", states
            assert states["good"] in ("finished", "aborted"), states
            assert "failed" in tasks.rows_by_key["broken"].problems
            tasks.move_cursor(row=list(tasks.rows_by_key).index("broken"))
            await pilot.press("enter")
            await until(pilot, lambda: type(app.screen).__name__ == "TextViewer")
            assert "broken on purpose" in app.screen.query_one("#viewer").text
            await pilot.press("escape", "escape")
            await until(pilot, lambda: packages.rows_by_key["broken"].cells[2] == "failed", 10, "the new states")
        assert app.build.code == 1
    try:
        asyncio.run(test())
    finally:
        stop_daemon(env)


def test_tui_options_need_a_terminal(tmp_path: Path) -> None:
    root = make_workspace(tmp_path / "ws")
    for command in (["tui"], ["work", "build", "--tui"]):
        done = subprocess.run([str(BIN / "roc"), *command], cwd=root, env={**os.environ, **ros_env()},
                              capture_output=True, text=True, stdin=subprocess.DEVNULL, timeout=60)
        assert done.returncode == 2 and done.stderr.startswith("roc: error: ") and "needs a terminal" in done.stderr, \
            done.stderr
        assert not (root / "build").exists()


@pytest.mark.slow
def test_x_stops_a_build_and_its_processes(tmp_path: Path, monkeypatch) -> None:
    """A package whose configure step sleeps: x stops the build (its process tree ends), then q quits
    with the code of an interrupted build."""
    from roc.commands.work.build import build_runner
    from roc.tui.app import RocApp

    package = tmp_path / "ws" / "src" / "slow"
    package.mkdir(parents=True)
    (package / "CMakeLists.txt").write_text(CMAKE.format(name="slow", extra="execute_process(COMMAND sleep 300)\n"))
    (package / "package.xml").write_text(MANIFEST.format(name="slow", depends=""))
    for name, value in ros_env().items():
        monkeypatch.setenv(name, value)
    monkeypatch.chdir(package.parents[1])

    def sleepers() -> list[psutil.Process]:
        return [p for p in psutil.Process().children(recursive=True) if p.name() == "sleep"]

    async def test() -> None:
        app = RocApp(build=build_runner([]))
        async with app.run_test(size=SIZE) as pilot:
            await until(pilot, lambda: sleepers() != [], 60, "the configure step to start")
            await pilot.press("x")
            await until(pilot, lambda: app.build.board.finished, 30, "the build to stop")
            assert {row.key: row.state for row in app.build.board.rows()} == {"slow": "aborted"}
            assert sleepers() == []
            await pilot.press("q")
        assert app.return_value == 130
    asyncio.run(test())
