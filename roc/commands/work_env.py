"""``roc work env PKG [-- CMD...]``: the environment a package is built in, printed or used to run CMD."""

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
from roc.render import print_json


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("package", metavar="PKG_NAME", help="the package")
    parser.add_argument("command", nargs=argparse.REMAINDER, metavar="-- CMD",
                        help="run CMD in that environment instead of printing it")
    add_base_arguments(parser)
    add_format_argument(parser)
    add_selection_arguments(parser)


def run(args: argparse.Namespace) -> int:
    from roc.builder.environment import build_environment, saved_environment
    from roc.buildtypes.context import BuildOptions
    from roc.workspace.dependencies import recursive_dependencies
    from roc.workspace.load import find_workspace_root_for

    root = find_workspace_root_for(args)
    build_base = root / args.build_base
    env = saved_environment(build_base, args.package)
    if env is None:  # not built yet: what it would be built in now
        from roc.workspace.load import load_workspace

        workspace = load_workspace(args)
        package = workspace.by_name.get(args.package)
        if package is None:
            raise UsageError(f"no package named '{args.package}' in the workspace; see 'roc work list -n'")
        options = BuildOptions(build_base=build_base, install_base=root / args.install_base,
                               merge_install=args.merge_install)
        recursive = recursive_dependencies(package, workspace.by_name)
        env = build_environment(package, [p.name for p in workspace.ordered if p.name in recursive], options)
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if command:
        sys.stdout.flush()
        try:
            os.execvpe(command[0], command, env)
        except OSError as error:
            raise UsageError(f"cannot run '{command[0]}': {error.strerror}") from None
    if args.format == "json":
        print_json(env)
    else:
        # Only names a shell can export (not e.g. BASH_FUNC_f%% of exported bash functions).
        sys.stdout.write("".join(f"export {name}={shlex.quote(value)}\n" for name, value in sorted(env.items())
                                 if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name)))
    return 0

