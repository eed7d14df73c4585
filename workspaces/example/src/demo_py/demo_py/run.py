"""Run one of the package's nodes until it is done (max_count messages) or interrupted."""

import rclpy
from rclpy.executors import ExternalShutdownException


def run_until_done(node_class, args=None):
    """Spin a node whose ``done`` future completes when it has handled ``max_count`` messages."""
    rclpy.init(args=args)
    node = node_class()
    try:
        rclpy.spin_until_future_complete(node, node.done)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
