"""Message <-> YAML/dict/CSV conversion (roc/ros/messages.py) and type resolution (roc/ros/types.py).

The oracle is the real rosidl_runtime_py 0.13.1 (what ``ros2 topic echo`` prints with), unpacked
from shared/oracles and imported from there; every installed message type goes through both.
"""

from __future__ import annotations

import importlib
import math
import re
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path
from typing import Any

import pytest
from helpers.build import REPO, in_sourced_shell, roc, ros_env
from helpers.oracles import SHARED, require_oracle
from rclpy.serialization import deserialize_message, serialize_message
from rosidl_parser import definition as idl

from roc.ros import messages
from roc.ros.messages import (
    MessageValueError,
    dict_to_yaml,
    echo_text,
    fill_message,
    get_field,
    message_to_csv,
    message_to_dict,
    message_to_yaml,
    parse_values,
    prototype,
)
from roc.ros.types import TypeNameError, UnknownTypeError, resolve_type, type_name

REFERENCE = SHARED / "reference" / "ros2cli"
INDEX = Path(sys.prefix) / "share" / "ament_index" / "resource_index" / "rosidl_interfaces"


@pytest.fixture(scope="session")
def oracle(tmp_path_factory: pytest.TempPathFactory) -> Any:
    """rosidl_runtime_py.convert, the code ros2 echoes messages with."""
    archive = require_oracle("rosidl_runtime_py", SHARED / "oracles" / "rosidl_runtime_py-0.13.1.tar.gz")
    target = tmp_path_factory.mktemp("oracle")
    with tarfile.open(archive) as tar:
        tar.extractall(target, filter="data")
    sys.path.insert(0, str(target / "rosidl_runtime_py"))
    try:
        return importlib.import_module("rosidl_runtime_py.convert")
    finally:
        sys.path.remove(str(target / "rosidl_runtime_py"))


def installed_message_types() -> list[str]:
    """Every message of the venv's interface packages, with the messages of their services and actions."""
    names = []
    for package in sorted(INDEX.iterdir()):
        for line in package.read_text().split():
            kind, _, file = line.partition("/")
            stem, suffix = file.rsplit(".", 1)
            if suffix != "idl":
                continue
            if kind == "msg":
                names.append(f"{package.name}/msg/{stem}")
            elif kind == "srv":
                names += [f"{package.name}/srv/{stem}_{part}" for part in ("Request", "Response")]
            elif kind == "action":
                names += [f"{package.name}/action/{stem}_{part}"
                          for part in ("Goal", "Result", "Feedback", "FeedbackMessage")]
    return names


ALL_TYPES = installed_message_types()
FLOAT32_MAX = 3.4028234663852886e38
SAMPLES: dict[str, list[Any]] = {
    "boolean": [True, False],
    "octet": ["\xff", "\x00", "\x7f"],
    "float": [FLOAT32_MAX, -FLOAT32_MAX, math.inf, -math.inf, 1.5, math.nan],
    "double": [sys.float_info.max, -sys.float_info.max, 5e-324, math.nan, -math.inf, 0.1],
}
TEXT = ["ünïcode: 'quoted' \"both\" # not a comment", "", "line\nbreak", "- dash",
        "emoji 😀, controls \x85 \u2028 \x07 \ttab, trailing space ", "null", "0x1F"]
WIDE = ["ハローワールド ✓", "", "Hellö", "😀 astral"]


def sample(slot: Any, variant: int) -> Any:
    """A value at the limits for a field (which limit depends on ``variant``), in echo's format."""
    if isinstance(slot, idl.AbstractNestedType):
        size = (slot.size if isinstance(slot, idl.Array) else slot.maximum_size
                if isinstance(slot, idl.BoundedSequence) else 3 - variant % 4)
        return [sample(slot.value_type, variant + i) for i in range(size)]
    if isinstance(slot, idl.BasicType):
        if slot.typename in messages.INT_RANGES:
            return messages.INT_RANGES[slot.typename][variant % 2 == 0]
        values = SAMPLES[slot.typename]
        return values[variant % len(values)]
    if isinstance(slot, idl.AbstractWString):
        text = WIDE[variant % len(WIDE)]
    elif isinstance(slot, idl.AbstractString):
        text = TEXT[variant % len(TEXT)]
    else:
        return sample_values(resolve_type("/".join(slot.namespaced_name())), variant)
    bound = getattr(slot, "maximum_size", None)
    return (text * 22)[:bound] if bound else text


