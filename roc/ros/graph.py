"""The ROS graph as plain data: the one place that creates an rclpy context and node.

rcl reads the discovery environment itself (``ROS_DOMAIN_ID``, ``RMW_IMPLEMENTATION``,
``ROS_AUTOMATIC_DISCOVERY_RANGE``, ``ROS_STATIC_PEERS``, ``ROS_LOCALHOST_ONLY``), so a ``Graph`` sees
what ros2 sees in the same environment. Every query returns dicts and lists (JSON-ready) and
never prints; ``handle`` maps a request (method name and parameters) to one of them, for the
daemon and for daemon-less runs alike.
"""

from __future__ import annotations

import contextlib
import logging
import os
import threading
import time
import traceback
from collections.abc import Callable, Iterator, Mapping, Sequence
from functools import partial
from pathlib import Path
from typing import Any

import rclpy
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from rclpy.node import Node, NodeNameNonExistentError
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions
from rclpy.task import Future

from roc.errors import RocError
from roc.ros import vendors
from roc.ros.discovery import (
    DISCOVERY_TOPIC,
    UNKNOWN_NODE,
    LocalParticipantProbe,
    Told,
    ask_local_participants_to_announce,
    enlarge_input_buffers,
    incomplete_participants,
    local_participant_count,
    local_peers_discovered,
    own_participant,
    writers_to_prompt,
)
from roc.ros.discovery_info import DiscoveryInfoReader
from roc.ros.params import WRITES, parameter_value
from roc.ros.protocol import (
    DEFAULT_SPIN_TIME,
    PARAMETER_TYPES,
    discovery_stays_local,
    full_name,
    is_own_node,
    middleware,
    own_node_name,
)
from roc.ros.raw_subscription import gid_text
from roc.ros.type_description import describe
from roc.ros.vendors.cyclonedds import close_at_once
from roc.ros.vendors.fastdds import PARTICIPANT_PROFILE, use_profile

# A fresh participant's discovery ends as soon as it has heard every participant of this host in its
# domain (roc.ros.discovery counts them), has discovered every node and endpoint each participant lists
# in its ros_discovery_info message (roc.ros.discovery_info), and the graph has been quiet for
# QUIET_SECONDS (LOCAL_QUIET_SECONDS when discovery stays on this host: no other host's participant can
# come then); at the latest after the period (``--spin-time``, default DEFAULT_SPIN_TIME, in
# roc.ros.protocol so that verbs can read it without rclpy: one Fast DDS announcement period and a
# margin, all a participant could wait before; without --spin-time, while the graph is known to be
# incomplete, what this process's DDS vendor may need more for a participant heard late: one more
# announcement period on Fast DDS, roc.ros.vendors). Measured with ten processes: complete in 20 of 20
# runs, where a fixed 3.5 s was needed before.
QUIET_SECONDS = 0.3
LOCAL_QUIET_SECONDS = 0.1
POLL_SECONDS = 0.05
# how often while roc prompts writers (Graph._prompt_writers), within PROMPT_POLL_LIMIT of the start: each
# answer acted on at once; after that second Fast DDS's endpoint discovery writers have sent their next HEARTBEAT
PROMPT_POLL_SECONDS, PROMPT_POLL_LIMIT = 0.01, 1.0
SERVICE_TIMEOUT = 5.0
KEPT_CLIENTS = 16  # clients of nodes' own services a graph keeps (Graph._node_service_client)
LOG = logging.getLogger(__name__)  # the daemon writes it to its log; a library adds no handler of its own
SPIN_SLICE = 0.1  # seconds an executor waits before it looks whether the graph is closing


OPEN_GRAPHS: set[int] = set()  # id() of every Graph whose rclpy context is initialised and not closed yet


def every_graph_closed() -> bool:
    """No participant of this process's Graphs (the only rclpy contexts roc makes) is left: its process may
    end without the middleware's teardown (roc.cli.process_exit)."""
    return not OPEN_GRAPHS


# Why Graph.wait_for_discovery ended: the graph was complete (every participant of this host discovered
# and wholly known, and quiet); the period ended with the graph complete as far as could be told (other
# hosts' participants cannot be counted, nor this host's off Linux); or it ended with the graph known to
# be incomplete
COMPLETE, PERIOD_ENDED, INCOMPLETE = "complete", "period ended", "incomplete"


