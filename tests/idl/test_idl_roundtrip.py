""".msg -> .proto -> .msg round trips of every installed interface .msg (common_interfaces, test_msgs, ...):
every field name, every constant, every type up to the documented widening; every .proto compiles."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.idl import check_msg_with_rosidl_parser, interface_msgs, write
from rosidl_adapter.parser import parse_message_file, parse_message_string

from roc.commands.idl.protobuf import convert
from roc.idl.msg_to_proto import SCALARS

# The ROS type each ROS type comes back as (msg -> proto -> msg).
WIDENED = {"byte": "uint32", "char": "uint32", "int8": "int32", "int16": "int32", "uint8": "uint32",
           "uint16": "uint32", "wstring": "string"}
INTEGERS = {"byte", "char", "int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "uint64"}
# builtin_interfaces (google.protobuf Timestamp/Duration on the way) is left out by that rule too.
# Only packages named *_msgs come back under their own name (others get "_msgs" added, see the README).
SOURCES = [f for f in interface_msgs() if f.parent.parent.name.endswith("_msgs")]


def widened(type_) -> str:
    """The type a field has after the round trip: arrays unbounded, strings unbounded, integers widened."""
    base = f"{type_.pkg_name}/{type_.type}" if type_.pkg_name else WIDENED.get(type_.type, type_.type)
    if type_.is_array and type_.type in ("uint8", "byte") and not type_.pkg_name:
        return "uint8[]"
    return base + ("[]" if type_.is_array else "")


@pytest.fixture(scope="module")
def round_trip(tmp_path_factory) -> tuple[Path, dict[str, str]]:
    protos = tmp_path_factory.mktemp("proto")
    write(convert(SOURCES, protos, None, [], None)[0], protos)
    back, _ = convert(sorted(protos.glob("*/*.proto")), Path("."), None, [protos], None)
    return protos, back


def test_sources_cover_common_interfaces_and_test_msgs():
    packages = {f.parent.parent.name for f in SOURCES}
    assert {"std_msgs", "geometry_msgs", "sensor_msgs", "nav_msgs", "visualization_msgs", "test_msgs"} <= packages
    assert len(SOURCES) > 100


def test_every_message_comes_back(round_trip):
    _, back = round_trip
    assert sorted(back) == sorted(f"{f.parent.parent.name}/msg/{f.name}" for f in SOURCES)


@pytest.mark.parametrize("source", SOURCES, ids=lambda f: f"{f.parent.parent.name}/{f.stem}")
def test_fields_constants_and_types_survive(round_trip, source):
    _, back = round_trip
    package = source.parent.parent.name
    original = parse_message_file(package, str(source))
    again = parse_message_string(package, source.stem, back[f"{package}/msg/{source.name}"])
    assert [f.name for f in again.fields] == [f.name for f in original.fields]
    types = [str(f.type).replace(f"{package}/", "", 0) for f in again.fields]
    assert types == [widened(f.type) for f in original.fields]
    before = {c.name: c for c in original.constants}
    after = {c.name: c for c in again.constants}
    assert set(after) == set(before)
    for name, constant in before.items():
        assert after[name].value == constant.value, name
        if constant.type in INTEGERS:  # grouped into a protobuf enum: uint8 when 0..255, else int32
            assert after[name].type in (constant.type, "uint8", "int32")
        else:
            assert after[name].type == constant.type


@pytest.mark.slow
def test_round_trip_outputs_pass_rosidl_parser(round_trip, tmp_path):
    _, back = round_trip
    write(back, tmp_path / "out")
    for relative in back:
        check_msg_with_rosidl_parser(tmp_path / "out", relative, tmp_path / "idl" / relative.split("/")[0])


def test_every_proto_type_is_a_protobuf_type(round_trip):
    protos, _ = round_trip
    text = (protos / "test_msgs" / "BasicTypes.proto").read_text()
    for ros, proto in SCALARS.items():
        if ros not in ("string", "wstring"):
            assert f"{proto} {ros}_value = " in text, ros
    assert "uint32 byte_value = 2;  // ROS: byte" in text
    assert "repeated double float64_values = 5;  // ROS: float64[3]" in (protos / "test_msgs" / "Arrays.proto").read_text()
