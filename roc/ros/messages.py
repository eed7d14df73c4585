"""Messages <-> plain data (dicts, YAML, CSV), as ros2 prints and reads them, without rosidl_runtime_py.

Output matches ``ros2 topic echo`` (rosidl_runtime_py's conversion): fields in definition order,
numeric arrays as lists, ``byte`` values as one-character strings, ``--truncate-length``,
``--no-arr`` and ``--no-str`` abbreviations. Input (``fill_message``) is checked field by field
before anything is sent: every error names the field path and what was expected.

Field definitions come from each generated class's ``SLOT_TYPES`` (rosidl_parser definitions).
"""

from __future__ import annotations

import array
import math
import sys
from collections.abc import Callable, Iterable
from functools import cache, partial
from typing import Any, cast

import yaml
from rosidl_parser import definition as idl

from roc.errors import UsageError
from roc.render import to_message_yaml
from roc.ros.types import InterfaceClass, interface_kind, resolve_type, type_name


class MessageValueError(UsageError):
    """A value that does not fit its message field (or values that are not valid YAML)."""


INT_RANGES = {
    "int8": (-(2**7), 2**7 - 1), "uint8": (0, 2**8 - 1), "char": (0, 2**8 - 1),
    "int16": (-(2**15), 2**15 - 1), "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1), "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1), "uint64": (0, 2**64 - 1),
}
TYPECODES = {"int8": "b", "uint8": "B", "char": "B", "int16": "h", "uint16": "H", "int32": "i",
             "uint32": "I", "int64": "q", "uint64": "Q", "float": "f", "double": "d"}
FLOAT32_MAX = 3.4028234663852886e38  # numpy.finfo(numpy.float32).max
# IDL names of basic types -> the names people write in .msg files (for error messages).
MSG_NAMES = {"boolean": "bool", "octet": "byte", "float": "float32", "double": "float64"}

Fields = tuple[tuple[str, Any], ...]


@cache
def fields(cls: InterfaceClass) -> Fields:
    """``(name, rosidl definition)`` of each field of a message class, in definition order."""
    return tuple(zip(cls.get_fields_and_field_types(), cls.SLOT_TYPES))


@cache
def _field_map(cls: InterfaceClass) -> dict[str, Any]:
    return dict(fields(cls))


def _nested_class(namespaced: idl.NamespacedType) -> InterfaceClass:
    return resolve_type("/".join(namespaced.namespaced_name()))


def _idl_name(value_type: Any) -> str:
    """A field's element type as ros2 names it in ``--no-arr`` summaries."""
    if isinstance(value_type, idl.BasicType):
        return value_type.typename
    if isinstance(value_type, idl.AbstractString):
        return "string"
    if isinstance(value_type, idl.AbstractWString):
        return "wstring"
    if isinstance(value_type, idl.NamespacedType):
        return "/".join(value_type.namespaced_name())
    if isinstance(value_type, idl.NamedType):
        return value_type.name
    return "unknown"


def _array_summary(value: Any, slot: Any) -> str:
    name = _idl_name(slot.value_type)
    if isinstance(slot, idl.Array):
        return f"<array type: {name}[{slot.size}]>"
    if isinstance(slot, idl.BoundedSequence):
        return f"<sequence type: {name}[{slot.maximum_size}], length: {len(value)}>"
    return f"<sequence type: {name}, length: {len(value)}>"


# ---- message -> data --------------------------------------------------------------------------

def message_to_dict(msg: Any, *, no_arr: bool = False, no_str: bool = False,
                    truncate_length: int | None = None) -> dict[str, Any]:
    """The message's fields in definition order, as ``ros2 topic echo`` shows them."""
    return {name: _to_data(getattr(msg, name), slot, no_arr, no_str, truncate_length)
            for name, slot in fields(msg.__class__)}


def _is_numpy(value: Any, kind: str) -> bool:
    """Whether ``value`` is a numpy ``kind`` (``ndarray``, ``generic``, ``number``). Only once numpy is
    imported can a value be one (rclpy's message classes import it for their arrays); roc itself does
    not import it here, as that would cost every echo and pub 0.15 s."""
    numpy = sys.modules.get("numpy")
    return numpy is not None and isinstance(value, getattr(numpy, kind))


def _is_number_array(value: Any) -> bool:
    """An array.array or numpy array: numbers in one buffer (``tolist()`` gives them as Python values)."""
    return isinstance(value, array.array) or _is_numpy(value, "ndarray")


