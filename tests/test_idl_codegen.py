"""roc.idl.codegen: a package with protobuf sources (workspaces/fixtures/idl) -> .msg files, roc_idl.cmake and
protoc's Python modules; the package then builds with rosidl and converts protobuf <-> ROS both ways.
(Not yet a task of roc work build: the test runs the step and passes ROC_IDL_DIR itself.)"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from build_helpers import FIXTURES, in_sourced_shell, roc
from roc.idl.codegen import generate

PACKAGE = FIXTURES / "idl" / "src" / "robot_proto_msgs"


def test_generate_writes_msgs_cmake_and_python(tmp_path):
    names = generate("robot_proto_msgs", PACKAGE / "proto", tmp_path)
    assert names == ["msg/Bytes.msg", "msg/Pose2D.msg", "msg/State.msg", "msg/StateSensorsEntry.msg"]
    cmake = (tmp_path / "roc_idl.cmake").read_text()
    assert f'"{tmp_path}:msg/State.msg"' in cmake and "set(ROC_IDL_DEPENDENCIES builtin_interfaces)" in cmake
    assert "Pose2D pose\nbuiltin_interfaces/Time stamp\nStateSensorsEntry[] sensors\n" in (
        tmp_path / "msg" / "State.msg").read_text()
    assert (tmp_path / "python" / "robot" / "state_pb2.py").is_file()


CHECK = """
from robot import state_pb2
from robot_proto_msgs.msg import State
from roc.idl.runtime import to_proto, to_ros
pb = state_pb2.State(mode=1, waypoint="dock", frames=[b"jpg"])
pb.pose.x, pb.pose.theta = 1.0, 0.5
pb.stamp.seconds = 42
pb.sensors["lidar"] = 0.25
ros = to_ros(pb, State)
assert ros.goal_case == State.GOAL_WAYPOINT and ros.mode == State.MODE_DRIVING and ros.stamp.sec == 42
assert to_proto(ros, state_pb2.State) == pb
print("converted")
"""


@pytest.mark.slow
def test_generated_package_builds_and_converts(tmp_path):
    workspace = tmp_path / "ws"
    shutil.copytree(PACKAGE, workspace / "src" / PACKAGE.name)
    generated = workspace / "build" / "roc_idl" / PACKAGE.name
    generate(PACKAGE.name, workspace / "src" / PACKAGE.name / "proto", generated)
    build = roc("work", "build", "--cmake-args", f"-DROC_IDL_DIR={generated}", cwd=workspace, timeout=900)
    assert build.returncode == 0, build.stdout + build.stderr
    (tmp_path / "check.py").write_text(CHECK)
    run = in_sourced_shell(workspace, f"PYTHONPATH={generated / 'python'}:$PYTHONPATH python {tmp_path / 'check.py'}")
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.strip() == "converted"
