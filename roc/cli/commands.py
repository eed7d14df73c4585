"""roc's command table and argument parser.

Each command names the module in ``roc.commands`` that defines it (``add_arguments`` and ``run``);
only the module of the command being run is imported, which keeps start-up short. Adding a verb is
one row in ``COMMANDS``.
"""

from __future__ import annotations

import argparse
import importlib

from roc import __version__
from roc.errors import EXIT_USAGE

# (command path, aliases, module in roc.commands, help)
COMMANDS = (
    (("work",), ("w",), None, "workspace: list, inspect and build packages"),
    (("work", "list"), ("ls",), "work_list", "list the packages of the workspace (like colcon list)"),
    (("work", "info"), (), "work_info", "show package details (like colcon info)"),
    (("work", "graph"), (), "work_graph", "show the dependency graph (like colcon graph)"),
    (("work", "build"), ("b",), "work_build", "build the workspace (a drop-in for colcon build)"),
    (("work", "test"), ("t",), "work_test", "test the workspace's packages (a drop-in for colcon test)"),
    (("work", "test-result"), (), "work_test_result", "summarize the test results (like colcon test-result)"),
    (("work", "clean"), (), None, "remove build, install, log and test result directories (like colcon clean)"),
    (("work", "clean", "workspace"), (), "work_clean_workspace", "clean the whole workspace's bases"),
    (("work", "clean", "packages"), (), "work_clean_packages", "clean the selected packages' directories"),
    (("work", "env"), (), "work_env", "print a package's build environment, or run a command in it"),
    (("work", "cache"), (), "work_cache", "CI caching of build results: cache key | export PATH | import PATH"),
    (("work", "config"), (), "work_config", "print the effective configuration and where each value comes from"),
    (("work", "create"), (), "work_create", "create a new package from a template (like ros2 pkg create)"),
    (("completion",), (), "completion", "print a shell completion script: bash, zsh or fish"),
)


# Verbs whose options roc.toml and colcon's defaults files can set.
CONFIGURED_VERBS = ("list", "info", "graph", "build", "test", "env", "cache")


class Parser(argparse.ArgumentParser):
    """argparse with roc's one-line usage errors; ``leaves`` maps each command path to its parser."""

    leaves: dict[tuple[str, ...], "Parser"]

    def error(self, message: str):  # type: ignore[override]
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def requested_command(argv: list[str]) -> tuple[str, ...]:
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
    wanted = requested_command(argv) if argv is not None else None
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
                command_module(module).add_arguments(sub)
                if path[0] == "work" and path[-1] in CONFIGURED_VERBS:
                    sub.add_argument("--profile", metavar="NAME", help="use [profile.NAME] of roc.toml")
            sub.set_defaults(_module=module, _group=None)
            leaves[path] = sub
    parser.leaves = leaves
    return parser


def command_module(name: str):
    return importlib.import_module(f"roc.commands.{name}")
