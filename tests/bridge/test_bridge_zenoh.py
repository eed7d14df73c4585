"""roc bridge across Zenoh: two ``roc bridge`` processes on localhost, each joining its own ROS domain
to a Zenoh session (one listens on a free TCP port, the other connects), with real rclpy nodes."""

from __future__ import annotations

import json
import shutil
import socket
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from helpers.bridge import (
    assert_each_arrived_once,
    bridge_line,
    hear_the_other_side,
    start_bridge,
    stop_bridge,
    talker_and_listener,
)
from helpers.build import ros_domain_id
from helpers.graph import assert_call_and_goal_work, graph_env, read_line, roc, start_nodes, stop_all, threads

pytestmark = pytest.mark.xdist_group("busy_or_timing")  # see scripts/test.sh

BASIC_TYPES = {"bool_value": True, "char_value": 65, "float32_value": 1.5, "float64_value": -2.25, "int8_value": -8,
               "uint8_value": 200, "int16_value": -1600, "uint16_value": 60000, "int32_value": -320000,
               "uint32_value": 4000000000, "int64_value": -(2 ** 40), "uint64_value": 2 ** 63}
PUBLISHED = [  # topic, type, values, QoS
    ("chatter", "std_msgs/msg/String", {"data": "hi"}, {}),
    ("cmd", "geometry_msgs/msg/Twist", {}, {"reliability": "best_effort"}),
    ("basic", "test_msgs/msg/BasicTypes", BASIC_TYPES, {}),
    ("sequences", "test_msgs/msg/UnboundedSequences",
     {"string_values": ["a", "b c"], "int32_values": [1, -2], "float64_values": [0.5]}, {}),
    ("joints", "sensor_msgs/msg/JointState", {"name": ["j1", "j2"], "position": [0.1, 0.2], "effort": [1.0]}, {}),
    ("latched", "std_msgs/msg/String", {"data": "kept"}, {"durability": "transient_local", "depth": 1}),
]


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def _link(env: dict[str, str], endpoint: str, *args: str) -> subprocess.Popen:
    """A ``roc bridge`` joining ``env``'s domain to Zenoh, printing JSON events; ``endpoint``: --zenoh-listen
    or --zenoh-connect and its value."""
    return start_bridge(*endpoint.split(), "--domain", env["ROS_DOMAIN_ID"], "--format", "json", *args, env=env)


def _events_until(process: subprocess.Popen, done: Callable[[list[dict]], bool], seconds: float = 40) -> list[dict]:
    """The JSON events the link prints until ``done(events)`` (which it must be within ``seconds``)."""
    events: list[dict] = []
    deadline = time.monotonic() + seconds
    while not done(events):
        assert time.monotonic() < deadline, events
        events.append(json.loads(bridge_line(process, deadline)))
    return events


def _carried(direction: str, topics: set[str]) -> Callable[[list[dict]], bool]:
    """Done once the link carries each of ``topics`` in ``direction`` ("out" or "in")."""
    return lambda events: topics <= {e["topic"] for e in events if e["event"] == "bridging"
                                     and e["direction"] == direction}


def _listener(side: str) -> dict:
    """A node in ``side`` that subscribes to every PUBLISHED topic with its QoS and prints each message."""
    return {"name": f"listener_{side}", "subscribers": [
        {"topic": topic, "type": type_name, "print": True, **qos} for topic, type_name, _values, qos in PUBLISHED]}


def _first_messages(process: subprocess.Popen, seconds: float = 40) -> dict[str, str]:
    """The first message (its repr) the listener printed for each PUBLISHED topic."""
    first: dict[str, str] = {}
    deadline = time.monotonic() + seconds
    while len(first) < len(PUBLISHED):
        assert time.monotonic() < deadline, first
        line = read_line(process, deadline - time.monotonic())
        assert line, f"the listener ended or said nothing: {first}"
        printed = json.loads(line)
        first.setdefault(printed["topic"], printed["message"])
    return first


