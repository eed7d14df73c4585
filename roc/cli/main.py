"""The ``roc`` command: argument parsing, dispatch and the error convention.

Exit codes: 0 ok, 1 failure, 2 usage error, 130 interrupted. Errors are one line on stderr; a Python
traceback only with ``--debug`` or ``ROC_DEBUG=1``. Command modules are imported only when run, so
that start-up stays light.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from pathlib import Path

from roc import __version__
from roc.errors import EXIT_FAILURE, EXIT_INTERRUPTED, EXIT_USAGE, RocError

# (command path, aliases, module in roc.commands, help)
COMMANDS = (
    (("work",), ("w",), None, "workspace: list, inspect and build packages"),
    (("work", "list"), ("ls",), "work_list", "list the packages of the workspace (like colcon list)"),
    (("work", "info"), (), "work_info", "show package details (like colcon info)"),
    (("work", "graph"), (), "work_graph", "show the dependency graph (like colcon graph)"),
    (("work", "build"), ("b",), "work_build", "build the workspace (a drop-in for colcon build)"),
    (("work", "env"), (), "work_env", "print a package's build environment, or run a command in it"),
    (("work", "cache"), (), "work_cache", "CI caching of build results: cache key | export PATH | import PATH"),
    (("work", "config"), (), "work_config", "print the effective configuration and where each value comes from"),
    (("work", "create"), (), "work_create", "create a new package from a template (like ros2 pkg create)"),
    (("completion",), (), "completion", "print a shell completion script: bash, zsh or fish"),
)


# Verbs whose options roc.toml and colcon's defaults files can set.
CONFIGURED_VERBS = ("list", "info", "graph", "build", "env", "cache")


class Parser(argparse.ArgumentParser):
    """argparse with roc's one-line usage errors."""

    def error(self, message: str):  # type: ignore[override]
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def _requested_command(argv: list[str]) -> tuple[str, ...]:
    """The command path named on the command line (aliases resolved), e.g. ("work", "list")."""
    path: tuple[str, ...] = ()
    words = iter(argv)
    for word in words:
        if word == "-C":
            next(words, None)
            continue
        if word.startswith("-"):
            continue
        for command, aliases, _, _ in COMMANDS:
            if command[:-1] == path and word in (command[-1], *aliases):
                path = command
                break
        else:
            break
    return path


def build_parser(argv: list[str] | None = None) -> Parser:
    """The argument parser; with ``argv`` only the named command's options are set up (every command
    is still listed), which keeps start-up short."""
    wanted = _requested_command(argv) if argv is not None else None
    parser = Parser(prog="roc", description="roc: fast, dependable tools for ROS 2 workspaces.")
    parser.add_argument("--version", action="version", version=f"roc {__version__}")
    parser.add_argument("--debug", action="store_true", help="show Python tracebacks for errors")
    parser.add_argument("-C", dest="directory", metavar="DIR", help="run as if roc was started in DIR")
    leaves: dict[tuple[str, ...], Parser] = {}
    groups: dict[tuple[str, ...], argparse._SubParsersAction] = {
        (): parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    }
    for path, aliases, module, help_text in COMMANDS:
        sub = groups[path[:-1]].add_parser(path[-1], aliases=list(aliases), help=help_text, description=help_text)
        if module is None:
            groups[path] = sub.add_subparsers(dest="_".join(path) + "_command", metavar="COMMAND", parser_class=Parser)
            sub.set_defaults(_group=sub)
        else:
            if wanted is None or wanted == path:
                _command_module(module).add_arguments(sub)
                if path[0] == "work" and path[-1] in CONFIGURED_VERBS:
                    sub.add_argument("--profile", metavar="NAME", help="use [profile.NAME] of roc.toml")
            sub.set_defaults(_module=module, _group=None)
            leaves[path] = sub
    parser.leaves = leaves  # type: ignore[attr-defined]
    return parser


def _early_value(argv: list[str], option: str) -> str | None:
    """The value of ``option`` (``-C DIR``, ``--profile NAME``) before argparse runs."""
    for index, word in enumerate(argv):
        if word == option and index + 1 < len(argv):
            return argv[index + 1]
        if word.startswith(option + "="):
            return word.split("=", 1)[1]
    return None


def _early_values(argv: list[str], option: str) -> list[str] | None:
    """The values after ``option`` up to the next option (``--metas A B``), None when it is absent."""
    if option not in argv:
        return None
    values = []
    for word in argv[argv.index(option) + 1:]:
        if word.startswith("-"):
            break
        values.append(word)
    return values


def _apply_workspace_configuration(parser: Parser, path: tuple[str, ...], argv: list[str]):
    """Make roc.toml / colcon defaults the defaults of the command's options (the command line wins)."""
    from roc.config import apply_configuration, load_configuration
    from roc.workspace.root import find_workspace_root

    cwd = Path.cwd()
    root = find_workspace_root(cwd) or cwd
    metas = _early_values(argv, "--metas")
    config = load_configuration(root, path[-1], _early_value(argv, "--profile"), metas,
                                ignore_user_meta="--ignore-user-meta" in argv)
    apply_configuration(parser.leaves[path], config)  # type: ignore[attr-defined]
    return config


def _command_module(name: str):
    return importlib.import_module(f"roc.commands.{name}")


def main(argv: list[str] | None = None) -> int:
    debug = os.environ.get("ROC_DEBUG") == "1" or "--debug" in (argv if argv is not None else sys.argv[1:])
    try:
        argv = list(sys.argv[1:] if argv is None else argv)
        first_word = next((i for i, w in enumerate(argv) if not w.startswith("-") and (i == 0 or argv[i - 1] != "-C")),
                          len(argv))
        directory = _early_value(argv[:first_word], "-C")
        if directory:
            try:
                os.chdir(directory)
            except OSError as error:
                raise RocError(f"-C {directory}: {error.strerror}") from None
        parser = build_parser(argv)
        path = _requested_command(argv)
        config = None
        if path in parser.leaves and path[0] == "work" and path[-1] in CONFIGURED_VERBS:  # type: ignore[attr-defined]
            config = _apply_workspace_configuration(parser, path, argv)
        if any(token in argv for token in ("--cmake-args", "--ament-cmake-args")):
            from roc.commands.completion import all_options
            from roc.commands.work_build import rewrite_passthrough

            argv = rewrite_passthrough(argv, all_options(parser))
        args = parser.parse_args(argv)
        args.configuration = config
        module = getattr(args, "_module", None)
        if module is None:
            (getattr(args, "_group", None) or parser).print_help(sys.stderr)
            return EXIT_USAGE
        return _command_module(module).run(args)
    except RocError as error:
        if debug:
            raise
        print(f"roc: error: {error}", file=sys.stderr)
        return error.exit_code
    except KeyboardInterrupt:
        print("roc: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        # The reader went away (e.g. `roc work list | head`): not an error worth a message.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as error:  # a path roc cannot create, read or write
        if debug:
            raise
        where = f"{error.filename}: " if error.filename else ""
        print(f"roc: error: {where}{error.strerror or error}; check the path and its permissions", file=sys.stderr)
        return EXIT_FAILURE
    except Exception as error:  # noqa: BLE001 - last resort: one line, details with --debug
        if debug:
            raise
        print(f"roc: internal error: {type(error).__name__}: {error} (run with --debug for details)", file=sys.stderr)
        return EXIT_FAILURE
