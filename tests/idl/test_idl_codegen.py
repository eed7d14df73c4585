"""roc.idl.codegen: a package with protobuf sources (workspaces/fixtures/idl) -> .msg files, roc_idl.cmake and
protoc's Python modules. roc work build runs it as the package's ``idl`` task (tests/idl/test_idl_task.py);
colcon through the package's CMakeLists.txt."""

from __future__ import annotations

import shutil

import pytest
from helpers.build import FIXTURES, colcon, in_sourced_shell

from roc.idl.codegen import generate

PACKAGE = FIXTURES / "idl" / "src" / "robot_proto_msgs"


def test_generate_writes_msgs_cmake_and_python(tmp_path):
    written = generate("robot_proto_msgs", PACKAGE / "proto", tmp_path)
    assert [f for f in written if f.startswith("msg/")] == [
        "msg/Bytes.msg", "msg/Pose2D.msg", "msg/State.msg", "msg/StateSensorsEntry.msg"]
    cmake = (tmp_path / "roc_idl.cmake").read_text()
    texts = [p.read_text() for p in tmp_path.rglob("*") if p.is_file()]
    assert not any(str(tmp_path) in t or str(PACKAGE) in t for t in texts)  # the same bytes wherever built
    assert '"${CMAKE_CURRENT_LIST_DIR}:msg/State.msg"' in cmake
    assert "set(ROC_IDL_DEPENDENCIES builtin_interfaces)" in cmake
    assert "Pose2D pose\nbuiltin_interfaces/Time stamp\nStateSensorsEntry[] sensors\n" in (
        tmp_path / "msg" / "State.msg").read_text()
    assert (tmp_path / "python" / "robot" / "state_pb2.py").is_file()
    assert (tmp_path / "python" / "robot_proto_msgs_protobuf" / "__init__.py").is_file()


def test_generate_again_rewrites_nothing_and_removes_what_is_no_longer_made(tmp_path):
    generate("robot_proto_msgs", PACKAGE / "proto", tmp_path)
    (tmp_path / "msg" / "Old.msg").write_text("int32 gone\n")
    assert generate("robot_proto_msgs", PACKAGE / "proto", tmp_path) == ["msg/Old.msg"]
    assert not (tmp_path / "msg" / "Old.msg").exists()


@pytest.mark.slow
@pytest.mark.colcon
def test_colcon_builds_it_through_the_cmake_fallback(tmp_path):
    """colcon knows nothing of the marker: the fixture's CMakeLists.txt runs the step at configure time."""
    workspace = tmp_path / "ws"
    shutil.copytree(PACKAGE, workspace / "src" / PACKAGE.name)
    build = colcon("build", cwd=workspace)
    assert build.returncode == 0, build.stdout + build.stderr
    run = in_sourced_shell(workspace, "python -c 'import robot_proto_msgs_protobuf, robot.state_pb2; "
                                      "from robot_proto_msgs.msg import State; print(State.GOAL_WAYPOINT)'",
                           strict=False)  # colcon's scripts do not run under set -u
    assert run.stdout.strip() == "2", run.stdout + run.stderr