class NotFound(RocError):
    """An unknown topic, node, service, action or parameter (the message is ros2's wording)."""


def _duration_ns(duration) -> int | None:
    """Nanoseconds, None for an infinite duration."""
    from rclpy.duration import Infinite

    return None if duration == Infinite else duration.nanoseconds


def _endpoint(info) -> dict[str, Any]:
    qos = info.qos_profile
    return {
        "node_name": info.node_name,
        "node_namespace": info.node_namespace,
        "topic_type": info.topic_type,
        "topic_type_hash": str(info.topic_type_hash),
        "endpoint_type": info.endpoint_type.name,
        "gid": gid_text(info.endpoint_gid),
        "qos": {
            "reliability": qos.reliability.name,
            "history": qos.history.name,
            "depth": qos.depth,
            "durability": qos.durability.name,
            "lifespan_ns": _duration_ns(qos.lifespan),
            "deadline_ns": _duration_ns(qos.deadline),
            "liveliness": qos.liveliness.name,
            "liveliness_lease_duration_ns": _duration_ns(qos.liveliness_lease_duration),
        },
    }


class CrashRisk(RocError):
    """A request roc does not send: it is known to crash the node that would get it."""


def _service_endpoint(info) -> dict[str, Any]:
    """An endpoint of a service's request or reply topic, its DDS type name (``std_srvs::srv::dds_::
    SetBool_Request_``) given as ROS names it (``std_srvs/srv/SetBool_Request``)."""
    endpoint = _endpoint(info)
    package, kind, _, name = (endpoint["topic_type"].split("::") + ["", "", "", ""])[:4]
    if name:
        endpoint["topic_type"] = f"{package}/{kind}/{name.rstrip('_')}"
    return endpoint


# rclpy.action.graph's queries, made as it makes them (Jazzy and Kilted): on the node's handle. Importing
# rclpy.action loads its client and server, and with them numpy: 0.1 s of every first query.
def _action_names_and_types(node: Node) -> list[tuple[str, list[str]]]:
    with node.handle:
        return node.handle.get_action_names_and_types()


def _action_servers(node: Node, name: str, namespace: str) -> list[tuple[str, list[str]]]:
    with node.handle:
        return node.handle.get_action_server_names_and_types_by_node(name, namespace)


def _action_clients(node: Node, name: str, namespace: str) -> list[tuple[str, list[str]]]:
    with node.handle:
        return node.handle.get_action_client_names_and_types_by_node(name, namespace)


def _names_and_types(pairs) -> list[dict[str, Any]]:
    return [{"name": name, "types": list(types)} for name, types in sorted(pairs)]


def _load_numpy() -> None:
    """Import numpy before a Graph's threads start, for a participant that streams: a message module with
    an array imports it, and imported first on one of the daemon's stream threads it hung that stream
    (4 of 9 runs of the TUI's diagnostics test). A participant that only asks (a query) needs none of it
    (0.07 s of its start)."""
    with contextlib.suppress(ImportError):
        import numpy  # noqa: F401, PLC0415


