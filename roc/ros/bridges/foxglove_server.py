"""A ROS domain served to Foxglove over its WebSocket protocol, with the ``foxglove-sdk`` server.

Every topic of the domain that has a publisher (other than ours), and matches ``include`` / none of
``exclude``, becomes a channel: schema encoding ``ros2msg`` (the type's .msg text, then each nested
type's, see ``schema_text``), message encoding ``cdr``. The raw CDR bytes of a ROS message are
logged as they arrive, never deserialised. Topics are looked for every second: new ones are
advertised, vanished ones unadvertised. A topic is subscribed in ROS only while a client subscribes
to its channel (as foxglove_bridge does), with QoS following its publishers; a transient-local topic
is subscribed anew for each client that joins, so that it too gets the kept messages (clients already
subscribed get them again). With ``clientPublish``, a client's channel (encoding ``cdr``, or ``json``
with a ROS message type as ``schemaName``) gets a ROS publisher on its topic: CDR is published as it
is, JSON sets the message's fields.

Why a relay in front of the SDK server: foxglove-sdk 0.30 accepts only the subprotocol
``foxglove.sdk.v1`` and answers clients that offer only ``foxglove.websocket.v1`` (older Foxglove apps,
other tools) with HTTP 400, although the wire format is the same. So the SDK server listens on a
free port of 127.0.0.1, and a small ``websockets`` server on the public address accepts either
name and relays every frame both ways unchanged (one upstream connection per client; ``_Session``
has the one repair). This keeps the whole protocol (channel ids, subscriptions, client channels) in
the maintained SDK rather than in a home-made server, adds only a localhost hop
(bench/foxglove_bench.py: 0.3 ms added at the median at 1 kHz, with the ROS side), and tells us
about client connections, which the SDK's listener does not.

The server never prints: ``run`` yields status events.
"""

from __future__ import annotations

import asyncio
import errno
import json
import queue
import re
import threading
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import foxglove
from foxglove import Channel, Schema
from foxglove.websocket import Capability, ServerListener
from rclpy.qos import DurabilityPolicy, QoSProfile
from rosidl_parser import definition as idl
from websockets.asyncio.client import connect
from websockets.asyncio.server import serve
from websockets.exceptions import ConnectionClosed
from websockets.typing import Subprotocol

from roc.errors import RocError
from roc.ros.bridges.domains import TopicFilter, receive_profile
from roc.ros.cdr import serialize
from roc.ros.dataplane import qos_profile
from roc.ros.graph import Graph
from roc.ros.interfaces import definition_path
from roc.ros.messages import fill_message
from roc.ros.types import InterfaceClass, message_class, type_name

SCAN_SECONDS = 1.0
LATCHED = DurabilityPolicy.TRANSIENT_LOCAL
SERVER_NODE = "_roc_foxglove"
SUBPROTOCOLS = ("foxglove.sdk.v1", "foxglove.websocket.v1")  # the SDK's own name first
SEPARATOR = "=" * 80
UNKNOWN_CHANNEL = re.compile(r"Unknown channel ID: (\d+)")  # the SDK's status text
RETRIES, RETRY_SECONDS = 20, 0.05
CLOSE_SECONDS = 1.0  # a peer that does not answer a close frame is given up on then (websockets waits 10 s)


def schema_text(name: str) -> str:
    """The ``ros2msg`` schema of a message type, as rosbag2 and foxglove_bridge write it: the type's
    .msg text, then for each nested type (depth first, each once) a line of 80 ``=``, a line
    ``MSG: pkg/msg/Type`` and its .msg text. Nested types come from the generated class (rosidl)."""
    parts: list[str] = []
    seen: set[str] = set()

    def add(cls: InterfaceClass, nested: bool) -> None:
        name_ = type_name(cls)
        path = definition_path(name_)
        if path.suffix != ".msg":
            raise RocError(f"{name_}: no .msg definition installed (only {path.name})")
        if nested:
            parts.append(f"{SEPARATOR}\nMSG: {name_}")
        parts.append(path.read_text().rstrip("\n"))
        for slot in cls.SLOT_TYPES:
            inner = slot.value_type if isinstance(slot, idl.AbstractNestedType) else slot
            if isinstance(inner, idl.NamespacedType):
                nested_name = "/".join([*inner.namespaces, inner.name])
                if nested_name not in seen:
                    seen.add(nested_name)
                    add(message_class(nested_name), True)

    add(message_class(name), False)
    return "\n".join(parts) + "\n"


@dataclass
class _Topic:
    """An advertised topic: its channel, and its ROS subscription while clients subscribe."""

    type: str
    cls: InterfaceClass
    channel: Channel
    subscription: Any = None
    clients: set[int] = field(default_factory=set)
    count: int = 0