def sample_values(cls: type, variant: int = 0) -> dict[str, Any]:
    return {name: sample(slot, variant + i) for i, (name, slot) in enumerate(messages.fields(cls))}


def test_every_installed_package_is_enumerated() -> None:
    for expected in ("std_msgs/msg/String", "sensor_msgs/msg/PointCloud2", "test_msgs/msg/MultiNested",
                     "test_msgs/msg/WStrings", "std_srvs/srv/SetBool_Request", "test_msgs/action/Fibonacci_Goal"):
        assert expected in ALL_TYPES
    assert len(ALL_TYPES) > 200


@pytest.mark.slow
@pytest.mark.parametrize("name", ALL_TYPES)
def test_yaml_round_trip_matches_ros2(name: str, oracle: Any) -> None:
    """YAML -> message -> YAML gives the same text, equal to rosidl_runtime_py's for the same message,
    and the message is valid for the wire (serialises and comes back the same)."""
    cls = resolve_type(name)
    for variant in (0, 1):
        text = dict_to_yaml(sample_values(cls, variant))
        msg = fill_message(cls, parse_values(text))
        assert message_to_yaml(msg) == text
        assert message_to_yaml(msg) == oracle.message_to_yaml(msg)
        again = deserialize_message(serialize_message(msg), cls)
        assert message_to_yaml(again) == oracle.message_to_yaml(again)
        for options in ({"truncate_length": 2}, {"no_arr": True}, {"no_str": True},
                        {"truncate_length": 1, "no_str": True}):
            assert message_to_yaml(again, **options) == oracle.message_to_yaml(again, **options), options
            assert message_to_csv(again, **options) == oracle.message_to_csv(again, **options), options
        assert message_to_csv(again) == oracle.message_to_csv(again)
        assert message_to_yaml(again, flow_style=True) == oracle.message_to_yaml(again, flow_style=True)


def test_defaults_and_constants(oracle: Any) -> None:
    from test_msgs.msg import Constants, Defaults

    assert message_to_dict(Constants()) == {}
    assert message_to_yaml(Constants()) == "{}\n"
    assert Constants.INT8_CONST == -50
    assert message_to_yaml(Defaults()) == oracle.message_to_yaml(Defaults())
    assert message_to_dict(Defaults())["byte_value"] == "2"  # byte 50, printed as its character
    assert message_to_dict(fill_message("test_msgs/msg/Defaults", {"int8_value": 1})) == {
        **message_to_dict(Defaults()), "int8_value": 1}


def test_limits_survive_the_wire() -> None:
    from test_msgs.msg import BasicTypes, BoundedSequences, WStrings

    msg = fill_message(BasicTypes, {"int64_value": -(2**63), "uint64_value": 2**64 - 1, "float32_value": ".nan",
                                    "float64_value": "-inf", "byte_value": 255, "char_value": 255})
    back = deserialize_message(serialize_message(msg), BasicTypes)
    assert (back.int64_value, back.uint64_value, back.byte_value, back.char_value) == (-(2**63), 2**64 - 1,
                                                                                      b"\xff", 255)
    assert math.isnan(back.float32_value) and back.float64_value == -math.inf
    wide = deserialize_message(serialize_message(fill_message(WStrings, {"wstring_value": "ハロー ✓"})), WStrings)
    assert wide.wstring_value == "ハロー ✓"
    full = fill_message(BoundedSequences, {"int8_values": [-128, 0, 127], "string_values": ["a", "b", "c"]})
    assert list(deserialize_message(serialize_message(full), BoundedSequences).int8_values) == [-128, 0, 127]


def test_large_arrays_take_the_fast_path() -> None:
    msg = fill_message("sensor_msgs/msg/PointCloud2", {"data": list(range(256)) * 4096})
    assert len(msg.data) == 1 << 20 and msg.data.typecode == "B"
    grid = fill_message("nav_msgs/msg/OccupancyGrid", {"data": [-1, 0, 100] * 1000})
    assert message_to_dict(grid)["data"][:3] == [-1, 0, 100]


