"""Daemon lifetime (the idle exit and its setting, roc daemon status --all) and the dynamic completion of
graph names through a running daemon, in a real bash, zsh and fish."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
from helpers.build import NODES, stop_process
from helpers.graph import graph_env, read_line, roc, start_nodes, stop_all, stop_daemon, with_tf2_msgs

from roc.ros import daemon

pytestmark = pytest.mark.slow


def test_idle_seconds_default_and_setting() -> None:
    assert daemon.DEFAULT_IDLE_SECONDS == 300  # docs/daemon.md says so
    assert daemon.idle_seconds({}) == 300 and daemon.idle_seconds({"ROC_DAEMON_IDLE_SECONDS": "42"}) == 42
    assert daemon.idle_seconds({"ROC_DAEMON_IDLE_SECONDS": "soon"}) == 300
    assert daemon.idle_seconds({"ROC_DAEMON_IDLE_SECONDS": "-1"}) == 300


def _status(env: dict[str, str], *flags: str):
    return json.loads(roc("daemon", "status", "--format", "json", *flags, env=env).stdout)


@pytest.fixture
def short_runtime():
    """A runtime directory of this test alone whose path is short enough for a Unix socket (else roc
    falls back to the user's shared /tmp/roc-UID, where 'daemon stop --all' would meet other tests')."""
    path = Path(tempfile.mkdtemp(prefix="rt", dir="/tmp"))
    yield path
    shutil.rmtree(path, ignore_errors=True)


def test_status_all_lists_every_daemon_with_its_environment(short_runtime: Path) -> None:
    env = graph_env(27, short_runtime)
    other = {**env, "ROS_STATIC_PEERS": "127.0.0.1"}  # another discovery environment: another daemon
    try:
        assert roc("daemon", "status", "--all", env=env).stdout == "No daemon is running\n"
        assert _status(env, "--all") == []
        roc("daemon", "start", env=env)
        roc("daemon", "start", env={**other, "ROC_DAEMON_IDLE_SECONDS": "120"})
        listed = _status(env, "--all")
        assert [d["pid"] for d in listed] == [_status(env)["pid"], _status(other)["pid"]]  # oldest first
        assert [d["environment"]["ROS_STATIC_PEERS"] for d in listed] == ["", "127.0.0.1"]
        assert [d["idle_seconds"] for d in listed] == [300, 120]
        assert all(Path(d["socket"]).parent == short_runtime / "roc" for d in listed)
        lines = roc("daemon", "status", "--all", env=env).stdout.splitlines()
        assert lines[0].split() == ["PID", "UPTIME", "SOCKET", "ENVIRONMENT"]
        domain = env["ROS_DOMAIN_ID"]
        assert lines[1].split()[0] == str(listed[0]["pid"]) and lines[1].endswith(
            f"ROS_DOMAIN_ID={domain} ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST")
        assert lines[2].endswith(
            f"ROS_DOMAIN_ID={domain} ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST ROS_STATIC_PEERS=127.0.0.1")
        assert roc("daemon", "stop", "--all", env=env).stdout == "Stopped 2 daemons\n"
        assert _status(env, "--all") == []
    finally:
        stop_daemon(other)
        stop_daemon(env)


# ---- completion of graph names -------------------------------------------------------------------

GRAPH = [{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String"}],
          "parameters": {"max_speed": 1.5, "mode": "fast"}},
         {"name": "motor", "services": [{"name": "~/enable", "type": "std_srvs/srv/SetBool"}],
          "actions": [{"name": "fibonacci"}]}]


@pytest.fixture(scope="module")
def graph(tmp_path_factory):
    env = graph_env(27, tmp_path_factory.mktemp("runtime"))
    processes = start_nodes([GRAPH], env)
    yield env
    stop_daemon(env)
    stop_all(processes)


def names(env: dict[str, str], kind: str, *flags: str) -> list[str]:
    result = roc("completion", "--names", kind, *flags, env=env)
    assert result.returncode == 0 and result.stderr == ""
    return result.stdout.split()


def test_without_a_daemon_nothing_starts_and_only_installed_types_complete(graph):
    env = graph
    stop_daemon(env)
    for kind in ("topics", "nodes", "services", "actions", "frames"):
        assert names(env, kind) == []
    assert names(env, "params", "--node", "/talker") == []
    assert "std_msgs/msg/String" in names(env, "types") and "std_srvs/srv/SetBool" in names(env, "srv-types")
    assert "std_srvs/srv/SetBool" not in names(env, "msg-types")
    assert _status(env)["running"] is False  # no daemon was started, nor any participant


def _wait_for_names(env: dict[str, str]) -> None:
    roc("daemon", "start", env=env)
    deadline = time.monotonic() + 20
    while "/fibonacci" not in names(env, "actions") or "/chatter" not in names(env, "topics"):
        assert time.monotonic() < deadline, "the daemon never saw the graph"
        time.sleep(0.2)


def test_names_from_a_running_daemon(graph):
    env = graph
    _wait_for_names(env)
    assert "/chatter" in names(env, "topics") and "/parameter_events" in names(env, "topics")
    assert names(env, "nodes") == ["/motor", "/talker"]
    assert "/motor/enable" in names(env, "services")
    assert names(env, "actions") == ["/fibonacci"]
    assert {"max_speed", "mode", "use_sim_time"} <= set(names(env, "params", "--node", "/talker"))


BASH_PROBES = [  # words after 'roc' -> what bash offers
    (["topic", "echo", "/ch"], "/chatter"),
    (["topic", "echo", "--qos-depth", "5", "/ch"], "/chatter"),  # past an option and its value
    (["topic", "echo", "/chatter", "std_msgs/msg/Str"], "std_msgs/msg/String"),  # the second positional: a type
    (["topic", "hz", "/chatter", "/ch"], "/chatter"),  # every topic of a list
    (["node", "info", "/t"], "/talker"),
    (["service", "call", "/motor/en"], "/motor/enable"),
    (["service", "call", "/motor/enable", "std_srvs/srv/SetB"], "std_srvs/srv/SetBool"),
    (["action", "send_goal", "/f"], "/fibonacci"),
    (["param", "get", "/talker", "max"], "max_speed"),
    (["param", "get", "/tal"], "/talker"),
    (["lifecycle", "get", "/mo"], "/motor"),
    (["interface", "show", "std_srvs/srv/Trig"], "std_srvs/srv/Trigger"),
    (["topic", "echo", "--qos-profile", "sensor"], "sensor_data"),
]


def _bash(script: Path, probes: list, env: dict[str, str]) -> list[str]:
    lines = [f"source {script}"]
    for words, _ in probes:
        quoted = " ".join(f"'{w}'" for w in ["roc", *words])
        lines.append(f'COMP_WORDS=({quoted}); COMP_CWORD={len(words)}; _roc_complete; echo "${{COMPREPLY[*]}}"')
    result = subprocess.run(["bash", "-c", "\n".join(lines)], env=env, capture_output=True, text=True, timeout=120)
    return result.stdout.splitlines()


def _script(shell: str, env: dict[str, str], directory: Path) -> Path:
    path = directory / f"roc.{shell}"
    path.write_text(roc("completion", shell, env=env).stdout)
    return path


def test_bash_completes_graph_names(graph, tmp_path: Path):
    env = graph
    _wait_for_names(env)
    assert _bash(_script("bash", env, tmp_path), BASH_PROBES, env) == [expected for _, expected in BASH_PROBES]


def test_zsh_completes_graph_names(graph, tmp_path: Path):
    if shutil.which("zsh") is None:
        pytest.skip("zsh is not installed (scripts/setup.sh installs it when apt is available)")
    env = graph
    _wait_for_names(env)
    script = _script("zsh", env, tmp_path)
    # zsh's compgen emulation leaves filtering to zsh's completion system (not run here): each probe
    # shows every name of the kind offered
    probes = [(["node", "info", "/t"], "/motor /talker"), (["action", "send_goal", "/f"], "/fibonacci"),
              (["param", "describe", "/talker", "m"], None)]
    lines = [f"source {script}", "setopt ksharrays"]
    for words, _ in probes:
        lines.append(f"COMP_WORDS=(roc {' '.join(words)}); COMP_CWORD={len(words)}; _roc_complete; "
                     'echo "${COMPREPLY[*]}"')
    result = subprocess.run(["zsh", "-f", "-c", "\n".join(lines)], env={**env, "HOME": str(tmp_path)},
                            capture_output=True, text=True, timeout=120)
    got = result.stdout.splitlines()
    assert got[:2] == ["/motor /talker", "/fibonacci"], result.stderr
    assert {"max_speed", "mode", "use_sim_time"} <= set(got[2].split())


@pytest.mark.parametrize("line, expected", [
    ("roc topic echo /ch", ["/chatter"]),
    ("roc topic echo /chatter std_msgs/msg/Str", ["std_msgs/msg/String"]),
    ("roc node info /ta", ["/talker"]),
    ("roc param get /talker max", ["max_speed"]),
    ("roc action send_goal /fi", ["/fibonacci"]),
    ("roc service type /motor/en", ["/motor/enable"]),
])
def test_fish_completes_graph_names(graph, tmp_path: Path, line: str, expected: list[str]):
    if shutil.which("fish") is None:
        pytest.skip("fish is not installed (scripts/setup.sh installs it when apt is available)")
    env = graph
    _wait_for_names(env)
    script = _script("fish", env, tmp_path)
    assert subprocess.run(["fish", "-n", str(script)], capture_output=True).returncode == 0
    result = subprocess.run(["fish", "--no-config", "-c", f"source {script}; complete -C '{line}'"],
                            env={**env, "HOME": str(tmp_path)}, capture_output=True, text=True, timeout=120)
    assert [row.split("\t")[0] for row in result.stdout.splitlines()] == expected, result.stderr


def test_frames_complete_from_tf(tmp_path: Path):
    """tf2_msgs (not among the wheels) built from the example workspace and sourced, a tf publisher."""
    (tmp_path / "runtime").mkdir()
    env = with_tf2_msgs(graph_env(27, tmp_path / "runtime"))
    publisher = subprocess.Popen([sys.executable, str(NODES / "tf_node.py"), "publish"], env=env,
                                 stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        assert read_line(publisher, 60) == "ready\n"
        assert names(env, "frames") == []  # no daemon: nothing, and none started
        roc("daemon", "start", env=env)
        deadline = time.monotonic() + 20
        while names(env, "frames") != ["base_link", "laser", "map", "odom"]:
            assert time.monotonic() < deadline, names(env, "frames")
        probe = [(["frame", "echo", "map", "la"], "laser")]
        assert _bash(_script("bash", env, tmp_path), probe, env) == ["laser"]
    finally:
        stop_process(publisher)
        stop_daemon(env)
