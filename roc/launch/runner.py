"""The launch runner: runs one launch file with the real ROS 2 launch library, in a process of its own.

``roc launch FILE`` starts ``python -m roc.launch.runner SPEC`` (SPEC: JSON, see ``RunnerSpec`` in
roc/launch/launch_file.py) and stays outside it: this is the one module of roc that imports ``launch`` (and,
through the launch file, ``launch_ros`` and rclpy). It prints what ros2 launch prints (the library's own
screen output) and reports each process's start, output and exit to roc as JSON lines on the file
descriptor ``events_fd``. With ``warm_start`` (a fork server's socket, from roc), its event loop forks the
Python processes the server serves (roc/launch/warm_loop.py).

It runs in a process group of its own (roc starts it so), so the terminal's Ctrl+C reaches roc alone: roc
sends it one SIGINT, and the library, told it is non-interactive, passes SIGINT on to every process and
escalates to SIGTERM and SIGKILL as ros2 launch does. Its output goes through roc, so it never writes to
the terminal from a background process group.
"""

from __future__ import annotations

import json
import os
import sys
from collections.abc import Callable
from typing import Any


def _reporter(fd: int | None) -> Callable[[dict[str, Any]], None]:
    """Writes one JSON line per event to ``fd`` (nothing when None); a reader that went away is ignored."""
    if fd is None:
        return lambda _record: None
    os.set_inheritable(fd, False)  # the launched processes must not hold roc's end open
    stream = os.fdopen(fd, "w", buffering=1)

    def report(record: dict[str, Any]) -> None:
        try:
            stream.write(json.dumps(record) + "\n")
        except (BrokenPipeError, OSError):
            pass

    return report


def _event_handlers(report: Callable[[dict[str, Any]], None], forked: set[int]) -> list:
    from launch.actions import RegisterEventHandler
    from launch.event_handlers import OnProcessExit, OnProcessIO, OnProcessStart

    def output(stream: str) -> Callable:
        def on_output(event) -> None:
            report({"event": "output", "name": event.process_name, "pid": event.pid, "stream": stream,
                    "text": event.text.decode(errors="replace")})
        return on_output

    return [
        RegisterEventHandler(OnProcessStart(on_start=lambda event, _context: report(
            {"event": "start", "name": event.process_name, "pid": event.pid, "cmd": list(event.cmd),
             "warm": event.pid in forked}))),
        RegisterEventHandler(OnProcessIO(on_stdout=output("stdout"), on_stderr=output("stderr"))),
        RegisterEventHandler(OnProcessExit(on_exit=lambda event, _context: report(
            {"event": "exit", "name": event.process_name, "pid": event.pid, "code": event.returncode}))),
    ]


def launch(spec: dict[str, Any]) -> int:
    """Run the launch file as ros2 launch does (its arguments as ``name:=value``); the library's exit code."""
    warm_loop = None
    if spec.get("warm_start"):  # before the library makes its event loop
        from roc.launch.warm_loop import install

        warm_loop = install(spec["warm_start"]["fd"], spec["warm_start"]["interpreter"])
    import launch
    from launch.launch_description_sources import AnyLaunchDescriptionSource

    if spec.get("log_dir"):
        launch.logging.launch_config.log_dir = spec["log_dir"]
    arguments = [f"{name}:={value}" for name, value in spec["arguments"]]
    service = launch.LaunchService(argv=arguments, noninteractive=True, debug=spec.get("debug", False))
    include = launch.actions.IncludeLaunchDescription(AnyLaunchDescriptionSource(spec["path"]),
                                                      launch_arguments=list(spec["arguments"]))
    report = _reporter(spec.get("events_fd"))
    handlers = _event_handlers(report, warm_loop.forked if warm_loop else set())
    service.include_launch_description(launch.LaunchDescription([*handlers, include]))
    try:
        return service.run()
    finally:
        if warm_loop is not None:
            warm_loop.warm.close()


def describe(spec: dict[str, Any]) -> int:
    """``--print``: the launch description as the library's introspector writes it."""
    import launch
    from launch.launch_description_sources import get_launch_description_from_any_launch_file

    description = get_launch_description_from_any_launch_file(spec["path"])
    print(launch.LaunchIntrospector().format_launch_description(description))
    return 0


def _result(spec: dict[str, Any], data: dict[str, Any]) -> None:
    """``--explain`` and ``--show-args`` answer roc as JSON on the file descriptor ``result_fd``."""
    with os.fdopen(spec["result_fd"], "w") as stream:
        json.dump(data, stream)


def explain(spec: dict[str, Any]) -> int:
    """``--explain``: what the launch would start, nothing started (roc/launch/introspect.py)."""
    from roc.launch.introspect import explain as evaluate

    code, data = evaluate(spec["path"], [tuple(pair) for pair in spec["arguments"]], spec.get("debug", False))
    _result(spec, data)
    return code


def show_arguments(spec: dict[str, Any]) -> int:
    """``--show-args``: the arguments of the file and of the files it includes (roc/launch/introspect.py)."""
    from roc.launch.introspect import arguments

    _result(spec, arguments(spec["path"], [tuple(pair) for pair in spec["arguments"]]))
    return 0


MODES = {"launch": launch, "print": describe, "show-args": show_arguments, "explain": explain}


def main(argv: list[str]) -> int:
    import signal

    signal.signal(signal.SIGINT, signal.default_int_handler)  # even if started with SIGINT ignored
    spec = json.loads(argv[0])
    try:
        return MODES[spec["mode"]](spec)
    except Exception as error:  # noqa: BLE001 - a launch file that cannot be loaded: one line, as roc reports errors
        if spec.get("debug"):
            raise
        print(f"roc: error: {spec['path']}: {type(error).__name__}: {error}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
