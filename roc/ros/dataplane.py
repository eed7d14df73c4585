"""Moving data on a live graph: subscriptions (``echo``, ``stats``, ``frames``) and a publisher
(``publish``) on a Graph's node, each a stream of plain-data events (roc.ros.streams names them
all). The same generators run inside the roc daemon (each event a line on the client's socket, so
the endpoint lives in an already discovered participant) and in a daemon-less run. Messages travel as
serialised CDR (base64 in JSON); the client turns them into message objects
(``roc.ros.cdr.decode``), so the daemon never needs a verb's output options.

A stream ends when its generator is closed: the daemon closes it when the client goes away (a
heartbeat event at least every HEARTBEAT_SECONDS finds out), and the ``finally`` blocks destroy the
endpoint, so an interrupted client leaves none behind.
"""

from __future__ import annotations

import base64
import itertools
import struct
import time
from collections.abc import Callable, Hashable
from typing import Any

from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSPresetProfiles,
    QoSProfile,
    ReliabilityPolicy,
)
from rclpy.serialization import deserialize_message

from roc.errors import RocError
from roc.ros import vendors
from roc.ros.content_filter import ContentFilter
from roc.ros.messages import value_to_data
from roc.ros.protocol import HEARTBEAT_SECONDS, Events, full_name, task_node_name
from roc.ros.raw_subscription import Receiver, gid_text
from roc.ros.types import TF_TYPE, message_class

MAX_BATCH = 1000  # messages in one ``messages`` event
# What roc's subscriptions keep when no depth is asked for: a burst waits for a busy reader rather than
# being dropped (ros2 topic echo keeps 5; a bridge kept 10 and lost 0.8 % at 5 kHz).
RECEIVE_DEPTH = 1000
POLL_SECONDS = 0.05
# numbers the nodes of publishing streams whose client named none
UNNAMED_PUBLISHERS = itertools.count(1)
_POLICIES = {"history": HistoryPolicy, "reliability": ReliabilityPolicy, "durability": DurabilityPolicy,
             "liveliness": LivelinessPolicy}


def qos_profile(options: dict[str, Any], publishers: list | None = None) -> QoSProfile:
    """The profile ``options`` ask for (``profile``, ``depth``, ``history``, ``reliability``,
    ``durability``, ``liveliness``, ``liveliness_lease_seconds``). Reliability and durability not given
    follow ``publishers`` (rclpy endpoint infos) as ros2 does: reliable / transient local only when
    every publisher is."""
    profile = QoSPresetProfiles.get_from_short_key(options.get("profile", "default"))
    profile = QoSProfile(**{slot.lstrip("_"): getattr(profile, slot) for slot in profile.__slots__})
    for name, policy in _POLICIES.items():
        if options.get(name):
            setattr(profile, name, policy.get_from_short_key(options[name]))
    if options.get("depth") is not None:
        profile.depth = options["depth"]
    if options.get("liveliness_lease_seconds") is not None:
        from rclpy.duration import Duration

        profile.liveliness_lease_duration = Duration(seconds=options["liveliness_lease_seconds"])
    if publishers:
        if not options.get("reliability"):
            reliable = all(p.qos_profile.reliability == ReliabilityPolicy.RELIABLE for p in publishers)
            profile.reliability = ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT
        if not options.get("durability"):
            latched = all(p.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in publishers)
            profile.durability = DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE
    return profile


def subscription_profile(options: dict[str, Any], publishers: list | None = None) -> QoSProfile:
    """``qos_profile`` for a subscription: RECEIVE_DEPTH deep unless ``options`` ask otherwise."""
    if options.get("depth") is None and options.get("history") != "keep_all":
        options = {**options, "depth": RECEIVE_DEPTH}
    return qos_profile(options, publishers)


def publishers(graph, topic: str, wait: float) -> list:
    """The topic's publishers (rclpy endpoint infos), waiting up to ``wait`` seconds for one to appear
    (a fresh participant discovers them)."""
    deadline = time.monotonic() + wait
    while True:
        found = graph.node.get_publishers_info_by_topic(topic)
        if found or time.monotonic() >= deadline:
            return found
        time.sleep(POLL_SECONDS)


def _graph_type(graph, topic: str) -> str | None:
    return next((types[0] for name, types in graph.node.get_topic_names_and_types() if name == topic), None)


