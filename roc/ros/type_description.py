"""A message type's definition from the nodes that use it (``roc interface show`` of a type that is not
installed here): every Jazzy node serves ``~/get_type_description`` (type_description_interfaces),
which answers for the types of its own endpoints, given the type's hash, with the ``.msg`` text of the
type and of every type it refers to.

The hash comes with each endpoint the graph lists, so the nodes asked are those with an endpoint of
the type; a type that is only nested in another (std_msgs/msg/Header in a PoseStamped) is found among
the types the topics' descriptions refer to.
"""

from __future__ import annotations

from typing import Any

from roc.errors import RocError
from roc.ros.protocol import full_name


def _endpoints(graph, topic: str) -> list:
    node = graph.node
    return [*node.get_publishers_info_by_topic(topic), *node.get_subscriptions_info_by_topic(topic)]


def _ask(graph, info) -> dict[str, Any] | None:
    """What the node of endpoint ``info`` says about the endpoint's type: {type, node, sources: {type:
    {encoding, text}}}, or None when it does not answer."""
    from type_description_interfaces.srv import GetTypeDescription

    node_name = full_name(info.node_namespace, info.node_name)
    request = GetTypeDescription.Request(type_name=info.topic_type, type_hash=str(info.topic_type_hash),
                                         include_type_sources=True)
    try:
        response = graph.call_node_service(node_name, "get_type_description", GetTypeDescription, request)
    except RocError:
        return None
    if not response.successful:
        return None
    sources = {s.type_name: {"encoding": s.encoding, "text": s.raw_file_contents} for s in response.type_sources}
    return {"type": info.topic_type, "node": node_name, "sources": sources}


def describe(graph, type_name: str) -> dict[str, Any]:
    """{type, node, sources} for message type ``type_name``: the first node with an endpoint of that type
    that answers, else the first description of a topic's type that refers to it."""
    topics = graph.node.get_topic_names_and_types()
    served = {name for name, _ in graph.node.get_service_names_and_types()}

    def described(info) -> dict[str, Any] | None:  # a node without the service is not waited for
        node_name = full_name(info.node_namespace, info.node_name)
        return _ask(graph, info) if f"{node_name}/get_type_description" in served else None

    carrying = [topic for topic, types in topics if type_name in types]
    for topic in carrying:
        for info in _endpoints(graph, topic):
            if info.topic_type == type_name and (found := described(info)):
                return found
    asked: set[str] = set()
    for topic, _ in topics:
        for info in _endpoints(graph, topic):
            if info.topic_type in asked or info.topic_type == type_name:
                continue
            found = described(info)
            if found is None:
                continue
            asked.add(info.topic_type)
            if type_name in found["sources"]:
                return {**found, "type": type_name}
    raise RocError(f"No node on the graph describes the type '{type_name}'")
