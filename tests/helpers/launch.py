"""Helpers for the tests of roc pkg, roc run and roc launch: the fixture package roc_launch_demo built by roc
(workspaces/fixtures/launch), its environment, a running roc or ros2 launch, and what a launched system looks
like in the graph (nodes, their parameters and endpoints), read with roc's graph verbs."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from helpers.build import BIN, FIXTURES, stop_process
from helpers.graph import ORACLE_VENV, graph_env, roc
from helpers.rmw import middleware_prefixes, suite_environment

SITE = f"lib/python{sys.version_info.major}.{sys.version_info.minor}/site-packages"
DEMO_NODES = {"/robot1/talker", "/robot1/listener", "/map_server"}


def skip_without_launch_library() -> None:
    """Launch files need the ROS 2 launch library in roc's venv (scripts/setup.sh installs it from
    ../shared/oracles when that exists)."""
    import importlib.util

    import pytest

    if importlib.util.find_spec("launch_ros") is None:
        pytest.skip("the ROS 2 launch library is not installed in this venv (see scripts/setup.sh)")


def build_demo(directory: Path) -> Path:
    """roc_launch_demo built by roc in a copy of the fixture workspace; its install prefix."""
    import shutil

    workspace = directory / "ws"
    shutil.copytree(FIXTURES / "launch", workspace)
    env = {**os.environ, "AMENT_PREFIX_PATH": sys.prefix}
    built = subprocess.run([str(BIN / "roc"), "work", "build"], cwd=workspace, env=env, capture_output=True,
                           text=True, timeout=300)
    assert built.returncode == 0, built.stdout + built.stderr
    return workspace / "install" / "roc_launch_demo"


def demo_env(slot: int, runtime: Path, prefix: Path, **extra: str) -> dict[str, str]:
    """The test's ROS domain with roc_launch_demo sourced over the wheels (and the oracle's venv)."""
    env = graph_env(slot, runtime, **extra)
    env["AMENT_PREFIX_PATH"] = os.pathsep.join([str(prefix), *middleware_prefixes(), str(ORACLE_VENV), sys.prefix])
    env.update(suite_environment())
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(prefix / SITE), env.get("PYTHONPATH")]))
    env.pop("ROC_LAUNCH_ID", None)
    return env


class Launcher:
    """A launcher (roc or ros2) running in the background, its output (stdout and stderr) in a file."""

    def __init__(self, command: list[str], env: dict[str, str], log: Path, cwd: Path | None = None):
        self.log = log
        with open(log, "w") as output:
            self.process = subprocess.Popen(command, env=env, cwd=cwd, stdin=subprocess.DEVNULL, stdout=output,
                                            stderr=subprocess.STDOUT)

    @property
    def pid(self) -> int:
        return self.process.pid

    def output(self) -> str:
        return self.log.read_text(errors="replace")

    def wait_for_output(self, text: str, timeout: float = 30.0) -> str:
        return wait_until(lambda: text in self.output() and self.output(), timeout, f"{text!r} in {self.log}")

    def stop(self, signum: int = signal.SIGINT, timeout: float = 30.0) -> int:
        """Signal it and wait for its end; its exit code."""
        if self.process.poll() is None:
            self.process.send_signal(signum)
        try:
            return self.process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            stop_process(self.process)
            raise AssertionError(f"{self.process.args[:3]} did not stop within {timeout:g} s after "
                                 f"{signum!r}") from None


def roc_launch(*args: str, env: dict[str, str], log: Path, cwd: Path | None = None) -> Launcher:
    """roc launch in ``cwd`` (default: the log's directory), its logs in log/ beside ``log``."""
    return Launcher([str(BIN / "roc"), "launch", "--log-base", str(log.parent / "log"), *args], env, log,
                    cwd or log.parent)


def ros2_launch(*args: str, env: dict[str, str], log: Path) -> Launcher:
    return Launcher([str(ORACLE_VENV / "bin" / "ros2"), "launch", *args], env, log)


def wait_until(condition, timeout: float, what: str, period: float = 0.3):
    """``condition()``'s first true value within ``timeout`` seconds, else the test fails saying ``what``."""
    deadline = time.monotonic() + timeout
    while True:
        value = condition()
        if value:
            return value
        assert time.monotonic() < deadline, f"timed out after {timeout:g} s waiting for {what}"
        time.sleep(period)


def nodes(env: dict[str, str]) -> set[str]:
    listed = roc("node", "list", env=env)
    return set(listed.stdout.split()) if listed.returncode == 0 else set()


def wait_for_nodes(env: dict[str, str], expected: set[str], timeout: float = 30.0) -> set[str]:
    return wait_until(lambda: (found := nodes(env)) >= expected and found, timeout, f"the nodes {sorted(expected)}")


def describe(env: dict[str, str], names: set[str]) -> dict[str, dict]:
    """Each node's parameters (as param dump writes them) and endpoints (node info)."""
    system = {}
    for name in sorted(names):
        info = roc("node", "info", name, "--format", "json", env=env)
        assert info.returncode == 0, info.stderr
        params = roc("param", "dump", name, "--format", "json", env=env)
        assert params.returncode == 0, params.stderr
        system[name] = {"info": json.loads(info.stdout), "parameters": json.loads(params.stdout)}
    return system


def processes_with(marker: str) -> list[int]:
    """The PIDs of live processes whose command line holds ``marker`` (a test's own temporary path), and of
    roc's fork servers whose environment holds it (their command line names roc's script only)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            state = (entry / "stat").read_text().rsplit(")", 1)[1].split()[0]
            if "roc/launch/forkserver.py" in command:
                command += (entry / "environ").read_bytes().decode(errors="replace")
        except OSError:
            continue
        if marker in command and state not in ("Z", "X"):
            found.append(int(entry.name))
    return found


def process_view(pid: int) -> dict:
    """What ps and pkill see of a process: its name, command line, parent and process group."""
    proc = Path(f"/proc/{pid}")
    fields = (proc / "stat").read_text().rsplit(")", 1)[1].split()
    return {"comm": (proc / "comm").read_text().strip(),
            "cmdline": (proc / "cmdline").read_bytes().rstrip(b"\0").decode().replace("\0", " ").split(" "),
            "ppid": int(fields[1]), "pgid": int(fields[2])}


def kill_leftovers(marker: str) -> list[int]:
    """Kill (by PID) what is left of a test's processes, so one failing test leaves nothing behind."""
    left = processes_with(marker)
    for pid in left:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    return left