def _topic_class(graph, topic: str, params: dict[str, Any], wait_for_type: bool):
    """Events while the topic's publishers and type are looked up (``not_published {topic}``, and
    heartbeats while waiting for a type with ``wait_for_type``); returns (class, type name, publishers).
    The type is resolved before any event, so that a type the daemon lacks is found first (client.stream)."""
    found = publishers(graph, topic, params.get("wait", 0.0))
    type_name = params.get("type") or _graph_type(graph, topic)
    cls = message_class(type_name) if type_name else None
    if not found:
        yield {"event": "not_published", "topic": topic}
    while cls is None and wait_for_type:  # as ros2 topic hz: until the topic appears
        yield {"event": "heartbeat"}
        time.sleep(POLL_SECONDS)
        type_name = _graph_type(graph, topic)
        cls = message_class(type_name) if type_name else None
        found = graph.node.get_publishers_info_by_topic(topic)
    if cls is None:
        raise RocError("Could not determine the type for the passed topic")
    return cls, type_name, found


def content_filter(params: dict[str, Any], cls) -> ContentFilter | None:
    """The ``content_filter`` of stream ``params`` ({expression, parameters, middleware}), checked
    against the topic's message class (a ContentFilterError names what is wrong)."""
    given = params.get("content_filter")
    if not given:
        return None
    found = ContentFilter(given["expression"], given.get("parameters") or [])
    found.check(cls)
    return found


def subscribe_filtered(receiver: Receiver, topic: str, cls, qos: QoSProfile, found: ContentFilter | None,
                       middleware: bool = True) -> dict[str, Any]:
    """Subscribe ``receiver`` to ``topic``; with a content filter, the middleware filters where it can
    (``middleware``: may it; the user may ask roc to). Returns the ``content_filter`` of the
    ``subscribed`` event: {by: "middleware" | "roc", reason} (empty without a filter)."""
    if found is None:
        receiver.subscribe(topic, cls, topic, qos)
        return {}
    if not middleware:
        receiver.subscribe(topic, cls, topic, qos)
        return {"by": "roc", "reason": "asked to filter in roc (ROC_MIDDLEWARE_CONTENT_FILTER=0)"}
    unfiltered = receiver.subscribe(topic, cls, topic, qos, (found.expression, found.parameters))
    return {"by": "roc", "reason": unfiltered} if unfiltered else {"by": "middleware", "reason": None}


def total_lost(counts: list[int | None]) -> int | None:
    """The sum of lost-message counts; None (unknown) when one of them is unknown."""
    return None if None in counts else sum(count for count in counts if count is not None)


