"""Real C++ nodes on rclcpp (the C++ stack built by roc, tests/helpers/cpp.py), started from a shell that
sourced the stack, seen and driven by roc's graph verbs and compared with the real ros2 CLI on the same
graph: demo_nodes_cpp's talker, listener, add_two_ints_server and parameter_blackboard, and
action_tutorials_cpp's Fibonacci server."""

from __future__ import annotations

import json
import re
import signal
import subprocess
import time

import pytest
from helpers.build import BIN, stop_process
from helpers.cpp import require_stack, sourced
from helpers.graph import graph_env, install_oracle, read_line, roc, ros2, stop_daemon, wait_for

pytestmark = [pytest.mark.slow, pytest.mark.cpp]

SLOT = 28
NODES = ["/add_two_ints_server", "/fibonacci_action_server", "/listener", "/parameter_blackboard", "/talker"]


def cpp_node(install, package: str, executable: str, env: dict[str, str], *args: str) -> subprocess.Popen:
    """A C++ program of the stack, run as a user runs it from a shell that sourced the stack."""
    program = install / package / "lib" / package / executable
    return subprocess.Popen([str(program), *args], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)


@pytest.fixture(scope="module")
def cpp_graph(tmp_path_factory):
    install = require_stack()
    env = sourced(graph_env(SLOT, tmp_path_factory.mktemp("runtime")))
    processes = [cpp_node(install, "demo_nodes_cpp", "talker", env),
                 cpp_node(install, "demo_nodes_cpp", "listener", env),
                 cpp_node(install, "demo_nodes_cpp", "add_two_ints_server", env),
                 cpp_node(install, "demo_nodes_cpp", "parameter_blackboard", env, "--ros-args",
                          "-p", "robot_name:=cpp_bot", "-p", "max_speed:=1.5"),
                 cpp_node(install, "action_tutorials_cpp", "fibonacci_action_server", env)]
    try:
        wait_for(lambda: roc("node", "list", env=env).stdout.split() == NODES, timeout=30)
        yield env, processes
    finally:
        stop_daemon(env)
        for process in processes:
            stop_process(process)


@pytest.fixture(scope="module")
def with_ros2(cpp_graph):
    """The graph with the ros2 CLI oracle's daemon started and caught up."""
    reason = install_oracle()
    if reason:
        pytest.skip(f"the ros2 CLI oracle is not available: {reason}")
    env, _ = cpp_graph
    ros2("daemon", "start", env=env)
    wait_for(lambda: ros2("node", "list", env=env).stdout.split() == NODES, timeout=30)
    yield env
    ros2("daemon", "stop", env=env)


def test_the_cpp_listener_hears_the_cpp_talker(cpp_graph):
    _, processes = cpp_graph
    listener = processes[1]
    line = ""
    deadline = time.monotonic() + 20
    while "I heard: [Hello World: " not in line and time.monotonic() < deadline:
        line = listener.stderr.readline()
    assert "I heard: [Hello World: " in line


def test_echo_and_hz_read_the_cpp_talker(cpp_graph):
    env, _ = cpp_graph
    echo = roc("topic", "echo", "/chatter", "--once", env=env)
    assert echo.returncode == 0, echo.stderr
    assert echo.stdout.startswith("data: 'Hello World: ") and echo.stdout.endswith("\n---\n")
    hz = subprocess.Popen([str(BIN / "roc"), "topic", "hz", "/chatter"], env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.DEVNULL, text=True)
    try:
        line = read_line(hz, timeout=15)
        assert line is not None and line.startswith("average rate: ")
        assert 0.8 < float(line.split()[-1]) < 1.2  # the talker publishes once a second
    finally:
        stop_process(hz)


@pytest.mark.parametrize("command", [
    ("node", "list"),
    ("topic", "list", "-t"),
    ("topic", "info", "-v", "/chatter"),
    ("service", "list", "-t"),
    ("action", "list", "-t"),
    ("action", "info", "/fibonacci"),
    ("node", "info", "/talker"),
    ("node", "info", "/fibonacci_action_server"),
    ("param", "list", "/parameter_blackboard"),
    ("param", "get", "/parameter_blackboard", "robot_name"),
    ("interface", "show", "action_tutorials_interfaces/action/Fibonacci"),
], ids=" ".join)
def test_graph_verbs_answer_as_ros2_on_cpp_nodes(with_ros2, command):
    env = with_ros2
    got = roc(*command, env=env)
    expected = ros2(*command, env=env)
    for _ in range(2):  # under load ros2 may leave out a node whose services answer late: ask again
        if expected.stdout == got.stdout:
            break
        expected = ros2(*command, env=env)
    assert got.returncode == expected.returncode == 0, got.stderr + expected.stderr
    assert got.stdout.splitlines() == expected.stdout.splitlines()


