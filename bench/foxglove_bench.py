#!/usr/bin/env python3
"""Throughput and latency through ``roc bridge --foxglove``, against a direct rclpy subscription in the
same run.

    .venv/bin/python bench/foxglove_bench.py [--rates 1000 5000] [--seconds 5]

For each rate: bench/paced_publisher.py sends std_msgs/String messages stamped with their publication
time for SECONDS; bench/counting_subscriber.py (rclpy on the C++ EventsExecutor, depth 1000) is the
direct subscription, and a Foxglove WebSocket client of the bridge (the ``websockets`` package, in this
process) subscribes to the channel. Prints one JSON line per rate: sent, received by each, loss and
latency median / 99th percentile in ms. ROS domain 231, localhost discovery; every process shares the
machine's cores.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import socket
import statistics
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
TOPIC = "/bench_stamped"


def _summary(received: int, sent: int, median_ms: float | None, p99_ms: float | None) -> dict:
    return {"received": received, "loss_pct": round(100 * (1 - received / sent), 2),
            "median_ms": round(median_ms, 3) if median_ms is not None else None,
            "p99_ms": round(p99_ms, 3) if p99_ms is not None else None}


def run_rate(rate: float, seconds: float, env: dict[str, str]) -> dict:
    from rclpy.serialization import deserialize_message
    from std_msgs.msg import String
    from websockets.sync.client import connect

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    python = sys.executable
    bridge = subprocess.Popen([str(Path(sys.executable).parent / "roc"), "bridge", "--foxglove", "--port", str(port),
                               "--format", "json"], env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                              text=True)
    subscriber = subprocess.Popen([python, HERE / "counting_subscriber.py", TOPIC, "latency", "events"], env=env,
                                  stdout=subprocess.PIPE, text=True)
    publisher = subprocess.Popen([python, HERE / "paced_publisher.py", TOPIC, str(rate), str(seconds), "6", "stamped"],
                                 env=env, stdout=subprocess.PIPE, text=True)
    try:
        assert subscriber.stdout.readline().strip() == "ready"
        assert json.loads(bridge.stdout.readline())["event"] == "serving"
        threading.Thread(target=bridge.stdout.read, daemon=True).start()  # its status lines, unread
        ages: list[float] = []  # ms
        with connect(f"ws://127.0.0.1:{port}", subprotocols=["foxglove.sdk.v1"], max_size=None) as ws:
            deadline = time.monotonic() + 20
            channel = None
            while channel is None and time.monotonic() < deadline:
                op = json.loads(ws.recv(timeout=20))
                channel = next((c["id"] for c in op.get("channels", []) if c["topic"] == TOPIC), None)
            ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": channel}]}))
            quiet_until = time.monotonic() + seconds + 10
            while time.monotonic() < quiet_until:
                try:
                    frame = ws.recv(timeout=2 if ages else 10)
                except TimeoutError:
                    break
                if isinstance(frame, bytes) and frame[0] == 1 and struct.unpack_from("<I", frame, 1)[0] == 1:
                    ages.append((time.time_ns() - int(deserialize_message(frame[13:], String).data)) / 1e6)
        sent = json.loads(publisher.communicate(timeout=60)[0])
        subscriber.send_signal(signal.SIGINT)
        direct = json.loads(subscriber.communicate(timeout=30)[0])
    finally:
        for process in (publisher, subscriber, bridge):
            if process.poll() is None:
                process.send_signal(signal.SIGINT)
                try:
                    process.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    process.kill()
    return {"rate_hz": rate, "sent": sent["count"], "true_rate_hz": round(sent["rate"], 1),
            "direct": _summary(direct["count"], sent["count"], direct.get("median_ms"), direct.get("p99_ms")),
            "foxglove": _summary(len(ages), sent["count"], statistics.median(ages) if len(ages) > 1 else None,
                                 statistics.quantiles(ages, n=100)[98] if len(ages) > 1 else None)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rates", type=float, nargs="+", default=[1000, 5000])
    parser.add_argument("--seconds", type=float, default=5)
    args = parser.parse_args()
    env = {**os.environ, "ROS_DOMAIN_ID": "231", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    for rate in args.rates:
        print(json.dumps(run_rate(rate, args.seconds, env)), flush=True)


if __name__ == "__main__":
    main()
