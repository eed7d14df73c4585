"""Topics from one ROS domain republished in another, as serialised CDR (never deserialised).

Each bridged topic gets a raw subscription in the source domain, with QoS following its publishers
there (reliable or transient local only when every publisher is, as ``topic echo`` subscribes), and a
publisher in the destination domain that offers the same reliability and durability, so a transient
local topic stays transient local on the other side. Topics are looked for again every second, so a
publisher that appears later is picked up. The bridge never prints: ``run`` yields status events.
"""

from __future__ import annotations

import re
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from roc.ros.dataplane import qos_profile
from roc.ros.graph import Graph
from roc.ros.types import message_class

SCAN_SECONDS = 1.0
BRIDGE_NODE = "_roc_bridge"


@dataclass
class Route:
    """One topic to bridge: ``topic`` in ``from_domain`` to ``remap`` (default the same name) in ``to_domain``."""

    topic: str
    from_domain: int
    to_domain: int
    type: str | None = None  # else the type the source graph gives the topic
    remap: str | None = None
    qos: dict[str, Any] = field(default_factory=dict)  # overrides: reliability, durability, history, depth

    @property
    def target(self) -> str:
        return self.remap or self.topic


@dataclass
class _Link:
    route: Route
    type: str
    subscription: Any
    publisher: Any
    count: int = 0


class DomainBridge:
    def __init__(self, routes: list[Route], include: list[str] = (), exclude: list[str] = (),
                 everything: tuple[int, int] | None = None):
        """``routes``: the topics named; ``everything`` (from, to): also every topic of the source domain
        whose name matches one of ``include`` (all when empty) and none of ``exclude``."""
        self.routes = list(routes)
        self.include = [re.compile(pattern) for pattern in include]
        self.exclude = [re.compile(pattern) for pattern in exclude]
        self.everything = everything
        domains = {d for r in self.routes for d in (r.from_domain, r.to_domain)} | set(everything or ())
        self.graphs = {domain: Graph(f"{BRIDGE_NODE}_{domain}", domain_id=domain) for domain in sorted(domains)}
        self.links: dict[tuple[int, str, int], _Link] = {}
        self.lock = threading.Lock()

    def close(self) -> None:
        for graph in self.graphs.values():
            graph.close()

    def _wanted(self) -> list[Route]:
        routes = list(self.routes)
        if self.everything is not None:
            source, target = self.everything
            named = {r.topic for r in routes if r.from_domain == source}
            for name, _types in self.graphs[source].node.get_topic_names_and_types():
                if name in named or any(p.search(name) for p in self.exclude):
                    continue
                if not self.include or any(p.search(name) for p in self.include):
                    routes.append(Route(name, source, target))
        return routes

    def _publishers(self, route: Route) -> list:
        """The source-side publishers of the route's topic, other than bridges'."""
        return [p for p in self.graphs[route.from_domain].node.get_publishers_info_by_topic(route.topic)
                if not p.node_name.startswith(BRIDGE_NODE)]

    def _connect(self, route: Route) -> dict[str, Any] | None:
        """Bridge the route once its topic has a publisher (and a type); its ``bridging`` event."""
        publishers = self._publishers(route)
        source = self.graphs[route.from_domain].node
        type_name = route.type or next((t[0] for n, t in source.get_topic_names_and_types() if n == route.topic), None)
        if not publishers or type_name is None:
            return None
        cls = message_class(type_name)
        incoming = qos_profile({"profile": "default", **route.qos}, publishers)
        outgoing = QoSProfile(depth=incoming.depth, history=incoming.history, reliability=incoming.reliability,
                              durability=incoming.durability)
        publisher = self.graphs[route.to_domain].node.create_publisher(cls, route.target, outgoing)
        link = _Link(route, type_name, None, publisher)

        def forward(data: bytes) -> None:
            publisher.publish(data)
            link.count += 1
        link.subscription = source.create_subscription(cls, route.topic, forward, incoming, raw=True)
        self.links[(route.from_domain, route.topic, route.to_domain)] = link
        return {"event": "bridging", "topic": route.topic, "target": route.target, "type": type_name,
                "from_domain": route.from_domain, "to_domain": route.to_domain,
                "reliability": "reliable" if incoming.reliability == ReliabilityPolicy.RELIABLE else "best_effort",
                "durability": ("transient_local" if incoming.durability == DurabilityPolicy.TRANSIENT_LOCAL
                               else "volatile")}

    def run(self, period: float = 1.0) -> Iterator[dict[str, Any]]:
        """``bridging`` events as topics are bridged and a ``rates`` event every ``period`` seconds
        (messages a second per bridged topic), until closed."""
        last, counts = time.monotonic(), {}
        next_scan = 0.0
        while True:
            now = time.monotonic()
            if now >= next_scan:
                next_scan = now + SCAN_SECONDS
                for route in self._wanted():
                    if (route.from_domain, route.topic, route.to_domain) not in self.links:
                        event = self._connect(route)
                        if event is not None:
                            yield event
            time.sleep(min(period, SCAN_SECONDS) / 2)
            now = time.monotonic()
            if now - last >= period:
                rates = {}
                for key, link in self.links.items():
                    rates[f"{link.route.topic} ({key[0]}->{key[2]})"] = (link.count - counts.get(key, 0)) / (now - last)
                    counts[key] = link.count
                last = now
                yield {"event": "rates", "rates": rates}
