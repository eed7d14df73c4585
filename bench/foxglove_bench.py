#!/usr/bin/env python3
"""Throughput and latency through ``roc bridge --foxglove``, against a direct rclpy subscription in the
same run.

    .venv/bin/python bench/foxglove_bench.py [--rates 1000 5000] [--seconds 5]

For each rate: a publisher process sends std_msgs/String messages whose data is the send time (ns)
for SECONDS, paced; a direct rclpy subscriber process (reliable, depth 1000) and a Foxglove WebSocket
client of the bridge (the ``websockets`` package, subscribed to the channel) count what arrives and
the latency (receive time - send time). Prints one JSON line per rate: sent, received by each, loss
and latency median / 99th percentile in ms. Private ROS domain 231, localhost discovery.

The modes ``publish`` and ``direct`` are the helper processes.
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

ROOT = Path(__file__).resolve().parents[1]
TOPIC = "/bench_stamped"


def publish(rate: float, seconds: float, wait: float) -> None:
    import rclpy
    from rclpy.qos import QoSProfile
    from std_msgs.msg import String

    rclpy.init()
    node = rclpy.create_node("foxglove_bench_publisher")
    publisher = node.create_publisher(String, TOPIC, QoSProfile(depth=1000))
    time.sleep(wait)
    period, count = 1.0 / rate, 0
    start = time.perf_counter()
    while (now := time.perf_counter()) - start < seconds:
        due = start + count * period
        if now < due:
            time.sleep(due - now)
        publisher.publish(String(data=str(time.time_ns())))
        count += 1
    print(json.dumps({"count": count, "rate": count / (time.perf_counter() - start)}), flush=True)
    time.sleep(1)  # the last messages reach the subscribers
    rclpy.shutdown()


def direct() -> None:
    import rclpy
    from rclpy.qos import QoSProfile
    from std_msgs.msg import String

    rclpy.init(signal_handler_options=rclpy.signals.SignalHandlerOptions.NO)
    node = rclpy.create_node("foxglove_bench_direct")
    latencies: list[int] = []
    node.create_subscription(String, TOPIC, lambda m: latencies.append(time.time_ns() - int(m.data)),
                             QoSProfile(depth=1000))
    stop: list[bool] = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(True))
    print("ready", flush=True)
    while not stop:
        rclpy.spin_once(node, timeout_sec=0.1)
    print(json.dumps({"latencies": latencies}), flush=True)


def _summary(latencies: list[int], sent: int) -> dict:
    ms = sorted(value / 1e6 for value in latencies)
    return {"received": len(ms), "loss_pct": round(100 * (1 - len(ms) / sent), 2),
            "median_ms": round(statistics.median(ms), 3) if ms else None,
            "p99_ms": round(ms[int(0.99 * (len(ms) - 1))], 3) if ms else None}


def run_rate(rate: float, seconds: float, env: dict[str, str]) -> dict:
    from rclpy.serialization import deserialize_message
    from std_msgs.msg import String
    from websockets.sync.client import connect

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    python = sys.executable
    bridge = subprocess.Popen([str(ROOT / ".venv" / "bin" / "roc"), "bridge", "--foxglove", "--port", str(port),
                               "--format", "json"], env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                              text=True)
    subscriber = subprocess.Popen([python, __file__, "direct"], env=env, stdout=subprocess.PIPE, text=True)
    publisher = subprocess.Popen([python, __file__, "publish", str(rate), str(seconds), "6"], env=env,
                                 stdout=subprocess.PIPE, text=True)
    try:
        assert subscriber.stdout.readline().strip() == "ready"
        assert json.loads(bridge.stdout.readline())["event"] == "serving"
        threading.Thread(target=bridge.stdout.read, daemon=True).start()  # its status lines, unread
        latencies: list[int] = []
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
                    frame = ws.recv(timeout=2 if latencies else 10)
                except TimeoutError:
                    break
                if isinstance(frame, bytes) and frame[0] == 1 and struct.unpack_from("<I", frame, 1)[0] == 1:
                    latencies.append(time.time_ns() - int(deserialize_message(frame[13:], String).data))
        sent = json.loads(publisher.communicate(timeout=60)[0])
        subscriber.send_signal(signal.SIGINT)
        direct_latencies = json.loads(subscriber.communicate(timeout=30)[0])["latencies"]
    finally:
        for process in (publisher, subscriber, bridge):
            if process.poll() is None:
                process.send_signal(signal.SIGINT)
                try:
                    process.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    process.kill()
    return {"rate_hz": rate, "sent": sent["count"], "true_rate_hz": round(sent["rate"], 1),
            "direct": _summary(direct_latencies, sent["count"]), "foxglove": _summary(latencies, sent["count"])}


def main() -> None:
    if sys.argv[1:2] == ["publish"]:
        return publish(float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]))
    if sys.argv[1:2] == ["direct"]:
        return direct()
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rates", type=float, nargs="+", default=[1000, 5000])
    parser.add_argument("--seconds", type=float, default=5)
    args = parser.parse_args()
    env = {**os.environ, "ROS_DOMAIN_ID": "231", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    for rate in args.rates:
        print(json.dumps(run_rate(rate, args.seconds, env)), flush=True)


if __name__ == "__main__":
    main()
