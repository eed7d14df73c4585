"""roc param get: a parameter's value (like ros2 param get)."""

from __future__ import annotations

import argparse

from roc.commands.param.target import add_node_arguments, ask_node
from roc.errors import RocError
from roc.render import render

LABELS = {"boolean": "Boolean value is:", "integer": "Integer value is:", "double": "Double value is:",
          "string": "String value is:", "byte array": "Byte values are:", "boolean array": "Boolean values are:",
          "integer array": "Integer values are:", "double array": "Double values are:",
          "string array": "String values are:"}


def python_text(value) -> str:
    """The value as ros2 prints it (Python's str: True, [1.0, 2.0], ['a', 'b'])."""
    return str(value)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_node_arguments(parser)
    parser.add_argument("parameter_name", help="name of the parameter")
    parser.add_argument("--hide-type", action="store_true", help="print only the value")


def run(args: argparse.Namespace) -> int:
    values = ask_node(args, "param_get", {"names": [args.parameter_name]})
    if not values:
        raise RocError("Parameter not set")
    value = values[0]
    if value["type"] == "not set":
        line = "Parameter not set."
    elif args.hide_type:
        line = python_text(value["value"])
    else:
        line = f"{LABELS[value['type']]} {python_text(value['value'])}"
    render({"name": args.parameter_name, **value}, args.format, [line])
    return 0
