"""A test node for the graph tests: publishes, subscribes, serves and holds parameters as told.

    python graph_node.py '{"name": "talker", "namespace": "/", "publishers": [{"topic": "chatter",
        "type": "std_msgs/msg/String", "reliability": "best_effort", "durability": "volatile",
        "depth": 10, "deadline_ms": 0, "values": {"data": "hi"}, "rate_hz": 10}], "subscribers": [{..., "print": true}], "services": [{"name": "reset",
        "type": "std_srvs/srv/Trigger", "echo": false, "introspection": "contents"}], "actions": [{"name": "fibonacci"}], "parameters": {"max_speed": 1.5},
        "lifecycle": {"fail": ["activate"]}}'

Several nodes in one process: pass a JSON list. Prints "ready" once everything is created, then
spins until killed.
"""

from __future__ import annotations

import importlib
import json
import sys
import time

import rclpy
from rclpy.action import CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy


def load(type_name: str):
    package, kind, name = type_name.split("/")
    return getattr(importlib.import_module(f"{package}.{kind}"), name)


def qos(spec: dict) -> QoSProfile:
    profile = QoSProfile(depth=spec.get("depth", 10),
                         reliability=ReliabilityPolicy[spec.get("reliability", "reliable").upper()],
                         durability=DurabilityPolicy[spec.get("durability", "volatile").upper()])
    if spec.get("deadline_ms"):
        profile.deadline = Duration(nanoseconds=spec["deadline_ms"] * 1_000_000)
    return profile


def lifecycle_node(spec: dict, **options) -> Node:
    """A managed node (rclpy.lifecycle) whose transitions succeed, except those ``spec["lifecycle"]``
    names under "fail" (e.g. ["activate"]), which fail."""
    from rclpy.lifecycle import LifecycleNode, TransitionCallbackReturn

    failing = set(spec["lifecycle"].get("fail", []))

    class Managed(LifecycleNode):
        def _outcome(self, transition: str) -> TransitionCallbackReturn:
            return TransitionCallbackReturn.FAILURE if transition in failing else TransitionCallbackReturn.SUCCESS

        def on_configure(self, state):
            return self._outcome("configure")

        def on_activate(self, state):
            return self._outcome("activate")

        def on_deactivate(self, state):
            return self._outcome("deactivate")

        def on_cleanup(self, state):
            return self._outcome("cleanup")

    return Managed(spec["name"], **options)


def make_node(spec: dict) -> Node:
    options = {"namespace": spec.get("namespace", "/"),
               "allow_undeclared_parameters": spec.get("undeclared_parameters", False)}
    node = lifecycle_node(spec, **options) if "lifecycle" in spec else Node(spec["name"], **options)
    for name, value in spec.get("parameters", {}).items():
        node.declare_parameter(name, value)
    for pub in spec.get("publishers", []):
        publisher = node.create_publisher(load(pub["type"]), pub["topic"], qos(pub))
        if "values" in pub:  # {"data": "hello"}: published at once, then at "rate_hz" if given
            message = load(pub["type"])(**pub["values"])
            publisher.publish(message)
            if pub.get("rate_hz"):
                stamp_now = pub.get("stamp_now", False)

                def tick(p=publisher, m=message, n=node, stamp=stamp_now) -> None:
                    if stamp:  # a std_msgs/Header: stamped with the time of publication
                        m.stamp = n.get_clock().now().to_msg()
                    p.publish(m)
                node.create_timer(1.0 / pub["rate_hz"], tick)
    for sub in spec.get("subscribers", []):
        show_messages = sub.get("print", False)

        def received(msg, topic=sub["topic"], show=show_messages) -> None:
            if show:  # one line per message: the topic and the message's repr
                print(json.dumps({"topic": topic, "message": repr(msg)}), flush=True)
        node.create_subscription(load(sub["type"]), sub["topic"], received, qos(sub))
    for srv in spec.get("services", []):
        server = node.create_service(load(srv["type"]), srv["name"],
                                     echo if srv.get("echo") else lambda _req, resp: resp)
        introspect(node, server, srv)
    for client in spec.get("clients", []):
        introspect(node, node.create_client(load(client["type"]), client["name"]), client)
    for action in spec.get("actions", []):
        from rclpy.action import ActionServer

        node._roc_action = ActionServer(node, load(action.get("type", "test_msgs/action/Fibonacci")),
                                        action["name"], fibonacci(action.get("step_seconds", 0.0)),
                                        callback_group=ReentrantCallbackGroup(),
                                        cancel_callback=lambda _goal: CancelResponse.ACCEPT)
    return node


def introspect(node: Node, endpoint, spec: dict) -> None:
    """Service introspection as ``spec["introspection"]`` asks: "contents", "metadata" or "off"."""
    if spec.get("introspection"):
        from rclpy.qos import qos_profile_system_default
        from rclpy.service_introspection import ServiceIntrospectionState

        endpoint.configure_introspection(node.get_clock(), qos_profile_system_default,
                                         getattr(ServiceIntrospectionState, spec["introspection"].upper()))


def echo(request, response):
    """A service whose response repeats the request's fields of the same name (test_msgs/srv/BasicTypes)."""
    for name in response.get_fields_and_field_types():
        if hasattr(request, name):
            setattr(response, name, getattr(request, name))
    return response


def fibonacci(step_seconds: float):
    """A test_msgs/action/Fibonacci server: feedback after each number, ``step_seconds`` apart; a
    canceled goal ends canceled, and prints ``canceled``."""
    def execute(goal_handle):
        from test_msgs.action import Fibonacci

        sequence = [0, 1]
        for _ in range(max(0, goal_handle.request.order - 1)):
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                print("canceled", flush=True)
                return Fibonacci.Result(sequence=sequence)
            sequence.append(sequence[-1] + sequence[-2])
            goal_handle.publish_feedback(Fibonacci.Feedback(sequence=sequence))
            time.sleep(step_seconds)
        goal_handle.succeed()
        return Fibonacci.Result(sequence=sequence)
    return execute


def main() -> None:
    specs = json.loads(sys.argv[1])
    rclpy.init()
    executor = MultiThreadedExecutor()  # an action's execute callback may run while others are served
    for spec in specs if isinstance(specs, list) else [specs]:
        executor.add_node(make_node(spec))
    serve(executor)


def serve(executor) -> None:
    """Print "ready", then spin until killed (the test nodes' and tests/nodes/container_node.py's main loop)."""
    print("ready", flush=True)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass


if __name__ == "__main__":
    main()
