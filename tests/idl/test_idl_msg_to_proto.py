"""roc idl protobuf, .msg -> .proto: enums from constant groups, comments, imports, errors."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.idl import write

from roc.commands.idl.protobuf import convert
from roc.errors import RocError

STATUS = """\
# A status.
int8 LEVEL_WARN=4
int8 LEVEL_ERROR=8
int8 LEVEL_ALIAS=8
uint32 BIG_A=1
uint32 BIG_B=4000000000
float64 PI=3.14159
string NAME="roc"
uint8 MODE_A=0
uint8 MODE_B=1
std_msgs/Header header
builtin_interfaces/Time stamp
int8 level 4
string<=10 label
float64[3] xyz
uint8[] payload
byte[4] magic
Other[<=2] others
"""


@pytest.fixture
def package(tmp_path: Path) -> Path:
    msg = tmp_path / "demo_msgs" / "msg"
    msg.mkdir(parents=True)
    (msg / "Status.msg").write_text(STATUS)
    (msg / "Other.msg").write_text("wstring w\n")
    return msg


def test_enums_constants_comments_and_imports(package, tmp_path):
    outputs, _ = convert([package / "Status.msg", package / "Other.msg"], tmp_path, None, [], None)
    text = outputs["demo_msgs/Status.proto"]
    assert 'package demo_msgs;' in text
    assert 'import "demo_msgs/Other.proto";' in text and 'import "std_msgs/Header.proto";' in text
    assert 'import "google/protobuf/timestamp.proto";' in text
    assert "  enum Level {\n    option allow_alias = true;\n    LEVEL_UNSPECIFIED = 0;  // roc: added" in text
    assert "  enum Mode {\n    MODE_A = 0;\n    MODE_B = 1;\n  }" in text
    for constant in ("uint32 BIG_A=1", "uint32 BIG_B=4000000000", "float64 PI=3.14159", "string NAME='roc'"):
        assert f"// ROS constant: {constant}\n" in text
    assert "  .std_msgs.Header header = 1;\n  google.protobuf.Timestamp stamp = 2;\n" in text
    assert "  int32 level = 3;  // ROS: int8, default: 4\n" in text
    assert "  string label = 4;  // ROS: string<=10\n" in text
    assert "  repeated double xyz = 5;  // ROS: float64[3]\n" in text
    assert "  bytes payload = 6;\n" in text and "  bytes magic = 7;  // ROS: byte[4]\n" in text
    assert "  repeated .demo_msgs.Other others = 8;  // ROS: demo_msgs/Other[<=2]\n" in text
    assert "  string w = 1;  // ROS: wstring\n" in outputs["demo_msgs/Other.proto"]


def test_back_to_msg_keeps_constants_exactly_where_protobuf_has_no_enum(package, tmp_path):
    protos, _ = convert([package / "Status.msg", package / "Other.msg"], tmp_path, None, [], None)
    write(protos, tmp_path / "p")
    (tmp_path / "p" / "std_msgs").mkdir()
    (tmp_path / "p" / "std_msgs" / "Header.proto").write_text('syntax = "proto3";\npackage std_msgs;\nmessage Header {}\n')
    back, _ = convert([tmp_path / "p" / "demo_msgs" / "Status.proto"], tmp_path, None, [tmp_path / "p"], None)
    text = back["demo_msgs/msg/Status.msg"]
    assert "uint32 BIG_B=4000000000\nfloat64 PI=3.14159\nstring NAME='roc'\n" in text
    assert "uint8 LEVEL_WARN=4\n" in text and "LEVEL_UNSPECIFIED" not in text
    assert "std_msgs/Header header\nbuiltin_interfaces/Time stamp\n" in text


def test_package_from_option_or_directory(tmp_path):
    loose = tmp_path / "Loose.msg"
    loose.write_text("int32 a\n")
    with pytest.raises(RocError, match=r"Loose.msg: cannot tell its ROS package .*--package"):
        convert([loose], tmp_path, None, [], None)
    assert list(convert([loose], tmp_path, "loose_msgs", [], None)[0]) == ["loose_msgs/Loose.proto"]


def test_invalid_msg_is_one_error_naming_the_file(tmp_path):
    bad = tmp_path / "demo_msgs" / "msg" / "Bad.msg"
    bad.parent.mkdir(parents=True)
    bad.write_text("int32 Bad-Name\n")
    with pytest.raises(RocError, match=r"Bad.msg: not a valid ROS 2 message"):
        convert([bad], tmp_path, None, [], None)


def test_generated_helper_collision_and_repeated_field_mask_are_errors(tmp_path):
    proto = tmp_path / "clash.proto"
    proto.write_text('syntax = "proto3";\npackage x;\nimport "google/protobuf/field_mask.proto";\n'
                     "message Bytes { int32 a = 1; }\nmessage M { repeated bytes b = 1; }\n")
    with pytest.raises(RocError, match=r"clash.proto:5: the message roc generates for Bytes collides"):
        convert([proto], tmp_path, None, [], None)
    proto.write_text('syntax = "proto3";\npackage x;\nimport "google/protobuf/field_mask.proto";\n'
                     "message N { repeated google.protobuf.FieldMask m = 1; }\n")
    with pytest.raises(RocError, match=r"clash.proto:4: repeated google.protobuf.FieldMask has no ROS type"):
        convert([proto], tmp_path, None, [], None)
