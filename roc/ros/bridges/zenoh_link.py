"""A ROS domain joined to a Zenoh session: ``roc bridge --zenoh-listen/--zenoh-connect``.

Two links (two processes, on two hosts or in two domains) connected over Zenoh carry the selected
topics both ways, as serialised CDR (never deserialised). Each selected local topic that has a
publisher other than a bridge's gets a raw subscription (QoS following its publishers, as the domain
bridge does) whose messages are put on the Zenoh key ``roc/topic/NAME`` (``roc/latched/NAME`` for
transient local topics). Every sample carries, as its Zenoh attachment, the topic's type, reliability,
durability and depth, so the far side creates a publisher with the same name, type and QoS without
guessing. The link also announces each topic it carries out with a Zenoh liveliness token
(``roc/announce/ZID/NAME/-/TYPE/RELIABILITY/DURABILITY/DEPTH``: ``-`` is no ROS name), so the far side
creates the publisher before the first message, and its subscribers have matched it by then. A
transient local topic's last ``depth`` messages stay in a Zenoh publication cache, which a far side
that joins later queries (a Zenoh advanced subscriber with history), so latched messages reach it too.
Topics are looked for again every second, so a publisher that appears later is picked up. Services
(and actions' services) named on both sides are offered by the side with the server
(roc.ros.bridges.zenoh_services), announced the same way (``roc/announce/ZID/NAME/-/TYPE``).

No loops: the link forwards only topics with a publisher other than a bridge's (so a topic the link
only republishes goes no further); the link's participant ignores its own endpoints (Fast DDS's
BRIDGE_PROFILE, or the user's, checked by ``loop_guard``), so what it publishes never reaches its
own subscriptions even when a topic has publishers on both sides; and its Zenoh subscribers take
remote samples only, so a link never receives its own puts. The link never prints: ``run`` yields
status events.
"""

from __future__ import annotations

import json
import os
import queue
import re
import threading
import time
from collections import deque
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import zenoh
import zenoh.ext
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

from roc.errors import RocError, UsageError
from roc.ros.bridges.domains import (
    BRIDGE_NODE,
    Route,
    TopicFilter,
    action_routes,
    loop_guard,
    qos_name,
    receive_profile,
)
from roc.ros.bridges.zenoh_services import ServiceOffer, ServiceProxy
from roc.ros.dataplane import qos_profile
from roc.ros.graph import Graph
from roc.ros.types import message_class
from roc.ros.vendors.fastdds import BRIDGE_PROFILE

SCAN_SECONDS = 1.0
LINK_NODE = f"{BRIDGE_NODE}_zenoh"  # a bridge's node: domain bridges leave its topics alone too
VOLATILE_PREFIX = "roc/topic"
LATCHED_PREFIX = "roc/latched"
ANNOUNCE_PREFIX = "roc/announce"
# A link's socket is polled by Zenoh's net runtime and its messages decoded on the rx runtime, so
# each message woke two threads; with rx handed over to net it wakes one (at 5 kHz the receiving
# bridge's threads woke 1.6 times per message instead of 3.1; over eight interleaved benchmark runs
# the link added 0.2 ms less on average, though single runs vary by more).
RUNTIME = "(rx: (handover: net))"
IP_ENDPOINT = re.compile(r"(tcp|udp|tls|quic|ws)/(\[[0-9a-fA-F:.]+\]|[^/:?#\[\]]+):(\d{1,5})([?#].*)?")


def _zenoh_message(error: Exception) -> str:
    """Zenoh's error text without the Rust source locations and parser wrappers it adds."""
    text = re.sub(r" at /\S+\.rs:\d+\.?", "", str(error)).strip()
    quoted = re.search(r'msg: "(.*?)"', text)
    return (quoted.group(1) if quoted else text).splitlines()[0]


def _check_endpoint(option: str, endpoint: str) -> None:
    """An IP endpoint needs a host and a port: Zenoh itself would only find out when it connects."""
    protocol = endpoint.split("/", 1)[0]
    match = IP_ENDPOINT.fullmatch(endpoint)
    if protocol in ("tcp", "udp", "tls", "quic", "ws") and not (match and int(match.group(3)) <= 65535):
        raise UsageError(f"{option} {endpoint}: expected {protocol}/HOST:PORT, e.g. {protocol}/127.0.0.1:7447")


