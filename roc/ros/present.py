"""Graph data as ros2 prints it, and roc's checks on it. Plain functions on the dicts of roc.ros.graph
(no rclpy here: the client side of a daemon query uses them)."""

from __future__ import annotations

from typing import Any


def is_hidden(name: str) -> bool:
    """ros2's rule: a name is hidden when one of its tokens starts with an underscore."""
    return any(token.startswith("_") for token in name.split("/"))


def _duration(ns: int | None) -> str:
    return "Infinite" if ns is None else f"{ns} nanoseconds"


def endpoint_lines(endpoint: dict[str, Any]) -> list[str]:
    qos = endpoint["qos"]
    history = qos["history"] if qos["history"] != "KEEP_LAST" else f"KEEP_LAST ({qos['depth']})"
    return [
        f"Node name: {endpoint['node_name']}",
        f"Node namespace: {endpoint['node_namespace']}",
        f"Topic type: {endpoint['topic_type']}",
        f"Topic type hash: {endpoint['topic_type_hash']}",
        f"Endpoint type: {endpoint['endpoint_type']}",
        f"GID: {endpoint['gid']}",
        "QoS profile:",
        f"  Reliability: {qos['reliability']}",
        f"  History (Depth): {history}",
        f"  Durability: {qos['durability']}",
        f"  Lifespan: {_duration(qos['lifespan_ns'])}",
        f"  Deadline: {_duration(qos['deadline_ns'])}",
        f"  Liveliness: {qos['liveliness']}",
        f"  Liveliness lease duration: {_duration(qos['liveliness_lease_duration_ns'])}",
    ]


def _longer(offered: int | None, requested: int | None) -> bool:
    """An offered period longer than the requested one (None is infinite)."""
    if requested is None:
        return False
    return offered is None or offered > requested


_LIVELINESS_ORDER = {"AUTOMATIC": 0, "MANUAL_BY_TOPIC": 1}


def qos_problems(publisher: dict[str, Any], subscriber: dict[str, Any]) -> list[dict[str, str]]:
    """Why this publisher and subscriber cannot match (DDS request/offer rules), with the fix."""
    offered, requested = publisher["qos"], subscriber["qos"]
    problems = []
    if offered["reliability"] == "BEST_EFFORT" and requested["reliability"] == "RELIABLE":
        problems.append({"policy": "reliability", "message": "publisher offers BEST_EFFORT, subscriber requests "
                         "RELIABLE", "fix": "make the subscriber BEST_EFFORT or the publisher RELIABLE"})
    if offered["durability"] == "VOLATILE" and requested["durability"] == "TRANSIENT_LOCAL":
        problems.append({"policy": "durability", "message": "publisher offers VOLATILE, subscriber requests "
                         "TRANSIENT_LOCAL", "fix": "make the subscriber VOLATILE or the publisher TRANSIENT_LOCAL"})
    if _longer(offered["deadline_ns"], requested["deadline_ns"]):
        problems.append({"policy": "deadline", "message": f"publisher offers a deadline of "
                         f"{_duration(offered['deadline_ns'])}, subscriber requests "
                         f"{_duration(requested['deadline_ns'])}",
                         "fix": "give the publisher a deadline no longer than the subscriber's, or lengthen the "
                                "subscriber's"})
    if _LIVELINESS_ORDER.get(offered["liveliness"], 0) < _LIVELINESS_ORDER.get(requested["liveliness"], 0):
        problems.append({"policy": "liveliness", "message": f"publisher offers {offered['liveliness']}, subscriber "
                         f"requests {requested['liveliness']}", "fix": f"make the subscriber {offered['liveliness']} "
                         f"or the publisher {requested['liveliness']}"})
    if _longer(offered["liveliness_lease_duration_ns"], requested["liveliness_lease_duration_ns"]):
        problems.append({"policy": "liveliness_lease_duration", "message": "publisher offers a lease of "
                         f"{_duration(offered['liveliness_lease_duration_ns'])}, subscriber requests "
                         f"{_duration(requested['liveliness_lease_duration_ns'])}",
                         "fix": "shorten the publisher's lease duration or lengthen the subscriber's"})
    return problems


def topic_problems(info: dict[str, Any]) -> list[dict[str, Any]]:
    """QoS-incompatible publisher/subscriber pairs and endpoints that disagree on the type or its hash."""
    problems = []
    for pub in info["publishers"]:
        for sub in info["subscribers"]:
            for problem in qos_problems(pub, sub):
                problems.append({"kind": "qos", "publisher": _who(pub), "subscriber": _who(sub), **problem})
    endpoints = info["publishers"] + info["subscribers"]
    kinds = {(e["topic_type"], e["topic_type_hash"]) for e in endpoints}
    if len(kinds) > 1:
        problems.append({"kind": "type", "policy": "type", "message": "endpoints disagree on the type: " + ", ".join(
            f"{_who(e)} {e['endpoint_type'].lower()} {e['topic_type']} ({e['topic_type_hash']})" for e in endpoints),
            "fix": "build every node against the same interface definitions"})
    return problems


def _who(endpoint: dict[str, Any]) -> str:
    namespace = endpoint["node_namespace"].rstrip("/")
    return f"{namespace}/{endpoint['node_name']}"


def problem_line(problem: dict[str, Any]) -> str:
    if problem["kind"] == "qos":
        return (f"QoS incompatible ({problem['policy']}): {problem['publisher']} -> {problem['subscriber']}: "
                f"{problem['message']}; {problem['fix']}")
    return f"type mismatch: {problem['message']}; {problem['fix']}"