@pytest.mark.slow
def test_topics_arrive_intact_with_their_names_types_and_qos_and_a_service_and_an_action_answer(tmp_path: Path) -> None:
    a = graph_env(12, tmp_path / "a")
    b = {**a, "ROS_DOMAIN_ID": ros_domain_id(13)}
    endpoint = f"tcp/127.0.0.1:{_free_port()}"
    talker = start_nodes([[{"name": "talker", "publishers": [
        {"topic": topic, "type": type_name, "values": values, **qos, **({} if topic == "latched" else {"rate_hz": 10})}
        for topic, type_name, values, qos in PUBLISHED],
        "services": [{"name": "echo_types", "type": "test_msgs/srv/BasicTypes", "echo": True}],
        "actions": [{"name": "fibonacci", "step_seconds": 0.05}]}]], a)
    processes, links = list(talker), []
    try:
        links.append(_link(a, f"--zenoh-listen {endpoint}", "--all", "--service", "/echo_types",
                           "--action", "fibonacci"))
        out = _events_until(links[0], _carried("out", {f"/{topic}" for topic, *_ in PUBLISHED} | {"/echo_types"}))
        # the far side joins after the latched message went out: it reaches it from the publication cache
        links.append(_link(b, f"--zenoh-connect {endpoint}", *(f"/{topic}" for topic, *_ in PUBLISHED),
                           "--service", "echo_types", "--action", "/fibonacci"))
        action = {f"/fibonacci/_action/{part}"
                  for part in ("send_goal", "cancel_goal", "get_result", "feedback", "status")}
        came_in = _events_until(links[1], _carried("in", {f"/{topic}" for topic, *_ in PUBLISHED} | {"/echo_types"}
                                                   | action))
        assert_call_and_goal_work(b)
        # listeners that start later still: the latched message is kept on both sides
        processes += start_nodes([[_listener("a")]], a) + start_nodes([[_listener("b")]], b)
        direct, bridged = _first_messages(processes[-2]), _first_messages(processes[-1])
        assert bridged == direct
        assert bridged["latched"] == "std_msgs.msg.String(data='kept')"
        assert "uint64_value=9223372036854775808" in bridged["basic"]
        described = {e["topic"]: (e["type"], e.get("reliability"), e.get("durability"))
                     for e in came_in if e["event"] == "bridging"}
        assert {e["topic"]: described[e["topic"]] for e in out if e["event"] == "bridging"} == {
            e["topic"]: (e["type"], e.get("reliability"), e.get("durability")) for e in out if e["event"] == "bridging"}
        assert described["/echo_types"] == ("test_msgs/srv/BasicTypes", None, None)
        assert described["/cmd"] == ("geometry_msgs/msg/Twist", "best_effort", "volatile")
        assert described["/latched"] == ("std_msgs/msg/String", "reliable", "transient_local")
        info = json.loads(roc("topic", "info", "-v", "/latched", "--format", "json", "--no-daemon", env=b).stdout)
        assert [(p["topic_type"], p["qos"]["durability"]) for p in info["publishers"]] == [
            ("std_msgs/msg/String", "TRANSIENT_LOCAL")]
        assert (stop_bridge(links[1]), stop_bridge(links[0])) == (130, 130)
    finally:
        stop_all([*links, *processes])


@pytest.mark.slow
def test_both_ways_without_loops_and_a_late_publisher(tmp_path: Path) -> None:
    """Both links carry every topic; /chatter has a talker on each side: every message reaches the
    other side once and nothing comes back; a publisher started later on side B reaches side A."""
    a = graph_env(12, tmp_path / "a")
    b = {**a, "ROS_DOMAIN_ID": ros_domain_id(13)}
    endpoint = f"tcp/127.0.0.1:{_free_port()}"
    nodes = start_nodes([[talker_and_listener("a")]], a) + start_nodes([[talker_and_listener("b")]], b)
    links, late = [], []
    try:
        links = [_link(a, f"--zenoh-listen {endpoint}", "--all"), _link(b, f"--zenoh-connect {endpoint}", "--all")]
        for link in links:
            _events_until(link, lambda events: all(_carried(way, {"/chatter"})(events) for way in ("out", "in")))
        for link in links:  # Zenoh's receive work runs on its net runtime: no rx threads
            names = {name for name, _ in threads(link)}
            assert "net-0" in names and not any(name.startswith("rx-") for name in names)
        late = start_nodes([[{"name": "late", "publishers": [
            {"topic": "late_news", "type": "std_msgs/msg/String", "values": {"data": "new"}, "rate_hz": 10}]}]], b)
        _events_until(links[0], _carried("in", {"/late_news"}))
        assert roc("topic", "echo", "/late_news", "--once", "--no-daemon", env=a).stdout == "data: new\n---\n"
        deadline = time.monotonic() + 30
        while True:  # a loop would carry each message again and again: hundreds a second
            event = json.loads(bridge_line(links[0], deadline))
            rates = event.get("rates", {})
            if min(rates.get(f"/chatter ({way})", 0) for way in ("in", "out")) > 5:
                break
        assert max(rates.values()) < 40, event
        heard = hear_the_other_side(nodes)
        assert [stop_bridge(link) for link in links] == [130, 130]
    finally:
        stop_all([*links, *late])
        stop_all(nodes)
    assert_each_arrived_once(nodes, heard)


