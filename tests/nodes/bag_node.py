"""A test node for the bag tests.

    python bag_node.py publish COUNT RATE_HZ TYPE...   each type on /<lower-case name>: COUNT messages
        (helpers.bag.filled, seeds 0..COUNT-1) at RATE_HZ, once every topic has a subscriber; prints
        "ready" when created and "done" when every message was acknowledged, then spins until killed.
    python bag_node.py service COUNT   serves /toggle (std_srvs/SetBool) and calls it COUNT times, with
        service introspection (contents) on the server; prints "ready", then "done" after the calls.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/: the helpers package
from helpers.bag import filled, load  # noqa: E402


def publish(node: Node, count: int, rate: float, types: list[str]) -> None:
    publishers = [(node.create_publisher(load(t), "/" + t.split("/")[-1].lower(), QoSProfile(depth=1000)), load(t))
                  for t in types]
    print("ready", flush=True)
    while not all(p.get_subscription_count() for p, _ in publishers):
        time.sleep(0.05)
    for seed in range(count):
        for publisher, cls in publishers:
            publisher.publish(filled(cls, seed))
        time.sleep(1.0 / rate)
    for publisher, _ in publishers:
        publisher.wait_for_all_acked(Duration(seconds=10))
    print("done", flush=True)


def service(node: Node, count: int) -> None:
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.service_introspection import ServiceIntrospectionState
    from std_srvs.srv import SetBool

    def answer(request, response):
        response.success = request.data
        return response

    server = node.create_service(SetBool, "/toggle", answer)
    # events kept for a late subscriber (the recorder matches the event publisher only a moment after it
    # has subscribed), and the recorder adapts to that QoS
    kept = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL, reliability=ReliabilityPolicy.RELIABLE)
    server.configure_introspection(node.get_clock(), kept, ServiceIntrospectionState.CONTENTS)
    client = node.create_client(SetBool, "/toggle")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    print("ready", flush=True)
    for line in sys.stdin:  # "go": the recorder is listening
        if line.strip() == "go":
            break
    client.wait_for_service()
    for index in range(count):
        future = client.call_async(SetBool.Request(data=index % 2 == 0))
        executor.spin_until_future_complete(future, timeout_sec=10)
    print("done", flush=True)
    executor.spin()


def main() -> None:
    rclpy.init()
    node = Node("bag_node")
    if sys.argv[1] == "publish":
        publish(node, int(sys.argv[2]), float(sys.argv[3]), sys.argv[4:])
        rclpy.spin(node)
    else:
        service(node, int(sys.argv[2]))


if __name__ == "__main__":
    try:
        main()
    except KeyboardInterrupt:
        pass
