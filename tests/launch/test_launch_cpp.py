"""roc launch of C++ systems (the C++ stack built by roc, tests/helpers/cpp.py): the demos' launch file
with a ComposableNodeContainer (rclcpp_components' real container loading the composition demo's
components), and a roc.toml system mixing a C++ talker with a Python listener. After kill -9 of roc, no
process of either is left."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import psutil
import pytest
from helpers.cpp import require_stack, sourced
from helpers.graph import roc, stop_daemon
from helpers.launch import SITE, demo_env, roc_launch, skip_without_launch_library, wait_for_nodes, wait_until

pytestmark = [pytest.mark.slow, pytest.mark.cpp]

SLOT = 30

SYSTEM = """\
[launch.mixed]
[[launch.mixed.process]]
package = "demo_nodes_cpp"
executable = "talker"

[[launch.mixed.process]]
package = "roc_launch_demo"
executable = "listener"
after = ["topic /chatter publishes at >= 0.5 Hz"]
"""


@pytest.fixture(scope="module")
def env(tmp_path_factory, launch_demo_prefix):
    skip_without_launch_library()
    require_stack()
    base = demo_env(SLOT, tmp_path_factory.mktemp("runtime"), launch_demo_prefix)
    environment = sourced(base)
    # the stack's setup script put its own packages first and kept the launch demo's from the environment
    assert str(launch_demo_prefix) in environment["AMENT_PREFIX_PATH"].split(os.pathsep)
    assert str(launch_demo_prefix / SITE) in environment["PYTHONPATH"].split(os.pathsep)
    yield environment
    stop_daemon(environment)


def descendants(pid: int) -> list[psutil.Process]:
    """The processes roc launch started, but roc's daemon, which a condition's probe may have started and
    which outlives roc on purpose (it ends after its idle time)."""
    return [p for p in psutil.Process(pid).children(recursive=True) if "roc.ros.daemon" not in p.cmdline()]


def alive(processes: list[psutil.Process]) -> list[str]:
    """The command lines of those still running."""
    found = []
    for process in processes:
        try:
            if process.is_running() and process.status() != psutil.STATUS_ZOMBIE:
                found.append(" ".join(process.cmdline()))
        except psutil.Error:
            continue
    return found


def assert_sigkill_leaves_nothing(launcher, started: list[psutil.Process]) -> None:
    assert launcher.stop(signal.SIGKILL) == -signal.SIGKILL
    try:
        wait_until(lambda: not alive(started), 20, "every launched process to end after roc was killed")
    except AssertionError:
        raise AssertionError(f"left after kill -9 of roc: {alive(started)}") from None


def test_a_launch_file_s_composable_node_container_loads_the_cpp_components(env, tmp_path: Path) -> None:
    launcher = roc_launch("composition", "composition_demo_launch.py", env=env, log=tmp_path / "roc.log")
    try:
        wait_for_nodes(env, {"/my_container", "/talker", "/listener"})
        listed = roc("component", "list", env=env)
        assert listed.stdout == "/my_container\n  1  /talker\n  2  /listener\n", listed.stderr
        launcher.wait_for_output("I heard: [Hello World: ")  # the container's output, through roc
        started = descendants(launcher.pid)
        assert any(p.name() == "component_conta" or "component_container" in " ".join(p.cmdline())
                   for p in started), [p.cmdline() for p in started]
    except BaseException:
        launcher.stop(signal.SIGINT)
        raise
    assert_sigkill_leaves_nothing(launcher, started)


def test_a_roc_toml_system_runs_a_cpp_talker_and_a_python_listener(env, tmp_path: Path) -> None:
    (tmp_path / "roc.toml").write_text(SYSTEM)
    launcher = roc_launch("mixed", env=env, log=tmp_path / "roc.log")
    try:
        wait_for_nodes(env, {"/talker", "/listener"})
        info = roc("node", "info", "/listener", env=env)
        assert "/chatter: std_msgs/msg/String" in info.stdout, info.stderr
        started = descendants(launcher.pid)
        programs = " ".join(" ".join(p.cmdline()) for p in started)
        assert "demo_nodes_cpp/talker" in programs and "roc_launch_demo" in programs
    except BaseException:
        launcher.stop(signal.SIGINT)
        raise
    assert_sigkill_leaves_nothing(launcher, started)
