"""The roc daemon's lifecycle: auto start, status, stop, replacement, socket mode, concurrent clients;
and daemon-less discovery that is complete on a graph of several processes."""

from __future__ import annotations

import json
import os
import signal
import stat
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from helpers.build import ros_domain_id
from helpers.graph import BIN, graph_env, roc, start_nodes, stop_all, stop_daemon

pytestmark = pytest.mark.slow


def status(env: dict[str, str]) -> dict:
    return json.loads(roc("daemon", "status", "--format", "json", env=env).stdout)


@pytest.fixture
def talker(tmp_path):
    env = graph_env(1, tmp_path / "runtime")
    (tmp_path / "runtime").mkdir()
    processes = start_nodes([{"name": "talker", "publishers": [{"topic": "chatter", "type": "std_msgs/msg/String"}]}],
                            env)
    yield env
    stop_daemon(env)
    stop_daemon({**env, "ROS_DOMAIN_ID": ros_domain_id(17)})
    stop_all(processes)


def test_lifecycle(talker):
    env = talker
    assert roc("daemon", "status", env=env).stdout.splitlines()[0] == "The daemon is not running"
    listed = roc("topic", "list", env=env)  # starts the daemon
    assert listed.returncode == 0 and "/chatter" in listed.stdout.splitlines()
    first = status(env)
    assert first["running"] and first["environment"]["ROS_DOMAIN_ID"] == env["ROS_DOMAIN_ID"]
    sock = Path(first["socket"])
    assert stat.S_IMODE(sock.stat().st_mode) == 0o600
    assert stat.S_IMODE(sock.parent.stat().st_mode) == 0o700
    assert roc("daemon", "status", env=env).stdout.splitlines()[0] == "The daemon is running"

    # Another discovery environment gets its own daemon.
    other = {**env, "ROS_DOMAIN_ID": ros_domain_id(17)}
    assert "/chatter" not in roc("topic", "list", env=other).stdout.splitlines()
    assert status(other)["pid"] != first["pid"]

    # A killed daemon leaves a dead socket: cleaned up and replaced.
    os.kill(first["pid"], 9)
    time.sleep(0.2)
    assert sock.exists()
    assert "/chatter" in roc("topic", "list", env=env).stdout.splitlines()
    second = status(env)
    assert second["pid"] != first["pid"]

    assert roc("daemon", "stop", env=env).stdout == "The daemon has been stopped\n"
    assert not sock.exists()
    assert roc("daemon", "stop", env=env).stdout == "The daemon is not running\n"

    # --all stops the daemons of every environment (here: the other domain's).
    assert status(other)["running"]
    assert roc("daemon", "stop", "--all", env=env).stdout == "Stopped 1 daemon\n"
    assert status(other)["running"] is False
    assert json.loads(roc("daemon", "stop", "--all", "--format", "json", env=env).stdout) == {"stopped": False,
                                                                                            "count": 0}


SESSION_WITHOUT_DAEMON = """
import json
from roc.ros.client import Session, daemon_status
session = Session()
running_during = daemon_status() is not None
nodes = [node["full_name"] for node in session.query("snapshot")["nodes"]]
session.close()
after = daemon_status()
print(json.dumps({"running_during": running_during, "nodes": nodes, "pid_after": after and after["pid"]}))
"""


def test_without_a_daemon_a_verb_answers_in_its_process_and_leaves_a_daemon_for_the_next(talker):
    """As ros2 does: a cold verb does not wait for a daemon to start and discover; it discovers in its
    own process and starts the daemon as it ends."""
    ran = subprocess.run([sys.executable, "-c", SESSION_WITHOUT_DAEMON], env=talker, capture_output=True,
                         text=True, timeout=60, cwd=Path(__file__).parents[2])
    assert ran.returncode == 0, ran.stderr
    result = json.loads(ran.stdout)
    assert result["running_during"] is False and result["nodes"] == ["/talker"]
    assert result["pid_after"] == status(talker)["pid"]
    assert roc("node", "list", env=talker).stdout == "/talker\n"  # the daemon's answer now


def test_the_daemon_is_out_of_the_terminal_s_reach_but_in_its_session(talker):
    """Its own process group: the terminal's Ctrl+C goes to the foreground group only; hang-up is
    ignored. The caller's session: a session of its own is a scheduling group of its own on Linux,
    where a busy machine starved the daemon for seconds (roc.ros.client.start_daemon)."""
    assert roc("daemon", "start", env=talker).returncode == 0
    pid = status(talker)["pid"]
    assert os.getpgid(pid) == pid
    assert os.getsid(pid) == os.getsid(0)
    os.kill(pid, signal.SIGHUP)
    time.sleep(0.5)
    assert status(talker)["pid"] == pid


def test_concurrent_clients_share_one_daemon(talker):
    env = talker
    with ThreadPoolExecutor(6) as pool:
        results = list(pool.map(lambda _: roc("node", "list", env=env), range(6)))
    assert all(r.returncode == 0 and r.stdout == "/talker\n" for r in results), [(r.stdout, r.stderr) for r in results]
    pids = [p for p in os.listdir("/proc") if p.isdigit()]
    daemons = []
    for pid in pids:
        try:
            cmdline = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
            environ = Path(f"/proc/{pid}/environ").read_bytes()
        except OSError:
            continue
        if b"roc.ros.daemon" in cmdline and env["XDG_RUNTIME_DIR"].encode() in environ:
            daemons.append(pid)
    assert len(daemons) == 1


def test_idle_daemon_exits(talker):
    env = {**talker, "ROC_DAEMON_IDLE_SECONDS": "1"}
    roc("daemon", "start", env=env)
    pid = status(env)["pid"]
    time.sleep(3)
    assert not Path(f"/proc/{pid}").exists() or b"Z" in Path(f"/proc/{pid}/stat").read_bytes().split()[2]
    assert roc("daemon", "status", env=env).stdout.splitlines()[0] == "The daemon is not running"


