"""roc's command table and argument parser.

Each command names the module in ``roc.commands`` that defines it (``add_arguments`` and ``run``);
only the module of the command being run is imported, which keeps start-up short. Adding a verb is
one row in ``COMMANDS``.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys

from roc import __version__
from roc.errors import EXIT_USAGE
from roc.messages import did_you_mean

# (command path, aliases, module in roc.commands, help); a group's help (module None) is followed by the
# names of its commands in the parser
COMMANDS = (
    (("work",), ("w",), None, "the workspace's packages"),
    (("work", "list"), ("ls",), "work.list", "list the packages of the workspace (like colcon list)"),
    (("work", "info"), (), "work.info", "show package details (like colcon info)"),
    (("work", "graph"), (), "work.graph", "show the dependency graph (like colcon graph)"),
    (("work", "build"), ("b",), "work.build", "build the workspace (a drop-in for colcon build)"),
    (("work", "test"), ("t",), "work.test", "test the workspace's packages (a drop-in for colcon test)"),
    (("work", "test-result"), (), "work.test_result", "summarize the test results (like colcon test-result)"),
    (("work", "clean"), (), None, "remove build, install, log and test result directories, like colcon clean"),
    (("work", "clean", "workspace"), (), "work.clean.workspace", "clean the whole workspace's bases"),
    (("work", "clean", "packages"), (), "work.clean.packages", "clean the selected packages' directories"),
    (("work", "env"), (), "work.env", "print a package's build environment, or run a command in it"),
    (("work", "cache"), (), "work.cache", "CI caching of build results: cache key | export PATH | import PATH"),
    (("work", "config"), (), "work.config", "print the effective configuration and where each value comes from"),
    (("work", "create"), (), "work.create", "create a new package from a template (like ros2 pkg create)"),
    (("work", "worker"), (), "work.worker", "run a Dask worker that builds and tests packages for --cluster"),
    (("topic",), (), None, "ROS topics"),
    (("topic", "list"), (), "topic.list", "list the topics of the ROS graph"),
    (("topic", "info"), (), "topic.info", "a topic's type and endpoints (-v: QoS and compatibility checks)"),
    (("topic", "type"), (), "topic.type", "print a topic's type"),
    (("topic", "find"), (), "topic.find", "list the topics of a given type"),
    (("topic", "echo"), (), "topic.echo", "print the messages of a topic (and count lost ones)"),
    (("topic", "pub"), (), "topic.pub", "publish messages on a topic"),
    (("topic", "hz"), (), "topic.hz", "the publishing rate of topics (from sequence numbers, losses counted)"),
    (("topic", "bw"), (), "topic.bw", "the bandwidth a topic uses (true serialised sizes)"),
    (("topic", "delay"), (), "topic.delay", "delay between header stamps and reception"),
    (("node",), (), None, "ROS nodes"),
    (("node", "list"), (), "node.list", "list the nodes of the ROS graph"),
    (("node", "info"), (), "node.info", "what a node publishes, subscribes, serves and calls"),
    (("service",), (), None, "ROS services"),
    (("service", "list"), (), "service.list", "list the services of the ROS graph"),
    (("service", "info"), (), "service.info", "a service's type and its clients and servers (-v: their endpoints)"),
    (("service", "type"), (), "service.type", "print a service's type"),
    (("service", "find"), (), "service.find", "list the services of a given type"),
    (("service", "call"), (), "service.call", "call a service"),
    (("service", "echo"), (), "service.echo", "print a service's requests and responses (service introspection)"),
    (("action",), (), None, "ROS actions"),
    (("action", "list"), (), "action.list", "list the actions of the ROS graph"),
    (("action", "info"), (), "action.info", "the servers and clients of an action"),
    (("action", "type"), (), "action.type", "print an action's type"),
    (("action", "send_goal"), (), "action.send_goal", "send a goal to an action server and wait for its result"),
    (("param",), (), None, "ROS parameters"),
    (("param", "list"), (), "param.list", "list the parameters of one node or of every node"),
    (("param", "get"), (), "param.get", "print a parameter's value"),
    (("param", "describe"), (), "param.describe", "print a parameter's descriptor"),
    (("param", "dump"), (), "param.dump", "print a node's parameters as a YAML parameter file"),
    (("param", "set"), (), "param.set", "set parameters of a node"),
    (("param", "delete"), (), "param.delete", "delete parameters of a node"),
    (("param", "load"), (), "param.load", "set a node's parameters from a parameter file (as param dump writes it)"),
    (("lifecycle",), (), None, "managed (lifecycle) nodes"),
    (("lifecycle", "nodes"), (), "lifecycle.nodes", "list the managed nodes of the ROS graph"),
    (("lifecycle", "get"), (), "lifecycle.get", "the lifecycle state of one managed node or of every one"),
    (("lifecycle", "list"), (), "lifecycle.list", "the transitions a managed node can take"),
    (("lifecycle", "set"), (), "lifecycle.set", "trigger a lifecycle transition of a managed node"),
    (("component",), (), None, "components and their containers"),
    (("component", "types"), (), "component.types", "list the component types the ament index registers"),
    (("component", "list"), (), "component.list", "list the container nodes and their components"),
    (("component", "load"), (), "component.load", "load a component into a container node"),
    (("component", "unload"), (), "component.unload", "unload components from a container node"),
    (("component", "standalone"), (), "component.standalone", "run a component in a container node of its own"),
    (("doctor",), ("wtf",), "doctor.check", "check the environment, the network and the live graph (like ros2 doctor)"),
    (("doctor", "hello"), (), "doctor.hello", "check that this host and others hear each other (topic and multicast)"),
    (("multicast",), (), None, "UDP multicast between hosts"),
    (("multicast", "send"), (), "multicast.send", "send one UDP multicast datagram"),
    (("multicast", "receive"), (), "multicast.receive", "wait for one UDP multicast datagram"),
    (("interface",), (), None, "ROS interfaces from the ament index"),
    (("interface", "list"), (), "interface.list", "list the messages, services and actions installed"),
    (("interface", "packages"), (), "interface.packages", "list the packages that define interfaces"),
    (("interface", "package"), (), "interface.package", "list the interfaces of one package"),
    (("interface", "show"), (), "interface.show", "print an interface definition, nested types expanded"),
    (("interface", "proto"), (), "interface.proto", "print a YAML prototype of a message, request or goal"),
    (("pkg",), (), None, "installed packages (the ament index)"),
    (("pkg", "list"), (), "pkg.list", "list the installed packages (like ros2 pkg list)"),
    (("pkg", "prefix"), (), "pkg.prefix", "print a package's install prefix, or its share directory"),
    (("pkg", "executables"), (), "pkg.executables", "list the executables of installed packages"),
    (("pkg", "xml"), (), "pkg.xml", "print a package's manifest, or the text of one of its tags"),
    (("run",), (), "run", "run an executable of an installed package (like ros2 run)"),
    (("launch",), (), "launch.command",
     "start a system: a launch file (Python, XML, YAML) or a [launch.NAME] of roc.toml (like ros2 launch)"),
    (("graph",), (), None, "the running ROS system as a whole"),
    (("graph", "check"), (), "graph.check", "probe the running system against roc.toml's [check] expectations"),
    (("graph", "snapshot"), (), "graph.snapshot", "print the [check] expectations the running system meets now"),
    (("frame",), (), None, "tf frames and transforms"),
    (("frame", "list"), (), "frame.list", "every tf frame: parent, static or dynamic, rate, age, publishers"),
    (("frame", "echo"), (), "frame.echo", "the transform between two frames (like tf2_echo)"),
    (("frame", "tree"), (), "frame.tree", "the tf tree as text, DOT, SVG, PNG or PDF"),
    (("frame", "monitor"), (), "frame.monitor", "rate and delay of each frame, live (like tf2_monitor)"),
    (("frame", "pub"), (), "frame.pub", "publish a transform, static or at a rate (like static_transform_publisher)"),
    (("frame", "convert"), (), "frame.convert",
     "convert rotations between representations; compose and invert transforms"),
    (("bridge",), (), "bridge.command", "bridge topics from one ROS domain into another (like domain_bridge)"),
    (("bag",), (), None, "rosbag2 bags (MCAP, sqlite3)"),
    (("bag", "info"), (), "bag.info", "what a bag holds (like ros2 bag info)"),
    (("bag", "record"), (), "bag.record", "record topics and services into a bag (like ros2 bag record)"),
    (("bag", "play"), (), "bag.play", "play a bag back (like ros2 bag play)"),
    (("bag", "convert"), (), "bag.convert", "rewrite bags with other storage, splits, compression or topics"),
    (("bag", "reindex"), (), "bag.reindex", "rebuild a bag's metadata.yaml from its files (after a crash)"),
    (("bag", "list"), (), "bag.list", "the storage and compression formats roc supports"),
    (("daemon",), (), None, "the roc daemon (a warm graph participant)"),
    (("daemon", "start"), (), "daemon.start", "start the roc daemon of this discovery environment"),
    (("daemon", "stop"), (), "daemon.stop", "stop the roc daemon of this discovery environment"),
    (("daemon", "status"), (), "daemon.status", "whether the roc daemon of this environment runs"),
    (("idl",), (), None, "interface definitions, converted between protobuf and ROS 2 messages"),
    (("idl", "protobuf"), (), "idl.protobuf", "convert .proto files to .msg files, or .msg files to .proto"),
    (("tui",), (), "tui", "the terminal user interface: the running ROS graph, live, and the workspace's builds"),
    (("completion",), (), "completion", "print a shell completion script: bash, zsh or fish"),
)


# Commands with commands below them.
PARENTS = {path[:-1] for path, _, _, _ in COMMANDS if len(path) > 1}

# Verbs whose options roc.toml and colcon's defaults files can set.
CONFIGURED_VERBS = ("list", "info", "graph", "build", "test", "env", "cache")


# colcon options (from extensions roc does not replace) that roc does not have, and what to do instead.
COLCON_ONLY_OPTIONS = {
    "--mixin": "colcon-mixin; put the arguments in a [profile.NAME] of roc.toml and use --profile NAME",
    "--mixin-files": "colcon-mixin; put the arguments in a [profile.NAME] of roc.toml and use --profile NAME",
    "--log-level": "colcon's logging; use --debug for tracebacks and the log/ directory for build logs",
}


def _terminal_columns() -> int:
    """shutil.get_terminal_size().columns without importing shutil (and with it bz2, lzma and zlib),
    which argparse does for every option added: $COLUMNS, else the terminal's width, else 80."""
    try:
        columns = int(os.environ.get("COLUMNS", "0"))
    except ValueError:
        columns = 0
    if columns <= 0:
        try:
            columns = os.get_terminal_size(sys.__stdout__.fileno()).columns if sys.__stdout__ else 0
        except (ValueError, OSError):
            columns = 0
    return columns or 80