def echo(graph, params: dict[str, Any]) -> Events:
    """Subscribe to ``params["topic"]`` and yield ``{"event": "messages", "messages": [{data, info,
    lost, publisher}]}`` with what arrived since the last event (``lost``: messages the publisher's
    sequence numbers say never arrived; None, unknown, where the middleware gives none: Cyclone DDS;
    ``publisher``: its gid, as roc.ros.raw_subscription.gid_text),
    ``{"event": "subscribed", "type"}`` first and heartbeats in between.
    Params: ``topic``, ``wait`` (seconds to wait for a publisher to be discovered), ``type`` (else the
    graph's), ``qos`` (see qos_profile), ``timeout`` (seconds for the first message, counted from the
    start, the wait for a publisher included; then ``{"event": "timeout"}`` ends the stream),
    ``latest_value`` (the last message of each event also as plain data, ``value``, its strings and
    arrays cut after ``truncate_length`` elements: for a client that loads no rclpy), ``content_filter``
    (``{expression, parameters, middleware}``: only the messages that pass, filtered by the middleware
    where it can, else here; ``subscribed`` then says which, and no message counts as lost, since the
    ones filtered out leave gaps in the sequence numbers), ``latest_every`` (seconds: only the newest message,
    in at most one event this often, for an image preview; the ones left out are not lost)."""
    topic, timeout = params["topic"], params.get("timeout")
    started = time.monotonic()
    if timeout is not None:
        params = {**params, "wait": min(params.get("wait", 0.0), timeout)}
    cls, type_name, found = yield from _topic_class(graph, topic, params, wait_for_type=False)
    wanted = content_filter(params, cls)
    receiver = Receiver(graph.node)
    try:
        filtering = subscribe_filtered(receiver, topic, cls, subscription_profile(params.get("qos", {}), found),
                                       wanted, (params.get("content_filter") or {}).get("middleware", True))
        local = wanted if filtering.get("by") == "roc" else None
        yield {"event": "subscribed", "type": type_name, **({"content_filter": filtering} if filtering else {})}
        last_sequence: dict[str, int] = {}  # by publisher gid
        deadline = started + timeout if timeout is not None else None
        latest_every, sent = params.get("latest_every"), 0.0  # sent: time.monotonic() of the last event

        def received(seconds: float) -> list:
            batch = receiver.batch(seconds, MAX_BATCH)
            return [item for item in batch if local.accepts(deserialize_message(item[1], cls))] if local else batch

        def lost(info: dict[str, Any]) -> int | None:
            """The messages of info's publisher that never arrived since its last one; None, unknown,
            where the middleware gives no sequence numbers (Cyclone DDS)."""
            sequence, gid = info["publication_sequence_number"], info["gid"]
            if wanted is not None:
                return 0  # the messages filtered out are not lost
            if sequence is None:
                return None
            previous, last_sequence[gid] = last_sequence.get(gid), sequence
            return max(sequence - previous - 1, 0) if previous is not None else 0
        while True:
            batch = received(HEARTBEAT_SECONDS)
            if not batch:
                if deadline is not None and time.monotonic() >= deadline:
                    yield {"event": "timeout"}
                    return
                yield {"event": "heartbeat"}
                continue
            deadline = None  # a message arrived: the timeout is over
            carried: int | None = 0  # lost before the messages left out for ``latest_every``
            if latest_every:  # until it is due, newer messages replace the ones kept
                while (remaining := sent + latest_every - time.monotonic()) > 0:
                    if newer := received(remaining):
                        carried = total_lost([carried, *(lost(info) for _, _, info in batch)])
                        batch = newer
                carried = total_lost([carried, *(lost(info) for _, _, info in batch[:-1])])
                batch, sent = batch[-1:], time.monotonic()
            messages: list[dict[str, Any]] = [
                {"data": base64.b64encode(data).decode(), "lost": lost(info), "publisher": info["gid"],
                 "info": {key: value for key, value in info.items() if value is not None and key != "gid"}}
                for _, data, info in batch]
            messages[0]["lost"] = total_lost([messages[0]["lost"], carried])
            if params.get("latest_value"):
                messages[-1]["value"] = value_to_data(deserialize_message(batch[-1][1], cls),
                                                      truncate_length=params.get("truncate_length"))
            yield {"event": "messages", "messages": messages}
    finally:
        receiver.close()


def publish(graph, params: dict[str, Any], prepare: Callable[[], bytes] | None = None) -> Events:
    """Publish ``params["data"]`` (base64 CDR of a ``type`` message) on ``topic``: wait for ``wait``
    matching subscriptions (``{"event": "waiting"}`` each second, at most ``max_wait`` seconds), then
    ``times`` messages (0: until closed) at ``rate`` Hz (``value``, plain data, in place of ``data``: for a
    client that loads no rclpy), ``{"event": "published", "count"}`` after each,
    keeping the publisher ``keep_alive`` seconds after the last (null: until closed). In-process only:
    ``prepare`` gives the CDR to send before each message (stamped with the time).

    The publisher is on a node of its own, ``node`` (roc.ros.protocol.task_node_name; default
    ``roc_pub_<pid>_<n>``), not on the graph's hidden one: a topic the user asked roc to publish is
    listed like any other, under a node named for what publishes it."""
    cls = message_class(params["type"])
    data = base64.b64decode(params["data"]) if "data" in params else _filled(cls, params["value"])
    profile = qos_profile({"profile": "default", **params.get("qos", {})})
    node = graph.task_node(params.get("node") or f"{task_node_name('pub')}_{next(UNNAMED_PUBLISHERS)}")
    try:
        publisher = node.create_publisher(cls, params["topic"], profile)
        wanted, max_wait = params.get("wait", 0), params.get("max_wait")
        started = next_notice = time.monotonic()
        while publisher.get_subscription_count() < wanted:
            now = time.monotonic()
            if max_wait is not None and now - started >= max_wait:
                raise RocError(f"Timed out waiting for subscribers: Expected {wanted} subscribers but only got "
                               f"{publisher.get_subscription_count()} subscribers")
            if now >= next_notice:
                yield {"event": "waiting", "subscriptions": wanted}
                next_notice += 1.0
            time.sleep(POLL_SECONDS)
        yield {"event": "started"}
        times, period = params.get("times", 0), 1.0 / params["rate"] if params.get("rate") else 1.0
        count, due = 0, time.monotonic()
        while not times or count < times:
            publisher.publish(prepare() if prepare is not None else data)
            count += 1
            yield {"event": "published", "count": count}
            if times and count == times:
                break
            due += period
            while (remaining := due - time.monotonic()) > 0:
                time.sleep(min(remaining, HEARTBEAT_SECONDS))
                if remaining > HEARTBEAT_SECONDS:
                    yield {"event": "heartbeat"}
        keep_alive = params.get("keep_alive", 0.1)
        kept_until = time.monotonic() + keep_alive if keep_alive is not None else float("inf")  # null: until closed
        while (remaining := kept_until - time.monotonic()) > 0:
            time.sleep(min(remaining, HEARTBEAT_SECONDS))
            yield {"event": "heartbeat"}
    finally:
        node.destroy_node()  # and its publisher