@dataclass
class _ClientTopic:
    """A channel a client advertised, and the ROS publisher its messages go to."""

    topic: str
    cls: type
    encoding: str
    publisher: Any
    failed: bool = False


class _Relay:
    """The public WebSocket server: accepts either subprotocol and relays frames to the SDK server."""

    def __init__(self, host: str, port: int, events: queue.Queue) -> None:
        self.events = events
        self.upstream = 0  # the SDK server's port, set before any client can be relayed
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        try:
            self.server = asyncio.run_coroutine_threadsafe(self._start(host, port), self.loop).result()
        except OSError as error:
            self._stop_loop()
            if error.errno == errno.EADDRINUSE:
                raise RocError(f"port {port} on {host} is in use: stop what listens there or choose "
                               "another with --port") from None
            raise RocError(f"cannot listen on {host}:{port}: {error.strerror or error}") from None

    async def _start(self, host: str, port: int):
        return await serve(self._relay, host, port, subprotocols=[Subprotocol(name) for name in SUBPROTOCOLS],
                           compression=None,
                           max_size=None, close_timeout=CLOSE_SECONDS)

    async def _relay(self, client) -> None:
        peer = ":".join(str(part) for part in client.remote_address[:2])
        self.events.put({"event": "client_connected", "client": peer, "subprotocol": client.subprotocol})
        try:
            async with connect(f"ws://127.0.0.1:{self.upstream}", subprotocols=[Subprotocol(SUBPROTOCOLS[0])],
                               compression=None, max_size=None, close_timeout=CLOSE_SECONDS) as server:
                session = _Session(client, server)
                pumps = [asyncio.ensure_future(session.upward()), asyncio.ensure_future(session.downward())]
                _done, pending = await asyncio.wait(pumps, return_when=asyncio.FIRST_COMPLETED)
                for pump in pending:
                    pump.cancel()
        finally:
            self.events.put({"event": "client_disconnected", "client": peer})

    def _stop_loop(self) -> None:
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(timeout=5)

    def close(self) -> None:
        async def stop() -> None:
            self.server.close()
            await self.server.wait_closed()
        try:
            asyncio.run_coroutine_threadsafe(stop(), self.loop).result(timeout=5)
        finally:
            self._stop_loop()


class _Session:
    """One client's frames relayed both ways unchanged (text stays text, binary binary), with one repair.

    The SDK sends an ``advertise`` before it records the channel as advertised to that client, so a
    client that subscribes at once (as the Foxglove app does) may get "Unknown channel ID". Such a
    subscription, to a channel the relay saw advertised, is sent again a little later instead of
    passing the error on."""

    def __init__(self, client, server) -> None:
        self.client, self.server = client, server
        self.advertised: set[int] = set()
        self.asked: dict[int, dict] = {}  # channel id -> the client's subscription to it
        self.retries: dict[int, int] = {}

    async def upward(self) -> None:
        await self._pump(self.client, self.server, self._from_client)

    async def downward(self) -> None:
        await self._pump(self.server, self.client, self._from_server)

    @staticmethod
    async def _pump(source, target, keep) -> None:
        """Frames from ``source`` to ``target`` (those ``keep`` passes) until either side closes; then
        ``target`` is closed too."""
        try:
            async for frame in source:
                if keep(_control(frame)):
                    await target.send(frame)
        except ConnectionClosed:
            pass
        finally:
            await target.close()

    def _from_client(self, op: dict) -> bool:
        if op.get("op") == "subscribe":
            self.asked.update({s.get("channelId"): s for s in op.get("subscriptions", [])})
        return True

    def _from_server(self, op: dict) -> bool:
        if op.get("op") == "advertise":
            self.advertised.update(channel.get("id") for channel in op.get("channels", []))
        elif op.get("op") == "unadvertise":
            self.advertised.difference_update(op.get("channelIds", []))
        elif op.get("op") == "status":
            return not self._retry(op.get("message", ""))
        return True

    def _retry(self, message: str) -> bool:
        found = UNKNOWN_CHANNEL.fullmatch(message)
        channel = int(found.group(1)) if found else None
        if channel not in self.advertised or channel not in self.asked or self.retries.get(channel, 0) >= RETRIES:
            return False
        self.retries[channel] = self.retries.get(channel, 0) + 1
        subscribe = json.dumps({"op": "subscribe", "subscriptions": [self.asked[channel]]})
        asyncio.get_running_loop().call_later(RETRY_SECONDS, asyncio.ensure_future, self._send_up(subscribe))
        return True

    async def _send_up(self, frame: str) -> None:
        try:
            await self.server.send(frame)
        except ConnectionClosed:
            pass


