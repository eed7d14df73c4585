"""roc launch of a Python and an XML launch file on the distribution that runs the tests: the launch library
(Jazzy's sources, on Kilted's rclpy too) starts the nodes, roc's fork server starts the Python ones warm
(forked from it, not executed), the talker's messages reach the listener, and Ctrl+C leaves nothing."""

from __future__ import annotations

from pathlib import Path

import pytest
from helpers.graph import stop_daemon
from helpers.launch import (
    DEMO_NODES,
    demo_env,
    kill_leftovers,
    nodes,
    process_view,
    processes_with,
    roc_launch,
    skip_without_launch_library,
    wait_for_nodes,
    wait_until,
)

pytestmark = [pytest.mark.distro, pytest.mark.slow]
PACKAGE = "roc_launch_demo"


@pytest.fixture(scope="module")
def demo(tmp_path_factory, launch_demo_prefix):
    skip_without_launch_library()
    env = demo_env(51, tmp_path_factory.mktemp("runtime"), launch_demo_prefix)
    yield env, launch_demo_prefix
    stop_daemon(env)
    kill_leftovers(str(launch_demo_prefix))


@pytest.mark.parametrize("file", ["demo.launch.py", "demo.launch.xml"])
def test_a_launch_file_starts_its_nodes_warm_and_stops_them(demo, tmp_path: Path, file: str) -> None:
    env, prefix = demo
    launcher = roc_launch(PACKAGE, file, env=env, log=tmp_path / "roc.log")
    try:
        wait_for_nodes(env, DEMO_NODES)
        wait_until(lambda: "heard: " in launcher.output(), 30, "the listener to hear the talker")
        views = {pid: process_view(pid) for pid in processes_with(str(prefix))}
        servers = [pid for pid, view in views.items() if view["comm"] == "roc-forkserver"]
        forked = {view["comm"] for view in views.values() if view["ppid"] in servers}
        assert len(servers) == 1 and forked == {"talker", "listener", "server"}, views
    finally:
        code = launcher.stop()
    assert code == 0, launcher.output()
    assert launcher.output().count("sending signal 'SIGINT' to process") == 3, launcher.output()
    assert processes_with(str(prefix)) == []  # (how each node ends is rclpy's: Jazzy's can crash in a callback)
    wait_until(lambda: not nodes(env) & DEMO_NODES, 20, "the nodes to leave the graph")
