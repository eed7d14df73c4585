"""``roc launch PKG FILE`` / ``roc launch PATH``: a launch file run by the real launch library in a runner
process (roc/launch/runner.py), watched from here.

The runner prints what ros2 launch prints; here roc keeps the process table (from the runner's events),
the per-process logs, the live view or the plain lines, the ``--check`` report, and the guarantee that no
process outlives the run (roc/launch/guard.py).
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from roc.launch.running import Running, RunOptions
from roc.launch.status import SignalControl, serve
from roc.launch.warm_start import NOT_USED_SECONDS, start_server, wait_for_server

SETTLE_SECONDS = 1.0  # --check starts once no process has started for this long
CAUGHT = "Caught exception in launch (see debug for traceback)"  # the launch library's error line


@dataclass
class LaunchFile:
    path: Path
    arguments: list[tuple[str, str]] = field(default_factory=list)
    debug: bool = False
    show_all_output: bool = False
    launch_prefix: str | None = None
    launch_prefix_filter: str | None = None


def _runner_command(spec: dict) -> list[str]:
    return [sys.executable, "-m", "roc.launch.runner", json.dumps(spec)]


def inspect(launch_file: LaunchFile) -> int:
    """``--print``: the runner prints, nothing is started."""
    spec = {"mode": "print", "path": str(launch_file.path), "arguments": [], "debug": launch_file.debug}
    return subprocess.run(_runner_command(spec), stdin=subprocess.DEVNULL).returncode


def evaluate(launch_file: LaunchFile, mode: str, env: dict[str, str]) -> dict:
    """``--explain`` or ``--show-args``: what the runner found (roc/launch/introspect.py), nothing started;
    a RocError with the runner's output when the launch file cannot be evaluated."""
    import tempfile

    from roc.errors import RocError

    with tempfile.TemporaryFile("w+") as result:
        spec = {"mode": mode, "path": str(launch_file.path), "arguments": _arguments(launch_file),
                "debug": launch_file.debug, "result_fd": result.fileno()}
        done = subprocess.run(_runner_command(spec), stdin=subprocess.DEVNULL, capture_output=True, text=True,
                              pass_fds=(result.fileno(),), env=env)
        result.seek(0)
        text = result.read()
    if done.returncode != 0 or not text:
        output = (done.stdout + done.stderr).strip()
        if CAUGHT in output and not launch_file.debug:  # the library's error, made one line
            from roc.launch.files import one_line

            raise RocError(f"{launch_file.path}: {one_line(output.split(CAUGHT, 1)[1].removeprefix(': '))}")
        if launch_file.debug or "\n" in output:
            print(output, file=sys.stderr)
            raise RocError(f"{launch_file.path}: the launch failed while evaluated (its output is above)")
        raise RocError(output.removeprefix("roc: error: ") or f"{launch_file.path}: the launch runner failed")
    return json.loads(text)


def _arguments(launch_file: LaunchFile) -> list[tuple[str, str]]:
    """The file's arguments, with --launch-prefix and --launch-prefix-filter as ros2 launch passes them."""
    arguments = dict(launch_file.arguments)
    if launch_file.launch_prefix:
        arguments["launch-prefix"] = launch_file.launch_prefix
    if launch_file.launch_prefix_filter:
        arguments["launch-prefix-filter"] = launch_file.launch_prefix_filter
    return list(arguments.items())


