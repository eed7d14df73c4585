"""Fixes of issue 33 (what a newcomer trial found) on a live graph of real rclpy nodes: echo --once right
after a publisher appears, pub's waiting line, graph check's output, param set's and daemon status's
messages."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest
from build_helpers import BIN, stop_process
from graph_helpers import NODE_SCRIPT, graph_env, read_line, roc, start_nodes, stop_all, stop_daemon

pytestmark = pytest.mark.slow

SYSTEM = [
    [{"name": "talker", "publishers": [
        {"topic": "chatter", "type": "std_msgs/msg/String", "values": {"data": "hi"}, "rate_hz": 20},
        {"topic": "scan", "type": "std_msgs/msg/String", "values": {"data": "s"}, "rate_hz": 10,
         "reliability": "best_effort"}]}],
    [{"name": "listener", "subscribers": [{"topic": "scan", "type": "std_msgs/msg/String"}]},
     {"name": "motor", "services": [{"name": "~/enable", "type": "std_srvs/srv/SetBool"}],
      "parameters": {"max_speed": 1.5}}],
]


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    env = graph_env(18, tmp_path_factory.mktemp("runtime"))
    processes = start_nodes(SYSTEM, env)
    assert roc("topic", "list", env=env).returncode == 0  # the daemon is up and warm
    yield env
    stop_daemon(env)
    stop_all(processes)


def test_echo_once_as_a_publisher_starts_waits_for_it(graph) -> None:
    """echo --once through the warm daemon, and a publisher started at the same moment (so that the
    daemon has not discovered it when echo asks): echo waits for it, within --timeout, instead of
    giving up on a topic it cannot find a type for."""
    spec = {"name": "late", "publishers": [{"topic": "late", "type": "std_msgs/msg/String",
                                            "values": {"data": "here"}, "rate_hz": 10}]}
    echo = subprocess.Popen([str(BIN / "roc"), "topic", "echo", "/late", "--once", "--timeout", "60"], env=graph,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    late = subprocess.Popen([sys.executable, str(NODE_SCRIPT), json.dumps(spec)], env=graph,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        stdout, stderr = echo.communicate(timeout=90)
        assert (echo.returncode, stdout, stderr) == (0, "data: here\n---\n", "")
    finally:
        stop_process(echo)
        stop_process(late)


def test_echo_of_a_topic_nobody_publishes_still_gives_up_within_its_timeout(graph) -> None:
    started = time.monotonic()
    quiet = roc("topic", "echo", "/nobody", "std_msgs/msg/String", "--timeout", "1", env=graph)
    assert (quiet.returncode, quiet.stderr) == (1, "roc: error: no message on /nobody within 1 s (--timeout)\n")
    assert time.monotonic() - started < 10


def test_pub_once_without_a_subscriber_says_how_to_stop_waiting_and_then_waits_quietly(graph) -> None:
    pub = subprocess.Popen([str(BIN / "roc"), "topic", "pub", "/unheard", "std_msgs/msg/String", "--once"],
                           env=graph, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        lines = [read_line(pub, timeout=10) for _ in range(5)]
        assert lines[:4] == ["Waiting for at least 1 matching subscription(s)...\n"] * 4
        assert lines[4].startswith("Still waiting for 1 matching subscription(s) after 4 s, until they appear: ")
        assert "'-w 0'" in lines[4] and "'--max-wait-time-secs SECONDS'" in lines[4]
        assert read_line(pub, timeout=3) is None  # no more lines (the wait goes on)
        assert pub.poll() is None
    finally:
        stop_process(pub)


CHECKS = """
[check]
timeout = 3
rate-window = 2
nodes = ["/ghost_node"]

[[check.topic]]
name = "/scan"
min-rate = 50

[[check.parameter]]
node = "/motor"
name = "max_speed"
value = 2.0

[[check.service]]
name = "/motor/enable"
request = "{data: true}"
"""


def test_graph_check_reports_every_failure_apart_in_yaml_and_json(graph, tmp_path: Path) -> None:
    check = tmp_path / "checks.toml"
    check.write_text(CHECKS)
    text = roc("graph", "check", "--file", str(check), env=graph)
    assert text.returncode == 1
    assert "  3 probes failed: node /ghost_node, parameter /motor max_speed, topic /scan\n" in text.stdout
    assert "Finished <<< service /motor/enable [" in text.stdout
    assert "]  answered {success: false, message: ''}\n" in text.stdout
    assert ", fail: 1.5, expected 2.0 (" in text.stdout
    scan = next(line for line in text.stdout.splitlines() if line.startswith("Failed   <<< topic /scan"))
    assert "QoS incompatible (reliability): talker -> listener" in scan and " Hz, expected 50 Hz (" in scan

    events = [json.loads(line) for line in roc("graph", "check", "--file", str(check), "--output", "json",
                                               env=graph).stdout.splitlines()]
    assert (events[-1]["event"], events[-1]["kind"]) == ("RunFinished", "probe")
    verdicts = {e["task"]: e for e in events if e["event"] == "ProbeResult"}
    assert verdicts["service /motor/enable"]["message"] == "answered {success: false, message: ''}"
    assert verdicts["topic /scan"]["measured"]["rate"] < 50


def test_param_set_names_the_undeclared_parameter(graph) -> None:
    result = roc("param", "set", "/motor", "max_sped", "2.0", env=graph)
    assert (result.returncode, result.stderr) == (
        1, "Setting parameter failed: Invalid access to undeclared parameter(s): max_sped\n")


def test_daemon_status_says_pid_environment_and_socket(graph) -> None:
    status = json.loads(roc("daemon", "status", "--format", "json", env=graph).stdout)
    assert status["running"] is True and status["environment"]["ROS_DOMAIN_ID"] == graph["ROS_DOMAIN_ID"]
    text = roc("daemon", "status", env=graph).stdout.splitlines()
    assert text == ["The daemon is running", f"  pid: {status['pid']}",
                    f"  discovery environment: ROS_DOMAIN_ID={graph['ROS_DOMAIN_ID']} "
                    "ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST", f"  socket: {status['socket']}"]
    assert Path(status["socket"]).is_socket()