def stdout_of(reference: str) -> str:
    require_oracle("ros2 reference outputs", REFERENCE)
    text = require_oracle("ros2 reference output", REFERENCE / reference).read_text()
    return text.split("--- stdout ---\n", 1)[1].split("--- stderr ---\n", 1)[0]


@pytest.mark.parametrize("reference, type_", [
    ("topic_echo_once.txt", "std_msgs/msg/String"),
    ("topic_echo_once_odom.txt", "nav_msgs/msg/Odometry"),
    ("topic_echo_once_map.txt", "nav_msgs/msg/OccupancyGrid"),
])
def test_echo_text_equals_ros2(reference: str, type_: str) -> None:
    """The same values print as ros2 topic echo printed them, byte for byte."""
    expected = stdout_of(reference)
    assert expected.endswith("\n---\n")
    msg = fill_message(type_, parse_values(expected.removesuffix("---\n")))
    assert echo_text(msg) == expected
    assert echo_text(msg, csv=True) == message_to_csv(msg) + "\n"


def test_echo_field_selects_like_ros2() -> None:
    expected = stdout_of("topic_echo_once_field.txt")
    msg = fill_message("std_msgs/msg/String", {"data": "Hello World: 224"})
    assert echo_text(get_field(msg, "data")) == expected
    odom = fill_message("nav_msgs/msg/Odometry", {"pose": {"pose": {"position": {"x": 1.5}}}})
    assert message_to_dict(get_field(odom, "pose.pose.position")) == {"x": 1.5, "y": 0.0, "z": 0.0}
    with pytest.raises(MessageValueError) as error:
        get_field(odom, "pose.q")
    assert str(error.value) == "pose.q: geometry_msgs/msg/PoseWithCovariance has no field 'q' (pose, covariance)"
    assert error.value.ros2_line == "Invalid field 'pose.q': 'PoseWithCovariance' object has no attribute 'q'"
    with pytest.raises(MessageValueError) as error:
        get_field(odom, "child_frame_id.x")
    assert str(error.value) == "child_frame_id.x: 'child_frame_id' is not a message"
    assert error.value.ros2_line == "Invalid field 'child_frame_id.x': 'str' object has no attribute 'x'"
    with pytest.raises(MessageValueError) as error:
        get_field(fill_message("std_msgs/msg/Empty", {}), "x")
    assert str(error.value) == "x: std_msgs/msg/Empty has no field 'x' (it has no fields)"
    with pytest.raises(MessageValueError) as error:
        get_field(odom, ".")
    assert error.value.ros2_line == "Invalid field value '.'"


def test_flow_style_and_csv() -> None:
    msg = fill_message("geometry_msgs/msg/Twist", parse_values("{linear: {x: 2.0}, angular: {z: -1}}"))
    assert message_to_yaml(msg, flow_style=True) == message_to_yaml(msg)  # ros2 keeps mappings in block style
    array = fill_message("std_msgs/msg/Float64MultiArray", {"data": [1.0, 2.5]})
    assert message_to_yaml(array, flow_style=True) == "layout:\n  dim: []\n  data_offset: 0\ndata: [1.0, 2.5]\n"
    assert message_to_csv(msg) == "2.0,0.0,0.0,0.0,0.0,-1.0"
    assert message_to_yaml(fill_message("std_msgs/msg/String", {"data": "x" * 200})) == f"data: {'x' * 200}\n"


def test_prototype(oracle: Any) -> None:
    assert prototype("geometry_msgs/msg/Twist") == {"linear": {"x": 0.0, "y": 0.0, "z": 0.0},
                                                    "angular": {"x": 0.0, "y": 0.0, "z": 0.0}}
    assert prototype("std_srvs/srv/SetBool") == {"data": False}
    assert prototype("std_srvs/srv/Trigger") == {}
    assert prototype("test_msgs/action/Fibonacci") == {"order": 0}
    assert prototype("std_msgs/String") == {"data": ""}
    from sensor_msgs.msg import Imu

    assert dict_to_yaml(prototype("sensor_msgs/msg/Imu")) == oracle.message_to_yaml(Imu())


