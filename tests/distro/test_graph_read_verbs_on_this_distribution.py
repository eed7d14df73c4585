"""Every graph read verb of roc on the distribution that runs the tests, through the daemon, on the demo
graph of shared/reference/ros2cli (nodes of this distribution's rclpy): each answers in JSON with what the
graph holds (the ros2 CLI comparisons run on Jazzy; on Kilted the oracle would be Jazzy's ros2cli anyway)."""

from __future__ import annotations

import json
import time

import pytest
from helpers.graph import DEMO_GRAPH, graph_env, roc, start_nodes, stop_all, stop_daemon

pytestmark = [pytest.mark.distro, pytest.mark.slow]

# each read verb, and what its JSON must hold
EXPECTED = [
    (("topic", "list"), '"name": "/chatter", "types": ["std_msgs/msg/String"], "publishers": 1, "subscribers": 1'),
    (("topic", "list", "-c"), None), (("topic", "type", "/chatter"), "std_msgs/msg/String"),
    (("topic", "info", "-v", "/robot1/odom"), '"reliability": "BEST_EFFORT"'),
    (("topic", "info", "-v", "/chatter"), '"topic_type_hash": "RIHS01_'),
    (("topic", "find", "std_msgs/msg/String"), "/chatter"),
    (("node", "list"), '{"name": "/robot1/odom_pub", "duplicate": false}'),
    (("node", "info", "/talker"), '{"name": "/chatter", "types": ["std_msgs/msg/String"]}'),
    (("service", "list"), "/motor_controller/enable"),
    (("service", "type", "/motor_controller/enable"), "std_srvs/srv/SetBool"),
    (("service", "find", "std_srvs/srv/Trigger"), "/motor_controller/reset"),
    (("action", "list"), "/fibonacci"), (("action", "type", "/fibonacci"), "test_msgs/action/Fibonacci"),
    (("action", "info", "/fibonacci"), "/fibonacci_server"),
    (("param", "list", "/motor_controller"), "pid_gains"),
    (("param", "get", "/motor_controller", "wheel_names"), '"value": ["left_wheel", "right_wheel"]'),
    (("param", "describe", "/motor_controller", "max_speed"), "max_speed"),
    (("param", "dump", "/motor_controller"), '"robot_name": "demo_bot"'),
    (("interface", "list"), "test_msgs/action/Fibonacci"), (("interface", "packages"), "std_srvs"),
    (("interface", "package", "std_srvs"), "std_srvs/srv/SetBool"),
    (("interface", "show", "std_srvs/srv/SetBool"), "bool data"),
    (("interface", "proto", "std_srvs/srv/SetBool"), "\"data\": false"),
    (("daemon", "status"), '"running": true'),
]


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    env = graph_env(53, tmp_path_factory.mktemp("runtime"))
    processes = start_nodes(DEMO_GRAPH, env)
    roc("daemon", "start", env=env)
    yield env
    stop_daemon(env)
    stop_all(processes)


def test_every_read_verb_answers_in_json_with_the_graph(demo) -> None:
    pending = dict(EXPECTED)
    deadline = time.monotonic() + 30  # the daemon hears every participant's announcement within a few seconds
    while pending:
        for command, wanted in list(pending.items()):
            got = roc(*command, "--format", "json", env=demo)
            text = json.dumps(json.loads(got.stdout)) if got.returncode == 0 and got.stdout.strip() else ""
            if text and (wanted is None or wanted in text):
                del pending[command]
        assert pending == {} or time.monotonic() < deadline, {c: roc(*c, "--format", "json", env=demo).stdout[:300]
                                                              for c in pending}
