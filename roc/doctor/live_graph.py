"""The live-graph checks of ``roc doctor``: nodes sharing a name, QoS-incompatible or type-mismatched
endpoints, and topics published but not subscribed (or the reverse), from the daemon protocol's
``snapshot`` and ``topic_endpoints`` answers."""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from typing import Any

from roc.doctor.findings import Finding
from roc.ros import vendors
from roc.ros.present import is_hidden, qos_problems, topic_problems

CATEGORY = "graph"
SKIP_TOPICS = ("/parameter_events", "/rosout")  # every node has them, as ros2 doctor skips them

Ask = Callable[[str, dict[str, Any]], Any]


def _topics(graph: dict[str, Any]) -> list[dict[str, Any]]:
    return [t for t in graph["topics"] if t["name"] not in SKIP_TOPICS and not is_hidden(t["name"])]


def checks(ask: Ask) -> tuple[list[Finding], dict[str, Any]]:
    """The findings, and what was asked of the graph (for the reports)."""
    graph = ask("snapshot", {})
    findings = []
    names = Counter(n["full_name"] for n in graph["nodes"] if not n["name"].startswith("_"))
    for name, count in sorted(names.items()):
        if count > 1:
            findings.append(Finding(CATEGORY, "node names", "error", f"{count} nodes are named {name}",
                                    "give each node a unique name (parameters, services and node info mix them up)"))
    if not findings:
        findings.append(Finding(CATEGORY, "node names", "ok", f"{len(names)} node(s), each named once"))
    endpoints = {}
    for topic in _topics(graph):
        try:
            endpoints[topic["name"]] = ask("topic_endpoints", {"topic": topic["name"]})
        except Exception:  # noqa: BLE001 - the topic went away since the snapshot
            continue
    compatible = True
    for name, info in endpoints.items():
        for problem in topic_problems(info):
            compatible = False
            if problem["kind"] == "qos":
                check, text = "qos", (f"{name}: {problem['publisher']} -> {problem['subscriber']}: incompatible "
                                      f"{problem['policy']}: {problem['message']}")
            else:
                check, text = "types", f"{name}: {problem['message']}"
            findings.append(Finding(CATEGORY, check, "error", text, problem["fix"], details={"topic": name, **problem}))
    if compatible:
        findings.append(Finding(CATEGORY, "qos", "ok", f"{len(endpoints)} topic(s), every publisher and subscriber "
                                                       "compatible"))
    lonely = False
    for topic in _topics(graph):
        if topic["publishers"] and not topic["subscribers"]:
            lonely = True
            findings.append(Finding(CATEGORY, "topics", "warning", f"Publisher without subscriber detected on "
                                    f"{topic['name']}.", details={"topic": topic["name"]}))
        elif topic["subscribers"] and not topic["publishers"]:
            lonely = True
            findings.append(Finding(CATEGORY, "topics", "warning", f"Subscriber without publisher detected on "
                                    f"{topic['name']}.", details={"topic": topic["name"]}))
    if not lonely:
        findings.append(Finding(CATEGORY, "topics", "ok", "every topic has publishers and subscribers"))
    findings.append(middlewares(ask))
    return findings, {"graph": graph, "endpoints": endpoints}


def middlewares(ask: Ask) -> Finding:
    """The middlewares of the graph's nodes, told by the vendor id of their /rosout publishers' GIDs: a
    mixed domain (Fast DDS and Cyclone DDS nodes) works, but has a known way to crash a node."""
    try:
        rosout = ask("topic_endpoints", {"topic": "/rosout"})["publishers"]
    except Exception:  # noqa: BLE001 - no node publishes /rosout
        rosout = []
    nodes: Counter[str] = Counter()
    for endpoint in rosout:
        vendor = vendors.of_prefix(bytes(int(part, 16) for part in endpoint["gid"].split(".")[:2]))
        nodes[vendor.name if vendor else "another middleware"] += 1
    if len(nodes) <= 1:
        return Finding(CATEGORY, "middlewares", "ok", f"every node on {next(iter(nodes), 'one middleware')}")
    counts = ", ".join(f"{count} node(s) on {name}" for name, count in sorted(nodes.items()))
    return Finding(CATEGORY, "middlewares", "warning", f"a mixed domain: {counts}; topics interoperate, but a "
                   "Cyclone DDS client's service request can crash a Fast DDS node (ros2/rmw_cyclonedds#577), so "
                   "roc on Cyclone DDS asks no Fast DDS node", "run every process on one middleware "
                   "(RMW_IMPLEMENTATION), or ask Fast DDS nodes from a process on Fast DDS")


def reports(asked: dict[str, Any]) -> dict[str, list[tuple[str, str]]]:
    """ros2 doctor's TOPIC LIST and QOS COMPATIBILITY LIST."""
    topics: list[tuple[str, str]] = []
    for topic in _topics(asked["graph"]):
        topics += [("topic", topic["name"]), ("publisher count", str(topic["publishers"])),
                   ("subscriber count", str(topic["subscribers"]))]
    if not topics:
        topics = [("topic", "none"), ("publisher count", "0"), ("subscriber count", "0")]
    pairs: list[tuple[str, str]] = []
    for name, info in asked["endpoints"].items():
        for pub in info["publishers"]:
            for sub in info["subscribers"]:
                problems = qos_problems(pub, sub)
                pairs += [("topic [type]", f"{name} [{pub['topic_type']}]"), ("publisher node", pub["node_name"]),
                          ("subscriber node", sub["node_name"]),
                          ("compatibility status", "; ".join(p["message"] for p in problems) or "OK")]
    if not pairs:
        pairs = [("compatibility status", "No publisher/subscriber pairs found")]
    return {"TOPIC LIST": topics, "QOS COMPATIBILITY LIST": pairs}