def _control(frame: str | bytes) -> dict:
    """A text frame's JSON object (a control message), else {}."""
    if isinstance(frame, bytes):
        return {}
    try:
        op = json.loads(frame)
    except ValueError:
        return {}
    return op if isinstance(op, dict) else {}


class FoxgloveServer:
    """The relay on ``host:port``, the SDK server behind it and a hidden node in ``domain`` (default
    ROS_DOMAIN_ID); ``run`` drives it, ``close`` stops all three."""

    def __init__(self, host: str = "127.0.0.1", port: int = 8765, domain: int | None = None,
                 include: Sequence[str] = (), exclude: Sequence[str] = ()) -> None:
        self._wanted = TopicFilter(include, exclude)
        self.host = host
        self.events: queue.Queue[dict[str, Any]] = queue.Queue()
        self.topics: dict[str, _Topic] = {}
        self.skipped: set[str] = set()
        self.client_topics: dict[tuple[int, int], _ClientTopic] = {}
        self.lock = threading.Lock()
        self.relay = _Relay(host, port, self.events)  # first: a port in use fails before ROS starts
        self.port = self.relay.server.sockets[0].getsockname()[1]
        self.context = foxglove.Context()
        self.sdk = None
        try:
            self.sdk = foxglove.start_server(name="roc bridge", host="127.0.0.1", port=0, context=self.context,
                                             capabilities=[Capability.ClientPublish], server_listener=_Listener(self),
                                             supported_encodings=["cdr", "json"])
            self.relay.upstream = self.sdk.port
            self.graph = Graph(SERVER_NODE, domain_id=domain, events=True)  # as the domain bridge: fast
        except BaseException:
            self.relay.close()
            if self.sdk is not None:
                self.sdk.stop()
            raise

    def close(self) -> None:
        self.relay.close()
        if self.sdk is not None:
            self.sdk.stop()
        with self.lock:
            for topic in self.topics.values():
                topic.channel.close()
        self.graph.close()

    # -- ROS topics to channels -----------------------------------------------------------------
    def _published(self, name: str) -> bool:
        return any(p.node_name != SERVER_NODE for p in self.graph.node.get_publishers_info_by_topic(name))

    def _scan(self) -> Iterator[dict[str, Any]]:
        """Advertise new topics, unadvertise vanished ones; their events."""
        present = {name: types[0] for name, types in self.graph.node.get_topic_names_and_types()
                   if types and self._wanted(name) and self._published(name)}
        for name, type_ in sorted(present.items()):
            if name in self.topics or f"{name} {type_}" in self.skipped:
                continue
            try:
                cls, schema = message_class(type_), schema_text(type_)
            except RocError as error:
                self.skipped.add(f"{name} {type_}")
                yield {"event": "skipped", "topic": name, "type": type_, "reason": str(error)}
                continue
            channel = Channel(name, schema=Schema(name=type_, encoding="ros2msg", data=schema.encode()),
                              message_encoding="cdr", context=self.context)
            with self.lock:
                self.topics[name] = _Topic(type_, cls, channel)
            yield {"event": "advertised", "topic": name, "type": type_, "channel": channel.id()}
        for name in sorted(set(self.topics) - set(present)):
            with self.lock:
                topic = self.topics.pop(name)
                self._unsubscribe_ros(topic)
            topic.channel.close()
            yield {"event": "unadvertised", "topic": name, "type": topic.type}

    def _topic_of(self, channel_id: int) -> tuple[str, _Topic] | None:
        return next(((n, t) for n, t in self.topics.items() if t.channel.id() == channel_id), None)

    def subscribe(self, client: int, channel_id: int) -> None:
        with self.lock:
            found = self._topic_of(channel_id)
            if found is None:
                return
            name, topic = found
            joins = client not in topic.clients
            topic.clients.add(client)
            if joins and topic.subscription is not None and topic.subscription.qos_profile.durability == LATCHED:
                self._unsubscribe_ros(topic)  # a new subscription gets the kept messages for the new client too
            if topic.subscription is None:
                publishers = self.graph.node.get_publishers_info_by_topic(name)
                qos = receive_profile(qos_profile({"profile": "default"}, publishers))
                log = topic.channel.log

                def forward(data: bytes, topic: _Topic = topic) -> None:
                    log(data)
                    topic.count += 1
                topic.subscription = self.graph.node.create_subscription(topic.cls, name, forward, qos, raw=True)
        self.events.put({"event": "subscribed", "topic": name, "client": client})

    def unsubscribe(self, client: int, channel_id: int) -> None:
        with self.lock:
            found = self._topic_of(channel_id)
            if found is None:
                return
            name, topic = found
            topic.clients.discard(client)
            if not topic.clients:
                self._unsubscribe_ros(topic)
        self.events.put({"event": "unsubscribed", "topic": name, "client": client})

    def _unsubscribe_ros(self, topic: _Topic) -> None:
        if topic.subscription is not None:
            self.graph.node.destroy_subscription(topic.subscription)
            topic.subscription = None

    # -- client channels to ROS publishers --------------------------------------------------------
    def client_advertise(self, client: int, channel) -> None:
        base = {"client": client, "topic": channel.topic, "type": channel.schema_name, "encoding": channel.encoding}
        try:
            if channel.encoding not in ("cdr", "json"):
                raise RocError(f"message encoding '{channel.encoding}' is not supported (use cdr or json)")
            cls = message_class(channel.schema_name)
        except RocError as error:
            self.events.put({"event": "client_publish_refused", **base, "reason": str(error)})
            return
        with self.lock:
            publisher = self.graph.node.create_publisher(cls, channel.topic, QoSProfile(depth=10))
            self.client_topics[(client, channel.id)] = _ClientTopic(channel.topic, cls, channel.encoding, publisher)
        self.events.put({"event": "client_advertised", **base})

    def client_unadvertise(self, client: int, channel_id: int) -> None:
        with self.lock:
            found = self.client_topics.pop((client, channel_id), None)
            if found is not None:
                self.graph.node.destroy_publisher(found.publisher)
        if found is not None:
            self.events.put({"event": "client_unadvertised", "client": client, "topic": found.topic})

    def client_message(self, client: int, channel_id: int, data: bytes) -> None:
        target = self.client_topics.get((client, channel_id))
        if target is None:
            return
        try:
            if target.encoding == "json":
                data = serialize(fill_message(target.cls, json.loads(data)))
            target.publisher.publish(data)
        except (ValueError, RocError) as error:  # bad JSON or fields: said once per channel
            if not target.failed:
                target.failed = True
                self.events.put({"event": "client_message_refused", "client": client, "topic": target.topic,
                                 "reason": str(error)})

    # -- the status stream ------------------------------------------------------------------------
    def run(self, period: float = 1.0) -> Iterator[dict[str, Any]]:
        """A ``serving`` event, then ``advertised``/``unadvertised``, client events as they happen and a
        ``rates`` event every ``period`` seconds (messages a second per subscribed topic), until closed."""
        yield {"event": "serving", "url": f"ws://{self.host}:{self.port}", "host": self.host, "port": self.port,
               "domain": self.graph.context.get_domain_id(), "subprotocols": list(SUBPROTOCOLS)}
        now = time.monotonic()
        next_scan, last_rates = now, now
        counts: dict[str, int] = {}
        while True:
            now = time.monotonic()
            if now >= next_scan:
                yield from self._scan()
                next_scan = time.monotonic() + SCAN_SECONDS
            if now - last_rates >= period:
                with self.lock:
                    now_counts = {name: topic.count for name, topic in self.topics.items()}
                    active = [name for name, topic in self.topics.items() if topic.subscription]
                yield {"event": "rates", "rates": {name: (now_counts[name] - counts.get(name, 0)) / (now - last_rates)
                                                   for name in active}}
                counts, last_rates = now_counts, now
            try:
                yield self.events.get(timeout=max(0.01, min(next_scan, last_rates + period) - time.monotonic()))
            except queue.Empty:
                pass


class _Listener(ServerListener):
    """The SDK's callbacks (on its threads), handed to the server; an error becomes an event, never
    an exception in the SDK."""

    def __init__(self, server: FoxgloveServer) -> None:
        self.server = server

    def _guard(self, action, *args) -> None:
        try:
            action(*args)
        except Exception as error:  # noqa: BLE001 - reported as an event, the server keeps serving
            self.server.events.put({"event": "error", "reason": f"{type(error).__name__}: {error}"})

    def on_subscribe(self, client, channel) -> None:
        self._guard(self.server.subscribe, client.id, channel.id)

    def on_unsubscribe(self, client, channel) -> None:
        self._guard(self.server.unsubscribe, client.id, channel.id)

    def on_client_advertise(self, client, channel) -> None:
        self._guard(self.server.client_advertise, client.id, channel)

    def on_client_unadvertise(self, client, client_channel_id: int) -> None:
        self._guard(self.server.client_unadvertise, client.id, client_channel_id)

    def on_message_data(self, client, client_channel_id: int, data: bytes) -> None:
        self._guard(self.server.client_message, client.id, client_channel_id, data)