def _filled(cls, value: Any) -> bytes:
    from roc.ros.cdr import serialize
    from roc.ros.messages import fill_message

    return serialize(fill_message(cls, value))


def header_stamp_ns(data: bytes) -> int | None:
    """The ``header.stamp`` of a message whose first field is a std_msgs/Header, read from its CDR
    (encapsulation, then int32 sec and uint32 nanosec) without deserialising it."""
    if len(data) < 12:
        return None
    order = "<" if data[1] & 1 else ">"
    sec, nanosec = struct.unpack(order + "iI", data[4:12])
    return sec * 1_000_000_000 + nanosec


def stats(graph, params: dict[str, Any]) -> Events:
    """Subscribe to each of ``params["topics"]`` and yield, every ``period`` seconds, a ``batch`` of
    what arrived: per topic, lists of publication sequence numbers, source and reception timestamps
    (ns), serialised sizes, publishers (a number per publisher gid, counted from 0 in each stream: a
    rate is the sum of the publishers', roc.ros.rates) and, with ``stamps``, header stamps (ns) — never
    deserialising a message, so that a fast topic does not outrun the subscriber. ``subscribed {topic,
    type}`` (or ``not_published {topic}``, then heartbeats until the topic appears) first, per topic.
    Volatile unless ``qos`` says otherwise: a measure counts what is published from now on, and a
    transient local publisher's history (Fast DDS's writers are transient local by default, depth 1)
    would come first, late, and count as a delay of up to a period (``topic delay``) or bytes
    received at once (``topic bw``)."""
    period, stamps = params.get("period", 1.0), params.get("stamps")
    qos = {**(params.get("qos") or {}), "durability": (params.get("qos") or {}).get("durability") or "volatile"}
    columns = ("sequence", "source", "received", "size", "stamp", "publisher")
    receiver = Receiver(graph.node)
    local: dict[Hashable, tuple[ContentFilter, Any]] = {}  # filtered here, with the topic's class
    numbers: dict[str, int] = {}  # publisher gid -> its number in the ``publisher`` column
    try:
        for topic in params["topics"]:
            cls, type_name, found = yield from _topic_class(graph, topic, params, wait_for_type=True)
            wanted = content_filter(params, cls)
            filtering = subscribe_filtered(receiver, topic, cls, subscription_profile(qos, found), wanted,
                                           (params.get("content_filter") or {}).get("middleware", True))
            if wanted is not None and filtering["by"] == "roc":
                local[topic] = (wanted, cls)
            yield {"event": "subscribed", "topic": topic, "type": type_name,
                   **({"content_filter": filtering} if filtering else {})}
        filtered = bool(params.get("content_filter"))  # sequence numbers have gaps: the rate is of what came
        while True:
            arrived: dict[Hashable, dict[str, list]] = {topic: {column: [] for column in columns}
                                                        for topic in params["topics"]}
            due = time.monotonic() + period
            while (remaining := due - time.monotonic()) > 0:
                for topic, data, info in receiver.batch(remaining):
                    if topic in local and not local[topic][0].accepts(deserialize_message(data, local[topic][1])):
                        continue
                    columns_of_topic = arrived[topic]
                    columns_of_topic["sequence"].append(None if filtered else info["publication_sequence_number"])
                    columns_of_topic["source"].append(info["source_timestamp"])
                    columns_of_topic["received"].append(info["received_timestamp"])
                    columns_of_topic["size"].append(len(data))
                    columns_of_topic["stamp"].append(header_stamp_ns(data) if stamps else None)
                    columns_of_topic["publisher"].append(numbers.setdefault(info["gid"], len(numbers)))
            yield {"event": "batch", "topics": arrived}
    finally:
        receiver.close()


