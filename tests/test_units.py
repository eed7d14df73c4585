"""Fast unit tests of the build logic: the jobserver, dsv operations, fingerprint parts and changes,
and cancellation in the engine."""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import pytest

from roc.builder.fingerprint import EDITOR_DROPPINGS, build_tools, changes, source_parts, source_stamps
from roc.engine.events import TaskAborted
from roc.engine.executor import execute
from roc.engine.jobserver import Jobserver, jobs_from_makeflags
from roc.engine.ready import Task
from roc.environment.dsv import Operation, apply_operations, resolve_operations


def test_jobserver_holds_jobs_minus_one_tokens_and_rewrites_makeflags() -> None:
    jobserver = Jobserver(4)
    try:
        os.set_blocking(jobserver.read_fd, False)
        assert os.read(jobserver.read_fd, 100) == b"+++"
        read, write = jobserver.fds
        assert jobserver.makeflags("-j8 -k --jobserver-auth=3,4") == f"-k -j4 --jobserver-auth={read},{write}"
    finally:
        jobserver.close()
    assert [jobs_from_makeflags(flags) for flags in ("-j3", "-k --jobs=5", "-j", "w")] == [3, 5, None, None]


def test_dsv_operations_follow_sourced_twins_and_apply_as_a_shell_would(tmp_path: Path) -> None:
    prefix = tmp_path / "install" / "pkg"
    (prefix / "share" / "pkg" / "hook").mkdir(parents=True)
    (prefix / "lib").mkdir()
    (prefix / "share" / "pkg" / "hook" / "path.dsv").write_text("prepend-non-duplicate;PATH;bin\n")
    (prefix / "share" / "pkg" / "package.dsv").write_text(
        "source;share/pkg/hook/path.sh\nsource;share/pkg/hook/only.sh\n"
        "prepend-non-duplicate-if-exists;LD_LIBRARY_PATH;lib\nprepend-non-duplicate-if-exists;MISSING;nope\n"
        "append-non-duplicate;TAIL;x\nset-if-unset;KEEP;value\nset;NAME;lib\n")
    (prefix / "share" / "pkg" / "hook" / "path.sh").write_text("")
    operations = resolve_operations(prefix, prefix / "share" / "pkg" / "package.dsv")
    assert operations[0] == Operation("prepend-non-duplicate", "PATH", ("bin",))
    assert operations[1] == Operation("source", "share/pkg/hook/only.sh")  # no .dsv twin: the shell sources it
    env = {"PATH": f"/usr/bin{os.pathsep}{prefix}/bin", "TAIL": "a", "KEEP": "mine"}
    apply_operations(env, prefix, operations)
    assert env == {"PATH": f"{prefix}/bin{os.pathsep}/usr/bin", "LD_LIBRARY_PATH": f"{prefix}/lib",
                   "TAIL": f"a{os.pathsep}{prefix}/x", "KEEP": "mine", "NAME": f"{prefix}/lib"}


def test_build_tools_are_the_ones_a_build_runs() -> None:
    assert build_tools("ament_python", {}, ()) == ()
    assert build_tools("cmake", {}, ()) == ("cmake", "make", "cc", "c++")
    assert build_tools("ament_cmake", {"CMAKE_GENERATOR": "Ninja", "CC": "clang"}, ()) == ("cmake", "ninja", "clang", "c++")
    assert build_tools("cmake", {"CMAKE_GENERATOR": "Ninja"}, ("-G", "Unix Makefiles"))[1] == "make"
    assert build_tools("cmake", {}, ("-GNinja",))[1] == "ninja"


def test_source_stamps_leave_out_editor_droppings(tmp_path: Path) -> None:
    for name in (".a.cpp.swp", ".a.cpp.swx", "a.cpp~", ".#a.cpp", "#a.cpp#", ".DS_Store", "4913", "a.cpp", "a.swp"):
        (tmp_path / name).write_text("x")
    assert sorted(source_stamps(tmp_path, {})) == ["a.cpp", "a.swp"]
    assert EDITOR_DROPPINGS.match(".x.swq") is None  # vim's swap names end at .swp ... .swa


def test_changes_name_each_kind_of_change(tmp_path: Path) -> None:
    (tmp_path / "a.cpp").write_text("1")
    (tmp_path / "b.cpp").write_text("2")
    before = {"sources": source_parts(source_stamps(tmp_path, {})), "options": {"cmake-args": []},
              "toolchain": {"tool c++": "/usr/bin/c++:1"}, "dependencies": {"core": "f1"}}
    (tmp_path / "a.cpp").write_text("changed")
    (tmp_path / "b.cpp").unlink()
    (tmp_path / "c.cpp").write_text("3")
    now = {"sources": source_parts(source_stamps(tmp_path, {})), "options": {"cmake-args": ["-DX=1"]},
           "toolchain": {"tool c++": "/opt/c++:1"}, "dependencies": {"core": "f2"}}
    assert changes(before, now) == ["files added: c.cpp", "files changed: a.cpp", "files removed: b.cpp",
                                    "option changed: cmake-args", "toolchain changed: tool c++",
                                    "dependency changed: core"]
    assert changes(now, now) == []


def test_cancellation_aborts_running_tasks_and_starts_no_more() -> None:
    """A failure without --continue-on-error cancels the tasks running beside it (their contexts are
    cancelled, as Ctrl+C does), which end as aborted."""
    started = threading.Event()

    def slow(context) -> None:
        started.set()
        deadline = time.monotonic() + 10
        while not context.cancelled and time.monotonic() < deadline:
            time.sleep(0.01)
        if context.cancelled:
            from roc.engine.process import TaskCancelled

            raise TaskCancelled

    def failing(_context) -> None:
        started.wait(5)
        from roc.engine.process import TaskError

        raise TaskError("broken")

    events: list = []
    begun = time.monotonic()
    result = execute([Task("slow", set(), slow), Task("bad", set(), failing), Task("later", {"bad"}, lambda c: None)],
                     [events.append], workers=2)
    assert time.monotonic() - begun < 5
    assert (result.failed, result.aborted, result.not_started) == (["bad"], ["slow"], ["later"])
    assert [e.task for e in events if isinstance(e, TaskAborted)] == ["slow"]


@pytest.mark.parametrize("flags, jobs", [("", None), ("-j 2", 2)])
def test_jobs_from_makeflags_accepts_a_space(flags: str, jobs: int | None) -> None:
    assert jobs_from_makeflags(flags) == jobs
