"""roc graph check and roc graph snapshot against a live graph (real rclpy nodes), and the [check]
file's errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from helpers.graph import graph_env, roc, start_nodes, stop_all, stop_daemon, wait_for

from roc.check.expectations import load_checks
from roc.errors import UsageError

SYSTEM = [
    [{"name": "talker", "publishers": [
        {"topic": "chatter", "type": "std_msgs/msg/String", "values": {"data": "hi"}, "rate_hz": 20},
        {"topic": "scan", "type": "std_msgs/msg/String", "values": {"data": "s"}, "rate_hz": 10,
         "reliability": "best_effort"}]}],
    [{"name": "listener", "subscribers": [{"topic": "chatter", "type": "std_msgs/msg/String"},
                                          {"topic": "scan", "type": "std_msgs/msg/String"}]},
     {"name": "motor", "services": [{"name": "~/enable", "type": "std_srvs/srv/SetBool"}],
      "parameters": {"max_speed": 1.5}, "actions": [{"name": "fibonacci"}]}],
]

GOOD = """
[check]
timeout = 5
rate-window = 2
nodes = ["/talker", "/listener", "/motor"]

[[check.topic]]
name = "/chatter"
type = "std_msgs/msg/String"
min-rate = 18
max-rate = 22
publishers = 1
subscribers = 1
reliability = "reliable"

[[check.service]]
name = "/motor/enable"
type = "std_srvs/srv/SetBool"
request = "{data: true}"
response = { success = false }

[[check.action]]
name = "/fibonacci"
type = "test_msgs/action/Fibonacci"

[[check.parameter]]
node = "/motor"
name = "max_speed"
value = 1.5
"""

# One violation of each kind, and the words its failure must say.
VIOLATIONS = {
    'nodes = ["/ghost"]': "node /ghost [",
    '[[check.topic]]\nname = "/chatter"\ntype = "std_msgs/msg/Int32"':
        "fail: type std_msgs/msg/String, expected std_msgs/msg/Int32",
    '[[check.topic]]\nname = "/chatter"\nmin-rate = 50': " Hz, expected 50 Hz (",
    '[[check.topic]]\nname = "/scan"':
        "fail: QoS incompatible (reliability): talker -> listener: publisher offers BEST_EFFORT, subscriber requests RELIABLE",
    '[[check.parameter]]\nnode = "/motor"\nname = "max_speed"\nvalue = 2.0': "fail: 1.5, expected 2.0",
    '[[check.service]]\nname = "/motor/enable"\nrequest = "{data: true}"\nresponse = { success = true }':
        "fail: response success: false, expected true",
    '[[check.service]]\nname = "/nobody/home"': "fail: no service /nobody/home",
}


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    env = graph_env(9, tmp_path_factory.mktemp("runtime"))
    processes = start_nodes(SYSTEM, env)
    yield env
    stop_daemon(env)
    stop_all(processes)


@pytest.mark.slow
def test_a_system_that_meets_every_expectation(graph, tmp_path: Path) -> None:
    from junitparser import JUnitXml

    (tmp_path / "roc.toml").write_text(GOOD)
    report = tmp_path / "report.xml"
    result = roc("-C", str(tmp_path), "graph", "check", "--junit-xml", str(report), env=graph)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Summary: 7 probes finished" in result.stdout
    assert "Finished <<< topic /chatter [" in result.stdout and " Hz, 1 publisher, 1 subscriber" in result.stdout
    suite = next(iter(JUnitXml.fromfile(str(report))))
    assert (suite.tests, suite.failures, suite.errors) == (7, 0, 0)
    assert sorted(case.name for case in suite) == ["/chatter", "/fibonacci", "/listener", "/motor", "/motor max_speed",
                                                   "/motor/enable", "/talker"]


@pytest.mark.slow
@pytest.mark.parametrize("violation", list(VIOLATIONS), ids=[v.split("\n")[-1][:30] for v in VIOLATIONS])
def test_each_kind_of_violation_is_reported_precisely(graph, tmp_path: Path, violation: str) -> None:
    check = tmp_path / "expected.toml"
    check.write_text(f"[check]\ntimeout = 3\nrate-window = 2\n{violation}\n")
    result = roc("graph", "check", "--file", str(check), env=graph)
    assert result.returncode == 1
    assert VIOLATIONS[violation] in result.stdout, result.stdout
    assert "1 probe failed" in result.stdout


@pytest.mark.slow
def test_json_events_carry_each_probes_verdict_without_a_daemon(graph, tmp_path: Path) -> None:
    check = tmp_path / "expected.toml"
    check.write_text('[check]\nnodes = ["/talker", "/ghost"]\n')
    result = roc("graph", "check", "--file", str(check), "--output", "json", "--no-daemon", env=graph)
    verdicts = {e["task"]: (e["status"], e["message"]) for e in map(json.loads, result.stdout.splitlines())
                if e["event"] == "ProbeResult"}
    assert result.returncode == 1
    assert verdicts["node /talker"] == ("pass", "running")
    assert verdicts["node /ghost"][0] == "fail" and verdicts["node /ghost"][1].startswith("no node /ghost (nodes: ")


@pytest.mark.slow
@pytest.mark.parametrize("flags", [[], ["--no-daemon"]], ids=["daemon", "no-daemon"])
def test_a_snapshot_checks_green_against_its_system(graph, tmp_path: Path, flags: list[str]) -> None:
    """Its counts are the system's: the subscriptions roc makes to measure rates are not counted (through
    the daemon, they once made every topic's subscriber count one too many)."""
    snapshot = roc("graph", "snapshot", "--rate-window", "2", *flags, env=graph)
    assert snapshot.returncode == 0, snapshot.stderr
    (tmp_path / "snapshot.toml").write_text(snapshot.stdout)
    checks = load_checks(tmp_path / "snapshot.toml")
    topics = {e.label: e.values for e in checks.expectations if e.label.startswith("topic ")}
    assert topics["topic /chatter"]["type"] == "std_msgs/msg/String"
    assert topics["topic /chatter"]["min-rate"] < 20 < topics["topic /chatter"]["max-rate"]
    assert {label: (values["publishers"], values["subscribers"]) for label, values in topics.items()} == {
        "topic /chatter": (1, 1), "topic /scan": (1, 1)}  # not /rosout, /parameter_events: every node adds to them
    result = roc("graph", "check", "--file", str(tmp_path / "snapshot.toml"), *flags, env=graph)
    # /scan's publisher and subscriber cannot match: the snapshot records the system, incompatible or not
    failed = [line for line in result.stdout.splitlines() if line.startswith("Failed")]
    assert [line.split(" [")[0] for line in failed] == ["Failed   <<< topic /scan"], result.stdout


