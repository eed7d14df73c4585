"""Topics and services from one ROS domain served in another, as domain_bridge does.

Each bridged topic gets a raw subscription in the source domain, with QoS following its publishers
there (reliable or transient local only when every publisher is, as ``topic echo`` subscribes), and a
publisher in the destination domain that offers the same reliability and durability, so a transient
local topic stays transient local on the other side. Messages pass as serialised CDR, never
deserialised. A bridged service gets a server in the destination domain that forwards each request to
the source domain's server and returns its response. Topics and services are looked for again every
second, so those that appear later are picked up. The bridge never prints: ``run`` yields status events.

Bridging both ways: each domain has one participant in this process, holding the publisher of one
direction and the subscription of the other. Fast DDS's ``fastdds.ignore_local_endpoints`` keeps them
from matching (rcl's ``ignore_local_publications``, which rclpy cannot set), so nothing the bridge
publishes comes back to it: the bridge's participants take BRIDGE_PROFILE, and ``loop_guard`` checks
a profile the user chose instead.
"""

from __future__ import annotations

import os
import re
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from roc.errors import UsageError
from roc.ros.bridges.services import ServiceLink
from roc.ros.dataplane import RECEIVE_DEPTH, qos_profile
from roc.ros.graph import Graph
from roc.ros.protocol import middleware
from roc.ros.types import message_class
from roc.ros.vendors.fastdds import BRIDGE_PROFILE, users_profile

SCAN_SECONDS = 1.0
BRIDGE_NODE = "_roc_bridge"
IGNORE_LOCAL_PROPERTY = "fastdds.ignore_local_endpoints"


@dataclass(frozen=True)
class Route:
    """One topic, service or action to bridge: ``name`` in ``from_domain`` to ``remap`` (default the
    same name) in ``to_domain``; a service's or action's server is in ``from_domain``."""

    name: str
    from_domain: int
    to_domain: int
    type: str | None = None  # else the type the source graph gives it
    remap: str | None = None
    qos: dict[str, Any] = field(default_factory=dict, hash=False)  # reliability, durability, history, depth, ...
    kind: str = "topic"  # or "service", "action" (see action_routes)

    @property
    def target(self) -> str:
        return self.remap or self.name

    @property
    def key(self) -> tuple[str, int, str, int]:
        return (self.kind, self.from_domain, self.name, self.to_domain)

    def swapped(self) -> Route:
        """The same route with its domains swapped (domain_bridge's ``reversed``)."""
        return replace(self, from_domain=self.to_domain, to_domain=self.from_domain)


class TopicFilter:
    """``--include``/``--exclude``: a name passes when it matches one of ``include`` (any name when
    empty) and none of ``exclude`` (regular expressions, searched)."""

    def __init__(self, include: Sequence[str] = (), exclude: Sequence[str] = ()) -> None:
        try:
            self.include = [re.compile(pattern) for pattern in include]
            self.exclude = [re.compile(pattern) for pattern in exclude]
        except re.error as error:
            raise UsageError(f"--include/--exclude: invalid regular expression '{error.pattern!s}': {error}") from None

    def __call__(self, name: str) -> bool:
        return (not any(p.search(name) for p in self.exclude)
                and (not self.include or any(p.search(name) for p in self.include)))


def action_routes(action: Route) -> list[Route]:
    """An action is three services and two topics (``NAME/_action/...``); bridging those bridges it."""
    def part(suffix: str, kind: str) -> Route:
        return replace(action, name=f"{action.name}/_action/{suffix}", type=None, kind=kind,
                       remap=f"{action.remap}/_action/{suffix}" if action.remap else None)
    return ([part(suffix, "service") for suffix in ("send_goal", "cancel_goal", "get_result")]
            + [part(suffix, "topic") for suffix in ("feedback", "status")])


def two_way(routes: list[Route]) -> list[str]:
    """Names a participant both publishes and subscribes to: those need the loop guard (a route named
    ``*`` stands for ``--all``)."""
    published = {(r.to_domain, r.target) for r in routes if r.kind == "topic"}
    return sorted({r.name for r in routes if r.kind == "topic"
                   and ((r.from_domain, r.name) in published or (r.from_domain, "*") in published
                        or (r.name == "*" and any(d == r.from_domain for d, _ in published)))})


def loop_guard(routes: list[Route], environment: Mapping[str, str] = os.environ) -> None:
    """Keep the bridge's own publications from reaching its subscriptions (see the module docstring):
    the bridge's Graphs take BRIDGE_PROFILE, unless the user gave a profile, which must then set the
    property when a topic is bridged both ways; other middlewares cannot bridge both ways."""
    looping = two_way(routes)
    rmw = middleware(environment)
    if looping and not rmw.startswith("rmw_fastrtps"):
        raise UsageError(f"{looping[0]}: bridging both ways needs Fast DDS (RMW_IMPLEMENTATION=rmw_fastrtps_cpp), "
                         f"not {rmw}: {rmw} cannot keep the bridge from receiving its own messages")
    own = users_profile(environment)
    if own is not None and looping:
        try:
            text = Path(own).read_text()
        except OSError as error:
            raise UsageError(f"{own}: cannot read the Fast DDS profile ({error.strerror})") from None
        if IGNORE_LOCAL_PROPERTY not in text:
            raise UsageError(f"{own}: bridging {looping[0]} both ways needs the participant property "
                             f"{IGNORE_LOCAL_PROPERTY}=true in this Fast DDS profile (see {BRIDGE_PROFILE})")


def receive_profile(offered: QoSProfile) -> QoSProfile:
    """A bridge's subscription for what is ``offered``: the same reliability and durability, a deep queue."""
    return QoSProfile(depth=max(offered.depth, RECEIVE_DEPTH), history=offered.history,
                      reliability=offered.reliability, durability=offered.durability)


