"""The ``idl`` task (roc/idl/task.py): its up-to-date check and its action on the idl fixture, then
``roc work build`` of the fixture, where it runs before the package's build task (events.log)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from helpers.build import FIXTURES, in_sourced_shell, roc
from helpers.idl import CONVERT

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


def test_damaged_state_is_reported_and_generates_again(tmp_path, capsys):
    source, build_dir = tmp_path / "src", tmp_path / "build"
    shutil.copytree(PACKAGE, source)
    generation = IdlGeneration("robot_proto_msgs", source, build_dir, forced=[], record=True)
    _run(generation)
    (build_dir / STATE_FILE).write_text('{"inputs": [')
    assert generation.check() == ["its last code generation did not succeed"]
    assert f"{build_dir / STATE_FILE}: damaged code-generation state" in capsys.readouterr().err


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


def _events(workspace: Path) -> list[dict]:
    lines = (workspace / "log" / "latest_build" / "events.log").read_text().splitlines()
    return [json.loads(line) for line in lines]


def _reasons(events: list[dict]) -> dict[str, list[str]]:
    """Why each task ran, by task key."""
    return {(e["task"] if e["kind"] == "build" else f"{e['kind']}:{e['task']}"): e["reasons"]
            for e in events if e["event"] == "TaskStarted"}


def _build(workspace: Path, *args: str):
    result = roc("work", "build", *args, cwd=workspace, timeout=900)
    assert result.returncode == 0, result.stdout + result.stderr
    return result


@pytest.mark.slow
def test_roc_work_build_runs_the_idl_task_first_and_again_only_when_needed(tmp_path):
    workspace = tmp_path / "ws"
    shutil.copytree(SOURCES, workspace / "src")
    _build(workspace)
    order = [(e["event"], e["kind"], e["task"]) for e in _events(workspace)
             if e["event"] in ("TaskStarted", "TaskFinished")]
    assert order == [("TaskStarted", "idl", "robot_proto_msgs"), ("TaskFinished", "idl", "robot_proto_msgs"),
                     ("TaskStarted", "build", "robot_proto_msgs"), ("TaskFinished", "build", "robot_proto_msgs"),
                     ("TaskStarted", "build", "robot_proto_tools"), ("TaskFinished", "build", "robot_proto_tools")]
    assert _reasons(_events(workspace))["idl:robot_proto_msgs"] == ["never generated"]
    idl_log = workspace / "log" / "latest_build" / "robot_proto_msgs" / "idl" / "command.log"
    assert "-m roc.idl.codegen robot_proto_msgs" in idl_log.read_text()
    (tmp_path / "convert.py").write_text(CONVERT)
    run = in_sourced_shell(workspace, f"python {tmp_path / 'convert.py'}")
    assert run.returncode == 0 and run.stdout.strip() == "x y theta", run.stdout + run.stderr

    # nothing changed: every task cached, no tool runs
    again = _build(workspace)
    assert _reasons(_events(workspace)) == {}
    cached = [e for e in _events(workspace) if e["event"] == "TaskFinished" and e["cached"]]
    assert len(cached) == 3 and "2 packages and 1 idl task up to date" in again.stdout

    # a .proto edited: --explain says what would run and why; then generated again, the package and its
    # dependent built again, saying why
    _edit(workspace / "src" / "robot_proto_msgs" / TYPES, "double theta = 3;", "double theta = 3;\n  string frame = 4;")
    explained = roc("work", "build", "--explain", cwd=workspace)
    assert explained.stdout.splitlines()[:2] == [f"idl:robot_proto_msgs: files changed: {TYPES}",
                                                 f"robot_proto_msgs: files changed: {TYPES}"], explained.stdout
    as_json = json.loads(roc("work", "build", "--explain", "--output", "json", cwd=workspace).stdout)
    assert [(e["kind"], e["package"]) for e in as_json] == [("idl", "robot_proto_msgs"), ("build", "robot_proto_msgs"),
                                                            ("build", "robot_proto_tools")]
    _build(workspace)
    reasons = _reasons(_events(workspace))
    assert reasons["idl:robot_proto_msgs"] == [f"files changed: {TYPES}"]
    assert reasons["robot_proto_msgs"][0] == f"files changed: {TYPES}"
    assert reasons["robot_proto_tools"] == ["dependency changed: robot_proto_msgs"]
    run = in_sourced_shell(workspace, f"python {tmp_path / 'convert.py'}")
    assert run.stdout.strip() == "x y theta frame", run.stdout + run.stderr

    # --force and --no-cache generate again (rewriting nothing that did not change)
    state_msg = workspace / "build" / "robot_proto_msgs" / "roc_idl" / "msg" / "State.msg"
    before = state_msg.stat().st_mtime_ns
    for option in ("--force", "--no-cache"):
        _build(workspace, option, "--packages-select", "robot_proto_msgs")
        assert _reasons(_events(workspace)) == {"idl:robot_proto_msgs": [option], "robot_proto_msgs": [option]}
    assert state_msg.stat().st_mtime_ns == before

    # a bad .proto: the build fails with the file and line, no traceback, the idl task's log kept
    _edit(workspace / "src" / "robot_proto_msgs" / TYPES, "double y = 2;", "double y = 2 oops;")
    failed = roc("work", "build", cwd=workspace, timeout=900)
    output = failed.stdout + failed.stderr
    assert failed.returncode == 1 and "Traceback" not in output, output
    error = f'roc: error: {workspace / "src" / "robot_proto_msgs" / TYPES}:6:16: Expected ";".'
    assert error in output.splitlines() and "1 idl task failed: idl:robot_proto_msgs" in output, output
    assert error in (workspace / "log" / "latest_build" / "robot_proto_msgs" / "idl" / "stderr.log").read_text()
    assert [e["kind"] for e in _events(workspace) if e["event"] == "TaskStarted"] == ["idl"]
    # so the package's build did not succeed (--packages-select-build-failed picks it)
    assert (workspace / "build" / "robot_proto_msgs" / "colcon_build.rc").read_text() == "1\n"
