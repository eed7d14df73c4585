"""The harness of the ported ros2cli 0.32.2 CLI tests (tests/test_ros2cli_*.py): the fixture graph in
subprocesses (tests/nodes/ros2cli_fixtures.py), each case run against ``roc`` and against the real ``ros2``
(the oracle, as a control) on the same graph, and launch_testing's output matching, so that a ported
case asserts what the upstream case asserts.

Upstream runs each command under launch_testing: its output is stdout and stderr together, and
``expect_output(expected_lines=..., strict=...)`` matches lines so: a string expects a line that
contains it, a compiled pattern a line it matches from the start; ``strict`` expects the lines in a
row from the first line on (more lines may follow), otherwise in order anywhere. ``expect_lines`` does
the same here. Each tool gets a phase of its own on the graph: the other tool's daemon is stopped
(each CLI's daemon is a node the other would list), its own started, as upstream restarts the ros2
daemon before each test file.
"""

from __future__ import annotations

import functools
import re
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from helpers.build import BIN, stop_process
from helpers.graph import ORACLE_VENV, install_oracle, read_line, roc, ros2, stop_daemon

FIXTURES = Path(__file__).resolve().parents[1] / "nodes" / "ros2cli_fixtures.py"
TOOLS = ("ros2", "roc")
Expected = str | re.Pattern


@pytest.fixture(scope="session")
def oracle() -> None:
    """The real ros2 CLI (the control); the ported cases are skipped without it."""
    reason = install_oracle()
    if reason:
        pytest.skip(f"the ros2 CLI oracle is not available: {reason}")


def expect_lines(output: str, expected: Iterable[Expected], strict: bool = False) -> bool:
    """launch_testing's expect_output(text=output, expected_lines=expected, strict=strict)."""
    lines = output.splitlines()
    position = 0
    for wanted in expected:
        found = next((i for i in range(position, len(lines)) if _matches(wanted, lines[i])), None)
        if found is None or (strict and found != position):
            return False
        position = found + 1
    return True


def _matches(wanted: Expected, line: str) -> bool:
    return wanted in line if isinstance(wanted, str) else wanted.match(line) is not None


def output_filter(prefixes: Iterable[str] = (), patterns: Iterable[str] = ()) -> Callable[[str], str]:
    """launch_testing's basic_output_filter: drop the lines that start with a prefix or match a pattern."""
    compiled = [re.compile(p) for p in patterns]
    prefixes = tuple(prefixes)

    def keep(line: str) -> bool:
        return not (prefixes and line.startswith(prefixes)) and not any(p.match(line) for p in compiled)
    return lambda text: "".join(line for line in text.splitlines(keepends=True) if keep(line))


def retry(times: int):
    """launch_testing.markers.retry_on_failure: the case passes when one of ``times`` attempts does (a
    graph may still be settling); the last attempt's failure is reported."""
    def decorate(case):
        @functools.wraps(case)
        def attempts(*args, **kwargs):
            for attempt in range(times):
                try:
                    return case(*args, **kwargs)
                except AssertionError:
                    if attempt == times - 1:
                        raise
                    time.sleep(1)
        return attempts
    return decorate


@dataclass
class Fixture:
    """A fixture process: its stdout and stderr as one stream, read through helpers.graph.read_line."""
    process: subprocess.Popen
    lines: list[str] = field(default_factory=list)

    def read_until(self, expected: list[Expected], since: int, timeout: float) -> bool:
        """Whether the output after line ``since`` holds ``expected`` (in order) within ``timeout`` s."""
        deadline = time.monotonic() + timeout
        while not expect_lines("".join(self.lines[since:]), expected):
            line = read_line(self.process, deadline - time.monotonic())
            if not line:
                return False
            self.lines.append(line)
        return True

    def mark(self) -> int:
        """The position from which read_until looks: what this process printed up to now is read first."""
        while (line := read_line(self.process, 0.01)):
            self.lines.append(line)
        return len(self.lines)


