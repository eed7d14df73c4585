"""Conversion between protobuf objects and ROS 2 messages, both ways, following roc idl's rules.

Generic (driven by the protobuf descriptor and the ROS message's ``SLOT_TYPES``), so it needs no generated
code: ``to_ros(pb_object, RosClass)`` and ``to_proto(ros_message, PbClass)``. Imports neither rclpy nor a
message package itself; the ROS classes of nested fields are imported from their package's ``msg`` module.
What a ROS message cannot hold is lost: the presence of wrappers and message fields.
"""

from __future__ import annotations

import importlib
from typing import Any

from roc.idl.naming import snake

TIMES = {"google.protobuf.Timestamp", "google.protobuf.Duration"}
JSON = {"google.protobuf.Struct", "google.protobuf.Value", "google.protobuf.ListValue"}
WRAPPERS = {f"google.protobuf.{n}Value" for n in ("Double", "Float", "Int64", "UInt64", "Int32", "UInt32", "Bool",
                                                  "String", "Bytes")}


def _oneof_members(descriptor) -> dict[str, tuple[str, int]]:
    """Field name -> (the ROS ``<oneof>_case`` field, the member's case number) for real oneofs."""
    members = {}
    for oneof in descriptor.oneofs:
        if not _synthetic(oneof):
            for number, field in enumerate(oneof.fields, 1):
                members[field.name] = (f"{snake(oneof.name)}_case", number)
    return members


def _synthetic(oneof) -> bool:
    """proto3 ``optional``: a oneof protoc makes for one field, named ``_<field>``."""
    return len(oneof.fields) == 1 and oneof.name == f"_{oneof.fields[0].name}"


def _element(slot):
    return getattr(slot, "value_type", slot)


def _ros_class(slot):
    slot = _element(slot)
    module = importlib.import_module(".".join(slot.namespaces))
    return getattr(module, slot.name)


def _is_map(field) -> bool:
    return field.message_type is not None and field.message_type.GetOptions().map_entry


def _is_repeated(field) -> bool:
    return field.is_repeated


# ---- protobuf -> ROS ---------------------------------------------------------------------------
def to_ros(message, ros_type) -> Any:
    """A ROS message of class ``ros_type`` holding the protobuf object ``message``."""
    ros = ros_type()
    slots = dict(zip(ros.get_fields_and_field_types(), ros.SLOT_TYPES))
    members = _oneof_members(message.DESCRIPTOR)
    for oneof in message.DESCRIPTOR.oneofs:
        if not _synthetic(oneof):
            chosen = message.WhichOneof(oneof.name)
            setattr(ros, f"{snake(oneof.name)}_case", members[chosen][1] if chosen else 0)
    for field in message.DESCRIPTOR.fields:
        name = snake(field.name)
        value = getattr(message, field.name)
        slot = slots[name]
        if _is_map(field):
            entry, value_field = _ros_class(slot), field.message_type.fields_by_name["value"]
            slot_of_values = _entry_value_slot(entry)
            value = [entry(key=k, value=_to_ros_single(value_field, v, slot_of_values)) for k, v in value.items()]
        elif _is_repeated(field):
            value = [_to_ros_single(field, v, _element(slot), repeated=True) for v in value]
        else:
            value = _to_ros_single(field, value, slot)
        setattr(ros, name, value)
    return ros


def _entry_value_slot(entry):
    return dict(zip(entry.get_fields_and_field_types(), entry.SLOT_TYPES))["value"]


def _to_ros_single(field, value, slot, repeated: bool = False) -> Any:
    if field.type == field.TYPE_BYTES:
        return _ros_class(slot)(data=list(value)) if repeated else _to_ros_bytes(value, slot)
    if field.message_type is None:
        octet = getattr(_element(slot), "typename", "") == "octet"  # ROS byte: a one-byte bytes
        return bytes([value]) if octet and isinstance(value, int) else value
    full = field.message_type.full_name
    if full in TIMES:
        return _ros_class(slot)(sec=value.seconds, nanosec=value.nanos)
    if full in JSON:
        from google.protobuf import json_format

        return json_format.MessageToJson(value, indent=None) if value.ByteSize() else ""
    if full in WRAPPERS:
        return _to_ros_bytes(value.value, slot) if full.endswith("BytesValue") else value.value
    if full == "google.protobuf.FieldMask":
        return list(value.paths)
    if full == "google.protobuf.Any":
        return _ros_class(slot)(type_url=value.type_url, value=list(value.value))
    if full == "google.protobuf.Empty":
        return _ros_class(slot)()
    return to_ros(value, _ros_class(slot))


def _to_ros_bytes(value: bytes, slot) -> Any:
    if getattr(_element(slot), "typename", "") == "octet":  # byte[]: a list of one-byte bytes
        return [bytes([b]) for b in value]
    return list(value)


# ---- ROS -> protobuf ---------------------------------------------------------------------------
def to_proto(ros, message_type) -> Any:
    """A protobuf object of class ``message_type`` holding the ROS message ``ros``."""
    message = message_type()
    slots = dict(zip(ros.get_fields_and_field_types(), ros.SLOT_TYPES))
    members = _oneof_members(message.DESCRIPTOR)
    for field in message.DESCRIPTOR.fields:
        name = snake(field.name)
        if field.name in members:
            case, number = members[field.name]
            if getattr(ros, case) != number:
                continue
        value = getattr(ros, name)
        target = getattr(message, field.name)
        if _is_map(field):
            value_field = field.message_type.fields_by_name["value"]
            for entry in value:
                if value_field.message_type is None:
                    target[entry.key] = _plain(entry.value, value_field)
                else:
                    _to_proto_message(value_field, entry.value, target[entry.key])
        elif _is_repeated(field):
            if field.message_type is None:
                target.extend(_plain(v, field, _element(slots[name])) for v in value)
            else:
                for item in value:
                    _to_proto_message(field, item, target.add())
        elif field.message_type is None:
            setattr(message, field.name, _plain(value, field, slots[name]))
        else:
            _to_proto_message(field, value, target)
    return message


def _plain(value, field, slot=None) -> Any:
    """A ROS value (numpy scalars, one-byte bytes, arrays) as the protobuf scalar of ``field``."""
    if field.type == field.TYPE_BYTES:
        if hasattr(value, "data"):  # a generated Bytes message (repeated bytes)
            value = value.data
        return b"".join(value) if value and isinstance(value[0], bytes) else bytes(list(value))
    if isinstance(value, bytes):  # ROS byte
        return value[0]
    return value.item() if hasattr(value, "item") else value


def _to_proto_message(field, value, target) -> None:
    full = field.message_type.full_name
    if field.type == field.TYPE_BYTES:
        return
    if full in TIMES:
        target.seconds, target.nanos = value.sec, value.nanosec
    elif full in JSON:
        from google.protobuf import json_format

        if value:
            json_format.Parse(value, target)
    elif full in WRAPPERS:
        target.value = _plain(value, target.DESCRIPTOR.fields_by_name["value"])
    elif full == "google.protobuf.FieldMask":
        target.paths.extend(value)
    elif full == "google.protobuf.Any":
        target.type_url, target.value = value.type_url, bytes(list(value.value))
    elif full == "google.protobuf.Empty":
        target.SetInParent()
    else:
        converted = to_proto(value, type(target))
        if converted.ByteSize():  # an all-default ROS message leaves the protobuf field unset
            target.CopyFrom(converted)
