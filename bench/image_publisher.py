#!/usr/bin/env python3
"""A paced publisher of large sensor_msgs/Image messages for bag_bench.py: WIDTH x HEIGHT rgb8 on
TOPIC at RATE Hz for SECONDS seconds after WAIT seconds; prints the count as JSON.

    python bench/image_publisher.py TOPIC RATE SECONDS WAIT [WIDTH HEIGHT]
"""

from __future__ import annotations

import json
import sys
import time

import rclpy
from rclpy.qos import QoSProfile
from sensor_msgs.msg import Image


def main() -> None:
    topic, rate, seconds, wait = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
    width, height = (int(sys.argv[5]), int(sys.argv[6])) if len(sys.argv) > 6 else (1000, 700)
    rclpy.init()
    node = rclpy.create_node("image_publisher")
    publisher = node.create_publisher(Image, topic, QoSProfile(depth=10))
    image = Image(width=width, height=height, encoding="rgb8", step=width * 3)
    image.data = bytes(width * height * 3)
    time.sleep(wait)
    period, count = 1.0 / rate, 0
    start = time.perf_counter()
    while (now := time.perf_counter()) - start < seconds:
        due = start + count * period
        if now < due:
            time.sleep(due - now)
        image.header.frame_id = str(count)
        publisher.publish(image)
        count += 1
    print(json.dumps({"count": count, "rate": count / (time.perf_counter() - start)}), flush=True)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
