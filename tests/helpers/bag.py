"""Helpers for the bag tests: messages of any type with every field set to a non-default value, a
publisher process that sends them, and a bag of a type no installed package has."""

from __future__ import annotations

import importlib
from typing import Any

TEST_MSGS = ("Arrays", "BasicTypes", "BoundedPlainSequences", "BoundedSequences", "Builtins", "Constants",
             "Defaults", "Empty", "MultiNested", "Nested", "Strings", "UnboundedSequences", "WStrings")


def load(type_name: str) -> type:
    package, kind, name = type_name.split("/")
    return getattr(importlib.import_module(f"{package}.{kind}"), name)


def _value(slot: Any, seed: int) -> Any:
    from rosidl_parser import definition as d

    if isinstance(slot, d.AbstractNestedType):
        size = slot.size if isinstance(slot, d.Array) else min(2, getattr(slot, "maximum_size", 2) or 2)
        return [_value(slot.value_type, seed + i) for i in range(size)]
    if isinstance(slot, d.NamespacedType):
        cls = load("/".join([*slot.namespaces, slot.name]))
        return filled(cls, seed)
    if isinstance(slot, (d.AbstractString, d.AbstractWString)):
        bound = getattr(slot, "maximum_size", None)
        text = f"v{seed}é" if isinstance(slot, d.AbstractWString) else f"value {seed}"
        return text[:bound] if bound else text
    kind = slot.typename
    if kind == "boolean":
        return seed % 2 == 0
    if kind == "octet":
        return bytes([seed % 256])
    if kind in ("float", "double"):
        return seed + 0.5
    if kind == "char":
        return 65 + seed % 26
    return seed % 100 + 1


def filled(cls: type, seed: int = 1) -> Any:
    """An instance of ``cls`` with every field set (nested messages and arrays too)."""
    import numpy

    message = cls()
    for index, (name, slot) in enumerate(zip(cls.get_fields_and_field_types(), cls.SLOT_TYPES)):
        value = _value(slot, seed + index)
        current = getattr(message, name)
        if isinstance(current, numpy.ndarray):
            value = numpy.array(value, dtype=current.dtype)
        elif hasattr(current, "typecode"):  # array.array
            import array

            value = array.array(current.typecode, value)
        setattr(message, name, value)
    return message


# A message type no installed package has, as a bag recorded elsewhere holds it: its CDR is that of
# geometry_msgs/msg/Vector3Stamped (a header and three float64), its definition the bag's own.
BAG_ONLY_TYPE = "bagonly_msgs/msg/Stamped"
BAG_ONLY_DEFINITION = (
    "std_msgs/Header header\nbagonly_msgs/Vec3 vec # three numbers\n"
    "================================================================================\n"
    "MSG: bagonly_msgs/Vec3\nfloat64 x\nfloat64 y\nfloat64 z\n"
    "================================================================================\n"
    "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
    "================================================================================\n"
    "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n")


def write_bag_only_bag(path, count: int, definition: str = BAG_ONLY_DEFINITION) -> list[bytes]:
    """A bag of ``count`` messages of BAG_ONLY_TYPE on /vec, 10 ms apart; returns their CDR."""
    from geometry_msgs.msg import Vector3Stamped
    from rclpy.serialization import serialize_message

    from roc.bag.message import Definition
    from roc.bag.metadata import Topic
    from roc.bag.qos import default_profile
    from roc.bag.writer import BagWriter, WriteOptions

    writer = BagWriter(path, WriteOptions())
    writer.add_topic(Topic("/vec", BAG_ONLY_TYPE, "cdr", [default_profile()]),
                     Definition(BAG_ONLY_TYPE, "ros2msg", definition))
    data = []
    for index in range(count):
        message = Vector3Stamped()
        message.header.frame_id = f"frame {index}"
        message.vector.x, message.vector.z = float(index), -1.5
        data.append(serialize_message(message))
        writer.write("/vec", data[-1], 1_700_000_000_000_000_000 + index * 10_000_000)
    writer.close()
    return data


def string_cdr(text: str) -> bytes:
    """A std_msgs/msg/String as CDR (little endian), without rclpy."""
    import struct

    data = text.encode() + b"\0"
    return b"\0\1\0\0" + struct.pack("<I", len(data)) + data


def write_split_bag_with_tf_static(path, seconds: int = 4) -> None:
    """A bag split every second whose files each begin with the one /tf_static message (transient local,
    written at the start: ``--repeat-transient-local``), beside /data at 10 Hz: a std_msgs/msg/String each."""
    from roc.bag.definitions import definition
    from roc.bag.metadata import Topic
    from roc.bag.qos import default_profile
    from roc.bag.writer import BagWriter, WriteOptions

    start = 1_700_000_000_000_000_000
    writer = BagWriter(path, WriteOptions(max_bag_duration=1_000_000_000, repeat_all_transient_local=1))
    for name, durability in (("/tf_static", "transient_local"), ("/data", "volatile")):
        writer.add_topic(Topic(name, "std_msgs/msg/String", "cdr", [{**default_profile(), "durability": durability}]),
                         definition("std_msgs/msg/String"))
    writer.write("/tf_static", string_cdr("static"), start)
    for index in range(seconds * 10):
        writer.write("/data", string_cdr(f"data {index}"), start + 1_000_000 + index * 100_000_000)
    writer.close()