class Graph:
    """An rclpy node in its own context (by default roc's own, hidden: see is_own_node), spun in a
    background thread (for service calls); in ``domain_id`` when given, else in the environment's ROS
    domain. Its participant takes Fast DDS's
    settings from ``profile`` (unless the user chose a profile file): PARTICIPANT_PROFILE, or
    BRIDGE_PROFILE for a bridge's. Both announce the participant every 0.5 s."""

    def __init__(self, node_name: str | None = None, domain_id: int | None = None, events: bool = False,
                 profile: Path = PARTICIPANT_PROFILE, arguments: Sequence[str] = (), asks_only: bool = False) -> None:
        """``events``: spin with rclpy's C++ EventsExecutor, which takes a message in a fraction of the
        Python executor's time (at 5 kHz: no loss and 0.2 ms instead of 10 % loss and 60 ms here). In
        rclpy 7.1.6 it never calls a callback that takes message info, so echo and hz take their
        messages with roc.ros.raw_subscription instead.

        ``arguments``: the node's ROS arguments (``--ros-args --remap OLD:=NEW``, as rosbag2 gives its
        player's). rcl never reads roc's own command line, where it would take any ``NAME:=VALUE`` word
        for a remapping rule (and warn that this syntax is deprecated).

        ``asks_only``: the participant only queries and waits for the answers to its requests, so it may
        close without waiting for its last messages to be acknowledged (roc.ros.vendors.cyclonedds)."""
        use_profile(profile)
        if not asks_only:
            _load_numpy()
        with close_at_once() if asks_only else contextlib.nullcontext():
            self.context = Context()
            rclpy.init(args=[], context=self.context, signal_handler_options=SignalHandlerOptions.NO,
                       domain_id=domain_id)
            OPEN_GRAPHS.add(id(self))
            self.node = self.task_node(node_name or own_node_name(os.getpid()), arguments)
        if vendors.speaks_rtps(middleware()):  # DDS's discovery ports and announcements (not rmw_zenoh's)
            enlarge_input_buffers(self.context.get_domain_id())
            ask_local_participants_to_announce(self.context.get_domain_id())
        self.events = events
        self.executor = EventsExecutor(context=self.context) if events else SingleThreadedExecutor(context=self.context)
        self._stopping = threading.Event()
        # (service, type) -> a kept client and how many calls use it now, the latest used last
        self._clients: dict[tuple[str, Any], tuple[Any, int]] = {}
        self._clients_lock = threading.Lock()
        self.executor.add_node(self.node)
        self._spinner = threading.Thread(target=self._spin, daemon=True)
        self._spinner.start()

    def _spin(self) -> None:
        """Spin until closed. A callback that raises is logged once per kind of failure (its exception's
        type and the line that raised it) and spinning goes on: one failure must not stop every later
        request of a daemon that serves for hours."""
        logged: set[tuple[str, str, int | None]] = set()
        while not self._stopping.is_set():
            try:
                self.executor.spin_once(timeout_sec=SPIN_SLICE)
            except Exception as error:  # noqa: BLE001 - see the docstring
                if self._stopping.is_set() or not self.context.ok():
                    return  # the context was shut down under it
                where = traceback.extract_tb(error.__traceback__)[-1]
                kind = (type(error).__qualname__, where.filename, where.lineno)
                if kind not in logged:
                    logged.add(kind)
                    LOG.warning("a callback failed on the graph's spinning thread; spinning on", exc_info=True)

    def close(self) -> None:
        """Stop spinning, then shut down. The EventsExecutor deadlocks if its context is shut down while
        it spins (its shutdown callback waits for the spin), and may miss a wake that comes before it
        waits (so it waits SPIN_SLICE at most); the Python executor wakes for the shutdown only."""
        self._stopping.set()
        if self.events:
            self.executor.wake()
        else:
            rclpy.try_shutdown(context=self.context)
        self._spinner.join(timeout=2)
        self.executor.shutdown(timeout_sec=1)
        rclpy.try_shutdown(context=self.context)
        self.node.destroy_node()
        OPEN_GRAPHS.discard(id(self))  # rmw deleted the participant at the shutdown

    def task_node(self, name: str, arguments: Sequence[str] = ()) -> Node:
        """A node of this participant that shows only the endpoints made on it, to other tools too: no
        parameter, type description or /rosout endpoints, and no /parameter_events publisher (its
        parameters never change). The graph's own node, and the node a stream publishes from
        (roc.ros.dataplane.publish, which destroys it when the stream ends; not spun)."""
        node = Node(name, context=self.context, start_parameter_services=False, enable_rosout=False,
                    cli_args=list(arguments),
                    parameter_overrides=[Parameter("start_type_description_service", value=False)])
        for publisher in list(node.publishers):
            if publisher.topic_name == "/parameter_events":
                node.destroy_publisher(publisher)
        return node

    def on_spinner(self, function: Callable[[], Any]) -> Future:
        """Run ``function()`` on the thread that spins the node, between two callbacks; the future's
        result is what it returns. Why: rclpy 7's action client records a request only after sending
        it, so a response handled on the spinning thread in between is dropped as unexpected and the
        request never completes (a goal hung about once in 150 on a busy machine); and rclpy 9 adds an
        action client to the node's waitables before the client is whole."""
        return self.executor.create_task(function)

    # -- discovery ------------------------------------------------------------------------------------
    def signature(self) -> tuple:
        node = self.node
        return (tuple(sorted(node.get_node_names_and_namespaces())),
                tuple((n, tuple(t), node.count_publishers(n), node.count_subscribers(n))
                      for n, t in sorted(node.get_topic_names_and_types())),
                tuple((n, tuple(t)) for n, t in sorted(node.get_service_names_and_types())))

    def wait_for_discovery(self, period: float | None = None, probe: LocalParticipantProbe | None = None) -> str:
        """Return once this host's participants are discovered, every participant discovered is wholly
        known (see _complete) and the graph has been unchanged for a quiet time (see QUIET_SECONDS); at
        the latest after ``period``. Without one, after DEFAULT_SPIN_TIME, or, while the graph is known
        to be incomplete (a participant of this host not heard yet, a node or endpoint it told not
        discovered yet), what this process's DDS vendor may need more for a participant it heard only at
        its next periodic announcement (roc.ros.vendors: one more announcement period on Fast DDS, on a
        loaded machine). Returns why it ended: COMPLETE, PERIOD_ENDED or INCOMPLETE.

        ``probe``: the domain's probe, made before this participant (roc.ros.discovery.early_probe), whose
        fetched endpoint announcements it passes on; this closes it. By default, one made now."""
        quiet = LOCAL_QUIET_SECONDS if discovery_stays_local() else QUIET_SECONDS
        bound = DEFAULT_SPIN_TIME if period is None else period
        vendor = vendors.of_middleware(middleware())
        longest = bound + (vendor.late_answer_seconds if vendor else 0.0) if period is None else period
        domain = self.context.get_domain_id()
        reader = DiscoveryInfoReader(self.node)
        if probe is None and vendors.speaks_rtps(middleware()):
            probe = LocalParticipantProbe(domain)
        prompter = probe if vendor is not None and vendor.loses_early_heartbeats else None
        try:
            start = last_change = time.monotonic()
            if probe is not None:
                probe.ask()
            last, prompting = self.signature(), prompter is not None
            while True:
                soon = prompting and time.monotonic() - start < PROMPT_POLL_LIMIT
                if probe is not None:
                    probe.pass_on_endpoints()
                time.sleep(PROMPT_POLL_SECONDS if soon else POLL_SECONDS)
                now = time.monotonic()
                current = self.signature()
                told = reader.take()
                if prompter is not None:
                    prompting = self._prompt_writers(prompter, told)
                if current != last:
                    last, last_change = current, now
                elapsed = now - start
                if now - last_change < quiet and elapsed < bound:
                    continue
                peers = self._local_peers_discovered(domain, probe)
                complete = peers is not False and self._complete(told)
                if complete and peers and now - last_change >= quiet:
                    return COMPLETE
                if complete and elapsed >= bound:
                    return PERIOD_ENDED
                if elapsed >= longest:
                    return INCOMPLETE
        finally:
            if probe is not None:
                probe.close()
            reader.close()

    def _prompt_writers(self, probe: LocalParticipantProbe, told: Mapping[bytes, Told]) -> bool:
        """Prompt the writers that tell of this host's participants not wholly heard yet (``told``: no
        message of theirs has come) to send this participant a HEARTBEAT, where their vendor takes a
        prompt (roc.ros.vendors.fastdds; why: roc.ros.vendors.cyclonedds). Returns whether it may prompt
        more: this participant's own message has not come yet, or a participant prompted is not heard
        wholly yet."""
        own = own_participant(told, self.node.get_name())
        if own is None:
            return True
        if not probe.heard() - told.keys():
            return False
        node = self.node
        writers = node.get_publishers_info_by_topic(DISCOVERY_TOPIC, no_mangle=True)
        readers = node.get_subscriptions_info_by_topic(DISCOVERY_TOPIC, no_mangle=True)
        prompted = False
        for prefix, endpoints in writers_to_prompt(own, probe.heard(), told, writers, readers).items():
            vendor = vendors.of_prefix(prefix)
            if vendor is not None and vendor.prompt_count is not None:
                probe.prompt(own, prefix, endpoints, vendor.prompt_count)
                prompted = True
        return prompted

    def _local_peers_discovered(self, domain: int, probe: LocalParticipantProbe | None) -> bool | None:
        """Every participant of another process on this host in ``domain`` has been discovered
        (roc.ros.discovery.local_peers_discovered; None when that cannot be told: not Linux, or no ``probe``
        on a middleware without RTPS). While some have not answered ``probe``, it asks them again (one
        that came since, or whose answer was lost)."""
        if probe is None:
            return None
        expected = local_participant_count(domain)
        heard = probe.heard()
        if expected is not None and len(heard) < expected:
            probe.ask_again()
        writers = self.node.get_publishers_info_by_topic(DISCOVERY_TOPIC, no_mangle=True)
        return local_peers_discovered(expected, heard, writers)

    def _complete(self, told: Mapping[bytes, Told]) -> bool:
        """Every endpoint's node is known (a participant seen before its node names is not complete), and
        every participant discovered is wholly known: its latest ``ros_discovery_info`` message
        (``told``, by participant GUID prefix) has come and each node and endpoint it lists has been discovered
        (roc.ros.discovery.incomplete_participants)."""
        node = self.node
        endpoints: set[bytes] = set()
        for name, _ in node.get_topic_names_and_types(no_demangle=True):  # services' request and reply too
            found = [*node.get_publishers_info_by_topic(name, no_mangle=True),
                     *node.get_subscriptions_info_by_topic(name, no_mangle=True)]
            if name != DISCOVERY_TOPIC and any(info.node_name == UNKNOWN_NODE for info in found):
                return False  # rmw's own endpoints, on DISCOVERY_TOPIC, never have a node name
            endpoints.update(bytes(info.endpoint_gid) for info in found)
        writers = node.get_publishers_info_by_topic(DISCOVERY_TOPIC, no_mangle=True)
        nodes = {(namespace, name) for name, namespace in node.get_node_names_and_namespaces()}
        return incomplete_participants(writers, told, endpoints, nodes) == 0

    # -- roc's own participants (roc.ros.protocol.is_own_node) are in no answer ---------------------------
    def _nodes(self, own: bool = False) -> list[tuple[str, str]]:
        """(name, namespace) of every node but roc's own (``own``: of roc's own only)."""
        return [(name, namespace) for name, namespace in self.node.get_node_names_and_namespaces()
                if is_own_node(name) == own]

    def _names_by_node(self, nodes: list[tuple[str, str]], queries) -> set[str]:
        """The names ``queries`` (functions of node name and namespace) give for ``nodes``."""
        names: set[str] = set()
        for name, namespace in nodes:
            for by_node in queries:
                try:
                    names.update(entry for entry, _ in by_node(name, namespace))
                except NodeNameNonExistentError:  # gone since it was listed
                    pass
        return names

    def _others_only(self, pairs, queries) -> list:
        """``pairs`` (name, types) without the names only roc's own nodes use (by ``queries``)."""
        own = self._names_by_node(self._nodes(own=True), queries)
        if not any(name in own for name, _ in pairs):
            return list(pairs)
        others = self._names_by_node(self._nodes(), queries)
        return [(name, types) for name, types in pairs if name not in own or name in others]

    def _endpoints(self, topic: str) -> tuple[list, list]:
        """The topic's publishers and subscriptions (rclpy endpoint infos) but roc's own."""
        node = self.node
        return ([i for i in node.get_publishers_info_by_topic(topic) if not is_own_node(i.node_name)],
                [i for i in node.get_subscriptions_info_by_topic(topic) if not is_own_node(i.node_name)])

    def _topics(self) -> list[dict[str, Any]]:
        """Topics with their endpoint counts; roc's own endpoints are not counted, and a topic only they
        use is left out."""
        node = self.node
        own = self._names_by_node(self._nodes(own=True), (node.get_publisher_names_and_types_by_node,
                                                          node.get_subscriber_names_and_types_by_node))
        topics = []
        for topic in _names_and_types(node.get_topic_names_and_types()):
            if topic["name"] in own:
                publishers, subscribers = (len(found) for found in self._endpoints(topic["name"]))
                if not publishers and not subscribers:
                    continue
            else:
                publishers, subscribers = node.count_publishers(topic["name"]), node.count_subscribers(topic["name"])
            topics.append({**topic, "publishers": publishers, "subscribers": subscribers})
        return topics

    # -- queries --------------------------------------------------------------------------------------
    def snapshot(self, endpoints: bool = False) -> dict[str, Any]:
        """Nodes, topics (with endpoint counts; with ``endpoints``, each topic's endpoints too, as
        ``topic_endpoints`` gives them: one request instead of one per topic), services and actions;
        roc's own left out."""
        node = self.node
        services = self._others_only(node.get_service_names_and_types(), (node.get_service_names_and_types_by_node,
                                                                          node.get_client_names_and_types_by_node))
        actions = self._others_only(_action_names_and_types(node), (
            partial(_action_servers, node), partial(_action_clients, node)))
        topics = self._topics()
        if endpoints:
            for topic in topics:
                publishers, subscribers = self._endpoints(topic["name"])
                topic["endpoints"] = {"publishers": [_endpoint(i) for i in publishers],
                                      "subscribers": [_endpoint(i) for i in subscribers]}
        return {
            "nodes": [{"name": name, "namespace": namespace, "full_name": full_name(namespace, name)}
                      for name, namespace in sorted(self._nodes(), key=lambda p: full_name(p[1], p[0]))],
            "topics": topics,
            "services": _names_and_types(services),
            "actions": _names_and_types(actions),
        }

    def topic_endpoints(self, topic: str) -> dict[str, Any]:
        types = dict(self.node.get_topic_names_and_types()).get(topic)
        publishers, subscribers = self._endpoints(topic) if types is not None else ([], [])
        if types is None or not publishers and not subscribers:
            raise NotFound(f"Unknown topic '{topic}'")
        return {"name": topic, "types": list(types),
                "publishers": [_endpoint(i) for i in publishers], "subscribers": [_endpoint(i) for i in subscribers]}

    def _find_node(self, name: str) -> tuple[str, str]:
        for node_name, namespace in self._nodes():
            if full_name(namespace, node_name) == name:
                return node_name, namespace
        raise NotFound(f"Unable to find node '{name}'")

    def node_info(self, name: str) -> dict[str, Any]:
        node_name, namespace = self._find_node(name)
        node = self.node
        return {
            "name": full_name(namespace, node_name),
            "subscribers": _names_and_types(node.get_subscriber_names_and_types_by_node(node_name, namespace)),
            "publishers": _names_and_types(node.get_publisher_names_and_types_by_node(node_name, namespace)),
            "service_servers": _names_and_types(node.get_service_names_and_types_by_node(node_name, namespace)),
            "service_clients": _names_and_types(node.get_client_names_and_types_by_node(node_name, namespace)),
            "action_servers": _names_and_types(
                _action_servers(node, node_name, namespace)),
            "action_clients": _names_and_types(
                _action_clients(node, node_name, namespace)),
        }

    def action_info(self, action: str) -> dict[str, Any]:
        """The nodes serving and using ``action`` with the types they give it."""
        servers: list[dict[str, Any]] = []
        clients: list[dict[str, Any]] = []
        for node_name, namespace in sorted(self._nodes()):
            for found, query in ((servers, _action_servers), (clients, _action_clients)):
                for name, types in query(self.node, node_name, namespace):
                    if name == action:
                        found.append({"node": full_name(namespace, node_name), "types": list(types)})
        return {"name": action, "servers": servers, "clients": clients}

    def service_info(self, service: str) -> dict[str, Any]:
        """A service's types, client and server counts, and (from the DDS topics the middleware makes
        of it, ``rq/NAMERequest`` and ``rr/NAMEReply``) the endpoints of its clients and servers."""
        node = self.node
        types = dict(node.get_service_names_and_types()).get(service)
        if types is None:
            raise NotFound(f"Unknown service '{service}'")
        request, reply = f"rq{service}Request", f"rr{service}Reply"
        requests = node.get_publishers_info_by_topic(request, no_mangle=True)
        clients = [info for info in requests + node.get_subscriptions_info_by_topic(reply, no_mangle=True)
                   if not is_own_node(info.node_name)]  # roc's own (a daemon's kept client) left out
        servers = (node.get_subscriptions_info_by_topic(request, no_mangle=True)
                   + node.get_publishers_info_by_topic(reply, no_mangle=True))
        own_clients = sum(is_own_node(info.node_name) for info in requests)
        return {"name": service, "types": list(types),
                "clients_count": node.count_clients(service) - own_clients,
                "services_count": node.count_services(service),
                "clients": [_service_endpoint(i) for i in clients], "servers": [_service_endpoint(i) for i in servers]}

    # -- parameters (service calls to the node) ------------------------------------------------------
    def wait_for_node(self, node_name: str, timeout: float = 0.0) -> str:
        """The node's full name (a relative name is taken from the root, as ros2 param does) once the
        graph knows it, waiting up to ``timeout`` seconds; ros2 param's "Node not found" if it does not."""
        name = node_name if node_name.startswith("/") else f"/{node_name}"
        deadline = time.monotonic() + timeout
        while True:
            try:
                self._find_node(name)
                return name
            except NotFound:
                if time.monotonic() >= deadline:
                    raise NotFound("Node not found") from None
            time.sleep(POLL_SECONDS)

    def refuse_crashing_request(self, service: str) -> None:
        """Raise CrashRisk when a server of ``service`` runs on a middleware that a request from this
        process's is known to crash (roc.ros.vendors.request_crash: Cyclone DDS to Fast DDS)."""
        client = vendors.of_middleware(middleware())
        if client is None or not client.crashes_servers_of:  # nothing to look up on every other middleware
            return
        for info in self.node.get_subscriptions_info_by_topic(f"rq{service}Request", no_mangle=True):
            reason = vendors.request_crash(middleware(), bytes(info.endpoint_gid))
            if reason:
                node = full_name(info.node_namespace, info.node_name)
                raise CrashRisk(f"{node}: not asked: {reason}; ask from a process on its middleware "
                                f"(RMW_IMPLEMENTATION=rmw_fastrtps_cpp)")

    @contextlib.contextmanager
    def _node_service_client(self, srv_type, service: str) -> Iterator[Any]:
        """The graph node's client of a node's own service (parameters, type description: call_node_service),
        kept for later calls: the KEPT_CLIENTS used last, while the graph lives (the daemon's, until it exits
        when idle). Why: a server on Cyclone DDS answers a client new to it only once it has discovered the
        client's reader, polling every 10 ms (rmw_cyclonedds 2.2.2's rmw_send_response), which made each
        roc param get through the daemon 11 ms slower than on Fast DDS; a kept client's call takes 0.7 ms
        on either. roc's answers leave its own clients out (service_info), as they leave its nodes out."""
        key = (service, srv_type)
        with self._clients_lock:
            client, users = self._clients.pop(key, (None, 0))
            self._clients[key] = (client or self.node.create_client(srv_type, service), users + 1)
            client = self._clients[key][0]
            idle = [kept for kept, (_, using) in self._clients.items() if not using]
            for kept in idle[:max(0, len(self._clients) - KEPT_CLIENTS)]:  # the longest unused first
                self.node.destroy_client(self._clients.pop(kept)[0])
        try:
            yield client
        finally:
            with self._clients_lock:
                self._clients[key] = (client, self._clients[key][1] - 1)

    def call_node_service(self, node_name: str, service: str, srv_type, request) -> Any:
        """Call the node's service ``service`` (e.g. ``set_parameters``) and return the response."""
        self.refuse_crashing_request(f"{node_name.rstrip('/')}/{service}")
        with self._node_service_client(srv_type, f"{node_name.rstrip('/')}/{service}") as client:
            if not client.wait_for_service(timeout_sec=SERVICE_TIMEOUT):
                raise RocError(f"{node_name}: parameter service '{service}' not available")
            done = threading.Event()
            future = client.call_async(request)
            future.add_done_callback(lambda _: done.set())
            if not done.wait(SERVICE_TIMEOUT):
                client.remove_pending_request(future)
                raise RocError(f"{node_name}: '{service}' did not answer within {SERVICE_TIMEOUT:g} s")
            return future.result()

    def param_names(self, node_name: str, prefixes: list[str] | None = None) -> list[str]:
        from rcl_interfaces.srv import ListParameters

        request = ListParameters.Request(prefixes=prefixes or [], depth=0)
        return sorted(self.call_node_service(node_name, "list_parameters", ListParameters, request).result.names)

    def param_values(self, node_name: str, names: list[str]) -> list[dict[str, Any]]:
        from rcl_interfaces.srv import GetParameters

        request = GetParameters.Request(names=names)
        response = self.call_node_service(node_name, "get_parameters", GetParameters, request)
        return [parameter_value(v) for v in response.values]

    def param_types(self, node_name: str, names: list[str]) -> list[int]:
        from rcl_interfaces.srv import GetParameterTypes

        request = GetParameterTypes.Request(names=names)
        return list(self.call_node_service(node_name, "get_parameter_types", GetParameterTypes, request).types)

    def param_descriptors(self, node_name: str, names: list[str]) -> list[dict[str, Any]]:
        from rcl_interfaces.srv import DescribeParameters

        request = DescribeParameters.Request(names=names)
        response = self.call_node_service(node_name, "describe_parameters", DescribeParameters, request)
        return [{
            "name": d.name, "type": PARAMETER_TYPES.get(d.type, "not set"), "description": d.description,
            "additional_constraints": d.additional_constraints, "read_only": d.read_only,
            "dynamic_typing": d.dynamic_typing,
            "floating_point_range": [{"from_value": r.from_value, "to_value": r.to_value, "step": r.step}
                                     for r in d.floating_point_range],
            "integer_range": [{"from_value": r.from_value, "to_value": r.to_value, "step": r.step}
                              for r in d.integer_range],
        } for d in response.descriptors]

    def param_list(self, node_name: str | None, prefixes: list[str] | None, with_types: bool,
                   hidden: bool = False) -> list[dict]:
        """[{node, parameters: [{name, type?}]}] for one node or every node (``hidden``: hidden nodes too);
        a node not asked, since the request could crash it, has ``left_out`` (why) and no parameters."""
        graph = self.snapshot()
        served = {s["name"] for s in graph["services"]}  # a node without parameter services is left out at once
        names = [node_name] if node_name else [n["full_name"] for n in graph["nodes"]
                                               if (hidden or not n["name"].startswith("_"))
                                               and f"{n['full_name']}/list_parameters" in served]
        result: list[dict[str, Any]] = []
        for name in names:
            try:
                params = self.param_names(name, prefixes)
            except CrashRisk as risk:
                if node_name:
                    raise
                result.append({"node": name, "parameters": [], "left_out": str(risk)})
                continue
            except RocError:
                if node_name:
                    raise
                continue  # a node without parameter services: ros2 leaves it out too
            entry = [{"name": p} for p in params]
            if with_types and params:
                for item, kind in zip(entry, self.param_types(name, params)):
                    item["type"] = PARAMETER_TYPES.get(kind, "not set")
            result.append({"node": name, "parameters": entry})
        return result

    def handle(self, method: str, params: dict[str, Any]) -> Any:
        """One request of the daemon protocol (see docs/daemon.md)."""
        if method == "node_wait" or (method.startswith("param_") and params.get("node")):
            params = {**params, "node": self.wait_for_node(params["node"], params.get("timeout", 0.0))}
        if method == "node_wait":
            return params["node"]
        if method == "snapshot":
            return self.snapshot(params.get("endpoints", False))
        if method == "topic_endpoints":
            return self.topic_endpoints(params["topic"])
        if method == "node_info":
            return self.node_info(params["node"])
        if method == "type_description":
            return describe(self, params["type"])
        if method == "service_info":
            return self.service_info(params["service"])
        if method == "action_info":
            return self.action_info(params["action"])
        if method == "param_list":
            return self.param_list(params.get("node"), params.get("prefixes"), params.get("types", False),
                                   params.get("hidden", False))
        if method == "param_get":
            names = params["names"]
            return self.param_values(params["node"], names)
        if method == "param_describe":
            return self.param_descriptors(params["node"], params["names"])
        if method == "param_dump":
            names = self.param_names(params["node"])
            return dict(zip(names, self.param_values(params["node"], names)))
        if method in WRITES:
            return WRITES[method](self, params)
        raise RocError(f"unknown request '{method}'")

