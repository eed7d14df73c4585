"""What the component verbs share: the component types the ament index registers (rclcpp_components
resources), the containers of the graph (nodes serving composition_interfaces' ``_container/load_node``,
``unload_node`` and ``list_nodes``, as ros2 finds them) and the calls to them."""

from __future__ import annotations

import argparse
from typing import Any

from roc.ament_index import resource_text, resources
from roc.commands.node_services import SERVICE_TIMEOUT, call, node_is_hidden, services_of_type
from roc.errors import RocError
from roc.ros.client import Session

RESOURCE = "rclcpp_components"
CONTAINER_SERVICES = {"_container/load_node": "composition_interfaces/srv/LoadNode",
                      "_container/unload_node": "composition_interfaces/srv/UnloadNode",
                      "_container/list_nodes": "composition_interfaces/srv/ListNodes"}
# rcutils' severities, by the names --log-level takes
LOG_LEVELS = {"unset": 0, "debug": 10, "info": 20, "warn": 30, "error": 40, "fatal": 50}


def component_types(package: str) -> list[str]:
    """The component classes ``package`` registers (one ``CLASS;LIBRARY`` line each)."""
    text = resource_text(RESOURCE, package) or ""
    return [line.split(";")[0] for line in text.splitlines() if line.strip()]


def packages_with_components() -> list[str]:
    return sorted(resources(RESOURCE))


def containers(opened: Session) -> list[str]:
    """The full names of the graph's visible container nodes, sorted."""
    graph = opened.query("snapshot")
    found: set[str] | None = None
    for suffix, type_name in CONTAINER_SERVICES.items():
        serving = services_of_type(graph, suffix, type_name)
        found = serving if found is None else found & serving
    return sorted(name for name in found or () if not node_is_hidden(name))


def container(opened: Session, name: str) -> str:
    """``name`` if it is a container, else ros2's error."""
    if name not in containers(opened):
        raise RocError(f"Unable to find container node '{name}'")
    return name


def components(opened: Session, name: str) -> list[dict[str, Any]]:
    """The components a container holds: [{uid, name}]."""
    from composition_interfaces.srv import ListNodes

    try:
        response = call(opened, f"{name}/_container/list_nodes", CONTAINER_SERVICES["_container/list_nodes"],
                        ListNodes.Request())
    except RocError:
        raise RocError("No 'list_nodes' service response") from None
    return [{"uid": uid, "name": node} for uid, node in zip(response.unique_ids, response.full_node_names)]


def add_component_arguments(parser: argparse.ArgumentParser) -> None:
    """What names a component and how its node is made, as ros2 component load/standalone take them."""
    parser.add_argument("package_name", help="name of the package where the component is to be found")
    parser.add_argument("plugin_name", help="type name of the component to be loaded, e.g. demo_nodes::Talker")
    parser.add_argument("-n", "--node-name", help="component node name")
    parser.add_argument("--node-namespace", help="component node namespace")
    parser.add_argument("--log-level", help="component node log level: " + ", ".join(LOG_LEVELS) + " or a number")
    parser.add_argument("-r", "--remap-rule", action="append", dest="remap_rules", default=[],
                        help="component node remapping rules, in the 'from:=to' form")
    parser.add_argument("-p", "--parameter", action="append", dest="parameters", default=[],
                        help="component node parameters, in the 'name:=value' form (values in YAML)")
    parser.add_argument("-e", "--extra-argument", action="append", dest="extra_arguments", default=[],
                        help="extra arguments for the container, in the 'name:=value' form")


def _parameters(assignments: list[str], option: str) -> list[Any]:
    """rcl_interfaces Parameters from ``name:=value`` words, values typed as ``param set`` types them."""
    from rcl_interfaces.msg import Parameter, ParameterValue

    from roc.commands.param.set import parse_value
    from roc.ros.protocol import PARAMETER_TYPES, VALUE_FIELDS

    codes = {name: code for code, name in PARAMETER_TYPES.items()}
    parameters = []
    for assignment in assignments:
        name, separator, text = assignment.partition(":=")
        if not separator or not name:
            raise RocError(f"{option} '{assignment}': expected NAME:=VALUE")
        typed = parse_value(text)
        code = codes[typed["type"]]
        parameters.append(Parameter(name=name, value=ParameterValue(type=code, **{VALUE_FIELDS[code]: typed["value"]})))
    return parameters


def _log_level(text: str | None) -> int:
    if text is None:
        return 0
    if text.lower() in LOG_LEVELS:
        return LOG_LEVELS[text.lower()]
    if text.isdigit() and int(text) < 256:
        return int(text)
    raise RocError(f"--log-level '{text}': expected one of {', '.join(LOG_LEVELS)} or a number")


def load(opened: Session, name: str, args: argparse.Namespace, timeout: float = SERVICE_TIMEOUT) -> dict[str, Any]:
    """Load the component the command line describes into container ``name``: {uid, name}; ros2's
    error when the container refuses, or when it does not serve within ``timeout`` seconds."""
    from composition_interfaces.srv import LoadNode

    request = LoadNode.Request(package_name=args.package_name, plugin_name=args.plugin_name,
                               node_name=args.node_name or "", node_namespace=args.node_namespace or "",
                               log_level=_log_level(args.log_level), remap_rules=args.remap_rules,
                               parameters=_parameters(args.parameters, "--parameter"),
                               extra_arguments=_parameters(args.extra_arguments, "--extra-argument"))
    service = f"{name}/_container/load_node"
    try:
        response = call(opened, service, CONTAINER_SERVICES["_container/load_node"], request, timeout)
    except RocError:
        raise RocError(f"No 'load_node' service found for '{name}' container") from None
    if not response.success:
        raise RocError(f"Failed to load component: {response.error_message.capitalize()}")
    return {"uid": response.unique_id, "name": response.full_node_name}