@pytest.mark.slow
def test_a_snapshot_still_holds_when_one_more_node_joins(graph, tmp_path: Path) -> None:
    """A snapshot pins the system's own topics, not those every node publishes on (/rosout,
    /parameter_events), whose counts change whenever any node starts."""
    snapshot = roc("graph", "snapshot", "--rate-window", "0", env=graph)
    assert snapshot.returncode == 0, snapshot.stderr
    (tmp_path / "snapshot.toml").write_text(snapshot.stdout)
    newcomer = start_nodes([{"name": "newcomer"}], graph)
    try:
        wait_for(lambda: "/newcomer" in roc("node", "list", env=graph).stdout.split())
        result = roc("graph", "check", "--file", str(tmp_path / "snapshot.toml"), env=graph)
    finally:
        stop_all(newcomer)
    failed = [line.split(" [")[0] for line in result.stdout.splitlines() if line.startswith("Failed")]
    assert failed == ["Failed   <<< topic /scan"], result.stdout  # its QoS never matched (see above)


# What roc graph snapshot writes: the nodes one a line, services and actions as inline tables.
SNAPSHOT = """# roc graph snapshot: ...
[check]
nodes = [
    "/listener",
    "/motor",  # the motor's node
]
service = [
    { name = "/motor/enable", type = "std_srvs/srv/SetBool", request = "{data: [1, 2]}" },
    { name = "/motor/reset", type = "std_srvs/srv/Trigger" },
]
action = [{ name = "/fibonacci", type = "test_msgs/action/Fibonacci" }]

[[check.topic]]
name = "/chatter"

[[check.topic]]
name = "/scan"
"""


def test_each_expectation_points_at_its_own_line(tmp_path: Path) -> None:
    """A failing probe names the line of its entry (a node's name, a [[check.topic]] table, an inline
    table), not the [check] header."""
    (tmp_path / "snapshot.toml").write_text(SNAPSHOT)
    checks = load_checks(tmp_path / "snapshot.toml")
    assert {e.label: int(e.where.rsplit(":", 1)[1]) for e in checks.expectations} == {
        "node /listener": 4, "node /motor": 5, "service /motor/enable": 8, "service /motor/reset": 9,
        "action /fibonacci": 11, "topic /chatter": 13, "topic /scan": 16}