@pytest.mark.parametrize("type_, values, message", [
    ("geometry_msgs/msg/Twist", {"linear": {"q": 1}},
     "linear.q: geometry_msgs/msg/Vector3 has no field 'q' (x, y, z)"),
    ("std_msgs/msg/Int8", {"data": 300}, "data: expected int8 in -128..127, got 300"),
    ("std_msgs/msg/UInt64", {"data": -1}, "data: expected uint64 in 0..18446744073709551615, got -1"),
    ("std_msgs/msg/Int32", {"data": "ten"}, "data: expected int32 in -2147483648..2147483647, got 'ten'"),
    ("std_msgs/msg/Int32", {"data": 1.5}, "data: expected int32 in -2147483648..2147483647, got 1.5"),
    ("std_msgs/msg/Float64", {"data": [1]}, "data: expected float64, got a list of 1"),
    ("std_msgs/msg/Float32", {"data": 1e39},
     f"data: expected float32 in -{FLOAT32_MAX}..{FLOAT32_MAX}, got 1e+39"),
    ("std_msgs/msg/Bool", {"data": "maybe"}, "data: expected bool (true or false), got 'maybe'"),
    ("std_msgs/msg/Byte", {"data": 256}, "data: expected byte (an integer in 0..255 or one character), got 256"),
    ("std_msgs/msg/String", {"data": None}, "data: expected string, got null"),
    ("test_msgs/msg/Strings", {"bounded_string_value": "x" * 23},
     "bounded_string_value: expected string of at most 22 characters, got 23 characters"),
    ("test_msgs/msg/WStrings", {"wstring_value": {"a": 1}}, "wstring_value: expected wstring, got a mapping"),
    ("test_msgs/msg/Arrays", {"int8_values": [1, 2]}, "int8_values: expected 3 elements, got 2"),
    ("test_msgs/msg/Arrays", {"int8_values": 5}, "int8_values: expected a list of int8, got 5"),
    ("test_msgs/msg/BoundedSequences", {"float32_values": [1.0, 2.0, 3.0, 4.0]},
     "float32_values: expected at most 3 elements, got 4"),
    ("test_msgs/msg/UnboundedSequences", {"uint8_values": [1, 256]},
     "uint8_values[1]: expected uint8 in 0..255, got 256"),
    ("test_msgs/msg/UnboundedSequences", {"float32_values": [1.0, 1e39]},
     f"float32_values[1]: expected float32 in -{FLOAT32_MAX}..{FLOAT32_MAX}, got 1e+39"),
    ("test_msgs/msg/UnboundedSequences", {"basic_types_values": [{}, {"int16_value": 40000}]},
     "basic_types_values[1].int16_value: expected int16 in -32768..32767, got 40000"),
    ("test_msgs/msg/Nested", {"basic_types_value": 3},
     "basic_types_value: expected a mapping of test_msgs/msg/BasicTypes fields, got 3"),
    ("geometry_msgs/msg/Twist", [1, 2], "expected a mapping of geometry_msgs/msg/Twist fields, got a list of 2"),
    ("std_msgs/msg/Empty", {"x": 1}, "x: std_msgs/msg/Empty has no field 'x' (it has no fields)"),
    ("nav_msgs/msg/Path", {"poses": [{"pose": {"position": {"x": "far"}}}]},
     "poses[0].pose.position.x: expected float64, got 'far'"),
])
def test_fill_errors(type_: str, values: Any, message: str) -> None:
    with pytest.raises(MessageValueError) as error:
        fill_message(type_, values)
    assert str(error.value) == message


def test_fill_accepts_what_ros2_accepts() -> None:
    msg = fill_message("test_msgs/msg/BasicTypes", {"int32_value": "42", "float64_value": 3, "bool_value": 1,
                                                   "byte_value": "A", "float32_value": "nan"})
    assert (msg.int32_value, msg.float64_value, msg.bool_value, msg.byte_value) == (42, 3.0, True, b"A")
    assert fill_message("std_msgs/msg/String", {"data": 123}).data == "123"
    data = fill_message("std_msgs/msg/UInt8MultiArray", parse_values("data: !!binary AAH/")).data
    assert list(data) == [0, 1, 255]


