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
from roc.messages import did_you_mean

# (command path, aliases, module in roc.commands, help)
COMMANDS = (
    (("work",), ("w",), None, "workspace: list, inspect and build packages"),
    (("work", "list"), ("ls",), "work.list", "list the packages of the workspace (like colcon list)"),
    (("work", "info"), (), "work.info", "show package details (like colcon info)"),
    (("work", "graph"), (), "work.graph", "show the dependency graph (like colcon graph)"),
    (("work", "build"), ("b",), "work.build", "build the workspace (a drop-in for colcon build)"),
    (("work", "test"), ("t",), "work.test", "test the workspace's packages (a drop-in for colcon test)"),
    (("work", "test-result"), (), "work.test_result", "summarize the test results (like colcon test-result)"),
    (("work", "clean"), (), None, "remove build, install, log and test result directories (like colcon clean)"),
    (("work", "clean", "workspace"), (), "work.clean.workspace", "clean the whole workspace's bases"),
    (("work", "clean", "packages"), (), "work.clean.packages", "clean the selected packages' directories"),
    (("work", "env"), (), "work.env", "print a package's build environment, or run a command in it"),
    (("work", "cache"), (), "work.cache", "CI caching of build results: cache key | export PATH | import PATH"),
    (("work", "config"), (), "work.config", "print the effective configuration and where each value comes from"),
    (("work", "create"), (), "work.create", "create a new package from a template (like ros2 pkg create)"),
    (("topic",), (), None, "ROS topics: list, info, type, find, echo, pub, hz, bw, delay"),
    (("topic", "list"), (), "topic.list", "list the topics of the ROS graph"),
    (("topic", "info"), (), "topic.info", "a topic's type and endpoints (-v: QoS and compatibility checks)"),
    (("topic", "type"), (), "topic.type", "print a topic's type"),
    (("topic", "find"), (), "topic.find", "list the topics of a given type"),
    (("topic", "echo"), (), "topic.echo", "print the messages of a topic (and count lost ones)"),
    (("topic", "pub"), (), "topic.pub", "publish messages on a topic"),
    (("topic", "hz"), (), "topic.hz", "the publishing rate of topics (from sequence numbers, losses counted)"),
    (("topic", "bw"), (), "topic.bw", "the bandwidth a topic uses (true serialised sizes)"),
    (("topic", "delay"), (), "topic.delay", "delay between header stamps and reception"),
    (("node",), (), None, "ROS nodes: list, info"),
    (("node", "list"), (), "node.list", "list the nodes of the ROS graph"),
    (("node", "info"), (), "node.info", "what a node publishes, subscribes, serves and calls"),
    (("service",), (), None, "ROS services: list, type, find, call"),
    (("service", "list"), (), "service.list", "list the services of the ROS graph"),
    (("service", "type"), (), "service.type", "print a service's type"),
    (("service", "find"), (), "service.find", "list the services of a given type"),
    (("service", "call"), (), "service.call", "call a service"),
    (("action",), (), None, "ROS actions: list, info, type, send_goal"),
    (("action", "list"), (), "action.list", "list the actions of the ROS graph"),
    (("action", "info"), (), "action.info", "the servers and clients of an action"),
    (("action", "type"), (), "action.type", "print an action's type"),
    (("action", "send_goal"), (), "action.send_goal", "send a goal to an action server and wait for its result"),
    (("param",), (), None, "ROS parameters: list, get, describe, dump, set, delete, load"),
    (("param", "list"), (), "param.list", "list the parameters of one node or of every node"),
    (("param", "get"), (), "param.get", "print a parameter's value"),
    (("param", "describe"), (), "param.describe", "print a parameter's descriptor"),
    (("param", "dump"), (), "param.dump", "print a node's parameters as a YAML parameter file"),
    (("param", "set"), (), "param.set", "set parameters of a node"),
    (("param", "delete"), (), "param.delete", "delete parameters of a node"),
    (("param", "load"), (), "param.load", "set a node's parameters from a parameter file (as param dump writes it)"),
    (("interface",), (), None, "ROS interfaces from the ament index: list, packages, package, show"),
    (("interface", "list"), (), "interface.list", "list the messages, services and actions installed"),
    (("interface", "packages"), (), "interface.packages", "list the packages that define interfaces"),
    (("interface", "package"), (), "interface.package", "list the interfaces of one package"),
    (("interface", "show"), (), "interface.show", "print an interface definition, nested types expanded"),
    (("interface", "proto"), (), "interface.proto", "print a YAML prototype of a message, request or goal"),
    (("pkg",), (), None, "installed packages (the ament index): list, prefix, executables, xml"),
    (("pkg", "list"), (), "pkg.list", "list the installed packages (like ros2 pkg list)"),
    (("pkg", "prefix"), (), "pkg.prefix", "print a package's install prefix, or its share directory"),
    (("pkg", "executables"), (), "pkg.executables", "list the executables of installed packages"),
    (("pkg", "xml"), (), "pkg.xml", "print a package's manifest, or the text of one of its tags"),
    (("run",), (), "run", "run an executable of an installed package (like ros2 run)"),
    (("launch",), (), "launch.command",
     "start a system: a launch file (Python, XML, YAML) or a [launch.NAME] of roc.toml (like ros2 launch)"),
    (("graph",), (), None, "the running ROS system as a whole: check, snapshot"),
    (("graph", "check"), (), "graph.check", "probe the running system against roc.toml's [check] expectations"),
    (("graph", "snapshot"), (), "graph.snapshot", "print the [check] expectations the running system meets now"),
    (("frame",), (), None, "tf frames and transforms: list, echo, tree, monitor, pub, convert"),
    (("frame", "list"), (), "frame.list", "every tf frame: parent, static or dynamic, rate, age, publishers"),
    (("frame", "echo"), (), "frame.echo", "the transform between two frames (like tf2_echo)"),
    (("frame", "tree"), (), "frame.tree", "the tf tree as text, DOT, SVG, PNG or PDF"),
    (("frame", "monitor"), (), "frame.monitor", "rate and delay of each frame, live (like tf2_monitor)"),
    (("frame", "pub"), (), "frame.pub", "publish a transform, static or at a rate (like static_transform_publisher)"),
    (("frame", "convert"), (), "frame.convert", "convert rotations between representations; compose and invert transforms"),
    (("bridge",), (), "bridge.command", "bridge topics from one ROS domain into another (like domain_bridge)"),
    (("daemon",), (), None, "the roc daemon (a warm graph participant): start, stop, status"),
    (("daemon", "start"), (), "daemon.start", "start the roc daemon of this discovery environment"),
    (("daemon", "stop"), (), "daemon.stop", "stop the roc daemon of this discovery environment"),
    (("daemon", "status"), (), "daemon.status", "whether the roc daemon of this environment runs"),
    (("idl",), (), None, "interface definitions: convert between protobuf and ROS 2 messages"),
    (("idl", "protobuf"), (), "idl.protobuf", "convert .proto files to .msg files, or .msg files to .proto"),
    (("completion",), (), "completion", "print a shell completion script: bash, zsh or fish"),
)


