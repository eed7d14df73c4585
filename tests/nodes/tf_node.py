"""A tf publisher for the frame tests (needs tf2_msgs installed):

    python tf_node.py publish   # /tf_static: map->odom (x 1), base_link->laser (y 1);
                                # /tf at 20 Hz: odom->base_link (yaw 90 degrees)
    python tf_node.py camera    # a second node on /tf, at 10 Hz: camera->lens (z 1)
    python tf_node.py listen    # prints each transform heard on /tf_static as a JSON line

Prints "ready" once its endpoints exist, then spins until killed.
"""

from __future__ import annotations

import json
import math
import sys

import rclpy
from geometry_msgs.msg import TransformStamped
from rclpy.executors import ExternalShutdownException
from rclpy.qos import DurabilityPolicy, QoSProfile
from tf2_msgs.msg import TFMessage

STATIC = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def stamped(node, parent: str, child: str, xyz=(0.0, 0.0, 0.0), yaw: float = 0.0) -> TransformStamped:
    t = TransformStamped()
    t.header.stamp = node.get_clock().now().to_msg()
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
    t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return t


def main() -> None:
    rclpy.init()
    node = rclpy.create_node(f"tf_{sys.argv[1]}")
    if sys.argv[1] == "publish":
        static = node.create_publisher(TFMessage, "/tf_static", STATIC)
        static.publish(TFMessage(transforms=[stamped(node, "map", "odom", (1.0, 0.0, 0.0)),
                                             stamped(node, "base_link", "laser", (0.0, 1.0, 0.0))]))
        dynamic = node.create_publisher(TFMessage, "/tf", 100)
        node.create_timer(0.05, lambda: dynamic.publish(
            TFMessage(transforms=[stamped(node, "odom", "base_link", yaw=math.pi / 2)])))
    elif sys.argv[1] == "camera":
        dynamic = node.create_publisher(TFMessage, "/tf", 100)
        node.create_timer(0.1, lambda: dynamic.publish(TFMessage(transforms=[stamped(node, "camera", "lens", (0.0, 0.0, 1.0))])))
    else:
        def heard(message: TFMessage) -> None:
            for t in message.transforms:
                print(json.dumps({"parent": t.header.frame_id, "child": t.child_frame_id,
                                  "x": t.transform.translation.x}), flush=True)
        node.create_subscription(TFMessage, "/tf_static", heard, STATIC)
    print("ready", flush=True)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass


if __name__ == "__main__":
    main()