def test_header_auto_and_time_now() -> None:
    from builtin_interfaces.msg import Time

    stamps: list = []
    msg = fill_message("geometry_msgs/msg/PoseStamped", {"header": "auto"}, stamps=stamps)
    other = fill_message("builtin_interfaces/msg/Duration", {}, stamps=stamps)
    assert other is not None and len(stamps) == 1
    stamps[0](Time(sec=5))
    assert msg.header.stamp.sec == 5
    ref: list = []
    msg = fill_message("test_msgs/msg/Builtins", {"time_value": "now"}, stamps=ref)
    ref[0](Time(sec=7))
    assert msg.time_value.sec == 7
    with pytest.raises(MessageValueError) as error:
        fill_message("geometry_msgs/msg/PoseStamped", {"header": "auto"})
    assert str(error.value) == "header: expected a mapping of std_msgs/msg/Header fields, got 'auto'"


@pytest.mark.parametrize("text, message", [
    ("{linear: {x: 1.0}", "values: line 1, column 18: invalid YAML (while parsing a flow mapping "
                          "expected ',' or '}', but got '<stream end>')"),
    ("data: [1, 2", "values: line 1, column 12: invalid YAML (while parsing a flow sequence "
                    "expected ',' or ']', but got '<stream end>')"),
    ("a: b: c", "values: line 1, column 5: invalid YAML (mapping values are not allowed here)"),
    ("- 1\n- 2", "values: expected a YAML mapping of field values such as '{data: 1}', got a list of 2"),
    ("hello", "values: expected a YAML mapping of field values such as '{data: 1}', got 'hello'"),
    ("!!python/object:os.system {}", "values: line 1, column 1: invalid YAML (could not determine a "
                                     "constructor for the tag 'tag:yaml.org,2002:python/object:os.system')"),
])
def test_parse_values_errors(text: str, message: str) -> None:
    with pytest.raises(MessageValueError) as error:
        parse_values(text)
    assert str(error.value) == message


def test_parse_values() -> None:
    assert parse_values("") == {} and parse_values(None) == {} and parse_values("~") == {}
    assert parse_values("{linear: {x: 2.0}}") == {"linear": {"x": 2.0}}
    assert parse_values("data: .nan")["data"] != parse_values("data: .nan")["data"]
    with pytest.raises(MessageValueError, match=r"^goal.yaml: line 3, column 1: invalid YAML \(while parsing"):
        parse_values("a: 1\nb: [\n", source="goal.yaml")


# ---- types ------------------------------------------------------------------------------------

def test_resolve_every_spelling() -> None:
    from std_srvs.srv import SetBool
    from test_msgs.action import Fibonacci

    assert resolve_type("std_msgs/msg/String").__name__ == "String"
    assert resolve_type("std_msgs/String", "msg") is resolve_type("std_msgs/msg/String")
    assert resolve_type("std_srvs/SetBool") is SetBool and resolve_type("std_srvs/srv/SetBool", "srv") is SetBool
    assert resolve_type("test_msgs/action/Fibonacci", "action") is Fibonacci
    assert resolve_type("test_msgs/action/Fibonacci_FeedbackMessage") is Fibonacci.Impl.FeedbackMessage
    assert resolve_type("test_msgs/action/Fibonacci_Goal") is Fibonacci.Goal
    assert resolve_type("std_srvs/srv/SetBool_Event") is SetBool.Event
    assert type_name(Fibonacci.Goal) == "test_msgs/action/Fibonacci_Goal"
    assert type_name(SetBool.Request()) == "std_srvs/srv/SetBool_Request"


