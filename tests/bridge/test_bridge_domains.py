"""roc bridge between two ROS domains, with real rclpy nodes on each side."""

from __future__ import annotations

import json
import subprocess
import time
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

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("busy_or_timing")]  # see scripts/test.sh

TALKER = {"name": "talker", "publishers": [
    {"topic": "chatter", "type": "std_msgs/msg/String", "values": {"data": "hi"}, "rate_hz": 20},
    {"topic": "latched", "type": "std_msgs/msg/String", "values": {"data": "kept"}, "durability": "transient_local",
     "depth": 1},
    {"topic": "cmd", "type": "geometry_msgs/msg/Twist", "values": {}, "rate_hz": 20, "reliability": "best_effort"}]}


@pytest.fixture
def domains(tmp_path):
    """Two ROS domains of this worker's own (A with a talker), and an environment for each."""
    a = graph_env(10, tmp_path / "a")
    b = {**a, "ROS_DOMAIN_ID": ros_domain_id(11)}
    processes = start_nodes([[TALKER]], a)
    yield a, b
    stop_all(processes)


def _bridging_lines(process: subprocess.Popen, count: int, seconds: float = 20) -> list[str]:
    """The first ``count`` "bridging ..." lines the bridge prints (rate tables in between left out)."""
    lines: list[str] = []
    deadline = time.monotonic() + seconds
    while len(lines) < count:
        assert time.monotonic() < deadline, lines
        line = bridge_line(process, deadline)
        if line.startswith("bridging "):
            lines.append(line)
    return lines


def _events_until(process: subprocess.Popen, topic: str, seconds: float = 20) -> list[dict]:
    """The JSON events the bridge prints until it bridges ``topic`` (which it must within ``seconds``)."""
    events: list[dict] = []
    deadline = time.monotonic() + seconds
    while not any(e["event"] == "bridging" and e["topic"] == topic for e in events):
        assert time.monotonic() < deadline, events
        events.append(json.loads(bridge_line(process, deadline)))
    return events


@pytest.mark.distro
def test_topics_arrive_in_the_other_domain_with_their_qos(domains) -> None:
    a, b = domains
    bridge = start_bridge("--from-domain", a["ROS_DOMAIN_ID"], "--to-domain", b["ROS_DOMAIN_ID"], "/chatter", "latched",
                     "/cmd", env=a)
    try:
        announced = sorted(_bridging_lines(bridge, 3))
        assert announced == [
            f"bridging /chatter [std_msgs/msg/String] domain {a['ROS_DOMAIN_ID']} -> {b['ROS_DOMAIN_ID']} (reliable, volatile)\n",
            f"bridging /cmd [geometry_msgs/msg/Twist] domain {a['ROS_DOMAIN_ID']} -> {b['ROS_DOMAIN_ID']} (best_effort, volatile)\n",
            f"bridging /latched [std_msgs/msg/String] domain {a['ROS_DOMAIN_ID']} -> {b['ROS_DOMAIN_ID']} (reliable, transient_local)\n"]
        echoed = roc("topic", "echo", "/chatter", "--once", "--no-daemon", env=b)
        assert (echoed.returncode, echoed.stdout) == (0, "data: hi\n---\n")
        kept = roc("topic", "echo", "/latched", "--once", "--no-daemon", env=b)  # published once, before
        assert (kept.returncode, kept.stdout) == (0, "data: kept\n---\n")
        info = json.loads(roc("topic", "info", "-v", "/latched", "--format", "json", "--no-daemon", env=b).stdout)
        assert [p["qos"]["durability"] for p in info["publishers"]] == ["TRANSIENT_LOCAL"]
        twist = roc("topic", "echo", "/cmd", "--once", "--no-daemon", "--field", "linear.x", env=b)
        assert (twist.returncode, twist.stdout) == (0, "0.0\n---\n")
    finally:
        assert stop_bridge(bridge) == 130


