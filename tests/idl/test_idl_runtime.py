"""roc.idl.runtime: ROS messages (real rosidl-generated classes) -> protobuf objects (from the .proto files
roc wrote, compiled by protoc) -> ROS messages, equal."""

from __future__ import annotations

import importlib

import pytest
from google.protobuf import descriptor_pool, message_factory
from helpers.idl import interface_msgs, write

from roc.commands.idl.protobuf import convert
from roc.idl import protoc
from roc.idl.runtime import to_proto, to_ros

PACKAGES = ["std_msgs", "geometry_msgs", "sensor_msgs", "test_msgs", "visualization_msgs", "nav_msgs"]


@pytest.fixture(scope="module")
def pool(tmp_path_factory):
    root = tmp_path_factory.mktemp("proto")
    write(convert(interface_msgs(PACKAGES), root, None, [], None)[0], root)
    files = sorted(root.glob("*/*.proto"))
    pool = descriptor_pool.DescriptorPool()
    for file in protoc.descriptor_set(files, [root]).file:
        pool.Add(file)
    return pool


def proto_class(pool, full_name: str):
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(full_name))


def ros_class(name: str):
    package, type_name = name.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), type_name)


def sample(name: str):
    from builtin_interfaces.msg import Time
    from geometry_msgs.msg import Point, Pose
    from std_msgs.msg import Header

    ros = ros_class(name)()
    if name == "test_msgs/BasicTypes":
        ros.bool_value, ros.byte_value, ros.char_value = True, b"\x07", 65
        ros.float32_value, ros.float64_value, ros.int8_value, ros.uint8_value = 1.5, -2.25, -8, 200
        ros.int16_value, ros.uint16_value, ros.int32_value, ros.uint32_value = -300, 60000, -70000, 4000000000
        ros.int64_value, ros.uint64_value = -(2**40), 2**63
    elif name == "test_msgs/Arrays":
        ros.uint8_values, ros.byte_values = [1, 2, 3], [b"a", b"b", b"c"]
        ros.string_values, ros.float64_values = ["x", "", "zz"], [0.5, 1.5, 2.5]
    elif name == "test_msgs/UnboundedSequences":
        ros.uint8_values, ros.byte_values, ros.int16_values = [9, 8], [b"\x01"], [-1, 2, -3]
        ros.basic_types_values = [sample("test_msgs/BasicTypes")]
    elif name == "test_msgs/Strings":
        ros.string_value, ros.bounded_string_value = "héllo", "abc"
    elif name == "sensor_msgs/BatteryState":
        ros.header = Header(stamp=Time(sec=12, nanosec=34), frame_id="base")
        ros.voltage, ros.power_supply_status, ros.cell_voltage = 12.5, 3, [3.5, 3.75]
        ros.location = "left"
    elif name == "visualization_msgs/Marker":
        ros.header.frame_id, ros.ns, ros.id, ros.type = "map", "ns", 7, 2
        ros.pose = Pose(position=Point(x=1.0, y=2.0, z=3.0))
        ros.lifetime.sec = 5
        ros.points = [Point(x=1.0), Point(y=2.0)]
        ros.texture.data = [1, 2, 3]
    elif name == "sensor_msgs/Image":
        ros.height, ros.width, ros.encoding, ros.data = 1, 2, "mono8", [0, 255]
    return ros


@pytest.mark.parametrize("name", ["test_msgs/BasicTypes", "test_msgs/Arrays", "test_msgs/UnboundedSequences",
                                  "test_msgs/Strings", "test_msgs/Nested", "sensor_msgs/BatteryState",
                                  "visualization_msgs/Marker", "sensor_msgs/Image", "nav_msgs/Odometry"])
def test_ros_to_protobuf_and_back_is_equal(pool, name):
    ros = sample(name)
    message = to_proto(ros, proto_class(pool, name.replace("/", ".")))
    assert to_ros(message, type(ros)) == ros
    message_again = to_proto(to_ros(message, type(ros)), type(message))
    assert message_again == message


def test_values_land_in_the_protobuf_fields(pool):
    message = to_proto(sample("sensor_msgs/BatteryState"), proto_class(pool, "sensor_msgs.BatteryState"))
    assert message.header.stamp.seconds == 12 and message.header.stamp.nanos == 34
    assert message.header.frame_id == "base" and message.power_supply_status == 3
    assert list(message.cell_voltage) == [3.5, 3.75]
    basic = to_proto(sample("test_msgs/BasicTypes"), proto_class(pool, "test_msgs.BasicTypes"))
    assert basic.byte_value == 7 and basic.uint64_value == 2**63 and basic.int8_value == -8
    arrays = to_proto(sample("test_msgs/Arrays"), proto_class(pool, "test_msgs.Arrays"))
    assert arrays.uint8_values == b"\x01\x02\x03" and arrays.byte_values == b"abc"
