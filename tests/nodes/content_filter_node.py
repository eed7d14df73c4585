"""A publisher for the content filter tests: std_msgs/String on /numbers at RATE Hz, each message
"<n % 10> <n>" padded with spaces to SIZE bytes (n counts from 0), so that a filter on its first
character passes one message in ten.

    python content_filter_node.py RATE SIZE [COUNT_FILE]

Prints "ready" once its publisher exists, then publishes until killed; with COUNT_FILE, it writes
there how many it has published after each message (a loaded machine publishes less than RATE)."""

from __future__ import annotations

import os
import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from std_msgs.msg import String


def main() -> None:
    rate, size = float(sys.argv[1]), int(sys.argv[2])
    rclpy.init()
    node = rclpy.create_node("numbers")
    publisher = node.create_publisher(String, "/numbers", 10)
    count = [0]
    count_file = os.open(sys.argv[3], os.O_WRONLY | os.O_CREAT, 0o600) if len(sys.argv) > 3 else None

    def tick() -> None:
        n = count[0]
        publisher.publish(String(data=f"{n % 10} {n}".ljust(size)))
        count[0] += 1
        if count_file is not None:
            os.pwrite(count_file, f"{count[0]:16d}".encode(), 0)

    node.create_timer(1.0 / rate, tick)
    print("ready", flush=True)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass


if __name__ == "__main__":
    main()
