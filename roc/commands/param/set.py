"""roc param set: set parameters of a node (like ros2 param set), values typed as ros2 types them."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import Any

import yaml

from roc.commands.param.target import add_node_arguments, ask_node
from roc.errors import UsageError
from roc.render import print_lines, render

ARRAY_TYPES = ((bool, "boolean array"), (int, "integer array"), (float, "double array"), (str, "string array"))


def typed_value(value: Any, text: str | None = None) -> dict[str, Any]:
    """``{type, value}`` of a YAML value as ros2 types it: bool, integer, double, arrays of one kind;
    anything else is the string (``text``: as the user wrote it)."""
    if isinstance(value, bool):
        return {"type": "boolean", "value": value}
    if isinstance(value, int):
        return {"type": "integer", "value": value}
    if isinstance(value, float):
        return {"type": "double", "value": value}
    if isinstance(value, list) and value:
        for kind, name in ARRAY_TYPES:
            if all(isinstance(item, kind) and (kind is bool or not isinstance(item, bool)) for item in value):
                return {"type": name, "value": value}
    if isinstance(value, str):
        return {"type": "string", "value": value}
    return {"type": "string", "value": text if text is not None else str(value)}


def parse_value(text: str) -> dict[str, Any]:
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        value = text
    return typed_value(value, text)


def set_parameters(args: argparse.Namespace, parameters: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Send the parameters ({name, type, value}) to ``args.node_name``; the node's verdict per parameter."""
    return ask_node(args, "param_set", {"parameters": parameters})


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_node_arguments(parser)
    parser.add_argument("assignments", nargs="+", metavar="NAME VALUE",
                        help="parameter name and value (YAML: 1 is an integer, 1.0 a double, [1, 2] an array)")


def named_reason(name: str, reason: str) -> str:
    """The node's reason, naming the parameter where rclpy leaves its list empty (``Invalid access to
    undeclared parameter(s): []``)."""
    return reason.replace("parameter(s): []", f"parameter(s): {name}")


def report(args: argparse.Namespace, results: list[dict[str, Any]], succeeded: Callable[[str], str],
           failed: Callable[[str], str]) -> int:
    """ros2's line per parameter (``succeeded(name)``; ``failed(name)`` and the node's reason): the
    successes on stdout, the failures on stderr. Exit 1 when one failed (ros2 exits 0)."""
    render(results, args.format, [succeeded(r["name"]) for r in results if r["successful"]])
    if args.format == "text":
        print_lines([failed(r["name"]) + (f": {named_reason(r['name'], r['reason'])}" if r["reason"] else "")
                     for r in results if not r["successful"]], sys.stderr)
    return 0 if all(r["successful"] for r in results) else 1


def run(args: argparse.Namespace) -> int:
    if len(args.assignments) % 2:
        raise UsageError(f"parameter '{args.assignments[-1]}' has no value: give NAME VALUE pairs")
    pairs = list(zip(args.assignments[::2], args.assignments[1::2]))
    results = set_parameters(args, [{"name": name, **parse_value(text)} for name, text in pairs])
    if len(results) == 1:  # ros2's text for one parameter
        return report(args, results, lambda _: "Set parameter successful", lambda _: "Setting parameter failed")
    return report(args, results, lambda name: f"Set parameter {name} successful",
                  lambda name: f"Set parameter {name} failed")
