"""Turn the discovery and selection options of a command into the packages it works on."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from roc.environment import with_implicit_underlay
from roc.workspace.cache import cached_discovery
from roc.workspace.conditions import condition_environment
from roc.workspace.dependencies import DependencyIndex, topological_order
from roc.workspace.package import Package
from roc.workspace.root import find_workspace_root
from roc.workspace.selection import (
    check_selection_arguments,
    ignore_packages,
    select_packages,
)


class Workspace:
    def __init__(self, root: Path, ordered: list[Package], selected: set[str], index: DependencyIndex | None = None):
        self.root = root
        self.ordered = ordered  # every package not ignored, in topological order
        self.selected = selected
        self.dependencies = index or DependencyIndex(ordered)

    @property
    def by_name(self) -> dict[str, Package]:
        return self.dependencies.by_name

    def selected_in_order(self) -> list[Package]:
        return [p for p in self.ordered if p.name in self.selected]


def resolve_root(args: argparse.Namespace) -> Path:
    """--base-paths/--paths given on the command line are taken from the current directory, as colcon
    does; otherwise (also when roc.toml sets them) roc looks upward for the workspace root and says so
    when it is not the current directory."""
    config = getattr(args, "configuration", None)
    for dest in ("base_paths", "paths"):
        if getattr(args, dest) is not None and not (config and config.from_configuration(args, dest)):
            return Path.cwd()
    return find_workspace_root_for(args)


def find_workspace_root_for(args: argparse.Namespace) -> Path:
    """The workspace root around the current directory, announced when it is another directory."""
    cwd = Path.cwd()
    root = find_workspace_root(cwd) or cwd
    if root != cwd:
        print(f"roc: using workspace root {root}", file=sys.stderr)
    return root


def discover_workspace(root: Path, base_paths: list[str] | None = None,
                       paths: list[str] | None = None) -> list[Package]:
    """The packages of the workspace at ``root`` (from the discovery cache when nothing changed)."""
    return _discover(root, base_paths, paths)[0]


def _discover(root: Path, base_paths: list[str] | None, paths: list[str] | None) -> tuple[list[Package], bool]:
    """``discover_workspace``'s packages, and whether they are in topological order already."""
    variables = condition_environment(with_implicit_underlay(os.environ))

    def discover(visited: list[str]) -> list[Package]:
        from roc.workspace.discovery import discover_packages

        return discover_packages(root, variables, base_paths, paths, visited)

    return cached_discovery(root, variables, base_paths, paths, discover)


def load_workspace(args: argparse.Namespace) -> Workspace:
    root = resolve_root(args)
    packages, in_order = _discover(root, args.base_paths, args.paths)
    names = {p.name for p in packages}
    config = getattr(args, "configuration", None)
    if config is not None:
        from roc.config import check_package_tables

        check_package_tables(config, names)
    check_selection_arguments(args, names)
    kept = ignore_packages(args, packages)
    # with packages left out, colcon's layers of the others can differ: order them again
    ordered = kept if in_order and len(kept) == len(packages) else topological_order(kept)
    build_base = root / getattr(args, "build_base", "build")
    index = DependencyIndex(ordered)
    return Workspace(root, ordered, select_packages(args, ordered, build_base, index), index)