def test_bad_request_gets_an_error_line(talker):
    import socket

    env = talker
    roc("daemon", "start", env=env)
    sock = socket.socket(socket.AF_UNIX)
    sock.connect(status(env)["socket"])
    sock.sendall(b'{"id": 7, "method": "no_such_thing"}\nnot json\n')
    reader = sock.makefile()
    first, second = json.loads(reader.readline()), json.loads(reader.readline())
    sock.close()
    assert first["id"] == 7 and first["final"] and "no_such_thing" in first["error"]["message"]
    assert second["final"] and "error" in second


def test_a_client_gone_with_answers_unread_leaves_no_traceback_in_the_daemon_s_log(talker):
    """Closing a Unix socket with data unread resets the connection: the daemon's next read fails."""
    import socket

    env = talker
    roc("daemon", "start", env=env)
    path = Path(status(env)["socket"])
    before = path.with_suffix(".log").stat().st_size  # the log is appended to, run after run
    sock = socket.socket(socket.AF_UNIX)
    sock.connect(str(path))
    sock.sendall(b'{"id": 1, "method": "hello"}\n')
    time.sleep(0.3)  # the answer waits, unread
    sock.close()
    assert roc("topic", "list", env=env).returncode == 0  # the daemon still answers
    log = path.with_suffix(".log").read_bytes()[before:].decode()
    assert "Traceback" not in log, log


@pytest.mark.xdist_group("busy_or_timing")
def test_no_daemon_is_complete(tmp_path):
    """Five processes, ten daemon-less runs: every node every time (ros2 misses some in most runs)."""
    env = graph_env(2, tmp_path)
    specs = [{"name": f"node{i}", "publishers": [{"topic": f"topic{i}", "type": "std_msgs/msg/String"}]}
             for i in range(5)]
    processes = start_nodes(specs, env)
    try:
        expected = [f"/node{i}" for i in range(5)]
        for _ in range(5):
            got = roc("node", "list", "--no-daemon", env=env)
            assert got.stdout.splitlines() == expected
        assert status(env)["running"] is False
    finally:
        stop_all(processes)


def test_broken_pipe_is_quiet(talker):
    done = subprocess.run(f"'{BIN / 'roc'}' topic list --no-daemon --spin-time 0.5 | head -0", shell=True,
                          env=talker, capture_output=True, text=True, timeout=60)
    assert done.stderr == ""


@pytest.mark.parametrize("variable, value", [("ROS_DOMAIN_ID", "7"), ("RMW_IMPLEMENTATION", "rmw_cyclonedds_cpp"),
                                             ("ROS_AUTOMATIC_DISCOVERY_RANGE", "SUBNET"),
                                             ("ROS_STATIC_PEERS", "192.168.1.2"), ("ROS_LOCALHOST_ONLY", "1")])
def test_each_discovery_variable_has_its_own_daemon(variable: str, value: str) -> None:
    from roc.ros.client import daemon_key

    base = {"ROS_DOMAIN_ID": "3", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST", "PATH": "/usr/bin"}
    assert daemon_key({**base, variable: value}) != daemon_key(base)
    assert daemon_key({**base, "PATH": "/elsewhere", "HOME": "/tmp"}) == daemon_key(base)


def test_the_graph_honours_the_discovery_range(talker):
    """rcl applies the variables to roc's participant as to ros2's: with automatic discovery off (and no
    static peer) the talker on localhost is not found."""
    seen = roc("node", "list", "--no-daemon", env=talker).stdout.split()
    assert "/talker" in seen
    off = roc("node", "list", "--no-daemon", "--spin-time", "1", env={**talker, "ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"})
    assert off.returncode == 0 and "/talker" not in off.stdout.split()


LATE_PUBLISHER = r'''
import sys, time
import rclpy
from rclpy.qos import QoSProfile
from std_msgs.msg import String
rclpy.init()
node = rclpy.create_node("late_publisher")
publisher = node.create_publisher(String, "/late", QoSProfile(depth=100))
time.sleep(1.5)
for number in range(20):
    publisher.publish(String(data=str(number)))
    time.sleep(0.01)
time.sleep(0.5)
node.destroy_node()
rclpy.shutdown()
'''


def test_a_long_running_daemon_hears_each_new_publisher_from_its_first_message(tmp_path):
    """A Fast DDS participant that starts while an older one announces itself can miss the older one
    until its next announcement (Fast DDS: every 3 s). Through a daemon that had run a while, echo
    started up to 3 s late on a new publisher, in about half the runs; roc's participants announce
    themselves every 0.5 s (roc/ros/vendors/fastdds_participant.xml)."""
    env = graph_env(16, tmp_path)
    try:
        assert roc("daemon", "start", env=env).returncode == 0
        time.sleep(4)  # the daemon announces itself periodically by now
        echo = subprocess.Popen([str(BIN / "roc"), "topic", "echo", "/late", "std_msgs/msg/String", "--format", "json"],
                                env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        try:
            time.sleep(1.5)  # subscribed in the daemon
            for _ in range(5):  # five new publishers, one after the other, each sending 1.5 s after it started
                subprocess.run([sys.executable, "-c", LATE_PUBLISHER], env=env, check=True, timeout=60)
            time.sleep(0.5)
        finally:
            echo.send_signal(signal.SIGINT)
            output = echo.communicate(timeout=15)[0]
    finally:
        stop_daemon(env)
    received = [json.loads(line)["message"]["data"] for line in output.splitlines() if line.startswith("{")]
    assert received == [str(number) for number in range(20)] * 5