def launch(launch_file: LaunchFile, options: RunOptions) -> int:
    running = Running(options, echo=False)
    library_logs = running.log_directory / "launch" if running.log_directory else None
    if library_logs is not None:
        library_logs.mkdir()
    events_read, events_write = os.pipe()
    spec = {"mode": "launch", "path": str(launch_file.path), "arguments": _arguments(launch_file),
            "debug": launch_file.debug, "events_fd": events_write,
            "log_dir": str(library_logs) if library_logs else None}
    extra = {"OVERRIDE_LAUNCH_PROCESS_OUTPUT": "both"} if launch_file.show_all_output else {}
    env = running.environment(extra)
    runners: list[subprocess.Popen] = []

    def stop() -> None:
        for runner in runners:  # the library stops its processes (SIGINT, then SIGTERM, then SIGKILL)
            try:
                runner.send_signal(signal.SIGINT)
            except ProcessLookupError:
                pass

    running.catch_signals(stop)  # first: no process may inherit an ignored SIGINT (a background job's)
    server, channel = _fork_server(env) if options.warm_start else (None, None)
    passed: tuple[int, ...] = (events_write,)
    if server is not None and channel is not None:
        running.guard.record(server.pid)
        spec["warm_start"] = {"fd": channel.fileno(), "interpreter": sys.executable}
        passed += (channel.fileno(),)
    try:
        # a process group of its own in roc's session: the terminal's signals reach roc alone, and the
        # system shares the terminal session's CPU share (its autogroup), as under ros2 launch
        runner = subprocess.Popen(_runner_command(spec), stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                  stderr=subprocess.STDOUT, pass_fds=passed,
                                  process_group=0, env=env)
    except BaseException:
        if server is not None:
            server.kill()
            server.wait()
        running.close()
        raise
    finally:
        os.close(events_write)
        if channel is not None:
            channel.close()  # the runner's now: the server ends when the runner does
    runners.append(runner)
    running.guard.record(runner.pid)
    running.guard.group(runner.pid)
    if running.stopping.is_set():
        stop()
    started = threading.Event()  # the first process started
    settled = threading.Event()  # and no other started for SETTLE_SECONDS
    threads = [threading.Thread(target=_read_events, args=(events_read, running, started), daemon=True)]
    if runner.stdout is not None:
        threads.append(threading.Thread(target=_relay, args=(runner.stdout, running), daemon=True))
    for thread in threads:
        thread.start()

    running.start_check(settled, stop)
    status = serve(running, SignalControl(running.monitor))  # roc tui's view of the run
    threading.Thread(target=_settle, args=(running, started, settled, runner), daemon=True).start()
    try:
        code = runner.wait()
        if server is not None:
            wait_for_server(server)
    finally:
        if status is not None:
            status.close()
        settled.set()
        running.stopping.set()
        for thread in threads:
            thread.join(timeout=5.0)
        running.close()
    return running.exit_code(code)


def _fork_server(env: dict[str, str]) -> tuple[subprocess.Popen | None, socket.socket | None]:
    """A fork server for the Python processes of the launch file (roc/launch/warm_start.py), started now so
    that its preloads overlap the runner's start. The guess: the nodes run on roc's interpreter, which has
    the launch library; when none does, the server ends after a while, unused."""
    try:
        return start_server(sys.executable, env, NOT_USED_SECONDS)
    except OSError:
        return None, None


def _read_events(fd: int, running: Running, started: threading.Event) -> None:
    """The runner's JSON lines: each process's start, output and exit."""
    monitor = running.monitor
    with os.fdopen(fd, "r", errors="replace") as stream:
        for line in stream:
            try:
                event = json.loads(line)
            except ValueError:
                continue
            if event["event"] == "start":
                running.guard.record(event["pid"])
                monitor.started(event["name"], event["pid"], event["cmd"], warm=event.get("warm", False))
                started.set()
            elif event["event"] == "output":
                monitor.output_text(event["name"], event["text"])
            elif event["event"] == "exit":
                monitor.exited(event["name"], event["pid"], event["code"])


def _settle(running: Running, started: threading.Event, settled: threading.Event, runner: subprocess.Popen) -> None:
    """Sets ``settled`` once processes started and none started for SETTLE_SECONDS (or the run ended)."""
    started.wait()
    while runner.poll() is None:
        quiet = time.monotonic() - running.monitor.last_start
        if quiet >= SETTLE_SECONDS:
            break
        settled.wait(SETTLE_SECONDS - quiet)
    settled.set()


def _relay(stream, running: Running) -> None:
    """The runner's own output (ros2 launch's lines), printed as it comes (above the live view)."""
    while True:
        data = os.read(stream.fileno(), 65536)
        if not data:
            break
        running.output.write(data.decode(errors="replace"))


def argument_text(data: dict) -> str:
    """``--show-args`` as ros2 launch prints it, plus, for an argument of an included file, the file that
    declares it and the includes that lead there, and the value an include sets it to; then the includes
    that cannot be followed without running the launch."""
    text = "Arguments (pass arguments as '<name>:=<value>'):\n"
    conditional = False
    for argument in data["arguments"]:
        starred = "*" if argument["conditional"] else ""
        conditional = conditional or argument["conditional"]
        text += f"\n    '{argument['name']}':{starred}\n        {argument['description']}\n"
        if argument["default"] is not None:
            text += f"        (default: {argument['default']})\n"
        if argument["included_by"]:
            chain = " < ".join(os.path.basename(file) for file in reversed(argument["included_by"]))
            text += f"        (declared in {argument['file']}, included by {chain})\n"
        if argument["set_by"]:
            value = argument["set_by"]["value"]
            text += (f"        (set to {value!r} by the include in {os.path.basename(argument['set_by']['file'])}: "
                     "a value given on the command line does not reach it)\n" if value is not None else
                     f"        (set by the include in {os.path.basename(argument['set_by']['file'])})\n")
    if not data["arguments"]:
        text += "\n  No arguments.\n"
    elif conditional:
        text += "\n* argument(s) which are only used if specific conditions occur\n"
    if data["unknown"]:
        text += "\nNot known without running the launch:\n" + "".join(f"    {line}\n" for line in data["unknown"])
    return text
