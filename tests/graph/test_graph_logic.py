"""Fast unit tests of the graph verbs' shared pieces (no ROS graph): listings, find and type verbs on a
fixed snapshot, the daemon's replacement check and daemon-less discovery's quiet period."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from roc.cli.main import main

SNAPSHOT = {
    "topics": [{"name": "/_hidden/t", "types": ["std_msgs/msg/String"], "publishers": 1, "subscribers": 0},
               {"name": "/chatter", "types": ["std_msgs/msg/String"], "publishers": 1, "subscribers": 2},
               {"name": "/odom", "types": ["nav_msgs/msg/Odometry"], "publishers": 0, "subscribers": 1}],
    "services": [{"name": "/a/_private", "types": ["std_srvs/srv/Empty"]},
                 {"name": "/reset", "types": ["std_srvs/srv/Empty"]}],
    "actions": [{"name": "/fibonacci", "types": ["test_msgs/action/Fibonacci"]}],
    "nodes": [{"name": "talker", "namespace": "/", "full_name": "/talker"},
              {"name": "_roc_1", "namespace": "/", "full_name": "/_roc_1"},
              {"name": "talker", "namespace": "/", "full_name": "/talker"}],
}


@pytest.fixture
def graph(monkeypatch):
    """Graph verbs answer from SNAPSHOT; returns a runner giving (exit code, stdout, stderr)."""
    calls = []

    def fake_query(method, params=None, *, use_daemon=True, spin_time=None):
        calls.append((method, use_daemon, spin_time))
        return json.loads(json.dumps(SNAPSHOT))

    monkeypatch.setattr("roc.commands.graph_query.query", fake_query)

    def run(capsys, *argv):
        code = main(list(argv))
        out, err = capsys.readouterr()
        return code, out, err

    run.calls = calls
    return run


@pytest.mark.parametrize("argv, expected", [
    (("topic", "list"), "/chatter\n/odom\n"),
    (("topic", "list", "--include-hidden-topics"), "/_hidden/t\n/chatter\n/odom\n"),
    (("topic", "list", "-t"), "/chatter [std_msgs/msg/String]\n/odom [nav_msgs/msg/Odometry]\n"),
    (("topic", "list", "-c"), "2\n"),
    (("topic", "list", "--count-topics", "--include-hidden-topics"), "3\n"),
    (("topic", "list", "-v"), "Published topics:\n * /chatter [std_msgs/msg/String] 1 publisher\n\n"
                              "Subscribed topics:\n * /chatter [std_msgs/msg/String] 2 subscribers\n"
                              " * /odom [nav_msgs/msg/Odometry] 1 subscriber\n\n"),
    (("service", "list", "-t"), "/reset [std_srvs/srv/Empty]\n"),
    (("service", "list", "--include-hidden-services", "-c"), "2\n"),
    (("action", "list", "-t"), "/fibonacci [test_msgs/action/Fibonacci]\n"),
    (("action", "list", "--count-actions"), "1\n"),
    (("topic", "find", "std_msgs/msg/String"), "/chatter\n"),
    (("topic", "find", "-c", "--include-hidden-topics", "std_msgs/msg/String"), "2\n"),
    (("service", "find", "std_srvs/srv/Empty", "--include-hidden-services"), "/a/_private\n/reset\n"),
    (("service", "find", "-c", "std_srvs/srv/Nope"), "0\n"),
    (("topic", "type", "/odom"), "nav_msgs/msg/Odometry\n"),
    (("service", "type", "/reset"), "std_srvs/srv/Empty\n"),
    (("action", "type", "/fibonacci"), "test_msgs/action/Fibonacci\n"),
    (("node", "list", "-a"), "/_roc_1\n/talker\n/talker\n"),
    (("node", "list", "--count-nodes"), "2\n"),
])
def test_listings_as_ros2(graph, capsys, argv, expected):
    code, out, _ = graph(capsys, *argv)
    assert (code, out) == (0, expected)


def test_json_shapes_of_listings(graph, capsys):
    assert json.loads(graph(capsys, "topic", "list", "-c", "--format", "json")[1]) == {"count": 2}
    assert json.loads(graph(capsys, "service", "list", "--format", "json")[1]) == [
        {"name": "/reset", "types": ["std_srvs/srv/Empty"]}]
    assert json.loads(graph(capsys, "topic", "find", "std_msgs/msg/String", "--format", "json")[1]) == ["/chatter"]
    assert json.loads(graph(capsys, "action", "type", "/fibonacci", "--format", "json")[1]) == {
        "name": "/fibonacci", "types": ["test_msgs/action/Fibonacci"]}
    assert json.loads(graph(capsys, "node", "list", "--format", "json")[1]) == [
        {"name": "/talker", "duplicate": True}, {"name": "/talker", "duplicate": True}]


def test_duplicate_node_names_warned_once(graph, capsys):
    code, out, err = graph(capsys, "node", "list")
    assert (code, out) == (0, "/talker\n/talker\n")
    assert err.splitlines() == ["roc: warning: several nodes are named /talker: 2 nodes; give each a unique name "
                                "(parameters, services and node info mix them up)"]


@pytest.mark.parametrize("noun", ["topic", "service", "action"])
def test_unknown_name_is_ros2s_message(graph, capsys, noun):
    code, out, err = graph(capsys, noun, "type", "/nope")
    assert (code, out, err) == (1, "", f"roc: error: Unknown {noun} '/nope'\n")


def test_no_daemon_and_spin_time_reach_the_query(graph, capsys):
    graph(capsys, "topic", "list")
    graph(capsys, "service", "find", "x", "--no-daemon", "--spin-time", "0.7")
    assert graph.calls == [("snapshot", True, None), ("snapshot", False, 0.7)]


class FakeConnection:
    def __init__(self, hello):
        self.hello, self.sent, self.closed = hello, [], False

    def request(self, method, params=None, timeout=None):
        self.sent.append(method)
        return self.hello if method == "hello" else {"stopping": True}

    def close(self):
        self.closed = True


def test_daemon_of_another_version_or_environment_is_shut_down():
    from roc import __version__
    from roc.ros.client import _usable
    from roc.ros.protocol import discovery_environment

    same = FakeConnection({"version": __version__, "environment": discovery_environment()})
    assert _usable(same) and same.sent == ["hello"] and not same.closed
    for hello in ({"version": "0.0.0-other", "environment": discovery_environment()},
                  {"version": __version__, "environment": {**discovery_environment(), "ROS_DOMAIN_ID": "x"}}):
        other = FakeConnection(hello)
        assert not _usable(other)
        assert other.sent == ["hello", "shutdown"] and other.closed


class FakeClock:
    """Stands in for the time module in roc.ros.graph: sleeping advances it."""

    def __init__(self) -> None:
        self.now = 0.0

    def monotonic(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.now += seconds


class FakeGraph:
    """Stands in for roc.ros.graph.Graph: its signature changes until ``settles_at``, this host's other
    participants are all discovered from ``peers_at`` (never when None; "uncountable": cannot be told)."""

    def __init__(self, clock: FakeClock, settles_at: float, peers_at: float | None):
        self.clock, self.settles_at, self.peers_at = clock, settles_at, peers_at

    def signature(self):
        return round(self.clock.now, 2) if self.clock.now < self.settles_at else "settled"

    def _complete(self, told):
        return True

    def _prompt_writers(self, probe, told) -> bool:  # on Cyclone DDS: no writer to prompt
        return False

    def _local_peers_discovered(self, domain: int, probe) -> bool | None:
        if self.peers_at == "uncountable":
            return None
        return self.peers_at is not None and self.clock.now >= self.peers_at


class FakeReader:
    """Stands in for roc.ros.discovery_info.DiscoveryInfoReader: nothing told, nothing to wait for."""

    def __init__(self, node) -> None:
        pass

    def take(self) -> dict:
        return {}

    def close(self) -> None:
        pass


class FakeProbe:
    """Stands in for roc.ros.discovery.LocalParticipantProbe (FakeGraph tells who has been discovered)."""

    def __init__(self, domain: int) -> None:
        pass

    def ask(self) -> int:
        return 0

    def pass_on_endpoints(self) -> int:
        return 0

    def close(self) -> None:
        pass


def _fake_graph(monkeypatch, clock: FakeClock, settles_at: float, peers_at, middleware: str = "rmw_fastrtps_cpp"):
    from roc.ros import graph as graph_module

    monkeypatch.setattr(graph_module, "time", clock)
    monkeypatch.setattr(graph_module, "DiscoveryInfoReader", FakeReader)
    monkeypatch.setattr(graph_module, "LocalParticipantProbe", FakeProbe)
    monkeypatch.setenv("RMW_IMPLEMENTATION", middleware)
    fake = FakeGraph(clock, settles_at, peers_at)
    fake.node = None
    fake.context = type("Context", (), {"get_domain_id": lambda self: 0})()
    return fake


@pytest.mark.parametrize("settles_at, peers_at, period, ends_at, why", [
    (0.0, 0.0, 3.5, 0.1, "complete"),  # quiet and every local participant heard: at once (after the local quiet time)
    (0.6, 0.2, 3.5, 0.7, "complete"),  # still changing until 0.6 s: 0.1 s of quiet more
    (0.0, 1.2, 3.5, 1.2, "complete"),  # a participant of this host not heard yet: waits for it
    (0.0, None, 3.5, 3.5, "incomplete"),  # one never heard: the whole period (--spin-time)
    (60.0, 0.0, 2.0, 2.0, "period ended"),  # never quiet: the period
    (0.0, None, None, 6.5, "incomplete"),  # without --spin-time, one known unheard: one more announcement period
    (0.0, 5.0, None, 5.0, "complete"),  # ... ending when it is heard
    (0.0, "uncountable", None, 3.5, "period ended"),  # the default period when who is missing cannot be told
    (60.0, 0.0, None, 3.5, "period ended"),  # never quiet but complete: the default period
])
def test_discovery_ends_when_this_hosts_participants_are_heard_and_the_graph_is_quiet(
        monkeypatch, settles_at, peers_at, period, ends_at, why):
    pytest.importorskip("rclpy")
    from roc.ros import graph as graph_module

    clock = FakeClock()
    fake = _fake_graph(monkeypatch, clock, settles_at, peers_at)
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    assert graph_module.Graph.wait_for_discovery(fake, period) == why
    assert clock.now == pytest.approx(ends_at, abs=graph_module.POLL_SECONDS + 1e-9)


def test_no_fast_dds_announcement_period_is_waited_for_on_another_middleware(monkeypatch):
    """Without --spin-time, a participant of this host never heard: Fast DDS waits one more of its
    announcement periods (3 s); Cyclone DDS and a middleware roc does not know, the default period only."""
    pytest.importorskip("rclpy")
    from roc.ros import graph as graph_module

    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    for middleware, ends_at in (("rmw_fastrtps_cpp", 6.5), ("rmw_cyclonedds_cpp", 3.5), ("rmw_zenoh_cpp", 3.5)):
        clock = FakeClock()
        fake = _fake_graph(monkeypatch, clock, 0.0, None, middleware)
        assert graph_module.Graph.wait_for_discovery(fake, None) == "incomplete"
        assert clock.now == pytest.approx(ends_at, abs=graph_module.POLL_SECONDS + 1e-9), middleware


def test_beyond_this_host_discovery_waits_longer_for_quiet(monkeypatch):
    pytest.importorskip("rclpy")
    from roc.ros import graph as graph_module

    clock = FakeClock()
    fake = _fake_graph(monkeypatch, clock, 0.0, 0.0)
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "SUBNET")
    assert graph_module.Graph.wait_for_discovery(fake, 3.5) == "complete"
    assert clock.now == pytest.approx(graph_module.QUIET_SECONDS, abs=graph_module.POLL_SECONDS + 1e-9)


# ---- roc bridge: domain_bridge configs and the loop guard ------------------------------------------

def test_a_domain_bridge_config_keeps_repeated_topics_and_reverses(tmp_path: Path) -> None:
    """domain_bridge's own example names a topic several times; each entry is a route."""
    from roc.commands.bridge.domains import routes_from_config
    from roc.ros.bridges.domains import Route

    config = tmp_path / "bridge.yaml"
    config.write_text("name: my_bridge\nfrom_domain: 2\nto_domain: 3\ntopics:\n"
                      "  chatter:\n    type: example_interfaces/msg/String\n    qos:\n      reliability: best_effort\n"
                      "  chatter:\n    type: example_interfaces/msg/String\n    to_domain: 4\n"
                      "  chatter:\n    type: example_interfaces/msg/String\n    reversed: True\n"
                      "  chatter:\n    type: example_interfaces/msg/String\n    from_domain: 7\n    to_domain: 8\n"
                      "    bidirectional: True\n"
                      "  chatter:\n    type: example_interfaces/msg/String\n    remap: chitter\n"
                      "services:\n  add_two_ints:\n    type: example_interfaces/srv/AddTwoInts\n    from_domain: 4\n"
                      "actions:\n  fibonacci:\n    type: example_interfaces/action/Fibonacci\n    from_domain: 1\n")
    string = "example_interfaces/msg/String"
    assert routes_from_config(config) == [
        Route("/chatter", 2, 3, string, qos={"reliability": "best_effort"}), Route("/chatter", 2, 4, string),
        Route("/chatter", 3, 2, string), Route("/chatter", 7, 8, string), Route("/chatter", 8, 7, string),
        Route("/chatter", 2, 3, string, "/chitter"),
        Route("/add_two_ints", 4, 3, "example_interfaces/srv/AddTwoInts", kind="service"),
        Route("/fibonacci", 1, 3, "example_interfaces/action/Fibonacci", kind="action")]


