"""roc param load: set a node's parameters from a YAML parameter file, as ``param dump`` writes it
(like ros2 param load)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from roc.commands.param.set import report, set_parameters, typed_value
from roc.commands.param.target import add_node_arguments, ask_node
from roc.errors import UsageError
from roc.fsutil import read_yaml
from roc.messages import warn

WILDCARD = "/**"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_node_arguments(parser)
    parser.add_argument("parameter_file", type=Path, help="YAML file: {NODE or /**: {ros__parameters: {...}}}")
    parser.add_argument("--no-use-wildcard", action="store_true",
                        help=f"leave out the parameters of the file's '{WILDCARD}' section (for every node)")


def flattened(tree: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested mappings as dotted names (the inverse of param dump's nesting)."""
    flat: dict[str, Any] = {}
    for key, value in tree.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            flat.update(flattened(value, f"{name}."))
        else:
            flat[name] = value
    return flat


def file_parameters(path: Path, node: str, use_wildcard: bool = True) -> dict[str, Any]:
    """The parameters the file gives ``node``: its own section over the ``/**`` one (``use_wildcard``)."""
    document = read_yaml(path)
    if not isinstance(document, dict):
        raise UsageError(f"{path}: expected a mapping of node names to {{ros__parameters: ...}}")
    values: dict[str, Any] = {}
    for key in ((WILDCARD,) if use_wildcard else ()) + (node, node.lstrip("/")):
        section = document.get(key)
        if section is None:
            continue
        if not isinstance(section, dict) or not isinstance(section.get("ros__parameters"), dict):
            raise UsageError(f"{path}: '{key}' has no 'ros__parameters' mapping")
        values.update(flattened(section["ros__parameters"]))
    if not values:
        raise UsageError(f"{path}: no parameters for {node} (sections: {', '.join(map(str, document)) or 'none'}"
                         + ("; --no-use-wildcard leaves out '/**'" if not use_wildcard and WILDCARD in document else "")
                         + ")", ros2_line="Param file does not contain selected parameters")
    return values


def run(args: argparse.Namespace) -> int:
    """Read-only parameters (which param dump writes too) are left out with a note, so that a dump
    loads back; exit 1 when the node refused another. As ros2, the node is looked for first."""
    ask_node(args, "node_wait")
    values = file_parameters(args.parameter_file, args.node_name, use_wildcard=not args.no_use_wildcard)
    descriptors = ask_node(args, "param_describe", {"names": list(values), "timeout": 0})
    read_only = [d["name"] for d in descriptors if d["read_only"]]
    for name in read_only:
        warn(f"{args.parameter_file}: {name} is read-only on {args.node_name}; not set")
    results = set_parameters(args, [{"name": name, **typed_value(value)}
                                                    for name, value in values.items() if name not in read_only])
    return report(args, results, lambda name: f"Set parameter {name} successful",
                  lambda name: f"Set parameter {name} failed")