class FixtureGraph:
    """Upstream's fixture nodes on the graph of ``env`` (graph_env's, unbuffered as upstream runs every
    process); leaving it stops them and both CLIs' daemons."""

    def __init__(self, env: dict[str, str]) -> None:
        self.env = {**env, "PYTHONUNBUFFERED": "1"}
        self.fixtures: dict[str, Fixture] = {}

    def start(self, fixture: str, *arguments: str, name: str | None = None, namespace: str | None = None,
              remap: Iterable[tuple[str, str]] = (), key: str | None = None) -> Fixture:
        """A fixture node (kept as ``key``, default its name or the fixture's), as launch_ros's
        Node(name=..., namespace=..., remappings=...) starts it (a relative namespace is taken from
        the root); returns once it is created."""
        namespace = namespace and "/" + namespace.lstrip("/")
        ros_args = [*(["-r", f"__node:={name}"] if name else []), *(["-r", f"__ns:={namespace}"] if namespace else []),
                    *(a for pair in remap for a in ("-r", f"{pair[0]}:={pair[1]}"))]
        command = [sys.executable, str(FIXTURES), fixture, *arguments, *(["--ros-args", *ros_args] if ros_args else [])]
        process = subprocess.Popen(command, env=self.env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        started = self.fixtures[key or name or fixture] = Fixture(process)
        assert started.read_until(["ready"], 0, 30), f"{fixture} did not start: {started.lines}"
        return started

    def stop(self, key: str) -> None:
        stop_process(self.fixtures.pop(key).process)

    def __enter__(self) -> FixtureGraph:
        return self

    def __exit__(self, *_exc) -> None:
        stop_daemon(self.env)
        for key in list(self.fixtures):
            self.stop(key)


@dataclass
class Result:
    exit_code: int | None
    output: str


class Stream:
    """A command left running (echo, hz, pub): launch_testing's launch_process and wait_for_output."""

    def __init__(self, command: list[str], env: dict[str, str], output: Callable[[str], str]):
        self.process = subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                        text=True)
        self.filter = output
        self.text = ""
        self.exit_code: int | None = None

    @property
    def output(self) -> str:
        return self.filter(self.text)

    def wait_for_output(self, expected: list[Expected], strict: bool = False, timeout: float = 10.0) -> bool:
        deadline = time.monotonic() + timeout
        while not expect_lines(self.output, expected, strict):
            line = read_line(self.process, deadline - time.monotonic())
            if not line:
                return False
            self.text += line
        return True

    def wait_for_shutdown(self, timeout: float = 10.0) -> bool:
        """Whether it ended by itself within ``timeout`` seconds (its output read to the end)."""
        try:
            self.exit_code = self.process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            return False
        while (line := read_line(self.process, 5)):
            self.text += line
        return True

    def stop(self) -> bool:
        """What leaving launch_process does: SIGINT, then whether it ended within 10 s (killed if not)."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        ended = self.wait_for_shutdown(10)
        if not ended:
            stop_process(self.process)
        return ended

    def __enter__(self) -> Stream:
        return self

    def __exit__(self, *_exc) -> None:
        self.stop()


class Cli:
    """One tool (``ros2`` or ``roc``) with one verb group (``topic``, ``node``, ...) on the graph of ``env``;
    ``output`` is the upstream test's output filter."""

    def __init__(self, tool: str, env: dict[str, str], output: Callable[[str], str] = lambda text: text):
        self.tool = tool
        self.env = env
        self.filter = output
        self.executable = str(ORACLE_VENV / "bin" / "ros2") if tool == "ros2" else str(BIN / "roc")

    def run(self, *arguments: str, timeout: float = 10.0) -> Result:
        """Run to the end (launch_testing's wait_for_shutdown(timeout)): exit code None if it ran longer."""
        with self.stream(*arguments) as command:
            command.wait_for_shutdown(timeout)
        return Result(command.exit_code, command.output)

    def stream(self, *arguments: str) -> Stream:
        return Stream([self.executable, *arguments], self.env, self.filter)

    def shell(self, text: str, timeout: float = 10.0) -> Result:
        """A shell command line in which ``CLI`` stands for the tool."""
        done = subprocess.run(text.replace("CLI", self.executable), shell=True, env=self.env, timeout=timeout,
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        return Result(done.returncode, self.filter(done.stdout))


def tool_phase(tool: str, env: dict[str, str], ready: Callable[[Cli], bool],
               output: Callable[[str], str] = lambda text: text, timeout: float = 30.0) -> Cli:
    """Start ``tool``'s phase: the other tool's daemon stopped, this one's started, and ``ready`` true
    of what it sees (the fixture graph discovered) within ``timeout`` seconds; the tool, its output
    filtered by ``output``."""
    if tool == "ros2":
        stop_daemon(env)  # roc's (and ros2's: restarted, as upstream does)
        ros2("daemon", "start", env=env)
    else:
        ros2("daemon", "stop", env=env)
        roc("daemon", "start", env=env)
    cli = Cli(tool, env)
    deadline = time.monotonic() + timeout
    while not ready(cli):
        assert time.monotonic() < deadline, f"{tool} did not discover the fixture graph within {timeout:g} s"
        time.sleep(0.5)
    return Cli(tool, env, output)