def value_to_data(value: Any, *, no_arr: bool = False, no_str: bool = False,
                  truncate_length: int | None = None) -> Any:
    """A message or a field value (``echo --field``) as plain data."""
    return _to_data(value, None, no_arr, no_str, truncate_length)


def _to_data(value: Any, slot: Any, no_arr: bool, no_str: bool, limit: int | None) -> Any:
    if isinstance(value, (bool, int, float)):
        return cast(Any, value).item() if _is_numpy(value, "generic") else value  # numpy scalars subclass float
    if isinstance(value, str):
        if no_str:
            return f"<string length: <{len(value)}>>"
        return value[:limit] + "..." if limit is not None and len(value) > limit else value
    if isinstance(value, bytes):
        if limit is not None and len(value) > limit:
            return value[:limit].decode("latin-1") + "..."
        return value.decode("latin-1")
    if isinstance(value, (list, tuple)) or _is_number_array(value):
        if no_arr and slot is not None:
            return _array_summary(value, slot)
        truncated = limit is not None and len(value) > limit
        items = value[:limit] if truncated else value
        if _is_number_array(items):
            data = items.tolist()
        else:
            data = [_to_data(item, None, no_arr, no_str, limit) for item in items]
        return data + ["..."] if truncated else data
    if _is_numpy(value, "generic"):
        return value.item()
    return message_to_dict(value, no_arr=no_arr, no_str=no_str, truncate_length=limit)


def message_to_yaml(msg: Any, *, no_arr: bool = False, no_str: bool = False,
                    truncate_length: int | None = None, flow_style: bool = False) -> str:
    """The YAML text ``ros2 topic echo`` prints for a message (without the ``---`` line)."""
    return dict_to_yaml(message_to_dict(msg, no_arr=no_arr, no_str=no_str, truncate_length=truncate_length),
                        flow_style=flow_style)


def dict_to_yaml(data: dict[str, Any], *, flow_style: bool = False) -> str:
    """Message data as YAML text, as ros2 prints it (see render.to_message_yaml)."""
    return to_message_yaml(data, flow_style=flow_style)


def message_to_csv(msg: Any, *, no_arr: bool = False, no_str: bool = False,
                   truncate_length: int | None = None) -> str:
    """All fields, recursively, separated by commas, as ``ros2 topic echo --csv`` prints them."""
    return _csv_join(_csv(getattr(msg, name), slot, no_arr, no_str, truncate_length)
                     for name, slot in fields(msg.__class__))


def _csv_join(parts: Iterable[str]) -> str:
    """Comma-joined, as ros2 joins: no comma after a still empty line (leading empty values vanish)."""
    line = ""
    for part in parts:
        line = f"{line},{part}" if line else part
    return line


def _csv(value: Any, slot: Any, no_arr: bool, no_str: bool, limit: int | None) -> str:
    if isinstance(value, (list, tuple)) or _is_number_array(value):
        if no_arr and slot is not None:
            return _array_summary(value, slot)
        parts = [_csv(item, None, no_arr, no_str, limit)
                 for item in (value if limit is None else value[:limit])]
        if limit is not None and len(value) > limit:
            parts.append("...")
        return _csv_join(parts)
    if isinstance(value, str):
        if no_str:
            return f"<string length: <{len(value)}>>"
        return value[:limit] + "..." if limit is not None and len(value) > limit else value
    if isinstance(value, bytes):
        return str(value[:limit] + b"..." if limit is not None and len(value) > limit else value)
    if isinstance(value, (bool, int, float)) or _is_numpy(value, "number"):
        return str(value)
    return message_to_csv(value, no_arr=no_arr, no_str=no_str, truncate_length=limit)


def echo_text(value: Any, *, csv: bool = False, flow_style: bool = False, no_arr: bool = False,
              no_str: bool = False, truncate_length: int | None = None) -> str:
    """What ``ros2 topic echo`` prints for one message, or for the value ``--field`` selected:
    YAML and a ``---`` line, one CSV line, or a plain value as Python prints it and ``---``."""
    if not hasattr(type(value), "SLOT_TYPES"):
        return f"{value}\n---\n"
    if csv:
        return message_to_csv(value, no_arr=no_arr, no_str=no_str, truncate_length=truncate_length) + "\n"
    return message_to_yaml(value, no_arr=no_arr, no_str=no_str, truncate_length=truncate_length,
                           flow_style=flow_style) + "---\n"


def field_names(path: str) -> list[str]:
    """The names of a dotted field path (``pose.pose.position``), at least one."""
    names = [name for name in path.split(".") if name]
    if not names:
        raise MessageValueError(f"invalid field '{path}': expected field names separated by dots",
                                ros2_line=f"Invalid field value '{path}'")
    return names


