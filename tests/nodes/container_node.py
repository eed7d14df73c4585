"""A component container for the component tests, in Python: serves composition_interfaces'
``~/_container/load_node``, ``unload_node`` and ``list_nodes`` as rclcpp_components' ComponentManager
does, with its error texts.

    python container_node.py --ros-args -r __node:=my_container

As rclcpp's, it looks a component up in the ament index (``rclcpp_components`` resources: one
``CLASS;LIBRARY`` line per component); the classes it can "load" are the Python nodes of PLUGINS
(a talker publishing std_msgs/String on ``chatter``, a listener), made with the node name, namespace,
remapping rules and parameters of the request. Unique ids count from 1. Prints "ready", then spins
until killed.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import rclpy
from composition_interfaces.srv import ListNodes, LoadNode, UnloadNode
from graph_node import serve
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import String

# class name -> (default node name, what the node does)
PLUGINS = {
    "demo_components::Talker": ("talker", lambda node: node.create_publisher(String, "chatter", 10)),
    "demo_components::Listener": ("listener", lambda node: node.create_subscription(String, "chatter", print, 10)),
}


def registered(package: str) -> list[str] | None:
    """The component classes ``package`` registers in the ament index, None when it registers none."""
    for prefix in filter(None, os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep)):
        resource = Path(prefix) / "share" / "ament_index" / "resource_index" / "rclcpp_components" / package
        if resource.is_file():
            return [line.split(";")[0] for line in resource.read_text().splitlines() if line.strip()]
    return None


class Container(Node):
    def __init__(self, executor: MultiThreadedExecutor) -> None:
        super().__init__("ComponentManager")
        self.executor_ = executor
        self.components: dict[int, Node] = {}
        self.next_id = 1
        self.create_service(LoadNode, "~/_container/load_node", self.load)
        self.create_service(UnloadNode, "~/_container/unload_node", self.unload)
        self.create_service(ListNodes, "~/_container/list_nodes", self.list)

    def load(self, request: LoadNode.Request, response: LoadNode.Response) -> LoadNode.Response:
        classes = registered(request.package_name)
        if classes is None:
            response.error_message = "Could not find requested resource in ament index"
            return response
        if request.plugin_name not in classes or request.plugin_name not in PLUGINS:
            response.error_message = "Failed to find class with the requested plugin name."
            return response
        default_name, make = PLUGINS[request.plugin_name]
        arguments = ["--ros-args", *[part for rule in request.remap_rules for part in ("-r", rule)]]
        overrides = [Parameter.from_parameter_msg(p) for p in request.parameters]
        node = Node(request.node_name or default_name, namespace=request.node_namespace or "/",
                    cli_args=arguments, use_global_arguments=False, parameter_overrides=overrides,
                    allow_undeclared_parameters=True, automatically_declare_parameters_from_overrides=True)
        make(node)
        self.executor_.add_node(node)
        response.unique_id, self.next_id = self.next_id, self.next_id + 1
        response.full_node_name = node.get_fully_qualified_name()
        response.success = True
        self.components[response.unique_id] = node
        return response

    def unload(self, request: UnloadNode.Request, response: UnloadNode.Response) -> UnloadNode.Response:
        node = self.components.pop(request.unique_id, None)
        if node is None:
            response.error_message = f"No node found with unique_id: {request.unique_id}"
            return response
        self.executor_.remove_node(node)
        node.destroy_node()
        response.success = True
        return response

    def list(self, _request: ListNodes.Request, response: ListNodes.Response) -> ListNodes.Response:
        response.unique_ids = list(self.components)
        response.full_node_names = [node.get_fully_qualified_name() for node in self.components.values()]
        return response


def main() -> None:
    rclpy.init(args=sys.argv)
    executor = MultiThreadedExecutor()
    executor.add_node(Container(executor))
    serve(executor)


if __name__ == "__main__":
    main()
