#!/usr/bin/env python3
"""The minimal rclpy subscriber of dataplane_bench.py: counts std_msgs/String messages on TOPIC
(reliable, depth 1000) until SIGINT, then prints the count as JSON."""

from __future__ import annotations

import json
import signal
import sys

import rclpy
from rclpy.qos import QoSProfile
from std_msgs.msg import String


def main() -> None:
    rclpy.init(signal_handler_options=rclpy.signals.SignalHandlerOptions.NO)
    node = rclpy.create_node("counting_subscriber")
    count = [0]
    node.create_subscription(String, sys.argv[1], lambda _m: count.__setitem__(0, count[0] + 1), QoSProfile(depth=1000))
    stop = []
    signal.signal(signal.SIGINT, lambda *_: stop.append(True))
    print("ready", flush=True)
    while not stop:
        rclpy.spin_once(node, timeout_sec=0.1)
    print(json.dumps({"count": count[0]}), flush=True)


if __name__ == "__main__":
    main()
