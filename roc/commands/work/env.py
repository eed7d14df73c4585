"""``roc work env PKG [-- CMD...]``: what a package's build environment changes (to eval), all of it,
or CMD run in it."""

from __future__ import annotations

import argparse
import os
import re
import shlex
import sys

from roc.cli.options import (
    add_base_arguments,
    add_format_argument,
    add_selection_arguments,
)
from roc.errors import UsageError
from roc.render import print_json, print_lines


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("package", nargs="?", metavar="PKG_NAME", help="the package")
    parser.add_argument("command", nargs="*", metavar="-- CMD",
                        help="run CMD in the environment PKG was built in instead of printing it")
    parser.add_argument("--all", action="store_true",
                        help="print every variable of the environment PKG was built in (default: only "
                             "those its build environment sets or changes relative to the current one)")
    add_base_arguments(parser)
    add_format_argument(parser)
    add_selection_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from roc.builder.environment import saved_environment
    from roc.workspace.load import find_workspace_root_for

    if not args.package:
        raise UsageError("roc work env needs a package: roc work env PKG_NAME [-- CMD...] "
                         "(see 'roc work env --help')")
    root = find_workspace_root_for(args)
    build_base = root / args.build_base
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    saved = saved_environment(build_base, args.package) if command or args.all else None
    env = saved if saved is not None else _current_build_environment(args, root)
    if command:
        sys.stdout.flush()
        try:
            os.execvpe(command[0], command, env)
        except OSError as error:
            raise UsageError(f"cannot run '{command[0]}': {error.strerror}") from None
    if not args.all:  # what eval-ing the output changes, so that it never resets PATH wholesale
        env = {name: value for name, value in env.items() if os.environ.get(name) != value}
    if args.format == "json":
        print_json(env)
    else:
        # Only names a shell can export (not e.g. BASH_FUNC_f%% of exported bash functions).
        print_lines(f"export {name}={shlex.quote(value)}" for name, value in sorted(env.items())
                    if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name))
    return 0


def _current_build_environment(args: argparse.Namespace, root) -> dict[str, str]:
    """The environment PKG's build runs in now: the current one plus its installed dependencies' hooks."""
    from roc.builder.environment import build_environment
    from roc.buildtypes.context import BuildOptions
    from roc.messages import unknown_package
    from roc.workspace.load import load_workspace

    workspace = load_workspace(args)
    package = workspace.by_name.get(args.package)
    if package is None:
        raise UsageError(unknown_package(args.package, workspace.by_name))
    options = BuildOptions(build_base=root / args.build_base, install_base=root / args.install_base,
                           merge_install=args.merge_install)
    return build_environment(package, workspace.dependencies.in_order(package.name), options)
