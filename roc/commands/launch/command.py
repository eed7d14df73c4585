"""roc launch: start a system and keep it running until Ctrl+C, as ros2 launch does, with no process left
behind however roc ends.

    roc launch PKG FILE [NAME:=VALUE ...]   a launch file of an installed package (Python, XML, YAML)
    roc launch PATH [NAME:=VALUE ...]       a launch file by path
    roc launch NAME                         a system declared in roc.toml's [launch.NAME]

Launch files run in the real launch library (roc/launch/runner.py); roc.toml systems in roc's engine.
The manual page is docs/commands/launch.md.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from roc.cli.options import add_discovery_arguments, add_format_argument
from roc.errors import UsageError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("target", metavar="PKG|PATH|NAME",
                        help="a package holding the launch file, a launch file's path, or a [launch.NAME] of roc.toml")
    parser.add_argument("rest", nargs="*", metavar="FILE|NAME:=VALUE",
                        help="the launch file's name (after PKG), then launch arguments NAME:=VALUE (the last of "
                             "duplicates wins)")
    ros2 = parser.add_argument_group("as ros2 launch")
    ros2.add_argument("-n", "--noninteractive", action="store_true",
                      help="accepted for ros2 launch's sake: roc always passes signals on to the processes itself")
    ros2.add_argument("-d", "--debug", dest="launch_debug", action="store_true",
                      help="put the launch library in debug mode (more output)")
    shown = ros2.add_mutually_exclusive_group()
    shown.add_argument("-p", "--print", "--print-description", dest="print_description", action="store_true",
                       help="print the launch description without launching it")
    shown.add_argument("-s", "--show-args", "--show-arguments", dest="show_args", action="store_true",
                       help="print the arguments the launch file takes")
    ros2.add_argument("-a", "--show-all-subprocesses-output", action="store_true",
                      help="show every process's output, whatever its output setting "
                           "(OVERRIDE_LAUNCH_PROCESS_OUTPUT=both)")
    ros2.add_argument("--launch-prefix", metavar="CMD",
                      help="a command to put before every executable, e.g. --launch-prefix 'xterm -e gdb --args'")
    ros2.add_argument("--launch-prefix-filter", metavar="REGEX",
                      help="with --launch-prefix: only for executables whose name matches REGEX")
    roc = parser.add_argument_group("roc's own")
    roc.add_argument("--check", type=Path, metavar="FILE",
                     help="once everything started, probe the [check] expectations of FILE (as roc graph check) "
                          "and report")
    roc.add_argument("--exit-after-check", action="store_true",
                     help="with --check: stop the system after the report; exit 0 only when every expectation held "
                          "(a launch smoke test for CI)")
    roc.add_argument("--explain", action="store_true",
                     help="print what a start would run and exit, nothing started: each process's command line, "
                          "working directory, added environment, parameters, remappings and host (and for a "
                          "roc.toml system what it waits for, in start-up order)")
    roc.add_argument("--no-warm-start", dest="warm_start", action="store_false",
                     help="start every process with its own fresh interpreter: no Python node is forked from roc's "
                          "warm interpreter (see the manual's 'Warm start')")
    roc.add_argument("--plain", action="store_true",
                     help="plain lines on a terminal too, without the live status view")
    roc.add_argument("--log-base", metavar="DIR",
                     help="where the run's logs go: DIR/launch_<time>/<process>.log (default: log at the workspace "
                          "root; outside a workspace, where ros2 launch writes its logs: $ROS_LOG_DIR, else "
                          "$ROS_HOME/log, else ~/.ros/log; /dev/null for none)")
    add_format_argument(parser)
    add_discovery_arguments(parser)


def _target(args: argparse.Namespace) -> tuple[str, Path | None, list[str]]:
    """("file", path, argument words) or ("system", None, [])."""
    if os.path.isfile(args.target):
        return "file", Path(args.target), args.rest
    if args.rest and ":=" not in args.rest[0]:
        from roc.launch.files import find_in_package

        return "file", find_in_package(args.target, args.rest[0]), args.rest[1:]
    return "system", None, args.rest


def _run_options(args: argparse.Namespace, title: str):
    from roc.launch.check import CheckOptions
    from roc.launch.running import RunOptions
    from roc.workspace.root import find_workspace_root

    if args.exit_after_check and args.check is None:
        raise UsageError("--exit-after-check goes with --check FILE")
    check = None
    if args.check is not None:
        check = CheckOptions(args.check, args.exit_after_check, not args.no_daemon, args.spin_time)
    root = find_workspace_root(Path.cwd())
    outside = root is None and args.log_base is None  # not into ./log of wherever the user stands: ros2's place
    if outside:
        from roc.launch.logs import ros_log_directory

        log_base: Path | None = ros_log_directory()
    else:
        log_base = None if args.log_base == os.devnull else (root or Path.cwd()) / (args.log_base or "log")
    view = not args.plain and sys.stdout.isatty() and os.environ.get("TERM") != "dumb"
    return RunOptions(title, log_base, view, check, args.warm_start, ros_log_layout=outside)


def run(args: argparse.Namespace) -> int:
    if args.launch_prefix_filter is not None and args.launch_prefix is None:
        raise UsageError("--launch-prefix-filter goes with --launch-prefix")
    if args.format != "text" and not (args.explain or args.show_args):
        raise UsageError("--format goes with --explain or --show-args")
    from roc.distribution import refuse_mix

    refuse_mix()  # the runner, the warm start's fork server and the nodes would load both distributions
    kind, path, words = _target(args)
    if kind == "system":
        return _run_system(args, words)
    assert path is not None
    from roc.launch.files import parse_arguments, require_launch_library
    from roc.launch.launch_file import LaunchFile, inspect, launch

    arguments = parse_arguments(words)
    require_launch_library()
    launch_file = LaunchFile(path, arguments, args.launch_debug, args.show_all_subprocesses_output,
                             args.launch_prefix, args.launch_prefix_filter)
    if args.explain or args.show_args:
        return _evaluate(args, launch_file)
    if args.print_description:
        return inspect(launch_file)
    return launch(launch_file, _run_options(args, f"roc launch {path.name}"))


def _evaluate(args: argparse.Namespace, launch_file) -> int:
    """--explain or --show-args of a launch file."""
    from roc.launch.launch_file import argument_text, evaluate
    from roc.render import print_json, print_lines, print_text

    env = dict(os.environ)
    if launch_file.show_all_output:
        env["OVERRIDE_LAUNCH_PROCESS_OUTPUT"] = "both"
    if args.show_args:
        data = evaluate(launch_file, "show-args", env)
        print_json(data) if args.format == "json" else print_text(argument_text(data))
        return 0
    from roc.launch.explain import environment_changes, file_lines, ros_arguments

    entries = []
    for process in evaluate(launch_file, "explain", env)["processes"]:
        changed, unset = environment_changes(env, process["env"]) if process["env"] is not None else ({}, [])
        entries.append({"name": process["name"], "host": None, "setup": [], "command": process["command"],
                        "cwd": process["cwd"], "env": changed, "unset": unset, **ros_arguments(process["command"]),
                        "written_parameters": process["written_parameters"], "respawn": process["respawn"],
                        "loads": process["loads"]})
    if args.format == "json":
        print_json(entries)
    else:
        print_lines(file_lines(str(launch_file.path), entries, os.getcwd()))
    return 0


def _run_system(args: argparse.Namespace, words: list[str]) -> int:
    from roc.launch.system import find_roc_toml, load_system, system_names

    roc_toml = find_roc_toml(Path.cwd())
    names = system_names(roc_toml) if roc_toml else []
    if args.target not in names:
        where = f"no [launch.{args.target}] in {roc_toml}" if roc_toml else "no roc.toml here"
        systems = f" (systems: {', '.join(names)})" if names else ""
        raise UsageError(f"'{args.target}' is not a launch file, and {where}{systems}; to launch a package's "
                         "file: roc launch PKG FILE")
    assert roc_toml is not None
    if words:
        raise UsageError(f"{' '.join(words)}: the systems of roc.toml take no launch arguments")
    if args.print_description or args.show_args or args.launch_prefix or args.show_all_subprocesses_output:
        raise UsageError("--print, --show-args, --launch-prefix and -a are for launch files")
    system = load_system(roc_toml, args.target)
    options = None if args.explain else _run_options(args, f"roc launch {args.target}")
    found: dict[str, dict] = {}
    if system.remote():  # every host reachable, with every executable, before anything starts
        from roc.launch.remote import check_hosts

        found = check_hosts(system, dict(os.environ))
    if options is None:
        return _explain_system(args, system, found)
    from roc.launch.system_run import launch_system

    return launch_system(system, options, not args.no_daemon, args.spin_time)


def _explain_system(args: argparse.Namespace, system, found: dict[str, dict]) -> int:
    from roc.launch.explain import system_entries, system_lines
    from roc.launch.plan import LazySession, plan
    from roc.launch.remote import remote_environment
    from roc.launch.supervisor import command
    from roc.render import print_json, print_lines

    def command_there(spec) -> list[str]:
        if not spec.host:
            return command(spec)
        return [found[spec.host]["found"][f"{spec.package}/{spec.executable}"], *spec.arguments,
                *spec.ros_arguments()]

    def cwd(spec) -> str:
        return found[spec.host]["cwd"] if spec.host else os.getcwd()

    tasks = plan(system, lambda _spec: None, LazySession(), lambda: False)
    entries = system_entries(system, tasks, command_there, remote_environment, cwd)
    print_json(entries) if args.format == "json" else print_lines(system_lines(system, entries))
    return 0