def get_field(msg: Any, path: str) -> Any:
    """The value at a dotted field path (``pose.pose.position``), as ``echo --field`` selects it; the
    errors come after ros2's lines for them."""
    value = msg
    names = field_names(path)
    for depth, name in enumerate(names):
        where = ".".join(names[: depth + 1])
        ros2_line = f"Invalid field '{'.'.join(names)}': '{type(value).__name__}' object has no attribute '{name}'"
        if not hasattr(type(value), "SLOT_TYPES"):
            raise MessageValueError(f"{where}: '{'.'.join(names[:depth])}' is not a message", ros2_line=ros2_line)
        known = _field_map(value.__class__)
        if name not in known:
            listed = ", ".join(known) or "it has no fields"
            raise MessageValueError(f"{where}: {type_name(value)} has no field '{name}' ({listed})",
                                    ros2_line=ros2_line)
        value = getattr(value, name)
    return value


def prototype(type_name_: str) -> dict[str, Any]:
    """A default-valued message (a service's request, an action's goal) as data, as
    ``ros2 interface proto`` shows it."""
    cls = resolve_type(type_name_)
    kind = interface_kind(cls)
    instance = cls.Goal() if kind == "action" else cls.Request() if kind == "srv" else cls()
    return message_to_dict(instance)


# ---- data -> message --------------------------------------------------------------------------

def parse_values(text: str | None, source: str = "values") -> dict[str, Any]:
    """Field values written as YAML (``'{linear: {x: 1.0}}'``); empty text is ``{}``."""
    if text is None or not text.strip():
        return {}
    try:
        data = yaml.safe_load(text)
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        problem = " ".join(filter(None, [error.context, error.problem]))
        raise MessageValueError(f"{source}: {where}invalid YAML ({problem})") from None
    except yaml.YAMLError as error:
        raise MessageValueError(f"{source}: invalid YAML ({error})") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise MessageValueError(
            f"{source}: expected a YAML mapping of field values such as '{{data: 1}}', got {_show(data)}")
    return data


StampSetters = list[Callable[[Any], None]]


def fill_message(target: Any, values: Any, *, stamps: StampSetters | None = None) -> Any:
    """A message (``target`` is one, its class or its type name) with ``values`` set on it.

    With a ``stamps`` list, ``header: auto`` (a std_msgs/Header) and ``stamp: now`` (a
    builtin_interfaces/Time) are accepted as in ``ros2 topic pub``: each adds a function that sets
    the time, to call just before each publication.
    """
    if isinstance(target, str):
        target = resolve_type(target, "msg")
    msg = target() if isinstance(target, type) else target
    _fill(msg, values, "", stamps)
    return msg


def _show(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, (list, tuple)):
        return f"a list of {len(value)}"
    return repr(value) if isinstance(value, (str, bytes)) else str(value)


def _fill(msg: Any, values: Any, path: str, stamps: StampSetters | None) -> None:
    cls = msg.__class__
    if not isinstance(values, dict):
        where = f"{path}: " if path else ""
        raise MessageValueError(f"{where}expected a mapping of {type_name(cls)} fields, got {_show(values)}")
    known = _field_map(cls)
    for key, value in values.items():
        where = f"{path}.{key}" if path else str(key)
        slot = known.get(key)
        if slot is None:
            listed = ", ".join(known) or "it has no fields"
            raise MessageValueError(f"{where}: {type_name(cls)} has no field '{key}' ({listed})")
        if stamps is not None and isinstance(slot, idl.NamespacedType) and isinstance(value, str):
            nested = slot.namespaced_name()
            if value == "auto" and nested == ("std_msgs", "msg", "Header"):
                header = _nested_class(slot)()
                stamps.append(partial(setattr, header, "stamp"))
                setattr(msg, key, header)
                continue
            if value == "now" and nested == ("builtin_interfaces", "msg", "Time"):
                stamps.append(partial(setattr, msg, key))
                continue
        setattr(msg, key, _field_value(value, slot, where, stamps))


def _field_value(value: Any, slot: Any, where: str, stamps: StampSetters | None) -> Any:
    if isinstance(slot, idl.AbstractNestedType):
        return _sequence(value, slot, where, stamps)
    return _element(value, slot, where, stamps)


def _element(value: Any, slot: Any, where: str, stamps: StampSetters | None) -> Any:
    if isinstance(slot, idl.BasicType):
        return _basic(value, slot.typename, where)
    if isinstance(slot, (idl.AbstractString, idl.AbstractWString)):
        return _string(value, slot, where)
    cls = _nested_class(slot)
    if isinstance(value, cls):
        return value
    nested = cls()
    _fill(nested, value, where, stamps)
    return nested