def test_a_cpp_node_s_parameters_are_set_and_read(cpp_graph):
    env, _ = cpp_graph
    assert roc("param", "set", "/parameter_blackboard", "max_speed", "2.5", env=env).stdout == \
        "Set parameter successful\n"
    assert roc("param", "get", "/parameter_blackboard", "max_speed", env=env).stdout == "Double value is: 2.5\n"
    dump = roc("param", "dump", "/parameter_blackboard", env=env)
    assert "robot_name: cpp_bot" in dump.stdout and "max_speed: 2.5" in dump.stdout


def test_a_cpp_service_answers_roc_s_call(cpp_graph):
    env, _ = cpp_graph
    called = roc("service", "call", "/add_two_ints", "example_interfaces/srv/AddTwoInts", "{a: 2, b: 40}", env=env)
    assert called.returncode == 0, called.stderr
    assert "response:\nexample_interfaces.srv.AddTwoInts_Response(sum=42)\n" in called.stdout


def test_a_cpp_action_server_runs_roc_s_goal_with_feedback(cpp_graph):
    env, _ = cpp_graph
    goal = roc("action", "send_goal", "/fibonacci", "action_tutorials_interfaces/action/Fibonacci", "{order: 5}",
               "--feedback", env=env, timeout=60)
    assert goal.returncode == 0, goal.stderr
    assert "Feedback:\n    partial_sequence:\n" in goal.stdout
    assert "sequence:\n- 0\n- 1\n- 1\n- 2\n- 3\n- 5\n" in goal.stdout
    assert "Goal finished with status: SUCCEEDED" in goal.stdout


def heard(listener: subprocess.Popen, number: int, timeout: float = 20) -> None:
    """Wait until a demo listener prints that it heard message ``number`` (or a later one) of the talker;
    its log goes to stderr, where earlier lines may wait unread."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        found = re.search(r"I heard: \[Hello World: (\d+)\]", listener.stderr.readline())
        if found and int(found.group(1)) >= number:
            return
    raise AssertionError(f"the listener never heard message {number}")


def current_message(env: dict[str, str]) -> int:
    """The number of the talker's latest message."""
    echo = roc("topic", "echo", "/chatter", "--once", "--field", "data", env=env)
    return int(re.search(r"Hello World: (\d+)", echo.stdout).group(1))


def test_a_bag_recorded_from_the_cpp_talker_plays_to_a_cpp_listener(cpp_graph, tmp_path):
    env, processes = cpp_graph
    bag = tmp_path / "chatter"
    recorder = subprocess.Popen([str(BIN / "roc"), "bag", "record", "/chatter", "-o", str(bag),
                                 "--disable-keyboard-controls"], env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
    try:
        lines = [read_line(recorder, 30) or "" for _ in range(2)]
        assert lines[-1].strip() == "Subscribed to topic '/chatter'", lines
        heard(processes[1], current_message(env) + 3)  # the talker published three times since
        recorder.send_signal(signal.SIGINT)
        assert recorder.wait(timeout=30) == 0, recorder.stderr.read()
    finally:
        stop_process(recorder)
    info = roc("bag", "info", str(bag), "--format", "json", env=env)
    assert info.returncode == 0, info.stderr
    topics = {t["name"]: t for t in json.loads(info.stdout)["topics"]}
    assert topics["/chatter"]["type"] == "std_msgs/msg/String" and topics["/chatter"]["message_count"] >= 2, topics

    install = require_stack()
    replayed = cpp_node(install, "demo_nodes_cpp", "listener", env, "--ros-args", "-r", "chatter:=replayed",
                        "-r", "__node:=replay_listener")
    try:
        wait_for(lambda: "/replay_listener" in roc("node", "list", env=env).stdout.split())
        played = roc("bag", "play", str(bag), "--remap", "/chatter:=/replayed", "--disable-keyboard-controls",
                     "--wait-for-subscribers", env=env, timeout=60)
        assert played.returncode == 0, played.stderr
        heard(replayed, 0)
    finally:
        stop_process(replayed)