def zenoh_config(listen: list[str], connect: list[str], path: Path | None = None) -> zenoh.Config:
    """A peer's configuration: ``path`` (a Zenoh JSON5 file, where TLS is configured) or defaults
    without multicast scouting (the far side is named by an endpoint), plus the endpoints given, and
    timestamps on (the publication caches of transient local topics need them)."""
    if path is not None:
        try:
            config = zenoh.Config.from_file(str(path))
        except zenoh.ZError as error:
            raise UsageError(f"{path}: not a Zenoh configuration: {_zenoh_message(error)}") from None
    else:
        config = zenoh.Config()
        config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("timestamping/enabled", "true")
    for option, key, endpoints in (("--zenoh-listen", "listen/endpoints", listen),
                                   ("--zenoh-connect", "connect/endpoints", connect)):
        for endpoint in endpoints:
            _check_endpoint(option, endpoint)
            try:  # one at a time, so that the error names the endpoint
                config.insert_json5(key, json.dumps([endpoint]))
            except zenoh.ZError as error:
                raise UsageError(f"{option} {endpoint}: {_zenoh_message(error)} (e.g. tcp/127.0.0.1:7447)") from None
        if endpoints:
            config.insert_json5(key, json.dumps(endpoints))
    return config


def open_session(config: zenoh.Config) -> zenoh.Session:
    """A Zenoh session, its runtimes set up (once per process) with RUNTIME unless the user set
    ZENOH_RUNTIME."""
    os.environ.setdefault("ZENOH_RUNTIME", RUNTIME)
    try:
        return zenoh.open(config)
    except zenoh.ZError as error:
        raise UsageError(f"cannot open the Zenoh session: {_zenoh_message(error)}") from None


def _announcement(zid: str, name: str, header: dict[str, Any]) -> str:
    """A topic's (type and QoS) or a service's (type only) announcement key."""
    qos = [header["reliability"], header["durability"], str(header["depth"])] if "depth" in header else []
    return "/".join([f"{ANNOUNCE_PREFIX}/{zid}{name}", "-", header["type"], *qos])


def _announced(key: str) -> tuple[str, str, dict[str, Any]]:
    """The announcing link's zid, the topic or service and its header."""
    parts = key.split("/")
    separator = parts.index("-", 3)
    package, kind, type_name, *qos = parts[separator + 1:]
    header: dict[str, Any] = {"type": f"{package}/{kind}/{type_name}"}
    if qos:
        header.update(reliability=qos[0], durability=qos[1], depth=int(qos[2]))
    return parts[2], "/" + "/".join(parts[3:separator]), header


@dataclass
class _Topic:
    """A topic the link carries one way: ``direction`` "out" (ROS to Zenoh) or "in" (Zenoh to ROS)."""

    name: str
    type: str
    direction: str
    endpoint: Any  # the raw subscription (out) or the publisher (in)
    count: int = 0