def test_an_action_is_bridged_as_its_services_and_topics() -> None:
    from roc.ros.bridges.domains import Route, action_routes

    parts = action_routes(Route("/fib", 1, 2, "test_msgs/action/Fibonacci", "/fob", kind="action"))
    assert [(p.kind, p.name, p.target, p.type) for p in parts] == [
        ("service", "/fib/_action/send_goal", "/fob/_action/send_goal", None),
        ("service", "/fib/_action/cancel_goal", "/fob/_action/cancel_goal", None),
        ("service", "/fib/_action/get_result", "/fob/_action/get_result", None),
        ("topic", "/fib/_action/feedback", "/fob/_action/feedback", None),
        ("topic", "/fib/_action/status", "/fob/_action/status", None)]


def test_the_loop_guard_checks_the_user_s_profile(tmp_path: Path) -> None:
    from roc.errors import UsageError
    from roc.ros.bridges.domains import Route, loop_guard, two_way
    from roc.ros.vendors.fastdds import BRIDGE_PROFILE

    both = [Route("/x", 1, 2), Route("/x", 2, 1)]
    assert two_way(both) == ["/x"] and two_way([Route("/x", 1, 2), Route("/x", 1, 3)]) == []
    assert two_way([Route("*", 1, 2), Route("/y", 2, 1)]) == ["*", "/y"]
    loop_guard(both, {})  # the bridge's participants take BRIDGE_PROFILE
    loop_guard(both, {"FASTRTPS_DEFAULT_PROFILES_FILE": str(BRIDGE_PROFILE)})  # inherited from roc: not the user's
    assert "<name>fastdds.ignore_local_endpoints</name>" in BRIDGE_PROFILE.read_text()
    theirs = tmp_path / "profile.xml"
    theirs.write_text("<dds/>")
    loop_guard([Route("/x", 1, 2)], {"FASTRTPS_DEFAULT_PROFILES_FILE": str(theirs)})  # one way: any profile
    with pytest.raises(UsageError, match=f"{theirs}: bridging /x both ways needs the participant property"):
        loop_guard(both, {"FASTRTPS_DEFAULT_PROFILES_FILE": str(theirs)})
    with pytest.raises(UsageError, match="/x: bridging both ways needs Fast DDS"):
        loop_guard(both, {"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"})