def _certificates(directory: Path) -> dict[str, Path]:
    """A certificate authority and a server certificate for localhost it signs (with openssl)."""
    files = {name: directory / name for name in ("ca.key", "ca.pem", "server.key", "server.csr", "server.pem",
                                                 "san.cnf")}
    files["san.cnf"].write_text("subjectAltName=DNS:localhost,IP:127.0.0.1\n")
    new_key = ["req", "-newkey", "rsa:2048", "-nodes", "-keyout"]
    for command in ([*new_key, files["ca.key"], "-x509", "-out", files["ca.pem"], "-days", "1", "-subj", "/CN=roc CA"],
                    [*new_key, files["server.key"], "-out", files["server.csr"], "-subj", "/CN=localhost"],
                    ["x509", "-req", "-in", files["server.csr"], "-CA", files["ca.pem"], "-CAkey", files["ca.key"],
                     "-CAcreateserial", "-out", files["server.pem"], "-days", "1", "-extfile", files["san.cnf"]]):
        subprocess.run(["openssl", *map(str, command)], check=True, capture_output=True)
    return files


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("openssl") is None, reason="openssl makes the test certificates")
def test_tls_as_zenoh_configures_it(tmp_path: Path) -> None:
    a = graph_env(12, tmp_path / "a")
    b = {**a, "ROS_DOMAIN_ID": ros_domain_id(13)}
    files = _certificates(tmp_path)
    listen, connect = tmp_path / "listen.json5", tmp_path / "connect.json5"
    no_scouting = "scouting: {multicast: {enabled: false}}"
    listen.write_text(f'{{{no_scouting}, transport: {{link: {{tls: {{listen_private_key: "{files["server.key"]}", '
                      f'listen_certificate: "{files["server.pem"]}"}}}}}}}}')
    connect.write_text(f'{{{no_scouting}, transport: {{link: {{tls: {{root_ca_certificate: "{files["ca.pem"]}"}}}}}}}}')
    endpoint = f"tls/localhost:{_free_port()}"
    talker = start_nodes([[{"name": "talker", "publishers": [
        {"topic": "chatter", "type": "std_msgs/msg/String", "values": {"data": "secret"}, "rate_hz": 10}]}]], a)
    links = []
    try:
        links = [_link(a, f"--zenoh-listen {endpoint}", "--zenoh-config", str(listen), "/chatter"),
                 _link(b, f"--zenoh-connect {endpoint}", "--zenoh-config", str(connect), "/chatter")]
        _events_until(links[1], _carried("in", {"/chatter"}))
        assert roc("topic", "echo", "/chatter", "--once", "--no-daemon", env=b).stdout == "data: secret\n---\n"
    finally:
        stop_all([*links, *talker])


@pytest.mark.parametrize("args, error", [
    (["--zenoh-listen", "nonsense", "/chatter"], "--zenoh-listen nonsense: Endpoints must be of the form "
                                                 "<protocol>/<address>"),
    (["--zenoh-connect", "tcp/127.0.0.1:x", "/chatter"], "--zenoh-connect tcp/127.0.0.1:x: expected tcp/HOST:PORT"),
    (["--zenoh-connect", "tcp/127.0.0.1:7447"], "nothing to bridge: name topics, --all, --service or --action"),
    (["--zenoh-connect", "tcp/127.0.0.1:7447", "--from-domain", "1", "/chatter"], "--from-domain, --to-domain"),
    (["--zenoh-config", "missing.json5", "--all"], "missing.json5: not a Zenoh configuration: No such file"),
    (["--zenoh-listen", "tcp/127.0.0.1:7447", "--domain", "300", "--all"], "--domain: expected a ROS domain id"),
])
def test_bad_zenoh_bridges_are_one_line(tmp_path: Path, args: list[str], error: str) -> None:
    result = roc("bridge", *args, env=graph_env(12, tmp_path))
    assert result.returncode == 2 and error in result.stderr.splitlines()[0], result.stderr


def test_a_busy_listen_port_is_one_line(tmp_path: Path) -> None:
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        endpoint = f"tcp/127.0.0.1:{busy.getsockname()[1]}"
        result = roc("bridge", "--zenoh-listen", endpoint, "--all", env=graph_env(12, tmp_path))
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith(f"roc: error: cannot open the Zenoh session: Can not create a new TCP listener "
                                    f"bound to {endpoint}"), result.stderr


def test_an_announcement_key_gives_back_the_topic_and_its_header() -> None:
    from roc.ros.bridges.zenoh_link import _announced, _announcement

    header = {"type": "sensor_msgs/msg/Image", "reliability": "best_effort", "durability": "volatile", "depth": 5}
    key = _announcement("a514b943", "/robot_1/camera/image", header)
    assert key == "roc/announce/a514b943/robot_1/camera/image/-/sensor_msgs/msg/Image/best_effort/volatile/5"
    assert _announced(key) == ("a514b943", "/robot_1/camera/image", header)