class ZenohLink:
    def __init__(self, domain: int, topics: list[str], include: Sequence[str] = (), exclude: Sequence[str] = (),
                 everything: bool = False, config: zenoh.Config | None = None, services: Sequence[str] = (),
                 actions: Sequence[str] = ()) -> None:
        """Carry ``topics`` (and with ``everything`` each topic whose name matches one of ``include``, all
        when empty, and none of ``exclude``), ``services`` and ``actions`` between ROS domain ``domain`` and
        the Zenoh peers ``config`` names, both ways (a service or action is offered by the side with its
        server; an action is its three services and two topics)."""
        parts = [part for name in actions for part in action_routes(Route(name, domain, domain, kind="action"))]
        topics = [*topics, *(part.name for part in parts if part.kind == "topic")]
        self.domain = domain
        self.topics = set(topics)
        self.wanted = TopicFilter(include, exclude)
        self.everything = everything
        self.events: queue.SimpleQueue[dict[str, Any]] = queue.SimpleQueue()
        self.outgoing: dict[str, _Topic] = {}
        self.incoming: dict[str, _Topic] = {}
        self.services = {*services, *(part.name for part in parts if part.kind == "service")}
        self.offers: dict[str, ServiceOffer] = {}
        self.proxies: dict[str, ServiceProxy] = {}
        self.errors: deque[str] = deque()
        self.ignored: set[str] = set()  # remote topics not selected, or whose type this side cannot load
        self.lock = threading.Lock()
        self.session = open_session(config or zenoh_config([], []))
        self.graph: Graph | None = None
        self.subscribers: list[Any] = []  # zenoh subscribers, each with undeclare()
        self.tokens: list[zenoh.LivelinessToken] = []
        try:
            # every topic may have publishers on both sides, so the link may both publish and subscribe it
            loop_guard([Route(name, domain, domain) for name in topics] + [Route("*", domain, domain)] * everything)
            self.graph = Graph(f"{LINK_NODE}_{domain}", domain_id=domain, events=True, profile=BRIDGE_PROFILE)
            self.zid = str(self.session.zid())
            self.subscribers = [
                self.session.declare_subscriber(f"{VOLATILE_PREFIX}/**", self._received,
                                                allowed_origin=zenoh.Locality.REMOTE),
                zenoh.ext.declare_advanced_subscriber(
                    self.session, f"{LATCHED_PREFIX}/**", self._received, allowed_origin=zenoh.Locality.REMOTE,
                    history=zenoh.ext.HistoryConfig(detect_late_publishers=True)),
                self.session.liveliness().declare_subscriber(f"{ANNOUNCE_PREFIX}/**", self._announced, history=True)]
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        """Stop carrying: the Zenoh session closed, the rclpy context shut down."""
        for subscriber in self.subscribers:  # nothing more comes in
            subscriber.undeclare()
        services: list[ServiceOffer | ServiceProxy] = [*self.offers.values(), *self.proxies.values()]
        for service in services:
            service.close()
        if self.graph is not None:
            self.graph.close()
        if not self.session.is_closed():
            self.session.close()

    def selected(self, topic: str) -> bool:
        if topic in self.topics:
            return True
        return self.everything and self.wanted(topic)

    # -- ROS to Zenoh -------------------------------------------------------------------------------
    def _live_graph(self) -> Graph:
        """The participant, which exists from the end of __init__ until close."""
        assert self.graph is not None, "the link is closed"
        return self.graph

    def _scan(self) -> None:
        """Carry out each selected local topic that has a publisher other than a bridge's."""
        node = self._live_graph().node
        for name, types in node.get_topic_names_and_types():
            if name in self.outgoing or not self.selected(name):
                continue
            publishers = [p for p in node.get_publishers_info_by_topic(name)
                          if not p.node_name.startswith(BRIDGE_NODE)]
            if publishers:
                self._carry_out(name, types[0], publishers)
        service_types = dict(node.get_service_names_and_types())
        for name in sorted(self.services - set(self.offers) - set(self.proxies)):
            servers = [n for n, ns in node.get_node_names_and_namespaces() if not n.startswith(BRIDGE_NODE)
                       and any(s == name for s, _ in node.get_service_names_and_types_by_node(n, ns))]
            if servers and name in service_types:
                type_name = service_types[name][0]
                with self.lock:
                    self.offers[name] = ServiceOffer(self.session, self._live_graph(), name, type_name, self.errors)
                self.tokens.append(self.session.liveliness().declare_token(
                    _announcement(self.zid, name, {"type": type_name})))
                self.events.put({"event": "bridging", "kind": "service", "direction": "out", "topic": name,
                                 "type": type_name, "domain": self.domain})

    def _carry_out(self, name: str, type_name: str, publishers: list) -> None:
        offered = qos_profile({"profile": "default"}, publishers)
        incoming = receive_profile(offered)
        reliability, durability = qos_name(incoming)
        reliable = reliability == "reliable"
        congestion = zenoh.CongestionControl.BLOCK if reliable else zenoh.CongestionControl.DROP
        delivery = zenoh.Reliability.RELIABLE if reliable else zenoh.Reliability.BEST_EFFORT
        publisher: zenoh.Publisher | zenoh.ext.AdvancedPublisher
        if durability == "transient_local":
            publisher = zenoh.ext.declare_advanced_publisher(
                self.session, f"{LATCHED_PREFIX}{name}", cache=zenoh.ext.CacheConfig(offered.depth),
                publisher_detection=True, congestion_control=congestion, reliability=delivery)
        else:
            publisher = self.session.declare_publisher(f"{VOLATILE_PREFIX}{name}", congestion_control=congestion,
                                                       reliability=delivery)
        header = {"type": type_name, "reliability": reliability, "durability": durability, "depth": offered.depth}
        attachment = zenoh.ZBytes(json.dumps(header).encode())
        topic = _Topic(name, type_name, "out", None)

        def forward(data: bytes) -> None:
            publisher.put(data, attachment=attachment)
            topic.count += 1
        topic.endpoint = self._live_graph().node.create_subscription(message_class(type_name), name, forward, incoming,
                                                             raw=True)
        self.outgoing[name] = topic
        self.tokens.append(self.session.liveliness().declare_token(_announcement(self.zid, name, header)))
        self.events.put({"event": "bridging", "kind": "topic", "direction": "out", "topic": name,
                         "type": type_name, "domain": self.domain, "reliability": reliability,
                         "durability": durability})

    # -- Zenoh to ROS -------------------------------------------------------------------------------
    def _received(self, sample: zenoh.Sample) -> None:
        """A remote sample (in a Zenoh thread): published in the local domain (the publisher created
        with the type and QoS its attachment gives, if the announcement has not come first)."""
        key = str(sample.key_expr)
        name = key[key.index("/", len("roc/")):]
        topic = self.incoming.get(name)
        if topic is None and sample.attachment is not None:
            topic = self._carry_in(name, json.loads(sample.attachment.to_bytes()))
        if topic is not None:
            topic.endpoint.publish(sample.payload.to_bytes())
            topic.count += 1

    def _announced(self, sample: zenoh.Sample) -> None:
        """A link's announcement of a topic it carries (in a Zenoh thread): the publisher made ready."""
        zid, name, header = _announced(str(sample.key_expr))
        if sample.kind != zenoh.SampleKind.PUT or zid == self.zid:
            return
        if "depth" in header:
            self._carry_in(name, header)
        elif name in self.services:
            self._serve_in(name, header["type"])

    def _serve_in(self, name: str, type_name: str) -> None:
        """Serve a far side's service in the local domain (once)."""
        with self.lock:
            if name in self.proxies or name in self.offers:
                return
            try:
                self.proxies[name] = ServiceProxy(self.session, self._live_graph(), name, type_name,
                                                  f"{LINK_NODE}_{self.domain}_service_{len(self.proxies)}", self.errors)
            except RocError as error:
                self.errors.append(f"{name}: cannot serve it here: {error}")
                return
        self.events.put({"event": "bridging", "kind": "service", "direction": "in", "topic": name,
                         "type": type_name, "domain": self.domain})

    def _carry_in(self, name: str, header: dict[str, Any]) -> _Topic | None:
        """The local publisher of a selected remote topic (None if not selected or its type is unknown
        here), created with the header's type and QoS once."""
        with self.lock:
            if name in self.incoming or name in self.ignored:
                return self.incoming.get(name)
            if not self.selected(name):
                self.ignored.add(name)
                return None
            return self._publisher_for(name, header)

    def _publisher_for(self, name: str, header: dict[str, Any]) -> _Topic | None:
        try:
            cls = message_class(header["type"])
        except RocError as error:
            self.ignored.add(name)
            self.errors.append(f"{name}: cannot publish it here: {error}")
            return None
        profile = QoSProfile(depth=header["depth"],
                             reliability=ReliabilityPolicy.get_from_short_key(header["reliability"]),
                             durability=DurabilityPolicy.get_from_short_key(header["durability"]))
        topic = _Topic(name, header["type"], "in", self._live_graph().node.create_publisher(cls, name, profile))
        self.incoming[name] = topic
        self.events.put({"event": "bridging", "kind": "topic", "direction": "in", "topic": name,
                         "type": header["type"], "domain": self.domain, "reliability": header["reliability"],
                         "durability": header["durability"]})
        return topic

    # -- status -------------------------------------------------------------------------------------
    def _peers(self) -> set[str]:
        return {str(zid) for zid in self.session.info.peers_zid()}

    def run(self, period: float = 1.0) -> Iterator[dict[str, Any]]:
        """A ``session`` event, then ``peer`` events as Zenoh peers come and go, ``bridging`` events as
        topics are carried out or in, ``error`` events, and a ``rates`` event every ``period`` seconds
        (messages or calls a second per topic or service and direction), until closed."""
        yield {"event": "session", "zid": self.zid, "domain": self.domain}
        peers: set[str] = set()
        last, counts = time.monotonic(), dict[str, int]()
        next_scan = 0.0
        while True:
            now = time.monotonic()
            if now >= next_scan:
                next_scan = now + SCAN_SECONDS
                self._scan()
                current = self._peers()
                for zid in sorted(current ^ peers):
                    yield {"event": "peer", "zid": zid, "connected": zid in current}
                peers = current
            while not self.events.empty():
                yield self.events.get()
            while self.errors:
                yield {"event": "error", "message": self.errors.popleft()}
            time.sleep(min(period, SCAN_SECONDS) / 4)
            now = time.monotonic()
            if now - last >= period:
                rates = {}
                carried: list[tuple[str, _Topic | ServiceOffer | ServiceProxy]] = [(f"{t.name} ({t.direction})", t)
                           for t in [*self.outgoing.values(), *self.incoming.values()]]
                carried += [(f"service {s.name} ({way})", s) for way, services
                            in (("out", self.offers), ("in", self.proxies)) for s in services.values()]
                for key, counted in carried:
                    rates[key] = (counted.count - counts.get(key, 0)) / (now - last)
                    counts[key] = counted.count
                last = now
                yield {"event": "rates", "rates": rates}
