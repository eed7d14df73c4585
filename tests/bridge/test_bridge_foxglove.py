"""roc bridge --foxglove: a real talker, a real roc bridge, and a Foxglove WebSocket protocol client (the
``websockets`` package) offering either subprotocol name."""

from __future__ import annotations

import asyncio
import json
import signal
import socket
import struct
import subprocess
import time
from pathlib import Path

import pytest
from helpers.build import BIN, stop_process
from helpers.graph import graph_env, read_line, roc, start_nodes, stop_all
from websockets.sync.client import connect

from roc.ros.bridges.foxglove_server import SEPARATOR, _Session, schema_text
from roc.ros.interfaces import definition_path

pytestmark = pytest.mark.xdist_group("busy_or_timing")  # see scripts/test.sh

SUBPROTOCOLS = ["foxglove.sdk.v1", "foxglove.websocket.v1"]
TALKER = {"name": "talker", "publishers": [
    {"topic": "chatter", "type": "std_msgs/msg/String", "values": {"data": "hi"}, "rate_hz": 20},
    {"topic": "cmd", "type": "geometry_msgs/msg/Twist", "values": {}, "rate_hz": 20, "reliability": "best_effort"},
    {"topic": "latched", "type": "std_msgs/msg/String", "values": {"data": "kept"}, "durability": "transient_local",
     "depth": 1}],
    "subscribers": [{"topic": "from_json", "type": "std_msgs/msg/String", "print": True},
                    {"topic": "from_cdr", "type": "geometry_msgs/msg/Twist", "print": True}]}


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class Bridge:
    """A running ``roc bridge --foxglove --format json`` and its status events."""

    def __init__(self, env: dict[str, str], *args: str) -> None:
        self.port = _free_port()
        self.process = subprocess.Popen([str(BIN / "roc"), "bridge", "--foxglove", "--port", str(self.port),
                                         "--format", "json", *args], env=env, stdout=subprocess.PIPE,
                                        stderr=subprocess.PIPE, text=True)
        self.events: list[dict] = []
        self.event(lambda e: e["event"] == "serving")

    def event(self, wanted, seconds: float = 30, after: dict | None = None) -> dict:
        """The first event (seen so far or to come within ``seconds``; only those that came after the
        event ``after``, if given) for which ``wanted`` is true."""
        deadline = time.monotonic() + seconds
        start = 0 if after is None else next(i for i, e in enumerate(self.events) if e is after) + 1
        while True:
            found = next((e for e in self.events[start:] if wanted(e)), None)
            if found:
                return found
            line = read_line(self.process, deadline - time.monotonic())
            assert line, f"no such event in {seconds} s; got {self.events}"
            self.events.append(json.loads(line))

    def drain(self) -> list[dict]:
        """Every event so far."""
        while line := read_line(self.process, 0):
            self.events.append(json.loads(line))
        return self.events

    def stop(self) -> int:
        """Ctrl+C, as a person stops it: the exit code."""
        self.process.send_signal(signal.SIGINT)
        try:
            return self.process.wait(timeout=20)
        finally:
            stop_process(self.process)


def _client(port: int, subprotocol: str):
    """A connection offering only ``subprotocol``, to use in a ``with``."""
    return connect(f"ws://127.0.0.1:{port}", subprotocols=[subprotocol], max_size=None, open_timeout=20)