def frames(graph, params: dict[str, Any]) -> Events:
    """Subscribe to /tf (QoS following the publishers known, else reliable as tf2's listener; depth
    100) and /tf_static (transient local, as tf2's static listener does) and yield ``messages
    {messages: [{static, transforms, received, publisher}]}`` batches (``transforms``: each of the
    TFMessage's ``[parent, child, stamp_ns, [x, y, z], [qx, qy, qz, qw]]``, decoded here so that the
    client loads no rclpy; ``publisher``: the sending node's full name, null while the graph does not
    know it), ``subscribed`` first and heartbeats in between. It needs no discovered graph: with
    ``early``, a daemon that is starting serves it before its discovery period."""
    cls = message_class(TF_TYPE)
    dynamic = qos_profile({"profile": "default", "depth": 100}, graph.node.get_publishers_info_by_topic("/tf"))
    static = qos_profile({"profile": "default", "depth": 100, "durability": "transient_local",
                          "reliability": "reliable"})
    receiver = Receiver(graph.node)
    nodes = PublisherNames(graph)
    try:
        receiver.subscribe("/tf", cls, "/tf", dynamic)
        receiver.subscribe("/tf_static", cls, "/tf_static", static)
        yield {"event": "subscribed", "type": TF_TYPE}
        while True:
            messages = [{"static": topic == "/tf_static", "transforms": _transforms(deserialize_message(data, cls)),
                         "received": info["received_timestamp"], "publisher": nodes.name(str(topic), info["gid"])}
                        for topic, data, info in receiver.batch(HEARTBEAT_SECONDS, MAX_BATCH)]
            yield {"event": "messages", "messages": messages} if messages else {"event": "heartbeat"}
    finally:
        receiver.close()


def _transforms(message: Any) -> list[list]:
    """A TFMessage's transforms as ``[parent, child, stamp_ns, [x, y, z], [qx, qy, qz, qw]]``."""
    found = []
    for stamped in message.transforms:
        t, r, stamp = stamped.transform.translation, stamped.transform.rotation, stamped.header.stamp
        found.append([stamped.header.frame_id, stamped.child_frame_id, stamp.sec * 1_000_000_000 + stamp.nanosec,
                      [t.x, t.y, t.z], [r.x, r.y, r.z, r.w]])
    return found


class PublisherNames:
    """The full names of the nodes behind publisher gids on a topic, from the graph (looked up again,
    at most every POLL_SECONDS, when a gid is not known yet). Where the middleware gives no writer GUID
    with a message (Cyclone DDS: an instance handle, roc.ros.vendors.cyclonedds), a message is named
    only while its topic has one publishing node, and is unnamed (None) when several publish it."""

    def __init__(self, graph) -> None:
        self._graph = graph
        self._names: dict[tuple[str, str], str] = {}
        self._only: dict[str, str | None] = {}  # each topic's one publishing node (None: several, or none)
        self._looked: dict[str, float] = {}

    def name(self, topic: str, gid: str) -> str | None:
        if (topic, gid) not in self._names and time.monotonic() - self._looked.get(topic, 0.0) >= POLL_SECONDS:
            self._looked[topic] = time.monotonic()
            now = {gid_text(info.endpoint_gid): full_name(info.node_namespace, info.node_name)
                   for info in self._graph.node.get_publishers_info_by_topic(topic)
                   if info.node_name != "_NODE_NAME_UNKNOWN_"}
            self._names.update({(topic, known): name for known, name in now.items()})
            self._only[topic] = next(iter(set(now.values()))) if len(set(now.values())) == 1 else None
        if (topic, gid) in self._names:
            return self._names[topic, gid]
        return self._only.get(topic) if vendors.of_prefix(bytes.fromhex(gid.replace(".", ""))) is None else None
