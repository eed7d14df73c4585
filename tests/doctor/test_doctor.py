"""roc doctor (checks, reports, hello) and roc multicast send/receive: the environment checks as units,
the graph checks and hello on live nodes, multicast datagrams over the loopback interface.

The installed ros2 CLI oracle has neither ros2doctor nor ros2multicast; roc's multicast datagrams and
hello messages were checked against ros2cli 0.32.2's (installed from its jazzy sources) when these
tests were written: each side heard the other."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest
from helpers.build import BIN, stop_process
from helpers.graph import graph_env, read_line, roc, start_nodes, stop_all, stop_daemon, wait_for

from roc.doctor import environment, network
from roc.doctor.findings import Finding, summary
from roc.ros.protocol import discovery_range

# ---- units: the environment checks ---------------------------------------------------------------


@pytest.mark.parametrize("value, level", [("", "ok"), ("42", "ok"), ("230", "ok"), ("150", "warning"),
                                          ("233", "error"), ("x", "error")])
def test_domain_check(value: str, level: str) -> None:
    assert environment.domain({"ROS_DOMAIN_ID": value}).level == level


@pytest.mark.parametrize("env, levels", [
    ({}, ["ok"]), ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}, ["ok"]),
    ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "NEARBY"}, ["error"]), ({"ROS_LOCALHOST_ONLY": "1"}, ["warning"]),
    ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"}, ["warning"]),
    ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF", "ROS_STATIC_PEERS": "10.0.0.2"}, ["ok"])])
def test_discovery_check(env: dict[str, str], levels: list[str]) -> None:
    assert [f.level for f in environment.discovery(env)] == levels
    assert discovery_range({"ROS_LOCALHOST_ONLY": "1"}) == "LOCALHOST"


@pytest.mark.parametrize("rmem_max, level", [("212992\n", "info"), ("4194304\n", "ok"), ("8388608\n", "ok")])
def test_socket_buffer_check_tells_when_input_sockets_cannot_grow_to_what_roc_asks(
        tmp_path: Path, rmem_max: str, level: str) -> None:
    bound = tmp_path / "rmem_max"
    bound.write_text(rmem_max)
    found = network.socket_buffer_check(bound)
    assert found is not None and found.level == level
    assert ("sysctl -w net.core.rmem_max=4194304" in found.fix) == (level == "info")
    assert network.socket_buffer_check(tmp_path / "absent") is None


def _prefix(root: Path, *packages: str) -> Path:
    index = root / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    for package in packages:
        (index / package).write_text("")
    return root


def test_overlays_that_shadow_each_other_and_missing_prefixes(tmp_path: Path) -> None:
    overlay, underlay = _prefix(tmp_path / "ws", "a", "b", "own"), _prefix(tmp_path / "opt", "a", "b", "c")
    missing = tmp_path / "gone"
    findings = environment.overlays({"AMENT_PREFIX_PATH": os.pathsep.join(map(str, (overlay, missing, underlay)))})
    assert [(f.level, f.message) for f in findings] == [
        ("warning", f"{missing} (on AMENT_PREFIX_PATH) does not exist"),
        ("warning", f"2 package(s) of {overlay} shadow those of {underlay}: a, b")]
    assert environment.overlays({"AMENT_PREFIX_PATH": str(underlay)})[0].level == "ok"


def test_distribution_and_middleware_from_the_ament_index(monkeypatch, tmp_path: Path) -> None:
    monkeypatch.setenv("AMENT_PREFIX_PATH", sys.prefix)  # the venv's wheels: jazzy's rclpy, Fast DDS
    assert environment.distribution({"ROS_DISTRO": "jazzy"}).level == "ok"
    mixed = environment.distribution({"ROS_DISTRO": "humble"})
    assert mixed.level == "error" and "two distributions are sourced" in mixed.message
    assert environment.distribution({}).level == "info"
    assert environment.middleware({}).level == "ok"
    assert environment.middleware({"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}).level == "error"
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(_prefix(tmp_path / "empty")))
    monkeypatch.setattr("roc.environment.own_prefix", lambda: None)  # no ROS in roc's own environment either
    assert environment.distribution({}).level == "error"
    assert environment.distribution({"ROS_DISTRO": "foxy"}).level == "warning"


def test_a_check_fails_on_errors_and_with_include_warnings_on_warnings() -> None:
    findings = [Finding("graph", "qos", "error", "x"), Finding("graph", "qos", "error", "y"),
                Finding("graph", "topics", "warning", "z"), Finding("network", "multicast", "ok", "fine")]
    assert summary(findings, False) == {"checks": 3, "failed": 1, "failed_categories": ["graph"], "errors": 2,
                                             "warnings": 1}
    assert summary(findings, True)["failed"] == 2


# ---- live: roc doctor on graphs ------------------------------------------------------------------

TROUBLED = [{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String"},
                                              {"topic": "scan", "type": "std_msgs/msg/String",
                                               "reliability": "best_effort"}]},
            {"name": "listener", "subscribers": [{"topic": "scan", "type": "std_msgs/msg/String"},
                                                 {"topic": "cmd", "type": "std_msgs/msg/String"}]},
            {"name": "talker"}]
HEALTHY = [{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]},
           {"name": "listener", "subscribers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]}]



@pytest.fixture
def doctor_env(tmp_path: Path):
    env = graph_env(26, tmp_path / "runtime", AMENT_PREFIX_PATH=sys.prefix)
    yield env
    stop_daemon(env)


@contextlib.contextmanager
def running(specs: list, env: dict[str, str], topic: str):
    """The nodes of ``specs`` in one process, once the daemon has seen ``topic``."""
    processes = start_nodes([specs], env)
    try:
        wait_for(lambda: topic in roc("topic", "list", env=env).stdout.split())
        yield
    finally:
        stop_all(processes)


@pytest.mark.slow
def test_doctor_finds_what_is_wrong_with_a_graph(doctor_env):
    env = doctor_env
    with running(TROUBLED, env, "/cmd"):
        text = roc("doctor", env=env)
        assert text.returncode == 1, text.stdout + text.stderr
        assert "  error    node names: 2 nodes are named /talker\n" in text.stdout
        assert ("  error    qos: /scan: /talker -> /listener: incompatible reliability: publisher offers BEST_EFFORT, "
                "subscriber requests RELIABLE\n           fix: make the subscriber BEST_EFFORT or the publisher "
                "RELIABLE\n") in text.stdout
        assert "  warning  topics: Publisher without subscriber detected on /chatter.\n" in text.stdout
        assert "  warning  topics: Subscriber without publisher detected on /cmd.\n" in text.stdout
        assert text.stdout.endswith("/17 check(s) failed\n\nFailed modules: graph\n")
        data = json.loads(roc("doctor", "--format", "json", env=env).stdout)
        assert data["failed_categories"] == ["graph"] and data["errors"] == 2
        assert {(f["check"], f["level"]) for f in data["findings"] if f["category"] == "graph"} == {
            ("node names", "error"), ("qos", "error"), ("topics", "warning"), ("middlewares", "ok")}
        failed = roc("doctor", "--report-failed", env=env).stdout
        assert "\n   QOS COMPATIBILITY LIST\ntopic [type]            : /scan [std_msgs/msg/String]\n" in failed
        assert "PLATFORM INFORMATION" not in failed and "NETWORK CONFIGURATION" not in failed
        no_daemon = roc("doctor", "--no-daemon", "--format", "json", env=env)
        assert json.loads(no_daemon.stdout)["errors"] == 2


@pytest.mark.slow
def test_doctor_passes_a_healthy_graph_and_reports(doctor_env):
    env = doctor_env
    with running(HEALTHY, env, "/chatter"):
        healthy = roc("doctor", env=env)
        assert healthy.returncode == 0, healthy.stdout
        assert "graph:\n  ok       node names: 2 node(s), each named once\n" in healthy.stdout
        assert healthy.stdout.endswith("\nAll 17 checks passed\n")
        assert roc("wtf", env=env).returncode == 0  # ros2's alias
        report = roc("doctor", "--report", env=env)
        assert report.returncode == 0
        sections = [line.strip() for line in report.stdout.splitlines() if line.startswith("   ")]
        assert sections == ["PLATFORM INFORMATION", "ROS 2 INFORMATION", "ROS ENVIRONMENT", "RMW MIDDLEWARE",
                            "NETWORK CONFIGURATION", "TOPIC LIST", "QOS COMPATIBILITY LIST"]
        assert "topic               : /chatter\npublisher count     : 1\nsubscriber count    : 1\n" in report.stdout
        assert "middleware name    : rmw_fastrtps_cpp\n" in report.stdout
        strict = roc("doctor", "--include-warnings", "--no-daemon", env={**env, "ROS_LOCALHOST_ONLY": "1"})
        assert strict.returncode == 1 and "Failed modules: environment" in strict.stdout


# ---- multicast and hello ---------------------------------------------------------------------------

def _port(env: dict[str, str]) -> str:
    """A multicast port of this test file and worker (as its ROS domain is)."""
    return str(40000 + int(env["ROS_DOMAIN_ID"]))


@pytest.mark.slow
def test_multicast_send_and_receive_over_loopback(doctor_env):
    env, port = doctor_env, _port(doctor_env)
    on_loopback = ("--interface", "127.0.0.1", "--port", port)
    receiving = subprocess.Popen([str(BIN / "roc"), "multicast", "receive", *on_loopback, "--timeout", "20"],
                                 env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert read_line(receiving) == "Waiting for UDP multicast datagram...\n"
        sent = roc("multicast", "send", *on_loopback, env=env)
        assert (sent.returncode, sent.stdout) == (0, "Sending one UDP multicast datagram...\n")
        line = read_line(receiving)
        assert line.startswith("Received from 127.0.0.1:") and line.endswith(": 'Hello World!'\n")
        assert receiving.wait(timeout=10) == 0
    finally:
        stop_process(receiving)
    nothing = roc("multicast", "receive", *on_loopback, "--timeout", "0.3", "--format", "json", env=env)
    assert nothing.returncode == 1 and f"no datagram to 225.0.0.1:{port} within 0.3 s" in nothing.stderr
    assert roc("multicast", "send", "--port", "0", env=env).returncode == 2  # ros2's positive port


def _hello(env: dict[str, str], hostname: str | None, *flags: str) -> subprocess.Popen:
    command = [str(BIN / "roc"), "doctor", "hello", "--format", "json", "-pp", "0.5", "--interface", "127.0.0.1",
               "--port", _port(env), *flags]
    if hostname:  # another host: this machine in a UTS namespace of its own
        command = ["unshare", "-u", "sh", "-c", f'hostname {hostname} && exec "$@"', "hello", *command]
    return subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


@pytest.mark.slow
def test_doctor_hello_hosts_hear_each_other(doctor_env):
    if shutil.which("unshare") is None or subprocess.run(["unshare", "-u", "true"]).returncode != 0:
        pytest.skip("a second host needs a UTS namespace (unshare -u), which this user cannot make")
    env = doctor_env
    hellos = [_hello(env, None), _hello(env, "roc-doctor-peer", "--no-daemon")]
    try:
        # each summary counts one print period: the first ones may come before a host's own publisher
        # is up (the first starts the daemon), so wait for one where each host sent and heard
        heard: list[dict] = [{}, {}]
        last: list[dict] = [{}, {}]
        deadline = time.monotonic() + 30
        while not all(heard):
            assert time.monotonic() < deadline, last
            for index, hello in enumerate(hellos):
                line = read_line(hello, timeout=0.5)
                if line:
                    last[index] = json.loads(line)
                    if all(last[index][key] for key in ("published", "sent", "subscribed", "received")):
                        heard[index] = last[index]
        assert list(heard[1]["subscribed"]) == list(heard[1]["received"]) == [os.uname().nodename]
        assert list(heard[0]["subscribed"]) == list(heard[0]["received"]) == ["roc-doctor-peer"]
    finally:
        for hello in hellos:
            stop_process(hello)
    once = roc("doctor", "hello", "--once", "--interface", "127.0.0.1", "--port", _port(env), env=env)
    assert once.returncode == 0 and once.stdout.startswith("MULTIMACHINE COMMUNICATION SUMMARY\nTopic: "
                                                           "/canyouhearme, Published Msg Count: 1\n")
