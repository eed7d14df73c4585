"""roc.idl.codegen: a package with protobuf sources (workspaces/fixtures/idl) -> .msg files, roc_idl.cmake and
protoc's Python modules; the package then builds with rosidl and converts protobuf <-> ROS both ways.
The step runs inside the package's CMake build handler (roc/idl/buildstep.py)."""

from __future__ import annotations

import shutil

import pytest

from build_helpers import FIXTURES, colcon, in_sourced_shell, roc
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
from robot_proto_msgs_protobuf import to_proto, to_ros  # installed with the package
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
def test_roc_work_build_generates_builds_installs_converters_and_rebuilds_on_edit(tmp_path):
    workspace = tmp_path / "ws"
    shutil.copytree(PACKAGE, workspace / "src" / PACKAGE.name)
    build = roc("work", "build", cwd=workspace, timeout=900)
    assert build.returncode == 0, build.stdout + build.stderr
    assert "-m roc.idl.codegen robot_proto_msgs" in (workspace / "log" / "latest" / PACKAGE.name / "command.log").read_text()
    (tmp_path / "check.py").write_text(CHECK)
    run = in_sourced_shell(workspace, f"python {tmp_path / 'check.py'}")
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.strip() == "converted"
    # unchanged: skipped (fingerprints); a .proto edited: generated and built again
    again = roc("work", "build", cwd=workspace, timeout=900)
    assert again.returncode == 0 and "1 package up to date (not rebuilt): robot_proto_msgs" in again.stdout + again.stderr
    proto = workspace / "src" / PACKAGE.name / "proto" / "robot" / "types.proto"
    proto.write_text(proto.read_text().replace("double theta = 3;", "double theta = 3;\n  string frame = 4;"))
    edited = roc("work", "build", cwd=workspace, timeout=900)
    assert edited.returncode == 0, edited.stdout + edited.stderr
    assert "string frame" in (workspace / "build" / PACKAGE.name / "roc_idl" / "msg" / "Pose2D.msg").read_text()
    run = in_sourced_shell(workspace, "python -c 'from robot_proto_msgs.msg import Pose2D; print(Pose2D().frame == \"\")'")
    assert run.stdout.strip() == "True", run.stdout + run.stderr


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