# Verbs whose options roc.toml and colcon's defaults files can set.
CONFIGURED_VERBS = ("list", "info", "graph", "build", "test", "env", "cache")


# colcon options (from extensions roc does not replace) that roc does not have, and what to do instead.
COLCON_ONLY_OPTIONS = {
    "--mixin": "colcon-mixin; put the arguments in a [profile.NAME] of roc.toml and use --profile NAME",
    "--mixin-files": "colcon-mixin; put the arguments in a [profile.NAME] of roc.toml and use --profile NAME",
    "--packages-select-test-failures": "colcon-test-result; roc has no test verb yet",
    "--packages-skip-test-passed": "colcon-test-result; roc has no test verb yet",
    "--log-level": "colcon's logging; use --debug for tracebacks and the log/ directory for build logs",
}


class Parser(argparse.ArgumentParser):
    """argparse with roc's one-line usage errors (``roc: error: ... (see 'roc work build --help')``) and
    no abbreviated options (``--symlink-instal`` is an error, not ``--symlink-install``); ``leaves``
    maps each command path to its parser."""

    leaves: dict[tuple[str, ...], Parser]

    def __init__(self, *args, **kwargs) -> None:
        kwargs["allow_abbrev"] = False
        super().__init__(*args, **kwargs)

    def error(self, message: str):  # type: ignore[override]
        self.exit(EXIT_USAGE, f"roc: error: {message} (see '{self.prog} --help')\n")

    def parse_args(self, args=None, namespace=None):  # type: ignore[override]
        """Unknown arguments are reported by the parser of the command they were given to."""
        namespace, extras = self.parse_known_args(args, namespace)
        if extras:
            leaf = getattr(self, "leaves", {}).get(requested_command(list(args or [])), self)
            leaf.error(_unrecognized(leaf, extras))
        return namespace


def _unrecognized(parser: argparse.ArgumentParser, extras: list[str]) -> str:
    """The message for arguments ``parser`` does not know: colcon options roc lacks by name, and the
    closest option for a misspelled one."""
    for word in extras:
        option = word.split("=", 1)[0]
        if option in COLCON_ONLY_OPTIONS:
            return f"roc does not support {option} ({COLCON_ONLY_OPTIONS[option]})"
    message = f"unrecognized arguments: {' '.join(extras)}"
    known = [o for a in parser._actions for o in a.option_strings]
    for word in extras:
        hint = did_you_mean(word.split("=", 1)[0], known, count=1, quote=False) if word.startswith("--") else ""
        if hint:
            return f"{message}; {hint}"
    return message


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