@pytest.mark.parametrize(("environment", "chosen"), [
    ({}, "bridge"),
    ({"RMW_IMPLEMENTATION": "rmw_fastrtps_dynamic_cpp"}, "bridge"),
    ({"FASTRTPS_DEFAULT_PROFILES_FILE": "participant"}, "bridge"),
    ({"FASTRTPS_DEFAULT_PROFILES_FILE": "/mine.xml"}, "/mine.xml"),
    ({"FASTDDS_DEFAULT_PROFILES_FILE": "/mine.xml"}, None),
    ({"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}, None),
], ids=["fast-dds", "dynamic", "roc-s-own", "user-profile", "user-profile-fast-dds-3", "cyclone"])
def test_roc_s_participants_take_roc_s_profile_unless_the_user_chose(environment: dict, chosen: str | None) -> None:
    from roc.ros.vendors.fastdds import BRIDGE_PROFILE, PARTICIPANT_PROFILE, use_profile

    ours = {"participant": str(PARTICIPANT_PROFILE), "bridge": str(BRIDGE_PROFILE)}
    environment = {k: ours.get(v, v) for k, v in environment.items()}
    use_profile(BRIDGE_PROFILE, environment)
    assert environment.get("FASTRTPS_DEFAULT_PROFILES_FILE") == ours.get(chosen, chosen)
    for profile in (PARTICIPANT_PROFILE, BRIDGE_PROFILE):  # every roc participant announces itself every 0.5 s
        assert "<leaseAnnouncement><sec>0</sec><nanosec>500000000</nanosec></leaseAnnouncement>" in profile.read_text()


def test_only_middlewares_that_speak_rtps_get_port_counting_and_stand_in_announcements() -> None:
    from roc.ros import vendors

    assert vendors.speaks_rtps("rmw_fastrtps_cpp") and vendors.speaks_rtps("rmw_cyclonedds_cpp")
    assert vendors.speaks_rtps("rmw_connextdds")  # a DDS roc has no module for: still RTPS
    assert not vendors.speaks_rtps("rmw_zenoh_cpp")
    assert vendors.discovery_of("rmw_zenoh_cpp").startswith("Zenoh")
    assert vendors.discovery_of("rmw_cyclonedds_cpp").startswith("DDS")
