#!/usr/bin/env python3
"""The minimal rclpy subscriber of dataplane_bench.py, bridge_bench.py and bag_bench.py: counts
std_msgs/String messages (or ``type=pkg/msg/Type``'s) on TOPIC (reliable, depth 1000) until SIGINT,
then prints the count as JSON. ``latency``:
also each message's age on arrival (its data is its publication time, paced_publisher.py ``stamped``),
as the median and 99th percentile in milliseconds. ``events``: spin with rclpy's C++ EventsExecutor
(a far cheaper receiver, so that it does not limit what it measures).

    python bench/counting_subscriber.py TOPIC [latency] [events] [type=pkg/msg/Type]
"""

from __future__ import annotations

import json
import signal
import statistics
import sys
import time

import rclpy
import rclpy.executors
from rclpy.qos import QoSProfile
from std_msgs.msg import String


def main() -> None:
    rclpy.init(signal_handler_options=rclpy.signals.SignalHandlerOptions.NO)
    node = rclpy.create_node("counting_subscriber")
    count, ages = [0], []
    timed = "latency" in sys.argv[2:]

    def received(message: String) -> None:
        count[0] += 1
        if timed:
            ages.append((time.time_ns() - int(message.data)) / 1e6)
    message_type = String
    for argument in sys.argv[2:]:
        if argument.startswith("type="):
            package, kind, name = argument[5:].split("/")
            message_type = getattr(__import__(f"{package}.{kind}", fromlist=[name]), name)
    node.create_subscription(message_type, sys.argv[1], received, QoSProfile(depth=1000))
    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(True))
    if "events" in sys.argv[2:]:
        from rclpy.experimental import EventsExecutor

        executor = EventsExecutor()
    else:
        executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(node)
    print("ready", flush=True)
    while not stop:
        executor.spin_once(timeout_sec=0.1)
    result = {"count": count[0]}
    if len(ages) >= 2:
        result.update(median_ms=statistics.median(ages), p99_ms=statistics.quantiles(ages, n=100)[98])
    print(json.dumps(result), flush=True)


if __name__ == "__main__":
    main()