class Client:
    """A Foxglove WebSocket protocol client: the channels the server advertises and the messages it sends."""

    def __init__(self, ws) -> None:
        self.ws = ws
        self.channels: dict[str, dict] = {}
        self.ops: list[dict] = []
        self.messages: list[tuple[int, bytes]] = []

    def _receive(self, deadline: float) -> None:
        try:
            frame = self.ws.recv(timeout=max(0.1, deadline - time.monotonic()))
        except TimeoutError:
            return
        if isinstance(frame, bytes):
            assert frame[0] == 1, frame[:1]  # messageData: subscription id, receive time, payload
            self.messages.append((struct.unpack_from("<I", frame, 1)[0], frame[13:]))
            return
        op = json.loads(frame)
        self.ops.append(op)
        if op["op"] == "advertise":
            self.channels.update({channel["topic"]: channel for channel in op["channels"]})
        elif op["op"] == "unadvertise":
            self.channels = {t: c for t, c in self.channels.items() if c["id"] not in op["channelIds"]}

    def until(self, done, seconds: float = 30):
        deadline = time.monotonic() + seconds
        while not (result := done()):
            assert time.monotonic() < deadline, f"not in {seconds} s; ops {self.ops}"
            self._receive(deadline)
        return result

    def channel(self, topic: str) -> dict:
        return self.until(lambda: self.channels.get(topic))

    def subscribe(self, subscription: int, topic: str) -> bytes:
        """Subscribe to the topic's channel; the CDR payload of the first message that arrives."""
        self.ws.send(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": subscription, "channelId": self.channel(topic)["id"]}]}))
        return self.until(lambda: next((data for sid, data in self.messages if sid == subscription), None))

    def send(self, channel: int, payload: bytes) -> None:
        self.ws.send(b"\x01" + struct.pack("<I", channel) + payload)


@pytest.fixture
def talker_env(tmp_path):
    env = graph_env(14, tmp_path)
    talker = start_nodes([[TALKER]], env)
    yield env, talker[0]
    stop_all(talker)


@pytest.fixture
def bridge(talker_env):
    env, _talker = talker_env
    served = Bridge(env)
    yield served
    assert served.stop() == 130


def _deserialize(data: bytes, type_name: str):
    from rclpy.serialization import deserialize_message

    from roc.ros.types import message_class

    return deserialize_message(data, message_class(type_name))


def _text(type_name: str) -> str:
    return definition_path(type_name).read_text().rstrip("\n")


def test_schema_text_is_the_msg_then_each_nested_type_once_depth_first() -> None:
    section = f"{SEPARATOR}\nMSG: "
    assert schema_text("geometry_msgs/msg/Twist") == "\n".join([
        _text("geometry_msgs/msg/Twist"), f"{section}geometry_msgs/msg/Vector3",
        _text("geometry_msgs/msg/Vector3")]) + "\n"
    nested = ["std_msgs/msg/Header", "builtin_interfaces/msg/Time", "geometry_msgs/msg/Pose",
              "geometry_msgs/msg/Point", "geometry_msgs/msg/Quaternion"]
    assert schema_text("geometry_msgs/msg/PoseStamped") == "\n".join(
        [_text("geometry_msgs/msg/PoseStamped")] + [f"{section}{t}\n{_text(t)}" for t in nested]) + "\n"
    assert schema_text("std_msgs/msg/String") == _text("std_msgs/msg/String") + "\n"


@pytest.mark.slow
@pytest.mark.parametrize("subprotocol", SUBPROTOCOLS)
def test_a_client_gets_channels_with_ros2msg_schemas_and_cdr_messages(bridge: Bridge, subprotocol: str) -> None:
    with _client(bridge.port, subprotocol) as ws:
        client = Client(ws)
        assert client.ws.subprotocol == subprotocol
        info = client.until(lambda: next((op for op in client.ops if op["op"] == "serverInfo"), None))
        assert "clientPublish" in info["capabilities"] and {"cdr", "json"} <= set(info["supportedEncodings"])
        cmd = client.channel("/cmd")
        assert (cmd["encoding"], cmd["schemaName"], cmd["schemaEncoding"]) == (
            "cdr", "geometry_msgs/msg/Twist", "ros2msg")
        assert cmd["schema"] == schema_text("geometry_msgs/msg/Twist")
        assert f"{SEPARATOR}\nMSG: geometry_msgs/msg/Vector3\n" in cmd["schema"]
        assert client.channel("/chatter")["schemaName"] == "std_msgs/msg/String"
        assert _deserialize(client.subscribe(1, "/chatter"), "std_msgs/msg/String").data == "hi"
        assert _deserialize(client.subscribe(2, "/cmd"), "geometry_msgs/msg/Twist").linear.x == 0.0
        connected = bridge.event(lambda e: e["event"] == "client_connected")
        assert connected["subprotocol"] == subprotocol
        subscribed = bridge.event(lambda e: e["event"] == "subscribed" and e["topic"] == "/cmd")
        rates = bridge.event(lambda e: e["event"] == "rates" and e["rates"].get("/chatter", 0) > 0, after=subscribed)
        assert set(rates["rates"]) == {"/chatter", "/cmd"}  # only what clients subscribe to
    assert bridge.event(lambda e: e["event"] == "unsubscribed" and e["topic"] == "/chatter")


@pytest.mark.slow
def test_client_publishing_reaches_a_ros_subscriber(bridge: Bridge, talker_env) -> None:
    _env, talker = talker_env
    with _client(bridge.port, "foxglove.websocket.v1") as ws:
        client = Client(ws)
        client.ws.send(json.dumps({"op": "advertise", "channels": [
            {"id": 7, "topic": "/from_json", "encoding": "json", "schemaName": "std_msgs/msg/String"},
            {"id": 8, "topic": "/from_cdr", "encoding": "cdr", "schemaName": "geometry_msgs/msg/Twist"}]}))
        from rclpy.serialization import serialize_message

        twist = serialize_message(_twist(2.5))
        wanted = {"from_json": "std_msgs.msg.String(data='hello')", "from_cdr": repr(_twist(2.5))}
        received: dict[str, str] = {}
        deadline = time.monotonic() + 30
        while set(received) != set(wanted):  # published until the subscriber has matched and received
            assert time.monotonic() < deadline, (received, bridge.events)
            client.send(7, json.dumps({"data": "hello"}).encode())
            client.send(8, twist)
            while line := read_line(talker, 0.3):
                message = json.loads(line)
                received[message["topic"]] = message["message"]
        assert received == wanted
        cdr = bridge.event(lambda e: e["event"] == "client_advertised" and e["topic"] == "/from_cdr")
        assert cdr["encoding"] == "cdr"
        client.ws.send(json.dumps({"op": "advertise", "channels": [
            {"id": 9, "topic": "/nowhere", "encoding": "json", "schemaName": "no_such_msgs/msg/Thing"}]}))
        refused = bridge.event(lambda e: e["event"] == "client_publish_refused")
        assert refused["topic"] == "/nowhere" and "no_such_msgs" in refused["reason"]
        client.ws.send(json.dumps({"op": "advertise", "channels": [
            {"id": 10, "topic": "/from_json", "encoding": "json", "schemaName": "std_msgs/msg/String"}]}))
        bridge.event(lambda _e: sum(e["event"] == "client_advertised" and e["topic"] == "/from_json"
                                    for e in bridge.events) == 2)
        client.send(10, json.dumps({"colour": "red"}).encode())
        wrong = bridge.event(lambda e: e["event"] == "client_message_refused")
        assert wrong["topic"] == "/from_json" and "colour" in wrong["reason"], wrong


@pytest.mark.slow
def test_every_client_gets_a_transient_local_topics_kept_message(bridge: Bridge) -> None:
    with _client(bridge.port, "foxglove.sdk.v1") as first, _client(bridge.port, "foxglove.websocket.v1") as second:
        assert _deserialize(Client(first).subscribe(1, "/latched"), "std_msgs/msg/String").data == "kept"
        assert _deserialize(Client(second).subscribe(1, "/latched"), "std_msgs/msg/String").data == "kept"


def _twist(x: float):
    from geometry_msgs.msg import Twist, Vector3

    return Twist(linear=Vector3(x=x))


@pytest.mark.slow
def test_a_later_topic_is_advertised_and_unadvertised_when_it_goes(bridge: Bridge, talker_env) -> None:
    env, _talker = talker_env
    with _client(bridge.port, "foxglove.sdk.v1") as ws:
        client = Client(ws)
        client.channel("/chatter")
        late = start_nodes([[{"name": "late", "publishers": [
            {"topic": "late_news", "type": "std_msgs/msg/String", "values": {"data": "new"}, "rate_hz": 10}]}]], env)
        try:
            channel = client.channel("/late_news")
            assert _deserialize(client.subscribe(3, "/late_news"), "std_msgs/msg/String").data == "new"
        finally:
            stop_all(late)
        client.until(lambda: any(op["op"] == "unadvertise" and channel["id"] in op["channelIds"] for op in client.ops))
    assert bridge.event(lambda e: e["event"] == "unadvertised" and e["topic"] == "/late_news")


@pytest.mark.slow
def test_include_and_exclude_select_the_channels_and_ctrl_c_stops_with_a_client(talker_env) -> None:
    env, _talker = talker_env
    served = Bridge(env, "--include", "^/c", "--exclude", "^/cmd$")
    try:
        with _client(served.port, "foxglove.websocket.v1") as ws:
            client = Client(ws)
            client.subscribe(1, "/chatter")
            time.sleep(2)  # two more scans
            assert [e["topic"] for e in served.drain() if e["event"] == "advertised"] == ["/chatter"]
            assert set(client.channels) == {"/chatter"}
            assert served.stop() == 130  # Ctrl+C with a client connected and subscribed
        assert served.process.stderr.read() == "roc: interrupted\n"  # no traceback, no thread left hanging
    finally:
        stop_process(served.process)


def test_a_port_in_use_is_one_line(tmp_path: Path) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        result = roc("bridge", "--foxglove", "--port", str(port), env=graph_env(14, tmp_path))
    assert result.returncode == 1 and result.stderr.splitlines() == [
        f"roc: error: port {port} on 127.0.0.1 is in use: stop what listens there or choose another with --port"]


@pytest.mark.parametrize("args, error", [
    (["--from-domain", "1"], "--foxglove serves every topic of one domain: drop --from-domain"),
    (["/chatter"], "--foxglove serves every topic of one domain: drop the topic names"),
    (["--port", "70000"], "--port: expected 0 to 65535, got 70000"),
    (["--include", "("], "--include/--exclude: invalid regular expression '('"),
])
def test_bad_foxglove_options_are_one_line(tmp_path: Path, args: list[str], error: str) -> None:
    result = roc("bridge", "--foxglove", *args, env=graph_env(14, tmp_path))
    assert result.returncode == 2 and error in result.stderr.splitlines()[0], result.stderr


class _Connection:
    """A stand-in for one side of a relayed WebSocket connection: the frames it brings, those sent to it."""

    def __init__(self, *frames: str) -> None:
        self.frames, self.sent = list(frames), []

    async def __aiter__(self):
        for frame in self.frames:
            yield frame

    async def send(self, frame: str) -> None:
        self.sent.append(frame)

    async def close(self) -> None:
        pass


def test_the_relay_sends_again_a_subscription_refused_for_a_channel_just_advertised() -> None:
    subscribe = {"op": "subscribe", "subscriptions": [{"id": 3, "channelId": 5}, {"id": 4, "channelId": 9}]}
    client = _Connection(json.dumps(subscribe))
    server = _Connection(json.dumps({"op": "advertise", "channels": [{"id": 5, "topic": "/a"}]}),
                         json.dumps({"op": "status", "level": 2, "message": "Unknown channel ID: 5"}),
                         json.dumps({"op": "status", "level": 2, "message": "Unknown channel ID: 9"}))

    async def relay() -> None:
        session = _Session(client, server)
        await session.upward()
        await session.downward()
        await asyncio.sleep(0.3)
    asyncio.run(relay())
    assert [json.loads(frame) for frame in server.sent] == [
        subscribe, {"op": "subscribe", "subscriptions": [{"id": 3, "channelId": 5}]}]
    assert [json.loads(frame)["op"] for frame in client.sent] == ["advertise", "status"]  # 9 was never advertised
    assert "Unknown channel ID: 9" in client.sent[-1]
