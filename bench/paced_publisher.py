#!/usr/bin/env python3
"""A paced publisher for dataplane_bench.py, bridge_bench.py and foxglove_bench.py: std_msgs/String
on TOPIC at RATE Hz for SECONDS seconds, after WAIT seconds (for the consumers to subscribe). Prints
the count and the true rate as JSON, and the rate of the last HZ_WINDOW messages (``tail_rate``:
what a topic hz's last report should show, as the publisher's pace can drift under load).
``stamped``: each message's data is its publication time (``time.time_ns()``), for latency
(counting_subscriber.py ``latency``).

``steady``: it raises its own priority (nice -5) where allowed, for benchmarks that compare a rate
with the true one: the consumers it measures share two cores with it, and a starved publisher sends
in bursts. Latency benchmarks leave it off: the stamp is taken as each message is sent, so a late
send does not skew it, while a publisher that outranks every other process makes the processes it
measures wait for a core (through roc bridge's Zenoh link, 0.4 to 0.6 ms more added median at 5 kHz).

``sine``: std_msgs/Float64 messages instead, a sine of 0.5 Hz (for a plot, tui_bench.py).

    python bench/paced_publisher.py TOPIC RATE SECONDS WAIT [stamped] [steady] [sine]
"""

from __future__ import annotations

import collections
import json
import math
import os
import sys
import time

import rclpy
from rclpy.qos import QoSProfile
from std_msgs.msg import Float64, String

HZ_WINDOW = 10000  # roc's and ros2's topic hz measure over the last 10000 messages by default


def main() -> None:
    topic, rate, seconds, wait = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
    stamped, steady, sine = "stamped" in sys.argv[5:], "steady" in sys.argv[5:], "sine" in sys.argv[5:]
    if steady:
        try:
            os.nice(-5)
        except PermissionError:
            print("paced_publisher: cannot raise its priority (not root); under load its rate may drift",
                  file=sys.stderr)
    rclpy.init()
    node = rclpy.create_node("paced_publisher")
    publisher = node.create_publisher(Float64 if sine else String, topic, QoSProfile(depth=1000))
    message = Float64() if sine else String(data="x" * 64)
    time.sleep(wait)
    period, count = 1.0 / rate, 0
    sent = collections.deque(maxlen=HZ_WINDOW)
    start = time.perf_counter()
    while (now := time.perf_counter()) - start < seconds:
        due = start + count * period
        if now < due:  # sleep, not spin: the consumers share the machine's cores
            time.sleep(due - now)
        if stamped:
            message.data = str(time.time_ns())
        elif sine:
            message.data = math.sin(math.pi * count / rate)
        publisher.publish(message)
        sent.append(time.perf_counter())
        count += 1
    elapsed = time.perf_counter() - start
    tail_rate = (len(sent) - 1) / (sent[-1] - sent[0])
    print(json.dumps({"count": count, "rate": count / elapsed, "tail_rate": tail_rate}), flush=True)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