def _basic(value: Any, typename: str, where: str) -> Any:
    if typename in INT_RANGES:
        low, high = INT_RANGES[typename]
        number = _as_int(value)
        if number is None or not low <= number <= high:
            raise MessageValueError(f"{where}: expected {typename} in {low}..{high}, got {_show(value)}")
        return number
    if typename in ("float", "double"):
        real = _as_float(value)
        if real is None or (typename == "float" and math.isfinite(real) and abs(real) > FLOAT32_MAX):
            limit = f" in -{FLOAT32_MAX}..{FLOAT32_MAX}" if typename == "float" else ""
            raise MessageValueError(f"{where}: expected {MSG_NAMES[typename]}{limit}, got {_show(value)}")
        return real
    if typename == "boolean":
        if isinstance(value, bool):
            return value
        if isinstance(value, int) and value in (0, 1):
            return bool(value)
        raise MessageValueError(f"{where}: expected bool (true or false), got {_show(value)}")
    if typename == "octet":
        if isinstance(value, bytes) and len(value) == 1:
            return value
        if isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= 255:
            return bytes([value])
        if isinstance(value, str) and len(value) == 1 and ord(value) < 256:
            return value.encode("latin-1")
        raise MessageValueError(
            f"{where}: expected byte (an integer in 0..255 or one character), got {_show(value)}")
    raise MessageValueError(f"{where}: fields of type {typename} are not supported")


def _as_int(value: Any) -> int | None:
    if isinstance(value, int):
        return int(value)
    if isinstance(value, float) and value.is_integer():
        return int(value)
    if isinstance(value, str):
        try:
            return int(value.strip())
        except ValueError:
            return None
    return None


def _as_float(value: Any) -> float | None:
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, str):
        try:  # also YAML's spellings: .nan, .inf, -.inf
            return float(value.strip().lower().replace(".inf", "inf").replace(".nan", "nan"))
        except ValueError:
            return None
    return None


def _string(value: Any, slot: Any, where: str) -> str:
    kind = "wstring" if isinstance(slot, idl.AbstractWString) else "string"
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        value = str(value)
    if not isinstance(value, str):
        raise MessageValueError(f"{where}: expected {kind}, got {_show(value)}")
    bound = getattr(slot, "maximum_size", None)
    if bound is not None and len(value) > bound:
        raise MessageValueError(
            f"{where}: expected {kind} of at most {bound} characters, got {len(value)} characters")
    return value


def _element_name(value_type: Any) -> str:
    if isinstance(value_type, idl.BasicType):
        return MSG_NAMES.get(value_type.typename, value_type.typename)
    return _idl_name(value_type)


def _sequence(value: Any, slot: Any, where: str, stamps: StampSetters | None) -> Any:
    element = slot.value_type
    if isinstance(value, (bytes, bytearray)) and isinstance(element, idl.BasicType) \
            and element.typename in ("octet", "uint8", "char"):
        value = list(value)
    if _is_number_array(value):
        value = value.tolist()
    if not isinstance(value, (list, tuple)):
        raise MessageValueError(f"{where}: expected a list of {_element_name(element)}, got {_show(value)}")
    if isinstance(slot, idl.Array) and len(value) != slot.size:
        raise MessageValueError(f"{where}: expected {slot.size} elements, got {len(value)}")
    if isinstance(slot, idl.BoundedSequence) and len(value) > slot.maximum_size:
        raise MessageValueError(f"{where}: expected at most {slot.maximum_size} elements, got {len(value)}")
    code = TYPECODES.get(element.typename) if isinstance(element, idl.BasicType) else None
    if code is not None:
        numbers = _numeric_array(value, code, element.typename)
        if numbers is not None:
            return numbers
    return [_element(item, element, f"{where}[{index}]", stamps) for index, item in enumerate(value)]


def _numeric_array(values: list | tuple, code: str, typename: str) -> array.array | None:
    """The values as an array.array, checked in C (fast for large data); None when some value
    needs the per-element path (strings, non-integral floats, out of range), which names it."""
    try:
        numbers = array.array("d" if code == "f" else code, values)
    except (TypeError, OverflowError):
        return None
    if code == "f":
        import numpy

        magnitudes = numpy.abs(numpy.frombuffer(numbers, dtype=numpy.float64))
        if ((magnitudes > FLOAT32_MAX) & numpy.isfinite(magnitudes)).any():
            return None
        return array.array("f", numbers)
    return numbers