def test_all_picks_up_a_late_publisher_and_a_config_remaps(domains, tmp_path: Path) -> None:
    a, b = domains
    config = tmp_path / "bridge.yaml"
    config.write_text(f"name: test\nfrom_domain: {a['ROS_DOMAIN_ID']}\nto_domain: {b['ROS_DOMAIN_ID']}\n"
                      "topics:\n  chatter:\n    type: std_msgs/msg/String\n    remap: chatter_b\n")
    bridge = start_bridge("--config", str(config), "--all", "--from-domain", a["ROS_DOMAIN_ID"], "--to-domain",
                     b["ROS_DOMAIN_ID"], "--exclude", "^/(rosout|parameter_events|latched|cmd)$", "--format", "json",
                     env=a)
    late = None
    try:
        events = _events_until(bridge, "/chatter")
        chatter = next(e for e in events if e.get("topic") == "/chatter")
        assert (chatter["target"], chatter["from_domain"]) == ("/chatter_b", int(a["ROS_DOMAIN_ID"]))
        late = start_nodes([[{"name": "late", "publishers": [
            {"topic": "late_news", "type": "std_msgs/msg/String", "values": {"data": "new"}, "rate_hz": 10}]}]], a)
        events += _events_until(bridge, "/late_news")
        assert roc("topic", "echo", "/late_news", "--once", "--no-daemon", env=b).stdout == "data: new\n---\n"
        assert roc("topic", "echo", "/chatter_b", "--once", "--no-daemon", env=b).stdout == "data: hi\n---\n"
        rates = next(e for e in events if e["event"] == "rates")["rates"]
        assert all(key.endswith(f"({a['ROS_DOMAIN_ID']}->{b['ROS_DOMAIN_ID']})") for key in rates)
    finally:
        assert stop_bridge(bridge) == 130
        if late:
            stop_all(late)


@pytest.mark.parametrize("args, config, error", [
    (["/chatter"], None, "give --from-domain and --to-domain with topics, --service, --action or --all"),
    (["--from-domain", "3", "--to-domain", "3", "/chatter"], None, "/chatter: bridging domain 3 into itself would loop"),
    ([], "mode: compress\ntopics:\n  chatter:\n    type: std_msgs/msg/String\n", "mode: only 'normal' is supported"),
    ([], "services:\n  add:\n    bidirectional: true\n", ":2: services: add: bidirectional: only topics go both ways"),
    ([], "topics:\n  chatter:\n    colour: red\n", ":2: topics: chatter: unknown key 'colour'"),
    ([], "topics:\n  chatter:\n    qos: {deadline: 5}\n", "qos: deadline: only 'auto' is supported"),
    ([], "from_domain: 999\ntopics:\n  chatter: {}\n", "topics: chatter: from_domain: expected a ROS domain id"),
    ([], "colour: red\n", ":1: unknown key 'colour'"),
    ([], "topics: [a\n", "not valid YAML"),
])
def test_bad_bridges_are_one_line(tmp_path: Path, args: list[str], config: str | None, error: str) -> None:
    if config is not None:
        (tmp_path / "bridge.yaml").write_text(config)
        args = [*args, "--config", str(tmp_path / "bridge.yaml")]
    result = roc("bridge", *args, env=graph_env(10, tmp_path))
    assert result.returncode == 2 and error in result.stderr.splitlines()[0], result.stderr


def test_both_ways_without_loops(tmp_path: Path) -> None:
    """/chatter bridged both ways between two domains, each with a talker: every message reaches the
    other domain once, and nothing the bridge publishes comes back to it."""
    a = graph_env(10, tmp_path / "a")
    b = {**a, "ROS_DOMAIN_ID": ros_domain_id(11)}
    nodes = start_nodes([[talker_and_listener("a")]], a) + start_nodes([[talker_and_listener("b")]], b)
    bridge = start_bridge("--from-domain", a["ROS_DOMAIN_ID"], "--to-domain", b["ROS_DOMAIN_ID"], "--bidirectional",
                     "/chatter", "--format", "json", env=a)
    try:
        events = _events_until(bridge, "/chatter", 30)
        while sum(e["event"] == "bridging" for e in events) < 2:
            events.append(json.loads(bridge_line(bridge, time.monotonic() + 30)))
        assert sorted((e["from_domain"], e["to_domain"]) for e in events if e["event"] == "bridging") == sorted(
            [(int(a["ROS_DOMAIN_ID"]), int(b["ROS_DOMAIN_ID"])), (int(b["ROS_DOMAIN_ID"]), int(a["ROS_DOMAIN_ID"]))])
        deadline = time.monotonic() + 30
        while True:  # a rates event once both directions carry messages (a loop would make it hundreds)
            event = json.loads(bridge_line(bridge, deadline))
            if event["event"] == "rates" and len(event["rates"]) == 2 and min(event["rates"].values()) > 5:
                break
        assert max(event["rates"].values()) < 40, event
        heard = hear_the_other_side(nodes)
    finally:
        assert stop_bridge(bridge) == 130
        stop_all(nodes)
    assert_each_arrived_once(nodes, heard)


