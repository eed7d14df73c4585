"""roc interface verbs against the real ros2 CLI (same AMENT_PREFIX_PATH), and roc's QoS checks."""

from __future__ import annotations

import json
import re

import pytest
from helpers.graph import graph_env, install_oracle, roc, ros2, stop_daemon

from roc.ros.present import qos_problems, topic_problems
from roc.ros.types import UnknownTypeError, resolve_type


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    reason = install_oracle()
    if reason:
        pytest.skip(f"the ros2 CLI oracle is not available: {reason}")
    env = graph_env(4, tmp_path_factory.mktemp("runtime"))
    yield env
    stop_daemon(env)  # interface show asks the graph (through the daemon) for a type not installed


TYPES = ["nav_msgs/msg/Odometry", "geometry_msgs/msg/Twist", "std_srvs/srv/SetBool", "test_msgs/action/Fibonacci",
         "sensor_msgs/msg/Image", "rcl_interfaces/msg/ParameterDescriptor", "visualization_msgs/msg/MarkerArray",
         "rcl_interfaces/msg/Log", "trajectory_msgs/msg/JointTrajectory", "sensor_msgs/msg/CameraInfo"]


@pytest.mark.slow
@pytest.mark.parametrize("options", [(), ("--no-comments",), ("--all-comments",)], ids=lambda o: " ".join(o) or "default")
@pytest.mark.parametrize("type_name", TYPES)
def test_show_same_as_ros2(env, type_name, options):
    got, expected = roc("interface", "show", *options, type_name, env=env), ros2("interface", "show", *options,
                                                                                type_name, env=env)
    assert got.returncode == 0, got.stderr
    assert got.stdout.splitlines() == expected.stdout.splitlines()


@pytest.mark.slow
@pytest.mark.parametrize("command", [("list",), ("list", "-m"), ("list", "-s", "-a"), ("packages",),
                                     ("packages", "-a"), ("package", "std_msgs"), ("package", "test_msgs")])
def test_listings_same_as_ros2(env, command):
    got, expected = roc("interface", *command, env=env), ros2("interface", *command, env=env)
    assert got.returncode == 0, got.stderr
    # ros2 prints one package's interfaces in no particular order; roc sorts them.
    key = sorted if command[0] == "package" else list
    assert key(got.stdout.splitlines()) == key(expected.stdout.splitlines())


@pytest.mark.slow
@pytest.mark.parametrize("options", [(), ("--no-quotes",)], ids=lambda o: " ".join(o) or "default")
@pytest.mark.parametrize("type_name", ["geometry_msgs/msg/Twist", "std_srvs/srv/SetBool", "test_msgs/action/Fibonacci",
                                       "nav_msgs/msg/Odometry", "visualization_msgs/msg/Marker"])
def test_proto_same_as_ros2(env, type_name, options):
    import sys
    from pathlib import Path

    site = Path(sys.prefix) / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "site-packages"
    oracle_env = {**env, "PYTHONPATH": str(site)}  # the oracle's venv lacks the message packages
    got, expected = roc("interface", "proto", *options, type_name, env=env), ros2("interface", "proto", *options,
                                                                                 type_name, env=oracle_env)
    assert got.returncode == 0, got.stderr
    assert got.stdout == expected.stdout


def test_unknown_interface_says_ros2s_line_then_roc_s(env):
    got = roc("interface", "show", "std_msgs/msg/Strin", env=env)
    ros2_line, roc_line = got.stderr.splitlines()
    assert got.returncode == 1 and re.fullmatch(r"Could not find the interface '.+/std_msgs/msg/Strin\.idl'", ros2_line)
    assert roc_line == "roc: error: std_msgs has no msg named 'Strin'; did you mean 'String'?"
    got = roc("interface", "show", "std_msgs/msg/Nope", env=env)
    assert got.stderr.splitlines()[1] == ("roc: error: std_msgs has no msg named 'Nope'; 'roc interface package "
                                          "std_msgs' lists its interfaces")
    assert roc("interface", "package", "nope", env=env).stderr == "roc: error: Unknown package 'nope'\n"
    proto = roc("interface", "proto", "nope/msg/X", env=env)
    assert proto.returncode == 1 and len(proto.stderr.splitlines()) == 1


def test_show_json(env):
    data = json.loads(roc("interface", "show", "std_msgs/msg/String", "--format", "json", env=env).stdout)
    assert data["type"] == "std_msgs/msg/String" and data["file"].endswith("String.msg")
    assert "string data" in data["text"]


def _endpoint(kind: str, **qos) -> dict:
    base = {"reliability": "RELIABLE", "history": "UNKNOWN", "depth": 0, "durability": "VOLATILE",
            "lifespan_ns": None, "deadline_ns": None, "liveliness": "AUTOMATIC", "liveliness_lease_duration_ns": None}
    return {"node_name": kind, "node_namespace": "/", "topic_type": "std_msgs/msg/String",
            "topic_type_hash": "RIHS01_a", "endpoint_type": kind.upper(), "gid": "0", "qos": {**base, **qos}}


def test_qos_checks_name_the_policy_and_fix():
    assert qos_problems(_endpoint("publisher"), _endpoint("subscription")) == []
    problems = qos_problems(_endpoint("publisher", reliability="BEST_EFFORT", durability="VOLATILE",
                                      deadline_ns=None, liveliness_lease_duration_ns=2_000_000_000),
                            _endpoint("subscription", durability="TRANSIENT_LOCAL", deadline_ns=100_000_000,
                                      liveliness="MANUAL_BY_TOPIC", liveliness_lease_duration_ns=1_000_000_000))
    assert [p["policy"] for p in problems] == ["reliability", "durability", "deadline", "liveliness",
                                               "liveliness_lease_duration"]
    assert all(p["fix"] for p in problems)
    # Offering more than requested is fine.
    assert qos_problems(_endpoint("publisher", durability="TRANSIENT_LOCAL", deadline_ns=10),
                        _endpoint("subscription", reliability="BEST_EFFORT", deadline_ns=20)) == []


def test_type_mismatch_is_flagged():
    other = _endpoint("subscription")
    other["topic_type_hash"] = "RIHS01_b"
    problems = topic_problems({"publishers": [_endpoint("publisher")], "subscribers": [other]})
    assert [p["kind"] for p in problems] == ["type"]


def test_only_close_interface_package_names_are_suggested() -> None:
    with pytest.raises(UnknownTypeError) as far:
        resolve_type("foo_msgs/msg/Bar")
    assert "did you mean" not in str(far.value)
    with pytest.raises(UnknownTypeError) as near:
        resolve_type("std_msg/msg/String")
    assert "(did you mean 'std_msgs'?)" in str(near.value)
