"""``roc work graph``: the dependency graph as colcon draws it (ASCII matrix or ``--dot``), or JSON."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from roc.cli.options import add_format_argument, add_selection_arguments
from roc.render import print_json, print_lines
from roc.workspace.load import Workspace
from roc.workspace.package import CATEGORIES, Package

COLORS = {"build": "#0000ff", "run": "#ff0000", "test": "#d2b48c"}  # blue, red, tan
LEGEND = (
    "+ marks when the package in this row can be processed",
    "* marks a direct dependency from the package indicated by the + in the same column to the package in this row",
    ". marks a transitive dependency",
)
Edges = dict[tuple[str, str], set[str]]  # (dependent, dependency) -> categories


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--dot", action="store_true",
                        help="print Graphviz DOT (e.g. '| dot -Tpng -o graph.png'); "
                             "blue=build, red=run, tan=test, dashed=indirect")
    parser.add_argument("--density", action="store_true", help="print the density of the graph")
    parser.add_argument("--legend", action="store_true", help="print a legend")
    parser.add_argument("--dot-cluster", action="store_true", help="cluster packages by directory (with --dot)")
    parser.add_argument("--dot-include-skipped", action="store_true", help="also show skipped packages (with --dot)")
    parser.add_argument("--build-base", default="build", help="build base, read by --packages-select-build-failed")
    add_format_argument(parser)
    add_selection_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from roc.workspace.load import load_workspace

    workspace = load_workspace(args)
    if args.format == "json":
        print_json(graph_json(workspace))
    elif args.dot:
        print_lines(dot_lines(workspace, args.dot_include_skipped, args.dot_cluster, args.legend))
    else:
        print_lines(matrix_lines(workspace, args.density, args.legend))
    return 0


def _recursive(workspace: Workspace) -> dict[str, dict[str, int]]:
    return {p.name: workspace.dependencies.recursive(p.name) for p in workspace.ordered}


def matrix_lines(workspace: Workspace, density: bool, legend: bool) -> list[str]:
    """One row and one column per selected package in topological order: ``+`` where the column's
    package is built, ``*`` for its direct dependencies, ``.`` for its transitive ones."""
    shown = workspace.selected_in_order()
    recursive = _recursive(workspace)
    width = max((len(p.name) for p in shown), default=0) + 2
    rows = [p.name.ljust(width) for p in shown]
    empty = 0
    for column, package in enumerate(shown):
        direct = package.direct_dependencies()
        for row, other in enumerate(shown):
            if row == column:
                mark = "+"
            elif other.name in direct:
                mark = "*"
            elif other.name in recursive[package.name]:
                mark = "."
            else:
                mark = " "
                empty += 1
            rows[row] += mark
    header = [*LEGEND, ""] if legend else []
    if density:
        fraction = empty / (len(rows) * (len(rows) - 1)) if len(rows) > 1 else 1.0
        header += [f"dependency density {200.0 * (1.0 - fraction):.2f} %", ""]
    return header + rows


def _edges(workspace: Workspace, shown: list[Package]) -> tuple[Edges, Edges]:
    """Direct edges between shown packages, and dashed indirect ones through packages not shown."""
    shown_names = {p.name for p in shown}
    known = workspace.by_name
    recursive = _recursive(workspace)
    direct: Edges = {}
    indirect: Edges = {}
    for package in shown:
        for category in CATEGORIES:
            for dependency in sorted(package.dependencies.get(category, ())):
                if dependency in shown_names and dependency != package.name:
                    direct.setdefault((package.name, dependency), set()).add(category)
    for package in shown:
        if package.name not in workspace.selected:
            continue
        for category in CATEGORIES:
            for dependency in sorted(package.dependencies.get(category, ())):
                if dependency in shown_names or dependency not in known:
                    continue
                for further in recursive[dependency]:
                    if further in shown_names and (package.name, further) not in direct:
                        indirect.setdefault((package.name, further), set()).add(category)
    return direct, indirect


def dot_lines(workspace: Workspace, include_skipped: bool, cluster: bool, legend: bool) -> list[str]:
    shown = [p for p in reversed(workspace.ordered) if include_skipped or p.name in workspace.selected]
    selected = workspace.selected
    direct, indirect = _edges(workspace, shown)

    def node(package: Package) -> str:
        gray = "" if package.name in selected else '[color = "gray" fontcolor = "gray"]'
        return f'"{package.name}"{gray};'

    lines = ["digraph graphname {"]
    parents = {p.name: Path(p.path).parent for p in shown}
    common = os.path.commonpath([str(path) for path in parents.values()]) if shown else None
    if cluster and common is not None:
        clusters: dict[Path, list[Package]] = {}
        for package in shown:
            clusters.setdefault(parents[package.name].relative_to(common), []).append(package)
        for index, (path, members) in enumerate(clusters.items()):
            indent = "    " if path.name else "  "
            if path.name:
                lines += [f"  subgraph cluster_{index} {{", f'    label = "{path}";']
            lines += [indent + node(p) for p in sorted(members, key=lambda p: p.name)]
            if path.name:
                lines.append("  }")
    else:
        lines += ["  " + node(p) for p in shown]
    for style, edges in (("", direct), (', style="dashed"', indirect)):
        for (start, end), categories in edges.items():
            alpha = "" if start in selected and end in selected else "77"
            colors = ":".join(COLORS[c] + alpha for c in CATEGORIES if c in categories)
            lines.append(f'  "{start}" -> "{end}" [color="{colors}"{style}];')
    if legend:
        lines += _dot_legend()
    lines.append("}")
    return lines


def _dot_legend() -> list[str]:
    lines = ["  subgraph cluster_legend {", "    color=gray", '    label="Legend";', "    margin=0;",
             '    node [label="", shape=none];']
    previous = "_legend_first"
    for category, color in COLORS.items():
        lines.append(f'    {previous} -> _legend_{category} [label="{category} dep.", color="{color}"];')
        previous = f"_legend_{category}"
    lines.append(f'    {previous} -> _legend_last [label="indirect dep.", style="dashed"];')
    lines += ["    {", "      rank=same;", "      _legend_first;", *[f"      _legend_{c};" for c in COLORS],
              "      _legend_last;", "    }", "  }"]
    return lines


def graph_json(workspace: Workspace) -> dict:
    shown = workspace.selected_in_order()
    direct, indirect = _edges(workspace, shown)
    return {
        "nodes": [{"name": p.name, "path": str(p.path), "type": p.type} for p in shown],
        "edges": [
            {"from": start, "to": end, "categories": [c for c in CATEGORIES if c in categories], "indirect": dashed}
            for dashed, edges in ((False, direct), (True, indirect))
            for (start, end), categories in edges.items()
        ],
    }
