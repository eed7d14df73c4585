"""roc idl protobuf, .proto -> .msg: the corpus in tests/data/idl, each output checked by ROS 2's parsers."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from helpers.idl import DATA, check_msg_with_rosidl_parser, write
from rosidl_adapter.parser import parse_message_string

from roc.commands.idl.protobuf import convert
from roc.errors import RocError
from roc.idl import msg_to_proto

CORPUS = sorted((DATA / "example").rglob("*.proto"))


@pytest.fixture(scope="module")
def outputs() -> dict[str, str]:
    result, _ = convert(CORPUS, Path("."), None, [DATA], None)
    return result


def spec(outputs: dict[str, str], relative: str):
    package, _, name = relative.split("/")
    return parse_message_string(package, name[:-4], outputs[relative])


def fields(outputs: dict[str, str], relative: str) -> dict[str, str]:
    return {f.name: str(f.type) for f in spec(outputs, relative).fields}


def constants(outputs: dict[str, str], relative: str) -> dict[str, tuple[str, object]]:
    return {c.name: (c.type, c.value) for c in spec(outputs, relative).constants}


@pytest.mark.slow
def test_every_output_passes_both_ros_parsers(outputs, tmp_path):
    write(outputs, tmp_path / "out")
    for relative in outputs:
        check_msg_with_rosidl_parser(tmp_path / "out", relative, tmp_path / "idl")


def test_every_output_converts_back_to_a_proto_that_compiles(outputs, tmp_path):
    write(outputs, tmp_path)
    msg_to_proto.convert(sorted(tmp_path.glob("*/msg/*.msg")), None, msg_to_proto.Config(), [])


def test_layout_packages_and_flattened_names(outputs):
    assert set(outputs) == {
        "example_common_msgs/msg/Point.msg", "example_common_msgs/msg/Unit.msg",
        "example_enums_msgs/msg/Color.msg", "example_enums_msgs/msg/Signed.msg",
        "example_legacy_msgs/msg/Settings.msg", "example_legacy_msgs/msg/Tuning.msg",
        "example_robot_msgs/msg/Robot.msg", "example_robot_msgs/msg/RobotJoint.msg",
        "example_robot_msgs/msg/RobotJointLimits.msg", "example_robot_msgs/msg/FooBar.msg",
        "example_robot_msgs/msg/RobotJointsByNameEntry.msg", "example_robot_msgs/msg/RobotGainsEntry.msg",
        "example_robot_msgs/msg/Bytes.msg",
        "example_wkt_msgs/msg/Everything.msg", "example_wkt_msgs/msg/EverythingAttributesEntry.msg",
        "example_wkt_msgs/msg/Any.msg", "example_wkt_msgs/msg/Empty.msg", "example_wkt_msgs/msg/Bytes.msg",
    }


def test_scalars_enums_oneof_maps_and_imports(outputs):
    robot = fields(outputs, "example_robot_msgs/msg/Robot.msg")
    assert robot == {
        "name": "string", "status": "uint8", "level": "int32", "joints": "example_robot_msgs/RobotJoint[]",
        "joints_by_name": "example_robot_msgs/RobotJointsByNameEntry[]",
        "gains": "example_robot_msgs/RobotGainsEntry[]", "target_case": "uint8",
        "point": "example_common_msgs/Point", "frame_id": "string", "stamp": "builtin_interfaces/Time",
        "uptime": "builtin_interfaces/Duration", "blobs": "example_robot_msgs/Bytes[]", "payload": "uint8[]",
        "battery": "int32", "serial_number": "int64", "unit": "uint8", "path": "example_common_msgs/Point[]",
        "s32": "int32", "sf64": "int64", "f32": "uint32", "u64": "uint64", "ratio": "float32", "enabled": "bool",
    }
    assert constants(outputs, "example_robot_msgs/msg/Robot.msg") == {
        "STATUS_UNKNOWN": ("uint8", 0), "STATUS_OK": ("uint8", 1), "STATUS_FAULT": ("uint8", 2),
        "K_LOW": ("int32", 0), "K_HIGH": ("int32", 1000), "K_MAX": ("int32", 1000),
        "TARGET_NOT_SET": ("uint8", 0), "TARGET_POINT": ("uint8", 1), "TARGET_FRAME_ID": ("uint8", 2),
    }
    assert fields(outputs, "example_robot_msgs/msg/RobotGainsEntry.msg") == {"key": "int32", "value": "float64"}
    assert fields(outputs, "example_robot_msgs/msg/RobotJointsByNameEntry.msg") == {
        "key": "string", "value": "example_robot_msgs/RobotJoint"}
    assert fields(outputs, "example_robot_msgs/msg/Bytes.msg") == {"data": "uint8[]"}
    assert fields(outputs, "example_robot_msgs/msg/FooBar.msg") == {
        "limits": "example_robot_msgs/RobotJointLimits", "status": "uint8"}


def test_enum_only_files_and_top_level_enums(outputs):
    assert fields(outputs, "example_enums_msgs/msg/Color.msg") == {}
    assert constants(outputs, "example_enums_msgs/msg/Color.msg") == {
        "COLOR_UNSPECIFIED": ("uint8", 0), "COLOR_RED": ("uint8", 1), "COLOR_GREEN": ("uint8", 2)}
    assert constants(outputs, "example_enums_msgs/msg/Signed.msg") == {
        "SIGNED_ZERO": ("int32", 0), "SIGNED_NEGATIVE": ("int32", -1)}


def test_proto2_defaults(outputs):
    defaults = {f.name: f.default_value for f in spec(outputs, "example_legacy_msgs/msg/Settings.msg").fields}
    text = outputs["example_legacy_msgs/msg/Settings.msg"]
    # nan and inf pass the ROS parsers but rosidl's C generator cannot build them: kept as comments
    assert "# default: nan (not finite: rosidl cannot build it)\nfloat64 gain\n" in text
    assert "# default: inf (not finite: rosidl cannot build it)\nfloat32 limit\n" in text
    assert "# default: -inf (not finite: rosidl cannot build it)\nfloat32 floor\n" in text
    assert defaults == {"gain": None, "limit": None, "floor": None, "count": -7, "big": 2**64 - 1,
                        "label": 'say "hi"', "magic": [1, 2, 65, 66], "flag": True, "mode": 1,
                        "id": None, "values": None}


def test_well_known_types(outputs):
    assert fields(outputs, "example_wkt_msgs/msg/Everything.msg") == {
        "any": "example_wkt_msgs/Any", "duration": "builtin_interfaces/Duration", "empty": "example_wkt_msgs/Empty",
        "mask": "string[]", "struct_value": "string", "value": "string", "list": "string",
        "time": "builtin_interfaces/Time", "d": "float64", "f": "float32", "i64": "int64", "u64": "uint64",
        "i32": "int32", "u32": "uint32", "b": "bool", "s": "string", "bytes_value": "uint8[]",
        "times": "builtin_interfaces/Time[]", "blobs": "example_wkt_msgs/Bytes[]",
        "attributes": "example_wkt_msgs/EverythingAttributesEntry[]", "null_value": "uint8",
    }
    assert fields(outputs, "example_wkt_msgs/msg/Any.msg") == {"type_url": "string", "value": "uint8[]"}
    assert fields(outputs, "example_wkt_msgs/msg/Empty.msg") == {}


def test_config_retypes_the_field_closing_a_cycle(tmp_path):
    errors = DATA / "errors"
    with pytest.raises(RocError, match=r"recursive.proto:10: recursive type example.tree.Node.branch -> "
                                       r"example.tree.Branch.children -> example.tree.Node"):
        convert([errors / "recursive.proto"], tmp_path, None, [], None)
    result, notes = convert([errors / "recursive.proto"], tmp_path, None, [], errors / "recursive.yaml")
    assert "string[] children" in result["example_tree_msgs/msg/Branch.msg"]
    assert notes == ["example.tree.Branch.children: retyped to string[] (--config)"]


def test_config_renames_and_packages(tmp_path):
    config = tmp_path / "c.yaml"
    config.write_text("renames:\n  example.clash.Robot.Status: RobotState\npackages:\n  example.clash: clash_msgs\n")
    result, _ = convert([DATA / "errors" / "collision.proto"], tmp_path, None, [], config)
    assert sorted(result) == ["clash_msgs/msg/Robot.msg", "clash_msgs/msg/RobotState.msg",
                              "clash_msgs/msg/RobotStatus.msg"]


def test_package_option_for_files_without_package(tmp_path):
    result, _ = convert([DATA / "errors" / "no_package.proto"], tmp_path, "loose_msgs", [], None)
    assert list(result) == ["loose_msgs/msg/Loose.msg"]


def roc(*arguments: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "roc", *arguments], cwd=cwd, capture_output=True, text=True)


@pytest.mark.parametrize("arguments, message", [
    (["a.proto", "b.msg"], "roc: error: a.proto and b.msg: mixed .proto and .msg files"),
    (["a.txt"], "roc: error: a.txt: unknown extension '.txt'"),
    (["missing.proto"], "roc: error: missing.proto: no such file"),
    ([str(DATA / "errors" / "syntax.proto")], "syntax.proto:6:1: Expected \";\"."),
    ([str(DATA / "errors" / "recursive.proto")], "roc: error: recursive.proto:10: recursive type"),
    ([str(DATA / "errors" / "collision.proto")], "roc: error: collision.proto:8: 'example.clash.RobotStatus' and"),
    ([str(DATA / "errors" / "no_package.proto")], "roc: error: no_package.proto: no 'package' statement"),
    (["-c", str(DATA / "errors" / "bad_key.yaml"), str(DATA / "errors" / "no_package.proto")],
     "bad_key.yaml: unknown key 'typos'"),
])
def test_bad_input_is_one_line_and_writes_nothing(tmp_path, arguments, message):
    (tmp_path / "a.proto").write_text('syntax = "proto3";\n')
    (tmp_path / "b.msg").write_text("int32 a\n")
    (tmp_path / "a.txt").write_text("")
    result = roc("idl", "protobuf", "-o", "out", *arguments, cwd=tmp_path)
    assert result.returncode == 1
    assert len(result.stderr.splitlines()) == 1 and result.stderr.startswith("roc: error: ")
    assert message in result.stderr
    assert not (tmp_path / "out").exists()


def test_cli_writes_and_dry_run_does_not(tmp_path):
    source = str(DATA / "example" / "enums_only.proto")
    dry = roc("idl", "protobuf", "-n", "-o", "out", source, cwd=tmp_path)
    assert dry.returncode == 0 and "would write out/example_enums_msgs/msg/Color.msg" in dry.stdout
    assert not (tmp_path / "out").exists()
    done = roc("idl", "protobuf", "-o", "out", source, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "out" / "example_enums_msgs" / "msg" / "Color.msg").read_text().endswith("COLOR_GREEN=2\n")