def qos_name(profile: QoSProfile) -> tuple[str, str]:
    return ("reliable" if profile.reliability == ReliabilityPolicy.RELIABLE else "best_effort",
            "transient_local" if profile.durability == DurabilityPolicy.TRANSIENT_LOCAL else "volatile")


@dataclass
class _TopicLink:
    route: Route
    type: str
    subscription: Any
    publisher: Any
    count: int = 0


class DomainBridge:
    def __init__(self, routes: list[Route], include: Sequence[str] = (), exclude: Sequence[str] = (),
                 everything: tuple[int, int] | None = None):
        """``routes``: the topics and services named; ``everything`` (from, to): also every topic of the
        source domain whose name matches one of ``include`` (all when empty) and none of ``exclude``.
        Checks the ``loop_guard``; make it the process's first participant (Fast DDS reads its profile once)."""
        self.routes = [part for r in routes for part in (action_routes(r) if r.kind == "action" else [r])]
        self.wanted = TopicFilter(include, exclude)
        self.everything = everything
        loop_guard(self.routes + ([Route("*", *everything)] if everything else []))
        domains = {d for r in self.routes for d in (r.from_domain, r.to_domain)} | set(everything or ())
        self.graphs = {domain: Graph(f"{BRIDGE_NODE}_{domain}", domain_id=domain, events=True, profile=BRIDGE_PROFILE)
                       for domain in sorted(domains)}
        self.links: dict[tuple, _TopicLink | ServiceLink] = {}

    def close(self) -> None:
        for link in self.links.values():
            if isinstance(link, ServiceLink):
                link.close()
        for graph in self.graphs.values():
            graph.close()

    def _wanted(self) -> list[Route]:
        routes = list(self.routes)
        if self.everything is not None:
            source, target = self.everything
            named = {r.name for r in routes if r.from_domain == source and r.kind == "topic"}
            found = self.graphs[source].node.get_topic_names_and_types()
            routes += [Route(name, source, target) for name, _types in found if name not in named and self.wanted(name)]
        return routes

    def _source_type(self, route: Route) -> str | None:
        node = self.graphs[route.from_domain].node
        pairs = node.get_topic_names_and_types() if route.kind == "topic" else node.get_service_names_and_types()
        return route.type or next((types[0] for name, types in pairs if name == route.name), None)

    def _connect_topic(self, route: Route) -> dict[str, Any] | None:
        """Bridge the topic once it has a publisher other than a bridge (and a type); its ``bridging`` event."""
        source = self.graphs[route.from_domain].node
        publishers = [p for p in source.get_publishers_info_by_topic(route.name)
                      if not p.node_name.startswith(BRIDGE_NODE)]
        type_name = self._source_type(route)
        if not publishers or type_name is None:
            return None
        cls = message_class(type_name)
        outgoing = qos_profile({"profile": "default", **route.qos}, publishers)
        incoming = receive_profile(outgoing)
        publisher = self.graphs[route.to_domain].node.create_publisher(cls, route.target, outgoing)
        link = _TopicLink(route, type_name, None, publisher)

        def forward(data: bytes) -> None:
            publisher.publish(data)
            link.count += 1
        link.subscription = source.create_subscription(cls, route.name, forward, incoming, raw=True)
        self.links[route.key] = link
        reliability, durability = qos_name(incoming)
        return {**self._described(route, type_name), "reliability": reliability, "durability": durability}

    def _connect_service(self, route: Route) -> dict[str, Any] | None:
        """Serve the service in the destination domain once a server other than a bridge's offers it."""
        source = self.graphs[route.from_domain].node
        type_name = self._source_type(route)
        servers = [n for n, ns in source.get_node_names_and_namespaces() if not n.startswith(BRIDGE_NODE)
                   and any(s == route.name for s, _ in source.get_service_names_and_types_by_node(n, ns))]
        if not servers or type_name is None:
            return None
        self.links[route.key] = ServiceLink(route.name, route.target, type_name, self.graphs[route.from_domain],
                                            self.graphs[route.to_domain],
                                            f"{BRIDGE_NODE}_{route.to_domain}_service_{len(self.links)}")
        return self._described(route, type_name)

    @staticmethod
    def _described(route: Route, type_name: str) -> dict[str, Any]:
        return {"event": "bridging", "kind": route.kind, "topic": route.name, "target": route.target,
                "type": type_name, "from_domain": route.from_domain, "to_domain": route.to_domain}

    def run(self, period: float = 1.0) -> Iterator[dict[str, Any]]:
        """``bridging`` events as topics and services are bridged, ``error`` events (a bridged call that
        found no server) and a ``rates`` event every ``period`` seconds (messages or calls a second per
        bridged name), until closed."""
        last, counts = time.monotonic(), dict[tuple, int]()
        next_scan = 0.0
        connect = {"topic": self._connect_topic, "service": self._connect_service}
        while True:
            now = time.monotonic()
            if now >= next_scan:
                next_scan = now + SCAN_SECONDS
                for route in self._wanted():
                    if route.key not in self.links:
                        event = connect[route.kind](route)
                        if event is not None:
                            yield event
            for link in self.links.values():
                while isinstance(link, ServiceLink) and link.errors:
                    yield {"event": "error", "message": link.errors.popleft()}
            time.sleep(min(period, SCAN_SECONDS) / 2)
            now = time.monotonic()
            if now - last >= period:
                rates = {}
                for key, link in self.links.items():
                    kind, source, name, target = key
                    label = f"{'service ' if kind == 'service' else ''}{name} ({source}->{target})"
                    rates[label] = (link.count - counts.get(key, 0)) / (now - last)
                    counts[key] = link.count
                last = now
                yield {"event": "rates", "rates": rates}

