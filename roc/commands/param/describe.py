"""roc param describe: parameter descriptors, type and constraints (like ros2 param describe)."""

from __future__ import annotations

import argparse

from roc.commands.param.target import add_node_arguments, ask_node
from roc.render import render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_node_arguments(parser)
    parser.add_argument("parameter_names", nargs="+", help="names of the parameters")


def descriptor_lines(d: dict) -> list[str]:
    lines = [f"Parameter name: {d['name']}", f"  Type: {d['type']}"]
    if d["description"]:
        lines.append(f"  Description: {d['description']}")
    lines.append("  Constraints:")
    if d["read_only"]:
        lines.append("    Read only: true")
    ranges = d["floating_point_range"] + d["integer_range"]
    if ranges:
        lines += [f"    Min value: {ranges[0]['from_value']}", f"    Max value: {ranges[0]['to_value']}"]
        if ranges[0]["step"]:
            lines.append(f"    Step: {ranges[0]['step']}")
    if d["additional_constraints"]:
        lines.append(f"    Additional constraints: {d['additional_constraints']}")
    return lines


def run(args: argparse.Namespace) -> int:
    descriptors = ask_node(args, "param_describe", {"names": args.parameter_names})
    render(descriptors, args.format, [line for d in descriptors for line in descriptor_lines(d)])
    return 0
