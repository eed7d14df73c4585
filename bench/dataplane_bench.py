#!/usr/bin/env python3
"""roc against the real ros2 CLI moving data on one live graph: median wall times of a warm
``topic echo --once`` of a 10 Hz topic and ``topic pub --once`` to a subscriber, both tools' daemons
running, runs interleaved.

    python bench/dataplane_bench.py [--runs 10]

ROS domain 91, localhost discovery, roc's daemon in a private runtime directory; ros2 is the tests'
oracle (~/.cache/roc-tests/ros2cli-venv). Environments as graph_bench.py's "warm" mode. Target (issue
11): roc at most 1/3 of ros2's time. ``topic hz``/``bw``/``delay`` and the 1/5 kHz rates are not
measured yet (those verbs do not exist yet).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from graph_bench import graph_env, install_oracle, start_nodes, stop_all, stop_daemon, timed, tool  # noqa: E402

GRAPH = [[{"name": "talker", "publishers": [
              {"topic": "chatter", "type": "std_msgs/msg/String", "values": {"data": "hello"}, "rate_hz": 10}]}],
         [{"name": "listener", "subscribers": [{"topic": "cmd", "type": "geometry_msgs/msg/Twist"}]}]]
COMMANDS = [("topic", "echo", "/chatter", "--once"),
            ("topic", "pub", "--once", "/cmd", "geometry_msgs/msg/Twist", "{linear: {x: 0.5}}")]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    options = parser.parse_args()
    reason = install_oracle()
    if reason:
        raise SystemExit(f"the ros2 CLI is not available: {reason}")
    env = graph_env(91, Path(tempfile.mkdtemp(prefix="roc-dataplane-bench-")))
    env["ROS_DOMAIN_ID"] = "91"
    processes = start_nodes(GRAPH, env)
    try:
        for name in ("roc", "ros2"):
            subprocess.run([tool(name), "daemon", "start"], env=env, capture_output=True, timeout=60)
        time.sleep(4)
        print(f"{'command':75} {'roc s':>7} {'ros2 s':>7} {'roc/ros2':>8}  failed runs roc, ros2")
        for command in COMMANDS:
            times: dict[str, list[float]] = {"roc": [], "ros2": []}
            failed = {"roc": 0, "ros2": 0}
            for _ in range(options.runs):
                for name in ("roc", "ros2"):
                    elapsed, _, code = timed(name, command, env)
                    times[name].append(elapsed)
                    failed[name] += code != 0
            roc_time, ros2_time = statistics.median(times["roc"]), statistics.median(times["ros2"])
            print(f"{' '.join(command):75} {roc_time:7.3f} {ros2_time:7.3f} {roc_time / ros2_time:8.2f}  "
                  f"{failed['roc']}, {failed['ros2']}")
    finally:
        stop_daemon(env)
        subprocess.run([tool("ros2"), "daemon", "stop"], env=env, capture_output=True, timeout=60)
        stop_all(processes)
    return 0


if __name__ == "__main__":
    sys.exit(main())