@pytest.mark.parametrize("name, kind, message", [
    ("std_msg/msg/String", None,
     "unknown message type 'std_msg/msg/String': no interface package 'std_msg' is installed "
     "(did you mean 'std_msgs'?); install it or source the workspace that builds it"),
    ("std_msgs/msg/Strin", None,
     "unknown message type 'std_msgs/msg/Strin': package 'std_msgs' has no msg 'Strin' "
     "(did you mean 'String'?); see 'roc interface list'"),
    ("std_msgs/Strng", "msg",
     "unknown message type 'std_msgs/Strng': package 'std_msgs' has no msg 'Strng' "
     "(did you mean 'String'?); see 'roc interface list'"),
    ("std_srvs/Nothing", None,
     "unknown message or service or action type 'std_srvs/Nothing': package 'std_srvs' has no "
     "msg, srv or action 'Nothing'; see 'roc interface list'"),
    ("String", None,
     "invalid type name 'String': expected pkg/msg/Type, pkg/srv/Type, pkg/action/Type or pkg/Type"),
    ("std_msgs/foo/String", None,
     "invalid type name 'std_msgs/foo/String': expected pkg/msg/Type, pkg/srv/Type, pkg/action/Type or pkg/Type"),
    ("std_srvs/srv/SetBool", "msg", "std_srvs/srv/SetBool is a service, not a message"),
])
def test_unknown_types(name: str, kind: str | None, message: str, monkeypatch: pytest.MonkeyPatch,
                       tmp_path: Path) -> None:
    monkeypatch.setenv("AMENT_PREFIX_PATH", sys.prefix)
    monkeypatch.chdir(tmp_path)
    with pytest.raises((UnknownTypeError, TypeNameError)) as error:
        resolve_type(name, kind)
    assert str(error.value) == message
    # not installed: exit 1; a name no type could have, or of the wrong kind: a usage error, exit 2
    assert error.value.exit_code == (1 if message.startswith("unknown") else 2)


def test_unsourced_system_install_is_pointed_at(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from roc.ros import types

    share = tmp_path / "opt" / "ros" / "jazzy" / "share" / "demo_nav_msgs" / "msg"
    share.mkdir(parents=True)
    (share / "Goal.msg").write_text("float64 x\n")
    monkeypatch.setattr(types, "SYSTEM_ROOTS", (tmp_path / "opt" / "ros",))
    monkeypatch.setenv("AMENT_PREFIX_PATH", sys.prefix)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(UnknownTypeError) as error:
        resolve_type("demo_nav_msgs/Goal", "msg")
    jazzy = tmp_path / "opt" / "ros" / "jazzy"
    assert str(error.value) == (
        "unknown message type 'demo_nav_msgs/Goal': no interface package 'demo_nav_msgs' is installed; "
        f"it is in {jazzy}, which is not sourced: source {jazzy}/setup.bash first")


@pytest.mark.slow
def test_unsourced_install_is_pointed_at(tmp_path: Path) -> None:
    """A type built in the workspace but not sourced: the error says to source install/setup.bash."""
    workspace = tmp_path / "ws"
    shutil.copytree(REPO / "workspaces" / "example" / "src", workspace / "src")
    built = roc("work", "build", "--packages-select", "demo_interfaces", cwd=workspace)
    assert built.returncode == 0, built.stdout + built.stderr
    probe = ("import sys\nfrom roc.ros.types import resolve_type\nfrom roc.errors import RocError\n"
             "try:\n    print(resolve_type(sys.argv[1]).__name__)\n"
             "except RocError as error:\n    print(error)\n")
    unsourced = subprocess.run([sys.executable, "-c", probe, "demo_interfaces/msg/Reading"], cwd=workspace / "src",
                               env=ros_env(), capture_output=True, text=True, timeout=60)
    assert unsourced.stdout == (
        "unknown message type 'demo_interfaces/msg/Reading': no interface package 'demo_interfaces' is installed; "
        "it is built in ../install, which is not sourced: source ../install/setup.bash first\n"), unsourced.stderr
    (workspace / "probe.py").write_text(probe + "from roc.ros.messages import prototype\n"
                                        "print(prototype('demo_interfaces/srv/Scale'))\n")
    sourced = in_sourced_shell(workspace, "python probe.py demo_interfaces/Reading")
    assert sourced.returncode == 0, sourced.stderr
    assert sourced.stdout.splitlines()[0] == "Reading"
    assert re.fullmatch(r"\{.*\}", sourced.stdout.splitlines()[1])
