"""Shared checks for the roc idl tests: outputs parsed by ROS 2's parsers and compiled by protoc."""

from __future__ import annotations

import contextlib
import io
import sys
from pathlib import Path

DATA = Path(__file__).resolve().parents[1] / "data" / "idl"
SHARE = Path(sys.prefix) / "share"


def interface_msgs(packages: list[str] | None = None) -> list[Path]:
    """The .msg files of the interface packages installed in the venv (common_interfaces, test_msgs, ...)."""
    files = sorted(SHARE.glob("*/msg/*.msg"))
    return [f for f in files if packages is None or f.parent.parent.name in packages]


def write(outputs: dict[str, str], root: Path) -> None:
    for relative, text in outputs.items():
        (root / relative).parent.mkdir(parents=True, exist_ok=True)
        (root / relative).write_text(text)


def check_msg_with_rosidl_parser(root: Path, relative: str, tmp: Path):
    """Beyond rosidl_adapter: the .msg -> .idl conversion and rosidl_parser's IDL grammar."""
    from rosidl_adapter.msg import convert_msg_to_idl
    from rosidl_parser.definition import IdlLocator
    from rosidl_parser.parser import parse_idl_file

    package = relative.split("/")[0]
    tmp.mkdir(parents=True, exist_ok=True)
    with contextlib.redirect_stdout(io.StringIO()):
        idl = convert_msg_to_idl(root / package, package, Path(relative).relative_to(package), tmp)
    return parse_idl_file(IdlLocator(tmp, idl.name))


# A program run in a sourced workspace of workspaces/fixtures/idl: the protobuf and ROS messages the
# package generated, converted both ways by its installed conversion module and used by its dependent.
CONVERT = """
from robot import state_pb2
from robot_proto_msgs.msg import State
from robot_proto_msgs_protobuf import to_proto, to_ros  # installed with the package
from robot_proto_tools import pose_fields  # the dependent package
pb = state_pb2.State(mode=1, waypoint="dock", frames=[b"jpg"])
pb.pose.x, pb.pose.theta = 1.0, 0.5
pb.stamp.seconds = 42
pb.sensors["lidar"] = 0.25
ros = to_ros(pb, State)
assert ros.goal_case == State.GOAL_WAYPOINT and ros.mode == State.MODE_DRIVING and ros.stamp.sec == 42
assert to_proto(ros, state_pb2.State) == pb
print(" ".join(pose_fields()))
"""
