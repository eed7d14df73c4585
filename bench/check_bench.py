#!/usr/bin/env python3
"""``roc graph check`` with 20 probes against the same checks done one after the other with the ros2
CLI, on one live graph: the tests' demo graph (six nodes in three processes) plus a talker at 20 Hz.

    python bench/check_bench.py [--runs 3]

The 20 probes: 6 nodes, 4 topics (type, publisher and subscriber counts), 2 topic rates (2 s each),
6 parameter values, 1 service call with an expected response, 1 action type. ros2 does each with one
command (``node list``, ``topic info``, ``timeout 2 topic hz``, ``param get``, ``service call``,
``action list -t``), its daemon warm, as a monitoring script would. Both tools' daemons are started
first; medians of ``--runs`` rounds, interleaved. ROS domain 94.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from graph_bench import (  # noqa: E402
    DEMO_GRAPH,
    live_graph,
    tool,
    tool_env,
)

RATED = [{"name": "rated", "publishers": [
    {"topic": "fast", "type": "std_msgs/msg/String", "values": {"data": "x"}, "rate_hz": 20},
    {"topic": "slow", "type": "std_msgs/msg/String", "values": {"data": "y"}, "rate_hz": 5}]}]
NODES = ["/talker", "/listener", "/robot1/odom_pub", "/map_server", "/motor_controller", "/fibonacci_server"]
TOPICS = [("/chatter", "std_msgs/msg/String"), ("/robot1/odom", "nav_msgs/msg/Odometry"),
          ("/map", "nav_msgs/msg/OccupancyGrid"), ("/fast", "std_msgs/msg/String")]
RATES = [("/fast", 15, 25), ("/slow", 4, 6)]
PARAMETERS = {"max_speed": 1.5, "robot_name": "demo_bot", "update_rate_hz": 50, "use_encoder": True,
              "pid_gains": [1.0, 0.1, 0.01], "wheel_names": ["left_wheel", "right_wheel"]}


def check_file(directory: Path) -> Path:
    lines = ["[check]", "rate-window = 2", f"nodes = {NODES!r}".replace("'", '"')]
    for name, type_name in TOPICS:
        lines += ["[[check.topic]]", f'name = "{name}"', f'type = "{type_name}"', "publishers = 1"]
    for name, low, high in RATES:
        lines += ["[[check.topic]]", f'name = "{name}"', f"min-rate = {low}", f"max-rate = {high}"]
    for name, value in PARAMETERS.items():
        toml_value = str(value).lower() if isinstance(value, bool) else repr(value).replace("'", '"')
        lines += ["[[check.parameter]]", 'node = "/motor_controller"', f'name = "{name}"', f"value = {toml_value}"]
    lines += ["[[check.service]]", 'name = "/motor_controller/enable"', 'type = "std_srvs/srv/SetBool"',
              'request = "{data: true}"', "response = { success = false }",
              "[[check.action]]", 'name = "/fibonacci"', 'type = "test_msgs/action/Fibonacci"']
    path = directory / "check.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def ros2_commands() -> list[list[str]]:
    ros2 = tool("ros2")
    commands = [[ros2, "node", "list"] for _ in NODES]
    commands += [[ros2, "topic", "info", name] for name, _ in TOPICS]
    commands += [["timeout", "-s", "INT", "2", ros2, "topic", "hz", name] for name, _, _ in RATES]
    commands += [[ros2, "param", "get", "/motor_controller", name] for name in PARAMETERS]
    commands += [[ros2, "service", "call", "/motor_controller/enable", "std_srvs/srv/SetBool", "{data: true}"],
                 [ros2, "action", "list", "-t"]]
    return commands


def timed(commands: list[list[str]], env: dict[str, str]) -> tuple[float, int]:
    """Wall time of the commands one after the other, and how many failed (hz ends by timeout: 124)."""
    start, failed = time.perf_counter(), 0
    for command in commands:
        done = subprocess.run(command, env=tool_env(env, True), capture_output=True, text=True, timeout=120)
        failed += done.returncode not in (0, 124)
    return time.perf_counter() - start, failed


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    options = parser.parse_args()
    with live_graph(94, [*DEMO_GRAPH, [RATED[0]]]) as (env, work):
        check = check_file(work)
        times: dict[str, list[float]] = {"roc": [], "ros2": []}
        failed = {"roc": 0, "ros2": 0}
        for _ in range(options.runs):
            elapsed, bad = timed([[tool("roc"), "graph", "check", "--file", str(check)]], env)
            times["roc"].append(elapsed)
            failed["roc"] += bad
            elapsed, bad = timed(ros2_commands(), env)
            times["ros2"].append(elapsed)
            failed["ros2"] += bad
        roc_time, ros2_time = statistics.median(times["roc"]), statistics.median(times["ros2"])
        print(f"20 probes: roc graph check {roc_time:.2f} s, sequential ros2 CLI {ros2_time:.2f} s, "
              f"roc/ros2 {roc_time / ros2_time:.2f} (failed runs: roc {failed['roc']}, ros2 commands {failed['ros2']})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
