"""roc run: run an executable of an installed package (like ros2 run: ``<prefix>/lib/<pkg>/<exe>`` found
through the ament index), its arguments passed through untouched.

roc replaces itself with the executable (exec), so the process the shell started is the node: its exit
code and the signal that ended it reach the shell unchanged, Ctrl+C and SIGTERM reach the node exactly
once, and no wrapper process can be left behind. ros2 run keeps a Python parent that a SIGTERM kills
while the node runs on."""

from __future__ import annotations

import argparse

from roc.errors import RocError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--prefix", metavar="CMD",
                        help="a command to put before the executable, e.g. --prefix 'gdb -ex run --args'")
    parser.add_argument("package_name", metavar="PKG", help="the package")
    parser.add_argument("executable_name", metavar="EXECUTABLE", help="the executable of the package")
    parser.add_argument("argv", nargs=argparse.REMAINDER, metavar="ARGS",
                        help="arguments for the executable, passed as they are (e.g. --ros-args -p rate:=5.0)")


def run(args: argparse.Namespace) -> int:
    import os
    import shlex
    import sys

    from roc.ament_index import find_executable
    from roc.middleware import process_environment

    path = str(find_executable(args.package_name, args.executable_name))
    try:
        prefix = shlex.split(args.prefix) if args.prefix is not None else []
    except ValueError as error:
        raise RocError(f"--prefix {args.prefix!r}: {error}") from None
    command = [*prefix, path, *args.argv]
    env = process_environment(os.environ)  # the middleware RMW_IMPLEMENTATION names, on the ROS 2 wheels
    sys.stdout.flush()
    sys.stderr.flush()
    try:
        os.execvpe(command[0], command, env)
    except OSError as error:
        raise RocError(f"cannot run '{command[0]}': {error.strerror}") from None
    return 1  # not reached: exec replaced this process
