"""A node's parameter values as plain data, and writing them over its parameter services (``param set``,
``delete``, ``load``).
Values arrive typed as plain data, ``{"type": "integer", "value": 5}`` (roc.ros.protocol's
PARAMETER_TYPES names; ``"not set"`` deletes), as ``param get`` returns them."""

from __future__ import annotations

from typing import Any

from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters

from roc.ros.protocol import PARAMETER_TYPES, VALUE_FIELDS

_TYPE_CODES = {name: code for code, name in PARAMETER_TYPES.items()}


def parameter_value(value) -> dict[str, Any]:
    """{type, value} of an rcl_interfaces ParameterValue, the value as plain JSON data."""
    field = VALUE_FIELDS.get(value.type)
    if field is None:
        return {"type": "not set", "value": None}
    data = getattr(value, field)
    if field == "byte_array_value":
        data = [b if isinstance(b, int) else ord(b) for b in data]
    elif field.endswith("_array_value"):
        data = list(data)
    return {"type": PARAMETER_TYPES.get(value.type, "not set"), "value": data}


def to_parameter_value(data: dict[str, Any]) -> ParameterValue:
    code = _TYPE_CODES[data["type"]]
    value = ParameterValue(type=code)
    if code == ParameterType.PARAMETER_BYTE_ARRAY:
        value.byte_array_value = [bytes([b]) for b in data["value"]]
    elif code != ParameterType.PARAMETER_NOT_SET:
        setattr(value, VALUE_FIELDS[code], data["value"])
    return value


def set_parameters(graph, params: dict[str, Any]) -> list[dict[str, Any]]:
    """Set (or, typed ``not set``, delete) ``params["parameters"]`` ([{name, type, value}]) on
    ``params["node"]``, one by one as ros2 does; [{name, successful, reason}]."""
    items = params["parameters"]
    request = SetParameters.Request(parameters=[Parameter(name=item["name"], value=to_parameter_value(item))
                                                for item in items])
    response = graph.call_node_service(params["node"], "set_parameters", SetParameters, request)
    return [{"name": item["name"], "successful": result.successful, "reason": result.reason}
            for item, result in zip(items, response.results)]


WRITES = {"param_set": set_parameters}
