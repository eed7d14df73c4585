"""The fixture nodes of ros2cli 0.32.2's CLI tests, written for roc's harness (tests/test_ros2cli_cases.py)
from what the upstream fixtures do: the same node names, topics, types, QoS and rates.

    python ros2cli_fixtures.py FIXTURE [ARGUMENT] [--ros-args -r __node:=NAME -r __ns:=/NS -r FROM:=TO]

FIXTURE is one of FIXTURES. The ROS arguments stand for what launch_ros's Node action passes (name,
namespace, remappings). Prints "ready" once the node exists, then spins until SIGINT or SIGTERM.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable

import rclpy
from rclpy.action import ActionServer
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.parameter import PARAMETER_SEPARATOR_STRING
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_profile_system_default
from rclpy.utilities import remove_ros_args

PERIOD = 1.0  # every upstream fixture that publishes does so once a second


def talker() -> Node:
    """ros2topic's talker_node: "Hello World: N" on chatter (depth 10), N counting from 1."""
    from std_msgs.msg import String

    node = Node("talker_node")
    publisher = node.create_publisher(String, "chatter", 10)
    count = iter(range(1, sys.maxsize))
    node.create_timer(PERIOD, lambda: publisher.publish(String(data=f"Hello World: {next(count)}")))
    return node


def listener() -> Node:
    """ros2topic's listener: logs "I heard: [DATA]" for each String on chatter (reliable, transient local)."""
    from std_msgs.msg import String

    node = Node("listener")
    qos = QoSProfile(history=qos_profile_system_default.history, depth=qos_profile_system_default.depth,
                     reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    node.create_subscription(String, "chatter", lambda msg: node.get_logger().info(f"I heard: [{msg.data}]"), qos)
    return node


def repeater(type_name: str) -> Node:
    """ros2topic's repeater_node: a default-valued TYPE on ~/output (system default QoS)."""
    package, kind, name = type_name.split("/")
    message_type = getattr(importlib.import_module(f"{package}.{kind}"), name)
    node = Node("repeater_node")
    publisher = node.create_publisher(message_type, "~/output", qos_profile_system_default)
    node.create_timer(PERIOD, lambda: publisher.publish(message_type()))
    return node


def controller() -> Node:
    """ros2topic's controller: geometry_msgs/TwistStamped on cmd_vel, stamped when published, linear.x 1."""
    from geometry_msgs.msg import TwistStamped

    node = Node("controller")
    publisher = node.create_publisher(TwistStamped, "cmd_vel", qos_profile_system_default)

    def publish() -> None:
        message = TwistStamped()
        message.header.stamp = node.get_clock().now().to_msg()
        message.twist.linear.x = 1.0
        publisher.publish(message)
    node.create_timer(PERIOD, publish)
    return node


def complex_node() -> Node:
    """ros2node's complex_node: publishes Arrays on arrays, subscribes Strings on strings, serves basic
    (BasicTypes) and the fibonacci action (each goal succeeds at once with an empty result)."""
    from test_msgs.action import Fibonacci
    from test_msgs.msg import Arrays, Strings
    from test_msgs.srv import BasicTypes

    node = Node("complex_node")
    publisher = node.create_publisher(Arrays, "arrays", qos_profile_system_default)
    node.create_subscription(Strings, "strings", lambda _msg: None, qos_profile_system_default)
    node.create_service(BasicTypes, "basic", lambda _request, response: response)

    def succeed(goal_handle):
        goal_handle.succeed()
        return Fibonacci.Result()
    node._fixture_action = ActionServer(node, Fibonacci, "fibonacci", succeed)
    node.create_timer(PERIOD, lambda: publisher.publish(Arrays()))
    return node


def echo_server() -> Node:
    """ros2service's echo_server: echo (BasicTypes) answers with the request's fields."""
    from test_msgs.srv import BasicTypes

    def echo(request, response):
        for field in request.get_fields_and_field_types():
            setattr(response, field, getattr(request, field))
        return response
    node = Node("echo_server")
    node.create_service(BasicTypes, "echo", echo)
    return node


def fibonacci_action_server() -> Node:
    """ros2action's server: fibonacci, one feedback per number after the first two, then the sequence."""
    from test_msgs.action import Fibonacci

    def execute(goal_handle):
        sequence = [0, 1]
        for _ in range(1, goal_handle.request.order):
            sequence.append(sequence[-1] + sequence[-2])
            goal_handle.publish_feedback(Fibonacci.Feedback(sequence=sequence))
        goal_handle.succeed()
        return Fibonacci.Result(sequence=sequence)
    node = Node("fibonacci_action_server")
    node._fixture_action = ActionServer(node, Fibonacci, "fibonacci", execute)
    return node


def parameter_node() -> Node:
    """ros2param's parameter_node: one parameter of each type, and two nested string parameters."""
    node = Node("parameter_node")
    dot = PARAMETER_SEPARATOR_STRING
    for name, value in (("bool_param", True), ("int_param", 42), ("double_param", 1.23),
                        ("str_param", "Hello World"), ("bool_array_param", [False, False, True]),
                        ("int_array_param", [1, 2, 3]), ("str_array_param", ["foo", "bar", "baz"]),
                        ("double_array_param", [3.125, 6.25, 12.5]), (f"foo{dot}str_param", "foo"),
                        (f"foo{dot}bar{dot}str_param", "foobar")):
        node.declare_parameter(name, value)
    return node


FIXTURES: dict[str, Callable[..., Node]] = {
    "talker": talker, "listener": listener, "repeater": repeater, "controller": controller,
    "complex_node": complex_node, "echo_server": echo_server,
    "fibonacci_action_server": fibonacci_action_server, "parameter_node": parameter_node,
}


def main() -> None:
    fixture, *arguments = remove_ros_args(sys.argv)[1:]
    rclpy.init(args=sys.argv)
    node = FIXTURES[fixture](*arguments)
    print("ready", flush=True)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