def test_a_service_and_an_action_are_served_in_the_other_domain(tmp_path: Path) -> None:
    a = graph_env(10, tmp_path / "a")
    b = {**a, "ROS_DOMAIN_ID": ros_domain_id(11)}
    server = start_nodes([[{"name": "server", "services": [
        {"name": "echo_types", "type": "test_msgs/srv/BasicTypes", "echo": True}],
        "actions": [{"name": "fibonacci", "step_seconds": 0.05}]}]], a)
    bridge = start_bridge("--from-domain", a["ROS_DOMAIN_ID"], "--to-domain", b["ROS_DOMAIN_ID"], "--service",
                     "echo_types", "--action", "/fibonacci", env=a)
    try:
        announced = _bridging_lines(bridge, 6)
        assert (f"bridging service /echo_types [test_msgs/srv/BasicTypes] domain {a['ROS_DOMAIN_ID']} -> "
                f"{b['ROS_DOMAIN_ID']}\n") in announced
        assert_call_and_goal_work(b)
    finally:
        assert stop_bridge(bridge) == 130
        stop_all(server)


def _event_thread_wakes(process: subprocess.Popen) -> int:
    """How many times the Fast DDS event threads (``dds.ev.N``, one per participant) of ``process`` slept."""
    return sum(int(task.joinpath("status").read_text().split("voluntary_ctxt_switches:")[1].split()[0])
               for name, task in threads(process) if name.startswith("dds.ev"))


def test_the_bridges_writer_does_not_wake_fast_dds_for_each_message(tmp_path: Path) -> None:
    """A reliable writer with Fast DDS's default NACK suppression (0 s) wakes its participant's event
    thread more than twice per message sent to another process; the bridge's profile (20 ms) covers
    many messages with one timer."""
    a = graph_env(10, tmp_path / "a")
    b = {**a, "ROS_DOMAIN_ID": ros_domain_id(11)}
    nodes = start_nodes([[{"name": "fast_talker", "publishers": [
        {"topic": "fast", "type": "std_msgs/msg/String", "values": {"data": "x"}, "rate_hz": 500}]}]], a)
    nodes += start_nodes([[{"name": "listener", "subscribers": [{"topic": "fast", "type": "std_msgs/msg/String"}]}]],
                         b)
    bridge = start_bridge("--from-domain", a["ROS_DOMAIN_ID"], "--to-domain", b["ROS_DOMAIN_ID"], "/fast",
                     "--format", "json", env=a)
    deadline = time.monotonic() + 40

    def bridged_per_second() -> float:
        """The next rates event's count (messages a second, over about a second)."""
        while (event := json.loads(bridge_line(bridge, deadline)))["event"] != "rates":
            pass
        return sum(event["rates"].values())
    try:
        _events_until(bridge, "/fast")
        while bridged_per_second() < 100:  # messages flow
            pass
        info = json.loads(roc("topic", "info", "-v", "/fast", "--format", "json", "--no-daemon", env=b).stdout)
        assert [s["node_name"] for s in info["subscribers"]] == ["listener"]  # else the writer sends to no one
        while read_line(bridge, 0):  # printed while topic info ran
            pass
        bridged_per_second()  # the count starts with a rates period
        wakes = _event_thread_wakes(bridge)
        bridged = sum(bridged_per_second() for _ in range(3))
        wakes = _event_thread_wakes(bridge) - wakes
        assert bridged > 300
        assert wakes < bridged, (wakes, bridged)  # 2.6 a message with Fast DDS's default, 0.4 with roc's
    finally:
        assert stop_bridge(bridge) == 130
        stop_all(nodes)
