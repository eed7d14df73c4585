"""``roc work clean packages``: remove the selected packages' directories from the bases, like
``colcon clean packages``; the next build rebuilds them."""

from __future__ import annotations

import argparse

from roc.cli.options import add_selection_arguments
from roc.commands.work.clean import workspace as clean_workspace


def add_arguments(parser: argparse.ArgumentParser) -> None:
    clean_workspace.add_arguments(parser)
    parser.add_argument("--merge-install", action="store_true",
                        help="the install base is merged (package files are not removed from it)")
    parser.add_argument("packages", nargs="*", metavar="PKG_NAME", help="shorthand for --packages-select PKG_NAME...")
    add_selection_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from roc.builder.clean import base_directories, check_inside, chosen_bases, package_directories
    from roc.builder.layout import refresh_install_scripts
    from roc.messages import warn
    from roc.workspace.load import load_workspace

    if args.packages:
        args.packages_select = [*(args.packages_select or []), *args.packages]
    workspace = load_workspace(args)
    bases = base_directories(args, workspace.root)
    chosen = chosen_bases(args)
    if args.merge_install and "install" in chosen:
        warn("with --merge-install the packages' installed files stay (clean the workspace's install base)")
    paths = set()
    for name in chosen:
        if name not in bases:
            continue
        for package in workspace.selected_in_order():
            for path in package_directories(name, bases[name], package.name, args.merge_install):
                check_inside(path, bases[name])
                if path.exists() or path.is_symlink():
                    paths.add(path)
    status = clean_workspace.remove_paths(sorted(paths), args.yes)
    install = bases.get("install")
    if install and any(path.parent == install and not path.exists() for path in paths):
        refresh_install_scripts(install, args.merge_install)
    return status
