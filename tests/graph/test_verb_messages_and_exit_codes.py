"""What the graph verbs say and exit with, on a live graph of real rclpy nodes and without one: echo
--once right after a publisher appears, echo giving up, pub's waiting line, graph check's failures in
text, YAML and JSON, param set's and daemon status's messages, and exit codes 1 and 2 for types not
installed and malformed names."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.build import BIN, stop_process
from helpers.graph import NODE_SCRIPT, graph_env, read_line, roc, start_nodes, stop_all, stop_daemon

from roc.commands.topic.pub import waiting_text

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


def cli(*args: str, env: dict[str, str], cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([str(BIN / "roc"), *args], env=env, cwd=cwd, capture_output=True, text=True, timeout=60,
                          stdin=subprocess.DEVNULL)


@pytest.fixture
def runtime(tmp_path_factory) -> Path:
    """A runtime directory short enough for the daemon's socket (a long one falls back to a shared one)."""
    return tmp_path_factory.mktemp("rt")


@pytest.mark.parametrize("verb", [
    ["topic", "pub", "/x"], *(pytest.param(verb, marks=pytest.mark.slow) for verb in [
        ["interface", "show"], ["topic", "echo", "/x"], ["interface", "proto"], ["service", "call", "/x"],
        ["action", "send_goal", "/x"]])],
    ids=lambda verb: " ".join(verb[:2]))
def test_every_verb_exits_1_for_a_type_not_installed_and_2_for_a_malformed_name(runtime: Path, verb) -> None:
    kind = {"service": "srv", "action": "action"}.get(verb[0], "msg")
    extra = ["{}"] if verb[0] == "action" else []
    env = graph_env(19, runtime)
    unknown = cli(*verb, f"foo_{kind}s/{kind}/Bar", *extra, env=env)
    assert (unknown.returncode, unknown.stdout, len(unknown.stderr.splitlines())) == (1, "", 1), unknown.stderr
    malformed = cli(*verb, "Bar", *extra, env=env)
    assert (malformed.returncode, malformed.stdout, len(malformed.stderr.splitlines())) == (2, "", 1), malformed.stderr
    status = json.loads(cli("daemon", "status", "--format", "json", env=env).stdout)
    # decided before any daemon was asked: none was started (interface show asks the graph's nodes for a
    # type not installed here only through a daemon that is already running)
    assert status["running"] is False


def test_pub_says_once_how_to_stop_waiting_instead_of_repeating_its_waiting_line() -> None:
    lines = [waiting_text(count, 1) for count in range(1, 9)]
    assert lines[:4] == ["Waiting for at least 1 matching subscription(s)...\n"] * 4
    assert lines[4] == ("Still waiting for 1 matching subscription(s) after 4 s, until they appear: Ctrl+C stops, "
                        "'-w 0' publishes without waiting, '--max-wait-time-secs SECONDS' gives up\n")
    assert lines[5:] == ["", "", ""]


def test_param_set_names_an_undeclared_parameter() -> None:
    from roc.commands.param.set import named_reason

    assert named_reason("max_sped", "Invalid access to undeclared parameter(s): []") == (
        "Invalid access to undeclared parameter(s): max_sped")
    assert named_reason("x", "Wrong parameter type") == "Wrong parameter type"


def test_daemon_status_says_which_daemon(runtime: Path) -> None:
    from roc.commands.daemon.status import status_lines

    running = {"running": True, "pid": 42, "socket": "/run/roc/daemon-1.sock",
               "environment": {"ROS_DOMAIN_ID": "", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}}
    assert status_lines(running) == ["The daemon is running", "  pid: 42",
                                     "  discovery environment: ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST",
                                     "  socket: /run/roc/daemon-1.sock"]
    env = graph_env(19, runtime)
    stopped = json.loads(cli("daemon", "status", "--format", "json", env=env).stdout)
    assert stopped["running"] is False and stopped["environment"]["ROS_DOMAIN_ID"] == env["ROS_DOMAIN_ID"]
    assert stopped["socket"].startswith(f"{runtime}/roc/daemon-") and stopped["socket"].endswith(".sock")
