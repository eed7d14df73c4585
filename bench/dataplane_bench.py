#!/usr/bin/env python3
"""roc against the real ros2 CLI moving data on one live graph: median wall times of a warm
``topic echo --once`` of a 10 Hz topic, ``topic pub --once`` to a subscriber, ``param get`` and
``service call``, both tools' daemons running, runs interleaved; then, per rate (1 kHz, 5 kHz), a
paced publisher (bench/paced_publisher.py) for ``--seconds`` with every consumer listening at once:
roc and ros2 ``topic hz`` (the last rate each printed against the publisher's own rate over their
window, its last 10000 messages), and how many messages roc and ros2 ``topic echo`` and a minimal
rclpy counting subscriber (bench/counting_subscriber.py) received, and the losses roc reported
(roc's echo may lag at 5 kHz: it is given time to print what it holds; "neither" counts messages
it neither printed nor reported lost).

    python bench/dataplane_bench.py [--runs 10] [--rates 1000 5000] [--seconds 10]

ROS domain 91, localhost discovery, roc's daemon in a private runtime directory; ros2 is the tests'
oracle (~/.cache/roc-tests/ros2cli-venv). Environments as graph_bench.py's "warm" mode. Target (issue
11): roc at most 1/3 of ros2's time; ``hz`` within 1 % of the true rate at 5 kHz; roc's echo receives
at least as many messages as the minimal subscriber and reports every loss.
"""

from __future__ import annotations

import argparse
import json
import signal
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from graph_bench import (  # noqa: E402
    live_graph,
    timed,
    tool,
    tool_env,
)
from paced_publisher import HZ_WINDOW  # noqa: E402

GRAPH = [[{"name": "talker", "publishers": [
              {"topic": "chatter", "type": "std_msgs/msg/String", "values": {"data": "hello"}, "rate_hz": 10}]}],
         [{"name": "listener", "subscribers": [{"topic": "cmd", "type": "geometry_msgs/msg/Twist"}]}],
         [{"name": "motor_controller", "services": [{"name": "~/enable", "type": "std_srvs/srv/SetBool"}],
           "parameters": {"max_speed": 1.5}}]]
COMMANDS = [("topic", "echo", "/chatter", "--once"),
            ("topic", "pub", "--once", "/cmd", "geometry_msgs/msg/Twist", "{linear: {x: 0.5}}"),
            ("param", "get", "/motor_controller", "max_speed"),
            ("service", "call", "/motor_controller/enable", "std_srvs/srv/SetBool", "{data: true}")]


def _consumer(command: list[str], env: dict[str, str], out: Path) -> subprocess.Popen:
    return subprocess.Popen(command, env=tool_env(env, True), stdout=out.open("w"), stderr=subprocess.DEVNULL)


def settled(path: Path, quiet: float = 1.0, limit: float = 60.0) -> None:
    """Wait until ``path`` has not grown for ``quiet`` seconds (at most ``limit``)."""
    deadline, size, since = time.monotonic() + limit, -1, time.monotonic()
    while time.monotonic() < deadline:
        if path.stat().st_size != size:
            size, since = path.stat().st_size, time.monotonic()
        elif time.monotonic() - since >= quiet:
            return
        time.sleep(0.1)


def rate_run(env: dict[str, str], rate: float, seconds: float, work: Path) -> dict:
    """One paced publisher at ``rate`` for ``seconds``, with every consumer listening at once."""
    here = Path(__file__).resolve().parent
    topic = f"/fast_{int(rate)}"
    consumers = {
        "roc hz": [tool("roc"), "topic", "hz", topic, "--format", "json"],
        "ros2 hz": [tool("ros2"), "topic", "hz", topic],
        "roc echo": [tool("roc"), "topic", "echo", topic, "std_msgs/msg/String", "--format", "json"],
        "ros2 echo": [tool("ros2"), "topic", "echo", topic, "std_msgs/msg/String"],
        "rclpy subscriber": [sys.executable, str(here / "counting_subscriber.py"), topic],
    }
    outputs = {name: work / f"{name.replace(' ', '_')}_{int(rate)}.txt" for name in consumers}
    processes = {name: _consumer(command, env, outputs[name]) for name, command in consumers.items()}
    try:
        time.sleep(3)  # every consumer subscribed
        publisher = subprocess.run([sys.executable, str(here / "paced_publisher.py"), topic, str(rate), str(seconds),
                                    "1", "steady"], env=tool_env(env, True), capture_output=True, text=True,
                                   timeout=seconds + 60)
        truth = json.loads(publisher.stdout)
        time.sleep(1.5)
        settled(outputs["roc echo"])  # roc's echo delays rather than drops: let it print what it holds
    finally:
        for process in processes.values():
            process.send_signal(signal.SIGINT)
        for process in processes.values():
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()
    text = {name: path.read_text(errors="replace") for name, path in outputs.items()}
    roc_hz = [json.loads(line) for line in text["roc hz"].splitlines() if line.startswith("{")]
    ros2_hz = [float(line.split(": ")[1]) for line in text["ros2 hz"].splitlines() if line.startswith("average rate")]
    roc_echo = [json.loads(line) for line in text["roc echo"].splitlines() if line.startswith("{")]
    return {"true rate": truth["rate"], "tail rate": truth["tail_rate"], "published": truth["count"],
            "roc hz": roc_hz[-1]["rate"] if roc_hz else None, "ros2 hz": ros2_hz[-1] if ros2_hz else None,
            "rclpy subscriber": json.loads(text["rclpy subscriber"].splitlines()[-1])["count"],
            "roc echo": len(roc_echo), "roc echo lost": sum(line["lost"] for line in roc_echo),
            "ros2 echo": text["ros2 echo"].count("\n---\n")}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--rates", type=float, nargs="*", default=[1000, 5000], metavar="HZ")
    parser.add_argument("--seconds", type=float, default=10)
    options = parser.parse_args()
    with live_graph(91, GRAPH) as (env, work):
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
        for rate in options.rates:
            row = rate_run(env, rate, options.seconds, work)
            truth = row["tail rate"]  # over the hz tools' window: their last report's

            def error(name: str, row: dict = row, truth: float = truth) -> str:
                if row[name] is None:
                    return "no output"
                return f"{row[name]:.1f} Hz ({(row[name] / truth - 1) * 100:+.2f}%)"
            print(f"\n{rate:g} Hz for {options.seconds:g} s: published {row['published']} at {row['true rate']:.1f} Hz, "
                  f"the last {min(row['published'], HZ_WINDOW)} at {truth:.1f} Hz")
            print(f"  hz: roc {error('roc hz')}, ros2 {error('ros2 hz')}")
            unaccounted = row["published"] - row["roc echo"] - row["roc echo lost"]
            print(f"  received: rclpy subscriber {row['rclpy subscriber']}, roc echo {row['roc echo']} "
                  f"(reported lost {row['roc echo lost']}, neither {unaccounted}), ros2 echo {row['ros2 echo']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