@pytest.mark.parametrize("text, error", [
    ("[check]\nnodez = []\n", "roc.toml:2: 'nodez': unknown key of [check]; did you mean 'nodes'?"),
    ("[check]\n[[check.topic]]\nname = '/a'\nmin_rate = 1\n",
     "roc.toml:4: 'min_rate': unknown key of [[check.topic]]; did you mean 'min-rate'?"),
    ("[check]\n[[check.topic]]\nname = '/a'\n[[check.topic]]\nname = '/b'\npublishers = 'one'\n",
     "roc.toml:6: 'publishers': expected an integer, got 'one'"),
    ("[check]\n[[check.parameter]]\nnode = '/a'\nname = 'x'\n", "roc.toml:2: 'value': missing in [[check.parameter]]"),
    ("[check]\n[[check.topic]]\nname = '/a'\nreliability = 'sometimes'\n",
     "roc.toml:4: 'reliability': expected reliable or best_effort, got 'sometimes'"),
])
def test_bad_expectations_name_file_line_and_key(tmp_path: Path, text: str, error: str) -> None:
    (tmp_path / "roc.toml").write_text(text)
    with pytest.raises(UsageError) as raised:
        load_checks(tmp_path / "roc.toml")
    assert str(raised.value).startswith(f"{tmp_path}/{error}")


def _free_port() -> int:
    import socket

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@pytest.mark.slow
def test_watch_serves_prometheus_metrics_until_ctrl_c(graph, tmp_path: Path) -> None:
    import signal
    import subprocess
    import time
    import urllib.error
    import urllib.request

    from helpers.build import BIN, stop_process
    from prometheus_client.parser import text_string_to_metric_families

    check = tmp_path / "expected.toml"
    check.write_text('[check]\nrate-window = 1\nnodes = ["/talker", "/ghost"]\n'
                     '[[check.topic]]\nname = "/chatter"\nmin-rate = 15\n')
    port = _free_port()
    url = f"http://127.0.0.1:{port}/metrics"
    watch = subprocess.Popen([str(BIN / "roc"), "graph", "check", "--file", str(check), "--watch", "--interval", "1",
                              "--prometheus", str(port)], env=graph, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
    try:
        samples: dict = {}
        deadline = time.monotonic() + 30
        while samples.get(("roc_check_rounds", ())) is None or samples[("roc_check_rounds", ())] < 2:
            assert time.monotonic() < deadline, "no second round of metrics"
            time.sleep(0.3)
            try:
                text = urllib.request.urlopen(url, timeout=2).read().decode()
            except (urllib.error.URLError, ConnectionError):
                continue
            samples = {(s.name, tuple(sorted(s.labels.items()))): s.value
                       for family in text_string_to_metric_families(text) for s in family.samples}
        assert samples[("roc_probe_status", (("kind", "node"), ("probe", "node /talker")))] == 1.0
        assert samples[("roc_probe_status", (("kind", "node"), ("probe", "node /ghost")))] == 0.0
        assert samples[("roc_topic_rate_hz", (("topic", "/chatter"),))] == pytest.approx(20, rel=0.05)
        assert samples[("roc_topic_endpoints", (("side", "publishers"), ("topic", "/chatter")))] == 1.0
        watch.send_signal(signal.SIGINT)
        assert watch.wait(timeout=15) == 130
    finally:
        stop_process(watch)
    with pytest.raises(urllib.error.URLError):
        urllib.request.urlopen(url, timeout=2)


def test_probe_values_are_printed_as_yaml() -> None:
    from roc.check.probes import _mismatches
    from roc.render import to_yaml_line

    assert to_yaml_line({"success": True, "message": ""}) == "{success: true, message: ''}"
    assert [to_yaml_line(v) for v in (1.5, "demo_bot", [1.0, 0.1], None)] == ["1.5", "demo_bot", "[1.0, 0.1]", "null"]
    assert _mismatches({"success": True, "pose": {"x": 1}}, {"success": False, "pose": {"x": 2}}) == [
        "success: false, expected true", "pose.x: 2, expected 1"]
