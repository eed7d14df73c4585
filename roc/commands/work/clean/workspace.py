"""``roc work clean workspace``: remove the workspace's bases, like ``colcon clean workspace``."""

from __future__ import annotations

import argparse
import os
from pathlib import Path

from roc.builder.clean import BASES
from roc.errors import UsageError
from roc.render import print_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add = parser.add_argument
    add("-y", "--yes", action="store_true", help="remove without asking")
    add("--base-select", nargs="*", metavar="BASE_NAME", choices=BASES, default=list(BASES),
        help=f"the bases to clean (default: {' '.join(BASES)})")
    add("--base-ignore", nargs="*", metavar="BASE_NAME", choices=BASES, default=[],
        help="bases not to clean (default: none)")
    add("--build-base", default="build", help="base directory of the build directories (default: build)")
    add("--install-base", default="install", help="base directory of the install prefixes (default: install)")
    add("--log-base", default="log", help="base directory of the logs (default: log)")
    add("--test-result-base", default="build", help="base directory of the test results (default: build)")


def run(args: argparse.Namespace) -> int:
    from roc.builder.clean import base_directories, chosen_bases
    from roc.workspace.load import find_workspace_root_for

    root = find_workspace_root_for(args)
    bases = base_directories(args, root)
    paths = set()
    for name in chosen_bases(args):
        base = bases.get(name)
        if base is None:
            continue
        if base.resolve() == root.resolve() or base.resolve() in root.resolve().parents:
            raise UsageError(f"the {name} base '{base}' is the workspace or contains it; refusing to remove it")
        if base.exists() or base.is_symlink():
            paths.add(base)
    return remove_paths(sorted(paths), args.yes)


def remove_paths(paths: list[Path], yes: bool) -> int:
    """List, confirm and remove (colcon clean's messages), then say what was removed (colcon says nothing)."""
    from roc.builder.clean import remove
    from roc.cli.confirm import confirm

    if not paths:
        print_lines(["No paths cleaned."])
        return 0
    if not yes:
        print_lines(["Paths:", *(f"     {os.path.relpath(path)}" for path in paths)])
        if not confirm("Clean the above paths?", "-y/--yes"):
            print_lines(["Nothing removed."])
            return 0
    for path in paths:
        remove(path)
    print_lines(["Removed:", *(f"     {os.path.relpath(path)}" for path in paths)])
    return 0