class HelpFormatter(argparse.HelpFormatter):
    def __init__(self, prog: str, indent_increment: int = 2, max_help_position: int = 24,
                 width: int | None = None) -> None:
        super().__init__(prog, indent_increment, max_help_position,
                         width if width is not None else _terminal_columns() - 2)


class Parser(argparse.ArgumentParser):
    """argparse with roc's one-line usage errors (``roc work build: error: ... (see 'roc work build --help')``) and
    no abbreviated options (``--symlink-instal`` is an error, not ``--symlink-install``); ``leaves``
    maps each command path to its parser."""

    leaves: dict[tuple[str, ...], Parser]

    def __init__(self, *args, **kwargs) -> None:
        kwargs["allow_abbrev"] = False
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str):
        """argparse's (and ros2's and colcon's) ``PROG: error: MESSAGE``, one line, with where to look."""
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")

    def _check_value(self, action: argparse.Action, value) -> None:
        """A command or verb that does not exist gets the hint a mistyped option gets (the closest
        name), in place of argparse's list of every choice."""
        if isinstance(action, argparse._SubParsersAction) and value not in action.choices:
            hint = did_you_mean(value, action.choices, count=1) or f"choose from {', '.join(action.choices)}"
            raise argparse.ArgumentError(None, f"unknown command '{value}'; {hint}")
        super()._check_value(action, value)

    def parse_args(self, args=None, namespace=None):
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
    """The argument parser; with ``argv`` naming a command, only the parsers on the way to it are made
    (otherwise every command is listed, for help and errors), which keeps start-up short."""
    wanted = requested_command(argv) if argv is not None else None
    parser = Parser(prog="roc", description="roc: fast, dependable tools for ROS 2 workspaces.")
    parser.add_argument("--version", action="version", version=f"roc {__version__}")
    parser.add_argument("--debug", action="store_true",
                        help="show Python tracebacks for errors (also after the command: roc doctor --debug)")
    parser.add_argument("-C", dest="directory", metavar="DIR", help="run as if roc was started in DIR")
    leaves: dict[tuple[str, ...], Parser] = {}
    groups: dict[tuple[str, ...], argparse._SubParsersAction] = {
        (): parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    }
    leaf_named = wanted is not None and any(path == wanted and module for path, _, module, _ in COMMANDS)
    for path, aliases, module, help_text in COMMANDS:
        # -h only on the way to the named command: argparse builds a help formatter for each -h it adds
        on_the_way = wanted is None or path == wanted[:len(path)]
        if leaf_named and not on_the_way:
            continue  # a command is named: the parsers of the others are never used
        if module is None:
            help_text = f"{help_text}: {', '.join(verbs(path))}"
        sub = groups[path[:-1]].add_parser(path[-1], aliases=list(aliases), help=help_text, description=help_text,
                                           add_help=on_the_way)
        if module is None or path in PARENTS:  # a command may run itself and have commands below it (doctor)
            groups[path] = sub.add_subparsers(dest="_".join(path) + "_command", metavar="COMMAND", parser_class=Parser)
            sub.set_defaults(_group=sub)
        if module is not None:
            if wanted is None or wanted == path:
                command_module(module).add_arguments(sub)
                if "--debug" not in sub._option_string_actions:  # roc launch's -d/--debug is ros2 launch's
                    # roc's own --debug where a user puts it (roc.cli.main reads it), shown once in `roc --help`
                    sub.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS)
                if path[0] == "work" and path[-1] in CONFIGURED_VERBS:
                    sub.add_argument("--profile", metavar="NAME", help="use [profile.NAME] of roc.toml")
            sub.set_defaults(_module=module, _group=None)
            leaves[path] = sub
    parser.leaves = leaves
    return parser


def verbs(group: tuple[str, ...]) -> list[str]:
    """The names of a group's commands, in the table's order."""
    return [path[-1] for path, _, _, _ in COMMANDS if path[:-1] == group]


def command_module(name: str):
    return importlib.import_module(f"roc.commands.{name}")
