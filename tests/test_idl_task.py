"""The ``idl`` task (roc/idl/task.py): its up-to-date check and its action on the idl fixture, then
``roc work build`` of the fixture, where it runs before the package's build task (events.log)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from build_helpers import FIXTURES, in_sourced_shell, roc
from roc.engine.events import TaskOutput
from roc.engine.process import TaskContext, TaskError
from roc.idl.task import STATE_FILE, IdlGeneration, proto_directory

SOURCES = FIXTURES / "idl" / "src"
PACKAGE = SOURCES / "robot_proto_msgs"
TYPES = Path("proto") / "robot" / "types.proto"


def _run(generation: IdlGeneration) -> str:
    """Run the task's action; what it printed on stderr, or TaskError's message and that."""
    events = []
    try:
        generation.run(TaskContext(generation.name, events.append, kind="idl"))
        failure = ""
    except TaskError as error:
        failure = f"{error}\n"
    return failure + b"".join(e.data for e in events if isinstance(e, TaskOutput) and e.stream == "stderr").decode()


def _edit(path: Path, old: str, new: str) -> None:
    path.write_text(path.read_text().replace(old, new))


def test_proto_directory_from_the_export_marker():
    assert proto_directory(PACKAGE) == PACKAGE / "proto"
    assert proto_directory(SOURCES / "robot_proto_tools") is None


def test_check_says_why_and_run_rewrites_only_what_changed(tmp_path):
    source, build_dir = tmp_path / "src", tmp_path / "build"
    shutil.copytree(PACKAGE, source)
    generation = IdlGeneration("robot_proto_msgs", source, build_dir, forced=[], record=True)
    assert generation.check() == ["never generated"]
    assert _run(generation) == ""
    out = build_dir / "roc_idl"
    assert (out / "msg" / "Pose2D.msg").is_file() and generation.check() == []
    state = out / "msg" / "State.msg"
    before = state.stat().st_mtime_ns

    _edit(source / TYPES, "double theta = 3;", "double theta = 3;\n  string frame = 4;")
    assert generation.check() == [f"files changed: {TYPES}"]
    _run(generation)
    assert "string frame" in (out / "msg" / "Pose2D.msg").read_text()
    assert state.stat().st_mtime_ns == before  # same text: not rewritten, so CMake sees no change
    assert generation.check() == []

    (out / "msg" / "Pose2D.msg").unlink()
    assert generation.check() == ["generated files missing: msg/Pose2D.msg"]
    _run(generation)
    record = json.loads((build_dir / STATE_FILE).read_text())
    (build_dir / STATE_FILE).write_text(json.dumps({**record, "generator": "an older roc"}))
    assert generation.check() == ["code generator changed"]
    assert IdlGeneration("robot_proto_msgs", source, build_dir, ["--force"], True).check() == ["--force"]


def test_no_cache_generates_without_recording(tmp_path):
    source, build_dir = tmp_path / "src", tmp_path / "build"
    shutil.copytree(PACKAGE, source)
    _run(IdlGeneration("robot_proto_msgs", source, build_dir, forced=["--no-cache"], record=False))
    assert (build_dir / "roc_idl" / "roc_idl.cmake").is_file() and not (build_dir / STATE_FILE).exists()


def test_bad_proto_fails_with_its_file_and_line_and_is_never_up_to_date(tmp_path):
    source, build_dir = tmp_path / "src", tmp_path / "build"
    shutil.copytree(PACKAGE, source)
    generation = IdlGeneration("robot_proto_msgs", source, build_dir, forced=[], record=True)
    _run(generation)
    _edit(source / TYPES, "double y = 2;", "double y = 2 oops;")
    output = _run(generation)
    assert output.splitlines() == ["code generation failed", f'roc: error: {source / TYPES}:6:16: Expected ";".']
    assert generation.check() == ["its last code generation did not succeed"]
