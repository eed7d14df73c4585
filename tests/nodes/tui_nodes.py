"""Nodes for the TUI tests, each a real rclpy node in this process:

- ``chatty_logger`` logs one line at each level (debug to fatal) every 0.2 s, numbered ("debug 3");
- ``diagnoser`` publishes /diagnostics (diagnostic_msgs/DiagnosticArray) at 5 Hz: a motor that is OK, a
  battery whose level goes OK, WARN, ERROR in turn (each for 1 s), a lidar that is STALE;
- ``poser`` publishes /pose (geometry_msgs/PoseStamped) at ``--pose-hz`` Hz: position.x counts the
  messages, position.y is x * 2.

    python tui_nodes.py [--pose-hz 50]

Prints "ready" once everything is created, then spins until killed.
"""

from __future__ import annotations

import argparse

import rclpy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import PoseStamped
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.logging import LoggingSeverity
from rclpy.node import Node


def logger_node() -> Node:
    node = Node("chatty_logger")
    node.get_logger().set_level(LoggingSeverity.DEBUG)
    count = [0]

    def log() -> None:
        count[0] += 1
        logger = node.get_logger()
        logger.debug(f"debug {count[0]}")
        logger.info(f"info {count[0]}")
        logger.warning(f"warn {count[0]}")
        logger.error(f"error {count[0]}")
        logger.fatal(f"fatal {count[0]}")
    node.create_timer(0.2, log)
    return node


def diagnostics_node() -> Node:
    node = Node("diagnoser")
    publisher = node.create_publisher(DiagnosticArray, "/diagnostics", 10)
    count = [0]

    def publish() -> None:
        count[0] += 1
        battery = (count[0] // 5) % 3  # OK, WARN, ERROR, each for a second
        array = DiagnosticArray()
        array.header.stamp = node.get_clock().now().to_msg()
        array.status = [
            DiagnosticStatus(level=DiagnosticStatus.OK, name="motor: driver", hardware_id="motor-1",
                             message="running", values=[KeyValue(key="temperature", value="41.5")]),
            DiagnosticStatus(level=bytes([battery]), name="power: battery", hardware_id="bms-7",
                             message=["charged", "low", "empty"][battery],
                             values=[KeyValue(key="percent", value=str(90 - 40 * battery))]),
            DiagnosticStatus(level=DiagnosticStatus.STALE, name="lidar: scan", hardware_id="lidar-2",
                             message="no data"),
        ]
        publisher.publish(array)
    node.create_timer(0.2, publish)
    return node


def pose_node(rate_hz: float) -> Node:
    node = Node("poser")
    publisher = node.create_publisher(PoseStamped, "/pose", 10)
    count = [0]

    def publish() -> None:
        count[0] += 1
        message = PoseStamped()
        message.header.stamp = node.get_clock().now().to_msg()
        message.header.frame_id = "map"
        message.pose.position.x = float(count[0])
        message.pose.position.y = 2.0 * count[0]
        publisher.publish(message)
    node.create_timer(1.0 / rate_hz, publish)
    return node


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--pose-hz", type=float, default=50.0)
    options = parser.parse_args()
    rclpy.init()
    executor = SingleThreadedExecutor()
    for node in (logger_node(), diagnostics_node(), pose_node(options.pose_hz)):
        executor.add_node(node)
    print("ready", flush=True)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass


if __name__ == "__main__":
    main()
